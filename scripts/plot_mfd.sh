#!/usr/bin/env bash
# A run's earthquake catalog as two figures: the rupture catalog /ruptures (connected slip
# episodes, README "Ruptures"; the default) or, with --table events, the time-window catalog
# /events (maximal intervals during which some block slips):
#   OUTDIR/<stem>_ruptures_mfd.<fmt>  magnitude-frequency distribution: incremental (points)
#       (events: <stem>_mfd.<fmt>)    and cumulative (line and points) counts per magnitude
#                                     bin on a log scale, the fitted Gutenberg-Richter law
#                                     log10 N = a - b M from Mc up, b and its error and the
#                                     fit test's verdict (or why there is no b), Mc marked,
#                                     and the GR law on the largest range [Mc, Mu] its fit
#                                     test passes (fitted counts per bin; Mu marked): where a
#                                     size cutoff bends the distribution, the law below it;
#   OUTDIR/<stem>_ruptures_spacetime.<fmt>  every rupture's (event's) extent (blocks
#       (events: <stem>_spacetime.<fmt>)    left..right) at its start time, coloured by
#                                           magnitude; one that wraps past block 0 on a ring
#                                           (left > right) is drawn as two segments.  A chain
#                                           only: on a lattice left..right bound a box, and
#                                           the plot is left out with a warning.
# The statistics are `bksim stats FILE --table TABLE` (complete rows only; Mc by maximum
# curvature + 0.2, bins of 0.1); the rows are `bksim export FILE --table TABLE` (every row,
# running ones too).  A file without the table is an error (an older file has no /ruptures:
# give --table events).  <stem> is FILE's name without .h5 (and .part); OUTDIR defaults to
# FILE's directory.  Optional XRANGE=lo:hi (s) zooms the space-time plot in time.
# usage: plot_mfd.sh [--format png|pdf|svg] [-o OUTDIR] [--table ruptures|events] FILE.h5
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
table=ruptures
while [ $# -gt 0 ]; do
    case $1 in
        --table) bk_need_value $# "$1"; table=$2; shift 2 ;;
        --table=*) table=${1#--table=}; shift ;;
        *) plot_file_option "$@"; shift "$PLOT_SHIFT" ;;
    esac
done
case $table in ruptures|events) ;; *) bk_usage "--table must be ruptures or events, got '$table'" ;; esac
plot_file_setup
# The words and file names of the catalog.
if [ "$table" = ruptures ]; then
    rows_word=ruptures prefix=${stem}_ruptures export_args=(--table ruptures) mfd_of=" of the ruptures"
else
    rows_word=events prefix=$stem export_args=(--events) mfd_of=""
fi
mfd_out="$outdir/${prefix}_mfd.$format"
st_out="$outdir/${prefix}_spacetime.$format"

no_table_hint=""
[ "$table" = events ] || no_table_hint=" (--table events plots the time-window catalog /events)"
"$bksim" export "$file" "${export_args[@]}" > "$tmp/events.tsv" 2> "$tmp/err" ||
    bk_fail 1 "$(cat "$tmp/err")$no_table_hint"
"$bksim" stats "$file" --table "$table" --json --tsv "$tmp/stats" > "$tmp/stats.json" 2> "$tmp/err" ||
    bk_fail 1 "$(cat "$tmp/err")"
# A top-level value of the JSON report (the first occurrence of the key): a number, or
# null when bksim could not estimate it; json_note gives a *_note string.
json() { grep -o "\"$1\": [^,}]*" "$tmp/stats.json" | head -n 1 | sed 's/^[^:]*: //'; }
json_note() { grep -o "\"$1\": \"[^\"]*\"" "$tmp/stats.json" | head -n 1 | sed 's/^[^:]*: "//; s/"$//'; }
n_rows=$(json n_rows); n_events=$(json n_events)
n_incomplete=$(json n_incomplete); n_nonfinite=$(json n_nonfinite)
n_mc=$(json n_above_mc); mc=$(json mc); b=$(json b_value); b_err=$(json b_value_error); a=$(json a_value)
dm=$(json bin); m_max=$(json magnitude_max)
[ "$n_rows" -gt 0 ] || bk_fail 1 "$file: /$table is empty: nothing to plot"

