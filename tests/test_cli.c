/* The bksim commands end to end, as a user and a batch script meet them: the paper's configs
 * give the closed-form transitions in the HDF5 file; a one-line lattice is the chain; check,
 * info, export, stats and keys, --help and usage errors; progress on a terminal; damaged
 * files; README's config reference.  Runs ./bksim from the repository root.  Bad input is
 * test_cli_input.c's, stopped and restarted runs test_cli_restart.c's, the scripts
 * test_scripts.c's. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <hdf5.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "command.h"
#include "exact_single.h"
#include "files.h"
#include "good_config.h"
#include "same_output.h"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    return make_temp_dir(tmpdir, sizeof tmpdir, "bksim_cli");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

/* --- the paper's configs --------------------------------------------------------------- */

static void check_paper_case(const char *stem, double mu_d, int tension_only)
{
    char out[512], cmd[1024];
    snprintf(out, sizeof out, "%s/%s.h5", tmpdir, stem);
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/%s.ini -o %s --quiet", stem, out);
    char *text = NULL;
    int status = run_command(cmd, &text);
    if (status != 0)
        print_error("%s\n", text);
    free(text);
    assert_int_equal(status, 0);
    assert_true(path_exists(out));

    bk_transition *rows = NULL;
    size_t n = 0;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_transitions(out, &rows, &n, &err), BK_OK);
    exact_params p = {1.0, 1e4, 9.81, 0.6, mu_d, 1e-3, tension_only};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, 5.0, &ex), 0);
    assert_int_equal(n, ex.n_events);
    /* First slip at t = 0.5886 s; every transition's time and position to 1e-8. */
    assert_close(rows[0].t, 0.5886, 1e-12, 0.0);
    double worst = 0.0;
    for (size_t k = 0; k < n; ++k) {
        assert_int_equal(rows[k].from, ex.events[k].from);
        assert_int_equal(rows[k].to, ex.events[k].to);
        assert_close(rows[k].t, ex.events[k].t, 1e-8, 0.0);
        assert_close(rows[k].x, ex.events[k].x, 1e-8, 1e-15);
        double rel = fabs(rows[k].t - ex.events[k].t) / ex.events[k].t;
        worst = rel > worst ? rel : worst;
    }
    /* With method = auto these run on the exact stepper: every slip and every stick,
     * including case C's 0.2 ms sticks after grazing stops, to 1e-8. */
    for (size_t k = 0; k + 1 < n; ++k)
        assert_close(rows[k + 1].t - rows[k].t, ex.events[k + 1].t - ex.events[k].t, 1e-8, 0.0);
    print_message("%s: %zu transitions, worst relative time error %.2g\n", stem, n, worst);
    if (mu_d == 0.1 && !tension_only) /* case A's first slip lasts 31.82 ms */
        assert_close(rows[1].t - rows[0].t, 31.82e-3, 2e-4, 0.0);

    /* The time series: rows at 0.1 ms plus one per transition instant. */
    double *time = NULL;
    size_t t_rows, cols;
    assert_int_equal(bk_h5_read_doubles(out, "/time", &time, &t_rows, &cols, &err), BK_OK);
    assert_close(time[t_rows - 1], 5.0, 0, 0);
    assert_true(t_rows >= 50001);
    free(time);
    free(rows);
    exact_free(&ex);
}

static void test_paper_configs(void **state)
{
    (void)state;
    check_paper_case("case_a_coulomb", 0.1, 0);
    check_paper_case("case_b_coulomb", 0.5, 0);
    check_paper_case("case_c_coulomb", 0.5999, 0);
    check_paper_case("case_a_coulomb_tension_only", 0.1, 1);
    check_paper_case("case_b_coulomb_tension_only", 0.5, 1);
    check_paper_case("case_c_coulomb_tension_only", 0.5999, 1);
}

/* The paper's rate-and-state cases as the equations give them (converged, see README):
 * A and B stick-slip, B's slips more frequent and lower; C slips once, then slides steadily. */
typedef struct slip_summary {
    long slips;          /* stick -> slip transitions */
    double peak;         /* peak slip rate, m/s */
    double late_swing;   /* max |v - V| over the last second */
} slip_summary;

