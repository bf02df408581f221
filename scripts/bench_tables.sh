#!/usr/bin/env bash
# Markdown tables from the benchmark's TSVs (scripts/bench.sh writes them to bench/tables.md;
# README's "Choosing a solver" quotes them): CPU and error of every back-end at rtol 1e-8,
# the references' uncertainty, CPU per transition against chain length with the fitted
# slopes, and the phase drift over 1e4 cycles.
# usage: scripts/bench_tables.sh [DIR]   (DIR holds the TSVs; default bench)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
case ${1:-} in -h|--help) bk_help ;; esac
dir=${1:-bench}
results=$dir/results.tsv
for table in "$results" "$dir/scaling.tsv" "$dir/scaling_slopes.tsv" "$dir/long_run.tsv"; do
    bk_need_file "$table" "file (scripts/bench.sh writes it)" 2
done

# Cell: CPU in ms (error in m); "†" marks a run whose stick-slip events differ from the
# reference's; an error below the reference's uncertainty is shown as "< uncertainty".
awk -F'\t' '
    NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
    $c["method"] ~ /^reference_vs_/ { if ($c["error_x_m"] != "nan" && $c["error_x_m"] > floor[$1]) floor[$1] = $c["error_x_m"]; next }
    $c["method"] == "reference" { ref[$1] = $c["rtol"]; next }
    !($1 in seen_case) { seen_case[$1] = 1; cases[++nc] = $1 }
    !($c["method"] in seen_method) { seen_method[$c["method"]] = 1; methods[++nm] = $c["method"] }
    ($c["rtol"] == "1e-08" || ($c["method"] == "exact" && $c["rtol"] == "0")) {
        key = $1 SUBSEP $c["method"]
        if ($c["status"] != "ok") { cell[key] = $c["message"] ~ /needs Coulomb/ ? "n/a (not Coulomb)" : "failed"; next }
        err = $c["error_x_m"]
        shown = (err + 0 == 0) ? "0 m" : sprintf("%.1e m", err)
        if ($1 in floor && err + 0 < floor[$1]) shown = "< uncertainty"
        cell[key] = sprintf("%.3g ms (%s)%s", 1000 * $c["cpu_s"], shown, $c["events"] == "same" ? "" : " †")
    }
    END {
        printf "| case |"; for (m = 1; m <= nm; ++m) printf " %s |", methods[m]; print ""
        printf "| --- |"; for (m = 1; m <= nm; ++m) printf " --- |"; print ""
        for (k = 1; k <= nc; ++k) {
            printf "| %s |", cases[k]
            for (m = 1; m <= nm; ++m) { key = cases[k] SUBSEP methods[m]; printf " %s |", (key in cell) ? cell[key] : "n/a" }
            print ""
        }
        print ""
        print "| case | reference | its uncertainty (largest difference from the checks) |"
        print "| --- | --- | --- |"
        for (k = 1; k <= nc; ++k)
            printf "| %s | %s | %s |\n", cases[k], ref[cases[k]] == "0" ? "exact stepper" : "integrator at rtol " ref[cases[k]],
                   (cases[k] in floor) ? sprintf("%.1e m", floor[cases[k]]) : "0 (closed form)"
    }' "$results"
echo

# CPU per transition (us) and peak resident memory (MB) against N, per chain; the window
# (t_end) is the column's unless marked.
window=$(awk -F'\t' 'NR == 2 {print $4}' "$dir/scaling.tsv")
awk -F'\t' -v window="$window" '
    NR == 1 { next }
    { key = $1 SUBSEP $2 SUBSEP $3
      if ($5 != "ok") v[key] = "failed"
      else v[key] = sprintf("%.3g us, %.0f MB%s", 1e6 * $9, $10, $4 == window ? "" : sprintf(" (t_end %s s: %d transitions)", $4, $6))
      if (!(($1 SUBSEP $3) in seen)) { seen[$1 SUBSEP $3] = 1; m[$1, ++nm[$1]] = $3 }
      if (!(($1 SUBSEP $2) in seenn)) { seenn[$1 SUBSEP $2] = 1; n[$1, ++nn[$1]] = $2 } }
    END {
        split("random uniform", chains, " ")
        for (c = 1; c <= 2; ++c) {
            ch = chains[c]; if (!(ch in nm)) continue
            printf "| N (%s chain), t_end %s s |", ch, window; for (j = 1; j <= nm[ch]; ++j) printf " %s |", m[ch, j]; print ""
            printf "| --- |"; for (j = 1; j <= nm[ch]; ++j) printf " --- |"; print ""
            for (i = 1; i <= nn[ch]; ++i) {
                printf "| %s |", n[ch, i]
                for (j = 1; j <= nm[ch]; ++j) { key = ch SUBSEP n[ch, i] SUBSEP m[ch, j]; printf " %s |", (key in v) ? v[key] : "-" }
                print ""
            }
            print ""
        }
    }' "$dir/scaling.tsv"
echo "| chain | method | sizes (same window) | slope of CPU per transition vs N | CPU per transition, 1e5 / 1e3 blocks |"
echo "| --- | --- | --- | --- | --- |"
awk -F'\t' 'NR > 1 {printf "| %s | %s | %s | %s | %s |\n", $1, $2, $4, $5, $6}' "$dir/scaling_slopes.tsv"
# Peak memory against the length of a run (random chain): flat when it follows the chain.
if [ -s "$dir/scaling_run_length.tsv" ]; then
    echo
    echo "| N (random chain) | method | t_end | transitions | CPU per transition | peak resident memory |"
    echo "| --- | --- | --- | --- | --- | --- |"
    awk -F'\t' 'NR > 1 { printf "| %s | %s | %s s | %s | %s | %s |\n", $2, $3, $4, $6,
                         $5 == "ok" ? sprintf("%.3g us", 1e6 * $9) : "failed", $5 == "ok" ? sprintf("%.0f MB", $10) : "-" }' \
        "$dir/scaling_run_length.tsv"
fi
[ -e "$dir/scaling_machine.txt" ] && echo && echo "Measured on: $(paste -sd ';' "$dir/scaling_machine.txt" | sed 's/;/; /g')"
echo

echo "| method (rtol 1e-8) | CPU | events | phase error, first 100 cycles | last 100 cycles | growth (last / first) |"
echo "| --- | --- | --- | --- | --- | --- |"
awk -F'\t' 'NR > 1 {
    if ($1 == "exact") printf "| %s | %.3g s | (the reference) | - | - | - |\n", $1, $4
    else printf "| %s | %.3g s | %s | %s s | %s s | %s |\n", $1, $4, $6, $7, $8, $9 }' "$dir/long_run.tsv"
