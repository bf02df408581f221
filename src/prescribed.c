/* Prescribed motion: one block slides at a piecewise-constant slip rate v_k for duration
 * T_k (v_k = 0: a hold).  Nothing is integrated: the friction state follows the law's
 * exact evolution at constant rate (eq. 5 for the paper's law), always advanced from the
 * segment's start so no error accumulates.  Rows carry x = slip distance, v = slip rate,
 * friction = mu N, cof = mu, the state, and mode stick during holds.  During a hold the
 * friction reported is the law's static threshold (the largest shear the contact holds),
 * or its sliding force at zero rate for laws without one.  A row is written at every
 * segment start (the state just after the rate step: the spike of Figure 2). */
#include "prescribed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bksim/modes.h"

typedef struct emitter {
    const bk_config *config;
    const bk_sink *sink;
    bk_error *err;
    bk_run_stats *stats;
    const bk_block *block;
    double *state;           /* n_state, scratch */
} emitter;

static int emit(emitter *em, double t, double slip, double rate, const double *state, bk_row_kind kind)
{
    const bk_block *b = em->block;
    const bk_friction_law *law = b->law;
    double friction = rate > 0.0 || !(law->flags & BK_FRICTION_STATIC_THRESHOLD)
                          ? law->sliding_force(b->friction_params, b->normal_force, rate, state)
                          : law->static_threshold(b->friction_params, b->normal_force, state);
    double cof = friction / b->normal_force;
    int8_t mode = (int8_t)(rate > 0.0 ? BK_MODE_SLIP_POS : BK_MODE_STICK);
    bk_sample sample = {
        .t = t,
        .driver = slip,
        .n_blocks = 1,
        .x = &slip,
        .v = &rate,
        .friction = &friction,
        .cof = &cof,
        .mode = &mode,
        .friction_state = law->n_state ? state : NULL,
        .is_event = (int)kind,
    };
    if (em->stats)
        em->stats->rows++;
    if (!em->sink || !em->sink->sample)
        return BK_OK;
    int rc = em->sink->sample(em->sink->self, &sample, em->err);
    return rc == BK_OK ? BK_OK : (rc < 0 ? rc : BK_ERR_SINK);
}

static int transition(emitter *em, double t, double slip, bk_mode from, bk_mode to)
{
    if (em->stats)
        em->stats->transitions++;
    if (!em->config->output.transitions || !em->sink || !em->sink->transition)
        return BK_OK;
    bk_transition tr = {.t = t, .block = 0, .from = (int8_t)from, .to = (int8_t)to, .x = slip, .v = 0.0,
                        .force = NAN};
    int rc = em->sink->transition(em->sink->self, &tr, em->err);
    return rc == BK_OK ? BK_OK : (rc < 0 ? rc : BK_ERR_SINK);
}

/* State at dt into a segment that started from start_state. */
static const double *state_at(emitter *em, const double *start_state, double rate, double dt)
{
    const bk_friction_law *law = em->block->law;
    if (law->n_state == 0)
        return NULL;
    memcpy(em->state, start_state, law->n_state * sizeof *em->state);
    law->state_advance(em->block->friction_params, rate, dt, em->state);
    return em->state;
}

int bk_run_prescribed(const bk_config *config, const bk_sink *sink, bk_run_stats *stats,
                      bk_progress_fn progress, void *progress_user, bk_error *err)
{
    clock_t cpu0 = clock();
    const bk_prescribed *pr = config->prescribed;
    const bk_block *b = &config->model->blocks[0];
    const bk_friction_law *law = b->law;
    if (law->n_state > 0 && !law->state_advance)
        return BK_FAIL(err, BK_ERR_CONFIG, "law '%s' has no exact state evolution for prescribed motion",
                       law->name);
    double start_state[BK_FRICTION_MAX_STATE] = {0}, scratch[BK_FRICTION_MAX_STATE] = {0};
    if (law->n_state > 0)
        law->state_init(b->friction_params, start_state);
    emitter em = {config, sink, err, stats, b, scratch};
    if (stats)
        memset(stats, 0, sizeof *stats);

    double t_end = config->t_end, interval = config->output.interval;
    double segment_start = 0.0, slip_start = 0.0;
    long next_sample = 1;
    int rc = BK_OK;
    bk_mode previous_mode = BK_MODE_STICK;
    double previous_rate = 0.0;
    for (size_t k = 0; k < pr->n_segments && segment_start < t_end && rc == BK_OK; ++k) {
        double rate = pr->slip_rate[k];
        double segment_end = k + 1 == pr->n_segments ? t_end : fmin(segment_start + pr->duration[k], t_end);
        bk_mode mode = rate > 0.0 ? BK_MODE_SLIP_POS : BK_MODE_STICK;
        /* The rate step: the state is continuous, the friction jumps. */
        if (mode != previous_mode && (rc = transition(&em, segment_start, slip_start, previous_mode, mode)) != BK_OK)
            break;
        previous_mode = mode;
        /* A rate step is an instant of two rows, before it and after (as a run's transitions). */
        if (k > 0 || mode != BK_MODE_STICK) {
            double t0 = segment_start, x0 = slip_start;
            if ((rc = emit(&em, t0, x0, previous_rate, start_state, BK_ROW_BEFORE_TRANSITION)) != BK_OK ||
                (rc = emit(&em, t0, x0, rate, start_state, BK_ROW_AFTER_TRANSITION)) != BK_OK)
                break;
        } else if ((rc = emit(&em, segment_start, slip_start, rate, start_state, BK_ROW_SAMPLE)) != BK_OK)
            break;
        previous_rate = rate;
        /* Samples inside the segment; its end belongs to the next segment's first row,
         * except at t_end. */
        for (;; ++next_sample) {
            double ts = interval > 0.0 ? (double)next_sample * interval : t_end;
            if (ts >= t_end - 1e-9 * (interval > 0.0 ? interval : t_end))
                ts = t_end;
            if (ts <= segment_start + 1e-9 * interval) /* the segment's first row has it */
                continue;
            if (ts > segment_end || (ts == segment_end && segment_end < t_end))
                break;
            double dt = ts - segment_start;
            if ((rc = emit(&em, ts, slip_start + rate * dt, rate, state_at(&em, start_state, rate, dt), BK_ROW_SAMPLE)) != BK_OK ||
                ts >= t_end)
                break;
        }
        double dt = segment_end - segment_start;
        if (law->n_state > 0)
            law->state_advance(b->friction_params, rate, dt, start_state);
        slip_start += rate * dt;
        segment_start = segment_end;
        bk_progress report = {
            .t = segment_start, .t_end = t_end, .transitions = stats ? stats->transitions : 0, .events = -1};
        if (rc == BK_OK && progress && progress(progress_user, &report) != 0)
            rc = BK_FAIL(err, BK_ERR_INTERRUPTED, "run interrupted at t = %.17g s", segment_start);
    }
    if (stats) {
        snprintf(stats->method, sizeof stats->method, "prescribed");
        stats->t_reached = segment_start;
        stats->cpu_time = (double)(clock() - cpu0) / CLOCKS_PER_SEC;
        stats->wall_time = stats->cpu_time;
    }
    return rc;
}
