#!/usr/bin/env bash
# Output speed (part of make bench): what dense output costs.
#   1. The writer against a plain HDF5 program (bench/h5_plain.c) writing the same datasets
#      (types, chunks, Fletcher32 copied from bksim's file) from memory, one H5Dwrite each,
#      then fsync: case B (Coulomb, 50 s, rows every 0.1 ms, N = 1) and a resting chain of
#      N = 100 and 10,000 blocks (every field, about 40 MB each).  Two comparisons: the two
#      whole processes (the plain one without the time it spends reading its input), and
#      bksim's wall_time (its run loop, rows and writes included) against the plain
#      program's writing alone.  Runs alternate, REPEATS pairs; medians and the median of
#      the pairwise ratios.
#   2. Right-hand-side evaluations and wall time of case B (Coulomb and rate-and-state,
#      rtol 1e-8) with rows every 1e-3, 1e-4, 1e-5 s against transitions only, per back-end.
#   3. The exact stepper's cost per row on one slipping non-uniform cluster of p blocks:
#      the rows' path (bench/exact_rows.c) against the modal sum, p = 16 .. 2048.
# usage: scripts/bench_output.sh [--quick] OUT_DIR
# Writes OUT_DIR/output_writer.tsv, OUT_DIR/output_rhs.tsv, OUT_DIR/output_exact_rows.tsv
# and OUT_DIR/output.md.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"
quick=0
case ${1:-} in
    --quick) quick=1; shift ;;
    -h|--help) bk_help ;;
