/* Friction laws: one battery over every registered law (parameter tables, finiteness at the
 * limits, exact state evolution against the integrated state equation), then each law's
 * own values and limits, the paper law's steady state and degenerate printed form, the
 * Dieterich-Ruina laws' exact derivatives against difference quotients, each state law's
 * relaxation time against its own state decay, and the Rice-Ruina stability boundary of a
 * block under Dieterich-Ruina friction. */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"

/* Parameters for each law: its defaults, with the required ones filled. */
static void law_params(const bk_friction_law *law, double *p)
{
    for (size_t i = 0; i < law->n_params; ++i)
        p[i] = law->params[i].default_value;
    struct {
        const char *key;
        double value;
    } fill[] = {{"mu_s", 0.6}, {"mu_d", 0.5}, {"F0", 5.886}, {"sigma", 0.2}, {"alpha", 3.0},
                {"a", 0.01}, {"b", 0.015}, {"Dc", 1e-5}, {"V0", 1e-6}, {"f0", 0.6}};
    for (size_t k = 0; k < sizeof fill / sizeof fill[0]; ++k) {
        int i = bk_friction_param_index(law, fill[k].key);
        if (i >= 0 && isnan(p[i]))
            p[i] = fill[k].value;
    }
    if (law->complete) {
        bk_friction_context ctx = {1e-3, 9.81};
        law->complete(p, &ctx);
    }
}

/* Every law: documented parameters with units, finite forces at extreme rates and states. */
static void test_battery(void **state)
{
    (void)state;
    size_t count = 0;
    for (const bk_friction_law *const *l = bk_friction_laws(); *l; ++l, ++count) {
        const bk_friction_law *law = *l;
        assert_ptr_equal(bk_friction_law_find(law->name), law);
        assert_true(law->n_params <= BK_FRICTION_MAX_PARAMS && law->n_state <= BK_FRICTION_MAX_STATE);
        assert_non_null(law->doc);
        for (size_t i = 0; i < law->n_params; ++i) {
            assert_non_null(law->params[i].unit);
            assert_non_null(law->params[i].doc);
        }
        /* Stateful laws bring the whole state machinery. */
        assert_int_equal(law->n_state > 0, law->state_rate != NULL);
        assert_int_equal(law->n_state > 0, law->state_init != NULL);
        assert_int_equal(law->n_state > 0, law->state_advance != NULL);
        assert_int_equal((law->flags & BK_FRICTION_STATIC_THRESHOLD) != 0, law->static_threshold != NULL);
        double p[BK_FRICTION_MAX_PARAMS];
        law_params(law, p);
        char msg[256];
        assert_int_equal(law->validate ? law->validate(p, msg, sizeof msg) : -1, -1);
        double st[BK_FRICTION_MAX_STATE] = {0};
        if (law->n_state)
            law->state_init(p, st);
        const double rates[] = {-1e-6, 0.0, 1e-12, 1e-3, 1.0, 1e3};
        const double thetas[] = {1e-300, 1e-9, 2e-2, 1e6, 1e300};
        for (size_t r = 0; r < 6; ++r)
            for (size_t s = 0; s < (law->n_state ? 5u : 1u); ++s) {
                if (law->n_state)
                    st[0] = thetas[s];
                double f = law->sliding_force(p, 9.81, rates[r], st);
                if (!isfinite(f))
                    print_error("%s: force %g at rate %g, state %g\n", law->name, f, rates[r], st[0]);
                assert_true(isfinite(f));
                if (law->static_threshold)
                    assert_true(isfinite(law->static_threshold(p, 9.81, st)) &&
                                law->static_threshold(p, 9.81, st) >= 0.0);
            }
        /* Laws that never stick are odd and smooth through v = 0. */
        if (!(law->flags & BK_FRICTION_STATIC_THRESHOLD)) {
            if (law->n_state)
                law->state_init(p, st);
            assert_close(law->sliding_force(p, 9.81, -2.385e-4, st), -law->sliding_force(p, 9.81, 2.385e-4, st),
                         1e-14, 0);
            assert_close(law->sliding_force(p, 9.81, 0.0, st), 0.0, 0, 0);
        }
    }
    assert_int_equal(count, 5);
}

/* --- exact state evolution against the integrated state equation ---------------------- */

typedef struct state_problem {
    const bk_friction_law *law;
    const double *p;
    double speed;
} state_problem;

