#!/usr/bin/env bash
# Set up a fresh Debian 12 machine and run one job:
#   scripts/quickstart.sh paper   install dependencies, build, run the paper's cases, plot
#   scripts/quickstart.sh test    install dependencies, build, run the test suite
# Installs with apt-get (as root, or through sudo); everything else runs as the caller.
set -euo pipefail
cd "$(dirname "$0")/.."

target=${1:-paper}
case "$target" in
    paper|test|bench|all) ;;
    *) echo "usage: $0 {paper|test}" >&2; exit 2 ;;
esac

packages=(build-essential pkg-config libsundials-dev libgsl-dev libhdf5-dev libcmocka-dev
          libinih-dev liblapacke-dev hdf5-tools gnuplot-nox time parallel procps)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "quickstart: installing ${missing[*]}"
    as_root=()
    [ "$(id -u)" -eq 0 ] || as_root=(sudo)
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

make -j"$(nproc)" bksim
make "$target"
