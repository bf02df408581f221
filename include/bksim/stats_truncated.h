/* The Gutenberg-Richter law on a bounded magnitude range (src/stats_truncated.c).
 *
 * A Burridge-Knopoff chain's magnitude-frequency distribution is often a power law from Mc
 * up to some magnitude and something else above it: the system-size bump, events that
 * rupture the whole chain, far more of them than the law's tail allows.  The untruncated fit
 * (bk_b_value) fails its goodness-of-fit test on such a catalog, and its b is pulled by the
 * bump.  The estimators here fit the law between Mc and an upper magnitude Mu, test it, and
 * find the largest Mu for which it describes the data.
 *
 * The law.  Magnitudes are binned as in bksim/stats.h (bins of dm centred on multiples of
 * dm).  Mc = k_mc dm and Mu = k_mu dm are bin centres; the magnitudes in the bins k_mc..k_mu
 * are bin offsets j = k - k_mc = 0..J, J = k_mu - k_mc >= 1, and
 *
 *     P(j) = q^j (1 - q) / (1 - q^(J + 1)),   q = 10^(-b dm)          (q = 1: 1 / (J + 1)),
 *
 * the binned doubly truncated exponential: Weichert's (1980, BSSA 70(4), 1337-1346) grouped
 * estimator with one completeness period, the binned form of Page's (1968, BSSA 58(3),
 * 1131-1168) truncated b-value.  Magnitudes outside [Mc, Mu] are not part of the sample
 * (counted, not used).  The maximum-likelihood q solves
 *
 *     mean(j) = E_q[j] = q / (1 - q) - (J + 1) q^(J + 1) / (1 - q^(J + 1)),
 *
 * and E_q[j] rises from 0 to J as q goes from 0 to infinity, so a mean strictly between 0
 * and J (at least two bins occupied) has exactly one root.  As J -> infinity the equation is
 * q = mean / (1 + mean), Tinti & Mulargia's (1987) binned estimator (bk_b_tinti), not the
 * Aki-Utsu b of bk_b_value, which is b_AU = log10(e) / ((mean + 1/2) dm) and lies below it by
 * a relative (b ln(10) dm)^2 / 12 to leading order.  The law is a distribution for every
 * q > 0: a range whose counts grow with magnitude has q > 1, b < 0, and that is what is
 * reported (not refused, not clipped to 0); the goodness-of-fit test says whether the law
 * describes the range at all, and a caller that wants a decaying law checks b > 0.
 *
 * Standard error: the log-likelihood is n [ln(1 - q) - ln(1 - q^(J + 1))] + ln(q) sum j, an
 * exponential family in theta = ln q with Fisher information n Var_q(j), so
 *
 *     sigma_b = 1 / (dm ln(10) sqrt(n Var_q(j))),
 *
 * with Var_q(j) of the fitted law.  As J -> infinity, Var = q / (1 - q)^2 and sigma_b =
 * (1 - q) / (dm ln(10) sqrt(n q)), Aki's b / sqrt(n) in the limit dm -> 0; J = 1 is a
 * Bernoulli count, Var = q / (1 + q)^2.
 *
 * a-values, so that the fit can be drawn over the catalog's bins.  a_bin: the fitted count of
 * the bin centred on M (Mc <= M <= Mu) is n P(j) = 10^(a_bin - b M).  a: the untruncated law
 * N(>= M) = 10^(a - b M) whose bins Mc..Mu hold those counts, a = a_bin - log10(1 - q), so
 * the fitted count in [M, Mu] is 10^(a - b M) - 10^(a - b (Mu + dm)); as J -> infinity it is
 * bk_b_value's convention log10(n) + b Mc.  a is NaN for b <= 0 (no such untruncated law).
 *
 * Every function returns BK_OK or a negative status, with a message in err that names what
 * was wrong and the allowed range. */
#ifndef BKSIM_STATS_TRUNCATED_H
#define BKSIM_STATS_TRUNCATED_H