static int state_rhs(double t, const double *y, double *ydot, void *user)
{
    (void)t;
    const state_problem *sp = user;
    sp->law->state_rate(sp->p, sp->speed, y, ydot);
    return 0;
}

/* Integrate theta' at constant rate with CVODE (rtol 1e-13) and compare with the law's
 * closed form (eq. 5 for the paper's law) to 1e-10 relative. */
static void check_state_evolution(const bk_friction_law *law, double speed, double theta0, double span)
{
    double p[BK_FRICTION_MAX_PARAMS];
    law_params(law, p);
    state_problem sp = {law, p, speed};
    const bk_solver_backend *b = bk_solver_backend_find("cvode_adams");
    bk_solver_options o;
    memset(&o, 0, sizeof o);
    o.rtol = 1e-13;
    snprintf(o.linear_solver, sizeof o.linear_solver, "dense");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, &o, &err), BK_OK);
    bk_ode_problem prob = {.user = &sp, .rhs = state_rhs, .half_bandwidth = 1};
    double y0[1] = {theta0}, atol[1] = {1e-20}, y[1];
    assert_int_equal(b->start(mem, &prob, 0.0, y0, atol, 1, span, &err), BK_OK);
    double t = 0.0;
    int rc;
    while ((rc = b->step(mem, &t, y, &err)) == BK_STEP_OK) {
        double exact[1] = {theta0};
        law->state_advance(p, speed, t, exact);
        assert_close(y[0], exact[0], 1e-10, 0.0);
    }
    assert_int_equal(rc, BK_STEP_STOP);
    double exact[1] = {theta0};
    law->state_advance(p, speed, span, exact);
    assert_close(y[0], exact[0], 1e-10, 0.0);
    b->destroy(mem);
}

static void test_state_evolution_exact(void **state)
{
    (void)state;
    for (const bk_friction_law *const *l = bk_friction_laws(); *l; ++l) {
        if ((*l)->n_state == 0)
            continue;
        const double speeds[] = {0.0, 1e-3, 1e-2};
        for (size_t k = 0; k < 3; ++k) {
            check_state_evolution(*l, speeds[k], 2e-2, 0.05); /* from far above steady state */
            check_state_evolution(*l, speeds[k], 1e-4, 0.05); /* from below */
        }
    }
}

/* --- the paper's law ------------------------------------------------------------------- */

static void test_rate_state_steady_state(void **state)
{
    (void)state;
    const bk_friction_law *law = &bk_friction_rate_state;
    double p[BK_FRICTION_MAX_PARAMS];
    law_params(law, p);
    const double rates[] = {1e-6, 1e-3, 2.385e-3, 1e-2, 0.1};
    for (size_t k = 0; k < 5; ++k) {
        double v = rates[k];
        double theta[1] = {2e-5 / v}; /* steady state L0 / v */
        double mu = law->sliding_force(p, 1.0, v, theta);
        double expected = 0.5 + (0.6 - 0.5) * exp(-pow(v / 1e-3, 1.2));
        assert_close(mu, expected, 1e-13, 0);
    }
    /* The numbers NOTES.md quotes. */
    double theta_1mm[1] = {2e-2}, theta_10mm[1] = {2e-3};
    assert_close(law->sliding_force(p, 1.0, 1e-3, theta_1mm), 0.5368, 0, 5e-5);
    assert_close(law->sliding_force(p, 1.0, 1e-2, theta_10mm), 0.5000, 0, 5e-5);
    /* Figure 2's spike and dip: the rate jumps, the state does not. */
    assert_close(law->sliding_force(p, 1.0, 1e-2, theta_1mm), 0.587, 0, 5e-4);
    assert_close(law->sliding_force(p, 1.0, 1e-3, theta_10mm), 0.457, 0, 5e-4);
}

/* The printed form (v_theta_ref = v1) leaves no friction: mu ~ 1e-302 at 1 mm/s. */
static void test_rate_state_printed_form_degenerate(void **state)
{
    (void)state;
    const bk_friction_law *law = &bk_friction_rate_state;
    double p[BK_FRICTION_MAX_PARAMS];
    law_params(law, p);
    p[bk_friction_param_index(law, "v_theta_ref")] = p[bk_friction_param_index(law, "v1")];
    double theta[1] = {2e-2};
    double mu = law->sliding_force(p, 1.0, 1e-3, theta);
    assert_true(mu > 0.0 && mu < 1e-290);
    assert_true(law->static_threshold(p, 1.0, theta) < 1e-290);
}

