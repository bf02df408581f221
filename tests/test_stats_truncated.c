/* The doubly truncated Gutenberg-Richter fit, its goodness of fit and the scan for the upper
 * magnitude (src/stats_truncated.c), on hand-computable cases and seeded synthetic catalogs
 * drawn from the exact binned law.
 *
 * Levels, stated (seeded, so the counts are fixed; the bounds say how far from the expected
 * value a calibrated estimator may scatter): on 400 samples of 2,000 magnitudes (b = 1,
 * bins of 0.1 from Mc = 0 to Mu = 2.0, J = 20) the true b lies within 2 sigma of the
 * estimate in at least 90 % (95.4 % expected, 5 sd below), and the standard deviation of the
 * 400 estimates agrees with the mean sigma to 10 % (its own relative error is 3.5 %); on the
 * first 100 of them the bootstrap p-values of KS and of the deviance are about uniform: p <
 * 0.05 in at most 12 (5 expected, 3 sd above), p < 0.01 in at most 4, p < 0.5 in 35 to 65;
 * their combination 2 min(p_ks, p_g) as well below 0.05 and 0.01, and below 0.5 in 20 to
 * 60.  Measured values are printed. */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "bk_test.h"
#include "bksim/stats.h"
#include "bksim/stats_truncated.h"

#define LN_10 2.30258509299404568402
#define DM 0.1

/* Continuous GR magnitudes of slope b from the lower edge of the Mc bin, kept below the upper
 * edge of the Mu bin (rejection): binned, exactly the truncated law of the header. */
static void truncated_gr(gsl_rng *rng, double b, double mc, double mu, size_t n, double *m)
{
    double lo = mc - 0.5 * DM, hi = mu + 0.5 * DM, scale = 1.0 / (b * LN_10);
    for (size_t i = 0; i < n;) {
        double x = lo + gsl_ran_exponential(rng, scale);
        if (x < hi)
            m[i++] = x;
    }
}

static gsl_rng *seeded(unsigned long seed)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(rng);
    gsl_rng_set(rng, seed);
    return rng;
}

static void expect_invalid(int rc, const bk_error *err, const char *part)
{
    assert_int_equal(rc, BK_ERR_INVALID);
    if (!strstr(err->message, part))
        print_error("message: %s\nexpected: %s\n", err->message, part);
    assert_non_null(strstr(err->message, part));
}

/* Two bins: the likelihood equation is mean = q / (1 + q), so q = mean / (1 - mean), the
 * fitted bin counts are the observed ones, and Var(j) = q / (1 + q)^2 (a Bernoulli count). */
static void check_two_bins(size_t n0, size_t n1)
{
    enum { EXTRA = 4 };
    size_t n = n0 + n1 + EXTRA;
    double *m = malloc(n * sizeof *m);
    assert_non_null(m);
    size_t i = 0;
    for (size_t k = 0; k < n0; ++k)
        m[i++] = 1.0 + 0.04 * (double)(k % 3) - 0.04; /* 0.96, 1.0, 1.04: bin 1.0 */
    for (size_t k = 0; k < n1; ++k)
        m[i++] = k == 0 ? 1.05 : 1.1; /* 1.05 is half-way: up, into bin 1.1 */
    m[i++] = 0.9;                     /* below Mc */
    m[i++] = 0.94;                    /* below Mc: bin 0.9 */
    m[i++] = 1.2;                     /* above Mu */
    m[i++] = 3.0;                     /* above Mu */
    bk_b_truncated_estimate est;
    bk_error err = {0};
    assert_int_equal(bk_b_truncated(m, n, 1.0, 1.1, DM, &est, &err), BK_OK);
    double nd = (double)(n0 + n1), mean = (double)n1 / nd, q = mean / (1.0 - mean);
    double b = 0.0 - log10(q) / DM; /* + 0 for q = 1 */
    assert_int_equal(est.n, n0 + n1);
    assert_int_equal(est.n_below, 2);
    assert_int_equal(est.n_above, 2);
    assert_int_equal(est.n_bins, 2);
    assert_close(est.mean, 1.0 + mean * DM, 1e-14, 0.0);
    assert_close(est.b, b, 1e-12, 1e-14);
    assert_close(est.sigma, 1.0 / (DM * LN_10 * sqrt(nd * q / ((1.0 + q) * (1.0 + q)))), 1e-12, 0.0);
    /* The fitted count of the bin of Mc is its observed count, 10^(a_bin - b Mc). */
    assert_close(est.a_bin, log10((double)n0) + est.b * 1.0, 1e-12, 1e-14);
    if (q < 1.0)
        assert_close(est.a, est.a_bin - log10(1.0 - q), 1e-12, 0.0);
    else
        assert_true(isnan(est.a));
    print_message("two bins %zu + %zu: b = %.15g (closed form %.15g) +- %.6g\n", n0, n1, est.b, b, est.sigma);
    /* The fit reproduces both counts: both distances vanish, and every synthetic sample's
     * (its own fit reproduces it too) ties with them. */
    bk_truncated_gof gof;
    assert_int_equal(bk_b_truncated_gof(m, n, &est, 50, 1, &gof, &err), BK_OK);
    assert_true(gof.d < 1e-14 && gof.g < 1e-12);
    assert_true(gof.p_ks == 1.0 && gof.p_g == 1.0 && gof.p == 1.0);
    free(m);
}

