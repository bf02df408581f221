/* The mainshock-sequence section of `bksim stats` (bk_stats_report's sequences): text, JSON
 * and the TSV tables of the Omori plot (scripts/plot_stats.sh). */
#include "stats_print_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Logarithmic bins of the stacked offsets per decade: the Omori plot's resolution. */
#define OMORI_BINS_PER_DECADE 5

static void text_stack(FILE *out, const bk_sequences *s, const bk_sequence_stack *k, const char *name,
                       const char *law, const char *decay)
{
    if (!k->have_fit) {
        fprintf(out, "  %s: not available: %s\n", name, k->note);
        return;
    }
    const bk_omori *f = &k->fit;
    double per = 1.0 / (double)s->n_mainshocks;
    fprintf(out, "  %s (%s, stacked over %zu mainshocks): %zu events in (0, %.6g] s\n", name, law, s->n_mainshocks,
            k->n, s->window);
    fprintf(out, "    n(t) = K / (t + c)^p: K = %.4g +- %.2g per mainshock, c = %.4g +- %.2g s, p = %.4f +- %.4f\n",
            f->k * per, f->k_sigma * per, f->c, f->c_sigma, f->p, f->p_sigma);
    int changes = f->lr > BK_OMORI_LR_CHI2_2DOF_1PC;
    fprintf(out, "    likelihood ratio against a constant rate: %.4g (%s %.4g: %s)\n", f->lr, changes ? ">" : "<=",
            BK_OMORI_LR_CHI2_2DOF_1PC,
            f->decays ? decay
                      : changes ? "p <= 0: no decay" : "no significant change from a constant rate");
    if (f->p <= BK_OMORI_P_LOWEST + 1e-6 || f->p >= BK_OMORI_P_HIGHEST - 1e-6)
        fprintf(out, "    p is at the bound of the search (%g < p < %g): the law does not fit these times\n",
                BK_OMORI_P_LOWEST, BK_OMORI_P_HIGHEST);
    if (k->have_residuals)
        fprintf(out, "    residuals (Ogata's transformed time, %.6g events expected): KS D = %.4f, p = %.3g: %s\n",
                k->residuals.tau_end, k->residuals.d, k->residuals.p,
                k->residuals.p < BK_GOF_LEVEL ? "the fitted law does not describe the times"
                                              : "consistent with the fitted law");
}

void bk_stats_text_sequences(const bk_stats_report *r, FILE *out)
{
    if (!r->have_sequences) {
        if (r->have_mc)
            fprintf(out, "mainshock sequences: not available: %s\n", r->sequences_note);
        return;
    }
    const bk_sequences *s = &r->sequences;
    fprintf(out, "mainshock sequences (mainshocks: M >= %.6g, the largest within +-%.6g s; events M >= Mc = %.6g):\n",
            s->m_main, s->window, s->m_min);
    fprintf(out, "  mainshocks: %zu of %zu events at or above %.6g (%zu with a larger or earlier equal event within "
                 "+-%.6g s, %zu too near the span's ends)\n",
            s->n_mainshocks, s->n_candidates, s->m_main, s->n_not_largest, s->window, s->n_at_edges);
    if (s->n_mainshocks == 0)
        return;
    text_stack(out, s, &s->after, "aftershocks", "Omori-Utsu, Ogata 1983", "decays, 1 % level");
    text_stack(out, s, &s->before, "foreshocks", "inverse Omori, time before the mainshock",
               "grows toward the mainshock, 1 % level");
    if (s->n_fitted > 0) {
        size_t decays = 0;
        double p_lo = INFINITY, p_hi = -INFINITY;
        for (size_t i = 0; i < s->n_mainshocks; ++i)
            if (s->sequence[i].have_fit) {
                decays += (size_t)s->sequence[i].fit.decays;
                p_lo = fmin(p_lo, s->sequence[i].fit.p);
                p_hi = fmax(p_hi, s->sequence[i].fit.p);
            }
        fprintf(out, "  single sequences with >= %d aftershocks: %zu fitted, %zu decay (1 %% level); p from %.4g to %.4g\n",
                BK_OMORI_MIN_EVENTS, s->n_fitted, decays, p_lo, p_hi);
    } else {
        fprintf(out, "  single sequences: none with >= %d aftershocks\n", BK_OMORI_MIN_EVENTS);
    }
}