static void test_rate_state_limits(void **state)
{
    (void)state;
    const bk_friction_law *law = &bk_friction_rate_state;
    double p[BK_FRICTION_MAX_PARAMS];
    law_params(law, p);
    double aged[1] = {1e12}, fresh[1] = {1e-15};
    /* theta -> inf: the threshold tends to mu_s N; theta -> 0: to 0. */
    assert_close(law->static_threshold(p, 9.81, aged), 0.6 * 9.81, 1e-12, 0);
    assert_true(law->static_threshold(p, 9.81, fresh) < 1e-100);
    /* v -> 0 is continuous with the threshold; v -> inf grows as (v/v0 + 1)^(1/m). */
    double theta[1] = {2e-2};
    assert_close(law->sliding_force(p, 9.81, 1e-15, theta), law->static_threshold(p, 9.81, theta), 1e-12, 0);
    assert_true(law->sliding_force(p, 9.81, 1.0, theta) > law->sliding_force(p, 9.81, 0.1, theta));
    /* theta' = B while stuck, B (1 - v theta / L0) while slipping. */
    double rate[1];
    law->state_rate(p, 0.0, theta, rate);
    assert_close(rate[0], 4.6, 1e-15, 0);
    law->state_rate(p, 1e-3, theta, rate);
    assert_close(rate[0], 0.0, 0, 1e-15);
    /* The default initial state is the steady state at the driver speed. */
    double init[1];
    law->state_init(p, init);
    assert_close(init[0], 2e-5 / 1e-3, 1e-15, 0);
}

/* --- Carlson-Langer -------------------------------------------------------------------- */

static void test_carlson_langer(void **state)
{
    (void)state;
    const bk_friction_law *law = &bk_friction_carlson_langer;
    double p[BK_FRICTION_MAX_PARAMS];
    law_params(law, p);
    /* A static peak F0, a drop to F0 (1 - sigma) at the onset, weakening with speed. */
    assert_close(law->static_threshold(p, 9.81, NULL), 5.886, 0, 0);
    assert_close(law->sliding_force(p, 9.81, 0.0, NULL), 5.886 * 0.8, 1e-15, 0);
    double v = 0.2385;
    assert_close(law->sliding_force(p, 9.81, v, NULL), 5.886 * 0.8 / (1 + 2 * 3.0 * v / 0.8), 1e-15, 0);
    assert_true(law->sliding_force(p, 9.81, 1e9, NULL) < 1e-8);
    assert_int_equal(law->n_state, 0);
}

/* --- Dieterich-Ruina ------------------------------------------------------------------- */

static void test_dieterich_ruina(void **state)
{
    (void)state;
    const bk_friction_law *laws[] = {&bk_friction_dieterich_ruina_aging, &bk_friction_dieterich_ruina_slip};
    for (size_t k = 0; k < 2; ++k) {
        const bk_friction_law *law = laws[k];
        double p[BK_FRICTION_MAX_PARAMS];
        law_params(law, p);
        /* Steady state at v >> V0: f0 + (a - b) ln(v / V0). */
        const double rates[] = {1e-4, 1e-2, 10.0};
        for (size_t r = 0; r < 3; ++r) {
            double v = rates[r];
            double theta[1] = {1e-5 / v};
            double mu = law->sliding_force(p, 1.0, v, theta);
            assert_close(mu, 0.6 + (0.01 - 0.015) * log(v / 1e-6), 1e-12, 1e-12);
        }
        /* Direct effect: an instant rate step by e changes mu by a. */
        double theta[1] = {10.0};
        double jump = law->sliding_force(p, 1.0, 1e-4 * exp(1.0), theta) - law->sliding_force(p, 1.0, 1e-4, theta);
        assert_close(jump, 0.01, 1e-9, 0);
        /* Steady state of the state laws: theta' = 0 at theta = Dc / v. */
        double rate[1], steady[1] = {1e-5 / 2.385e-3};
        law->state_rate(p, 2.385e-3, steady, rate);
        assert_close(rate[0], 0.0, 0, 1e-12);
        assert_null(law->static_threshold);
    }
    /* Aging heals during a hold, slip does not. */
    double p[BK_FRICTION_MAX_PARAMS], rate[1], theta[1] = {0.1};
    law_params(&bk_friction_dieterich_ruina_aging, p);
    bk_friction_dieterich_ruina_aging.state_rate(p, 0.0, theta, rate);
    assert_close(rate[0], 1.0, 0, 0);
    bk_friction_dieterich_ruina_slip.state_rate(p, 0.0, theta, rate);
    assert_close(rate[0], 0.0, 0, 0);
}

