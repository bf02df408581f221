/* Front and precursor diagnostics (bksim/fronts.h). */
#include "bksim/fronts.h"

#include <math.h>
#include <stdlib.h>

#include "bksim/modes.h"

/* Least-squares slope of d against t (blocks per second); NaN with fewer than 3 points or
 * when d does not vary, inf when t does not (all at once). */
static double slope_of(const double sums[5])
{
    double n = sums[4], sd = sums[0], st = sums[1], stt = sums[2], sdt = sums[3];
    if (n < 3.0)
        return NAN;
    double var_t = stt - st * st / n, cov = sdt - sd * st / n;
    if (!(var_t > 0.0))
        return cov == 0.0 && n > 0.0 ? INFINITY : NAN;
    return cov / var_t;
}

static void add_point(double sums[5], double d, double t)
{
    sums[0] += d;
    sums[1] += t;
    sums[2] += t * t;
    sums[3] += d * t;
    sums[4] += 1.0;
}

static double edge_distance(int32_t block, size_t n_blocks, int edge_right)
{
    return edge_right ? (double)(n_blocks - 1) - (double)block : (double)block;
}

typedef struct start_of {
    double t;
    size_t rupture;
} start_of;

static int by_start(const void *a, const void *b)
{
    double ta = ((const start_of *)a)->t, tb = ((const start_of *)b)->t;
    return ta < tb ? -1 : ta > tb;
}

int bk_fronts_edge_force(const bk_model *model, const bk_transition *transitions, size_t n_transitions,
                         const bk_rupture *ruptures, size_t n_ruptures, int edge_right, double *force,
                         bk_error *err)
{
    size_t edge = edge_right ? model->n_blocks - 1 : 0;
    const bk_block *b = &model->blocks[edge];
    start_of *order = malloc((n_ruptures ? n_ruptures : 1) * sizeof *order);
    if (!order)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu ruptures", n_ruptures);
    for (size_t r = 0; r < n_ruptures; ++r)
        order[r] = (start_of){ruptures[r].t_start, r};
    qsort(order, n_ruptures, sizeof *order, by_start);
    /* In order of their start, one walk through the transitions serves every rupture. */
    double x = b->x_init, t_last = -INFINITY;
    int stuck = b->v_init == 0.0;
    size_t k = 0;
    for (size_t i = 0; i < n_ruptures; ++i) {
        size_t r = order[i].rupture;
        double t = ruptures[r].t_start;
        for (; k < n_transitions && transitions[k].t <= t; ++k)
            if ((size_t)transitions[k].block == edge) {
                x = transitions[k].x;
                t_last = transitions[k].t;
                stuck = transitions[k].to == BK_MODE_STICK;
            }
        /* Its position is known while it rests, at the instant it breaks away, and at t = 0
         * (its x_init, slipping or not). */
        int known = stuck || t_last == t || (t == 0.0 && t_last == -INFINITY);
        double stretch = bk_driver_position(&model->driver, t) - x;
        if (model->spring == BK_SPRING_TENSION_ONLY && stretch < 0.0)
            stretch = 0.0;
        force[r] = known ? b->driver_stiffness * stretch + b->applied_force : NAN;
    }
    free(order);
    return BK_OK;
}

int bk_fronts(const bk_rupture *ruptures, size_t n_ruptures, const bk_rupture_block *blocks, size_t n_rows,
              size_t n_blocks, int edge_right, const double *edge_force, bk_front *out, bk_error *err)
{
    if (n_blocks == 0)
        return BK_FAIL(err, BK_ERR_INVALID, "front diagnostics need a chain of at least one block");
    for (size_t r = 0; r < n_ruptures; ++r) {
        const bk_rupture *rup = &ruptures[r];
        out[r] = (bk_front){.rupture = (int64_t)r,
                            .t_start = rup->t_start,
                            .edge_force = edge_force ? edge_force[r] : NAN,
                            .first_block = rup->first_block,
                            .n_blocks = rup->n_blocks,
                            .arrest_length = 0,
                            .from_edge = edge_distance(rup->first_block, n_blocks, edge_right) == 0.0,
                            .crossed = 0,
                            .mean_speed = NAN,
                            .duration = rup->duration};
    }
    /* Rows of a rupture are contiguous; one pass, sums per rupture. */
    size_t k = 0;
    while (k < n_rows) {
        int64_t r = blocks[k].rupture;
        if (r < 0 || (size_t)r >= n_ruptures)
            return BK_FAIL(err, BK_ERR_INVALID, "rupture block row %zu names rupture %lld, outside the %zu ruptures",
                           k, (long long)r, n_ruptures);
        double sums[5] = {0};
        double reach = 0.0, t0 = blocks[k].t_onset;
        size_t first = k;
        for (; k < n_rows && blocks[k].rupture == r; ++k) {
            if (blocks[k].block < 0 || (size_t)blocks[k].block >= n_blocks)
                return BK_FAIL(err, BK_ERR_INVALID, "rupture block row %zu names block %d, outside the chain's %zu",
                               k, (int)blocks[k].block, n_blocks);
            if (blocks[k].t_onset < t0)
                t0 = blocks[k].t_onset;
        }
        for (size_t j = first; j < k; ++j) {
            double d = edge_distance(blocks[j].block, n_blocks, edge_right);
            reach = fmax(reach, d);
            add_point(sums, d, blocks[j].t_onset - t0); /* times from the first arrival: no cancellation */
        }
        bk_front *f = &out[r];
        f->arrest_length = (int32_t)reach + 1;
        f->crossed = reach == (double)(n_blocks - 1);
        f->mean_speed = slope_of(sums);
    }
    return BK_OK;
}

int bk_front_profile(const bk_rupture_block *blocks, size_t count, size_t n_blocks, int edge_right, size_t window,
                     double *distance, double *speed, bk_error *err)
{
    if (window < 2)
        return BK_FAIL(err, BK_ERR_INVALID, "a front speed window of %zu blocks (allowed: at least 2)", window);
    if (count == 0)
        return BK_OK;
    double t0 = blocks[0].t_onset;
    for (size_t k = 0; k < count; ++k) {
        if (blocks[k].block < 0 || (size_t)blocks[k].block >= n_blocks)
            return BK_FAIL(err, BK_ERR_INVALID, "rupture block row %zu names block %d, outside the chain's %zu", k,
                           (int)blocks[k].block, n_blocks);
        t0 = fmin(t0, blocks[k].t_onset);
        distance[k] = edge_distance(blocks[k].block, n_blocks, edge_right);
    }
    double half = 0.5 * (double)window;
    /* Rows are in block order, so the blocks within half a window of one are a contiguous run
     * around it; each fit sums its own window (window + 1 blocks at most): O(count window). */
    size_t lo = 0, hi = 0;
    for (size_t k = 0; k < count; ++k) {
        double b = (double)blocks[k].block;
        while (hi < count && (double)blocks[hi].block <= b + half)
            ++hi;
        while ((double)blocks[lo].block < b - half)
            ++lo;
        double sums[5] = {0};
        for (size_t j = lo; j < hi; ++j)
            add_point(sums, distance[j], blocks[j].t_onset - t0);
        speed[k] = slope_of(sums);
    }
    return BK_OK;
}
