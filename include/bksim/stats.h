/* Earthquake-catalog statistics: the numbers behind `bksim stats FILE`.
 *
 * Nothing here touches a file format.  The estimators (src/stats.c) are pure numerics on
 * plain arrays; the report (src/stats_report.c) runs them on a catalog's columns in memory
 * (bk_event_table) and is printed by src/stats_print.c.  Reading a catalog from an HDF5 file
 * is the read side's (bksim/inspect.h: bk_h5_read_event_table, bk_stats_report_read), which
 * also chooses the table: the rupture catalog /ruptures by default, the time-window catalog
 * /events (or any other) by name.  The report calls each row an event whichever it is.
 *
 * Magnitude bins.  Bins of width dm are centred on multiples of dm: a magnitude M belongs to
 * bin k = floor(M/dm + 0.5 + eps), eps = BK_MAG_BIN_EPS, whose centre is k dm.  The epsilon
 * keeps catalog magnitudes written to dm's precision (2.35 stored as 2.3499999999999996)
 * in the bin their decimal text names: half-way values round up, as in SeismoStats.  Every
 * magnitude statistic below works on binned magnitudes, and "M >= Mc" means "the bin of M
 * is at or above the bin Mc", i.e. M >= Mc - dm/2 for continuous magnitudes.
 *
 * Completeness magnitude Mc.  Maximum curvature (Wiemer & Wyss 2000): the centre of the
 * bin of the incremental distribution with the most events (the lowest such bin on a tie),
 * plus a correction, +0.2 by default (Woessner & Wiemer 2005, BSSA 95(2), 684-698), which
 * is rounded to whole bins so that Mc stays a bin centre (2 bins at dm = 0.1).
 *
 * b-value.  Aki's (1965) maximum-likelihood estimator with Utsu's (1966) correction for
 * binned magnitudes:
 *
 *     b = log10(e) / (mean(M >= Mc) - (Mc - dm/2)),
 *
 * where the mean is over the binned magnitudes of the bins >= Mc.  It is the continuous
 * estimator with the threshold moved to the lower edge of the Mc bin, the form of
 * SeismoStats' UtsuBValueEstimator (not Tinti & Mulargia's exact discrete estimator).
 * Its standard error is Shi & Bolt's (1982, BSSA 72(5), 1677-1687)
 *
 *     sigma_b = ln(10) b^2 sqrt( sum (M_i - mean)^2 / (n (n - 1)) ),
 *
 * with ln(10) = 2.3026 where Shi & Bolt printed 2.30; Aki's b / sqrt(n) is given as well.
 * The a-value is log10(n) + b Mc: the catalog's count N(M >= Mc) = 10^(a - b Mc).
 *
 * Potency exponent.  For potencies P >= P_min the continuous power-law maximum-likelihood
 * estimate (e.g. Clauset, Shalizi & Newman 2009, eq. 3.1) of the density exponent,
 *
 *     alpha = 1 + n / sum ln(P_i / P_min),   sigma_alpha = (alpha - 1) / sqrt(n).
 *
 * The cumulative count falls as P^-(alpha - 1); with magnitudes m = (2/3) log10 P + const,
 * N(>= m) ~ 10^(-b m) = P^(-(2/3) b), so beta = alpha - 1 = (2/3) b.
 *
 * Two-sample Kolmogorov-Smirnov test.  D = max |F1 - F2| of the empirical distribution
 * functions, exact with ties (a tied value steps both functions before they are compared);
 * the p-value is the asymptotic Q_KS(lambda) with lambda = (sqrt(ne) + 0.12 + 0.11/sqrt(ne)) D,
 * ne = n1 n2 / (n1 + n2) (Stephens 1970; Numerical Recipes, section 14.3).
 *
 * Every function returns BK_OK or a negative status, with a message in err that names
 * what was wrong and the allowed range. */
#ifndef BKSIM_STATS_H
#define BKSIM_STATS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "bksim/status.h"

#define BK_STATS_DEFAULT_DM 0.1
#define BK_MAXC_CORRECTION 0.2
/* In units of one bin: see "Magnitude bins" above. */
#define BK_MAG_BIN_EPS 1e-9
/* A magnitude-frequency distribution of more bins than this is refused (a bin width far
 * too small for the magnitudes' range). */
