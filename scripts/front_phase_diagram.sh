#!/usr/bin/env bash
# The front types of the Oslo group's 1D model (configs/fronts/oslo_front.ini) over prestress
# tau_bar and viscosity alpha, from a sweep (scripts/sweep.sh: resumable, one run per point):
# for each point the front's mean speed (blocks per unit time; the sound speed is 1), how far
# it got, and the moment-duration exponent beta of its growth, M0(t) ~ t^beta, fitted
# (log-log least squares) to the potency the front has released, M0(t) = the integral of its
# moment rate (/rupture_rate), while it runs from 10 % to 90 % of the length it reaches.
# Thoegersen et al. (GRL 46, 12805, 2019) class fronts by beta: slow ones 0.63 to 1.5,
# sub-Rayleigh 2, supershear 3.  Writes DIR/phase.tsv (tau_bar, alpha, speed, reached, beta,
# class) and DIR/phase_speed.<fmt>, DIR/phase_beta.<fmt> (points on the (alpha, tau_bar)
# plane, log alpha, coloured by the speed and by beta, arrested fronts marked); prints the
# table and the figures' paths.
# usage: scripts/front_phase_diagram.sh [-j JOBS] [-o DIR] [--format png|pdf|svg]
#                                       [--taus LIST] [--alphas LIST] [--t-end T]
#   LIST   comma-separated values (defaults: tau_bar 0.01,0.05,0.1,0.2,0.3,0.5,0.7,0.8,0.9,0.95;
#          alpha 0.01,0.03,0.1,0.3,1,3,10)
#   T      each run's length in unit times (default 2000: the slowest fronts that cross need it)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"
jobs=$(nproc) dir=out/sweeps/fronts format=png
taus=0.01,0.05,0.1,0.2,0.3,0.5,0.7,0.8,0.9,0.95 alphas=0.01,0.03,0.1,0.3,1,3,10 t_end=2000
while [ $# -gt 0 ]; do
    case $1 in
        -j) bk_need_value $# "$1"; jobs=$2; shift 2 ;;
        -o) bk_need_value $# "$1"; dir=$2; shift 2 ;;
        --format) bk_need_value $# "$1"; format=$2; shift 2 ;;
        --taus) bk_need_value $# "$1"; taus=$2; shift 2 ;;
        --alphas) bk_need_value $# "$1"; alphas=$2; shift 2 ;;
        --t-end) bk_need_value $# "$1"; t_end=$2; shift 2 ;;
        -h|--help) bk_help ;;
        *) bk_usage "unknown option '$1'" ;;
    esac
done
list='^[0-9.eE+-]+(,[0-9.eE+-]+)*$'
[[ $taus =~ $list ]] || bk_usage "--taus needs comma-separated numbers, got '$taus'"
[[ $alphas =~ $list ]] || bk_usage "--alphas needs comma-separated numbers, got '$alphas'"
[[ $t_end =~ ^[0-9.]+([eE][-+]?[0-9]+)?$ ]] && awk -v t="$t_end" 'BEGIN {exit !(t > 0)}' ||
    bk_usage "--t-end needs a time > 0, got '$t_end'"
bk_terminal terminal "$format"
bk_need_command gnuplot gnuplot-nox
bk_find_bksim bksim
bk_temp_dir tmp
export BKSIM=$bksim
# tau_bar is applied_force - 1 (the config says why); slow fronts need long runs.
forces=$(tr ',' '\n' <<<"$taus" | awk '{printf "%s%.10g", (NR > 1 ? "," : ""), $1 + 1}')
scripts/sweep.sh -j "$jobs" -o "$dir" configs/fronts/oslo_front.ini \
    block.applied_force="$forces" block.damping="$alphas" run.t_end="$t_end" >&2 ||
    bk_fail 1 "the sweep failed: $dir/sweep.log says why"

