/* The memory-recording sink of the run tests; see recorder.h. */
#include "recorder.h"

#include <math.h>
#include <stdlib.h>

int record_sample(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    recorder *r = self;
    /* Times increase, but for a transition instant's before and after rows (equal times). */
    int pair = r->rows > 0 && r->last_kind == BK_ROW_BEFORE_TRANSITION;
    if (r->rows > 0 && (pair ? s->t != r->last_t || s->is_event != BK_ROW_AFTER_TRANSITION : !(s->t > r->last_t)))
        r->time_decreased = 1;
    r->last_kind = s->is_event;
    r->before_rows += s->is_event == BK_ROW_BEFORE_TRANSITION;
    r->after_rows += s->is_event == BK_ROW_AFTER_TRANSITION;
    if (r->rows == 0) {
        r->elastic0 = s->elastic_energy;
        r->kinetic0 = s->kinetic_energy;
    }
    r->last_t = s->t;
    r->rows++;
    for (size_t i = 0; i < s->n_blocks; ++i)
        if (!isfinite(s->x[i]) || !isfinite(s->v[i]) || !isfinite(s->friction[i]))
            r->non_finite = 1;
    double balance = s->work_driver - (s->elastic_energy - r->elastic0) -
                     (s->kinetic_energy - r->kinetic0) - s->dissipation - s->damping_dissipation;
    r->max_balance_error = fmax(r->max_balance_error, fabs(balance));
    r->max_work = fmax(r->max_work, fabs(s->work_driver));
    if (r->exact) {
        double x, v;
        exact_state(r->exact, s->t, &x, &v);
        r->max_position_error = fmax(r->max_position_error, fabs(s->x[0] - x));
        if (!s->is_event)
            r->max_position_error_regular = fmax(r->max_position_error_regular, fabs(s->x[0] - x));
    }
    return BK_OK;
}

int record_transition(void *self, const bk_transition *t, bk_error *err)
{
    (void)err;
    recorder *r = self;
    if (r->n_transitions == r->cap_transitions) {
        size_t cap = r->cap_transitions ? 2 * r->cap_transitions : 64;
        bk_transition *grown = realloc(r->transitions, cap * sizeof *grown);
        if (!grown)
            return BK_ERR_NOMEM;
        r->transitions = grown;
        r->cap_transitions = cap;
    }
    r->transitions[r->n_transitions++] = *t;
    return BK_OK;
}

bk_sink recorder_sink(recorder *r)
{
    return (bk_sink){.self = r, .sample = record_sample, .transition = record_transition};
}

int run_recorded(const bk_config *c, recorder *r, bk_run_stats *stats, bk_error *err)
{
    bk_sink sink = recorder_sink(r);
    return bk_run(c, &sink, stats, NULL, NULL, err);
}

void recorder_free(recorder *r) { free(r->transitions); }
