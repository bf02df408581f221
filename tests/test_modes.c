/* The stick/slip machine (paper Figure 3). */
#include "bk_test.h"
#include "bksim/modes.h"

static void test_at_rest(void **state)
{
    (void)state;
    assert_int_equal(bk_mode_at_rest(3.0, 5.886), BK_MODE_STICK);
    assert_int_equal(bk_mode_at_rest(-5.886, 5.886), BK_MODE_STICK); /* at the threshold: holds */
    assert_int_equal(bk_mode_at_rest(5.887, 5.886), BK_MODE_SLIP_POS);
    assert_int_equal(bk_mode_at_rest(-6.0, 5.886), BK_MODE_SLIP_NEG);
    assert_int_equal(bk_mode_at_rest(0.0, 0.0), BK_MODE_STICK);
}

static void test_stop(void **state)
{
    (void)state;
    /* A stop sticks below the threshold, reverses beyond it the other way... */
    assert_int_equal(bk_mode_next(BK_MODE_SLIP_POS, BK_EVENT_STOP, -3.92, 5.886), BK_MODE_STICK);
    assert_int_equal(bk_mode_next(BK_MODE_SLIP_POS, BK_EVENT_STOP, -7.1, 5.886), BK_MODE_SLIP_NEG);
    assert_int_equal(bk_mode_next(BK_MODE_SLIP_NEG, BK_EVENT_STOP, 7.1, 5.886), BK_MODE_SLIP_POS);
    /* ...and never goes straight from one slip direction to the other without the check. */
    assert_int_equal(bk_mode_next(BK_MODE_SLIP_NEG, BK_EVENT_STOP, 1.0, 5.886), BK_MODE_STICK);
}

static void test_breakaway(void **state)
{
    (void)state;
    assert_int_equal(bk_mode_next(BK_MODE_STICK, BK_EVENT_BREAKAWAY, 5.886, 5.886), BK_MODE_SLIP_POS);
    /* The root finder located the crossing: rounding just below the threshold still slips. */
    assert_int_equal(bk_mode_next(BK_MODE_STICK, BK_EVENT_BREAKAWAY, 5.8859999999, 5.886),
                     BK_MODE_SLIP_POS);
    assert_int_equal(bk_mode_next(BK_MODE_STICK, BK_EVENT_BREAKAWAY, -5.886, 5.886), BK_MODE_SLIP_NEG);
    assert_int_equal(bk_mode_next(BK_MODE_STICK, BK_EVENT_BREAKAWAY, 0.0, 0.0), BK_MODE_STICK);
}

static void test_names(void **state)
{
    (void)state;
    assert_string_equal(bk_mode_name(BK_MODE_STICK), "stick");
    assert_string_equal(bk_mode_name(BK_MODE_SLIP_POS), "slip+");
    assert_string_equal(bk_mode_name(BK_MODE_SLIP_NEG), "slip-");
    assert_int_equal(bk_mode_direction(BK_MODE_SLIP_NEG), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_at_rest),
        cmocka_unit_test(test_stop),
        cmocka_unit_test(test_breakaway),
        cmocka_unit_test(test_names),
    };
    return cmocka_run_group_tests_name("modes", tests, NULL, NULL);
}
