/* Bad input through the bksim command line: every bad config line, every key's every kind of
 * bad value and every bad distribution gives a clear message naming file:line (or the --set),
 * exit status 2 and no output file; a suspicious value draws a warning, an error under
 * --strict.  Runs ./bksim from the repository root. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "command.h"
#include "files.h"
#include "good_config.h"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    return make_temp_dir(tmpdir, sizeof tmpdir, "bksim_cli_input");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

/* --- bad input: clear message, exit 2, no file ----------------------------------------- */

typedef struct bad_case {
    const char *line, *replacement;
    const char *expect; /* substring of the message */
} bad_case;

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
        /* Messages that once were untrue or silent (issue 35, part 8). */
        {"[model]", "[modle]", "bad.ini:1: [modle]: unknown section (allowed: model, block, block.I, friction, "
                               "friction.I, driver, solver, output, catalog, run, prescribed; I is a block index"},
        {"velocity = 1e-3", "velocity = 1e-400", "bad.ini:11: [driver] velocity: 1e-400 is smaller than any double "
                                                 "(it would be read as 0; write 0 if that is meant)"},
        {"t_end = 0.7", "t_end = 0.7\n[catalog]\nmagnitude_offset = 1e308",
         "bad.ini:15: [catalog] magnitude_offset: out of range, got 1e308 (allowed: -100 <= magnitude_offset <= 100)"},
        {"velocity = 1e-3", "velocities = 1e-3,,0\ndurations = 1, 1, 1",
         "bad.ini:11: [driver] velocities: item 2 is empty"},
    };
    char path[512], out[512], cmd[2048], cwd[1024];
    assert_non_null(getcwd(cwd, sizeof cwd));
    snprintf(path, sizeof path, "%s/bad.ini", tmpdir);
    snprintf(out, sizeof out, "%s/never.h5", tmpdir);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        write_good_config(path, cases[k].line, cases[k].replacement);
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
    /* A directory given as the config: a usage error, exit 2. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", tmpdir, out);
    expect_command(cmd, 2, "is a directory (allowed: a config file)");
    /* [catalog] in a prescribed scene describes nothing: refused, not ignored. */
    expect_command("./bksim check configs/paper/fig2_velocity_step.ini --set catalog.rupture_rate=false", 2,
                   "[catalog] rupture_rate: a prescribed scene keeps no catalog");
    /* An unreadable config: I/O failure, exit 1, nothing written. */
    snprintf(cmd, sizeof cmd, "./bksim run %s/missing.ini -o %s", tmpdir, out);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 1);
    assert_non_null(strstr(text, "missing.ini"));
    assert_false(path_exists(out));
    free(text);
    /* A bad --set names itself as the location. */
    write_good_config(path, NULL, NULL);
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
        {"driver.velocity=uniform(1e-3, 2e-3)", "[driver] velocity: a distribution or profile gives each block its value"},
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
        {"solver.max_step=0.1", "[solver] max_step = 0.1 s is longer than the fastest damped oscillation's period"},
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_every_key_rejects_bad_values),
        cmocka_unit_test(test_distribution_errors),
        cmocka_unit_test(test_warnings_and_strict),
    };
    return cmocka_run_group_tests_name("cli_input", tests, setup, teardown);
}
