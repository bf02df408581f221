#!/usr/bin/env bash
# Converged statistics per tolerance (issue 33 part 7): for each integrator back-end and rtol,
# is the rupture-size distribution the same as a converged reference's?  Beside the CPU time
# of each run, `bksim compare` of its catalog against the reference: the two-sample KS
# distance and p-value of log10 potency (rounded to 1e-4), the p-values of magnitude and
# n_blocks, and of log10 potency as stored (ks_p_raw: one-block ruptures share one potency up
# to the integrator's last digits, which alone tells tolerances apart), and the verdict at the
# 1 % level.  The chain is chaotic: runs at different tolerances part ways early and their
# catalogs differ event by event; only distributions compare, and two seeds of the reference
# show what no difference looks like (the KS p-value of two catalogs of one law is uniform on
# [0, 1]: one comparison in 100 is told apart at 1 % by chance).
# Scenes (each run one process, timed by /usr/bin/time: CPU = user + sys):
#   chain    configs/chains/carlson_langer_100.ini (the Carlson-Langer ring of 100 blocks), to
#            t = 10^4 (about 24,000 ruptures), ruptures starting after t = 500 compared (the
#            spin-up from the near-uniform start, and the start every run shares: runs at
#            different tolerances part ways at t = 170 to 220, left out); back-ends
#            cvode_adams at rtol 1e-4, 1e-6, 1e-8, 1e-10, cvode_bdf, arkode_dp45 (explicit),
#            arkode_dirk (implicit), ida and gsl_rk8pd at 1e-4, 1e-6, 1e-8
#   lattice  the same parameters on a 10 x 10 torus (--set model.rows=10 --set model.cols=10:
#            four neighbours each), to t = 2000 (about 5,000 ruptures), after t = 200 (runs
#            part ways at t = 90 to 100);
#            cvode_adams, cvode_bdf, arkode_dp45, gsl_rk8pd at 1e-4, 1e-6, 1e-8.  (configs/lattices/
#            lattice_64x64.ini is Coulomb: auto integrates its 4096 blocks with gsl_rk8pd, 18 s
#            to its t_end, but Coulomb slips are linear between transitions and its sizes
#            barely move with the tolerance (at the default rtol against the exact stepper,
#            its natural reference, which costs 390 s: gsl_rk8pd p = 0.99, cvode_adams 0.43).)
# Each scene also runs method = auto at the default rtol (what a user gets), the reference
# (gsl_rk8pd at rtol 1e-10: eighth order, as cheap there as at 1e-8), reference_2 (gsl_rk8pd
# at rtol 1e-11: it agreeing with the reference shows the reference converged) and seed_2
# (the reference with model.seed = 2: another start, the same law).  Not rtol 1e-12: its
# default atol_x (rtol 1e-3 F0/k = 1e-15) is below the roundoff of positions that the driver
# carries to v t = 100, and the ring's cost grows faster than t (gsl_rk8pd: 3.5 s of CPU to
# t = 1000, 10 s to 2000, 32 s to 4000; rtol 1e-10: 4.3 s to 2000, 8.9 s to 4000).  Other
# back-ends (arkode_bs23, arkode_erk, arkode_imex, gsl_rkf45, gsl_msbdf) and the lattice's
# implicit ones beyond cvode_bdf are left out to keep the whole at about 25 minutes of CPU on
# the machine in bench/stats_convergence_machine.txt; --method measures others.
# usage: scripts/bench_stats_convergence.sh [--quick | --plot-only] [--scene chain|lattice]...
#                                           [--method NAME:RTOL[,RTOL...]]... [--limit SECONDS]
#                                           [--format png|pdf|svg] [OUTDIR]
#   --quick            a smoke run: the chain to t = 600 (after t = 100), the lattice to
#                      t = 150 (after t = 50), cvode_adams and gsl_rk8pd at 1e-6; OUTDIR
#                      defaults to a new temporary directory
#   --plot-only        redraw the table and plot from OUTDIR/stats_convergence.tsv, run nothing
#   --scene S          only scene S (repeatable; default both)
#   --method M:R,...   measure back-end M at these rtols instead of the scene's list
#                      (repeatable; every scene)
#   --limit SECONDS    wall time allowed to one run before it is stopped (default 900)
#   --format F         the plot's format (default png)
# Writes OUTDIR (default bench/) stats_convergence.tsv (one row per run, under '#' lines that
# say how it was measured), stats_convergence.md (a Markdown table per scene and the loosest
# rtol at which every back-end agrees), stats_convergence_machine.txt and
# stats_convergence.png (KS p-value against CPU per back-end, log-log, a panel per scene).
# A relative OUTDIR is taken from where the script is started.  Exits 1 when a run failed.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
cd "$BK_REPO"

