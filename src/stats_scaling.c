/* Scaling relations (bksim/stats_scaling.h): power-law exponents of potency against
 * duration and length by least squares on log-log axes with the reduced major axis and the
 * inverse regression beside them (Warton et al., Biol. Rev. 81, 259, 2006; Isobe et al.,
 * ApJ 364, 104, 1990), over magnitude bands; their reading against Thøgersen et al. (GRL 46,
 * 12805, 2019); medians in logarithmic bins for plotting.  Sums are taken about the means
 * (two passes) and the residual sum of squares from the residuals themselves, so that an
 * exact power law gives r = 1 and a zero error rather than the rounding of Svv - b Suv. */
#include "bksim/stats_scaling.h"
#include "stats_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_statistics_double.h>

/* How a fit's messages name what it fits. */
typedef struct fit_names {
    const char *prefix;  /* "scaling fit: " or "" */
    const char *items;   /* "pairs", "ruptures" */
    const char *x, *y;
} fit_names;

static int valid_pair(double x, double y)
{
    return isfinite(x) && isfinite(y) && x > 0.0 && y > 0.0;
}

static int in_range(double x, double lo, double hi)
{
    return x >= lo && x < hi;
}

/* bk_scaling_fit_pairs with the caller's minimum count; names word the messages for pairs
 * or for a band's ruptures. */
static int fit(const double *x, const double *y, size_t n, double x_lo, double x_hi, size_t min_pairs,
               const fit_names *names, bk_scaling_fit *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    out->x_lo = x_lo;
    out->x_hi = x_hi;
    if (isnan(x_lo) || isnan(x_hi) || !(x_lo < x_hi))
        return BK_FAIL(err, BK_ERR_INVALID, "%s%s range [%g, %g): allowed x_lo < x_hi, neither NaN", names->prefix,
                       names->x, x_lo, x_hi);
    double sum_u = 0.0, sum_v = 0.0, y_min = INFINITY, y_max = -INFINITY;
    out->x_min = INFINITY;
    out->x_max = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        if (!valid_pair(x[i], y[i])) {
            out->n_invalid++;
            continue;
        }
        if (!in_range(x[i], x_lo, x_hi)) {
            out->n_outside++;
            continue;
        }
        out->n++;
        sum_u += log10(x[i]);
        sum_v += log10(y[i]);
        out->x_min = fmin(out->x_min, x[i]);
        out->x_max = fmax(out->x_max, x[i]);
        y_min = fmin(y_min, y[i]);
        y_max = fmax(y_max, y[i]);
    }
    if (out->n < min_pairs) {
        char range[96] = "", skipped[160] = "";
        if (isfinite(x_lo) || isfinite(x_hi))
            snprintf(range, sizeof range, " and %s in [%g, %g)", names->x, x_lo, x_hi);
        if (out->n_invalid || out->n_outside)
            snprintf(skipped, sizeof skipped, " (%zu skipped: not finite or <= 0; %zu outside the range)",
                     out->n_invalid, out->n_outside);
        return BK_FAIL(err, BK_ERR_INVALID, "%s%zu %s with %s, %s finite and > 0%s%s: needs at least %zu",
                       names->prefix, out->n, names->items, names->x, names->y, range, skipped, min_pairs);
    }
    double nn = (double)out->n, mean_u = sum_u / nn, mean_v = sum_v / nn;
    double suu = 0.0, svv = 0.0, suv = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (!valid_pair(x[i], y[i]) || !in_range(x[i], x_lo, x_hi))
            continue;
        double du = log10(x[i]) - mean_u, dv = log10(y[i]) - mean_v;
        suu += du * du;
        svv += dv * dv;
        suv += du * dv;
    }
    /* Equal values are told by exact comparison (their mean need not reproduce them to the
     * last bit, leaving Suu a rounding above 0); the sums catch neighbours whose logarithms
     * coincide. */
    if (out->x_min == out->x_max || !(suu > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "%sall %zu %s fitted have %s = %g: no spread in %s to fit a slope",
                       names->prefix, out->n, names->items, names->x, out->x_min, names->x);
    if (y_min == y_max || !(svv > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "%sall %zu %s fitted have %s = %g: no spread in %s, no power law to fit",
                       names->prefix, out->n, names->items, names->y, y_min, names->y);
    double b = suv / suu, a = mean_v - b * mean_u, sse = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (!valid_pair(x[i], y[i]) || !in_range(x[i], x_lo, x_hi))
            continue;
        double e = (log10(y[i]) - mean_v) - b * (log10(x[i]) - mean_u);
        sse += e * e;
    }
    double s2 = sse / (nn - 2.0);
    out->slope = b;
    out->intercept = a;
    out->slope_sigma = sqrt(s2 / suu);
    out->intercept_sigma = sqrt(s2 * (1.0 / nn + mean_u * mean_u / suu));
    out->residual_sd = sqrt(s2);
    out->r = fmax(-1.0, fmin(1.0, suv / sqrt(suu * svv)));
    out->slope_rma = copysign(sqrt(svv / suu), suv);
    /* 1 - r^2 = SSE / Svv without the cancellation of 1 - r * r near r = 1. */
    out->slope_rma_sigma = fabs(out->slope_rma) * sqrt(fmin(1.0, sse / svv) / (nn - 2.0));
    out->slope_inverse = svv / suv;
    return BK_OK;
}

