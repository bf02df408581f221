/* Every registered back-end on the same battery: a harmonic oscillator's value, its root
 * at a quarter period, dense output, restarts with a different size, stop time, counters. */
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/solver.h"

#define PI 3.14159265358979323846

/* y0' = y1, y1' = -w^2 y0 (size 2); a third component, when present, is a quadrature of
 * the position, y2' = y0.  Affine, so the exact stepper runs the battery too. */
static const double omega = 2.385;

static int oscillator(double t, const double *y, double *ydot, void *user)
{
    (void)t;
    size_t n = *(const size_t *)user;
    ydot[0] = y[1];
    ydot[1] = -omega * omega * y[0];
    if (n > 2)
        ydot[2] = y[0];
    return 0;
}

static int crossing(double t, const double *y, double *g, void *user)
{
    (void)t;
    (void)user;
    g[0] = y[0]; /* position through zero */
    return 0;
}

static bk_solver_options options(const char *linear_solver)
{
    bk_solver_options o;
    memset(&o, 0, sizeof o);
    o.rtol = 1e-10;
    o.max_step = 0.0;
    o.max_steps = 100000;
    snprintf(o.linear_solver, sizeof o.linear_solver, "%s", linear_solver);
    return o;
}

static void battery(const bk_solver_backend *b, const char *linear_solver)
{
    bk_solver_options o = options(linear_solver);
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, &o, &err), BK_OK);
    size_t n = 2;
    int direction[1] = {-1};
    static const double unit_mass[1] = {1.0};
    bk_ode_problem p = {.user = &n, .rhs = oscillator, .roots = crossing, .n_roots = 1,
                        .root_direction = direction, .half_bandwidth = 1, .n_pairs = 1,
                        .pair_mass = unit_mass, .affine = 1};
    double y0[3] = {1.0, 0.0, 1.0}, atol[3] = {1e-14, 1e-14, 1e-14}, y[3];
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, n, 10.0, &err), BK_OK);
    double t = 0.0;
    int rc;
    long steps = 0;
    while ((rc = b->step(mem, &t, y, &err)) == BK_STEP_OK)
        ++steps;
    /* cos(w t) reaches zero falling at a quarter period. */
    assert_int_equal(rc, BK_STEP_ROOT);
    assert_close(t, PI / (2 * omega), 1e-9, 0);
    assert_close(y[0], 0.0, 0, 1e-9);
    assert_close(y[1], -omega, 1e-8, 0);
    int found[1] = {0};
    assert_int_equal(b->root_info(mem, found), BK_OK);
    assert_int_equal(found[0], -1);
    /* Dense output inside the last step. */
    double lo, hi, yi[3];
    b->last_step(mem, &lo, &hi);
    assert_true(lo < t && t <= hi);
    double tm = 0.5 * (lo + t);
    assert_int_equal(b->interpolate(mem, tm, yi, &err), BK_OK);
    assert_close(yi[0], cos(omega * tm), 1e-8, 1e-10);

    /* Restart with three components from the root; run to the stop time. */
    n = 3;
    double z0[3] = {0.0, -omega, 1.0};
    // cppcheck-suppress unreadVariable ; read through p.root_direction by the back-end
    direction[0] = +1; /* the next crossing rises, half a period on */
    assert_int_equal(b->start(mem, &p, t, z0, atol, n, t + 0.25 * PI / omega, &err), BK_OK);
    double t_start = t;
    while ((rc = b->step(mem, &t, y, &err)) == BK_STEP_OK)
        ;
    assert_int_equal(rc, BK_STEP_STOP);
    assert_close(t, t_start + 0.25 * PI / omega, 1e-14, 0);
    assert_close(y[2], 1.0 + (cos(omega * (t - t_start)) - 1.0) / omega, 1e-8, 1e-10);
    assert_close(y[0], -sin(omega * (t - t_start)), 1e-8, 1e-10);

    bk_solver_counters c;
    b->counters(mem, &c);
    assert_true(c.steps > steps);      /* both starts counted */
    assert_true(c.rhs_evals >= c.steps);
    assert_true(c.root_evals > 0);
    b->destroy(mem);
}

static void test_every_backend(void **state)
{
    (void)state;
    size_t count = 0;
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b, ++count) {
        print_message("back-end %s\n", (*b)->name);
        battery(*b, "dense");
        battery(*b, "band");
        assert_ptr_equal(bk_solver_backend_find((*b)->name), *b);
    }
    assert_true(count >= 2);
    assert_null(bk_solver_backend_find("no_such_method"));
}

/* A semi-explicit DAE, the shape of the full layout: the oscillator, a stuck pair
 * (xi' = v, 0 = -v) and a driven algebraic z (0 = sin t - z). */
