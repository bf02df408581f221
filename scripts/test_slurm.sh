#!/usr/bin/env bash
# make test-slurm: the sweep's SLURM path for real, on a single-node cluster this script
# starts itself on localhost (munged, slurmctld and slurmd with a generated config in a
# temporary directory, as root), then stops.  Submits an 8-point array through
# scripts/slurm/submit.sh, waits for it and its summary job, checks every output, the summary
# and a direct run of one point, resubmits (every point must be skipped), and stops the
# daemons.  A cluster that cannot be started is a failure, never a silent skip.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
BK_PROG="test-slurm: FAILED" # what every failure below starts with
cd "$BK_REPO"
[ "$(id -u)" -eq 0 ] || bk_fail 1 "needs root (it starts slurmd and munged): run as root, e.g. in CI"
mapfile -t packages < <(bk_missing_packages slurm-wlm munge parallel procps)
if [ ${#packages[@]} -gt 0 ]; then
    env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${packages[@]}" \
        > /dev/null || bk_fail 1 "cannot install ${packages[*]}"
fi
# The binary every run below uses, the sweep's jobs too (submit.sh hands them $BKSIM).
bk_find_bksim bksim
export BKSIM=$bksim

tmp=$(mktemp -d /tmp/bksim_slurm_XXXXXX)
export SLURM_CONF=$tmp/slurm.conf
cleanup() {
    scancel --quiet --user=root 2> /dev/null || true
    for pid in "$tmp/slurmd.pid" "$tmp/slurmctld.pid"; do
        [ -f "$pid" ] && kill "$(cat "$pid")" 2> /dev/null || true
    done
    munged --stop --socket="$tmp/munge/socket" > /dev/null 2>&1 || true
    sleep 1
    rm -rf "$tmp"
}
bk_at_exit cleanup
show_logs() { tail -n 20 "$tmp"/log/*.log "$tmp"/munge/log 2> /dev/null >&2 || true; }

mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/log"
chmod 700 "$tmp/munge"
dd if=/dev/urandom of="$tmp/munge/key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge/key"
munged --force --key-file="$tmp/munge/key" --socket="$tmp/munge/socket" \
    --pid-file="$tmp/munge/pid" --log-file="$tmp/munge/log" --seed-file="$tmp/munge/seed" ||
    { show_logs; bk_fail 1 "munged did not start"; }
node=$(hostname -s)
cat > "$SLURM_CONF" << CONF
ClusterName=bksimtest
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge/socket
CredType=cred/munge
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
ProctrackType=proctrack/pgid
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -f "$SLURM_CONF" || { show_logs; bk_fail 1 "slurmctld did not start"; }
slurmd -f "$SLURM_CONF" || { show_logs; bk_fail 1 "slurmd did not start"; }
for _ in $(seq 60); do
    state=$(sinfo -h -o %T 2> /dev/null || true)
    [[ $state == idle* ]] && break
    sleep 1
done
[[ $state == idle* ]] || { show_logs; bk_fail 1 "the node did not come up (state '$state')"; }
echo "test-slurm: single-node cluster up on $node ($(nproc) CPUs)"

wait_for() {
    for _ in $(seq 300); do
        [ -z "$(squeue -h -j "$1" 2> /dev/null)" ] && return 0
        sleep 1
    done
    squeue >&2
    show_logs
    bk_fail 1 "jobs $1 still queued or running after 300 s"
}

dir=$tmp/sweep
grid=(configs/paper/case_a_coulomb.ini friction.mu_d=0.1,0.2,0.3,0.4 driver.velocity=1e-3,2e-3
      run.t_end=2)
read -r array summary < <(scripts/slurm/submit.sh -c 1 -o "$dir" "${grid[@]}" | tail -n 1)
echo "test-slurm: array job $array, summary job $summary"
wait_for "$array,$summary"
outputs=("$dir"/*.h5)
finished=0
for f in "${outputs[@]}"; do
    [ "$(basename "$f")" = summary.h5 ] && continue
    "$bksim" info "$f" > /dev/null || bk_fail 1 "$f does not verify"
    finished=$((finished + 1))
done
[ "$finished" -eq 8 ] || { cat "$dir/sweep.log" >&2; bk_fail 1 "$finished of 8 outputs"; }
rows=$(grep -c '\.h5	' "$dir/summary.tsv" || true)
[ "$rows" -eq 8 ] || bk_fail 1 "summary.tsv has $rows rows, not 8"
[ -s "$dir/summary.h5" ] || bk_fail 1 "no summary.h5"
grep -q "8 of 8 points finished" "$dir/sweep.log" || bk_fail 1 "the summary job did not report"
# Any host, any node: one point reproduces a direct run, transition for transition.
point='friction.mu_d=0.3,driver.velocity=2e-3'
"$bksim" run configs/paper/case_a_coulomb.ini -q -o "$tmp/direct.h5" --set friction.mu_d=0.3 \
    --set driver.velocity=2e-3 --set run.t_end=2
cmp <("$bksim" export "$dir/$point.h5" --transitions) <("$bksim" export "$tmp/direct.h5" --transitions) ||
    bk_fail 1 "$point differs from a direct run"
cmp <("$bksim" export "$dir/$point.h5") <("$bksim" export "$tmp/direct.h5") ||
    bk_fail 1 "$point's time series differs from a direct run"
[ "$(h5dump -a point "$dir/$point.h5" | grep -c "$point")" -ge 1 ] || bk_fail 1 "no point attribute"

# Resubmitted: every point is skipped, nothing is rewritten.
before=$(stat -c '%i %Y' "$dir/$point.h5")
read -r array summary < <(scripts/slurm/submit.sh -o "$dir" "${grid[@]}" | tail -n 1)
wait_for "$array,$summary"
skipped=$(grep -c 'skipped: finished before' "$dir/sweep.log" || true)
[ "$skipped" -eq 8 ] || bk_fail 1 "$skipped of 8 points skipped on resubmission"
[ "$(stat -c '%i %Y' "$dir/$point.h5")" = "$before" ] || bk_fail 1 "a finished output was rewritten"
echo "test-slurm: 8-point array, summary job and resubmission passed"
