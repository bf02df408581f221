/* Local time stepping: a chain whose blocks never stick is one island, and integrating it
 * whole makes every block take the steps of the fastest rupture anywhere, so a step costs
 * the chain and a rupture costs the chain times its steps.  Here the island is cut into
 * segments of [solver] segment_blocks blocks (default 8; run_partition.c cuts; scene.h),
 * each with its own integrator and its own time, and a rupture costs the segments it runs
 * through.
 *
 * Coupling.  A segment sees a partner in another segment (a ghost) through the track that
 * segment publishes after each of its steps: the integrator's own polynomial for the block's
 * slip and velocity, which is its dense output over the step just taken and its predictor
 * for the next.  The scheduler (run.c) always steps the segment furthest behind, so a
 * neighbour's last step reaches back past the segment's time: up to the neighbour's time a
 * ghost is interpolated, beyond it extrapolated, and a segment may step only as far as its
 * ghosts' tracks are trusted (their limit).
 *
 * How far a track is trusted.  The predictor's error over a step of length h is what the
 * integrator's error test measures, r = |local error| / tolerance for the block's slip and
 * velocity (the corrector's distance from the predictor is about q + 1 times it); over a
 * lookahead L it grows as (L / h)^(q + 1) at order q.  So a track is trusted for
 * L = h (safety / ((q + 1) r))^(1 / (q + 1)), and at most GROWTH times the owner's step
 * (see there) and the step limit max_step.  The owner's step is the longer of the last
 * and the one it plans next: a step cut short (by a stop, or at the integrator's start) has
 * a proportionally smaller error and is followed by a longer one, so a block at the quiet
 * edge of a busy segment gets a long lookahead although its segment steps finely, and the
 * slowdown a rupture imposes fades within a segment or two.
 *
 * The coupling error, measured.  When a segment steps again, the time up to which its old
 * track could have been used (its limit, or the new step's end) is where that
 * extrapolation is worst: the old polynomial is compared there with the new solution, over
 * the same tolerance.  The run keeps the largest ratio (stats coupling_error) and counts
 * those above 1 (coupling_exceedances); after each excess the block's safety halves. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "run_ctx.h"

/* The predictor's error estimate is trusted to this fraction of the tolerance at first. */
#define SAFETY_START 0.25
#define SAFETY_MIN 1e-4
/* A start's track: linear extrapolation trusted while the acceleration's term stays below
 * this fraction of the position tolerance. */
#define START_FRACTION 0.1
/* Lookahead at most this many of the owner's steps, the longer of its last and its next:
 * the polynomial's higher coefficients carry the integrator's error over h^k, which
 * extrapolation over L multiplies by (L / h)^k. */
#define GROWTH 4.0

int bk_run_segments_init(run_ctx *ctx)
{
    bk_scene *scene = &ctx->scene;
    if (ctx->segment_blocks == 0)
        return BK_OK;
    size_t n = scene->n;
    scene->track_of = malloc(n * sizeof *scene->track_of);
    scene->ghost_x = calloc(n, sizeof *scene->ghost_x);
    scene->ghost_v = calloc(n, sizeof *scene->ghost_v);
    ctx->segment_of = malloc(n * sizeof *ctx->segment_of);
    if (!scene->track_of || !scene->ghost_x || !scene->ghost_v || !ctx->segment_of)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the segments of %zu blocks", n);
    /* A ghost's velocity enters only through coupling dashpots and the force balance of a
     * block without mass; otherwise its position alone couples, and only it is checked. */
    ctx->ghost_velocities = ctx->model->coupling_damping > 0.0;
    for (size_t i = 0; i < n; ++i) {
        scene->track_of[i] = BK_NO_TRACK;
        if (!(ctx->model->blocks[i].mass > 0.0))
            ctx->ghost_velocities = 1;
    }
    scene->segmented = 1;
    return BK_OK;
}

void bk_run_segments_free(run_ctx *ctx)
{
    free(ctx->segment_of);
    ctx->segment_of = NULL;
}

/* A track for block i, if it has none yet. */
static int ensure_track(run_ctx *ctx, size_t i)
{
    bk_scene *scene = &ctx->scene;
    if (scene->track_of[i] != BK_NO_TRACK)
        return BK_OK;
    if (ctx->n_tracks == ctx->tracks_capacity) {
        size_t cap = ctx->tracks_capacity ? 2 * ctx->tracks_capacity : 64;
        bk_track *grown = realloc(scene->tracks, cap * sizeof *grown);
        if (!grown)
            return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the segments' tracks");
        scene->tracks = grown;
        ctx->tracks_capacity = cap;
    }
    scene->track_of[i] = ctx->n_tracks++;
    return BK_OK;
}

/* Block i at rest in its track at t: the chain's arrays, nothing trusted beyond t. */
static void track_from_chain(bk_scene *scene, size_t i, double t)
{
    bk_track *track = &scene->tracks[scene->track_of[i]];
    memset(track, 0, sizeof *track);
    track->t_n = t;
    track->x0 = scene->x[i];
    track->limit = t;
    track->safety = SAFETY_START;
    track->order = 1;
    track->slip[1] = scene->v[i];
    track->velocity[0] = scene->v[i];
}

