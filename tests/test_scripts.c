/* The scripts under scripts/ end to end, as a user runs them: summary.sh, the paper's plot
 * scripts, the catalogs' (event_ruptures.sh, plot_mfd.sh, plot_slip_map.sh, plot_ruptures.sh),
 * the fronts' (plot_fronts.sh, front_phase_diagram.sh, with bksim fronts)
 * and the benchmarks' smoke runs (bench.sh --quick, bench_output.sh --quick); sweep.sh is
 * test_sweep.c's.  Runs from the repository root, with ./bksim (or $BKSIM). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "command.h"
#include "files.h"

static char tmpdir[256];
/* A 4 x 5 Coulomb lattice for half a second: a few ruptures, the largest still running at the end. */
static const char sheet_ini[] = "[model]\nrows = 4\ncols = 5\ncoupling_stiffness = 2e4\n"
                                "[block]\nmass = 1\ndriver_stiffness = 1e4\nx_init_random = 2e-5\n"
                                "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
                                "[driver]\nvelocity = 1e-3\n[output]\ninterval = 0\n[run]\nt_end = 0.5\n";

static int setup(void **state)
{
    (void)state;
    return make_temp_dir(tmpdir, sizeof tmpdir, "bksim_scripts");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

/* scripts/summary.sh counts every block and goes on past a file it cannot summarise. */
static void test_summary_script(void **state)
{
    (void)state;
    char two[512], bare[512], cmd[2048];
    snprintf(two, sizeof two, "%s/two_blocks.h5", tmpdir);
    snprintf(bare, sizeof bare, "%s/no_cof.h5", tmpdir);
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/chains/two_block_coulomb.ini -q -o %s && "
             "./bksim run configs/paper/case_a_coulomb.ini -q -o %s --set output.fields=x,v",
             two, bare);
    assert_int_equal(run_command(cmd, NULL), 0);
    bk_transition *rows = NULL;
    size_t n = 0;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_transitions(two, &rows, &n, &err), BK_OK);
    long onsets[2] = {0, 0};
    for (size_t k = 0; k < n; ++k)
        onsets[rows[k].block] += rows[k].from == 0 && rows[k].to != 0;
    free(rows);
    assert_true(onsets[0] > 0 && onsets[1] > 0);
    char *text = NULL;
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/summary.sh %s %s/missing.h5 %s", two, tmpdir, bare);
    assert_int_equal(run_command(cmd, &text), 1);
    char expected[64];
    snprintf(expected, sizeof expected, "slip events %4ld", onsets[0] + onsets[1]);
    assert_non_null(strstr(text, expected));
    assert_non_null(strstr(text, "missing.h5: No such file"));
    assert_non_null(strstr(text, "no_cof "));
    assert_non_null(strstr(text, "apparent COF n/a"));
    free(text);

    /* A run without sample rows (interval = 0: rows only at t = 0, t_end and its transition
     * instants) has no slip's peak in it: no figure rather than a low one, and the kinematics
     * plot refuses instead of drawing lines through slips that did not happen. */
    char no_rows[512];
    snprintf(no_rows, sizeof no_rows, "%s/no_rows.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk10_coulomb.ini -q -o %s --set output.interval=0 "
             "--set run.t_end=5", no_rows);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/summary.sh %s", no_rows);
    expect_command(cmd, 0, "peak slip rate n/a (no sample rows between t = 0 and the end)");
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/plot_kinematics.sh %s/k.png t %s:run:blue", tmpdir, no_rows);
    expect_command(cmd, 1, "has no sample rows between t = 0 and its end (as with [output] interval = 0)");
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/plot_cof.sh %s/c.png t %s:run:blue", tmpdir, no_rows);
    expect_command(cmd, 1, "nothing of block 0's apparent COF between its transitions is in it");
    snprintf(cmd, sizeof cmd, "%s/k.png", tmpdir);
    assert_false(path_exists(cmd));
    snprintf(cmd, sizeof cmd, "%s/c.png", tmpdir);
    assert_false(path_exists(cmd));
}

