/* The config loader: every value lands where it should, defaults apply, every rejection
 * path gives its exact message, and every shipped config loads. */
#define _POSIX_C_SOURCE 200809L
#include <glob.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bk_test.h"
#include "bksim/config.h"
#include "files.h"
#include "bksim/run.h"

static const char *const full_config =
    "; a full config\n"
    "[model]\n"
    "n_blocks = 3\n"
    "boundary = fixed\n"
    "coupling_stiffness = 2.385e3\n"
    "gravity = 9.8\n"
    "[block]\n"
    "mass = 1.5\n"
    "driver_stiffness = 1e4\n"
    "x_init = 1e-6\n"
    "[block.1]\n"
    "mass = 2.5\n"
    "normal_force = 30\n"
    "v_init = -0.01\n"
    "[friction]\n"
    "law = coulomb\n"
    "mu_s = 0.6\n"
    "mu_d = 0.5\n"
    "[friction.2]\n"
    "mu_d = 0.4\n"
    "[driver]\n"
    "velocity = 2e-3\n"
    "spring = tension_only\n"
    "start_position = 1e-4\n"
    "[solver]\n"
    "method = cvode_bdf\n"
    "linear_solver = band\n"
    "rtol = 1e-9\n"
    "atol_x = 1e-15\n"
    "max_steps = 5000\n"
    "detect_velocity_extrema = no\n"
    "max_transitions_per_instant = 7\n"
    "[output]\n"
    "path = out/x.h5\n"
    "interval = 0.01\n"
    "fields = x, v mode\n"
    "transitions = false\n"
    "[run]\n"
    "t_end = 2.5\n";

static const char *const minimal_config =
    "[model]\nn_blocks = 1\n"
    "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
    "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
    "[driver]\nvelocity = 1e-3\n"
    "[run]\nt_end = 5\n";

/* Dashpot keys: per block (with [block.I] and distributions) and beside the couplings. */
static void test_damping_keys(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text, "%s", minimal_config);
    char *n = strstr(text, "n_blocks = 1");
    n[11] = '3';
    strcat(text, "[model]\ncoupling_damping = 2.5\n[block.1]\ndamping = 0.75\n");
    const char *overrides[] = {"block.damping=uniform(1, 2)"};
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = bk_config_load_string(text, "d.ini", overrides, 1, &c, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    assert_close(c->model->coupling_damping, 2.5, 0, 0);
    assert_close(c->model->blocks[1].damping, 0.75, 0, 0);
    for (size_t i = 0; i < 3; i += 2)
        assert_true(c->model->blocks[i].damping >= 1.0 && c->model->blocks[i].damping <= 2.0);
    assert_true(bk_model_is_damped(c->model));
    assert_true(c->model->blocks[0].damping != c->model->blocks[2].damping);
    bk_config_free(c);
    /* A prescribed scene imposes the slip rate: a dashpot there is a mistake. */
    const char *prescribed = "[prescribed]\nslip_rates = 1e-6\ndurations = 10\n[friction]\nlaw = rate_state\n"
                             "[block]\ndamping = 3\n";
    assert_int_equal(bk_config_load_string(prescribed, "p.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "p.ini:7: [block] damping: a prescribed scene imposes the slip rate"));
}

/* A driver history: segments from velocities and durations, t_end their sum by default. */
static void test_driver_history_keys(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text, "%s", minimal_config);
    char *at = strstr(text, "velocity = 1e-3\n");
    const char *history = "velocities = 1e-3 0 3e-3\ndurations = 2, 0.5, 1\n";
    char rest[512];
    snprintf(rest, sizeof rest, "%s", at + strlen("velocity = 1e-3\n"));
    snprintf(at, sizeof text - (size_t)(at - text), "%s%s", history, rest);
    char *t_end = strstr(text, "[run]\nt_end = 5\n");
    *t_end = '\0';
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = bk_config_load_string(text, "h.ini", NULL, 0, &c, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    const bk_driver *d = &c->model->driver;
    assert_int_equal(d->n_segments, 3);
    assert_close(c->t_end, 3.5, 0, 0);
    assert_close(d->velocity, 1e-3, 0, 0);
    assert_close(d->segment_start[2], 2.5, 0, 0);
    assert_close(bk_driver_position(d, 3.5), 2e-3 + 3e-3, 1e-15, 0);
    bk_config_free(c);
    const char *shorter[] = {"run.t_end=3"};
    assert_int_equal(bk_config_load_string(text, "h.ini", shorter, 1, &c, &err), BK_OK);
    assert_close(c->t_end, 3.0, 0, 0);
    bk_config_free(c);
}

static void test_full_config(void **state)
{
    (void)state;
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(full_config, "full.ini", NULL, 0, &c, &err), BK_OK);
    const bk_model *m = c->model;
    assert_int_equal(m->n_blocks, 3);
    assert_int_equal(m->boundary_cols, BK_BOUNDARY_FIXED);
    assert_close(m->coupling_stiffness, 2.385e3, 0, 0);
    assert_close(m->gravity, 9.8, 0, 0);
    assert_close(m->blocks[0].mass, 1.5, 0, 0);
    assert_close(m->blocks[1].mass, 2.5, 0, 0);
    assert_close(m->blocks[2].mass, 1.5, 0, 0);
    assert_close(m->blocks[0].normal_force, 1.5 * 9.8, 1e-15, 0); /* m g */
    assert_close(m->blocks[1].normal_force, 30, 0, 0);
    assert_close(m->blocks[0].x_init, 1e-6, 0, 0);
    assert_close(m->blocks[1].v_init, -0.01, 0, 0);
    assert_close(m->blocks[2].v_init, 0.0, 0, 0);
    assert_ptr_equal(m->blocks[2].law, &bk_friction_coulomb);
    assert_close(m->blocks[0].friction_params[1], 0.5, 0, 0);
    assert_close(m->blocks[2].friction_params[0], 0.6, 0, 0); /* inherited */
    assert_close(m->blocks[2].friction_params[1], 0.4, 0, 0); /* overridden */
    assert_int_equal(m->n_friction_state, 0);
    assert_close(m->driver.velocity, 2e-3, 0, 0);
    assert_close(m->driver.start_position, 1e-4, 0, 0);
    assert_int_equal(m->spring, BK_SPRING_TENSION_ONLY);
    assert_string_equal(c->solver.method, "cvode_bdf");
    assert_string_equal(c->solver.linear_solver, "band");
    assert_close(c->solver.rtol, 1e-9, 0, 0);
    assert_close(c->solver.atol_x, 1e-15, 0, 0);
    assert_true(isnan(c->solver.atol_v) && isnan(c->solver.max_step) && isnan(c->solver.instant_window));
    assert_int_equal(c->solver.max_steps, 5000);
    assert_int_equal(c->solver.detect_velocity_extrema, 0);
    assert_int_equal(c->solver.max_transitions_per_instant, 7);
    assert_string_equal(c->output.path, "out/x.h5");
    assert_close(c->output.interval, 0.01, 0, 0);
    assert_int_equal(c->output.fields, BK_FIELD_X | BK_FIELD_V | BK_FIELD_MODE);
    assert_int_equal(c->output.transitions, 0);
    assert_int_equal(c->output.event_rows, 1);
    assert_close(c->t_end, 2.5, 0, 0);
    assert_string_equal(c->source_name, "full.ini");
    assert_string_equal(c->text, full_config);
    bk_config_free(c);
}

static void test_defaults(void **state)
{
    (void)state;
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(minimal_config, "some/dir/case_q.ini", NULL, 0, &c, &err), BK_OK);
    assert_int_equal(c->model->boundary_cols, BK_BOUNDARY_FREE);
    assert_int_equal(c->model->spring, BK_SPRING_LINEAR);
    assert_close(c->model->gravity, 9.81, 0, 0);
    assert_close(c->model->blocks[0].normal_force, 9.81, 0, 0);
    assert_string_equal(c->solver.method, "auto");
    assert_string_equal(c->solver.linear_solver, "auto");
    assert_close(c->solver.rtol, 1e-8, 0, 0);
    assert_int_equal(c->solver.max_steps, 100000);
    assert_int_equal(c->solver.detect_velocity_extrema, 1);
    assert_int_equal(c->solver.max_transitions_per_instant, 100);
    assert_string_equal(c->output.path, "case_q.h5");
    assert_close(c->output.interval, 5e-3, 1e-15, 0); /* t_end / 1000 */
    assert_int_equal(c->output.fields, BK_FIELD_ALL);
    assert_int_equal(c->output.transitions, 1);
    assert_int_equal(c->output.event_rows, 1); /* auto: a short chain gets event rows */
    /* Restart points by work, written by the wall clock. */
    assert_close(c->output.checkpoint_interval, 0.0, 0, 0);
    assert_close(c->output.checkpoint_work, BK_CHECKPOINT_WORK + BK_CHECKPOINT_WORK_PER_BLOCK, 0, 0);
    assert_close(c->output.checkpoint_wall_interval, BK_CHECKPOINT_WALL_INTERVAL, 0, 0);
    bk_config_free(c);
}

