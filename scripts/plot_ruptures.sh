#!/usr/bin/env bash
# The rupture catalog of a run (/ruptures, /rupture_blocks, /rupture_rate: README "Ruptures"),
# as four figures:
#   OUTDIR/<stem>_ruptures_slip_spacetime.<fmt>  (a chain only) every rupture's blocks, each a
#       bar at its block from its first onset t_onset to its last stop t_stop, coloured by its
#       slip (m); the epicentres (first_block at t_start) are dots.  --from T1 / --to T2 keep
#       the time window [T1, T2];
#   OUTDIR/<stem>_rupture_<K>_front.<fmt>  rupture K's front: each block's arrival time
#       t_onset - t_start against the block (a chain) or against the radial distance from the
#       epicentre (a lattice), and the two fronts' speeds of /ruptures (blocks/s, a
#       least-squares fit on each side of the epicentre) as lines through the epicentre;
#   OUTDIR/<stem>_rupture_<K>_rate.<fmt>  rupture K's moment-rate function (the sum of |v|
#       over its slipping blocks, m/s, from /rupture_rate) against t - t_start, and its
#       integral beside the potency of /ruptures (none, with a warning, for a run with
#       [catalog] rupture_rate = false);
#   OUTDIR/<stem>_ruptures_moment_duration.<fmt>  log10 potency against log10 duration of
#       every complete rupture of positive potency and duration, with a least-squares line
#       per size range: n_blocks 1-3, 4-30 and >= 31 (--by blocks, the default) or the
#       terciles of duration (--by duration); guides of slopes 1.5, 2, 3 for comparison with
#       Thoegersen et al. (GRL 46, 12805, 2019: in a 1D Burridge-Knopoff model potency ~
#       T^0.63, to T^1.5 for longer systems, for slow ruptures, T^2 sub-shear, T^3 supershear).
# K is the 0-based row of /ruptures (`bksim export FILE --table ruptures`); by default, or with
# --largest, the rupture of largest potency.  Prints the fits as TSV (a '#' header line, one
# row per size range and one for all), then the figures' paths, one a line.  <stem> is FILE's
# name without .h5 (and .part); OUTDIR defaults to FILE's directory.  A file without
# /ruptures (a run with [output] events = false, or older than the rupture catalog) is an
# error (exit status 1; bad options 2).
# usage: plot_ruptures.sh [--format png|pdf|svg] [-o OUTDIR] [--rupture K | --largest]
#                         [--from T] [--to T] [--by blocks|duration] FILE.h5
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
rupture="" from="" to="" by=blocks
number='^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$'
while [ $# -gt 0 ]; do
    case $1 in
        --rupture) bk_need_value $# "$1"; rupture=$2; shift 2 ;;
        --rupture=*) rupture=${1#--rupture=}; shift ;;
        --largest) rupture=""; shift ;;
        --from) bk_need_value $# "$1"; from=$2; shift 2 ;;
        --from=*) from=${1#--from=}; shift ;;
        --to) bk_need_value $# "$1"; to=$2; shift 2 ;;
        --to=*) to=${1#--to=}; shift ;;
        --by) bk_need_value $# "$1"; by=$2; shift 2 ;;
        --by=*) by=${1#--by=}; shift ;;
        *) plot_file_option "$@"; shift "$PLOT_SHIFT" ;;
    esac
done
[ -z "$rupture" ] || bk_check_whole --rupture "$rupture" "a rupture row" 0
[ -z "$from" ] || [[ $from =~ $number ]] || bk_usage "--from needs a time in s, got '$from'"
[ -z "$to" ] || [[ $to =~ $number ]] || bk_usage "--to needs a time in s, got '$to'"
if [ -n "$from" ] && [ -n "$to" ] && ! awk -v a="$from" -v b="$to" 'BEGIN {exit !(a + 0 < b + 0)}'; then
    bk_usage "--from must be before --to, got $from and $to"
fi
case $by in blocks|duration) ;; *) bk_usage "--by must be blocks or duration, got '$by'" ;; esac
plot_file_setup

