/* Test support: runs stopped on purpose, to restart them: a sink that stops a run a given
 * number of rows after a given checkpoint, and the paper's case B with checkpoints. */
#ifndef TEST_STOPPING_SINK_H
#define TEST_STOPPING_SINK_H

#include <stddef.h>

#include "bksim/bksim.h"

/* A sink that passes everything to inner and stops the run `samples` rows after its
 * `checkpoints`-th checkpoint, as a kill would (here cleanly, through abandon). */
typedef struct stopping_sink {
    bk_sink inner;
    int checkpoints;
    int samples;
} stopping_sink;

int stopping_sample(void *self, const bk_sample *sample, bk_error *err);
int stopping_transition(void *self, const bk_transition *t, bk_error *err);
int stopping_checkpoint(void *self, const bk_checkpoint *cp, bk_error *err);
/* The sink of s, with its checkpoint callback. */
bk_sink stopping_sink_of(stopping_sink *s);

/* configs/paper/case_b_coulomb.ini to t_end = 1.2 s with a checkpoint every 0.25 s, and up
 * to six more --set overrides; fails the test if it does not load. */
bk_config *checkpointed_paper_config(const char *const *extra, size_t n_extra);

/* Run config into path: whole (checkpoints < 0), or stopped `samples` rows after that many
 * checkpoints, leaving path.part (abandoned, as a killed run would leave it). */
void run_into(const bk_config *config, const char *path, int checkpoints, int samples);

#endif
