/* The bksim command line end to end, as a user and a batch script meet it: the paper's
 * configs give the closed-form transitions in the HDF5 file; every bad input gives a
 * clear message, exit status 2 and no output file. Runs ./bksim from the repository root. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <hdf5.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "command.h"
#include "exact_single.h"
#include "files.h"
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

/* --- bad input: clear message, exit 2, no file ----------------------------------------- */

static const char *const good_config =
    "[model]\n"
    "n_blocks = 1\n"
    "[block]\n"
    "mass = 1\n"
    "driver_stiffness = 1e4\n"
    "[friction]\n"
    "law = coulomb\n"
    "mu_s = 0.6\n"
    "mu_d = 0.5\n"
    "[driver]\n"
    "velocity = 1e-3\n"
    "[run]\n"
    "t_end = 0.7\n";

/* Write good_config with `line` replaced by `replacement` (NULL: dropped). */
static void write_config(const char *path, const char *line, const char *replacement)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    const char *p = good_config;
    while (*p) {
        const char *eol = strchr(p, '\n');
        size_t len = (size_t)(eol - p);
        if (line && strlen(line) == len && strncmp(p, line, len) == 0) {
            if (replacement)
                fprintf(f, "%s\n", replacement);
        } else {
            fprintf(f, "%.*s\n", (int)len, p);
        }
        p = eol + 1;
    }
    fclose(f);
}

typedef struct bad_case {
    const char *line, *replacement;
    const char *expect; /* substring of the message */
} bad_case;

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

static void test_bad_inputs(void **state)
{
    (void)state;
    const bad_case cases[] = {
        {"mass = 1", "mass = 0", "bad.ini:4: [block] mass:"},
        {"mass = 1", "mass = -2", "bad.ini:4: [block] mass:"},
        {"mass = 1", "mass = nan", "bad.ini:4: [block] mass:"},
        {"mass = 1", "mass = 1 # kg", "bad.ini:4: [block] mass:"},
        {"mass = 1", NULL, "bad.ini: [block] mass: required key missing"},
        {"mu_d = 0.5", "mu_d = 0.7", "bad.ini:9: [friction] mu_d: must be <= mu_s (0.6), got 0.7"},
        {"driver_stiffness = 1e4", "driver_stiffness = -1e4", "bad.ini:5: [block] driver_stiffness:"},
        {"t_end = 0.7", "t_end = 0", "bad.ini:13: [run] t_end:"},
        {"t_end = 0.7", "t_end = -1", "bad.ini:13: [run] t_end:"},
        {"t_end = 0.7", NULL, "bad.ini: [run] t_end: required key missing"},
        {"velocity = 1e-3", "velocity = 1e-3\nspeed = 2", "bad.ini:12: [driver] speed:"},
        {"law = coulomb", "law = magic", "bad.ini:7: [friction] law:"},
        {"[model]", "[modle]", "bad.ini:1:"},
        {"velocity = 1e-3", "velocities = 1e-3, 0\ndurations = 1", "bad.ini:12: [driver] durations: has 1 values, velocities has 2"},
        {"mass = 1", "mass = 1\ndamping = -1", "bad.ini:5: [block] damping: out of range, got -1"},
        {"[model]", "[model]\ncoupling_damping = -3", "bad.ini:2: [model] coupling_damping: out of range, got -3"},
        {"mass = 1", "mass = 1\ndamping = normal(1, -0.5)", "bad.ini:5: [block] damping: normal(1, -0.5) has a negative width"},
        {"n_blocks = 1", "n_blocks = 6\nrows = 2\ncols = 4", "bad.ini:2: [model] n_blocks: 6 blocks, but rows * cols = 2 * 4 = 8"},
        {"n_blocks = 1", "n_blocks = 6\nrows = 4", "bad.ini:3: [model] rows: 4 does not divide n_blocks = 6"},
        {"n_blocks = 1", "rows = 3", "bad.ini: [model] n_blocks: required key missing (allowed: 1 <= n_blocks"},
        {"n_blocks = 1", "rows = 0\ncols = 4", "bad.ini:2: [model] rows: out of range, got 0"},
        {"n_blocks = 1", "rows = 2\ncols = 2.5", "bad.ini:3: [model] cols:"},
        {"n_blocks = 1", "rows = 2000\ncols = 2000", "bad.ini:3: [model] cols: rows * cols = 4000000 blocks (allowed: at most 1000000)"},
        {"n_blocks = 1", "n_blocks = 4\nboundary_rows = twisted", "bad.ini:3: [model] boundary_rows:"},
    };
    char path[512], out[512], cmd[2048], cwd[1024];
    assert_non_null(getcwd(cwd, sizeof cwd));
    snprintf(path, sizeof path, "%s/bad.ini", tmpdir);
    snprintf(out, sizeof out, "%s/never.h5", tmpdir);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        write_config(path, cases[k].line, cases[k].replacement);
        snprintf(cmd, sizeof cmd, "cd %s && %s/%s run bad.ini -o %s", tmpdir, cwd, bksim_binary(), out);
        char *text = NULL;
        int status = run_command(cmd, &text);
        if (status != 2 || !strstr(text, cases[k].expect))
            print_error("case %zu: status %d, output:\n%s\nexpected: %s\n", k, status, text,
                        cases[k].expect);
        assert_int_equal(status, 2);
        assert_non_null(strstr(text, cases[k].expect));
        assert_false(path_exists(out));
        char part[600];
        snprintf(part, sizeof part, "%s.part", out);
        assert_false(path_exists(part));
        free(text);
        /* check says the same */
        snprintf(cmd, sizeof cmd, "cd %s && %s/%s check bad.ini", tmpdir, cwd, bksim_binary());
        assert_int_equal(run_command(cmd, NULL), 2);
    }
    /* An unreadable config: I/O failure, exit 1, nothing written. */
    snprintf(cmd, sizeof cmd, "./bksim run %s/missing.ini -o %s", tmpdir, out);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 1);
    assert_non_null(strstr(text, "missing.ini"));
    assert_false(path_exists(out));
    free(text);
    /* A bad --set names itself as the location. */
    write_config(path, NULL, NULL);
    snprintf(cmd, sizeof cmd, "./bksim run %s --set block.mass=0 -o %s", path, out);
    assert_int_equal(run_command(cmd, &text), 2);
    assert_non_null(strstr(text, "--set block.mass=0: [block] mass:"));
    assert_false(path_exists(out));
    free(text);
}

