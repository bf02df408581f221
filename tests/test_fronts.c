/* Front and precursor diagnostics (src/fronts.c) on ruptures whose answers are known: a front
 * at constant speed, one that arrives everywhere at once, one that starts away from the edge,
 * one too short for a speed; the same seen from the other edge; a front that changes speed,
 * block by block; the edge force from the driver's schedule and the edge block's transitions,
 * ruptures listed out of order; bad rows refused.  And a chain pushed at one edge, run. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "recorder.h"

#define N_CHAIN 20

static size_t add_rows(bk_rupture_block *rows, size_t n, int64_t rupture, int first, int last, double t0, double dt)
{
    for (int b = first; b <= last; ++b)
        rows[n++] = (bk_rupture_block){rupture, b, t0 + dt * (double)(b - first), t0 + 10.0, 1e-3};
    return n;
}

static void test_fronts_known(void **state)
{
    (void)state;
    bk_rupture ruptures[4];
    memset(ruptures, 0, sizeof ruptures);
    bk_rupture_block rows[64];
    size_t n = 0;
    /* 0: blocks 0..9 from the edge at 2 blocks/s; 1: all 20 at once; 2: blocks 5..7 from block
     * 5 outward; 3: two blocks. */
    n = add_rows(rows, n, 0, 0, 9, 1.0, 0.5);
    n = add_rows(rows, n, 1, 0, 19, 5.0, 0.0);
    n = add_rows(rows, n, 2, 5, 7, 8.0, 0.25);
    n = add_rows(rows, n, 3, 12, 13, 9.0, 0.1);
    const int first[4] = {0, 0, 5, 12}, count[4] = {10, 20, 3, 2};
    const double start[4] = {1.0, 5.0, 8.0, 9.0};
    for (int r = 0; r < 4; ++r) {
        ruptures[r].t_start = start[r];
        ruptures[r].first_block = first[r];
        ruptures[r].n_blocks = count[r];
        ruptures[r].duration = 10.0;
    }
    bk_front f[4];
    bk_error err = {0};
    const double force[4] = {1.0, 2.0, 3.0, 4.0};
    assert_int_equal(bk_fronts(ruptures, 4, rows, n, N_CHAIN, 0, force, f, &err), BK_OK);
    assert_int_equal(f[0].arrest_length, 10);
    assert_true(f[0].from_edge && !f[0].crossed);
    assert_true(fabs(f[0].mean_speed - 2.0) < 1e-12);
    assert_true(f[0].edge_force == 1.0 && f[0].t_start == 1.0);
    assert_int_equal(f[1].arrest_length, 20);
    assert_true(f[1].crossed && isinf(f[1].mean_speed) && f[1].mean_speed > 0.0);
    assert_int_equal(f[2].arrest_length, 8);
    assert_true(!f[2].from_edge && !f[2].crossed);
    assert_true(fabs(f[2].mean_speed - 4.0) < 1e-12);
    assert_true(isnan(f[3].mean_speed));
    assert_int_equal(f[3].arrest_length, 14);

    /* From the other edge: the first front runs toward it, the far edge is block 0. */
    assert_int_equal(bk_fronts(ruptures, 4, rows, n, N_CHAIN, 1, NULL, f, &err), BK_OK);
    assert_int_equal(f[0].arrest_length, 20);
    assert_true(f[0].crossed && !f[0].from_edge);
    assert_true(fabs(f[0].mean_speed + 2.0) < 1e-12);
    assert_true(isnan(f[0].edge_force));
    assert_int_equal(f[2].arrest_length, 15);

    /* Rows that name no rupture, or a block off the chain. */
    rows[3].rupture = 9;
    assert_int_equal(bk_fronts(ruptures, 4, rows, n, N_CHAIN, 0, NULL, f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "names rupture 9, outside the 4 ruptures"));
    rows[3].rupture = 0;
    rows[4].block = N_CHAIN;
    assert_int_equal(bk_fronts(ruptures, 4, rows, n, N_CHAIN, 0, NULL, f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "names block 20, outside the chain's 20"));
}

/* 1 block/s over blocks 0..9, then 4 blocks/s: the local fit gives each speed exactly away
 * from the change. */
