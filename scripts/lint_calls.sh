#!/usr/bin/env bash
# Fail when the given object files call one another in a circle (make lint runs it on the
# library's objects).  File A calls file B when A leaves undefined a symbol that B defines
# (nm).  The files must stand in layers, each calling only files below it (README "Layout
# and development"): a satellite reaches its top file only through function pointers it is
# handed.  tsort finds the circles; each is printed with the names that tie its files.
# Calls through pointers and static inline functions tie no object to another and are not
# seen.
# usage: scripts/lint_calls.sh OBJECT.o...
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
case "${1:-}" in -h | --help) bk_help ;; esac
[ $# -gt 0 ] || bk_usage
for object in "$@"; do bk_need_file "$object" object 2; done
bk_need_command nm binutils
bk_need_command tsort coreutils
bk_temp_dir work
for object in "$@"; do
    nm --defined-only "$object" | awk -v f="$object" 'NF == 3 && $2 ~ /[TDRB]/ {print $3, f}'
done | sort > "$work/defined"
for object in "$@"; do
    nm --undefined-only "$object" | awk '{print $NF}' | sort -u | join - "$work/defined" |
        awk -v f="$object" '$2 != f {print f, $2, $1}'
done > "$work/calls"
cut -d' ' -f1,2 "$work/calls" | sort -u | tsort > /dev/null 2> "$work/loops" || true
if [ ! -s "$work/loops" ]; then
    echo "lint: no circle of calls among the $# objects"
    exit 0
fi
echo "lint: files that call one another in a circle (each must call only files below it):" >&2
awk '/input contains a loop/ {if (n) print ""; n++; next} {sub(/^tsort: /, ""); printf "  %s", $0} END {print ""}' \
    "$work/loops" >&2
echo "calls among them (caller callee name):" >&2
members=$(sed -n 's/^tsort: \([^-].*\)$/\1/p' "$work/loops" | sort -u)
awk 'NR == FNR {in_loop[$1] = 1; next} ($1 in in_loop) && ($2 in in_loop) {print "  " $0}' \
    <(printf '%s\n' $members) "$work/calls" >&2
exit 1
