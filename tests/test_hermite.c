/* The output rows' Hermite interpolation (src/solver/hermite.c): exact for polynomials of
 * its degree, its tail the share of the last node, and on sin the error its formula gives. */
#include <math.h>

#include "bk_test.h"
#include "solver/hermite.h"

/* p(t) = sum a_j t^j and its derivative, for two components (p and 2 p + 1). */
static void poly(const double *a, size_t degree, double t, double *y, double *f)
{
    double v = 0.0, d = 0.0;
    for (size_t j = degree + 1; j-- > 0;) {
        d = d * t + v;
        v = v * t + a[j];
    }
    y[0] = v, y[1] = 2.0 * v + 1.0;
    f[0] = d, f[1] = 2.0 * d;
}

static void test_reproduces_its_degree(void **state)
{
    (void)state;
    const double a[12] = {0.3, -1.1, 0.7, 2.0, -0.4, 0.25, 1.5, -0.9, 0.6, -0.2, 0.1, 0.05};
    const double nodes[6] = {0.0, 1.0, -0.3, -0.8, 0.45, -1.2};
    for (size_t k = 1; k <= 6; ++k) {
        bk_hermite h = {0};
        assert_int_equal(bk_hermite_reserve(&h, 2), 0);
        double yv[6][2], fv[6][2];
        const double *ys[6], *fs[6];
        for (size_t j = 0; j < k; ++j) {
            poly(a, 2 * k - 1, nodes[j], yv[j], fv[j]);
            ys[j] = yv[j];
            fs[j] = fv[j];
        }
        bk_hermite_build(&h, k, nodes, ys, fs);
        for (double t = -0.1; t <= 1.1; t += 0.05) {
            double want[2], df[2], got[2], tail[2];
            poly(a, 2 * k - 1, t, want, df);
            bk_hermite_eval(&h, t, got, tail);
            assert_close(got[0], want[0], 1e-11, 1e-11);
            assert_close(got[1], want[1], 1e-11, 1e-11);
        }
        bk_hermite_free(&h);
    }
}

/* The tail vanishes when the nodes before the last already fit (a polynomial two degrees
 * lower), and on sin through 4 nodes it bounds the true error from above. */
static void test_tail(void **state)
{
    (void)state;
    const double a[4] = {1.0, -2.0, 0.5, 0.25};
    const double nodes[3] = {0.0, 1.0, -0.5};
    bk_hermite h = {0};
    assert_int_equal(bk_hermite_reserve(&h, 2), 0);
    double yv[3][2], fv[3][2];
    const double *ys[3], *fs[3];
    for (size_t j = 0; j < 3; ++j) {
        poly(a, 3, nodes[j], yv[j], fv[j]);
        ys[j] = yv[j];
        fs[j] = fv[j];
    }
    bk_hermite_build(&h, 3, nodes, ys, fs);
    double out[2], tail[2];
    bk_hermite_eval(&h, 0.4, out, tail);
    assert_true(fabs(tail[0]) < 1e-12 && fabs(tail[1]) < 1e-12);

    const double sin_nodes[4] = {0.0, 0.5, -0.4, -0.7};
    double sy[4][2], sf[4][2];
    const double *sys[4], *sfs[4];
    for (size_t j = 0; j < 4; ++j) {
        sy[j][0] = sin(sin_nodes[j]), sy[j][1] = cos(sin_nodes[j]);
        sf[j][0] = cos(sin_nodes[j]), sf[j][1] = -sin(sin_nodes[j]);
        sys[j] = sy[j];
        sfs[j] = sf[j];
    }
    bk_hermite_build(&h, 4, sin_nodes, sys, sfs);
    for (double t = 0.05; t < 0.5; t += 0.05) {
        bk_hermite_eval(&h, t, out, tail);
        double err = fabs(out[0] - sin(t));
        /* |sin^(8)| <= 1: error <= prod (t - t_j)^2 / 8! */
        double bound = 1.0 / 40320.0;
        for (size_t j = 0; j < 4; ++j)
            bound *= (t - sin_nodes[j]) * (t - sin_nodes[j]);
        assert_true(err <= bound);
        assert_true(err <= fabs(tail[0]) * 1.01);
    }
    bk_hermite_free(&h);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reproduces_its_degree),
        cmocka_unit_test(test_tail),
    };
    return cmocka_run_group_tests_name("hermite", tests, NULL, NULL);
}
