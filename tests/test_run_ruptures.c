/* The rupture catalog of real runs (src/run_ruptures.c): the ruptures a run writes are those
 * rebuilt from its /transitions by the definition (an independent rebuild here: episodes,
 * every linked pair found by a sweep over neighbouring blocks, connected components), on a
 * free chain, a ring and a torus; ruptures at opposite ends that overlap in time are two,
 * fronts that meet are one, a rupture running at t_end is kept and marked; a uniform ring
 * gives one rupture per cycle with the single block's closed form and a simultaneous front;
 * and every rupture's moment-rate function integrates to its potency to 1e-3. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "capacity.h"
#include "bksim/bksim.h"
#include "exact_single.h"

typedef struct rupture_sink {
    bk_transition *transitions;
    size_t n_transitions, cap_transitions;
    bk_rupture *ruptures;
    size_t n_ruptures, cap_ruptures;
    bk_rupture_block *blocks;
    size_t n_blocks, cap_blocks;
    bk_rupture_rate *rate;
    size_t n_rate, cap_rate;
    size_t n_events;
    double *x_last;
    double t_last;
} rupture_sink;

static void *grow(void *items, size_t *capacity, size_t need, size_t size)
{
    void *grown = bk_grow_array(items, capacity, need, size, 64);
    assert_non_null(grown);
    return grown;
}

static int on_sample(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    rupture_sink *c = self;
    if (!c->x_last)
        c->x_last = malloc(s->n_blocks * sizeof *c->x_last);
    memcpy(c->x_last, s->x, s->n_blocks * sizeof *s->x);
    c->t_last = s->t;
    return BK_OK;
}

static int on_transition(void *self, const bk_transition *t, bk_error *err)
{
    (void)err;
    rupture_sink *c = self;
    c->transitions = grow(c->transitions, &c->cap_transitions, c->n_transitions + 1, sizeof *t);
    c->transitions[c->n_transitions++] = *t;
    return BK_OK;
}

static int on_event(void *self, const bk_event *e, bk_error *err)
{
    (void)e;
    (void)err;
    ((rupture_sink *)self)->n_events++;
    return BK_OK;
}

static int on_rupture(void *self, const bk_rupture *r, const bk_rupture_block *blocks, size_t n_blocks,
                      const bk_rupture_rate *rate, size_t n_rate, bk_error *err)
{
    (void)err;
    rupture_sink *c = self;
    assert_int_equal((size_t)r->n_blocks, n_blocks);
    c->ruptures = grow(c->ruptures, &c->cap_ruptures, c->n_ruptures + 1, sizeof *r);
    c->ruptures[c->n_ruptures++] = *r;
    c->blocks = grow(c->blocks, &c->cap_blocks, c->n_blocks + n_blocks, sizeof *blocks);
    memcpy(c->blocks + c->n_blocks, blocks, n_blocks * sizeof *blocks);
    c->n_blocks += n_blocks;
    if (n_rate > 0) {
        c->rate = grow(c->rate, &c->cap_rate, c->n_rate + n_rate, sizeof *rate);
        memcpy(c->rate + c->n_rate, rate, n_rate * sizeof *rate);
        c->n_rate += n_rate;
    }
    return BK_OK;
}

static void sink_free(rupture_sink *c)
{
    free(c->transitions);
    free(c->ruptures);
    free(c->blocks);
    free(c->rate);
    free(c->x_last);
}

static bk_config *load(const char *text_or_path, int is_path, const char *const *overrides, size_t n)
{
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = is_path ? bk_config_load_file(text_or_path, overrides, n, &c, &err)
                     : bk_config_load_string(text_or_path, "ruptures.ini", overrides, n, &c, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    return c;
}

static void run_into(const bk_config *c, rupture_sink *s)
{
    bk_sink sink = {.self = s, .sample = on_sample, .transition = on_transition, .event = on_event,
                    .rupture = on_rupture};
    bk_error err = {0};
    if (bk_run(c, &sink, NULL, NULL, NULL, &err) != BK_OK)
        fail_msg("%s", err.message);
}

/* ------------------------------------------------------- the rebuild --- */

