/* libFuzzer harness over the INI -> model path: arbitrary text is a config, optionally
 * followed by a line "%%" and one --set override per line.  Anything may be rejected, but
 * with a located message; anything accepted must be a model the run loop can take. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    const char *overrides[16];
    size_t n_overrides = 0;
    char *split = strstr(text, "\n%%\n");
    if (split) {
        *split = '\0';
        for (char *line = strtok(split + 4, "\n"); line && n_overrides < 16; line = strtok(NULL, "\n"))
            overrides[n_overrides++] = line;
    }
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = bk_config_load_string(text, "fuzz.ini", overrides, n_overrides, &c, &err);
    if (rc != BK_OK) {
        /* Rejected: located, and nothing returned. */
        if (c != NULL || err.message[0] == '\0' ||
            (strncmp(err.message, "fuzz.ini", 8) != 0 && strncmp(err.message, "--set", 5) != 0))
            abort();
    } else {
        const bk_model *m = c->model;
        if (!m || m->n_blocks == 0 || !(c->t_end > 0.0) || !isfinite(c->t_end) || !c->output.path ||
            !(c->solver.rtol > 0.0) ||
            (strcmp(c->solver.method, "auto") != 0 && !bk_solver_backend_find(c->solver.method)) ||
            !isfinite(m->driver.velocity) || !isfinite(m->driver.start_position) ||
            !(m->coupling_damping >= 0.0) || !isfinite(m->coupling_damping))
            abort();
        /* Every value finite and in range, derived ones (normal_force = mass * gravity) too. */
        for (size_t i = 0; i < m->n_blocks; ++i) {
            const bk_block *b = &m->blocks[i];
            /* A block without mass (quasi-dynamic) creeps, with a dashpot to bound it. */
            if (b->mass == 0.0 && (!b->law || b->law->static_threshold || !(b->damping > 0.0)))
                abort();
            if (!b->law || !(b->mass >= 0.0) || !isfinite(b->mass) || !(b->normal_force > 0.0) ||
                !isfinite(b->normal_force) || !isfinite(b->driver_stiffness) || !isfinite(b->x_init) ||
                !isfinite(b->v_init) || !(b->damping >= 0.0) || !isfinite(b->damping))
                abort();
            for (size_t p = 0; p < b->law->n_params; ++p)
                if (!isfinite(b->friction_params[p]))
                    abort();
        }
        if (c->prescribed)
            for (size_t k = 0; k < c->prescribed->n_segments; ++k)
                if (!(c->prescribed->duration[k] > 0.0) || !(c->prescribed->slip_rate[k] >= 0.0))
                    abort();
        /* The plausibility checks take any config that loads (at most one warning each). */
        if (bk_config_warnings(c, NULL, NULL) > 3)
            abort();
        bk_config_free(c);
    }
    free(text);
    return 0;
}
