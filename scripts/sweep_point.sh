#!/usr/bin/env bash
# One point of a sweep planned by scripts/sweep.sh (GNU parallel and SLURM run this alike):
# skip it when DIR/<point>.h5 is finished, else `bksim run DIR/base.ini --resume` with the
# point's --set values (a .part with a checkpoint continues from it; anything else starts
# over).  Prints one status line for DIR/sweep.log; the run's own messages are appended to
# DIR/logs/<point>.log.  Exit status 0 when the point is finished, 1 when it failed.
# usage: scripts/sweep_point.sh DIR POINT
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/sweep_lib.sh"
[ $# -eq 2 ] || bk_usage
dir=$1 name=$2
out=$dir/$name.h5
log=$dir/logs/$name.log
stamp() { date '+%F %T'; }
if [ -e "$out" ]; then
    printf '%s\t%s\tskipped: finished before\n' "$(stamp)" "$name"
    exit 0
fi
sets=()
found=0
{
    IFS=$'\t' read -r -a keys
    while IFS=$'\t' read -r -a values; do
        [ "${values[0]}" = "$name" ] || continue
        found=1
        for i in $(seq 1 $((${#keys[@]} - 1))); do sets+=(--set "${keys[$i]}=${values[$i]}"); done
        break
    done
} < "$dir/points.tsv"
if [ "$found" != 1 ]; then
    printf '%s\t%s\tFAILED: no such point in %s/points.tsv\n' "$(stamp)" "$name" "$dir"
    exit 1
fi
bk_find_bksim bksim 2
mkdir -p "$dir/logs"
printf '== %s on %s: bksim run %s -o %s --resume --point %s %s\n' "$(stamp)" "$(hostname)" \
    "$dir/base.ini" "$out" "$name" "${sets[*]}" >> "$log"
start=$(date +%s.%N)
"$bksim" run "$dir/base.ini" -o "$out" --resume --point "$name" "${sets[@]}" >> "$log" 2>&1
status=$?
seconds=$(echo "$(date +%s.%N) $start" | awk '{printf "%.1f", $1 - $2}')
# This attempt's messages: the log's lines after its last '==' header.
attempt=$(awk '/^== / {text = ""; next} {text = text $0 "\n"} END {printf "%s", text}' "$log")
resumed=$(grep -o 'continuing .* from its checkpoint t = [^ ]*' <<< "$attempt" | tail -1)
if [ $status -eq 0 ]; then
    printf '%s\t%s\tdone in %s s%s\n' "$(stamp)" "$name" "$seconds" "${resumed:+ ($resumed)}"
    exit 0
fi
printf '%s\t%s\tFAILED (exit %d after %s s): %s\n' "$(stamp)" "$name" "$status" "$seconds" \
    "$(tail -n 2 <<< "$attempt" | tr '\n' ' ')"
exit 1
