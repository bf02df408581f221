/* The scaling-relation section of `bksim stats` (bk_stats_report's scaling; the fits are
 * bksim/stats_scaling.h's): text, JSON, and the binned medians the plot draws. */
#include "bksim/stats_scaling.h"
#include "stats_print_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Logarithmic bins per decade of duration and length in the TSV tables. */
#define SCALING_BINS_PER_DECADE 5

static void text_fit(FILE *out, int have, const bk_scaling_fit *f)
{
    if (have)
        fprintf(out, " %7.3f +- %5.3f [%6.3f, %6.3f] %6zu", f->slope, f->slope_sigma, f->slope, f->slope_inverse, f->n);
    else
        fprintf(out, " %-42s", "    not available");
}

static void text_band(FILE *out, const char *name, const bk_scaling_band *b)
{
    char hi[32] = "";
    if (isfinite(b->m_hi))
        snprintf(hi, sizeof hi, "%.4g", b->m_hi);
    fprintf(out, "  %-4s %7.4g %6s %8zu", name, b->m_lo, isfinite(b->m_hi) ? hi : "up", b->n_events);
    text_fit(out, b->have_duration, &b->duration);
    text_fit(out, b->have_length, &b->length);
    fprintf(out, "\n");
}

void bk_stats_text_scaling(const bk_stats_report *r, FILE *out)
{
    if (!r->scaling) {
        if (r->have_mc)
            fprintf(out, "scaling relations: not available: %s\n", r->scaling_note);
        return;
    }
    const bk_scaling *s = r->scaling;
    fprintf(out, "scaling relations (potency P against duration T and length L in blocks, ruptures of >= %d blocks; "
                 "exponent by least squares of log P on log x, [that, the inverse regression's] bracket it):\n",
            (int)s->options.min_blocks);
    fprintf(out, "  %-4s %7s %6s %8s %-43s %-43s\n", "", "M from", "to", "events", " P ~ T^g: g +- error [bracket] pairs",
            " P ~ L^g: g +- error [bracket] pairs");
    text_band(out, "all", &s->all);
    for (size_t k = 0; k < s->n_bands; ++k)
        text_band(out, "", &s->band[k]);
    if (!s->all.have_duration)
        fprintf(out, "  duration, M >= Mc: not available: %s\n", s->all.duration_note);
    if (!s->all.have_length)
        fprintf(out, "  length, M >= Mc: not available: %s\n", s->all.length_note);
    if (s->all.have_duration) {
        char text[256];
        bk_scaling_class cls;
        if (bk_scaling_classify(s->all.duration.slope, s->all.duration.slope_sigma, &cls, text, sizeof text, NULL) ==
            BK_OK)
            fprintf(out, "  moment-duration exponent (M >= Mc) against Thøgersen et al. 2019 (1D, indicative): %s\n",
                    text);
    }
}

static void json_fit(FILE *out, const char *key, int have, const bk_scaling_fit *f, const char *note)
{
    fprintf(out, "\"%s\": ", key);
    if (!have) {
        fprintf(out, "null, ");
        char note_key[64];
        snprintf(note_key, sizeof note_key, "%s_note", key);
        bk_json_note(out, note_key, 0, note);
        return;
    }
    fprintf(out, "{");
    bk_json_count(out, "n", f->n);
    bk_json_number(out, "slope", f->slope, 0);
    bk_json_number(out, "slope_error", f->slope_sigma, 0);
    bk_json_number(out, "slope_inverse", f->slope_inverse, 0);
    bk_json_number(out, "slope_rma", f->slope_rma, 0);
    bk_json_number(out, "intercept", f->intercept, 0);
    bk_json_number(out, "r", f->r, 0);
    bk_json_number(out, "x_min", f->x_min, 0);
    bk_json_number(out, "x_max", f->x_max, 1);
    fprintf(out, "}, ");
}

static void json_band(FILE *out, const bk_scaling_band *b)
{
    /* magnitude_max null: the band has no upper limit. */
    fprintf(out, "{");
    json_fit(out, "duration", b->have_duration, &b->duration, b->duration_note);
    json_fit(out, "length", b->have_length, &b->length, b->length_note);
    bk_json_number(out, "magnitude_min", b->m_lo, 0);
    bk_json_number(out, "magnitude_max", b->m_hi, 0);
    bk_json_count(out, "n_events", b->n_events);
    fprintf(out, "\"n_small\": %zu}", b->n_small);
}

