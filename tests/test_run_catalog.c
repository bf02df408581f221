/* The event catalog of real runs (src/run_catalog.c): the events a run writes are the events
 * rebuilt from its transitions by the definition (bit for bit), ruptures at opposite ends
 * that overlap in time are one event, an event running at t_end is kept and marked, a
 * uniform ring follows the single block's closed form, the largest slip rate is the true
 * maximum, and laws without a stuck state are catalogued by their slip-rate threshold. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "capacity.h"
#include "bksim/bksim.h"
#include "exact_single.h"
#include "same_output.h"

typedef struct catalog_sink {
    bk_transition *transitions;
    size_t n_transitions, cap_transitions;
    bk_event *events;
    size_t n_events, cap_events;
    double *x_last;           /* the last row's positions */
    double t_last, driver_last;
    struct row {
        double t, speed; /* s; the largest |v| of the row, m/s */
    } *rows;
    size_t n_rows, cap_rows;
    int sink_has_events;      /* the run keeps a catalog */
} catalog_sink;

/* Room for one more item (a failed allocation fails the test). */
static void *grow(void *items, size_t *capacity, size_t count, size_t size)
{
    void *grown = bk_grow_array(items, capacity, count + 1, size, 64);
    assert_non_null(grown);
    return grown;
}

static int on_sample(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    catalog_sink *c = self;
    if (!c->x_last)
        c->x_last = malloc(s->n_blocks * sizeof *c->x_last);
    memcpy(c->x_last, s->x, s->n_blocks * sizeof *s->x);
    c->t_last = s->t;
    c->driver_last = s->driver;
    double speed = 0.0;
    for (size_t i = 0; i < s->n_blocks; ++i)
        speed = fmax(speed, fabs(s->v[i]));
    c->rows = grow(c->rows, &c->cap_rows, c->n_rows, sizeof *c->rows);
    c->rows[c->n_rows++] = (struct row){s->t, speed};
    return BK_OK;
}

static int on_transition(void *self, const bk_transition *t, bk_error *err)
{
    (void)err;
    catalog_sink *c = self;
    c->transitions = grow(c->transitions, &c->cap_transitions, c->n_transitions, sizeof *t);
    c->transitions[c->n_transitions++] = *t;
    return BK_OK;
}

static int on_event(void *self, const bk_event *e, bk_error *err)
{
    (void)err;
    catalog_sink *c = self;
    c->events = grow(c->events, &c->cap_events, c->n_events, sizeof *e);
    c->events[c->n_events++] = *e;
    return BK_OK;
}

static void sink_free(catalog_sink *c)
{
    free(c->transitions);
    free(c->events);
    free(c->x_last);
    free(c->rows);
}

