#!/usr/bin/env bash
# Apparent coefficient of friction (friction / normal force) of block 0 against time, one
# panel per run, stacked in the order given.
# Optional XRANGE=lo:hi (s) zooms in time; the value axes then fit the visible data.
# usage: plot_cof.sh OUT.png "TITLE" RUN.h5:LABEL:COLOR [RUN.h5:LABEL:COLOR]...
set -euo pipefail
bksim=${BKSIM:-./bksim}
out=$1; title=$2; shift 2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

panels=""; k=0
for spec in "$@"; do
    IFS=: read -r file label color <<<"$spec"
    "$bksim" export "$file" --datasets time,cof --block 0 > "$tmp/$k.dat"
    last=$(( $# - 1 ))
    if [ $k -eq $last ]; then xfmt="set format x '%g'; set xlabel 'time [s]'"; else xfmt="set format x ''; unset xlabel"; fi
    panels="$panels
$xfmt
plot '$tmp/$k.dat' using 1:2 with lines lc rgb '$color' lw 1.5 title '$label'"
    k=$((k + 1))
done

gnuplot <<GP
set terminal pngcairo size 1200,800 font 'Sans,13' noenhanced
set output '$out'
set multiplot layout $#,1 title '$title'
set grid
${XRANGE:+set xrange [$XRANGE]}
set key top right
set ylabel 'apparent COF [1]'
$panels
unset multiplot
GP
