/* The driver's position: constant velocity, and a history of piecewise-constant velocities
 * (segments found at and between breakpoints, positions continuous across them, the time the
 * driver reaches a position across holds and reversals). */
#include <math.h>

#include "bk_test.h"
#include "bksim/driver.h"

static void test_constant(void **state)
{
    (void)state;
    bk_driver d = {.velocity = 2.385e-3, .start_position = 1e-3};
    assert_close(bk_driver_position(&d, 4.0), 1e-3 + 4.0 * 2.385e-3, 1e-15, 0);
    assert_close(bk_driver_velocity(&d, 7.0), 2.385e-3, 0, 0);
    assert_int_equal(bk_driver_segment(&d, 9.0), 0);
    assert_true(isinf(bk_driver_next_breakpoint(&d, 0.0)));
    assert_close(bk_driver_time_at(&d, 0.0, 1e-3 + 2.385e-3), 1.0, 1e-15, 0);
    assert_true(isinf(bk_driver_time_at(&d, 0.0, 0.0))); /* behind it */
}

/* Slide, hold, slide back, slide on: 0..1 s at 1 mm/s, 1..3 s held, 3..3.5 s at -2 mm/s,
 * then 4 mm/s from 3.5 s on. */
static void test_history(void **state)
{
    (void)state;
    const double v[] = {1e-3, 0.0, -2e-3, 4e-3}, dur[] = {1.0, 2.0, 0.5, 10.0};
    bk_driver d = {.velocity = 5.0, .start_position = 0.5e-3};
    assert_int_equal(bk_driver_set_history(&d, v, dur, 4), 0);
    assert_close(d.velocity, 1e-3, 0, 0); /* the first non-zero speed */
    /* Segments: the later one at a breakpoint, the last past its end. */
    assert_int_equal(bk_driver_segment(&d, 0.0), 0);
    assert_int_equal(bk_driver_segment(&d, 0.999), 0);
    assert_int_equal(bk_driver_segment(&d, 1.0), 1);
    assert_int_equal(bk_driver_segment(&d, 3.25), 2);
    assert_int_equal(bk_driver_segment(&d, 3.5), 3);
    assert_int_equal(bk_driver_segment(&d, 100.0), 3);
    assert_close(bk_driver_next_breakpoint(&d, 0.0), 1.0, 0, 0);
    assert_close(bk_driver_next_breakpoint(&d, 1.0), 3.0, 0, 0);
    assert_close(bk_driver_next_breakpoint(&d, 3.4), 3.5, 0, 0);
    assert_true(isinf(bk_driver_next_breakpoint(&d, 3.5)));
    /* Positions: continuous across each breakpoint, flat in the hold. */
    assert_close(bk_driver_position(&d, 1.0), 1.5e-3, 1e-15, 0);
    assert_close(bk_driver_position(&d, 2.0), 1.5e-3, 1e-15, 0);
    assert_close(bk_driver_position(&d, 3.5), 0.5e-3, 1e-12, 0);
    assert_close(bk_driver_position(&d, 4.0), 2.5e-3, 1e-12, 0);
    for (size_t k = 1; k < 4; ++k) {
        double t = d.segment_start[k];
        assert_close(bk_driver_segment_position(&d, k - 1, t), bk_driver_segment_position(&d, k, t), 1e-15, 1e-18);
    }
    assert_close(bk_driver_velocity(&d, 1.0), 0.0, 0, 0);
    assert_close(bk_driver_velocity(&d, 3.0), -2e-3, 0, 0);
    /* A segment's own line continues past its end (an integrator's step ending there). */
    assert_close(bk_driver_segment_position(&d, 0, 1.5), 2.0e-3, 1e-15, 0);
    /* When the driver gets somewhere: not during the hold; back down on the reversal. */
    assert_close(bk_driver_time_at(&d, 0.0, 1.0e-3), 0.5, 1e-12, 0);
    assert_close(bk_driver_time_at(&d, 1.2, 1.5e-3), 1.2, 0, 0); /* already there */
    assert_close(bk_driver_time_at(&d, 1.2, 1.0e-3), 3.25, 1e-12, 0);
    assert_close(bk_driver_time_at(&d, 1.2, 2.0e-3), 3.5 + 1.5e-3 / 4e-3, 1e-12, 0);
    assert_true(isinf(bk_driver_time_at(&d, 3.6, 0.1e-3)));
    bk_driver_free_history(&d);
    assert_int_equal(d.n_segments, 0);
    assert_null(d.segment_start);
    /* A history of holds only has no speed to scale by. */
    const double still[] = {0.0, 0.0};
    assert_int_equal(bk_driver_set_history(&d, still, dur, 2), 0);
    assert_close(d.velocity, 0.0, 0, 0);
    assert_true(isinf(bk_driver_time_at(&d, 0.0, 1.0)));
    bk_driver_free_history(&d);
    assert_int_equal(bk_driver_set_history(&d, still, dur, 0), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant),
        cmocka_unit_test(test_history),
    };
    return cmocka_run_group_tests_name("driver", tests, NULL, NULL);
}