int bk_scaling_fit_pairs(const double *x, const double *y, size_t n, double x_lo, double x_hi,
                         bk_scaling_fit *out, bk_error *err)
{
    const fit_names names = {"scaling fit: ", "pairs", "x", "y"};
    return fit(x, y, n, x_lo, x_hi, BK_SCALING_MIN_PAIRS, &names, out, err);
}

/* ------------------------------------------------------- magnitude bands --- */

void bk_scaling_options_default(bk_scaling_options *opt)
{
    opt->dm = BK_STATS_DEFAULT_DM;
    opt->mc = NAN;
    opt->band_width = BK_SCALING_BAND_WIDTH;
    opt->min_pairs = BK_SCALING_BAND_MIN_PAIRS;
    opt->min_blocks = BK_SCALING_MIN_BLOCKS;
}

int bk_scaling_options_check(const bk_scaling_options *opt, bk_error *err)
{
    long k = 0;
    if (!(isfinite(opt->dm) && opt->dm > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "scaling: magnitude bin width dm = %g: must be finite and > 0", opt->dm);
    if (!isfinite(opt->mc))
        return BK_FAIL(err, BK_ERR_INVALID, "scaling: Mc = %g: must be finite (a bin centre: a multiple of dm = %g)",
                       opt->mc, opt->dm);
    if (!bk_stats_centre_bin(opt->mc, opt->dm, &k))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "scaling: Mc = %g is not a bin centre: it must be a multiple of the bin width dm = %g",
                       opt->mc, opt->dm);
    if (!(bk_stats_centre_bin(opt->band_width, opt->dm, &k) && k >= 1))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "scaling: band width %g: must be a positive multiple of the bin width dm = %g", opt->band_width,
                       opt->dm);
    if (opt->min_pairs < BK_SCALING_MIN_PAIRS)
        return BK_FAIL(err, BK_ERR_INVALID, "scaling: at least %zu ruptures per fit: allowed %d or more",
                       opt->min_pairs, BK_SCALING_MIN_PAIRS);
    if (opt->min_blocks < 1)
        return BK_FAIL(err, BK_ERR_INVALID, "scaling: ruptures of at least %d blocks: allowed 1 or more",
                       (int)opt->min_blocks);
    return BK_OK;
}

/* Rows outside every band. */
#define NO_BAND (-1L)

/* Which rows a band holds: band index (or every band, for the whole range). */
typedef struct band_rows {
    const long *band;
    long which;   /* NO_BAND: the whole range */
} band_rows;

static int in_band(const band_rows *rows, size_t i)
{
    return rows->band[i] != NO_BAND && (rows->which == NO_BAND || rows->band[i] == rows->which);
}

static int small_rupture(const bk_scaling_columns *c, const bk_scaling_options *opt, size_t i)
{
    return c->n_blocks && c->n_blocks[i] < opt->min_blocks;
}

/* A fit's message as a band's note; the messages are far shorter than the note, and a longer
 * one is cut, not refused. */
static void set_note(char *note, size_t len, const char *message, const char *extra)
{
    int written = snprintf(note, len, "%s%s", message, extra);
    if (written < 0)
        note[0] = '\0';
}

