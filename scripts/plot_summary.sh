#!/usr/bin/env bash
# Any column of a sweep's summary (bksim summary DIR) against any other, one figure:
#   Y (points joined by lines, in the order of X) against X; an optional Y2 on the right
#   axis; --errors COL draws COL as Y's error bars; --by KEY draws one line per value of
#   KEY (another swept key).  Columns are named as in the header of DIR/summary.tsv
#   (friction.mu_d, mean_recurrence, peak_slip_rate, b_value, ...); nan rows are left out.
#   --x-transform EXPR plots EXPR of x (a gnuplot expression, e.g. 'sqrt(x)') instead of X;
#   --xlabel, --ylabel, --y2label replace the axis labels (column name and unit).
# Output: OUT (default DIR/summary_<Y>_vs_<X>.<fmt>).
# usage: plot_summary.sh [--format png|pdf|svg] [-o OUT] [--errors COL] [--by KEY]
#                        [--logx] [--logy] [--title TEXT] [--x-transform EXPR]
#                        [--xlabel TEXT] [--ylabel TEXT] [--y2label TEXT] DIR|SUMMARY.tsv X Y [Y2]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

format=png; out=""; errors=""; by=""; logx=0; logy=0; title=""; args=()
transform=x; xlabel=""; ylabel=""; y2label=""
while [ $# -gt 0 ]; do
    case $1 in
        --format) bk_need_value $# "$1"; format=$2; shift 2 ;;
        --format=*) format=${1#--format=}; shift ;;
        -o|--output) bk_need_value $# "$1"; out=$2; shift 2 ;;
        --errors) bk_need_value $# "$1"; errors=$2; shift 2 ;;
        --by) bk_need_value $# "$1"; by=$2; shift 2 ;;
        --logx) logx=1; shift ;;
        --logy) logy=1; shift ;;
        --title) bk_need_value $# "$1"; title=$2; shift 2 ;;
        --x-transform) bk_need_value $# "$1"; transform=$2; shift 2 ;;
        --xlabel) bk_need_value $# "$1"; xlabel=$2; shift 2 ;;
        --ylabel) bk_need_value $# "$1"; ylabel=$2; shift 2 ;;
        --y2label) bk_need_value $# "$1"; y2label=$2; shift 2 ;;
        -h|--help) bk_help ;;
        -*) bk_usage "unknown option '$1'" ;;
        *) args+=("$1"); shift ;;
    esac
done
[ ${#args[@]} -ge 3 ] && [ ${#args[@]} -le 4 ] || bk_usage
source=${args[0]} x=${args[1]} y=${args[2]} y2=${args[3]:-}
[ -d "$source" ] && source=$source/summary.tsv
bk_need_file "$source" "summary (run: bksim summary DIR)"
bk_terminal terminal "$format"
bk_need_command gnuplot gnuplot-nox
out=${out:-$(dirname "$source")/summary_${y}_vs_${x}.$format}

bk_temp_dir tmp
# Columns by name; rows sorted by X within each --by group, groups as gnuplot data blocks.
awk -F'\t' -v x="$x" -v y="$y" -v y2="$y2" -v e="$errors" -v by="$by" -v data="$tmp/data" \
    -v groups="$tmp/groups" -v units="$tmp/units" '
    /^#/ { if (match($0, /units: .*/)) print substr($0, RSTART + 7) > units; next }
    !header { header = 1
              for (i = 1; i <= NF; ++i) col[$i] = i
              split(x " " y " " y2 " " e " " by, want, " ")
              for (k in want) if (want[k] != "" && !(want[k] in col)) {
                  print "no column \"" want[k] "\" in the summary" > "/dev/stderr"; bad = 1; exit 1 }
              next }
    { if ($col[x] == "nan" || $col[y] == "nan") next
      g = by == "" ? "all" : $col[by]
      if (!(g in seen)) { seen[g] = 1; order[++n] = g }
      line = $col[x] "\t" $col[y] "\t" (y2 == "" ? "nan" : $col[y2]) "\t" (e == "" ? 0 : $col[e])
      rows[g] = rows[g] line "\n" }
    END { if (bad) exit 1
          for (k = 1; k <= n; ++k) {
              printf "%s", rows[order[k]] | ("sort -g > " data "." k)
              close("sort -g > " data "." k)
              print order[k] > groups } }' "$source" || bk_fail 1 "$source: cannot read the columns asked for"
[ -s "$tmp/groups" ] || bk_fail 1 "$source: no row with both $x and $y"
unit_of() { tr ',' '\n' < "$tmp/units" | awk -v c="$1" '{sub(/^ /, "")} $1 == c {print $2}'; }
label() { local u; u=$(unit_of "$1"); [ -n "$u" ] && [ "$u" != 1 ] && echo "$1 ($u)" || echo "$1"; }
: > "$tmp/all"
k=0
while IFS= read -r g; do
    k=$((k + 1)); cat "$tmp/data.$k" >> "$tmp/all"; printf '\n\n' >> "$tmp/all"
done < "$tmp/groups"
n_groups=$k

{
    echo "set terminal $terminal"
    echo "set output '$out'"
    echo "set datafile separator '\t'"
    echo "set key below"
    echo "set grid lc rgb '#dddddd'"
    echo "set offsets graph 0.03, graph 0.03, graph 0.05, graph 0.05"
    echo "xt(x) = $transform"
    echo "set xlabel '${xlabel:-$(label "$x")}' noenhanced"
    echo "set ylabel '${ylabel:-$(label "$y")}' noenhanced"
    [ -n "$title" ] && echo "set title '$title' noenhanced"
    [ $logx -eq 1 ] && echo "set logscale x"
    [ $logy -eq 1 ] && echo "set logscale y"
    if [ -n "$y2" ]; then
        echo "set y2label '${y2label:-$(label "$y2")}' noenhanced"
        echo "set ytics nomirror; set y2tics"
    fi
    printf 'plot '
    k=0
    while IFS= read -r g; do
        name=$y; [ -n "$by" ] && name="$y, $by = $g"
        [ $k -gt 0 ] && printf ', '
        if [ -n "$errors" ]; then
            printf "'%s' index %d using (xt(\$1)):2:4 with yerrorlines lw 2 pt 7 title '%s' noenhanced" "$tmp/all" "$k" "$name"
        else
            printf "'%s' index %d using (xt(\$1)):2 with linespoints lw 2 pt 7 title '%s' noenhanced" "$tmp/all" "$k" "$name"
        fi
        if [ -n "$y2" ]; then
            printf ", '%s' index %d using (xt(\$1)):3 axes x1y2 with linespoints lw 2 pt 5 dt 2 title '%s' noenhanced" \
                "$tmp/all" "$k" "$y2${by:+, $by = $g}"
        fi
        k=$((k + 1))
    done < "$tmp/groups"
    echo
} > "$tmp/plot.gp"
gnuplot "$tmp/plot.gp" 2> "$tmp/err" || bk_fail 1 "gnuplot: $(cat "$tmp/err")"
echo "$out ($n_groups line$([ "$n_groups" -eq 1 ] || echo s))"
