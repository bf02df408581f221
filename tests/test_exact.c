/* The exact piecewise-analytic stepper: its modal solution against independent closed forms,
 * the paper's single block (cases A, B, C, both springs) against tests/support/exact_single.c
 * to ~1e-12 (every transition, including case C's 0.2 ms sticks that integrators cannot
 * resolve), 10-block chains against CVODE Adams at rtol 1e-12, refusal of non-affine
 * problems with a clear message, and its speed next to CVODE (reported, not asserted). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "exact_single.h"
#include "linear_chain.h"
#include "recorder.h"
#include "solver/exact_backend.h"
#include "scene_spec.h"

#define PI 3.14159265358979323846

static double relative(double a, double b) { return fabs(a - b) / fmax(fabs(b), DBL_MIN); }

/* --- the back-end alone against closed forms ------------------------------------------- */

/* x'' = -w^2 x + g + d t (one pair, unit mass) with quadratures q0' = 2 x + 3 v + 1 + 0.5 t
 * and q1' = v; w = 0 makes it polynomial. */
typedef struct forced {
    double w, g, d;
} forced;

static int forced_rhs(double t, const double *y, double *ydot, void *user)
{
    const forced *f = user;
    ydot[0] = y[1];
    ydot[1] = -f->w * f->w * y[0] + f->g + f->d * t;
    ydot[2] = 2.0 * y[0] + 3.0 * y[1] + 1.0 + 0.5 * t;
    ydot[3] = y[1];
    return 0;
}

static int forced_roots(double t, const double *y, double *g, void *user)
{
    (void)t;
    (void)user;
    g[0] = y[0] - 0.25; /* position through 0.25 */
    g[1] = y[1];        /* velocity through zero */
    return 0;
}

/* Reference in long double: the Taylor series of the ODE itself (a_{n+2} from a_n) while
 * w tau < 2, else the textbook trigonometric form (whose cancellation the extra precision
 * covers there). */
static void forced_exact(const forced *f, double t0, const double *y0, double t, long double *y)
{
    long double w = f->w, w2 = w * w, tau = (long double)t - t0;
    long double x0 = y0[0], v0 = y0[1];
    long double g = (long double)f->g + (long double)f->d * t0, d = f->d; /* forcing g + d tau */
    long double x = 0, v = 0, ix = 0;
    if (w * tau < 2.0L) {
        long double a[64];
        a[0] = x0;
        a[1] = v0;
        for (int k = 0; k + 2 < 64; ++k)
            a[k + 2] = (-w2 * a[k] + (k == 0 ? g : k == 1 ? d : 0.0L)) / ((k + 1) * (k + 2));
        long double power = 1.0L; /* tau^k */
        for (int k = 0; k < 64; ++k) {
            if (k > 0)
                v += k * a[k] * power / tau;
            x += a[k] * power;
            ix += a[k] * power * tau / (k + 1);
            power *= tau;
        }
    } else {
        long double c = cosl(w * tau), s = sinl(w * tau);
        long double A = x0 - g / w2, B = (v0 - d / w2) / w; /* about the particular (g + d tau)/w^2 */
        x = g / w2 + d * tau / w2 + A * c + B * s;
        v = d / w2 - A * w * s + B * w * c;
        ix = g * tau / w2 + d * tau * tau / (2 * w2) + A * s / w + B * (1 - c) / w;
    }
    y[0] = x;
    y[1] = v;
    y[2] = y0[2] + 2 * ix + 3 * (x - x0) + tau + 0.25L * ((long double)t * t - (long double)t0 * t0);
    y[3] = y0[3] + (x - x0);
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

/* Dense output against the closed form over many decades of w tau, both sides of the
 * series/closed-form switch, for oscillating, free (w = 0) and nearly free modes; one
 * back-end restarted for each. */
static void test_forced_oscillator(void **state)
{
    (void)state;
    const forced cases[] = {{100.0, 0.37, -2.1}, {2.385, -1.5, 0.8}, {0.0, 0.37, -2.1},
                            {1e-9, 0.2, 0.1}};
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    assert_non_null(b);
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    double worst = 0.0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        forced f = cases[c];
        int direction[2] = {0, 0};
        static const double unit_mass[1] = {1.0};
        bk_ode_problem p = {.user = &f, .rhs = forced_rhs, .roots = forced_roots, .n_roots = 2,
                            .root_direction = direction, .n_pairs = 1, .pair_mass = unit_mass,
                            .affine = 1};
        const double t0 = 3.25, y0[4] = {0.1, -0.4, 0.5, -0.3};
        double atol[4] = {1e-12, 1e-12, 1e-12, 1e-12};
        double t_stop = t0 + 40.0;
        assert_int_equal(b->start(mem, &p, t0, y0, atol, 4, t_stop, &err), BK_OK);
        /* Each component's scale over the sweep; the rounding of the phase w tau alone moves
         * a value by ~eps w tau times that scale, so errors are measured in those units. */
        double scale[4] = {0, 0, 0, 0};
        for (int e = -60; e <= 50; ++e) {
            long double ref[4];
            forced_exact(&f, t0, y0, t0 + 40.0 * pow(2.0, (double)e / 10.0 - 5.0), ref);
            for (size_t k = 0; k < 4; ++k)
                scale[k] = fmax(scale[k], fabs((double)ref[k]));
        }
        for (int e = -60; e <= 50; ++e) {
            double tau = 40.0 * pow(2.0, (double)e / 10.0 - 5.0);
            double t = t0 + tau, y[4];
            assert_int_equal(b->interpolate(mem, t, y, &err), BK_OK);
            long double ref[4];
            forced_exact(&f, t0, y0, t, ref);
            for (size_t k = 0; k < 4; ++k) {
                double units = DBL_EPSILON * (1.0 + f.w * (t - t0)) * scale[k];
                double e_units = fabs(y[k] - (double)ref[k]) / units;
                if (e_units > 16.0)
                    print_error("case %zu tau %.3g component %zu: %.17g vs %.17Lg (%.3g)\n", c,
                                tau, k, y[k], ref[k], e_units);
                assert_true(e_units <= 16.0);
                worst = fmax(worst, e_units);
            }
        }
        /* Outside the segment is an error, not an extrapolation. */
        double y[4];
        assert_int_equal(b->interpolate(mem, t0 - 1e-3, y, &err), BK_ERR_SOLVER);
        assert_int_equal(b->interpolate(mem, t_stop + 1e-3, y, &err), BK_ERR_SOLVER);
    }
    print_message("forced oscillator: worst error of the dense output %.3g eps (1 + w tau) "
                  "times the component's scale\n",
                  worst);
    b->destroy(mem);
}

