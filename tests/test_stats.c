/* Catalog statistics (bksim/stats.h): the estimators against published reference values and
 * against synthetic Gutenberg-Richter catalogs, the KS test, and the report computed from
 * catalogs built here in memory (reading them from HDF5 is test_h5_event_table.c's). */
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
#include "bksim/stats.h"
#include "bksim/stats_scaling.h"
#include "bksim/stats_truncated.h"
#include "files.h"

#define N_OF(a) (sizeof(a) / sizeof((a)[0]))

/* ------------------------------------------------------ reference values --- */

/* SeismoStats (github.com/swiss-seismological-service/SeismoStats, commit 4605c4e2d7bb),
 * seismostats/analysis/bvalue/utsu.py, the UtsuBValueEstimator docstring example: these 24
 * magnitudes with mc = 2.0, delta_m = 0.1 give b = 1.1088369750721319.  Their estimator is
 * beta = 1 / mean(m - mc + delta_m/2), the Aki-Utsu form of bk_b_value. */
static const double UTSU_EXAMPLE[] = {
    2.0, 2.5, 2.1, 2.2, 2.5, 2.2, 2.6, 2.3, 2.7, 2.2, 2.4, 2.0,
    2.7, 2.2, 2.3, 2.1, 2.4, 2.6, 2.2, 2.2, 2.7, 2.4, 2.2, 2.5,
};

/* SeismoStats, seismostats/analysis/tests/test_estimate_mc.py, MAGNITUDES: 100 magnitudes
 * for which test_estimate_mc_maxc expects estimate_mc_maxc(fmd_bin=0.1,
 * correction_factor=0.2) = 1.3.  Bins 1.1 and 1.2 both hold 19 events: the lower wins. */
static const double MAXC_EXAMPLE[] = {
    2.3, 1.2, 1.5, 1.2, 1.7, 1.1, 1.2, 1.5, 1.8, 1.6, 1.2, 1.5, 1.2, 1.7, 1.6, 1.1, 1.1,
    1.2, 2.0, 1.1, 1.2, 1.1, 1.2, 1.6, 1.9, 1.3, 1.7, 1.3, 1.0, 1.2, 1.7, 1.3, 1.3, 1.1,
    1.5, 1.4, 1.1, 2.1, 1.2, 2.2, 1.7, 1.6, 1.1, 2.0, 2.1, 1.2, 1.0, 1.5, 1.2, 1.7, 1.8,
    1.1, 1.3, 1.1, 1.3, 1.4, 2.1, 2.0, 1.1, 2.2, 1.8, 1.4, 1.1, 1.0, 2.0, 2.0, 1.1, 1.0,
    1.0, 1.5, 1.6, 3.7, 2.8, 1.5, 1.1, 1.2, 1.4, 2.3, 1.5, 1.2, 1.7, 1.1, 1.6, 1.2, 1.5,
    1.1, 1.2, 1.7, 1.2, 1.6, 1.2, 1.1, 1.8, 1.2, 1.1, 1.0, 1.3, 1.1, 1.6, 1.6,
};

/* SeismoStats, seismostats/analysis/bvalue/tests/data/simulated_magnitudes.csv, the first
 * 100 values of column "b_value = 1"; test_utils.py, test_shi_bolt_confidence, expects
 * shi_bolt_confidence(these, b=1) = 0.09776728958456313 (ln(10) b^2 std / sqrt(n - 1),
 * std with 1/n: Shi & Bolt's 2.30 b^2 sqrt(sum (m - mean)^2 / (n (n - 1)))). */
static const double SHI_BOLT_EXAMPLE[] = {
    -0.004055829867952748, -0.2254136609722491,   0.024663348582245115, 0.36936225208728624,
    -0.15531837631312978,  -0.16274390349481888,  -0.15921892068683874, -0.12483975814313611,
    -0.1576745647366838,   0.11672390423393358,   0.06353934893511404,  -0.12556314640806837,
    0.5431074454368369,    -0.21635303140626808,  0.5607921442675717,   -0.01780544580133714,
    0.8810007749748121,    0.14028026793009613,   0.7812484046878623,   0.0406899385125884,
    -0.11340798898235951,  -0.027858350486637956, -0.16828500670169144, -0.15976236972257482,
    0.8027353113781226,    0.09866610973248718,   0.5088348133700401,   0.19558767487529172,
    -0.10581645606506726,  -0.014058053239028673, -0.20308356850387435, -0.21591016374798444,
    0.10674381941940231,   -0.14087106365541321,  0.060249456287832015, -0.009695895342168248,
    -0.15473781249887852,  -0.058942056989461644, -0.24218549447114543, 0.2073176079649231,
    -0.16719080277610365,  -0.10100818412524651,  0.5186262883861209,   0.07446894728775105,
    -0.002204172737201998, -0.19966757367746465,  -0.02387363247963023, 0.06153524777190761,
    -0.22806986104290206,  -0.0510218069456026,   -0.23420035893736924, -0.12347817513414219,
    -0.15336757442120177,  0.004495049911551141,  -0.08410966992448979, -0.22271869359418345,
    2.4065232581274407,    0.3837815664528744,    0.29518509145839134,  -0.2436771101730134,
    0.5674033963627843,    0.46403672141437236,   0.5096328102331716,   -0.08936021200386374,
    0.22893436342416001,   -0.0339333562930626,   0.24820635496933996,  -0.22724909341527114,
    -0.16254147596505178,  -0.00762243663324122,  0.9350636443833402,   0.46800874422135963,
    0.627431941417221,     0.3316587730839763,    -0.06085126834085314, 0.569550990508713,
    0.4388920664763757,    -0.16533914021176294,  0.6536832320260693,   -0.2000705202004301,
    0.1892688778432225,    -0.21785453957079687,  0.516055838916183,    0.31788691024921756,
    -0.16048141237433544,  0.028968022551882355,  0.21558093631608827,  2.033460739626325,
    -0.220660790832087,    0.5210358655147198,    0.5247996557142484,   -0.08255359409756843,
    0.13538310995216107,   0.5504919434890134,    0.07786809362180086,  -0.20788457608503783,
    0.20342737003402211,   -0.08857408515452411,  0.08136221902214835,  0.5761316205151151,
};

static void test_b_value_reference(void **state)
{
    (void)state;
    bk_b_estimate est;
    bk_error err = {0};
    assert_int_equal(bk_b_value(UTSU_EXAMPLE, N_OF(UTSU_EXAMPLE), 2.0, 0.1, &est, &err), BK_OK);
    assert_close(est.b, 1.1088369750721319, 1e-13, 0.0);
    assert_int_equal(est.n, 24);
    assert_close(est.mc, 2.0, 0.0, 1e-15);
    /* The error is Shi & Bolt's on the same (binned) magnitudes. */
    double sigma = 0.0;
    assert_int_equal(bk_shi_bolt(UTSU_EXAMPLE, N_OF(UTSU_EXAMPLE), est.b, &sigma, &err), BK_OK);
    assert_close(est.sigma, sigma, 1e-12, 0.0);
    assert_close(est.sigma_aki, est.b / sqrt(24.0), 1e-15, 0.0);
    assert_close(est.a, log10(24.0) + est.b * 2.0, 1e-15, 0.0);
    /* Magnitudes below Mc are not part of the estimate. */
    double more[N_OF(UTSU_EXAMPLE) + 3];
    memcpy(more, UTSU_EXAMPLE, sizeof UTSU_EXAMPLE);
    more[24] = 1.9, more[25] = 1.0, more[26] = -3.0;
    bk_b_estimate est2;
    assert_int_equal(bk_b_value(more, N_OF(more), 2.0, 0.1, &est2, &err), BK_OK);
    assert_close(est2.b, est.b, 0.0, 0.0);
    assert_int_equal(est2.n, 24);
}

static void test_shi_bolt_reference(void **state)
{
    (void)state;
    double sigma = 0.0;
    bk_error err = {0};
    assert_int_equal(bk_shi_bolt(SHI_BOLT_EXAMPLE, N_OF(SHI_BOLT_EXAMPLE), 1.0, &sigma, &err),
                     BK_OK);
    assert_close(sigma, 0.09776728958456313, 1e-13, 0.0);
    /* b enters squared. */
    assert_int_equal(bk_shi_bolt(SHI_BOLT_EXAMPLE, N_OF(SHI_BOLT_EXAMPLE), 2.0, &sigma, &err),
                     BK_OK);
    assert_close(sigma, 4.0 * 0.09776728958456313, 1e-13, 0.0);
    assert_int_equal(bk_shi_bolt(SHI_BOLT_EXAMPLE, 1, 1.0, &sigma, &err), BK_ERR_INVALID);
}