/* The paper's plot scripts: any block, png/pdf/svg, and a clear refusal of bad options. */
static void test_plot_scripts(void **state)
{
    (void)state;
    char run[512], cmd[2048];
    snprintf(run, sizeof run, "%s/plot_two.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/two_block_coulomb.ini -q -o %s", run);
    assert_int_equal(run_command(cmd, NULL), 0);
    const char *bin = bksim_binary();
    static const char *const scripts[] = {"plot_cof.sh", "plot_kinematics.sh"};
    for (size_t k = 0; k < 2; ++k) {
        snprintf(cmd, sizeof cmd,
                 "BKSIM=%s scripts/%s --format svg --block 1 %s/fig_%zu.svg 'two blocks' %s:block:black && "
                 "grep -c '<svg' %s/fig_%zu.svg && grep -c 'block 1' %s/fig_%zu.svg",
                 bin, scripts[k], tmpdir, k, run, tmpdir, k, tmpdir, k);
        assert_int_equal(run_command(cmd, NULL), 0);
        snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/%s --format pdf %s/fig_%zu.pdf t %s:b:black && "
                 "head -c 5 %s/fig_%zu.pdf | grep -q '%%PDF'", bin, scripts[k], tmpdir, k, run, tmpdir, k);
        assert_int_equal(run_command(cmd, NULL), 0);
        snprintf(cmd, sizeof cmd, "scripts/%s --format gif %s/x t %s:b:black", scripts[k], tmpdir, run);
        expect_command(cmd, 2, "--format must be png, pdf or svg");
        snprintf(cmd, sizeof cmd, "scripts/%s --block -1 %s/x t %s:b:black", scripts[k], tmpdir, run);
        expect_command(cmd, 2, "--block needs a block index");
    }
}

/* Every line of text naming a file under dir (the figures a plot script printed) exists;
 * returns how many there were. */
static int printed_files_exist(char *text, const char *dir)
{
    int count = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (strncmp(line, dir, strlen(dir)) != 0)
            continue;
        if (!path_exists(line))
            fail_msg("%s: printed, but not written", line);
        ++count;
    }
    return count;
}

/* The catalogs' scripts on a 40-block chain whose ends fail 1 ms apart and slip at once
 * (test_run_catalog.c's overlap scene): its first event holds two separate ruptures, which
 * event_ruptures.sh counts from /ruptures; plot_mfd.sh draws both figures of either catalog;
 * a file without the rupture catalog is a clear error to each. */
