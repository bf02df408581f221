/* Scaling relations of a rupture catalog (issue 33 part 6; src/stats_scaling.c): potency
 * against duration and against rupture length (blocks), as power laws fitted on log-log
 * axes, over the whole range M >= Mc and in magnitude bands above it, with a reading of the
 * moment-duration exponent beside Thøgersen et al. (GRL 46, 12805, 2019).
 *
 * The fit.  For pairs (x_i, y_i) with both finite and > 0 (the others are skipped and
 * counted), the exponent of y ~ x^gamma is estimated on u = log10 x, v = log10 y by
 *
 *   - ordinary least squares of v on u (the headline): slope = Suv / Suu, its classical
 *     standard error sqrt(SSE / ((n - 2) Suu)), the intercept and its error;
 *   - the reduced (standardised) major axis, slope_rma = sign(r) sqrt(Svv / Suu), the
 *     geometric mean of the two least-squares slopes (Warton, Wright, Falster & Westoby,
 *     Biol. Rev. 81, 259, 2006), with the large-sample error |slope_rma| sqrt((1 - r^2) /
 *     (n - 2)) of the test Warton et al. use (Pitman 1939), numerically equal to the OLS
 *     error;
 *   - the inverse slope, 1 / (OLS of u on v) = Svv / Suv = slope / r^2.
 *
 * Why OLS is the headline.  Moment-duration studies, Thøgersen et al. among them, report
 * least squares of log moment on log duration: the headline is the number they can be set
 * beside.  And a simulator measures durations, potencies and block counts without the
 * measurement error whose regression dilution (Fuller 1987; Isobe et al., ApJ 364, 104,
 * 1990) makes OLS flatten a slope: the scatter of a simulated catalog is the ruptures'
 * own variety, and OLS estimates E[log P | log T], a well-defined conditional exponent, with
 * a calibrated error.  Two effects can still bias it, and the other two slopes show them:
 * scatter in x (durations quantised by the output's time step, lengths by the lattice)
 * flattens OLS, and so does selecting by magnitude, which selects on y (bksim's magnitude
 * is (2/3) log10 P + offset): a band of width w cuts log P to 1.5 w decades, and where the
 * scatter about the law is comparable with that the band's OLS slope drops towards 0.  The
 * inverse slope is unmoved by a cut in y (it regresses x on y, and a cut in its regressor
 * leaves that regression unbiased) and by scatter in y it is steepened instead.  So when
 * the model is a straight line in log-log, the exponent lies between slope and
 * slope_inverse (r > 0) whichever variable carries the scatter; slope_rma, their geometric
 * mean, is exact when the scatter in v is gamma times that in u.  When the three agree
 * (r near 1) the exponent is well determined; when they do not, quote the bracket.  The
 * classical error is conditional on the x values and on the model; it holds no systematic
 * bias (truncation, the lattice, the choice of band): at thousands of ruptures it is far
 * smaller than those.
 *
 * Magnitude bands.  Magnitudes are binned as in bksim/stats.h ("M >= Mc" means the bin of M
 * is at or above the bin Mc): band k holds the binned magnitudes in [Mc + k w, Mc + (k + 1) w),
 * w = band_width, a multiple of dm; the whole range is every binned M >= Mc.  Ruptures of
 * fewer than min_blocks blocks are left out of both fits (counted): one-block ruptures are
 * the lattice's own events, a single block's slip episode with its own fixed duration, and
 * in Carlson-Langer chains they sit as one cluster in the (T, P) plane whose step to the
 * many-block ruptures would set a pooled slope (README, "Moment against duration").  Pass
 * only complete ruptures: one still running at the end of the run has a truncated duration
 * and potency.
 *
 * Length.  In a 1D chain the potency is n_blocks times the mean slip, so P ~ L^1 when the
 * mean slip does not grow with length and P ~ L^2 for crack-like ruptures whose slip grows
 * in proportion to their length (slip ~ stress drop x L / stiffness).  No published exponent
 * is set beside it here.
 *
 * Thøgersen et al. (2019), "The moment duration scaling relation for slow rupture arises
 * from transient rupture speeds": in a minimal 1D Burridge-Knopoff model, mean moment
 * against mean duration scales as T^0.63 for slow ruptures, rising to T^1.5 for longer
 * systems or larger prestress, T^2 for sub-shear (sub-Rayleigh) and T^3 for supershear
 * fronts.  The comparison is indicative only: their model is built to isolate single
 * ruptures at a chosen prestress with a friction law that has a slow-rupture branch, fitted
 * on averages per class of rupture speed; a Carlson-Langer chain (no slow-slip branch)
 * produces its ruptures as a sequence, and the fits here are per rupture, in magnitude
 * bands.  bk_scaling_classify places an exponent against their values with its error.
 *
 * Every function that can fail returns BK_OK or a negative status with a message in err
 * naming what was wrong and the allowed range. */