static void test_maxc_reference(void **state)
{
    (void)state;
    bk_mfd mfd;
    bk_error err = {0};
    assert_int_equal(bk_mfd_build(MAXC_EXAMPLE, N_OF(MAXC_EXAMPLE), 0.1, &mfd, &err), BK_OK);
    double mc = 0.0;
    assert_int_equal(bk_mc_maxc(&mfd, BK_MAXC_CORRECTION, &mc, &err), BK_OK);
    assert_close(mc, 1.3, 0.0, 1e-12);
    assert_int_equal(bk_mc_maxc(&mfd, 0.0, &mc, &err), BK_OK);
    assert_close(mc, 1.1, 0.0, 1e-12);
    bk_mfd_free(&mfd);
}

/* ------------------------------------------------------- binning, MFD --- */

static void test_binning(void **state)
{
    (void)state;
    bk_error err = {0};
    long k = 99;
    /* Half-way values go up, also where the decimal text is rounded down in binary. */
    assert_int_equal(bk_mag_bin(0.25, 0.1, &k, &err), BK_OK);
    assert_int_equal(k, 3);
    assert_int_equal(bk_mag_bin(0.15, 0.1, &k, &err), BK_OK); /* 1.4999999999999998 bins */
    assert_int_equal(k, 2);
    assert_int_equal(bk_mag_bin(2.15, 0.1, &k, &err), BK_OK); /* 21.499999999999996 bins */
    assert_int_equal(k, 22);
    assert_int_equal(bk_mag_bin(-0.15, 0.1, &k, &err), BK_OK); /* up is towards +inf */
    assert_int_equal(k, -1);
    assert_int_equal(bk_mag_bin(-0.05, 0.1, &k, &err), BK_OK);
    assert_int_equal(k, 0);
    assert_int_equal(bk_mag_bin(-0.0500001, 0.1, &k, &err), BK_OK);
    assert_int_equal(k, -1);
    assert_int_equal(bk_mag_bin(0.3, 0.1, &k, &err), BK_OK); /* 2.9999999999999996 bins */
    assert_int_equal(k, 3);
    assert_int_equal(bk_mag_bin(1.0, 0.25, &k, &err), BK_OK);
    assert_int_equal(k, 4);
    assert_int_equal(bk_mag_bin(NAN, 0.1, &k, &err), BK_ERR_INVALID);
    assert_int_equal(bk_mag_bin(1.0, 0.0, &k, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "dm"));

    const double m[] = {0.25, 0.31, 2.35, -0.05, 0.049999, 0.3};
    bk_mfd mfd;
    assert_int_equal(bk_mfd_build(m, N_OF(m), 0.1, &mfd, &err), BK_OK);
    assert_int_equal(mfd.first_bin, 0);
    assert_int_equal(mfd.n_bins, 25);
    assert_int_equal(mfd.n_events, 6);
    assert_int_equal(mfd.incremental[0], 2);
    assert_int_equal(mfd.incremental[3], 3);
    assert_int_equal(mfd.incremental[24], 1);
    assert_int_equal(mfd.cumulative[0], 6);
    assert_int_equal(mfd.cumulative[1], 4);
    assert_int_equal(mfd.cumulative[4], 1);
    assert_int_equal(mfd.cumulative[24], 1);
    assert_close(bk_mfd_centre(&mfd, 24), 2.4, 0.0, 1e-12);
    bk_mfd_free(&mfd);

    assert_int_equal(bk_mfd_build(m, 0, 0.1, &mfd, &err), BK_ERR_INVALID);
    const double wide[] = {-5.0, 5.0};
    assert_int_equal(bk_mfd_build(wide, 2, 1e-7, &mfd, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "wider bin"));
}

/* Ties go to the lowest bin; the correction is rounded to whole bins. */
static void test_maxc_rules(void **state)
{
    (void)state;
    const double m[] = {1.0, 1.0, 1.1, 1.1, 1.2, 0.5};
    bk_mfd mfd;
    bk_error err = {0};
    double mc = 0.0;
    assert_int_equal(bk_mfd_build(m, N_OF(m), 0.1, &mfd, &err), BK_OK);
    assert_int_equal(bk_mc_maxc(&mfd, 0.2, &mc, &err), BK_OK);
    assert_close(mc, 1.2, 0.0, 1e-12);
    bk_mfd_free(&mfd);
    assert_int_equal(bk_mfd_build(m, N_OF(m), 0.25, &mfd, &err), BK_OK);
    assert_int_equal(bk_mc_maxc(&mfd, 0.2, &mc, &err), BK_OK); /* bins 1.0: 4, 1.25: 1 */
    assert_close(mc, 1.25, 0.0, 1e-12);
    assert_int_equal(bk_mc_maxc(&mfd, NAN, &mc, &err), BK_ERR_INVALID);
    bk_mfd_free(&mfd);
}

static void test_b_value_errors(void **state)
{
    (void)state;
    bk_b_estimate est;
    bk_error err = {0};
    const double m[] = {1.0, 1.5, 2.0, 0.2};
    assert_int_equal(bk_b_value(m, N_OF(m), 2.0, 0.1, &est, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "1 magnitude at or above Mc = 2"));
    assert_non_null(strstr(err.message, "at least 10"));
    assert_int_equal(bk_b_value(m, N_OF(m), 1.05, 0.1, &est, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "not a bin centre"));
    const double bad[] = {1.0, NAN, 2.0};
    assert_int_equal(bk_b_value(bad, N_OF(bad), 1.0, 0.1, &est, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "magnitude 1"));
    /* Nine magnitudes: under the minimum (SeismoStats' example of 24 computes). */
    const double nine[] = {2.0, 2.1, 2.3, 2.0, 2.5, 2.2, 2.0, 2.1, 2.9};
    assert_int_equal(bk_b_value(nine, N_OF(nine), 2.0, 0.1, &est, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "9 magnitudes at or above Mc = 2"));
    assert_int_equal(bk_b_value(UTSU_EXAMPLE, 10, 2.0, 0.1, &est, &err), BK_OK);
    /* Every magnitude in the Mc bin: no spread, no slope (the estimator alone would give
     * log10(e) / (dm / 2) = 8.69 +- 0). */
    const double same[] = {2.0, 2.0, 2.04, 1.96, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 1.2};
    assert_int_equal(bk_b_value(same, N_OF(same), 2.0, 0.1, &est, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "all 11 magnitudes at or above Mc = 2 fall in one bin"));
}

/* --------------------------------------------------- synthetic catalogs --- */

/* A Gutenberg-Richter sample: n_complete magnitudes >= 1.95 (bins from 2.0 up) drawn with
 * slope b, and, when lower < 1.95, the events from lower up to 1.95 detected with
 * probability 10^(-5 (1.95 - M)), interleaved as a catalog would have them.  Returns how
 * many magnitudes it wrote (at most cap). */
static size_t gr_sample(gsl_rng *rng, double b, double lower, size_t n_complete, double *out,
                        size_t cap)
{
    double mean = log10(exp(1.0)) / b;
    size_t n = 0, complete = 0;
    while (complete < n_complete && n < cap) {
        double m = lower + gsl_ran_exponential(rng, mean);
        if (m >= 1.95)
            ++complete;
        else if (gsl_rng_uniform(rng) >= pow(10.0, -5.0 * (1.95 - m)))
            continue;
        out[n++] = m;
    }
    return n;
}

#define GR_CAP 60000