# The chain's length and shape (plot_file_shape), else the largest block an event reached.
plot_file_shape "$file"
if [ -z "$n_blocks" ]; then
    n_blocks=$(awk -F'\t' '!/^#/ {m = $5 > m ? $5 : m; m = $6 > m ? $6 : m} END {print m + 1}' \
        "$tmp/events.tsv")
fi

# Numbers as text: a minus sign, not a hyphen.
num() { LC_ALL=C printf "%.${2}${3:-f}" "$1" | sed 's/^-/−/'; }

# ------------------------------------------------------- (a) magnitude-frequency ---
left_out=""
[ "$n_incomplete" -eq 0 ] || left_out="$n_incomplete still running at the end"
[ "$n_nonfinite" -eq 0 ] || left_out="${left_out:+$left_out, }$n_nonfinite of zero potency (M = −∞)"
subtitle="$n_events complete $rows_word in bins of ΔM = $dm${left_out:+; left out: $left_out}"
# An object of the JSON report ("gr_fit", "gr_truncated") as one line, and a value in it.
json_object() { { grep -o "\"$1\": {[^}]*}" "$tmp/stats.json" || true; } | head -n 1; }
json_field() { grep -o "\"$2\": [^,}]*" <<< "$1" | head -n 1 | sed 's/^[^:]*: //'; }
# Legend entries stay short enough for one line of the key (gnuplot drops a key wider than
# the canvas): notes longer than that are cut.
short() { local text=$1; [ ${#text} -le 95 ] && printf '%s' "$text" || printf '%s…' "${text:0:94}"; }
gof=$(json_object gr_fit)
verdict=""
if [ -n "$gof" ]; then
    verdict="KS distance $(num "$(json_field "$gof" ks_distance)" 3), bootstrap p = $(num "$(json_field "$gof" p_value)" 2 g)"
fi
if [ "$b" != null ]; then
    b_err_text=""
    [ "$b_err" = null ] || b_err_text=" ± $(num "$b_err" 3)"
    fit_title="GR fit for M ≥ Mc: log₁₀ N = a − b M, b = $(num "$b" 3)${b_err_text}, a = $(num "$a" 3) ($n_mc $rows_word)"
    fit_plot=", [x=$mc:$m_max + $dm/2] 10**($a - $b*x) with lines lw 2.5 lc rgb '#d62728' title '$(bk_gp_quote "$fit_title")'"
    [ -z "$verdict" ] ||
        fit_plot+=", NaN with lines lw 0 lc rgb 'white' title '$(bk_gp_quote "   consistent with GR above Mc: $verdict")'"
elif [ -n "$verdict" ] && [ "$(json_field "$gof" consistent)" = false ]; then
    fit_plot=", NaN with lines lw 2.5 lc rgb '#d62728' title '$(bk_gp_quote "no b: not a Gutenberg–Richter distribution above Mc ($verdict)")'"
else
    fit_plot=", NaN with lines lw 2.5 lc rgb '#d62728' title '$(bk_gp_quote "$(short "no b: $(json_note b_value_note)")")'"
fi
# The truncated law (GR on [Mc, Mu], the largest range its fit test passes): fitted counts per
# bin beside the incremental points, Mu marked.
truncated=$(json_object gr_truncated)
mu_arrow=""
if [ -n "$truncated" ] && [ -s "$tmp/stats/gr_truncated_fit.tsv" ]; then
    mu=$(json_field "$truncated" magnitude_max); n_above=$(json_field "$truncated" n_above)
    t_title="GR on Mc ≤ M ≤ Mu = $(num "$mu" 6 g): b = $(num "$(json_field "$truncated" b_value)" 3) ± $(num "$(json_field "$truncated" b_value_error)" 3), p = $(num "$(json_field "$truncated" p_value)" 2 g), counts per bin"
    [ "$n_above" = 0 ] || t_title+="; $n_above above Mu left out"
    fit_plot+=", '$tmp/stats/gr_truncated_fit.tsv' using 1:2 with lines lw 2 dt 4 lc rgb '#2ca02c' title '$(bk_gp_quote "$t_title")'"
    mu_arrow="set arrow 2 from $mu + $dm/2, graph 0 to $mu + $dm/2, graph 1 nohead dt 4 lw 1.5 lc rgb '#2ca02c' back"
else
    fit_plot+=", NaN with lines lw 2 dt 4 lc rgb '#2ca02c' title '$(bk_gp_quote "$(short "no truncated GR fit: $(json_note gr_truncated_note)")")'"
fi
mc_arrow=""; mc_plot=""
if [ "$mc" != null ]; then
    mc_arrow="set arrow 1 from $mc, graph 0 to $mc, graph 1 nohead dt 2 lw 2 lc rgb '#555555' back"
    mc_plot=", NaN with lines dt 2 lw 2 lc rgb '#555555' title 'completeness magnitude Mc = $(num "$mc" 6 g)'"
fi
if [ -s "$tmp/stats/mfd.tsv" ]; then
# The magnitude axis covers every bin and Mc; the count axis from below 1 to twice the
# number of events (at least 10).
mfd_x=$(awk -v mc="$mc" -v dm="$dm" '!/^#/ {if (!n++) lo = hi = $1; if ($1 < lo) lo = $1; if ($1 > hi) hi = $1}
    END {if (mc != "null") {if (mc < lo) lo = mc; if (mc > hi) hi = mc}
         printf "%.10g:%.10g", lo - dm, hi + dm}' "$tmp/stats/mfd.tsv")
mfd_ymax=$(awk '!/^#/ && $3 > m {m = $3} END {print (2 * m > 10 ? 2 * m : 10)}' \
           "$tmp/stats/mfd.tsv")
gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $mfd_out"
set encoding utf8
set terminal $terminal
set output '$(bk_gp_quote "$mfd_out")'
set title '$(bk_gp_quote "$stem"): magnitude-frequency distribution$mfd_of' . "\n" . '$(bk_gp_quote "$subtitle")'
set grid lc rgb '#c0c0c0' lw 1 dt 3
set xlabel 'magnitude M'
set ylabel 'number of $rows_word N'
set xrange [$mfd_x]
set logscale y
set format y '%g'
set yrange [0.5:$mfd_ymax]
set mytics 10
set key outside below center vertical Left reverse width -4 spacing 1.2
$mc_arrow
$mu_arrow
plot '$tmp/stats/mfd.tsv' using 1:(\$3 > 0 ? \$3 : NaN) with linespoints pt 7 ps 0.9 lw 1.5 lc rgb '#1f77b4' title 'cumulative N(≥ M)', \
     '' using 1:(\$2 > 0 ? \$2 : NaN) with points pt 6 ps 1.3 lw 1.5 lc rgb '#ff7f0e' title 'incremental N(M), per bin' \
     $fit_plot $mc_plot
GP
else
    bk_warn "$file: no complete row of /$table with a finite magnitude: no $mfd_out"
fi

# ------------------------------------------------------------- (b) space-time ---
# On a lattice left..right are the flat indices of a bounding box, not a span of blocks: a
# segment between them would draw blocks that did not slip.
if [ "$rows" -gt 1 ]; then
    bk_warn "$file: a $rows x $cols lattice: no space-time plot (left..right are the flat block indices of a bounding box, not a span of blocks; plot_slip_map.sh maps a rupture's own blocks)"
    echo "$mfd_out"
    exit 0
fi
# Segments t, from, to, magnitude, the blocks as cells [i - 1/2, i + 1/2]; a wrapping event
# gives two.  Sorted by magnitude, so that the larger events are drawn on top.  Events of
# zero potency (magnitude -inf) go to a file of their own, drawn grey.
awk -F'\t' -v n="$n_blocks" -v seg="$tmp/seg.unsorted" -v zero="$tmp/zero.dat" '
    BEGIN { printf "" > seg; printf "" > zero }
    /^#/ { next }
    { out = ($9 ~ /inf|nan/) ? zero : seg
      if ($5 <= $6) print $1, $5 - 0.5, $6 + 0.5, $9 > out
      else { print $1, $5 - 0.5, n - 0.5, $9 > out; print $1, -0.5, $6 + 0.5, $9 > out } }' \
    "$tmp/events.tsv"
sort -g -k4,4 "$tmp/seg.unsorted" > "$tmp/seg.dat"
n_wrap=$(awk -F'\t' '!/^#/ && $5 > $6' "$tmp/events.tsv" | wc -l)
n_zero=$(awk -F'\t' '!/^#/ && $9 ~ /inf|nan/' "$tmp/events.tsv" | wc -l)
t_range=$(awk -F'\t' '!/^#/ {if (!n++) lo = hi = $1; if ($1 < lo) lo = $1; if ($1 > hi) hi = $1}
                      END {d = hi > lo ? 0.01 * (hi - lo) : 1; printf "%.17g:%.17g", lo - d, hi + d}' \
          "$tmp/events.tsv")
m_range=$(awk '{if (!n++) lo = hi = $4; if ($4 < lo) lo = $4; if ($4 > hi) hi = $4}
               END {if (!n) lo = hi = 0; if (hi - lo < 0.1) {c = (lo + hi) / 2; lo = c - 0.05; hi = c + 0.05}
                    printf "%.17g:%.17g", lo, hi}' \
          "$tmp/seg.dat")
zero_plot=""
[ "$n_zero" -eq 0 ] ||
    zero_plot=", '$tmp/zero.dat' using 1:2:(0):(\$3 - \$2) with vectors nohead lw 2 lc rgb '#999999' title 'zero potency (M = −∞)'"
wrap_note=""
[ "$n_wrap" -eq 0 ] || wrap_note=", $n_wrap wrapping past block 0 (drawn as two segments)"
gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $st_out"
set encoding utf8
set terminal $terminal
set output '$(bk_gp_quote "$st_out")'
set title '$(bk_gp_quote "$stem"): $rows_word in space and time' . "\n" . \
          '$n_rows $rows_word$wrap_note; a segment spans blocks left..right at t_start'
set xlabel '${rows_word%s} start time t_start [s]'
set ylabel 'block'
set xrange [${XRANGE:-$t_range}]
set yrange [-0.5 : $n_blocks - 0.5]
set ytics out nomirror
$(if [ "$n_blocks" -le 12 ]; then echo "set ytics 1"; else echo "set mytics"; fi)
set grid back lc rgb '#c0c0c0' lw 1 dt 3
set cbrange [$m_range]
set cblabel 'magnitude M'
set rmargin at screen 0.84
set colorbox vertical user origin screen 0.865, screen 0.2 size screen 0.025, screen 0.65
set palette defined (0 '#30123b', 0.15 '#4662d7', 0.3 '#36aaf9', 0.45 '#1ae4b6', 0.6 '#72fe5e', 0.75 '#c8ef34', 0.85 '#faba39', 0.93 '#f66b19', 1 '#7a0403')
set key outside below center horizontal
${zero_plot:+set bmargin 5.5}
plot '$tmp/seg.dat' using 1:2:(0):(\$3 - \$2):4 with vectors nohead lw 2 lc palette notitle $zero_plot
GP
echo "$mfd_out"
echo "$st_out"
