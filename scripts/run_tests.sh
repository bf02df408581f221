#!/usr/bin/env bash
# Run every test program given (under $VALGRIND when set); report each, fail if any failed.
# TEST_JOBS=N runs up to N at a time, each one's output printed whole when it ends; the
# programs whose names are in TEST_ALONE (kills and wall clocks, timed against the machine)
# then run one at a time.
# usage: scripts/run_tests.sh LABEL PROGRAM...
set -u
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
[ $# -ge 1 ] || bk_usage
label=$1; shift
jobs=${TEST_JOBS:-1}
failed=()
together=() alone=()
for t in "$@"; do
    if [[ " ${TEST_ALONE:-} " == *" $(basename "$t") "* ]]; then alone+=("$t"); else together+=("$t"); fi
done
[ "$jobs" -gt 1 ] || { alone=("$@"); together=(); }

bk_temp_dir tmp
declare -A program_of
finish_one() {
    local pid status
    wait -n -p pid
    status=$?
    cat "$tmp/$pid.out"
    [ "$status" -eq 0 ] || failed+=("${program_of[$pid]}")
}
running=0
for t in "${together[@]}"; do
    [ "$running" -lt "$jobs" ] || { finish_one; running=$((running - 1)); }
    (exec ${VALGRIND:-} "$t" > "$tmp/$BASHPID.out" 2>&1) &
    program_of[$!]=$t
    running=$((running + 1))
done
while [ "$running" -gt 0 ]; do finish_one; running=$((running - 1)); done

for t in "${alone[@]}"; do
    if ${VALGRIND:-} "$t"; then :; else failed+=("$t"); fi
done
if [ ${#failed[@]} -ne 0 ]; then
    echo "FAILED ($label): ${failed[*]}" >&2
    exit 1
fi
echo "all ${#@} test programs passed ($label)"