static void test_two_bins(void **state)
{
    (void)state;
    check_two_bins(70, 30);
    /* More in the top bin: q = 7/3 > 1, b < 0, reported as the maximum-likelihood answer. */
    check_two_bins(30, 70);
    check_two_bins(50, 50); /* q = 1, b = 0 exactly */
}

/* J = 200 on a GR sample that never reaches Mu: the truncation term q^201 is 1e-20, so the
 * estimate is Tinti & Mulargia's, q = mean / (1 + mean), and its error the geometric law's
 * (1 - q) / (dm ln10 sqrt(n q)).  Aki-Utsu's b = log10(e) / ((mean + 1/2) dm) is another
 * function of the same mean: b = log10(1 + 1 / (log10(e) / (b_AU dm) - 1/2)) / dm exactly, about
 * (b ln10 dm)^2 / 12 above it. */
static void test_untruncated_limit(void **state)
{
    (void)state;
    enum { N = 1000 };
    gsl_rng *rng = seeded(7);
    double m[N];
    for (size_t i = 0; i < N; ++i) /* bin centres, as a catalog written to dm's precision */
        m[i] = (double)(10 + (long)floor(gsl_ran_exponential(rng, 1.0 / (LN_10 * DM)) + 0.5)) * DM;
    bk_b_truncated_estimate est;
    bk_b_estimate tinti, aki;
    bk_error err = {0};
    assert_int_equal(bk_b_truncated(m, N, 1.0, 21.0, DM, &est, &err), BK_OK);
    assert_int_equal(bk_b_tinti(m, N, 1.0, DM, &tinti, &err), BK_OK);
    assert_int_equal(bk_b_value(m, N, 1.0, DM, &aki, &err), BK_OK);
    assert_int_equal(est.n, N);
    assert_int_equal(est.n_bins, 201);
    assert_close(est.b, tinti.b, 1e-10, 0.0);
    double q = pow(10.0, -tinti.b * DM);
    assert_close(est.sigma, (1.0 - q) / (DM * LN_10 * sqrt(N * q)), 1e-10, 0.0);
    assert_close(est.a, log10((double)N) + est.b * 1.0, 1e-10, 0.0);
    assert_close(est.a_bin, log10(N * (1.0 - q)) + est.b * 1.0, 1e-10, 0.0);
    double exact = log10(1.0 + 1.0 / (log10(exp(1.0)) / (aki.b * DM) - 0.5)) / DM;
    assert_close(est.b, exact, 1e-10, 0.0);
    double gap = est.b / aki.b - 1.0, leading = pow(aki.b * LN_10 * DM, 2.0) / 12.0;
    print_message("J = 200: b = %.12f, Tinti-Mulargia %.12f, Aki-Utsu %.12f (%.3g above it; leading term %.3g); "
                  "sigma %.5f, Aki b/sqrt(n) %.5f\n",
                  est.b, tinti.b, aki.b, gap, leading, est.sigma, aki.sigma_aki);
    assert_close(gap, leading, 0.1, 0.0);
    gsl_rng_free(rng);
}

/* Offsets drawn by inversion of the law's table (long double), magnitudes at bin centres. */
static void law_sample(gsl_rng *rng, double b, size_t j_top, size_t n, double *m)
{
    long double cdf[64], total = 0.0L, q = powl(10.0L, -(long double)b * DM);
    assert_true(j_top < 64);
    for (size_t j = 0; j <= j_top; ++j)
        cdf[j] = (total += powl(q, (long double)j));
    for (size_t i = 0; i < n; ++i) {
        long double u = (long double)gsl_rng_uniform(rng) * total;
        size_t j = 0;
        while (j < j_top && cdf[j] <= u)
            ++j;
        m[i] = (double)j * DM;
    }
}

