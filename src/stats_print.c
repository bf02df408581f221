/* `bksim stats`: the report of src/stats_report.c presented as text, one JSON object, or
 * TSV tables for gnuplot. */
#include "bksim/stats.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ------------------------------------------------------------------ text --- */

static int write_failed(FILE *out, const char *what, bk_error *err)
{
    if (ferror(out))
        return BK_FAIL(err, BK_ERR_IO, "writing the %s failed: %s", what, strerror(errno));
    return BK_OK;
}

int bk_stats_report_text(const bk_stats_report *r, FILE *out, bk_error *err)
{
    const bk_stats_options *o = &r->options;
    fprintf(out, "catalog: %s\n", r->path);
    /* Which table: the default /ruptures, the /events it falls back to, or one named. */
    const char *what = "";
    if (r->table && r->table_fallback)
        what = " (the time-window catalog: the file has no /ruptures)";
    else if (r->table && strcmp(r->table, "ruptures") == 0)
        what = " (the rupture catalog)";
    else if (r->table && strcmp(r->table, "events") == 0)
        what = " (the time-window catalog)";
    fprintf(out, "  %s%s%s: %zu rows; fields beyond t_start, magnitude:%s%s%s%s%s\n",
            r->table ? "/" : "", r->table ? r->table : "table", what, r->n_rows,
            r->has_t_end ? " t_end" : "", r->has_potency ? " potency" : "",
            r->has_n_blocks ? " n_blocks" : "", r->has_complete ? " complete" : "",
            r->has_t_end || r->has_potency || r->has_n_blocks || r->has_complete ? "" : " none");
    if (r->n_incomplete || r->n_nonfinite)
        fprintf(out, "  left out: %zu still running at the end (complete = 0), %zu without a "
                     "finite t_start and magnitude%s\n",
                r->n_incomplete, r->n_nonfinite,
                r->n_nonfinite && r->has_potency ? " (zero potency: magnitude -inf)" : "");
    if (isfinite(o->t_from) || isfinite(o->t_to)) {
        char from[48] = "", to[48] = "";
        if (isfinite(o->t_from))
            snprintf(from, sizeof from, " t >= %.9g s", o->t_from);
        if (isfinite(o->t_to))
            snprintf(to, sizeof to, "%s t < %.9g s", *from ? " and" : "", o->t_to);
        fprintf(out, "  time window: events starting at%s%s; %zu outside it left out\n", from, to,
                r->n_outside);
    }
    fprintf(out, "  events: %zu", r->n_events);
    if (r->n_events) {
        fprintf(out, ", starts from %.9g s to %.9g s\n", r->t_first, r->t_last);
        fprintf(out, "  duration: %.9g s (%s%s); rate %.6g events/s\n", r->duration,
                r->duration_from_run ? "the run's t_reached" : "the catalog's span",
                isfinite(o->t_from) || isfinite(o->t_to) ? " within the window" : "", r->rate);
        fprintf(out, "  magnitudes: %.4f to %.4f\n", r->m_min, r->m_max);
    } else {
        fprintf(out, "\n");
    }
    if (r->have_mc) {
        char method[64];
        double shift = floor(o->mc_correction / o->dm + 0.5 + BK_MAG_BIN_EPS) * o->dm;
        if (o->mc_auto)
            snprintf(method, sizeof method, "maximum curvature %s %g, Woessner & Wiemer 2005",
                     shift < 0.0 ? "-" : "+", fabs(shift));
        else
            snprintf(method, sizeof method, "given");
        fprintf(out, "completeness: Mc = %.6g (%s), bins of dm = %g\n", r->mc, method, o->dm);
        fprintf(out, "  events at or above Mc: %zu (rate %.6g events/s)\n", r->n_above_mc,
                r->rate_above_mc);
    }
    if (r->have_b) {
        fprintf(out,
                "b-value: %.4f +- %.4f (Aki-Utsu maximum likelihood, Shi & Bolt error; Aki's "
                "b/sqrt(n) = %.4f), a = %.4f, over %zu events, mean magnitude %.4f\n",
                r->b.b, r->b.sigma, r->b.sigma_aki, r->b.a, r->b.n, r->b.mean);
        if (r->b_small_sample)
            fprintf(out, "  warning: small sample, %zu events at or above Mc (< %d): b is uncertain to "
                         "about 1/sqrt(n) = %.0f %%\n",
                    r->b.n, BK_B_SMALL_SAMPLE, 100.0 / sqrt((double)r->b.n));
        if (r->have_b_spread)
            fprintf(out, "  bootstrap (%zu resamples of the catalog, Mc %s): b +- %.4f, Mc +- %.4f\n",
                    r->b_spread.n_used, o->mc_auto ? "re-estimated" : "given", r->b_spread.b_sigma,
                    r->b_spread.mc_sigma);
    } else {
        fprintf(out, "b-value: not available: %s\n", r->b_note);
    }
    if (!r->have_gr_gof && r->have_b)
        fprintf(out, "  fit: not tested (--bootstrap 0)\n");
    if (r->have_gr_gof)
        fprintf(out, "  fit: %s Gutenberg-Richter above Mc: KS distance %.4f, bootstrap p = %.3g (%zu "
                     "synthetic samples, refitted)\n",
                r->gr_gof.p < BK_GOF_LEVEL ? "not" : "consistent with", r->gr_gof.d, r->gr_gof.p,
                r->gr_gof.n_synthetic);
    if (r->have_b_positive) {
        const bk_b_positive_estimate *bp = &r->b_positive;
        fprintf(out, "b-positive (van der Elst 2021; differences of successive magnitudes >= %g, binned "
                     "maximum likelihood): %.4f +- %.4f over %zu differences",
                bp->dmc, bp->fit.b, bp->fit.sigma, bp->fit.n);
        if (isfinite(bp->a))
            fprintf(out, ", a = %.4f (SeismoStats' a-positive)", bp->a);
        fprintf(out, "\n");
    } else if (r->have_mc) {
        fprintf(out, "b-positive: not available: %s\n", r->b_positive_note);
    }
    if (r->have_mc_stability)
        fprintf(out, "Mc by b-value stability (Woessner & Wiemer 2005, range 0.5): %.6g (b = %.4f, |b_avg - b| = %.3g "
                     "sigma)\n",
                r->mc_stability.mc, r->mc_stability.b, r->mc_stability.diff);
    else if (r->have_mfd)
        fprintf(out, "Mc by b-value stability: not available: %s\n", r->mc_stability_note);
    if (r->have_potency_exponent) {
        const bk_power_law *p = &r->potency_fit;
        fprintf(out, "potency exponent: alpha = %.4f +- %.4f over %zu events with P >= %.6g m "
                     "(%s)\n",
                p->alpha, p->sigma, p->n, p->x_min,
                r->potency_threshold_from_mc ? "the potency of M = Mc - dm/2"
                                             : "the smallest potency at or above Mc");
        if (r->have_b)
            fprintf(out, "  beta = alpha - 1 = %.4f; (2/3) b = %.4f (equal for m = (2/3) log10 P "
                         "+ const)\n",
                    p->alpha - 1.0, 2.0 / 3.0 * r->b.b);
    } else {
        fprintf(out, "potency exponent: not available: %s\n", r->potency_note);
    }
    if (r->have_potency_gof)
        fprintf(out, "  fit: %s a power law above P_min: KS distance %.4f, bootstrap p = %.3g (%zu "
                     "synthetic samples, refitted)\n",
                r->potency_gof.p < BK_GOF_LEVEL ? "not" : "consistent with", r->potency_gof.d, r->potency_gof.p,
                r->potency_gof.n_synthetic);
    if (r->have_recurrence)
        fprintf(out, "recurrence (M >= Mc): %zu events, mean interval %.6g s, sd %.6g s, "
                     "CV %.4f (1 for a Poisson process)\n",
                r->recurrence.n_events, r->recurrence.mean, r->recurrence.sd, r->recurrence.cv);
    else
        fprintf(out, "recurrence: not available: %s\n", r->recurrence_note);
    if (r->n_interevent > 0) {
        fprintf(out, "interevent times (Corral 2004: theta = tau R, R the rate above the threshold; "
                     "gamma fit by maximum likelihood; 1 for a Poisson process):\n");
        fprintf(out, "  %10s %8s %12s %8s %16s %10s\n", "M >=", "events", "R [1/s]", "CV", "gamma shape",
                "scale");
        for (size_t k = 0; k < r->n_interevent; ++k) {
            const bk_interevent *ie = &r->interevent[k];
            fprintf(out, "  %10.4g %8zu %12.6g %8.4f %8.4f +- %5.4f %10.4f%s\n", ie->m_min, ie->n_events, ie->rate,
                    ie->cv, ie->gamma_shape, ie->gamma_shape_sigma, ie->gamma_scale,
                    ie->n_zero ? " (zero intervals left out)" : "");
        }
    } else {
        fprintf(out, "interevent times: not available: %s\n", r->interevent_note);
    }
    if (r->have_sizes)
        fprintf(out, "sizes: %zu complete events, 1 to %d blocks, mean %.4g\n", r->sizes.n_events,
                (int)r->sizes.max_size, r->sizes.mean);
    else
        fprintf(out, "sizes: not available: %s\n", r->sizes_note);
    if (r->have_ks)
        fprintf(out, "stationarity: KS test of the binned magnitudes >= Mc before and after t = %.6g s "
                     "(%zu and %zu events): D = %.4f, p = %.4g%s\n",
                r->ks_t_split, r->ks.n1, r->ks.n2, r->ks.d, r->ks.p,
                r->ks.p < 0.05 ? " (differ at 5%)" : "");
    else
        fprintf(out, "stationarity: not available: %s\n", r->ks_note);
    if (r->have_mfd) {
        fprintf(out, "magnitude-frequency distribution:\n  %9s %12s %12s\n", "magnitude",
                "incremental", "cumulative");
        for (size_t i = 0; i < r->mfd.n_bins; ++i)
            fprintf(out, "  %9.4g %12zu %12zu\n", bk_mfd_centre(&r->mfd, i),
                    r->mfd.incremental[i], r->mfd.cumulative[i]);
    }
    return write_failed(out, "report", err);
}

