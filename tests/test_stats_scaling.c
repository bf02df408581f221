/* Scaling relations (src/stats_scaling.c).  An exact power law is recovered to rounding;
 * on seeded noisy laws (GSL MT19937) the OLS slope falls within 2 of its standard errors of
 * the true exponent in at least 90 % of 200 samples (nominal 95.4 %: 9 misses expected, 20
 * allowed, 3.7 binomial sigma above) and its mean error matches the slopes' spread to 15 %
 * (the spread of 200 slopes is itself known to 5 %); exponents 2.0 and 2.3 differ by far
 * more than 3 errors.  With scatter in x OLS is flattened by the attenuation factor and the
 * reduced major axis is closer; the OLS and inverse slopes bracket the exponent both when
 * the scatter is in x and when it is in y.  A synthetic catalog with potency = duration^3
 * below magnitude 0 and duration^2 above gives back 3 and 2 in its magnitude bands. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "bk_test.h"
#include "bksim/stats_scaling.h"

static void test_exact_power_law(void **state)
{
    (void)state;
    enum { N = 50 };
    double x[N], y[N];
    for (size_t i = 0; i < N; ++i) {
        x[i] = pow(10.0, 2.0 * (double)i / (N - 1)); /* 1 .. 100 */
        y[i] = 3.0 * pow(x[i], 1.5);
    }
    bk_scaling_fit f;
    bk_error err = {0};
    assert_int_equal(bk_scaling_fit_pairs(x, y, N, -INFINITY, INFINITY, &f, &err), BK_OK);
    assert_int_equal(f.n, N);
    assert_close(f.slope, 1.5, 0.0, 1e-12);
    assert_close(f.intercept, log10(3.0), 0.0, 1e-12);
    assert_close(f.r, 1.0, 0.0, 1e-12);
    assert_true(f.slope_sigma < 1e-12 && f.residual_sd < 1e-12);
    assert_close(f.slope_rma, 1.5, 0.0, 1e-12);
    assert_close(f.slope_inverse, 1.5, 0.0, 1e-12);
    assert_close(f.x_min, 1.0, 1e-15, 0.0);
    assert_close(f.x_max, 100.0, 1e-15, 0.0);
    /* A range: x in [10, 50) only. */
    assert_int_equal(bk_scaling_fit_pairs(x, y, N, 10.0, 50.0, &f, &err), BK_OK);
    size_t inside = 0;
    for (size_t i = 0; i < N; ++i)
        inside += x[i] >= 10.0 && x[i] < 50.0;
    assert_int_equal(f.n, inside);
    assert_int_equal(f.n_outside, N - inside);
    assert_close(f.slope, 1.5, 0.0, 1e-12);
    assert_true(f.x_min >= 10.0 && f.x_max < 50.0);
}

/* n pairs with log10 x uniform on [0, 2] and log10 y = a + gamma log10 x + N(0, sigma). */
static void noisy_law(gsl_rng *rng, double a, double gamma, double sigma, double *x, double *y, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        double u = 2.0 * gsl_rng_uniform(rng);
        x[i] = pow(10.0, u);
        y[i] = pow(10.0, a + gamma * u + gsl_ran_gaussian(rng, sigma));
    }
}

