/* Scenes built in code for the run tests; see scene_spec.h. */
#include "scene_spec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bk_test.h"

scene_spec paper_case(double mu_d, bk_spring spring, double rtol, const char *method)
{
    return (scene_spec){.n = 1, .mass = 1.0, .stiffness = 1e4, .coupling = 0.0, .mu_s = 0.6,
                        .mu_d = mu_d, .velocity = 1e-3, .t_end = 5.0, .rtol = rtol,
                        .interval = 1e-3, .spring = spring, .boundary = BK_BOUNDARY_FREE,
                        .method = method, .detect_extrema = 1, .max_per_instant = 100};
}

bk_config *scene_config(const scene_spec *spec)
{
    bk_config *c = calloc(1, sizeof *c);
    assert_non_null(c);
    bk_model *m = bk_model_create(spec->n);
    assert_non_null(m);
    m->boundary_cols = spec->boundary;
    m->coupling_stiffness = spec->coupling;
    m->gravity = 9.81;
    m->spring = spec->spring;
    m->driver.velocity = spec->velocity;
    for (size_t i = 0; i < spec->n; ++i) {
        bk_block *b = &m->blocks[i];
        b->mass = spec->mass;
        b->driver_stiffness = spec->stiffness;
        b->normal_force = spec->mass * 9.81;
        b->law = &bk_friction_coulomb;
        b->friction_params[0] = spec->mu_s;
        b->friction_params[1] = spec->mu_d;
    }
    bk_model_finalize(m);
    c->model = m;
    c->t_end = spec->t_end;
    snprintf(c->solver.method, sizeof c->solver.method, "%s", spec->method);
    snprintf(c->solver.linear_solver, sizeof c->solver.linear_solver, "auto");
    c->solver.rtol = spec->rtol;
    c->solver.atol_x = c->solver.atol_v = c->solver.max_step = NAN;
    c->solver.max_steps = 1000000;
    c->solver.detect_velocity_extrema = spec->detect_extrema;
    c->solver.max_transitions_per_instant = spec->max_per_instant;
    c->solver.instant_window = NAN;
    c->output.interval = spec->interval;
    c->output.fields = BK_FIELD_ALL;
    c->output.transitions = 1;
    c->output.event_rows = 1;
    return c;
}

int run_spec(const scene_spec *spec, recorder *r, bk_run_stats *stats, bk_error *err)
{
    bk_config *c = scene_config(spec);
    int rc = run_recorded(c, r, stats, err);
    bk_config_free(c);
    return rc;
}