config=configs/chains/carlson_langer_100.ini
quick=0 plot_only=0 format=png limit=900 out=""
scenes=() methods=()
while [ $# -gt 0 ]; do
    case $1 in
        --quick) quick=1; shift ;;
        --plot-only) plot_only=1; shift ;;
        --scene) bk_need_value $# "$1" "chain or lattice"
                 [[ $2 == chain || $2 == lattice ]] || bk_usage "--scene needs chain or lattice, got '$2'"
                 scenes+=("$2"); shift 2 ;;
        --method) bk_need_value $# "$1" "NAME:RTOL[,RTOL...]"
                  [[ $2 =~ ^[a-z0-9_]+:[0-9.eE+-]+(,[0-9.eE+-]+)*$ ]] ||
                      bk_usage "--method needs NAME:RTOL[,RTOL...], got '$2'"
                  methods+=("$2"); shift 2 ;;
        --limit) bk_need_value $# "$1" "a wall time in seconds"; bk_check_whole --limit "$2" "a wall time in seconds" 1
                 limit=$2; shift 2 ;;
        --format) bk_need_value $# "$1" "png, pdf or svg"; format=$2; shift 2 ;;
        -h|--help) bk_help ;;
        -*) bk_usage "unknown option '$1'" ;;
        *) [ -z "$out" ] || bk_usage "unexpected argument '$1'"
           out=$1; shift ;;
    esac
done
[ $((quick + plot_only)) -le 1 ] || bk_usage "--quick and --plot-only exclude each other"
bk_terminal terminal "$format"
terminal+=" noenhanced"
if [ -z "$out" ]; then
    if [ $quick = 1 ]; then out=$(mktemp -d) || bk_fail 1 "cannot create a temporary directory"
    else out=$BK_REPO/bench; fi
