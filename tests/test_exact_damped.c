/* The exact stepper with dashpots: the damped modal solution against a long double Taylor
 * integration in every regime (underdamped, critical, 1 +- 1e-9, overdamped, free), the
 * dashpots' dissipation from the modes' energy balance against its own quadrature, the
 * sampling step of overdamped modes, refusal of damping that couples the modes, a single
 * damped block against an independent long double closed form (transition times to 1e-12),
 * uniform damped chains sliding as one, and damped chains (uniform and heterogeneous,
 * substrate and coupling dashpots) against CVODE at rtol 1e-12. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "linear_chain.h"
#include "recorder.h"
#include "scene_spec.h"
#include "solver/exact_backend.h"

#define PI 3.14159265358979323846

static double relative(double a, double b) { return fabs(a - b) / fmax(fabs(b), DBL_MIN); }

/* The long double references below are worth their 11 extra bits only where long double
 * arithmetic has them: valgrind does it in double, and then the references round like the
 * stepper and the bounds on their difference widen by this (measured there: 131 eps where
 * 2.5 natively, and the overdamped closed form must avoid cosh overflowing). */
static double reference_slack(void)
{
    volatile long double one = 1.0L, tiny = 0x1p-60L;
    return one + tiny != one ? 1.0 : 64.0;
}

static const bk_solver_options *default_options(void)
{
    static bk_solver_options o;
    memset(&o, 0, sizeof o);
    snprintf(o.method, sizeof o.method, "exact");
    snprintf(o.linear_solver, sizeof o.linear_solver, "auto");
    o.rtol = 1e-8;
    o.max_step = NAN;
    o.max_steps = 100000;
    return &o;
}

/* --- the back-end alone: one damped forced oscillator ------------------------------------ */

/* x'' = -w^2 x - gamma v + g + d t (unit mass), quadratures q0' = 2 x + 3 v + 1 + 0.5 t and
 * q1' = gamma v^2, the dashpot's dissipation (declared the last component). */
typedef struct damped {
    double w, gamma, g, d;
} damped;

static int damped_rhs(double t, const double *y, double *ydot, void *user)
{
    const damped *f = user;
    ydot[0] = y[1];
    ydot[1] = -f->w * f->w * y[0] - f->gamma * y[1] + f->g + f->d * t;
    ydot[2] = 2.0 * y[0] + 3.0 * y[1] + 1.0 + 0.5 * t;
    ydot[3] = f->gamma * y[1] * y[1];
    return 0;
}

static int damped_jacobian(double t, const double *y, void *user,
                           void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix)
{
    (void)t;
    const damped *f = user;
    put(matrix, 0, 1, 1.0);
    put(matrix, 1, 0, -f->w * f->w);
    put(matrix, 1, 1, -f->gamma);
    put(matrix, 2, 0, 2.0);
    put(matrix, 2, 1, 3.0);
    put(matrix, 3, 1, 2.0 * f->gamma * y[1]);
    return 0;
}

/* Reference: the ODE's own Taylor series in long double, stepped from t0 in steps of a
 * quarter over the largest characteristic root (terms shrink as 4^-n), 40 terms; the
 * dissipation integrated term by term from the series of v^2.  No closed form shared with
 * the stepper. */
typedef struct reference {
    const damped *f;
    long double t, x, v, q0, q1;
} reference;

#define TAYLOR_TERMS 40

static void reference_advance(reference *r, long double t_to)
{
    const damped *f = r->f;
    long double w2 = (long double)f->w * f->w, gamma = f->gamma;
    long double sigma = gamma / 2, disc = sigma * sigma - w2;
    long double rate = disc > 0 ? sigma + sqrtl(disc) : sqrtl(w2);
    long double h_max = 0.25L / fmaxl(rate, 1e-3L);
    while (r->t < t_to) {
        long double h = fminl(h_max, t_to - r->t);
        long double a[TAYLOR_TERMS + 2], b[TAYLOR_TERMS + 1];
        a[0] = r->x;
        a[1] = r->v;
        for (int k = 0; k + 2 < TAYLOR_TERMS + 2; ++k) {
            long double force = k == 0 ? (long double)f->g + (long double)f->d * r->t : k == 1 ? (long double)f->d : 0.0L;
            a[k + 2] = (-w2 * a[k] - gamma * (k + 1) * a[k + 1] + force) / ((long double)(k + 1) * (k + 2));
        }
        for (int k = 0; k <= TAYLOR_TERMS; ++k)
            b[k] = (k + 1) * a[k + 1]; /* v's coefficients */
        long double x = 0, v = 0, ix = 0, iv2 = 0, power = 1; /* power = h^k */
        for (int k = 0; k <= TAYLOR_TERMS; ++k) {
            x += a[k] * power;
            v += b[k] * power;
            ix += a[k] * power * h / (k + 1);
            long double square = 0; /* coefficient k of v^2 */
            for (int i = 0; i <= k; ++i)
                square += b[i] * b[k - i];
            iv2 += square * power * h / (k + 1);
            power *= h;
        }
        long double t1 = r->t + h;
        r->q0 += 2 * ix + 3 * (x - r->x) + h + 0.25L * (t1 * t1 - r->t * r->t);
        r->q1 += gamma * iv2;
        r->x = x;
        r->v = v;
        r->t = t1;
    }
}

/* Dense output against the reference over tau = 2^-11 .. 1 times 40 s, in units of
 * eps (1 + |root| tau) of each component's scale (rounding the phase of an oscillation
 * costs eps w tau in any closed form), with and without the problem's Jacobian. */