static void test_calibrated_error(void **state)
{
    (void)state;
    enum { N = 500, SEEDS = 200 };
    static double x[N], y[N];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    bk_error err = {0};
    size_t misses = 0;
    double sum = 0.0, sum2 = 0.0, sum_sigma = 0.0, sum_rma = 0.0, sum_inverse = 0.0;
    for (unsigned long seed = 1; seed <= SEEDS; ++seed) {
        gsl_rng_set(rng, seed);
        noisy_law(rng, 0.5, 2.0, 0.2, x, y, N);
        bk_scaling_fit f;
        assert_int_equal(bk_scaling_fit_pairs(x, y, N, -INFINITY, INFINITY, &f, &err), BK_OK);
        misses += fabs(f.slope - 2.0) > 2.0 * f.slope_sigma;
        sum += f.slope;
        sum2 += f.slope * f.slope;
        sum_sigma += f.slope_sigma;
        sum_rma += f.slope_rma;
        sum_inverse += f.slope_inverse;
    }
    double mean = sum / SEEDS, sd = sqrt((sum2 - SEEDS * mean * mean) / (SEEDS - 1)), sigma = sum_sigma / SEEDS;
    print_message("gamma 2.0, n = %d, %d seeds: mean slope %.4f, spread %.4f, mean error %.4f (ratio %.3f), "
                  "%zu outside 2 errors; mean RMA %.4f, inverse %.4f\n",
                  N, SEEDS, mean, sd, sigma, sigma / sd, misses, sum_rma / SEEDS, sum_inverse / SEEDS);
    assert_true(misses <= SEEDS / 10);
    assert_close(sigma, sd, 0.15, 0.0);
    /* Unbiased: the mean of 200 within 3 of its own errors. */
    assert_close(mean, 2.0, 0.0, 3.0 * sd / sqrt(SEEDS));
    /* Scatter in y only: the RMA and the inverse slope lie above (by 1/r and 1/r^2:
     * r^2 = 4/3 / (4/3 + 0.04) here, so 2.030 and 2.060). */
    assert_close(sum_rma / SEEDS, 2.0 / sqrt((4.0 / 3.0) / (4.0 / 3.0 + 0.04)), 0.0, 0.005);
    assert_close(sum_inverse / SEEDS, 2.0 * (4.0 / 3.0 + 0.04) / (4.0 / 3.0), 0.0, 0.005);

    /* 2.0 against 2.3. */
    bk_scaling_fit f20, f23;
    gsl_rng_set(rng, 2019);
    noisy_law(rng, 0.5, 2.0, 0.2, x, y, N);
    assert_int_equal(bk_scaling_fit_pairs(x, y, N, -INFINITY, INFINITY, &f20, &err), BK_OK);
    noisy_law(rng, 0.5, 2.3, 0.2, x, y, N);
    assert_int_equal(bk_scaling_fit_pairs(x, y, N, -INFINITY, INFINITY, &f23, &err), BK_OK);
    double z = (f23.slope - f20.slope) / hypot(f20.slope_sigma, f23.slope_sigma);
    print_message("2.0 -> %.4f +- %.4f, 2.3 -> %.4f +- %.4f: %.1f sigma apart\n", f20.slope, f20.slope_sigma, f23.slope,
                  f23.slope_sigma, z);
    assert_true(z > 3.0);
    gsl_rng_free(rng);
}

static void test_regression_dilution(void **state)
{
    (void)state;
    /* log10 x_true ~ N(0, 0.5), observed with N(0, 0.25) added; log10 y = 0.3 + 2 log10
     * x_true + N(0, 0.2).  Attenuation Var(true) / Var(observed) = 0.25 / 0.3125 = 0.8: OLS
     * 1.6; RMA sqrt((4 * 0.25 + 0.04) / 0.3125) = 1.824; inverse 2 + 0.04 / (2 * 0.25) = 2.08. */
    enum { N = 5000 };
    static double x[N], y[N];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 1987);
    for (size_t i = 0; i < N; ++i) {
        double u = gsl_ran_gaussian(rng, 0.5);
        x[i] = pow(10.0, u + gsl_ran_gaussian(rng, 0.25));
        y[i] = pow(10.0, 0.3 + 2.0 * u + gsl_ran_gaussian(rng, 0.2));
    }
    bk_scaling_fit f;
    bk_error err = {0};
    assert_int_equal(bk_scaling_fit_pairs(x, y, N, -INFINITY, INFINITY, &f, &err), BK_OK);
    print_message("dilution: OLS %.4f +- %.4f (expected 1.6), RMA %.4f +- %.4f (1.824), inverse %.4f (2.08), r %.4f\n",
                  f.slope, f.slope_sigma, f.slope_rma, f.slope_rma_sigma, f.slope_inverse, f.r);
    assert_true(f.slope < 2.0 - 10.0 * f.slope_sigma); /* flattened, far beyond its error */
    assert_close(f.slope, 1.6, 0.0, 0.04);
    assert_true(fabs(f.slope_rma - 2.0) < 0.5 * fabs(f.slope - 2.0));
    assert_close(f.slope_rma, 1.824, 0.0, 0.04);
    assert_true(f.slope < 2.0 && f.slope_inverse > 2.0);
    assert_close(f.slope_inverse, 2.08, 0.0, 0.05);
    gsl_rng_free(rng);
}

