#!/usr/bin/env bash
# The clustering statistics of a run's catalog (`bksim stats`, README "Catalog statistics") as
# two figures, for the rupture catalog /ruptures (the default) or the table --table names:
#   OUTDIR/<stem>_<table>_interevent.<fmt>  interevent times rescaled by the rate above each
#       magnitude threshold (Corral 2004): the density of theta = tau R on logarithmic bins,
#       one colour per threshold (Mc, Mc + 0.5, ...), the gamma fit of the lowest threshold,
#       and the exponential (Poisson) law; the curves collapse onto one when the scaling
#       holds, and their CV and gamma shapes are in the legend;
#   OUTDIR/<stem>_<table>_omori.<fmt>  two panels: the stacked rate of events after the
#       mainshocks (and, inverted, before them) per mainshock against the time from the
#       mainshock on log axes, with the fitted Omori-Utsu laws K/(t + c)^p, the mainshock
#       count, p and the likelihood-ratio verdict; and Ogata's residual plot (cumulative count
#       against transformed time), which follows the diagonal when the law holds.
# A statistic bksim could not estimate is drawn as a note saying why (the JSON note), not as
# an empty frame.  The options after FILE.h5 are `bksim stats` options and are passed on:
# --from T (leave out a spin-up), --mainshock M, --window T, --mc, --bin.
# usage: plot_stats.sh [--format png|pdf|svg] [-o OUTDIR] [--table NAME] FILE.h5 [STATS OPTIONS]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/plot_lib.sh"
table=ruptures
stats_args=()
while [ $# -gt 0 ]; do
    case $1 in
        --table) bk_need_value $# "$1"; table=$2; shift 2 ;;
        --table=*) table=${1#--table=}; shift ;;
        --from|--to|--mainshock|--window|--mc|--bin)
            bk_need_value $# "$1"; stats_args+=("$1" "$2"); shift 2 ;;
        *) plot_file_option "$@"; shift "$PLOT_SHIFT" ;;
    esac
done
plot_file_setup
prefix=${stem}_$table
ie_out="$outdir/${prefix}_interevent.$format"
omori_out="$outdir/${prefix}_omori.$format"

# No bootstrap: these figures need none of its tests, and it is the report's slow part.
"$bksim" stats "$file" --table "$table" --bootstrap 0 "${stats_args[@]}" --json --tsv "$tmp/stats" \
    > "$tmp/stats.json" 2> "$tmp/err" || bk_fail 1 "$(cat "$tmp/err")"
# A value in the aftershocks' or foreshocks' part of the JSON report: the first "key": between
# "aftershocks": { and "foreshocks", or "foreshocks": { and "single" (a number, null, true or
# false); json gives a top-level value, note a string.
json_in() {
    local end=foreshocks
    [ "$1" = aftershocks ] || end=single
    awk -v from="\"$1\": {" -v to="\"$end\"" '{ i = index($0, from); if (!i) exit
        rest = substr($0, i + length(from)); j = index(rest, to); print (j ? substr(rest, 1, j) : rest) }' \
        "$tmp/stats.json" | grep -o "\"$2\": [^,}]*" | head -n 1 | sed 's/^[^:]*: //'
}
json() { grep -o "\"$1\": [^,}]*" "$tmp/stats.json" | head -n 1 | sed 's/^[^:]*: //'; }
note() { grep -o "\"$1\": \"[^\"]*\"" "$tmp/stats.json" | head -n 1 | sed 's/^[^:]*: "//; s/"$//'; }
num() { LC_ALL=C printf "%.${2}${3:-f}" "$1" | sed 's/^-/−/'; }
# note_figure OUT WHAT NOTE: a figure that holds why WHAT is not available, not an empty frame.
note_figure() {
    gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $1"
set encoding utf8
set terminal $terminal
set output '$(bk_gp_quote "$1")'
set title '$(bk_gp_quote "$stem"): $2 of the $table'
unset border; unset tics
set label 1 'not available: $(bk_gp_quote "$3")' at graph 0.5, graph 0.5 center
plot [0:1] [0:1] NaN notitle
GP
}
n_events=$(json n_events)
[ "$n_events" -gt 0 ] || bk_fail 1 "$file: /$table has no complete row with a finite magnitude: nothing to plot"

# ------------------------------------------------------------ (a) interevent ---
if [ -s "$tmp/stats/interevent.tsv" ]; then
    # One block per threshold: its legend from the JSON array, in the same order.
    mapfile -t legends < <(grep -o '"interevent": \[[^]]*\]' "$tmp/stats.json" |
        grep -o '{[^}]*}' | sed 's/[{}"]//g' | awk -F', ' '{
            for (i = 1; i <= NF; ++i) { split($i, kv, ": "); v[kv[1]] = kv[2] }
            printf "M ≥ %.4g: %d events, CV %.2f, gamma shape %.2f\n", v["magnitude_min"], v["n_events"], v["cv"], v["gamma_shape"] }')
    colors=('#1f77b4' '#ff7f0e' '#2ca02c' '#d62728' '#9467bd')
    plot="plot "
    for k in "${!legends[@]}"; do
        plot+="'$tmp/stats/interevent.tsv' index $k using 2:(\$3 > 0 ? \$3 : NaN) with linespoints pt 7 ps 1.1 lw 1.5 lc rgb '${colors[$k]}' title '$(bk_gp_quote "${legends[$k]}" | sed 's/-/−/g')', "
    done
    plot+="'$tmp/stats/interevent.tsv' index 0 using 2:4 with lines lw 2 dt 2 lc rgb '#444444' title 'gamma fit of the lowest threshold', "
    plot+="exp(-x) with lines lw 1.5 dt 3 lc rgb '#888888' title 'Poisson process: exp(−θ)'"
    # The axes cover the data (a decade of margin below): the fitted laws fall steeply beyond.
    ie_range=$(awk '!/^#/ && NF >= 3 && $3 > 0 { if (!n++) { xl = xh = $2; yl = yh = $3 }
        xl = $2 < xl ? $2 : xl; xh = $2 > xh ? $2 : xh; yl = $3 < yl ? $3 : yl; yh = $3 > yh ? $3 : yh }
        END { printf "set xrange [%g:%g]\nset yrange [%g:%g]\n", xl / 2, xh * 2, yl / 10, yh * 3 }' \
        "$tmp/stats/interevent.tsv")
    gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $ie_out"