static void test_damped_oscillator(void **state)
{
    (void)state;
    const damped cases[] = {
        {100.0, 20.0, 0.37, -2.1},                  /* zeta = 0.1 */
        {100.0, 200.0, 0.37, -2.1},                 /* critical, exactly */
        {100.0, 200.0 * (1.0 - 1e-9), 0.37, -2.1},  /* just under */
        {100.0, 200.0 * (1.0 + 1e-9), 0.37, -2.1},  /* just over */
        {100.0, 600.0, 0.37, -2.1},                 /* zeta = 3 */
        {2.385, 1e3, -1.5, 0.8},                    /* zeta = 210: a slow and a fast root */
        {0.0, 3.3, 0.37, -2.1},                     /* free, damped */
        {1e-9, 0.7, 0.2, 0.1},                      /* nearly free */
    };
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    double worst = 0.0;
    for (size_t c = 0; c < 2 * sizeof cases / sizeof cases[0]; ++c) {
        damped f = cases[c / 2];
        int with_jacobian = c % 2;
        static const double unit_mass[1] = {1.0};
        bk_ode_problem p = {.user = &f, .rhs = damped_rhs, .jacobian = with_jacobian ? damped_jacobian : NULL,
                            .n_pairs = 1, .pair_mass = unit_mass, .affine = 1, .dissipation_last = 1};
        const double t0 = 3.25, y0[4] = {0.1, -0.4, 0.5, -0.3};
        double atol[4] = {1e-12, 1e-12, 1e-12, 1e-12};
        if (b->start(mem, &p, t0, y0, atol, 4, t0 + 40.0, &err) != BK_OK)
            fail_msg("case %zu: %s", c, err.message);
        long double ref[111][4];
        double scale[4] = {0, 0, 0, 0};
        reference r = {&f, t0, y0[0], y0[1], y0[2], y0[3]};
        for (int e = -60; e <= 50; ++e) {
            /* at the double t the stepper is asked for, not at t0 + tau rounded otherwise */
            reference_advance(&r, (long double)(t0 + 40.0 * pow(2.0, (double)e / 10.0 - 5.0)));
            long double *row = ref[e + 60];
            row[0] = r.x, row[1] = r.v, row[2] = r.q0, row[3] = r.q1;
            for (size_t k = 0; k < 4; ++k)
                scale[k] = fmax(scale[k], fabs((double)row[k]));
        }
        double root, radius;
        bk_exact_damped_root(f.w * f.w, f.gamma, &root, &radius);
        double case_worst = 0.0;
        for (int e = -60; e <= 50; ++e) {
            double tau = 40.0 * pow(2.0, (double)e / 10.0 - 5.0);
            double y[4];
            assert_int_equal(b->interpolate(mem, t0 + tau, y, &err), BK_OK);
            for (size_t k = 0; k < 4; ++k) {
                double units = DBL_EPSILON * (1.0 + fmax(f.w, radius) * tau) * scale[k];
                double e_units = fabs(y[k] - (double)ref[e + 60][k]) / units;
                if (e_units > 16.0 * reference_slack())
                    print_error("case %zu tau %.3g component %zu: %.17g vs %.17Lg (%.3g)\n", c, tau, k, y[k],
                                ref[e + 60][k], e_units);
                assert_true(e_units <= 16.0 * reference_slack());
                case_worst = fmax(case_worst, e_units);
            }
        }
        print_message("w %-6g gamma %-14.10g (%s Jacobian): worst %.3g eps (1 + |root| tau) of the scale\n", f.w,
                      f.gamma, with_jacobian ? "with" : "without", case_worst);
        worst = fmax(worst, case_worst);
    }
    print_message("damped oscillator: worst %.3g\n", worst);
    b->destroy(mem);
}

/* An overdamped mode's fast exponential limits the sampling step to 2 pi / (16 l-) until
 * it decayed (l- tau >= 40), then only the slow root does; a velocity root located on it. */
static void test_overdamped_sampling(void **state)
{
    (void)state;
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    damped f = {10.0, 1e3, 0.0, 0.0}; /* l+ = -0.1, l- = -999.9 */
    static const double unit_mass[1] = {1.0};
    bk_ode_problem p = {.user = &f, .rhs = damped_rhs, .n_pairs = 1, .pair_mass = unit_mass, .affine = 1,
                        .dissipation_last = 1};
    double y0[4] = {1.0, 0.0, 0.0, 0.0}, atol[4] = {1, 1, 1, 1}, y[4], t = 0.0, lo, hi;
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 4, 60.0, &err), BK_OK);
    double mu = sqrt(500.0 * 500.0 - 100.0), fast = 500.0 + mu, slow = 100.0 / (500.0 + mu);
    double h_fast = 2.0 * PI / (16.0 * fast), h_slow = 2.0 * PI / (16.0 * slow);
    long fast_steps = 0, slow_steps = 0;
    int rc;
    while ((rc = b->step(mem, &t, y, &err)) == BK_STEP_OK) {
        b->last_step(mem, &lo, &hi);
        double h = hi - lo;
        if (lo * fast < 40.0) {
            assert_true(h <= h_fast * (1.0 + 1e-12));
            fast_steps++;
        } else {
            assert_true(h <= h_slow * (1.0 + 1e-12));
            slow_steps++;
        }
    }
    assert_int_equal(rc, BK_STEP_STOP);
    print_message("overdamped: %ld steps while the fast root (%.6g /s) lives, %ld after (h %.3g s)\n", fast_steps,
                  fast, slow_steps, h_slow);
    assert_true(fast_steps >= (long)(40.0 / fast / h_fast) && fast_steps <= (long)(40.0 / fast / h_fast) + 2);
    assert_true(slow_steps <= (long)(60.0 / h_slow) + 2);
    /* x = (l- e^(l+ t) - l+ e^(l- t)) / (l- - l+) from rest at 1 */
    double l1 = -slow, l2 = -fast;
    assert_close(y[0], (l2 * exp(l1 * 60.0) - l1 * exp(l2 * 60.0)) / (l2 - l1), 1e-13, 0.0);
    b->destroy(mem);
}

/* A small chain of n pairs with any symmetric stiffness and damping matrices (N/m, N s/m):
 * x'' = M^-1 (-K x - C v + f0 + f1 t), quadratures q0' = sum (w_i x_i + z_i v_i) + 1 + 0.5 t and
 * q1' = v^T C v (the dissipation, declared last).  Dashpots out of proportion with the
 * masses and springs couple the modes: exact_coupled.c's state-space modes. */
#define SMALL_MAX 4