/* --- Dieterich-Ruina: exact derivatives of the sliding force ---------------------------- */

/* a = 0.01, b = 0.015, Dc = 1e-5, f0 = 0.6, the given V0; theta_init = Dc / 1e-3. */
static void dr_params(const bk_friction_law *law, double V0, double *p)
{
    law_params(law, p);
    p[bk_friction_param_index(law, "V0")] = V0;
}

/* ln z = ln(|v| / (2 V0)) + (f0 + b ln(V0 theta / Dc)) / a, formed as the law forms it, so
 * that the test knows which branch each point takes. */
static double dr_log_scale(const bk_friction_law *law, const double *p, double theta)
{
    double a = p[bk_friction_param_index(law, "a")], b = p[bk_friction_param_index(law, "b")];
    double Dc = p[bk_friction_param_index(law, "Dc")], V0 = p[bk_friction_param_index(law, "V0")];
    double f0 = p[bk_friction_param_index(law, "f0")];
    return (f0 + b * log(V0 * theta / Dc)) / a;
}

static double dr_log_z(const bk_friction_law *law, const double *p, double v, double theta)
{
    double V0 = p[bk_friction_param_index(law, "V0")];
    return log(fabs(v) / (2.0 * V0)) + dr_log_scale(law, p, theta);
}

/* The sliding force as a function of the slip rate (vary_state 0) or of the state (1). */
typedef struct force_slice {
    const bk_friction_law *law;
    const double *p;
    double normal_force, slip_rate, theta;
    int vary_state;
} force_slice;

static double slice_at(const force_slice *s, double x)
{
    double st[1] = {s->vary_state ? x : s->theta};
    return s->law->sliding_force(s->p, s->normal_force, s->vary_state ? s->slip_rate : x, st);
}

/* Central differences at h, h/2, h/4, Richardson-extrapolated twice: error O(h^6). */
static double richardson(const force_slice *s, double x, double h)
{
    double d[3];
    for (int k = 0; k < 3; ++k, h *= 0.5)
        d[k] = (slice_at(s, x + h) - slice_at(s, x - h)) / (2.0 * h);
    double r0 = (4.0 * d[1] - d[0]) / 3.0, r1 = (4.0 * d[2] - d[1]) / 3.0;
    return (16.0 * r1 - r0) / 15.0;
}

static double relative_error(double a, double b) { return fabs(a - b) / fabs(b); }

/* dF/dv and dF/dtheta against extrapolated difference quotients of sliding_force, for both
 * state laws, two reference velocities, states Dc/V from 1e-6 to 1e6 s and slip rates from
 * 1e-45 to 10 m/s of either sign: all three branches (ln z < -20, between, > 20) agree to
 * 1e-7 relative.  A wrong factor, sign or branch would miss by far more. */