/* The root is the same for q > 1: a range whose counts grow is fitted, with a negative b. */
static void test_negative_b(void **state)
{
    (void)state;
    enum { N = 3000 };
    gsl_rng *rng = seeded(12);
    double m[N];
    law_sample(rng, -0.5, 10, N, m);
    bk_b_truncated_estimate est;
    bk_error err = {0};
    assert_int_equal(bk_b_truncated(m, N, 0.0, 1.0, DM, &est, &err), BK_OK);
    bk_truncated_gof gof;
    assert_int_equal(bk_b_truncated_gof(m, N, &est, 500, 3, &gof, &err), BK_OK);
    print_message("b = -0.5: %.4f +- %.4f, GoF p = %.3f (KS %.3f, deviance %.3f)\n", est.b, est.sigma, gof.p,
                  gof.p_ks, gof.p_g);
    assert_close(est.b, -0.5, 0.0, 3.0 * est.sigma);
    assert_true(isnan(est.a) && isfinite(est.a_bin));
    assert_true(gof.p >= BK_GOF_LEVEL);
    gsl_rng_free(rng);
}

#define N_COVER 400
#define N_GOF 100
#define SAMPLE 2000

/* Coverage and the error's size over seeded samples from the law; the p-value's spread on
 * the first of them. */
static void test_calibration(void **state)
{
    (void)state;
    gsl_rng *rng = seeded(2026);
    double *m = malloc(SAMPLE * sizeof *m);
    assert_non_null(m);
    size_t covered = 0, p05[3] = {0}, p01[3] = {0}, p50[3] = {0};
    double sum = 0.0, sum2 = 0.0, sigma_sum = 0.0;
    bk_error err = {0};
    for (size_t s = 0; s < N_COVER; ++s) {
        truncated_gr(rng, 1.0, 0.0, 2.0, SAMPLE, m);
        bk_b_truncated_estimate est;
        assert_int_equal(bk_b_truncated(m, SAMPLE, 0.0, 2.0, DM, &est, &err), BK_OK);
        assert_int_equal(est.n, SAMPLE);
        assert_int_equal(est.n_above + est.n_below, 0);
        covered += fabs(est.b - 1.0) <= 2.0 * est.sigma;
        sum += est.b;
        sum2 += est.b * est.b;
        sigma_sum += est.sigma;
        if (s < N_GOF) {
            bk_truncated_gof gof;
            assert_int_equal(bk_b_truncated_gof(m, SAMPLE, &est, 200, 100 + s, &gof, &err), BK_OK);
            assert_int_equal(gof.n, SAMPLE);
            const double p[3] = {gof.p_ks, gof.p_g, gof.p};
            for (size_t k = 0; k < 3; ++k) {
                p05[k] += p[k] < 0.05;
                p01[k] += p[k] < 0.01;
                p50[k] += p[k] < 0.5;
            }
        }
    }
    double mean = sum / N_COVER, sd = sqrt((sum2 - N_COVER * mean * mean) / (N_COVER - 1)),
           sigma = sigma_sum / N_COVER;
    print_message("%d samples of %d (b = 1, J = 20): b within 2 sigma in %zu; mean b %.5f, sd %.5f, mean sigma %.5f "
                  "(ratio %.3f)\n",
                  N_COVER, SAMPLE, covered, mean, sd, sigma, sd / sigma);
    print_message("GoF on %d of them, p < 0.05 / 0.01 / 0.5: KS %zu / %zu / %zu, deviance %zu / %zu / %zu, "
                  "combined %zu / %zu / %zu\n",
                  N_GOF, p05[0], p01[0], p50[0], p05[1], p01[1], p50[1], p05[2], p01[2], p50[2]);
    assert_true(covered >= N_COVER * 9 / 10);
    assert_close(sd, sigma, 0.1, 0.0);
    assert_close(mean, 1.0, 0.0, 3.0 * sd / sqrt(N_COVER));
    for (size_t k = 0; k < 3; ++k) {
        assert_true(p05[k] <= 12);
        assert_true(p01[k] <= 4);
    }
    /* Each test's p about uniform; the combination, 2 min(p_ks, p_g), lies below 0.5 more
     * often (between 1 and 2 times 25 %, by how far the two tests agree). */
    assert_true(p50[0] >= 35 && p50[0] <= 65 && p50[1] >= 35 && p50[1] <= 65);
    assert_true(p50[2] >= 20 && p50[2] <= 60);
    free(m);
    gsl_rng_free(rng);
}