/* The synthetic catalog: log10 T uniform on [-1.2, 1.2]; log10 P = 3 log10 T + noise below
 * magnitude 0 (T < 1) and 2 log10 T + noise above; M = (2/3) log10 P; n_blocks = round(15 T)
 * (one-block ruptures among the shortest), every rupture of M >= 1 spans the whole ring of
 * 500 blocks; and rows the fits must skip. */
enum { CAT = 4000, EXTRA = 8, ROWS = CAT + EXTRA };

typedef struct catalog {
    double t_start[ROWS], t_end[ROWS], m[ROWS], p[ROWS];
    int32_t blocks[ROWS];
} catalog;

static void make_catalog(catalog *c)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 12805);
    for (size_t i = 0; i < CAT; ++i) {
        double u = -1.2 + 2.4 * gsl_rng_uniform(rng), t = pow(10.0, u);
        double log_p = (u < 0.0 ? 3.0 : 2.0) * u + gsl_ran_gaussian(rng, 0.05);
        c->t_start[i] = 10.0 * (double)i;
        c->t_end[i] = c->t_start[i] + t;
        c->p[i] = pow(10.0, log_p);
        c->m[i] = 2.0 / 3.0 * log_p;
        c->blocks[i] = c->m[i] >= 0.95 ? 500 : (int32_t)fmax(1.0, floor(15.0 * t + 0.5));
    }
    gsl_rng_free(rng);
    /* Three zero-duration ruptures of 36 blocks at M 0.5 (on the length law: 15 x 10^(0.75 /
     * 2) = 35.6), two one-block ruptures of zero duration, a NaN magnitude, a potency of 0
     * (M -inf) and a NaN potency at M 0.5. */
    for (size_t k = 0; k < EXTRA; ++k) {
        size_t i = CAT + k;
        c->t_start[i] = c->t_end[i] = 1e6 + (double)k;
        c->p[i] = pow(10.0, 0.75);
        c->m[i] = 0.5;
        c->blocks[i] = k < 3 ? 36 : 1;
    }
    c->m[CAT + 5] = NAN;
    c->p[CAT + 6] = 0.0;
    c->m[CAT + 6] = -INFINITY;
    c->p[CAT + 7] = NAN;
    c->blocks[CAT + 7] = 36;
    c->t_end[CAT + 7] += 1.0;
}

