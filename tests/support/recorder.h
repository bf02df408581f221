/* Test support: a memory sink that keeps every transition of a run and watches its rows
 * (time order, finite values, energy balance, and optionally the distance from the
 * closed-form single block). */
#ifndef TEST_RECORDER_H
#define TEST_RECORDER_H

#include <stddef.h>

#include "bksim/bksim.h"
#include "exact_single.h"

typedef struct recorder {
    bk_transition *transitions;
    size_t n_transitions, cap_transitions;
    size_t rows;
    double last_t;
    int last_kind;               /* bk_row_kind of the last row */
    size_t before_rows, after_rows; /* of transition instants (bk_row_kind) */
    int time_decreased;          /* or equal, other than at a transition instant's two rows */
    int non_finite;              /* a row had a non-finite x, v or friction */
    const exact_solution *exact; /* when set: track block 0's position error at every row */
    double max_position_error;   /* m, over all rows */
    /* m, over the regular rows only: event rows sit at the run's own transition times */
    double max_position_error_regular;
    double max_balance_error;    /* |W - dE_el - dE_kin - D| over rows, J */
    double max_work;             /* J */
    double elastic0, kinetic0;
} recorder;

int record_sample(void *self, const bk_sample *s, bk_error *err);
int record_transition(void *self, const bk_transition *t, bk_error *err);
/* A sink writing into r (no checkpoints). */
bk_sink recorder_sink(recorder *r);
/* bk_run of c into r, without a progress callback; returns its status. */
int run_recorded(const bk_config *c, recorder *r, bk_run_stats *stats, bk_error *err);
void recorder_free(recorder *r);

#endif