/* Roots: both directions, every crossing in order, located to a few doubles and reported
 * just after the crossing; counters. */
static void test_roots_in_order(void **state)
{
    (void)state;
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    forced f = {3.0, 0.0, 0.0}; /* x = cos(3 tau), v = -3 sin(3 tau) */
    int direction[2] = {0, +1};
    static const double unit_mass[1] = {1.0};
    bk_ode_problem p = {.user = &f, .rhs = forced_rhs, .roots = forced_roots, .n_roots = 2,
                        .root_direction = direction, .n_pairs = 1, .pair_mass = unit_mass,
                        .affine = 1};
    double y0[4] = {1.0, 0.0, 0.0, 0.0}, atol[4] = {1, 1, 1, 1}, y[4], t;
    double t_stop = 2.0 * PI / 3.0 * 2.9;
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 4, t_stop, &err), BK_OK);
    /* v starts at exactly zero: inactive until it moves.  Expected, per period: x = 0.25
     * falling at acos(0.25)/3, v rising through 0 at pi/3, x = 0.25 rising at
     * (2 pi - acos(0.25))/3; v's falling zero at 2 pi/3 is not listened to. */
    double a = acos(0.25) / 3.0;
    double expect[] = {a, PI / 3.0, 2.0 * PI / 3.0 - a, 2.0 * PI / 3.0 + a, PI,
                       4.0 * PI / 3.0 - a, 4.0 * PI / 3.0 + a, 5.0 * PI / 3.0, 2.0 * PI - a};
    int which[] = {0, 1, 0, 0, 1, 0, 0, 1, 0};
    int dir[] = {-1, +1, +1, -1, +1, +1, -1, +1, +1};
    size_t k = 0;
    int rc;
    while ((rc = b->step(mem, &t, y, &err)) != BK_STEP_STOP) {
        assert_true(rc == BK_STEP_OK || rc == BK_STEP_ROOT);
        if (rc != BK_STEP_ROOT)
            continue;
        assert_true(k < sizeof expect / sizeof expect[0]);
        int found[2];
        assert_int_equal(b->root_info(mem, found), BK_OK);
        assert_int_equal(found[which[k]], dir[k]);
        assert_int_equal(found[1 - which[k]], 0);
        assert_close(t, expect[k], 4.0 * DBL_EPSILON, 0.0);
        /* after the crossing: the function holds its new sign, or is zero */
        double g = which[k] == 0 ? y[0] - 0.25 : y[1];
        assert_true(g * dir[k] >= 0.0);
        double lo, hi;
        b->last_step(mem, &lo, &hi);
        assert_true(lo < t && hi == t);
        ++k;
    }
    assert_int_equal(k, sizeof expect / sizeof expect[0]);
    assert_true(t == t_stop);
    /* Stepping after the stop stays there. */
    assert_int_equal(b->step(mem, &t, y, &err), BK_STEP_STOP);
    assert_true(t == t_stop);
    bk_solver_counters c;
    b->counters(mem, &c);
    print_message("roots: %ld steps, %ld rhs probes, %ld root evaluations\n", c.steps, c.rhs_evals,
                  c.root_evals);
    /* 2.9 periods at 16 samples each, plus one short step per root */
    assert_true(c.steps >= 47 && c.steps <= 47 + 9);
    assert_int_equal(c.rhs_evals, 1 + 1 + 1 + 1 + 2); /* f0, position, time, velocity, 2 quadratures */
    assert_true(c.root_evals > c.steps);
    assert_int_equal(c.err_test_fails, 0);
    assert_int_equal(c.nonlin_iters, 0);
    b->destroy(mem);
}