/* --- every key rejects every kind of bad value the same way ----------------------------- */

typedef struct base_section {
    const char *name;
    const char *lines[12];
} base_section;

/* A valid config for `law` (NULL: coulomb), or a prescribed scene. */
static size_t base_config(const char *law, int prescribed, base_section *out)
{
    static const base_section chain[] = {
        {"model", {"n_blocks = 1"}},
        {"block", {"mass = 1", "driver_stiffness = 1e4"}},
        {"friction", {0}},
        {"driver", {"velocity = 1e-3"}},
        {"solver", {0}},
        {"output", {0}},
        {"run", {"t_end = 0.01"}},
    };
    size_t n = 0;
    if (prescribed) {
        out[n++] = (base_section){"prescribed", {"slip_rates = 1e-3", "durations = 0.01"}};
    } else {
        for (size_t k = 0; k < sizeof chain / sizeof chain[0]; ++k)
            out[n++] = chain[k];
    }
    base_section friction = {"friction", {"law = coulomb", "mu_s = 0.6", "mu_d = 0.5"}};
    if (law && strcmp(law, "carlson_langer") == 0)
        friction = (base_section){"friction", {"law = carlson_langer", "F0 = 5", "sigma = 0.2", "alpha = 3"}};
    else if (law && strcmp(law, "rate_state") == 0)
        friction = (base_section){"friction", {"law = rate_state"}};
    else if (law && strncmp(law, "dieterich_ruina", 15) == 0)
        friction = (base_section){"friction", {law[16] == 'a' ? "law = dieterich_ruina_aging" : "law = dieterich_ruina_slip",
                                               "a = 0.05", "b = 0.06", "Dc = 1e-5", "V0 = 1e-3", "f0 = 0.45"}};
    for (size_t k = 0; k < n; ++k)
        if (strcmp(out[k].name, "friction") == 0)
            out[k] = friction;
    if (prescribed)
        out[n++] = friction;
    return n;
}

/* Write the base with `key = value` in [section] (replacing the base's own line for key);
 * returns the line number of that line. */
static int write_with(const char *path, const base_section *base, size_t n, const char *section,
                      const char *key, const char *value)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    int line = 0, at = 0, placed = 0;
    size_t key_len = strlen(key);
    for (size_t k = 0; k < n; ++k) {
        fprintf(f, "[%s]\n", base[k].name);
        ++line;
        for (size_t j = 0; j < 12 && base[k].lines[j]; ++j) {
            const char *l = base[k].lines[j];
            if (strcmp(base[k].name, section) == 0 && strncmp(l, key, key_len) == 0 && l[key_len] == ' ')
                continue;
            fprintf(f, "%s\n", l);
            ++line;
        }
        if (strcmp(base[k].name, section) == 0) {
            fprintf(f, "%s = %s\n", key, value);
            at = ++line;
            placed = 1;
        }
    }
    if (!placed) {
        fprintf(f, "[%s]\n%s = %s\n", section, key, value);
        at = line + 2;
    }
    fclose(f);
    return at;
}

/* The message a bad value of this kind must get, or NULL when the value is acceptable on
 * its own (a cross-key rule may still reject it, but not as a malformed value). */
static const char *expected_complaint(bk_key_kind kind, const bk_param *param, const char *value, char *buf,
                                      size_t len)
{
    char *end = NULL;
    double x = strtod(value, &end);
    int numeric = *value && end && *end == '\0' && isfinite(x);
    switch (kind) {
    case BK_KEY_NUMBER:
    case BK_KEY_INTEGER: {
        char range[256];
        bk_param_format_range(param, range, sizeof range);
        int integral = numeric && x == floor(x) && !strchr(value, 'e') && !strchr(value, '.');
        if (!numeric || (kind == BK_KEY_INTEGER && !integral))
            snprintf(buf, len, "%s \"%s\"", kind == BK_KEY_INTEGER ? "not an integer:" : "not a number:", value);
        else if (!bk_param_in_range(param, x))
            snprintf(buf, len, "out of range, got %s (allowed: %s", value, range);
        else
            return NULL;
        return buf;
    }
    case BK_KEY_LIST:
        if (!*value)
            snprintf(buf, len, "empty list");
        else if (!numeric || !bk_param_in_range(param, x))
            snprintf(buf, len, "bad value \"%s\" (item 1)", value);
        else
            return NULL;
        return buf;
    case BK_KEY_BOOLEAN:
        if (strcmp(value, "0") == 0)
            return NULL;
        snprintf(buf, len, "not a boolean: \"%s\"", value);
        return buf;
    case BK_KEY_CHOICE:
        snprintf(buf, len, "unknown value \"%s\"", value);
        return buf;
    case BK_KEY_TEXT:
        if (*value)
            return NULL;
        snprintf(buf, len, "empty value");
        return buf;
    case BK_KEY_FIELDS:
        snprintf(buf, len, "unknown field \"%s\"", *value ? value : "(empty)");
        return buf;
    }
    return NULL;
}

