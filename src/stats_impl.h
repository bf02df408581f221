/* Internal: what the statistics files share beyond the public bksim/stats.h. */
#ifndef BKSIM_STATS_IMPL_H
#define BKSIM_STATS_IMPL_H

#include <stddef.h>

/* The Kolmogorov-Smirnov distance between bin offsets k >= 0 (sorted here, in place) and the
 * binned Gutenberg-Richter law P(K <= k) = 1 - q^(k + 1), evaluated at the bin centres up to
 * the largest offset (as SeismoStats' ks_test_gr; src/stats_fit.c). */
double bk_gr_distance(long *k, size_t n, double q);

#endif