/* The sampling step is a sixteenth of the shortest period, or max_step when smaller. */
static void test_sampling_step(void **state)
{
    (void)state;
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    const double max_steps[2] = {NAN, 0.05};
    const long expected[2] = {8, 20}; /* 1 s: period 2 pi / 3 = 2.09 s / 16 = 0.131 s, or 0.05 s */
    for (int k = 0; k < 2; ++k) {
        bk_solver_options o = *default_options();
        o.max_step = max_steps[k];
        void *mem = NULL;
        bk_error err = {0};
        assert_int_equal(b->create(&mem, &o, &err), BK_OK);
        forced f = {3.0, 0.0, 0.0};
        static const double unit_mass[1] = {1.0};
        bk_ode_problem p = {.user = &f, .rhs = forced_rhs, .n_pairs = 1, .pair_mass = unit_mass,
                            .affine = 1};
        double y0[4] = {1.0, 0.0, 0.0, 0.0}, atol[4] = {1, 1, 1, 1}, y[4], t = 0.0, lo, hi;
        assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 4, 1.0, &err), BK_OK);
        int rc;
        double longest = 0.0;
        while ((rc = b->step(mem, &t, y, &err)) == BK_STEP_OK) {
            b->last_step(mem, &lo, &hi);
            longest = fmax(longest, hi - lo);
        }
        assert_int_equal(rc, BK_STEP_STOP);
        bk_solver_counters c;
        b->counters(mem, &c);
        assert_int_equal(c.steps, expected[k]);
        assert_true(longest <= (k == 0 ? 2.0 * PI / 3.0 / 16.0 : 0.05) * (1.0 + 1e-12));
        b->destroy(mem);
    }
}

/* Problems the exact stepper cannot solve are refused at start with a clear message. */
static int damped_rhs(double t, const double *y, double *ydot, void *user)
{
    (void)t;
    (void)user;
    ydot[0] = y[1];
    ydot[1] = -4.0 * y[0] - 0.1 * y[1];
    return 0;
}

static int growing_rhs(double t, const double *y, double *ydot, void *user)
{
    (void)t;
    (void)user;
    ydot[0] = y[1];
    ydot[1] = -4.0 * y[0];
    ydot[2] = y[2]; /* grows with itself: no quadrature */
    return 0;
}