typedef struct small_chain {
    size_t n;
    double mass[SMALL_MAX], K[SMALL_MAX][SMALL_MAX], C[SMALL_MAX][SMALL_MAX];
    double f0[SMALL_MAX], f1[SMALL_MAX], w[SMALL_MAX], z[SMALL_MAX];
    double dissipation; /* the last rate is dissipation times v^T C v (1: the truth) */
} small_chain;

static int small_rhs(double t, const double *y, double *ydot, void *user)
{
    const small_chain *c = user;
    size_t n = c->n;
    double q0 = 1.0 + 0.5 * t, q1 = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double f = c->f0[i] + c->f1[i] * t, cv = 0.0;
        for (size_t j = 0; j < n; ++j) {
            f -= c->K[i][j] * y[2 * j] + c->C[i][j] * y[2 * j + 1];
            cv += c->C[i][j] * y[2 * j + 1];
        }
        ydot[2 * i] = y[2 * i + 1];
        ydot[2 * i + 1] = f / c->mass[i];
        q0 += c->w[i] * y[2 * i] + c->z[i] * y[2 * i + 1];
        q1 += y[2 * i + 1] * cv;
    }
    ydot[2 * n] = q0;
    ydot[2 * n + 1] = c->dissipation * q1;
    return 0;
}

/* The same Taylor stepping as the oscillator's, with vectors; steps of a quarter over the
 * largest Gershgorin rate. */
typedef struct small_reference {
    const small_chain *c;
    long double t, x[SMALL_MAX], v[SMALL_MAX], q0, q1;
} small_reference;

static void small_advance(small_reference *r, long double t_to)
{
    const small_chain *c = r->c;
    size_t n = c->n;
    long double rate = 1.0L;
    for (size_t i = 0; i < n; ++i) {
        long double k = 0, d = 0;
        for (size_t j = 0; j < n; ++j) {
            k += fabsl((long double)c->K[i][j]);
            d += fabsl((long double)c->C[i][j]);
        }
        rate = fmaxl(rate, sqrtl(k / c->mass[i]) + d / c->mass[i]);
    }
    long double h_max = 0.25L / rate;
    while (r->t < t_to) {
        long double h = fminl(h_max, t_to - r->t);
        long double a[TAYLOR_TERMS + 2][SMALL_MAX], b[TAYLOR_TERMS + 1][SMALL_MAX];
        for (size_t i = 0; i < n; ++i) {
            a[0][i] = r->x[i];
            a[1][i] = r->v[i];
        }
        for (int k = 0; k + 2 < TAYLOR_TERMS + 2; ++k)
            for (size_t i = 0; i < n; ++i) {
                long double f = k == 0 ? (long double)c->f0[i] + (long double)c->f1[i] * r->t
                                       : k == 1 ? (long double)c->f1[i] : 0.0L;
                for (size_t j = 0; j < n; ++j)
                    f -= c->K[i][j] * a[k][j] + c->C[i][j] * (k + 1) * a[k + 1][j];
                a[k + 2][i] = f / c->mass[i] / ((long double)(k + 1) * (k + 2));
            }
        for (int k = 0; k <= TAYLOR_TERMS; ++k)
            for (size_t i = 0; i < n; ++i)
                b[k][i] = (k + 1) * a[k + 1][i];
        long double x[SMALL_MAX] = {0}, v[SMALL_MAX] = {0}, iq0 = 0, iq1 = 0, power = 1;
        for (int k = 0; k <= TAYLOR_TERMS; ++k) {
            long double affine = 0, square = 0;
            for (size_t i = 0; i < n; ++i) {
                x[i] += a[k][i] * power;
                v[i] += b[k][i] * power;
                affine += c->w[i] * a[k][i] + c->z[i] * b[k][i];
                for (int l = 0; l <= k; ++l)
                    for (size_t j = 0; j < n; ++j)
                        square += b[l][i] * c->C[i][j] * b[k - l][j];
            }
            iq0 += affine * power * h / (k + 1);
            iq1 += square * power * h / (k + 1);
            power *= h;
        }
        long double t1 = r->t + h;
        r->q0 += iq0 + h + 0.25L * (t1 * t1 - r->t * r->t);
        r->q1 += iq1;
        for (size_t i = 0; i < n; ++i) {
            r->x[i] = x[i];
            r->v[i] = v[i];
        }
        r->t = t1;
    }
}

/* Three pairs, driver springs and a coupling each, dashpots unlike their springs:
 * lightly damped, with an overdamped (real) mode, and heterogeneous masses with a ramp. */
static small_chain small_case(int which)
{
    small_chain c = {.n = 3, .dissipation = 1.0};
    const double kp[3] = {1e4, 1.3e4, 0.8e4}, kc[2] = {2e4, 1.5e4};
    const double light[3] = {2.0, 30.0, 5.0}, heavy[3] = {900.0, 10.0, 40.0};
    for (size_t i = 0; i < 3; ++i) {
        c.mass[i] = which == 2 ? 1.0 + 0.6 * (double)i : 1.0;
        c.K[i][i] = kp[i];
        c.C[i][i] = which == 1 ? heavy[i] : light[i];
        c.f0[i] = 5.0 * (double)i - 3.0;
        c.f1[i] = which == 2 ? 40.0 - 25.0 * (double)i : 0.0;
        c.w[i] = 0.3 * (double)i - 0.2;
        c.z[i] = 0.7 - 0.4 * (double)i;
    }
    for (size_t i = 0; i < 2; ++i) {
        c.K[i][i] += kc[i];
        c.K[i + 1][i + 1] += kc[i];
        c.K[i][i + 1] = c.K[i + 1][i] = -kc[i];
        double etac = which == 1 ? 3.0 : 7.0 * (double)(i + 1);
        c.C[i][i] += etac;
        c.C[i + 1][i + 1] += etac;
        c.C[i][i + 1] = c.C[i + 1][i] = -etac;
    }
    return c;
}

/* Dense output of coupled clusters against the reference, in units of eps (1 + |l| tau)
 * of each component's scale; the dissipation is the energy lost. */
