#!/usr/bin/env bash
# One line per run: slip events (stick -> slip), peak slip rate and the range of the
# apparent COF of block 0.
# usage: summary.sh RUN.h5...
set -euo pipefail
bksim=${BKSIM:-./bksim}
for file in "$@"; do
    slips=$("$bksim" export "$file" --transitions --block 0 | awk '!/^#/ && $3 == 0 && $4 != 0 {n++} END {print n+0}')
    "$bksim" export "$file" --datasets time,v,cof --block 0 | awk -v f="$(basename "$file" .h5)" -v slips="$slips" '
        /^#/ {next}
        { v = $2 < 0 ? -$2 : $2; if (v > vmax) vmax = v
          if (n++ == 0 || $3 < cmin) cmin = $3; if (n == 1 || $3 > cmax) cmax = $3 }
        END { printf "%-32s slip events %4d   peak slip rate %.4g m/s   apparent COF %.4g .. %.4g\n",
                     f, slips, vmax, cmin, cmax }'
done