static void test_refuses_non_affine(void **state)
{
    (void)state;
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    forced f = {2.0, 0.0, 0.0};
    static const double masses[2] = {1.0, 1.0};
    double y0[4] = {1, 0, 0, 0}, atol[4] = {1, 1, 1, 1};

    /* What the run loop hands over for a friction law that is not constant-sliding. */
    bk_ode_problem p = {.user = &f, .rhs = forced_rhs, .n_pairs = 1, .pair_mass = masses,
                        .affine = 0};
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 4, 1.0, &err), BK_ERR_CONFIG);
    print_message("affine = 0: %s\n", err.message);
    assert_non_null(strstr(err.message, "method exact needs Coulomb friction"));
    assert_non_null(strstr(err.message, "use method = auto"));

    /* An acceleration that depends on the velocity (a dashpot) is no refusal any more: one
     * damped pair, x = e^(-t/20) (cos nu t + sin(nu t) / (20 nu)) (test_exact_damped.c has
     * the rest). */
    bk_ode_problem damped = {.rhs = damped_rhs, .n_pairs = 1, .pair_mass = masses, .affine = 1};
    assert_int_equal(b->start(mem, &damped, 0.0, y0, atol, 2, 1.0, &err), BK_OK);
    double yd[2], td;
    assert_int_equal(b->step(mem, &td, yd, &err), BK_STEP_OK);
    double nu = sqrt(4.0 - 0.0025);
    assert_close(yd[0], exp(-0.05 * td) * (cos(nu * td) + 0.05 / nu * sin(nu * td)), 1e-15, 1e-16);

    /* A trailing component whose rate depends on itself. */
    bk_ode_problem growing = {.rhs = growing_rhs, .n_pairs = 1, .pair_mass = masses, .affine = 1};
    assert_int_equal(b->start(mem, &growing, 0.0, y0, atol, 3, 1.0, &err), BK_ERR_CONFIG);
    print_message("growing: %s\n", err.message);
    assert_non_null(strstr(err.message, "quadrature"));

    /* Pairs that do not fit the state. */
    p.affine = 1;
    p.n_pairs = 2;
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 3, 1.0, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "pairs"));

    /* After a refusal the same back-end still solves a good problem. */
    p.n_pairs = 1;
    double y[4], t;
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 4, 1.0, &err), BK_OK);
    assert_int_equal(b->step(mem, &t, y, &err), BK_STEP_OK);
    assert_close(y[0], cos(2.0 * t), 1e-15, 1e-16);
    b->destroy(mem);
}

/* --- the paper's single block ------------------------------------------------------------ */

typedef struct single_errors {
    double time, position, slip_duration, slip_distance, stick_duration, energy;
    double stick_ulps; /* worst stick-duration error in units of eps t */
} single_errors;

static void compare_single(double mu_d, bk_spring spring)
{
    scene_spec spec = paper_case(mu_d, spring, 1e-10, "exact");
    exact_params p = {1.0, 1e4, 9.81, 0.6, mu_d, 1e-3, spring == BK_SPRING_TENSION_ONLY};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, spec.t_end, &ex), 0);
    bk_config *c = scene_config(&spec);
    recorder r = {0};
    bk_run_stats stats;
    bk_error err = {0};
    assert_int_equal(run_recorded(c, &r, &stats, &err), BK_OK);
    assert_int_equal(r.n_transitions, ex.n_events);
    assert_false(r.time_decreased);
    single_errors e = {0};
    for (size_t k = 0; k < ex.n_events; ++k) {
        const bk_transition *tr = &r.transitions[k];
        const exact_event *ev = &ex.events[k];
        assert_int_equal(tr->from, ev->from);
        assert_int_equal(tr->to, ev->to);
        e.time = fmax(e.time, relative(tr->t, ev->t));
        e.position = fmax(e.position, relative(tr->x, ev->x));
        if (k + 1 == ex.n_events)
            continue;
        double duration = r.transitions[k + 1].t - tr->t, exact_duration = ex.events[k + 1].t - ev->t;
        if (ev->to == BK_MODE_STICK) {
            /* Case C's sticks last 0.2 ms: 1e-12 of that is below the spacing of doubles
             * near t = 1..5 s (eps t = 2e-16..1.1e-15 s), so the duration of a stick that ends
             * at t is held to 1e-12 relative or 2 eps t, whichever is larger. */
            double error = fabs(duration - exact_duration);
            double t_end_stick = ex.events[k + 1].t;
            e.stick_duration = fmax(e.stick_duration, relative(duration, exact_duration));
            e.stick_ulps = fmax(e.stick_ulps, error / (DBL_EPSILON * t_end_stick));
            assert_true(error <= fmax(1e-12 * exact_duration, 2.0 * DBL_EPSILON * t_end_stick));
        } else {
            e.slip_duration = fmax(e.slip_duration, relative(duration, exact_duration));
            e.slip_distance = fmax(e.slip_distance, relative(r.transitions[k + 1].x - tr->x,
                                                             ex.events[k + 1].x - ev->x));
        }
    }
    e.energy = fabs(stats.energy_residual);
    print_message("mu_d %-6g %-12s %3zu transitions: worst relative error of times %.2g, "
                  "positions %.2g, slip durations %.2g, slip distances %.2g, stick durations "
                  "%.2g (%.2g eps t); energy residual %.2g\n",
                  mu_d, spring == BK_SPRING_LINEAR ? "linear" : "tension-only", ex.n_events,
                  e.time, e.position, e.slip_duration, e.slip_distance, e.stick_duration,
                  e.stick_ulps, e.energy);
    assert_true(e.time <= 1e-12);
    assert_true(e.position <= 1e-12);
    assert_true(e.slip_duration <= 1e-12);
    assert_true(e.slip_distance <= 1e-12);
    assert_true(e.energy <= 1e-12);
    recorder_free(&r);
    bk_config_free(c);
    exact_free(&ex);
}