static long check_key(const char *law, int prescribed, const char *section, bk_key_kind kind, const bk_param *param)
{
    char out_of_range[64];
    if (isfinite(param->max))
        snprintf(out_of_range, sizeof out_of_range, "%.17g", param->max * 10 + 1);
    else if (isfinite(param->min))
        snprintf(out_of_range, sizeof out_of_range, "%.17g", param->min - 1);
    else
        snprintf(out_of_range, sizeof out_of_range, "1e400");
    const char *values[] = {"", "abc", "nan", "inf", "-inf", "-1", "0", out_of_range};
    base_section base[10];
    size_t n = base_config(law, prescribed, base);
    char path[512], out[512], part[600], cmd[2048];
    snprintf(path, sizeof path, "%s/key.ini", tmpdir);
    snprintf(out, sizeof out, "%s/key.h5", tmpdir);
    snprintf(part, sizeof part, "%s.part", out);
    long rejected = 0;
    for (size_t v = 0; v < sizeof values / sizeof values[0]; ++v) {
        int line = write_with(path, base, n, section, param->key, values[v]);
        char complaint[512], prefix[600];
        const char *expected = expected_complaint(kind, param, values[v], complaint, sizeof complaint);
        snprintf(prefix, sizeof prefix, "%s:%d: [%s] %s: ", path, line, section, param->key);
        bk_config *c = NULL;
        bk_error err = {0};
        int rc = bk_config_load_file(path, NULL, 0, &c, &err);
        bk_config_free(c);
        if (!expected) {
            /* Acceptable as a value: anything rejected must be a cross-key rule. */
            if (rc != BK_OK && strncmp(err.message, prefix, strlen(prefix)) == 0 &&
                (strstr(err.message, "not a number") || strstr(err.message, "out of range")))
                fail_msg("%s = \"%s\" was rejected as malformed: %s", param->key, values[v], err.message);
            continue;
        }
        char full[1200];
        snprintf(full, sizeof full, "%s%s", prefix, expected);
        if (rc != BK_ERR_CONFIG || strncmp(err.message, full, strlen(full)) != 0)
            fail_msg("[%s] %s = \"%s\" (law %s):\n got:      %s\n expected: %s...", section, param->key,
                     values[v], law ? law : "-", err.message, full);
        if (!strstr(err.message, "(allowed: "))
            fail_msg("no allowed range in: %s", err.message);
        /* The CLI: exit status 2, the same message, and no file. */
        snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", path, out);
        char *text = NULL;
        assert_int_equal(run_command(cmd, &text), 2);
        assert_non_null(strstr(text, full));
        free(text);
        assert_false(path_exists(out));
        assert_false(path_exists(part));
        ++rejected;
    }
    return rejected;
}

static void test_every_key_rejects_bad_values(void **state)
{
    (void)state;
    long rejected = 0, keys = 0;
    bk_key_info info;
    for (size_t i = 0; bk_config_key(i, &info) == 0; ++i, ++keys)
        rejected += check_key(NULL, strcmp(info.section, "prescribed") == 0, info.section, info.kind, info.param);
    for (const bk_friction_law *const *l = bk_friction_laws(); *l; ++l)
        for (size_t p = 0; p < (*l)->n_params; ++p, ++keys)
            rejected += check_key((*l)->name, 0, "friction", BK_KEY_NUMBER, &(*l)->params[p]);
    print_message("%ld keys, %ld bad values rejected with exact messages, exit 2, no file\n", keys, rejected);
    assert_true(keys > 50 && rejected > 5 * keys);
}