#define BK_MFD_MAX_BINS 10000000L

/* -------------------------------------------------------------- binning --- */

/* The bin of m (see above); BK_ERR_INVALID for a non-finite m or dm <= 0, or when m/dm is
 * beyond +-1e15 (no integer bin index). */
int bk_mag_bin(double m, double dm, long *bin, bk_error *err);

/* The incremental and cumulative magnitude-frequency distribution. */
typedef struct bk_mfd {
    double dm;             /* bin width */
    long first_bin;        /* bin index of entry 0: its centre is first_bin * dm */
    size_t n_bins;         /* from the lowest to the highest occupied bin */
    size_t n_events;
    size_t *incremental;   /* events in bin first_bin + i */
    size_t *cumulative;    /* events in bins >= first_bin + i */
} bk_mfd;

/* The distribution of n >= 1 finite magnitudes in bins of width dm > 0.  mfd is
 * overwritten (free it with bk_mfd_free). */
int bk_mfd_build(const double *m, size_t n, double dm, bk_mfd *mfd, bk_error *err);
/* Centre of entry i. */
double bk_mfd_centre(const bk_mfd *mfd, size_t i);
void bk_mfd_free(bk_mfd *mfd);

/* ------------------------------------------------- completeness, b-value --- */

/* Mc by maximum curvature plus correction (finite; rounded to whole bins), from a built
 * distribution; *mc is a bin centre. */
int bk_mc_maxc(const bk_mfd *mfd, double correction, double *mc, bk_error *err);

typedef struct bk_b_estimate {
    double mc, dm;      /* the completeness magnitude (a bin centre) and the bin width */
    size_t n;           /* magnitudes in bins >= Mc */
    double mean;        /* their mean binned magnitude */
    double b;           /* Aki-Utsu maximum likelihood */
    double sigma;       /* Shi & Bolt standard error */
    double sigma_aki;   /* b / sqrt(n) */
    double a;           /* log10(n) + b Mc */
} bk_b_estimate;

/* Fewer magnitudes at or above Mc than this give no b-value (SeismoStats' worked example of
 * 24 still computes); fewer than BK_B_SMALL_SAMPLE carry a small-sample warning (the
 * relative error of b is about 1/sqrt(n): 14 % at 50). */
#define BK_B_MIN_EVENTS 10
#define BK_B_SMALL_SAMPLE 50

/* The b-value of the finite magnitudes m[0..n) at or above mc, which must be a bin centre
 * (a multiple of dm to within 1e-6 of a bin); BK_ERR_INVALID when fewer than
 * BK_B_MIN_EVENTS magnitudes are at or above Mc, or all of them fall in one bin (no spread
 * to estimate a slope from).  Magnitudes below Mc are ignored. */
int bk_b_value(const double *m, size_t n, double mc, double dm, bk_b_estimate *out,
               bk_error *err);
/* Shi & Bolt's standard error of b for the magnitudes m[0..n) as given (no binning, no
 * threshold), n >= 2: ln(10) b^2 sqrt(sum (m_i - mean)^2 / (n (n - 1))). */
int bk_shi_bolt(const double *m, size_t n, double b, double *sigma, bk_error *err);

/* The binned maximum-likelihood b of Tinti & Mulargia (1987), SeismoStats' classic
 * estimator: beta = ln(1 + dm / mean(M - Mc)) / dm over M >= Mc - dm/2 (Mc need not be a
 * bin centre), b = beta / ln 10, Shi & Bolt's error with the population sd over
 * sqrt(n - 1) (NaN for one magnitude).  At least 1 magnitude and a positive mean excess. */
int bk_b_tinti(const double *m, size_t n, double mc, double dm, bk_b_estimate *out, bk_error *err);

/* b-positive (van der Elst 2021; src/stats_positive.c) as SeismoStats computes it: the events
 * M >= Mc - dm/2 in time order (t NULL: array order; ties in array order), the differences
 * of successive magnitudes at least dMc - dm/2, rounded to dm, fitted by bk_b_tinti with
 * reference dMc (SeismoStats' default dMc is dm). */
