#!/usr/bin/env bash
# The grid of scripts/sweep.sh as a SLURM job array: one array task per CHUNK points, then
# `bksim summary DIR` as a job that waits for the array (afterany: it summarises whatever
# finished).  Resumable the same way as sweep.sh: submitting the same command again skips
# finished points and continues interrupted ones from their checkpoints.  bksim schedules
# nothing itself; sbatch must be on PATH and DIR on a file system the nodes share.
#
# usage: scripts/slurm/submit.sh [-c CHUNK] [-o DIR] [--sbatch "OPTIONS"] BASE.ini KEY=V1,V2,... [KEY=V ...]
#   -c CHUNK          points per array task (default 1)
#   -o DIR            as for sweep.sh (default out/sweeps/<BASE name>)
#   --sbatch OPTIONS  extra sbatch options for both jobs, e.g. "--partition=short --time=2:00:00"
# Prints the array's and the summary's job ids.  Each task's status lines go to
# DIR/sweep.log, SLURM's own output to DIR/logs/slurm-<job>_<task>.out.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../sweep_lib.sh"
scripts=$BK_SCRIPTS # the jobs are told where the scripts are: SLURM runs copies of them

chunk=1
dir=
sbatch_options=
while [ $# -gt 0 ]; do
    case $1 in
        -c) bk_need_value $# "$1" "a number of points"; chunk=$2; shift 2 ;;
        -o) bk_need_value $# "$1" "a directory"; dir=$2; shift 2 ;;
        --sbatch) bk_need_value $# "$1" "options"; sbatch_options=$2; shift 2 ;;
        -h|--help) bk_help ;;
        -*) bk_usage "unknown option '$1'" ;;
        *) break ;;
    esac
done
bk_check_whole -c "$chunk" "a whole number of points" 1
[ $# -ge 1 ] || bk_usage "missing BASE.ini"
command -v sbatch > /dev/null || bk_fail 2 "no sbatch on PATH: is this a SLURM login node?"
sweep_plan "$dir" "$@"
dir=$(cd "$SWEEP_DIR" && pwd)
tasks=$(( (SWEEP_POINTS + chunk - 1) / chunk ))
bk_find_bksim bksim 2
# shellcheck disable=SC2086 # the extra options are meant to split into words
array=$(sbatch --parsable --job-name=bksim-sweep --array=0-$((tasks - 1)) --ntasks=1 \
    --output="$dir/logs/slurm-%A_%a.out" --export=ALL,BKSIM="$bksim" $sbatch_options \
    "$scripts/slurm/sweep.sbatch" "$scripts" "$dir" "$chunk")
array=${array%%;*}
# shellcheck disable=SC2086
summary=$(sbatch --parsable --job-name=bksim-summary --dependency=afterany:"$array" --ntasks=1 \
    --output="$dir/logs/slurm-summary-%j.out" --export=ALL,BKSIM="$bksim" $sbatch_options \
    "$scripts/slurm/summary.sbatch" "$scripts" "$dir")
summary=${summary%%;*}
echo "sweep: $SWEEP_POINTS points in $dir: array job $array ($tasks tasks of $chunk), summary job $summary"
echo "$array $summary"