static void json_omori(FILE *out, const bk_omori *f, double per)
{
    fprintf(out, "{");
    bk_json_count(out, "n", f->n);
    bk_json_number(out, "k_per_mainshock", f->k * per, 0);
    bk_json_number(out, "k_per_mainshock_error", f->k_sigma * per, 0);
    bk_json_number(out, "c", f->c, 0);
    bk_json_number(out, "c_error", f->c_sigma, 0);
    bk_json_number(out, "p", f->p, 0);
    bk_json_number(out, "p_error", f->p_sigma, 0);
    bk_json_number(out, "likelihood_ratio", f->lr, 0);
    fprintf(out, "\"decays\": %s}", f->decays ? "true" : "false");
}

static void json_stack(FILE *out, const char *key, const bk_sequences *s, const bk_sequence_stack *k)
{
    fprintf(out, "\"%s\": {", key);
    bk_json_count(out, "n", k->n);
    fprintf(out, "\"omori\": ");
    if (k->have_fit) {
        json_omori(out, &k->fit, 1.0 / (double)s->n_mainshocks);
        fprintf(out, ", ");
    } else {
        fprintf(out, "null, ");
        bk_json_note(out, "omori_note", 0, k->note);
    }
    fprintf(out, "\"residuals\": ");
    if (k->have_residuals) {
        fprintf(out, "{");
        bk_json_number(out, "expected", k->residuals.tau_end, 0);
        bk_json_number(out, "ks_distance", k->residuals.d, 0);
        bk_json_number(out, "p_value", k->residuals.p, 0);
        fprintf(out, "\"consistent\": %s}", k->residuals.p < BK_GOF_LEVEL ? "false" : "true");
    } else {
        fprintf(out, "null");
    }
    fprintf(out, "}, ");
}

void bk_stats_json_sequences(const bk_stats_report *r, FILE *out)
{
    fprintf(out, "\"sequences\": ");
    if (!r->have_sequences) {
        fprintf(out, "null, ");
        bk_json_note(out, "sequences_note", 0, r->have_mc ? r->sequences_note : "no Mc");
        return;
    }
    const bk_sequences *s = &r->sequences;
    fprintf(out, "{");
    bk_json_number(out, "mainshock_magnitude", s->m_main, 0);
    bk_json_number(out, "magnitude_min", s->m_min, 0);
    bk_json_number(out, "window", s->window, 0);
    bk_json_count(out, "n_candidates", s->n_candidates);
    bk_json_count(out, "n_not_largest", s->n_not_largest);
    bk_json_count(out, "n_at_edges", s->n_at_edges);
    bk_json_count(out, "n_simultaneous", s->n_simultaneous);
    bk_json_count(out, "n_mainshocks", s->n_mainshocks);
    json_stack(out, "aftershocks", s, &s->after);
    json_stack(out, "foreshocks", s, &s->before);
    fprintf(out, "\"single\": [");
    for (size_t i = 0; i < s->n_mainshocks; ++i) {
        const bk_sequence *q = &s->sequence[i];
        fprintf(out, "%s{", i ? ", " : "");
        bk_json_number(out, "t", q->t_main, 0);
        bk_json_number(out, "magnitude", q->m_main, 0);
        bk_json_count(out, "n_after", q->n_after);
        bk_json_count(out, "n_before", q->n_before);
        fprintf(out, "\"omori\": ");
        if (q->have_fit)
            json_omori(out, &q->fit, 1.0);
        else
            fprintf(out, "null");
        fprintf(out, "}");
    }
    fprintf(out, "]}, ");
}

