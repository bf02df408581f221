#!/usr/bin/env bash
# The machine a benchmark ran on, for bench/machine.txt and bench/scaling_machine.txt.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
bk_find_bksim bksim
echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')"
echo "cores: $(nproc)"
echo "memory: $(awk '/^MemTotal/ {printf "%.1f GB", $2 / 1048576}' /proc/meminfo)"
echo "os: $(. /etc/os-release && echo "$PRETTY_NAME")"
echo "compiler: $(${CC:-cc} --version | head -1)"
echo "sundials: $(grep -m1 SUNDIALS_VERSION /usr/include/sundials/sundials_config.h | cut -d'"' -f2)"
echo "gsl: $(pkg-config --modversion gsl)"
echo "bksim: $("$bksim" --version)"
