#!/usr/bin/env bash
# Position (top) and velocity (bottom) of one block and the driver against time.  Legends sit
# outside the panels and the value axes leave a margin, so no curve lies under a legend.
# Optional XRANGE=lo:hi (s) zooms in time; the value axes then fit the visible data.
# usage: plot_kinematics.sh [--format png|pdf|svg] [--block I] OUT "TITLE" RUN.h5:LABEL:COLOR [RUN.h5:LABEL:COLOR]...
#   --format   gnuplot's cairo terminal (default png); OUT is written as given
#   --block I  the block to draw (default 0)
# The driver (grey) is taken from the first run.  Data come through `bksim export`.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
plot_setup 3 "$@"
set -- "${PLOT_ARGS[@]}"
out=$1; title=$2; shift 2

pos_plot=""; vel_plot=""; k=0
for spec in "$@"; do
    IFS=: read -r file label color <<<"$spec"
    plot_require_sample_rows "$file" "x(t) and v(t)"
    # Column 5: driver velocity by finite differences over rows at least 1 us apart.
    "$bksim" export "$file" --datasets time,driver,x,v --block "$PLOT_BLOCK" |
        awk '/^#/ {next} { if (n++ && $1 - t > 1e-6) u = ($2 - d) / ($1 - t)
                           if (n == 1 || $1 - t > 1e-6) { t = $1; d = $2 }
                           print $0, (n > 1 ? u : "NaN") }' > "$tmp/$k.dat"
    if [ $k -eq 0 ]; then
        pos_plot="'$tmp/0.dat' using 1:(\$2*1e3) with lines lc rgb '#999999' lw 2 title 'driver'"
        vel_plot="'$tmp/0.dat' using 1:(\$5*1e3) with lines lc rgb '#999999' lw 2 title 'driver'"
    fi
    pos_plot="$pos_plot, '$tmp/$k.dat' using 1:(\$3*1e3) with lines lc rgb '$color' lw 1.5 title '$label'"
    vel_plot="$vel_plot, '$tmp/$k.dat' using 1:(\$4*1e3) with lines lc rgb '$color' lw 1.5 title '$label'"
    k=$((k + 1))
done

gnuplot <<GP
$(plot_panels "$out" "$title" 2 0.05)
set ylabel 'position, block $PLOT_BLOCK (mm)'
set format x ''
plot $pos_plot
set format x '%g'
set xlabel 'time (s)'
set ylabel 'velocity, block $PLOT_BLOCK (mm/s)'
plot $vel_plot
unset multiplot
GP