#ifndef BKSIM_STATS_SCALING_H
#define BKSIM_STATS_SCALING_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/stats.h"

/* Fewer pairs than this give no fit. */
#define BK_SCALING_MIN_PAIRS 10
/* The bands' defaults: a magnitude unit (1.5 decades of potency: a band's lever arm, since
 * narrower bands cut potency closer and flatten OLS), at least 30 pairs per fit (the
 * classical error is then itself known to about 1/sqrt(2 (n - 2)) = 13 %), ruptures of 2
 * blocks or more. */
#define BK_SCALING_BAND_WIDTH 1.0
#define BK_SCALING_BAND_MIN_PAIRS 30
#define BK_SCALING_MIN_BLOCKS 2
/* Bands above Mc: the last holds every magnitude from its lower limit up. */
#define BK_SCALING_MAX_BANDS 16
/* Per-fit notes ("not available: ..."). */
#define BK_SCALING_NOTE_LEN 256
/* bk_scaling_classify: an exponent is consistent with a value within this many errors. */
#define BK_SCALING_CLASS_SIGMAS 2.0
/* Thøgersen et al.'s 1D exponents of moment against duration. */
#define BK_THOGERSEN_SLOW_MIN 0.63
#define BK_THOGERSEN_SLOW_MAX 1.5
#define BK_THOGERSEN_SUBSHEAR 2.0
#define BK_THOGERSEN_SUPERSHEAR 3.0

/* -------------------------------------------------------------------- fit --- */

typedef struct bk_scaling_fit {
    double x_lo, x_hi;       /* the x range asked for: x in [x_lo, x_hi) */
    size_t n;                /* pairs fitted */
    size_t n_invalid;        /* pairs with x or y not finite and > 0: skipped */
    size_t n_outside;        /* valid pairs with x outside [x_lo, x_hi) */
    double x_min, x_max;     /* of the fitted pairs: the lever arm */
    double slope;            /* OLS of log10 y on log10 x: the headline exponent */
    double slope_sigma;      /* its classical standard error */
    double intercept;        /* y = 10^intercept x^slope */
    double intercept_sigma;
    double r;                /* Pearson correlation of log10 x and log10 y */
    double residual_sd;      /* of log10 y about the line: sqrt(SSE / (n - 2)), decades */
    double slope_rma;        /* reduced major axis: sign(r) sd(log y) / sd(log x) */
    double slope_rma_sigma;  /* |slope_rma| sqrt((1 - r^2) / (n - 2)) */
    double slope_inverse;    /* 1 / OLS of log10 x on log10 y = slope / r^2 */
} bk_scaling_fit;

/* The power-law exponent of y against x over the n pairs with x in [x_lo, x_hi) (x_lo <
 * x_hi, neither NaN; -inf and +inf allowed) and x, y finite and > 0; pairs failing the
 * latter are skipped and counted (n_invalid) before the range is applied (n_outside).
 * BK_ERR_INVALID when fewer than BK_SCALING_MIN_PAIRS pairs remain, or their x (or y) are
 * all equal. */
int bk_scaling_fit_pairs(const double *x, const double *y, size_t n, double x_lo, double x_hi,
                         bk_scaling_fit *out, bk_error *err);

/* ------------------------------------------------------- magnitude bands --- */

/* A catalog's columns, one entry per rupture (the caller's selection: complete ruptures in
 * the analysed window).  magnitude and potency are required; without t_start or t_end
 * there are no duration fits, without n_blocks no length fits (and no min_blocks cut). */
typedef struct bk_scaling_columns {
    size_t n;
    const double *t_start, *t_end;   /* s: duration t_end - t_start */
    const double *magnitude;
    const double *potency;           /* m */
    const int32_t *n_blocks;
} bk_scaling_columns;

typedef struct bk_scaling_options {
    double dm;            /* magnitude bin width, > 0 (the report's) */
    double mc;            /* where the bands start: a bin centre (default NaN: set it) */
    double band_width;    /* a positive multiple of dm */
    size_t min_pairs;     /* per fit, >= BK_SCALING_MIN_PAIRS */
    int32_t min_blocks;   /* ruptures of fewer blocks are left out of both fits, >= 1 */
} bk_scaling_options;

/* dm BK_STATS_DEFAULT_DM, mc NaN, BK_SCALING_BAND_WIDTH, BK_SCALING_BAND_MIN_PAIRS,
 * BK_SCALING_MIN_BLOCKS. */
