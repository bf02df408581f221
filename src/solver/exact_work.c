/* The exact stepper's memory (exact.c says what it computes): the work space a start needs
 * and no instance keeps between calls, shared by the thread's instances and
 * reference-counted, and each instance's own arena sized by its problem.  Buffers are
 * reallocated only when they do not fit, so restarts of islands of similar size allocate
 * nothing. */
#include <stdlib.h>

#include "exact_backend.h"

static _Thread_local exact_shared *thread_shared;

void bk_exact_shared_release(exact_shared *s)
{
    if (!s || --s->users > 0)
        return;
    gsl_root_fsolver_free(s->brent);
    free(s->start);
    free(s->modes);
    free(s->indices);
    free(s->couplings);
    free(s->dampings);
    free(s);
    thread_shared = NULL;
}

exact_shared *bk_exact_shared_acquire(void)
{
    exact_shared *s = thread_shared;
    if (!s) {
        s = calloc(1, sizeof *s);
        if (!s)
            return NULL;
        s->brent = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
        if (!s->brent) {
            free(s);
            return NULL;
        }
        thread_shared = s;
    }
    s->users++;
    return s;
}

int bk_exact_reserve_coupling(exact_backend *eb)
{
    exact_shared *s = eb->shared;
    coupling *couplings =
        bk_grow_array(s->couplings, &s->couplings_cap, eb->n_couplings + 1, sizeof *couplings, 256);
    if (!couplings)
        return -1;
    s->couplings = couplings;
    return 0;
}

int bk_exact_reserve_damping(exact_backend *eb)
{
    exact_shared *s = eb->shared;
    coupling *dampings =
        bk_grow_array(s->dampings, &s->dampings_cap, eb->n_dampings + 1, sizeof *dampings, 256);
    if (!dampings)
        return -1;
    s->dampings = dampings;
    return 0;
}

int bk_exact_reserve_work(exact_backend *eb, size_t largest, bk_error *err)
{
    exact_shared *s = eb->shared;
    double *modes = bk_grow_array(s->modes, &s->modes_cap, largest * largest + 3 * largest + 1,
                                  sizeof *modes, 64);
    if (!modes)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the modes of %zu pairs",
                       largest);
    eb->work = s->modes = modes;
    return BK_OK;
}

int bk_exact_reserve(exact_backend *eb, size_t n, size_t p, size_t m, size_t n_roots, bk_error *err)
{
    exact_shared *s = eb->shared;
    double *work = bk_grow_array(s->start, &s->start_cap, 5 * n + 1, sizeof *work, 64);
    if (work)
        s->start = work;
    size_t *indices =
        work ? bk_grow_array(s->indices, &s->indices_cap, 3 * (p + 1), sizeof *indices, 64) : NULL;
    if (!indices)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu components", n);
    s->indices = indices;
    double *w = s->start;
    eb->f0 = w, w += n;
    eb->probe = w, w += n;
    eb->scale = w, w += n;
    eb->delta = w, w += n;
    eb->predicted = w;
    eb->cluster_of = s->indices;
    eb->local = s->indices + p + 1;
    eb->parent = s->indices + 2 * (p + 1);

    size_t need = 2 * n + 29 * p + 4 * m * p + 2 * m + 2;
    double *arena = bk_fit_buffer(eb->arena, &eb->arena_cap, need, sizeof *arena);
    if (!arena)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu components", n);
    eb->arena = arena;
    double *a = eb->arena;
    eb->y0 = a, a += n;
    eb->scratch = a, a += n;
    eb->sqrt_mass = a, a += p;
    eb->omega2 = a, a += p;
    eb->omega = a, a += p;
    eb->gamma = a, a += p;
    eb->root = a, a += p;
    eb->radius = a, a += p;
    eb->mode_mass = a, a += p;
    eb->fast = a, a += 2 * p;
    eb->c = a, a += p;
    eb->g = a, a += p;
    eb->d = a, a += p;
    eb->eta = a, a += p;
    eb->deta = a, a += p;
    eb->ieta = a, a += p;
    eb->idv = a, a += p;
    eb->accel0 = a, a += p;
    eb->accel_rate = a, a += p;
    eb->row_sum = a, a += p;
    eb->row_scale = a, a += p;
    eb->damp_sum = a, a += p;
    eb->damp_scale = a, a += p;
    eb->yc = a, a += 2 * p;
    eb->even = a, a += p;
    eb->odd = a, a += p;
    eb->next_even = a, a += p;
    eb->next_odd = a, a += p;
    eb->cluster_omega = a, a += p + 1;
    eb->P = a, a += m * p;
    eb->Q = a, a += m * p;
    eb->P_modal = a, a += m * p;
    eb->Q_modal = a, a += m * p;
    eb->qdot0 = a, a += m;
    eb->q_rate = a;

    size_t *own_indices = bk_fit_buffer(eb->indices, &eb->indices_cap, 8 * (p + 1), sizeof *own_indices);
    if (!own_indices)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu pairs", p);
    eb->indices = own_indices;
    size_t *ix = eb->indices;
    eb->members = ix, ix += p + 1;
    eb->first = ix, ix += p + 1;
    eb->offset = ix, ix += p + 1;
    eb->uniform = ix, ix += p + 1;
    eb->series = ix, ix += p + 1;
    eb->coupled = ix, ix += p + 1;
    eb->row_start = ix, ix += p + 1;
    eb->damp_start = ix;

    if (n_roots > 0 && !bk_capacity_fits(n_roots, eb->roots_cap)) {
        free(eb->direction);
        free(eb->sign);
        free(eb->found);
        free(eb->g_hi);
        eb->direction = malloc(n_roots * sizeof *eb->direction);
        eb->sign = malloc(n_roots * sizeof *eb->sign);
        eb->found = malloc(n_roots * sizeof *eb->found);
        eb->g_hi = malloc(3 * n_roots * sizeof *eb->g_hi);
        eb->roots_cap = 0;
        if (!eb->direction || !eb->sign || !eb->found || !eb->g_hi)
            return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu root functions",
                           n_roots);
        eb->roots_cap = n_roots;
    }
    if (eb->g_hi) {
        eb->g_try = eb->g_hi + eb->roots_cap;
        eb->root_t = eb->g_try + eb->roots_cap;
    }
    return BK_OK;
}