/* Keys given as distributions: one value per block from [model] seed, each entry its own stream
 * (a block's value depends on the seed, the entry and its index only), a block's own section
 * winning without shifting the others, and every block's value kept for /parameters. */
#define DRAWN_CONFIG(block7)                                                     \
    "[model]\nn_blocks = 2000\ncoupling_stiffness = 1e4\n"                       \
    "[block]\nmass = normal(2, 0.1)\ndriver_stiffness = lognormal(9.2, 0.05)\n" \
    "[block.7]\n" block7 "[friction]\nlaw = coulomb\nmu_s = uniform(0.55, 0.65)\nmu_d = 0.5\n" \
    "[driver]\nvelocity = 1e-3\n[run]\nt_end = 1\n"
static const char *const drawn_config = DRAWN_CONFIG("mass = 3\n");

static bk_config *load_drawn(const char *text, const char *override)
{
    bk_config *c = NULL;
    bk_error err = {0};
    const char *overrides[1] = {override};
    int rc = bk_config_load_string(text, "drawn.ini", overrides, override ? 1 : 0, &c, &err);
    if (rc != BK_OK)
        print_error("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    return c;
}

static void test_distributions(void **state)
{
    (void)state;
    bk_config *c = load_drawn(drawn_config, NULL);
    const bk_model *m = c->model;
    size_t n = m->n_blocks;
    double sum = 0.0, sum2 = 0.0, log_sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double mu_s = m->blocks[i].friction_params[0];
        assert_true(mu_s >= 0.55 && mu_s <= 0.65);
        log_sum += log(m->blocks[i].driver_stiffness);
        if (i == 7)
            continue;
        sum += m->blocks[i].mass;
        sum2 += m->blocks[i].mass * m->blocks[i].mass;
    }
    assert_close(m->blocks[7].mass, 3.0, 0, 0);
    double mean = sum / (double)(n - 1), sd = sqrt(sum2 / (double)(n - 1) - mean * mean);
    print_message("2000 blocks: mass mean %.4f sd %.4f (normal(2, 0.1)); mean log k %.4f (lognormal(9.2, 0.05))\n",
                  mean, sd, log_sum / (double)n);
    assert_true(fabs(mean - 2.0) < 5 * 0.1 / sqrt((double)n));
    assert_true(fabs(sd - 0.1) < 0.01);
    assert_true(fabs(log_sum / (double)n - 9.2) < 5 * 0.05 / sqrt((double)n));
    /* Every block's value, for /parameters, in the order the keys first appear. */
    assert_int_equal(c->n_parameters, 3);
    assert_string_equal(c->parameters[0].name, "block.mass");
    assert_string_equal(c->parameters[0].unit, "kg");
    assert_string_equal(c->parameters[1].name, "block.driver_stiffness");
    assert_string_equal(c->parameters[2].name, "friction.mu_s");
    for (size_t i = 0; i < n; ++i) {
        assert_true(c->parameters[0].values[i] == m->blocks[i].mass);
        assert_true(c->parameters[1].values[i] == m->blocks[i].driver_stiffness);
        assert_true(c->parameters[2].values[i] == m->blocks[i].friction_params[0]);
    }

    /* The same seed, the same values; another seed, others. */
    bk_config *same = load_drawn(drawn_config, NULL), *other = load_drawn(drawn_config, "model.seed=2");
    size_t differ = 0;
    for (size_t i = 0; i < n; ++i) {
        assert_true(same->model->blocks[i].mass == m->blocks[i].mass);
        differ += other->model->blocks[i].mass != m->blocks[i].mass;
    }
    assert_int_equal(differ, n - 1); /* all but block 7 */
    bk_config_free(same);
    bk_config_free(other);

    /* Without block 7's own value, and with another key drawn too: every other block keeps its
     * mass, bit for bit. */
    bk_config *changed = load_drawn(DRAWN_CONFIG("x_init = normal(0, 1e-6)\n"), "block.v_init=normal(0, 1e-4)");
    for (size_t i = 0; i < n; ++i)
        if (i != 7)
            assert_true(changed->model->blocks[i].mass == m->blocks[i].mass);
    assert_true(changed->model->blocks[7].mass != 3.0);
    assert_true(changed->model->blocks[0].v_init != 0.0);
    bk_config_free(changed);
    bk_config_free(c);
    /* A block that sets the key itself never sees the shared draw, in range or not. */
    bk_config *own = load_drawn("[model]\nn_blocks = 1\n[block]\nmass = normal(-5, 0.1)\ndriver_stiffness = 1e4\n"
                                "[block.0]\nmass = 1\n[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
                                "[driver]\nvelocity = 1e-3\n[run]\nt_end = 1\n", NULL);
    assert_close(own->model->blocks[0].mass, 1.0, 0, 0);
    bk_config_free(own);
}

/* An interval given in simulated time writes every restart point unless a wall-clock interval
 * is given too; 0 turns restart points off altogether. */
static void test_checkpoint_keys(void **state)
{
    (void)state;
    const struct {
        const char *overrides[2];
        double interval, work, wall;
    } cases[] = {
        {{"output.checkpoint_interval=0.5", NULL}, 0.5, 0.0, 0.0},
        {{"output.checkpoint_interval=0.5", "output.checkpoint_wall_interval=60"}, 0.5, 0.0, 60.0},
        {{"output.checkpoint_interval=0", NULL}, 0.0, 0.0, 0.0},
        {{"output.checkpoint_work=2e4", NULL}, 0.0, 2e4, BK_CHECKPOINT_WALL_INTERVAL},
        {{"model.n_blocks=1000", NULL}, 0.0, BK_CHECKPOINT_WORK + 1000 * BK_CHECKPOINT_WORK_PER_BLOCK,
         BK_CHECKPOINT_WALL_INTERVAL},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        bk_config *c = NULL;
        bk_error err = {0};
        size_t n = cases[k].overrides[1] ? 2 : 1;
        assert_int_equal(bk_config_load_string(minimal_config, "cp.ini", cases[k].overrides, n, &c, &err), BK_OK);
        assert_close(c->output.checkpoint_interval, cases[k].interval, 0, 0);
        assert_close(c->output.checkpoint_work, cases[k].work, 0, 0);
        assert_close(c->output.checkpoint_wall_interval, cases[k].wall, 0, 0);
        bk_config_free(c);
    }
}

/* event_rows = auto (the default, or by name) writes full rows at transitions on chains of
 * up to BK_EVENT_ROWS_AUTO_BLOCKS blocks and none on longer ones; true and false win. */
static void test_event_rows_auto(void **state)
{
    (void)state;
    const struct {
        const char *n_blocks, *event_rows;
        int expected;
    } cases[] = {
        {"model.n_blocks=16", NULL, 1},          {"model.n_blocks=17", NULL, 0},
        {"model.n_blocks=1000", "output.event_rows=auto", 0},
        {"model.n_blocks=1000", "output.event_rows=true", 1},
        {"model.n_blocks=2", "output.event_rows=off", 0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        const char *overrides[2] = {cases[k].n_blocks, cases[k].event_rows};
        bk_config *c = NULL;
        bk_error err = {0};
        int rc = bk_config_load_string(minimal_config, "auto.ini", overrides, cases[k].event_rows ? 2 : 1, &c, &err);
        if (rc != BK_OK)
            fail_msg("%s", err.message);
        assert_int_equal(c->output.event_rows, cases[k].expected);
        bk_config_free(c);
    }
    const char *bad[] = {"output.event_rows=sometimes"};
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(minimal_config, "auto.ini", bad, 1, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "(allowed: auto, true, false, yes, no, on, off, 1, 0)"));
}

