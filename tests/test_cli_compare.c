/* `bksim compare A.h5 B.h5` end to end, as a user and a batch script meet it: catalogs written
 * here with plain HDF5 calls (the same, shifted, another program's with magnitudes only) and two
 * short runs of the Carlson-Langer ring; the verdict, the JSON, the window and the level; --help
 * and the command list; usage errors (exit 2) and files that are no catalog (exit 1, the
 * message naming the file); and the smoke run of scripts/bench_stats_convergence.sh, which
 * compares runs at several tolerances with `bksim compare`.  The numbers are
 * test_stats_compare.c's.  Runs ./bksim from the repository root. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

#include "bk_test.h"
#include "command.h"
#include "files.h"

static char tmpdir[256];
static char same[512], shifted[512], magnitudes[512], empty[512];

typedef struct row {
    double t_start, magnitude, potency;
    int32_t n_blocks;
    int8_t complete;
} row;

typedef struct short_row {
    double t_start, magnitude;
} short_row;

/* A table of n rows at /name of a new file path, in the layout `type` gives. */
static void write_table(const char *path, const char *name, hid_t type, const void *rows, size_t n)
{
    hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(file >= 0);
    hsize_t dims[1] = {n};
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t dset = H5Dcreate2(file, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(dset >= 0);
    assert_true(H5Dwrite(dset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) >= 0);
    H5Dclose(dset);
    H5Sclose(space);
    H5Fclose(file);
}

/* 1000 ruptures one a second from t = 0.5 s, potencies a power law of exponent 1.7 from 1e-4
 * (a fixed sequence: quantiles of the law), each times factor; the last still running. */
static void write_catalog(const char *path, double factor)
{
    enum { N = 1000 };
    /* Zeroed and filled field by field: the struct's padding goes to the file too, and
     * valgrind rightly calls uninitialised bytes written out an error. */
    row *rows = calloc(N, sizeof *rows);
    assert_non_null(rows);
    for (size_t i = 0; i < N; ++i) {
        /* The quantiles in a scrambled order (7 is prime to 1000). */
        double u = ((double)((i * 7) % N) + 0.5) / N;
        double p = factor * 1e-4 * pow(u, -1.0 / 0.7);
        rows[i].t_start = 0.5 + (double)i;
        rows[i].magnitude = 2.0 / 3.0 * log10(p) + 1.0;
        rows[i].potency = p;
        rows[i].n_blocks = (int32_t)ceil(p / 1e-4);
        rows[i].complete = (int8_t)(i + 1 < N);
    }
    hid_t type = H5Tcreate(H5T_COMPOUND, sizeof(row));
    H5Tinsert(type, "t_start", HOFFSET(row, t_start), H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "magnitude", HOFFSET(row, magnitude), H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "potency", HOFFSET(row, potency), H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "n_blocks", HOFFSET(row, n_blocks), H5T_NATIVE_INT32);
    H5Tinsert(type, "complete", HOFFSET(row, complete), H5T_NATIVE_INT8);
    write_table(path, "ruptures", type, rows, N);
    H5Tclose(type);
    free(rows);
}

static int setup(void **state)
{
    (void)state;
    if (make_temp_dir(tmpdir, sizeof tmpdir, "bksim_cli_compare") != 0)
        return -1;
    snprintf(same, sizeof same, "%s/same.h5", tmpdir);
    snprintf(shifted, sizeof shifted, "%s/shifted.h5", tmpdir);
    snprintf(magnitudes, sizeof magnitudes, "%s/magnitudes.h5", tmpdir);
    snprintf(empty, sizeof empty, "%s/empty.h5", tmpdir);
    write_catalog(same, 1.0);
    write_catalog(shifted, 2.0);
    /* Another program's catalog: /events of t_start and magnitude, the same magnitudes. */
    short_row rows[999];
    for (size_t i = 0; i < 999; ++i) {
        double u = ((double)((i * 7) % 1000) + 0.5) / 1000;
        rows[i] = (short_row){0.5 + (double)i, 2.0 / 3.0 * log10(1e-4 * pow(u, -1.0 / 0.7)) + 1.0};
    }
    hid_t type = H5Tcreate(H5T_COMPOUND, sizeof(short_row));
    H5Tinsert(type, "t_start", HOFFSET(short_row, t_start), H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "magnitude", HOFFSET(short_row, magnitude), H5T_NATIVE_DOUBLE);
    write_table(magnitudes, "events", type, rows, 999);
    H5Tclose(type);
    /* An HDF5 file without a catalog. */
    hid_t file = H5Fcreate(empty, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(file);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

static void test_verdicts(void **state)
{
    (void)state;
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s", same, same);
    expect_command(cmd, 0, "verdict: not told apart at the 1 % level (log10 potency: p = 1 >= 0.01)");
    expect_command(cmd, 0, "A: ");
    expect_command(cmd, 0, "/ruptures (the rupture catalog): 1000 rows\n  left out: 1 still running at the end "
                           "(complete = 0)\n  events: 999; span 998 s (the catalog's span)");
    expect_command(cmd, 0, "  log10 potency  D = 0.0000  p = 1  (n = 999, 999)\n");
    /* Potencies doubled: D = 1 - 2^-0.7 = 0.384 in every test. */
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s", same, shifted);
    expect_command(cmd, 0, "  log10 potency  D = 0.3844  p = ");
    expect_command(cmd, 0, "  n_blocks       D = 0.3");
    expect_command(cmd, 0, "verdict: told apart at the 1 % level (log10 potency: p = ");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --json", same, shifted);
    expect_command(cmd, 0, "\"verdict\": {\"test\": \"log10_potency\", \"told_apart\": true, \"level\": 0.01}}\n");
    /* The window: 200 of the 999 complete events start in [100, 300); without the run's
     * t_reached the span is theirs, from 100.5 s to 299.5 s (as `bksim stats` has it). */
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --from 100 --to=300 --json", same, same);
    expect_command(cmd, 0, "\"n_outside_window\": 799, \"n_events\": 200, ");
    expect_command(cmd, 0, "\"duration\": 199, \"duration_from_run\": false, ");
    /* Unrounded, the same files are still the same; a level of 5 % is said so. */
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --round 0 --level=0.05", same, same);
    expect_command(cmd, 0, "(values as stored; ties exact, p asymptotic), \"differ\": p < 0.05:");
    expect_command(cmd, 0, "verdict: not told apart at the 5 % level");
    /* Another program's /events (the default falls back to it): judged by magnitudes. */
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s", magnitudes, same);
    expect_command(cmd, 0, "/events (the time-window catalog: the file has no /ruptures): 999 rows");
    expect_command(cmd, 0, "  log10 potency  not tested: potency: no potency field in A");
    expect_command(cmd, 0, "verdict: not told apart at the 1 % level (magnitude: p = 1 >= 0.01)");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --table events", same, magnitudes);
    expect_command(cmd, 1, "same.h5: no /events table");
}

/* Two runs of the Carlson-Langer ring: the same config twice is the same catalog, two seeds
 * are two catalogs of one law; each comparison ends with a verdict. */
static void test_runs(void **state)
{
    (void)state;
    char one[512], two[512], cmd[2048];
    snprintf(one, sizeof one, "%s/seed1.h5", tmpdir);
    snprintf(two, sizeof two, "%s/seed2.h5", tmpdir);
    const char *run = "./bksim run configs/chains/carlson_langer_100.ini --quiet --force --set run.t_end=300 "
                      "--set catalog.rupture_rate=false --set output.checkpoint_interval=0";
    snprintf(cmd, sizeof cmd, "%s -o %s && %s -o %s --set model.seed=2", run, one, run, two);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --from 100", one, one);
    expect_command(cmd, 0, "verdict: not told apart at the 1 % level (log10 potency: p = 1 >= 0.01)");
    expect_command(cmd, 0, "span 200 s (the run's t_reached within the window)");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --from 100", one, two);
    expect_command(cmd, 0, "verdict: ");
    expect_command(cmd, 0, "rates: B / A = ");
}

static void test_usage_and_errors(void **state)
{
    (void)state;
    char cmd[2048];
    expect_command("./bksim compare --help", 0, "usage: bksim compare A.h5 B.h5 [--table NAME]");
    expect_command("./bksim compare -h", 0, "  --round R         round log10 potency and magnitude");
    expect_command("./bksim --help", 0, "  compare A.h5 B.h5 [--table NAME]");
    expect_command("./bksim compare", 2, "bksim compare: missing A.h5 and B.h5\n(see `bksim compare --help`)");
    snprintf(cmd, sizeof cmd, "./bksim compare %s", same);
    expect_command(cmd, 2, "missing B.h5: give two catalogs, A and B");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s %s", same, same, same);
    expect_command(cmd, 2, "unexpected argument");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --level 1", same, same);
    expect_command(cmd, 2, "level 1: allowed 0 < level < 1");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --level 1%%", same, same);
    expect_command(cmd, 2, "--level needs a level 0 < L < 1, got '1%'");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --round=-1", same, same);
    expect_command(cmd, 2, "rounding -1: allowed 0 <= round <= 1");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --from x", same, same);
    expect_command(cmd, 2, "--from needs a time in s, got 'x'");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --from 30 --to 10", same, same);
    expect_command(cmd, 2, "time window [30, 10) s");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --table=", same, same);
    expect_command(cmd, 2, "--table needs a table name");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --table", same, same);
    expect_command(cmd, 2, "unknown or incomplete option '--table'");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --bins 3", same, same);
    expect_command(cmd, 2, "unknown or incomplete option '--bins'");
    /* Files: missing, no catalog, no event in the window; each named. */
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s/missing.h5", same, tmpdir);
    expect_command(cmd, 1, "missing.h5");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s", empty, same);
    expect_command(cmd, 1, "empty.h5: no /ruptures table (the rupture catalog), and no /events");
    snprintf(cmd, sizeof cmd, "./bksim compare %s %s --from 5000", same, shifted);
    expect_command(cmd, 1, "same.h5: no event to compare: of 1000 rows, 1 still running at the end");
}

/* The benchmark's smoke run (--quick: short runs of both scenes, two back-ends at rtol 1e-6
 * against references at 1e-10 and 1e-11 and another seed): a row per run, every one compared
 * and none told apart (its runs share their first 100 s with the reference), its table and plot;
 * and its usage errors. */
static void test_bench_script(void **state)
{
    (void)state;
    if (run_command("command -v gnuplot", NULL) != 0)
        return; /* the plot needs gnuplot (quickstart.sh installs it) */
    char dir[512], cmd[2048], path[600];
    snprintf(dir, sizeof dir, "%s/bench", tmpdir);
    snprintf(cmd, sizeof cmd, "BKSIM=./bksim scripts/bench_stats_convergence.sh --quick %s", dir);
    expect_command(cmd, 0, "stats convergence written to ");
    snprintf(path, sizeof path, "%s/stats_convergence.tsv", dir);
    char *text = NULL;
    snprintf(cmd, sizeof cmd, "grep -v '^#' %s", path);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "scene\tmethod\trtol\tcpu_s\truptures\tks_d\tks_p\tks_p_magnitude\tverdict\t"));
    assert_non_null(strstr(text, "chain\treference\t1e-10\t"));
    assert_non_null(strstr(text, "lattice\tseed_2\t1e-10\t"));
    assert_non_null(strstr(text, "chain\tauto (gsl_rk8pd)\tdefault\t"));
    assert_non_null(strstr(text, "lattice\tcvode_adams\t1e-6\t"));
    assert_null(strstr(text, "told apart"));
    assert_null(strstr(text, "failed"));
    free(text);
    /* 2 scenes x (reference, reference_2, seed_2, auto, 2 back-ends) and the header. */
    snprintf(cmd, sizeof cmd, "test $(grep -vc '^#' %s) = 13", path);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(path, sizeof path, "%s/stats_convergence.md", dir);
    snprintf(cmd, sizeof cmd, "cat %s", path);
    expect_command(cmd, 0, "| method | rtol | CPU [s] | ruptures | KS D | p (log10 potency) |");
    expect_command(cmd, 0, "Loosest rtol at which every back-end agrees with the reference: 1e-6;");
    const char *files[] = {"stats_convergence.png", "stats_convergence_machine.txt"};
    for (size_t k = 0; k < 2; ++k) {
        snprintf(path, sizeof path, "%s/%s", dir, files[k]);
        assert_true(path_exists(path));
    }
    snprintf(cmd, sizeof cmd, "scripts/bench_stats_convergence.sh --plot-only %s", dir);
    expect_command(cmd, 0, "stats_convergence.png");
    expect_command("scripts/bench_stats_convergence.sh --help", 0, "usage: scripts/bench_stats_convergence.sh");
    expect_command("scripts/bench_stats_convergence.sh --scene ring", 2, "--scene needs chain or lattice, got 'ring'");
    expect_command("scripts/bench_stats_convergence.sh --method cvode_adams", 2,
                   "--method needs NAME:RTOL[,RTOL...], got 'cvode_adams'");
    expect_command("scripts/bench_stats_convergence.sh --quick --plot-only", 2, "exclude each other");
    snprintf(cmd, sizeof cmd, "scripts/bench_stats_convergence.sh --plot-only %s/nothing", tmpdir);
    expect_command(cmd, 1, "nothing: no such directory");
    snprintf(cmd, sizeof cmd, "scripts/bench_stats_convergence.sh --plot-only %s", tmpdir);
    expect_command(cmd, 1, "stats_convergence.tsv: no such table");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_verdicts),
        cmocka_unit_test(test_runs),
        cmocka_unit_test(test_usage_and_errors),
        cmocka_unit_test(test_bench_script),
    };
    return cmocka_run_group_tests_name("cli_compare", tests, setup, teardown);
}
