/* `bksim compare`: two catalogs' distributions side by side (bksim/stats_compare.h), from
 * their columns in memory through bk_ks_two_sample, as text or one JSON object.  No HDF5
 * here: the command reads each catalog with bk_h5_read_event_table. */
#include "bksim/stats_compare.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stats_impl.h"
#include "stats_print_impl.h"

void bk_compare_options_default(bk_compare_options *opt)
{
    opt->t_from = -INFINITY;
    opt->t_to = INFINITY;
    opt->round = BK_COMPARE_DEFAULT_ROUND;
    opt->level = BK_COMPARE_DEFAULT_LEVEL;
}

int bk_compare_options_check(const bk_compare_options *opt, bk_error *err)
{
    if (isnan(opt->t_from) || isnan(opt->t_to) || !(opt->t_from < opt->t_to) ||
        opt->t_from == INFINITY || opt->t_to == -INFINITY)
        return BK_FAIL(err, BK_ERR_INVALID, "time window [%g, %g) s: allowed from < to", opt->t_from,
                       opt->t_to);
    if (!(opt->round >= 0.0 && opt->round <= 1.0))
        return BK_FAIL(err, BK_ERR_INVALID, "rounding %g: allowed 0 <= round <= 1 (0: values as stored)",
                       opt->round);
    if (!(opt->level > 0.0 && opt->level < 1.0))
        return BK_FAIL(err, BK_ERR_INVALID, "level %g: allowed 0 < level < 1 (0.01: the 1 %% level)",
                       opt->level);
    return BK_OK;
}

