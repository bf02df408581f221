#!/usr/bin/env bash
# Cost per transition against chain length (part of make bench): the random 1000-block
# Coulomb chain of configs/chains/bk1000_coulomb.ini cut or grown to N blocks, and the same
# chain uniform (every block alike, started relaxed: it slides as one), run by the CLI as a
# user would (output.interval = 0, everything else at its default) with the exact stepper,
# the default integrator (gsl_rk8pd, what auto picks for a non-stiff scene that is not
# Coulomb) and cvode_bdf.  Each run is one process timed by /usr/bin/time: CPU (user + sys)
# and peak resident memory.  Every N up to 1e5 runs the same simulated window (t_end = 2 s,
# the config's), so each size sees the same physics; N = 1e6 runs one short window.
# usage: scripts/bench_scaling.sh [--quick | --plot-only] OUTDIR
# Writes OUTDIR/scaling.tsv, scaling_slopes.tsv (least-squares slope of log CPU per
# transition against log N over the full-window sizes, and the ratio at 1e5 over 1e3),
# scaling.png and scaling_memory.png; and peak memory against the length of a run on the
# random chain (scaling_run_length.tsv, scaling_run_length.png): a long run's memory must
# follow the chain, not the run.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"
quick=0 plot_only=0
case "${1:-}" in
    --quick) quick=1; shift ;;
    --plot-only) plot_only=1; shift ;;
    -h|--help) bk_help ;;