static void test_case_a_linear(void **state)
{
    (void)state;
    compare_single(0.1, BK_SPRING_LINEAR);
}
static void test_case_b_linear(void **state)
{
    (void)state;
    compare_single(0.5, BK_SPRING_LINEAR);
}
static void test_case_c_linear(void **state)
{
    (void)state;
    compare_single(0.5999, BK_SPRING_LINEAR);
}
static void test_case_a_tension_only(void **state)
{
    (void)state;
    compare_single(0.1, BK_SPRING_TENSION_ONLY);
}
static void test_case_b_tension_only(void **state)
{
    (void)state;
    compare_single(0.5, BK_SPRING_TENSION_ONLY);
}
static void test_case_c_tension_only(void **state)
{
    (void)state;
    compare_single(0.5999, BK_SPRING_TENSION_ONLY);
}

/* Identical twins: each breakaway and each stop is one event for both blocks. */
static void test_simultaneous_transitions(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, 1e-10, "exact");
    spec.n = 2;
    spec.coupling = 3e3;
    bk_config *c = scene_config(&spec);
    recorder r = {0};
    bk_error err = {0};
    assert_int_equal(run_recorded(c, &r, NULL, &err), BK_OK);
    assert_int_equal(r.n_transitions, 20);
    for (size_t k = 0; k + 1 < r.n_transitions; k += 2) {
        assert_true(r.transitions[k].t == r.transitions[k + 1].t);
        assert_int_equal(r.transitions[k].block, 0);
        assert_int_equal(r.transitions[k + 1].block, 1);
        assert_int_equal(r.transitions[k].to, r.transitions[k + 1].to);
    }
    recorder_free(&r);
    bk_config_free(c);
}

/* A block launched at 0.5 m/s with the driver at rest swings back past its threshold: the
 * stop (slip rate s v, not from rest) is a reversal slip+ -> slip- at
 * t = atan(v0 w m / f_k) / w exactly. */
static void test_reversal(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.05, BK_SPRING_LINEAR, 1e-10, "exact");
    spec.velocity = 0.0;
    spec.t_end = 0.2;
    bk_config *c = scene_config(&spec);
    c->model->blocks[0].v_init = 0.5;
    recorder r = {0};
    bk_run_stats stats;
    bk_error err = {0};
    assert_int_equal(run_recorded(c, &r, &stats, &err), BK_OK);
    assert_true(r.n_transitions >= 2);
    assert_int_equal(r.transitions[0].from, BK_MODE_SLIP_POS);
    assert_int_equal(r.transitions[0].to, BK_MODE_SLIP_NEG);
    double w = 100.0, fk = 0.05 * 9.81;
    double t_stop = atan(0.5 * w / fk) / w;
    double x_stop = -fk / (w * w) * (1.0 - cos(w * t_stop)) + 0.5 / w * sin(w * t_stop);
    print_message("reversal at %.17g s (exact %.17g), x %.17g m (exact %.17g), energy residual %.2g\n",
                  r.transitions[0].t, t_stop, r.transitions[0].x, x_stop, stats.energy_residual);
    assert_close(r.transitions[0].t, t_stop, 4.0 * DBL_EPSILON, 0.0);
    assert_close(r.transitions[0].x, x_stop, 1e-14, 0.0);
    assert_true(fabs(stats.energy_residual) <= 1e-13);
    recorder_free(&r);
    bk_config_free(c);
}

/* No driver springs: the pair slides on its coupling alone, with a free (w = 0) mode next to
 * an oscillating one, until both stop; CVODE at rtol 1e-12 agrees. */
static void test_free_mode(void **state)
{
    (void)state;
    recorder r[2] = {{0}, {0}};
    bk_run_stats stats[2];
    const char *methods[2] = {"exact", "cvode_adams"};
    for (int k = 0; k < 2; ++k) {
        scene_spec spec = paper_case(0.3, BK_SPRING_LINEAR, 1e-10, methods[k]);
        spec.n = 2;
        spec.stiffness = 0.0;
        spec.coupling = 2e4;
        spec.velocity = 0.0;
        spec.t_end = 0.5;
        spec.rtol = 1e-12;
        bk_config *c = scene_config(&spec);
        c->model->blocks[0].v_init = 0.4;
        c->model->blocks[1].v_init = 0.1;
        bk_error err = {0};
        assert_int_equal(run_recorded(c, &r[k], &stats[k], &err), BK_OK);
        bk_config_free(c);
    }
    assert_true(r[0].n_transitions >= 2);
    assert_int_equal(r[0].n_transitions, r[1].n_transitions);
    double worst = 0.0;
    for (size_t k = 0; k < r[0].n_transitions; ++k) {
        assert_int_equal(r[0].transitions[k].block, r[1].transitions[k].block);
        assert_int_equal(r[0].transitions[k].to, r[1].transitions[k].to);
        worst = fmax(worst, relative(r[0].transitions[k].t, r[1].transitions[k].t));
    }
    print_message("free mode: %zu transitions, times agree with CVODE to %.2g; energy residual %.2g\n",
                  r[0].n_transitions, worst, stats[0].energy_residual);
    assert_true(worst <= 1e-8);
    assert_true(fabs(stats[0].energy_residual) <= 1e-12);
    recorder_free(&r[0]);
    recorder_free(&r[1]);
}

