/* Per-block values drawn at load time: a numeric key of [block] or [friction] (or of a
 * [block.I] / [friction.I] section) given as uniform(a, b), normal(mean, sd) or
 * lognormal(mu, sigma).  Each such entry draws from its own stream, seeded from [model] seed
 * and the entry's section and key, and block i takes its i-th number (the draws of blocks that
 * set the key in their own section are made and dropped), so a block's value depends on
 * nothing but the seed, the entry and its index.  The values every block ends with are kept for the output
 * (/parameters). */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "config_loader.h"

static const char *const distribution_names[] = {"", "uniform", "normal", "lognormal"};

/* "name(a, b)" with finite numbers; 0 when the text is no distribution at all. */
static int split_distribution(const char *text, int *kind, double *a, double *b)
{
    size_t k = 1;
    size_t len = 0;
    for (; k < sizeof distribution_names / sizeof *distribution_names; ++k) {
        len = strlen(distribution_names[k]);
        if (strncmp(text, distribution_names[k], len) == 0 && text[len] == '(')
            break;
    }
    if (k == sizeof distribution_names / sizeof *distribution_names)
        return 0;
    *kind = (int)k;
    const char *p = text + len + 1;
    char *end = NULL;
    *a = strtod(p, &end);
    if (end == p || strpbrk(p, "xX"))
        return -1;
    while (isspace((unsigned char)*end))
        ++end;
    if (*end != ',')
        return -1;
    p = end + 1;
    *b = strtod(p, &end);
    if (end == p)
        return -1;
    while (isspace((unsigned char)*end))
        ++end;
    if (*end != ')' || end[1] != '\0' || !isfinite(*a) || !isfinite(*b))
        return -1;
    return 1;
}

int bk_config_parse_distribution(loader *ld, entry *e, const bk_param *param, const char *allowed)
{
    int kind = 0;
    double a = 0.0, b = 0.0;
    int found = split_distribution(e->value, &kind, &a, &b);
    if (found == 0)
        return 0;
    if (found < 0) {
        bk_config_report_entry(ld, e, "not a distribution: \"%s\" (allowed: uniform(a, b), normal(mean, sd) or "
                               "lognormal(mu, sigma) with finite numbers)", e->value);
        return -1;
    }
    if (e->index == -1 && strcmp(e->base, "block") != 0 && strcmp(e->base, "friction") != 0) {
        bk_config_report_entry(ld, e, "a distribution is drawn per block: only keys of [block] and [friction] "
                               "take one (allowed: %s)", allowed);
        return -1;
    }
    if (kind == 1 && !(b >= a)) {
        bk_config_report_entry(ld, e, "uniform(%g, %g) has a negative width (allowed: a <= b)", a, b);
        return -1;
    }
    if (kind != 1 && !(b >= 0.0)) {
        bk_config_report_entry(ld, e, "%s(%g, %g) has a negative width (allowed: %s >= 0)", distribution_names[kind],
                               a, b, kind == 2 ? "sd" : "sigma");
        return -1;
    }
    /* A uniform draw's every value is known now: outside the range it is an error here. */
    if (kind == 1 && (!bk_param_in_range(param, a) || !bk_param_in_range(param, b))) {
        bk_config_report_entry(ld, e, "uniform(%g, %g) reaches outside the allowed range (allowed: %s)", a, b, allowed);
        return -1;
    }
    e->distribution = kind;
    e->dist_a = a;
    e->dist_b = b;
    e->number = NAN; /* drawn per block: bk_config_draw */
    return 1;
}

/* FNV-1a over the seed and the entry's section and key: the entry's own stream. */
static unsigned long stream_seed(unsigned long seed, const entry *e)
{
    unsigned long long h = 1469598103934665603ull;
    char text[SECTION_LEN + KEY_LEN + 32];
    snprintf(text, sizeof text, "%lu/%s/%s", seed, e->section, e->key);
    for (const char *c = text; *c; ++c) {
        h ^= (unsigned char)*c;
        h *= 1099511628211ull;
    }
    return (unsigned long)(h ^ (h >> 32));
}

