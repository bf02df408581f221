#!/usr/bin/env bash
# A parameter sweep on this machine: the Cartesian product of the values given becomes one
# `bksim run BASE.ini --set KEY=V ...` per grid point, run by GNU parallel (Debian package
# `parallel`) on JOBS cores, then `bksim summary DIR`.  Resumable: the same command again
# skips every point whose DIR/<point>.h5 exists (finished), continues a DIR/<point>.h5.part
# from its checkpoint when it has one (bksim run --resume), reruns the rest, and never
# touches finished files.  scripts/slurm/submit.sh runs the same grid as a SLURM job array.
#
# usage: scripts/sweep.sh [-j JOBS] [-o DIR] [--plan] BASE.ini KEY=V1,V2,... [KEY=V ...]
#   KEY        section.key as for --set (block.3.mass for one block); a single value fixes
#              the key for every point
#   -j JOBS    parallel runs (default: every core)
#   -o DIR     where the outputs go (default: out/sweeps/<BASE name>)
#   --plan     write DIR's plan (base.ini, points.tsv) and stop: what submit.sh does first
# In DIR: base.ini (the config every point runs; a rerun with a different BASE is refused),
# points.tsv (point name, then one column per KEY), <point>.h5, logs/<point>.log (each
# run's own messages), sweep.log (one line per point and attempt: done, skipped, or FAILED
# with the exit status and the run's last message), summary.tsv and summary.h5.
# Exit status: 0 every point finished; 1 some point failed (sweep.log says which and why);
# 2 bad usage.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/sweep_lib.sh"

jobs=$(nproc)
dir=
plan_only=0
while [ $# -gt 0 ]; do
    case $1 in
        -j) bk_need_value $# "$1" "a number of jobs"; jobs=$2; shift 2 ;;
        -j*) jobs=${1#-j}; shift ;;
        -o) bk_need_value $# "$1" "a directory"; dir=$2; shift 2 ;;
        --plan) plan_only=1; shift ;;
        -h|--help) bk_help ;;
        --) shift; break ;;
        -*) bk_usage "unknown option '$1'" ;;
        *) break ;;
    esac
done
bk_check_whole -j "$jobs" "a whole number of jobs" 1
sweep_plan "$dir" "$@"
dir=$SWEEP_DIR
[ "$plan_only" -eq 1 ] && { echo "sweep: planned $SWEEP_POINTS points in $dir (points.tsv)"; exit 0; }

command -v parallel > /dev/null ||
    bk_fail 2 "GNU parallel is not installed (Debian: apt-get install parallel)"
echo "sweep: $SWEEP_POINTS points in $dir on $jobs jobs" >&2
# Each job prints one status line; --line-buffer keeps them whole and in the log as they end.
status=0
tail -n +2 "$dir/points.tsv" | cut -f1 |
    parallel --will-cite --quote --jobs "$jobs" --halt never --line-buffer \
        "$BK_SCRIPTS/sweep_point.sh" "$dir" {} >> "$dir/sweep.log" || status=1
sweep_report "$dir" || status=1
exit $status