static void test_synthetic_b1(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 20240613);
    double *m = malloc(GR_CAP * sizeof *m);
    size_t n = gr_sample(rng, 1.0, 1.0, 5000, m, GR_CAP);
    assert_true(n > 6000 && n < GR_CAP);
    bk_error err = {0};
    bk_mfd mfd;
    assert_int_equal(bk_mfd_build(m, n, 0.1, &mfd, &err), BK_OK);
    double mc = 0.0;
    assert_int_equal(bk_mc_maxc(&mfd, BK_MAXC_CORRECTION, &mc, &err), BK_OK);
    /* The first complete bin is 2.0; maximum curvature plus 0.2 lands at most 2 bins above. */
    assert_true(mc > 2.0 - 1e-9 && mc < 2.2 + 1e-9);
    bk_b_estimate est;
    assert_int_equal(bk_b_value(m, n, mc, 0.1, &est, &err), BK_OK);
    assert_true(est.n > 2500);
    assert_close(est.sigma, 1.0 / sqrt((double)est.n), 0.1, 0.0); /* about b / sqrt(n) */
    assert_close(est.b, 1.0, 0.0, 3.0 * est.sigma);
    /* From the true cut the estimate holds too; below it the thinned events drag b down
     * far beyond its error: the incomplete part is really there. */
    bk_b_estimate cut, low;
    assert_int_equal(bk_b_value(m, n, 2.0, 0.1, &cut, &err), BK_OK);
    assert_close(cut.b, 1.0, 0.0, 3.0 * cut.sigma);
    assert_int_equal(bk_b_value(m, n, 1.5, 0.1, &low, &err), BK_OK);
    assert_true(low.b < 1.0 - 10.0 * low.sigma);
    /* Without Utsu's half-bin correction (threshold Mc instead of Mc - dm/2) the estimate
     * would be log10(e) / (mean - Mc): well outside 3 sigma, so the check above has teeth. */
    double uncorrected = log10(exp(1.0)) / (cut.mean - cut.mc);
    assert_true(fabs(uncorrected - 1.0) > 5.0 * cut.sigma);
    bk_mfd_free(&mfd);
    free(m);
    gsl_rng_free(rng);
}

static void test_synthetic_b15(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 7);
    double *m = malloc(GR_CAP * sizeof *m);
    size_t n = gr_sample(rng, 1.5, 1.95, 5000, m, GR_CAP);
    assert_int_equal(n, 5000);
    bk_error err = {0};
    bk_b_estimate est;
    assert_int_equal(bk_b_value(m, n, 2.0, 0.1, &est, &err), BK_OK);
    assert_int_equal(est.n, 5000);
    assert_close(est.b, 1.5, 0.0, 3.0 * est.sigma);
    assert_true(est.sigma < 0.03);
    /* Mc auto on a complete sample: the 2.0 bin is the fullest. */
    bk_mfd mfd;
    double mc = 0.0;
    assert_int_equal(bk_mfd_build(m, n, 0.1, &mfd, &err), BK_OK);
    assert_int_equal(bk_mc_maxc(&mfd, 0.0, &mc, &err), BK_OK);
    assert_close(mc, 2.0, 0.0, 1e-12);
    bk_mfd_free(&mfd);
    free(m);
    gsl_rng_free(rng);
}

/* ------------------------------------------------------------ power law --- */

static void test_power_law(void **state)
{
    (void)state;
    bk_error err = {0};
    bk_power_law fit;
    /* By hand: sum ln(x / 1) = ln 2 + ln 4 + ln 8 = 6 ln 2 over 4 values (0.5 is below). */
    const double x[] = {1.0, 2.0, 4.0, 8.0, 0.5};
    assert_int_equal(bk_power_law_mle(x, N_OF(x), 1.0, &fit, &err), BK_OK);
    assert_int_equal(fit.n, 4);
    assert_close(fit.alpha, 1.0 + 4.0 / (6.0 * log(2.0)), 1e-15, 0.0);
    assert_close(fit.sigma, 4.0 / (6.0 * log(2.0)) / 2.0, 1e-15, 0.0);
    assert_int_equal(bk_power_law_mle(x, N_OF(x), 8.0, &fit, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "at least 2"));
    assert_int_equal(bk_power_law_mle(x, N_OF(x), 0.0, &fit, &err), BK_ERR_INVALID);
    const double flat[] = {3.0, 3.0};
    assert_int_equal(bk_power_law_mle(flat, 2, 3.0, &fit, &err), BK_ERR_INVALID);

    /* Pareto: density a x_m^a / x^(a+1), so alpha = a + 1. */
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 11);
    enum { N = 4000 };
    double *p = malloc(N * sizeof *p);
    for (size_t i = 0; i < N; ++i)
        p[i] = gsl_ran_pareto(rng, 1.5, 2e-3);
    assert_int_equal(bk_power_law_mle(p, N, 2e-3, &fit, &err), BK_OK);
    assert_close(fit.alpha, 2.5, 0.0, 3.0 * fit.sigma);
    assert_true(fit.sigma < 0.03);

    /* Potencies of Gutenberg-Richter magnitudes: beta = alpha - 1 = (2/3) b. */
    size_t n = gr_sample(rng, 1.0, 1.95, N, p, N);
    for (size_t i = 0; i < n; ++i)
        p[i] = pow(10.0, 1.5 * (p[i] - 0.3));
    assert_int_equal(bk_power_law_mle(p, n, pow(10.0, 1.5 * (1.95 - 0.3)), &fit, &err), BK_OK);
    assert_int_equal(fit.n, N);
    assert_close(fit.alpha - 1.0, 2.0 / 3.0, 0.0, 3.0 * fit.sigma);
    free(p);
    gsl_rng_free(rng);
}

/* ------------------------------------------------ sizes and recurrence --- */

static void test_sizes(void **state)
{
    (void)state;
    const int32_t s[] = {1, 1, 2, 3, 4, 7, 8, 16};
    bk_size_dist d;
    bk_error err = {0};
    assert_int_equal(bk_size_dist_build(s, N_OF(s), &d, &err), BK_OK);
    assert_int_equal(d.n_events, 8);
    assert_int_equal(d.max_size, 16);
    assert_close(d.mean, 42.0 / 8.0, 1e-15, 0.0);
    assert_int_equal(d.count[1], 2);
    assert_int_equal(d.count[5], 0);
    assert_int_equal(d.count[16], 1);
    const size_t log2_expected[] = {2, 2, 2, 1, 1}; /* 1, 2-3, 4-7, 8-15, 16-31 */
    assert_int_equal(d.n_log2, 5);
    for (size_t j = 0; j < 5; ++j)
        assert_int_equal(d.log2_count[j], log2_expected[j]);
    bk_size_dist_free(&d);
    const int32_t bad[] = {1, 0};
    assert_int_equal(bk_size_dist_build(bad, 2, &d, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "event 1 involved 0 blocks"));
}

static void test_recurrence(void **state)
{
    (void)state;
    /* Out of time order, with two small events in between that the threshold drops. */
    const double t[] = {6.0, 0.0, 3.0, 2.0, 10.0, 1.0, 4.0};
    const double m[] = {3.0, 2.5, 2.0, 1.0, 2.2, 2.1, 1.9};
    bk_recurrence rec;
    bk_error err = {0};
    assert_int_equal(bk_recurrence_intervals(t, m, N_OF(t), 2.0, &rec, &err), BK_OK);
    assert_int_equal(rec.n_events, 5);
    assert_int_equal(rec.n_intervals, 4);
    const double expected[] = {1.0, 2.0, 3.0, 4.0}; /* starts 0, 1, 3, 6, 10 */
    for (size_t i = 0; i < 4; ++i)
        assert_close(rec.interval[i], expected[i], 0.0, 0.0);
    assert_close(rec.t[3], 10.0, 0.0, 0.0);
    assert_close(rec.mean, 2.5, 1e-15, 0.0);
    assert_close(rec.sd, sqrt(5.0 / 3.0), 1e-15, 0.0);
    assert_close(rec.cv, sqrt(5.0 / 3.0) / 2.5, 1e-15, 0.0);
    bk_recurrence_free(&rec);
    assert_int_equal(bk_recurrence_intervals(t, m, N_OF(t), 2.4, &rec, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "2 events at or above M = 2.4"));
    assert_int_equal(bk_recurrence_intervals(t, NULL, N_OF(t), 0.0, &rec, &err), BK_OK);
    assert_int_equal(rec.n_events, 7);
    bk_recurrence_free(&rec);
    const double same[] = {1.0, 1.0, 1.0};
    assert_int_equal(bk_recurrence_intervals(same, NULL, 3, 0.0, &rec, &err), BK_ERR_INVALID);
}

/* ---------------------------------------------------- Kolmogorov-Smirnov --- */