typedef struct episode {
    long block;
    double a, b, xa, xb; /* onset and stop times, positions */
    int open;
    size_t root;
} episode;

static size_t find(episode *e, size_t k)
{
    while (e[k].root != k) {
        e[k].root = e[e[k].root].root;
        k = e[k].root;
    }
    return k;
}

static void link(episode *e, size_t p, size_t q)
{
    size_t a = find(e, p), b = find(e, q);
    if (a != b)
        e[a > b ? a : b].root = a < b ? a : b;
}

typedef struct rebuilt {
    double t_start, t_end, potency, path; /* path: sum of |slip| over the episodes */
    long first_block, n_blocks, n_episodes, lo, hi;
    int complete;
} rebuilt;

static int by_start(const void *p, const void *q)
{
    const rebuilt *a = p, *b = q;
    if (a->t_start != b->t_start)
        return (a->t_start > b->t_start) - (a->t_start < b->t_start);
    return (a->first_block > b->first_block) - (a->first_block < b->first_block);
}

static const bk_rupture *sorting; /* qsort has no user pointer */
static int rupture_by_start(const void *p, const void *q)
{
    const bk_rupture *a = &sorting[*(const size_t *)p], *b = &sorting[*(const size_t *)q];
    if (a->t_start != b->t_start)
        return (a->t_start > b->t_start) - (a->t_start < b->t_start);
    return (a->first_block > b->first_block) - (a->first_block < b->first_block);
}

/* The ruptures by the definition, from the transitions alone (every block at rest at t = 0;
 * episodes still open end at the last row). */
