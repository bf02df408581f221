#!/usr/bin/env bash
# The rupture catalog at scale (part of make bench): the random Coulomb chain of
# configs/chains/bk1000_coulomb.ini grown to 10^6 blocks, run as a user would keep only the
# catalog (output.interval = 0, transitions = false), with /rupture_rate (the default) and
# without.  Each run is one process timed by /usr/bin/time: wall and CPU time (user + sys) and
# peak resident memory, beside the complete ruptures it wrote and the output's size.  The
# targets (README "Ruptures"): at least 10^4 complete ruptures in under 4 minutes of wall time
# and under 1 GB resident; a run that misses one is reported and the script exits 1.
# --quick runs 10^5 blocks (a smoke run; targets not checked).
# usage: scripts/bench_ruptures.sh [--quick] OUTDIR
# Writes OUTDIR/ruptures_bench.tsv and OUTDIR/ruptures_machine.txt.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"
quick=0
case "${1:-}" in
    --quick) quick=1; shift ;;
    -h|--help) bk_help ;;
esac
[ $# -ge 1 ] || bk_usage "missing OUTDIR"
out=$1
mkdir -p "$out"
bk_need_command /usr/bin/time time
bk_need_command h5dump hdf5-tools
bk_find_bksim bksim
bk_temp_dir scratch

if [ $quick = 1 ]; then n=100000; t_end=0.3; else n=1000000; t_end=0.3; fi
scripts/machine_info.sh > "$out/ruptures_machine.txt"
tsv=$out/ruptures_bench.tsv
printf 'n_blocks\tt_end_s\trupture_rate\twall_s\tcpu_s\tpeak_rss_mb\ttransitions\truptures\tcomplete\trupture_blocks_rows\trupture_rate_rows\tfile_mb\n' > "$tsv"
missed=0
for rate in true false; do
    h5=$scratch/chain_$rate.h5
    /usr/bin/time -f '%e %U %S %M' -o "$scratch/time" "$bksim" run configs/chains/bk1000_coulomb.ini --quiet \
        --set model.n_blocks=$n --set run.t_end=$t_end --set output.interval=0 --set output.transitions=false \
        --set catalog.rupture_rate=$rate -o "$h5" --force ||
        bk_fail 1 "the $n-block run (rupture_rate = $rate) failed"
    read -r wall user sys rss_kb < <(tail -1 "$scratch/time")
    transitions=$(h5dump -a /stats/transitions "$h5" 2>/dev/null | awk '/\(0\)/ {print $2; exit}')
    "$bksim" export "$h5" --table ruptures > "$scratch/ruptures.tsv"
    ruptures=$(awk '!/^#/' "$scratch/ruptures.tsv" | wc -l)
    complete=$(awk -F'\t' '!/^#/ && $NF == 1' "$scratch/ruptures.tsv" | wc -l)
    block_rows=$("$bksim" export "$h5" --table rupture_blocks | awk '!/^#/' | wc -l)
    rate_rows=0
    [ "$rate" = false ] || rate_rows=$("$bksim" export "$h5" --table rupture_rate | awk '!/^#/' | wc -l)
    file_mb=$(awk -v b="$(stat -c %s "$h5")" 'BEGIN {printf "%.1f", b / 1e6}')
    cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN {printf "%.2f", u + s}')
    rss=$(awk -v k="$rss_kb" 'BEGIN {printf "%.0f", k / 1024}')
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$n" "$t_end" "$rate" "$wall" "$cpu" "$rss" \
        "${transitions:-NaN}" "$ruptures" "$complete" "$block_rows" "$rate_rows" "$file_mb" >> "$tsv"
    echo "$n blocks, rupture_rate = $rate: $complete complete ruptures in $wall s wall ($cpu s CPU), $rss MB peak, $file_mb MB"
    rm -f "$h5"
    if [ $quick = 0 ] && { [ "$complete" -lt 10000 ] || awk -v w="$wall" -v r="$rss" 'BEGIN {exit !(w >= 240 || r >= 1024)}'; }; then
        echo "target missed: >= 10^4 complete ruptures in < 240 s wall and < 1 GB resident" >&2
        missed=1
    fi
done
exit $missed
