/* Carlson-Langer velocity-weakening friction (Carlson & Langer 1989): a static peak F0
 * at rest and, while slipping,
 *
 *   phi(v) = F0 (1 - sigma) / (1 + 2 alpha |v| / (1 - sigma))
 *
 * so the force drops by sigma F0 at the onset of slip and weakens further with speed.
 * Stateless; a force law (independent of the normal force).
 *
 *   parameter  unit  range              meaning
 *   F0         N     0 < F0             static peak (threshold at rest)
 *   sigma      1     0 <= sigma < 1     drop at the onset of slip, as a fraction of F0
 *   alpha      s/m   0 <= alpha         velocity-weakening rate */
#include <math.h>

#include "bksim/friction.h"

enum { F0, SIGMA, ALPHA, N_PARAMS };

static const bk_param params[N_PARAMS] = {
    [F0] = {"F0", "N", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE, "static peak force"},
    [SIGMA] = {"sigma", "1", NAN, 0.0, 1.0, BK_PARAM_REQUIRED | BK_PARAM_MAX_EXCLUSIVE,
               "drop at the onset of slip, fraction of F0"},
    [ALPHA] = {"alpha", "s/m", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED, "velocity-weakening rate"},
};

static double sliding_force(const double *p, double normal_force, double slip_rate, const double *state)
{
    (void)normal_force;
    (void)state;
    double weak = 1.0 - p[SIGMA];
    /* Slightly negative trial rates (while a stop is bracketed) continue the formula. */
    double denominator = 1.0 + 2.0 * p[ALPHA] * slip_rate / weak;
    if (denominator < 0.5)
        denominator = 0.5;
    return p[F0] * weak / denominator;
}

static double static_threshold(const double *p, double normal_force, const double *state)
{
    (void)normal_force;
    (void)state;
    return p[F0];
}

const bk_friction_law bk_friction_carlson_langer = {
    .name = "carlson_langer",
    .doc = "Carlson-Langer velocity weakening: static peak F0, F0 (1 - sigma) / (1 + 2 alpha |v| / (1 - sigma)) while slipping",
    .flags = BK_FRICTION_STATIC_THRESHOLD,
    .n_state = 0,
    .params = params,
    .n_params = N_PARAMS,
    .complete = NULL,
    .validate = NULL,
    .sliding_force = sliding_force,
    .static_threshold = static_threshold,
    .state_rate = NULL,
    .state_init = NULL,
    .state_advance = NULL,
};
