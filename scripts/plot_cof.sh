#!/usr/bin/env bash
# Apparent coefficient of friction (friction / normal force) of one block against time, one
# panel per run, stacked in the order given.  Legends sit outside the panels and the value
# axes leave a margin, so no curve lies on the frame or under a legend.
# Optional XRANGE=lo:hi (s) zooms in time; the value axes then fit the visible data.
# usage: plot_cof.sh [--format png|pdf|svg] [--block I] OUT "TITLE" RUN.h5:LABEL:COLOR [RUN.h5:LABEL:COLOR]...
#   --format   gnuplot's cairo terminal (default png); OUT is written as given
#   --block I  the block to draw (default 0)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
plot_setup 3 "$@"
set -- "${PLOT_ARGS[@]}"
out=$1; title=$2; shift 2

panels=""; k=0
for spec in "$@"; do
    IFS=: read -r file label color <<<"$spec"
    plot_require_sample_rows "$file" "apparent COF"
    "$bksim" export "$file" --datasets time,cof --block "$PLOT_BLOCK" > "$tmp/$k.dat"
    last=$(( $# - 1 ))
    if [ $k -eq $last ]; then xfmt="set format x '%g'; set xlabel 'time (s)'"; else xfmt="set format x ''; unset xlabel"; fi
    panels="$panels
$xfmt
plot '$tmp/$k.dat' using 1:2 with lines lc rgb '$color' lw 1.5 title '$label'"
    k=$((k + 1))
done

gnuplot <<GP
$(plot_panels "$out" "$title" $# 0.08)
set ylabel 'apparent COF, block $PLOT_BLOCK'
$panels
unset multiplot
GP