/* One band's two fits; x and y are scratch of columns->n entries. */
static void fit_band(const bk_scaling_columns *c, const bk_scaling_options *opt, const band_rows *rows,
                     double *x, double *y, bk_scaling_band *out)
{
    for (size_t i = 0; i < c->n; ++i)
        if (in_band(rows, i)) {
            out->n_events++;
            if (small_rupture(c, opt, i))
                out->n_small++;
        }
    char small[96] = "";
    if (out->n_small)
        snprintf(small, sizeof small, " (%zu of fewer than %d blocks left out)", out->n_small, (int)opt->min_blocks);
    bk_error inner = {0};
    if (!c->t_start || !c->t_end) {
        snprintf(out->duration_note, sizeof out->duration_note, "the catalog has no t_start and t_end");
    } else {
        size_t k = 0;
        for (size_t i = 0; i < c->n; ++i)
            if (in_band(rows, i) && !small_rupture(c, opt, i)) {
                x[k] = c->t_end[i] - c->t_start[i];
                y[k++] = c->potency[i];
            }
        const fit_names names = {"", "ruptures", "duration", "potency"};
        if (fit(x, y, k, -INFINITY, INFINITY, opt->min_pairs, &names, &out->duration, &inner) == BK_OK)
            out->have_duration = 1;
        else
            set_note(out->duration_note, sizeof out->duration_note, inner.message, small);
    }
    if (!c->n_blocks) {
        snprintf(out->length_note, sizeof out->length_note, "the catalog has no n_blocks");
    } else {
        size_t k = 0;
        for (size_t i = 0; i < c->n; ++i)
            if (in_band(rows, i) && !small_rupture(c, opt, i)) {
                x[k] = (double)c->n_blocks[i];
                y[k++] = c->potency[i];
            }
        const fit_names names = {"", "ruptures", "n_blocks", "potency"};
        if (fit(x, y, k, -INFINITY, INFINITY, opt->min_pairs, &names, &out->length, &inner) == BK_OK)
            out->have_length = 1;
        else
            set_note(out->length_note, sizeof out->length_note, inner.message, small);
    }
}

int bk_scaling_by_magnitude(const bk_scaling_columns *columns, const bk_scaling_options *opt, bk_scaling *out,
                            bk_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = bk_scaling_options_check(opt, err);
    if (rc != BK_OK)
        return rc;
    if (!columns->magnitude || !columns->potency)
        return BK_FAIL(err, BK_ERR_INVALID, "scaling: the catalog has no %s column: needed for the scaling fits",
                       columns->magnitude ? "potency" : "magnitude");
    out->options = *opt;
    out->n_rows = columns->n;
    /* Both are whole bins: bk_scaling_options_check said so. */
    long k_mc = 0, w = 0;
    bk_stats_centre_bin(opt->mc, opt->dm, &k_mc);
    bk_stats_centre_bin(opt->band_width, opt->dm, &w);
    size_t n = columns->n ? columns->n : 1;
    long *band = malloc(n * sizeof *band);
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    if (!band || !x || !y) {
        free(band);
        free(x);
        free(y);
        return BK_FAIL(err, BK_ERR_NOMEM, "scaling: out of memory for %zu ruptures", columns->n);
    }
    long top = NO_BAND;
    for (size_t i = 0; i < columns->n; ++i) {
        long bin = 0;
        bk_error inner = {0};
        band[i] = NO_BAND;
        /* bk_mag_bin refuses only what has no bin: a non-finite magnitude or one beyond 1e15 bins. */
        if (!isfinite(columns->magnitude[i]) || bk_mag_bin(columns->magnitude[i], opt->dm, &bin, &inner) != BK_OK) {
            out->n_nonfinite++;
            continue;
        }
        if (bin < k_mc) {
            out->n_below_mc++;
            continue;
        }
        long b = (bin - k_mc) / w;
        band[i] = b < BK_SCALING_MAX_BANDS - 1 ? b : BK_SCALING_MAX_BANDS - 1;
        if (band[i] > top)
            top = band[i];
    }
    band_rows rows = {band, NO_BAND};
    out->all.m_lo = (double)k_mc * opt->dm;
    out->all.m_hi = INFINITY;
    fit_band(columns, opt, &rows, x, y, &out->all);
    out->n_bands = (size_t)(top + 1);
    for (size_t b = 0; b < out->n_bands; ++b) {
        bk_scaling_band *s = &out->band[b];
        /* From bin indices, so that band limits are the bin centres they name. */
        s->m_lo = (double)(k_mc + (long)b * w) * opt->dm;
        s->m_hi = b + 1 == BK_SCALING_MAX_BANDS ? INFINITY : (double)(k_mc + (long)(b + 1) * w) * opt->dm;
        rows.which = (long)b;
        fit_band(columns, opt, &rows, x, y, s);
    }
    free(band);
    free(x);
    free(y);
    return BK_OK;
}