/* b = 1.0 and b = 1.2 on samples of the same size are told apart by more than 3 errors. */
static void test_tells_apart(void **state)
{
    (void)state;
    gsl_rng *rng = seeded(99);
    double *m = malloc(SAMPLE * sizeof *m);
    assert_non_null(m);
    bk_b_truncated_estimate one, other;
    bk_error err = {0};
    truncated_gr(rng, 1.0, 0.0, 2.0, SAMPLE, m);
    assert_int_equal(bk_b_truncated(m, SAMPLE, 0.0, 2.0, DM, &one, &err), BK_OK);
    truncated_gr(rng, 1.2, 0.0, 2.0, SAMPLE, m);
    assert_int_equal(bk_b_truncated(m, SAMPLE, 0.0, 2.0, DM, &other, &err), BK_OK);
    double z = (other.b - one.b) / hypot(one.sigma, other.sigma);
    print_message("b = 1.0: %.4f +- %.4f; b = 1.2: %.4f +- %.4f; %.1f sigma apart\n", one.b, one.sigma, other.b,
                  other.sigma, z);
    assert_true(z > 3.0);
    free(m);
    gsl_rng_free(rng);
}

/* A catalog of n: GR (b = 1) from Mc = 0, up to Mu = 2.0 (truncate) or unbounded, and a bump
 * of bump_fraction of the events uniform in [2.9, 3.1). */
static double *bump_catalog(gsl_rng *rng, size_t n, int truncate, double bump_fraction)
{
    double *m = malloc(n * sizeof *m);
    assert_non_null(m);
    size_t n_bump = (size_t)(bump_fraction * (double)n + 0.5), n_gr = n - n_bump;
    truncated_gr(rng, 1.0, 0.0, truncate ? 2.0 : 1e6, n_gr, m);
    for (size_t i = n_gr; i < n; ++i)
        m[i] = 2.9 + 0.2 * gsl_rng_uniform(rng);
    return m;
}

/* The untruncated fit's failure, seen by the truncated law's test over the whole range. */
static void test_bump_rejected(void **state)
{
    (void)state;
    enum { N = 5000 };
    gsl_rng *rng = seeded(31);
    double *m = bump_catalog(rng, N, 0, 0.03);
    bk_mfd mfd;
    bk_error err = {0};
    assert_int_equal(bk_mfd_build(m, N, DM, &mfd, &err), BK_OK);
    double top = bk_mfd_centre(&mfd, mfd.n_bins - 1);
    bk_mfd_free(&mfd);
    bk_b_truncated_estimate est;
    assert_int_equal(bk_b_truncated(m, N, 0.0, top, DM, &est, &err), BK_OK);
    bk_truncated_gof gof;
    assert_int_equal(bk_b_truncated_gof(m, N, &est, 1000, 5, &gof, &err), BK_OK);
    print_message("GR + 3 %% bump, Mu = %g: b = %.4f +- %.4f, D = %.4f (p %.3g), G = %.1f (p %.3g)\n", top, est.b,
                  est.sigma, gof.d, gof.p_ks, gof.g, gof.p_g);
    assert_true(gof.p < BK_GOF_LEVEL && gof.p_ks < BK_GOF_LEVEL && gof.p_g < BK_GOF_LEVEL);
    free(m);
    gsl_rng_free(rng);
}

/* A bend of the whole range, log10 of the density -0.5 M - 0.1 M^2 over 40 bins: no bump for
 * the deviance to see, the distribution function's slow drift is KS's to catch. */