/* The stacked rate per mainshock on logarithmic bins of the offset, beside the fitted law's
 * mean over each bin.  The first bin starts at the smallest offset (rounded down to a bin
 * edge): Omori's early times span decades. */
static void rate_block(FILE *f, const bk_sequences *s, const bk_sequence_stack *k)
{
    double lo = INFINITY;
    for (size_t i = 0; i < k->n; ++i)
        lo = fmin(lo, k->offset[i]);
    if (!(lo > 0.0) || !isfinite(lo))
        return;
    double step = 1.0 / OMORI_BINS_PER_DECADE;
    double first = floor(log10(lo) / step) * step, last = log10(s->window);
    size_t n_bins = (size_t)ceil((last - first) / step);
    if (n_bins == 0)
        n_bins = 1;
    size_t *count = calloc(n_bins, sizeof *count);
    if (!count)
        return;
    for (size_t i = 0; i < k->n; ++i) {
        double x = (log10(k->offset[i]) - first) / step;
        size_t b = x < 0.0 ? 0 : (size_t)x;
        count[b < n_bins ? b : n_bins - 1]++;
    }
    double per = 1.0 / (double)s->n_mainshocks;
    const bk_omori *fit = &k->fit;
    for (size_t b = 0; b < n_bins; ++b) {
        double a = pow(10.0, first + step * (double)b), z = fmin(pow(10.0, first + step * (double)(b + 1)), s->window);
        if (!(z > a))
            continue;
        double mean_fit = NAN;
        if (k->have_fit) {
            double integral = fabs(fit->p - 1.0) < 1e-9
                                  ? log((z + fit->c) / (a + fit->c))
                                  : (pow(z + fit->c, 1.0 - fit->p) - pow(a + fit->c, 1.0 - fit->p)) / (1.0 - fit->p);
            mean_fit = fit->k * per * integral / (z - a);
        }
        fprintf(f, "%.10g\t%.10g\t%zu\t%.10g\n", sqrt(a * z), (double)count[b] * per / (z - a), count[b], mean_fit);
    }
    free(count);
}

int bk_stats_tsv_sequences(const bk_stats_report *r, const char *dir, bk_error *err)
{
    if (!r->have_sequences || r->sequences.n_mainshocks == 0)
        return BK_OK;
    const bk_sequences *s = &r->sequences;
    char path[4096];
    /* Aftershocks then foreshocks, one block each (gnuplot's index 0 and 1). */
    FILE *f = bk_stats_open_table(dir, "omori.tsv", path, sizeof path,
                                  "# time_from_mainshock[s]\trate_per_mainshock[1/s]\tcount[1]\tfit_rate[1/s]", err);
    if (!f)
        return err ? err->status : BK_ERR_IO;
    rate_block(f, s, &s->after);
    fprintf(f, "\n\n");
    rate_block(f, s, &s->before);
    int rc = bk_stats_close_table(f, path, err);
    if (rc != BK_OK)
        return rc;
    /* Ogata's residual plot: cumulative count against transformed time, the diagonal under
     * the fitted law. */
    f = bk_stats_open_table(dir, "omori_residuals.tsv", path, sizeof path,
                            "# transformed_time[1]\tcumulative_count[1]", err);
    if (!f)
        return err ? err->status : BK_ERR_IO;
    const bk_sequence_stack *stacks[2] = {&s->after, &s->before};
    for (int j = 0; j < 2; ++j) {
        if (j)
            fprintf(f, "\n\n");
        if (stacks[j]->have_residuals)
            for (size_t i = 0; i < stacks[j]->residuals.n; ++i)
                fprintf(f, "%.10g\t%zu\n", stacks[j]->residuals.tau[i], i + 1);
    }
    return bk_stats_close_table(f, path, err);
}