typedef struct bk_b_positive_estimate {
    double mc, dmc;
    size_t n_events;        /* events at or above Mc */
    bk_b_estimate fit;      /* of the differences: fit.n of them, fit.b, fit.sigma */
    double a;               /* log10 of their count over the fraction of the span the kept
                               pairs cover (SeismoStats' APositiveAValueEstimator; NaN
                               without times) */
} bk_b_positive_estimate;
int bk_b_positive(const double *m, const double *t, size_t n, double mc, double dm, double dmc,
                  bk_b_positive_estimate *out, bk_error *err);

/* Mc by b-value stability (Woessner & Wiemer 2005; src/stats_mc.c) as SeismoStats computes
 * it: candidates from the smallest magnitude up in steps of dm (the last steps - 1 left out,
 * steps = ceil(range / dm)); the first whose bk_b_tinti b differs from the sum of the
 * b-values at Mc, Mc + dm, ... below Mc + range (and at most the largest magnitude) over
 * steps by at most its own error. */
typedef struct bk_mc_stability {
    int found;
    double mc, b, diff;     /* the Mc, its b, |b_avg - b| / sigma there */
    double range;
    size_t steps, n_tested;
} bk_mc_stability;
int bk_mc_b_stability(const double *m, size_t n, double dm, double range, bk_mc_stability *out, bk_error *err);

/* Mc by the Kolmogorov-Smirnov method (src/stats_mc.c) as SeismoStats' estimate_mc_ks: the
 * first candidate (from the smallest magnitude up in steps of dm) whose magnitudes at or
 * above it pass a KS test against their bk_b_tinti GR fit at p >= p_pass, p the fraction of
 * n_synthetic samples from that law at least as far from it.  out holds the last candidate
 * tested (the passing one when found). */
#define BK_MC_KS_P_PASS 0.1 /* SeismoStats' default */
typedef struct bk_mc_ks_result {
    int found;
    double mc, b, d, p;
    size_t n, n_tested;
} bk_mc_ks_result;
int bk_mc_ks(const double *m, size_t n, double dm, double p_pass, size_t n_synthetic, unsigned long seed,
             bk_mc_ks_result *out, bk_error *err);
/* The KS distance of bk_mc_ks (and SeismoStats' ks_test_gr) between the magnitudes at or
 * above Mc and the binned GR law of slope b from Mc. */
int bk_gr_ks_distance(const double *m, size_t n, double mc, double dm, double b, double *d, bk_error *err);

/* ------------------------------------------- goodness of fit, bootstrap --- */

/* Bootstrap sizes allowed; the report's default, and its seed (any fixed value: reports are
 * reproducible). */
#define BK_BOOTSTRAP_MAX 1000000
#define BK_BOOTSTRAP_DEFAULT 1000
#define BK_BOOTSTRAP_SEED 20261127UL
/* A fit whose goodness-of-fit p-value is below this does not describe its sample: the
 * report gives no parameter for it (Clauset et al. reject at 0.1, a test of the fit; here
 * the bar is for withholding a number, and a true law passes it 99 times in 100). */
#define BK_GOF_LEVEL 0.01

typedef struct bk_gof {
    size_t n;            /* values the fit describes (at or above its threshold) */
    double d;            /* Kolmogorov-Smirnov distance between them and the fitted law */
    double p;            /* fraction of n_synthetic samples drawn from the fitted law, each
                            refitted, at least d from their own fit */
    size_t n_synthetic;
} bk_gof;

/* The binned Gutenberg-Richter law of fit (bk_b_value's, on m[0..n)) against the magnitudes
 * it was fitted to: above Mc the bin offsets are geometric, P(k) = (1 - q) q^k with
 * q = 10^(-b dm); synthetic samples of the same size are drawn from it and refitted by the
 * same estimator.  seed: GSL MT19937's. */
int bk_gr_gof(const double *m, size_t n, const bk_b_estimate *fit, size_t n_synthetic, unsigned long seed,
              bk_gof *out, bk_error *err);

/* How b and Mc are estimated on a resample: Mc by maximum curvature plus mc_correction
 * (mc_auto) or the given mc, in bins of dm. */