/* ------------------------------------------- against Thøgersen et al. 2019 --- */

/* "3.2 sigma above 2": how far slope is from a value in errors (without the count when the
 * error is 0). */
static void sigmas(char *buf, size_t len, double d, double sigma, const char *side, double value)
{
    if (sigma > 0.0)
        snprintf(buf, len, "%.1f sigma %s %g", d / sigma, side, value);
    else
        snprintf(buf, len, "%s %g", side, value);
}

int bk_scaling_classify(double slope, double sigma, bk_scaling_class *cls, char *text, size_t len, bk_error *err)
{
    if (!isfinite(slope) || !isfinite(sigma) || sigma < 0.0)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "scaling class: exponent %g +- %g: the exponent must be finite and its error finite and >= 0",
                       slope, sigma);
    const double k = BK_SCALING_CLASS_SIGMAS, lo = slope - k * sigma, hi = slope + k * sigma;
    const double slow_min = BK_THOGERSEN_SLOW_MIN, slow_max = BK_THOGERSEN_SLOW_MAX;
    const double sub = BK_THOGERSEN_SUBSHEAR, super = BK_THOGERSEN_SUPERSHEAR;
    int slow = hi >= slow_min && lo <= slow_max, subshear = lo <= sub && hi >= sub;
    int supershear = lo <= super && hi >= super;
    char buf[BK_SCALING_NOTE_LEN], a[64], b[64];
    if (slow + subshear + supershear > 1) {
        *cls = BK_SCALING_AMBIGUOUS;
        snprintf(buf, sizeof buf,
                 "consistent with %s%s%s%s%s within %g sigma: the error is too large to tell them apart",
                 slow ? "slow ruptures (0.63 to 1.5)" : "", slow && subshear ? (supershear ? ", " : " and ") : "",
                 subshear ? "sub-shear fronts (2)" : "", supershear ? " and " : "",
                 supershear ? "supershear fronts (3)" : "", k);
    } else if (slow) {
        *cls = BK_SCALING_SLOW;
        snprintf(buf, sizeof buf, "consistent with slow ruptures (0.63 to 1.5) within %g sigma", k);
    } else if (subshear) {
        *cls = BK_SCALING_SUBSHEAR;
        snprintf(buf, sizeof buf, "consistent with sub-shear fronts (2) within %g sigma", k);
    } else if (supershear) {
        *cls = BK_SCALING_SUPERSHEAR;
        snprintf(buf, sizeof buf, "consistent with supershear fronts (3) within %g sigma", k);
    } else if (slope < slow_min) {
        *cls = BK_SCALING_BELOW_SLOW;
        sigmas(a, sizeof a, slow_min - slope, sigma, "below", slow_min);
        snprintf(buf, sizeof buf, "below the slow range (0.63 to 1.5): %s", a);
    } else if (slope < sub) {
        *cls = BK_SCALING_SLOW_TO_SUBSHEAR;
        sigmas(a, sizeof a, slope - slow_max, sigma, "above", slow_max);
        sigmas(b, sizeof b, sub - slope, sigma, "below", sub);
        snprintf(buf, sizeof buf, "between slow (0.63 to 1.5) and sub-shear (2): %s, %s", a, b);
    } else if (slope < super) {
        *cls = BK_SCALING_SUB_TO_SUPERSHEAR;
        sigmas(a, sizeof a, slope - sub, sigma, "above", sub);
        sigmas(b, sizeof b, super - slope, sigma, "below", super);
        snprintf(buf, sizeof buf, "between sub-shear (2) and supershear (3): %s, %s", a, b);
    } else {
        *cls = BK_SCALING_ABOVE_SUPERSHEAR;
        sigmas(a, sizeof a, slope - super, sigma, "above", super);
        snprintf(buf, sizeof buf, "above supershear (3): %s", a);
    }
    if (text && len > 0)
        snprintf(text, len, "%s", buf);
    return BK_OK;
}

