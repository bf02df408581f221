#!/usr/bin/env bash
# CPU per rupture against chain length on a rate-and-state chain (issue 32): the
# Dieterich-Ruina ring of configs/chains/dieterich_ruina_30.ini resized to N blocks
# (model.n_blocks = N, every block drawn its own x_init_random from the config's seed), run
# as a user keeps only the catalog (output.interval = 0: rows at t = 0 and t_end only; the
# rupture catalog on), each run one process timed by /usr/bin/time (CPU = user + sys, and
# peak resident memory).  A rate-and-state block never sticks, so the whole ring is one
# island: integrated at once (method "whole", local_stepping = off) a rupture's cost grows
# with N; cut into segments with their own integrators ("local", local_stepping = on, README
# "Long chains") it should not.  The target: CPU per rupture at N = 10^4 within 3x that of
# N = 30 (the flat line on the plot).
# The chain starts at steady sliding and its first seconds are a transient (quiet, then a
# burst of ruptures as the perturbations grow), so each N is run twice from the same start:
# to t_skip and to t_end.  The window is [t_skip, t_end]: its CPU is the difference of the
# two runs' CPU, its ruptures are the rows of /ruptures that start in it (complete or still
# running at t_end: the work of those straddling either end is counted at one end as it is
# not at the other), and CPU per rupture is the one over the other.  t_end = t_skip + R /
# (rate * N) holds about R ruptures: rate is the ruptures per block per second the previous
# N's window showed (0.16 for the first, the config's 967 ruptures in 200 s at N = 30).
# Sizes grow until a size's projected CPU (both runs, from the previous size's CPU scaled by
# the growth of CPU per rupture seen so far, N^1 at first) exceeds the budget: that size and
# the larger ones get a row "skipped"; a run still going after 3x the budget of wall time
# is stopped ("timeout").  Exits 1 when a run failed (the table and plot are written still).
# usage: scripts/bench_rs_chains.sh [--quick | --plot-only] [--method SPEC]... [--sizes LIST]
#                                   [--ruptures R] [--skip SECONDS] [--budget SECONDS]
#                                   [--set S.K=V]... [--format png|pdf|svg] OUTDIR
#   --quick            N = 30 100, R = 20, t_skip = 1 s, budget 60 s: a smoke run
#   --plot-only        redraw the plot from OUTDIR/rs_chains.tsv, run nothing
#   --method SPEC      a method to measure (repeatable; default $RS_METHODS, a list
#                      separated by spaces, else the whole ring and the ring in segments,
#                      cvode_bdf as the config has it: whole:solver.local_stepping=off
#                      local:solver.local_stepping=on): a value of
#                      solver.method, or LABEL:S.K=V[,S.K=V...] (the settings that select
#                      it, the label naming its rows and curve)
#   --sizes LIST       chain lengths, comma-separated (default 30,100,300,1000,3000,10000)
#   --ruptures R       ruptures wanted in each window (default 200)
#   --skip SECONDS     t_skip, the transient left out (default 2)
#   --budget SECONDS   CPU allowed to one size, both runs (default 600)
#   --set S.K=V        passed to every run (repeatable), after the method's settings
#   --format F         the plot's format (default png)
# Writes OUTDIR/rs_chains.tsv (one row per method and N, under '#' comment lines that say
# how it was measured and on what machine), OUTDIR/rs_chains_machine.txt and
# OUTDIR/rs_chains.png (or .pdf, .svg: CPU per rupture against N, log-log, with 3x N = 30 of
# the first method and a line proportional to N through that N = 30, for reference).  A
# relative OUTDIR is taken from where the script is started.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"

