/* Output-row nodes (src/solver/row_nodes.c): which nodes the polynomial gets, and that the
 * rows through them follow the solution they sample. */
#include <math.h>

#include "bk_test.h"
#include "solver/row_nodes.h"

static void at(double t, double *y, double *f)
{
    y[0] = sin(t), f[0] = cos(t);
}

/* Older step ends join up to the count wanted, newest first, and stop at one closer than
 * 1/8 of the step to the next; a new integration forgets them. */
static void test_node_choice(void **state)
{
    (void)state;
    bk_row_nodes r = {0};
    assert_int_equal(bk_row_nodes_start(&r, 1), 0);
    double y[1], f[1];
    const double ends[] = {-1.0, -0.98, -0.6, -0.3, 0.0};
    for (size_t k = 0; k < 4; ++k) {
        at(ends[k], y, f);
        bk_row_nodes_push(&r, ends[k], y, f);
    }
    double y_lo[1], f_lo[1], y_hi[1], f_hi[1];
    at(0.0, y_lo, f_lo);
    at(0.8, y_hi, f_hi);
    bk_row_nodes_prepare(&r, 6, 0.0, y_lo, f_lo, 0.8, y_hi, f_hi);
    /* -0.3, -0.6 and -0.98 are 0.3 and more apart; -1.0 is 0.02 from -0.98. */
    assert_int_equal(r.poly.m, 2 * 5);
    bk_row_nodes_prepare(&r, 3, 0.0, y_lo, f_lo, 0.8, y_hi, f_hi); /* same step: kept */
    assert_int_equal(r.poly.m, 2 * 5);
    double out[1], tail[1];
    bk_hermite_eval(&r.poly, 0.37, out, tail);
    /* Within the error formula (|sin^(10)| <= 1, nodes 0, 0.8, -0.3, -0.6, -0.98: 5.4e-9;
     * measured 8.6e-10) and the tail's estimate. */
    double bound = 1.0 / 3628800.0;
    const double used[] = {0.0, 0.8, -0.3, -0.6, -0.98};
    for (size_t k = 0; k < 5; ++k)
        bound *= (0.37 - used[k]) * (0.37 - used[k]);
    assert_true(fabs(out[0] - sin(0.37)) <= bound);
    assert_true(fabs(out[0] - sin(0.37)) <= fabs(tail[0]));

    assert_int_equal(bk_row_nodes_start(&r, 1), 0);
    bk_row_nodes_prepare(&r, 6, 0.0, y_lo, f_lo, 0.8, y_hi, f_hi);
    assert_int_equal(r.poly.m, 2 * 2);
    bk_row_nodes_free(&r);
}

/* Nodes inside the step: up to BK_ROW_INNER, each rebuilding the polynomial, none after. */
static void test_inner_nodes(void **state)
{
    (void)state;
    bk_row_nodes r = {0};
    assert_int_equal(bk_row_nodes_start(&r, 1), 0);
    double y_lo[1], f_lo[1], y_hi[1], f_hi[1];
    at(0.0, y_lo, f_lo);
    at(1.5, y_hi, f_hi);
    bk_row_nodes_prepare(&r, 6, 0.0, y_lo, f_lo, 1.5, y_hi, f_hi);
    double out[1], tail[1];
    bk_hermite_eval(&r.poly, 0.7, out, tail);
    double cubic_error = fabs(out[0] - sin(0.7));
    for (size_t k = 0; k < BK_ROW_INNER; ++k) {
        double *y, *f, t = 1.5 * (double)(k + 1) / (BK_ROW_INNER + 1);
        assert_int_equal(bk_row_nodes_inner(&r, &y, &f), 1);
        at(t, y, f);
        bk_row_nodes_add_inner(&r, t);
        assert_int_equal(r.poly.m, 2 * (k + 3));
    }
    double *y, *f;
    assert_int_equal(bk_row_nodes_inner(&r, &y, &f), 0);
    bk_hermite_eval(&r.poly, 0.7, out, tail);
    assert_true(fabs(out[0] - sin(0.7)) < 1e-6 * cubic_error);
    bk_row_nodes_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_node_choice),
        cmocka_unit_test(test_inner_nodes),
    };
    return cmocka_run_group_tests_name("row_nodes", tests, NULL, NULL);
}