static void test_front_profile(void **state)
{
    (void)state;
    bk_rupture_block rows[N_CHAIN];
    double t = 0.0;
    for (int b = 0; b < N_CHAIN; ++b) {
        rows[b] = (bk_rupture_block){0, b, t, 100.0, 0.0};
        t += b < 9 ? 1.0 : 0.25;
    }
    double distance[N_CHAIN], speed[N_CHAIN];
    bk_error err = {0};
    assert_int_equal(bk_front_profile(rows, N_CHAIN, N_CHAIN, 0, 4, distance, speed, &err), BK_OK);
    for (int b = 0; b < N_CHAIN; ++b) {
        assert_true(distance[b] == (double)b);
        if (b <= 7)
            assert_true(fabs(speed[b] - 1.0) < 1e-12);
        if (b >= 11)
            assert_true(fabs(speed[b] - 4.0) < 1e-12);
        if (b > 7 && b < 11)
            assert_true(speed[b] > 1.0 && speed[b] < 4.0);
    }
    assert_int_equal(bk_front_profile(rows, N_CHAIN, N_CHAIN, 0, 1, distance, speed, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "window of 1 blocks (allowed: at least 2)"));
}

/* Block 0 on a driver spring k = 2 N/m moving at 1 m/s, with 0.25 N applied: stuck at 0 until
 * t = 1, slipping to 0.5 m until t = 2.  Ruptures begin at 3 s, 1 s and 1.5 s (listed out of
 * order): k (D - x) + 0.25 = 5.25, 2.25, and unknown (the edge block slips then). */
static void test_edge_force(void **state)
{
    (void)state;
    bk_model *model = bk_model_create(3);
    assert_non_null(model);
    model->blocks[0].driver_stiffness = 2.0;
    model->blocks[0].applied_force = 0.25;
    model->driver.velocity = 1.0;
    const bk_transition transitions[] = {
        {1.0, 0, BK_MODE_STICK, BK_MODE_SLIP_POS, 0.0, 0.0, 2.0},
        {1.2, 1, BK_MODE_STICK, BK_MODE_SLIP_POS, 0.1, 0.0, 1.0},
        {2.0, 0, BK_MODE_SLIP_POS, BK_MODE_STICK, 0.5, 0.0, 1.0},
    };
    bk_rupture ruptures[3];
    memset(ruptures, 0, sizeof ruptures);
    ruptures[0].t_start = 3.0;
    ruptures[1].t_start = 1.0;
    ruptures[2].t_start = 1.5;
    double force[3];
    bk_error err = {0};
    assert_int_equal(bk_fronts_edge_force(model, transitions, 3, ruptures, 3, 0, force, &err), BK_OK);
    assert_true(fabs(force[0] - 5.25) < 1e-15);
    assert_true(fabs(force[1] - 2.25) < 1e-15);
    assert_true(isnan(force[2]));
    /* The right edge: block 2, no driver spring, never moved: its applied force only. */
    model->blocks[2].applied_force = -0.5;
    assert_int_equal(bk_fronts_edge_force(model, transitions, 3, ruptures, 3, 1, force, &err), BK_OK);
    assert_true(force[0] == -0.5 && force[1] == -0.5 && force[2] == -0.5);
    bk_model_free(model);
}

/* --- a side-driven chain, run ---------------------------------------------------------- */

typedef struct catalog_sink {
    bk_rupture *r;
    bk_rupture_block *b;
    bk_transition *t;
    size_t n_r, n_b, n_t, cap_r, cap_b, cap_t;
} catalog_sink;

static int keep_transition(void *self, const bk_transition *t, bk_error *err)
{
    (void)err;
    catalog_sink *c = self;
    if (c->n_t == c->cap_t) {
        c->cap_t = c->cap_t ? 2 * c->cap_t : 1024;
        c->t = realloc(c->t, c->cap_t * sizeof *c->t);
        assert_non_null(c->t);
    }
    c->t[c->n_t++] = *t;
    return 0;
}

static int keep_rupture(void *self, const bk_rupture *r, const bk_rupture_block *blocks, size_t n_blocks,
                        const bk_rupture_rate *rate, size_t n_rate, bk_error *err)
{
    (void)rate;
    (void)n_rate;
    (void)err;
    catalog_sink *c = self;
    if (c->n_r == c->cap_r) {
        c->cap_r = c->cap_r ? 2 * c->cap_r : 256;
        c->r = realloc(c->r, c->cap_r * sizeof *c->r);
        assert_non_null(c->r);
    }
    while (c->n_b + n_blocks > c->cap_b) {
        c->cap_b = c->cap_b ? 2 * c->cap_b : 1024;
        c->b = realloc(c->b, c->cap_b * sizeof *c->b);
        assert_non_null(c->b);
    }
    for (size_t k = 0; k < n_blocks; ++k) {
        c->b[c->n_b + k] = blocks[k];
        c->b[c->n_b + k].rupture = (int64_t)c->n_r;
    }
    c->n_b += n_blocks;
    c->r[c->n_r++] = *r;
    return 0;
}

