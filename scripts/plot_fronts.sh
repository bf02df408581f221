#!/usr/bin/env bash
# Fronts on a chain loaded from one edge (`bksim fronts`), as three figures:
#   OUTDIR/<stem>_precursors.<fmt>  the precursor plot of Rubinstein, Cohen & Fineberg (PRL
#       98, 226103, 2007) and the 1D spring-block models: each rupture that began at the
#       loaded edge, its arrest length (blocks from the edge to the farthest it reached)
#       against the edge force as it began; those that crossed the chain marked apart, the
#       records (longer than every one before) joined; with --kinetic F the quasi-static
#       estimate L = F_edge / F (the blocks a precursor moved stop near the kinetic friction
#       F per block, and carry the edge force at rest);
#   OUTDIR/<stem>_fronts.<fmt>  the fronts of the records: each block's arrival time
#       t_onset - t_start against its distance from the edge, one curve per record, so the
#       arrests are seen to move out;
#   OUTDIR/<stem>_front_<K>_speed.<fmt>  rupture K's local front speed (a least-squares fit
#       over --window blocks) against the distance from the edge; by default K is the first
#       rupture that crossed the chain, else the longest.
# Prints the precursor table (bksim fronts) of the ruptures from the edge, then the figures'
# paths, one a line.  <stem> is FILE's name without .h5 (and .part); OUTDIR defaults to
# FILE's directory.  A lattice, or a file without /ruptures, is an error (exit status 1; bad
# options 2).
# usage: plot_fronts.sh [--format png|pdf|svg] [-o OUTDIR] [--edge left|right] [--rupture K]
#                       [--window W] [--kinetic F] FILE.h5
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
edge=left rupture="" window=8 kinetic=""
number='^([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$'
while [ $# -gt 0 ]; do
    case $1 in
        --edge) bk_need_value $# "$1"; edge=$2; shift 2 ;;
        --rupture) bk_need_value $# "$1"; rupture=$2; shift 2 ;;
        --window) bk_need_value $# "$1"; window=$2; shift 2 ;;
        --kinetic) bk_need_value $# "$1"; kinetic=$2; shift 2 ;;
        *) plot_file_option "$@"; shift "$PLOT_SHIFT" ;;
    esac
done
case $edge in left|right) ;; *) bk_usage "--edge must be left or right, got '$edge'" ;; esac
[ -z "$rupture" ] || bk_check_whole --rupture "$rupture" "a rupture row" 0
bk_check_whole --window "$window" "a number of blocks" 2
[ -z "$kinetic" ] || { [[ $kinetic =~ $number ]] && awk -v f="$kinetic" 'BEGIN {exit !(f > 0)}'; } ||
    bk_usage "--kinetic needs a force > 0 N, got '$kinetic'"
plot_file_setup

"$bksim" fronts "$file" --edge "$edge" > "$tmp/fronts.tsv" 2> "$tmp/err" || bk_fail 1 "$(cat "$tmp/err")"
# From the edge, in order of start (the table's order).
awk -F'\t' '/^#/ || $7 == 1' "$tmp/fronts.tsv" > "$tmp/edge.tsv"
n_edge=$(awk '!/^#/' "$tmp/edge.tsv" | wc -l)
[ "$n_edge" -gt 0 ] || bk_fail 1 "$file: no rupture began at the $edge edge: nothing to plot (another --edge?)"
n_blocks=$(awk '/^# fronts of/ {gsub(/[(]/, ""); for (i = 1; i <= NF; ++i) if ($(i + 1) == "blocks),") print $i}' "$tmp/fronts.tsv")
[[ ${n_blocks:-} =~ ^[0-9]+$ ]] || n_blocks=$(awk '!/^#/ && $6 > m {m = $6} END {print m + 0}' "$tmp/edge.tsv")
cat "$tmp/edge.tsv"
outputs=() # the figures' paths, in the order drawn (plot_draw)


# --------------------------------------------------------------- (a) precursors ---
awk -F'\t' '!/^#/ && $3 != "nan" && $8 == 0 {print $3, $6}' "$tmp/edge.tsv" > "$tmp/arrested.dat"
awk -F'\t' '!/^#/ && $3 != "nan" && $8 == 1 {print $3, $6}' "$tmp/edge.tsv" > "$tmp/crossed.dat"
awk -F'\t' '!/^#/ && $3 != "nan" && $6 > best {best = $6; print $3, $6, $1}' "$tmp/edge.tsv" > "$tmp/records.dat"
[ -s "$tmp/arrested.dat" ] || [ -s "$tmp/crossed.dat" ] ||
    bk_fail 1 "$file: no edge force is known (no /transitions, or the edge block was slipping as each began)"
