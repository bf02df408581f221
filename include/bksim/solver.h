/* Solver back-ends: each is one file exporting one const bk_solver_backend.  Back-ends
 * only integrate; the run loop owns the mode machine, the roots' meaning and the output.
 *
 * The problem handed to a back-end is a smooth ODE y' = f(t, y) of size n with nroots root
 * functions g(t, y); the run loop changes n, f's meaning and the root directions between
 * (re)starts.  A back-end that sets wants_full_layout gets a semi-explicit DAE instead (see
 * differential_id). */
#ifndef BKSIM_SOLVER_H
#define BKSIM_SOLVER_H

#include <stddef.h>

#include "bksim/status.h"

/* [solver] in the config (bksim/config.h): what a back-end is asked for. */
typedef struct bk_solver_options {
    char method[32];        /* back-end name, e.g. "cvode_adams"; default "auto" */
    char linear_solver[16]; /* "dense" | "band" | "auto" (implicit methods); default "auto" */
    double rtol;            /* relative tolerance; default 1e-8 */
    double atol_x;          /* m; NaN = auto (rtol * 1e-3 * slip length scale) */
    double atol_v;          /* m/s; NaN = auto (rtol * 1e-3 * velocity scale) */
    double max_step;        /* s; NaN = auto (1/8 of bk_model_step_time_scale) */
    long max_steps;         /* solver steps allowed between two output rows; default 100000 */
    int detect_velocity_extrema; /* locate slip-rate minima to catch hidden stops; default 1 */
    long max_transitions_per_instant; /* per block, before a chattering error; default 100 */
    double instant_window;  /* s: transitions closer than this count as one instant;
                               NaN = auto (1e-6 of the fastest natural period) */
    double min_step;        /* s: a step below this is an error; 0 = no limit (default) */
    char arkode_table[48];  /* ARKODE Butcher table of arkode_erk / arkode_dirk; "default":
                               the method's own (Zonneveld 5_3_4, ESDIRK43I6L2SA 6_3_4) */
    char local_stepping[8]; /* "auto" | "on" | "off": segments with their own integrators */
    long segment_blocks;    /* blocks per segment; default 32 */
} bk_solver_options;

typedef struct bk_ode_problem {
    void *user;
    /* Return 0 on success, > 0 for a recoverable failure, < 0 to abort. */
    int (*rhs)(double t, const double *y, double *ydot, void *user);
    int (*roots)(double t, const double *y, double *g, void *user);
    size_t n_roots;
    const int *root_direction; /* n_roots: +1 rising only, -1 falling only, 0 both */
    size_t half_bandwidth;     /* Jacobian bandwidth each side, for band solvers */
    /* Structure, for back-ends that exploit it (the exact stepper).  y starts with n_pairs
     * (position, velocity) pairs; the rest are quadratures (their derivatives do not depend
     * on themselves).  When affine is set, y' = A y + b0 + b1 t exactly, and pair_mass[k] is
     * the mass of pair k (kg), so that M^(1/2) (d accel / d position) M^(-1/2) and, with
     * dashpots, M^(1/2) (d accel / d velocity) M^(-1/2) are symmetric.  dissipation_last
     * (with affine) excepts the last component, a quadrature of the dashpots' dissipation
     * rate v^T C v, C = -M (d accel / d velocity), the one rate that is not affine. */
    size_t n_pairs;
    const double *pair_mass;
    int affine;
    int dissipation_last;
    /* Optional exact Jacobian d(ydot)/dy for implicit methods: calls put(matrix, row, col,
     * value) for each non-zero entry (entries for one position add up).  A banded back-end
     * drops the entries outside its band instead of approximating them by grouped
     * difference quotients, which would spill rows that depend on everything (the energy
     * quadratures, a periodic chain's wrap) into the band.  NULL: back-ends use their own
     * difference quotients. */
    int (*jacobian)(double t, const double *y, void *user,
                    void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix);
    /* NULL: an ODE.  Otherwise (only for back-ends with wants_full_layout) a semi-explicit
     * DAE of size n: y_k' = f_k(t, y) where differential_id[k] = 1, and the algebraic
     * constraint 0 = f_k(t, y) where it is 0, i.e. the residual diag(id) y' - f(t, y) = 0.
     * The start vector satisfies the constraints, and y' = diag(id) f(t0, y0) is consistent
     * with it.  jacobian is still d f / dy, algebraic rows included. */
    const double *differential_id;
    /* Optional additive split f = f_E + f_I for IMEX methods, in one pass: f_I is the
     * friction (its force in the velocity rows, the friction-state rates), stiff at low slip
     * rates (rate-and-state's direct effect, d mu / d v ~ a / v) and at short slip
     * distances (state relaxation ~ B v / L0); f_E the rest (kinematics, springs, energy
     * quadratures).  jacobian_implicit is d f_I / dy, in jacobian's form.  NULL: no split. */
    int (*rhs_split)(double t, const double *y, double *f_explicit, double *f_implicit, void *user);
    int (*jacobian_implicit)(double t, const double *y, void *user,
                             void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix);
} bk_ode_problem;