/* --- chains against CVODE ---------------------------------------------------------------- */

/* Kinetic coefficients 0.45..0.49 along the chain; with tension-only springs 0.10..0.30,
 * so that slipping blocks overtake the driver and their springs go slack. */
static bk_config *chain_config(bk_spring spring, bk_boundary boundary, const char *method,
                               double rtol, double t_end)
{
    scene_spec spec = paper_case(0.5, spring, 1e-10, method);
    spec.n = 10;
    spec.coupling = 2e4;
    spec.boundary = boundary;
    spec.rtol = rtol;
    spec.t_end = t_end;
    bk_config *c = scene_config(&spec);
    for (size_t i = 0; i < spec.n; ++i) {
        c->model->blocks[i].x_init = 1e-5 * sin(2.385 * (double)i);
        c->model->blocks[i].friction_params[1] = spring == BK_SPRING_LINEAR
                                                      ? 0.45 + 0.01 * (double)(i % 5)
                                                      : 0.10 + 0.05 * (double)(i % 5);
    }
    return c;
}

#define CHAIN_COMPARED 50

static void test_chains_against_cvode(void **state)
{
    (void)state;
    const bk_spring springs[] = {BK_SPRING_LINEAR, BK_SPRING_TENSION_ONLY};
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED, BK_BOUNDARY_PERIODIC};
    const char *boundary_names[] = {"free", "fixed", "periodic"};
    for (size_t s = 0; s < 2; ++s)
        for (size_t b = 0; b < 3; ++b) {
            /* the slower tension-only chains need longer for as many transitions */
            double t_end = springs[s] == BK_SPRING_LINEAR ? 1.0 : 2.0;
            bk_config *ce = chain_config(springs[s], boundaries[b], "exact", 1e-10, t_end);
            bk_config *cc = chain_config(springs[s], boundaries[b], "cvode_adams", 1e-12, t_end);
            recorder re = {0}, rc = {0};
            bk_run_stats se, sc;
            bk_error err = {0};
            assert_int_equal(run_recorded(ce, &re, &se, &err), BK_OK);
            assert_int_equal(run_recorded(cc, &rc, &sc, &err), BK_OK);
            assert_true(re.n_transitions >= CHAIN_COMPARED);
            assert_true(rc.n_transitions >= CHAIN_COMPARED);
            double worst = 0.0;
            for (size_t k = 0; k < CHAIN_COMPARED; ++k) {
                const bk_transition *a = &re.transitions[k], *c = &rc.transitions[k];
                assert_int_equal(a->block, c->block);
                assert_int_equal(a->from, c->from);
                assert_int_equal(a->to, c->to);
                worst = fmax(worst, relative(a->t, c->t));
            }
            print_message("10 blocks, %s spring, %s ends: %zu / %zu transitions (exact / CVODE), "
                          "%ld restarts, first %d agree, times to %.2g relative; energy residual "
                          "exact %.2g, CVODE %.2g\n",
                          springs[s] == BK_SPRING_LINEAR ? "linear" : "tension-only",
                          boundary_names[b], re.n_transitions, rc.n_transitions,
                          se.integrator_starts, CHAIN_COMPARED, worst, se.energy_residual,
                          sc.energy_residual);
            assert_true(worst <= 1e-7);
            assert_true(fabs(se.energy_residual) <= 1e-11);
            assert_true(re.max_balance_error <= 1e-11 * re.max_work);
            assert_false(re.time_decreased);
            recorder_free(&re);
            recorder_free(&rc);
            bk_config_free(ce);
            bk_config_free(cc);
        }
}

/* A 64-block chain with scattered initial offsets (as the 1000-block config): many short
 * slipping stretches at once, each an independent cluster of the exact stepper, with blocks
 * joining and leaving them, and with periodic ends a stretch across the wrap.  Every
 * transition must match CVODE Adams at rtol 1e-10 (a cluster split that dropped or invented
 * a coupling would change the motion). */
