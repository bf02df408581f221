/* `bksim stats`: everything the report says about one catalog, from its columns in memory
 * (bk_event_table; src/output/h5_event_table.c reads them from an HDF5 file) through the
 * estimators of stats.c.  No HDF5 and no printing here (stats_print.c presents the report).
 *
 * A catalog needs only t_start and magnitude; the other fields of bksim's own catalogs
 * (potency, n_blocks, complete, t_end) add statistics when present. */
#include "bksim/stats.h"
#include "bksim/stats_scaling.h"
#include "bksim/stats_truncated.h"
#include "stats_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#define TWO_THIRDS (2.0 / 3.0)
/* Magnitudes and potencies obey m = (2/3) log10 P + offset to this (in magnitude units) in
 * a bksim catalog; 1e-6 leaves room for a catalog written in single precision elsewhere. */
#define OFFSET_TOLERANCE 1e-6

void bk_stats_options_default(bk_stats_options *opt)
{
    opt->dm = BK_STATS_DEFAULT_DM;
    opt->mc_auto = 1;
    opt->mc = 0.0;
    opt->mc_correction = BK_MAXC_CORRECTION;
    opt->t_from = -INFINITY;
    opt->t_to = INFINITY;
    opt->bootstrap = BK_BOOTSTRAP_DEFAULT;
    opt->seed = BK_BOOTSTRAP_SEED;
    opt->mainshock_auto = 1;
    opt->mainshock = 0.0;
    opt->window = 0.0;
}