series() { # FILE STYLE TITLE
    if [ -s "$1" ]; then echo "'$1' using 1:2 $2 title '$3'"; else echo "NaN $2 title '$3'"; fi
}
guide=""
[ -z "$kinetic" ] || guide=", x / $kinetic with lines lw 2 dt 2 lc rgb '#555555' title 'L = F_edge / $kinetic N (at rest near the kinetic friction)'"
out="$outdir/${stem}_precursors.$format"
plot_draw "$out" <<GP
set title '$(bk_gp_quote "$stem"): precursors from the $edge edge ($n_edge ruptures began there)'
set xlabel 'edge force as the rupture began [N]'
set ylabel 'arrest length [blocks from the edge]'
set yrange [0 : $n_blocks * 1.05 + 1]
set grid lc rgb '#c0c0c0' lw 1 dt 3
set key outside below center vertical Left reverse
set bmargin 8
plot $(series "$tmp/arrested.dat" "with points pt 7 ps 0.6 lc rgb '#1f77b4'" "arrested (a precursor)"), \
     $(series "$tmp/crossed.dat" "with points pt 5 ps 1.2 lc rgb '#d62728'" "crossed the chain"), \
     $(series "$tmp/records.dat" "with linespoints pt 6 ps 1.2 lw 1.5 lc rgb '#ff7f0e'" "records: longer than every one before") $guide
GP

# --------------------------------------------------------- (b) the records' fronts ---
# The last ten records, each one's front as distance against arrival time.
tail -n 10 "$tmp/records.dat" | awk '{print $3}' > "$tmp/record_ids"
plots=() k=0
while read -r id; do
    "$bksim" fronts "$file" --edge "$edge" --rupture "$id" --window "$window" > "$tmp/r$id.tsv" 2> "$tmp/err" ||
        bk_fail 1 "$(cat "$tmp/err")"
    awk -F'\t' '!/^#/ {if (!n++) t0 = $3; print $2, $3 - t0}' "$tmp/r$id.tsv" > "$tmp/r$id.dat"
    length=$(awk '$1 > m {m = $1} END {print m + 1}' "$tmp/r$id.dat")
    plots+=("'$tmp/r$id.dat' using 1:2 with linespoints pt 7 ps 0.5 lw 1.5 lc palette frac $(awk -v k="$k" 'BEGIN {print k / 10}') title 'rupture $id: $length blocks'")
    k=$((k + 1))
done < "$tmp/record_ids"
out="$outdir/${stem}_fronts.$format"
plot_draw "$out" <<GP
set title '$(bk_gp_quote "$stem"): the fronts of the longest precursors so far (the records)'
set xlabel 'distance from the $edge edge [blocks]'
set ylabel 'arrival time t_onset − t_start [s]'
set grid lc rgb '#c0c0c0' lw 1 dt 3
set palette defined (0 '#1f77b4', 1 '#d62728')
unset colorbox
set key outside right top
plot $(IFS=,; echo "${plots[*]}")
GP

# ------------------------------------------------------------ (c) one front's speed ---
if [ -z "$rupture" ]; then
    rupture=$(awk -F'\t' '!/^#/ && $8 == 1 {print $1; exit}' "$tmp/fronts.tsv")
    [ -n "$rupture" ] || rupture=$(awk -F'\t' '!/^#/ && $6 > m {m = $6; k = $1} END {print k}' "$tmp/fronts.tsv")
fi
"$bksim" fronts "$file" --edge "$edge" --rupture "$rupture" --window "$window" > "$tmp/one.tsv" 2> "$tmp/err" ||
    bk_fail 1 "$(cat "$tmp/err")"
awk -F'\t' '!/^#/ && $6 != "nan" && $6 != "inf" {print $2, $6}' "$tmp/one.tsv" > "$tmp/speed.dat"
mean=$(awk -F'\t' -v k="$rupture" '!/^#/ && $1 == k {print $9}' "$tmp/fronts.tsv")
out="$outdir/${stem}_front_${rupture}_speed.$format"
plot_draw "$out" <<GP
set title '$(bk_gp_quote "$stem"): rupture $rupture, its front speed along the chain' . "\n" . \
          'least squares over $window blocks; mean over the rupture $mean blocks/s'
set xlabel 'distance from the $edge edge [blocks]'
set ylabel 'front speed [blocks/s]'
set grid lc rgb '#c0c0c0' lw 1 dt 3
set key outside below center
plot $(series "$tmp/speed.dat" "with linespoints pt 7 ps 0.6 lw 1.5 lc rgb '#1f77b4'" "local front speed")
GP
printf '%s\n' "${outputs[@]}"