static bk_config *load(const char *text_or_path, int is_path, const char *const *overrides, size_t n)
{
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = is_path ? bk_config_load_file(text_or_path, overrides, n, &c, &err)
                     : bk_config_load_string(text_or_path, "catalog.ini", overrides, n, &c, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    return c;
}

static void run_into(const bk_config *c, catalog_sink *s)
{
    bk_sink sink = {.self = s, .sample = on_sample, .transition = on_transition, .event = on_event};
    bk_error err = {0};
    if (bk_run(c, &sink, NULL, NULL, NULL, &err) != BK_OK)
        fail_msg("%s", err.message);
}

typedef struct force_ctx {
    const bk_model *model;
    const double *x;
    double driver;
} force_ctx;

static double force_at(const void *user, size_t i)
{
    const force_ctx *f = user;
    return bk_model_applied_force(f->model, i, f->x, f->driver);
}

/* The catalog by the definition, from the transitions alone (every block at rest at t = 0),
 * closed at the last row; returns the events in a malloc'ed array. */
static bk_event *rebuild(const bk_config *c, const catalog_sink *s, size_t *count)
{
    const bk_model *m = c->model;
    bk_catalog *b = bk_catalog_create_lattice(m->rows, m->cols, m->boundary_rows == BK_BOUNDARY_PERIODIC,
                                              m->boundary_cols == BK_BOUNDARY_PERIODIC, c->catalog.magnitude_offset);
    assert_non_null(b);
    bk_event *out = calloc(s->n_transitions + 2, sizeof *out);
    size_t n = 0;
    for (size_t k = 0; k < s->n_transitions; ++k) {
        int done = 0;
        assert_int_equal(bk_catalog_add(b, &s->transitions[k], &out[n], &done), BK_OK);
        n += (size_t)done;
    }
    force_ctx f = {m, s->x_last, s->driver_last};
    n += (size_t)bk_catalog_finish(b, s->t_last, s->x_last, force_at, &f, &out[n]);
    bk_catalog_free(b);
    *count = n;
    return out;
}

/* Every field but max_slip_rate, which the transitions do not hold, bit for bit. */
static void expect_rebuilt(const bk_config *c, const catalog_sink *s)
{
    size_t n = 0;
    bk_event *rebuilt = rebuild(c, s, &n);
    assert_int_equal(s->n_events, n);
    for (size_t k = 0; k < n; ++k) {
        rebuilt[k].max_slip_rate = s->events[k].max_slip_rate;
        assert_same_event(&s->events[k], &rebuilt[k]);
    }
    free(rebuilt);
}

/* Done-when 1: the 1,000-block chain shipped in configs/, with the exact stepper and with an
 * integrator, the 1,000-block Carlson-Langer ring, and a lattice. */
static void test_chain_1000_matches_rebuild(void **state)
{
    (void)state;
    static const char *const exact[] = {"run.t_end=1", "output.interval=0"};
    static const char *const rk[] = {"run.t_end=0.5", "output.interval=0", "solver.method=gsl_rk8pd"};
    static const char *const ring[] = {"run.t_end=100", "output.interval=0", "output.transitions=true"};
    /* A 12 x 12 torus of random strength: bounding boxes that wrap round its edges. */
    static const char *const torus[] = {"model.rows=12", "model.cols=12", "model.boundary=periodic",
                                        "driver.velocity=1e-5", "run.t_end=62"};
    struct {
        const char *path;
        const char *const *overrides;
        size_t n;
    } runs[] = {{"configs/chains/bk1000_coulomb.ini", exact, 2},
                {"configs/chains/bk1000_coulomb.ini", rk, 3},
                {"configs/chains/carlson_langer_1000.ini", ring, 3},
                {"configs/lattices/lattice_64x64.ini", torus, 5}};
    for (size_t r = 0; r < sizeof runs / sizeof runs[0]; ++r) {
        bk_config *c = load(runs[r].path, 1, runs[r].overrides, runs[r].n);
        catalog_sink s = {0};
        run_into(c, &s);
        print_message("%s: %zu transitions, %zu events\n", runs[r].path, s.n_transitions, s.n_events);
        assert_true(s.n_events >= 2);
        expect_rebuilt(c, &s);
        size_t largest = 0;
        for (size_t k = 0; k < s.n_events; ++k)
            largest = s.events[k].n_blocks > s.events[largest].n_blocks ? k : largest;
        assert_true(s.events[largest].n_blocks > 10); /* not only single-block events */
        if (c->model->rows > 1) {
            size_t wrapped = 0;
            for (size_t k = 0; k < s.n_events; ++k)
                wrapped += s.events[k].left > s.events[k].right;
            print_message("%zu events' boxes wrap round an edge\n", wrapped);
            assert_true(wrapped > 0);
        }
        sink_free(&s);
        bk_config_free(c);
    }
}

static const char *const chain_text =
    "[model]\nn_blocks = 40\ncoupling_stiffness = 100\n"
    "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
    "[block.0]\nx_init = -2e-4\n[block.39]\nx_init = -1.99e-4\n"
    "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
    "[driver]\nvelocity = 1e-3\n[output]\ninterval = 0\n[run]\nt_end = 0.5\n";

/* Block 0 fails 1 ms before block 39 (both 0.2 s before the rest) and slips for ~30 ms: two ruptures at opposite ends,
 * overlapping in time, one event by the definition. */
static void test_overlap_at_opposite_ends(void **state)
{
    (void)state;
    bk_config *c = load(chain_text, 0, NULL, 0);
    catalog_sink s = {0};
    run_into(c, &s);
    assert_true(s.n_events >= 1);
    const bk_event *e = &s.events[0];
    assert_int_equal(e->first_block, 0);
    assert_int_equal(e->left, 0);
    assert_int_equal(e->right, 39);
    assert_true(e->n_blocks >= 2 && e->n_blocks <= 6); /* the middle of the chain stays stuck */
    assert_true(e->complete);
    /* Block 39's slip began before block 0's ended. */
    double end0 = NAN, start39 = NAN;
    for (size_t k = 0; k < s.n_transitions; ++k) {
        const bk_transition *t = &s.transitions[k];
        if (t->block == 0 && t->to == BK_MODE_STICK && isnan(end0))
            end0 = t->t;
        if (t->block == 39 && t->to != BK_MODE_STICK && isnan(start39))
            start39 = t->t;
    }
    assert_true(start39 < end0);
    expect_rebuilt(c, &s);
    sink_free(&s);
    bk_config_free(c);
}

/* What a progress callback is told matches what the sink has received at that moment. */
typedef struct progress_check {
    const catalog_sink *sink;
    long calls;
    double t_last;
} progress_check;

static int check_progress(void *user, const bk_progress *p)
{
    progress_check *pc = user;
    pc->calls++;
    assert_true(p->t >= pc->t_last && p->t <= p->t_end);
    pc->t_last = p->t;
    assert_true(p->t_resumed == 0.0 && p->events_resumed == 0);
    /* Transitions of the instant under way are counted before the sink has them. */
    long pending = p->transitions - (long)pc->sink->n_transitions;
    assert_true(pending >= 0 && pending <= 2 * 40);
    assert_int_equal(p->events, pc->sink->sink_has_events ? (long)pc->sink->n_events : -1);
    return 0;
}

static void test_progress_counts(void **state)
{
    (void)state;
    for (int with_events = 1; with_events >= 0; --with_events) {
        const char *overrides[] = {with_events ? "output.events=true" : "output.events=false", "run.t_end=3"};
        bk_config *c = load(chain_text, 0, overrides, 2);
        catalog_sink s = {.sink_has_events = with_events};
        progress_check pc = {.sink = &s};
        bk_sink sink = {.self = &s, .sample = on_sample, .transition = on_transition, .event = on_event};
        bk_error err = {0};
        if (bk_run(c, &sink, NULL, check_progress, &pc, &err) != BK_OK)
            fail_msg("%s", err.message);
        assert_true(pc.calls > 10);
        assert_true(!with_events || s.n_events >= 2);
        sink_free(&s);
        bk_config_free(c);
    }
}

/* Case A's first slip runs from 0.5886 s to 0.6204 s: a run ending at 0.6 s keeps it, marked
 * incomplete, with the slip so far as its potency (the closed form's). */
static void test_event_running_at_end(void **state)
{
    (void)state;
    const char *text = "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                       "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.1\n[driver]\nvelocity = 1e-3\n"
                       "[output]\ninterval = 0\n[run]\nt_end = 0.6\n";
    bk_config *c = load(text, 0, NULL, 0);
    catalog_sink s = {0};
    run_into(c, &s);
    exact_params p = {1.0, 1e4, 9.81, 0.6, 0.1, 1e-3, 0};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, 0.6, &ex), 0);
    double x_end, v_end;
    exact_state(&ex, 0.6, &x_end, &v_end);
    assert_int_equal(s.n_events, 1);
    const bk_event *e = &s.events[0];
    assert_int_equal(e->complete, 0);
    assert_close(e->t_start, 0.5886, 1e-14, 0.0);
    assert_close(e->t_end, 0.6, 0.0, 0.0);
    assert_close(e->potency, x_end - ex.events[0].x, 1e-12, 0.0);
    assert_close(e->max_slip_rate, v_end, 1e-12, 0.0); /* still accelerating at 0.6 s */
    expect_rebuilt(c, &s);
    exact_free(&ex);
    sink_free(&s);
    bk_config_free(c);
}