/* A distribution's bad input through the CLI: file:line, exit 2, no output file. */
static void test_distribution_errors(void **state)
{
    (void)state;
    const struct {
        const char *set, *message;
    } cases[] = {
        {"friction.mu_s=normal(0.6, -0.01)", "[friction] mu_s: normal(0.6, -0.01) has a negative width (allowed: sd >= 0)"},
        {"block.mass=uniform(2, 1)", "[block] mass: uniform(2, 1) has a negative width (allowed: a <= b)"},
        {"block.mass=normal(0.01, 1)", "for block "},
        {"driver.velocity=uniform(1e-3, 2e-3)", "[driver] velocity: a distribution is drawn per block"},
    };
    char out[512], cmd[2048];
    snprintf(out, sizeof out, "%s/drawn.h5", tmpdir);
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk10_coulomb.ini -o %s --set '%s'", out, cases[k].set);
        expect_command(cmd, 2, cases[k].message);
        expect_command(cmd, 2, "--set ");
        assert_false(path_exists(out));
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
    write_config(path, NULL, NULL);

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

    /* stats: a run's output holds its catalog (case A: one slip in 0.65 s); without one, a
     * message names /events; a table of t_start and magnitude written elsewhere is read. */
    snprintf(cmd, sizeof cmd, "./bksim stats %s --json", out);
    expect_command(cmd, 0, "\"n_events\": 1,");
    char bare[512];
    snprintf(bare, sizeof bare, "%s/bare.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --set run.t_end=0.65 --set output.events=false --quiet", path,
             bare);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim stats %s", bare);
    expect_command(cmd, 1, "/events");
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
    free(text);
    /* t_start 0..39: --from 10 --to=30 keeps 20 of them. */
    snprintf(cmd, sizeof cmd, "./bksim stats %s --mc 2.0 --json --from 10 --to=30", catalog);
    expect_command(cmd, 0, "\"n_outside_window\": 20, \"n_events\": 20");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --bin -1", catalog);
    assert_int_equal(run_command(cmd, NULL), 2);
    snprintf(cmd, sizeof cmd, "./bksim stats %s --from 1e3x", catalog);
    expect_command(cmd, 2, "--from needs a time in s, got '1e3x'");
    snprintf(cmd, sizeof cmd, "./bksim stats %s --from 30 --to 10", catalog);
    expect_command(cmd, 2, "time window [30, 10) s");
    assert_int_equal(run_command("./bksim stats", NULL), 2);

    const char *helps[] = {"run", "check", "info", "export", "keys", "stats"};
    for (size_t k = 0; k < 6; ++k) {
        snprintf(cmd, sizeof cmd, "./bksim %s --help", helps[k]);
        expect_command(cmd, 0, "usage: bksim");
    }
    assert_int_equal(run_command("./bksim frobnicate", NULL), 2);
    assert_int_equal(run_command("./bksim", NULL), 2);
    assert_int_equal(run_command("./bksim run", NULL), 2);
    assert_int_equal(run_command("./bksim --version", &text), 0);
    assert_non_null(strstr(text, BKSIM_VERSION));
    free(text);
    expect_command("./bksim keys", 0, "mu_d");
}

/* A long run in a real child process, stopped by `signal` after a second. */
static int run_and_signal(const char *out, const char *signal_name, char **text)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/paper/case_c_coulomb.ini -o %s --quiet "
             "--set run.t_end=100000 --set output.interval=1e-3 & pid=$!; sleep 1; "
             "kill -%s $pid; wait $pid",
             out, signal_name);
    return run_command(cmd, text);
}

/* SIGTERM and SIGINT stop the run at the next step: the file stays "<out>.part", intact and
 * marked incomplete (complete = 0, t_reached); `bksim info` says so with exit status 3. */
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

static void test_interrupted_run_is_marked(void **state)
{
    (void)state;
    const char *signals[] = {"TERM", "INT"};
    for (size_t k = 0; k < 2; ++k) {
        char out[512], part[600], cmd[1024];
        snprintf(out, sizeof out, "%s/stopped_%s.h5", tmpdir, signals[k]);
        snprintf(part, sizeof part, "%s.part", out);
        char *text = NULL;
        assert_int_equal(run_and_signal(out, signals[k], &text), 1);
        assert_non_null(strstr(text, "interrupted"));
        free(text);
        assert_false(path_exists(out));
        assert_true(path_exists(part));
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE);
        snprintf(cmd, sizeof cmd, "./bksim info %s", part);
        assert_int_equal(run_command(cmd, &text), 3);
        assert_non_null(strstr(text, "complete     0 (run did not finish)"));
        assert_non_null(strstr(text, "error        run interrupted at t = "));
        free(text);
    }
}

/* SIGKILL leaves no chance to close: at most "<out>.part", which bksim reports as the output
 * of a run that did not finish, never as a complete file. */
static void test_killed_run_leaves_partial(void **state)
{
    (void)state;
    char out[512], part[600], cmd[1024];
    snprintf(out, sizeof out, "%s/killed.h5", tmpdir);
    snprintf(part, sizeof part, "%s.part", out);
    char *text = NULL;
    assert_int_equal(run_and_signal(out, "KILL", &text), 137);
    free(text);
    assert_false(path_exists(out));
    assert_true(path_exists(part));
    snprintf(cmd, sizeof cmd, "./bksim info %s", part);
    int status = run_command(cmd, &text);
    /* Readable (flushed chunk by chunk) and incomplete, or unreadable and said to be partial. */
    if (status == 3)
        assert_non_null(strstr(text, "did not finish"));
    else
        assert_true(status == 1 && strstr(text, "did not finish"));
    free(text);
}

/* While a run writes its .part: `bksim info` reports its progress (exit 3) instead of a
 * damaged file, and a second run with the same -o, a --restart and a reader are refused
 * with a message that names the owner, never HDF5's "Resource temporarily unavailable". */
static void test_running_output(void **state)
{
    (void)state;
    char out[512], cmd[2048];
    snprintf(out, sizeof out, "%s/running.h5", tmpdir);
    const char *scene = "configs/paper/case_b_coulomb.ini -q --set run.t_end=1e6 "
                        "--set solver.method=cvode_adams --set output.checkpoint_interval=2 "
                        "--set output.interval=0.01";
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s > /dev/null 2>&1 & echo $!", scene, out);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 0);
    long pid = strtol(text, NULL, 10);
    free(text);
    assert_true(pid > 0);
    /* Until a checkpoint has been flushed: then the progress is that checkpoint's. */
    int status = -1;
    double t = 0.0;
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    for (int tries = 0; tries < 600 && !(t > 0.0); ++tries) {
        nanosleep(&(struct timespec){0, 20000000L}, NULL);
        status = run_command(cmd, &text);
        const char *progress = strstr(text, "in progress, t = ");
        if (progress)
            t = strtod(progress + strlen("in progress, t = "), NULL);
        if (t > 0.0) {
            assert_int_equal(status, 3);
            assert_non_null(strstr(text, "transitions so far"));
            assert_non_null(strstr(text, "checkpoint   t = "));
        }
        free(text);
    }
    assert_true(t > 0.0);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, out);
    expect_command(cmd, 1, "another run owns this file");
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --force", scene, out);
    expect_command(cmd, 1, "another run owns this file");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part", out);
    expect_command(cmd, 1, "another run owns this file");
    snprintf(cmd, sizeof cmd, "./bksim export %s.part --transitions", out);
    expect_command(cmd, 1, "a run is still writing this file");
    /* The run was not disturbed: stopped now, it leaves a .part to continue from. */
    snprintf(cmd, sizeof cmd, "kill -TERM %ld; while kill -0 %ld 2>/dev/null; do sleep 0.02; done; "
             "./bksim info %s.part", pid, pid, out);
    status = run_command(cmd, &text);
    assert_int_equal(status, 3);
    assert_non_null(strstr(text, "did not finish"));
    assert_null(strstr(text, "in progress"));
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
}

