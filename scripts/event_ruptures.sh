#!/usr/bin/env bash
# How many spatially separate ruptures each catalogued event holds.  bksim's events are
# temporal (README "Earthquake catalogs and statistics"): two ruptures far apart that
# overlap in time are one event.  Papers that count a connected slipping cluster as an
# event see such an event as several; this script measures how often that happens.
# A rupture is a maximal run of neighbouring blocks (round the ring when periodic) that
# slipped during the event; blocks slipping at different moments of one event count
# together.  Needs /transitions (run with [output] transitions = true).
# Prints one summary line; with --table, first one row per complete event:
#   t_start  n_blocks  ruptures
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
"$bksim" info "$file" > "$tmp/info" 2> "$tmp/err" || [ $? -eq 3 ] || bk_fail 1 "$(cat "$tmp/err")"
n=$(awk '$1 == "n_blocks" {print $2; exit}' "$tmp/info")
boundary=$(awk '$1 == "boundary" && $2 == "=" {print $3; exit}' "$tmp/info")
[[ $n =~ ^[0-9]+$ ]] || bk_fail 1 "$file: no n_blocks in bksim info"
"$bksim" export "$file" --events > "$tmp/events.tsv" 2> "$tmp/err" || bk_fail 1 "$(cat "$tmp/err")"
"$bksim" export "$file" --transitions > "$tmp/transitions.tsv" 2> "$tmp/err" ||
    bk_fail 1 "$(cat "$tmp/err")"
[ "$(grep -vc '^#' "$tmp/transitions.tsv")" -gt 0 ] ||
    bk_fail 1 "$file: /transitions is empty (run with [output] transitions = true)"

# Events (t_start t_end n_blocks complete) in order, then transitions in time order: each
# onset (to != 0) belongs to the event whose interval holds its time.
awk -v n="$n" -v ring="$([ "$boundary" = periodic ] && echo 1 || echo 0)" \
    -v table="$table" '
function close_event(   b, runs, all) {
    if (k < 1 || !complete[k]) return
    runs = 0; all = 1
    for (b = 0; b < n; ++b) {
        if (!(b in slipped)) { all = 0; continue }
        if (b > 0 && ((b - 1) in slipped)) continue
        if (b == 0 && ring && ((n - 1) in slipped)) continue
        ++runs
    }
    if (all) runs = 1
    if (table) printf "%.17g\t%d\t%d\n", t0[k], size[k], runs
    ++events; if (runs > 1) ++merged; total += runs
}
FNR == 1 { file_no++ }
/^#/ { next }
file_no == 1 { ++m; t0[m] = $1; t1[m] = $2; size[m] = $4; complete[m] = $12; next }
{
    t = $1 + 0; to = $4 + 0
    if (to == 0) next
    while (k < m && (k < 1 || t > t1[k])) { close_event(); delete slipped; ++k }
    if (k >= 1 && t >= t0[k] && t <= t1[k]) slipped[$2 + 0] = 1
}
END {
    close_event()
    if (table) printf "# "
    printf "%d complete events with onsets in /transitions; %d (%.1f %%) hold two or more separate ruptures; %d ruptures in all\n",
        events, merged, events ? 100 * merged / events : 0, total
}' "$tmp/events.tsv" "$tmp/transitions.tsv"