/* ------------------------------------------------------------------ JSON --- */

/* The shortest text that reads back as the same double (0.1, not 0.10000000000000001);
 * JSON has no NaN or infinity: null. */
static void json_number(FILE *out, const char *key, double value, int last)
{
    char text[32] = "null";
    if (isfinite(value))
        for (int digits = 15; digits <= 17; ++digits) {
            snprintf(text, sizeof text, "%.*g", digits, value);
            if (strtod(text, NULL) == value)
                break;
        }
    fprintf(out, "\"%s\": %s%s", key, text, last ? "" : ", ");
}

static void json_count(FILE *out, const char *key, size_t value)
{
    fprintf(out, "\"%s\": %zu, ", key, value);
}

static void json_string_value(FILE *out, const char *s)
{
    fputc('"', out);
    for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
        if (*p == '"' || *p == '\\')
            fprintf(out, "\\%c", *p);
        else if (*p < 0x20)
            fprintf(out, "\\u%04x", *p);
        else
            fputc(*p, out);
    }
    fputc('"', out);
}

static void json_note(FILE *out, const char *key, int have, const char *note)
{
    if (have)
        return;
    fprintf(out, "\"%s\": ", key);
    json_string_value(out, note);
    fprintf(out, ", ");
}

/* "key": {"n": .., "ks_distance": .., "p_value": .., "synthetic_samples": .., "consistent": ..}
 * or null when the fit was not tested. */