static void test_catalog_scripts(void **state)
{
    (void)state;
    char path[512], out[512], cmd[2048];
    char *text = NULL;
    snprintf(path, sizeof path, "%s/ends.ini", tmpdir);
    snprintf(out, sizeof out, "%s/ends.h5", tmpdir);
    const char *ends = "[model]\nn_blocks = 40\ncoupling_stiffness = 100\n"
                       "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                       "[block.0]\nx_init = -2e-4\n[block.39]\nx_init = -1.99e-4\n"
                       "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
                       "[driver]\nvelocity = 1e-3\n[output]\ninterval = 0\n[run]\nt_end = 0.5\n";
    assert_int_equal(write_text(path, ends), 0);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --quiet", path, out);
    assert_int_equal(run_command(cmd, NULL), 0);
    const char *bin = bksim_binary();
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/event_ruptures.sh --table %s", bin, out);
    assert_int_equal(run_command(cmd, &text), 0);
    double t_start;
    int n_blocks, ruptures;
    assert_int_equal(sscanf(text, "%lf %d %d", &t_start, &n_blocks, &ruptures), 3);
    assert_true(n_blocks >= 2 && ruptures == 2);
    assert_non_null(strstr(text, "(100.0 %) hold two or more separate ruptures; 2 ruptures in all"));
    free(text);
    /* Without the rupture catalog there is nothing to count: an error, not a count of 0. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s/bare.h5 --set output.events=false --quiet "
             "&& BKSIM=%s scripts/event_ruptures.sh %s/bare.h5", path, tmpdir, bin, tmpdir);
    expect_command(cmd, 1, "no table /ruptures");

    /* /ruptures by default, /events with --table events (the figures' names say which). */
    static const char *const mfd_runs[][2] = {{"", "ends_ruptures"}, {"--table events", "ends"}};
    for (size_t k = 0; k < 2; ++k) {
        snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_mfd.sh %s -o %s/fig %s", bin, mfd_runs[k][0], tmpdir, out);
        assert_int_equal(run_command(cmd, &text), 0);
        free(text);
        snprintf(cmd, sizeof cmd, "%s/fig/%s_mfd.png", tmpdir, mfd_runs[k][1]);
        assert_true(path_exists(cmd));
        snprintf(cmd, sizeof cmd, "%s/fig/%s_spacetime.png", tmpdir, mfd_runs[k][1]);
        assert_true(path_exists(cmd));
    }
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_mfd.sh -o %s/fig %s/bare.h5", bin, tmpdir, tmpdir);
    expect_command(cmd, 1, "no table /ruptures");
    snprintf(cmd, sizeof cmd, "scripts/plot_mfd.sh --table quakes %s", out);
    expect_command(cmd, 2, "--table must be ruptures or events");
    /* plot_stats.sh on a catalog of two ruptures: no interevent times, no mainshock; each
     * figure says why instead of drawing an empty frame. */
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_stats.sh --format svg -o %s/fig %s --from 0", bin, tmpdir, out);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_int_equal(printed_files_exist(text, tmpdir), 2);
    free(text);
    snprintf(cmd, sizeof cmd, "grep -l 'not available: ' %s/fig/ends_ruptures_interevent.svg %s/fig/ends_ruptures_omori.svg | wc -l",
             tmpdir, tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_string_equal(text, "2\n");
    free(text);
    snprintf(cmd, sizeof cmd, "scripts/plot_stats.sh %s --window", out);
    expect_command(cmd, 2, "--window needs a value");
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_stats.sh -o %s/fig %s/bare.h5", bin, tmpdir, tmpdir);
    expect_command(cmd, 1, "bare.h5: no /ruptures table");

    /* plot_slip_map.sh on a 4 x 5 lattice: the largest rupture, a chosen event, and rows past
     * either table's end. */
    snprintf(path, sizeof path, "%s/sheet.ini", tmpdir);
    assert_int_equal(write_text(path, sheet_ini), 0);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s/sheet.h5 --quiet", path, tmpdir);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_slip_map.sh -o %s/fig %s/sheet.h5", bin, tmpdir, tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "/fig/sheet_rupture_"));
    assert_non_null(strstr(text, "_slip_map.png"));
    free(text);
    /* On a chain, slip against block (bars), not a one-row colour map stretched over the frame. */
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_slip_map.sh --format svg -o %s/fig %s > /dev/null && "
             "grep -c -e '>block<' -e '>slip during the rupture \\[m\\]<' %s/fig/ends_rupture_*_slip_map.svg",
             bin, tmpdir, out, tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_string_equal(text, "2\n");
    free(text);
    /* plot_mfd.sh on the lattice: its MFD, and no space-time plot of flat block indices
     * (left..right bound a box on a lattice), said on stderr. */
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_mfd.sh -o %s/fig %s/sheet.h5", bin, tmpdir, tmpdir);
    expect_command(cmd, 0, "a 4 x 5 lattice: no space-time plot (left..right are the flat block indices");
    snprintf(cmd, sizeof cmd, "%s/fig/sheet_ruptures_spacetime.png", tmpdir);
    assert_false(path_exists(cmd));
    snprintf(cmd, sizeof cmd, "%s/fig/sheet_ruptures_mfd.png", tmpdir);
    assert_true(path_exists(cmd));
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_slip_map.sh --format svg --event 0 -o %s/fig %s/sheet.h5", bin,
             tmpdir, tmpdir);
    assert_int_equal(run_command(cmd, NULL), 0);
    /* Drawn as the 4 x 5 lattice it is, never as a strip of 20. */
    snprintf(cmd, sizeof cmd, "grep -c -e '>row (block i / 5)<' -e '>column (block i %% 5)<' %s/fig/sheet_slip_map_0.svg",
             tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_string_equal(text, "2\n");
    free(text);
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_slip_map.sh --event 99999 -o %s/fig %s/sheet.h5", bin, tmpdir,
             tmpdir);
    expect_command(cmd, 1, "out of range");
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_slip_map.sh --rupture 99999 -o %s/fig %s/sheet.h5", bin, tmpdir,
             tmpdir);
    expect_command(cmd, 1, "--rupture 99999 out of range: /ruptures has");
    snprintf(cmd, sizeof cmd, "scripts/plot_slip_map.sh --rupture 0 --table events %s/sheet.h5", tmpdir);
    expect_command(cmd, 2, "--rupture K reads /ruptures");
}


/* plot_ruptures.sh on a 60-block chain (a second of stick-slip: about 70 ruptures of 1 to 28
 * blocks) and on a 4 x 5 lattice: its figures in png (the chain's four, the lattice's three:
 * no space-time plot), the fits' TSV, and a clear refusal of bad input. */