void bk_stats_json_scaling(const bk_stats_report *r, FILE *out)
{
    fprintf(out, "\"scaling\": ");
    if (!r->scaling) {
        fprintf(out, "null, ");
        bk_json_note(out, "scaling_note", 0, r->have_mc ? r->scaling_note : "no Mc");
        return;
    }
    const bk_scaling *s = r->scaling;
    fprintf(out, "{\"min_blocks\": %d, ", (int)s->options.min_blocks);
    bk_json_number(out, "band_width", s->options.band_width, 0);
    fprintf(out, "\"all\": ");
    json_band(out, &s->all);
    fprintf(out, ", \"bands\": [");
    for (size_t k = 0; k < s->n_bands; ++k) {
        if (k)
            fprintf(out, ", ");
        json_band(out, &s->band[k]);
    }
    fprintf(out, "]");
    if (s->all.have_duration) {
        char text[256];
        bk_scaling_class cls;
        if (bk_scaling_classify(s->all.duration.slope, s->all.duration.slope_sigma, &cls, text, sizeof text, NULL) ==
            BK_OK) {
            fprintf(out, ", \"duration_vs_thogersen\": ");
            bk_json_string(out, text);
        }
    }
    fprintf(out, "}, ");
}

/* Median potency in logarithmic bins of x (duration or length) over the ruptures the fits
 * used (M >= Mc, >= min_blocks blocks), with the M >= Mc fit's line at the bin centres. */
static int medians_table(const bk_stats_report *r, const char *dir, const char *name, const char *unit, int length,
                         bk_error *err)
{
    const bk_scaling *s = r->scaling;
    const bk_scaling_fit *fit = length ? &s->all.length : &s->all.duration;
    int have_fit = length ? s->all.have_length : s->all.have_duration;
    size_t n = r->n_events;
    double *x = malloc((n ? n : 1) * sizeof *x), *y = malloc((n ? n : 1) * sizeof *y);
    if (!x || !y) {
        free(x);
        free(y);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu ruptures", n);
    }
    size_t used = 0;
    double m_min = r->mc - 0.5 * r->options.dm;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        if (bk_mag_bin(r->magnitude[i], r->options.dm, &k, NULL) != BK_OK ||
            (double)k * r->options.dm < m_min || (r->n_blocks && r->n_blocks[i] < s->options.min_blocks))
            continue;
        x[used] = length ? (double)r->n_blocks[i] : r->t_end[i] - r->t_start[i];
        y[used++] = r->potency[i];
    }
    bk_scaling_bins bins;
    bk_error inner = {0};
    int rc = bk_scaling_binned_medians(x, y, used, SCALING_BINS_PER_DECADE, &bins, &inner);
    free(x);
    free(y);
    if (rc == BK_ERR_INVALID)
        return BK_OK; /* no rupture with both: no table (the report's note says why) */
    if (rc != BK_OK) {
        if (err)
            *err = inner;
        return rc;
    }
    char path[4096], header[160];
    snprintf(header, sizeof header, "# %s[%s]\tcount[1]\tmedian_potency[m]\tq25_potency[m]\tq75_potency[m]\tfit[m]",
             length ? "n_blocks" : "duration", unit);
    FILE *f = bk_stats_open_table(dir, name, path, sizeof path, header, err);
    if (!f) {
        bk_scaling_bins_free(&bins);
        return err ? err->status : BK_ERR_IO;
    }
    for (size_t b = 0; b < bins.n_bins; ++b) {
        double c = bins.x_centre[b];
        fprintf(f, "%.10g\t%zu\t%.10g\t%.10g\t%.10g\t%.10g\n", c, bins.count[b], bins.median[b], bins.q25[b],
                bins.q75[b], have_fit ? pow(10.0, fit->intercept) * pow(c, fit->slope) : NAN);
    }
    bk_scaling_bins_free(&bins);
    return bk_stats_close_table(f, path, err);
}

int bk_stats_tsv_scaling(const bk_stats_report *r, const char *dir, bk_error *err)
{
    if (!r->scaling)
        return BK_OK;
    int rc = BK_OK;
    if (r->t_end)
        rc = medians_table(r, dir, "scaling_duration.tsv", "s", 0, err);
    if (rc == BK_OK && r->n_blocks)
        rc = medians_table(r, dir, "scaling_length.tsv", "1", 1, err);
    return rc;
}