# bksim's own message when the export fails (no such table, not an HDF5 file, ...).
export_table() { # TABLE OUT
    "$bksim" export "$file" --table "$1" > "$2" 2> "$tmp/err" || bk_fail 1 "$(cat "$tmp/err")"
}
export_table ruptures "$tmp/ruptures.tsv"
n_rup=$(awk '!/^#/' "$tmp/ruptures.tsv" | wc -l)
[ "$n_rup" -gt 0 ] || bk_fail 1 "$file: /ruptures is empty: no rupture to plot"

# The rupture: row K, or the largest finite potency (the first of equals; row 0 if none is).
if [ -z "$rupture" ]; then
    rupture=$(awk -F'\t' '/^#/ {next}
        {k = n++; p = $8 + 0}
        $8 !~ /nan|inf/ && (best == "" || p > pmax) {best = k; pmax = p}
        END {print best == "" ? 0 : best}' "$tmp/ruptures.tsv")
    what="; the largest by potency"
else
    rupture=$(echo "$rupture" | sed 's/^0*//; s/^$/0/')
    if [ ${#rupture} -gt 15 ] || [ "$rupture" -ge "$n_rup" ]; then
        bk_fail 1 "$file: --rupture $rupture out of range: /ruptures has $n_rup rows (0..$((n_rup - 1)))"
    fi
    what=""
fi
IFS=$'\t' read -r t_start _ first_block r_blocks left right _ potency magnitude _ _ duration \
    v_left v_right complete < <(awk -F'\t' -v k="$rupture" '!/^#/ && n++ == k' "$tmp/ruptures.tsv")

plot_file_shape "$file"
[ -n "$n_blocks" ] || bk_fail 1 "$file: bksim info gives no n_blocks"

export_table rupture_blocks "$tmp/blocks.tsv"
awk -F'\t' -v k="$rupture" '!/^#/ && $1 == k' "$tmp/blocks.tsv" > "$tmp/one.tsv"
[ -s "$tmp/one.tsv" ] || bk_fail 1 "$file: /rupture_blocks has no row of rupture $rupture"

# The time window of the space-time plot, checked before any figure is drawn.
if [ "$rows" -eq 1 ]; then
    awk -F'\t' -v from="$from" -v to="$to" '!/^#/ && (from == "" || $4 >= from + 0) && (to == "" || $3 <= to + 0)' \
        "$tmp/blocks.tsv" > "$tmp/window.tsv"
    if [ ! -s "$tmp/window.tsv" ]; then
        [ -n "$from$to" ] || bk_fail 1 "$file: /rupture_blocks is empty: nothing to plot"
        bk_fail 1 "$file: no rupture slips between ${from:-the start} and ${to:-the end}${from:+ s}"
    fi
else
    bk_warn "$file: a $rows x $cols lattice: no space-time plot of slip (plot_slip_map.sh maps a rupture's slip)${from:+; --from ignored}${to:+; --to ignored}"
fi

# Numbers as text: a minus sign, not a hyphen.
g() { LC_ALL=C printf "%.${2:-4}g" "$1" | sed 's/^-/−/'; }
# The figures' paths, in the order drawn (plot_draw).
outputs=()

running=""; [ "$complete" = 1 ] || running=", still running at the end of the run"
blocks_word=blocks; [ "$r_blocks" != 1 ] || blocks_word=block
title_k="$stem: rupture $rupture (of 0..$((n_rup - 1))$what)$running"
about_k="t_start = $(g "$t_start" 6) s, $r_blocks $blocks_word, epicentre block $first_block, potency $(g "$potency") m, M = $(g "$magnitude"), duration $(g "$duration") s"

# ------------------------------------------------------------ (a) space-time of slip ---
if [ "$rows" -eq 1 ]; then
    out="$outdir/${stem}_ruptures_slip_spacetime.$format"
    # Drawn in order of slip, so that the larger slips are on top.
    sort -t $'\t' -g -k5,5 "$tmp/window.tsv" > "$tmp/bars.tsv"
    read -r _ n_in slip_lo slip_hi t_lo t_hi < <(awk -F'\t' '
        { if (!n++) {lo = hi = $5; a = $3; b = $4}
          lo = $5 < lo ? $5 : lo; hi = $5 > hi ? $5 : hi; a = $3 < a ? $3 : a; b = $4 > b ? $4 : b
          seen[$1] = 1 }
        END { if (lo > 0) lo = 0; if (hi <= lo) hi = lo + 1e-12
              printf "%d %d %.10g %.10g %.17g %.17g\n", n, length(seen), lo, hi, a, b }' "$tmp/bars.tsv")
    # The epicentres of the ruptures drawn: (t_start, first_block) of each row in the window.
    awk -F'\t' -v from="$from" -v to="$to" '!/^#/ && (from == "" || $2 >= from + 0) && (to == "" || $1 <= to + 0) {print $1 "\t" $3}' \
        "$tmp/ruptures.tsv" > "$tmp/epicentres.dat"
    x_lo=${from:-$(awk -v a="$t_lo" -v b="$t_hi" 'BEGIN {printf "%.17g", a - 0.01 * (b - a)}')}
    x_hi=${to:-$(awk -v a="$t_lo" -v b="$t_hi" 'BEGIN {printf "%.17g", b + 0.01 * (b - a)}')}
    window=""; [ -z "$from$to" ] || window=" between t = ${from:-start} and ${to:-end}${to:+ s}"
    epi_plot=""
    [ ! -s "$tmp/epicentres.dat" ] ||
        epi_plot=", '$tmp/epicentres.dat' using 1:2 with points pt 7 ps 0.5 lc rgb '#000000' title 'epicentre: first_block at t_start'"
    plot_draw "$out" <<GP
set title '$(bk_gp_quote "$stem"): slip of the ruptures in space and time' . "\n" . \
          '$n_in ruptures$window; each block of a rupture is a bar from its first onset to its last stop'
set xlabel 'time t [s]'
set ylabel 'block'
set xrange [$x_lo : $x_hi]
set yrange [-0.5 : $n_blocks - 0.5]
set ytics out nomirror
$(if [ "$n_blocks" -le 12 ]; then echo "set ytics 1"; else echo "set mytics"; fi)
set grid back lc rgb '#c0c0c0' lw 1 dt 3
set cbrange [$slip_lo : $slip_hi]
set cblabel 'slip of the block in the rupture [m]'
set rmargin at screen 0.84
set colorbox vertical user origin screen 0.865, screen 0.2 size screen 0.025, screen 0.65
set palette defined (0 '#30123b', 0.15 '#4662d7', 0.3 '#36aaf9', 0.45 '#1ae4b6', 0.6 '#72fe5e', 0.75 '#c8ef34', 0.85 '#faba39', 0.93 '#f66b19', 1 '#7a0403')
set key outside below center horizontal
set bmargin 5
set datafile separator '\t'
plot '$tmp/bars.tsv' using ((\$3 + \$4) / 2):2:((\$4 - \$3) / 2):(0.5):5 with boxxyerror fs solid 1 noborder lc palette notitle$epi_plot
GP
fi

# ---------------------------------------------------------------------- (b) the front ---
out="$outdir/${stem}_rupture_${rupture}_front.$format"
# Why a speed is NaN: fewer than 3 blocks on its side (the epicentre counts on both), else
# the arrival times fall with distance.  NAME SPEED COUNT -> the legend's words for it.
speed_text() {
    case $2 in
        nan|-nan) if [ "$3" -lt 3 ]; then echo "$1 front: speed NaN (fewer than 3 blocks on this side)"
                  else echo "$1 front: speed NaN (arrival times fall with distance)"; fi ;;
        inf) echo "$1 front: speed ∞ (every block on this side arrived at once)" ;;
        *) echo "$1 front: $(g "$2") blocks/s (least-squares fit of /ruptures, drawn through the epicentre)" ;;
    esac
}
# A line through the epicentre (x0, 0) with slope 1/SPEED over x0..X1 (a vertical offset of 0
# for an infinite speed); nothing for NaN.  SPEED X0 X1 -> "x t" rows.
front_line() {
    awk -v v="$1" -v x0="$2" -v x1="$3" 'BEGIN {
        if (v ~ /nan/) exit
        s = v ~ /inf/ ? 0 : 1 / v
        d = x1 > x0 ? x1 - x0 : x0 - x1
        printf "%.17g 0\n%.17g %.17g\n", x0, x1, d * s }'
}
if [ "$rows" -eq 1 ]; then
    # A chain: positions are blocks, round past block 0 when the rupture wraps (left > right).
    awk -F'\t' -v n="$n_blocks" -v l="$left" -v r="$right" -v t0="$t_start" -v e="$first_block" '
        function pos(b) { return (l > r && b < l) ? b + n : b }
        { printf "%.17g %.17g\n", pos($2), $3 - t0 }
        END { printf "%.17g\n", pos(e) > "/dev/stderr" }' "$tmp/one.tsv" > "$tmp/front.dat" 2> "$tmp/epi_pos"
    epi=$(cat "$tmp/epi_pos")
    read -r x_min x_max n_left n_right < <(awk -v e="$epi" '
        {if (!n++) lo = hi = $1; lo = $1 < lo ? $1 : lo; hi = $1 > hi ? $1 : hi; nl += $1 <= e; nr += $1 >= e}
        END {print lo, hi, nl, nr}' "$tmp/front.dat")
    points="'$tmp/front.dat' using 1:2 with points pt 7 ps 1.1 lc rgb '#1f77b4' title 'arrival of the front: first onset of each block'"
    xlabel="block"
    [ "$(awk -v a="$x_min" -v b="$x_max" 'BEGIN {print b - a <= 20}')" = 0 ] || xtics_one="set xtics 1"
    [ "$left" -le "$right" ] || xlabel="block (the rupture wraps past block 0: n + i for block i past it, n = $n_blocks)"
    left_words="left" right_words="right"
else
    # A lattice: the radial distance from the epicentre, the shorter way round an edge that the
    # rupture's bounding box wraps.  Sides as bksim fits them: by column, and in the epicentre's
    # column by row (above: left, below: right); the epicentre is on both.
    awk -F'\t' -v cols="$cols" -v rows="$rows" -v l="$left" -v r="$right" -v t0="$t_start" -v e="$first_block" \
        -v lf="$tmp/front_left.dat" -v rf="$tmp/front_right.dat" '
        function dist(a, c, len, wrap,   d) { d = c - a
            if (wrap) { d = ((d % len) + len) % len; if (d > len / 2) d -= len }
            return d }
        BEGIN { wr = int(l / cols) > int(r / cols); wc = l % cols > r % cols
                er = int(e / cols); ec = e % cols; printf "" > lf; printf "" > rf }
        { dc = dist(ec, $2 % cols, cols, wc); dr = dist(er, int($2 / cols), rows, wr)
          d = sqrt(dr * dr + dc * dc); t = $3 - t0
          along = dc != 0 ? dc : dr
          if (along <= 0) printf "%.17g %.17g\n", d, t > lf
          if (along >= 0) printf "%.17g %.17g\n", d, t > rf }' "$tmp/one.tsv"
    epi=0 x_min=0
    x_max=$(cat "$tmp/front_left.dat" "$tmp/front_right.dat" | awk '$1 > m {m = $1} END {print m + 0}')
    n_left=$(wc -l < "$tmp/front_left.dat"); n_right=$(wc -l < "$tmp/front_right.dat")
    points="'$tmp/front_left.dat' using 1:2 with points pt 7 ps 1.1 lc rgb '#1f77b4' title 'arrival (first onset) on the left side: columns left of the epicentre''s, or above it in its column', \
     '$tmp/front_right.dat' using 1:2 with points pt 6 ps 1.6 lw 1.5 lc rgb '#2ca02c' title 'arrival (first onset) on the right side: columns right of the epicentre''s, or below it in its column'"
    xlabel="distance from the epicentre [blocks] (radial: √(Δrow² + Δcolumn²))"
    left_words="left" right_words="right"
fi
front_line "$v_left" "$epi" "$( [ "$rows" -eq 1 ] && echo "$x_min" || echo "$x_max")" > "$tmp/line_left.dat"
front_line "$v_right" "$epi" "$x_max" > "$tmp/line_right.dat"
line_plot() { # FILE TITLE COLOUR DASH
    if [ -s "$1" ]; then echo ", '$1' using 1:2 with lines lw 2.5 dt $4 lc rgb '$3' title '$(bk_gp_quote "$2")'"
    else echo ", NaN with lines lw 2.5 dt $4 lc rgb '$3' title '$(bk_gp_quote "$2")'"; fi
}
pad=$(awk -v a="$x_min" -v b="$x_max" 'BEGIN {d = b - a; print (d > 0 ? 0.03 * d : 0.5)}')
plot_draw "$out" <<GP
set title '$(bk_gp_quote "$title_k: the front")' . "\n" . '$(bk_gp_quote "$about_k")'
set xlabel '$(bk_gp_quote "$xlabel")'
${xtics_one:-}
set ylabel 'arrival time t_onset − t_start [s]'
set xrange [$x_min - $pad : $x_max + $pad]
set offsets 0, 0, graph 0.05, graph 0.05
set grid lc rgb '#c0c0c0' lw 1 dt 3
set key outside below center vertical Left reverse
set bmargin 9
plot $points, \
     '-' using 1:2 with points pt 3 ps 2.5 lw 2 lc rgb '#000000' title 'epicentre (first_block)' \
     $(line_plot "$tmp/line_left.dat" "$(speed_text "$left_words" "$v_left" "$n_left")" '#d62728' 1) \
     $(line_plot "$tmp/line_right.dat" "$(speed_text "$right_words" "$v_right" "$n_right")" '#ff7f0e' 2)
$epi 0
e
GP

# ----------------------------------------------------------------- (c) moment rate ---
out="$outdir/${stem}_rupture_${rupture}_rate.$format"
# Rupture K's rows only.  They are in rupture order, so awk stops past them and the export dies
# of SIGPIPE, which is fine once awk has seen them; any other failure is reported.
rate_rc=0
{ "$bksim" export "$file" --table rupture_rate 2> "$tmp/err" || echo $? > "$tmp/rate_rc"; } |
    awk -F'\t' -v k="$rupture" -v t0="$t_start" '/^#/ {next}
        $1 == k {printf "%.17g %.17g\n", $2 - t0, $3; seen = 1; next}
        seen && $1 > k {exit}' > "$tmp/rate.dat" || rate_rc=$?
[ "$rate_rc" -eq 0 ] || bk_fail 1 "awk failed reading /rupture_rate of $file"
if [ ! -s "$tmp/rate.dat" ] && [ -s "$tmp/rate_rc" ]; then
    bk_warn "$(cat "$tmp/err"): no moment-rate figure (a run with [catalog] rupture_rate = false writes none)"
elif [ ! -s "$tmp/rate.dat" ]; then
    bk_warn "$file: /rupture_rate has no sample of rupture $rupture: no moment-rate figure"
else
    read -r n_samples integral rate_max < <(awk '
        {if (n++) s += ($1 - t) * ($2 + r) / 2; t = $1; r = $2; m = $2 > m ? $2 : m}
        END {printf "%d %.10g %.10g\n", n, s, m}' "$tmp/rate.dat")
    plot_draw "$out" <<GP
set title '$(bk_gp_quote "$title_k: the moment-rate function")' . "\n" . '$(bk_gp_quote "$about_k")'
set xlabel 'time since the rupture started, t − t_start [s]'
set ylabel 'moment (potency) rate Σ|v| over the slipping blocks [m/s]'
set offsets graph 0.02, graph 0.02, graph 0.05, 0
set yrange [0:*]
set grid lc rgb '#c0c0c0' lw 1 dt 3
set key outside below center vertical Left reverse
plot '$tmp/rate.dat' using 1:2 with lines lw 2 lc rgb '#1f77b4' \
         title '$(bk_gp_quote "/rupture_rate, $n_samples samples (peak $(g "$rate_max") m/s); ∫ rate dt = $(g "$integral") m against potency $(g "$potency") m")'
GP
fi

# ------------------------------------------------------------- (d) moment-duration ---
out="$outdir/${stem}_ruptures_moment_duration.$format"
# log10 T, log10 P and n_blocks of the complete ruptures of positive potency and duration.
awk -F'\t' '!/^#/ && $15 == 1 && $8 > 0 && $12 > 0 && $8 !~ /nan|inf/ && $12 !~ /nan|inf/ {
        printf "%.17g\t%.17g\t%d\n", log($12) / log(10), log($8) / log(10), $4 }' \
    "$tmp/ruptures.tsv" | sort -t $'\t' -g -k1,1 > "$tmp/md.tsv"
n_md=$(wc -l < "$tmp/md.tsv")
read -r n_incomplete n_zero < <(awk -F'\t' '!/^#/ {i += $15 != 1; z += $15 == 1 && !($8 > 0 && $12 > 0)} END {print i + 0, z + 0}' \
    "$tmp/ruptures.tsv")
[ "$n_md" -gt 0 ] || bk_fail 1 "$file: no complete rupture of positive potency and duration: no moment-duration figure"
# Classes 1..3 into md_<c>.tsv; their names and the fits (range n slope se intercept Tmin Tmax)
# into fits.tsv, the last row all of them.  A fit needs durations that differ (log10 T by more
# than 1e-6: a Coulomb chain's one-block ruptures all last the same) and its error 3 points;
# else nan.  The rows come sorted by duration.
awk -F'\t' -v by="$by" -v n_all="$n_md" -v dir="$tmp" '
    function fit(c, name,   n, sx, sy, sxx, sxy, b, a, sse, se, i, vx) {
        n = cnt[c]
        if (n > 0) {
            for (i = 1; i <= n; i++) { sx += X[c, i]; sy += Y[c, i] }
            mx = sx / n; my = sy / n
            for (i = 1; i <= n; i++) { vx = X[c, i] - mx; sxx += vx * vx; sxy += vx * (Y[c, i] - my) }
        }
        b = a = se = "nan"
        if (n >= 2 && hi[c] - lo[c] > 1e-6) {
            b = sxy / sxx; a = my - b * mx
            if (n >= 3) { for (i = 1; i <= n; i++) sse += (Y[c, i] - a - b * X[c, i]) ^ 2
                          se = sqrt(sse / (n - 2) / sxx) }
        }
        printf "%s\t%d\t%s\t%s\t%s\t%s\t%s\n", name, n, num(b), num(se), num(a),
               n ? num(10 ^ lo[c]) : "nan", n ? num(10 ^ hi[c]) : "nan" > (dir "/fits.tsv")
    }
    function num(v) { return v == "nan" ? v : sprintf("%.6g", v) }
    function add(c, x, y) { i = ++cnt[c]; X[c, i] = x; Y[c, i] = y
        if (i == 1 || x < lo[c]) lo[c] = x; if (i == 1 || x > hi[c]) hi[c] = x
        if (++pile[c, sprintf("%.6f %.6f", x, y)] > most[c]) most[c] = pile[c, sprintf("%.6f %.6f", x, y)]
        print x "\t" y > (dir "/md_" c ".tsv") }
    BEGIN { for (c = 1; c <= 3; c++) printf "" > (dir "/md_" c ".tsv")
            k1 = int((n_all + 2) / 3); k2 = int((2 * n_all + 2) / 3) }
    { r = NR
      if (by == "blocks") c = $3 <= 3 ? 1 : $3 <= 30 ? 2 : 3
      else {
          # Terciles by value: the durations at ranks k1 = ceil(n/3) and k2 = ceil(2n/3) bound
          # them, and a duration equal to a bound (within 1e-6 in log10) goes with it: ties never split.
          if (r == k1) q1 = $1; if (r == k2) q2 = $1
          c = (r <= k1 || $1 <= q1 + 1e-6) ? 1 : (r <= k2 || $1 <= q2 + 1e-6) ? 2 : 3
      }
      add(c, $1, $2); add(4, $1, $2) }
    END {
        for (c = 1; c <= 3; c++) {
            if (by == "blocks") name = c == 1 ? "n_blocks 1-3" : c == 2 ? "n_blocks 4-30" : "n_blocks >=31"
            else name = sprintf("duration tercile %d", c)
            fit(c, name)
        }
        fit(4, "all")
        for (c = 1; c <= 4; c++) print most[c] + 0 > (dir "/piles.txt")
    }' "$tmp/md.tsv"
# A class's legend: its range (the terciles' durations), count, the largest number of its points
# that coincide (to 1e-6 in log10; drawn as one) when 10 or more do, and its fit.
label() { # ROW of fits.tsv -> the legend text
    awk -F'\t' -v k="$1" -v by="$by" -v pile="$(sed -n "${1}p" "$tmp/piles.txt")" 'NR == k {
        range = $1
        if (by == "duration" && k <= 3 && $2 > 0) range = sprintf("tercile %d, T %.3g–%.3g s", k, $6, $7)
        else sub(/>=/, "≥ ", range)
        if ($3 == "nan") fit = "no fit (a single duration)"
        else fit = sprintf("slope %.3g%s", $3, $4 == "nan" ? "" : sprintf(" ± %.2g", $4))
        printf "%s: %d ruptures%s, %s", range, $2, (pile >= 10 ? sprintf(" (%d of them at one point)", pile) : ""), fit }' "$tmp/fits.tsv"
}
fit_line() { # ROW COLOUR DASH -> a plot clause for the row's fit over its durations, or ""
    awk -F'\t' -v k="$1" -v c="$2" -v d="$3" 'NR == k && $3 != "nan" {
        printf ", [x=%.10g:%.10g] %s + %s * x with lines lw 2.5 dt %s lc rgb \047%s\047 notitle",
               log($6) / log(10), log($7) / log(10), $5, $3, d, c }' "$tmp/fits.tsv"
}
colours=('#1f77b4' '#2ca02c' '#d62728')
series=""
for c in 1 2 3; do
    [ -s "$tmp/md_$c.tsv" ] || continue
    series+="${series:+, }'$tmp/md_$c.tsv' using 1:2 with points pt 7 ps 0.6 lc rgb '${colours[c - 1]}' title '$(bk_gp_quote "$(label "$c")")'"
    series+=$(fit_line "$c" "${colours[c - 1]}" 1)