/* A suspicious value draws a warning naming the key from check and run; --strict makes
 * each an error (exit 2, nothing written). */
static void test_warnings_and_strict(void **state)
{
    (void)state;
    char out[512], cmd[1024];
    snprintf(out, sizeof out, "%s/strict.h5", tmpdir);
    static const struct {
        const char *set, *needle;
    } cases[] = {
        {"driver.velocity=1", "[driver] velocity = 1 m/s is faster than the blocks' own slip speeds"},
        {"output.interval=0.05", "[output] interval = 0.05 s is longer than a slip"},
        {"solver.max_step=0.1", "[solver] max_step = 0.1 s is longer than the fastest natural period"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        snprintf(cmd, sizeof cmd, "./bksim check configs/paper/case_a_coulomb.ini --set %s", cases[k].set);
        expect_command(cmd, 0, cases[k].needle);
        expect_command(cmd, 0, "warning: configs/paper/case_a_coulomb.ini: ");
        snprintf(cmd, sizeof cmd, "./bksim check configs/paper/case_a_coulomb.ini --strict --set %s",
                 cases[k].set);
        expect_command(cmd, 2, "error (--strict): configs/paper/case_a_coulomb.ini: ");
        snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -q -o %s --strict --set %s",
                 out, cases[k].set);
        expect_command(cmd, 2, cases[k].needle);
        assert_false(path_exists(out));
        assert_false(path_exists(part_path(out)));
    }
    /* run warns too, and runs. */
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -q -o %s --set run.t_end=0.5 "
             "--set solver.max_step=0.1", out);
    expect_command(cmd, 0, "warning: ");
    assert_true(path_exists(out));
    expect_command("./bksim check configs/paper/case_a_coulomb.ini --strict", 0, ": ok: ");
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

/* A stopped run says how to go on: the --restart command and its checkpoint's time, or that
 * without a checkpoint it can only be run again; `bksim info` says the same of the .part;
 * and running the same command again says that it starts over. */