static rebuilt *rebuild(const bk_model *m, const rupture_sink *s, size_t *count)
{
    size_t n = m->n_blocks;
    episode *e = calloc(s->n_transitions + n + 1, sizeof *e);
    long *open_of = malloc(n * sizeof *open_of);
    assert_true(e && open_of);
    for (size_t i = 0; i < n; ++i)
        open_of[i] = -1;
    size_t n_e = 0;
    for (size_t k = 0; k < s->n_transitions; ++k) {
        const bk_transition *t = &s->transitions[k];
        size_t i = (size_t)t->block;
        if (open_of[i] < 0 && t->to != BK_MODE_STICK) {
            e[n_e] = (episode){(long)i, t->t, NAN, t->x, NAN, 1, n_e};
            open_of[i] = (long)n_e++;
        } else if (open_of[i] >= 0 && t->to == BK_MODE_STICK) {
            episode *ep = &e[open_of[i]];
            ep->b = t->t;
            ep->xb = t->x;
            ep->open = 0;
            open_of[i] = -1;
        }
    }
    for (size_t i = 0; i < n; ++i)
        if (open_of[i] >= 0) {
            e[open_of[i]].b = s->t_last;
            e[open_of[i]].xb = s->x_last[i];
        }
    /* Episodes per block in time order (they are created in time order). */
    size_t *start = calloc(n + 1, sizeof *start), *order = malloc((n_e + 1) * sizeof *order);
    assert_true(start && order);
    for (size_t k = 0; k < n_e; ++k)
        start[e[k].block + 1]++;
    for (size_t i = 0; i < n; ++i)
        start[i + 1] += start[i];
    size_t *fill = malloc((n + 1) * sizeof *fill);
    memcpy(fill, start, (n + 1) * sizeof *fill);
    for (size_t k = 0; k < n_e; ++k)
        order[fill[e[k].block]++] = k;
    free(fill);
    for (size_t i = 0; i < n; ++i) {
        /* The same block: one episode's stop at the next one's onset. */
        for (size_t p = start[i]; p + 1 < start[i + 1]; ++p)
            if (e[order[p]].b >= e[order[p + 1]].a)
                link(e, order[p], order[p + 1]);
        long partners[BK_MAX_NEIGHBOURS];
        bk_model_neighbours(m, i, partners);
        for (size_t d = 0; d < BK_MAX_NEIGHBOURS; ++d) {
            if (partners[d] < 0 || (size_t)partners[d] <= i)
                continue;
            size_t j = (size_t)partners[d];
            /* Two sorted lists of disjoint intervals: every meeting pair by a merge walk. */
            size_t p = start[i], q = start[j];
            while (p < start[i + 1] && q < start[j + 1]) {
                const episode *x = &e[order[p]], *y = &e[order[q]];
                if (fmax(x->a, y->a) <= fmin(x->b, y->b))
                    link(e, order[p], order[q]);
                if (x->b < y->b || (x->b == y->b && p + 1 < start[i + 1]))
                    p++;
                else
                    q++;
            }
        }
    }
    /* The components. */
    rebuilt *out = calloc(n_e + 1, sizeof *out);
    long *slot = malloc((n_e + 1) * sizeof *slot);
    assert_true(out && slot);
    size_t n_out = 0;
    for (size_t k = 0; k < n_e; ++k)
        slot[k] = -1;
    for (size_t k = 0; k < n_e; ++k) {
        size_t r = find(e, k);
        if (slot[r] < 0) {
            slot[r] = (long)n_out;
            out[n_out++] = (rebuilt){INFINITY, -INFINITY, 0.0, 0.0, -1, 0, 0, (long)n, -1, 1};
        }
        rebuilt *c = &out[slot[r]];
        const episode *ep = &e[k];
        if (ep->a < c->t_start || (ep->a == c->t_start && ep->block < c->first_block)) {
            c->t_start = ep->a;
            c->first_block = ep->block;
        }
        c->t_end = fmax(c->t_end, ep->b);
        c->potency += ep->xb - ep->xa; /* signed: a slip back counts negative */
        c->path += fabs(ep->xb - ep->xa);
        c->n_episodes++;
        c->lo = ep->block < c->lo ? ep->block : c->lo;
        c->hi = ep->block > c->hi ? ep->block : c->hi;
        c->complete &= !ep->open;
    }
    /* Distinct blocks: episodes visited block by block, a component counting a block the
     * first time it meets it. */
    long *last_block = malloc((n_out + 1) * sizeof *last_block);
    assert_non_null(last_block);
    for (size_t c = 0; c < n_out; ++c)
        last_block[c] = -1;
    for (size_t i = 0; i < n; ++i)
        for (size_t p = start[i]; p < start[i + 1]; ++p) {
            size_t c = (size_t)slot[find(e, order[p])];
            if (last_block[c] != (long)i) {
                last_block[c] = (long)i;
                out[c].n_blocks++;
            }
        }
    free(last_block);
    qsort(out, n_out, sizeof *out, by_start);
    free(slot);
    free(start);
    free(order);
    free(open_of);
    free(e);
    *count = n_out;
    return out;
}

/* The run's ruptures are the rebuilt ones; a free chain's extent is the first and last
 * block.  Returns each rupture's path (the sum of |slip| over its episodes, what its rate
 * integrates to), in the run's order. */
static double *expect_rebuilt(const bk_config *c, rupture_sink *s)
{
    size_t n = 0;
    rebuilt *r = rebuild(c->model, s, &n);
    assert_int_equal(s->n_ruptures, n);
    size_t *order = malloc((n + 1) * sizeof *order);
    double *path = malloc((n + 1) * sizeof *path);
    assert_true(order && path);
    for (size_t k = 0; k < n; ++k)
        order[k] = k;
    sorting = s->ruptures;
    qsort(order, n, sizeof *order, rupture_by_start);
    int free_chain = c->model->rows == 1 && c->model->boundary_cols != BK_BOUNDARY_PERIODIC;
    for (size_t k = 0; k < n; ++k) {
        const bk_rupture *a = &s->ruptures[order[k]];
        const rebuilt *b = &r[k];
        path[order[k]] = b->path;
        assert_true(a->t_start == b->t_start && a->t_end == b->t_end);
        assert_int_equal(a->first_block, b->first_block);
        assert_int_equal(a->n_blocks, b->n_blocks);
        assert_int_equal(a->n_episodes, b->n_episodes);
        assert_int_equal(a->complete, b->complete);
        assert_close(a->potency, b->potency, 1e-12, 1e-300);
        assert_close(a->duration, b->t_end - b->t_start, 0.0, 0.0);
        if (free_chain) {
            assert_int_equal(a->left, b->lo);
            assert_int_equal(a->right, b->hi);
        }
    }
    free(order);
    free(r);
    return path;
}

