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
    };
    return cmocka_run_group_tests_name("solver", tests, NULL, NULL);
}