typedef struct bk_b_options {
    double dm;
    int mc_auto;
    double mc, mc_correction;
} bk_b_options;

typedef struct bk_b_spread {
    size_t n_resamples, n_used; /* resamples drawn; those that gave a b-value */
    double b_sigma;             /* standard deviation of b over them */
    double mc_sigma;            /* of Mc (0 for a given Mc) */
} bk_b_spread;

/* Bootstrap standard errors of b and Mc: the n magnitudes resampled with replacement
 * n_resamples times, Mc and b estimated on each as opt says. */
int bk_b_bootstrap(const double *m, size_t n, const bk_b_options *opt, size_t n_resamples, unsigned long seed,
                   bk_b_spread *out, bk_error *err);

/* ------------------------------------------------------- potency exponent --- */

typedef struct bk_power_law {
    double x_min;   /* the threshold */
    size_t n;       /* values >= x_min */
    double alpha;   /* density exponent: p(x) ~ x^-alpha */
    double sigma;   /* (alpha - 1) / sqrt(n) */
} bk_power_law;

/* The exponent of the values x >= x_min > 0 (values below are ignored, NaN is refused);
 * BK_ERR_INVALID when fewer than 2 values are at or above x_min, or all equal x_min. */
int bk_power_law_mle(const double *x, size_t n, double x_min, bk_power_law *out,
                     bk_error *err);
/* The power law of fit (x_min fixed) against the values x >= x_min it describes, as
 * bk_gr_gof: synthetic samples drawn from it and refitted by bk_power_law_mle's estimator. */
int bk_power_law_gof(const double *x, size_t n, const bk_power_law *fit, size_t n_synthetic,
                     unsigned long seed, bk_gof *out, bk_error *err);

/* ------------------------------------------------------------------ sizes --- */

typedef struct bk_size_dist {
    size_t n_events;
    int32_t max_size;
    double mean;
    size_t *count;        /* count[s], s = 0..max_size: events that involved s blocks */
    size_t n_log2;
    size_t *log2_count;   /* bin j: sizes 2^j .. 2^(j+1) - 1 */
} bk_size_dist;

/* The distribution of n >= 1 event sizes (blocks per event, each >= 1). */
int bk_size_dist_build(const int32_t *size, size_t n, bk_size_dist *out, bk_error *err);
void bk_size_dist_free(bk_size_dist *dist);

/* ------------------------------------------------------------- recurrence --- */

typedef struct bk_recurrence {
    double m_min;       /* the magnitude threshold (-inf: every event) */
    size_t n_events;    /* events at or above it */
    double mean;        /* mean interval between their consecutive starts, s */
    double sd;          /* sample standard deviation of the intervals, s */
    double cv;          /* sd / mean */
    size_t n_intervals; /* n_events - 1 */
    double *interval;   /* the intervals in time order */
    double *t;          /* the start of the later event of each interval */
} bk_recurrence;

/* Intervals between the sorted start times t of the events with m >= m_min (m may be NULL:
 * every event).  NaN times or magnitudes are refused; at least 3 events are needed (2
 * intervals for a standard deviation) and the mean interval must be > 0. */
int bk_recurrence_intervals(const double *t, const double *m, size_t n, double m_min,
                            bk_recurrence *out, bk_error *err);
void bk_recurrence_free(bk_recurrence *rec);

/* ------------------------------------------------------ interevent times --- */

/* Thresholds of the report: Mc, Mc + 0.5, Mc + 1, Mc + 1.5, each with at least
 * BK_INTEREVENT_MIN_EVENTS events; logarithmic bins per decade of theta. */
#define BK_INTEREVENT_THRESHOLDS 4
#define BK_INTEREVENT_STEP 0.5
#define BK_INTEREVENT_MIN_EVENTS 30
#define BK_INTEREVENT_BINS_PER_DECADE 5