/* Every complete rupture's rate rows integrate (trapezoids) to its path (its potency when no
 * episode slips back) to 1e-3. */
static double worst_rate_error(const rupture_sink *s, const double *path)
{
    double *integral = calloc(s->n_ruptures + 1, sizeof *integral);
    for (size_t k = 1; k < s->n_rate; ++k) {
        const bk_rupture_rate *p = &s->rate[k - 1], *q = &s->rate[k];
        if (p->rupture == q->rupture)
            integral[q->rupture] += 0.5 * (q->t - p->t) * (p->rate + q->rate);
    }
    double worst = 0.0;
    size_t checked = 0;
    for (size_t k = 0; k < s->n_ruptures; ++k) {
        const bk_rupture *r = &s->ruptures[k];
        if (!r->complete || !(path[k] > 0.0))
            continue;
        worst = fmax(worst, fabs(integral[k] - path[k]) / path[k]);
        checked++;
    }
    assert_true(checked > 0);
    free(integral);
    return worst;
}

/* Done-when 1 and 4: the shipped 1,000-block chain (exact stepper and an integrator), the
 * 1,000-block Carlson-Langer ring and a 12 x 12 torus. */
static void test_runs_match_rebuild(void **state)
{
    (void)state;
    static const char *const exact[] = {"run.t_end=1", "output.interval=0"};
    static const char *const rk[] = {"run.t_end=0.5", "output.interval=0", "solver.method=gsl_rk8pd"};
    static const char *const ring[] = {"run.t_end=100", "output.interval=0", "output.transitions=true"};
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
        rupture_sink s = {0};
        run_into(c, &s);
        size_t largest = 0;
        for (size_t k = 0; k < s.n_ruptures; ++k)
            largest = s.ruptures[k].n_blocks > s.ruptures[largest].n_blocks ? k : largest;
        double *path = expect_rebuilt(c, &s);
        double worst = worst_rate_error(&s, path);
        size_t back = 0;
        for (size_t k = 0; k < s.n_ruptures; ++k)
            back += path[k] > s.ruptures[k].potency * (1.0 + 1e-12);
        free(path);
        print_message("%s: %zu transitions, %zu events, %zu ruptures (largest %d blocks), %zu rate rows, "
                      "worst rate integral error %.2g; %zu ruptures slip back somewhere\n", runs[r].path,
                      s.n_transitions, s.n_events, s.n_ruptures, s.ruptures[largest].n_blocks, s.n_rate, worst, back);
        assert_true(s.n_ruptures > s.n_events); /* windows merge ruptures */
        assert_true(s.ruptures[largest].n_blocks > 5);
        assert_true(worst <= 1e-3);
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

/* Block 0 fails 1 ms before block 39 and both slip for ~30 ms: one time window, two
 * ruptures. */
static void test_opposite_ends_are_two(void **state)
{
    (void)state;
    bk_config *c = load(chain_text, 0, NULL, 0);
    rupture_sink s = {0};
    run_into(c, &s);
    assert_true(s.n_ruptures >= 2);
    const bk_rupture *a = &s.ruptures[0], *b = &s.ruptures[1];
    assert_int_equal(a->first_block, 0);
    assert_int_equal(b->first_block, 39);
    assert_true(a->right < 5 && b->left > 34);
    assert_true(b->t_start < a->t_end); /* they overlap in time */
    free(expect_rebuilt(c, &s));
    sink_free(&s);
    bk_config_free(c);
}

/* A strongly coupled chain loaded at both ends: fronts start at blocks 0 and 20 at one
 * instant, run inwards and meet; one rupture of all 21 blocks, whose last arrival is in the
 * middle. */
static void test_fronts_that_meet_are_one(void **state)
{
    (void)state;
    const char *text = "[model]\nn_blocks = 21\ncoupling_stiffness = 1e5\n"
                       "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                       "[block.0]\nx_init = -1e-5\n[block.20]\nx_init = -1e-5\n"
                       "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.3\n"
                       "[driver]\nvelocity = 1e-3\n[solver]\nmethod = exact\n[output]\ninterval = 0\n"
                       "[run]\nt_end = 0.6\n";
    bk_config *c = load(text, 0, NULL, 0);
    rupture_sink s = {0};
    run_into(c, &s);
    assert_true(s.n_ruptures >= 1);
    const bk_rupture *r = &s.ruptures[0];
    print_message("first rupture: %d blocks from block %d, %.6g s, fronts %.4g and %.4g blocks/s\n", r->n_blocks,
                  r->first_block, r->duration, r->front_speed_left, r->front_speed_right);
    assert_int_equal(r->n_blocks, 21);
    assert_int_equal(r->first_block, 0);
    double last = -INFINITY;
    int32_t last_block = -1;
    for (size_t k = 0; k < (size_t)r->n_blocks; ++k)
        if (s.blocks[k].t_onset > last) {
            last = s.blocks[k].t_onset;
            last_block = s.blocks[k].block;
        }
    assert_true(last_block >= 8 && last_block <= 12);
    assert_true(s.blocks[20].t_onset == s.blocks[0].t_onset); /* both ends at one instant */
    free(expect_rebuilt(c, &s));
    sink_free(&s);
    bk_config_free(c);
}

/* Case A's first slip runs from 0.5886 s to 0.6204 s: a run ending at 0.6 s keeps its
 * rupture, marked incomplete, with the slip so far (the closed form's). */
static void test_running_at_end(void **state)
{
    (void)state;
    const char *text = "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                       "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.1\n[driver]\nvelocity = 1e-3\n"
                       "[output]\ninterval = 0\n[run]\nt_end = 0.6\n";
    bk_config *c = load(text, 0, NULL, 0);
    rupture_sink s = {0};
    run_into(c, &s);
    exact_params p = {1.0, 1e4, 9.81, 0.6, 0.1, 1e-3, 0};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, 0.6, &ex), 0);
    double x_end, v_end;
    exact_state(&ex, 0.6, &x_end, &v_end);
    assert_int_equal(s.n_ruptures, 1);
    const bk_rupture *r = &s.ruptures[0];
    assert_int_equal(r->complete, 0);
    assert_close(r->t_start, 0.5886, 1e-14, 0.0);
    assert_close(r->t_end, 0.6, 0.0, 0.0);
    assert_close(r->potency, x_end - ex.events[0].x, 1e-12, 0.0);
    assert_close(r->max_slip_rate, v_end, 1e-12, 0.0);
    assert_close(s.blocks[0].slip, x_end - ex.events[0].x, 1e-12, 0.0);
    free(expect_rebuilt(c, &s));
    exact_free(&ex);
    sink_free(&s);
    bk_config_free(c);
}