/* scipy (github.com/scipy/scipy, read at commit 188235ae5cef),
 * scipy/special/tests/test_kolmogorov.py, TestKolmogorov:
 * scipy.special.kolmogorov is the survival function Q_KS.  test_basic: Q(0.5), Q(1), Q(2);
 * test_smallx: Q(x_k) = 1 - 10^-k for k = 1..13.  scipy checks both at rtol 1e-10. */
static void test_ks_q(void **state)
{
    (void)state;
    assert_close(bk_ks_q(0.0), 1.0, 0.0, 0.0);
    assert_close(bk_ks_q(0.5), 0.96394524366487511, 1e-10, 0.0);
    assert_close(bk_ks_q(1.0), 0.26999967167735456, 1e-10, 0.0);
    assert_close(bk_ks_q(2.0), 0.00067092525577969533, 1e-10, 0.0);
    const double x[] = {0.571173265106, 0.441027698518, 0.374219690278, 0.331392659217,
                        0.300820537459, 0.277539353999, 0.259023494805, 0.243829561254,
                        0.231063086389, 0.220135543236, 0.210641372041, 0.202290283658,
                        0.19487060742};
    for (size_t k = 0; k < N_OF(x); ++k) {
        double eps = pow(10.0, -(double)(k + 1));
        assert_close(bk_ks_q(x[k]), 1.0 - eps, 1e-10, 0.0);
        /* 1 - Q itself, to the precision the 12 digits of x allow, while it is well above
         * the rounding of Q. */
        if (k < 6)
            assert_close(1.0 - bk_ks_q(x[k]), eps, 1e-8, 0.0);
    }
    /* The familiar 5 % point (Smirnov's table: 1.36), and the critical values
     * c(alpha) = sqrt(-ln(alpha / 2) / 2) of the series' first term; the second,
     * -2 exp(-8 c^2), is 8e-7 at alpha = 0.05 and 1e-9 at 0.01. */
    assert_close(bk_ks_q(1.36), 0.049, 0.0, 0.001);
    assert_close(bk_ks_q(sqrt(-0.5 * log(0.05 / 2.0))), 0.05, 2e-5, 0.0); /* next: 8e-7 */
    assert_close(bk_ks_q(sqrt(-0.5 * log(0.01 / 2.0))), 0.01, 1e-6, 0.0);
    assert_close(bk_ks_q(3.0), 2.0 * exp(-18.0), 1e-12, 0.0);
    /* The two series meet at 1.18. */
    assert_close(bk_ks_q(1.18 - 1e-12), bk_ks_q(1.18), 1e-11, 0.0);
    /* Far below 1.18 the alternating series would need thousands of terms. */
    assert_close(bk_ks_q(0.02), 1.0, 1e-15, 0.0);
    assert_true(isnan(bk_ks_q(NAN)));
}

static void test_ks_statistic(void **state)
{
    (void)state;
    bk_ks_result ks;
    bk_error err = {0};
    /* By hand: F1 steps 1/4 at 1, 2/4 at 2 (tied), 1/4 at 3; F2 2/3 at 2 (tied), 1/3 at 4.
     * After 1: |1/4 - 0| = 1/4; after 2: |3/4 - 2/3| = 1/12; after 3: |1 - 2/3| = 1/3.
     * Stepping through the tie one value at a time would report 1/2 (2/4 vs 0). */
    const double a[] = {3.0, 2.0, 1.0, 2.0};
    const double b[] = {2.0, 4.0, 2.0};
    assert_int_equal(bk_ks_two_sample(a, 4, b, 3, &ks, &err), BK_OK);
    assert_close(ks.d, 1.0 / 3.0, 1e-15, 0.0);
    assert_close(ks.ne, 12.0 / 7.0, 1e-15, 0.0);
    double root = sqrt(12.0 / 7.0);
    assert_close(ks.lambda, (root + 0.12 + 0.11 / root) / 3.0, 1e-15, 0.0);
    assert_close(ks.p, bk_ks_q(ks.lambda), 0.0, 0.0);
    /* Symmetric in its samples, and the inputs are left as they were. */
    bk_ks_result back;
    assert_int_equal(bk_ks_two_sample(b, 3, a, 4, &back, &err), BK_OK);
    assert_close(back.d, ks.d, 0.0, 0.0);
    assert_close(a[0], 3.0, 0.0, 0.0);
    /* Equal samples, ties throughout: D = 0. */
    assert_int_equal(bk_ks_two_sample(b, 3, b, 3, &ks, &err), BK_OK);
    assert_close(ks.d, 0.0, 0.0, 0.0);
    assert_close(ks.p, 1.0, 0.0, 0.0);
    /* Disjoint samples: D = 1. */
    const double c[] = {5.0, 6.0};
    assert_int_equal(bk_ks_two_sample(a, 4, c, 2, &ks, &err), BK_OK);
    assert_close(ks.d, 1.0, 0.0, 0.0);
    assert_int_equal(bk_ks_two_sample(a, 0, c, 2, &ks, &err), BK_ERR_INVALID);
    const double nan_sample[] = {1.0, NAN};
    assert_int_equal(bk_ks_two_sample(a, 4, nan_sample, 2, &ks, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "NaN"));
}

static void test_ks_samples(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 3);
    enum { N1 = 600, N2 = 400 };
    double x1[N1], x2[N2], shifted[N2];
    for (size_t i = 0; i < N1; ++i)
        x1[i] = gsl_ran_exponential(rng, 1.0);
    for (size_t i = 0; i < N2; ++i) {
        x2[i] = gsl_ran_exponential(rng, 1.0);
        shifted[i] = gsl_ran_exponential(rng, 1.0) + 0.3;
    }
    bk_ks_result ks;
    bk_error err = {0};
    assert_int_equal(bk_ks_two_sample(x1, N1, x2, N2, &ks, &err), BK_OK);
    assert_true(ks.p > 0.05);
    assert_int_equal(bk_ks_two_sample(x1, N1, shifted, N2, &ks, &err), BK_OK);
    assert_true(ks.p < 0.05);
    /* A shift of 0.3 of an exponential: D near 1 - exp(-0.3) = 0.26. */
    assert_close(ks.d, 1.0 - exp(-0.3), 0.0, 0.06);
    gsl_rng_free(rng);
}

/* --------------------------------------------------------------- report --- */

/* A catalog in memory: its columns over rows [0, n), bksim's six fields. */
typedef struct catalog {
    size_t n;
    double *t_start, *t_end, *potency, *magnitude;
    int32_t *n_blocks;
    int8_t *complete;
} catalog;

static void catalog_init(catalog *c, size_t n)
{
    c->n = n;
    c->t_start = calloc(n, sizeof *c->t_start);
    c->t_end = calloc(n, sizeof *c->t_end);
    c->potency = calloc(n, sizeof *c->potency);
    c->magnitude = calloc(n, sizeof *c->magnitude);
    c->n_blocks = calloc(n, sizeof *c->n_blocks);
    c->complete = calloc(n, sizeof *c->complete);
    assert_true(c->t_start && c->t_end && c->potency && c->magnitude && c->n_blocks && c->complete);
}

static void catalog_free(catalog *c)
{
    free(c->t_start);
    free(c->t_end);
    free(c->potency);
    free(c->magnitude);
    free(c->n_blocks);
    free(c->complete);
}

/* Row j of c takes row i's values. */
static void catalog_copy_row(catalog *c, size_t j, size_t i)
{
    c->t_start[j] = c->t_start[i];
    c->t_end[j] = c->t_end[i];
    c->potency[j] = c->potency[i];
    c->magnitude[j] = c->magnitude[i];
    c->n_blocks[j] = c->n_blocks[i];
    c->complete[j] = c->complete[i];
}

/* The table a reader would hand over for c (columns borrowed, not copied). */
static bk_event_table table_of(const catalog *c, double t_reached)
{
    bk_event_table t = {
        .n = c->n,
        .t_start = c->t_start,
        .magnitude = c->magnitude,
        .t_end = c->t_end,
        .potency = c->potency,
        .n_blocks = c->n_blocks,
        .complete = c->complete,
        .t_reached = t_reached,
    };
    return t;
}

static char *read_text(FILE *f)
{
    char *text = written_text(f);
    assert_non_null(text);
    return text;
}