static void test_dieterich_ruina_derivatives(void **state)
{
    (void)state;
    const bk_friction_law *laws[] = {&bk_friction_dieterich_ruina_aging, &bk_friction_dieterich_ruina_slip};
    const double V0s[] = {1e-5, 1e-3}, N = 5e6, delta = 0.05, tol = 1e-7;
    double worst_rate = 0.0, worst_state = 0.0;
    size_t branch_hits[3] = {0, 0, 0}, points = 0;
    for (size_t k = 0; k < 2; ++k) {
        const bk_friction_law *law = laws[k];
        assert_non_null(law->sliding_force_derivatives);
        for (size_t iv = 0; iv < 2; ++iv) {
            double p[BK_FRICTION_MAX_PARAMS];
            dr_params(law, V0s[iv], p);
            for (int te = -12; te <= 12; ++te) { /* theta = 1e-6 ... 1e6 s, half decades */
                double theta = pow(10.0, 0.5 * te);
                for (int re = -90; re <= 2; ++re) { /* |v| = 1e-45 ... 10 m/s, half decades */
                    if (re < -60 && re % 10 != 0)
                        continue; /* below 1e-30 m/s, every 5 decades */
                    for (int sign = -1; sign <= 1; sign += 2) {
                        double v = sign * pow(10.0, 0.5 * re), st[1] = {theta}, d_rate, d_state;
                        law->sliding_force_derivatives(p, N, v, st, &d_rate, &d_state);
                        double log_z = dr_log_z(law, p, v, theta);
                        branch_hits[log_z < -20.0 ? 0 : log_z > 20.0 ? 2 : 1]++;
                        force_slice by_rate = {law, p, N, v, theta, 0}, by_state = {law, p, N, v, theta, 1};
                        double q_rate = richardson(&by_rate, v, delta * fabs(v));
                        double q_state = richardson(&by_state, theta, delta * theta);
                        double e_rate = relative_error(d_rate, q_rate), e_state = relative_error(d_state, q_state);
                        if (!(e_rate <= tol && e_state <= tol))
                            print_error("%s V0 %g: v = %g, theta = %g, ln z = %.3f\n", law->name, V0s[iv], v,
                                        theta, log_z);
                        assert_close(d_rate, q_rate, tol, 0);
                        assert_close(d_state, q_state, tol, 0);
                        worst_rate = fmax(worst_rate, e_rate);
                        worst_state = fmax(worst_state, e_state);
                        points++;
                    }
                }
            }
        }
    }
    print_message("%zu points (ln z < -20: %zu, between: %zu, > 20: %zu): worst relative error "
                  "dF/dv %.2g, dF/dtheta %.2g\n",
                  points, branch_hits[0], branch_hits[1], branch_hits[2], worst_rate, worst_state);
    for (size_t b = 0; b < 3; ++b)
        assert_true(branch_hits[b] > 10);
}

/* dF/dv even and dF/dtheta odd in v; at v = 0 dF/dtheta = 0 (F(0, theta) = 0) and dF/dv is
 * both the difference quotient there and the limit of small v; values just either side of
 * the branch switches at ln z = -20 and ln z = 20 agree. */
static void test_dieterich_ruina_derivatives_limits(void **state)
{
    (void)state;
    const bk_friction_law *laws[] = {&bk_friction_dieterich_ruina_aging, &bk_friction_dieterich_ruina_slip};
    const double V0s[] = {1e-5, 1e-3}, thetas[] = {1e-6, 3e-3, 1.0, 1e6}, N = 5e6;
    double worst_zero = 0.0, worst_limit = 0.0, worst_switch = 0.0;
    for (size_t k = 0; k < 2; ++k) {
        const bk_friction_law *law = laws[k];
        for (size_t iv = 0; iv < 2; ++iv) {
            double p[BK_FRICTION_MAX_PARAMS];
            dr_params(law, V0s[iv], p);
            for (size_t it = 0; it < 4; ++it) {
                double theta = thetas[it], st[1] = {theta}, dr_pos, ds_pos, dr_neg, ds_neg;
                /* Symmetry, exactly. */
                const double rates[] = {1e-45, 1e-30, 1e-20, 1e-9, 1e-5, 1e-3, 1.0, 10.0};
                for (size_t r = 0; r < 8; ++r) {
                    law->sliding_force_derivatives(p, N, rates[r], st, &dr_pos, &ds_pos);
                    law->sliding_force_derivatives(p, N, -rates[r], st, &dr_neg, &ds_neg);
                    assert_true(dr_pos > 0.0 && ds_pos > 0.0);
                    assert_close(dr_neg, dr_pos, 0, 0);
                    assert_close(ds_neg, -ds_pos, 0, 0);
                }
                /* v = 0: z = v / v_c with v_c = 2 V0 e^(-psi / a), F = N a asinh(v / v_c). */
                double v_c = 2.0 * V0s[iv] * exp(-dr_log_scale(law, p, theta));
                double d_rate0, d_state0;
                law->sliding_force_derivatives(p, N, 0.0, st, &d_rate0, &d_state0);
                assert_close(d_state0, 0.0, 0, 0);
                assert_close(d_rate0, N * 0.01 / v_c, 1e-12, 0);
                force_slice by_rate = {law, p, N, 0.0, theta, 0};
                double q = richardson(&by_rate, 0.0, 0.05 * v_c);
                assert_close(d_rate0, q, 1e-9, 0);
                worst_zero = fmax(worst_zero, relative_error(d_rate0, q));
                /* Small v: dF/dv = d_rate0 / sqrt(1 + z^2), z = 1e-3 (between) to 1e-12 (ln z < -20). */
                const double zs[] = {1e-3, 1e-6, 1e-8, 1e-12};
                for (size_t iz = 0; iz < 4; ++iz) {
                    double d_rate, d_state;
                    law->sliding_force_derivatives(p, N, zs[iz] * v_c, st, &d_rate, &d_state);
                    double limit = d_rate0 / sqrt(1.0 + zs[iz] * zs[iz]);
                    assert_close(d_rate, limit, 1e-12, 0);
                    worst_limit = fmax(worst_limit, relative_error(d_rate, limit));
                }
                /* Either side of ln z = +-20: slip rates 1e-12 apart straddling the switch. */
                const double edges[] = {-20.0, 20.0};
                for (size_t ie = 0; ie < 2; ++ie) {
                    double v_edge = v_c * exp(edges[ie]);
                    double below = v_edge * (1.0 - 1e-12), above = v_edge * (1.0 + 1e-12);
                    assert_true(dr_log_z(law, p, below, theta) < edges[ie]);
                    assert_true(dr_log_z(law, p, above, theta) > edges[ie]);
                    double r_below, s_below, r_above, s_above;
                    law->sliding_force_derivatives(p, N, below, st, &r_below, &s_below);
                    law->sliding_force_derivatives(p, N, above, st, &r_above, &s_above);
                    assert_close(r_above, r_below, 1e-8, 0);
                    assert_close(s_above, s_below, 1e-8, 0);
                    worst_switch = fmax(worst_switch, fmax(relative_error(r_above, r_below),
                                                           relative_error(s_above, s_below)));
                }
            }
        }
    }
    print_message("v = 0: dF/dv against its quotient %.2g, small v against d_rate(0) / sqrt(1 + z^2) %.2g; "
                  "branch switches at ln z = +-20: worst relative jump %.2g\n",
                  worst_zero, worst_limit, worst_switch);
}

