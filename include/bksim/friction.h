/* The friction-law interface.  Each law is one file exporting one const bk_friction_law;
 * the run loop asks the table (flags, n_state) instead of switching on names.
 *
 * Conventions: forces in N, slip rates in m/s.  sliding_force() returns the magnitude of
 * the friction force while a block slips with slip_rate = s*v in its slip direction s; the
 * integrator may probe slip_rate slightly below zero while it brackets a stop, so a law
 * must return a finite value there.  The force on the block is -s * sliding_force().
 *
 * A law without BK_FRICTION_STATIC_THRESHOLD never sticks: its sliding_force must be an
 * odd, smooth function of the signed slip rate (e.g. regularised rate-and-state), and the
 * block is integrated through v = 0 without events. */
#ifndef BKSIM_FRICTION_H
#define BKSIM_FRICTION_H

#include <stddef.h>

#include "bksim/param.h"

#define BK_FRICTION_MAX_PARAMS 16
#define BK_FRICTION_MAX_STATE 2

enum {
    /* A stuck block stays stuck while |applied force| <= static_threshold(). */
    BK_FRICTION_STATIC_THRESHOLD = 1u << 0,
    /* sliding_force does not depend on slip rate or state (Coulomb): exact stepping applies. */
    BK_FRICTION_CONSTANT_SLIDING = 1u << 1
};

/* Values a law may need to complete derived defaults. */
typedef struct bk_friction_context {
    double driver_speed; /* m/s, |driver velocity| at t = 0 */
    double normal_force; /* N */
} bk_friction_context;

typedef struct bk_friction_law {
    const char *name;     /* value of [friction] law */
    const char *doc;      /* one line for the README / key reference */
    unsigned flags;       /* BK_FRICTION_* */
    size_t n_state;       /* state variables per block (0: the block carries none) */
    const bk_param *params;
    size_t n_params;
    /* Fill DERIVED parameters left as NaN; may be NULL. */
    void (*complete)(double *params, const bk_friction_context *ctx);
    /* Cross-parameter checks beyond each key's own range.  Returns -1 when valid, else the
     * index of the offending parameter with a message ("must be <= mu_s (0.6), got 0.7"). */
    int (*validate)(const double *params, char *msg, size_t msg_len);
    double (*sliding_force)(const double *params, double normal_force, double slip_rate,
                            const double *state);
    /* Largest |applied force| a stuck block withstands; NULL without STATIC_THRESHOLD. */
    double (*static_threshold)(const double *params, double normal_force, const double *state);
    /* d(state)/dt at the given |slip rate| (0 while stuck); NULL when n_state == 0. */
    void (*state_rate)(const double *params, double speed, const double *state, double *rate);
    /* Initial state; NULL when n_state == 0. */
    void (*state_init)(const double *params, double *state);
    /* Exact state after dt (s) at constant |slip rate| speed (m/s, 0 for a hold), in place;
     * NULL when n_state == 0.  Prescribed-motion scenes rely on it. */
    void (*state_advance)(const double *params, double speed, double dt, double *state);
    /* Time (s) the state takes to relax toward steady sliding at |slip rate| speed > 0 (the
     * law's own slip time scale, e.g. Dc / v); NULL when n_state == 0.  Default step limits
     * use it where no oscillation sets one. */
    double (*relaxation_time)(const double *params, double speed);
    /* d sliding_force / d slip_rate (N s/m) and / d state[0] (N per state unit) at slip_rate,
     * exact; NULL: callers take difference quotients.  Blocks without mass need it (their
     * slip rate follows the force balance, whose time derivative it enters). */
    void (*sliding_force_derivatives)(const double *params, double normal_force, double slip_rate,
                                      const double *state, double *d_rate, double *d_state);
} bk_friction_law;

/* Registry: the law named `name`, or NULL. */
const bk_friction_law *bk_friction_law_find(const char *name);
/* All registered laws, NULL-terminated. */
const bk_friction_law *const *bk_friction_laws(void);

/* Index of `key` in the law's parameter table, or -1. */
int bk_friction_param_index(const bk_friction_law *law, const char *key);

extern const bk_friction_law bk_friction_coulomb;
extern const bk_friction_law bk_friction_rate_state;
extern const bk_friction_law bk_friction_carlson_langer;
extern const bk_friction_law bk_friction_dieterich_ruina_aging;
extern const bk_friction_law bk_friction_dieterich_ruina_slip;

#endif
