/* `bksim stats`: the report of src/stats_report.c presented as text, one JSON object, or
 * TSV tables for gnuplot. */
#include "bksim/stats.h"
#include "bksim/stats_truncated.h"
#include "stats_print_impl.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ------------------------------------------------------------------ text --- */

int bk_stats_report_text(const bk_stats_report *r, FILE *out, bk_error *err)
{
    const bk_stats_options *o = &r->options;
    fprintf(out, "catalog: %s\n", r->path);
    /* Which table: the default /ruptures, the /events it falls back to, or one named. */
    const char *what = bk_stats_table_note(r->table, r->table_fallback);
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
    if (r->truncation) {
        const bk_gr_truncation *tr = r->truncation;
        const bk_b_truncated_estimate *f = &tr->fit;
        fprintf(out, "truncated GR (Mc to the largest Mu whose range passes the fit test; Weichert 1980, binned): "
                     "%.4f +- %.4f over M %.6g to %.6g, %zu events",
                f->b, f->sigma, f->mc, f->mu, f->n);
        if (f->n_above)
            fprintf(out, "; %zu above Mu (up to %.6g) left out: a size cutoff", f->n_above, tr->m_top);
        else
            fprintf(out, "; the whole range (no cutoff)");
        fprintf(out, "\n  fit: KS distance %.4f, deviance %.4g, p = %.3g (%zu synthetic samples, refitted)\n",
                tr->gof.d, tr->gof.g, tr->gof.p, tr->gof.n_synthetic);
    } else if (r->have_mc) {
        fprintf(out, "truncated GR: not available: %s\n", r->truncation_note);
    }
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
    if (r->have_mc_ks)
        fprintf(out, "Mc by the KS method (first magnitude whose GR fit passes at p >= %g, %zu synthetic samples): %.6g "
                     "(b = %.4f, KS distance %.4f, p = %.3g, %zu events)\n",
                BK_MC_KS_P_PASS, r->options.bootstrap, r->mc_ks.mc, r->mc_ks.b, r->mc_ks.d, r->mc_ks.p, r->mc_ks.n);
    else if (r->have_mfd)
        fprintf(out, "Mc by the KS method: not available: %s\n", r->mc_ks_note);
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
    bk_stats_text_sequences(r, out);
    bk_stats_text_scaling(r, out);
    if (r->have_sizes) {
        int smallest = 0; /* the counts hold it: sizes begin at 1 only where an event of one block was */
        while (smallest < r->sizes.max_size && r->sizes.count[smallest] == 0)
            ++smallest;
        fprintf(out, "sizes: %zu complete events, %d to %d blocks, mean %.4g\n", r->sizes.n_events, smallest,
                (int)r->sizes.max_size, r->sizes.mean);
    }
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
    return bk_stats_write_failed(out, "report", err);
}

/* ------------------------------------------------------------------ JSON --- */