static double rounded(double x, double round)
{
    return round > 0.0 ? bk_stats_to_bin(x, round) : x;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of x[0..n) (sorted here, in place); NaN for n = 0. */
static double median(double *x, size_t n)
{
    if (n == 0)
        return NAN;
    qsort(x, n, sizeof *x, compare_doubles);
    return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

/* The columns one side's tests use: its events' rounded log10 potencies, rounded magnitudes
 * and block counts. */
typedef struct side_values {
    double *log10_potency, *magnitude, *n_blocks;
} side_values;

static void side_values_free(side_values *v)
{
    free(v->log10_potency);
    free(v->magnitude);
    free(v->n_blocks);
    memset(v, 0, sizeof *v);
}

/* Select side s's events from table t and fill its counts, span and values. */
static int select_side(const bk_event_table *t, const char *name, const bk_compare_options *opt,
                       bk_compare_side *s, side_values *v, bk_error *err)
{
    memset(v, 0, sizeof *v);
    s->source = strdup(name ? name : "catalog");
    s->table = t->name ? strdup(t->name) : NULL;
    if (!s->source || (t->name && !s->table))
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", name ? name : "catalog");
    s->table_fallback = t->fallback;
    s->has_potency = t->potency != NULL;
    s->has_n_blocks = t->n_blocks != NULL;
    s->has_complete = t->complete != NULL;
    s->n_rows = t->n;
    s->m_min = s->m_max = s->log10_potency_median = s->n_blocks_mean = NAN;
    if (t->n && (!t->t_start || !t->magnitude))
        return BK_FAIL(err, BK_ERR_INVALID, "%s: the catalog has no t_start or no magnitude column", s->source);
    size_t cap = t->n ? t->n : 1;
    v->magnitude = malloc(cap * sizeof *v->magnitude);
    v->log10_potency = s->has_potency ? malloc(cap * sizeof *v->log10_potency) : NULL;
    v->n_blocks = s->has_n_blocks ? malloc(cap * sizeof *v->n_blocks) : NULL;
    if (!v->magnitude || (s->has_potency && !v->log10_potency) || (s->has_n_blocks && !v->n_blocks))
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for %zu events", s->source, t->n);
    bk_event_selection sel;
    int rc = bk_event_select(t, opt->t_from, opt->t_to, &sel, err);
    if (rc != BK_OK)
        return rc;
    s->n_events = sel.n_events;
    s->n_incomplete = sel.n_incomplete;
    s->n_nonfinite = sel.n_nonfinite;
    s->n_outside = sel.n_outside;
    double blocks = 0.0;
    for (size_t k = 0; k < sel.n_events; ++k) {
        size_t i = sel.index[k];
        v->magnitude[k] = rounded(t->magnitude[i], opt->round);
        if (v->log10_potency && isfinite(t->potency[i]) && t->potency[i] > 0.0)
            v->log10_potency[s->n_potency++] = rounded(log10(t->potency[i]), opt->round);
        if (v->n_blocks) {
            v->n_blocks[k] = (double)t->n_blocks[i];
            blocks += v->n_blocks[k];
        }
    }
    if (s->n_events == 0) {
        bk_event_selection_free(&sel);
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: no event to compare: of %zu rows, %zu still running at the end (complete = 0), "
                       "%zu without a finite t_start and magnitude, %zu outside the time window",
                       s->source, s->n_rows, s->n_incomplete, s->n_nonfinite, s->n_outside);
    }
    s->m_min = sel.m_min;
    s->m_max = sel.m_max;
    s->span_start = sel.span_start;
    s->duration = sel.duration;
    s->duration_from_run = sel.duration_from_run;
    s->rate = s->duration > 0.0 ? (double)s->n_events / s->duration : 0.0;
    bk_event_selection_free(&sel);
    if (v->n_blocks)
        s->n_blocks_mean = blocks / (double)s->n_events;
    if (v->log10_potency && s->n_potency) /* sorts them: the KS test does not mind */
        s->log10_potency_median = median(v->log10_potency, s->n_potency);
    return BK_OK;
}

/* The KS test of x1[0..n1) against x2[0..n2), or a note saying why not. */
static int run_test(const char *what, const double *x1, size_t n1, const double *x2, size_t n2,
                    const bk_compare_result *r, bk_compare_test *test, bk_error *err)
{
    if (!x1 || !x2) {
        snprintf(test->note, sizeof test->note, "%s: no %s field in %s", what, what,
                 x1 ? "B" : x2 ? "A" : "either catalog");
        return BK_OK;
    }
    if (n1 == 0 || n2 == 0) {
        snprintf(test->note, sizeof test->note, "%s: no positive, finite value in %s", what,
                 n1 ? "B" : n2 ? "A" : "either catalog");
        return BK_OK;
    }
    int rc = bk_ks_two_sample(x1, n1, x2, n2, &test->ks, err);
    if (rc != BK_OK)
        return rc;
    test->done = 1;
    test->differ = test->ks.p < r->options.level;
    return BK_OK;
}

int bk_compare_tables(const bk_event_table *a, const char *name_a, const bk_event_table *b,
                      const char *name_b, const bk_compare_options *opt, bk_compare_result *out,
                      bk_error *err)
{
    memset(out, 0, sizeof *out);
    out->rate_ratio = NAN;
    if (opt)
        out->options = *opt;
    else
        bk_compare_options_default(&out->options);
    int rc = bk_compare_options_check(&out->options, err);
    if (rc != BK_OK)
        return rc;
    side_values va, vb;
    rc = select_side(a, name_a, &out->options, &out->a, &va, err);
    memset(&vb, 0, sizeof vb);
    if (rc == BK_OK)
        rc = select_side(b, name_b, &out->options, &out->b, &vb, err);
    if (rc == BK_OK)
        rc = run_test("potency", va.log10_potency, out->a.n_potency, vb.log10_potency, out->b.n_potency, out,
                      &out->log10_potency, err);
    if (rc == BK_OK)
        rc = run_test("magnitude", va.magnitude, out->a.n_events, vb.magnitude, out->b.n_events, out,
                      &out->magnitude, err);
    if (rc == BK_OK)
        rc = run_test("n_blocks", va.n_blocks, out->a.n_events, vb.n_blocks, out->b.n_events, out,
                      &out->n_blocks, err);
    side_values_free(&va);
    side_values_free(&vb);
    if (rc != BK_OK) {
        bk_compare_free(out);
        return rc;
    }
    if (out->a.rate > 0.0)
        out->rate_ratio = out->b.rate / out->a.rate;
    const bk_compare_test *primary = out->log10_potency.done ? &out->log10_potency : &out->magnitude;
    out->primary = primary == &out->log10_potency ? "log10_potency" : "magnitude";
    out->told_apart = primary->differ;
    return BK_OK;
}

void bk_compare_free(bk_compare_result *r)
{
    if (!r)
        return;
    free(r->a.source);
    free(r->a.table);
    free(r->b.source);
    free(r->b.table);
    memset(r, 0, sizeof *r);
    r->rate_ratio = NAN;
}

/* ------------------------------------------------------------------ text --- */

/* "/ruptures (the rupture catalog)", "/events (the time-window catalog: ...)", "/NAME". */
static void table_phrase(const bk_compare_side *s, char *buf, size_t len)
{
    snprintf(buf, len, "%s%s%s", s->table ? "/" : "", s->table ? s->table : "columns in memory",
             bk_stats_table_note(s->table, s->table_fallback));
}

/* The level as a person says it: 0.01 -> "1 %", 0.001 -> "0.1 %". */
static void level_phrase(double level, char *buf, size_t len)
{
    snprintf(buf, len, "%.6g %%", 100.0 * level);
}

static void text_side(FILE *out, const char *label, const bk_compare_side *s, const bk_compare_options *o)
{
    char table[160];
    table_phrase(s, table, sizeof table);
    fprintf(out, "%s: %s, %s: %zu rows\n", label, s->source, table, s->n_rows);
    /* What was left out, only the kinds there are. */
    const size_t count[3] = {s->n_incomplete, s->n_nonfinite, s->n_outside};
    const char *const why[3] = {"still running at the end (complete = 0)",
                                "without a finite t_start and magnitude", "outside the time window"};
    const char *sep = "  left out:";
    for (size_t k = 0; k < 3; ++k)
        if (count[k]) {
            fprintf(out, "%s %zu %s", sep, count[k], why[k]);
            sep = ",";
        }
    if (*sep == ',')
        fprintf(out, "\n");
    fprintf(out, "  events: %zu; span %.9g s (%s%s); rate %.6g events/s\n", s->n_events, s->duration,
            s->duration_from_run ? "the run's t_reached" : "the catalog's span",
            isfinite(o->t_from) || isfinite(o->t_to) ? " within the window" : "", s->rate);
    fprintf(out, "  magnitudes %.4f to %.4f", s->m_min, s->m_max);
    if (s->has_potency)
        fprintf(out, "; %zu with a potency, median log10 potency %.4f", s->n_potency, s->log10_potency_median);
    if (s->has_n_blocks)
        fprintf(out, "; mean n_blocks %.4g", s->n_blocks_mean);
    fprintf(out, "\n");
}

static void text_test(FILE *out, const char *label, const bk_compare_test *t)
{
    if (!t->done) {
        fprintf(out, "  %-14s not tested: %s\n", label, t->note);
        return;
    }
    fprintf(out, "  %-14s D = %.4f  p = %.3g  (n = %zu, %zu)%s\n", label, t->ks.d, t->ks.p, t->ks.n1, t->ks.n2,
            t->differ ? "  differ" : "");
}

int bk_compare_text(const bk_compare_result *r, FILE *out, bk_error *err)
{
    const bk_compare_options *o = &r->options;
    char level[32];
    level_phrase(o->level, level, sizeof level);
    text_side(out, "A", &r->a, o);
    text_side(out, "B", &r->b, o);
    if (isfinite(o->t_from) || isfinite(o->t_to)) {
        char from[48] = "", to[48] = "";
        if (isfinite(o->t_from))
            snprintf(from, sizeof from, " t >= %.9g s", o->t_from);
        if (isfinite(o->t_to))
            snprintf(to, sizeof to, "%s t < %.9g s", *from ? " and" : "", o->t_to);
        fprintf(out, "time window: events starting at%s%s\n", from, to);
    }
    fprintf(out, "rates: B / A = %.4g\n", r->rate_ratio);
    if (o->round > 0.0)
        fprintf(out, "two-sample KS tests (log10 potency and magnitude rounded to multiples of %g; ties exact, "
                     "p asymptotic), \"differ\": p < %g:\n",
                o->round, o->level);
    else
        fprintf(out, "two-sample KS tests (values as stored; ties exact, p asymptotic), \"differ\": p < %g:\n",
                o->level);
    text_test(out, "log10 potency", &r->log10_potency);
    text_test(out, "magnitude", &r->magnitude);
    text_test(out, "n_blocks", &r->n_blocks);
    const bk_compare_test *p = strcmp(r->primary, "log10_potency") == 0 ? &r->log10_potency : &r->magnitude;
    const char *name = p == &r->log10_potency ? "log10 potency" : "magnitude";
    if (p->done)
        fprintf(out, "verdict: %s at the %s level (%s: p = %.3g %s %g)\n",
                r->told_apart ? "told apart" : "not told apart", level, name, p->ks.p,
                r->told_apart ? "<" : ">=", o->level);
    else
        fprintf(out, "verdict: none (%s)\n", p->note);
    return bk_stats_write_failed(out, "comparison", err);
}

/* ------------------------------------------------------------------ JSON --- */

/* "key": "s" or "key": null, and a separator. */
static void json_string(FILE *out, const char *key, const char *s)
{
    fprintf(out, "\"%s\": ", key);
    if (s)
        bk_json_string(out, s);
    else
        fprintf(out, "null");
    fprintf(out, ", ");
}

static void json_side(FILE *out, const char *key, const bk_compare_side *s)
{
    fprintf(out, "\"%s\": {", key);
    json_string(out, "source", s->source);
    json_string(out, "table", s->table);
    fprintf(out, "\"table_fallback\": %s, \"n_rows\": %zu, \"n_incomplete\": %zu, \"n_nonfinite\": %zu, "
                 "\"n_outside_window\": %zu, \"n_events\": %zu, \"n_potency\": %zu, ",
            s->table_fallback ? "true" : "false", s->n_rows, s->n_incomplete, s->n_nonfinite, s->n_outside,
            s->n_events, s->n_potency);
    bk_json_number(out, "duration", s->duration, 0);
    fprintf(out, "\"duration_from_run\": %s, ", s->duration_from_run ? "true" : "false");
    bk_json_number(out, "rate", s->rate, 0);
    bk_json_number(out, "magnitude_min", s->m_min, 0);
    bk_json_number(out, "magnitude_max", s->m_max, 0);
    bk_json_number(out, "log10_potency_median", s->log10_potency_median, 0);
    bk_json_number(out, "n_blocks_mean", s->n_blocks_mean, 1);
    fprintf(out, "}, ");
}

static void json_test(FILE *out, const char *key, const bk_compare_test *t, int last)
{
    fprintf(out, "\"%s\": ", key);
    if (!t->done) {
        fprintf(out, "null%s", last ? "" : ", ");
        return;
    }
    fprintf(out, "{");
    bk_json_number(out, "ks_distance", t->ks.d, 0);
    bk_json_number(out, "p_value", t->ks.p, 0);
    fprintf(out, "\"n_a\": %zu, \"n_b\": %zu, \"differ\": %s}%s", t->ks.n1, t->ks.n2, t->differ ? "true" : "false",
            last ? "" : ", ");
}

int bk_compare_json(const bk_compare_result *r, FILE *out, bk_error *err)
{
    const bk_compare_options *o = &r->options;
    fprintf(out, "{");
    json_side(out, "a", &r->a);
    json_side(out, "b", &r->b);
    fprintf(out, "\"options\": {");
    bk_json_number(out, "t_from", o->t_from, 0);
    bk_json_number(out, "t_to", o->t_to, 0);
    bk_json_number(out, "round", o->round, 0);
    bk_json_number(out, "level", o->level, 1);
    fprintf(out, "}, \"tests\": {");
    json_test(out, "log10_potency", &r->log10_potency, 0);
    json_test(out, "magnitude", &r->magnitude, 0);
    json_test(out, "n_blocks", &r->n_blocks, 1);
    fprintf(out, "}, ");
    bk_json_number(out, "rate_ratio", r->rate_ratio, 0);
    const bk_compare_test *p = strcmp(r->primary, "log10_potency") == 0 ? &r->log10_potency : &r->magnitude;
    fprintf(out, "\"verdict\": {\"test\": \"%s\", ", r->primary);
    if (p->done)
        fprintf(out, "\"told_apart\": %s, ", r->told_apart ? "true" : "false");
    else
        fprintf(out, "\"told_apart\": null, ");
    bk_json_number(out, "level", o->level, 1);
    fprintf(out, "}}\n");
    return bk_stats_write_failed(out, "comparison", err);
}