static void json_gof(FILE *out, const char *key, int have, const bk_gof *g)
{
    fprintf(out, "\"%s\": ", key);
    if (!have) {
        fprintf(out, "null, ");
        return;
    }
    fprintf(out, "{\"n\": %zu, ", g->n);
    json_number(out, "ks_distance", g->d, 0);
    json_number(out, "p_value", g->p, 0);
    fprintf(out, "\"synthetic_samples\": %zu, \"consistent\": %s}, ", g->n_synthetic,
            g->p < BK_GOF_LEVEL ? "false" : "true");
}

int bk_stats_report_json(const bk_stats_report *r, FILE *out, bk_error *err)
{
    const double absent = NAN;
    fprintf(out, "{\"file\": ");
    json_string_value(out, r->path);
    fprintf(out, ", \"table\": ");
    if (r->table)
        json_string_value(out, r->table);
    else
        fprintf(out, "null");
    fprintf(out, ", \"table_fallback\": %s, ", r->table_fallback ? "true" : "false");
    json_count(out, "n_rows", r->n_rows);
    json_count(out, "n_incomplete", r->n_incomplete);
    json_count(out, "n_nonfinite", r->n_nonfinite);
    json_number(out, "t_from", r->options.t_from, 0);
    json_number(out, "t_to", r->options.t_to, 0);
    json_count(out, "n_outside_window", r->n_outside);
    json_count(out, "n_events", r->n_events);
    json_number(out, "duration", r->n_events ? r->duration : absent, 0);
    fprintf(out, "\"duration_source\": \"%s\", ", r->duration_from_run ? "run" : "catalog");
    json_number(out, "rate", r->n_events ? r->rate : absent, 0);
    json_number(out, "magnitude_min", r->n_events ? r->m_min : absent, 0);
    json_number(out, "magnitude_max", r->n_events ? r->m_max : absent, 0);
    json_number(out, "bin", r->options.dm, 0);
    json_number(out, "mc", r->have_mc ? r->mc : absent, 0);
    fprintf(out, "\"mc_method\": \"%s\", ", r->options.mc_auto ? "maxc" : "given");
    json_number(out, "mc_correction", r->options.mc_auto ? r->options.mc_correction : absent, 0);
    json_count(out, "n_above_mc", r->n_above_mc);
    json_number(out, "rate_above_mc", r->have_mc ? r->rate_above_mc : absent, 0);
    json_number(out, "b_value", r->have_b ? r->b.b : absent, 0);
    json_number(out, "b_value_error", r->have_b ? r->b.sigma : absent, 0);
    json_number(out, "b_value_error_aki", r->have_b ? r->b.sigma_aki : absent, 0);
    json_number(out, "a_value", r->have_b ? r->b.a : absent, 0);
    json_number(out, "mean_magnitude_above_mc", r->have_b ? r->b.mean : absent, 0);
    json_note(out, "b_value_note", r->have_b, r->b_note);
    fprintf(out, "\"n_b_value\": %zu, \"b_value_small_sample\": %s, ", r->have_b ? r->b.n : 0,
            r->have_b && r->b_small_sample ? "true" : "false");
    json_number(out, "b_value_error_bootstrap", r->have_b_spread ? r->b_spread.b_sigma : absent, 0);
    json_number(out, "mc_error_bootstrap", r->have_b_spread ? r->b_spread.mc_sigma : absent, 0);
    fprintf(out, "\"bootstrap_resamples\": %zu, ", r->have_b_spread ? r->b_spread.n_used : 0);
    json_gof(out, "gr_fit", r->have_gr_gof, &r->gr_gof);
    json_number(out, "b_positive", r->have_b_positive ? r->b_positive.fit.b : absent, 0);
    json_number(out, "b_positive_error", r->have_b_positive ? r->b_positive.fit.sigma : absent, 0);
    fprintf(out, "\"n_b_positive\": %zu, ", r->have_b_positive ? r->b_positive.fit.n : 0);
    json_number(out, "a_positive", r->have_b_positive ? r->b_positive.a : absent, 0);
    json_note(out, "b_positive_note", r->have_b_positive || !r->have_mc, r->b_positive_note);
    json_number(out, "mc_b_stability", r->have_mc_stability ? r->mc_stability.mc : absent, 0);
    json_note(out, "mc_b_stability_note", r->have_mc_stability || !r->have_mfd, r->mc_stability_note);
    const bk_power_law *p = &r->potency_fit;
    int hp = r->have_potency_exponent;
    json_number(out, "potency_exponent", hp ? p->alpha : absent, 0);
    json_number(out, "potency_exponent_error", hp ? p->sigma : absent, 0);
    json_number(out, "potency_min", hp ? p->x_min : absent, 0);
    fprintf(out, "\"n_potency\": %zu, ", hp ? p->n : 0);
    json_note(out, "potency_note", hp, r->potency_note);
    json_gof(out, "potency_fit", r->have_potency_gof, &r->potency_gof);
    const bk_recurrence *rec = &r->recurrence;
    int hr = r->have_recurrence;
    fprintf(out, "\"recurrence\": ");
    if (hr) {
        fprintf(out, "{");
        json_number(out, "magnitude_min", rec->m_min, 0);
        json_count(out, "n_events", rec->n_events);
        json_number(out, "mean_interval", rec->mean, 0);
        json_number(out, "sd_interval", rec->sd, 0);
        json_number(out, "cv", rec->cv, 1);
        fprintf(out, "}, ");
    } else {
        fprintf(out, "null, ");
    }
    json_note(out, "recurrence_note", hr, r->recurrence_note);
    fprintf(out, "\"interevent\": [");
    for (size_t k = 0; k < r->n_interevent; ++k) {
        const bk_interevent *ie = &r->interevent[k];
        fprintf(out, "%s{", k ? ", " : "");
        json_number(out, "magnitude_min", ie->m_min, 0);
        json_count(out, "n_events", ie->n_events);
        json_number(out, "rate", ie->rate, 0);
        json_number(out, "cv", ie->cv, 0);
        json_count(out, "zero_intervals", ie->n_zero);
        json_number(out, "gamma_shape", ie->gamma_shape, 0);
        json_number(out, "gamma_shape_error", ie->gamma_shape_sigma, 0);
        json_number(out, "gamma_scale", ie->gamma_scale, 1);
        fprintf(out, "}");
    }
    fprintf(out, "], ");
    if (r->n_interevent == 0) {
        fprintf(out, "\"interevent_note\": ");
        json_string_value(out, r->interevent_note);
        fprintf(out, ", ");
    }
    fprintf(out, "\"sizes\": ");
    if (r->have_sizes) {
        fprintf(out, "{");
        json_count(out, "n_events", r->sizes.n_events);
        fprintf(out, "\"max\": %d, ", (int)r->sizes.max_size);
        json_number(out, "mean", r->sizes.mean, 1);
        fprintf(out, "}, ");
    } else {
        fprintf(out, "null, ");
    }
    json_note(out, "sizes_note", r->have_sizes, r->sizes_note);
    fprintf(out, "\"ks_halves\": ");
    if (r->have_ks) {
        fprintf(out, "{");
        json_number(out, "t_split", r->ks_t_split, 0);
        json_count(out, "n1", r->ks.n1);
        json_count(out, "n2", r->ks.n2);
        json_number(out, "d", r->ks.d, 0);
        json_number(out, "p", r->ks.p, 1);
        fprintf(out, "}, ");
    } else {
        fprintf(out, "null, ");
    }
    json_note(out, "ks_note", r->have_ks, r->ks_note);
    fprintf(out, "\"mfd\": ");
    if (r->have_mfd) {
        const char *cols[] = {"magnitude", "incremental", "cumulative"};
        fprintf(out, "{");
        for (int c = 0; c < 3; ++c) {
            fprintf(out, "%s\"%s\": [", c ? ", " : "", cols[c]);
            for (size_t i = 0; i < r->mfd.n_bins; ++i) {
                if (i)
                    fprintf(out, ", ");
                if (c == 0)
                    fprintf(out, "%.10g", bk_mfd_centre(&r->mfd, i));
                else
                    fprintf(out, "%zu", c == 1 ? r->mfd.incremental[i] : r->mfd.cumulative[i]);
            }
            fprintf(out, "]");
        }
        fprintf(out, "}");
    } else {
        fprintf(out, "null");
    }
    fprintf(out, "}\n");
    return write_failed(out, "JSON report", err);
}

