#!/usr/bin/env bash
# One rupture's (or event's) slip over a 2D lattice, as a map of rows x cols cells (block i
# at row i / cols, column i % cols; row 0 on top), each coloured by how far block i slipped
# (m); over a chain, slip against block, a bar each:
#   OUTDIR/<stem>_rupture_<K>_slip_map.<fmt>  row K of the rupture catalog /ruptures (the
#       default; --rupture K): the slip of each of its blocks from /rupture_blocks, x at its
#       last stop minus x at its first onset in the rupture: exact, whatever the file keeps;
#   OUTDIR/<stem>_slip_map_<K>.<fmt>  row K of the time-window catalog /events (--table
#       events, or --event K).  With /transitions (the default) that is exact: x at the
#       block's last transition in the event minus x at its first.  Without, or for an
#       event still running at the end, it is x in the first sample row at or after t_end
#       (else the last row) minus x in the last one at or before t_start, which also counts
#       whatever else moved between those rows.
# The epicentre (first_block) is a point, the bounding box (left..right) a rectangle, in
# pieces when it wraps round a periodic edge.  K is the 0-based row (`bksim export FILE
# --table ruptures`, or --events); by default, or with --largest, the row of largest
# potency.  A file without the table is an error (an older file has no /ruptures: give
# --table events).  <stem> is FILE's name without .h5 (and .part); OUTDIR defaults to
# FILE's directory.
# usage: plot_slip_map.sh [--format png|pdf|svg] [-o OUTDIR] [--table ruptures|events]
#                         [--rupture K | --event K | --largest] FILE.h5
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
event="" table="" row_option=""
while [ $# -gt 0 ]; do
    case $1 in
        --rupture|--event) bk_need_value $# "$1"; event=$2; row_option=$1; shift 2 ;;
        --rupture=*|--event=*) event=${1#*=}; row_option=${1%%=*}; shift ;;
        --largest) event=""; shift ;;
        --table) bk_need_value $# "$1"; table=$2; shift 2 ;;
        --table=*) table=${1#--table=}; shift ;;
        *) plot_file_option "$@"; shift "$PLOT_SHIFT" ;;
    esac
done
case $table in ruptures|events|"") ;; *) bk_usage "--table must be ruptures or events, got '$table'" ;; esac
# --rupture K reads /ruptures, --event K /events; either with a --table that names the other
# is a usage error.
case $row_option in
    --rupture) [ "$table" != events ] || bk_usage "--rupture K reads /ruptures: not with --table events (give --event K)" ;;
    --event) [ "$table" != ruptures ] || bk_usage "--event K reads /events: not with --table ruptures (give --rupture K)"
             table=events ;;
esac
table=${table:-ruptures}
[ -z "$event" ] || bk_check_whole "${row_option}" "$event" "a row of /$table" 0
plot_file_setup
partial=""
bk_at_exit '[ -z "$partial" ] || rm -f "$partial"'
if [ "$table" = ruptures ]; then
    row_word=rupture export_args=(--table ruptures)
    no_table_hint=" (--table events maps a row of the time-window catalog /events)"
else
    row_word=event export_args=(--events) no_table_hint=""
fi
"$bksim" export "$file" "${export_args[@]}" > "$tmp/events.tsv" 2> "$tmp/err" ||
    bk_fail 1 "$(cat "$tmp/err")$no_table_hint"

