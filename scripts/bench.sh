#!/usr/bin/env bash
# The work-precision benchmark (make bench): every back-end x every rtol on the paper's cases
# and on Coulomb chains, CPU per transition against chain length, and phase drift over 1e4
# stick-slip cycles.  Writes, under bench/:
#   results.tsv, scaling.tsv, scaling_slopes.tsv (scripts/bench_scaling.sh), long_run.tsv,
#   machine.txt, tables.md, wp_<case>.png (error vs CPU, log-log), scaling.png,
#   scaling_memory.png, scaling_run_length.tsv and .png, and output_writer.tsv,
#   output_rhs.tsv, output.md (scripts/bench_output.sh: what dense output costs),
#   ruptures_bench.tsv (scripts/bench_ruptures.sh: the rupture catalog of a 10^6-block chain),
#   rs_chains.tsv, rs_chains.png (scripts/bench_rs_chains.sh: CPU per rupture against N on a
#   rate-and-state ring), stats_convergence.tsv, .md, .png (scripts/bench_stats_convergence.sh:
#   per back-end and rtol, the KS test of the Carlson-Langer ring's and lattice's rupture sizes
#   against a converged reference, beside CPU)
# Takes about 55 minutes (the scaling part alone 19, the statistics 25) on the machine in
# bench/machine.txt;
# `scripts/bench.sh --quick` is a smoke run into a temporary directory, `--plot-only`
# redraws the PNGs and tables from the TSVs in bench/.
# usage: scripts/bench.sh [--quick | --plot-only]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"
bench=build/bench/bksim_bench
out=bench
quick=()
plot_only=0
case "${1:-}" in
    --quick) quick=(--quick --repeats 1); out=$(mktemp -d) ;;
    --plot-only) plot_only=1 ;;
    -h|--help) bk_help ;;
    "") ;;
    *) bk_usage "unknown option '$1'" ;;
esac
mkdir -p "$out"

