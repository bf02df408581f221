/* The founding paper's rate-and-state law (Amireghbali & Coker 2018, eqs. 1-5), with the
 * decision of NOTES.md section 1: the denominator of g has its own reference velocity.
 *
 *   mu(v, theta) = f(|v|) g(theta)
 *   f(v)     = (v / v0 + 1)^(1/m)
 *   g(theta) = [mu_d + (mu_s - mu_d) exp(-((L0/theta) / v1)^p)] / ((L0/theta) / v_theta_ref + 1)^(1/m)
 *   theta'   = B (1 - |v| theta / L0)                       (eq. 4; theta' = B while stuck)
 *   theta(t) = (theta_n - L0/v) exp(-(v/L0) B (t - t_n)) + L0/v   at constant v   (eq. 5)
 * Static threshold while stuck: mu(0, theta) N = g(theta) N, tending to mu_s N after a long
 * stick.  With v_theta_ref = v0 the steady state is mu_d + (mu_s - mu_d) exp(-(v/v1)^p).
 * The printed form (v_theta_ref = v1) gives mu ~ 1e-302 at 1 mm/s: no friction at all.
 *
 *   parameter    unit  default (Table 1)  meaning
 *   mu_s         1     0.6                static coefficient (theta -> inf, v = 0)
 *   mu_d         1     0.5                dynamic coefficient (v -> inf steady state)
 *   v0           m/s   100                reference velocity of f
 *   v1           m/s   0.001              weakening velocity of g
 *   p            1     1.2                weakening exponent
 *   m            1     0.001              1/m is the power of f and of g's denominator
 *   L0           m     2e-5               characteristic slip distance
 *   B            1     4.6                state evolution rate
 *   v_theta_ref  m/s   v0                 reference velocity of g's denominator
 *   theta_init   s     L0 / driver speed  initial state (steady state at the driver speed) */
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "bksim/friction.h"

enum { MU_S, MU_D, V0, V1, P, M, L0, B, V_THETA_REF, THETA_INIT, N_PARAMS };

static const bk_param params[N_PARAMS] = {
    [MU_S] = {"mu_s", "1", 0.6, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE, "static coefficient"},
    [MU_D] = {"mu_d", "1", 0.5, 0.0, INFINITY, 0, "dynamic coefficient, <= mu_s"},
    [V0] = {"v0", "m/s", 100.0, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE, "reference velocity of f"},
    [V1] = {"v1", "m/s", 1e-3, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE, "weakening velocity of g"},
    [P] = {"p", "1", 1.2, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE, "weakening exponent"},
    [M] = {"m", "1", 1e-3, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
           "1/m is the power of f and of g's denominator (Table 1's Cyrillic letter)"},
    [L0] = {"L0", "m", 2e-5, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE, "characteristic slip distance"},
    [B] = {"B", "1", 4.6, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE, "state evolution rate (eq. 4)"},
    [V_THETA_REF] = {"v_theta_ref", "m/s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                     "reference velocity of g's denominator; default v0 (NOTES.md 1); v1 is the printed, degenerate form"},
    [THETA_INIT] = {"theta_init", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                    "initial state; default L0 / driver speed (steady state)"},
};

static void complete(double *p, const bk_friction_context *ctx)
{
    if (isnan(p[V_THETA_REF]))
        p[V_THETA_REF] = p[V0];
    if (isnan(p[THETA_INIT]) && ctx->driver_speed > 0.0)
        p[THETA_INIT] = p[L0] / ctx->driver_speed;
}

static int validate(const double *p, char *msg, size_t msg_len)
{
    if (p[MU_D] > p[MU_S]) {
        snprintf(msg, msg_len, "must be <= mu_s (%g), got %g", p[MU_S], p[MU_D]);
        return MU_D;
    }
    if (isnan(p[THETA_INIT])) {
        snprintf(msg, msg_len, "required when the driver does not move (default: L0 / driver speed)");
        return THETA_INIT;
    }
    return -1;
}

/* ln g(theta); -inf at theta <= 0 (g's limit there is 0). */
static double log_g(const double *p, double theta)
{
    if (!(theta > 0.0))
        return -INFINITY;
    double rate = p[L0] / theta;
    double numerator = p[MU_D] + (p[MU_S] - p[MU_D]) * exp(-pow(rate / p[V1], p[P]));
    /* log1p keeps x << 1 exact; the power 1/m = 1000 would overflow outside log space. */
    return log(numerator) - log1p(rate / p[V_THETA_REF]) / p[M];
}

/* N f(v) g(theta), formed in log space so that f's overflow at absurd rates meets g's
 * underflow at absurd states as a finite number; capped at DBL_MAX. */
static double friction_of(const double *p, double normal_force, double slip_rate, double theta)
{
    /* f is analytic through v = 0; clamp far below -v0, where it has no meaning. */
    double x = slip_rate / p[V0];
    if (x < -0.5)
        x = -0.5;
    double log_mu = log1p(x) / p[M] + log_g(p, theta);
    double mu = log_mu > 709.0 ? DBL_MAX : exp(log_mu);
    double force = normal_force * mu;
    return isfinite(force) ? force : DBL_MAX;
}

static double sliding_force(const double *p, double normal_force, double slip_rate, const double *state)
{
    return friction_of(p, normal_force, slip_rate, state[0]);
}

static double static_threshold(const double *p, double normal_force, const double *state)
{
    return friction_of(p, normal_force, 0.0, state[0]);
}

static void state_rate(const double *p, double speed, const double *state, double *rate)
{
    rate[0] = p[B] * (1.0 - speed * state[0] / p[L0]);
}

static void state_init(const double *p, double *state) { state[0] = p[THETA_INIT]; }

static void state_advance(const double *p, double speed, double dt, double *state)
{
    if (speed <= 0.0) {
        state[0] += p[B] * dt;
        return;
    }
    double steady = p[L0] / speed;
    state[0] = (state[0] - steady) * exp(-(speed / p[L0]) * p[B] * dt) + steady;
}

/* Eq. 5: the state relaxes as exp(-(v / L0) B t). */
static double relaxation_time(const double *p, double speed) { return p[L0] / (p[B] * speed); }

const bk_friction_law bk_friction_rate_state = {
    .name = "rate_state",
    .doc = "the founding paper's rate-and-state law, eqs. 1-4 (NOTES.md 1: g's denominator uses v_theta_ref, default v0)",
    .flags = BK_FRICTION_STATIC_THRESHOLD,
    .n_state = 1,
    .params = params,
    .n_params = N_PARAMS,
    .complete = complete,
    .validate = validate,
    .sliding_force = sliding_force,
    .static_threshold = static_threshold,
    .state_rate = state_rate,
    .state_init = state_init,
    .state_advance = state_advance,
    .relaxation_time = relaxation_time,
};