typedef struct bk_interevent {
    double m_min;            /* the threshold */
    size_t n_events, n_intervals;
    double rate;             /* R = events at or above m_min over the observed span, 1/s */
    double cv;               /* of the intervals */
    size_t n_zero;           /* zero intervals (events starting together): not in the fit or bins */
    double gamma_shape, gamma_shape_sigma, gamma_scale; /* ML fit of theta = tau R */
    size_t n_bins;
    double *theta;           /* geometric centres of the logarithmic bins */
    double *density;         /* per unit theta: count / (positive intervals x bin width) */
} bk_interevent;

/* Interevent times of the events with m >= m_min (m may be NULL: every event) over a span
 * of duration seconds, rescaled by their rate (Corral 2004; src/stats_interevent.c): CV,
 * gamma fit, density on bins_per_decade logarithmic bins.  At least 3 events and 2
 * positive intervals that differ. */
int bk_interevent_build(const double *t, const double *m, size_t n, double m_min, double duration,
                        size_t bins_per_decade, bk_interevent *out, bk_error *err);
void bk_interevent_free(bk_interevent *ie);

/* ------------------------------------------------------------ Omori-Utsu --- */

#define BK_OMORI_MIN_EVENTS 10
/* p is sought in (BK_OMORI_P_LOWEST, BK_OMORI_P_HIGHEST): a rate that rises or falls faster
 * is no Omori sequence, and the fit ends at the bound. */
#define BK_OMORI_P_LOWEST (-1.0)
#define BK_OMORI_P_HIGHEST 5.0
/* The 99 % quantile of chi-square with 2 degrees of freedom: the likelihood ratio of the
 * Omori-Utsu law against a constant rate (K, c, p against one rate) above it is a decay. */
#define BK_OMORI_LR_CHI2_2DOF_1PC 9.2103403719761836

typedef struct bk_omori {
    size_t n;
    double start, end;        /* s after the mainshock: the window fitted */
    double k, c, p;           /* n(t) = K / (t + c)^p, t from the mainshock; K in 1/s^(1-p) */
    double k_sigma, c_sigma, p_sigma; /* from the observed information (NaN when singular) */
    double log_likelihood;
    double lr;                /* 2 (l - l_constant) */
    int decays;               /* lr above BK_OMORI_LR_CHI2_2DOF_1PC and p > 0 */
} bk_omori;

/* Maximum-likelihood Omori-Utsu fit (Ogata 1983; src/stats_omori.c) of n >= BK_OMORI_MIN_EVENTS
 * times t (s after the mainshock, in [start, end], any order). */
int bk_omori_fit(const double *t, size_t n, double start, double end, bk_omori *out, bk_error *err);

/* Ogata's residual check of a fit (SAPP's respoi): the times transformed by the fitted
 * cumulative rate, tau_i = K int_start^t_i (u + c)^-p du, are a unit-rate Poisson process on
 * [0, tau_end] when the law holds; d and p are the one-sample KS test of tau / tau_end against
 * the uniform law (asymptotic p, conservative since the fit used the same times). */
typedef struct bk_omori_residuals {
    size_t n;
    double *tau;      /* sorted transformed times (malloc'ed) */
    double tau_end;   /* the fitted number of events in the window */
    double d, p;
} bk_omori_residuals;
int bk_omori_residual_check(const double *t, size_t n, const bk_omori *fit, bk_omori_residuals *out, bk_error *err);
void bk_omori_residuals_free(bk_omori_residuals *res);

/* ------------------------------------------------- mainshock sequences --- */

/* Sequences around mainshocks (src/stats_sequences.c), stacked in the superposed-epoch way:
 * a mainshock is an event of magnitude >= m_main that is the largest within +-window of its
 * start (an equal magnitude earlier in the window takes precedence) and whose +-window lies
 * inside the observed span [span_start, span_end]; its aftershocks are the events of
 * magnitude >= m_min starting in (t, t + window], its foreshocks those in [t - window, t),
 * as offsets from t.  The offsets of every mainshock are fitted together by bk_omori_fit
 * (K is then the sum over mainshocks) and each sequence with enough aftershocks alone;
 * both stacks get Ogata's residual check.  Other events of magnitude >= m_main inside a
 * window (smaller than its mainshock) stay in it with their own sequences: the stack is of
 * everything that follows a mainshock, as in the catalogs the law was found in. */
#define BK_SEQUENCE_MAINSHOCK_STEP 2.0 /* the report's default m_main: Mc + 2 */

