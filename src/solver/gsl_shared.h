/* What the GSL back-ends share (gsl.c): a scaled step-size control that reads its
 * weights through a pointer, and the stepper, evolve and control of one size, shared
 * by one thread's instances. */
#ifndef BKSIM_GSL_SHARED_H
#define BKSIM_GSL_SHARED_H

#include <stddef.h>

#include <gsl/gsl_odeiv2.h>

typedef struct bk_gsl_shared {
    const gsl_odeiv2_step_type *type;
    size_t n, users;
    gsl_odeiv2_step *stepper;     /* also the probe that re-steps for dense output */
    gsl_odeiv2_evolve *evolve;
    gsl_odeiv2_control *control; /* set per step with bk_gsl_control_weights */
    struct bk_gsl_shared *next;  /* same bucket */
} bk_gsl_shared;

/* The objects for (type, n), made on first use; NULL when out of memory. */
bk_gsl_shared *bk_gsl_shared_acquire(const gsl_odeiv2_step_type *type, size_t n);
/* Done with them: the last user frees them.  NULL is ignored. */
void bk_gsl_shared_release(bk_gsl_shared *shared);
/* Point the shared control at an instance's tolerances: D_i = eps_abs scale_i + eps_rel |y_i|. */
void bk_gsl_control_weights(gsl_odeiv2_control *control, double eps_abs, double eps_rel,
                            const double *scale);

/* A control of that kind of one's own (gsl_odeiv2_control_free frees it). */
gsl_odeiv2_control *bk_gsl_control_alloc(void);
/* errlevel (the scale msbdf's Newton iteration tests its corrections against) reports
 * factor * D_i for component i when |h| stiffness[i] > 1, D_i otherwise; hadjust, the
 * error test, keeps D_i.  stiffness (|d f_i/d y_i|, read through the pointer) may be NULL. */
void bk_gsl_control_stiff_errlevel(gsl_odeiv2_control *control, const double *stiffness, double factor);

#endif