config=configs/chains/dieterich_ruina_30.ini
quick=0 plot_only=0 format=png failures=0
specs=() sets=() set_values=() sizes_arg="" ruptures_arg="" skip_arg="" budget_arg="" out=""
while [ $# -gt 0 ]; do
    case $1 in
        --quick) quick=1; shift ;;
        --plot-only) plot_only=1; shift ;;
        --method) bk_need_value $# "$1" "a method"; specs+=("$2"); shift 2 ;;
        --sizes) bk_need_value $# "$1" "a list of chain lengths"; sizes_arg=$2; shift 2 ;;
        --ruptures) bk_need_value $# "$1" "a number of ruptures"; ruptures_arg=$2; shift 2 ;;
        --skip) bk_need_value $# "$1" "a time in seconds"; skip_arg=$2; shift 2 ;;
        --budget) bk_need_value $# "$1" "a CPU time in seconds"; budget_arg=$2; shift 2 ;;
        --set) bk_need_value $# "$1" "S.K=V"; sets+=(--set "$2"); set_values+=("$2"); shift 2 ;;
        --format) bk_need_value $# "$1" "png, pdf or svg"; format=$2; shift 2 ;;
        -h|--help) bk_help ;;
        -*) bk_usage "unknown option '$1'" ;;
        *) [ -z "$out" ] || bk_usage "unexpected argument '$1'"
           out=$1; shift ;;
    esac
