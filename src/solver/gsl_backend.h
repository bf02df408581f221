/* Internal to the GSL back-ends: the instance gsl.c steps, and what gsl_msbdf.c does to
 * it for msbdf on stiff problems (the derivative it restarts from and its dense output
 * use, a projection after repeated failures, the evolve loop that hands msbdf that
 * derivative).  gsl.c calls down into gsl_msbdf.c; gsl_msbdf.c reaches the problem's
 * right-hand side only through the instance's gsl_odeiv2_system. */
#ifndef BKSIM_GSL_BACKEND_H
#define BKSIM_GSL_BACKEND_H

#include <stddef.h>

#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_roots.h>

#include "bksim/solver.h"
#include "gsl_shared.h"
#include "solver/row_nodes.h"

typedef enum { DENSE_RESTEP, DENSE_HERMITE } dense_kind;

typedef struct gsl_variant {
    const char *label;
    const gsl_odeiv2_step_type *const *type;
    int order;              /* for the initial step estimate */
    int needs_jacobian;
    dense_kind dense;
    double tolerance_factor; /* GSL's control gets rtol and atol times this */
    size_t sample_nodes;     /* nodes of the output rows' Hermite polynomial (degree 2k - 1) */
} gsl_variant;

typedef struct gsl_backend {
    const gsl_variant *variant;
    bk_solver_options options;
    bk_ode_problem problem;
    double max_step;            /* INFINITY when unlimited */

    gsl_odeiv2_system sys;
    /* The objects a step uses.  msbdf carries history from step to step and reaches its
     * control through a driver, so each instance owns one; the RK pairs carry nothing but
     * evolve's dydt_out, which step() refills from f_lo, so they borrow shared ones. */
    gsl_odeiv2_driver *driver;  /* msbdf: owns stepper, control and evolve */
    bk_gsl_shared *shared;     /* RK: borrowed stepper (also the dense-output probe), evolve, control */
    gsl_odeiv2_step *stepper;
    gsl_odeiv2_evolve *evolve;
    gsl_odeiv2_control *control;
    size_t driver_n;            /* msbdf: the size the driver was made for */
    gsl_root_fsolver *brent;    /* event location, made at the first event */
    size_t n, capacity;         /* state size; allocated length of the arrays below */
    double *arena;              /* every array below but active and found */
    double *y_lo, *f_lo, *y_hi, *f_hi, *y_root, *y_probe, *atol, *work, *work2, *yerr,
           *scale, /* the control's absolute weights: atol_i / eps_abs */
           *y_back[2], /* msbdf: the two step ends before t_lo, newest first */
           *stiffness; /* msbdf: |d f_i/d y_i| from the last Jacobian (0 before one) */
    double eps_abs;
    size_t root_capacity;
    double *g_scan, *g_hi, *g_probe, *g_root;
    int *active, *found;

    double t_lo, t_hi;          /* the last step (t_lo == t_hi before the first) */
    double t_back[2];           /* msbdf: times of y_back */
    size_t n_back;              /* msbdf: how many of them this start has */
    double t_stop, h;           /* h: next step size to try */
    double t_scan;              /* roots before t_scan in the step are handled */
    int stepped;                /* a step has been taken since the start */
    int pending;                /* a root was returned inside the step: scan the rest */

    bk_row_nodes rows;          /* output rows' polynomial (sample) */

    bk_solver_counters count;   /* cumulative over starts */
    int rhs_status;             /* last failing return value of the problem's rhs */
    double rhs_fail_t;
    int status;                 /* failure inside a GSL callback (dense output, roots) */
} gsl_backend;

/* msbdf's derivative at t_hi into f_hi: f_exact, but on stiff components the derivative of
 * the polynomial through the last step ends (gsl_msbdf.c says why). */
void bk_gsl_history_derivative(gsl_backend *b, const double *f_exact);
/* gsl_odeiv2_evolve_apply for msbdf, restarting it from f_lo instead of f(t, y), and moving
 * the stiff components of the step's start onto their slow manifold after four failures. */
int bk_gsl_msbdf_evolve(gsl_backend *b, double *t, double t1, double *h);

#endif