/* --- relaxation times ------------------------------------------------------------------ */

/* After dt from a small offset off steady state at speed v, the offset has shrunk by
 * exp(-dt / tau) (for the slip law, the offset of ln theta); the linearised state equation
 * has slope -1 / tau there. */
static double check_relaxation(const bk_friction_law *law, const double *p, double speed, double steady)
{
    double tau = law->relaxation_time(p, speed), worst = 0.0;
    int log_offset = law == &bk_friction_dieterich_ruina_slip;
    const double offsets[] = {1e-3, -1e-3}, spans[] = {0.1, 1.0, 3.0};
    for (size_t o = 0; o < 2; ++o)
        for (size_t s = 0; s < 3; ++s) {
            double theta0 = log_offset ? steady * exp(offsets[o]) : steady * (1.0 + offsets[o]);
            double st[1] = {theta0};
            law->state_advance(p, speed, spans[s] * tau, st);
            double shrink = log_offset ? log(st[0] / steady) / log(theta0 / steady)
                                       : (st[0] - steady) / (theta0 - steady);
            assert_close(shrink, exp(-spans[s]), 1e-9, 0);
            worst = fmax(worst, relative_error(shrink, exp(-spans[s])));
        }
    /* d(theta')/d(theta) at steady state = -1 / tau. */
    double up[1] = {steady * (1.0 + 1e-6)}, down[1] = {steady * (1.0 - 1e-6)}, r_up[1], r_down[1];
    law->state_rate(p, speed, up, r_up);
    law->state_rate(p, speed, down, r_down);
    double slope = (r_up[0] - r_down[0]) / (up[0] - down[0]);
    assert_close(slope * tau, -1.0, 1e-6, 0);
    worst = fmax(worst, fabs(slope * tau + 1.0));
    return worst;
}

/* Dc / v for both Dieterich-Ruina laws, L0 / (B v) for the paper's law, each the decay time
 * of the law's own state_advance; laws without state have neither relaxation time nor
 * derivatives, and the paper's law leaves its derivatives to difference quotients. */
