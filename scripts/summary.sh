#!/usr/bin/env bash
# One line per run, over every block: slip events (stick -> slip transitions of any block),
# peak slip rate (largest |v| of any block) and the range of the apparent COF (all blocks).
# A file without /transitions, /v or /cof gets "n/a" for that figure, and the loop goes on;
# a file that cannot be read is named on stderr, and the exit status is then 1.  For a sweep
# directory, `bksim summary DIR` gives one table with every run's figures.
# usage: summary.sh RUN.h5...
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
[ $# -gt 0 ] || bk_usage
bk_find_bksim bksim
status=0
# The largest |value| (abs = 1) or the range of every column but none, of an export.
columns() {
    awk -v abs="$1" '/^#/ {next}
        { for (i = 1; i <= NF; ++i) { x = $i; if (abs && x < 0) x = -x
              if (n++ == 0 || x < lo) lo = x; if (n == 1 || x > hi) hi = x } }
        END { if (!n) print "n/a"; else if (abs) printf "%.4g\n", hi; else printf "%.4g .. %.4g\n", lo, hi }'
}
for file in "$@"; do
    name=$(basename "$file" .h5)
    # 0: complete; 3: a run that did not finish, summarised as far as it got.
    why=$("$bksim" info "$file" 2>&1 > /dev/null)
    case $? in
        0|3) ;;
        *) bk_warn "$(head -1 <<< "$why")"; status=1; continue ;;
    esac
    slips=$("$bksim" export "$file" --transitions 2> /dev/null |
        awk '!/^#/ && $3 == 0 && $4 != 0 {n++} END {print n+0}') || slips=n/a
    vmax=$("$bksim" export "$file" --datasets v 2> /dev/null | columns 1) || vmax=n/a
    # Rows only at transition instants miss every slip's peak: no figure rather than a low one.
    [ "$(bk_sample_rows "$file")" -gt 2 ] || vmax="n/a (no sample rows between t = 0 and the end)"
    cof=$("$bksim" export "$file" --datasets cof 2> /dev/null | columns 0) || cof=n/a
    unit=" m/s"; case $vmax in n/a*) unit="" ;; esac
    printf "%-32s slip events %4s   peak slip rate %s%s   apparent COF %s\n" "$name" "$slips" "${vmax:-n/a}" "$unit" \
        "${cof:-n/a}"
done
exit $status
