#!/usr/bin/env bash
# The work-precision benchmark (make bench): every back-end x every rtol on the paper's cases
# and on Coulomb chains, plus CPU per transition against chain length.  Writes, under bench/:
#   results.tsv, scaling.tsv, machine.txt, wp_<case>.png (error vs CPU, log-log), scaling.png
# Takes a few minutes (4 on the machine in bench/machine.txt); `scripts/bench.sh --quick` is a
# smoke run into a temporary directory, `--plot-only` redraws the PNGs from the TSVs in bench/.
set -euo pipefail
cd "$(dirname "$0")/.."
bench=build/bench/bksim_bench
out=bench
quick=()
plot_only=0
case "${1:-}" in
    --quick) quick=(--quick --repeats 1); out=$(mktemp -d) ;;
    --plot-only) plot_only=1 ;;
esac
mkdir -p "$out"

if [ $plot_only = 0 ]; then
    {
        echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
        echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')"
        echo "cores: $(nproc)"
        echo "os: $(. /etc/os-release && echo "$PRETTY_NAME")"
        echo "compiler: $(${CC:-cc} --version | head -1)"
        echo "sundials: $(grep -m1 SUNDIALS_VERSION /usr/include/sundials/sundials_config.h | cut -d'"' -f2)"
        echo "gsl: $(pkg-config --modversion gsl)"
        echo "bksim: $(./bksim --version)"
    } > "$out/machine.txt"

    "$bench" "${quick[@]}" --out "$out/results.tsv"
    "$bench" --scaling "${quick[@]}" --out "$out/scaling.tsv"
fi

# Error vs CPU per case, one curve per back-end; the exact stepper, being the Coulomb
# reference (error 0), is a vertical line at its CPU time.
for case in $(awk -F'\t' 'NR > 1 {print $1}' "$out/results.tsv" | sort -u); do
    awk -F'\t' -v c="$case" 'NR > 1 && $1 == c && $4 == "ok" && $2 !~ /^reference/ && $10 != "nan" && $10 > 0 {
            print $2, $5, $10 > "'"$out"'/wp_" c "_" $2 ".dat" }' "$out/results.tsv"
    plots=""
    k=0
    colors=(black '#e41a1c' '#377eb8' '#4daf4a' '#984ea3' '#ff7f00' '#a65628' '#f781bf' '#999999' '#17becf' '#bcbd22' '#1f3b99')
    for f in "$out"/wp_"$case"_*.dat; do
        [ -e "$f" ] || continue
        method=$(basename "$f" .dat); method=${method#wp_"$case"_}
        plots="$plots${plots:+, }'$f' using 2:3 with linespoints lw 1.5 lc rgb '${colors[k % 12]}' pt $((k % 13 + 1)) ps 1.1 title '$method'"
        k=$((k + 1))
    done
    [ -n "$plots" ] || continue
    exact_cpu=$(awk -F'\t' -v c="$case" '$1 == c && $2 == "exact" && $4 == "ok" {print $5}' "$out/results.tsv")
    exact_marker=""
    if [ -n "$exact_cpu" ]; then
        exact_marker="set arrow from $exact_cpu, graph 0 to $exact_cpu, graph 1 nohead dt 2 lw 2 lc rgb 'black'
            set label 'exact stepper (the reference, error 0)' at $exact_cpu, graph 0.03 left offset 0.5, 0"
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
$exact_marker
plot $plots
GP
    rm -f "$out"/wp_"$case"_*.dat
done

# CPU per transition vs chain length, with a slope-1 guide.
for m in cvode_adams cvode_bdf gsl_rk8pd exact; do
    awk -F'\t' -v m="$m" 'NR > 1 && $2 == m && $3 == "ok" {print $1, $6}' "$out/scaling.tsv" > "$out/scaling_$m.dat"
done
gnuplot <<GP
set terminal pngcairo size 1200,800 font 'Sans,12' noenhanced
set output '$out/scaling.png'
set title 'CPU time per transition vs chain length (Coulomb chain, rtol 1e-8, 0.5 s)'
set logscale xy
set xlabel 'blocks N'
set ylabel 'CPU time per transition [s]'
set format y '1e%L'
set grid
set key top left
f(x) = 1e-6 * x
plot '$out/scaling_cvode_adams.dat' using 1:2 with linespoints lw 2 pt 7 title 'cvode_adams', \
     '$out/scaling_cvode_bdf.dat' using 1:2 with linespoints lw 2 pt 5 title 'cvode_bdf (band)', \
     '$out/scaling_gsl_rk8pd.dat' using 1:2 with linespoints lw 2 pt 11 title 'gsl_rk8pd', \
     '$out/scaling_exact.dat' using 1:2 with linespoints lw 2 pt 9 title 'exact', \
     f(x) with lines dt 2 lc rgb '#777777' title 'slope 1 (linear in N)'
GP
rm -f "$out"/scaling_*.dat
echo "benchmark written to $out/"