done
# Guides of slopes 1.5, 2 and 3 (Thøgersen et al.'s slow, sub-shear and supershear 1D
# exponents) through the centre of the points.
read -r cx cy x_lo x_hi y_lo y_hi < <(awk -F'\t' '{sx += $1; sy += $2; if (!n++) {lo = hi = $1; ylo = yhi = $2}
        lo = $1 < lo ? $1 : lo; hi = $1 > hi ? $1 : hi; ylo = $2 < ylo ? $2 : ylo; yhi = $2 > yhi ? $2 : yhi}
    END {d = 0.05 * (hi - lo); e = 0.08 * (yhi - ylo); if (d < 0.05) d = 0.05; if (e < 0.05) e = 0.05
         printf "%.10g %.10g %.10g %.10g %.10g %.10g\n", sx / n, sy / n, lo - d, hi + d, ylo - e, yhi + e}' "$tmp/md.tsv")
guides=""
dash=2
for s in 1.5 2 3; do
    guide_title=notitle
    [ "$s" != 1.5 ] || guide_title="title 'grey guides through the centre of the points: potency ∝ T^1.5 (dashes), T² (dots), T³ (dash-dots)'"
    guides+=", $cy + $s * (x - $cx) with lines lw 1.5 dt $dash lc rgb '#7f7f7f' $guide_title"
    dash=$((dash + 1))