static void test_rupture_scripts(void **state)
{
    (void)state;
    char ini[300], chain[300], cmd[4096];
    char *text = NULL;
    const char *bin = bksim_binary();
    snprintf(ini, sizeof ini, "%s/chain60.ini", tmpdir);
    snprintf(chain, sizeof chain, "%s/chain60.h5", tmpdir);
    const char *scene = "[model]\nn_blocks = 60\ncoupling_stiffness = 2e4\nseed = 3\n"
                        "[block]\nmass = 1\ndriver_stiffness = 1e4\nx_init_random = 6e-5\n"
                        "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
                        "[driver]\nvelocity = 1e-3\n[output]\ninterval = 0\n[run]\nt_end = 1\n";
    assert_int_equal(write_text(ini, scene), 0);
    snprintf(cmd, sizeof cmd,
             "./bksim run %s -o %s --quiet && "
             "./bksim run %s -o %s/chain60_norate.h5 --quiet --set catalog.rupture_rate=false && "
             "./bksim run %s -o %s/chain60_bare.h5 --quiet --set output.events=false",
             ini, chain, ini, tmpdir, ini, tmpdir);
    assert_int_equal(run_command(cmd, NULL), 0);

    /* The largest rupture: four figures, and a fit per size range and for all. */
    char figs[300];
    snprintf(figs, sizeof figs, "%s/rup", tmpdir);
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_ruptures.sh -o %s %s", bin, figs, chain);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "# range\tn_ruptures[1]\tslope[1]\tslope_error[1]"));
    assert_non_null(strstr(text, "\nn_blocks 1-3\t"));
    assert_non_null(strstr(text, "\nn_blocks 4-30\t"));
    assert_non_null(strstr(text, "\nall\t"));
    for (const char *name = "_ruptures_slip_spacetime.png\0_front.png\0_rate.png\0_ruptures_moment_duration.png\0";
         *name; name += strlen(name) + 1)
        assert_non_null(strstr(text, name));
    assert_int_equal(printed_files_exist(text, figs), 4);
    free(text);

    /* A chosen rupture in a time window, drawn as svg: its front's legend states both speeds. */
    snprintf(cmd, sizeof cmd,
             "BKSIM=%s scripts/plot_ruptures.sh --format svg --rupture 0 --from 0.2 --to 0.6 --by duration -o %s %s "
             "> /dev/null && grep -c -e 'left front: ' -e 'right front: ' %s/chain60_rupture_0_front.svg",
             bin, figs, chain, figs);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_string_equal(text, "2\n");
    free(text);

    /* Without /rupture_rate: the other figures, and a warning for the moment rate. */
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_ruptures.sh -o %s/norate %s/chain60_norate.h5", bin, tmpdir,
             tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "no moment-rate figure"));
    assert_null(strstr(text, "_rate.png"));
    free(text);

    /* A lattice: no space-time plot (said on stderr), the three others. */
    char sheet[300];
    snprintf(ini, sizeof ini, "%s/sheet45.ini", tmpdir);
    snprintf(sheet, sizeof sheet, "%s/sheet45.h5", tmpdir);
    assert_int_equal(write_text(ini, sheet_ini), 0);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --quiet && BKSIM=%s scripts/plot_ruptures.sh -o %s %s", ini,
             sheet, bin, figs, sheet);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "a 4 x 5 lattice: no space-time plot"));
    assert_int_equal(printed_files_exist(text, figs), 3);
    free(text);

    /* Bad input: a clear message, exit status 1 (the file) or 2 (the options). */
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_ruptures.sh --rupture 99999 -o %s %s", bin, figs, chain);
    expect_command(cmd, 1, "--rupture 99999 out of range: /ruptures has");
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_ruptures.sh -o %s %s/chain60_bare.h5", bin, figs, tmpdir);
    expect_command(cmd, 1, "no table /ruptures");
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_ruptures.sh --from 5 -o %s %s", bin, figs, chain);
    expect_command(cmd, 1, "no rupture slips between 5 and the end");
    snprintf(cmd, sizeof cmd, "scripts/plot_ruptures.sh --from 0.8 --to 0.5 %s", chain);
    expect_command(cmd, 2, "--from must be before --to");
    snprintf(cmd, sizeof cmd, "scripts/plot_ruptures.sh --by size %s", chain);
    expect_command(cmd, 2, "--by must be blocks or duration");
    snprintf(cmd, sizeof cmd, "scripts/plot_ruptures.sh --rupture -1 %s", chain);
    expect_command(cmd, 2, "--rupture needs a rupture row >= 0");
    snprintf(cmd, sizeof cmd, "scripts/plot_ruptures.sh %s/missing.h5", tmpdir);
    expect_command(cmd, 1, "missing.h5: no such file");
}