/* Done-when 2: a uniform ring started relaxed moves as one block: one rupture per cycle, of
 * every block, with the single block's closed form (potency n times its slip, largest slip
 * rate V + sqrt((omega a)^2 + V^2)); the exact stepper starts every block at one instant, so
 * the front is simultaneous (speed +inf on both sides). */
static void test_uniform_ring_one_per_cycle(void **state)
{
    (void)state;
    const size_t n = 8;
    const char *text = "[model]\nn_blocks = 8\nboundary = periodic\ncoupling_stiffness = 2e4\n"
                       "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                       "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.1\n[driver]\nvelocity = 1e-3\n"
                       "[solver]\nmethod = exact\n[output]\ninterval = 0\n[run]\nt_end = 5\n";
    bk_config *c = load(text, 0, NULL, 0);
    rupture_sink s = {0};
    run_into(c, &s);
    exact_params p = {1.0, 1e4, 9.81, 0.6, 0.1, 1e-3, 0};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, 5.0, &ex), 0);
    size_t slips = 0;
    for (size_t k = 0; k < ex.n_events; ++k)
        slips += ex.events[k].to != BK_MODE_STICK;
    assert_int_equal(s.n_ruptures, slips);
    double omega = 100.0, amplitude = 0.5 * 9.81 / 1e4, V = 1e-3;
    double v_max = V + sqrt(omega * amplitude * omega * amplitude + V * V);
    for (size_t k = 0, e = 0; k + 1 < ex.n_events; ++k) {
        if (ex.events[k].to == BK_MODE_STICK)
            continue;
        const bk_rupture *r = &s.ruptures[e++];
        const exact_event *on = &ex.events[k], *off = &ex.events[k + 1];
        assert_int_equal(r->n_blocks, (int)n);
        assert_int_equal(r->n_episodes, (int)n);
        assert_int_equal(r->first_block, 0);
        assert_true(r->complete);
        assert_close(r->t_start, on->t, 1e-13, 0.0);
        assert_close(r->t_end, off->t, 1e-13, 0.0);
        assert_close(r->potency, (double)n * (off->x - on->x), 1e-11, 0.0);
        assert_close(r->stress_drop, on->force - off->force, 1e-11, 0.0);
        assert_close(r->max_slip_rate, v_max, 1e-12, 0.0);
        assert_true(isinf(r->front_speed_left) && r->front_speed_left > 0.0);
        assert_true(isinf(r->front_speed_right) && r->front_speed_right > 0.0);
    }
    double *path = expect_rebuilt(c, &s);
    assert_true(worst_rate_error(&s, path) <= 1e-3);
    free(path);
    exact_free(&ex);
    sink_free(&s);
    bk_config_free(c);
}