static void test_coupled_modes(void **state)
{
    (void)state;
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    double worst = 0.0;
    for (int which = 0; which < 3; ++which) {
        small_chain c = small_case(which);
        size_t n = 2 * c.n + 2;
        bk_ode_problem p = {.user = &c, .rhs = small_rhs, .n_pairs = c.n, .pair_mass = c.mass, .affine = 1,
                            .dissipation_last = 1};
        double y0[2 * SMALL_MAX + 2] = {1e-3, 0.05, -2e-3, -0.1, 5e-4, 0.02, 0.5, -0.3}, atol[2 * SMALL_MAX + 2];
        for (size_t k = 0; k < n; ++k)
            atol[k] = 1e-12;
        const double t0 = 1.5;
        if (b->start(mem, &p, t0, y0, atol, n, t0 + 2.0, &err) != BK_OK)
            fail_msg("case %d: %s", which, err.message);
        const exact_backend *eb = mem;
        assert_int_equal(eb->n_clusters, 1);
        assert_int_equal(eb->n_coupled, 1); /* not proportional: the state-space modes */
        long double ref[81][2 * SMALL_MAX + 2];
        double scale[2 * SMALL_MAX + 2] = {0};
        small_reference r = {.c = &c, .t = t0, .q0 = y0[2 * c.n], .q1 = y0[2 * c.n + 1]};
        for (size_t i = 0; i < c.n; ++i) {
            r.x[i] = y0[2 * i];
            r.v[i] = y0[2 * i + 1];
        }
        for (int e = -60; e <= 20; ++e) {
            small_advance(&r, (long double)(t0 + 2.0 * pow(2.0, (double)e / 4.0 - 5.0)));
            long double *row = ref[e + 60];
            for (size_t i = 0; i < c.n; ++i) {
                row[2 * i] = r.x[i];
                row[2 * i + 1] = r.v[i];
            }
            row[2 * c.n] = r.q0;
            row[2 * c.n + 1] = r.q1;
            /* positions, velocities, each quadrature: one scale each */
            for (size_t k = 0; k < n; ++k) {
                size_t kind = k < 2 * c.n ? k % 2 : k;
                scale[kind] = fmax(scale[kind], fabs((double)row[k]));
            }
        }
        double rate = 0.0, case_worst = 0.0;
        for (size_t i = 0; i < c.n; ++i) {
            double k = 0.0, d = 0.0;
            for (size_t j = 0; j < c.n; ++j) {
                k += fabs(c.K[i][j]);
                d += fabs(c.C[i][j]);
            }
            rate = fmax(rate, sqrt(k / c.mass[i]) + d / c.mass[i]);
        }
        for (int e = -60; e <= 20; ++e) {
            double tau = 2.0 * pow(2.0, (double)e / 4.0 - 5.0), y[2 * SMALL_MAX + 2];
            assert_int_equal(b->interpolate(mem, t0 + tau, y, &err), BK_OK);
            for (size_t k = 0; k < n; ++k) {
                size_t kind = k < 2 * c.n ? k % 2 : k;
                double units = DBL_EPSILON * (1.0 + rate * tau) * scale[kind];
                double e_units = fabs(y[k] - (double)ref[e + 60][k]) / units;
                if (e_units > 32.0 * reference_slack())
                    print_error("case %d tau %.3g component %zu: %.17g vs %.17Lg (%.3g)\n", which, tau, k, y[k],
                                ref[e + 60][k], e_units);
                assert_true(e_units <= 32.0 * reference_slack());
                case_worst = fmax(case_worst, e_units);
            }
        }
        print_message("coupled case %d: worst %.3g eps (1 + rate tau) of the component's scale\n", which,
                      case_worst);
        worst = fmax(worst, case_worst);
    }
    print_message("coupled modes: worst %.3g\n", worst);
    b->destroy(mem);
}

/* What the exact stepper cannot solve is refused at start, with the reason and the way
 * out: a last rate declared the dissipation that is not v^T C v, and coupled modes that
 * merge (three free pairs tied by springs and by dashpots in another ratio: the free
 * translation is undamped, a Jordan block no eigenvector basis holds). */
static void test_refusals(void **state)
{
    (void)state;
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    double y0[2 * SMALL_MAX + 2] = {1e-3, 0.05, -2e-3, -0.1, 5e-4, 0.02, 0.5, -0.3}, atol[2 * SMALL_MAX + 2];
    for (size_t k = 0; k < 2 * SMALL_MAX + 2; ++k)
        atol[k] = 1.0;
    small_chain twice = small_case(0);
    twice.dissipation = 2.0;
    bk_ode_problem p = {.user = &twice, .rhs = small_rhs, .n_pairs = 3, .pair_mass = twice.mass, .affine = 1,
                        .dissipation_last = 1};
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 8, 1.0, &err), BK_ERR_CONFIG);
    print_message("not the dissipation: %s\n", err.message);
    assert_non_null(strstr(err.message, "is not the dashpots' dissipation"));
    assert_non_null(strstr(err.message, "use method = auto"));

    small_chain free_chain = {.n = 3, .mass = {1.0, 1.0, 1.0}, .dissipation = 1.0};
    const double kc[2] = {2e4, 1e4}, etac[2] = {5.0, 20.0};
    for (size_t i = 0; i < 2; ++i) {
        free_chain.K[i][i] += kc[i];
        free_chain.K[i + 1][i + 1] += kc[i];
        free_chain.K[i][i + 1] = free_chain.K[i + 1][i] = -kc[i];
        free_chain.C[i][i] += etac[i];
        free_chain.C[i + 1][i + 1] += etac[i];
        free_chain.C[i][i + 1] = free_chain.C[i + 1][i] = -etac[i];
    }
    p.user = &free_chain;
    p.pair_mass = free_chain.mass;
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 8, 1.0, &err), BK_ERR_CONFIG);
    print_message("merging modes: %s\n", err.message);
    assert_non_null(strstr(err.message, "nearly defective"));
    assert_non_null(strstr(err.message, "use method = auto"));

    /* the same back-end then solves a good problem */
    small_chain good = small_case(1);
    p.user = &good;
    p.pair_mass = good.mass;
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 8, 1.0, &err), BK_OK);
    double y[8], t;
    assert_int_equal(b->step(mem, &t, y, &err), BK_STEP_OK);
    b->destroy(mem);
}