static void test_magnitude_bands(void **state)
{
    (void)state;
    static catalog c;
    make_catalog(&c);
    bk_scaling_columns cols = {ROWS, c.t_start, c.t_end, c.m, c.p, c.blocks};
    bk_scaling_options opt;
    bk_scaling_options_default(&opt);
    opt.mc = -2.0;
    /* First every rupture in the fits: the bands then select on potency alone. */
    opt.min_blocks = 1;
    static bk_scaling s;
    bk_error err = {0};
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_OK);
    size_t below = 0;
    for (size_t i = 0; i < CAT; ++i)
        below += c.m[i] < -2.05;
    assert_int_equal(s.n_rows, ROWS);
    assert_int_equal(s.n_nonfinite, 2); /* NaN and -inf */
    assert_int_equal(s.n_below_mc, below);
    assert_int_equal(s.n_bands, 4);
    const double expect[4] = {3.0, 3.0, 2.0, 2.0};
    size_t total = 0;
    for (size_t b = 0; b < s.n_bands; ++b) {
        const bk_scaling_band *band = &s.band[b];
        total += band->n_events;
        assert_close(band->m_lo, -2.0 + (double)b, 0.0, 1e-12);
        assert_close(band->m_hi, -1.0 + (double)b, 0.0, 1e-12);
        assert_true(band->have_duration);
        const bk_scaling_fit *d = &band->duration;
        char length[BK_SCALING_NOTE_LEN + 32];
        if (band->have_length)
            snprintf(length, sizeof length, "slope %.4f +- %.4f", band->length.slope, band->length.slope_sigma);
        else
            snprintf(length, sizeof length, "not available: %s", band->length_note);
        print_message("M [%g, %g): %zu ruptures; duration: n %zu, slope %.4f +- %.4f, RMA %.4f, inverse %.4f, "
                      "r %.4f; length: %s\n",
                      band->m_lo, band->m_hi, band->n_events, d->n, d->slope, d->slope_sigma, d->slope_rma,
                      d->slope_inverse, d->r, length);
        assert_close(d->slope, expect[b], 0.0, 0.1);
        /* The band cuts potency, the dependent variable: OLS is flattened (by 1 to 2 % at
         * this scatter of 0.05 decades), the inverse slope, whose regressor is cut, is the
         * closer; the two bracket the exponent (allowing each end 3 of its errors). */
        assert_true(d->slope < expect[b]);
        assert_true(fabs(d->slope_inverse - expect[b]) < fabs(d->slope - expect[b]));
        assert_true(d->slope - 3.0 * d->slope_sigma <= expect[b]);
        assert_true(d->slope_inverse + 3.0 * d->slope_sigma >= expect[b]);
    }
    assert_int_equal(total + s.n_below_mc + s.n_nonfinite, ROWS);
    assert_int_equal(s.all.n_events, total);
    /* Band [1, 2): every rupture spans the ring: no length fit, noted. */
    assert_false(s.band[3].have_length);
    assert_non_null(strstr(s.band[3].length_note, "have n_blocks = 500: no spread in n_blocks"));
    /* The whole range mixes the two laws. */
    assert_true(s.all.have_duration && s.all.have_length);
    print_message("M >= -2: slope %.4f +- %.4f (n %zu)\n", s.all.duration.slope, s.all.duration.slope_sigma,
                  s.all.duration.n);
    assert_true(s.all.duration.slope > 2.0 && s.all.duration.slope < 3.0);

    /* The default: the one-block ruptures of the lowest band are left out and counted.  In
     * band [0, 1) two one-block rows of zero duration, at the far left of the lengths, had
     * pulled the length slope down. */
    double length_with_small = s.band[2].length.slope;
    opt.min_blocks = BK_SCALING_MIN_BLOCKS;
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_OK);
    size_t small = 0;
    for (size_t i = 0; i < CAT; ++i)
        small += c.m[i] >= -2.05 && c.m[i] < -1.05 && c.blocks[i] < 2;
    assert_true(small > 0);
    assert_int_equal(s.band[0].n_small, small);
    assert_int_equal(s.band[0].duration.n + s.band[0].duration.n_invalid, s.band[0].n_events - small);
    /* Band [0, 1): the three zero-duration ruptures and the NaN potency are skipped and
     * counted, the one-block rows left out before; its lengths (15 to 84 blocks) give 2. */
    assert_int_equal(s.band[2].duration.n_invalid, 4);
    assert_int_equal(s.band[2].n_small, 2);
    assert_int_equal(s.band[2].length.n_invalid, 1);
    assert_true(s.band[2].have_length);
    print_message("M [0, 1) lengths: n %zu, slope %.4f +- %.4f\n", s.band[2].length.n, s.band[2].length.slope,
                  s.band[2].length.slope_sigma);
    assert_close(s.band[2].length.slope, 2.0, 0.0, 0.1);
    assert_true(fabs(s.band[2].length.slope - 2.0) < fabs(length_with_small - 2.0));

    /* A minimum count no band of this width reaches at the top: noted, not fatal. */
    opt.min_pairs = 5000;
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_OK);
    assert_false(s.band[3].have_duration);
    assert_non_null(strstr(s.band[3].duration_note, "ruptures with duration, potency finite and > 0: needs at least 5000"));
    /* Wider bands from Mc = -1: two, the upper one [1, 3). */
    opt.min_pairs = BK_SCALING_BAND_MIN_PAIRS;
    opt.mc = -1.0;
    opt.band_width = 2.0;
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_OK);
    assert_int_equal(s.n_bands, 2);
    assert_close(s.band[1].m_lo, 1.0, 0.0, 1e-12);
    assert_close(s.band[1].m_hi, 3.0, 0.0, 1e-12);
    /* Bands of one bin from -2: more than BK_SCALING_MAX_BANDS, the last open upward. */
    opt.mc = -2.0;
    opt.band_width = 0.1;
    opt.min_pairs = BK_SCALING_MIN_PAIRS;
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_OK);
    assert_int_equal(s.n_bands, BK_SCALING_MAX_BANDS);
    const bk_scaling_band *last = &s.band[BK_SCALING_MAX_BANDS - 1];
    assert_close(last->m_lo, -0.5, 0.0, 1e-12);
    assert_true(isinf(last->m_hi) && last->m_hi > 0.0);
    size_t open = 0;
    for (size_t i = 0; i < ROWS; ++i)
        open += isfinite(c.m[i]) && c.m[i] >= -0.55;
    assert_int_equal(last->n_events, open);
    /* No n_blocks column: every rupture in the duration fits, no length fits. */
    cols.n_blocks = NULL;
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_OK);
    assert_int_equal(s.band[0].n_small, 0);
    assert_false(s.band[0].have_length);
    assert_string_equal(s.band[0].length_note, "the catalog has no n_blocks");
    assert_true(s.band[0].have_duration);
}