int bk_stats_options_check(const bk_stats_options *opt, bk_error *err)
{
    if (!(isfinite(opt->dm) && opt->dm > 0.0 && opt->dm <= 10.0))
        return BK_FAIL(err, BK_ERR_INVALID, "magnitude bin width %g: allowed 0 < dm <= 10",
                       opt->dm);
    if (!isfinite(opt->mc_correction))
        return BK_FAIL(err, BK_ERR_INVALID, "Mc correction %g: must be finite",
                       opt->mc_correction);
    if (isnan(opt->t_from) || isnan(opt->t_to) || !(opt->t_from < opt->t_to) ||
        opt->t_from == INFINITY || opt->t_to == -INFINITY)
        return BK_FAIL(err, BK_ERR_INVALID, "time window [%g, %g) s: allowed from < to",
                       opt->t_from, opt->t_to);
    if (opt->bootstrap > BK_BOOTSTRAP_MAX)
        return BK_FAIL(err, BK_ERR_INVALID, "bootstrap samples %zu: allowed 0 .. %d", opt->bootstrap,
                       BK_BOOTSTRAP_MAX);
    if (!opt->mainshock_auto && !(isfinite(opt->mainshock) && fabs(opt->mainshock / opt->dm) <= 1e15))
        return BK_FAIL(err, BK_ERR_INVALID, "mainshock magnitude %g: allowed finite, within 1e15 bins of 0",
                       opt->mainshock);
    if (!(isfinite(opt->window) && opt->window >= 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "sequence window %g s: allowed > 0 (0: the span over the mainshock count)",
                       opt->window);
    if (!opt->mc_auto) {
        long k = 0;
        if (!bk_stats_centre_bin(opt->mc, opt->dm, &k))
            return BK_FAIL(err, BK_ERR_INVALID,
                           "Mc = %g: must be a bin centre, a multiple of the bin width %g "
                           "(bins are centred on multiples of dm)",
                           opt->mc, opt->dm);
    }
    return BK_OK;
}

/* Whether an event starting at t is inside the time window (a NaN start is not excluded
 * here: the callers that need a finite start check it themselves). */
static int in_window(const bk_stats_options *opt, double t)
{
    return !(t < opt->t_from) && !(t >= opt->t_to);
}

void bk_event_table_free(bk_event_table *t)
{
    free(t->t_start);
    free(t->magnitude);
    free(t->t_end);
    free(t->potency);
    free(t->max_slip_rate);
    free(t->n_blocks);
    free(t->complete);
    free(t->name);
    memset(t, 0, sizeof *t);
}

/* A statistic the catalog cannot support is noted, not fatal; anything else (memory) is. */
static int note_or_fail(int rc, const bk_error *inner, char *note, size_t len, bk_error *err)
{
    if (rc == BK_ERR_INVALID) {
        snprintf(note, len, "%s", inner->message);
        return BK_OK;
    }
    if (err)
        *err = *inner;
    return rc;
}

/* The potency threshold: the potency of the lower edge of the Mc bin when the catalog's
 * magnitudes are (2/3) log10 P plus one offset (bksim's are), so that the exponent and b
 * describe the same events; else the smallest potency among the events at or above Mc. */
static int fit_potency(bk_stats_report *r, const double *binned, bk_error *err)
{
    size_t n = r->n_events, count = 0;
    double *p = malloc((n ? n : 1) * sizeof *p);
    if (!p)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu potencies", n);
    double off_lo = INFINITY, off_hi = -INFINITY, p_above = INFINITY;
    for (size_t i = 0; i < n; ++i) {
        double pot = r->potency[i];
        if (!(isfinite(pot) && pot > 0.0))
            continue;
        p[count++] = pot;
        double off = r->magnitude[i] - TWO_THIRDS * log10(pot);
        off_lo = fmin(off_lo, off);
        off_hi = fmax(off_hi, off);
        if (binned[i] >= r->mc && pot < p_above)
            p_above = pot;
    }
    double p_min;
    if (count > 0 && off_hi - off_lo <= OFFSET_TOLERANCE) {
        r->magnitude_offset = 0.5 * (off_lo + off_hi);
        r->potency_threshold_from_mc = 1;
        p_min = pow(10.0, 1.5 * (r->mc - 0.5 * r->options.dm - r->magnitude_offset));
    } else if (isfinite(p_above)) {
        p_min = p_above;
    } else {
        snprintf(r->potency_note, sizeof r->potency_note,
                 "no event at or above Mc = %g has a positive, finite potency", r->mc);
        free(p);
        return BK_OK;
    }
    bk_error inner = {0};
    int rc = bk_power_law_mle(p, count, p_min, &r->potency_fit, &inner);
    if (rc == BK_OK && r->potency_fit.n < BK_B_MIN_EVENTS) {
        snprintf(r->potency_note, sizeof r->potency_note,
                 "%zu potencies at or above %g m: the exponent needs at least %d", r->potency_fit.n, p_min,
                 BK_B_MIN_EVENTS);
        free(p);
        return BK_OK;
    }
    if (rc == BK_OK && r->options.bootstrap > 0) {
        /* Tested as the GR fit is: a power law the potencies do not follow gives no exponent. */
        rc = bk_power_law_gof(p, count, &r->potency_fit, r->options.bootstrap, r->options.seed + 2,
                              &r->potency_gof, &inner);
        if (rc == BK_OK && (r->have_potency_gof = 1, r->potency_gof.p < BK_GOF_LEVEL)) {
            snprintf(r->potency_note, sizeof r->potency_note,
                     "the %zu potencies at or above %g m do not follow a power law: KS distance %.4f to the "
                     "fitted one, bootstrap p = %.3g < %g (%zu synthetic samples)",
                     r->potency_gof.n, p_min, r->potency_gof.d, r->potency_gof.p, BK_GOF_LEVEL,
                     r->potency_gof.n_synthetic);
            free(p);
            return BK_OK;
        }
    }
    free(p);
    if (rc == BK_OK) {
        r->have_potency_exponent = 1;
        return BK_OK;
    }
    return note_or_fail(rc, &inner, r->potency_note, sizeof r->potency_note, err);
}

/* The binned magnitudes at or above Mc, first half of the time span against the second: a
 * catalog whose loading has not settled (a spin-up still in it) fails this test.  Binned, as
 * the MFD and b see them: a chain's smallest events come in narrow clusters of nearly equal
 * magnitude (one block, two blocks...), and raw magnitudes would flag a drift inside one
 * cluster, far below the bin width (ties make the asymptotic p-value conservative). */
static int ks_halves(bk_stats_report *r, const double *binned, bk_error *err)
{
    r->ks_t_split = r->span_start + 0.5 * r->duration;
    double *first = malloc((r->n_events ? r->n_events : 1) * sizeof *first);
    double *second = malloc((r->n_events ? r->n_events : 1) * sizeof *second);
    if (!first || !second) {
        free(first);
        free(second);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu magnitudes", r->n_events);
    }
    size_t n1 = 0, n2 = 0;
    for (size_t i = 0; i < r->n_events; ++i)
        if (binned[i] >= r->mc) {
            if (r->t_start[i] < r->ks_t_split)
                first[n1++] = binned[i];
            else
                second[n2++] = binned[i];
        }
    bk_error inner = {0};
    int rc = n1 && n2 ? bk_ks_two_sample(first, n1, second, n2, &r->ks, &inner) : BK_ERR_INVALID;
    free(first);
    free(second);
    if (rc == BK_OK) {
        r->have_ks = 1;
        return BK_OK;
    }
    if (rc == BK_ERR_INVALID && !(n1 && n2)) {
        snprintf(r->ks_note, sizeof r->ks_note,
                 "%zu and %zu events at or above Mc = %g before and after t = %g s: the KS test "
                 "needs at least 1 in each half",
                 n1, n2, r->mc, r->ks_t_split);
        return BK_OK;
    }
    return note_or_fail(rc, &inner, r->ks_note, sizeof r->ks_note, err);
}

/* b-positive at Mc and Mc by b-value stability, beside the Aki-Utsu b and maximum curvature.
 * Neither is tested for fit here: they answer other questions (short-term incompleteness,
 * the choice of Mc). */
static int other_estimators(bk_stats_report *r, bk_error *err)
{
    const bk_stats_options *o = &r->options;
    bk_error inner = {0};
    int rc = bk_b_positive(r->magnitude, r->t_start, r->n_events, r->mc, o->dm, o->dm, &r->b_positive, &inner);
    if (rc == BK_OK && r->b_positive.fit.n < BK_B_MIN_EVENTS) {
        snprintf(r->b_positive_note, sizeof r->b_positive_note,
                 "%zu positive magnitude differences at or above %g: b-positive needs at least %d",
                 r->b_positive.fit.n, o->dm, BK_B_MIN_EVENTS);
    } else if (rc == BK_OK) {
        r->have_b_positive = 1;
    } else if ((rc = note_or_fail(rc, &inner, r->b_positive_note, sizeof r->b_positive_note, err)) != BK_OK) {
        return rc;
    }
    rc = bk_mc_b_stability(r->magnitude, r->n_events, o->dm, 0.5, &r->mc_stability, &inner);
    if (rc == BK_OK)
        r->have_mc_stability = 1;
    else if ((rc = note_or_fail(rc, &inner, r->mc_stability_note, sizeof r->mc_stability_note, err)) != BK_OK)
        return rc;
    if (o->bootstrap == 0) {
        snprintf(r->mc_ks_note, sizeof r->mc_ks_note, "the KS method draws synthetic samples: --bootstrap 0 draws none");
        return BK_OK;
    }
    rc = bk_mc_ks(r->magnitude, r->n_events, o->dm, BK_MC_KS_P_PASS, o->bootstrap, o->seed + 3, &r->mc_ks, &inner);
    if (rc != BK_OK)
        return note_or_fail(rc, &inner, r->mc_ks_note, sizeof r->mc_ks_note, err);
    if (r->mc_ks.found && r->mc_ks.n >= BK_B_SMALL_SAMPLE)
        r->have_mc_ks = 1;
    else if (r->mc_ks.found)
        /* A few dozen of the largest events pass almost any test (the KS test has little power
         * there): no completeness follows from it. */
        snprintf(r->mc_ks_note, sizeof r->mc_ks_note,
                 "the first candidate that passes the KS test at p >= %g, Mc = %g, leaves %zu events above it "
                 "(fewer than %d, too few for the test to reject): every lower one fails",
                 BK_MC_KS_P_PASS, r->mc_ks.mc, r->mc_ks.n, BK_B_SMALL_SAMPLE);
    else
        snprintf(r->mc_ks_note, sizeof r->mc_ks_note,
                 "no candidate of the %zu tested passes the KS test at p >= %g (the last: Mc = %g, p = %.3g)",
                 r->mc_ks.n_tested, BK_MC_KS_P_PASS, r->mc_ks.mc, r->mc_ks.p);
    return BK_OK;
}

/* Interevent times at Mc and every BK_INTEREVENT_STEP above it while enough events remain
 * (binned magnitudes, as every statistic above Mc). */
static int interevent(bk_stats_report *r, const double *binned, bk_error *err)
{
    bk_error inner = {0};
    size_t k = 0;
    for (; k < BK_INTEREVENT_THRESHOLDS; ++k) {
        double m_min = r->mc + BK_INTEREVENT_STEP * (double)k - 0.5 * r->options.dm;
        size_t count = 0;
        for (size_t i = 0; i < r->n_events; ++i)
            count += binned[i] >= m_min;
        if (count < BK_INTEREVENT_MIN_EVENTS)
            break;
        int rc = bk_interevent_build(r->t_start, binned, r->n_events, m_min, r->duration,
                                     BK_INTEREVENT_BINS_PER_DECADE, &r->interevent[k], &inner);
        if (rc != BK_OK) {
            if (k == 0)
                return note_or_fail(rc, &inner, r->interevent_note, sizeof r->interevent_note, err);
            break;
        }
        r->interevent[k].m_min = r->mc + BK_INTEREVENT_STEP * (double)k; /* the bin centre, as Mc */
        r->n_interevent = k + 1;
    }
    if (r->n_interevent == 0 && !r->interevent_note[0])
        snprintf(r->interevent_note, sizeof r->interevent_note,
                 "fewer than %d events at or above Mc = %g: interevent times need that many", BK_INTEREVENT_MIN_EVENTS,
                 r->mc);
    return BK_OK;
}

/* Potency against duration and length from Mc up (bksim/stats_scaling.h: the bands and the
 * bracket of slopes are its). */
static int scaling(bk_stats_report *r, bk_error *err)
{
    if (!r->potency) {
        snprintf(r->scaling_note, sizeof r->scaling_note, "the catalog has no potency field");
        return BK_OK;
    }
    bk_scaling_options opt;
    bk_scaling_options_default(&opt);
    opt.dm = r->options.dm;
    opt.mc = r->mc;
    /* A band of a magnitude unit holds whole bins whatever dm divides it; else one bin. */
    double bins = floor(opt.band_width / opt.dm + 0.5);
    opt.band_width = (bins >= 1.0 ? bins : 1.0) * opt.dm;
    bk_scaling_columns columns = {r->n_events, r->t_start, r->t_end, r->magnitude, r->potency, r->n_blocks};
    r->scaling = malloc(sizeof *r->scaling);
    if (!r->scaling)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for the scaling relations");
    bk_error inner = {0};
    int rc = bk_scaling_by_magnitude(&columns, &opt, r->scaling, &inner);
    if (rc != BK_OK) {
        free(r->scaling);
        r->scaling = NULL;
        return note_or_fail(rc, &inner, r->scaling_note, sizeof r->scaling_note, err);
    }
    return BK_OK;
}

/* Sequences around the events at or above the mainshock magnitude, of the events >= Mc (binned
 * magnitudes: thresholds at lower bin edges). */
static int sequences(bk_stats_report *r, const double *binned, bk_error *err)
{
    const bk_stats_options *o = &r->options;
    double m_main = r->mc + BK_SEQUENCE_MAINSHOCK_STEP;
    if (!o->mainshock_auto) {
        long k = 0;
        bk_mag_bin(o->mainshock, o->dm, &k, NULL);
        m_main = (double)k * o->dm;
    }
    size_t count = 0;
    for (size_t i = 0; i < r->n_events; ++i)
        count += binned[i] >= m_main - 0.5 * o->dm;
    if (count == 0) {
        snprintf(r->sequences_note, sizeof r->sequences_note, "no event at or above the mainshock magnitude %g%s",
                 m_main, o->mainshock_auto ? " (Mc + 2; --mainshock sets it)" : "");
        return BK_OK;
    }
    if (!(r->duration > 0.0)) {
        snprintf(r->sequences_note, sizeof r->sequences_note, "the observed span is empty");
        return BK_OK;
    }
    double window = o->window > 0.0 ? o->window : r->duration / (double)count;
    bk_error inner = {0};
    int rc = bk_sequences_build(r->t_start, binned, r->n_events, r->mc - 0.5 * o->dm, m_main - 0.5 * o->dm, window,
                                r->span_start, r->span_start + r->duration, &r->sequences, &inner);
    if (rc != BK_OK)
        return note_or_fail(rc, &inner, r->sequences_note, sizeof r->sequences_note, err);
    /* The thresholds as bin centres, as Mc is reported. */
    r->sequences.m_main = m_main;
    r->sequences.m_min = r->mc;
    r->have_sequences = 1;
    return BK_OK;
}

/* The GR fit above Mc tested against its magnitudes, and b's and Mc's bootstrap errors: a
 * fit the test rejects gives no b-value, and the note says why. */
static int test_gr(bk_stats_report *r, bk_error *err)
{
    const bk_stats_options *o = &r->options;
    r->have_b = 1;
    r->b_small_sample = r->b.n < BK_B_SMALL_SAMPLE;
    if (o->bootstrap == 0)
        return BK_OK;
    bk_error inner = {0};
    int rc = bk_gr_gof(r->magnitude, r->n_events, &r->b, o->bootstrap, o->seed, &r->gr_gof, &inner);
    if (rc != BK_OK)
        return note_or_fail(rc, &inner, r->b_note, sizeof r->b_note, err);
    r->have_gr_gof = 1;
    if (r->gr_gof.p < BK_GOF_LEVEL) {
        r->have_b = 0;
        snprintf(r->b_note, sizeof r->b_note,
                 "the %zu magnitudes at or above Mc = %g are not Gutenberg-Richter distributed: "
                 "KS distance %.4f to the fitted law, bootstrap p = %.3g < %g (%zu synthetic samples)",
                 r->gr_gof.n, r->mc, r->gr_gof.d, r->gr_gof.p, BK_GOF_LEVEL, r->gr_gof.n_synthetic);
        return BK_OK;
    }
    bk_b_options bo = {o->dm, o->mc_auto, r->mc, o->mc_correction};
    rc = bk_b_bootstrap(r->magnitude, r->n_events, &bo, o->bootstrap, o->seed + 1, &r->b_spread, &inner);
    if (rc == BK_OK)
        r->have_b_spread = 1;
    else if (rc != BK_ERR_INVALID)
        return note_or_fail(rc, &inner, r->b_note, sizeof r->b_note, err);
    return BK_OK;
}

/* The largest range [Mc, Mu] a GR law describes: where a size cutoff (the system-size bump)
 * spoils the fit above Mc, the law below it still has a b. */
static int truncation(bk_stats_report *r, bk_error *err)
{
    const bk_stats_options *o = &r->options;
    if (o->bootstrap < BK_TRUNCATED_MIN_SYNTHETIC) {
        snprintf(r->truncation_note, sizeof r->truncation_note,
                 "the range scan tests each upper magnitude with at least %d synthetic samples: --bootstrap %zu",
                 BK_TRUNCATED_MIN_SYNTHETIC, o->bootstrap);
        return BK_OK;
    }
    r->truncation = malloc(sizeof *r->truncation);
    if (!r->truncation)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for the truncated GR fit");
    bk_error inner = {0};
    int rc = bk_gr_truncation_scan(r->magnitude, r->n_events, r->mc, o->dm, BK_TRUNCATED_MIN_BINS, o->bootstrap,
                                   o->seed + 4, r->truncation, &inner);
    if (rc == BK_OK && !r->truncation->found)
        snprintf(r->truncation_note, sizeof r->truncation_note,
                 "no range from Mc = %g up to %d bins or more passes the fit test at p >= %g (best p = %.3g, Mu = %g)",
                 r->mc, BK_TRUNCATED_MIN_BINS, BK_GOF_LEVEL, r->truncation->gof.p, r->truncation->fit.mu);
    if (rc == BK_OK && r->truncation->found)
        return BK_OK;
    free(r->truncation);
    r->truncation = NULL;
    return rc == BK_OK ? BK_OK : note_or_fail(rc, &inner, r->truncation_note, sizeof r->truncation_note, err);
}

/* Everything that needs Mc. */
static int above_mc(bk_stats_report *r, bk_error *err)
{
    const bk_stats_options *o = &r->options;
    bk_error inner = {0};
    int rc;
    if (o->mc_auto) {
        if ((rc = bk_mc_maxc(&r->mfd, o->mc_correction, &r->mc, &inner)) != BK_OK)
            return note_or_fail(rc, &inner, r->b_note, sizeof r->b_note, err);
    } else {
        r->mc = o->mc;
    }
    r->have_mc = 1;
    double *binned = malloc(r->n_events * sizeof *binned);
    if (!binned)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu magnitudes", r->n_events);
    /* Binned magnitudes are k dm and Mc is k_mc dm: comparing them compares bin indices. */
    long k_mc = (long)floor(r->mc / o->dm + 0.5);
    r->mc = (double)k_mc * o->dm;
    for (size_t i = 0; i < r->n_events; ++i) {
        long k = 0;
        bk_mag_bin(r->magnitude[i], o->dm, &k, NULL);
        binned[i] = (double)k * o->dm;
        r->n_above_mc += k >= k_mc;
    }
    r->rate_above_mc = r->duration > 0.0 ? (double)r->n_above_mc / r->duration : 0.0;

    rc = bk_b_value(r->magnitude, r->n_events, r->mc, o->dm, &r->b, &inner);
    if (rc == BK_OK)
        rc = test_gr(r, err);
    else
        rc = note_or_fail(rc, &inner, r->b_note, sizeof r->b_note, err);
    if (rc == BK_OK)
        rc = truncation(r, err);
    if (rc == BK_OK && r->potency)
        rc = fit_potency(r, binned, err);
    if (rc == BK_OK) {
        rc = bk_recurrence_intervals(r->t_start, binned, r->n_events, r->mc, &r->recurrence,
                                     &inner);
        if (rc == BK_OK)
            r->have_recurrence = 1;
        else
            rc = note_or_fail(rc, &inner, r->recurrence_note, sizeof r->recurrence_note, err);
    }
    if (rc == BK_OK)
        rc = other_estimators(r, err);
    if (rc == BK_OK)
        rc = interevent(r, binned, err);
    if (rc == BK_OK)
        rc = sequences(r, binned, err);
    if (rc == BK_OK)
        rc = scaling(r, err);
    if (rc == BK_OK)
        rc = ks_halves(r, binned, err);
    free(binned);
    return rc;
}

static int compute_sizes(bk_stats_report *r, const bk_event_table *t, bk_error *err)
{
    if (!t->n_blocks) {
        snprintf(r->sizes_note, sizeof r->sizes_note, "the catalog has no n_blocks field");
        return BK_OK;
    }
    int32_t *sizes = malloc((t->n ? t->n : 1) * sizeof *sizes);
    if (!sizes)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu event sizes", t->n);
    size_t n = 0;
    for (size_t i = 0; i < t->n; ++i)
        if ((!t->complete || t->complete[i] != 0) && in_window(&r->options, t->t_start[i]))
            sizes[n++] = t->n_blocks[i];
    bk_error inner = {0};
    int rc = bk_size_dist_build(sizes, n, &r->sizes, &inner);
    free(sizes);
    if (rc == BK_OK) {
        r->have_sizes = 1;
        return BK_OK;
    }
    return note_or_fail(rc, &inner, r->sizes_note, sizeof r->sizes_note, err);
}

/* Keep the rows bk_event_select keeps (complete, finite start and magnitude, in the time
 * window), their columns copied, and the span they were observed over. */
static int select_events(bk_stats_report *r, const bk_event_table *t, bk_error *err)
{
    bk_event_selection sel;
    int rc = bk_event_select(t, r->options.t_from, r->options.t_to, &sel, err);
    if (rc != BK_OK)
        return rc;
    size_t n = sel.n_events ? sel.n_events : 1;
    r->t_start = malloc(n * sizeof *r->t_start);
    r->magnitude = malloc(n * sizeof *r->magnitude);
    r->potency = t->potency ? malloc(n * sizeof *r->potency) : NULL;
    r->t_end = t->t_end ? malloc(n * sizeof *r->t_end) : NULL;
    r->n_blocks = t->n_blocks ? malloc(n * sizeof *r->n_blocks) : NULL;
    if (!r->t_start || !r->magnitude || (t->potency && !r->potency) || (t->t_end && !r->t_end) ||
        (t->n_blocks && !r->n_blocks)) {
        bk_event_selection_free(&sel);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for %zu events", r->path, t->n);
    }
    for (size_t k = 0; k < sel.n_events; ++k) {
        size_t i = sel.index[k];
        r->t_start[k] = t->t_start[i];
        r->magnitude[k] = t->magnitude[i];
        if (r->potency)
            r->potency[k] = t->potency[i];
        if (r->t_end)
            r->t_end[k] = t->t_end[i];
        if (r->n_blocks)
            r->n_blocks[k] = t->n_blocks[i];
    }
    r->n_events = sel.n_events;
    r->n_incomplete = sel.n_incomplete;
    r->n_nonfinite = sel.n_nonfinite;
    r->n_outside = sel.n_outside;
    r->t_first = sel.t_first;
    r->t_last = sel.t_last;
    r->m_min = sel.m_min;
    r->m_max = sel.m_max;
    r->span_start = sel.span_start;
    r->duration = sel.duration;
    r->duration_from_run = sel.duration_from_run;
    r->rate = r->duration > 0.0 ? (double)r->n_events / r->duration : 0.0;
    bk_event_selection_free(&sel);
    return BK_OK;
}

static int compute(bk_stats_report *r, const bk_event_table *t, bk_error *err)
{
    r->n_rows = t->n;
    r->has_t_end = t->t_end != NULL;
    r->has_potency = t->potency != NULL;
    r->has_n_blocks = t->n_blocks != NULL;
    r->has_complete = t->complete != NULL;
    int rc = select_events(r, t, err);
    if (rc != BK_OK)
        return rc;
    if ((rc = compute_sizes(r, t, err)) != BK_OK)
        return rc;
    if (!r->has_potency)
        snprintf(r->potency_note, sizeof r->potency_note, "the catalog has no potency field");
    if (r->n_events == 0) {
        const char *none = "no complete event with a finite t_start and magnitude";
        snprintf(r->b_note, sizeof r->b_note, "%s", none);
        snprintf(r->recurrence_note, sizeof r->recurrence_note, "%s", none);
        snprintf(r->interevent_note, sizeof r->interevent_note, "%s", none);
        snprintf(r->ks_note, sizeof r->ks_note, "%s", none);
        snprintf(r->sequences_note, sizeof r->sequences_note, "%s", none);
        snprintf(r->scaling_note, sizeof r->scaling_note, "%s", none);
        if (r->has_potency)
            snprintf(r->potency_note, sizeof r->potency_note, "%s", none);
        return BK_OK;
    }
    bk_error inner = {0};
    rc = bk_mfd_build(r->magnitude, r->n_events, r->options.dm, &r->mfd, &inner);
    if (rc != BK_OK) {
        /* e.g. magnitudes spanning too many bins: the message says so. */
        rc = note_or_fail(rc, &inner, r->b_note, sizeof r->b_note, err);
        snprintf(r->recurrence_note, sizeof r->recurrence_note, "%s", r->b_note);
        snprintf(r->interevent_note, sizeof r->interevent_note, "%s", r->b_note);
        snprintf(r->ks_note, sizeof r->ks_note, "%s", r->b_note);
        snprintf(r->sequences_note, sizeof r->sequences_note, "%s", r->b_note);
        snprintf(r->scaling_note, sizeof r->scaling_note, "%s", r->b_note);
        if (r->has_potency)
            snprintf(r->potency_note, sizeof r->potency_note, "%s", r->b_note);
        return rc;
    }
    r->have_mfd = 1;
    return above_mc(r, err);
}

int bk_stats_report_compute(const bk_event_table *table, const char *source,
                            const bk_stats_options *opt, bk_stats_report **out, bk_error *err)
{
    *out = NULL;
    bk_stats_options defaults;
    bk_stats_options_default(&defaults);
    if (!opt)
        opt = &defaults;
    int rc = bk_stats_options_check(opt, err);
    if (rc != BK_OK)
        return rc;
    bk_stats_report *r = calloc(1, sizeof *r);
    if (r) {
        r->path = strdup(source);
        r->table = table->name ? strdup(table->name) : NULL;
        r->table_fallback = table->fallback;
    }
    if (!r || !r->path || (table->name && !r->table)) {
        bk_stats_report_free(r);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", source);
    }
    r->options = *opt;
    /* An estimator GSL cannot complete (a simplex, a singular matrix) is a note in the
     * report: GSL's default handler would abort the process instead. */
    gsl_error_handler_t *handler = gsl_set_error_handler_off();
    rc = compute(r, table, err);
    gsl_set_error_handler(handler);
    if (rc != BK_OK) {
        bk_stats_report_free(r);
        return rc;
    }
    *out = r;
    return BK_OK;
}

void bk_stats_report_free(bk_stats_report *r)
{
    if (!r)
        return;
    free(r->path);
    free(r->table);
    free(r->t_start);
    free(r->magnitude);
    free(r->potency);
    free(r->t_end);
    free(r->n_blocks);
    free(r->scaling);
    free(r->truncation);
    bk_mfd_free(&r->mfd);
    bk_recurrence_free(&r->recurrence);
    for (size_t k = 0; k < r->n_interevent; ++k)
        bk_interevent_free(&r->interevent[k]);
    bk_size_dist_free(&r->sizes);
    bk_sequences_free(&r->sequences);
    free(r);
}