done
all_fit=$(fit_line 4 '#000000' 1)
[ -z "$all_fit" ] || all_fit="${all_fit%notitle}title '$(bk_gp_quote "$(label 4)")'"
left_out=""
[ "$n_incomplete" -eq 0 ] || left_out="$n_incomplete still running at the end"
[ "$n_zero" -eq 0 ] || left_out="${left_out:+$left_out, }$n_zero of zero potency or duration"
ranges="by n_blocks"; [ "$by" = blocks ] || ranges="terciles of duration"
plot_draw "$out" <<GP
set title '$(bk_gp_quote "$stem"): moment (potency) against duration of the ruptures' . "\n" . \
          '$(bk_gp_quote "$n_md complete ruptures${left_out:+ (left out: $left_out)}; least-squares line per size range ($ranges)")' . "\n" . \
          'compare Thøgersen et al. (GRL 2019, 1D model): potency ∝ T^0.63 to T^1.5 slow, T² sub-shear, T³ supershear ruptures'
set xlabel 'log₁₀ duration T = t_end − t_start [s]'
set ylabel 'log₁₀ potency P [m]'
set xrange [$x_lo : $x_hi]
set yrange [$y_lo : $y_hi]
set grid lc rgb '#c0c0c0' lw 1 dt 3
set key outside below center vertical Left reverse
set bmargin 10
set datafile separator '\t'
plot $series $all_fit $guides
GP

printf '# range\tn_ruptures[1]\tslope[1]\tslope_error[1]\tintercept[1]\tduration_min[s]\tduration_max[s]\n'
cat "$tmp/fits.tsv"
printf '%s\n' "${outputs[@]}"
