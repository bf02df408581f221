#!/usr/bin/env bash
# The main job: every paper config, its HDF5 file and its figures under out/paper/, and a
# text summary per case (out/paper/summary.txt).
set -euo pipefail
cd "$(dirname "$0")/.."
bksim=${BKSIM:-./bksim}
out=out/paper
mkdir -p "$out"

for config in configs/paper/*.ini; do
    name=$(basename "$config" .ini)
    "$bksim" run "$config" -o "$out/$name.h5" --quiet
    echo "ran $config -> $out/$name.h5"
done

for c in a b c; do
    C=$(echo "$c" | tr a-z A-Z)
    scripts/plot_kinematics.sh "$out/case_${c}_kinematics.png" \
        "Case $C: position and velocity (Coulomb, linear spring)" \
        "$out/case_${c}_coulomb.h5:Coulomb:black"
    scripts/plot_cof.sh "$out/case_${c}_cof.png" "Case $C: apparent COF (Coulomb, linear spring)" \
        "$out/case_${c}_coulomb.h5:Coulomb:black"
done
scripts/plot_kinematics.sh "$out/case_a_tension_only_kinematics.png" \
    "Case A: linear vs tension-only driver spring (Coulomb)" \
    "$out/case_a_coulomb.h5:linear spring:black" \
    "$out/case_a_coulomb_tension_only.h5:tension-only spring:#1f77b4"

scripts/summary.sh "$out"/*.h5 | tee "$out/summary.txt"
echo "figures: $(ls "$out"/*.png | tr '\n' ' ')"