static slip_summary summarise(const char *stem)
{
    char out[512], cmd[1024];
    snprintf(out, sizeof out, "%s/%s.h5", tmpdir, stem);
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/%s.ini -o %s --quiet", stem, out);
    assert_int_equal(run_command(cmd, NULL), 0);
    bk_transition *tr = NULL;
    size_t n = 0;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_transitions(out, &tr, &n, &err), BK_OK);
    slip_summary s = {0, 0.0, 0.0};
    for (size_t k = 0; k < n; ++k)
        s.slips += tr[k].from == BK_MODE_STICK && tr[k].to != BK_MODE_STICK;
    double *t = NULL, *v = NULL;
    size_t rows, cols;
    assert_int_equal(bk_h5_read_doubles(out, "/time", &t, &rows, &cols, &err), BK_OK);
    assert_int_equal(bk_h5_read_doubles(out, "/v", &v, &rows, &cols, &err), BK_OK);
    for (size_t k = 0; k < rows; ++k) {
        s.peak = fmax(s.peak, fabs(v[k]));
        if (t[k] >= 4.0)
            s.late_swing = fmax(s.late_swing, fabs(v[k] - 1e-3));
    }
    print_message("%s: %ld slips, peak slip rate %.4g m/s, max |v - V| in the last second %.3g m/s\n",
                  stem, s.slips, s.peak, s.late_swing);
    free(t);
    free(v);
    free(tr);
    return s;
}

static void test_paper_rate_state(void **state)
{
    (void)state;
    slip_summary a = summarise("case_a_rs"), b = summarise("case_b_rs"), c = summarise("case_c_rs");
    assert_true(a.slips >= 5 && b.slips > a.slips); /* B: more frequent */
    assert_true(b.peak < 0.5 * a.peak);              /* and lower */
    assert_int_equal(c.slips, 1);                    /* C: one slip, then steady sliding */
    assert_true(c.late_swing < 1e-6);
    slip_summary a_to = summarise("case_a_rs_tension_only");
    assert_true(a_to.slips >= 2 && a_to.slips < a.slips); /* sparser without the push-back */
}

/* A chain as a 1 x N lattice, and as an N x 1 one (coupled up and down instead of left and
 * right), writes the chain's output bit for bit, with the chain's own `boundary` key and
 * method = auto choosing alike: free ends (bk10_coulomb), fixed walls, a ring with a
 * system-size event at 91 s (carlson_langer_100), and 1000 blocks that auto gives the
 * exact stepper (bk1000_coulomb). */
static void test_lattice_of_one_line_is_a_chain(void **state)
{
    (void)state;
    static const char *const chains[][2] = {
        {"configs/chains/bk10_coulomb.ini", "--set run.t_end=4"},
        {"configs/chains/bk10_coulomb.ini", "--set run.t_end=4 --set model.boundary=fixed"},
        {"configs/chains/carlson_langer_100.ini",
         "--set run.t_end=120 --set output.transitions=true --set output.interval=0.5"},
        {"configs/chains/bk1000_coulomb.ini", "--set run.t_end=0.5"},
    };
    char chain[600], lattice[600], cmd[2048];
    char *chain_info = NULL, *lattice_info = NULL;
    for (size_t k = 0; k < sizeof chains / sizeof chains[0]; ++k) {
        snprintf(chain, sizeof chain, "%s/line_chain.h5", tmpdir);
        snprintf(cmd, sizeof cmd, "./bksim run %s %s -o %s --quiet --force", chains[k][0], chains[k][1], chain);
        assert_int_equal(run_command(cmd, NULL), 0);
        snprintf(cmd, sizeof cmd, "./bksim info %s", chain);
        assert_int_equal(run_command(cmd, &chain_info), 0);
        for (int column = 0; column < 2; ++column) {
            snprintf(lattice, sizeof lattice, "%s/line_lattice.h5", tmpdir);
            /* n_blocks stays as the chain gives it: the other dimension follows. */
            snprintf(cmd, sizeof cmd, "./bksim run %s %s --set model.%s=1 -o %s --quiet --force", chains[k][0],
                     chains[k][1], column ? "cols" : "rows", lattice);
            assert_int_equal(run_command(cmd, NULL), 0);
            assert_same_output(chain, lattice);
            snprintf(cmd, sizeof cmd, "./bksim info %s", lattice);
            assert_int_equal(run_command(cmd, &lattice_info), 0);
            /* The stats' method line ("exact (auto)"), after the config's own "method = auto". */
            const char *method = strstr(chain_info, "    method   "), *same = strstr(lattice_info, "    method   ");
            assert_non_null(method);
            assert_non_null(same);
            assert_memory_equal(same, method, (size_t)(strchr(method, '\n') - method));
            if (column && k == 0)
                assert_non_null(strstr(lattice_info, "lattice      10 x 1 blocks (block i at lattice row i / 1, "
                                                     "column i % 1)\n"));
            free(lattice_info);
            lattice_info = NULL;
        }
        free(chain_info);
        chain_info = NULL;
    }
}

