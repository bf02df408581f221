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
scripts=$(cd "$(dirname "$0")/.." && pwd)
source "$scripts/sweep_lib.sh"

chunk=1
dir=
sbatch_options=
while [ $# -gt 0 ]; do
    case $1 in
        -c) [ $# -ge 2 ] || sweep_die "-c needs a number of points"; chunk=$2; shift 2 ;;
        -o) [ $# -ge 2 ] || sweep_die "-o needs a directory"; dir=$2; shift 2 ;;
        --sbatch) [ $# -ge 2 ] || sweep_die "--sbatch needs options"; sbatch_options=$2; shift 2 ;;
        -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2; exit 2 ;;
        -*) sweep_die "unknown option '$1'" ;;
        *) break ;;
    esac
done
[[ $chunk =~ ^[1-9][0-9]*$ ]] || sweep_die "-c needs a whole number of points >= 1, got '$chunk'"
[ $# -ge 1 ] || sweep_die "missing BASE.ini (see --help)"
command -v sbatch > /dev/null || sweep_die "no sbatch on PATH: is this a SLURM login node?"
base=$1
shift
[ -n "$dir" ] || dir=out/sweeps/$(basename "$base" .ini)
sweep_plan "$base" "$dir" "$@"
dir=$(cd "$dir" && pwd)
tasks=$(( (SWEEP_POINTS + chunk - 1) / chunk ))
bksim=$(sweep_bksim)
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