esac
[ $# -ge 1 ] || bk_usage "missing OUT_DIR"
out=$1
bk_find_bksim bksim 2
plain=build/bench/h5_plain
exact_rows=build/bench/exact_rows
for tool in "$plain" "$exact_rows"; do
    [ -x "$tool" ] || bk_fail 2 "$tool not built (make bench builds it)"
done
bk_temp_dir tmp
mkdir -p "$out"

repeats=7
t_end_b=50
sizes=(100 10000)
methods=(exact gsl_rk8pd gsl_rkf45 gsl_msbdf cvode_adams cvode_bdf ida arkode_dp45 arkode_bs23 arkode_erk arkode_dirk arkode_imex)
cluster_sizes=(16 32 64 128 256 512 1024 2048)
if [ $quick = 1 ]; then
    repeats=1; t_end_b=2; sizes=(100); methods=(exact gsl_rk8pd cvode_adams); cluster_sizes=(16 256)
fi

now() { date +%s.%N; }
median() { sort -g | awk '{ a[NR] = $1 } END { print NR % 2 ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
stat_of() { "$bksim" info "$1" | awk -v key="$2" '$1 == key { print $2; exit }'; }

# --- 1. the writer against the plain program -----------------------------------------------
writer_tsv="$out/output_writer.tsv"
printf 'scene\tn_blocks\trows\tbytes\tbksim_process_s\tbksim_wall_time_s\tplain_process_s\tplain_write_s\tratio_process\tratio_wall_time\trows_per_s_bksim\trows_per_s_plain\n' > "$writer_tsv"
writer_scene() { # name n_blocks bksim-args...
    local name=$1 n=$2
    shift 2
    local f
    for f in process wall plain_process plain r_process r_wall; do : > "$tmp/$f"; done
    for _ in $(seq "$repeats"); do
        local t0 t1 t2 t3 read_s write_s
        # Both programs replace an existing file, so both pay for freeing the old one.
        t0=$(now)
        "$bksim" run "$@" -o "$tmp/run.h5" --quiet
        t1=$(now)
        local process wall plain_process
        process=$(echo "$t1 - $t0" | bc -l)
        wall=$(stat_of "$tmp/run.h5" wall_time)
        t2=$(now)
        read -r _ rows _ bytes _ write_s _ read_s < <("$plain" "$tmp/run.h5" "$tmp/plain.h5")
        t3=$(now)
        # The plain program's whole process without its reading of the input: what a program
        # holding the data pays (start-up, HDF5's initialisation, the writing, exit).
        plain_process=$(echo "$t3 - $t2 - $read_s" | bc -l)
        echo "$process" >> "$tmp/process"; echo "$wall" >> "$tmp/wall"
        echo "$plain_process" >> "$tmp/plain_process"; echo "$write_s" >> "$tmp/plain"
        echo "$process / $plain_process" | bc -l >> "$tmp/r_process"
        echo "$wall / $write_s" | bc -l >> "$tmp/r_wall"
    done
    local mp mw mpp mpl rp rw
    mp=$(median < "$tmp/process"); mw=$(median < "$tmp/wall")
    mpp=$(median < "$tmp/plain_process"); mpl=$(median < "$tmp/plain")
    rp=$(median < "$tmp/r_process"); rw=$(median < "$tmp/r_wall")
    printf '%s\t%s\t%s\t%s\t%.4f\t%.4f\t%.4f\t%.4f\t%.2f\t%.2f\t%.0f\t%.0f\n' "$name" "$n" "$rows" "$bytes" \
        "$mp" "$mw" "$mpp" "$mpl" "$rp" "$rw" "$(echo "$rows / $mp" | bc -l)" "$(echo "$rows / $mpp" | bc -l)" >> "$writer_tsv"
}
writer_scene "case B, ${t_end_b} s, 0.1 ms rows" 1 configs/paper/case_b_coulomb.ini --set run.t_end=$t_end_b
for n in "${sizes[@]}"; do
    # About 40 MB of every field: a chain at rest (no slip), so the rows are all the work.
    interval=$(echo "2 * 33 * $n / 40000000" | bc -l)
    writer_scene "resting chain, every field" "$n" configs/chains/bk1000_coulomb.ini \
        --set model.n_blocks="$n" --set block.x_init_random=0 --set driver.velocity=1e-9 \
        --set output.fields=all --set output.interval="$interval" --set run.t_end=2
done

# --- 2. evaluations with and without rows, per back-end ---------------------------------------
rhs_tsv="$out/output_rhs.tsv"
printf 'case\tmethod\tinterval_s\trows\trhs_evals\trhs_ratio\twall_time_s\n' > "$rhs_tsv"
for case in coulomb rs; do
    config=configs/paper/case_b_$case.ini
    for method in "${methods[@]}"; do
        [ "$case" = rs ] && [ "$method" = exact ] && continue
        base=""
        for interval in 0 1e-3 1e-4 1e-5; do
            args=("$config" --set solver.method="$method" --set solver.rtol=1e-8 --set output.interval=$interval)
            [ $quick = 1 ] && args+=(--set run.t_end=1)
            "$bksim" run "${args[@]}" -o "$tmp/rhs.h5" --quiet
            rhs=$(stat_of "$tmp/rhs.h5" rhs_evals)
            [ -n "$base" ] || base=$rhs
            ratio=$([ "$base" -gt 0 ] && echo "$rhs / $base" | bc -l || echo 1)
            printf '%s\t%s\t%s\t%s\t%s\t%.3f\t%s\n' "$case" "$method" "$interval" \
                "$(stat_of "$tmp/rhs.h5" rows)" "$rhs" "$ratio" "$(stat_of "$tmp/rhs.h5" wall_time)" >> "$rhs_tsv"
            rm -f "$tmp/rhs.h5"
        done
    done
done

# --- 3. the exact stepper's rows on one long slipping cluster -------------------------------
exact_tsv="$out/output_exact_rows.tsv"
quick_flag=()
[ $quick = 1 ] && quick_flag=(--quick)
"$exact_rows" "${quick_flag[@]}" "${cluster_sizes[@]}" > "$exact_tsv"

# --- tables ---------------------------------------------------------------------------------
{
    echo "Writer against a plain HDF5 program writing the same datasets (median of $repeats alternating runs):"
    echo
    echo "| scene | N | rows | MB | bksim process (s) | bksim wall_time (s) | plain process (s) | plain writing (s) | process / process | wall_time / writing | rows/s bksim | rows/s plain |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    awk -F'\t' 'NR > 1 { printf "| %s | %s | %s | %.1f | %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4 / 1e6, $5, $6, $7, $8, $9, $10, $11, $12 }' "$writer_tsv"
    echo
    echo "Right-hand-side evaluations with rows every 1e-3 / 1e-4 / 1e-5 s, as multiples of a run with transitions only (case B, rtol 1e-8):"
    echo
    echo "| back-end | Coulomb 1e-3 | 1e-4 | 1e-5 | rate-and-state 1e-3 | 1e-4 | 1e-5 | RS evaluations without rows |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    awk -F'\t' 'NR > 1 { key = $2; order[key] = order[key] ? order[key] : ++n; names[n] = key;
                         if ($3 == 0) { if ($1 == "rs") base[key] = $5; next }
                         r[key, $1, $3] = $6 }
        END { for (i = 1; i <= n; ++i) { k = names[i];
                  printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", k,
                      (k SUBSEP "coulomb" SUBSEP "1e-3") in r ? r[k, "coulomb", "1e-3"] : "-",
                      (k SUBSEP "coulomb" SUBSEP "1e-4") in r ? r[k, "coulomb", "1e-4"] : "-",
                      (k SUBSEP "coulomb" SUBSEP "1e-5") in r ? r[k, "coulomb", "1e-5"] : "-",
                      (k SUBSEP "rs" SUBSEP "1e-3") in r ? r[k, "rs", "1e-3"] : "-",
                      (k SUBSEP "rs" SUBSEP "1e-4") in r ? r[k, "rs", "1e-4"] : "-",
                      (k SUBSEP "rs" SUBSEP "1e-5") in r ? r[k, "rs", "1e-5"] : "-",
                      k in base ? base[k] : "-" } }' "$rhs_tsv"
    echo
    echo "The exact stepper's cost per output row on one slipping non-uniform cluster of p blocks: the rows' path (Taylor series about the last step end from 64 blocks on) against the modal sum, and their largest difference (eps of the largest position or velocity):"
    echo
    echo "| blocks in the cluster | rows' path (ns/row) | modal sum (ns/row) | modal / rows' path | difference (eps) |"
    echo "| ---: | ---: | ---: | ---: | ---: |"
    awk -F'\t' 'NR > 1 { printf "| %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5 }' "$exact_tsv"
} > "$out/output.md"
cat "$out/output.md"