/* --- output rows of long damped clusters ------------------------------------------------- */

/* tests/support's 200-pair chain of unequal blocks with dashpots added: proportional
 * (C = alpha M + beta K, one damped oscillator per mode) or not (a dashpot of its own on
 * every block and one beside every coupling: the coupled modes); the dashpots' dissipation
 * a third quadrature after the chain's two. */
typedef struct damped_chain_problem {
    linear_chain *lc;
    bk_ode_problem inner;
    int proportional;
} damped_chain_problem;

static double chain_dashpot(const damped_chain_problem *d, size_t i, const double *y)
{
    /* force of the dashpots on block i: C v with C = alpha M + beta K, or own ones */
    const linear_chain *lc = d->lc;
    size_t p = lc->p;
    double v = y[2 * i + 1], force;
    if (d->proportional) {
        const double alpha = 3.0, beta = 2e-3;
        force = -(alpha * lc->mass[i] + beta * lc->ground[i]) * v;
        if (i > 0)
            force -= beta * lc->coupling[i - 1] * (v - y[2 * i - 1]);
        if (i + 1 < p)
            force -= beta * lc->coupling[i] * (v - y[2 * i + 3]);
        return force;
    }
    force = -(2.0 + 40.0 * (double)(i % 7) / 7.0) * v;
    if (i > 0)
        force -= 6.0 * (v - y[2 * i - 1]);
    if (i + 1 < p)
        force -= 6.0 * (v - y[2 * i + 3]);
    return force;
}

static int damped_chain_rhs(double t, const double *y, double *ydot, void *user)
{
    const damped_chain_problem *d = user;
    size_t p = d->lc->p;
    int rc = d->inner.rhs(t, y, ydot, d->inner.user);
    double dissipation = 0.0;
    for (size_t i = 0; i < p; ++i) {
        double force = chain_dashpot(d, i, y);
        ydot[2 * i + 1] += force / d->lc->mass[i];
        dissipation -= y[2 * i + 1] * force;
    }
    ydot[2 * p + 2] = dissipation;
    return rc;
}

/* Rows of a long damped cluster come from its series about the last step end (d_{n+2} =
 * -K d_n - D d_{n+1}): the modal closed form's to rounding at every point of a step,
 * positions, velocities and quadratures, proportional and coupled alike.  Measured: 62 eps
 * at worst, at a step's start, where the modal form is exact (tau = 0) and the series
 * carries the modal sum's rounding at its centre, the step's end; a series without the
 * dashpots' term misses by 2e11 eps. */
static void test_damped_rows_from_series(void **state)
{
    (void)state;
    const size_t p = 200, n = 2 * p + 3;
    for (int proportional = 1; proportional >= 0; --proportional) {
        linear_chain *lc = linear_chain_new(p, 11u);
        assert_non_null(lc);
        damped_chain_problem d = {lc, linear_chain_problem(lc), proportional};
        bk_ode_problem problem = d.inner;
        problem.user = &d;
        problem.rhs = damped_chain_rhs;
        problem.dissipation_last = 1;
        const bk_solver_backend *b = bk_solver_backend_find("exact");
        void *mem = NULL;
        bk_error err = {0};
        assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
        double *y0 = malloc(n * sizeof *y0), *atol = malloc(n * sizeof *atol);
        double *y = malloc(n * sizeof *y), *ref = malloc(n * sizeof *ref), *scale = calloc(n, sizeof *scale);
        assert_true(y0 && atol && y && ref && scale);
        linear_chain_start(lc, y0);
        y0[2 * p + 2] = 0.125;
        for (size_t k = 0; k < n; ++k)
            atol[k] = 1e-12;
        const double t0 = 2.0;
        if (b->start(mem, &problem, t0, y0, atol, n, t0 + 10.0, &err) != BK_OK)
            fail_msg("%s", err.message);
        const exact_backend *eb = mem;
        assert_int_equal(eb->n_clusters, 1);
        assert_int_equal(eb->n_coupled, proportional ? 0 : 1);
        assert_int_equal(eb->n_series, 1);
        double worst = 0.0;
        for (int step = 0; step < 30; ++step) {
            double t_reached, t_lo, t_hi;
            assert_int_equal(b->step(mem, &t_reached, y, &err), BK_STEP_OK);
            for (size_t k = 0; k < n; ++k)
                scale[k < 2 * p ? k % 2 : k] = fmax(scale[k < 2 * p ? k % 2 : k], fabs(y[k]));
            b->last_step(mem, &t_lo, &t_hi);
            for (int j = 0; j <= 8; ++j) {
                double t = t_lo + (t_hi - t_lo) * (double)j / 8.0;
                assert_int_equal(b->sample(mem, t, y, &err), BK_OK);
                assert_int_equal(b->interpolate(mem, t, ref, &err), BK_OK);
                /* the modal sum rounds its phases by eps w tau (the series' rate bound for w) */
                double phase = 1.0 + eb->cluster_omega[0] * (t - t0);
                for (size_t k = 0; k < n; ++k) {
                    double units = fabs(y[k] - ref[k]) / (DBL_EPSILON * phase * scale[k < 2 * p ? k % 2 : k]);
                    if (units > 128.0)
                        print_error("step %d, row %d/8, component %zu: %.17g vs %.17g (%.3g eps)\n", step, j,
                                    k, y[k], ref[k], units);
                    assert_true(units <= 128.0);
                    worst = fmax(worst, units);
                }
            }
        }
        print_message("rows of a %zu-pair %s cluster from the series: worst %.3g eps (1 + rate tau) of the "
                      "component's scale against the modal closed form\n",
                      p, proportional ? "proportionally damped" : "coupled", worst);
        b->destroy(mem);
        free(y0);
        free(atol);
        free(y);
        free(ref);
        free(scale);
        linear_chain_free(lc);
    }
}

/* --- one damped block: an independent closed form ---------------------------------------- */

