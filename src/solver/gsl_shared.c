/* Step-size control and the RK objects the GSL back-ends share (gsl_shared.h). */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_errno.h>

#include "gsl_shared.h"

/* GSL's scaled control (D_i = eps_abs scale_i + eps_rel |y_i|, with a_y = 1, a_dydt = 0)
 * reading its weights through a pointer instead of a copy made at allocation, so that one
 * control serves islands whose layouts differ.  hadjust is GSL's heuristic as documented
 * (decrease when the error exceeds D by 10 %, by S / r^(1/q) but at most 5 times;
 * increase when below half, by S / r^(1/(q+1)) at most 4.9 times; S = 0.9), evaluated
 * in GSL's order so that steps are bit-identical to gsl_odeiv2_control_scaled's. */
typedef struct scaled_control {
    double eps_abs, eps_rel;
    const double *scale;
    /* errlevel reports stiff_factor D_i for a component with h stiffness_i > 1 (NULL: none) */
    const double *stiffness;
    double stiff_factor;
} scaled_control;

static void *control_alloc(void)
{
    return calloc(1, sizeof(scaled_control));
}

static int control_init(void *state, double eps_abs, double eps_rel, double a_y, double a_dydt)
{
    (void)a_y;
    (void)a_dydt;
    scaled_control *c = state;
    c->eps_abs = eps_abs;
    c->eps_rel = eps_rel;
    return GSL_SUCCESS;
}

static int control_hadjust(void *state, size_t dim, unsigned int ord, const double y[],
                           const double yerr[], const double yp[], double *h)
{
    (void)yp;
    const scaled_control *c = state;
    const double S = 0.9, h_old = *h;
    double rmax = DBL_MIN;
    for (size_t i = 0; i < dim; ++i) {
        double d0 = c->eps_rel * fabs(y[i]) + c->eps_abs * c->scale[i];
        double r = fabs(yerr[i]) / fabs(d0);
        rmax = r > rmax ? r : rmax;
    }
    if (rmax > 1.1) {
        double r = S / pow(rmax, 1.0 / ord);
        *h = (r < 0.2 ? 0.2 : r) * h_old;
        return GSL_ODEIV_HADJ_DEC;
    }
    if (rmax < 0.5) {
        double r = S / pow(rmax, 1.0 / (ord + 1.0));
        r = r > 4.9 ? 4.9 : r;
        *h = (r < 1.0 ? 1.0 : r) * h_old;
        return GSL_ODEIV_HADJ_INC;
    }
    return GSL_ODEIV_HADJ_NIL;
}

static int control_errlevel(void *state, double y, double dydt, double h, size_t ind, double *errlev)
{
    (void)dydt;
    const scaled_control *c = state;
    *errlev = c->eps_rel * fabs(y) + c->eps_abs * c->scale[ind];
    if (c->stiffness && fabs(h) * c->stiffness[ind] > 1.0)
        *errlev *= c->stiff_factor;
    return *errlev > 0.0 ? GSL_SUCCESS : GSL_ESANITY;
}

static int control_set_driver(void *state, const gsl_odeiv2_driver *d)
{
    (void)state;
    (void)d;
    return GSL_SUCCESS;
}

static const gsl_odeiv2_control_type scaled_control_type = {
    "bksim scaled", control_alloc, control_init, control_hadjust, control_errlevel,
    control_set_driver, free};

/* The RK objects of one size, shared by this thread's instances: a long chain runs
 * thousands of islands in turn, and objects of their own (16 n doubles of stages and
 * copies in a dozen allocations) would be cold at every turn.  Sharing is exact: an RK
 * step reads nothing left by the last one except evolve's dydt_out, refilled per step, so
 * the stepper also serves as the probe that re-steps for dense output.
 * Reference-counted; an instance stays in the thread that made it. */
#define SHARED_BUCKETS 64
static _Thread_local bk_gsl_shared *shared_table[SHARED_BUCKETS];

static void shared_free(bk_gsl_shared *s)
{
    if (s->stepper)
        gsl_odeiv2_step_free(s->stepper);
    if (s->evolve)
        gsl_odeiv2_evolve_free(s->evolve);
    if (s->control)
        gsl_odeiv2_control_free(s->control);
    free(s);
}

bk_gsl_shared *bk_gsl_shared_acquire(const gsl_odeiv2_step_type *type, size_t n)
{
    bk_gsl_shared **bucket = &shared_table[n % SHARED_BUCKETS];
    for (bk_gsl_shared *s = *bucket; s; s = s->next)
        if (s->type == type && s->n == n) {
            s->users++;
            return s;
        }
    bk_gsl_shared *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    *s = (bk_gsl_shared){type, n, 1, gsl_odeiv2_step_alloc(type, n),
                     gsl_odeiv2_evolve_alloc(n), gsl_odeiv2_control_alloc(&scaled_control_type), *bucket};
    if (!s->stepper || !s->evolve || !s->control) {
        shared_free(s);
        return NULL;
    }
    *bucket = s;
    return s;
}

void bk_gsl_shared_release(bk_gsl_shared *s)
{
    if (!s || --s->users > 0)
        return;
    for (bk_gsl_shared **link = &shared_table[s->n % SHARED_BUCKETS]; *link; link = &(*link)->next)
        if (*link == s) {
            *link = s->next;
            break;
        }
    shared_free(s);
}


void bk_gsl_control_weights(gsl_odeiv2_control *control, double eps_abs, double eps_rel,
                            const double *scale)
{
    scaled_control *c = control->state;
    c->eps_abs = eps_abs;
    c->eps_rel = eps_rel;
    c->scale = scale;
}

gsl_odeiv2_control *bk_gsl_control_alloc(void)
{
    return gsl_odeiv2_control_alloc(&scaled_control_type);
}

void bk_gsl_control_stiff_errlevel(gsl_odeiv2_control *control, const double *stiffness, double factor)
{
    scaled_control *c = control->state;
    c->stiffness = stiffness;
    c->stiff_factor = factor;
}