static void classify(double slope, double sigma, bk_scaling_class expected, const char *text)
{
    char buf[BK_SCALING_NOTE_LEN];
    bk_scaling_class cls;
    bk_error err = {0};
    assert_int_equal(bk_scaling_classify(slope, sigma, &cls, buf, sizeof buf, &err), BK_OK);
    print_message("%g +- %g: %s\n", slope, sigma, buf);
    assert_int_equal(cls, expected);
    assert_string_equal(buf, text);
}

static void test_classify(void **state)
{
    (void)state;
    classify(1.0, 0.1, BK_SCALING_SLOW, "consistent with slow ruptures (0.63 to 1.5) within 2 sigma");
    classify(2.0, 0.1, BK_SCALING_SUBSHEAR, "consistent with sub-shear fronts (2) within 2 sigma");
    classify(3.0, 0.1, BK_SCALING_SUPERSHEAR, "consistent with supershear fronts (3) within 2 sigma");
    classify(2.5, 0.05, BK_SCALING_SUB_TO_SUPERSHEAR,
             "between sub-shear (2) and supershear (3): 10.0 sigma above 2, 10.0 sigma below 3");
    classify(1.75, 0.05, BK_SCALING_SLOW_TO_SUBSHEAR,
             "between slow (0.63 to 1.5) and sub-shear (2): 5.0 sigma above 1.5, 5.0 sigma below 2");
    classify(0.3, 0.1, BK_SCALING_BELOW_SLOW, "below the slow range (0.63 to 1.5): 3.3 sigma below 0.63");
    classify(3.5, 0.1, BK_SCALING_ABOVE_SUPERSHEAR, "above supershear (3): 5.0 sigma above 3");
    classify(2.5, 0.3, BK_SCALING_AMBIGUOUS,
             "consistent with sub-shear fronts (2) and supershear fronts (3) within 2 sigma: the error is too "
             "large to tell them apart");
    classify(1.7, 0.15, BK_SCALING_AMBIGUOUS,
             "consistent with slow ruptures (0.63 to 1.5) and sub-shear fronts (2) within 2 sigma: the error is "
             "too large to tell them apart");
    classify(2.0, 0.5, BK_SCALING_AMBIGUOUS,
             "consistent with slow ruptures (0.63 to 1.5), sub-shear fronts (2) and supershear fronts (3) within 2 "
             "sigma: the error is too large to tell them apart");
    /* Edges: 2 errors reach a value exactly; an exact exponent between the values. */
    classify(2.2, 0.1, BK_SCALING_SUBSHEAR, "consistent with sub-shear fronts (2) within 2 sigma");
    classify(2.5, 0.0, BK_SCALING_SUB_TO_SUPERSHEAR, "between sub-shear (2) and supershear (3): above 2, below 3");
    bk_scaling_class cls;
    bk_error err = {0};
    assert_int_equal(bk_scaling_classify(NAN, 0.1, &cls, NULL, 0, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "exponent nan +- 0.1: the exponent must be finite"));
    assert_int_equal(bk_scaling_classify(2.0, -0.1, &cls, NULL, 0, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "its error finite and >= 0"));
}

