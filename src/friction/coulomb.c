/* Coulomb friction: a stuck block holds until |F| exceeds mu_s N; a slipping block feels
 * a constant mu_d N opposing the slip.  Stateless.
 *
 *   parameter  unit  range               meaning
 *   mu_s       1     0 <= mu_s < inf     static coefficient
 *   mu_d       1     0 <= mu_d <= mu_s   kinetic (dynamic) coefficient */
#include <math.h>
#include <stdio.h>

#include "bksim/friction.h"

enum { MU_S, MU_D };

static const bk_param coulomb_params[] = {
    [MU_S] = {"mu_s", "1", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED, "static friction coefficient"},
    [MU_D] = {"mu_d", "1", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED,
              "kinetic friction coefficient, <= mu_s"},
};

static int coulomb_validate(const double *p, char *msg, size_t msg_len)
{
    if (p[MU_D] > p[MU_S]) {
        snprintf(msg, msg_len, "must be <= mu_s (%g), got %g", p[MU_S], p[MU_D]);
        return MU_D;
    }
    return -1;
}

static double coulomb_sliding_force(const double *p, double normal_force, double slip_rate,
                                    const double *state)
{
    (void)slip_rate;
    (void)state;
    return p[MU_D] * normal_force;
}

static double coulomb_static_threshold(const double *p, double normal_force, const double *state)
{
    (void)state;
    return p[MU_S] * normal_force;
}

const bk_friction_law bk_friction_coulomb = {
    .name = "coulomb",
    .doc = "Coulomb: static threshold mu_s N, constant kinetic force mu_d N",
    .flags = BK_FRICTION_STATIC_THRESHOLD | BK_FRICTION_CONSTANT_SLIDING,
    .n_state = 0,
    .params = coulomb_params,
    .n_params = sizeof coulomb_params / sizeof coulomb_params[0],
    .complete = NULL,
    .validate = coulomb_validate,
    .sliding_force = coulomb_sliding_force,
    .static_threshold = coulomb_static_threshold,
    .state_rate = NULL,
    .state_init = NULL,
    .state_advance = NULL,
};