esac
[ $# -ge 1 ] || bk_usage "missing OUTDIR"
out=$1
mkdir -p "$out"
bk_need_command /usr/bin/time time

config=configs/chains/bk1000_coulomb.ini
methods=(exact gsl_rk8pd cvode_bdf)
if [ $quick = 1 ]; then
    sizes=(100 1000); window=0.7; big=(); max_repeats=1
else
    sizes=(100 1000 10000 100000); window=2; big=(1000000); max_repeats=10
fi
# The short window: the random chain's first 1e5 transitions per 1e6 blocks (blocks with the
# largest offsets fail first); the uniform chain's first slide (at 0.5886 s, all blocks).
short_window() { [ "$1" = uniform ] && echo 0.7 || echo 0.3; }
# cvode_bdf's band solver on every island is an order slower: its largest full-window size
# would take about 15 minutes at 1e5 blocks (1e4 takes 100 s), so it runs the short window there.
bdf_full_max=10000
# Run lengths for the memory-over-time rows: the random chain at long_n blocks, windows that
# double, for exact and the default integrator; then the 1e6-block chain for 0.3 s and 1 s (13
# million transitions) with exact.
if [ $quick = 1 ]; then
    long_n=1000; lengths=(0.7 1.4 2.8); long_big=0
else
    long_n=100000; lengths=(0.5 1 2); long_big=1
fi

bk_temp_dir scratch

tsv=$out/scaling.tsv
if [ $plot_only = 0 ]; then
    bk_find_bksim bksim
    scripts/machine_info.sh > "$out/scaling_machine.txt"
    printf 'chain\tn_blocks\tmethod\tt_end_s\tstatus\ttransitions\tcpu_s\trepeats\tcpu_per_transition_s\tpeak_rss_mb\tsteps\trhs_evals\n' > "$tsv"

    # run CHAIN N METHOD T_END: one row of scaling.tsv.  A run under a second is repeated (up
    # to 10 times, until a second of CPU in all) against the 10 ms resolution of the clock.
    run() {
        local chain=$1 n=$2 method=$3 t_end=$4 extra=() status=ok cpu=0 rss=0 repeats=0
        [ "$chain" = uniform ] && extra=(--set block.x_init_random=0)
        local log=$scratch/log
        while :; do
            /usr/bin/time -f 'TIME %U %S %M' "$bksim" run "$config" --set model.n_blocks="$n" \
                --set output.interval=0 --set solver.method="$method" --set run.t_end="$t_end" \
                --set output.path="$scratch/run.h5" "${extra[@]}" > "$log" 2>&1 || status=failed
            rm -f "$scratch/run.h5"
            repeats=$((repeats + 1))
            read -r cpu rss < <(awk -v cpu="$cpu" -v rss="$rss" '/^TIME / {
                r = $4 / 1024; print cpu + $2 + $3, (r > rss ? r : rss) }' "$log")
            [ $status = ok ] && awk -v c="$cpu" -v k=$repeats -v max=$max_repeats 'BEGIN { exit !(c < 1 && k < max) }' || break
        done
        # The CLI's summary: "<file>: R rows, T transitions, t = ..., S steps, E RHS evaluations, ..."
        awk -v chain="$chain" -v n="$n" -v m="$method" -v t="$t_end" -v status="$status" -v cpu="$cpu" \
            -v rss="$rss" -v k=$repeats '
            / transitions, t = / { for (i = 1; i <= NF; ++i) {
                                       if ($(i + 1) ~ /^transitions,/) tr = $i
                                       if ($(i + 1) ~ /^steps,/) st = $i
                                       if ($(i + 1) == "RHS") rhs = $i } }
            END { if (tr == "") { status = "failed"; tr = 0 }
                  per = tr > 0 ? cpu / k / tr : 0
                  if (st == "") st = "-"
                  if (rhs == "") rhs = "-"
                  printf "%s\t%s\t%s\t%s\t%s\t%d\t%.3f\t%d\t%.4g\t%.1f\t%s\t%s\n", chain, n, m, t, status, tr,
                         cpu / k, k, per, rss, st, rhs }' "$log" >> "$tsv"
        tail -n 1 "$tsv" >&2
    }

    for chain in random uniform; do
        for n in "${sizes[@]}"; do
            for m in "${methods[@]}"; do
                if [ "$m" = cvode_bdf ] && [ "$n" -gt $bdf_full_max ]; then
                    run "$chain" "$n" "$m" "$(short_window "$chain")"
                else
                    run "$chain" "$n" "$m" "$window"
                fi
            done
        done
        for n in "${big[@]}"; do
            for m in "${methods[@]}"; do
                run "$chain" "$n" "$m" "$(short_window "$chain")"
            done
        done
    done

    # The same rows for runs of growing length, into their own table.
    full_tsv=$tsv
    tsv=$out/scaling_run_length.tsv
    head -n 1 "$full_tsv" > "$tsv"
    for t in "${lengths[@]}"; do
        for m in exact gsl_rk8pd; do
            run random "$long_n" "$m" "$t"
        done
    done
    if [ $long_big = 1 ]; then run random 1000000 exact 0.3 && run random 1000000 exact 1; fi
    tsv=$full_tsv
fi

# Slopes over the full-window sizes (>= 100 blocks), and the ratio 1e5 : 1e3 when both ran.
awk -F'\t' -v window=$window '
    NR > 1 && $5 == "ok" && $4 == window && $9 > 0 {
        key = $1 "\t" $3; x = log($2); y = log($9)
        n[key]++; sx[key] += x; sy[key] += y; sxx[key] += x * x; sxy[key] += x * y
        if ($2 == 1000) small[key] = $9
        if ($2 == 100000) large[key] = $9
        if (!(key in lo) || $2 < lo[key]) lo[key] = $2
        if ($2 > hi[key]) hi[key] = $2 }
    END { print "chain\tmethod\tpoints\tsizes\tslope\tratio_1e5_1e3"
          for (k in n) {
              if (n[k] < 2) continue
              ratio = "-"
              if ((k in small) && (k in large)) ratio = sprintf("%.2f", large[k] / small[k])
              slope = (n[k] * sxy[k] - sx[k] * sy[k]) / (n[k] * sxx[k] - sx[k] * sx[k])
              printf "%s\t%d\t%d-%d\t%.3f\t%s\n", k, n[k], lo[k], hi[k], slope, ratio
          } }' "$tsv" |
    (read -r head; echo "$head"; sort) > "$out/scaling_slopes.tsv"

# CPU per transition and peak memory against N, one curve per chain and method.
colors=('#000000' '#e41a1c' '#377eb8')
plots_cpu="" plots_mem=""
for chain in random uniform; do
    k=0
    for m in "${methods[@]}"; do
        f=$scratch/${chain}_$m.dat
        awk -F'\t' -v c="$chain" -v m="$m" 'NR > 1 && $1 == c && $3 == m && $5 == "ok" && $6 > 0 {print $2, $9, $10, $4}' "$tsv" > "$f"
        if [ -s "$f" ]; then
            dt=$([ $chain = uniform ] && echo 2 || echo 1)
            pt=$([ $chain = uniform ] && echo 6 || echo 7)
            plots_cpu="$plots_cpu${plots_cpu:+, }'$f' using 1:2 with linespoints lw 2 dt $dt pt $pt ps 1.4 lc rgb '${colors[k]}' title '$m, $chain chain'"
            plots_mem="$plots_mem${plots_mem:+, }'$f' using 1:3 with linespoints lw 2 dt $dt pt $pt ps 1.4 lc rgb '${colors[k]}' title '$m, $chain chain'"
        fi
        k=$((k + 1))
    done
done
gnuplot <<GP
set terminal pngcairo size 1200,800 font 'Sans,12' noenhanced
set output '$out/scaling.png'
set title 'CPU time per transition vs chain length (Coulomb chain, interval = 0; t_end = $window s, the largest sizes a short window)'
set logscale xy
set xlabel 'blocks N'
set ylabel 'CPU time per transition [s]'
set format x '1e%L'
set format y '1e%L'
set grid
set key top left
plot $plots_cpu
GP
gnuplot <<GP
set terminal pngcairo size 1200,800 font 'Sans,12' noenhanced
set output '$out/scaling_memory.png'
set title 'Peak resident memory vs chain length (same runs)'
set yrange [10:*]
set logscale xy
set xlabel 'blocks N'
set ylabel 'peak resident memory [MB]'
set format x '1e%L'
set grid
set key top left
f(x) = 1e-3 * x
plot $plots_mem, f(x) with lines dt 3 lc rgb '#777777' title '1 kB per block'
GP

# Peak memory against the transitions a run made, one curve per chain length and method:
# flat when memory follows the chain.
lengths_tsv=$out/scaling_run_length.tsv
if [ -s "$lengths_tsv" ]; then
    plots_len="" k=0
    for key in $(awk -F'\t' 'NR > 1 && $5 == "ok" {print $2 ":" $3}' "$lengths_tsv" | sort -u -t: -k1,1n -k2); do
        n=${key%%:*} m=${key#*:}
        f=$scratch/len_${n}_$m.dat
        awk -F'\t' -v n="$n" -v m="$m" 'NR > 1 && $2 == n && $3 == m && $5 == "ok" {print $6, $10}' "$lengths_tsv" > "$f"
        pt=$([ "$m" = exact ] && echo 7 || echo 5)
        plots_len="$plots_len${plots_len:+, }'$f' using 1:2 with linespoints lw 2 pt $pt ps 1.4 lc $((k + 1)) title '$m, N = $n'"
        k=$((k + 1))
    done
    gnuplot <<GP
set terminal pngcairo size 1200,800 font 'Sans,12' noenhanced
set output '$out/scaling_run_length.png'
set title 'Peak resident memory vs length of the run (random chain, interval = 0)'
set logscale x
set xlabel 'transitions in the run'
set ylabel 'peak resident memory [MB]'
set yrange [0:*]
set format x '1e%L'
set grid
set key top left
plot $plots_len
GP
fi
