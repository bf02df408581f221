#!/usr/bin/env bash
# The rupture catalog /ruptures of a run against its time-window catalog /events: how many
# ruptures there are, how large, and how many each event holds.  bksim's events are temporal
# (README "Earthquake catalogs and statistics"): two ruptures far apart that overlap in time
# are one event.  Papers that count a connected slipping cluster as an event see such an
# event as several; this script counts how often that happens.  A rupture (README
# "Ruptures") is a connected set of slip episodes of neighbouring blocks that overlap in
# time; it belongs to the event whose interval holds its t_start.
# Prints two summary lines: the ruptures (complete, still running, their sizes in blocks)
# and the complete events with how many hold two or more ruptures; with --table, first one
# row per complete event:
#   t_start  n_blocks  ruptures
# A file without /ruptures or /events is an error (exit status 1; bad options 2).
# usage: event_ruptures.sh [--table] FILE.h5
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

table=0; file=""
for arg in "$@"; do
    case $arg in
        --table) table=1 ;;
        -h|--help) bk_help ;;
        -*) bk_usage "unknown option '$arg'" ;;
        *) [ -z "$file" ] || bk_usage "unexpected argument '$arg'"
           file=$arg ;;
    esac
done
[ -n "$file" ] || bk_usage "missing FILE.h5"
bk_need_file "$file"
bk_find_bksim bksim

bk_temp_dir tmp
"$bksim" export "$file" --table ruptures > "$tmp/ruptures.tsv" 2> "$tmp/err" || bk_fail 1 "$(cat "$tmp/err")"
"$bksim" export "$file" --events > "$tmp/events.tsv" 2> "$tmp/err" || bk_fail 1 "$(cat "$tmp/err")"
# Ruptures by t_start (they are written as they complete), as "t_start n_blocks complete".
awk -F'\t' '!/^#/ {print $1 "\t" $4 "\t" $15}' "$tmp/ruptures.tsv" | sort -t $'\t' -g -k1,1 > "$tmp/sorted.tsv"

# Events (t_start t_end n_blocks complete) in time order, then the ruptures in time order:
# each belongs to the event whose interval holds its t_start.
awk -F'\t' -v table="$table" '
function close_event() {
    if (k < 1 || !complete[k]) return
    if (table) printf "%.17g\t%d\t%d\n", t0[k], size[k], count
    ++events; if (count > 1) ++merged; total += count
}
FNR == 1 { file_no++ }
/^#/ { next }
file_no == 1 { ++m; t0[m] = $1; t1[m] = $2; size[m] = $4; complete[m] = $12; next }
{
    t = $1 + 0
    ++ruptures; if ($3 == 1) { ++done; sizes[done] = $2 + 0; sum += $2 } else ++running
    while (k < m && (k < 1 || t > t1[k])) { close_event(); count = 0; ++k }
    if (k >= 1 && t >= t0[k] && t <= t1[k]) ++count
}
END {
    close_event()
    n = done
    for (i = 1; i <= n; i++) { c = sizes[i] <= 1 ? 1 : sizes[i] <= 3 ? 2 : sizes[i] <= 30 ? 3 : 4; ++cls[c]
                               if (i == 1 || sizes[i] > max) max = sizes[i]; if (i == 1 || sizes[i] < min) min = sizes[i] }
    # The (lower) median by counting: sizes are whole numbers from min to max.
    for (i = 1; i <= n; i++) ++hist[sizes[i]]
    half = n / 2; below = 0; med = ""
    for (s = min; n && s <= max && med == ""; s++) { below += hist[s]; if (below >= half) med = s }
    if (table) printf "# "
    printf "%d ruptures: %d complete, %d still running at the end", ruptures, done, running
    if (n) printf "; complete ones of %d to %d blocks (median %d, mean %.3g): 1 block %d, 2-3 %d, 4-30 %d, >= 31 %d",
                  min, max, med, sum / n, cls[1], cls[2], cls[3], cls[4]
    printf "\n"
    if (table) printf "# "
    printf "%d complete events; %d (%.1f %%) hold two or more separate ruptures; %d ruptures in all\n",
        events, merged, events ? 100 * merged / events : 0, total
}' "$tmp/events.tsv" "$tmp/sorted.tsv"