/* A block of mass m on a driver spring k pulled at V from x = 0 (the driver at 0 at t = 0),
 * starting at v0 >= 0, with Coulomb friction (mu_s, mu_d of N) and a dashpot eta to the
 * substrate.  While it slips forward, y = x - (V t - e_ss), e_ss = (mu_d N + eta V) / k,
 * solves m y'' + eta y' + k y = 0:
 *     y'(tau) = e^(-sigma tau) (y0' C(tau) - (sigma y0' + w^2 y0) S(tau)),
 * C = cos(nu tau), S = sin(nu tau) / nu (nu^2 = w^2 - sigma^2 > 0), cosh / sinh for nu^2 < 0,
 * C = 1, S = tau at critical damping; it stops where v = V + y' = 0 (first crossing,
 * sampled at a 64th of the shortest time scale and bisected in long double), and sticks if
 * |k e| <= mu_s N there (else the case is not derived here); it breaks away where k (V t -
 * x) = mu_s N.  Everything in long double from the double parameters the run uses. */
typedef struct damped_block {
    double mass, stiffness, normal, mu_s, mu_d, velocity, eta, v0;
} damped_block;

typedef struct block_event {
    long double t;
    int to;
} block_event;

/* e^(-sigma tau) C(tau) and e^(-sigma tau) S(tau) of the block's slip (above), and sigma,
 * w^2; overdamped with mu tau > 1 from the two exponentials, so that nothing overflows
 * where long double has only double's range (valgrind). */
static void decayed_basis(const damped_block *p, long double tau, long double *C, long double *S,
                          long double *sigma_out, long double *w2_out)
{
    long double m = p->mass, k = p->stiffness, eta = p->eta;
    long double sigma = eta / (2 * m), w = sqrtl(k / m), nu2 = (w - sigma) * (w + sigma);
    long double decay = expl(-sigma * tau);
    if (nu2 > 0) {
        long double nu = sqrtl(nu2);
        *C = decay * cosl(nu * tau);
        *S = decay * sinl(nu * tau) / nu;
    } else if (nu2 < 0) {
        long double mu = sqrtl(-nu2);
        if (mu * tau < 1) {
            *C = decay * coshl(mu * tau);
            *S = decay * sinhl(mu * tau) / mu;
        } else {
            long double slow = expl((mu - sigma) * tau), fast = expl(-(mu + sigma) * tau);
            *C = (slow + fast) / 2;
            *S = (slow - fast) / (2 * mu);
        }
    } else {
        *C = decay;
        *S = decay * tau;
    }
    *sigma_out = sigma;
    *w2_out = w * w;
}

static long double slip_rate(const damped_block *p, long double y0, long double dy0, long double tau)
{
    long double C, S, sigma, w2;
    decayed_basis(p, tau, &C, &S, &sigma, &w2);
    return (long double)p->velocity + dy0 * C - (sigma * dy0 + w2 * y0) * S;
}

static long double slip_position(const damped_block *p, long double y0, long double dy0, long double tau)
{
    long double C, S, sigma, w2;
    decayed_basis(p, tau, &C, &S, &sigma, &w2);
    return y0 * C + (dy0 + sigma * y0) * S;
}

/* The block's transitions on [0, t_end]; the count, or -1 where the motion leaves the cases
 * derived here. */
static int damped_block_events(const damped_block *p, double t_end, block_event *events, int max_events)
{
    long double V = p->velocity, k = p->stiffness, m = p->mass;
    long double fs = (long double)p->mu_s * p->normal, fk = (long double)p->mu_d * p->normal;
    long double e_ss = (fk + (long double)p->eta * V) / k;
    long double sigma = (long double)p->eta / (2 * m), w = sqrtl(k / m);
    long double scale = 1.0L / (64.0L * fmaxl(w, sigma + sqrtl(fmaxl(sigma * sigma - w * w, 0))));
    long double t = 0, x = 0, v = p->v0;
    int n = 0, slipping = v > 0;
    while (n < max_events) {
        if (!slipping) {
            long double t_break = t + (fs / k - (V * t - x)) / V;
            if (t_break > t_end)
                return n;
            events[n++] = (block_event){t_break, BK_MODE_SLIP_POS};
            t = t_break;
            v = 0;
            slipping = 1;
            continue;
        }
        long double y0 = x - (V * t - e_ss), dy0 = v - V;
        long double lo = 0, hi = scale;
        /* from rest v starts at zero, rising: look from the first sample on */
        while (slip_rate(p, y0, dy0, hi) > 0) {
            lo = hi;
            hi += scale;
            if (t + lo > t_end)
                return n;
        }
        for (int it = 0; it < 200 && hi - lo > 0; ++it) {
            long double mid = lo + (hi - lo) / 2;
            if (mid == lo || mid == hi)
                break;
            if (slip_rate(p, y0, dy0, mid) > 0)
                lo = mid;
            else
                hi = mid;
        }
        long double t_stop = t + hi;
        if (t_stop > t_end)
            return n;
        x = V * t_stop - e_ss + slip_position(p, y0, dy0, hi);
        if (fabsl(k * (V * t_stop - x)) > fs)
            return -1; /* a reversal */
        events[n++] = (block_event){t_stop, BK_MODE_STICK};
        t = t_stop;
        v = 0;
        slipping = 0;
    }
    return n;
}

