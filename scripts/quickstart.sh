#!/usr/bin/env bash
# Set up a fresh Debian 12 machine and run one job:
#   scripts/quickstart.sh paper   install dependencies, build, run the paper's cases, plot
#   scripts/quickstart.sh test    install dependencies, build, run the test suite
# Installs with apt-get (as root, or through sudo); everything else runs as the caller.
# usage: scripts/quickstart.sh {paper|test}
set -euo pipefail
# Sourcing needs nothing built: this runs on a machine that has nothing yet.
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"

target=${1:-paper}
case "$target" in
    paper|test|bench|all) ;;
    -h|--help) bk_help ;;
    *) bk_usage "unknown job '$target'" ;;
esac

packages=(build-essential pkg-config libsundials-dev libgsl-dev libhdf5-dev libcmocka-dev
          libinih-dev liblapacke-dev hdf5-tools gnuplot-nox time parallel procps)
mapfile -t missing < <(bk_missing_packages "${packages[@]}")
if [ ${#missing[@]} -gt 0 ]; then
    echo "quickstart: installing ${missing[*]}"
    as_root=()
    [ "$(id -u)" -eq 0 ] || as_root=(sudo)
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

make -j"$(nproc)" bksim
make -j"$(nproc)" "$target"