int bk_stats_report_json(const bk_stats_report *r, FILE *out, bk_error *err)
{
    const double absent = NAN;
    fprintf(out, "{\"file\": ");
    bk_json_string(out, r->path);
    fprintf(out, ", \"table\": ");
    if (r->table)
        bk_json_string(out, r->table);
    else
        fprintf(out, "null");
    fprintf(out, ", \"table_fallback\": %s, ", r->table_fallback ? "true" : "false");
    bk_json_count(out, "n_rows", r->n_rows);
    bk_json_count(out, "n_incomplete", r->n_incomplete);
    bk_json_count(out, "n_nonfinite", r->n_nonfinite);
    bk_json_number(out, "t_from", r->options.t_from, 0);
    bk_json_number(out, "t_to", r->options.t_to, 0);
    bk_json_count(out, "n_outside_window", r->n_outside);
    bk_json_count(out, "n_events", r->n_events);
    bk_json_number(out, "duration", r->n_events ? r->duration : absent, 0);
    fprintf(out, "\"duration_source\": \"%s\", ", r->duration_from_run ? "run" : "catalog");
    bk_json_number(out, "rate", r->n_events ? r->rate : absent, 0);
    bk_json_number(out, "magnitude_min", r->n_events ? r->m_min : absent, 0);
    bk_json_number(out, "magnitude_max", r->n_events ? r->m_max : absent, 0);
    bk_json_number(out, "bin", r->options.dm, 0);
    bk_json_number(out, "mc", r->have_mc ? r->mc : absent, 0);
    fprintf(out, "\"mc_method\": \"%s\", ", r->options.mc_auto ? "maxc" : "given");
    bk_json_number(out, "mc_correction", r->options.mc_auto ? r->options.mc_correction : absent, 0);
    bk_json_count(out, "n_above_mc", r->n_above_mc);
    bk_json_number(out, "rate_above_mc", r->have_mc ? r->rate_above_mc : absent, 0);
    bk_json_number(out, "b_value", r->have_b ? r->b.b : absent, 0);
    bk_json_number(out, "b_value_error", r->have_b ? r->b.sigma : absent, 0);
    bk_json_number(out, "b_value_error_aki", r->have_b ? r->b.sigma_aki : absent, 0);
    bk_json_number(out, "a_value", r->have_b ? r->b.a : absent, 0);
    bk_json_number(out, "mean_magnitude_above_mc", r->have_b ? r->b.mean : absent, 0);
    bk_json_note(out, "b_value_note", r->have_b, r->b_note);
    fprintf(out, "\"n_b_value\": %zu, \"b_value_small_sample\": %s, ", r->have_b ? r->b.n : 0,
            r->have_b && r->b_small_sample ? "true" : "false");
    bk_json_number(out, "b_value_error_bootstrap", r->have_b_spread ? r->b_spread.b_sigma : absent, 0);
    bk_json_number(out, "mc_error_bootstrap", r->have_b_spread ? r->b_spread.mc_sigma : absent, 0);
    fprintf(out, "\"bootstrap_resamples\": %zu, ", r->have_b_spread ? r->b_spread.n_used : 0);
    bk_json_gof(out, "gr_fit", r->have_gr_gof, &r->gr_gof);
    fprintf(out, "\"gr_truncated\": ");
    if (r->truncation) {
        const bk_gr_truncation *tr = r->truncation;
        fprintf(out, "{");
        bk_json_number(out, "b_value", tr->fit.b, 0);
        bk_json_number(out, "b_value_error", tr->fit.sigma, 0);
        bk_json_number(out, "magnitude_min", tr->fit.mc, 0);
        bk_json_number(out, "magnitude_max", tr->fit.mu, 0);
        bk_json_number(out, "magnitude_top", tr->m_top, 0);
        bk_json_count(out, "n", tr->fit.n);
        bk_json_count(out, "n_above", tr->fit.n_above);
        bk_json_number(out, "a_bin", tr->fit.a_bin, 0);
        bk_json_number(out, "ks_distance", tr->gof.d, 0);
        bk_json_number(out, "deviance", tr->gof.g, 0);
        bk_json_number(out, "p_value", tr->gof.p, 0);
        fprintf(out, "\"synthetic_samples\": %zu}, ", tr->gof.n_synthetic);
    } else {
        fprintf(out, "null, ");
        bk_json_note(out, "gr_truncated_note", 0, r->have_mc ? r->truncation_note : "no Mc");
    }
    bk_json_number(out, "b_positive", r->have_b_positive ? r->b_positive.fit.b : absent, 0);
    bk_json_number(out, "b_positive_error", r->have_b_positive ? r->b_positive.fit.sigma : absent, 0);
    fprintf(out, "\"n_b_positive\": %zu, ", r->have_b_positive ? r->b_positive.fit.n : 0);
    bk_json_number(out, "a_positive", r->have_b_positive ? r->b_positive.a : absent, 0);
    bk_json_note(out, "b_positive_note", r->have_b_positive || !r->have_mc, r->b_positive_note);
    bk_json_number(out, "mc_b_stability", r->have_mc_stability ? r->mc_stability.mc : absent, 0);
    bk_json_note(out, "mc_b_stability_note", r->have_mc_stability || !r->have_mfd, r->mc_stability_note);
    bk_json_number(out, "mc_ks", r->have_mc_ks ? r->mc_ks.mc : absent, 0);
    bk_json_number(out, "mc_ks_p", r->have_mc_ks ? r->mc_ks.p : absent, 0);
    bk_json_note(out, "mc_ks_note", r->have_mc_ks || !r->have_mfd, r->mc_ks_note);
    const bk_power_law *p = &r->potency_fit;
    int hp = r->have_potency_exponent;
    bk_json_number(out, "potency_exponent", hp ? p->alpha : absent, 0);
    bk_json_number(out, "potency_exponent_error", hp ? p->sigma : absent, 0);
    bk_json_number(out, "potency_min", hp ? p->x_min : absent, 0);
    fprintf(out, "\"n_potency\": %zu, ", hp ? p->n : 0);
    bk_json_note(out, "potency_note", hp, r->potency_note);
    bk_json_gof(out, "potency_fit", r->have_potency_gof, &r->potency_gof);
    const bk_recurrence *rec = &r->recurrence;
    int hr = r->have_recurrence;
    fprintf(out, "\"recurrence\": ");
    if (hr) {
        fprintf(out, "{");
        bk_json_number(out, "magnitude_min", rec->m_min, 0);
        bk_json_count(out, "n_events", rec->n_events);
        bk_json_number(out, "mean_interval", rec->mean, 0);
        bk_json_number(out, "sd_interval", rec->sd, 0);
        bk_json_number(out, "cv", rec->cv, 1);
        fprintf(out, "}, ");
    } else {
        fprintf(out, "null, ");
    }
    bk_json_note(out, "recurrence_note", hr, r->recurrence_note);
    fprintf(out, "\"interevent\": [");
    for (size_t k = 0; k < r->n_interevent; ++k) {
        const bk_interevent *ie = &r->interevent[k];
        fprintf(out, "%s{", k ? ", " : "");
        bk_json_number(out, "magnitude_min", ie->m_min, 0);
        bk_json_count(out, "n_events", ie->n_events);
        bk_json_number(out, "rate", ie->rate, 0);
        bk_json_number(out, "cv", ie->cv, 0);
        bk_json_count(out, "zero_intervals", ie->n_zero);
        bk_json_number(out, "gamma_shape", ie->gamma_shape, 0);
        bk_json_number(out, "gamma_shape_error", ie->gamma_shape_sigma, 0);
        bk_json_number(out, "gamma_scale", ie->gamma_scale, 1);
        fprintf(out, "}");
    }
    fprintf(out, "], ");
    if (r->n_interevent == 0) {
        fprintf(out, "\"interevent_note\": ");
        bk_json_string(out, r->interevent_note);
        fprintf(out, ", ");
    }
    bk_stats_json_sequences(r, out);
    bk_stats_json_scaling(r, out);
    fprintf(out, "\"sizes\": ");
    if (r->have_sizes) {
        fprintf(out, "{");
        bk_json_count(out, "n_events", r->sizes.n_events);
        fprintf(out, "\"max\": %d, ", (int)r->sizes.max_size);
        bk_json_number(out, "mean", r->sizes.mean, 1);
        fprintf(out, "}, ");
    } else {
        fprintf(out, "null, ");
    }
    bk_json_note(out, "sizes_note", r->have_sizes, r->sizes_note);
    fprintf(out, "\"ks_halves\": ");
    if (r->have_ks) {
        fprintf(out, "{");
        bk_json_number(out, "t_split", r->ks_t_split, 0);
        bk_json_count(out, "n1", r->ks.n1);
        bk_json_count(out, "n2", r->ks.n2);
        bk_json_number(out, "d", r->ks.d, 0);
        bk_json_number(out, "p", r->ks.p, 1);
        fprintf(out, "}, ");
    } else {
        fprintf(out, "null, ");
    }
    bk_json_note(out, "ks_note", r->have_ks, r->ks_note);
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
    return bk_stats_write_failed(out, "JSON report", err);
}