static void test_bend_rejected(void **state)
{
    (void)state;
    enum { N = 3000 };
    gsl_rng *rng = seeded(53);
    double m[N];
    for (size_t i = 0; i < N;) {
        double x = gsl_ran_exponential(rng, 1.0 / (0.5 * LN_10));
        if (x < 4.0 && gsl_rng_uniform(rng) < pow(10.0, -0.1 * x * x))
            m[i++] = x - 0.05;
    }
    bk_b_truncated_estimate est;
    bk_truncated_gof gof;
    bk_error err = {0};
    assert_int_equal(bk_b_truncated(m, N, 0.0, 3.9, DM, &est, &err), BK_OK);
    assert_int_equal(bk_b_truncated_gof(m, N, &est, 500, 8, &gof, &err), BK_OK);
    print_message("bent GR: b = %.4f +- %.4f, D = %.4f (p %.3g), G = %.1f (p %.3g), p = %.3g\n", est.b, est.sigma,
                  gof.d, gof.p_ks, gof.g, gof.p_g, gof.p);
    assert_true(gof.p < BK_GOF_LEVEL);
    gsl_rng_free(rng);
}

/* The scan drops the bump and keeps the GR range: Mu at or just below 2.0 (never above: no
 * event lies between 2.05 and 2.85, so the next candidate above 2.0 includes the bump). */
static void test_scan_bump(void **state)
{
    (void)state;
    enum { N = 5000, CATALOGS = 20 };
    gsl_rng *rng = seeded(41);
    size_t within2 = 0;
    bk_error err = {0};
    for (size_t c = 0; c < CATALOGS; ++c) {
        double *m = bump_catalog(rng, N, 1, 0.03);
        bk_gr_truncation scan;
        assert_int_equal(bk_gr_truncation_scan(m, N, 0.0, DM, BK_TRUNCATED_MIN_BINS, 500, 77, &scan, &err), BK_OK);
        if (c == 0) {
            print_message("GR to 2.0 + bump at 3.0: Mu = %g after %zu candidates from %g, b = %.4f +- %.4f, "
                          "n = %zu, %zu above, D = %.4f, G = %.1f, p = %.3f\n",
                          scan.fit.mu, scan.n_tested, scan.m_top, scan.fit.b, scan.fit.sigma, scan.fit.n,
                          scan.fit.n_above, scan.gof.d, scan.gof.g, scan.gof.p);
            /* Why the test has the deviance: up to 2.9 the range holds the bump's lowest bin,
             * about the mass the law puts in the empty bins 2.1 .. 2.8, and KS barely moves. */
            bk_b_truncated_estimate est;
            bk_truncated_gof gof;
            assert_int_equal(bk_b_truncated(m, N, 0.0, 2.9, DM, &est, &err), BK_OK);
            assert_int_equal(bk_b_truncated_gof(m, N, &est, 500, 77, &gof, &err), BK_OK);
            print_message("  up to 2.9 (%zu events of the bump): D = %.4f, p_ks = %.3f; G = %.1f, p_g = %.3f\n",
                          est.n - scan.fit.n, gof.d, gof.p_ks, gof.g, gof.p_g);
            assert_true(gof.p_g < BK_GOF_LEVEL && gof.p < BK_GOF_LEVEL);
        }
        assert_true(scan.found);
        assert_true(scan.fit.mu <= 2.0 + 1e-9 && scan.fit.mu >= 1.8 - 1e-9);
        assert_true(scan.n_tested >= 4);         /* 3.1, 3.0, 2.9 (with the bump) rejected */
        assert_true(scan.fit.n_above >= N * 3 / 100); /* the bump left out */
        assert_true(scan.gof.p >= BK_GOF_LEVEL);
        assert_close(scan.fit.b, 1.0, 0.0, 3.0 * scan.fit.sigma);
        within2 += fabs(scan.fit.b - 1.0) <= 2.0 * scan.fit.sigma;
        free(m);
    }
    print_message("b within 2 sigma of 1 in %zu of %d catalogs\n", within2, CATALOGS);
    assert_true(within2 >= 17);
    gsl_rng_free(rng);
}

/* On pure GR the whole range (nearly) is kept. */
static void test_scan_pure(void **state)
{
    (void)state;
    enum { N = 5000, CATALOGS = 10 };
    gsl_rng *rng = seeded(43);
    bk_error err = {0};
    size_t most_above = 0;
    for (size_t c = 0; c < CATALOGS; ++c) {
        double *m = bump_catalog(rng, N, 0, 0.0);
        bk_gr_truncation scan;
        assert_int_equal(bk_gr_truncation_scan(m, N, 0.0, DM, BK_TRUNCATED_MIN_BINS, 500, 78, &scan, &err), BK_OK);
        assert_true(scan.found);
        assert_true(scan.fit.n_above <= 5);
        most_above = scan.fit.n_above > most_above ? scan.fit.n_above : most_above;
        assert_close(scan.fit.b, 1.0, 0.0, 3.0 * scan.fit.sigma);
        free(m);
    }
    print_message("pure GR: at most %zu of %d events above the Mu kept\n", most_above, N);
    gsl_rng_free(rng);
}