typedef struct bk_solver_counters {
    long steps, rhs_evals, root_evals, err_test_fails, nonlin_iters;
} bk_solver_counters;
/* sum += more, counter by counter. */
void bk_solver_counters_add(bk_solver_counters *sum, const bk_solver_counters *more);

enum {
    BK_STEP_OK = 0,      /* a step was taken; *t_reached < t_stop */
    BK_STEP_ROOT = 1,    /* a root was found at *t_reached; y holds the state there */
    BK_STEP_STOP = 2     /* reached t_stop exactly */
};

typedef struct bk_solver_backend {
    const char *name;  /* value of [solver] method */
    const char *doc;
    /* Ask the run loop for the full layout: every block in the unknowns, stuck ones pinned
     * by algebraic rows (bk_ode_problem.differential_id).  Otherwise stuck blocks are
     * removed and the problem is an ODE. */
    int wants_full_layout;
    /* Prepare for problems of size n; *mem owns everything. */
    int (*create)(void **mem, const bk_solver_options *options, bk_error *err);
    /* (Re)start at t0 from y0 (size n; may differ from the last start) with per-component
     * absolute tolerances atol (size n). */
    int (*start)(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err);
    /* One internal step toward t_stop; returns BK_STEP_* or a negative error. y (size n)
     * receives the state at *t_reached. */
    int (*step)(void *mem, double *t_reached, double *y, bk_error *err);
    /* Dense output inside the last step: y(t) into y, as accurate as the step (events and
     * merges continue from it). */
    int (*interpolate)(void *mem, double t, double *y, bk_error *err);
    /* Dense output for output rows only, inside the last step: within the bound the back-end
     * states of interpolate's, at no cost in steps and few right-hand side evaluations.
     * NULL: interpolate serves. */
    int (*sample)(void *mem, double t, double *y, bk_error *err);
    /* Interval [t_lo, t_hi] of the last step (where interpolate is valid). */
    void (*last_step)(void *mem, double *t_lo, double *t_hi);
    /* After BK_STEP_ROOT: found[i] = +1 / -1 for roots crossed rising / falling, else 0. */
    int (*root_info)(void *mem, int *found);
    void (*counters)(void *mem, bk_solver_counters *counters); /* cumulative over starts */
    void (*destroy)(void *mem);
    /* Options only some back-ends take ([solver] arkode_table): 0 if these are fine, else
     * -1 with the reason in message.  NULL: the back-end takes none. */
    int (*check_options)(const bk_solver_options *options, char *message, size_t len);
    /* Local time stepping ([solver] local_stepping) needs the next two; NULL: the back-end
     * cannot serve it.  set_stop moves the stop time t_stop given at start (to any time not
     * before the last step's end). */
    int (*set_stop)(void *mem, double t_stop, bk_error *err);
    /* The polynomial the back-end extrapolates its solution by into the next step (its
     * predictor), which is also its dense output over the last step, for `count` components:
     * about t_n, the last step's end, coef[j * (BK_PREDICTOR_MAX_ORDER + 1) + k] =
     * y_c^(k)(t_n) / k! for component c = components[j] and k = 0 .. *order; error_ratio[j]
     * the last step's local error estimate of component c over its tolerance (the error
     * test passes when their root mean square over all components is at most 1); *h_last
     * the last step's size and *h_next the one the back-end means to try next. */
    int (*predictor)(void *mem, const size_t *components, size_t count, double *t_n, double *h_last,
                     double *h_next, int *order, double *coef, double *error_ratio, bk_error *err);
} bk_solver_backend;

/* The highest order a back-end's predictor polynomial can have (CVODE's Adams method). */
#define BK_PREDICTOR_MAX_ORDER 12

const bk_solver_backend *bk_solver_backend_find(const char *name);
/* Names [solver] arkode_table accepts, i = 0, 1, ... (NULL past the end): "default" first,
 * then ARKODE 6.4's explicit tables that have an embedding (for arkode_erk), then its
 * diagonally implicit ones (for arkode_dirk). */
const char *bk_solver_arkode_table(size_t i);
/* All registered back-ends, NULL-terminated. */
const bk_solver_backend *const *bk_solver_backends(void);

extern const bk_solver_backend bk_solver_cvode_adams;
extern const bk_solver_backend bk_solver_cvode_bdf;
/* Exact piecewise-analytic (modal) stepper: affine problems only (Coulomb friction, dashpots). */
extern const bk_solver_backend bk_solver_exact;
/* ARKODE ARKStep (src/solver/arkode.c) */
extern const bk_solver_backend bk_solver_arkode_bs23;
extern const bk_solver_backend bk_solver_arkode_dp45;
extern const bk_solver_backend bk_solver_arkode_erk;
extern const bk_solver_backend bk_solver_arkode_dirk;
extern const bk_solver_backend bk_solver_arkode_imex;
/* IDA on the full layout, stuck blocks as algebraic rows v = 0 (src/solver/ida.c) */
extern const bk_solver_backend bk_solver_ida;
/* GSL odeiv2 with event location by bksim (src/solver/gsl.c) */
extern const bk_solver_backend bk_solver_gsl_rk8pd;
extern const bk_solver_backend bk_solver_gsl_rkf45;
extern const bk_solver_backend bk_solver_gsl_msbdf;

#endif