/* Indented keys, a 190-character line, CRLF line ends and ';' comments are all fine. */
static void test_tolerated_forms(void **state)
{
    (void)state;
    char text[2048];
    char comment[200];
    memset(comment, 'x', 188);
    comment[0] = ';';
    comment[188] = '\0';
    snprintf(text, sizeof text,
             "%s\r\n[model]\r\n  n_blocks = 1   ; one\r\n[block]\n\tmass = 1\n  driver_stiffness=1e4\n"
             "[friction]\nlaw=coulomb\nmu_s = 0.6\nmu_d = 0.5\n[driver]\nvelocity = 1e-3\n[run]\nt_end = 5",
             comment);
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "t.ini", NULL, 0, &c, &err), BK_OK);
    assert_close(c->model->blocks[0].mass, 1.0, 0, 0);
    bk_config_free(c);
    /* Lone CR line ends (old Mac files), with line numbers intact. */
    const char *cr = "[model]\rn_blocks = 1\r[block]\rmass = 1\rdriver_stiffness = 1e4\r[friction]\rlaw = coulomb\r"
                     "mu_s = 0.6\rmu_d = 0.5\r[driver]\rvelocity = 1e-3\r[run]\rt_end = 5\rt_end = 6\r";
    assert_int_equal(bk_config_load_string(cr, "t.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "t.ini:14: [run] t_end: duplicate key (first set at line 13)"));
}

/* Replace the line `line` (with its '\n') of minimal_config by `replacement`. */
static void variant(char *out, size_t len, const char *line, const char *replacement)
{
    const char *at = strstr(minimal_config, line);
    assert_non_null(at);
    snprintf(out, len, "%.*s%s%s", (int)(at - minimal_config), minimal_config, replacement,
             at + strlen(line));
}

/* The lattice's shape from any two of n_blocks, rows and cols, and `boundary` on each
 * direction the lattice extends along, whichever keys gave the shape: one row is the chain
 * (no walls above and below), one column the chain stood on end. */
static void test_lattice_shape_and_boundaries(void **state)
{
    (void)state;
    static const struct {
        const char *model;
        size_t rows, cols;
        bk_boundary boundary_rows, boundary_cols;
    } cases[] = {
        {"n_blocks = 12\nboundary = fixed\n", 1, 12, BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED},
        {"n_blocks = 12\nrows = 1\nboundary = fixed\n", 1, 12, BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED},
        {"n_blocks = 12\ncols = 4\nboundary = fixed\n", 3, 4, BK_BOUNDARY_FIXED, BK_BOUNDARY_FIXED},
        {"rows = 3\ncols = 4\nboundary = periodic\n", 3, 4, BK_BOUNDARY_PERIODIC, BK_BOUNDARY_PERIODIC},
        {"n_blocks = 12\ncols = 1\nboundary = periodic\n", 12, 1, BK_BOUNDARY_PERIODIC, BK_BOUNDARY_FREE},
        {"n_blocks = 1\nboundary = fixed\n", 1, 1, BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED},
        {"n_blocks = 12\nrows = 1\nboundary = fixed\nboundary_rows = periodic\n", 1, 12, BK_BOUNDARY_PERIODIC,
         BK_BOUNDARY_FIXED},
        {"n_blocks = 12\ncols = 1\nboundary_cols = fixed\n", 12, 1, BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED},
        {"rows = 2\ncols = 6\nboundary = fixed\nboundary_cols = periodic\n", 2, 6, BK_BOUNDARY_FIXED,
         BK_BOUNDARY_PERIODIC},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char text[1024];
        variant(text, sizeof text, "n_blocks = 1\n", cases[k].model);
        bk_config *c = NULL;
        bk_error err = {0};
        if (bk_config_load_string(text, "t.ini", NULL, 0, &c, &err) != BK_OK)
            fail_msg("case %zu: %s", k, err.message);
        assert_int_equal(c->model->n_blocks, cases[k].rows * cases[k].cols);
        assert_int_equal(c->model->rows, cases[k].rows);
        assert_int_equal(c->model->cols, cases[k].cols);
        assert_int_equal(c->model->boundary_rows, cases[k].boundary_rows);
        assert_int_equal(c->model->boundary_cols, cases[k].boundary_cols);
        bk_config_free(c);
    }
}

typedef struct rejection {
    const char *line, *replacement, *message;
} rejection;

/* QDYN's spring-block without inertia, and what a block without mass needs. */
static const char quasi_dynamic_config[] = "[model]\n"
                                           "n_blocks = 3\n"
                                           "coupling_stiffness = 1e9\n"
                                           "[block]\n"
                                           "mass = 0\n"
                                           "driver_stiffness = 2e9\n"
                                           "normal_force = 5e6\n"
                                           "damping = 3.3e5\n"
                                           "[friction]\n"
                                           "law = dieterich_ruina_aging\n"
                                           "a = 0.01\n"
                                           "b = 0.015\n"
                                           "Dc = 1e-5\n"
                                           "V0 = 1e-5\n"
                                           "f0 = 0.6\n"
                                           "[driver]\n"
                                           "velocity = 1e-5\n"
                                           "[catalog]\n"
                                           "slip_rate_threshold = 1e-2\n"
                                           "[run]\n"
                                           "t_end = 1\n";

/* [solver] local_stepping = on needs a back-end with a predictor and a chain that stays one
 * island; each refusal names the key, what is wrong and what is allowed. */
static void test_local_stepping(void **state)
{
    (void)state;
    bk_config *c = NULL;
    bk_error err = {0};
    const char *on[] = {"solver.local_stepping=on", "solver.method=cvode_bdf", "solver.segment_blocks=2"};
    assert_int_equal(bk_config_load_string(quasi_dynamic_config, "q.ini", on, 3, &c, &err), BK_OK);
    assert_string_equal(c->solver.local_stepping, "on");
    assert_int_equal(c->solver.segment_blocks, 2);
    bk_config_free(c);
    static const struct {
        const char *set[3];
        const char *message;
    } cases[] = {
        {{"solver.local_stepping=on", "solver.method=gsl_rk8pd", NULL},
         "[solver] local_stepping: needs method cvode_bdf, cvode_adams or auto; method is gsl_rk8pd"},
        {{"solver.local_stepping=on", "driver.spring=tension_only", NULL},
         "[solver] local_stepping: needs linear driver springs"},
        {{"solver.local_stepping=yes", NULL, NULL}, "[solver] local_stepping"},
        {{"solver.segment_blocks=1", NULL, NULL}, "[solver] segment_blocks"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        size_t n = cases[k].set[1] ? 2 : 1;
        c = (bk_config *)&c;
        int rc = bk_config_load_string(quasi_dynamic_config, "q.ini", cases[k].set, n, &c, &err);
        if (rc != BK_ERR_CONFIG || !strstr(err.message, cases[k].message))
            print_error("case %zu: rc %d\n got:      %s\n expected: %s\n", k, rc, err.message, cases[k].message);
        assert_int_equal(rc, BK_ERR_CONFIG);
        assert_null(c);
    }
    /* A law that sticks: its stuck blocks split the chain already. */
    const char *text = "[model]\nn_blocks = 3\ncoupling_stiffness = 1\n[block]\nmass = 1\ndriver_stiffness = 1\n"
                       "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n[driver]\nvelocity = 1e-3\n"
                       "[solver]\nmethod = cvode_bdf\nlocal_stepping = on\n[run]\nt_end = 1\n";
    c = (bk_config *)&c;
    int rc = bk_config_load_string(text, "c.ini", NULL, 0, &c, &err);
    assert_int_equal(rc, BK_ERR_CONFIG);
    assert_null(c);
    assert_non_null(strstr(err.message, "c.ini:15: [solver] local_stepping: needs laws without a stuck state on "
                                        "every block (such as rate-and-state); block 0 uses law coulomb"));
}

static void test_quasi_dynamic(void **state)
{
    (void)state;
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(quasi_dynamic_config, "q.ini", NULL, 0, &c, &err), BK_OK);
    assert_true(c->model->blocks[1].mass == 0.0);
    bk_config_free(c);
    /* Mixed: one block with mass among blocks without. */
    const char *mixed[] = {"block.1.mass=1e-3"};
    assert_int_equal(bk_config_load_string(quasi_dynamic_config, "q.ini", mixed, 1, &c, &err), BK_OK);
    bk_config_free(c);
    static const struct {
        const char *set;
        const char *message;
    } cases[] = {
        {"block.damping=0", "q.ini:5: [block] mass: 0 (a quasi-dynamic block) needs [block] damping > 0 N s/m on block 0"},
        {"block.2.damping=0", "needs [block] damping > 0 N s/m on block 2"},
        {"model.coupling_damping=1", "cannot have [model] coupling_damping = 1 N s/m"},
        {"block.v_init=1e-5", "takes no [block] v_init (block 0 has 1e-05 m/s)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        const char *set[] = {cases[k].set};
        c = (bk_config *)&c;
        int rc = bk_config_load_string(quasi_dynamic_config, "q.ini", set, 1, &c, &err);
        if (rc != BK_ERR_CONFIG || !strstr(err.message, cases[k].message))
            print_error("case %zu: rc %d\n got:      %s\n expected: %s\n", k, rc, err.message, cases[k].message);
        assert_int_equal(rc, BK_ERR_CONFIG);
        assert_null(c);
        assert_non_null(strstr(err.message, cases[k].message));
    }
    /* A law that sticks. */
    char text[2048];
    snprintf(text, sizeof text, "%s", quasi_dynamic_config);
    const char *rs = "law = dieterich_ruina_aging\na = 0.01\nb = 0.015\nDc = 1e-5\nV0 = 1e-5\nf0 = 0.6\n";
    const char *coulomb = "law = coulomb\nmu_s = 0.6\nmu_d = 0.5\n";
    char *law = strstr(text, rs);
    assert_non_null(law);
    memmove(law + strlen(coulomb), law + strlen(rs), strlen(law + strlen(rs)) + 1);
    memcpy(law, coulomb, strlen(coulomb));
    c = (bk_config *)&c;
    assert_int_equal(bk_config_load_string(text, "q.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_null(c);
    assert_non_null(strstr(err.message, "q.ini:5: [block] mass: 0 (a quasi-dynamic block) needs a law without a stuck "
                                        "state (dieterich_ruina_aging, dieterich_ruina_slip); block 0's law coulomb sticks"));
    /* The default normal force, mass * gravity, would be 0. */
    snprintf(text, sizeof text, "%s", quasi_dynamic_config);
    char *line = strstr(text, "normal_force = 5e6\n");
    memmove(line, line + strlen("normal_force = 5e6\n"), strlen(line + strlen("normal_force = 5e6\n")) + 1);
    c = (bk_config *)&c;
    assert_int_equal(bk_config_load_string(text, "q.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_null(c);
    assert_non_null(strstr(err.message, "needs [block] normal_force on block 0: its default, mass * gravity, would be 0 N"));
}

static void test_rejections(void **state)
{
    (void)state;
    char long_line[300]; /* a section header longer than inih's line: only values may be */
    memset(long_line, 'y', 250);
    long_line[0] = '[';
    long_line[249] = ']';
    long_line[250] = '\n';
    long_line[251] = '\0';
    const rejection cases[] = {
        {"[model]\n", "[modle]\n",
         "t.ini:1: [modle]: unknown section (allowed: model, block, block.I, friction, friction.I, driver, "
         "solver, output, catalog, run, prescribed; I is a block index from 0)"},
        {"mass = 1\n", "mass = 1\nmas = 2\n",
         "t.ini:5: [block] mas: unknown key (allowed: mass, driver_stiffness, normal_force, x_init, v_init, x_init_random, damping, applied_force)"},
        {"mass = 1\n", "mass = 1\nmass = 2\n", "t.ini:5: [block] mass: duplicate key (first set at line 4)"},
        {"n_blocks = 1\n", "", "t.ini: [model] n_blocks: required key missing (allowed: 1 <= n_blocks <= 1000000, an integer)"},
        {"mass = 1\n", "", "t.ini: [block] mass: required key missing (allowed: 0 <= mass < inf kg)"},
        {"driver_stiffness = 1e4\n", "", "t.ini: [block] driver_stiffness: required key missing (allowed: 0 <= driver_stiffness < inf N/m)"},
        {"law = coulomb\n", "", "t.ini: [friction] law: required key missing (allowed: coulomb, rate_state, carlson_langer, dieterich_ruina_aging, dieterich_ruina_slip)"},
        {"mu_s = 0.6\n", "", "t.ini: [friction] mu_s: required key missing (allowed: 0 <= mu_s < inf)"},
        {"velocity = 1e-3\n", "", "t.ini: [driver] velocity: required key missing (allowed: -inf < velocity < inf m/s)"},
        {"t_end = 5\n", "", "t.ini: [run] t_end: required key missing (allowed: 0 < t_end < inf s)"},
        {"mass = 1\n", "mass = heavy\n", "t.ini:4: [block] mass: not a number: \"heavy\" (allowed: 0 <= mass < inf kg)"},
        {"mass = 1\n", "mass = 2.0 # kg\n",
         "t.ini:4: [block] mass: not a number: \"2.0 # kg\" (inline comments start with ';') (allowed: 0 <= mass < inf kg)"},
        {"mass = 1\n", "mass = 1.5x\n", "t.ini:4: [block] mass: not a number: \"1.5x\""},
        {"mass = 1\n", "mass =\n", "t.ini:4: [block] mass: not a number: \"\""},
        {"mass = 1\n", "mass = nan\n", "t.ini:4: [block] mass: not a number: \"nan\""},
        {"mass = 1\n", "mass = inf\n", "t.ini:4: [block] mass: not a number: \"inf\""},
        {"mass = 1\n", "mass = -inf\n", "t.ini:4: [block] mass: not a number: \"-inf\""},
        {"mass = 1\n", "mass = 1e999\n", "t.ini:4: [block] mass: not a number: \"1e999\""},
        {"mass = 1\n", "mass = -1\n", "t.ini:4: [block] mass: out of range, got -1 (allowed: 0 <= mass < inf kg)"},
        {"mass = 1\n", "mass = 0\n", "t.ini:4: [block] mass: 0 (a quasi-dynamic block) needs a law without a stuck state"},
        {"driver_stiffness = 1e4\n", "driver_stiffness = -5\n",
         "t.ini:5: [block] driver_stiffness: out of range, got -5 (allowed: 0 <= driver_stiffness < inf N/m)"},
        {"n_blocks = 1\n", "n_blocks = 1.5\n", "t.ini:2: [model] n_blocks: not an integer: \"1.5\""},
        {"n_blocks = 1\n", "n_blocks = 0\n", "t.ini:2: [model] n_blocks: out of range, got 0"},
        {"n_blocks = 1\n", "n_blocks = 1\ncoupling_stiffness = -1\n",
         "t.ini:3: [model] coupling_stiffness: out of range, got -1 (allowed: 0 <= coupling_stiffness < inf N/m)"},
        {"mu_d = 0.5\n", "mu_d = 0.7\n", "t.ini:9: [friction] mu_d: must be <= mu_s (0.6), got 0.7"},
        {"mu_d = 0.5\n", "mu_d = -0.1\n", "t.ini:9: [friction] mu_d: out of range, got -0.1 (allowed: 0 <= mu_d < inf)"},
        {"mu_d = 0.5\n", "mu_d = 0.5\nv0 = 100\n",
         "t.ini:10: [friction] v0: not a parameter of law 'coulomb' (known: law, mu_s, mu_d)"},
        {"law = coulomb\n", "law = magic\n", "t.ini:7: [friction] law: unknown value \"magic\" (allowed: coulomb, rate_state, carlson_langer, dieterich_ruina_aging, dieterich_ruina_slip)"},
        {"t_end = 5\n", "t_end = 0\n", "t.ini:13: [run] t_end: out of range, got 0 (allowed: 0 < t_end < inf s)"},
        {"t_end = 5\n", "t_end = -3\n", "t.ini:13: [run] t_end: out of range, got -3"},
        {"t_end = 5\n", "t_end = 5\n[solver]\nrtol = 1\n",
         "t.ini:15: [solver] rtol: out of range, got 1 (allowed: 1e-15 <= rtol <= 0.1)"},
        {"t_end = 5\n", "t_end = 5\n[solver]\nmethod = euler\n",
         "t.ini:15: [solver] method: unknown value \"euler\" (allowed: auto, cvode_adams, cvode_bdf"},
        {"t_end = 5\n", "t_end = 5\n[solver]\ndetect_velocity_extrema = maybe\n",
         "t.ini:15: [solver] detect_velocity_extrema: not a boolean: \"maybe\" (allowed: true, false, yes, no, on, off, 1, 0)"},
        {"t_end = 5\n", "t_end = 5\n[output]\nfields = x, speed\n",
         "t.ini:15: [output] fields: unknown field \"speed\" (allowed: all, or a list of x, v, friction, cof, mode, energy, state)"},
        {"t_end = 5\n", "t_end = 5\n[output]\ninterval = 6\n", "t.ini:15: [output] interval: must be <= t_end (5 s), got 6"},
        {"t_end = 5\n", "t_end = 5\n[output]\npath =\n", "t.ini:15: [output] path: empty value"},
        {"t_end = 5\n", "t_end = 5\n[output]\ncheckpoint_interval = 1\ncheckpoint_work = 1e4\n",
         "t.ini:16: [output] checkpoint_work: applies only with checkpoint_interval = auto (not set); "
         "checkpoint_interval = 1 is given"},
        {"t_end = 5\n", "t_end = 5\n[output]\ncheckpoint_work = 0\n",
         "t.ini:15: [output] checkpoint_work: out of range, got 0 (allowed: 0 < checkpoint_work < inf)"},
        {"velocity = 1e-3\n", "velocity = 1e-3\nspring = elastic\n",
         "t.ini:12: [driver] spring: unknown value \"elastic\" (allowed: linear, tension_only)"},
        {"mass = 1\n", "mass = 1\n[block.1]\nmass = 2\n", "t.ini:5: [block.1]: block index out of range (allowed: 0..0)"},
        {"mass = 1\n", "mass = 1\n[block.x]\nmass = 2\n", "t.ini:5: [block.x]: unknown section"},
        {"mass = 1\n", "mass = 1\n[driver.0]\nvelocity = 2\n", "t.ini:5: [driver.0]: unknown section"},
        {"mass = 1\n", long_line, "t.ini:4: a line of 250 characters that is no \"key = value\" with a key of at "
                                  "most 192 characters (allowed: only values may be longer than a line of 198)"},
        {"velocity = 1e-3\n", "velocities = 1e-3,,0\ndurations = 1, 1\n",
         "t.ini:11: [driver] velocities: item 2 is empty (two commas, or a comma at an end)"},
        {"velocity = 1e-3\n", "velocities = 1e-3, \\\n   0,\ndurations = 1, 1\n",
         "t.ini:11: [driver] velocities: item 3 is empty"},
        {"velocity = 1e-3\n", "velocities = 1e-3 \\\n 0\ndurations = 1, \\\n 1\nspring = elastic\n",
         "t.ini:15: [driver] spring: unknown value \"elastic\""},
        {"velocity = 1e-3\n", "velocities_file = /nonexistent/h.tsv\n",
         "t.ini:11: [driver] velocities_file: /nonexistent/h.tsv: cannot open the history"},
        {"velocity = 1e-3\n", "velocity = 1e-3\nvelocities_file = /nonexistent/h.tsv\n",
         "t.ini:11: [driver] velocity: give velocities_file (a history from a table) or velocity, not both"},
        {"mass = 1\n", "mass 1\n", "t.ini:4: syntax error"},
        {"[block]\n", "[block\n", "t.ini:3: syntax error"},
        {"mass = 1\n", "mass = 0x1p0\n", "t.ini:4: [block] mass: not a number: \"0x1p0\""},
        {"mass = 1\n", "mass = 1\n[block.00]\nmass = 2\n", "t.ini:5: [block.00]: unknown section"},
        {"driver_stiffness = 1e4\n", "driver_stiffness = -1e-320\n", "t.ini:5: [block] driver_stiffness: out of range, got -1e-320"},
        {"t_end = 5\n", "t_end = 5\n[output]\nmax_bytes = 1e3\n",
         "t.ini:15: [output] max_bytes: the sample rows would take about"},
        {"t_end = 5\n", "t_end = 5\n[solver]\nmethod = exact\n[friction.0]\nlaw = carlson_langer\nF0 = 5\n"
         "sigma = 0.2\nalpha = 1\n",
         "t.ini:15: [solver] method: needs Coulomb friction (a constant sliding force, no friction state) on "
         "every block; block 0 uses law carlson_langer (allowed: auto, or an integrator such as gsl_rk8pd or "
         "cvode_bdf)"},
        {"mass = 1\n", "mass = 1\nv_init = 1e300\n",
         "t.ini:5: [block] v_init: block 0's initial kinetic energy overflows a double (inf J; allowed: a finite energy)"},
        {"mass = 1\n", "mass = 1\nx_init = -1e160\n",
         "t.ini:5: [block] x_init: block 0's initial elastic energy overflows a double"},
        {"mu_d = 0.5\n", "mu_d = 0.5\n[friction.0]\nmu_s = 0.4\n",
         "t.ini:9: [friction] mu_d: must be <= mu_s (0.4), got 0.5 (block 0: t.ini:11 sets [friction.0] mu_s = 0.4)"},
        /* Values drawn per block. */
        {"mass = 1\n", "mass = normal(1, -0.1)\n",
         "t.ini:4: [block] mass: normal(1, -0.1) has a negative width (allowed: sd >= 0)"},
        {"mass = 1\n", "mass = uniform(2, 1)\n", "t.ini:4: [block] mass: uniform(2, 1) has a negative width (allowed: a <= b)"},
        {"mass = 1\n", "mass = lognormal(0, -1)\n",
         "t.ini:4: [block] mass: lognormal(0, -1) has a negative width (allowed: sigma >= 0)"},
        {"mu_d = 0.5\n", "mu_d = uniform(-0.1, 0.5)\n",
         "t.ini:9: [friction] mu_d: uniform(-0.1, 0.5) reaches outside the allowed range (allowed: 0 <= mu_d < inf)"},
        {"mass = 1\n", "mass = normal(-1, 0.1)\n", "t.ini:4: [block] mass: normal(-1, 0.1) drew -"},
        {"mass = 1\n", "mass = normal(-1, 0.1)\n",
         "for block 0, outside the allowed range (allowed: 0 <= mass < inf kg; narrow the distribution, or set "
         "that block in [block.0])"},
        {"velocity = 1e-3\n", "velocity = uniform(1e-3, 2e-3)\n",
         "t.ini:11: [driver] velocity: a distribution or profile gives each block its value: only keys of [block] "
         "and [friction] take one"},
        {"mass = 1\n", "mass = normal(1)\n",
         "t.ini:4: [block] mass: not a distribution or profile: \"normal(1)\" (allowed: uniform(a, b), normal(mean, "
         "sd), lognormal(mu, sigma), linear(first, last), linear_rows(first, last) with finite numbers, or "
         "file(path[, column]))"},
        {"mass = 1\n", "mass = normal(1, 0.1) x\n", "t.ini:4: [block] mass: not a distribution"},
        {"mass = 1\n", "mass = gamma(1, 2)\n",
         "t.ini:4: [block] mass: unknown distribution or profile \"gamma\" (allowed: uniform(a, b),"},
        {"mass = 1\n", "mass = Uniform(1, 2)\n", "t.ini:4: [block] mass: unknown distribution or profile \"Uniform\""},
        /* Profiles. */
        {"mass = 1\n", "mass = linear(1, -1)\n",
         "t.ini:4: [block] mass: linear(1, -1) reaches outside the allowed range (allowed: 0 <= mass < inf kg)"},
        {"mass = 1\n", "mass = linear_rows(1)\n", "t.ini:4: [block] mass: not a distribution or profile"},
        {"mass = 1\n", "mass = 1\n[block.0]\napplied_force = linear(0, 1)\n",
         "t.ini:6: [block.0] applied_force: linear(...) is a profile across the blocks: give it in [block], not in "
         "[block.0]"},
        {"mass = 1\n", "mass = file(/nonexistent/profile.tsv)\n",
         "t.ini:4: [block] mass: /nonexistent/profile.tsv: cannot open the profile: No such file or directory"},
        {"mass = 1\n", "mass = file(/dev/null)\n", "t.ini:4: [block] mass: /dev/null: not a regular file"},
        {"mass = 1\n", "mass = file(p.tsv, 0)\n", "t.ini:4: [block] mass: not a distribution or profile"},
        {"mass = 1\n", "mass = file(p.tsv, 2) x\n", "t.ini:4: [block] mass: not a distribution or profile"},
        {"mass = 1\n", "mass = file()\n", "t.ini:4: [block] mass: not a distribution or profile"},
        {"mass = 1\n", "mass = 1\napplied_force = 1e400\n", "t.ini:5: [block] applied_force: not a number: \"1e400\" (allowed: -inf < applied_force < inf N)"},
        {"mu_d = 0.5\n", "mu_d = uniform(0.7, 0.8)\n",
         "t.ini:9: [friction] mu_d: must be <= mu_s (0.6), got 0.7"},
        {"mu_d = 0.5\n", "mu_d = uniform(0.7, 0.8)\n", "(drawn for block 0)"},
        {"mu_s = 0.6\n", "mu_s = uniform(0.3, 0.4)\n", "t.ini:9: [friction] mu_d: must be <= mu_s (0.3"},
        {"mu_s = 0.6\n", "mu_s = uniform(0.3, 0.4)\n", "(block 0: mu_s drew 0.3"},
        {"mu_s = 0.6\n", "mu_s = uniform(0.3, 0.4)\n", " from uniform(0.3, 0.4))"},
        /* Driver histories. */
        {"velocity = 1e-3\n", "velocities = 1e-3, 0, 2e-3\ndurations = 1, 2\n",
         "t.ini:12: [driver] durations: has 2 values, velocities has 3 (allowed: one duration per velocity)"},
        {"velocity = 1e-3\n", "velocity = 1e-3\nvelocities = 1e-3\ndurations = 1\n",
         "t.ini:12: [driver] velocities: give velocity (constant) or velocities (a history), not both"},
        {"velocity = 1e-3\n", "velocities = 1e-3, 0\n", "t.ini:11: [driver] velocities: needs [driver] durations"},
        {"velocity = 1e-3\n", "velocity = 1e-3\ndurations = 1\n",
         "t.ini:12: [driver] durations: applies with [driver] velocities, which is not given"},
        {"velocity = 1e-3\n", "velocities = 1e-3, 0\ndurations = 1, -2\n", "t.ini:12: [driver] durations:"},
        {"velocity = 1e-3\n", "velocities = 1e-3, 0\ndurations = 1, 2\n",
         "t.ini:14: [run] t_end: must be <= the driver history's length (3 s), got 5"},
        /* Dashpots. */
        {"mass = 1\n", "mass = 1\ndamping = -2\n",
         "t.ini:5: [block] damping: out of range, got -2 (allowed: 0 <= damping < inf N s/m)"},
        {"n_blocks = 1\n", "n_blocks = 1\ncoupling_damping = -0.5\n",
         "t.ini:3: [model] coupling_damping: out of range, got -0.5 (allowed: 0 <= coupling_damping < inf N s/m)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char text[4096];
        variant(text, sizeof text, cases[k].line, cases[k].replacement);
        bk_config *c = (bk_config *)&c; /* must be reset to NULL */
        bk_error err = {0};
        int rc = bk_config_load_string(text, "t.ini", NULL, 0, &c, &err);
        if (rc != BK_ERR_CONFIG || !strstr(err.message, cases[k].message))
            print_error("case %zu: rc %d\n got:      %s\n expected: %s\n", k, rc, err.message,
                        cases[k].message);
        assert_int_equal(rc, BK_ERR_CONFIG);
        assert_null(c);
        assert_non_null(strstr(err.message, cases[k].message));
    }
    /* A missing n_blocks stays the error when an interval is given: the interval <= t_end
     * cross-check must not run against a t_end that was never read. */
    char text[4096];
    variant(text, sizeof text, "n_blocks = 1\n", "");
    strncat(text, "[output]\ninterval = 1e-3\n", sizeof text - strlen(text) - 1);
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "t.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_string_equal(err.message,
                        "t.ini: [model] n_blocks: required key missing (allowed: 1 <= n_blocks <= 1000000, an integer)");
}

/* The first error in file order wins. */
static void test_first_error_reported(void **state)
{
    (void)state;
    char text[4096];
    variant(text, sizeof text, "mass = 1\n", "mass = -1\n");
    char both[4096];
    snprintf(both, sizeof both, "%s", text);
    char *t_end = strstr(both, "t_end = 5");
    assert_non_null(t_end);
    memcpy(t_end, "t_end =-5", 9);
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(both, "t.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "t.ini:4: [block] mass"));
}

/* A draw outside its key's range stays the error: the value must not go on into a law's
 * cross-check that an earlier line (mu_d) would report in its place. */
static void test_out_of_range_draw_stays_the_error(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text, "%s", minimal_config);
    strstr(text, "n_blocks = 1")[11] = '4';
    const char *overrides[] = {"friction.mu_s=normal(-1, 0.01)"};
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "t.ini", overrides, 1, &c, &err), BK_ERR_CONFIG);
    assert_null(c);
    assert_non_null(strstr(err.message, "--set friction.mu_s=normal(-1, 0.01): [friction] mu_s: normal(-1, 0.01) drew -"));
    assert_non_null(strstr(err.message, " for block 0, outside the allowed range"));
}

static void test_overrides(void **state)
{
    (void)state;
    const char *ok[] = {"friction.mu_d=0.3", "block.0.mass = 2", "solver.rtol=1e-10", "output.path=o.h5"};
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(minimal_config, "t.ini", ok, 4, &c, &err), BK_OK);
    assert_close(c->model->blocks[0].friction_params[1], 0.3, 0, 0);
    assert_close(c->model->blocks[0].mass, 2.0, 0, 0);
    assert_close(c->model->blocks[0].normal_force, 2.0 * 9.81, 1e-15, 0);
    assert_close(c->solver.rtol, 1e-10, 0, 0);
    assert_string_equal(c->output.path, "o.h5");
    assert_non_null(strstr(c->text, "; --set friction.mu_d=0.3\n"));
    assert_non_null(strstr(c->text, "; --set block.0.mass = 2\n"));
    bk_config_free(c);

    const char *bad_value[] = {"block.mass=-2"};
    assert_int_equal(bk_config_load_string(minimal_config, "t.ini", bad_value, 1, &c, &err), BK_ERR_CONFIG);
    assert_null(c);
    assert_string_equal(err.message, "--set block.mass=-2: [block] mass: out of range, got -2 (allowed: 0 <= mass < inf kg)");
    const char *malformed[] = {"blockmass=2"};
    assert_int_equal(bk_config_load_string(minimal_config, "t.ini", malformed, 1, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "--set blockmass=2: expected section.key=value"));
    const char *no_equals[] = {"block.mass"};
    assert_int_equal(bk_config_load_string(minimal_config, "t.ini", no_equals, 1, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "expected section.key=value"));
    const char *unknown[] = {"block.colour=red"};
    assert_int_equal(bk_config_load_string(minimal_config, "t.ini", unknown, 1, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "--set block.colour=red: [block] colour: unknown key"));
}

static void test_file_errors(void **state)
{
    (void)state;
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_file("/nonexistent/dir/x.ini", NULL, 0, &c, &err), BK_ERR_IO);
    assert_null(c);
    assert_non_null(strstr(err.message, "/nonexistent/dir/x.ini: cannot open: No such file or directory"));
    char path[] = "/tmp/bksim_cfg_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, "[model]\n\0\n", 10), 10);
    close(fd);
    assert_int_equal(bk_config_load_file(path, NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "NUL"));
    unlink(path);
}

/* Many [block.I] sections (a generated config): every one overrides [block] for its block,
 * the others keep [block]'s value, and a key given three times names its first line. */
static void test_many_sections(void **state)
{
    (void)state;
    const size_t n = 20000;
    size_t cap = 64 * n + 1024, used = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    used += (size_t)snprintf(text, cap, "[model]\nn_blocks = %zu\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                             "x_init = 7e-6\n[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n[driver]\n"
                             "velocity = 1e-3\n[run]\nt_end = 1\n", n);
    for (size_t i = 0; i < n; i += 2)
        used += (size_t)snprintf(text + used, cap - used, "[block.%zu]\nx_init = %zue-9\n", i, i);
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "many.ini", NULL, 0, &c, &err), BK_OK);
    for (size_t i = 0; i < n; i += 997)
        assert_close(c->model->blocks[i].x_init, i % 2 ? 7e-6 : (double)i * 1e-9, 1e-15, 0);
    bk_config_free(c);
    free(text);
    const char *triple = "[model]\nn_blocks = 1\n[block]\nmass = 1\nmass = 2\nmass = 3\n";
    assert_int_equal(bk_config_load_string(triple, "t.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "t.ini:5: [block] mass: duplicate key (first set at line 4)"));
}

/* A [friction.I] that changes law takes none of [friction]'s parameters; a per-block
 * override of the same law inherits them. */
static void test_per_block_friction(void **state)
{
    (void)state;
    char text[4096];
    snprintf(text, sizeof text, "%s", minimal_config);
    char *model = strstr(text, "n_blocks = 1");
    model[11] = '2';
    strcat(text, "[friction.1]\nlaw = coulomb\nmu_d = 0.2\n");
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "t.ini", NULL, 0, &c, &err), BK_OK);
    assert_close(c->model->blocks[1].friction_params[0], 0.6, 0, 0);
    assert_close(c->model->blocks[1].friction_params[1], 0.2, 0, 0);
    assert_close(c->model->blocks[0].friction_params[1], 0.5, 0, 0);
    bk_config_free(c);
    /* mu_d above the inherited mu_s is reported at the override's line */
    strcat(text, "mu_s = 0.1\n");
    assert_int_equal(bk_config_load_string(text, "t.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    if (!strstr(err.message, "t.ini:16: [friction.1] mu_d: must be <= mu_s (0.1), got 0.2"))
        print_error("%s\n", err.message);
    assert_non_null(strstr(err.message, "t.ini:16: [friction.1] mu_d: must be <= mu_s (0.1), got 0.2"));
}

/* Every shipped config loads (tests run from the repository root). */
static void test_shipped_configs(void **state)
{
    (void)state;
    glob_t g;
    assert_int_equal(glob("configs/*/*.ini", 0, NULL, &g), 0);
    assert_true(g.gl_pathc >= 8);
    for (size_t i = 0; i < g.gl_pathc; ++i) {
        bk_config *c = NULL;
        bk_error err = {0};
        int rc = bk_config_load_file(g.gl_pathv[i], NULL, 0, &c, &err);
        if (rc != BK_OK)
            print_error("%s\n", err.message);
        assert_int_equal(rc, BK_OK);
        /* What we ship draws no plausibility warning. */
        assert_int_equal(bk_config_warnings(c, NULL, NULL), 0);
        bk_config_free(c);
    }
    globfree(&g);
}

typedef struct warnings_seen {
    size_t count;
    char last[BK_ERROR_MESSAGE_LEN];
} warnings_seen;

static void record_warning(void *user, const char *message)
{
    warnings_seen *seen = user;
    ++seen->count;
    snprintf(seen->last, sizeof seen->last, "%s", message);
}

/* Each plausibility warning, from the values that draw it; and none at the edges that
 * should not (no force drop, a law without a stuck state, rows only at transitions). */
static void test_warnings(void **state)
{
    (void)state;
    static const struct {
        const char *overrides[3];
        size_t n;
        size_t count;
        const char *needle;
    } cases[] = {
        {{"output.interval=1e-4"}, 1, 0, NULL},
        /* 1 m/s meant as 1e-3: 0.6 * 9.81 N / 1e4 N/m * 100 /s = 59 mm/s at most. */
        {{"driver.velocity=1"}, 1, 1, "[driver] velocity = 1 m/s is faster than the blocks' own slip speeds (at most 0.0589 m/s"},
        {{"driver.velocity=-0.07"}, 1, 1, "[driver] velocity = -0.07 m/s"},
        {{"driver.velocity=0.05"}, 1, 0, NULL},
        {{"driver.velocity=1", "block.driver_stiffness=1"}, 2, 0, NULL}, /* a soft spring: 5.9 m/s */
        /* A slip lasts pi / 100 s = 31 ms. */
        {{"output.interval=0.05"}, 1, 1, "[output] interval = 0.05 s is longer than a slip (about 0.0314 s"},
        {{"output.interval=0.03"}, 1, 0, NULL},
        {{"output.interval=0"}, 1, 0, NULL},
        /* The natural period is 2 pi / 100 s = 63 ms. */
        {{"solver.max_step=0.1"}, 1, 1, "[solver] max_step = 0.1 s is longer than the fastest damped oscillation's period (0.0628 s)"},
        {{"solver.max_step=0.05"}, 1, 0, NULL},
        {{"driver.velocity=1", "output.interval=0.05", "solver.max_step=0.1"}, 3, 3, "max_step"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        bk_config *c = NULL;
        bk_error err = {0};
        assert_int_equal(bk_config_load_string(minimal_config, "w.ini", cases[k].overrides, cases[k].n, &c, &err), BK_OK);
        warnings_seen seen = {0, ""};
        assert_int_equal(bk_config_warnings(c, record_warning, &seen), cases[k].count);
        assert_int_equal(seen.count, cases[k].count);
        if (cases[k].needle && !strstr(seen.last, cases[k].needle))
            fail_msg("case %zu: \"%s\" lacks \"%s\"", k, seen.last, cases[k].needle);
        if (cases[k].count)
            assert_non_null(strstr(seen.last, "w.ini: "));
        bk_config_free(c);
    }
    /* A law without a stuck state creeps at any driver speed: no slip-speed scale. */
    static const char *const creeping =
        "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
        "[friction]\nlaw = dieterich_ruina_aging\nf0 = 0.6\na = 0.01\nb = 0.015\nV0 = 1e-3\nDc = 1e-5\n"
        "[driver]\nvelocity = 10\n[catalog]\nslip_rate_threshold = 1e-3\n[run]\nt_end = 1\n";
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = bk_config_load_string(creeping, "dr.ini", NULL, 0, &c, &err);
    if (rc != BK_OK)
        print_error("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    assert_int_equal(bk_config_warnings(c, NULL, NULL), 0);
    bk_config_free(c);
}

/* Inputs the fuzzers found: each is rejected with a located message, or loads into a model
 * that runs (under a wall-clock limit) to an end, never a crash or a hang. */
static void test_fuzz_regressions(void **state)
{
    (void)state;
    glob_t g;
    if (glob("tests/fuzz/regressions/*.ini", 0, NULL, &g) != 0)
        return;
    for (size_t i = 0; i < g.gl_pathc; ++i) {
        bk_config *c = NULL;
        bk_error err = {0};
        int rc = bk_config_load_file(g.gl_pathv[i], NULL, 0, &c, &err);
        if (rc != BK_OK) {
            assert_int_equal(rc, BK_ERR_CONFIG);
            assert_int_equal(strncmp(err.message, g.gl_pathv[i], strlen(g.gl_pathv[i])), 0);
            continue;
        }
        c->wall_time_limit = 1.0;
        rc = bk_run(c, NULL, NULL, NULL, NULL, &err);
        assert_true(rc == BK_OK || err.message[0] != '\0');
        bk_config_free(c);
    }
    print_message("%zu fuzz regression inputs\n", g.gl_pathc);
    globfree(&g);
}

static void test_reference(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    bk_config_write_reference(f);
    fclose(f);
    const char *expect[] = {"### [model]", "| `n_blocks` |", "| `mass` | kg | required | 0 <= mass < inf kg |",
                            "### [friction] law = coulomb", "| `mu_d` |", "| `t_end` | s |",
                            "| `interval` | s | t_end / 1000 |"};
    for (size_t k = 0; k < sizeof expect / sizeof expect[0]; ++k) {
        if (!strstr(buf, expect[k]))
            print_error("missing: %s\n", expect[k]);
        assert_non_null(strstr(buf, expect[k]));
    }
    free(buf);
}

/* Profiles across the blocks: linear() has its ends exactly and equal steps along a chain and
 * along a lattice's rows (by column), linear_rows() down its columns (by row); file() reads a
 * column of a file beside the config (comments and blank lines skipped); every block's value
 * is kept for /parameters; a file's bad line is named with the config's key. */
#define PROFILE_TAIL "[friction]\nlaw = coulomb\nmu_s = 1\nmu_d = 0\n[driver]\nvelocity = 0\n[run]\nt_end = 1\n"
/* A driver history of 400 segments (slide-hold-slide, 0.5 s each), written four ways: one line
 * of 2,400 characters (longer than inih's buffer), continuation lines, and a table of
 * durations or of start times (velocities_file): the same driver, bit for bit. */
static void test_long_protocols(void **state)
{
    (void)state;
    enum { N = 400 };
    size_t cap = 64 * N + 1024;
    char *one_line = malloc(cap), *continued = malloc(cap), *durations = malloc(cap);
    char *by_duration = malloc(cap), *by_time = malloc(cap);
    assert_true(one_line && continued && durations && by_duration && by_time);
    size_t a = 0, b = 0, d = 0, f = 0, g = 0;
    /* A comment longer than inih's line is skipped too. */
    a += (size_t)sprintf(one_line + a, "; %0300d\n", 0);
    a += (size_t)sprintf(one_line + a, "velocities = ");
    b += (size_t)sprintf(continued + b, "velocities = ");
    d += (size_t)sprintf(durations + d, "durations =");
    f += (size_t)sprintf(by_duration + f, "# a protocol\nduration[s]\tvelocity[m/s]\n");
    g += (size_t)sprintf(by_time + g, "velocity, t\n");
    for (int k = 0; k < N; ++k) {
        double v = k % 2 ? 0.0 : 1e-3 * (1 + k % 3);
        a += (size_t)sprintf(one_line + a, "%s%.17g", k ? ", " : "", v);
        b += (size_t)sprintf(continued + b, "%.17g%s\n", v, k + 1 < N ? ", \\" : "   ; the last");
        d += (size_t)sprintf(durations + d, " 0.5");
        f += (size_t)sprintf(by_duration + f, "0.5 %.17g  # segment %d\n", v, k);
        g += (size_t)sprintf(by_time + g, "%.17g,%g\n", v, 0.5 * k);
    }
    sprintf(one_line + a, "   ; %d segments on one line\n%s\n", N, durations);
    sprintf(continued + b, "%s\n", durations);
    char dir[256], name[512], path[512];
    assert_int_equal(make_temp_dir(dir, sizeof dir, "bksim_history"), 0);
    snprintf(name, sizeof name, "%s/scene.ini", dir);
    snprintf(path, sizeof path, "%s/by_duration.tsv", dir);
    assert_int_equal(write_text(path, by_duration), 0);
    snprintf(path, sizeof path, "%s/by_time.csv", dir);
    assert_int_equal(write_text(path, by_time), 0);
    const char *driver_keys[4] = {one_line, continued, "velocities_file = by_duration.tsv\n",
                                  "velocities_file = by_time.csv\n"};
    double *first_position = NULL;
    for (int way = 0; way < 4; ++way) {
        char *text = malloc(cap + 512);
        assert_non_null(text);
        sprintf(text, "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                      "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n[driver]\n%s[run]\n%s",
                driver_keys[way], way == 3 ? "t_end = 200\n" : "");
        bk_config *c = NULL;
        bk_error err = {0};
        int rc = bk_config_load_string(text, name, NULL, 0, &c, &err);
        if (rc != BK_OK)
            fail_msg("way %d: %s", way, err.message);
        const bk_driver *drv = &c->model->driver;
        assert_int_equal(drv->n_segments, N);
        assert_true(c->t_end == 200.0);
        for (size_t k = 0; k < N; ++k) {
            assert_true(drv->segment_velocity[k] == (k % 2 ? 0.0 : 1e-3 * (double)(1 + k % 3)));
            assert_true(drv->segment_start[k] == 0.5 * (double)k);
        }
        if (way == 0) {
            first_position = malloc(N * sizeof *first_position);
            assert_non_null(first_position);
            for (size_t k = 0; k < N; ++k)
                first_position[k] = drv->segment_position[k];
        } else {
            for (size_t k = 0; k < N; ++k)
                assert_true(drv->segment_position[k] == first_position[k]);
        }
        bk_config_free(c);
        free(text);
    }
    print_message("%d segments: one config of %zu characters, %d continuation lines and two tables agree\n", N,
                  strlen(one_line), N);

    /* Bad tables name their file:line. */
    static const struct {
        const char *table, *message;
    } bad[] = {
        {"velocity duration\n1e-3 0.5\n1e-3\n", "bad.tsv:3: one column"},
        {"velocity duration\n1e-3 0.5\n1e-3 0\n", "bad.tsv:3: duration 0 (allowed: > 0 s)"},
        {"velocity duration\n1e-3 0.5x\n", "bad.tsv:2: not a finite number: \"0.5x\""},
        {"t velocity\n0.1 1e-3\n", "bad.tsv:2: the first segment starts at t = 0.10000000000000001 s (allowed: 0)"},
        {"t velocity\n0 1e-3\n# hold\n2 0\n1 1e-3\n", "bad.tsv:5: t = 1 s after t = 2 s (allowed: increasing times)"},
        {"v duration\n", "bad.tsv:1: the first line names the columns: \"v duration\""},
        {"# nothing\n\n", "bad.tsv: empty"},
        {"velocity duration\n", "bad.tsv: no segments"},
    };
    snprintf(path, sizeof path, "%s/bad.tsv", dir);
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        assert_int_equal(write_text(path, bad[k].table), 0);
        bk_config *c = NULL;
        bk_error err = {0};
        assert_int_equal(bk_config_load_string("[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                                               "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n[driver]\n"
                                               "velocities_file = bad.tsv\n[run]\nt_end = 1\n",
                                               name, NULL, 0, &c, &err),
                         BK_ERR_CONFIG);
        if (!strstr(err.message, bad[k].message))
            fail_msg("table %zu: expected \"%s\" in \"%s\"", k, bad[k].message, err.message);
        assert_non_null(strstr(err.message, "scene.ini:11: [driver] velocities_file: "));
    }
    /* A t table without [run] t_end cannot say how long its last segment lasts. */
    assert_int_equal(write_text(path, "t velocity\n0 1e-3\n"), 0);
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string("[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                                           "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n[driver]\n"
                                           "velocities_file = bad.tsv\n",
                                           name, NULL, 0, &c, &err),
                     BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "bad.tsv:2: the last segment starts at t = 0 s; with a t column it lasts "
                                        "until [run] t_end, which must be given"));
    assert_int_equal(remove_tree(dir), 0);
    free(first_position);
    free(one_line);
    free(continued);
    free(durations);
    free(by_duration);
    free(by_time);
}

static void test_profiles(void **state)
{
    (void)state;
    bk_config *c = load_drawn("[model]\nn_blocks = 5\n[block]\nmass = 1\ndriver_stiffness = 0\n"
                              "applied_force = linear(-1, 3)\n" PROFILE_TAIL, NULL);
    for (size_t i = 0; i < 5; ++i)
        assert_true(c->model->blocks[i].applied_force == (double)i - 1.0);
    assert_int_equal(c->n_parameters, 1);
    assert_string_equal(c->parameters[0].name, "block.applied_force");
    assert_string_equal(c->parameters[0].unit, "N");
    assert_true(c->parameters[0].values[4] == 3.0);
    bk_config_free(c);

    c = load_drawn("[model]\nrows = 3\ncols = 4\n[block]\nmass = linear(1, 4)\ndriver_stiffness = 1\n"
                   "normal_force = linear_rows(10, 30)\n" PROFILE_TAIL, NULL);
    for (size_t i = 0; i < 12; ++i) {
        assert_true(c->model->blocks[i].mass == (double)(i % 4) + 1.0);
        assert_true(c->model->blocks[i].normal_force == 10.0 * (double)(i / 4) + 10.0);
    }
    bk_config_free(c);

    char dir[256], path[512], name[512];
    assert_int_equal(make_temp_dir(dir, sizeof dir, "bksim_profile"), 0);
    snprintf(path, sizeof path, "%s/mu.tsv", dir);
    assert_int_equal(write_text(path, "# block\tmu_s\n0\t0.5\n\n1 0.75\n2\t1.0\n# end\n3 0.625\n4 2.5e-1\n"), 0);
    snprintf(name, sizeof name, "%s/scene.ini", dir);
    bk_error err = {0};
    const char *text = "[model]\nn_blocks = 5\n[block]\nmass = 1\ndriver_stiffness = 1\n"
                       "[friction]\nlaw = coulomb\nmu_s = file(mu.tsv, 2)\nmu_d = 0.2\n[driver]\nvelocity = 0\n"
                       "[run]\nt_end = 1\n";
    c = NULL;
    int rc = bk_config_load_string(text, name, NULL, 0, &c, &err);
    if (rc != BK_OK)
        print_error("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    const double expected[] = {0.5, 0.75, 1.0, 0.625, 0.25};
    for (size_t i = 0; i < 5; ++i) {
        assert_true(c->model->blocks[i].friction_params[0] == expected[i]);
        assert_true(c->parameters[0].values[i] == expected[i]);
    }
    assert_string_equal(c->parameters[0].name, "friction.mu_s");
    bk_config_free(c);

    /* What is wrong, where: the config's key and the file's line. */
    const struct {
        const char *file_text, *message;
    } bad[] = {
        {"0 0.5\n1 0.6\n2 x\n3 0.5\n4 0.5\n", "mu.tsv:3: column 2: not a finite number: \"x\""},
        {"0 0.5\n1\n", "mu.tsv:2: no column 2"},
        {"0 0.5\n1 0.6\n", "mu.tsv: 2 values in column 2, the scene has 5 blocks"},
        {"0 0.5\n1 0.6\n2 0.5\n3 0.5\n4 0.5\n5 0.5\n", "mu.tsv:6: more values than the scene's 5 blocks"},
        {"0 0.5\n1 0.6\n2 0.1\n3 0.5\n4 0.5\n", "[friction] mu_d: must be <= mu_s (0.1), got 0.2"},
        {"0 0.5\n1 0.6\n# x\n2 -0.5\n3 0.5\n4 0.5\n", "mu.tsv:4: -0.5 for block 2 is outside the allowed range"},
        {"0 0.5\n1 0.6\n2 inf\n3 0.5\n4 0.5\n", "mu.tsv:3: column 2: not a finite number: \"inf\""},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        assert_int_equal(write_text(path, bad[k].file_text), 0);
        c = (bk_config *)&c;
        rc = bk_config_load_string(text, name, NULL, 0, &c, &err);
        if (rc != BK_ERR_CONFIG || !strstr(err.message, bad[k].message) || !strstr(err.message, "scene.ini:"))
            print_error("case %zu: rc %d\n got:      %s\n expected: %s\n", k, rc, err.message, bad[k].message);
        assert_int_equal(rc, BK_ERR_CONFIG);
        assert_null(c);
        assert_non_null(strstr(err.message, bad[k].message));
        assert_non_null(strstr(err.message, "scene.ini:8: [friction] mu_s: ") ||
                        strstr(err.message, "scene.ini:9: [friction] mu_d: "));
    }
    assert_int_equal(remove_tree(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_full_config),
        cmocka_unit_test(test_damping_keys),
        cmocka_unit_test(test_driver_history_keys),
        cmocka_unit_test(test_lattice_shape_and_boundaries),
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_checkpoint_keys),
        cmocka_unit_test(test_distributions),
        cmocka_unit_test(test_profiles),
        cmocka_unit_test(test_long_protocols),
        cmocka_unit_test(test_event_rows_auto),
        cmocka_unit_test(test_tolerated_forms),
        cmocka_unit_test(test_rejections),
        cmocka_unit_test(test_quasi_dynamic),
        cmocka_unit_test(test_local_stepping),
        cmocka_unit_test(test_first_error_reported),
        cmocka_unit_test(test_out_of_range_draw_stays_the_error),
        cmocka_unit_test(test_overrides),
        cmocka_unit_test(test_file_errors),
        cmocka_unit_test(test_per_block_friction),
        cmocka_unit_test(test_many_sections),
        cmocka_unit_test(test_shipped_configs),
        cmocka_unit_test(test_warnings),
        cmocka_unit_test(test_fuzz_regressions),
        cmocka_unit_test(test_reference),
    };
    return cmocka_run_group_tests_name("config", tests, NULL, NULL);
}
