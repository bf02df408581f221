/* Test support: a memory sink that keeps a run's ruptures (the first RUPTURE_LOG_MAX; n
 * counts them all) and block 0's slip rate at every regular output row. */
#ifndef TEST_RUPTURE_LOG_H
#define TEST_RUPTURE_LOG_H

#include <stddef.h>

#include "bksim/bksim.h"

#define RUPTURE_LOG_MAX 32
#define RUPTURE_LOG_ROWS 4096

typedef struct rupture_log {
    bk_rupture r[RUPTURE_LOG_MAX];
    size_t n;
    double row_t[RUPTURE_LOG_ROWS], row_v[RUPTURE_LOG_ROWS];
    size_t rows;
} rupture_log;

/* A sink writing into log (emptied first; no checkpoints). */
bk_sink rupture_log_sink(rupture_log *log);

#endif