/* The benchmark's smoke run: every back-end on case B at three tolerances, all succeed
 * with the reference's stick-slip events and an error against the exact stepper that falls
 * as rtol tightens; and the whole script (sweep, scaling, long run, plots, tables). */
static void test_bench_smoke(void **state)
{
    (void)state;
    char *text = NULL;
    assert_int_equal(run_command("build/bench/bksim_bench --quick --repeats 1 --case B_coulomb", &text), 0);
    char method[64] = "", last_method[64] = "";
    double last_error = 0.0;
    int rows = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        char name[64], status[16], events[16];
        double rtol, cpu, error_x;
        if (sscanf(line, "%63s %63s %lf %15s %lf %*f %*f %*d %*d %*d %*d %*d %15s %*d %lf", name, method, &rtol,
                   status, &cpu, events, &error_x) != 7 ||
            strcmp(name, "B_coulomb") != 0 || strncmp(method, "reference", 9) == 0)
            continue;
        ++rows;
        assert_string_equal(status, "ok");
        assert_string_equal(events, "same");
        /* Within one method's sweep the error falls (exact has a single row). */
        if (strcmp(method, last_method) == 0)
            assert_true(error_x < last_error);
        last_error = error_x;
        snprintf(last_method, sizeof last_method, "%s", method);
    }
    free(text);
    assert_true(rows >= 20);
    if (run_command("command -v gnuplot", NULL) != 0)
        return; /* the plots need gnuplot (quickstart.sh installs it) */
    assert_int_equal(run_command("scripts/bench.sh --quick", &text), 0);
    char dir[512] = "";
    const char *at = strstr(text, "benchmark written to ");
    assert_non_null(at);
    assert_int_equal(sscanf(at, "benchmark written to %511[^\n]", dir), 1);
    free(text);
    const char *files[] = {"results.tsv", "scaling.tsv", "long_run.tsv", "tables.md", "wp_B_coulomb.png",
                           "scaling.png"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; ++k) {
        char path[600];
        snprintf(path, sizeof path, "%s/%s", dir, files[k]);
        assert_true(path_exists(path));
    }
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(run_command(cmd, NULL), 0);
}

/* The output benchmark's smoke run: its three tables, the writer's two scenes, rows that
 * cost CVODE and the exact stepper no evaluation at all (they interpolate), and the exact
 * stepper's rows on a 256-block cluster. */
static void test_bench_output_smoke(void **state)
{
    (void)state;
    char dir[] = "/tmp/bksim_bench_output_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char cmd[256];
    snprintf(cmd, sizeof cmd, "scripts/bench_output.sh --quick %s", dir);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "| case B, 2 s, 0.1 ms rows | 1 |"));
    assert_non_null(strstr(text, "| resting chain, every field | 100 |"));
    assert_non_null(strstr(text, "| exact | 1.000 | 1.000 | 1.000 | - | - | - |"));
    assert_non_null(strstr(text, "| cvode_adams | 1.000 | 1.000 | 1.000 | 1.000 | 1.000 | 1.000 |"));
    assert_non_null(strstr(text, "| blocks in the cluster |"));
    assert_non_null(strstr(text, "\n| 256 | "));
    free(text);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
}

/* bksim fronts and plot_fronts.sh on the shipped 30-block side-driven chain (0.4 s): the
 * precursor table in order of start, the first crossing at an edge force near N mu_d N, one
 * front block by block, the three figures; the phase-diagram script on a 2 x 2 grid; what is
 * refused. */