static int ignore_sample(void *self, const bk_sample *s, bk_error *err)
{
    (void)self;
    (void)s;
    (void)err;
    return 0;
}

static int by_start(const void *a, const void *b)
{
    double x = ((const bk_front *)a)->t_start, y = ((const bk_front *)b)->t_start;
    return x < y ? -1 : x > y;
}

/* A 20-block chain pushed at block 0 through a driver spring: precursors from the edge that
 * arrest further as the edge force grows, until one crosses the chain.  At rest, the edge force
 * is carried by the friction of the blocks a precursor moved, stopped near the kinetic level
 * (overdamped stops): L ~ F / (mu_d N), which each record (a precursor longer than all before
 * it) follows, and the first to cross comes at F ~ N mu_d N.  (Small slips at the edge come
 * at every load; the records carry the law.) */
static void test_precursors(void **state)
{
    (void)state;
    const char *text = "[model]\nn_blocks = 20\ncoupling_stiffness = 1000\n[block]\nmass = 1\ndriver_stiffness = 0\n"
                       "normal_force = 1\ndamping = 2\n[block.0]\ndriver_stiffness = 1000\n[friction]\nlaw = coulomb\n"
                       "mu_s = 0.6\nmu_d = 0.4\n[driver]\nvelocity = 1e-3\n[solver]\nmethod = cvode_adams\n"
                       "rtol = 1e-7\n[output]\ninterval = 0\n[run]\nt_end = 90\n";
    bk_config *config = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "precursors.ini", NULL, 0, &config, &err), BK_OK);
    catalog_sink c;
    memset(&c, 0, sizeof c);
    bk_sink sink = {.self = &c, .sample = ignore_sample, .transition = keep_transition, .rupture = keep_rupture};
    bk_run_stats stats;
    assert_int_equal(bk_run(config, &sink, &stats, NULL, NULL, &err), BK_OK);
    double *force = malloc(c.n_r * sizeof *force);
    bk_front *fronts = malloc(c.n_r * sizeof *fronts);
    assert_int_equal(bk_fronts_edge_force(config->model, c.t, c.n_t, c.r, c.n_r, 0, force, &err), BK_OK);
    assert_int_equal(bk_fronts(c.r, c.n_r, c.b, c.n_b, 20, 0, force, fronts, &err), BK_OK);
    /* In order of start (ruptures complete out of it): the from-edge ruptures, and the records
     * among them. */
    qsort(fronts, c.n_r, sizeof *fronts, by_start);
    size_t n_edge = 0, records = 0;
    double best = 0.0, best_force = -INFINITY, first_crossing = NAN;
    for (size_t k = 0; k < c.n_r && isnan(first_crossing); ++k) {
        const bk_front *f = &fronts[k];
        if (!f->from_edge || !isfinite(f->edge_force))
            continue;
        ++n_edge;
        if (f->crossed)
            first_crossing = f->edge_force;
        if (f->arrest_length > best) {
            /* A record: longer than every precursor before it, at a larger edge force. */
            assert_true(f->edge_force > best_force);
            best = f->arrest_length;
            best_force = f->edge_force;
            double predicted = f->edge_force / 0.4;
            print_message("record: edge force %.3f N, arrest length %d blocks (F / mu_d N = %.1f)\n", f->edge_force,
                          (int)f->arrest_length, predicted);
            assert_true(fabs(f->arrest_length - predicted) <= 0.25 * predicted + 2.0);
            ++records;
        }
    }
    /* The chain crosses once its whole length can no longer hold the force at the kinetic level. */
    print_message("%zu ruptures, %zu from the edge before the first crossing, %zu records; the first crossing at an "
                  "edge force of %.3f N (N mu_d N = 8 N)\n", c.n_r, n_edge, records, first_crossing);
    assert_true(records >= 10);
    assert_true(fabs(first_crossing - 8.0) < 0.15 * 8.0);
    free(force);
    free(fronts);
    free(c.r);
    free(c.b);
    free(c.t);
    bk_config_free(config);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fronts_known),
        cmocka_unit_test(test_front_profile),
        cmocka_unit_test(test_edge_force),
        cmocka_unit_test(test_precursors),
    };
    return cmocka_run_group_tests_name("fronts", tests, NULL, NULL);
}