static bk_config *long_chain_config(bk_boundary boundary, const char *method, double rtol)
{
    scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, 1e-10, method);
    spec.n = 64;
    spec.coupling = 2e4;
    spec.boundary = boundary;
    spec.rtol = rtol;
    spec.t_end = 0.6;
    spec.interval = 1e-2;
    bk_config *c = scene_config(&spec);
    unsigned long state = 2385;
    for (size_t i = 0; i < spec.n; ++i) {
        state = (state * 6364136223846793005ul + 1442695040888963407ul) & 0xfffffffffffffffful;
        double uniform = (double)(state >> 11) / 9007199254740992.0; /* [0, 1) */
        c->model->blocks[i].x_init = 6e-5 * (2.0 * uniform - 1.0);
    }
    /* The most loaded blocks at the ends: with periodic ends the first slip straddles the
     * wrap. */
    c->model->blocks[0].x_init = c->model->blocks[spec.n - 1].x_init = -6e-5;
    return c;
}

static void test_long_chain_clusters(void **state)
{
    (void)state;
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_PERIODIC};
    for (size_t b = 0; b < 2; ++b) {
        bk_config *ce = long_chain_config(boundaries[b], "exact", 1e-10);
        bk_config *cc = long_chain_config(boundaries[b], "cvode_adams", 1e-10);
        recorder re = {0}, rc = {0};
        bk_run_stats se, sc;
        bk_error err = {0};
        assert_int_equal(run_recorded(ce, &re, &se, &err), BK_OK);
        assert_int_equal(run_recorded(cc, &rc, &sc, &err), BK_OK);
        assert_true(re.n_transitions >= 100);
        assert_int_equal(re.n_transitions, rc.n_transitions);
        double worst = 0.0;
        for (size_t k = 0; k < re.n_transitions; ++k) {
            const bk_transition *a = &re.transitions[k], *c = &rc.transitions[k];
            assert_int_equal(a->block, c->block);
            assert_int_equal(a->from, c->from);
            assert_int_equal(a->to, c->to);
            worst = fmax(worst, fabs(a->t - c->t));
        }
        print_message("64 blocks, %s ends: %zu transitions, times agree with CVODE to %.2g s; CPU "
                      "exact %.3g s, CVODE %.3g s; energy residual %.2g\n",
                      b == 0 ? "free" : "periodic", re.n_transitions, worst, se.cpu_time,
                      sc.cpu_time, se.energy_residual);
        assert_true(worst <= 1e-8);
        assert_true(fabs(se.energy_residual) <= 1e-11);
        recorder_free(&re);
        recorder_free(&rc);
        bk_config_free(ce);
        bk_config_free(cc);
    }
}

/* A uniform chain started relaxed slides as one block (its couplings never stretch), so
 * symmetric inputs must give symmetric outputs: every instant holds a transition of every
 * block, at the single block's closed-form times (the same dynamics: coupling plays no
 * part), on free and periodic chains of several lengths, as the integrators give too. */
static void test_uniform_chain_slides_as_one(void **state)
{
    (void)state;
    const size_t lengths[] = {2, 5, 16, 33};
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_PERIODIC};
    exact_params p = {1.0, 1e4, 9.81, 0.6, 0.5, 1e-3, 0};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, 3.0, &ex), 0);
    for (size_t b = 0; b < 2; ++b)
        for (size_t l = 0; l < sizeof lengths / sizeof *lengths; ++l) {
            scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, 1e-10, "exact");
            spec.n = lengths[l];
            spec.coupling = 2e4;
            spec.boundary = boundaries[b];
            spec.t_end = 3.0;
            recorder r = {0};
            bk_error err = {0};
            if (run_spec(&spec, &r, NULL, &err) != BK_OK)
                fail_msg("%s", err.message);
            assert_int_equal(r.n_transitions, spec.n * ex.n_events);
            double worst = 0.0;
            for (size_t e = 0; e < ex.n_events; ++e)
                for (size_t i = 0; i < spec.n; ++i) {
                    const bk_transition *t = &r.transitions[e * spec.n + i];
                    assert_int_equal(t->block, (int32_t)i); /* one instant, in block order */
                    assert_int_equal(t->to, ex.events[e].to);
                    assert_true(t->t == r.transitions[e * spec.n].t && t->x == r.transitions[e * spec.n].x);
                    worst = fmax(worst, relative(t->t, ex.events[e].t));
                }
            assert_true(worst <= 1e-13);
            recorder_free(&r);
        }
    exact_free(&ex);
}