static void test_front_scripts(void **state)
{
    (void)state;
    char out[512], figs[512], cmd[2048], expected[700];
    snprintf(out, sizeof out, "%s/precursors.h5", tmpdir);
    snprintf(figs, sizeof figs, "%s/front_figs", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run configs/fronts/precursors_30.ini -q -o %s && ./bksim fronts %s", out, out);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 0);
    snprintf(expected, sizeof expected, "# fronts of %s (30 blocks), loaded edge left\n# rupture[1]\tt_start[s]\t"
             "edge_force[N]\tfirst_block[1]\tn_blocks[1]\tarrest_length[blocks]\tfrom_edge[1]\tcrossed[1]\t"
             "mean_speed[blocks/s]\tduration[s]\n", out);
    assert_non_null(strstr(text, expected));
    /* The first row to cross: its edge force (column 3) and t_start in order. */
    double previous = -1.0, first_cross = NAN;
    int rows = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (line[0] == '#')
            continue;
        long k;
        double t, force;
        int first, n, length, from_edge, crossed;
        assert_int_equal(sscanf(line, "%ld %lf %lf %d %d %d %d %d", &k, &t, &force, &first, &n, &length, &from_edge,
                                &crossed), 8);
        assert_true(t >= previous);
        previous = t;
        ++rows;
        if (crossed && isnan(first_cross)) {
            first_cross = force;
            assert_int_equal(length, 30);
        }
    }
    free(text);
    print_message("%d ruptures; the first crossing at an edge force of %.3f N (30 mu_d N = 12 N)\n", rows, first_cross);
    assert_true(rows > 100 && fabs(first_cross - 12.0) < 0.15 * 12.0);
    snprintf(cmd, sizeof cmd, "./bksim fronts %s --rupture 0 --window 4", out);
    expect_command(cmd, 0, "# block[1]\tdistance[blocks]\tt_onset[s]\tt_stop[s]\tslip[m]\tspeed[blocks/s]\n0\t0\t");
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/plot_fronts.sh --kinetic 0.4 -o %s %s", figs, out);
    assert_int_equal(run_command(cmd, &text), 0);
    const char *names[] = {"precursors_precursors.png", "precursors_fronts.png"};
    for (size_t k = 0; k < 2; ++k) {
        char path[700];
        snprintf(path, sizeof path, "%s/%s", figs, names[k]);
        assert_non_null(strstr(text, path));
        assert_true(path_exists(path));
    }
    assert_non_null(strstr(text, "_speed.png"));
    free(text);

    /* Refused: a bad option or value, a rupture past the table, a lattice, no catalog. */
    snprintf(cmd, sizeof cmd, "./bksim fronts %s --edge top", out);
    expect_command(cmd, 2, "--edge top: allowed: left, right");
    snprintf(cmd, sizeof cmd, "./bksim fronts %s --window 1", out);
    expect_command(cmd, 2, "--window 1: not a whole number >= 2");
    snprintf(cmd, sizeof cmd, "./bksim fronts %s --rupture 100000", out);
    expect_command(cmd, 2, "--rupture 100000: it holds");
    snprintf(cmd, sizeof cmd, "./bksim fronts %s/none.h5", tmpdir);
    expect_command(cmd, 2, "none.h5: no such HDF5 file");
    char sheet[300], long_cmd[4096];
    snprintf(sheet, sizeof sheet, "%s/sheet_fronts", tmpdir);
    snprintf(long_cmd, sizeof long_cmd, "printf '%%s' '%s' > %s.ini && ./bksim run %s.ini -q -o %s.h5 && ./bksim fronts %s.h5",
             sheet_ini, sheet, sheet, sheet, sheet);
    expect_command(long_cmd, 2, "fronts are measured along a chain (one row of blocks); this is a lattice");
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/plot_fronts.sh --kinetic -1 %s", out);
    expect_command(cmd, 2, "--kinetic needs a force > 0 N, got '-1'");

    /* The phase diagram's script on four points of the Oslo model. */
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/front_phase_diagram.sh -j 2 -o %s/phase --taus 0.5,0.95 "
             "--alphas 0.01,1 --t-end 100 2>/dev/null", tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "# tau_bar\talpha\tspeed[blocks/unit time]\treached[blocks]\tbeta\tclass\n"));
    assert_non_null(strstr(text, "0.95\t0.01\t3.2"));
    assert_non_null(strstr(text, "supershear"));
    assert_non_null(strstr(text, "/phase/phase_beta.png"));
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_summary_script),
        cmocka_unit_test(test_plot_scripts),
        cmocka_unit_test(test_catalog_scripts),
        cmocka_unit_test(test_rupture_scripts),
        cmocka_unit_test(test_front_scripts),
        cmocka_unit_test(test_bench_smoke),
        cmocka_unit_test(test_bench_output_smoke),
    };
    return cmocka_run_group_tests_name("scripts", tests, setup, teardown);
}