/* The same seed gives the same p, and the scan's p for its Mu is the stand-alone test's. */
static void test_reproducible(void **state)
{
    (void)state;
    enum { N = 3000 };
    gsl_rng *rng = seeded(5);
    double *m = bump_catalog(rng, N, 1, 0.03);
    bk_error err = {0};
    bk_gr_truncation scan, again;
    assert_int_equal(bk_gr_truncation_scan(m, N, 0.0, DM, BK_TRUNCATED_MIN_BINS, 300, 9, &scan, &err), BK_OK);
    assert_int_equal(bk_gr_truncation_scan(m, N, 0.0, DM, BK_TRUNCATED_MIN_BINS, 300, 9, &again, &err), BK_OK);
    assert_true(scan.found && scan.gof.p == again.gof.p && scan.fit.mu == again.fit.mu);
    bk_b_truncated_estimate est;
    assert_int_equal(bk_b_truncated(m, N, 0.0, scan.fit.mu, DM, &est, &err), BK_OK);
    assert_true(est.b == scan.fit.b && est.sigma == scan.fit.sigma && est.n == scan.fit.n);
    assert_int_equal(est.n_above, scan.fit.n_above);
    bk_truncated_gof gof;
    assert_int_equal(bk_b_truncated_gof(m, N, &est, 300, 9, &gof, &err), BK_OK);
    assert_true(gof.d == scan.gof.d && gof.p == scan.gof.p);
    /* A wider minimum range than the data reach is refused, not silently narrowed. */
    expect_invalid(bk_gr_truncation_scan(m, N, 0.0, DM, 40, 300, 9, &scan, &err), &err,
                   "the scan needs at least 40");
    free(m);
    gsl_rng_free(rng);
}

/* The cost the report would pay: 50,000 magnitudes, 40 candidates rejected in turn (a GR
 * range to 2.0 under a flat tail to 6.0), 1,000 synthetic samples each. */
