/* Test support: the rupture sink (rupture_log.h). */
#include "rupture_log.h"

#include <string.h>

static int on_sample(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    rupture_log *log = self;
    if (s->is_event == BK_ROW_SAMPLE && log->rows < RUPTURE_LOG_ROWS) {
        log->row_t[log->rows] = s->t;
        log->row_v[log->rows++] = s->v[0];
    }
    return BK_OK;
}

static int on_transition(void *self, const bk_transition *t, bk_error *err)
{
    (void)self;
    (void)t;
    (void)err;
    return BK_OK;
}

static int on_rupture(void *self, const bk_rupture *r, const bk_rupture_block *blocks, size_t n_blocks,
                      const bk_rupture_rate *rate, size_t n_rate, bk_error *err)
{
    (void)blocks;
    (void)n_blocks;
    (void)rate;
    (void)n_rate;
    (void)err;
    rupture_log *log = self;
    if (log->n < RUPTURE_LOG_MAX)
        log->r[log->n] = *r;
    log->n++;
    return BK_OK;
}

bk_sink rupture_log_sink(rupture_log *log)
{
    memset(log, 0, sizeof *log);
    return (bk_sink){.self = log, .sample = on_sample, .transition = on_transition, .rupture = on_rupture};
}