typedef struct bk_sequence {
    double t_main, m_main;
    size_t n_after, n_before;
    int have_fit;              /* its own aftershocks fitted (>= BK_OMORI_MIN_EVENTS of them) */
    bk_omori fit;
} bk_sequence;

typedef struct bk_sequence_stack {
    size_t n;                  /* offsets in every window */
    double *offset;            /* s from the mainshocks, > 0, <= window (malloc'ed) */
    int have_fit;
    bk_omori fit;              /* over [0, window] */
    int have_residuals;
    bk_omori_residuals residuals;
    char note[BK_ERROR_MESSAGE_LEN]; /* why there is no fit */
} bk_sequence_stack;

typedef struct bk_sequences {
    double m_main, m_min, window;
    size_t n_candidates;       /* events at or above m_main */
    size_t n_not_largest;      /* a larger (or equal, earlier) event within +-window */
    size_t n_at_edges;         /* +-window not inside the observed span */
    size_t n_simultaneous;     /* events starting at a mainshock's instant: in neither stack */
    size_t n_mainshocks;
    bk_sequence *sequence;     /* the mainshocks in time order (malloc'ed) */
    size_t n_fitted;           /* sequences with have_fit */
    bk_sequence_stack after, before;
} bk_sequences;

/* t, m: n events in any order (finite).  window > 0 s; span_start < span_end. */
int bk_sequences_build(const double *t, const double *m, size_t n, double m_min, double m_main, double window,
                       double span_start, double span_end, bk_sequences *out, bk_error *err);
void bk_sequences_free(bk_sequences *s);

/* ------------------------------------------------------ Kolmogorov-Smirnov --- */

/* The Kolmogorov survival function Q_KS(lambda) = 2 sum_{j>=1} (-1)^(j-1) exp(-2 j^2 lambda^2)
 * (its theta-function form below lambda = 1.18, where that series converges slowly);
 * 1 for lambda <= 0, NaN for NaN. */
double bk_ks_q(double lambda);

typedef struct bk_ks_result {
    size_t n1, n2;
    double d;        /* the statistic */
    double ne;       /* n1 n2 / (n1 + n2) */
    double lambda;   /* (sqrt(ne) + 0.12 + 0.11 / sqrt(ne)) d */
    double p;        /* Q_KS(lambda) */
} bk_ks_result;

/* Two samples of n1, n2 >= 1 values (not NaN; neither array is modified). */
int bk_ks_two_sample(const double *x1, size_t n1, const double *x2, size_t n2,
                     bk_ks_result *out, bk_error *err);

/* ----------------------------------------------------------------- report --- */

typedef struct bk_stats_options {
    double dm;             /* bin width, > 0 */
    int mc_auto;           /* 1: maximum curvature plus mc_correction; 0: mc below */
    double mc;             /* a multiple of dm */
    double mc_correction;  /* BK_MAXC_CORRECTION */
    /* s: only events starting in [t_from, t_to) count (a spin-up left out); default the
     * whole catalog (-inf, +inf) */
    double t_from, t_to;
    /* Synthetic samples of the goodness-of-fit tests and resamples of the bootstrap errors
     * (BK_BOOTSTRAP_DEFAULT; 0: neither, the fits reported untested), and their seed. */
    size_t bootstrap;
    unsigned long seed;
    /* Mainshock sequences: mainshocks of magnitude >= mainshock (its bin), or Mc +
     * BK_SEQUENCE_MAINSHOCK_STEP when mainshock_auto; windows of +-window s, or (window 0)
     * the observed span over the number of events at or above the mainshock magnitude. */
    int mainshock_auto;
    double mainshock;
    double window;
} bk_stats_options;

void bk_stats_options_default(bk_stats_options *opt);
/* BK_ERR_INVALID with a message naming the option and its allowed range. */
int bk_stats_options_check(const bk_stats_options *opt, bk_error *err);

/* An earthquake catalog's columns in memory, one entry per event (a rupture of /ruptures,
 * an event of /events, a row of another program's table): t_start and magnitude always, the
 * others NULL where the catalog has no such field. */