/* Done-when 1, second part: a uniform ring started relaxed moves as one block, so every
 * event is the whole ring, and count, times, potency, stress drop and the largest slip rate
 * follow from the single block's closed form (max v = V + sqrt((omega a)^2 + V^2), a the
 * amplitude (mu_s - mu_d) N / k). */
static void test_uniform_ring_closed_form(void **state)
{
    (void)state;
    const size_t n = 8;
    const char *text = "[model]\nn_blocks = 8\nboundary = periodic\ncoupling_stiffness = 2e4\n"
                       "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                       "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.1\n[driver]\nvelocity = 1e-3\n"
                       "[solver]\nmethod = exact\n[output]\ninterval = 0\n[run]\nt_end = 5\n";
    bk_config *c = load(text, 0, NULL, 0);
    catalog_sink s = {0};
    run_into(c, &s);
    exact_params p = {1.0, 1e4, 9.81, 0.6, 0.1, 1e-3, 0};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, 5.0, &ex), 0);
    size_t slips = 0;
    for (size_t k = 0; k < ex.n_events; ++k)
        slips += ex.events[k].to != BK_MODE_STICK;
    assert_int_equal(s.n_events, slips);
    double omega = 100.0, amplitude = 0.5 * 9.81 / 1e4, V = 1e-3;
    double v_max = V + sqrt(omega * amplitude * omega * amplitude + V * V);
    for (size_t k = 0, e = 0; k + 1 < ex.n_events; ++k) {
        if (ex.events[k].to == BK_MODE_STICK)
            continue;
        const bk_event *ev = &s.events[e++];
        const exact_event *on = &ex.events[k], *off = &ex.events[k + 1];
        assert_int_equal(ev->n_blocks, (int)n);
        assert_int_equal(ev->n_episodes, (int)n);
        assert_int_equal(ev->first_block, 0);
        assert_int_equal(ev->left, 0);
        assert_int_equal(ev->right, (int)n - 1);
        assert_true(ev->complete);
        assert_close(ev->t_start, on->t, 1e-13, 0.0);
        assert_close(ev->t_end, off->t, 1e-13, 0.0);
        assert_close(ev->potency, (double)n * (off->x - on->x), 1e-11, 0.0);
        assert_close(ev->magnitude, 2.0 / 3.0 * log10((double)n * (off->x - on->x)), 0.0, 1e-11);
        assert_close(ev->stress_drop, on->force - off->force, 1e-11, 0.0);
        assert_close(ev->max_slip_rate, v_max, 1e-12, 0.0);
    }
    exact_free(&ex);
    sink_free(&s);
    bk_config_free(c);
}