/* Without /rupture_rate the catalog is the same, and no rate row is handed on. */
static void test_rate_off_same_catalog(void **state)
{
    (void)state;
    static const char *const with[] = {"run.t_end=0.5", "output.interval=0"};
    static const char *const without[] = {"run.t_end=0.5", "output.interval=0", "catalog.rupture_rate=false"};
    bk_config *a = load("configs/chains/bk1000_coulomb.ini", 1, with, 2);
    bk_config *b = load("configs/chains/bk1000_coulomb.ini", 1, without, 3);
    rupture_sink sa = {0}, sb = {0};
    run_into(a, &sa);
    run_into(b, &sb);
    assert_true(sa.n_rate > 0);
    assert_int_equal(sb.n_rate, 0);
    assert_int_equal(sa.n_ruptures, sb.n_ruptures);
    for (size_t k = 0; k < sa.n_ruptures; ++k) {
        assert_true(sa.ruptures[k].t_start == sb.ruptures[k].t_start);
        assert_true(sa.ruptures[k].potency == sb.ruptures[k].potency);
        assert_int_equal(sa.ruptures[k].n_blocks, sb.ruptures[k].n_blocks);
        /* The largest slip rate is located on the dense output either way. */
        assert_close(sa.ruptures[k].max_slip_rate, sb.ruptures[k].max_slip_rate, 1e-9, 0.0);
    }
    sink_free(&sa);
    sink_free(&sb);
    bk_config_free(a);
    bk_config_free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runs_match_rebuild),
        cmocka_unit_test(test_opposite_ends_are_two),
        cmocka_unit_test(test_fronts_that_meet_are_one),
        cmocka_unit_test(test_running_at_end),
        cmocka_unit_test(test_uniform_ring_one_per_cycle),
        cmocka_unit_test(test_rate_off_same_catalog),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
