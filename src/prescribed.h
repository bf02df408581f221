/* Internal: the prescribed-motion scene (bk_run dispatches here when config->prescribed). */
#ifndef BKSIM_PRESCRIBED_H
#define BKSIM_PRESCRIBED_H

#include "bksim/config.h"
#include "bksim/sink.h"

int bk_run_prescribed(const bk_config *config, const bk_sink *sink, bk_run_stats *stats,
                      bk_progress_fn progress, void *progress_user, bk_error *err);

#endif