# The row: K, or the largest finite potency (the first of equals; row 0 if none is finite).
# Its fields, tab-separated, go to the shell in one read.
n_events=$(awk '!/^#/' "$tmp/events.tsv" | wc -l)
[ "$n_events" -gt 0 ] || bk_fail 1 "$file: /$table is empty: no $row_word to map"
if [ -z "$event" ]; then
    event=$(awk -F'\t' '/^#/ {next}
        {k = n++; p = $8 + 0}
        $8 !~ /nan|inf/ && (best == "" || p > pmax) {best = k; pmax = p}
        END {print best == "" ? 0 : best}' "$tmp/events.tsv")
    what="; the largest by potency"
else
    event=$(echo "$event" | sed 's/^0*//; s/^$/0/')
    if [ ${#event} -gt 15 ] || [ "$event" -ge "$n_events" ]; then
        bk_fail 1 "$file: $row_option $event out of range: /$table has $n_events rows (0..$((n_events - 1)))"
    fi
    what=""
fi
# /events ends with complete; /ruptures has duration and the front speeds before it.
IFS=$'\t' read -r t_start t_end first_block ev_blocks left right _ _ magnitude _ _ complete < <(
    awk -F'\t' -v k="$event" -v ruptures="$([ "$table" = ruptures ] && echo 1 || echo 0)" '
        !/^#/ && n++ == k { if (ruptures) $12 = $15; NF = 12; print }' OFS='\t' "$tmp/events.tsv")

plot_file_shape "$file"
[ -n "$n_blocks" ] || bk_fail 1 "$file: bksim info gives no n_blocks"

# A rupture's slip is exact from /rupture_blocks: each of its blocks' x at its last stop
# minus x at its first onset in the rupture.
if [ "$table" = ruptures ]; then
    "$bksim" export "$file" --table rupture_blocks > "$tmp/blocks.tsv" 2> "$tmp/err" ||
        bk_fail 1 "$(cat "$tmp/err")"
    awk -F'\t' -v k="$event" '!/^#/ && $1 == k' "$tmp/blocks.tsv" > "$tmp/one.tsv"
    [ -s "$tmp/one.tsv" ] || bk_fail 1 "$file: /rupture_blocks has no row of rupture $event"
fi
# A finished event's slip is exact from /transitions, where the run kept them: a block is
# stuck between its episodes, so x at its last transition in the event minus x at its first
# is all it slipped, and nothing else that moved between two sample rows counts.  They come
# as two rows in the export's form (t_start, then t_end), so the map below takes either; so
# do a rupture's blocks (x = 0 at t_start, x = its slip at t_end).
from_transitions=0
if [ "$table" = events ] && [ "$complete" = 1 ] &&
   awk '$1 == "transitions" && $2 ~ /^[0-9]+$/ && $2 > 0 {found = 1} END {exit !found}' <<<"$info"; then
    from_transitions=1
fi
samples() {
    if [ "$table" = ruptures ]; then
        awk -F'\t' -v ts="$t_start" -v te="$t_end" -v n="$n_blocks" '
            { slip[$2] = $5 }
            END {
                printf "%s", ts; for (i = 0; i < n; i++) printf " 0"; print ""
                printf "%s", te; for (i = 0; i < n; i++) printf " %.17g", (i in slip) ? slip[i] : 0; print ""
            }' "$tmp/one.tsv"
        return
    fi
    if [ "$from_transitions" = 0 ]; then
        "$bksim" export "$file" --datasets time,x
        return
    fi
    "$bksim" export "$file" --transitions | awk -v ts="$t_start" -v te="$t_end" -v n="$n_blocks" '
        /^#/ { next }
        $1 + 0 < ts + 0 { next }
        $1 + 0 > te + 0 { exit }
        { if (!($2 in first)) first[$2] = $5; last[$2] = $5 }
        END {
            printf "%s", ts; for (i = 0; i < n; i++) printf " %.17g", (i in first) ? first[i] : 0; print ""
            printf "%s", te; for (i = 0; i < n; i++) printf " %.17g", (i in last) ? last[i] : 0; print ""
        }'
}

# The two sample rows, picked by awk as the export streams by (a 64x64 lattice's rows are
# ~100 kB each: bash never holds them), then the slip per cell as "col row slip".  awk
# stops at the "after" row; the export then dies of SIGPIPE (or a write error), which is
# fine once awk has both rows.
out_rc=0
{ samples 2> "$tmp/err" || echo $? > "$tmp/export_rc"; } |
awk -v ts="$t_start" -v te="$t_end" -v complete="$complete" -v cols="$cols" -v rows="$rows" \
    -v info="$tmp/rows.txt" '
    /^#/ { next }
    # The time by hand: $1 would split all n + 1 fields of every row.
    { n_rows++; t = substr($0, 1, match($0, /[ \t]/) - 1) + 0 }
    # The last row at or before t_start (the first row if there is none).
    !have_b || t <= ts + 0 { before = $0; have_b = 1 }
    complete + 0 == 1 && t >= te + 0 { after = $0; have_a = 1; early = 1; exit }
    { last = $0 }
    END {
        if (!n_rows) exit 3
        if (!have_a) after = last != "" ? last : before
        nb = split(before, b, " "); na = split(after, a, " ")
        n = nb - 1
        if (na != nb || n < 1) exit 4
        if (rows * cols != n) exit 5
        printf "%.17g %.17g %d %d %d %d\n", b[1], a[1], n, rows, cols, early > info
        # gnuplot images need 2 x 2 points: a single row or column is split in two halves.
        fr = rows == 1 ? 2 : 1; fc = cols == 1 ? 2 : 1
        for (r = 0; r < rows * fr; r++) {
            for (c = 0; c < cols * fc; c++) {
                i = int(r / fr) * cols + int(c / fc)
                printf "%.10g %.10g %.10g\n", (fc == 1 ? c : c / 2 - 0.25), (fr == 1 ? r : r / 2 - 0.25),
                       a[i + 2] - b[i + 2]
            }
            print ""
        }
    }' > "$tmp/slip.dat" || out_rc=$?
export_rc=$(cat "$tmp/export_rc" 2>/dev/null || echo 0)
early=0
[ "$out_rc" -ne 0 ] || read -r t_before t_after n rows cols early < "$tmp/rows.txt"
if [ "$export_rc" -ne 0 ] && [ "$early" -ne 1 ]; then
    [ -s "$tmp/err" ] || bk_fail 1 "bksim export $file --datasets time,x failed (status $export_rc)"
    bk_fail 1 "$(cat "$tmp/err")"
fi
case $out_rc in
    0) ;;
    3) bk_fail 1 "$file: no sample rows in /time: nothing to map" ;;
    4) bk_fail 1 "$file: cannot read the rows of 'bksim export --datasets time,x'" ;;
    5) bk_fail 1 "$file: the x columns do not make the ${rows} x ${cols} lattice bksim info reports" ;;
    *) bk_fail 1 "awk failed reading the samples of $file" ;;