set encoding utf8
set terminal $terminal
set output '$(bk_gp_quote "$ie_out")'
$ie_range
set title '$(bk_gp_quote "$stem"): interevent times of the $table, rescaled by the rate (Corral 2004)' . "\n" . 'θ = τ R, R the rate above each threshold; curves that collapse share one law'
set logscale xy
set format x '%g'
set format y '%g'
set grid lc rgb '#c0c0c0' lw 1 dt 3
set xlabel 'rescaled interevent time θ = τ R'
set ylabel 'probability density of θ'
set key outside below center vertical Left reverse spacing 1.2
set samples 400
$plot
GP
else
    note_figure "$ie_out" "interevent times" "$(note interevent_note)"
fi

# --------------------------------------------------------------- (b) Omori ---
if [ -s "$tmp/stats/omori.tsv" ]; then
    n_main=$(json n_mainshocks); m_main=$(json mainshock_magnitude); window=$(json window)
    # The fitted law per mainshock and its verdict, for aftershocks and foreshocks.
    describe() { # $1: aftershocks|foreshocks
        local p c k lr decays n
        n=$(json_in "$1" n); p=$(json_in "$1" p); c=$(json_in "$1" c); k=$(json_in "$1" k_per_mainshock)
        lr=$(json_in "$1" likelihood_ratio); decays=$(json_in "$1" decays)
        if [ "$p" = null ] || [ -z "$p" ] || [ "$(json_in "$1" omori)" = null ]; then
            echo "NaN|$1: no fit ($n events)"
            return
        fi
        local verdict="no significant decay"
        [ "$decays" = true ] && verdict="decays (likelihood ratio $(num "$lr" 1), 1 % level)"
        echo "$k/(x + $c)**$p|fit: p = $(num "$p" 2), c = $(num "$c" 3 g) s; $verdict"
    }
    # Two panels: the terminal's size, 1.4 times as tall.
    tall_terminal=$(sed 's/size 1200,800/size 1200,1120/; s/size 10in,6.67in/size 10in,9.33in/' <<< "$terminal")
    residual_p=$(json_in aftershocks p_value)
    [ -n "$residual_p" ] && [ "$residual_p" != null ] && residual_p=$(num "$residual_p" 3 g) || residual_p=none
    IFS='|' read -r after_fit after_title < <(describe aftershocks)
    IFS='|' read -r before_fit before_title < <(describe foreshocks)
    gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $omori_out"
set encoding utf8
set terminal $tall_terminal
set output '$(bk_gp_quote "$omori_out")'
set multiplot layout 2,1 title '$(bk_gp_quote "$stem"): $n_main mainshocks (M ≥ $(num "$m_main" 2 g)), windows of $(num "$window" 4 g) s, $table stacked'
set grid lc rgb '#c0c0c0' lw 1 dt 3
set key outside below center vertical Left reverse spacing 1.1
set logscale xy
set format x '%g'
set format y '%g'
set xlabel 'time from the mainshock [s]'
set ylabel 'rate per mainshock [1/s]'
set samples 400
plot '$tmp/stats/omori.tsv' index 0 using 1:(\$2 > 0 ? \$2 : NaN) with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'after the mainshocks', \
     [x=*:$window] $after_fit with lines lw 2 lc rgb '#1f77b4' title '$(bk_gp_quote "$after_title")', \
     '' index 1 using 1:(\$2 > 0 ? \$2 : NaN) with points pt 6 ps 1.2 lw 1.5 lc rgb '#d62728' title 'before (time to the mainshock)', \
     [x=*:$window] $before_fit with lines lw 2 dt 2 lc rgb '#d62728' title '$(bk_gp_quote "$before_title")'
unset logscale
set format x '%g'
set format y '%g'
set xlabel 'transformed time τ = ∫ fitted rate (events the law expects)'
set ylabel 'cumulative number of events'
set size ratio 0
plot '$tmp/stats/omori_residuals.tsv' index 0 using 1:2 with steps lw 2 lc rgb '#1f77b4' title 'after (residual KS p = $residual_p)', \
     '' index 1 using 1:2 with steps lw 2 dt 2 lc rgb '#d62728' title 'before', \
     x with lines lw 1 lc rgb '#555555' title 'the fitted law (diagonal)'
unset multiplot
GP
else
    note_figure "$omori_out" "mainshock sequences" "$(note sequences_note)"
fi
echo "$ie_out"
echo "$omori_out"