/* Output rows of a long non-uniform cluster come from the Taylor series about the last step
 * end (exact_rows.c), O(size) instead of the modal sum's O(size^2): they must be the closed
 * form's to rounding, at every point of a step, positions, velocities and quadratures, and
 * a row far from the last step falls back to the modal sum.  Measured: 34 eps at worst (the
 * modal sum over 200 modes rounds as much); a series cut at 9 terms misses by 3e4 eps. */
static void test_rows_from_series(void **state)
{
    (void)state;
    const size_t p = 200, n = 2 * p + 2;
    linear_chain *lc = linear_chain_new(p, 11u);
    assert_non_null(lc);
    bk_ode_problem problem = linear_chain_problem(lc);
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, default_options(), &err), BK_OK);
    double *y0 = malloc(n * sizeof *y0), *atol = malloc(n * sizeof *atol);
    double *y = malloc(n * sizeof *y), *ref = malloc(n * sizeof *ref), *scale = calloc(n, sizeof *scale);
    assert_true(y0 && atol && y && ref && scale);
    linear_chain_start(lc, y0);
    for (size_t k = 0; k < n; ++k)
        atol[k] = 1e-12;
    const double t0 = 2.0;
    assert_int_equal(b->start(mem, &problem, t0, y0, atol, n, t0 + 10.0, &err), BK_OK);
    const exact_backend *eb = mem;
    assert_int_equal(eb->n_clusters, 1);
    assert_int_equal(eb->n_series, 1); /* the rows below do take the series */
    double worst = 0.0;
    for (int s = 0; s < 40; ++s) {
        double t_reached, t_lo, t_hi;
        assert_int_equal(b->step(mem, &t_reached, y, &err), BK_STEP_OK);
        /* Scales: all positions, all velocities (the modal sum's own rounding is ~eps of
         * the cluster's largest, not of each component), each quadrature. */
        for (size_t k = 0; k < n; ++k)
            scale[k < 2 * p ? k % 2 : k] = fmax(scale[k < 2 * p ? k % 2 : k], fabs(y[k]));
        b->last_step(mem, &t_lo, &t_hi);
        for (int j = 0; j <= 8; ++j) {
            double t = t_lo + (t_hi - t_lo) * (double)j / 8.0;
            assert_int_equal(b->sample(mem, t, y, &err), BK_OK);
            assert_int_equal(b->interpolate(mem, t, ref, &err), BK_OK);
            for (size_t k = 0; k < n; ++k) {
                double units = fabs(y[k] - ref[k]) / (DBL_EPSILON * scale[k < 2 * p ? k % 2 : k]);
                if (units > 64.0)
                    print_error("step %d, row %d/8, component %zu: %.17g vs %.17g (%.3g eps)\n", s,
                                j, k, y[k], ref[k], units);
                assert_true(units <= 64.0);
                worst = fmax(worst, units);
            }
        }
    }
    /* Far from the last step: the modal sum, the same numbers as interpolate's. */
    assert_int_equal(b->sample(mem, t0 + 1e-3, y, &err), BK_OK);
    assert_int_equal(b->interpolate(mem, t0 + 1e-3, ref, &err), BK_OK);
    assert_memory_equal(y, ref, n * sizeof *y);
    print_message("rows of a %zu-pair cluster from the series: worst %.3g eps of the component's "
                  "scale against the modal sum\n", p, worst);
    b->destroy(mem);
    free(y0);
    free(atol);
    free(y);
    free(ref);
    free(scale);
    linear_chain_free(lc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_forced_oscillator),
        cmocka_unit_test(test_roots_in_order),
        cmocka_unit_test(test_sampling_step),
        cmocka_unit_test(test_refuses_non_affine),
        cmocka_unit_test(test_case_a_linear),
        cmocka_unit_test(test_case_b_linear),
        cmocka_unit_test(test_case_c_linear),
        cmocka_unit_test(test_case_a_tension_only),
        cmocka_unit_test(test_case_b_tension_only),
        cmocka_unit_test(test_case_c_tension_only),
        cmocka_unit_test(test_simultaneous_transitions),
        cmocka_unit_test(test_reversal),
        cmocka_unit_test(test_free_mode),
        cmocka_unit_test(test_chains_against_cvode),
        cmocka_unit_test(test_long_chain_clusters),
        cmocka_unit_test(test_uniform_chain_slides_as_one),
        cmocka_unit_test(test_rows_from_series),
    };
    return cmocka_run_group_tests_name("exact", tests, NULL, NULL);
}
