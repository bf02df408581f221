/* libFuzzer harness over config -> run: every config the loader accepts (small chains) is
 * run for at most a fraction of a second.  The run may fail, but only with a message, never
 * with a crash, undefined behaviour, a non-finite row or a hang. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int check_row(void *self, const bk_sample *s, bk_error *err)
{
    (void)self;
    (void)err;
    if (!isfinite(s->t))
        abort();
    for (size_t i = 0; i < s->n_blocks; ++i)
        if (!isfinite(s->x[i]) || !isfinite(s->v[i]))
            abort();
    return BK_OK;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    bk_config *c = NULL;
    bk_error err = {0};
    if (bk_config_load_string(text, "fuzz.ini", NULL, 0, &c, &err) == BK_OK && c->model->n_blocks <= 16) {
        c->wall_time_limit = 0.2;
        if (c->solver.max_steps > 5000)
            c->solver.max_steps = 5000;
        bk_sink sink = {.self = NULL, .sample = check_row, .transition = NULL};
        int rc = bk_run(c, &sink, NULL, NULL, NULL, &err);
        if (rc != BK_OK && err.message[0] == '\0')
            abort();
    }
    bk_config_free(c);
    free(text);
    return 0;
}
