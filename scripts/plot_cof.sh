#!/usr/bin/env bash
# Apparent coefficient of friction (friction / normal force) of one block against time, one
# panel per run, stacked in the order given.  Legends sit outside the panels and the value
# axes leave a margin, so no curve lies on the frame or under a legend.
# Optional XRANGE=lo:hi (s) zooms in time; the value axes then fit the visible data.
# usage: plot_cof.sh [--format png|pdf|svg] [--block I] OUT "TITLE" RUN.h5:LABEL:COLOR [RUN.h5:LABEL:COLOR]...
#   --format   gnuplot's cairo terminal (default png); OUT is written as given
#   --block I  the block to draw (default 0)
set -euo pipefail
here=$(dirname "$0")
source "$here/plot_lib.sh"
bksim=${BKSIM:-./bksim}
plot_setup "$0" 2,9 3 "$@"
set -- "${PLOT_ARGS[@]}"
terminal=$PLOT_TERMINAL
block=$PLOT_BLOCK
out=$1; title=$2; shift 2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

panels=""; k=0
for spec in "$@"; do
    IFS=: read -r file label color <<<"$spec"
    "$bksim" export "$file" --datasets time,cof --block "$block" > "$tmp/$k.dat"
    last=$(( $# - 1 ))
    if [ $k -eq $last ]; then xfmt="set format x '%g'; set xlabel 'time (s)'"; else xfmt="set format x ''; unset xlabel"; fi
    panels="$panels
$xfmt
plot '$tmp/$k.dat' using 1:2 with lines lc rgb '$color' lw 1.5 title '$label'"
    k=$((k + 1))
done

gnuplot <<GP
set terminal $terminal
set output '$out'
set multiplot layout $#,1 title '$title'
set grid
${XRANGE:+set xrange [$XRANGE]}
set offsets 0, 0, graph 0.08, graph 0.08
set key outside right top
# Fixed margins: panels line up whatever their legends' widths.
set lmargin at screen 0.09
set rmargin at screen 0.80
set ylabel 'apparent COF, block $block'
$panels
unset multiplot
GP