void bk_scaling_options_default(bk_scaling_options *opt);
/* BK_ERR_INVALID with a message naming the option and its allowed range. */
int bk_scaling_options_check(const bk_scaling_options *opt, bk_error *err);

typedef struct bk_scaling_band {
    double m_lo, m_hi;       /* binned magnitudes in [m_lo, m_hi); m_hi = +inf: no upper limit */
    size_t n_events;         /* ruptures in the band */
    size_t n_small;          /* of them, fewer than min_blocks blocks: in neither fit */
    int have_duration;
    bk_scaling_fit duration; /* log10 potency against log10 (t_end - t_start); its n_invalid
                                counts zero or negative durations, potencies <= 0, NaN */
    char duration_note[BK_SCALING_NOTE_LEN]; /* why not, when have_duration is 0 */
    int have_length;
    bk_scaling_fit length;   /* log10 potency against log10 n_blocks */
    char length_note[BK_SCALING_NOTE_LEN];
} bk_scaling_band;

typedef struct bk_scaling {
    bk_scaling_options options;
    size_t n_rows;           /* columns.n */
    size_t n_nonfinite;      /* rows without a finite magnitude: in no band */
    size_t n_below_mc;
    bk_scaling_band all;     /* every rupture at or above Mc: m_hi = +inf */
    size_t n_bands;          /* from Mc up to the band of the largest magnitude */
    bk_scaling_band band[BK_SCALING_MAX_BANDS];
} bk_scaling;

/* Potency against duration and against length over M >= Mc and in bands of band_width
 * from Mc up.  A fit a band cannot support (too few ruptures, no spread, no such column)
 * has have_* = 0 and the reason in its note; the call fails (BK_ERR_INVALID, BK_ERR_NOMEM)
 * only on bad options, a missing magnitude or potency column, or lack of memory. */
int bk_scaling_by_magnitude(const bk_scaling_columns *columns, const bk_scaling_options *opt,
                            bk_scaling *out, bk_error *err);

/* ------------------------------------------- against Thøgersen et al. 2019 --- */

typedef enum bk_scaling_class {
    BK_SCALING_SLOW,              /* consistent with 0.63 .. 1.5 only */
    BK_SCALING_SUBSHEAR,          /* with 2 only */
    BK_SCALING_SUPERSHEAR,        /* with 3 only */
    BK_SCALING_AMBIGUOUS,         /* with more than one: the error is too large */
    BK_SCALING_BELOW_SLOW,        /* below 0.63 */
    BK_SCALING_SLOW_TO_SUBSHEAR,  /* between 1.5 and 2 */
    BK_SCALING_SUB_TO_SUPERSHEAR, /* between 2 and 3 */
    BK_SCALING_ABOVE_SUPERSHEAR   /* above 3 */
} bk_scaling_class;

/* Where a moment-duration exponent slope +- sigma (finite, sigma >= 0) lies against
 * Thøgersen et al.'s 1D values: consistent with a value (or the slow range) when
 * [slope - k sigma, slope + k sigma], k = BK_SCALING_CLASS_SIGMAS, reaches it; otherwise
 * between which, and how many errors from each.  The text (e.g. "consistent with sub-shear
 * fronts (2) within 2 sigma", "between sub-shear (2) and supershear (3): 10.0 sigma above 2,
 * 10.0 sigma below 3") goes to text[0..len) when text is not NULL.  The statement is about
 * the statistics of the fit, not the physics: see the header comment. */
int bk_scaling_classify(double slope, double sigma, bk_scaling_class *cls, char *text, size_t len,
                        bk_error *err);

/* ------------------------------------------------------- binned medians --- */

typedef struct bk_scaling_bins {
    size_t bins_per_decade;
    size_t n_used, n_invalid;    /* pairs binned; pairs with x or y not finite and > 0 */
    size_t n_bins;               /* the occupied bins, in increasing x */
    double *x_lo, *x_hi;         /* edges 10^(k / bins_per_decade) */
    double *x_centre;            /* geometric centre sqrt(x_lo x_hi) */
    size_t *count;
    double *median, *q25, *q75;  /* of y in the bin (GSL's quantiles: linear between order
                                    statistics, R's type 7) */
} bk_scaling_bins;

/* Median y (and quartiles) of the pairs with x, y finite and > 0 in logarithmic x bins,
 * bins_per_decade (1 .. 100) to a decade, edges at powers of 10^(1 / bins_per_decade), for a
 * plot of e.g. median potency against duration.  *out is allocated (bk_scaling_bins_free);
 * BK_ERR_INVALID without a valid pair. */
int bk_scaling_binned_medians(const double *x, const double *y, size_t n, size_t bins_per_decade,
                              bk_scaling_bins *out, bk_error *err);
void bk_scaling_bins_free(bk_scaling_bins *bins);

#endif