/* The number after "key": in a JSON text. */
static double json_value(const char *json, const char *key)
{
    char quoted[64];
    snprintf(quoted, sizeof quoted, "\"%s\": ", key);
    const char *at = strstr(json, quoted);
    if (!at)
        fail_msg("no %s in %s", quoted, json);
    return strtod(at + strlen(quoted), NULL);
}

static size_t count_lines(const char *path, char *first, size_t len)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[256];
    size_t n = 0;
    while (fgets(line, sizeof line, f)) {
        if (n == 0)
            snprintf(first, len, "%s", line);
        ++n;
    }
    fclose(f);
    return n;
}

#define OFFSET 0.4

/* A bksim-like catalog: Gutenberg-Richter (b = 1) with an incomplete part, Poisson starts at
 * 2 events/s, potency and magnitude related as bksim relates them, one event still running
 * at the end and one of zero potency (magnitude -inf). */
static void test_report_bksim_catalog(void **state)
{
    (void)state;
    char dir[128], tsv[256], file[512], first[256];
    assert_int_equal(make_temp_dir(dir, sizeof dir, "bksim_stats"), 0);
    snprintf(tsv, sizeof tsv, "%s/tables", dir);

    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 99);
    double *m = malloc(GR_CAP * sizeof *m);
    size_t n = gr_sample(rng, 1.0, 1.0, 3000, m, GR_CAP);
    size_t rows = n + 2;
    catalog c;
    catalog_init(&c, rows);
    double t = 0.0;
    for (size_t i = 0; i < n; ++i) {
        t += gsl_ran_exponential(rng, 0.5);
        c.t_start[i] = t;
        c.t_end[i] = t + 1e-3;
        c.potency[i] = pow(10.0, 1.5 * (m[i] - OFFSET));
        c.magnitude[i] = 2.0 / 3.0 * log10(c.potency[i]) + OFFSET;
        c.n_blocks[i] = 1 + (int32_t)(i % 7);
        c.complete[i] = 1;
    }
    catalog_copy_row(&c, n, n - 1);
    c.t_start[n] = t + 0.2, c.t_end[n] = t + 0.3;
    c.potency[n] = 0.0, c.magnitude[n] = -INFINITY, c.n_blocks[n] = 1000;
    catalog_copy_row(&c, n + 1, n - 1);
    c.t_start[n + 1] = t + 0.4, c.t_end[n + 1] = t + 0.5, c.complete[n + 1] = 0;
    c.magnitude[n + 1] = 9.0, c.n_blocks[n + 1] = 2000;
    double t_reached = t + 0.5;
    bk_event_table table = table_of(&c, t_reached);
    char name[] = "ruptures"; /* as a reader names the table it read */
    table.name = name;

    bk_stats_options opt;
    bk_stats_options_default(&opt);
    bk_stats_report *rep = NULL;
    bk_error err = {0};
    assert_int_equal(bk_stats_report_compute(&table, "catalog", &opt, &rep, &err), BK_OK);
    /* The report keeps its own copy of the table's name. */
    assert_non_null(rep->table);
    assert_true(rep->table != table.name);
    assert_string_equal(rep->table, "ruptures");
    assert_int_equal(rep->table_fallback, 0);
    assert_int_equal(rep->n_rows, rows);
    assert_int_equal(rep->n_incomplete, 1);
    assert_int_equal(rep->n_nonfinite, 1);
    assert_int_equal(rep->n_events, n);
    assert_true(rep->has_potency && rep->has_n_blocks && rep->has_complete && rep->has_t_end);
    assert_int_equal(rep->duration_from_run, 1);
    assert_close(rep->duration, t_reached, 0.0, 0.0);
    assert_close(rep->rate, (double)n / t_reached, 1e-15, 0.0);

    /* The report's numbers are the estimators' on the complete, finite events. */
    bk_mfd mfd;
    double mc = 0.0;
    assert_int_equal(bk_mfd_build(m, n, 0.1, &mfd, &err), BK_OK);
    assert_int_equal(bk_mc_maxc(&mfd, 0.2, &mc, &err), BK_OK);
    assert_int_equal(rep->mfd.n_bins, mfd.n_bins);
    assert_close(rep->mc, mc, 0.0, 1e-12);
    assert_true(mc > 2.0 - 1e-9 && mc < 2.2 + 1e-9);
    bk_b_estimate b;
    assert_int_equal(bk_b_value(m, n, mc, 0.1, &b, &err), BK_OK);
    assert_true(rep->have_b);
    assert_close(rep->b.b, b.b, 1e-12, 0.0);
    assert_int_equal(rep->n_above_mc, b.n);
    assert_close(rep->b.b, 1.0, 0.0, 3.0 * rep->b.sigma);
    /* Mc by the KS method is the estimator's (same seed), and the magnitudes are complete from
     * 1.95 up (gr_sample tapers the smaller ones): the 2.0 bin, to a bin. */
    bk_mc_ks_result mc_ks;
    assert_int_equal(bk_mc_ks(m, n, 0.1, BK_MC_KS_P_PASS, opt.bootstrap, opt.seed + 3, &mc_ks, &err), BK_OK);
    print_message("Mc: maximum curvature + 0.2 = %g, KS method %g (p = %.3f)\n", mc, rep->mc_ks.mc, rep->mc_ks.p);
    assert_true(rep->have_mc_ks);
    assert_close(rep->mc_ks.mc, mc_ks.mc, 0.0, 1e-12);
    assert_close(rep->mc_ks.mc, 2.0, 0.0, 0.1 + 1e-9);
    assert_true(rep->mc_ks.p >= BK_MC_KS_P_PASS);
    /* The potency threshold is the potency of Mc - dm/2, so the exponent sees the same
     * events as b, and beta = (2/3) b. */
    assert_true(rep->have_potency_exponent);
    assert_int_equal(rep->potency_threshold_from_mc, 1);
    assert_close(rep->magnitude_offset, OFFSET, 0.0, 1e-12);
    assert_close(rep->potency_fit.x_min, pow(10.0, 1.5 * (mc - 0.05 - OFFSET)), 1e-9, 0.0);
    assert_int_equal(rep->potency_fit.n, b.n);
    assert_close(rep->potency_fit.alpha - 1.0, 2.0 / 3.0, 0.0, 3.0 * rep->potency_fit.sigma);
    /* Thinning a Poisson process by magnitude leaves a Poisson process: CV near 1. */
    assert_true(rep->have_recurrence);
    assert_int_equal(rep->recurrence.n_events, b.n);
    assert_close(rep->recurrence.cv, 1.0, 0.0, 0.1);
    assert_close(rep->recurrence.mean, 0.5 * (double)n / (double)b.n, 0.1, 0.0);
    /* Sizes count complete events whatever their magnitude: the -inf one (1000 blocks) is in,
     * the running one (2000) is not. */
    assert_true(rep->have_sizes);
    assert_int_equal(rep->sizes.n_events, n + 1);
    assert_int_equal(rep->sizes.max_size, 1000);
    /* The two-halves test compares the binned magnitudes above Mc before and after
     * t_reached / 2. */
    assert_true(rep->have_ks);
    assert_int_equal(rep->ks.n1 + rep->ks.n2, b.n);
    double *half1 = malloc(n * sizeof *half1), *half2 = malloc(n * sizeof *half2);
    size_t n1 = 0, n2 = 0;
    for (size_t i = 0; i < n; ++i)
        if (m[i] >= mc - 0.05) {
            long k;
            assert_int_equal(bk_mag_bin(c.magnitude[i], 0.1, &k, &err), BK_OK);
            if (c.t_start[i] < 0.5 * t_reached)
                half1[n1++] = 0.1 * (double)k;
            else
                half2[n2++] = 0.1 * (double)k;
        }
    bk_ks_result ks;
    assert_int_equal(bk_ks_two_sample(half1, n1, half2, n2, &ks, &err), BK_OK);
    assert_int_equal(rep->ks.n1, n1);
    assert_close(rep->ks.d, ks.d, 0.0, 0.0);
    assert_close(rep->ks.p, ks.p, 0.0, 0.0);
    free(half1);
    free(half2);

    FILE *f = tmpfile();
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    char *json = read_text(f);
    fclose(f);
    assert_true(json[0] == '{' && strstr(json, "}\n") != NULL);
    assert_non_null(strstr(json, "{\"file\": \"catalog\", \"table\": \"ruptures\", \"table_fallback\": false, "));
    assert_close(json_value(json, "n_events"), (double)n, 0.0, 0.0);
    assert_close(json_value(json, "mc"), rep->mc, 0.0, 0.0);
    assert_close(json_value(json, "n_above_mc"), (double)b.n, 0.0, 0.0);
    assert_close(json_value(json, "b_value"), rep->b.b, 0.0, 0.0);
    assert_close(json_value(json, "b_value_error"), rep->b.sigma, 0.0, 0.0);
    assert_close(json_value(json, "rate"), rep->rate, 0.0, 0.0);
    assert_close(json_value(json, "potency_exponent"), rep->potency_fit.alpha, 0.0, 0.0);
    assert_close(json_value(json, "cv"), rep->recurrence.cv, 0.0, 0.0);
    assert_null(strstr(json, "b_value_note"));
    free(json);

    f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    char *text = read_text(f);
    fclose(f);
    assert_non_null(strstr(text, "  /ruptures (the rupture catalog): "));
    assert_non_null(strstr(text, "left out: 1 still running at the end (complete = 0), 1 without"));
    assert_non_null(strstr(text, "b-value: "));
    assert_non_null(strstr(text, "maximum curvature + 0.2"));
    assert_non_null(strstr(text, "complete events, 1 to 1000 blocks, mean "));
    free(text);
    /* The smallest size is the catalog's, not a fixed 1 (it once always said "1 to"). */
    const size_t kept[3] = {rep->sizes.count[0], rep->sizes.count[1], rep->sizes.count[2]};
    rep->sizes.count[0] = rep->sizes.count[1] = rep->sizes.count[2] = 0;
    f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    text = read_text(f);
    fclose(f);
    assert_non_null(strstr(text, "complete events, 3 to 1000 blocks, mean "));
    free(text);
    for (size_t s = 0; s < 3; ++s)
        rep->sizes.count[s] = kept[s];

    assert_int_equal(bk_stats_report_tsv(rep, tsv, &err), BK_OK);
    snprintf(file, sizeof file, "%s/mfd.tsv", tsv);
    assert_int_equal(count_lines(file, first, sizeof first), mfd.n_bins + 1);
    assert_string_equal(first, "# magnitude[1]\tincremental[1]\tcumulative[1]\n");
    snprintf(file, sizeof file, "%s/sizes.tsv", tsv);
    assert_int_equal(count_lines(file, first, sizeof first), 7 + 1 + 1); /* 1..7 and 1000 */
    snprintf(file, sizeof file, "%s/intervals.tsv", tsv);
    assert_int_equal(count_lines(file, first, sizeof first), b.n - 1 + 1);
    snprintf(file, sizeof file, "%s/potency_ccdf.tsv", tsv);
    assert_true(count_lines(file, first, sizeof first) > n / 2);
    snprintf(file, sizeof file, "%s/gr_fit.tsv", tsv);
    assert_true(path_exists(file));
    snprintf(file, sizeof file, "%s/sizes_log2.tsv", tsv);
    assert_true(path_exists(file));

    bk_stats_report_free(rep);

    /* The same columns as the /events a reader fell back to: the report says so. */
    char events[] = "events";
    table.name = events;
    table.fallback = 1;
    assert_int_equal(bk_stats_report_compute(&table, "catalog", &opt, &rep, &err), BK_OK);
    assert_string_equal(rep->table, "events");
    assert_int_equal(rep->table_fallback, 1);
    f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    text = read_text(f);
    fclose(f);
    assert_non_null(strstr(text, "  /events (the time-window catalog: the file has no /ruptures): "));
    free(text);
    f = tmpfile();
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    json = read_text(f);
    fclose(f);
    assert_non_null(strstr(json, "\"table\": \"events\", \"table_fallback\": true, "));
    free(json);
    bk_stats_report_free(rep);
    table.name = NULL;
    table.fallback = 0;

    /* A time window: only the events starting in [t_reached / 4, 3 t_reached / 4) count,
     * and the span, the rate and the halves are the window's. */
    opt.t_from = 0.25 * t_reached;
    opt.t_to = 0.75 * t_reached;
    assert_int_equal(bk_stats_report_compute(&table, "catalog", &opt, &rep, &err), BK_OK);
    size_t inside = 0;
    for (size_t i = 0; i < n; ++i)
        inside += c.t_start[i] >= opt.t_from && c.t_start[i] < opt.t_to;
    assert_true(inside > n / 3 && inside < 2 * n / 3);
    assert_int_equal(rep->n_events, inside);
    assert_int_equal(rep->n_outside, n - inside); /* the -inf one counts as non-finite */
    assert_int_equal(rep->sizes.n_events, inside);
    assert_close(rep->duration, 0.5 * t_reached, 1e-15, 0.0);
    assert_close(rep->rate, (double)inside / (0.5 * t_reached), 1e-15, 0.0);
    assert_close(rep->ks_t_split, 0.5 * t_reached, 1e-15, 0.0);
    assert_true(rep->have_b && rep->n_above_mc < b.n);
    f = tmpfile();
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    json = read_text(f);
    fclose(f);
    assert_close(json_value(json, "t_from"), opt.t_from, 0.0, 0.0);
    assert_close(json_value(json, "n_outside_window"), (double)(n - inside), 0.0, 0.0);
    free(json);
    f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    text = read_text(f);
    fclose(f);
    assert_non_null(strstr(text, "time window: events starting at t >= "));
    free(text);
    bk_stats_report_free(rep);
    /* An empty or reversed window is refused, naming the window. */
    opt.t_to = opt.t_from;
    assert_int_equal(bk_stats_report_compute(&table, "catalog", &opt, &rep, &err), BK_ERR_INVALID);
    assert_null(rep);
    assert_non_null(strstr(err.message, "time window"));
    opt.t_from = -INFINITY;
    opt.t_to = INFINITY;
    /* A given Mc. */
    opt.mc_auto = 0;
    opt.mc = 2.0;
    assert_int_equal(bk_stats_report_compute(&table, "catalog", &opt, &rep, &err), BK_OK);
    assert_close(rep->mc, 2.0, 0.0, 1e-12);
    assert_close(rep->b.b, 1.0, 0.0, 3.0 * rep->b.sigma);
    bk_stats_report_free(rep);

    /* Magnitudes 0.3 larger in the second half of the run: the halves differ. */
    for (size_t i = 0; i < n; ++i)
        if (c.t_start[i] >= 0.5 * t_reached) {
            c.potency[i] *= pow(10.0, 1.5 * 0.3);
            c.magnitude[i] = 2.0 / 3.0 * log10(c.potency[i]) + OFFSET;
        }
    assert_int_equal(bk_stats_report_compute(&table, "catalog", &opt, &rep, &err), BK_OK);
    assert_true(rep->have_ks);
    assert_true(rep->ks.p < 1e-3);
    bk_stats_report_free(rep);

    bk_mfd_free(&mfd);
    catalog_free(&c);
    free(m);
    gsl_rng_free(rng);
    assert_int_equal(remove_tree(dir), 0);
}