double bk_config_draw(loader *ld, entry *e, size_t block, const bk_param *param)
{
    if (!e->rng) {
        e->rng = gsl_rng_alloc(gsl_rng_mt19937);
        if (!e->rng) {
            bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
            return NAN;
        }
        gsl_rng_set(e->rng, stream_seed(ld->seed, e));
    }
    /* Blocks ask in increasing order; a per-block section's entry serves one block: its first
     * draw. */
    size_t target = e->index >= 0 ? 0 : block;
    while (e->drawn <= target) {
        gsl_rng *rng = e->rng;
        double x = e->distribution == 1   ? e->dist_a + (e->dist_b - e->dist_a) * gsl_rng_uniform(rng)
                   : e->distribution == 2 ? e->dist_a + gsl_ran_gaussian_ziggurat(rng, e->dist_b)
                                          : gsl_ran_lognormal(rng, e->dist_a, e->dist_b);
        e->last_draw = x;
        e->drawn++;
    }
    double x = e->last_draw;
    if (bk_param_in_range(param, x))
        return x;
    /* NaN even when an earlier error stands: an out-of-range draw must not go on to trip a
     * cross-check (mu_d <= mu_s) that would be reported in its place. */
    if (e->rank < ld->error_rank) {
        char allowed[1536];
        bk_config_format_allowed(NULL, param, allowed, sizeof allowed);
        bk_config_report_entry(ld, e, "%s drew %.17g for block %zu, outside the allowed range (allowed: %s; "
                               "narrow the distribution, or set that block in [%s.%zu])",
                               e->value, x, block, allowed, e->base, block);
    }
    return NAN;
}

void bk_config_free_draws(entry *e)
{
    gsl_rng_free(e->rng);
    e->rng = NULL;
}

/* --- the values blocks end with, for /parameters ---------------------------------------- */

int bk_config_plan_parameters(loader *ld, size_t n_blocks)
{
    size_t i = 0;
    for (; i < ld->n; ++i) {
        const entry *e = &ld->entries[i];
        if (e->superseded || !e->distribution)
            continue;
        char name[BK_PARAMETER_NAME_LEN];
        snprintf(name, sizeof name, "%s.%s", e->base, e->key);
        int known = 0;
        for (size_t k = 0; k < ld->n_parameters && !known; ++k)
            known = strcmp(ld->parameters[k].name, name) == 0;
        if (known)
            continue;
        bk_block_parameter *grown = realloc(ld->parameters, (ld->n_parameters + 1) * sizeof *grown);
        if (!grown)
            break;
        ld->parameters = grown;
        bk_block_parameter *p = &ld->parameters[ld->n_parameters++];
        memset(p, 0, sizeof *p);
        snprintf(p->name, sizeof p->name, "%s", name);
        p->n_blocks = n_blocks;
        p->values = malloc(n_blocks * sizeof *p->values);
        if (!p->values)
            break;
        for (size_t b = 0; b < n_blocks; ++b)
            p->values[b] = NAN; /* a block whose law has no such parameter */
    }
    if (i == ld->n)
        return 0;
    bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
    return -1;
}

void bk_config_record_parameter(loader *ld, const char *base, const char *key, const char *unit, size_t block,
                                double value)
{
    for (size_t k = 0; k < ld->n_parameters; ++k) {
        bk_block_parameter *p = &ld->parameters[k];
        size_t len = strlen(base);
        if (strncmp(p->name, base, len) == 0 && p->name[len] == '.' && strcmp(p->name + len + 1, key) == 0) {
            if (block < p->n_blocks)
                p->values[block] = value;
            if (unit)
                snprintf(p->unit, sizeof p->unit, "%s", unit);
            return;
        }
    }
}

void bk_config_free_parameters(bk_block_parameter *parameters, size_t n)
{
    for (size_t k = 0; k < n; ++k)
        free(parameters[k].values);
    free(parameters);
}
