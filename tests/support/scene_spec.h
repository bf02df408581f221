/* Test support: Coulomb scenes built in code (the parser has its own tests): a spec of a
 * uniform chain, the paper's single block as a spec, the config made from a spec, and a run
 * of it into a recorder. */
#ifndef TEST_SCENE_SPEC_H
#define TEST_SCENE_SPEC_H

#include <stddef.h>

#include "bksim/bksim.h"
#include "recorder.h"

typedef struct scene_spec {
    size_t n;
    double mass, stiffness, coupling, mu_s, mu_d, velocity, t_end, rtol, interval;
    bk_spring spring;
    bk_boundary boundary;
    const char *method;
    int detect_extrema;
    long max_per_instant;
} scene_spec;

/* The paper's single block (m = 1 kg, k = 1e4 N/m, mu_s = 0.6, V = 1 mm/s, 5 s, rows every
 * 1 ms); mu_d 0.1, 0.5, 0.5999 are cases A, B, C. */
scene_spec paper_case(double mu_d, bk_spring spring, double rtol, const char *method);
/* Free it with bk_config_free. */
bk_config *scene_config(const scene_spec *spec);
/* Build, run into r and free the config; returns bk_run's status. */
int run_spec(const scene_spec *spec, recorder *r, bk_run_stats *stats, bk_error *err);

#endif