/* The largest slip rate against finely sampled rows: never below what the rows show, and
 * within their sampling error above it (rows 20 us apart, periods >= 21 ms). */
static void test_max_slip_rate_chain(void **state)
{
    (void)state;
    static const char *const methods[] = {"solver.method=exact", "solver.method=gsl_rk8pd",
                                          "solver.method=cvode_adams"};
    for (size_t m = 0; m < 3; ++m) {
        const char *overrides[] = {methods[m], "output.interval=2e-5", "run.t_end=2"};
        bk_config *c = load("configs/chains/bk10_coulomb.ini", 1, overrides, 3);
        catalog_sink s = {0};
        run_into(c, &s);
        assert_true(s.n_events > 5);
        for (size_t k = 0, row = 0; k < s.n_events; ++k) {
            const bk_event *e = &s.events[k];
            double sampled = 0.0;
            for (; row < s.n_rows && s.rows[row].t <= e->t_end; ++row)
                if (s.rows[row].t >= e->t_start)
                    sampled = fmax(sampled, s.rows[row].speed);
            assert_true(e->max_slip_rate >= sampled * (1.0 - 1e-9));
            assert_close(e->max_slip_rate, sampled, 2e-3, 0.0);
        }
        sink_free(&s);
        bk_config_free(c);
    }
}

/* A Dieterich-Ruina block never sticks: its events are the intervals where |v| exceeds the
 * threshold.  Rows between events stay below it, every event reaches above it, and nothing
 * goes into /transitions. */
static void test_threshold_law(void **state)
{
    (void)state;
    const char *text =
        "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 2e3\nv_init = 1e-3\n"
        "[friction]\nlaw = dieterich_ruina_aging\na = 0.01\nb = 0.015\nDc = 1e-5\nV0 = 1e-3\nf0 = 0.6\n"
        "theta_init = 0.0095\n[driver]\nvelocity = 1e-3\nstart_position = 2.943e-3\n"
        "[solver]\nmethod = cvode_bdf\nrtol = 1e-9\nmax_steps = 10000000\n"
        "[output]\ninterval = 2e-4\n[catalog]\nslip_rate_threshold = 3e-3\n[run]\nt_end = 3\n";
    bk_config *c = load(text, 0, NULL, 0);
    catalog_sink s = {0};
    run_into(c, &s);
    assert_int_equal(s.n_transitions, 0);
    assert_true(s.n_events >= 4);
    const double threshold = 3e-3;
    size_t k = 0;
    for (size_t row = 0; row < s.n_rows; ++row) {
        double t = s.rows[row].t;
        while (k < s.n_events && t > s.events[k].t_end)
            ++k;
        int inside = k < s.n_events && t >= s.events[k].t_start;
        if (!inside)
            assert_true(s.rows[row].speed <= threshold * (1.0 + 1e-9));
        else
            assert_true(s.rows[row].speed >= threshold * (1.0 - 1e-6));
    }
    for (k = 0; k < s.n_events; ++k) {
        assert_true(s.events[k].max_slip_rate > threshold);
        assert_true(s.events[k].potency > 0.0);
    }
    sink_free(&s);
    bk_config_free(c);

    /* Such a law without a threshold: refused at load, naming the key. */
    const char *missing = "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 2e3\n"
                          "[friction]\nlaw = dieterich_ruina_slip\na = 0.01\nb = 0.015\nDc = 1e-5\nV0 = 1e-3\n"
                          "f0 = 0.6\n[driver]\nvelocity = 1e-3\n[run]\nt_end = 1\n";
    bk_config *bad = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(missing, "dr.ini", NULL, 0, &bad, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "[catalog] slip_rate_threshold: required"));
    /* And a threshold where every block sticks: refused too. */
    const char *coulomb = "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 2e3\n"
                          "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n[driver]\nvelocity = 1e-3\n"
                          "[catalog]\nslip_rate_threshold = 1e-3\n[run]\nt_end = 1\n";
    assert_int_equal(bk_config_load_string(coulomb, "c.ini", NULL, 0, &bad, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "slip_rate_threshold: applies to laws without a stuck state"));
}