esac

g() { LC_ALL=C printf "%.${2:-6}g" "$1"; }

# The colour range: from 0 (or the most negative slip) to the largest, never empty.
cb_range=$(awk 'NF == 3 {if (!n++) lo = hi = $3; if ($3 < lo) lo = $3; if ($3 > hi) hi = $3}
    END {if (lo > 0) lo = 0; if (hi < 0) hi = 0; if (hi - lo <= 0) hi = lo + 1e-9
         printf "%.10g:%.10g", lo, hi}' "$tmp/slip.dat")

# The bounding box, left = top-left corner, right = bottom-right; a span whose first
# row/col is past its last wraps round a periodic edge: two intervals, so up to four pieces.
span() { # FIRST LAST SIZE -> "lo hi" intervals, one a line
    if [ "$1" -le "$2" ]; then echo "$1 $2"; else echo "$1 $(($3 - 1))"; echo "0 $2"; fi
}
boxes=""; n_pieces=0
if [[ $left =~ ^[0-9]+$ && $right =~ ^[0-9]+$ ]] && [ "$left" -lt "$n" ] && [ "$right" -lt "$n" ]; then
    while read -r r0 r1; do
        while read -r c0 c1; do
            n_pieces=$((n_pieces + 1))
            boxes+="set object $n_pieces rect from $c0 - 0.5, $r0 - 0.5 to $c1 + 0.5, $r1 + 0.5 front fs empty border lc rgb '#1f77b4' lw 3 dt 2
"
        done < <(span $((left % cols)) $((right % cols)) "$cols")
    done < <(span $((left / cols)) $((right / cols)) "$rows")
fi
box_plot=""
if [ "$n_pieces" -gt 0 ]; then
    box_title="bounding box, blocks $left..$right"
    [ "$n_pieces" -eq 1 ] || box_title="$box_title (wraps: $n_pieces pieces)"
    box_plot="NaN with lines lw 3 dt 2 lc rgb '#1f77b4' title '$(bk_gp_quote "$box_title")', "
fi
epi_r=$((first_block / cols)); epi_c=$((first_block % cols))

running=""; [ "$complete" = 1 ] || running=" (still running at the end)"
title1="$stem: $row_word $event (of 0..$((n_events - 1))$what), t = $(g "$t_start")..$(g "$t_end") s$running"
blocks_word=blocks; [ "$ev_blocks" != 1 ] || blocks_word=block
title2="$ev_blocks $blocks_word, M = $(g "$magnitude" 4); slip from the sample at t = $(g "$t_before") s to the one at t = $(g "$t_after") s"
[ "$from_transitions" = 0 ] ||
    title2="$ev_blocks $blocks_word, M = $(g "$magnitude" 4); slip from each block's first to its last transition in the event"
[ "$table" = events ] ||
    title2="$ev_blocks $blocks_word, M = $(g "$magnitude" 4); slip of each block, first onset to last stop (/rupture_blocks)"
# Square cells unless the lattice is long and thin (a chain): then the cells fill the frame.
ratio="set size ratio -1"
if [ $((rows * 4)) -lt "$cols" ] || [ $((cols * 4)) -lt "$rows" ]; then ratio="set size noratio"; fi
tics() { if [ "$1" -le 16 ]; then echo "set $2tics 1"; else echo "set $2tics out; set m$2tics"; fi; }

out_name=${stem}_slip_map_$event
[ "$table" = events ] || out_name=${stem}_rupture_${event}_slip_map
out="$outdir/$out_name.$format"
# Drawn to a hidden file beside the figure, renamed when gnuplot succeeded.
partial=$(mktemp "$outdir/.$out_name.XXXXXX") ||
    bk_fail 1 "$outdir: cannot write there"
if [ "$rows" -eq 1 ]; then
    # A chain: slip against block, a bar each (a one-row colour map stretched across the frame
    # showed the same numbers less readably); the bounding box shaded, the epicentre marked.
    awk 'NF == 3 { b = int($1 + 0.5); if (!(b in seen)) { seen[b] = 1; print b, $3 } }' "$tmp/slip.dat" |
        sort -n > "$tmp/chain.dat"
    shade=""
    if [ "$n_pieces" -gt 0 ]; then
        k=0
        while read -r c0 c1; do
            k=$((k + 1))
            shade+="set object $k rect from $c0 - 0.5, graph 0 to $c1 + 0.5, graph 1 back fs solid 0.12 noborder fc rgb '#1f77b4'
"
        done < <(span "$left" "$right" "$cols")
    fi
    gnuplot <<GP 2> "$tmp/gp.err" || bk_fail 1 "gnuplot failed drawing $out: $(cat "$tmp/gp.err")"
set encoding utf8
set terminal $terminal
set output '$(bk_gp_quote "$partial")'
set title '$(bk_gp_quote "$title1")' . "\n" . '$(bk_gp_quote "$title2")'
set xrange [-0.5 : $cols - 0.5]
$(tics "$cols" x)
set xlabel 'block'
set ylabel 'slip during the $row_word [m]'
set grid ytics lc rgb '#c0c0c0' dt 3
set key outside below center horizontal
set style fill solid 0.8 noborder
set boxwidth 0.8
$shade
plot '$tmp/chain.dat' using 1:2 with boxes lc rgb '#cc4c02' title 'slip', \
     ${box_plot:+NaN with boxes fs solid 0.12 lc rgb '#1f77b4' title '$(bk_gp_quote "${box_title:-}")', }'-' using 1:2 with points pt 7 ps 1.6 lc rgb '#17becf' title 'epicentre, block $first_block'
$epi_c 0
e
GP
else
gnuplot <<GP 2> "$tmp/gp.err" || bk_fail 1 "gnuplot failed drawing $out: $(cat "$tmp/gp.err")"
set encoding utf8
set terminal $terminal
set output '$(bk_gp_quote "$partial")'
set title '$(bk_gp_quote "$title1")' . "\n" . '$(bk_gp_quote "$title2")'
$ratio
set xrange [-0.5 : $cols - 0.5]
set yrange [$rows - 0.5 : -0.5]
$(tics "$cols" x)
$(tics "$rows" y)
$( [ "$rows" -gt 1 ] || echo "set ytics (0)")
set xlabel 'column (block i % $cols)'
set ylabel 'row (block i / $cols)'
set cbrange [$cb_range]
set cblabel 'slip during the $row_word [m]'
# Room on the right for the colour box's label.
set rmargin 18
set palette defined (0 '#ffffe5', 0.15 '#fff7bc', 0.3 '#fee391', 0.45 '#fec44f', 0.6 '#fe9929', 0.75 '#ec7014', 0.88 '#cc4c02', 1 '#662506')
set key outside below center horizontal
$boxes
plot '$tmp/slip.dat' using 1:2:3 with image notitle, \
     $box_plot'-' using 1:2 with points pt 7 ps 2.2 lc rgb '#000000' notitle, \
     '-' using 1:2 with points pt 7 ps 1.2 lc rgb '#17becf' title 'epicentre, block $first_block'
$epi_c $epi_r
e
$epi_c $epi_r
e
GP
fi
# mktemp made it private; give it the mode a new file would have.
chmod "$(printf %o $((0666 & ~0$(umask))))" "$partial" || true
mv -f "$partial" "$out" || bk_fail 1 "cannot rename $partial to $out"
partial=""
echo "$out"