typedef struct bk_event_table {
    size_t n;
    double *t_start, *magnitude;  /* s, 1 */
    double *t_end, *potency;      /* s, m */
    double *max_slip_rate;        /* m/s */
    int32_t *n_blocks;
    int8_t *complete;             /* 0: still running at the end of the run */
    double t_reached;             /* s: the simulated span of the run that wrote the catalog
                                     (runs start at t = 0), NaN when that is not known */
    char *name;                   /* the table the columns were read from ("ruptures",
                                     "events", ...; malloc'ed), NULL for columns made in memory */
    int fallback;                 /* 1: the file had no /ruptures, so the default read /events */
} bk_event_table;

/* Free the columns and zero the table. */
void bk_event_table_free(bk_event_table *table);

/* The rows every catalog statistic uses (src/stats_select.c): complete (complete != 0 where
 * the field exists), with a finite t_start and magnitude, starting in [t_from, t_to); the
 * others counted by why.  The observed span: from t = 0 to the run's t_reached when the table
 * has one at or after the last kept start, else from the first kept start to the latest
 * t_end (or start) of a row starting in the window; clipped to the window (0 without rows). */
typedef struct bk_event_selection {
    size_t n_events, n_incomplete, n_nonfinite, n_outside;
    size_t *index;            /* the kept rows, in table order (malloc'ed) */
    double t_first, t_last;   /* of the kept starts (0 without rows) */
    double m_min, m_max;      /* of their magnitudes (0 without rows) */
    double span_start, duration;
    int duration_from_run;    /* 1: the span is the run's */
} bk_event_selection;
int bk_event_select(const bk_event_table *table, double t_from, double t_to, bk_event_selection *out,
                    bk_error *err);
void bk_event_selection_free(bk_event_selection *selection);

/* Everything `bksim stats` reports about one catalog.  A statistic the catalog cannot
 * support (too few events above Mc, no potency field...) has have_* = 0 and the reason in
 * its *_note; the report as a whole fails only when the file is no catalog. */
struct bk_scaling;        /* bksim/stats_scaling.h */
struct bk_gr_truncation;  /* bksim/stats_truncated.h */