/* ------------------------------------------------------------------- TSV --- */

static FILE *open_table(const char *dir, const char *name, char *path, size_t len,
                        const char *header, bk_error *err)
{
    int w = snprintf(path, len, "%s/%s", dir, name);
    if (w < 0 || (size_t)w >= len) {
        BK_FAIL(err, BK_ERR_IO, "%s/%s: path too long", dir, name);
        return NULL;
    }
    FILE *f = fopen(path, "w");
    if (!f) {
        BK_FAIL(err, BK_ERR_IO, "%s: %s", path, strerror(errno));
        return NULL;
    }
    fprintf(f, "%s\n", header);
    return f;
}

static int close_table(FILE *f, const char *path, bk_error *err)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return BK_FAIL(err, BK_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return BK_OK;
}

static int compare_desc(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a < b) - (a > b);
}

static int potency_table(const bk_stats_report *r, const char *dir, char *path, size_t len,
                         bk_error *err)
{
    double *p = malloc((r->n_events ? r->n_events : 1) * sizeof *p);
    if (!p)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu potencies", r->n_events);
    size_t n = 0;
    for (size_t i = 0; i < r->n_events; ++i)
        if (isfinite(r->potency[i]) && r->potency[i] > 0.0)
            p[n++] = r->potency[i];
    qsort(p, n, sizeof *p, compare_desc);
    FILE *f = open_table(dir, "potency_ccdf.tsv", path, len, "# potency[m]\tn_at_or_above[1]", err);
    if (!f) {
        free(p);
        return err ? err->status : BK_ERR_IO;
    }
    /* One row per distinct potency: the count at or above it is the last rank of its ties. */
    for (size_t i = 0; i < n; ++i)
        if (i + 1 == n || p[i + 1] != p[i])
            fprintf(f, "%.10g\t%zu\n", p[i], i + 1);
    free(p);
    return close_table(f, path, err);
}