enum { DAE_N = 5 };
static const double dae_id[DAE_N] = {1, 1, 1, 0, 0};

static int dae_rhs(double t, const double *y, double *f, void *user)
{
    (void)user;
    f[0] = y[1];
    f[1] = -omega * omega * y[0];
    f[2] = y[3];
    f[3] = -y[3];
    f[4] = sin(t) - y[4];
    return 0;
}

static int dae_jacobian(double t, const double *y, void *user,
                        void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix)
{
    (void)t;
    (void)y;
    (void)user;
    put(matrix, 0, 1, 1.0);
    put(matrix, 1, 0, -omega * omega);
    put(matrix, 2, 3, 1.0);
    put(matrix, 3, 3, -1.0);
    put(matrix, 4, 4, -1.0);
    return 0;
}

/* ida honours differential_id: the algebraic z follows sin t at every step (were it
 * integrated as z' = sin t - z it would lag by far more), the stuck pair stays exactly 0
 * in steps and dense output, and the oscillator is unaffected; with the exact Jacobian and
 * with IDA's difference quotients, dense and band. */
static void test_ida_algebraic_rows(void **state)
{
    (void)state;
    assert_true(bk_solver_ida.wants_full_layout);
    const char *solvers[] = {"dense", "band"};
    for (size_t variant = 0; variant < 4; ++variant) {
        bk_solver_options o = options(solvers[variant % 2]);
        void *mem = NULL;
        bk_error err = {0};
        assert_int_equal(bk_solver_ida.create(&mem, &o, &err), BK_OK);
        int direction[1] = {-1};
        bk_ode_problem p = {.rhs = dae_rhs, .roots = crossing, .n_roots = 1,
                            .root_direction = direction, .half_bandwidth = 1,
                            .jacobian = variant < 2 ? dae_jacobian : NULL,
                            .differential_id = dae_id};
        double y0[DAE_N] = {1.0, 0.0, 0.0, 0.0, 0.0}, atol[DAE_N], y[DAE_N], yi[DAE_N];
        for (size_t k = 0; k < DAE_N; ++k)
            atol[k] = 1e-14;
        assert_int_equal(bk_solver_ida.start(mem, &p, 0.0, y0, atol, DAE_N, 2.0, &err), BK_OK);
        double t = 0.0;
        int rc;
        long steps = 0;
        while ((rc = bk_solver_ida.step(mem, &t, y, &err)) == BK_STEP_OK || rc == BK_STEP_ROOT) {
            ++steps;
            assert_close(y[4], sin(t), 0, 1e-9);
            assert_true(y[2] == 0.0 && y[3] == 0.0);
            double lo, hi;
            bk_solver_ida.last_step(mem, &lo, &hi);
            assert_int_equal(bk_solver_ida.interpolate(mem, 0.5 * (lo + hi), yi, &err), BK_OK);
            assert_true(yi[2] == 0.0 && yi[3] == 0.0);
            if (rc == BK_STEP_ROOT)
                assert_close(t, PI / (2 * omega), 1e-9, 0);
        }
        assert_int_equal(rc, BK_STEP_STOP);
        assert_true(steps > 10);
        assert_close(y[0], cos(omega * 2.0), 1e-7, 1e-9);
        bk_solver_ida.destroy(mem);
    }
}

/* A failing right-hand side is reported, not hidden. */
static int failing(double t, const double *y, double *ydot, void *user)
{
    (void)user;
    ydot[0] = y[1];
    ydot[1] = -y[0];
    return t > 0.0 ? -1 : 0; /* fails on the first step's evaluations */
}

static void test_failure_reported(void **state)
{
    (void)state;
    const bk_solver_backend *b = bk_solver_backend_find("cvode_adams");
    bk_solver_options o = options("dense");
    void *mem = NULL;
    bk_error err = {0};
    assert_int_equal(b->create(&mem, &o, &err), BK_OK);
    size_t n = 2;
    bk_ode_problem p = {.user = &n, .rhs = failing, .half_bandwidth = 1};
    double y0[2] = {1, 0}, atol[2] = {1e-12, 1e-12}, y[2], t;
    assert_int_equal(b->start(mem, &p, 0.0, y0, atol, 2, 10.0, &err), BK_OK);
    int rc = BK_STEP_OK;
    for (int k = 0; k < 1000 && rc == BK_STEP_OK; ++k)
        rc = b->step(mem, &t, y, &err);
    assert_int_equal(rc, BK_ERR_SOLVER);
    assert_non_null(strstr(err.message, "CVODE"));
    b->destroy(mem);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_backend),
        cmocka_unit_test(test_failure_reported),
        cmocka_unit_test(test_ida_algebraic_rows),
    };
    return cmocka_run_group_tests_name("solver", tests, NULL, NULL);
}