static void test_scan_cost(void **state)
{
    (void)state;
    enum { N = 50000, FLAT = 8000 };
    gsl_rng *rng = seeded(47);
    double *m = malloc(N * sizeof *m);
    assert_non_null(m);
    truncated_gr(rng, 1.0, 0.0, 2.0, N - FLAT, m);
    for (size_t i = N - FLAT; i < N; ++i)
        m[i] = 2.05 + 4.0 * gsl_rng_uniform(rng);
    bk_gr_truncation scan;
    bk_error err = {0};
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(bk_gr_truncation_scan(m, N, 0.0, DM, BK_TRUNCATED_MIN_BINS, 1000, 1, &scan, &err), BK_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    print_message("50,000 magnitudes: %zu candidates from %g tested in %.3f s; Mu = %g, b = %.4f +- %.4f, p = %.3f "
                  "(KS %.3f, deviance %.3f)\n",
                  scan.n_tested, scan.m_top, seconds, scan.fit.mu, scan.fit.b, scan.fit.sigma, scan.gof.p,
                  scan.gof.p_ks, scan.gof.p_g);
    assert_true(scan.n_tested >= 38);
    assert_true(scan.found && scan.fit.mu <= 2.2 + 1e-9);
    free(m);
    gsl_rng_free(rng);
}

static void test_refusals(void **state)
{
    (void)state;
    double m[40];
    for (size_t i = 0; i < 40; ++i)
        m[i] = (double)(i % 4) * DM; /* bins 0.0 .. 0.3, 10 each */
    bk_b_truncated_estimate est;
    bk_error err = {0};
    expect_invalid(bk_b_truncated(m, 9, 0.0, 0.3, DM, &est, &err), &err,
                   "9 magnitudes in Mc = 0 .. Mu = 0.3 (bins of dm = 0.1): the truncated b-value needs at least 10");
    expect_invalid(bk_b_truncated(m, 40, 0.3, 0.5, DM, &est, &err), &err,
                   "all 10 magnitudes in Mc = 0.3 .. Mu = 0.5 fall in one bin");
    expect_invalid(bk_b_truncated(m, 40, 0.3, 0.3, DM, &est, &err), &err, "Mu = 0.3: must be above Mc = 0.3");
    expect_invalid(bk_b_truncated(m, 40, 0.3, 0.1, DM, &est, &err), &err, "Mu = 0.1: must be above Mc = 0.3");
    expect_invalid(bk_b_truncated(m, 40, 0.05, 0.3, DM, &est, &err), &err,
                   "Mc = 0.05 is not a bin centre: it must be a multiple of the bin width dm = 0.1");
    expect_invalid(bk_b_truncated(m, 40, 0.0, 0.33, DM, &est, &err), &err, "Mu = 0.33 is not a bin centre");
    expect_invalid(bk_b_truncated(m, 40, 0.0, 0.3, 0.0, &est, &err), &err, "dm = 0: must be finite and > 0");
    m[17] = NAN;
    expect_invalid(bk_b_truncated(m, 40, 0.0, 0.3, DM, &est, &err), &err, "magnitude 17 is nan: must be finite");
    bk_gr_truncation scan;
    expect_invalid(bk_gr_truncation_scan(m, 40, 0.0, DM, BK_TRUNCATED_MIN_BINS, 1000, 1, &scan, &err), &err,
                   "magnitude 17 is nan");
    m[17] = 0.1;
    bk_truncated_gof gof;
    assert_int_equal(bk_b_truncated(m, 40, 0.0, 0.3, DM, &est, &err), BK_OK);
    expect_invalid(bk_b_truncated_gof(m, 40, &est, 0, 1, &gof, &err), &err, "synthetic samples 0: allowed 1 ..");
    expect_invalid(bk_b_truncated_gof(m, 30, &est, 100, 1, &gof, &err), &err,
                   "the fit describes 40 magnitudes in Mc = 0 .. Mu = 0.3 and the sample has 30 there");
    /* The scan cannot decide without a test, nor with too few samples to resolve p = 0.005. */
    expect_invalid(bk_gr_truncation_scan(m, 40, 0.0, DM, BK_TRUNCATED_MIN_BINS, 0, 1, &scan, &err), &err,
                   "synthetic samples 0: allowed 200 ..");
    expect_invalid(bk_gr_truncation_scan(m, 40, 0.0, DM, BK_TRUNCATED_MIN_BINS, 199, 1, &scan, &err), &err,
                   "synthetic samples 199: allowed 200 ..");
    expect_invalid(bk_gr_truncation_scan(m, 40, 0.0, DM, 4, 1000, 1, &scan, &err), &err,
                   "minimum range of 4 bins: allowed 5 ..");
    expect_invalid(bk_gr_truncation_scan(m, 40, 0.0, DM, BK_TRUNCATED_MIN_BINS, 1000, 1, &scan, &err), &err,
                   "reach 0.3, 4 bins of dm = 0.1: the scan needs at least 5");
    expect_invalid(bk_gr_truncation_scan(m, 40, 0.5, DM, BK_TRUNCATED_MIN_BINS, 1000, 1, &scan, &err), &err,
                   "no magnitude at or above Mc = 0.5");
    /* Wide enough, but no range holds the events a fit needs: 9 of them, or 12 in one bin. */
    double sparse[12] = {0.0, 0.0, 0.0, 0.0, 0.1, 0.1, 0.2, 0.4, 0.9};
    expect_invalid(bk_gr_truncation_scan(sparse, 9, 0.0, DM, BK_TRUNCATED_MIN_BINS, 1000, 1, &scan, &err), &err,
                   "no range from Mc = 0 of at least 5 bins holds 10 magnitudes in two bins or more");
    for (size_t i = 0; i < 12; ++i)
        sparse[i] = 0.5;
    expect_invalid(bk_gr_truncation_scan(sparse, 12, 0.0, DM, BK_TRUNCATED_MIN_BINS, 1000, 1, &scan, &err), &err,
                   "no range from Mc = 0 of at least 5 bins holds 10 magnitudes in two bins or more");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_bins),     cmocka_unit_test(test_untruncated_limit),
        cmocka_unit_test(test_negative_b),   cmocka_unit_test(test_calibration),
        cmocka_unit_test(test_tells_apart),  cmocka_unit_test(test_bump_rejected),
        cmocka_unit_test(test_bend_rejected),
        cmocka_unit_test(test_scan_bump),    cmocka_unit_test(test_scan_pure),
        cmocka_unit_test(test_reproducible), cmocka_unit_test(test_scan_cost),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