/* ------------------------------------------------------------------- TSV --- */

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
    FILE *f = bk_stats_open_table(dir, "potency_ccdf.tsv", path, len, "# potency[m]\tn_at_or_above[1]", err);
    if (!f) {
        free(p);
        return err ? err->status : BK_ERR_IO;
    }
    /* One row per distinct potency: the count at or above it is the last rank of its ties. */
    for (size_t i = 0; i < n; ++i)
        if (i + 1 == n || p[i + 1] != p[i])
            fprintf(f, "%.10g\t%zu\n", p[i], i + 1);
    free(p);
    return bk_stats_close_table(f, path, err);
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
        if (!(f = bk_stats_open_table(dir, "mfd.tsv", path, sizeof path,
                             "# magnitude[1]\tincremental[1]\tcumulative[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t i = 0; i < r->mfd.n_bins; ++i)
            fprintf(f, "%.10g\t%zu\t%zu\n", bk_mfd_centre(&r->mfd, i), r->mfd.incremental[i],
                    r->mfd.cumulative[i]);
        if ((rc = bk_stats_close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->have_b) {
        /* The fitted law N(>= M) = 10^(a - b M) at the bin centres from Mc up. */
        if (!(f = bk_stats_open_table(dir, "gr_fit.tsv", path, sizeof path,
                             "# magnitude[1]\tcumulative_fit[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t i = 0; i < r->mfd.n_bins; ++i) {
            double m = bk_mfd_centre(&r->mfd, i);
            if (m >= r->mc - 0.5 * r->options.dm)
                fprintf(f, "%.10g\t%.10g\n", m, pow(10.0, r->b.a - r->b.b * m));
        }
        if ((rc = bk_stats_close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->truncation) {
        /* The fitted count per bin from Mc to Mu, 10^(a_bin - b M), beside mfd.tsv's incremental counts. */
        const bk_b_truncated_estimate *t = &r->truncation->fit;
        if (!(f = bk_stats_open_table(dir, "gr_truncated_fit.tsv", path, sizeof path,
                                      "# magnitude[1]\tincremental_fit[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t j = 0; j < t->n_bins; ++j) {
            double m = t->mc + (double)j * t->dm;
            fprintf(f, "%.10g\t%.10g\n", m, pow(10.0, t->a_bin - t->b * m));
        }
        if ((rc = bk_stats_close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->have_sizes) {
        if (!(f = bk_stats_open_table(dir, "sizes.tsv", path, sizeof path, "# n_blocks[1]\tcount[1]", err)))
            return err ? err->status : BK_ERR_IO;
        for (int32_t s = 1; s <= r->sizes.max_size; ++s)
            if (r->sizes.count[s])
                fprintf(f, "%d\t%zu\n", (int)s, r->sizes.count[s]);
        if ((rc = bk_stats_close_table(f, path, err)) != BK_OK)
            return rc;
        if (!(f = bk_stats_open_table(dir, "sizes_log2.tsv", path, sizeof path,
                             "# n_blocks_min[1]\tn_blocks_max[1]\tcount[1]\tcount_per_size[1]",
                             err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t j = 0; j < r->sizes.n_log2; ++j) {
            double lo = ldexp(1.0, (int)j), hi = ldexp(1.0, (int)j + 1) - 1.0;
            fprintf(f, "%.0f\t%.0f\t%zu\t%.10g\n", lo, hi, r->sizes.log2_count[j],
                    (double)r->sizes.log2_count[j] / lo);
        }
        if ((rc = bk_stats_close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->have_recurrence) {
        if (!(f = bk_stats_open_table(dir, "intervals.tsv", path, sizeof path,
                             "# t_start[s]\tinterval[s]", err)))
            return err ? err->status : BK_ERR_IO;
        for (size_t i = 0; i < r->recurrence.n_intervals; ++i)
            fprintf(f, "%.17g\t%.17g\n", r->recurrence.t[i], r->recurrence.interval[i]);
        if ((rc = bk_stats_close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if (r->n_interevent > 0) {
        /* One block per threshold, blank lines between (gnuplot's index). */
        if (!(f = bk_stats_open_table(dir, "interevent.tsv", path, sizeof path,
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
        if ((rc = bk_stats_close_table(f, path, err)) != BK_OK)
            return rc;
    }
    if ((rc = bk_stats_tsv_sequences(r, dir, err)) != BK_OK || (rc = bk_stats_tsv_scaling(r, dir, err)) != BK_OK)
        return rc;
    if (r->potency && r->n_events)
        return potency_table(r, dir, path, sizeof path, err);
    return BK_OK;
}
