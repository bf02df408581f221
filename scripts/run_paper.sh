#!/usr/bin/env bash
# The main job: every paper config, its HDF5 file and the paper's Figures 2 and 4-9 under
# out/paper/, and a one-line summary per case (out/paper/summary.txt).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
bk_find_bksim bksim
export BKSIM=$bksim # the figures' scripts below run the same binary
cd "$BK_REPO"
out=out/paper
mkdir -p "$out"
rm -f "$out"/*.png "$out"/*.h5 "$out"/*.part

for config in configs/paper/*.ini; do
    name=$(basename "$config" .ini)
    "$bksim" run "$config" -o "$out/$name.h5" --quiet
    echo "ran $config -> $out/$name.h5"
done

scripts/plot_fig2.sh "$out/fig2_velocity_step.png" "$out/fig2_velocity_step.h5"
fig=4
for c in a b c; do
    C=$(echo "$c" | tr a-z A-Z)
    mu=$(awk -F'[=;]' '$1 ~ /^mu_d/ {gsub(/ /, "", $2); print $2}' "configs/paper/case_${c}_coulomb.ini")
    scripts/plot_kinematics.sh "$out/fig${fig}_case_${c}_kinematics.png" \
        "Figure $fig: case $C (μ_d = $mu), position and velocity of block and driver" \
        "$out/case_${c}_coulomb.h5:Coulomb:black" "$out/case_${c}_rs.h5:rate-and-state:red"
    scripts/plot_cof.sh "$out/fig$((fig + 1))_case_${c}_cof.png" \
        "Figure $((fig + 1)): case $C (μ_d = $mu), apparent COF (friction / normal force)" \
        "$out/case_${c}_coulomb.h5:Coulomb:black" "$out/case_${c}_rs.h5:rate-and-state:red"
    fig=$((fig + 2))
done
# Case C's Coulomb cycles (0.2 ms sticks, COF between 0.5999 and 0.6) need a closer look.
XRANGE=0.6:0.8 scripts/plot_kinematics.sh "$out/fig8_case_c_kinematics_zoom.png" \
    "Figure 8, zoomed: case C after the first slip" \
    "$out/case_c_coulomb.h5:Coulomb:black" "$out/case_c_rs.h5:rate-and-state:red"
XRANGE=0.6:0.8 scripts/plot_cof.sh "$out/fig9_case_c_cof_zoom.png" \
    "Figure 9, zoomed: case C apparent COF after the first slip" \
    "$out/case_c_coulomb.h5:Coulomb:black" "$out/case_c_rs.h5:rate-and-state:red"
# What the tension-only spring (the paper's text) changes in case A.
scripts/plot_kinematics.sh "$out/case_a_tension_only_kinematics.png" \
    "Case A with a tension-only driver spring (the twins of Figure 4)" \
    "$out/case_a_coulomb_tension_only.h5:Coulomb:black" "$out/case_a_rs_tension_only.h5:rate-and-state:red"
scripts/plot_cof.sh "$out/case_a_tension_only_cof.png" \
    "Case A with a tension-only driver spring (the twins of Figure 5)" \
    "$out/case_a_coulomb_tension_only.h5:Coulomb:black" "$out/case_a_rs_tension_only.h5:rate-and-state:red"

scripts/summary.sh "$out"/case_*.h5 | tee "$out/summary.txt"
echo "figures:"
ls "$out"/*.png
