/* Test support: assert_close, as cmocka 1.1.5 has no floating-point comparison with tolerances. */
#ifndef BK_TEST_H
#define BK_TEST_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

/* Passes when |a - b| <= atol + rtol * |b|; prints both values and the excess otherwise. */
#define assert_close(a, b, rtol, atol) \
    bk_assert_close_impl((a), (b), (rtol), (atol), #a, #b, __FILE__, __LINE__)

static inline void bk_assert_close_impl(double a, double b, double rtol, double atol,
                                        const char *a_text, const char *b_text,
                                        const char *file, int line)
{
    double diff = fabs(a - b);
    if (!(diff <= atol + rtol * fabs(b))) {
        print_error("%s = %.17g\n%s = %.17g\n|diff| = %.3g > atol %.3g + rtol %.3g * |b|"
                    " (relative %.3g)\n",
                    a_text, a, b_text, b, diff, atol, rtol, diff / (fabs(b) > 0 ? fabs(b) : 1.0));
        _fail(file, line);
    }
}

#endif