/* A catalog from elsewhere: only magnitude (single precision, as a reader converts it) and
 * t_start (whole seconds), and no run behind it (t_reached unknown). */
static void test_report_foreign_catalog(void **state)
{
    (void)state;
    double magnitude[N_OF(UTSU_EXAMPLE)], t_start[N_OF(UTSU_EXAMPLE)];
    for (size_t i = 0; i < N_OF(UTSU_EXAMPLE); ++i) {
        magnitude[i] = (double)(float)UTSU_EXAMPLE[i];
        t_start[i] = (double)(100 + 10 * (long long)i);
    }
    bk_event_table table = {
        .n = N_OF(UTSU_EXAMPLE), .t_start = t_start, .magnitude = magnitude, .t_reached = NAN};

    bk_stats_options opt;
    bk_stats_options_default(&opt);
    opt.mc_auto = 0;
    opt.mc = 2.0;
    bk_stats_report *rep = NULL;
    bk_error err = {0};
    /* Tested, these 24 magnitudes (most in the 2.2 bin) are no Gutenberg-Richter sample: the
     * report withholds b and says why (test_stats_fit.c tests the test). */
    assert_int_equal(bk_stats_report_compute(&table, "foreign", &opt, &rep, &err), BK_OK);
    assert_false(rep->have_b);
    assert_true(rep->have_gr_gof);
    assert_close(rep->gr_gof.d, 0.2332, 0.0, 1e-4);
    assert_true(rep->gr_gof.p < BK_GOF_LEVEL);
    assert_non_null(strstr(rep->b_note, "the 24 magnitudes at or above Mc = 2 are not Gutenberg-Richter "
                                        "distributed: KS distance 0.2332"));
    bk_stats_report_free(rep);
    /* Untested (bootstrap 0), the report gives the estimator's value. */
    opt.bootstrap = 0;
    assert_int_equal(bk_stats_report_compute(&table, "foreign", &opt, &rep, &err), BK_OK);
    assert_int_equal(rep->n_events, 24);
    assert_false(rep->have_gr_gof);
    assert_false(rep->has_potency || rep->has_n_blocks || rep->has_complete || rep->has_t_end);
    /* The single-precision magnitudes fall in the same bins: the reference value holds. */
    assert_true(rep->have_b);
    assert_close(rep->b.b, 1.1088369750721319, 1e-13, 0.0);
    assert_close(rep->t_first, 100.0, 0.0, 0.0);
    assert_close(rep->t_last, 330.0, 0.0, 0.0);
    assert_int_equal(rep->duration_from_run, 0);
    assert_close(rep->duration, 230.0, 0.0, 0.0);
    assert_true(rep->have_recurrence);
    assert_close(rep->recurrence.mean, 10.0, 1e-15, 0.0);
    assert_close(rep->recurrence.cv, 0.0, 0.0, 1e-15);
    assert_false(rep->have_potency_exponent);
    assert_non_null(strstr(rep->potency_note, "no potency field"));
    assert_false(rep->have_sizes);
    assert_non_null(strstr(rep->sizes_note, "no n_blocks field"));

    FILE *f = tmpfile();
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    char *json = read_text(f);
    fclose(f);
    assert_non_null(strstr(json, "\"potency_exponent\": null"));
    assert_non_null(strstr(json, "\"sizes\": null"));
    assert_non_null(strstr(json, "\"duration_source\": \"catalog\""));
    /* Columns made in memory name no table. */
    assert_null(rep->table);
    assert_non_null(strstr(json, "\"table\": null, \"table_fallback\": false, "));
    free(json);
    bk_stats_report_free(rep);

    /* Mc above every magnitude: the b-value is unavailable, with the reason, not NaN. */
    opt.mc = 2.8;
    assert_int_equal(bk_stats_report_compute(&table, "foreign", &opt, &rep, &err), BK_OK);
    assert_false(rep->have_b);
    assert_non_null(strstr(rep->b_note, "at least 10"));
    f = tmpfile();
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    json = read_text(f);
    fclose(f);
    assert_non_null(strstr(json, "\"b_value\": null"));
    assert_non_null(strstr(json, "\"b_value_note\": \"0 magnitudes at or above Mc = 2.8"));
    assert_null(strstr(json, "nan"));
    free(json);
    bk_stats_report_free(rep);
}