/* --- the other commands ---------------------------------------------------------------- */

static void test_commands(void **state)
{
    (void)state;
    char path[512], out[512], cmd[2048];
    char *text = NULL;
    snprintf(path, sizeof path, "%s/good.ini", tmpdir);
    snprintf(out, sizeof out, "%s/good.h5", tmpdir);
    write_good_config(path, NULL, NULL);

    snprintf(cmd, sizeof cmd, "./bksim check %s", path);
    expect_command(cmd, 0, "ok");

    /* --set changes the run: a shorter t_end. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --set run.t_end=0.65 --quiet", path, out);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_true(path_exists(out));
    double *time = NULL;
    size_t rows, cols;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_doubles(out, "/time", &time, &rows, &cols, &err), BK_OK);
    assert_close(time[rows - 1], 0.65, 0, 0);
    free(time);

    snprintf(cmd, sizeof cmd, "./bksim info %s", out);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "t_end"));
    assert_non_null(strstr(text, "--set run.t_end=0.65")); /* the config as run */
    free(text);

    snprintf(cmd, sizeof cmd, "./bksim export %s --datasets time,x,v --block 0", out);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_true(text[0] == '#');
    free(text);
    snprintf(cmd, sizeof cmd, "./bksim export %s --transitions", out);
    expect_command(cmd, 0, "0.5886");
    snprintf(cmd, sizeof cmd, "./bksim export %s --block 7", out);
    assert_int_equal(run_command(cmd, NULL), 1);
    snprintf(cmd, sizeof cmd, "./bksim info %s/nothing.h5", tmpdir);
    assert_int_equal(run_command(cmd, NULL), 1);

    /* stats: a run's output holds its catalogs (case A: one slip in 0.65 s), the rupture catalog
     * by default, the time-window catalog with --table events; without one, a message names
     * /ruptures and /events; a table of t_start and magnitude written elsewhere is read. */
    snprintf(cmd, sizeof cmd, "./bksim stats %s --json", out);
    expect_command(cmd, 0, "\"n_events\": 1,");
    expect_command(cmd, 0, "\"table\": \"ruptures\", \"table_fallback\": false,");
    snprintf(cmd, sizeof cmd, "./bksim stats %s", out);
    expect_command(cmd, 0, "  /ruptures (the rupture catalog): 1 rows");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --table events --json", out);
    expect_command(cmd, 0, "\"table\": \"events\", \"table_fallback\": false,");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --table=/events", out);
    expect_command(cmd, 0, "  /events (the time-window catalog): 1 rows");
    /* A table the file lacks: exit 1, naming the file and the table; no name: usage. */
    snprintf(cmd, sizeof cmd, "./bksim stats %s --table transitions_catalog", out);
    expect_command(cmd, 1, "good.h5: no /transitions_catalog table");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --table", out);
    expect_command(cmd, 2, "unknown or incomplete option '--table'");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --table=", out);
    expect_command(cmd, 2, "--table needs a table name");
    char bare[512];
    snprintf(bare, sizeof bare, "%s/bare.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --set run.t_end=0.65 --set output.events=false --quiet", path,
             bare);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim stats %s", bare);
    expect_command(cmd, 1, "bare.h5: no /ruptures table (the rupture catalog), and no /events");
    char catalog[512];
    snprintf(catalog, sizeof catalog, "%s/catalog.h5", tmpdir);
    typedef struct { double t_start, magnitude; } row;
    row rows_out[40];
    for (size_t k = 0; k < 40; ++k) /* 2.0 x 20, 2.1 x 10, 2.2 x 5, 2.3 x 5 */
        rows_out[k] = (row){(double)k, k < 20 ? 2.0 : k < 30 ? 2.1 : k < 35 ? 2.2 : 2.3};
    hid_t file = H5Fcreate(catalog, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t type = H5Tcreate(H5T_COMPOUND, sizeof(row));
    H5Tinsert(type, "t_start", HOFFSET(row, t_start), H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "magnitude", HOFFSET(row, magnitude), H5T_NATIVE_DOUBLE);
    hsize_t dims[1] = {40};
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t dset = H5Dcreate2(file, "events", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(H5Dwrite(dset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows_out) >= 0);
    H5Dclose(dset);
    H5Sclose(space);
    H5Tclose(type);
    H5Fclose(file);
    snprintf(cmd, sizeof cmd, "./bksim stats %s --mc 2.0 --json", catalog);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "\"n_events\": 40"));
    assert_non_null(strstr(text, "\"b_value\""));
    /* Another program's catalog has only /events: the default falls back to it, and says so. */
    assert_non_null(strstr(text, "\"table\": \"events\", \"table_fallback\": true,"));
    free(text);
    snprintf(cmd, sizeof cmd, "./bksim stats %s --mc 2.0", catalog);
    expect_command(cmd, 0, "  /events (the time-window catalog: the file has no /ruptures): 40 rows");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --table ruptures", catalog);
    expect_command(cmd, 1, "catalog.h5: no /ruptures table");
    /* t_start 0..39: --from 10 --to=30 keeps 20 of them. */
    snprintf(cmd, sizeof cmd, "./bksim stats %s --mc 2.0 --json --from 10 --to=30", catalog);
    expect_command(cmd, 0, "\"n_outside_window\": 20, \"n_events\": 20");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --bin -1", catalog);
    assert_int_equal(run_command(cmd, NULL), 2);
    snprintf(cmd, sizeof cmd, "./bksim stats %s --from 1e3x", catalog);
    expect_command(cmd, 2, "--from needs a time in s, got '1e3x'");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --from 30 --to 10", catalog);
    expect_command(cmd, 2, "time window [30, 10) s");
    /* The mainshock sequences' options reach the report: the five 2.3s at t = 35..39 s are the
     * candidates, the first the largest within 5 s (the others tie with an earlier one), and
     * its window ends past the catalog's span (t = 39 s). */
    snprintf(cmd, sizeof cmd, "./bksim stats %s --mc 2.0 --mainshock 2.3 --window=5 --bootstrap 0", catalog);
    expect_command(cmd, 0, "mainshock sequences (mainshocks: M >= 2.3, the largest within +-5 s; events M >= Mc = 2):\n"
                           "  mainshocks: 0 of 5 events at or above 2.3 (4 with a larger or earlier equal event within "
                           "+-5 s, 1 too near the span's ends)");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --mc 2.0 --mainshock auto --window auto --json --bootstrap 0", catalog);
    expect_command(cmd, 0, "\"sequences\": ");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --window 0", catalog);
    expect_command(cmd, 2, "--window needs 'auto' or a time > 0 in s, got '0'");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --mainshock big", catalog);
    expect_command(cmd, 2, "--mainshock needs 'auto' or a magnitude, got 'big'");
    snprintf(cmd, sizeof cmd, "./bksim summary %s --mainshock 2", tmpdir);
    expect_command(cmd, 2, "unknown or incomplete option '--mainshock'");
    assert_int_equal(run_command("./bksim stats", NULL), 2);

    const char *helps[] = {"run", "check", "info", "export", "keys", "stats", "summary"};
    for (size_t k = 0; k < 7; ++k) {
        snprintf(cmd, sizeof cmd, "./bksim %s --help", helps[k]);
        expect_command(cmd, 0, "usage: bksim");
    }
    expect_command("./bksim stats --help", 0, "  --table NAME      the catalog table: events");
    expect_command("./bksim --help", 0, "stats FILE [--table NAME]");
    assert_int_equal(run_command("./bksim frobnicate", NULL), 2);
    assert_int_equal(run_command("./bksim", NULL), 2);
    assert_int_equal(run_command("./bksim run", NULL), 2);
    assert_int_equal(run_command("./bksim --version", &text), 0);
    assert_non_null(strstr(text, BKSIM_VERSION));
    free(text);
    expect_command("./bksim keys", 0, "mu_d");
}