int bk_run_segments_prepare(run_ctx *ctx, const size_t *members, size_t count, size_t pieces, double t)
{
    bk_scene *scene = &ctx->scene;
    for (size_t p = 0; p < pieces; ++p)
        for (size_t k = p * count / pieces; k < (p + 1) * count / pieces; ++k)
            ctx->segment_of[members[k]] = p;
    for (size_t k = 0; k < count; ++k) {
        size_t i = members[k];
        const long *partner = bk_scene_partners(scene, i);
        int edge = 0;
        for (size_t d = 0; d < scene->n_directions; ++d)
            edge |= partner[d] >= 0 && ctx->segment_of[partner[d]] != ctx->segment_of[i];
        if (!edge)
            continue;
        int rc = ensure_track(ctx, i);
        if (rc != BK_OK)
            return rc;
        track_from_chain(scene, i, t);
    }
    ctx->stats->segments = (long)pieces;
    return BK_OK;
}

/* The scale of lookaheads where the step says nothing yet. */
static double lookahead_cap(const run_ctx *ctx)
{
    return ctx->options.max_step > 0.0 ? ctx->options.max_step : 1e-3 * ctx->t_end;
}

int bk_run_segment_started(run_ctx *ctx, run_island *isl)
{
    bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    double t = isl->t_reached;
    for (size_t e = 0; e < island->n_edges; ++e) {
        size_t i = island->edges[e], s = scene->slot[i];
        bk_track *track = &scene->tracks[scene->track_of[i]];
        double safety = track->safety > 0.0 ? track->safety : SAFETY_START;
        double accel = (double)scene->mode[i] * bk_island_slip_acceleration(island, i, t, isl->y);
        memset(track, 0, sizeof *track);
        track->t_n = t;
        track->x0 = scene->x_ref[i];
        track->safety = safety;
        track->order = 1;
        track->slip[0] = isl->y[s];
        track->slip[1] = isl->y[s + 1];
        track->velocity[0] = isl->y[s + 1];
        track->velocity[1] = accel;
        /* Linear in time until the first step says more: half a t^2 stays small. */
        double reach = lookahead_cap(ctx) * 1e-3;
        if (fabs(accel) > 0.0)
            reach = fmin(reach, sqrt(2.0 * START_FRACTION * ctx->atol_x / fabs(accel)));
        track->limit = t + reach;
    }
    return BK_OK;
}

int bk_run_segment_stop(run_ctx *ctx, run_island *isl)
{
    const bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    double stop = bk_run_stop_time(ctx);
    for (size_t g = 0; g < island->n_ghosts; ++g) {
        double limit = scene->tracks[scene->track_of[island->ghosts[g]]].limit;
        if (limit < stop)
            stop = limit;
    }
    /* Not before the integrator's own time (after a root it stands past the segment's
     * time, on what the ghosts' tracks allowed when it stepped), and when it stands at the
     * segment's time, past its rounding of it, or it would stop where it stands. */
    double lo, hi;
    ctx->backend->last_step(isl->solver, &lo, &hi);
    double least = hi > isl->t_reached ? hi : isl->t_reached + 1e3 * DBL_EPSILON * (fabs(hi) + fabs(hi - lo));
    if (stop < least)
        stop = least;
    return ctx->backend->set_stop(isl->solver, stop, ctx->err);
}

int bk_run_segment_stepped(run_ctx *ctx, run_island *isl)
{
    bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    enum { STRIDE = BK_PREDICTOR_MAX_ORDER + 1 };
    double rtol = ctx->options.rtol;
    int velocities = ctx->ghost_velocities;
    for (size_t e = 0; e < island->n_edges; ++e) {
        size_t i = island->edges[e], s = scene->slot[i];
        size_t components[2] = {s, s + 1};
        double coef[2 * STRIDE], ratio[2], t_n, h, h_next;
        int order;
        int rc = ctx->backend->predictor(isl->solver, components, 2, &t_n, &h, &h_next, &order, coef, ratio,
                                         ctx->err);
        if (rc != BK_OK)
            return rc;
        bk_track *track = &scene->tracks[scene->track_of[i]];
        /* The old track where its use could have gone furthest, against the new solution. */
        double at = fmin(t_n, track->limit);
        if (at > track->t_n) {
            double x_old, v_old;
            bk_track_eval(track, at, &x_old, &v_old);
            double slip_new = bk_track_horner(coef, order, at - t_n);
            double v_new = bk_track_horner(coef + STRIDE, order, at - t_n);
            double x_new = scene->x_ref[i] + slip_new;
            double error = fabs(x_old - x_new) / (ctx->atol_x + rtol * fabs(slip_new));
            if (velocities)
                error = fmax(error, fabs(v_old - v_new) / (ctx->atol_v + rtol * fabs(v_new)));
            if (error > ctx->stats->coupling_error)
                ctx->stats->coupling_error = error;
            if (error > 1.0) {
                ctx->stats->coupling_exceedances++;
                track->safety = fmax(0.5 * track->safety, SAFETY_MIN);
            } else if (error < 0.1) {
                track->safety = fmin(1.25 * track->safety, SAFETY_START);
            }
        }
        track->t_n = t_n;
        track->x0 = scene->x_ref[i];
        track->order = order;
        memcpy(track->slip, coef, (size_t)(order + 1) * sizeof *coef);
        memcpy(track->velocity, coef + STRIDE, (size_t)(order + 1) * sizeof *coef);
        double reach;
        if (order == 0 || !(h > 0.0)) {
            reach = 0.0;
        } else {
            /* The estimate is the corrector's distance from the predictor over about q + 1. */
            double r = (order + 1) * fmax(velocities ? fmax(ratio[0], ratio[1]) : ratio[0], 1e-12);
            reach = fmin(h * pow(track->safety / r, 1.0 / (order + 1)), GROWTH * fmax(h, h_next));
        }
        track->limit = t_n + fmin(reach, lookahead_cap(ctx));
    }
    return BK_OK;
}
