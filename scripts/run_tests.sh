#!/usr/bin/env bash
# Run every test program given (under $VALGRIND when set); report each, fail if any failed.
set -u
label=$1; shift
failed=()
for t in "$@"; do
    if ${VALGRIND:-} "$t"; then :; else failed+=("$t"); fi
done
if [ ${#failed[@]} -ne 0 ]; then
    echo "FAILED ($label): ${failed[*]}" >&2
    exit 1
fi
echo "all ${#@} test programs passed ($label)"