#include <stddef.h>

#include "bksim/stats.h"

typedef struct bk_b_truncated_estimate {
    double mc, mu, dm;     /* the range's lowest and highest bin centres, the bin width */
    size_t n_bins;         /* J + 1 */
    size_t n;              /* magnitudes in bins Mc..Mu: the sample */
    size_t n_below;        /* magnitudes below Mc (ignored) */
    size_t n_above;        /* magnitudes above Mu (excluded) */
    double mean;           /* the sample's mean binned magnitude */
    double b;              /* maximum likelihood; may be <= 0 (see above) */
    double sigma;          /* from the Fisher information */
    double a_bin;          /* fitted count of the bin centred on M: 10^(a_bin - b M) */
    double a;              /* of the untruncated law with those bin counts; NaN for b <= 0 */
} bk_b_truncated_estimate;

/* The maximum-likelihood b of the finite magnitudes m[0..n) in the bins of mc..mu, both bin
 * centres (multiples of dm to within 1e-6 of a bin), mu > mc.  BK_ERR_INVALID for a
 * non-finite magnitude (anywhere in m), fewer than BK_B_MIN_EVENTS magnitudes in the range,
 * or all of them in one bin (no spread: the root is at q = 0 or infinity). */
int bk_b_truncated(const double *m, size_t n, double mc, double mu, double dm, bk_b_truncated_estimate *out,
                   bk_error *err);

/* How well the truncated law describes the sample it was fitted to. */
typedef struct bk_truncated_gof {
    size_t n;            /* magnitudes in the range */
    double d;            /* Kolmogorov-Smirnov distance to the fitted law, at the bin centres */
    double g;            /* deviance 2 sum c_j ln(c_j / (n P(j))) against any law on the bins */
    double p_ks, p_g;    /* fraction of synthetic samples, each refitted, at least that far */
    double p;            /* min(1, 2 min(p_ks, p_g)): the verdict, rejected below BK_GOF_LEVEL */
    size_t n_synthetic;
} bk_truncated_gof;

/* Goodness of fit of the truncated law by a parametric bootstrap (Clauset, Shalizi & Newman
 * 2009, section 4.1, as bk_gr_gof): n_synthetic samples of the same size drawn from the
 * fitted law, each refitted by bk_b_truncated's estimator, and the fraction whose distance
 * to their own fit is at least the sample's (to within 1e-12, relative for g, so that a tie
 * computed in another order still counts), for two distances of the bin counts c_j:
 *
 *   d, Kolmogorov-Smirnov's max over j of |F_n(j) - F(j)| (as bk_gr_gof's), sensitive to a
 *     smooth bend of the whole distribution but nearly blind to where the last per cent of
 *     the events sit: a bump in the range's top bin that holds about the mass the law puts
 *     in the empty bins below it leaves d unchanged (GR to 2.0 and 0.66 % of the events at
 *     2.9, fitted up to 2.9: p_ks = 0.44, tests/test_stats_truncated.c);
 *   g, the deviance (likelihood ratio against an arbitrary distribution on the J + 1 bins),
 *     which weighs each bin's relative excess and sees that bump and empty bins at once
 *     (p_g = 0 of 500 there) but is the weaker of the two against a gentle bend of the
 *     whole range (log10 N with a term -0.15 M^2 over 20 bins, 2,000 events: rejected at
 *     0.01 by KS in 36 of 100 samples, by the deviance in 25, by the combination in 38, in
 *     a run outside the test program).
 *
 * The verdict p is Bonferroni's combination: the law is rejected at level alpha when either
 * test is at alpha / 2, a true law at most alpha of the time (measured on true samples: p <
 * 0.01 in 1 of 100 in the test, 6 of 400 in a longer run).
 * Each synthetic sample is drawn as bin counts (gsl_ran_multinomial over the J + 1 bins) and
 * fitted and measured from its counts: O(J) per sample, whatever n.  fit: bk_b_truncated's
 * on the same m; seed: GSL MT19937's (the same seed, the same p).  n_synthetic 1 ..
 * BK_BOOTSTRAP_MAX; at most UINT_MAX magnitudes in the range. */