table=$dir/phase.tsv
printf '# tau_bar\talpha\tspeed[blocks/unit time]\treached[blocks]\tbeta\tclass\n' > "$table"
while IFS=$'\t' read -r point force alpha _; do
    [ "$point" != point ] || continue
    file=$dir/$point.h5
    # The front: the first rupture from the edge (the table is in order of start).
    read -r k speed reached < <("$bksim" fronts "$file" | awk -F'\t' '!/^#/ && $7 == 1 {print $1, $9, $6; exit}')
    "$bksim" fronts "$file" --rupture "$k" > "$tmp/front.tsv"
    "$bksim" export "$file" --table rupture_rate | awk -F'\t' -v k="$k" '!/^#/ && $1 == k {print $2, $3}' > "$tmp/rate.dat"
    # Arrival at 10 % and 90 % of the reach, then log M0 against log t between them.
    beta=$(awk -v r="$reached" -v rate="$tmp/rate.dat" '
        !/^#/ { d = $2 + 0; t = $3 + 0
                if (d >= 0.1 * r && (a == "" || t < a)) a = t
                if (d <= 0.9 * r && t > b) b = t }
        END {
            while ((getline line < rate) > 0) {
                split(line, f, " "); t = f[1] + 0; v = f[2] + 0
                if (n++) m += 0.5 * (v + pv) * (t - pt)
                pt = t; pv = v
                if (a != "" && t >= a && t <= b && m > 0 && t > 0) {
                    x = log(t); y = log(m); sx += x; sy += y; sxx += x * x; sxy += x * y; c++ }
            }
            if (c < 5) { print "nan"; exit }
            printf "%.3f\n", (sxy - sx * sy / c) / (sxx - sx * sx / c)
        }' "$tmp/front.tsv")
    class=$(awk -v s="$speed" -v b="$beta" 'BEGIN {
        if (s == "nan") print "none"; else if (s + 0 > 1) print "supershear";
        else if (s + 0 < 0.3) print "slow"; else print "sub-Rayleigh" }')
    printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$(awk -v f="$force" 'BEGIN {printf "%.10g", f - 1}')" "$alpha" "$speed" \
        "$reached" "$beta" "$class" >> "$table"
done < "$dir/points.tsv"
cat "$table"

n_blocks=$(awk -F= '/^n_blocks/ {gsub(/[^0-9]/, "", $2); print $2; exit}' configs/fronts/oslo_front.ini)
awk -F'\t' -v n="$n_blocks" '!/^#/ && $4 < n' "$table" > "$tmp/arrested.dat"
arrested=NaN
[ ! -s "$tmp/arrested.dat" ] || arrested="'$tmp/arrested.dat' using 2:1"
for what in speed beta; do
    col=3 label='mean front speed [blocks per unit time; sound speed 1]' range='[0:3.5]'
    [ $what = speed ] || { col=5 label='moment-duration exponent β (M0 ~ t^β)'; range='[0:4]'; }
    out=$dir/phase_$what.$format
    gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $out"
set encoding utf8
set terminal $terminal noenhanced
set output '$(bk_gp_quote "$out")'
set title 'Oslo 1D model, $n_blocks blocks pushed at one edge: $label' . "\n" . \
          'Thøgersen et al. 2019: slow β 0.63–1.5, sub-Rayleigh β 2, supershear β 3; crosses: arrested fronts'
set xlabel 'viscosity α'
set ylabel 'prestress τ̄'
set logscale x
set cbrange $range
set palette defined (0 '#2c7bb6', 1 '#abd9e9', 2 '#ffffbf', 3 '#fdae61', 4 '#d7191c')
set colorbox
set grid
set key outside below
plot '$(bk_gp_quote "$table")' using 2:1:(\$$col) with points pt 5 ps 3 lc palette notitle, \
     $arrested with points pt 2 ps 2 lw 2 lc rgb '#000000' title 'arrested before the far edge'
GP
    echo "$out"
done