static void test_errors(void **state)
{
    (void)state;
    double x[20], y[20];
    for (size_t i = 0; i < 20; ++i) {
        x[i] = 1.0 + (double)i;
        y[i] = 2.0 * x[i] * x[i];
    }
    bk_scaling_fit f;
    bk_error err = {0};
    assert_int_equal(bk_scaling_fit_pairs(x, y, 9, -INFINITY, INFINITY, &f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "scaling fit: 9 pairs with x, y finite and > 0: needs at least 10"));
    assert_int_equal(bk_scaling_fit_pairs(x, y, 20, 5.0, 12.0, &f, &err), BK_ERR_INVALID);
    assert_non_null(
        strstr(err.message, "7 pairs with x, y finite and > 0 and x in [5, 12) (0 skipped: not finite or <= 0; "
                            "13 outside the range): needs at least 10"));
    assert_int_equal(bk_scaling_fit_pairs(x, y, 20, 5.0, 5.0, &f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "x range [5, 5): allowed x_lo < x_hi"));
    assert_int_equal(bk_scaling_fit_pairs(x, y, 20, NAN, 5.0, &f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "x range [nan, 5): allowed x_lo < x_hi, neither NaN"));
    /* Zero spread. */
    double same[12], ys[12];
    for (size_t i = 0; i < 12; ++i) {
        same[i] = 5.0;
        ys[i] = 1.0 + (double)i;
    }
    assert_int_equal(bk_scaling_fit_pairs(same, ys, 12, -INFINITY, INFINITY, &f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "all 12 pairs fitted have x = 5: no spread in x to fit a slope"));
    assert_int_equal(bk_scaling_fit_pairs(ys, same, 12, -INFINITY, INFINITY, &f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "all 12 pairs fitted have y = 5: no spread in y"));
    /* NaN, negative and zero values are skipped and counted; the rest fit as alone. */
    x[2] = NAN;
    y[5] = NAN;
    x[7] = -3.0;
    y[9] = 0.0;
    x[11] = INFINITY;
    assert_int_equal(bk_scaling_fit_pairs(x, y, 20, -INFINITY, INFINITY, &f, &err), BK_OK);
    assert_int_equal(f.n_invalid, 5);
    assert_int_equal(f.n, 15);
    assert_close(f.slope, 2.0, 0.0, 1e-12);
    assert_close(f.intercept, log10(2.0), 0.0, 1e-12);
    for (size_t i = 0; i < 20; ++i)
        y[i] = -1.0;
    assert_int_equal(bk_scaling_fit_pairs(x, y, 20, -INFINITY, INFINITY, &f, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "0 pairs with x, y finite and > 0 (20 skipped"));

    /* Options and columns of the bands. */
    bk_scaling_options opt;
    bk_scaling_options_default(&opt);
    bk_scaling s;
    bk_scaling_columns cols = {20, NULL, NULL, x, y, NULL};
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "Mc = nan: must be finite"));
    opt.mc = 1.05;
    assert_int_equal(bk_scaling_options_check(&opt, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "Mc = 1.05 is not a bin centre"));
    opt.mc = 1.0;
    opt.band_width = 0.25;
    assert_int_equal(bk_scaling_options_check(&opt, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "band width 0.25: must be a positive multiple of the bin width dm = 0.1"));
    opt.band_width = 0.0;
    assert_int_equal(bk_scaling_options_check(&opt, &err), BK_ERR_INVALID);
    opt.band_width = 0.5;
    opt.min_pairs = 9;
    assert_int_equal(bk_scaling_options_check(&opt, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "at least 9 ruptures per fit: allowed 10 or more"));
    opt.min_pairs = 10;
    opt.min_blocks = 0;
    assert_int_equal(bk_scaling_options_check(&opt, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "ruptures of at least 0 blocks: allowed 1 or more"));
    opt.min_blocks = 2;
    opt.dm = 0.0;
    assert_int_equal(bk_scaling_options_check(&opt, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "dm = 0: must be finite and > 0"));
    opt.dm = 0.1;
    assert_int_equal(bk_scaling_options_check(&opt, &err), BK_OK);
    cols.potency = NULL;
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "the catalog has no potency column"));
    /* No durations: noted per band. */
    cols.potency = x;
    assert_int_equal(bk_scaling_by_magnitude(&cols, &opt, &s, &err), BK_OK);
    assert_false(s.all.have_duration);
    assert_string_equal(s.all.duration_note, "the catalog has no t_start and t_end");
}