done
[ -n "$out" ] || bk_usage "missing OUTDIR"
[[ $out == /* ]] || out=$BK_START_DIR/$out
[ $((quick + plot_only)) -le 1 ] || bk_usage "--quick and --plot-only exclude each other"
bk_terminal terminal "$format"
terminal+=" noenhanced"

if [ $quick = 1 ]; then
    sizes_default=30,100 ruptures=20 skip=1 budget=60
else
    sizes_default=30,100,300,1000,3000,10000 ruptures=200 skip=2 budget=600
fi
ruptures=${ruptures_arg:-$ruptures} skip=${skip_arg:-$skip} budget=${budget_arg:-$budget}
bk_check_whole --ruptures "$ruptures" "a number of ruptures" 1
bk_check_whole --budget "$budget" "a CPU time in seconds" 1
[[ $skip =~ ^[0-9]+(\.[0-9]+)?$ ]] || bk_usage "--skip needs a time in seconds >= 0, got '$skip'"
IFS=, read -r -a sizes <<< "${sizes_arg:-$sizes_default}"
[ ${#sizes[@]} -gt 0 ] || bk_usage "--sizes needs a list of chain lengths"
for n in "${sizes[@]}"; do bk_check_whole --sizes "$n" "chain lengths" 1; done
mapfile -t sizes < <(printf '%s\n' "${sizes[@]}" | sort -n -u)
if [ ${#specs[@]} -eq 0 ]; then
    read -r -a specs <<< "${RS_METHODS:-whole:solver.local_stepping=off local:solver.local_stepping=on}"
    [ ${#specs[@]} -gt 0 ] || bk_usage "RS_METHODS is set but names no method"
fi
# A method's label, and its settings as bksim run arguments (into method_sets).
method_label() { echo "${1%%:*}"; }
method_sets() {
    method_sets=()
    local setting
    if [[ $1 == *:* ]]; then
        local settings
        IFS=, read -r -a settings <<< "${1#*:}"
        for setting in "${settings[@]}"; do method_sets+=(--set "$setting"); done
    else
        method_sets=(--set "solver.method=$1")
    fi
}
labels=()
for spec in "${specs[@]}"; do
    [[ $spec =~ ^[A-Za-z0-9_.-]+(:[A-Za-z0-9_.]+=[^,]+(,[A-Za-z0-9_.]+=[^,]+)*)?$ ]] ||
        bk_usage "--method needs NAME or LABEL:S.K=V[,S.K=V...], got '$spec'"
    label=$(method_label "$spec")
    for other in "${labels[@]}"; do
        [ "$other" != "$label" ] || bk_usage "--method: '$label' given twice"
    done
    labels+=("$label")
done

bk_need_command gnuplot gnuplot-nox # checked before the runs, not after them
mkdir -p "$out" || bk_fail 1 "$out: cannot create the output directory"
tsv=$out/rs_chains.tsv
scratch="" # set by bk_temp_dir
bk_temp_dir scratch
columns=(method n_blocks status t_skip_s t_end_s ruptures ruptures_complete cpu_s cpu_total_s cpu_skip_s
         cpu_per_rupture_s peak_rss_kb steps steps_window ratio_n30)

if [ $plot_only = 0 ]; then
    bk_need_command /usr/bin/time time
    bk_need_command timeout coreutils
    bksim="" # set by bk_find_bksim (a name shellcheck cannot follow)
    bk_find_bksim bksim
    bk_need_file "$config" config
    BKSIM=$bksim scripts/machine_info.sh > "$out/rs_chains_machine.txt" ||
        bk_fail 1 "scripts/machine_info.sh failed"
    machine=$(awk -F': ' '$1 == "cpu" {cpu = $2} $1 == "cores" {cores = $2} $1 == "bksim" {v = $2}
                          END {printf "%s, %s cores, %s", cpu, cores, v}' "$out/rs_chains_machine.txt")
    limit=$((3 * budget))
    {
        echo "# CPU per rupture against chain length: $config with model.n_blocks = N, output.interval = 0,"
        echo "# the rupture catalog on${set_values[*]:+, and ${set_values[*]}}; made by scripts/bench_rs_chains.sh."
        echo "# Each N runs twice from the same start, to t_skip (the transient left out) and to t_end;"
        echo "# CPU (user + sys, /usr/bin/time) of the window [t_skip, t_end]: cpu_s = cpu_total_s - cpu_skip_s."
        echo "# ruptures: rows of /ruptures that start in the window (ruptures_complete: of them, those"
        echo "# complete at t_end); cpu_per_rupture_s = cpu_s / ruptures.  peak_rss_kb and steps (bksim"
        echo "# run's report) are the run to t_end's; steps_window the difference of the two runs' steps."
        echo "# ratio_n30: cpu_per_rupture_s over the same method's at N = 30.  Target: ratio_n30 <= 3."
        for spec in "${specs[@]}"; do
            method_sets "$spec"
            echo "# method $(method_label "$spec"): ${method_sets[*]}"
        done
        echo "# machine: $machine"
        (IFS=$'\t'; echo "${columns[*]}")
    } > "$tsv"

    # run N T_END PREFIX: bksim run to T_END into PREFIX.h5; PREFIX.time holds "user sys
    # rss_kb", PREFIX.log the run's report.  Returns the run's status (124: stopped at limit).
    run() {
        local status=0
        /usr/bin/time -f '%U %S %M' -o "$3.time" timeout "$limit" "$bksim" run "$config" \
            --set model.n_blocks="$1" --set run.t_end="$2" --set output.interval=0 \
            --set output.events=true "${method_sets[@]}" "${sets[@]}" -o "$3.h5" --force \
            > "$3.log" 2>&1 || status=$?
        return $status
    }
    # The value before WORD in the run's report ("...: 2 rows, 0 transitions, t = 5 s, 47171
    # steps, 64147 RHS evaluations, ..."), else "-".
    report() {
        awk -v w="$2" '/ steps, / { for (i = 2; i <= NF; ++i) if ($i == w || $i == w ",") v = $(i - 1) }
                       END { print (v == "" ? "-" : v) }' "$1.log"
    }
    # row FIELD...: one row of the TSV.
    row() {
        (IFS=$'\t'; echo "$*") >> "$tsv"
    }

    failures=0
    for spec in "${specs[@]}"; do
        label=$(method_label "$spec")
        method_sets "$spec"
        rate=0.16 prev_n="" prev_skip=0 prev_window=0 alpha=1 first_n="" first_cpr="" cpr_n30="" stop=""
        for n in "${sizes[@]}"; do
            if [ -n "$prev_n" ]; then
                projected=$(awk -v n="$n" -v p="$prev_n" -v a="$alpha" -v s="$prev_skip" -v w="$prev_window" \
                    'BEGIN { g = n / p; printf "%.0f", 2 * s * g ^ (1 + a) + w * g ^ a }')
                [ -n "$stop" ] || [ "$projected" -le "$budget" ] ||
                    stop="projected $projected s CPU at N = $n, over the budget of $budget s"
            fi
            t_end=$(awk -v s="$skip" -v r="$ruptures" -v rate="$rate" -v n="$n" 'BEGIN { printf "%.4g", s + r / (rate * n) }')
            if [ -n "$stop" ]; then
                bk_warn "$label: N = $n skipped: $stop"
                row "$label" "$n" skipped "$skip" "$t_end" - - - - - - - - - -
                continue
            fi
            status=ok
            pre=$scratch/skip post=$scratch/end
            if awk -v s="$skip" 'BEGIN { exit !(s > 0) }'; then
                run "$n" "$skip" "$pre" || status=$?
                failed=$pre
            else
                printf '0 0 0\n' > "$pre.time"; echo "0 steps, 0 RHS evaluations" > "$pre.log"
            fi
            if [ $status = ok ]; then
                run "$n" "$t_end" "$post" || status=$?
                failed=$post
            fi
            if [ $status != ok ]; then
                what="the run to t = $skip s"
                [ "$failed" = "$pre" ] || what="the run to t = $t_end s"
                if [ "$status" = 124 ]; then
                    status=timeout
                    bk_warn "$label: N = $n: $what stopped at $limit s of wall time (3x the budget)"
                else
                    status=failed failures=1
                    bk_warn "$label: N = $n: $what failed: $(tail -n 2 "$failed.log" | tr '\n' ' ')"
                fi
                row "$label" "$n" "$status" "$skip" "$t_end" - - - - - - - - - -
                stop="N = $n $status"
                continue
            fi
            "$bksim" export "$post.h5" --table ruptures > "$scratch/ruptures.tsv" ||
                bk_fail 1 "bksim export of the N = $n run failed"
            read -r counted complete < <(awk -F'\t' -v s="$skip" '
                NR == 1 { for (i = 1; i <= NF; ++i) if ($i ~ /^complete\[/) c = i; next }
                /^#/ { next }
                $1 + 0 >= s + 0 { ++k; if ($c == 1) ++done }
                END { print k + 0, done + 0 }' "$scratch/ruptures.tsv")
            read -r cpu_total rss < <(tail -n 1 "$post.time" | awk '{ printf "%.2f %d\n", $1 + $2, $3 }')
            cpu_skip=$(tail -n 1 "$pre.time" | awk '{ printf "%.2f", $1 + $2 }')
            cpu=$(awk -v a="$cpu_total" -v b="$cpu_skip" 'BEGIN { printf "%.2f", a - b }')
            steps=$(report "$post" steps) steps_skip=$(report "$pre" steps)
            steps_window=-
            [ "$steps" = - ] || [ "$steps_skip" = - ] || steps_window=$((steps - steps_skip))
            cpr=- ratio=-
            if [ "$counted" -gt 0 ] && awk -v c="$cpu" 'BEGIN { exit !(c > 0) }'; then
                cpr=$(awk -v c="$cpu" -v k="$counted" 'BEGIN { printf "%.4g", c / k }')
                [ "$n" != 30 ] || cpr_n30=$cpr
                [ -z "$cpr_n30" ] || ratio=$(awk -v c="$cpr" -v r="$cpr_n30" 'BEGIN { printf "%.2f", c / r }')
                # Growth of CPU per rupture from the first size measured, for the next projection.
                if [ -z "$first_n" ]; then
                    first_n=$n first_cpr=$cpr
                else
                    alpha=$(awk -v n="$n" -v p="$first_n" -v c="$cpr" -v q="$first_cpr" \
                        'BEGIN { a = log(c / q) / log(n / p); printf "%.3f", (a < 0 ? 0 : (a > 2 ? 2 : a)) }')
                fi
                rate=$(awk -v k="$counted" -v n="$n" -v t="$t_end" -v s="$skip" 'BEGIN { printf "%.4g", k / (n * (t - s)) }')
            elif [ "$counted" -gt 0 ]; then
                status=too_short # the window's CPU under the clock's 10 ms
            else
                status=no_ruptures
            fi
            row "$label" "$n" "$status" "$skip" "$t_end" "$counted" "$complete" "$cpu" "$cpu_total" "$cpu_skip" \
                "$cpr" "$rss" "$steps" "$steps_window" "$ratio"
            times=""
            [ "$ratio" = - ] || times=" (${ratio}x N = 30)"
            echo "$label, N = $n: $counted ruptures in [$skip, $t_end] s, $cpu s CPU ($cpu_total s to t_end)," \
                "$cpr s per rupture$times"
            prev_n=$n prev_skip=$cpu_skip prev_window=$cpu
            rm -f "$pre.h5" "$post.h5"
        done
    done
fi

# --- the plot: CPU per rupture against N, one curve per method -------------------------------
[ -s "$tsv" ] || bk_fail 1 "$tsv: no such table (run without --plot-only first)"
plot_out=$out/rs_chains.$format
col() { awk -F'\t' -v name="$1" '!/^#/ { for (i = 1; i <= NF; ++i) if ($i == name) print i; exit }' "$tsv"; }
c_method=$(col method) c_n=$(col n_blocks) c_status=$(col status) c_cpr=$(col cpu_per_rupture_s)
[[ -n $c_method && -n $c_n && -n $c_status && -n $c_cpr ]] ||
    bk_fail 1 "$tsv: not a table of scripts/bench_rs_chains.sh (no column method, n_blocks, status or cpu_per_rupture_s)"
mapfile -t plotted < <(awk -F'\t' -v m="$c_method" '!/^#/ && ++k > 1 && !seen[$m]++ { print $m }' "$tsv")
plots="" reference="" k=0
colors=('#000000' '#e41a1c' '#377eb8' '#4daf4a' '#984ea3' '#ff7f00')
for label in "${plotted[@]}"; do
    f=$scratch/curve_$k.dat
    awk -F'\t' -v m="$label" -v cm="$c_method" -v cn="$c_n" -v cs="$c_status" -v cc="$c_cpr" \
        '!/^#/ && $cm == m && $cs == "ok" && $cc > 0 { print $cn, $cc }' "$tsv" > "$f"
    if [ -s "$f" ]; then
        plots+="${plots:+, }'$(bk_gp_quote "$f")' using 1:2 with linespoints lw 2 pt 7 ps 1.4 lc rgb '${colors[k % 6]}' title '$(bk_gp_quote "$label")'"
        # The reference lines hang from the first method's N = 30.
        if [ -z "$reference" ]; then
            reference=$(awk '$1 == 30 { print $2; exit }' "$f")
            [ -z "$reference" ] || reference_label=$label
        fi
    fi
    k=$((k + 1))
done
[ -n "$plots" ] || bk_fail 1 "$tsv: no row with status ok to plot"
# Every size measured, with a margin (the reference lines span the whole axis).
xrange=$(cat "$scratch"/curve_*.dat | awk 'NR == 1 || $1 < lo { lo = $1 } $1 > hi { hi = $1 }
                                          END { printf "%g:%g", lo / 1.5, hi * 1.5 }')
if [ -n "$reference" ]; then
    plots+=", 3 * $reference with lines dt 2 lw 2 lc rgb '#555555' title '3x N = 30 ($(bk_gp_quote "$reference_label")): the target'"
    plots+=", $reference * x / 30 with lines dt 3 lw 1.5 lc rgb '#999999' title 'proportional to N, through N = 30'"
fi
gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $plot_out"
set terminal $terminal
set output '$(bk_gp_quote "$plot_out")'
set title 'CPU per rupture vs chain length: Dieterich-Ruina ring ($config, N blocks), window [t_skip, t_end]'
set logscale xy
set xlabel 'blocks N'
set ylabel 'CPU time per rupture [s]'
set xrange [$xrange]
set format x '%g'
set format y '%g'
set grid
set key top left Left reverse
plot $plots
GP
echo "$plot_out"
exit $failures