/* ------------------------------------------------------- binned medians --- */

void bk_scaling_bins_free(bk_scaling_bins *bins)
{
    if (!bins)
        return;
    free(bins->x_lo);
    free(bins->x_hi);
    free(bins->x_centre);
    free(bins->count);
    free(bins->median);
    free(bins->q25);
    free(bins->q75);
    memset(bins, 0, sizeof *bins);
}

typedef struct binned_pair {
    long bin;
    double y;
} binned_pair;

static int compare_pairs(const void *pa, const void *pb)
{
    const binned_pair *a = pa, *b = pb;
    if (a->bin != b->bin)
        return (a->bin > b->bin) - (a->bin < b->bin);
    return (a->y > b->y) - (a->y < b->y);
}

int bk_scaling_binned_medians(const double *x, const double *y, size_t n, size_t bins_per_decade,
                              bk_scaling_bins *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (bins_per_decade < 1 || bins_per_decade > 100)
        return BK_FAIL(err, BK_ERR_INVALID, "scaling medians: %zu bins per decade: allowed 1 .. 100", bins_per_decade);
    out->bins_per_decade = bins_per_decade;
    for (size_t i = 0; i < n; ++i)
        if (valid_pair(x[i], y[i]))
            out->n_used++;
        else
            out->n_invalid++;
    if (out->n_used == 0)
        return BK_FAIL(err, BK_ERR_INVALID, "scaling medians: none of %zu pairs has x and y finite and > 0", n);
    binned_pair *pair = malloc(out->n_used * sizeof *pair);
    double *sorted = malloc(out->n_used * sizeof *sorted);
    if (!pair || !sorted) {
        free(pair);
        free(sorted);
        return BK_FAIL(err, BK_ERR_NOMEM, "scaling medians: out of memory for %zu pairs", out->n_used);
    }
    const double per = (double)bins_per_decade;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        if (valid_pair(x[i], y[i])) {
            /* The epsilon keeps a value written at an edge (x = 10, 0.1) in the bin it starts,
             * as BK_MAG_BIN_EPS does for magnitudes. */
            pair[m].bin = (long)floor(log10(x[i]) * per + 1e-9);
            pair[m++].y = y[i];
        }
    qsort(pair, m, sizeof *pair, compare_pairs);
    size_t bins = 1;
    for (size_t i = 1; i < m; ++i)
        bins += pair[i].bin != pair[i - 1].bin;
    out->x_lo = malloc(bins * sizeof *out->x_lo);
    out->x_hi = malloc(bins * sizeof *out->x_hi);
    out->x_centre = malloc(bins * sizeof *out->x_centre);
    out->count = malloc(bins * sizeof *out->count);
    out->median = malloc(bins * sizeof *out->median);
    out->q25 = malloc(bins * sizeof *out->q25);
    out->q75 = malloc(bins * sizeof *out->q75);
    if (!out->x_lo || !out->x_hi || !out->x_centre || !out->count || !out->median || !out->q25 || !out->q75) {
        free(pair);
        free(sorted);
        bk_scaling_bins_free(out);
        return BK_FAIL(err, BK_ERR_NOMEM, "scaling medians: out of memory for %zu bins", bins);
    }
    for (size_t i = 0; i < m; ++i)
        sorted[i] = pair[i].y;
    size_t b = 0;
    for (size_t start = 0; start < m; ++b) {
        size_t end = start;
        while (end < m && pair[end].bin == pair[start].bin)
            ++end;
        double k = (double)pair[start].bin;
        out->x_lo[b] = pow(10.0, k / per);
        out->x_hi[b] = pow(10.0, (k + 1.0) / per);
        out->x_centre[b] = pow(10.0, (k + 0.5) / per);
        out->count[b] = end - start;
        out->median[b] = gsl_stats_median_from_sorted_data(sorted + start, 1, end - start);
        out->q25[b] = gsl_stats_quantile_from_sorted_data(sorted + start, 1, end - start, 0.25);
        out->q75[b] = gsl_stats_quantile_from_sorted_data(sorted + start, 1, end - start, 0.75);
        start = end;
    }
    out->n_bins = bins;
    free(pair);
    free(sorted);
    return BK_OK;
}