int bk_b_truncated_gof(const double *m, size_t n, const bk_b_truncated_estimate *fit, size_t n_synthetic,
                       unsigned long seed, bk_truncated_gof *out, bk_error *err);

/* The narrowest range the scan fits: 5 bins, half a magnitude unit at dm = 0.1.  Over fewer
 * bins a straight line in log N is hardly a claim (any smooth curve is one locally) and the
 * test has almost no power against curvature, so a range that short passing would say
 * nothing about a power law. */
#define BK_TRUNCATED_MIN_BINS 5
/* The scan decides at p >= BK_GOF_LEVEL (0.01), i.e. both tests at p >= 0.005.  With n
 * synthetic samples the smallest non-zero p of one test is 1/n, and a true law gets p = 0
 * from one of the two with probability about 2/(n + 1): below 2 / 0.01 samples the scan
 * would reject true ranges more often than the level says (and with none it cannot decide
 * at all).  The scan refuses fewer than this. */
#define BK_TRUNCATED_MIN_SYNTHETIC 200

typedef struct bk_gr_truncation {
    int found;                   /* 1: a range passed; 0: none did */
    double mc, dm;
    double m_top;                /* the centre of the highest occupied bin at or above Mc */
    size_t n_tested;             /* candidate Mu fitted and tested */
    bk_b_truncated_estimate fit; /* found: at the largest passing Mu; else at the best p */
    bk_truncated_gof gof;        /* of that fit */
} bk_gr_truncation;

/* The largest upper magnitude Mu for which the truncated law on [Mc, Mu] describes the
 * finite magnitudes m[0..n) (bk_b_truncated_gof's combined p >= BK_GOF_LEVEL).
 * Candidates: the occupied bins at or above Mc + (min_bins - 1) dm, from the highest down;
 * an empty bin is never a candidate, since the likelihood of the same events rises as Mu
 * falls to the highest of them (the maximum-likelihood Mu of a truncated law is its largest
 * value).  A candidate whose range holds all its events in one bin is skipped; one with
 * fewer than BK_B_MIN_EVENTS ends the scan.  Each candidate's test draws from a generator
 * seeded by seed afresh, so the p reported for a Mu is bk_b_truncated_gof's with the same
 * seed.  found = 0 (and BK_OK) when no candidate passes; fit and gof are then the
 * candidate with the highest p.
 *
 * Multiple testing: the scan tests up to n_tested ranges and keeps the first that passes,
 * so its Mu is "the largest Mu not rejected at 1 %", not an estimate with a stated
 * confidence.  The test has limited power against a small excess in the last bins (which is
 * why it includes the deviance: KS alone keeps a bump's lowest bin in the range), so a weak
 * bump can still be kept inside the range and Mu errs upward; a true range is falsely
 * rejected about 1 time in 100 and the scan then goes on to a smaller Mu; and the p of the
 * Mu kept is not a p-value of the whole procedure.
 *
 * mc a bin centre; dm > 0; min_bins BK_TRUNCATED_MIN_BINS .. BK_MFD_MAX_BINS;
 * n_synthetic BK_TRUNCATED_MIN_SYNTHETIC .. BK_BOOTSTRAP_MAX (the scan needs a test: a
 * report run without bootstrap samples has no truncated fit).  BK_ERR_INVALID as well when
 * the occupied bins at or above Mc span fewer than min_bins, or no candidate could be
 * fitted.  Cost: O(n) to bin the magnitudes once, then O(n_synthetic J) per candidate. */
int bk_gr_truncation_scan(const double *m, size_t n, double mc, double dm, size_t min_bins, size_t n_synthetic,
                          unsigned long seed, bk_gr_truncation *out, bk_error *err);

#endif