int bk_stats_report_tsv(const bk_stats_report *r, const char *dir, bk_error *err)
{
    struct stat st;
    if (stat(dir, &st) != 0) {
        if (errno != ENOENT || mkdir(dir, 0777) != 0)
            return BK_FAIL(err, BK_ERR_IO, "%s: cannot create the table directory: %s", dir,
                           strerror(errno));
    } else if (!S_ISDIR(st.st_mode)) {
        return BK_FAIL(err, BK_ERR_IO, "%s: exists and is not a directory", dir);
    }
    char path[4096];
    FILE *f;
    int rc;
    if (r->have_mfd) {
        if (!(f = open_table(dir, "mfd.tsv", path, sizeof path,
                             "# magnitude[1]\tincremental[1]\tcumulative[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t i = 0; i < r->mfd.n_bins; ++i)
            fprintf(f, "%.10g\t%zu\t%zu\n", bk_mfd_centre(&r->mfd, i), r->mfd.incremental[i],
                    r->mfd.cumulative[i]);
        if ((rc = close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->have_b) {
        /* The fitted law N(>= M) = 10^(a - b M) at the bin centres from Mc up. */
        if (!(f = open_table(dir, "gr_fit.tsv", path, sizeof path,
                             "# magnitude[1]\tcumulative_fit[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t i = 0; i < r->mfd.n_bins; ++i) {
            double m = bk_mfd_centre(&r->mfd, i);
            if (m >= r->mc - 0.5 * r->options.dm)
                fprintf(f, "%.10g\t%.10g\n", m, pow(10.0, r->b.a - r->b.b * m));
        }
        if ((rc = close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->have_sizes) {
        if (!(f = open_table(dir, "sizes.tsv", path, sizeof path, "# n_blocks[1]\tcount[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (int32_t s = 1; s <= r->sizes.max_size; ++s)
            if (r->sizes.count[s])
                fprintf(f, "%d\t%zu\n", (int)s, r->sizes.count[s]);
        if ((rc = close_table(f, path, err)) != BK_OK)
            return rc;
        if (!(f = open_table(dir, "sizes_log2.tsv", path, sizeof path,
                             "# n_blocks_min[1]\tn_blocks_max[1]\tcount[1]\tcount_per_size[1]",
                             err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t j = 0; j < r->sizes.n_log2; ++j) {
            double lo = ldexp(1.0, (int)j), hi = ldexp(1.0, (int)j + 1) - 1.0;
            fprintf(f, "%.0f\t%.0f\t%zu\t%.10g\n", lo, hi, r->sizes.log2_count[j],
                    (double)r->sizes.log2_count[j] / lo);
        }
        if ((rc = close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->have_recurrence) {
        if (!(f = open_table(dir, "intervals.tsv", path, sizeof path,
                             "# t_start[s]\tinterval[s]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t i = 0; i < r->recurrence.n_intervals; ++i)
            fprintf(f, "%.17g\t%.17g\n", r->recurrence.t[i], r->recurrence.interval[i]);
        if ((rc = close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->n_interevent > 0) {
        /* One block per threshold, blank lines between (gnuplot's index). */
        if (!(f = open_table(dir, "interevent.tsv", path, sizeof path,
                             "# magnitude_min[1]\ttheta[1]\tdensity[1]\tgamma_fit[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t k = 0; k < r->n_interevent; ++k) {
            const bk_interevent *ie = &r->interevent[k];
            double norm = 1.0 / (tgamma(ie->gamma_shape) * pow(ie->gamma_scale, ie->gamma_shape));
            for (size_t b = 0; b < ie->n_bins; ++b) {
                double x = ie->theta[b];
                fprintf(f, "%.17g\t%.17g\t%.17g\t%.17g\n", ie->m_min, x, ie->density[b],
                        norm * pow(x, ie->gamma_shape - 1.0) * exp(-x / ie->gamma_scale));
            }
            if (k + 1 < r->n_interevent)
                fprintf(f, "\n\n");
        }
        if ((rc = close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->potency && r->n_events)
        return potency_table(r, dir, path, sizeof path, err);
    return BK_OK;
}