static void single_damped_block(double zeta, double v0, size_t *n_compared, double *worst_time)
{
    scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, 1e-10, "exact");
    bk_config *c = scene_config(&spec);
    double eta = 2.0 * zeta * sqrt(spec.stiffness * spec.mass);
    c->model->blocks[0].damping = eta;
    c->model->blocks[0].v_init = v0;
    bk_model_finalize(c->model);
    damped_block p = {spec.mass, spec.stiffness, spec.mass * 9.81, spec.mu_s, spec.mu_d, spec.velocity, eta, v0};
    block_event ex[64];
    int n = damped_block_events(&p, spec.t_end, ex, 64);
    assert_true(n >= 2);
    recorder r = {0};
    bk_run_stats stats;
    bk_error err = {0};
    if (run_recorded(c, &r, &stats, &err) != BK_OK)
        fail_msg("zeta %g: %s", zeta, err.message);
    if (r.n_transitions != (size_t)n)
        print_error("zeta %.17g: %zu transitions, the closed form has %d\n", zeta, r.n_transitions, n);
    assert_int_equal(r.n_transitions, (size_t)n);
    double worst = 0.0;
    for (int k = 0; k < n; ++k) {
        assert_int_equal(r.transitions[k].to, ex[k].to);
        assert_int_equal(r.transitions[k].from, ex[k].to == BK_MODE_STICK ? BK_MODE_SLIP_POS : BK_MODE_STICK);
        worst = fmax(worst, relative(r.transitions[k].t, (double)ex[k].t));
    }
    print_message("zeta %-12.10g v0 %-4g %2d transitions (first at %.17Lg s): worst relative time error %.2g; "
                  "energy residual %.2g\n",
                  zeta, v0, n, ex[0].t, worst, stats.energy_residual);
    assert_true(worst <= 1e-12);
    assert_true(fabs(stats.energy_residual) <= 1e-12);
    assert_true(r.max_balance_error <= 1e-12 * r.max_work);
    *n_compared += (size_t)n;
    *worst_time = fmax(*worst_time, worst);
    recorder_free(&r);
    bk_config_free(c);
}

/* Launched at 0.1 m/s, the block stops, sticks, breaks away when the driver has loaded its
 * spring to mu_s N, and (underdamped) stick-slips on; at and above critical damping it then
 * slides for good. */
static void test_single_damped_block(void **state)
{
    (void)state;
    const double zetas[] = {0.1, 1.0, 1.0 - 1e-9, 1.0 + 1e-9, 3.0};
    size_t compared = 0;
    double worst = 0.0;
    for (size_t z = 0; z < sizeof zetas / sizeof *zetas; ++z)
        single_damped_block(zetas[z], 0.1, &compared, &worst);
    /* from rest, underdamped: stick-slip from the start */
    single_damped_block(0.1, 0.0, &compared, &worst);
    single_damped_block(0.02, 0.0, &compared, &worst);
    print_message("single damped block: %zu transitions, worst relative time error %.2g\n", compared, worst);
}

/* --- chains ------------------------------------------------------------------------------- */

/* A uniform damped chain started relaxed slides as one damped block: every instant holds
 * every block's transition, at the single block's closed-form times; dashpots to the
 * substrate and between the blocks, free and periodic ends. */
static void test_uniform_damped_chain_slides_as_one(void **state)
{
    (void)state;
    const size_t lengths[] = {2, 5, 16};
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_PERIODIC};
    double eta = 2.0 * 0.05 * 100.0;
    damped_block p = {1.0, 1e4, 9.81, 0.6, 0.5, 1e-3, eta, 0.0};
    block_event ex[64];
    int n = damped_block_events(&p, 3.0, ex, 64);
    assert_true(n >= 4);
    for (size_t b = 0; b < 2; ++b)
        for (size_t l = 0; l < sizeof lengths / sizeof *lengths; ++l) {
            scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, 1e-10, "exact");
            spec.n = lengths[l];
            spec.coupling = 2e4;
            spec.boundary = boundaries[b];
            spec.t_end = 3.0;
            bk_config *c = scene_config(&spec);
            for (size_t i = 0; i < spec.n; ++i)
                c->model->blocks[i].damping = eta;
            c->model->coupling_damping = 30.0;
            bk_model_finalize(c->model);
            recorder r = {0};
            bk_error err = {0};
            if (run_recorded(c, &r, NULL, &err) != BK_OK)
                fail_msg("%s", err.message);
            assert_int_equal(r.n_transitions, spec.n * (size_t)n);
            double worst = 0.0;
            for (int e = 0; e < n; ++e)
                for (size_t i = 0; i < spec.n; ++i) {
                    const bk_transition *t = &r.transitions[(size_t)e * spec.n + i];
                    assert_int_equal(t->block, (int32_t)i);
                    assert_int_equal(t->to, ex[e].to);
                    assert_true(t->t == r.transitions[(size_t)e * spec.n].t);
                    worst = fmax(worst, relative(t->t, (double)ex[e].t));
                }
            print_message("uniform damped chain of %2zu, %s ends: %d instants, worst relative time error %.2g\n",
                          spec.n, b == 0 ? "free" : "periodic", n, worst);
            assert_true(worst <= 1e-12);
            recorder_free(&r);
            bk_config_free(c);
        }
}

/* Chains: uniform with dashpots to the substrate, uniform with coupling dashpots as well,
 * heterogeneous (masses and driver springs varying along the chain, the dashpots
 * C = alpha M + beta K so that the damping stays proportional), and heterogeneous with
 * dashpots unlike the springs (coupled modes, exact_coupled.c). */
enum { CHAIN_SUBSTRATE, CHAIN_COUPLING, CHAIN_HETEROGENEOUS, CHAIN_COUPLED };

static bk_config *damped_chain(int kind, const char *method, double rtol, double damping_scale)
{
    scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, 1e-10, method);
    spec.n = kind == CHAIN_SUBSTRATE ? 10 : kind == CHAIN_HETEROGENEOUS ? 30 : 20;
    spec.coupling = 2e4;
    spec.boundary = kind == CHAIN_COUPLING ? BK_BOUNDARY_FIXED : BK_BOUNDARY_FREE;
    spec.rtol = rtol;
    spec.t_end = kind == CHAIN_SUBSTRATE ? 1.5 : 1.0;
    bk_config *c = scene_config(&spec);
    bk_model *m = c->model;
    double alpha = 8.0, beta = kind == CHAIN_SUBSTRATE ? 0.0 : 1e-3;
    m->coupling_damping = damping_scale * beta * spec.coupling;
    for (size_t i = 0; i < spec.n; ++i) {
        bk_block *b = &m->blocks[i];
        b->x_init = 1e-5 * sin(2.385 * (double)i);
        b->friction_params[1] = 0.45 + 0.01 * (double)(i % 5);
        if (kind >= CHAIN_HETEROGENEOUS) {
            b->mass = 1.0 + 0.5 * sin(1.3 * (double)i);
            b->driver_stiffness = 1e4 * (1.0 + 0.3 * cos(0.7 * (double)i));
            b->normal_force = b->mass * 9.81;
        }
        b->damping = damping_scale * (alpha * b->mass + beta * b->driver_stiffness);
        if (kind == CHAIN_COUPLED)
            b->damping = damping_scale * (4.0 + 30.0 * (1.0 + sin(3.1 * (double)i)));
    }
    bk_model_finalize(m);
    return c;
}