static void test_stop_messages(void **state)
{
    (void)state;
    char out[512], cmd[2048];
    const char *scene = "configs/paper/case_b_coulomb.ini --set run.t_end=1e4 --set solver.method=cvode_adams "
                        "--set run.wall_time_limit=0.3";
    snprintf(out, sizeof out, "%s/with_checkpoint.h5", tmpdir);
    /* The output path from the config, not -o: --resume below must not read it from the
     * config it replaces by the stored one. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -q --set output.path=%s --set output.checkpoint_interval=5",
             scene, out);
    char expected[1200], *text = NULL;
    assert_int_equal(run_command(cmd, &text), 1);
    snprintf(expected, sizeof expected, "; continue it from its checkpoint t = ");
    assert_non_null(strstr(text, expected));
    snprintf(expected, sizeof expected, "with `bksim run --restart %s.part`", out);
    assert_non_null(strstr(text, expected));
    free(text);
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    snprintf(expected, sizeof expected, "`bksim run --restart %s.part` continues from it", out);
    expect_command(cmd, 3, expected);
    snprintf(cmd, sizeof cmd, "./bksim run %s --set output.path=%s --set output.checkpoint_interval=5 --resume",
             scene, out);
    snprintf(expected, sizeof expected, "bksim: continuing %s.part from its checkpoint t = ", out);
    expect_command(cmd, 1, expected);

    snprintf(out, sizeof out, "%s/without_checkpoint.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -q -o %s", scene, out);
    expect_command(cmd, 1, "it holds no checkpoint, so it cannot be continued: running again starts over");
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    expect_command(cmd, 3, "checkpoint   none: this run cannot be continued, only run again");
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, out);
    snprintf(expected, sizeof expected, "starting over: %s.part is replaced (it holds no checkpoint", out);
    expect_command(cmd, 1, expected);
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

/* Every guard against a hang stops the run with a message naming its key, and keeps what
 * was written as an incomplete .part. */
static void test_limits(void **state)
{
    (void)state;
    const struct {
        const char *sets, *message;
    } cases[] = {
        {"--set solver.method=cvode_adams --set solver.min_step=1e-3", "[solver] min_step = 0.001 s at t = 0.5886"},
        {"--set solver.method=arkode_dp45 --set solver.min_step=1e-3", "below [solver] min_step = 0.001 s, at t = 0.58"},
        {"--set run.wall_time_limit=0.05 --set run.t_end=1e3", "[run] wall_time_limit = 0.05 s reached at t = "},
        {"--set solver.method=cvode_adams --set solver.max_steps=5", "more than 5 solver steps since the last output row"},
        {"--set friction.mu_d=0.5999 --set solver.max_transitions_per_instant=1 --set solver.instant_window=1e-3",
         "block 0: more than 1 transitions within 0.001 s at t = 0.6514"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char out[512], part[600], cmd[2048];
        snprintf(out, sizeof out, "%s/limit%zu.h5", tmpdir, k);
        snprintf(part, sizeof part, "%s.part", out);
        snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -o %s -q %s", out, cases[k].sets);
        char *text = NULL;
        int status = run_command(cmd, &text);
        if (status != 1 || !strstr(text, cases[k].message))
            print_error("case %zu: status %d\n%s\nexpected: %s\n", k, status, text, cases[k].message);
        assert_int_equal(status, 1);
        assert_non_null(strstr(text, cases[k].message));
        free(text);
        assert_false(path_exists(out));
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE);
    }
}


/* A run stopped again and again and restarted from its checkpoints each time ends with the
 * very output of an uninterrupted run: every row and transition bit-identical. */
static void test_restart_equivalence(void **state)
{
    (void)state;
    /* gsl_rk8pd resets its stepper when a size repeats instead of making a new one: the
     * resumed run's fresh instances must compute what the reused ones do.  The damped run
     * carries its dashpot dissipation through the checkpoints; the slide-hold-slide chain
     * resumes between and at its driver's breakpoints. */
    const char *methods[] = {"cvode_adams", "exact", "gsl_rk8pd", "gsl_rk8pd", "gsl_rk8pd"};
    const char *extra[] = {"", "", "", "--set block.damping=20", ""};
    const char *configs[] = {"paper/case_b_coulomb", "paper/case_b_coulomb", "paper/case_b_coulomb",
                             "paper/case_b_coulomb", "chains/slide_hold_slide_10"};
    for (size_t m = 0; m < 5; ++m) {
        char reference[512], stopped[512], part[600], cmd[2048];
        snprintf(reference, sizeof reference, "%s/reference_%s_%zu.h5", tmpdir, methods[m], m);
        snprintf(stopped, sizeof stopped, "%s/stopped_%s_%zu.h5", tmpdir, methods[m], m);
        snprintf(part, sizeof part, "%s.part", stopped);
        char common[512];
        snprintf(common, sizeof common, "configs/%s.ini --quiet --set output.checkpoint_interval=0.1 %s",
                 configs[m], extra[m]);
        snprintf(cmd, sizeof cmd, "./bksim run %s --set solver.method=%s -o %s", common, methods[m], reference);
        assert_int_equal(run_command(cmd, NULL), 0);
        /* The same run under a wall-clock limit so short that it stops many times (each
         * invocation still passes a checkpoint, or it could not progress). */
        snprintf(cmd, sizeof cmd, "./bksim run %s --set solver.method=%s --set run.wall_time_limit=0.02 -o %s",
                 common, methods[m], stopped);
        int status = run_command(cmd, NULL);
        int restarts = 0;
        while (status == 1 && restarts < 500) {
            snprintf(cmd, sizeof cmd, "./bksim run --restart %s --quiet", part);
            status = run_command(cmd, NULL);
            ++restarts;
        }
        print_message("%s: finished after %d restarts\n", methods[m], restarts);
        assert_int_equal(status, 0);
        assert_true(restarts >= 1);
        assert_false(path_exists(part));
        assert_same_output(reference, stopped);
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(stopped, &err), BK_OK);
    }
}

/* SIGKILL at arbitrary moments, then --restart, again and again until the run completes:
 * the output is bit-identical to an uninterrupted run's.  Checkpoints are dense, so that
 * many kills land inside one.  (A checkpoint once was overwritten in place, and a kill
 * inside that write left positions of one time with attributes of another, from which a
 * restart went on: half of such chains ended with wrong output.) */
