/* Runs stopped on purpose; see stopping_sink.h. */
#include "stopping_sink.h"

#include "bk_test.h"

int stopping_sample(void *self, const bk_sample *sample, bk_error *err)
{
    stopping_sink *s = self;
    if (s->checkpoints == 0 && s->samples-- == 0)
        return BK_FAIL(err, BK_ERR_INTERRUPTED, "stopped by the test");
    return s->inner.sample(s->inner.self, sample, err);
}

int stopping_transition(void *self, const bk_transition *t, bk_error *err)
{
    stopping_sink *s = self;
    return s->inner.transition(s->inner.self, t, err);
}

int stopping_checkpoint(void *self, const bk_checkpoint *cp, bk_error *err)
{
    stopping_sink *s = self;
    int rc = s->inner.checkpoint(s->inner.self, cp, err);
    if (rc == BK_OK && s->checkpoints > 0)
        --s->checkpoints;
    return rc;
}

bk_sink stopping_sink_of(stopping_sink *s)
{
    return (bk_sink){.self = s, .sample = stopping_sample, .transition = stopping_transition,
                     .checkpoint = stopping_checkpoint};
}

bk_config *checkpointed_paper_config(const char *const *extra, size_t n_extra)
{
    const char *overrides[8] = {"output.checkpoint_interval=0.25", "run.t_end=1.2"};
    size_t n = 2;
    for (size_t k = 0; k < n_extra && n < 8; ++k)
        overrides[n++] = extra[k];
    bk_config *config = NULL;
    bk_error err = {0};
    int rc = bk_config_load_file("configs/paper/case_b_coulomb.ini", overrides, n, &config, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    return config;
}

/* Run config into path: whole (checkpoints < 0) or stopped `samples` rows after that many
 * checkpoints, leaving path.part. */
void run_into(const bk_config *config, const char *path, int checkpoints, int samples)
{
    bk_h5_writer *w;
    bk_error err = {0};
    assert_int_equal(bk_h5_writer_open(&w, config, path, &err), BK_OK);
    bk_sink inner = bk_h5_writer_sink(w);
    stopping_sink stop = {inner, checkpoints < 0 ? -1 : checkpoints, samples};
    bk_sink sink = stopping_sink_of(&stop);
    bk_run_stats stats;
    int rc = bk_run(config, checkpoints < 0 ? &inner : &sink, &stats, NULL, NULL, &err);
    if (checkpoints < 0) {
        if (rc != BK_OK)
            fail_msg("%s", err.message);
        assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    } else {
        assert_int_equal(rc, BK_ERR_INTERRUPTED);
        bk_h5_writer_abandon(w, err.message, &stats);
    }
}