#define CHAIN_COMPARED 60

static void test_damped_chains_against_cvode(void **state)
{
    (void)state;
    const char *names[] = {"10 blocks, substrate dashpots", "20 blocks, coupling dashpots, fixed ends",
                           "30 blocks, heterogeneous", "20 blocks, dashpots unlike the springs"};
    for (int kind = 0; kind < 4; ++kind) {
        bk_config *ce = damped_chain(kind, "exact", 1e-10, 1.0);
        bk_config *cc = damped_chain(kind, "cvode_adams", 1e-12, 1.0);
        bk_config *cw = damped_chain(kind, "exact", 1e-10, 0.9); /* damping 10% off */
        assert_int_equal(bk_model_damping_proportional(ce->model), kind != CHAIN_COUPLED);
        recorder re = {0}, rc = {0}, rw = {0};
        bk_run_stats se, sc, sw;
        bk_error err = {0};
        if (run_recorded(ce, &re, &se, &err) != BK_OK)
            fail_msg("%s: %s", names[kind], err.message);
        assert_int_equal(run_recorded(cc, &rc, &sc, &err), BK_OK);
        assert_int_equal(run_recorded(cw, &rw, &sw, &err), BK_OK);
        assert_true(re.n_transitions >= CHAIN_COMPARED);
        assert_true(rc.n_transitions >= CHAIN_COMPARED);
        double worst = 0.0, off = 0.0;
        size_t same = 0;
        for (size_t k = 0; k < CHAIN_COMPARED; ++k) {
            const bk_transition *a = &re.transitions[k], *b = &rc.transitions[k];
            assert_int_equal(a->block, b->block);
            assert_int_equal(a->from, b->from);
            assert_int_equal(a->to, b->to);
            worst = fmax(worst, relative(a->t, b->t));
            /* the same chain with its damping 10% off: how far it drifts */
            if (k < rw.n_transitions && rw.transitions[k].block == a->block && rw.transitions[k].to == a->to) {
                same++;
                off = fmax(off, relative(rw.transitions[k].t, a->t));
            }
        }
        print_message("%s: %zu / %zu transitions (exact / CVODE), first %d agree to %.2g relative; damping "
                      "10%% off: %zu of them alike, times off by %.2g; CPU exact %.3g s, CVODE %.3g s; energy "
                      "residual %.2g\n",
                      names[kind], re.n_transitions, rc.n_transitions, CHAIN_COMPARED, worst, same, off,
                      se.cpu_time, sc.cpu_time, se.energy_residual);
        assert_true(worst <= 1e-8);
        /* a tolerance the wrong damping fails by orders of magnitude */
        assert_true(same < CHAIN_COMPARED || off >= 1e4 * 1e-8);
        assert_true(fabs(se.energy_residual) <= 1e-11);
        assert_true(re.max_balance_error <= 1e-11 * re.max_work);
        recorder_free(&re);
        recorder_free(&rc);
        recorder_free(&rw);
        bk_config_free(ce);
        bk_config_free(cc);
        bk_config_free(cw);
    }
}

/* A damped chain pushed at one edge until it slides steadily (the Oslo model's supershear
 * front, 10 blocks): once the slip accelerations have decayed to the rounding of the forces,
 * the armed slip-rate minima flicker about zero, and locating the earliest zero of such a
 * function had crept back one tolerance per round until the stepper gave up ("cannot
 * separate the roots" at t = 90.5 with alpha = 0.3, 317 with 0.1).  The run ends, with the
 * transitions of gsl_rk8pd at rtol 1e-12. */
static void test_steady_sliding_after_front(void **state)
{
    (void)state;
    const double alphas[] = {0.3, 0.1};
    for (size_t k = 0; k < 2; ++k) {
        recorder r[2];
        memset(r, 0, sizeof r);
        const char *methods[] = {"exact", "gsl_rk8pd"};
        for (int m = 0; m < 2; ++m) {
            char damping[64], method[64];
            snprintf(damping, sizeof damping, "block.damping=%g", alphas[k]);
            snprintf(method, sizeof method, "solver.method=%s", methods[m]);
            const char *overrides[] = {damping, method, "block.applied_force=1.95", "model.n_blocks=10",
                                       "run.t_end=400", "solver.rtol=1e-12", "output.interval=0"};
            bk_config *c = NULL;
            bk_error err = {0};
            if (bk_config_load_file("configs/fronts/oslo_front.ini", overrides, 7, &c, &err) != BK_OK)
                fail_msg("%s", err.message);
            bk_run_stats stats;
            int rc = run_recorded(c, &r[m], &stats, &err);
            if (rc != BK_OK)
                fail_msg("%s, alpha %g: %s", methods[m], alphas[k], err.message);
            bk_config_free(c);
        }
        assert_int_equal(r[0].n_transitions, r[1].n_transitions);
        double worst = 0.0;
        for (size_t i = 0; i < r[0].n_transitions; ++i) {
            assert_int_equal(r[0].transitions[i].block, r[1].transitions[i].block);
            worst = fmax(worst, fabs(r[0].transitions[i].t - r[1].transitions[i].t));
        }
        print_message("alpha %g: %zu transitions, all alike within %.3g s\n", alphas[k], r[0].n_transitions, worst);
        assert_true(worst < 1e-9);
        recorder_free(&r[0]);
        recorder_free(&r[1]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_damped_oscillator),
        cmocka_unit_test(test_overdamped_sampling),
        cmocka_unit_test(test_coupled_modes),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_damped_rows_from_series),
        cmocka_unit_test(test_single_damped_block),
        cmocka_unit_test(test_uniform_damped_chain_slides_as_one),
        cmocka_unit_test(test_damped_chains_against_cvode),
        cmocka_unit_test(test_steady_sliding_after_front),
    };
    return cmocka_run_group_tests_name("exact_damped", tests, NULL, NULL);
}