static void test_relaxation_time(void **state)
{
    (void)state;
    const double speeds[] = {1e-9, 2.385e-3, 1.0, 10.0};
    double worst = 0.0;
    const bk_friction_law *drs[] = {&bk_friction_dieterich_ruina_aging, &bk_friction_dieterich_ruina_slip};
    for (size_t k = 0; k < 2; ++k) {
        double p[BK_FRICTION_MAX_PARAMS];
        law_params(drs[k], p);
        assert_non_null(drs[k]->relaxation_time);
        for (size_t s = 0; s < 4; ++s) {
            assert_close(drs[k]->relaxation_time(p, speeds[s]), 1e-5 / speeds[s], 1e-15, 0);
            worst = fmax(worst, check_relaxation(drs[k], p, speeds[s], 1e-5 / speeds[s]));
        }
    }
    const bk_friction_law *rs = &bk_friction_rate_state;
    double p[BK_FRICTION_MAX_PARAMS];
    law_params(rs, p);
    assert_non_null(rs->relaxation_time);
    assert_null(rs->sliding_force_derivatives);
    for (size_t s = 0; s < 4; ++s) {
        assert_close(rs->relaxation_time(p, speeds[s]), 2e-5 / (4.6 * speeds[s]), 1e-15, 0);
        worst = fmax(worst, check_relaxation(rs, p, speeds[s], 2e-5 / speeds[s]));
    }
    print_message("state decay against exp(-t / relaxation_time): worst relative error %.2g\n", worst);
    assert_null(bk_friction_coulomb.relaxation_time);
    assert_null(bk_friction_coulomb.sliding_force_derivatives);
    assert_null(bk_friction_carlson_langer.relaxation_time);
    assert_null(bk_friction_carlson_langer.sliding_force_derivatives);
    for (const bk_friction_law *const *l = bk_friction_laws(); *l; ++l)
        assert_int_equal((*l)->n_state > 0, (*l)->relaxation_time != NULL);
}

/* --- parameter validation through the config loader ------------------------------------ */

static void test_validation(void **state)
{
    (void)state;
    const struct {
        const char *friction, *message;
    } cases[] = {
        {"law = rate_state\nmu_s = 0.6\nmu_d = 0.7\n", "[friction] mu_d: must be <= mu_s (0.6), got 0.7"},
        {"law = rate_state\nmu_s = 0.6\nL0 = 0\n", "[friction] L0: out of range, got 0 (allowed: 0 < L0 < inf m)"},
        {"law = rate_state\nmu_s = 0.6\nm = -1\n", "[friction] m: out of range"},
        {"law = rate_state\nmu_s = 0.6\nv_theta_ref = nan\n", "[friction] v_theta_ref: not a number"},
        {"law = carlson_langer\nF0 = 5\nsigma = 1\nalpha = 1\n",
         "[friction] sigma: out of range, got 1 (allowed: 0 <= sigma < 1)"},
        {"law = carlson_langer\nF0 = 5\nalpha = 1\n", "[friction] sigma: required key missing"},
        {"law = dieterich_ruina_aging\na = 0\nb = 0.015\nDc = 1e-5\nV0 = 1e-6\nf0 = 0.6\n",
         "[friction] a: out of range, got 0 (allowed: 0 < a < inf)"},
        {"law = dieterich_ruina_slip\na = 0.01\nb = 0.015\nV0 = 1e-6\nf0 = 0.6\n", "[friction] Dc: required key missing"},
        {"law = dieterich_ruina_slip\na = 0.01\nb = 0.015\nDc = 1e-5\nV0 = 1e-6\nf0 = 0.6\nmu_s = 1\n",
         "[friction] mu_s: not a parameter of law 'dieterich_ruina_slip'"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char text[1024];
        snprintf(text, sizeof text,
                 "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n[friction]\n%s"
                 "[driver]\nvelocity = 1e-3\n[run]\nt_end = 1\n",
                 cases[k].friction);
        bk_config *c = NULL;
        bk_error err = {0};
        int rc = bk_config_load_string(text, "t.ini", NULL, 0, &c, &err);
        if (rc != BK_ERR_CONFIG || !strstr(err.message, cases[k].message))
            print_error("case %zu: %s\nexpected: %s\n", k, err.message, cases[k].message);
        assert_int_equal(rc, BK_ERR_CONFIG);
        assert_non_null(strstr(err.message, cases[k].message));
    }
    /* A law whose default initial state needs a moving driver says so. */
    const char *still = "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n[friction]\n"
                        "law = rate_state\nmu_s = 0.6\n[driver]\nvelocity = 0\n[run]\nt_end = 1\n";
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(still, "t.ini", NULL, 0, &c, &err), BK_ERR_CONFIG);
    assert_non_null(strstr(err.message, "theta_init: required when the driver does not move"));
}