fi
[[ $out == /* ]] || out=$BK_START_DIR/$out
[ ${#scenes[@]} -gt 0 ] || scenes=(chain lattice)

# A scene's settings: its label, t_end, the window's start, the --set arguments that make it
# from $config, and its back-ends with their rtols.
scene_setup() {
    scene_sets=(--set catalog.rupture_rate=false --set output.checkpoint_interval=0)
    case $1 in
        chain)
            if [ $quick = 1 ]; then t_end=600 t_from=100; else t_end=10000 t_from=500; fi
            scene_methods=("cvode_adams:1e-4,1e-6,1e-8,1e-10" "cvode_bdf:1e-4,1e-6,1e-8"
                           "arkode_dp45:1e-4,1e-6,1e-8" "arkode_dirk:1e-4,1e-6,1e-8" "ida:1e-4,1e-6,1e-8"
                           "gsl_rk8pd:1e-4,1e-6,1e-8") ;;
        lattice)
            if [ $quick = 1 ]; then t_end=150 t_from=50; else t_end=2000 t_from=200; fi
            scene_sets+=(--set model.rows=10 --set model.cols=10)
            scene_methods=("cvode_adams:1e-4,1e-6,1e-8" "cvode_bdf:1e-4,1e-6,1e-8" "arkode_dp45:1e-4,1e-6,1e-8"
                           "gsl_rk8pd:1e-4,1e-6,1e-8") ;;
    esac
    ref_rtol=1e-10 ref2_rtol=1e-11
    [ $quick = 0 ] || scene_methods=("cvode_adams:1e-6" "gsl_rk8pd:1e-6")
    [ ${#methods[@]} -eq 0 ] || scene_methods=("${methods[@]}")
}

bk_need_command gnuplot gnuplot-nox # checked before the runs, not after them
if [ $plot_only = 1 ]; then [ -d "$out" ] || bk_fail 1 "$out: no such directory"
else mkdir -p "$out" || bk_fail 1 "$out: cannot create the output directory"; fi
tsv=$out/stats_convergence.tsv md=$out/stats_convergence.md
scratch="" # set by bk_temp_dir
bk_temp_dir scratch
columns=(scene method rtol cpu_s ruptures ks_d ks_p ks_p_magnitude verdict ks_p_n_blocks ks_p_raw rate_ratio
         status)
failures=0

if [ $plot_only = 0 ]; then
    bk_need_command /usr/bin/time time
    bk_need_command timeout coreutils
    bksim="" # set by bk_find_bksim
    bk_find_bksim bksim
    bk_need_file "$config" config
    BKSIM=$bksim scripts/machine_info.sh > "$out/stats_convergence_machine.txt" ||
        bk_fail 1 "scripts/machine_info.sh failed"
    machine=$(awk -F': ' '$1 == "cpu" {cpu = $2} $1 == "cores" {cores = $2} $1 == "bksim" {v = $2}
                          END {printf "%s, %s cores, %s", cpu, cores, v}' "$out/stats_convergence_machine.txt")
    {
        echo "# Converged statistics per tolerance: each run's rupture catalog against the scene's reference,"
        echo "# \`bksim compare REFERENCE RUN --from T\` (two-sample KS of log10 potency rounded to 1e-4; of"
        echo "# magnitude likewise; of n_blocks; ks_p_raw: log10 potency as stored).  Made by"
        echo "# scripts/bench_stats_convergence.sh$([ $quick = 1 ] && echo ' --quick')."
        for scene in "${scenes[@]}"; do
            scene_setup "$scene"
            echo "# scene $scene: $config ${scene_sets[*]} --set run.t_end=$t_end; ruptures starting at t >= $t_from;"
            echo "#   reference: gsl_rk8pd rtol $ref_rtol; reference_2: gsl_rk8pd rtol $ref2_rtol; seed_2: the reference"
            echo "#   with model.seed=2; auto: method auto at the default rtol (the method auto chose in brackets)"
        done
        echo "# cpu_s: user + sys of the run (/usr/bin/time); ruptures: the complete ones compared; verdict at"
        echo "# the 1 % level (ks_p < 0.01: told apart); rate_ratio: the run's rupture rate over the reference's."
        echo "# machine: $machine"
        (IFS=$'\t'; echo "${columns[*]}")
    } > "$tsv"

    # run PREFIX SETTINGS...: bksim run of the scene into PREFIX.h5; PREFIX.time holds "user
    # sys", PREFIX.log the run's report.  Returns the run's status (124: stopped at the limit).
    run() {
        local prefix=$1 status=0
        shift
        /usr/bin/time -f '%U %S' -o "$prefix.time" nice -n 10 timeout "$limit" "$bksim" run "$config" \
            "${scene_sets[@]}" --set run.t_end="$t_end" "$@" -o "$prefix.h5" --force --quiet \
            > "$prefix.log" 2>&1 || status=$?
        return $status
    }
    # row FIELD...: one row of the TSV.
    row() {
        (IFS=$'\t'; echo "$*") >> "$tsv"
    }
    # A field of `bksim compare --json`: json_test TEST KEY (ks_distance, p_value) from $scratch/cmp.json.
    json_test() {
        sed -n "s/.*\"$1\": {\"ks_distance\": \([^,]*\), \"p_value\": \([^,]*\), .*/\1 \2/p" "$2" |
            awk -v k="$3" '{ print (k == "d" ? $1 : $2) }'
    }
    json_value() {
        sed -n "s/.*\"$1\": \([^,}]*\).*/\1/p" "$2" | head -n 1
    }
    # measure SCENE LABEL RTOL SETTINGS...: run, compare with the reference, one row.
    measure() {
        local scene=$1 label=$2 rtol=$3 prefix=$scratch/run status=0
        shift 3
        run "$prefix" "$@" || status=$?
        if [ $status != 0 ]; then
            if [ $status = 124 ]; then status=timeout; else status=failed; fi
            failures=1
            bk_warn "$scene, $label, rtol $rtol: $status: $(tail -n 2 "$prefix.log" | tr '\n' ' ')"
            row "$scene" "$label" "$rtol" - - - - - - - - - "$status"
            return 0
        fi
        local cpu
        cpu=$(awk '{ printf "%.2f", $1 + $2 }' "$prefix.time")
        if [ "$label" = auto ]; then
            label="auto ($(awk '$1 == "method" && $3 == "(auto)" { print $2; exit }' \
                          < <("$bksim" info "$prefix.h5" 2> /dev/null)))"
        fi
        if [ "$label" = reference ]; then
            mv "$prefix.h5" "$scratch/reference.h5"
            local n
            n=$("$bksim" compare "$scratch/reference.h5" "$scratch/reference.h5" --from "$t_from" --json |
                sed -n 's/.*"n_events": \([0-9]*\), .*/\1/p' | head -n 1)
            row "$scene" "$label" "$rtol" "$cpu" "$n" 0 1 1 reference 1 1 1 ok
            echo "$scene, reference (gsl_rk8pd, rtol $rtol): $n ruptures after t = $t_from, $cpu s CPU"
            return 0
        fi
        "$bksim" compare "$scratch/reference.h5" "$prefix.h5" --from "$t_from" --json > "$scratch/cmp.json" ||
            bk_fail 1 "bksim compare failed on the $scene run $label at rtol $rtol"
        "$bksim" compare "$scratch/reference.h5" "$prefix.h5" --from "$t_from" --round 0 --json \
            > "$scratch/raw.json" || bk_fail 1 "bksim compare --round 0 failed"
        local n d p pm pn praw ratio verdict
        n=$(sed -n 's/.*"b": {[^}]*"n_events": \([0-9]*\), .*/\1/p' "$scratch/cmp.json")
        d=$(json_test log10_potency "$scratch/cmp.json" d)
        p=$(json_test log10_potency "$scratch/cmp.json" p)
        pm=$(json_test magnitude "$scratch/cmp.json" p)
        pn=$(json_test n_blocks "$scratch/cmp.json" p)
        praw=$(json_test log10_potency "$scratch/raw.json" p)
        ratio=$(json_value rate_ratio "$scratch/cmp.json")
        verdict=agrees
        [ "$(json_value told_apart "$scratch/cmp.json")" = false ] || verdict="told apart"
        row "$scene" "$label" "$rtol" "$cpu" "$n" "$(printf '%.4f' "$d")" "$(printf '%.3g' "$p")" \
            "$(printf '%.3g' "$pm")" "$verdict" "$(printf '%.3g' "$pn")" "$(printf '%.3g' "$praw")" \
            "$(printf '%.4f' "$ratio")" ok
        printf '%s, %s, rtol %s: %s ruptures, %s s CPU, KS D = %.4f, p = %.3g (as stored %.3g): %s\n' \
            "$scene" "$label" "$rtol" "$n" "$cpu" "$d" "$p" "$praw" "$verdict"
    }

    for scene in "${scenes[@]}"; do
        scene_setup "$scene"
        measure "$scene" reference "$ref_rtol" --set solver.method=gsl_rk8pd --set solver.rtol="$ref_rtol"
        measure "$scene" reference_2 "$ref2_rtol" --set solver.method=gsl_rk8pd --set solver.rtol="$ref2_rtol"
        measure "$scene" seed_2 "$ref_rtol" --set solver.method=gsl_rk8pd --set solver.rtol="$ref_rtol" \
            --set model.seed=2
        measure "$scene" auto default --set solver.method=auto
        for spec in "${scene_methods[@]}"; do
            IFS=, read -r -a rtols <<< "${spec#*:}"
            for rtol in "${rtols[@]}"; do
                measure "$scene" "${spec%%:*}" "$rtol" --set solver.method="${spec%%:*}" --set solver.rtol="$rtol"
            done
        done
        rm -f "$scratch"/*.h5
    done
fi

# --- the Markdown table and the plot ------------------------------------------------------------
[ -s "$tsv" ] || bk_fail 1 "$tsv: no such table (run without --plot-only first)"
grep -q "^scene	method	rtol	cpu_s	" "$tsv" ||
    bk_fail 1 "$tsv: not a table of scripts/bench_stats_convergence.sh (no header scene, method, rtol, cpu_s)"
awk -F'\t' '
    /^# scene / { sub(/^# /, ""); about[++n_about] = $0; next }
    /^#   / { sub(/^#   /, ""); about[n_about] = about[n_about] " " $0; next }
    /^# machine: / { sub(/^# machine: /, ""); machine = $0; next }
    /^#/ || $1 == "scene" { next }
    {
        if (!($1 in seen)) { seen[$1] = 1; order[++n] = $1 }
        rows[$1] = rows[$1] sprintf("| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", $2, $3, $4, $5, $6, $7, $8,
                                    $10, $9 == "told apart" ? "**told apart**" : $9)
        # The back-ends: rtol per rtol, told apart or not (references, seed and auto aside).
        if ($13 == "ok" && $2 != "reference" && $2 != "reference_2" && $2 != "seed_2" && $2 !~ /^auto/) {
            key = $1 SUBSEP $3
            if (!(key in tested)) { tested[key] = 0; bad[key] = ""; rt[$1] = rt[$1] " " $3 }
            tested[key]++
            if ($9 == "told apart") bad[key] = bad[key] (bad[key] == "" ? "" : ", ") $2
        }
        if ($2 == "seed_2") seed_p[$1] = $7
        if ($2 == "reference_2") ref2_p[$1] = $7
        if ($2 ~ /^auto/) { auto_label[$1] = $2; auto_p[$1] = $7; auto_v[$1] = $9 }
    }
    END {
        print "# Converged statistics per tolerance"
        print ""
        print "Made by `scripts/bench_stats_convergence.sh` (its header, `--help`, says how).  Each run'"'"'s"
        print "rupture catalog against the scene'"'"'s converged reference by `bksim compare REFERENCE RUN --from T`:"
        print "two-sample Kolmogorov-Smirnov tests of log10 potency (rounded to 1e-4), magnitude and n_blocks;"
        print "\"told apart\" when the log10-potency p-value is below 0.01.  CPU is user + sys of the run."
        print "Machine: " machine "."
        print ""
        print "The KS test takes the ruptures as independent draws; a chain'"'"'s are not (large ruptures come"
        print "in cycles), so its p-values run small: one p just below 0.01 among the rest is to be repeated"
        print "with other seeds (`--set model.seed=N` on both the run and the reference) before it is believed."
        print "`ks_p_raw` in the TSV (log10 potency as stored, unrounded) is 0 for nearly every pair: the"
        print "one-block ruptures'"'"' shared potency differs in its last digits from run to run."
        for (k = 1; k <= n; ++k) {
            s = order[k]
            print ""
            print "## " s
            print ""
            for (a = 1; a <= n_about; ++a) if (index(about[a], "scene " s ":") == 1) print about[a] "."
            print ""
            print "| method | rtol | CPU [s] | ruptures | KS D | p (log10 potency) | p (magnitude) | p (n_blocks) | verdict |"
            print "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
            printf "%s", rows[s]
            print ""
            loosest = ""
            m = split(rt[s], list, " ")
            # Loose to tight: rtols sorted by value, descending.
            for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (list[j] + 0 > list[i] + 0) { t = list[i]; list[i] = list[j]; list[j] = t }
            line = ""
            for (i = 1; i <= m; ++i) {
                key = s SUBSEP list[i]
                line = line sprintf("%s%s: %s", i > 1 ? "; " : "", list[i],
                                    bad[key] == "" ? "none of " tested[key] " told apart" : "told apart: " bad[key])
                if (bad[key] == "" && loosest == "") loosest = list[i]
            }
            print "Per rtol: " line "."
            # The loosest rtol from which on every tighter one agrees as well.
            steady = ""
            for (i = m; i >= 1; --i) { if (bad[s SUBSEP list[i]] != "") break; steady = list[i] }
            print "Loosest rtol at which every back-end agrees with the reference: " (loosest == "" ? "none" : loosest) \
                  "; at which it and every tighter rtol agree: " (steady == "" ? "none" : steady) "."
            print "Baselines: seed_2 (another start, the same law) p = " seed_p[s] "; reference_2 (a tighter rtol) p = " \
                  ref2_p[s] ".  method = auto at the default rtol, " auto_label[s] ": p = " auto_p[s] ", " auto_v[s] "."
        }
    }' "$tsv" > "$md"

plot_out=$out/stats_convergence.$format
col() { awk -F'\t' -v name="$1" '!/^#/ { for (i = 1; i <= NF; ++i) if ($i == name) print i; exit }' "$tsv"; }
c_scene=$(col scene) c_method=$(col method) c_rtol=$(col rtol) c_cpu=$(col cpu_s) c_p=$(col ks_p) c_status=$(col status)
mapfile -t plotted_scenes < <(awk -F'\t' -v c="$c_scene" '!/^#/ && $c != "scene" && !seen[$c]++ { print $c }' "$tsv")
# One colour per back-end in every panel, in the order of their first rows.
mapfile -t all_backends < <(awk -F'\t' -v cm="$c_method" -v cs="$c_status" \
    '!/^#/ && $cm != "method" && $cs == "ok" && $cm != "reference" && !seen[$cm]++ { print $cm }' "$tsv")
colors=('#984ea3' '#377eb8' '#4daf4a' '#e41a1c' '#ff7f00' '#a65628' '#f781bf' '#17becf' '#000000' '#999999')
floor=1e-6
panels=""
for scene in "${plotted_scenes[@]}"; do
    plots="" k=0
    for b in "${all_backends[@]}"; do
        f=$scratch/plot_${scene}_$k.dat
        # p floored (the log axis has no 0, and the tail below it says nothing more).
        awk -F'\t' -v c="$c_scene" -v s="$scene" -v cm="$c_method" -v m="$b" -v cr="$c_rtol" -v cc="$c_cpu" \
            -v cp="$c_p" -v cs="$c_status" -v floor="$floor" \
            '!/^#/ && $c == s && $cm == m && $cs == "ok" { p = $cp + 0; if (p < floor) p = floor; print $cc, p, $cr }' \
            "$tsv" > "$f"
        color=${colors[k % 10]} k=$((k + 1))
        [ -s "$f" ] || continue
        case $b in
            reference_2|seed_2|auto*)
                plots+="${plots:+, }'$(bk_gp_quote "$f")' using 1:2 with points pt $((k % 4 + 4)) ps 2.2 lw 2 lc rgb '$color' title '$(bk_gp_quote "$b")'" ;;
            *)
                plots+="${plots:+, }'$(bk_gp_quote "$f")' using 1:2 with linespoints lw 1.5 pt 7 ps 1.1 lc rgb '$color' title '$(bk_gp_quote "$b")'"
                plots+=", '' using 1:2:3 with labels offset 0.5,0.5 left font ',8' tc rgb '$color' notitle" ;;
        esac
    done
    [ -n "$plots" ] || continue
    panels+="set title '$(bk_gp_quote "$scene")'
plot $plots
"
done
[ -n "$panels" ] || bk_fail 1 "$tsv: no row with status ok to plot"
gnuplot <<GP || bk_fail 1 "gnuplot failed drawing $plot_out"
set terminal $terminal
set output '$(bk_gp_quote "$plot_out")'
set multiplot layout 1,${#plotted_scenes[@]} title 'KS p-value of the rupture sizes (log10 potency) against the converged reference vs CPU, per back-end (points labelled by rtol)'
set logscale xy
set xlabel 'CPU time of the run [s]'
set ylabel 'KS p-value (below $floor drawn at $floor)'
set format x '%g'
set format y '1e%L'
set yrange [$floor / 2:3]
set grid
set key bottom right font ',10'
set arrow from graph 0, first 0.01 to graph 1, first 0.01 nohead dt 2 lw 2 lc rgb '#555555'
set label 'p = 0.01: told apart below' at graph 0.02, first 0.013 left font ',10'
$panels
unset multiplot
GP
echo "$md"
echo "$plot_out"
echo "stats convergence written to $out/"
exit $failures
