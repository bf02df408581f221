#!/usr/bin/env bash
# Paper Figure 2: the coefficient of friction against nondimensional slip distance (slip / L0)
# under a prescribed slip-rate schedule.
# usage: plot_fig2.sh [--format png|pdf|svg] [--block I] OUT RUN.h5 [L0 in m, default 2e-5]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
plot_setup 2 "$@"
out=${PLOT_ARGS[0]}; run=${PLOT_ARGS[1]}; L0=${PLOT_ARGS[2]:-2e-5}
"$bksim" export "$run" --datasets time,x,v,cof --block "$PLOT_BLOCK" > "$tmp/data"
gnuplot <<GP
set terminal $PLOT_TERMINAL
set output '$out'
set title 'Figure 2: rate-and-state COF under velocity steps 1 → 10 → 1 mm/s'
set grid
set xlabel 'slip distance / L0   (L0 = $L0 m)'
set ylabel 'coefficient of friction μ'
set key at graph 0.02, graph 0.04 left bottom Left reverse box opaque
set label 1 'A: 1 mm/s' at graph 0.15, graph 0.95 center
set label 2 'B: 10 mm/s' at graph 0.5, graph 0.95 center
set label 3 'C: 1 mm/s' at graph 0.85, graph 0.95 center
plot '$tmp/data' using (\$2/$L0):4 with lines lc rgb 'red' lw 2 title 'rate-and-state (eqs. 1–4)', \
     0.5368 with lines dt 2 lc rgb '#777777' title 'steady state, 1 mm/s (0.5368)', \
     0.5 with lines dt 3 lc rgb '#777777' title 'steady state, 10 mm/s (0.5000)'
GP