/* --- Rice-Ruina: steady sliding is unstable below k_c = N (b - a) / Dc ------------------ */

typedef struct velocity_log {
    double early, late; /* max |v - V| over the first and the last quarter of the run */
    double V, t_end;
} velocity_log;

static int log_velocity(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    velocity_log *log = self;
    double d = fabs(s->v[0] - log->V);
    if (s->t > 5.0 && s->t < 0.25 * log->t_end && d > log->early)
        log->early = d;
    if (s->t > 0.75 * log->t_end && d > log->late)
        log->late = d;
    return BK_OK;
}

static velocity_log run_rice_ruina(double stiffness_factor)
{
    const double a = 0.01, b = 0.015, Dc = 1e-5, V = 1e-5, N = 9.81, t_end = 80.0;
    double k_c = N * (b - a) / Dc;
    char text[2048];
    /* Near quasi-static (m V^2 / (N a Dc) = 1e-4), started with the state 5 % off. */
    snprintf(text, sizeof text,
             "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = %.17g\nv_init = %g\n[friction]\n"
             "law = dieterich_ruina_aging\na = %g\nb = %g\nDc = %g\nV0 = %g\nf0 = 0.6\ntheta_init = %.17g\n"
             "[driver]\nvelocity = %g\nstart_position = %.17g\n[solver]\nmethod = cvode_bdf\nrtol = 1e-9\n"
             "[output]\ninterval = 0.01\nevents = false\n[run]\nt_end = %g\n",
             stiffness_factor * k_c, V, a, b, Dc, V, 0.95 * Dc / V, V, 0.0, t_end);
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "rice_ruina.ini", NULL, 0, &c, &err), BK_OK);
    /* Put the spring at the steady friction force, so only the state is perturbed. */
    const bk_block *blk = &c->model->blocks[0];
    double steady_state[1] = {Dc / V}; // cppcheck-suppress duplicateExpression ; Dc and V happen to be equal here
    double friction = blk->law->sliding_force(blk->friction_params, blk->normal_force, V, steady_state);
    c->model->driver.start_position = friction / blk->driver_stiffness;
    velocity_log log = {0, 0, V, t_end};
    bk_sink sink = {.self = &log, .sample = log_velocity, .transition = NULL};
    bk_run_stats stats;
    int rc = bk_run(c, &sink, &stats, NULL, NULL, &err);
    if (rc != BK_OK)
        print_error("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    print_message("k = %.1f k_c: max |v - V| %.3g early, %.3g late (V = %g m/s), energy residual %.2g\n",
                  stiffness_factor, log.early, log.late, V, stats.energy_residual);
    bk_config_free(c);
    return log;
}

static void test_rice_ruina(void **state)
{
    (void)state;
    velocity_log soft = run_rice_ruina(0.8), stiff = run_rice_ruina(1.2);
    /* Below k_c the perturbation grows into stick-slip: slip-rate spikes far above V. */
    assert_true(soft.late > 10.0 * soft.early);
    assert_true(soft.late > 5.0 * 1e-5);
    /* Above k_c it decays to steady sliding (slowly this close to k_c). */
    assert_true(stiff.late < 0.2 * stiff.early);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_battery),
        cmocka_unit_test(test_state_evolution_exact),
        cmocka_unit_test(test_rate_state_steady_state),
        cmocka_unit_test(test_rate_state_printed_form_degenerate),
        cmocka_unit_test(test_rate_state_limits),
        cmocka_unit_test(test_carlson_langer),
        cmocka_unit_test(test_dieterich_ruina),
        cmocka_unit_test(test_dieterich_ruina_derivatives),
        cmocka_unit_test(test_dieterich_ruina_derivatives_limits),
        cmocka_unit_test(test_relaxation_time),
        cmocka_unit_test(test_validation),
        cmocka_unit_test(test_rice_ruina),
    };
    return cmocka_run_group_tests_name("friction", tests, NULL, NULL);
}