/* The report's mainshock sequences: mainshocks of magnitude 5 every 1,000 s, each followed by
 * K / (t + c)^p aftershocks (p = 1.1) over a Poisson background; the stacked fit finds the
 * decay within 2 of its errors, in text, JSON and omori.tsv, with the mainshock magnitude and
 * the window given or by default (Mc + 2; the span over the mainshock count). */
static void test_report_sequences(void **state)
{
    (void)state;
    enum { CAP = 100000 };
    double *t = malloc(CAP * sizeof *t), *m = malloc(CAP * sizeof *m);
    assert_true(t && m);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 1983);
    const double span = 20000.0, window = 500.0, c = 0.1, p = 1.1;
    size_t n = gsl_ran_poisson(rng, 0.005 * span);
    for (size_t i = 0; i < n; ++i) {
        t[i] = span * gsl_rng_uniform(rng);
        m[i] = fmin(-log10(gsl_rng_uniform_pos(rng)), 3.9);
    }
    double total = (pow(window + c, 1.0 - p) - pow(c, 1.0 - p)) / (1.0 - p);
    for (int j = 0; j < 19; ++j) {
        double t0 = 1000.0 * (j + 1);
        t[n] = t0;
        m[n++] = 5.0;
        size_t a = gsl_ran_poisson(rng, 20.0 * total);
        for (size_t i = 0; i < a && n < CAP; ++i) {
            double y = gsl_rng_uniform(rng) * total;
            t[n] = t0 + pow(pow(c, 1.0 - p) + (1.0 - p) * y, 1.0 / (1.0 - p)) - c;
            m[n++] = fmin(-log10(gsl_rng_uniform_pos(rng)), 3.9);
        }
    }
    gsl_rng_free(rng);
    bk_event_table table = {.n = n, .t_start = t, .magnitude = m, .t_reached = span};
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    opt.bootstrap = 0;
    opt.mc_auto = 0;
    opt.mc = 0.0;
    opt.mainshock_auto = 0;
    opt.mainshock = 4.96; /* its bin, 5.0 */
    opt.window = window;
    bk_stats_report *rep = NULL;
    bk_error err = {0};
    assert_int_equal(bk_stats_report_compute(&table, "sequences", &opt, &rep, &err), BK_OK);
    assert_true(rep->have_sequences);
    const bk_sequences *s = &rep->sequences;
    assert_close(s->m_main, 5.0, 0.0, 1e-12);
    assert_int_equal(s->n_mainshocks, 19);
    assert_true(s->after.have_fit && s->after.fit.decays);
    print_message("stacked: %zu aftershocks, p = %.4f +- %.4f\n", s->after.n, s->after.fit.p, s->after.fit.p_sigma);
    assert_close(s->after.fit.p, p, 0.0, 2.0 * s->after.fit.p_sigma);
    assert_true(s->after.have_residuals && s->after.residuals.p > BK_GOF_LEVEL);
    assert_false(s->before.have_fit && s->before.fit.decays);

    FILE *f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    char *text = read_text(f);
    fclose(f);
    assert_non_null(strstr(text, "mainshocks: 19 of 19 events at or above 5"));
    assert_non_null(strstr(text, "decays, 1 % level"));
    free(text);
    f = tmpfile();
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    char *json = read_text(f);
    fclose(f);
    assert_non_null(strstr(json, "\"sequences\": {\"mainshock_magnitude\": 5, "));
    assert_close(json_value(json, "n_mainshocks"), 19.0, 0.0, 0.0);
    assert_non_null(strstr(json, "\"decays\": true"));
    free(json);

    char dir[128], file[512], first[256];
    assert_int_equal(make_temp_dir(dir, sizeof dir, "bksim_sequences"), 0);
    assert_int_equal(bk_stats_report_tsv(rep, dir, &err), BK_OK);
    snprintf(file, sizeof file, "%s/omori.tsv", dir);
    assert_true(count_lines(file, first, sizeof first) > 10);
    assert_non_null(strstr(first, "rate_per_mainshock[1/s]"));
    snprintf(file, sizeof file, "%s/omori_residuals.tsv", dir);
    assert_true(count_lines(file, first, sizeof first) > s->after.n);
    bk_stats_report_free(rep);
    assert_int_equal(remove_tree(dir), 0);

    /* By default: mainshocks from Mc + 2 = 2 (background events up to 3.9 among them), windows
     * of the span over their count. */
    bk_stats_options_default(&opt);
    opt.bootstrap = 0;
    opt.mc_auto = 0;
    opt.mc = 0.0;
    assert_int_equal(bk_stats_report_compute(&table, "sequences", &opt, &rep, &err), BK_OK);
    assert_true(rep->have_sequences);
    size_t candidates = 0;
    for (size_t i = 0; i < n; ++i)
        candidates += m[i] >= 1.95;
    assert_int_equal(rep->sequences.n_candidates, candidates);
    assert_close(rep->sequences.window, span / (double)candidates, 1e-12, 0.0);
    bk_stats_report_free(rep);

    /* No event that large: a reason, not a number. */
    opt.mainshock_auto = 0;
    opt.mainshock = 7.0;
    assert_int_equal(bk_stats_report_compute(&table, "sequences", &opt, &rep, &err), BK_OK);
    assert_false(rep->have_sequences);
    assert_non_null(strstr(rep->sequences_note, "no event at or above the mainshock magnitude 7"));
    bk_stats_report_free(rep);
    opt.window = -1.0;
    assert_int_equal(bk_stats_report_compute(&table, "sequences", &opt, &rep, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "sequence window -1 s: allowed > 0"));
    opt.window = 0.0;
    opt.mainshock = 1e300;
    assert_int_equal(bk_stats_report_compute(&table, "sequences", &opt, &rep, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "mainshock magnitude 1e+300: allowed finite, within 1e15 bins"));
    free(t);
    free(m);
}