/* Progress of a long run on a terminal: simulated time, events so far and per second, and
 * an ETA, on stderr; silent with --quiet and when stderr is not a terminal (script(1) gives
 * the run a terminal). The run takes about 2 s: progress shows after the first second. */
static void test_progress_on_terminal(void **state)
{
    (void)state;
    char cmd[2048];
    char *text = NULL;
    const char *run = "./bksim run configs/chains/carlson_langer_100.ini --force --set run.t_end=1600 -o";
    snprintf(cmd, sizeof cmd, "script -qec \"%s %s/tty.h5\" /dev/null", run, tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    const char *line = strstr(text, "bksim: t = ");
    if (!line)
        print_error("%s\n", text);
    assert_non_null(line);
    assert_non_null(strstr(line, " of 1600 s ("));
    assert_non_null(strstr(line, " events ("));
    assert_non_null(strstr(line, " per s), "));
    assert_non_null(strstr(line, " elapsed, ETA "));
    assert_non_null(strstr(text, "tty.h5: ")); /* the summary follows on its own line */
    free(text);

    snprintf(cmd, sizeof cmd, "script -qec \"%s %s/quiet.h5 --quiet\" /dev/null", run, tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_string_equal(text, "");
    free(text);

    snprintf(cmd, sizeof cmd, "%s %s/pipe.h5 2>%s/pipe.err >/dev/null && cat %s/pipe.err", run, tmpdir, tmpdir,
             tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_string_equal(text, "");
    free(text);
}

/* 1,000 blocks: a summary of the phases in a few lines; the table behind --blocks. */
static void test_info_at_chain_scale(void **state)
{
    (void)state;
    char out[512], cmd[1024];
    snprintf(out, sizeof out, "%s/chain1000.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk1000_coulomb.ini -q -o %s --set run.t_end=0.5", out);
    assert_int_equal(run_command(cmd, NULL), 0);
    char *text = NULL;
    snprintf(cmd, sizeof cmd, "./bksim info %s", out);
    assert_int_equal(run_command(cmd, &text), 0);
    size_t lines = 0;
    for (const char *c = text; *c; ++c)
        lines += *c == '\n';
    print_message("bksim info of 1,000 blocks: %zu lines\n", lines);
    assert_true(lines < 100);
    assert_non_null(strstr(text, "phases per block: 1000 blocks, "));
    assert_non_null(strstr(text, "slips per block: min "));
    assert_non_null(strstr(text, "most active: block "));
    assert_null(strstr(text, "block 999:"));
    free(text);
    snprintf(cmd, sizeof cmd, "./bksim info %s --blocks", out);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "    block 0: "));
    assert_non_null(strstr(text, "    block 999: "));
    free(text);
    snprintf(cmd, sizeof cmd, "./bksim info %s --block", out);
    expect_command(cmd, 2, "unknown option '--block'");
}

/* A damaged file is reported as such: truncated, or hand-edited inconsistent. */
static void test_damaged_files(void **state)
{
    (void)state;
    char good[512], cmd[2048];
    snprintf(good, sizeof good, "%s/intact.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -o %s --quiet", good);
    assert_int_equal(run_command(cmd, NULL), 0);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(good, &err), BK_OK);
    char *text = NULL;

    /* Truncated to half its size. */
    snprintf(cmd, sizeof cmd, "cp %s %s/truncated.h5 && truncate -s $(( $(stat -c %%s %s) / 2 )) %s/truncated.h5",
             good, tmpdir, good, tmpdir);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim info %s/truncated.h5", tmpdir);
    assert_int_equal(run_command(cmd, &text), 1);
    free(text);

    /* Hand-corrupted: a time series shortened, and time made non-monotonic (h5 tools would do
     * this by hand; the library's own writer does it here through the HDF5 API). */
    char edited[512];
    snprintf(edited, sizeof edited, "%s/edited.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "cp %s %s", good, edited);
    assert_int_equal(run_command(cmd, NULL), 0);
    hid_t file = H5Fopen(edited, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t time = H5Dopen2(file, "time", H5P_DEFAULT);
    double backwards = 0.05; /* row 1000 is near t = 0.1 s */
    hsize_t row = 1000, one = 1;
    hid_t space = H5Dget_space(time), mem = H5Screate_simple(1, &one, NULL);
    H5Sselect_hyperslab(space, H5S_SELECT_SET, &row, NULL, &one, NULL);
    assert_true(H5Dwrite(time, H5T_NATIVE_DOUBLE, mem, space, H5P_DEFAULT, &backwards) >= 0);
    H5Sclose(mem);
    H5Sclose(space);
    H5Dclose(time);
    H5Fclose(file);
    assert_int_equal(bk_h5_verify(edited, &err), BK_ERR_DAMAGED);
    assert_non_null(strstr(err.message, "/time is not strictly increasing at row 1000"));
    snprintf(cmd, sizeof cmd, "./bksim info %s", edited);
    expect_command(cmd, 1, "DAMAGED");

    snprintf(cmd, sizeof cmd, "cp %s %s", good, edited);
    assert_int_equal(run_command(cmd, NULL), 0);
    file = H5Fopen(edited, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t v = H5Dopen2(file, "v", H5P_DEFAULT);
    hsize_t dims[2] = {100, 1};
    assert_true(H5Dset_extent(v, dims) >= 0);
    H5Dclose(v);
    H5Fclose(file);
    assert_int_equal(bk_h5_verify(edited, &err), BK_ERR_DAMAGED);
    assert_non_null(strstr(err.message, "/v has 100 rows"));
}

/* The file at path still holds exactly text. */
static void assert_file_holds(const char *path, const char *text)
{
    char *held = file_contents(path);
    assert_non_null(held);
    assert_string_equal(held, text);
    free(held);
}

/* `-o` never turns a file that is not bksim's into HDF5, whatever the flags: the run's own
 * config, a text file, a foreign .part; a bksim output is replaced as before.  `-o DIR/` and
 * `-o DIR` (an existing directory) write DIR/<config stem>.h5. */
static void test_never_replaces_others_files(void **state)
{
    (void)state;
    char cmd[4096], config[512], notes[512], out[512];
    snprintf(config, sizeof config, "%s/c.ini", tmpdir);
    snprintf(cmd, sizeof cmd, "cp configs/paper/case_a_coulomb.ini %s", config);
    assert_int_equal(run_command(cmd, NULL), 0);
    char *config_text = file_contents(config);
    assert_non_null(config_text);

    for (int force = 0; force < 2; ++force) {
        snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --quiet%s", config, config, force ? " --force" : "");
        expect_command(cmd, 2, "c.ini: exists and is not a bksim output (not an HDF5 file): bksim replaces only "
                               "its own outputs, whatever the flags");
        assert_file_holds(config, config_text);
        snprintf(notes, sizeof notes, "%s/notes.txt", tmpdir);
        assert_int_equal(write_text(notes, "my notes\n"), 0);
        snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --quiet%s", config, notes, force ? " --force" : "");
        expect_command(cmd, 2, "notes.txt: exists and is not a bksim output");
        assert_file_holds(notes, "my notes\n");
    }
    char part[600];
    snprintf(out, sizeof out, "%s/o.h5", tmpdir);
    snprintf(part, sizeof part, "%s.part", out);
    assert_int_equal(write_text(part, "not a run\n"), 0);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --quiet --force", config, out);
    expect_command(cmd, 2, "o.h5.part: exists and is not a bksim output");
    assert_file_holds(part, "not a run\n");
    assert_false(path_exists(out));
    remove(part);

    /* bksim's own output: replaced on a rerun, with or without --force. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --quiet && ./bksim run %s -o %s --quiet --force "
                              "&& ./bksim run %s -o %s --quiet", config, out, config, out, config, out);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_false(path_exists(part));

    /* A .part to continue (a finished run's, with its end checkpoint) whose final name a
     * file of the user's took meanwhile: --restart and --resume refuse before running. */
    char other[600], other_part[700];
    snprintf(other, sizeof other, "%s/other.h5", tmpdir);
    snprintf(other_part, sizeof other_part, "%s.part", other);
    snprintf(cmd, sizeof cmd, "cp %s %s", out, other_part);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_int_equal(write_text(other, "results of another program\n"), 0);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s", other_part);
    expect_command(cmd, 2, "other.h5: exists and is not a bksim output");
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --resume", config, other);
    expect_command(cmd, 2, "other.h5: exists and is not a bksim output");
    assert_file_holds(other, "results of another program\n");
    assert_true(path_exists(other_part));

    /* Directories. */
    char dir[600], expected[700];
    snprintf(dir, sizeof dir, "%s/new/", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --quiet", config, dir);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(expected, sizeof expected, "%sc.h5", dir);
    assert_true(path_exists(expected));
    snprintf(expected, sizeof expected, "%s.part", dir);
    assert_false(path_exists(expected));
    remove_tree(dir);
    snprintf(dir, sizeof dir, "%s/existing", tmpdir);
    assert_int_equal(mkdir(dir, 0700), 0);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", config, dir);
    expect_command(cmd, 0, "existing/c.h5: ");
    snprintf(expected, sizeof expected, "%s/c.h5", dir);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(expected, &err), BK_OK);
    remove_tree(dir);
    free(config_text);
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

/* Sizes that mean what they say: a run of two sample rows of 100 blocks makes a file of its
 * size (chunks sized to the run: it was 5.4 MB of 1 MiB chunks for 0.3 MB of content), a
 * file never passes [output] max_bytes (chunks and HDF5's metadata included; the run stops
 * with the key named), and `bksim check` says what the sample rows will weigh. */
static void test_sizes_mean_what_they_say(void **state)
{
    (void)state;
    const char *scene = "configs/chains/random_strength_100.ini --quiet --set output.interval=10 --set run.t_end=10";
    char out[512], cmd[2048], part[600];
    snprintf(out, sizeof out, "%s/small.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, out);
    assert_int_equal(run_command(cmd, NULL), 0);
    long whole = file_size(out);
    print_message("2 rows of 100 blocks with their catalog: %ld bytes\n", whole);
    assert_true(whole > 0 && whole < 400000);
    static const double bounds[] = {1e5, 2e5};
    for (size_t k = 0; k < 2; ++k) {
        snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --set output.max_bytes=%g", scene, out, bounds[k]);
        expect_command(cmd, 1, "[output] max_bytes = ");
        snprintf(part, sizeof part, "%s.part", out);
        long size = file_size(part);
        print_message("max_bytes = %g: the .part holds %ld bytes\n", bounds[k], size);
        assert_true(size > 0 && (double)size <= bounds[k]);
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE);
        remove(part);
    }
    /* The look ahead counts whole chunks, some twice while HDF5's chunk cache holds them: a
     * bound a quarter above the whole file lets the run finish. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --set output.max_bytes=%ld", scene, out, whole + whole / 4);
    assert_int_equal(run_command(cmd, NULL), 0);
    expect_command("./bksim check configs/paper/case_a_coulomb.ini", 0,
                   "case_a_coulomb.ini: output: about 4.1e+06 B of sample rows (50002 rows of 82 B, 8.2e+05 B per "
                   "simulated second), plus 38 B per transition");
}

/* README's config reference is exactly what `bksim keys` prints. */
static void test_readme_reference_current(void **state)
{
    (void)state;
    char *keys = NULL;
    assert_int_equal(run_command("./bksim keys", &keys), 0);
    FILE *f = fopen("README.md", "r");
    assert_non_null(f);
    char *readme = calloc(1, 1 << 20);
    assert_non_null(readme);
    size_t len = fread(readme, 1, (1 << 20) - 1, f);
    fclose(f);
    readme[len] = '\0';
    const char *begin = strstr(readme, "<!-- keys:begin -->\n");
    const char *end = strstr(readme, "<!-- keys:end -->");
    assert_non_null(begin);
    assert_non_null(end);
    begin += strlen("<!-- keys:begin -->\n");
    if ((size_t)(end - begin) != strlen(keys) || strncmp(begin, keys, strlen(keys)) != 0)
        print_error("README.md's config reference is stale: run scripts/update_readme_keys.sh\n");
    assert_int_equal((size_t)(end - begin), strlen(keys));
    assert_int_equal(strncmp(begin, keys, strlen(keys)), 0);
    free(readme);
    free(keys);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paper_configs),
        cmocka_unit_test(test_paper_rate_state),
        cmocka_unit_test(test_lattice_of_one_line_is_a_chain),
        cmocka_unit_test(test_commands),
        cmocka_unit_test(test_progress_on_terminal),
        cmocka_unit_test(test_info_at_chain_scale),
        cmocka_unit_test(test_damaged_files),
        cmocka_unit_test(test_never_replaces_others_files),
        cmocka_unit_test(test_sizes_mean_what_they_say),
        cmocka_unit_test(test_readme_reference_current),
    };
    return cmocka_run_group_tests_name("cli", tests, setup, teardown);
}