static void test_sigkill_restart_loop(void **state)
{
    (void)state;
    const char *common = "configs/paper/case_b_coulomb.ini --quiet --set solver.method=cvode_adams "
                         "--set output.checkpoint_interval=0.0005 --set run.t_end=1";
    char reference[512], cmd[2048];
    snprintf(reference, sizeof reference, "%s/kill_reference.h5", tmpdir);
    /* Kill times are fractions of the uninterrupted run's wall time, so that they fall
     * inside the run for the plain and the sanitizer build alike. */
    snprintf(cmd, sizeof cmd, "s=$(date +%%s%%N); ./bksim run %s -o %s && echo $(( $(date +%%s%%N) - s ))",
             common, reference);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 0);
    double wall = strtod(text, NULL) * 1e-9;
    free(text);
    assert_true(wall > 0.0);
    unsigned long long lcg = 20250101; /* fixed: the same kill times on every run of the test */
    int kills = 0, restarts = 0, fresh_starts = 0, finished_by_restart = 0;
    for (int chain = 0; chain < 4; ++chain) {
        char out[512];
        snprintf(out, sizeof out, "%s/killed_%d.h5", tmpdir, chain);
        int have_part = 0, status = -1;
        for (int attempt = 0; attempt < 300 && status != 0; ++attempt) {
            lcg = lcg * 6364136223846793005ull + 1442695040888963407ull;
            double u = (double)(lcg >> 11) / 9007199254740992.0;
            /* Later attempts wait longer, so that even a slow build gets past a checkpoint. */
            double delay = wall * (0.03 + 0.17 * u) * (1.0 + attempt / 20.0);
            if (have_part)
                snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part --quiet & pid=$!; sleep %.3f; "
                         "kill -9 $pid 2>/dev/null; wait $pid", out, delay);
            else
                snprintf(cmd, sizeof cmd, "rm -f %s.part; ./bksim run %s -o %s & pid=$!; sleep %.3f; "
                         "kill -9 $pid 2>/dev/null; wait $pid", out, common, out, delay);
            restarts += have_part;
            int was_restart = have_part;
            status = run_command(cmd, &text);
            finished_by_restart += status == 0 && was_restart;
            if (status == 137) {
                ++kills;
                have_part = 1;
            } else if (status != 0) {
                /* Killed before its first checkpoint (nothing to restart from), or, rarely,
                 * inside HDF5's own flush in a way that left the .part unreadable: refused
                 * loudly either way, and a fresh run is what a user would do. */
                print_message("chain %d attempt %d: exit %d: %s", chain, attempt, status, text);
                have_part = 0;
                ++fresh_starts;
            }
            free(text);
        }
        assert_int_equal(status, 0);
        assert_true(path_exists(out));
        assert_same_output(reference, out);
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(out, &err), BK_OK);
    }
    print_message("4 runs of %.2f s: %d kills, %d restarts, %d fresh starts, %d runs finished by a restart\n",
                  wall, kills, restarts, fresh_starts, finished_by_restart);
    assert_true(kills >= 4);
    /* The restarts must work, not only fresh starts that happen to outrun the kills. */
    assert_true(finished_by_restart >= 2);
}

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A run with the default checkpoint settings, scaled down (restart points every 2e4 units of
 * work instead of 1e7, some 45 in the run; the wall-clock interval a quarter of the run),
 * writes a checkpoint once that interval has passed; killed then and restarted, it ends with
 * the very output of an uninterrupted run that wrote no checkpoint at all: the restart
 * points are where the run's own work puts them, the same in every run, and the wall clock
 * only decides which of them are written. */
