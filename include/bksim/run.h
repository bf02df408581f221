/* The run loop: one loop for every solver back-end.  Advance to the next output time or
 * root, let the mode machine decide transitions, re-initialise, emit, repeat.  Results go
 * to a sink (bksim/sink.h: the HDF5 writer, or a test's memory sink). */
#ifndef BKSIM_RUN_H
#define BKSIM_RUN_H

#include "bksim/config.h"
#include "bksim/sink.h"
#include "bksim/status.h"

/* Run the configured scene from t = 0 to config->t_end, sending rows and transitions to
 * sink.  stats may be NULL.  Returns BK_OK, or a negative code with err filled (the sink
 * has then received a prefix of the run). */
int bk_run(const bk_config *config, const bk_sink *sink, bk_run_stats *stats,
           bk_progress_fn progress, void *progress_user, bk_error *err);

/* The same, continuing from a checkpoint of a run of the same config (NULL: from t = 0).
 * The sink then receives only what comes after the checkpoint. */
int bk_run_from(const bk_config *config, const bk_checkpoint *from, const bk_sink *sink,
                bk_run_stats *stats, bk_progress_fn progress, void *progress_user, bk_error *err);

/* Start config's run where another ended (src/run_start.c): end is the state of a run of
 * source at its end (bk_h5_read_end_state), and becomes config's state at t = 0 (the blocks'
 * x_init, v_init and friction states, the driver's start position; modes follow from them
 * as at any start).  The two must have the same shape and the same law on every block;
 * BK_ERR_INVALID says what differs, config unchanged. */
int bk_config_start_from(bk_config *config, const bk_config *source, const bk_checkpoint *end, bk_error *err);

#endif