/* Sizes (magnitudes, binned) of the complete events of a run of the 100-block Carlson-Langer
 * ring. */
static double *ring_sizes(const char *const *overrides, size_t n_overrides, size_t *count)
{
    bk_config *c = load("configs/chains/carlson_langer_100.ini", 1, overrides, n_overrides);
    catalog_sink s = {0};
    run_into(c, &s);
    double *p = malloc((s.n_events ? s.n_events : 1) * sizeof *p);
    assert_non_null(p);
    size_t n = 0;
    for (size_t k = 0; k < s.n_events; ++k)
        if (s.events[k].complete)
            p[n++] = floor(s.events[k].magnitude / 0.1 + 0.5); /* bins of 0.1 */
    sink_free(&s);
    bk_config_free(c);
    *count = n;
    return p;
}

/* The ring is chaotic: two back-ends (or tolerances) part ways event by event, but draw their
 * event sizes from one distribution.  A two-sample Kolmogorov-Smirnov test on the sizes
 * must not reject that at the 1 % level, and must reject it (p < 1e-3) for a ring with a
 * larger drop at the onset of slip (sigma 0.01 -> 0.1), which shifts every size. Sizes are
 * magnitudes in bins of 0.1, as bksim stats bins them: the single-block events, a third of
 * all, have one potency in exact arithmetic, and their rounding would otherwise make a
 * spurious step in the distribution. */
static void test_chaotic_ring_sizes_agree_across_backends(void **state)
{
    (void)state;
    static const char *const rk8pd[] = {"run.t_end=1000", "solver.method=gsl_rk8pd", "solver.rtol=1e-8"};
    static const char *const rkf45[] = {"run.t_end=1000", "solver.method=gsl_rkf45", "solver.rtol=1e-6"};
    static const char *const dropped[] = {"run.t_end=1000", "solver.method=gsl_rk8pd", "solver.rtol=1e-8",
                                         "friction.sigma=0.1"};
    size_t n1, n2, n3;
    double *p1 = ring_sizes(rk8pd, 3, &n1);
    double *p2 = ring_sizes(rkf45, 3, &n2);
    double *p3 = ring_sizes(dropped, 4, &n3);
    assert_true(n1 > 300 && n2 > 300 && n3 > 100);
    /* Trajectories differ: the catalogs are not the same list. */
    int same = n1 == n2;
    for (size_t k = 0; same && k < n1; ++k)
        same = p1[k] == p2[k];
    assert_false(same);
    bk_ks_result agree, differ;
    bk_error err = {0};
    assert_int_equal(bk_ks_two_sample(p1, n1, p2, n2, &agree, &err), BK_OK);
    assert_int_equal(bk_ks_two_sample(p1, n1, p3, n3, &differ, &err), BK_OK);
    print_message("KS on event sizes: gsl_rk8pd at rtol 1e-8 (%zu events) vs gsl_rkf45 at 1e-6 (%zu): D = %.4f, p = %.3g; "
                  "sigma 0.01 vs 0.1 (%zu): D = %.4f, p = %.3g\n",
                  n1, n2, agree.d, agree.p, n3, differ.d, differ.p);
    assert_true(agree.p > 0.01);
    assert_true(differ.p < 1e-3);
    free(p1);
    free(p2);
    free(p3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chain_1000_matches_rebuild),
        cmocka_unit_test(test_overlap_at_opposite_ends),
        cmocka_unit_test(test_progress_counts),
        cmocka_unit_test(test_event_running_at_end),
        cmocka_unit_test(test_uniform_ring_closed_form),
        cmocka_unit_test(test_max_slip_rate_chain),
        cmocka_unit_test(test_threshold_law),
        cmocka_unit_test(test_chaotic_ring_sizes_agree_across_backends),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