/* A chain-like catalog: GR (b = 1) from M 0 to 2 and a bump of system-size events at 3 (3 %),
 * potency P = 10^(1.5 (M - OFFSET)), duration T with P ~ T^2 and length L with P ~ L^1.5 (each
 * with 0.05 decades of scatter).  The report withholds the untruncated b (the bump), finds the
 * cutoff (Mu in [1.8, 2.0], the bump left out, b within 2 errors of 1), and gives the scaling
 * exponents within their brackets, in text, JSON and TSV. */
static void test_report_cutoff_and_scaling(void **state)
{
    (void)state;
    enum { N = 3000 };
    catalog c;
    catalog_init(&c, N);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 2019);
    double t = 0.0;
    for (size_t i = 0; i < N; ++i) {
        double m;
        if (gsl_rng_uniform(rng) < 0.03)
            m = 3.0 + gsl_ran_flat(rng, -0.1, 0.1);
        else
            do
                m = -0.05 - log10(gsl_rng_uniform_pos(rng));
            while (m >= 2.05);
        t += gsl_ran_exponential(rng, 1.0);
        c.potency[i] = pow(10.0, 1.5 * (m - OFFSET));
        c.magnitude[i] = 2.0 / 3.0 * log10(c.potency[i]) + OFFSET;
        c.t_start[i] = t;
        c.t_end[i] = t + sqrt(c.potency[i]) * pow(10.0, gsl_ran_gaussian(rng, 0.05));
        c.n_blocks[i] = (int32_t)fmax(2.0, floor(1e3 * pow(c.potency[i], 1.0 / 1.5) * pow(10.0, gsl_ran_gaussian(rng, 0.05))));
        c.complete[i] = 1;
    }
    gsl_rng_free(rng);
    bk_event_table table = table_of(&c, t + 1.0);
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    opt.bootstrap = 300;
    opt.mc_auto = 0;
    opt.mc = 0.0;
    bk_stats_report *rep = NULL;
    bk_error err = {0};
    assert_int_equal(bk_stats_report_compute(&table, "cutoff", &opt, &rep, &err), BK_OK);
    assert_false(rep->have_b);
    assert_non_null(rep->truncation);
    const bk_b_truncated_estimate *f = &rep->truncation->fit;
    print_message("truncated GR: b = %.4f +- %.4f over %g..%g, %zu above\n", f->b, f->sigma, f->mc, f->mu, f->n_above);
    assert_true(f->mu > 1.8 - 1e-9 && f->mu < 2.0 + 1e-9);
    assert_true(f->n_above > 50);
    assert_close(f->b, 1.0, 0.0, 2.0 * f->sigma);
    assert_non_null(rep->scaling);
    const bk_scaling_band *all = &rep->scaling->all;
    assert_true(all->have_duration && all->have_length);
    print_message("scaling: duration %.4f [%.4f], length %.4f [%.4f]\n", all->duration.slope, all->duration.slope_inverse,
                  all->length.slope, all->length.slope_inverse);
    assert_true(all->duration.slope <= 2.0 + 3.0 * all->duration.slope_sigma && all->duration.slope_inverse >= 2.0 - 0.05);
    assert_close(all->duration.slope, 2.0, 0.0, 0.1);
    assert_close(all->length.slope, 1.5, 0.0, 0.1);

    FILE *out = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, out, &err), BK_OK);
    char *text = read_text(out);
    fclose(out);
    assert_non_null(strstr(text, "above Mu (up to 3"));
    assert_non_null(strstr(text, "left out: a size cutoff"));
    assert_non_null(strstr(text, "moment-duration exponent (M >= Mc) against Thøgersen et al. 2019"));
    free(text);
    out = tmpfile();
    assert_int_equal(bk_stats_report_json(rep, out, &err), BK_OK);
    char *json = read_text(out);
    fclose(out);
    assert_non_null(strstr(json, "\"gr_truncated\": {\"b_value\": "));
    assert_close(json_value(json, "magnitude_top"), 3.1, 0.0, 0.1 + 1e-9);
    assert_non_null(strstr(json, "\"scaling\": {\"min_blocks\": 2, "));
    assert_null(strstr(json, "nan"));
    free(json);
    char dir[128], file[512], first[256];
    assert_int_equal(make_temp_dir(dir, sizeof dir, "bksim_cutoff"), 0);
    assert_int_equal(bk_stats_report_tsv(rep, dir, &err), BK_OK);
    snprintf(file, sizeof file, "%s/gr_truncated_fit.tsv", dir);
    assert_int_equal(count_lines(file, first, sizeof first), 1 + f->n_bins);
    snprintf(file, sizeof file, "%s/scaling_duration.tsv", dir);
    assert_true(count_lines(file, first, sizeof first) > 5);
    assert_non_null(strstr(first, "median_potency[m]"));
    snprintf(file, sizeof file, "%s/scaling_length.tsv", dir);
    assert_true(count_lines(file, first, sizeof first) > 5);
    assert_int_equal(remove_tree(dir), 0);
    bk_stats_report_free(rep);

    /* Too few synthetic samples for the range scan: a reason, not a fit. */
    opt.bootstrap = 100;
    assert_int_equal(bk_stats_report_compute(&table, "cutoff", &opt, &rep, &err), BK_OK);
    assert_null(rep->truncation);
    assert_non_null(strstr(rep->truncation_note, "at least 200 synthetic samples: --bootstrap 100"));
    bk_stats_report_free(rep);
    catalog_free(&c);
}

static void test_report_errors(void **state)
{
    (void)state;
    bk_stats_report *rep = NULL;
    bk_error err = {0};

    /* An empty catalog is a catalog: no statistics, each says why. */
    double none[1] = {0.0};
    bk_event_table table = {.n = 0, .t_start = none, .magnitude = none, .t_reached = 5.0};
    assert_int_equal(bk_stats_report_compute(&table, "empty", NULL, &rep, &err), BK_OK);
    assert_int_equal(rep->n_events, 0);
    assert_false(rep->have_b || rep->have_mfd || rep->have_recurrence || rep->have_ks);
    assert_non_null(strstr(rep->b_note, "no complete event"));
    FILE *f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    fclose(f);
    bk_stats_report_free(rep);

    /* Options are checked first, naming the option and its range. */
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    opt.mc_auto = 0;
    opt.mc = 1.05;
    assert_int_equal(bk_stats_options_check(&opt, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "multiple of the bin width"));
    assert_int_equal(bk_stats_report_compute(&table, "empty", &opt, &rep, &err), BK_ERR_INVALID);
    assert_null(rep);
    opt.mc = 1.3;
    assert_int_equal(bk_stats_options_check(&opt, &err), BK_OK);
    opt.dm = -0.1;
    assert_int_equal(bk_stats_report_compute(&table, "empty", &opt, &rep, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "0 < dm <= 10"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_b_value_reference),
        cmocka_unit_test(test_shi_bolt_reference),
        cmocka_unit_test(test_maxc_reference),
        cmocka_unit_test(test_binning),
        cmocka_unit_test(test_maxc_rules),
        cmocka_unit_test(test_b_value_errors),
        cmocka_unit_test(test_synthetic_b1),
        cmocka_unit_test(test_synthetic_b15),
        cmocka_unit_test(test_power_law),
        cmocka_unit_test(test_sizes),
        cmocka_unit_test(test_recurrence),
        cmocka_unit_test(test_ks_q),
        cmocka_unit_test(test_ks_statistic),
        cmocka_unit_test(test_ks_samples),
        cmocka_unit_test(test_report_bksim_catalog),
        cmocka_unit_test(test_report_foreign_catalog),
        cmocka_unit_test(test_report_sequences),
        cmocka_unit_test(test_report_cutoff_and_scaling),
        cmocka_unit_test(test_report_errors),
    };
    return cmocka_run_group_tests_name("stats", tests, NULL, NULL);
}