typedef struct bk_stats_report {
    char *path;
    char *table;           /* the catalog's table (bk_event_table's name), NULL when unnamed */
    int table_fallback;    /* 1: /events read because the file has no /ruptures */
    bk_stats_options options;
    /* the columns found in the table */
    int has_t_end, has_potency, has_n_blocks, has_complete;
    size_t n_rows;         /* rows of the table */
    size_t n_incomplete;   /* complete = 0: still running at the end, left out */
    size_t n_nonfinite;    /* complete rows without a finite t_start and magnitude */
    size_t n_outside;      /* complete rows starting outside [t_from, t_to) */
    size_t n_events;       /* the rest: the events every magnitude statistic uses */
    /* the analysed events, in file order */
    double *t_start, *magnitude, *potency;  /* potency NULL without the field */
    double *t_end;         /* NULL without the field */
    int32_t *n_blocks;     /* NULL without the field */
    double t_first, t_last;
    double span_start;     /* s: where the observed span begins (0 for a run, else t_first),
                            * t_from when that is later */
    double duration;       /* s: the observed span, the run's t_reached (else t_last - t_first)
                            * clipped to [t_from, t_to) */
    int duration_from_run; /* 1: the root attribute t_reached of a bksim output */
    double rate;           /* n_events / duration, 1/s (0 when the duration is 0) */
    double m_min, m_max;
    int have_mfd;
    bk_mfd mfd;
    int have_mc;
    double mc;
    size_t n_above_mc;
    double rate_above_mc;
    int have_b;
    bk_b_estimate b;
    char b_note[BK_ERROR_MESSAGE_LEN];
    int b_small_sample;            /* fewer than BK_B_SMALL_SAMPLE events above Mc */
    int have_gr_gof;               /* the GR fit tested (a b was estimated, bootstrap > 0) */
    bk_gof gr_gof;                 /* when p < BK_GOF_LEVEL, have_b is 0 and b_note says why */
    int have_b_spread;
    bk_b_spread b_spread;          /* bootstrap errors of b and Mc */
    /* GR on [Mc, Mu], Mu the largest magnitude whose range passes the fit test (NULL: see
     * the note; needs options.bootstrap >= BK_TRUNCATED_MIN_SYNTHETIC) */
    struct bk_gr_truncation *truncation;
    char truncation_note[BK_ERROR_MESSAGE_LEN];
    int have_b_positive;
    bk_b_positive_estimate b_positive; /* at Mc, dMc = dm, in start-time order */
    char b_positive_note[BK_ERROR_MESSAGE_LEN];
    int have_mc_stability;
    bk_mc_stability mc_stability;  /* Mc by b-value stability, range 0.5 (beside maximum curvature) */
    char mc_stability_note[BK_ERROR_MESSAGE_LEN];
    int have_mc_ks;
    bk_mc_ks_result mc_ks;         /* Mc by the KS method, p >= BK_MC_KS_P_PASS, options.bootstrap samples */
    char mc_ks_note[BK_ERROR_MESSAGE_LEN];
    int have_potency_exponent;
    bk_power_law potency_fit;
    int have_potency_gof;
    bk_gof potency_gof;            /* when p < BK_GOF_LEVEL, have_potency_exponent is 0 */
    int potency_threshold_from_mc; /* 1: P_min is the potency of Mc - dm/2 */
    double magnitude_offset;       /* M - (2/3) log10 P when that holds for every event */
    char potency_note[BK_ERROR_MESSAGE_LEN];
    int have_recurrence;
    bk_recurrence recurrence;      /* events at or above Mc */
    char recurrence_note[BK_ERROR_MESSAGE_LEN];
    size_t n_interevent;           /* thresholds with interevent statistics (0: see the note) */
    bk_interevent interevent[BK_INTEREVENT_THRESHOLDS];
    char interevent_note[BK_ERROR_MESSAGE_LEN];
    int have_sizes;
    bk_size_dist sizes;            /* complete events, any magnitude */
    char sizes_note[BK_ERROR_MESSAGE_LEN];
    struct bk_scaling *scaling;    /* potency against duration and length (NULL: see the note) */
    char scaling_note[BK_ERROR_MESSAGE_LEN];
    int have_sequences;
    bk_sequences sequences;        /* mainshocks, stacked aftershocks and foreshocks (>= Mc) */
    char sequences_note[BK_ERROR_MESSAGE_LEN];
    int have_ks;
    bk_ks_result ks;               /* magnitudes >= Mc, first vs second half of the time span */
    double ks_t_split;
    char ks_note[BK_ERROR_MESSAGE_LEN];
} bk_stats_report;

/* Compute everything from a catalog's columns (opt NULL: the defaults); source names the
 * catalog in the report and in messages, and the table's name and fallback flag are copied
 * into it.  *out is allocated (bk_stats_report_free).  Fails
 * only on bad options or lack of memory: a statistic the catalog cannot support is noted in
 * the report. */
int bk_stats_report_compute(const bk_event_table *table, const char *source,
                            const bk_stats_options *opt, bk_stats_report **out, bk_error *err);
void bk_stats_report_free(bk_stats_report *report);
/* The human-readable report; BK_ERR_IO when writing fails. */
int bk_stats_report_text(const bk_stats_report *report, FILE *out, bk_error *err);
/* One JSON object (and a newline). */
int bk_stats_report_json(const bk_stats_report *report, FILE *out, bk_error *err);
/* Tab-separated tables for gnuplot in dir (created when missing; one level), each with a
 * '#' header line of column names and units: mfd.tsv (magnitude, incremental, cumulative),
 * gr_fit.tsv (the fitted cumulative count 10^(a - b M) from Mc up), sizes.tsv (n_blocks,
 * count; sizes that occur), sizes_log2.tsv (sizes 2^j..2^(j+1)-1, count, count per size),
 * intervals.tsv (t_start, interval of the events >= Mc), interevent.tsv (threshold, theta,
 * density, gamma fit; a block per threshold), potency_ccdf.tsv (potency, events at or above it).  A table whose statistic is unavailable is not written. */
int bk_stats_report_tsv(const bk_stats_report *report, const char *dir, bk_error *err);

#endif
