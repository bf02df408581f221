/* Dieterich-Ruina rate-and-state friction in the regularised form that is smooth and odd
 * through v = 0 (Rice & Ben-Zion 1996; Lapusta et al. 2000), with the aging or the slip
 * state law.  No static threshold: a block under this law never sticks, it creeps.
 *
 *   mu(v, theta) = a asinh( v / (2 V0) exp( (f0 + b ln(V0 theta / Dc)) / a ) )
 *   aging:  theta' = 1 - |v| theta / Dc
 *   slip:   theta' = -(|v| theta / Dc) ln(|v| theta / Dc)
 * Steady state theta = Dc / |v|, mu_ss ~ f0 + (a - b) ln(|v| / V0): velocity weakening when
 * b > a.  Quasi-static steady sliding of a block on a spring k is unstable below
 * k_c = N (b - a) / Dc (Rice & Ruina 1983).
 *
 *   parameter   unit  range           meaning
 *   a           1     0 < a           direct-effect coefficient
 *   b           1     0 <= b          evolution-effect coefficient
 *   Dc          m     0 < Dc          characteristic slip distance
 *   V0          m/s   0 < V0          reference velocity
 *   f0          1     0 <= f0         steady-state coefficient at V0
 *   theta_init  s     0 < theta_init  initial state; default Dc / driver speed */
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "bksim/friction.h"

enum { A, B, DC, V_REF, F0, THETA_INIT, N_PARAMS };

static const bk_param params[N_PARAMS] = {
    [A] = {"a", "1", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE, "direct-effect coefficient"},
    [B] = {"b", "1", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED, "evolution-effect coefficient"},
    [DC] = {"Dc", "m", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE, "characteristic slip distance"},
    [V_REF] = {"V0", "m/s", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE, "reference velocity"},
    [F0] = {"f0", "1", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED, "steady-state coefficient at V0"},
    [THETA_INIT] = {"theta_init", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                    "initial state; default Dc / driver speed (steady state)"},
};

static void complete(double *p, const bk_friction_context *ctx)
{
    if (isnan(p[THETA_INIT]) && ctx->driver_speed > 0.0)
        p[THETA_INIT] = p[DC] / ctx->driver_speed;
}

static int validate(const double *p, char *msg, size_t msg_len)
{
    if (isnan(p[THETA_INIT])) {
        snprintf(msg, msg_len, "required when the driver does not move (default: Dc / driver speed)");
        return THETA_INIT;
    }
    return -1;
}

/* N a asinh(v / (2 V0) e^(psi / a)), odd in v; computed in log space where e^(psi/a) would
 * overflow. */
static double sliding_force(const double *p, double normal_force, double slip_rate, const double *state)
{
    if (slip_rate == 0.0)
        return 0.0;
    double theta = state[0] > 0.0 ? state[0] : DBL_MIN;
    double log_scale = (p[F0] + p[B] * log(p[V_REF] * theta / p[DC])) / p[A];
    double log_x = log(fabs(slip_rate) / (2.0 * p[V_REF])) + log_scale;
    double magnitude = log_x > 20.0 ? log_x + 0.69314718055994530942 /* ln 2 */ : asinh(exp(log_x));
    return copysign(normal_force * p[A] * magnitude, slip_rate);
}

/* With z = v / (2 V0) e^(psi / a): dF/dv = N a z / (v sqrt(1 + z^2)), which at v = 0 is
 * N a e^(psi / a) / (2 V0); dF/dtheta = N b z / (theta sqrt(1 + z^2)).  z / sqrt(1 + z^2)
 * is taken from log z, as z itself overflows at creep rates far below V0 e^(-f0 / a). */
static void sliding_force_derivatives(const double *p, double normal_force, double slip_rate,
                                      const double *state, double *d_rate, double *d_state)
{
    double theta = state[0] > 0.0 ? state[0] : DBL_MIN;
    double log_scale = (p[F0] + p[B] * log(p[V_REF] * theta / p[DC])) / p[A];
    if (slip_rate == 0.0) {
        *d_rate = normal_force * p[A] * exp(log_scale) / (2.0 * p[V_REF]);
        *d_state = 0.0;
        return;
    }
    double log_z = log(fabs(slip_rate) / (2.0 * p[V_REF])) + log_scale;
    if (log_z < -20.0) { /* z / sqrt(1 + z^2) = z to rounding */
        *d_rate = normal_force * p[A] * exp(log_scale) / (2.0 * p[V_REF]);
        *d_state = copysign(normal_force * p[B] * exp(log_z) / theta, slip_rate);
        return;
    }
    /* z / sqrt(1 + z^2) = 1 / sqrt(1 + z^-2) */
    double ratio = log_z > 20.0 ? 1.0 : 1.0 / sqrt(1.0 + exp(-2.0 * log_z));
    *d_rate = normal_force * p[A] * ratio / fabs(slip_rate);
    *d_state = copysign(normal_force * p[B] * ratio / theta, slip_rate);
}

static void aging_rate(const double *p, double speed, const double *state, double *rate)
{
    rate[0] = 1.0 - speed * state[0] / p[DC];
}

static void slip_rate_law(const double *p, double speed, const double *state, double *rate)
{
    double ratio = speed * state[0] / p[DC];
    rate[0] = ratio > 0.0 ? -ratio * log(ratio) : 0.0;
}

static void state_init(const double *p, double *state) { state[0] = p[THETA_INIT]; }

static void aging_advance(const double *p, double speed, double dt, double *state)
{
    if (speed <= 0.0) {
        state[0] += dt;
        return;
    }
    double steady = p[DC] / speed;
    state[0] = (state[0] - steady) * exp(-speed * dt / p[DC]) + steady;
}

/* ln(v theta / Dc) decays as exp(-v t / Dc); a hold leaves theta unchanged. */
static void slip_advance(const double *p, double speed, double dt, double *state)
{
    if (speed <= 0.0 || !(state[0] > 0.0))
        return;
    double steady = p[DC] / speed;
    state[0] = steady * exp(log(state[0] / steady) * exp(-speed * dt / p[DC]));
}

/* Both state laws relax as exp(-v t / Dc) near steady state. */
static double relaxation_time(const double *p, double speed) { return p[DC] / speed; }

#define DIETERICH_RUINA(var, law_name, law_doc, rate_fn, advance_fn)                               \
    const bk_friction_law var = {                                                                  \
        .name = law_name,                                                                          \
        .doc = law_doc,                                                                            \
        .flags = 0,                                                                                \
        .n_state = 1,                                                                              \
        .params = params,                                                                          \
        .n_params = N_PARAMS,                                                                      \
        .complete = complete,                                                                      \
        .validate = validate,                                                                      \
        .sliding_force = sliding_force,                                                            \
        .static_threshold = NULL,                                                                  \
        .state_rate = rate_fn,                                                                     \
        .state_init = state_init,                                                                  \
        .state_advance = advance_fn,                                                               \
        .relaxation_time = relaxation_time,                                                        \
        .sliding_force_derivatives = sliding_force_derivatives,                                    \
    }

DIETERICH_RUINA(bk_friction_dieterich_ruina_aging, "dieterich_ruina_aging",
                "Dieterich-Ruina rate-and-state, regularised (smooth through v = 0, never sticks), aging law",
                aging_rate, aging_advance);
DIETERICH_RUINA(bk_friction_dieterich_ruina_slip, "dieterich_ruina_slip",
                "Dieterich-Ruina rate-and-state, regularised (smooth through v = 0, never sticks), slip law",
                slip_rate_law, slip_advance);