static void test_wall_clock_checkpoint(void **state)
{
    (void)state;
    /* A chain of 10: chaotic, so any perturbation of a restart would show in every dataset. */
    const char *scene = "configs/chains/bk10_coulomb.ini --quiet --set run.t_end=20 --set output.checkpoint_work=2e4";
    char reference[512], out[512], cmd[2048], *text = NULL;
    snprintf(reference, sizeof reference, "%s/wall_reference.h5", tmpdir);
    snprintf(out, sizeof out, "%s/wall_killed.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, reference);
    double t0 = seconds_now();
    assert_int_equal(run_command(cmd, NULL), 0);
    double wall = seconds_now() - t0;
    hid_t file = H5Fopen(reference, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_true(H5Lexists(file, "checkpoint", H5P_DEFAULT) == 0); /* 300 s never passed */
    H5Fclose(file);

    double interval = 0.25 * wall;
    snprintf(cmd, sizeof cmd, "./bksim run %s --set output.checkpoint_wall_interval=%.3f -o %s "
             "> /dev/null 2>&1 & echo $!", scene, interval, out);
    t0 = seconds_now();
    assert_int_equal(run_command(cmd, &text), 0);
    long pid = strtol(text, NULL, 10);
    free(text);
    assert_true(pid > 0);
    int written = 0;
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    for (int tries = 0; tries < 2000 && !written; ++tries) {
        nanosleep(&(struct timespec){0, 5000000L}, NULL);
        run_command(cmd, &text);
        written = strstr(text, "checkpoint   t = ") != NULL;
        free(text);
    }
    double killed_after = seconds_now() - t0;
    snprintf(cmd, sizeof cmd, "kill -KILL %ld", pid);
    assert_int_equal(run_command(cmd, NULL), 0);
    print_message("run of %.2f s, wall-clock interval %.3f s: killed %.3f s in, after its first checkpoint\n",
                  wall, interval, killed_after);
    assert_true(written);
    assert_true(killed_after >= interval);
    /* Dead once the file is no longer locked (a zombie may linger, unreaped). */
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    int status = 3;
    for (int tries = 0; tries < 1000; ++tries) {
        status = run_command(cmd, &text);
        int running = strstr(text, "in progress") != NULL;
        free(text);
        if (!running)
            break;
        nanosleep(&(struct timespec){0, 5000000L}, NULL);
    }
    assert_int_equal(status, 3);
    double t_checkpoint = 0.0;
    bk_error err = {0};
    assert_int_equal(bk_h5_restartable(out, &t_checkpoint, &err), 1);
    assert_true(t_checkpoint > 0.0 && t_checkpoint < 20.0);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part --quiet", out);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_same_output(reference, out);
    assert_int_equal(bk_h5_verify(out, &err), BK_OK);
}

static void test_restart_errors(void **state)
{
    (void)state;
    char out[512], cmd[2048];
    char *text = NULL;
    snprintf(out, sizeof out, "%s/no_checkpoint.h5", tmpdir);
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/paper/case_b_coulomb.ini -o %s -q --set run.wall_time_limit=1e-4", out);
    assert_int_equal(run_command(cmd, NULL), 1);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part", out);
    expect_command(cmd, 2, "no checkpoint to restart from (a run writes its first once [output] "
                           "checkpoint_wall_interval has passed, 300 s by default");
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -q -o %s/finished.h5 "
                              "--set output.checkpoint_interval=1 && ./bksim run --restart %s/finished.h5",
             tmpdir, tmpdir);
    expect_command(cmd, 2, "the run is complete, nothing to restart");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s/nothing.h5", tmpdir);
    expect_command(cmd, 2, "no such file to restart from");
    expect_command("./bksim run configs/paper/case_b_coulomb.ini --restart x.h5", 2, "--restart takes no CONFIG");
    /* Running the same command again does not throw a restartable run's progress away. */
    snprintf(out, sizeof out, "%s/stopped.h5", tmpdir);
#define STOPPED_RUN "./bksim run configs/paper/case_b_coulomb.ini -q -o %s --set solver.method=cvode_bdf " \
                    "--set output.checkpoint_interval=0.01 --set run.wall_time_limit=%s"
    snprintf(cmd, sizeof cmd, STOPPED_RUN, out, "0.01");
    assert_int_equal(run_command(cmd, NULL), 1);
    char part[600];
    snprintf(part, sizeof part, "%s.part", out);
    double t_checkpoint = 0.0;
    bk_error err = {0};
    assert_int_equal(bk_h5_restartable(out, &t_checkpoint, &err), 1);
    snprintf(cmd, sizeof cmd, STOPPED_RUN, out, "0");
#undef STOPPED_RUN
    assert_int_equal(run_command(cmd, &text), 2);
    assert_non_null(strstr(text, "holds a run stopped at its checkpoint"));
    assert_non_null(strstr(text, "--force to start over"));
    free(text);
    double t_again = 0.0;
    assert_int_equal(bk_h5_restartable(out, &t_again, &err), 1);
    assert_true(t_again == t_checkpoint);
    strncat(cmd, " --force", sizeof cmd - strlen(cmd) - 1);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_true(path_exists(out) && !path_exists(part));
}

/* The catalog's scripts on a 40-block chain whose ends fail 1 ms apart and slip at once
 * (test_run_catalog.c's overlap scene): its first event holds two separate ruptures, which
 * event_ruptures.sh counts; plot_mfd.sh draws both figures. */
static void test_catalog_scripts(void **state)
{
    (void)state;
    char path[512], out[512], cmd[2048];
    char *text = NULL;
    snprintf(path, sizeof path, "%s/ends.ini", tmpdir);
    snprintf(out, sizeof out, "%s/ends.h5", tmpdir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("[model]\nn_blocks = 40\ncoupling_stiffness = 100\n"
          "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
          "[block.0]\nx_init = -2e-4\n[block.39]\nx_init = -1.99e-4\n"
          "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
          "[driver]\nvelocity = 1e-3\n[output]\ninterval = 0\n[run]\nt_end = 0.5\n",
          f);
    fclose(f);
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
    /* Without transitions there is nothing to count: an error, not a count of 0. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s/bare.h5 --set output.transitions=false --quiet "
             "&& BKSIM=%s scripts/event_ruptures.sh %s/bare.h5", path, tmpdir, bin, tmpdir);
    expect_command(cmd, 1, "transitions off");

    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_mfd.sh -o %s/fig %s", bin, tmpdir, out);
    assert_int_equal(run_command(cmd, &text), 0);
    free(text);
    snprintf(cmd, sizeof cmd, "%s/fig/ends_mfd.png", tmpdir);
    assert_true(path_exists(cmd));
    snprintf(cmd, sizeof cmd, "%s/fig/ends_spacetime.png", tmpdir);
    assert_true(path_exists(cmd));

    /* plot_slip_map.sh on a 4 x 5 lattice: the largest event, a chosen one, and one past the end. */
    snprintf(path, sizeof path, "%s/sheet.ini", tmpdir);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("[model]\nrows = 4\ncols = 5\ncoupling_stiffness = 2e4\n"
          "[block]\nmass = 1\ndriver_stiffness = 1e4\nx_init_random = 2e-5\n"
          "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
          "[driver]\nvelocity = 1e-3\n[output]\ninterval = 0\n[run]\nt_end = 0.5\n",
          f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s/sheet.h5 --quiet", path, tmpdir);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "BKSIM=%s scripts/plot_slip_map.sh -o %s/fig %s/sheet.h5", bin, tmpdir, tmpdir);
    assert_int_equal(run_command(cmd, &text), 0);
    assert_non_null(strstr(text, "/fig/sheet_slip_map_"));
    free(text);
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paper_configs),
        cmocka_unit_test(test_paper_rate_state),
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_lattice_of_one_line_is_a_chain),
        cmocka_unit_test(test_every_key_rejects_bad_values),
        cmocka_unit_test(test_distribution_errors),
        cmocka_unit_test(test_commands),
        cmocka_unit_test(test_progress_on_terminal),
        cmocka_unit_test(test_interrupted_run_is_marked),
        cmocka_unit_test(test_killed_run_leaves_partial),
        cmocka_unit_test(test_running_output),
        cmocka_unit_test(test_info_at_chain_scale),
        cmocka_unit_test(test_summary_script),
        cmocka_unit_test(test_warnings_and_strict),
        cmocka_unit_test(test_plot_scripts),
        cmocka_unit_test(test_stop_messages),
        cmocka_unit_test(test_damaged_files),
        cmocka_unit_test(test_limits),
        cmocka_unit_test(test_restart_equivalence),
        cmocka_unit_test(test_sigkill_restart_loop),
        cmocka_unit_test(test_wall_clock_checkpoint),
        cmocka_unit_test(test_restart_errors),
        cmocka_unit_test(test_catalog_scripts),
        cmocka_unit_test(test_bench_smoke),
        cmocka_unit_test(test_bench_output_smoke),
        cmocka_unit_test(test_readme_reference_current),
    };
    return cmocka_run_group_tests_name("cli", tests, setup, teardown);
}