static void test_medians(void **state)
{
    (void)state;
    /* 5 bins a decade: edges 10^(k/5); x = 1 and 10 start their bins. */
    const double x[] = {1.0, 1.2, 1.5, 2.0, 10.0, 10.0, 0.1, NAN, 3.0};
    const double y[] = {3.0, 1.0, 2.0, 10.0, 8.0, 7.0, 4.0, 1.0, -1.0};
    bk_scaling_bins bins;
    bk_error err = {0};
    assert_int_equal(bk_scaling_binned_medians(x, y, 9, 5, &bins, &err), BK_OK);
    assert_int_equal(bins.n_used, 7);
    assert_int_equal(bins.n_invalid, 2);
    assert_int_equal(bins.n_bins, 4);
    const double lo[] = {0.1, 1.0, pow(10.0, 0.2), 10.0}, median[] = {4.0, 2.0, 10.0, 7.5};
    const size_t count[] = {1, 3, 1, 2};
    for (size_t b = 0; b < 4; ++b) {
        assert_close(bins.x_lo[b], lo[b], 1e-12, 0.0);
        assert_close(bins.x_hi[b], lo[b] * pow(10.0, 0.2), 1e-12, 0.0);
        assert_close(bins.x_centre[b], lo[b] * pow(10.0, 0.1), 1e-12, 0.0);
        assert_int_equal(bins.count[b], count[b]);
        assert_close(bins.median[b], median[b], 1e-15, 0.0);
    }
    assert_close(bins.q25[1], 1.5, 1e-15, 0.0);
    assert_close(bins.q75[1], 2.5, 1e-15, 0.0);
    assert_close(bins.q25[3], 7.25, 1e-15, 0.0);
    assert_close(bins.q75[3], 7.75, 1e-15, 0.0);
    bk_scaling_bins_free(&bins);
    assert_int_equal(bk_scaling_binned_medians(x, y, 9, 0, &bins, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "0 bins per decade: allowed 1 .. 100"));
    assert_int_equal(bk_scaling_binned_medians(x + 7, y + 7, 2, 5, &bins, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "none of 2 pairs has x and y finite and > 0"));
    bk_scaling_bins_free(&bins);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_power_law),
        cmocka_unit_test(test_calibrated_error),
        cmocka_unit_test(test_regression_dilution),
        cmocka_unit_test(test_magnitude_bands),
        cmocka_unit_test(test_classify),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_medians),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