if [ $plot_only = 0 ]; then
    bk_find_bksim bksim
    export BKSIM=$bksim # what every part below runs
    scripts/machine_info.sh > "$out/machine.txt"

    "$bench" "${quick[@]}" --out "$out/results.tsv"
    scripts/bench_scaling.sh $([ ${#quick[@]} -gt 0 ] && echo --quick) "$out"
    "$bench" --long-run "${quick[@]}" --out "$out/long_run.tsv"
    scripts/bench_output.sh $([ ${#quick[@]} -gt 0 ] && echo --quick) "$out"
    scripts/bench_ruptures.sh $([ ${#quick[@]} -gt 0 ] && echo --quick) "$out"
    scripts/bench_rs_chains.sh $([ ${#quick[@]} -gt 0 ] && echo --quick) "$out"
    scripts/bench_stats_convergence.sh $([ ${#quick[@]} -gt 0 ] && echo --quick) "$out"
fi
if [ $plot_only = 1 ]; then scripts/bench_scaling.sh --plot-only "$out"; fi
if [ $plot_only = 1 ] && [ -s "$out/rs_chains.tsv" ]; then scripts/bench_rs_chains.sh --plot-only "$out"; fi
if [ $plot_only = 1 ] && [ -s "$out/stats_convergence.tsv" ]; then scripts/bench_stats_convergence.sh --plot-only "$out"; fi

# Columns of results.tsv, by name.
col() { awk -F'\t' -v name="$1" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == name) print i; exit }' "$out/results.tsv"; }
c_case=$(col case); c_method=$(col method); c_status=$(col status); c_cpu=$(col cpu_s)
c_events=$(col events); c_err=$(col error_x_m)

# Error vs CPU per case, one curve per back-end.  Runs whose stick-slip events differ from
# the reference's (lost or invented stops) are grey crosses, not points of their curve.  The
# exact stepper, the Coulomb reference (error 0), is a vertical line at its CPU time; for
# integrator references the largest reference_vs_* difference is a horizontal line: errors
# below it are not resolved.
colors=(black '#e41a1c' '#377eb8' '#4daf4a' '#984ea3' '#ff7f00' '#a65628' '#f781bf' '#006d6d' '#17becf' '#bcbd22' '#1f3b99')
for case in $(awk -F'\t' -v c="$c_case" 'NR > 1 {print $c}' "$out/results.tsv" | sort -u); do
    awk -F'\t' -v c="$case" -v cc="$c_case" -v cm="$c_method" -v cs="$c_status" -v ct="$c_cpu" -v ce="$c_events" -v cx="$c_err" -v dir="$out" '
        NR > 1 && $cc == c && $cs == "ok" && $cm !~ /^reference/ && $cx != "nan" && $cx > 0 {
            if ($ce == "same") print $ct, $cx > (dir "/wp_" c "_" $cm ".dat")
            else print $ct, $cx > (dir "/wp_" c "_differ.dat")
        }' "$out/results.tsv"
    plots=""
    k=0
    for b in $(awk -F'\t' -v cm="$c_method" 'NR > 1 && $cm !~ /^reference/ && !seen[$cm]++ {print $cm}' "$out/results.tsv"); do
        f="$out/wp_${case}_$b.dat"
        [ -e "$f" ] || continue
        plots="$plots${plots:+, }'$f' using 1:2 with linespoints lw 1.5 lc rgb '${colors[k % 12]}' pt $((k % 13 + 1)) ps 1.1 title '$b'"
        k=$((k + 1))
    done
    [ -n "$plots" ] || continue
    differ="$out/wp_${case}_differ.dat"
    [ -e "$differ" ] && plots="$plots, '$differ' using 1:2 with points pt 2 ps 1.6 lc rgb '#888888' title 'events differ from the reference'"
    marker=""
    exact_cpu=$(awk -F'\t' -v c="$case" -v cc="$c_case" -v cm="$c_method" -v cs="$c_status" -v ct="$c_cpu" \
        '$cc == c && $cm == "exact" && $cs == "ok" {print $ct}' "$out/results.tsv")
    floor=$(awk -F'\t' -v c="$case" -v cc="$c_case" -v cm="$c_method" -v cx="$c_err" \
        '$cc == c && $cm ~ /^reference_vs_/ && $cx != "nan" && $cx > m {m = $cx} END {if (m > 0) print m}' "$out/results.tsv")
    ref=$(awk -F'\t' -v c="$case" -v cc="$c_case" -v cm="$c_method" '$cc == c && $cm == "reference" {print $3; exit}' "$out/results.tsv")
    if [ -n "$exact_cpu" ] && [ "$ref" = 0 ]; then
        marker="set arrow from $exact_cpu, graph 0 to $exact_cpu, graph 1 nohead dt 2 lw 2 lc rgb 'black'
            set label 'exact stepper (the reference, error 0)' at $exact_cpu, graph 0.03 left offset 0.5, 0"
    elif [ -n "$floor" ]; then
        marker="set arrow from graph 0, first $floor to graph 1, first $floor nohead dt 2 lw 2 lc rgb 'black'
            set label 'reference uncertainty (largest reference_vs_* difference): errors below are not resolved' at graph 0.01, first $floor offset 0, -0.8 left font ',10'"
    fi
    gnuplot <<GP
set terminal pngcairo size 1200,800 font 'Sans,12' noenhanced
set output '$out/wp_$case.png'
set title 'Work-precision, $case: max position error against the reference vs CPU time (rtol 1e-3 ... 1e-12)'
set logscale xy
set format x '1e%L'
set format y '1e%L'
set xlabel 'CPU time per run [s] (median of repeats)'
set ylabel 'max |x - x_ref| [m]'
set grid
set key outside right
$marker
plot $plots
GP
    rm -f "$out"/wp_"$case"_*.dat
done

scripts/bench_tables.sh "$out" > "$out/tables.md"
# A full run into bench/ also refreshes the tables README quotes (between bench markers).
if [ "$out" = bench ] && grep -q '<!-- bench:begin -->' README.md && grep -q '<!-- bench:end -->' README.md; then
    awk -v tables="$out/tables.md" '
        /<!-- bench:begin -->/ { print; while ((getline line < tables) > 0) print line; skip = 1; next }
        /<!-- bench:end -->/   { skip = 0 }
        !skip' README.md > README.md.new
    mv README.md.new README.md
fi
echo "benchmark written to $out/"
