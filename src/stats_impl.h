/* Internal: what the statistics files share beyond the public bksim/stats.h. */
#ifndef BKSIM_STATS_IMPL_H
#define BKSIM_STATS_IMPL_H

#include <math.h>
#include <stddef.h>

#include <gsl/gsl_rng.h>

/* x rounded to a multiple of dx, half-way up (SeismoStats' bin_to_precision: its decimal
 * clean-up is the round trip through the bin index). */
static inline double bk_stats_to_bin(double x, double dx)
{
    return floor(x / dx + 0.5 + 1e-12) * dx;
}

/* Whether x is a bin centre, a multiple of dm to within 1e-6 of a bin (and within 1e15 bins
 * of 0, where bin indices are whole numbers), the test every given Mc or Mu passes; its bin
 * in *k when it is. */
static inline int bk_stats_centre_bin(double x, double dm, long *k)
{
    double q = x / dm;
    if (!(isfinite(q) && fabs(q) <= 1e15) || fabs(q - floor(q + 0.5)) > 1e-6)
        return 0;
    *k = (long)floor(q + 0.5);
    return 1;
}

/* A bin offset k >= 0 of the binned GR law, P(K >= k) = q^k, drawn by inversion (log_q =
 * ln q < 0). */
static inline long bk_stats_draw_offset(gsl_rng *rng, double log_q)
{
    return (long)floor(log(gsl_rng_uniform_pos(rng)) / log_q);
}

/* GSL's MT19937 seeded: the generator of every bootstrap (NULL when out of memory). */
gsl_rng *bk_stats_rng(unsigned long seed);

/* The Kolmogorov-Smirnov distance between bin offsets k >= 0 (n >= 1, not modified) and the
 * binned Gutenberg-Richter law P(K <= k) = 1 - q^(k + 1), evaluated at the bin centres up to
 * the largest offset (as SeismoStats' ks_test_gr; src/stats_fit.c); NaN when out of memory. */
double bk_gr_distance(const long *k, size_t n, double q);
/* The same distance from count[j], the offsets equal to j, j = 0..top (n in all). */
double bk_gr_distance_counts(const size_t *count, long top, size_t n, double q);

#endif
