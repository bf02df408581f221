/* Per-block values made at load time.  Drawn: a numeric key of [block] or [friction] (or of
 * a [block.I] / [friction.I] section) given as uniform(a, b), normal(mean, sd) or
 * lognormal(mu, sigma).  Profiles (of [block] or [friction] only): linear(first, last) along
 * each row by column (a chain's blocks), linear_rows(first, last) down the rows, and
 * file(path[, column]), one line per block.  Each such entry draws from its own stream, seeded from [model] seed
 * and the entry's section and key, and block i takes its i-th number (the draws of blocks that
 * set the key in their own section are made and dropped), so a block's value depends on
 * nothing but the seed, the entry and its index.  The values every block ends with are kept for the output
 * (/parameters). */
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "config_loader.h"

static const char *const distribution_names[] = {"", "uniform", "normal", "lognormal", "linear", "linear_rows",
                                                 "file"};
/* A million blocks at a few hundred bytes a line. */
#define MAX_PROFILE_BYTES (512 << 20)
#define N_FORMS (sizeof distribution_names / sizeof *distribution_names)
#define KNOWN_FORMS                                                                                        \
    "uniform(a, b), normal(mean, sd), lognormal(mu, sigma), linear(first, last), linear_rows(first, last) " \
    "with finite numbers, or file(path[, column])"

/* The form's name, when text starts with one followed by "(" (else 0). */
static int form_of(const char *text)
{
    for (size_t k = 1; k < N_FORMS; ++k) {
        size_t len = strlen(distribution_names[k]);
        if (strncmp(text, distribution_names[k], len) == 0 && text[len] == '(')
            return (int)k;
    }
    return 0;
}

/* "name(a, b)" with finite numbers: 1, or -1 when malformed. */
static int split_numbers(const char *text, int kind, double *a, double *b)
{
    const char *p = text + strlen(distribution_names[kind]) + 1;
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

/* "file(path)" or "file(path, column)": the path into buf and the column (1-based); 1, or -1
 * when malformed (no path, a column that is no whole number >= 1, text after the ")"). */
static int split_file(const char *text, char *buf, size_t len, long *column)
{
    const char *p = text + strlen("file(");
    size_t n = strlen(p);
    if (n == 0 || p[n - 1] != ')')
        return -1;
    n--; /* without the ")" */
    *column = 1;
    const char *comma = memchr(p, ',', n);
    size_t path_len = comma ? (size_t)(comma - p) : n;
    if (comma) {
        char *end = NULL;
        const char *q = comma + 1;
        errno = 0;
        long c = strtol(q, &end, 10);
        while (end && isspace((unsigned char)*end))
            ++end;
        if (end == q || errno || c < 1 || end != p + n)
            return -1;
        *column = c;
    }
    while (path_len > 0 && isspace((unsigned char)p[path_len - 1]))
        path_len--;
    while (path_len > 0 && isspace((unsigned char)*p)) {
        ++p;
        --path_len;
    }
    if (path_len == 0 || path_len >= len)
        return -1;
    memcpy(buf, p, path_len);
    buf[path_len] = '\0';
    return 1;
}

int bk_config_parse_distribution(loader *ld, entry *e, const bk_param *param, const char *allowed)
{
    int kind = form_of(e->value);
    if (kind == 0) {
        /* name(...) that names no form: say which there are, not "not a number". */
        size_t word = strspn(e->value, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_");
        size_t len = strlen(e->value);
        if (word == 0 || e->value[word] != '(' || e->value[len - 1] != ')')
            return 0;
        bk_config_report_entry(ld, e, "unknown distribution or profile \"%.*s\" (allowed: " KNOWN_FORMS ")",
                               (int)word, e->value);
        return -1;
    }
    double a = 0.0, b = 0.0;
    char path[PATH_MAX];
    long column = 1;
    int found = kind == BK_PROFILE_FILE ? split_file(e->value, path, sizeof path, &column)
                                        : split_numbers(e->value, kind, &a, &b);
    if (found < 0) {
        bk_config_report_entry(ld, e, "not a distribution or profile: \"%s\" (allowed: " KNOWN_FORMS ")", e->value);
        return -1;
    }
    if (e->index == -1 && strcmp(e->base, "block") != 0 && strcmp(e->base, "friction") != 0) {
        bk_config_report_entry(ld, e, "a distribution or profile gives each block its value: only keys of [block] "
                               "and [friction] take one (allowed: %s)", allowed);
        return -1;
    }
    if (kind >= BK_PROFILE_LINEAR && e->index >= 0) {
        bk_config_report_entry(ld, e, "%s(...) is a profile across the blocks: give it in [%s], not in [%s] "
                               "(allowed here: %s)", distribution_names[kind], e->base, e->section, allowed);
        return -1;
    }
    if (kind == BK_DRAW_UNIFORM && !(b >= a)) {
        bk_config_report_entry(ld, e, "uniform(%g, %g) has a negative width (allowed: a <= b)", a, b);
        return -1;
    }
    if ((kind == BK_DRAW_NORMAL || kind == BK_DRAW_LOGNORMAL) && !(b >= 0.0)) {
        bk_config_report_entry(ld, e, "%s(%g, %g) has a negative width (allowed: %s >= 0)", distribution_names[kind],
                               a, b, kind == BK_DRAW_NORMAL ? "sd" : "sigma");
        return -1;
    }
    /* Every value of a uniform draw or a linear profile lies between its two numbers, so both
     * in range is the whole check, made now. */
    if ((kind == BK_DRAW_UNIFORM || kind == BK_PROFILE_LINEAR || kind == BK_PROFILE_LINEAR_ROWS) &&
        (!bk_param_in_range(param, a) || !bk_param_in_range(param, b))) {
        bk_config_report_entry(ld, e, "%s(%g, %g) reaches outside the allowed range (allowed: %s)",
                               distribution_names[kind], a, b, allowed);
        return -1;
    }
    e->distribution = kind;
    e->dist_a = kind == BK_PROFILE_FILE ? (double)column : a;
    e->dist_b = b;
    e->number = NAN; /* per block: bk_config_draw */
    return 1;
}

/* The file a file(...) profile names: relative to the config file's directory. */
static void profile_path(const loader *ld, const entry *e, char *buf, size_t len)
{
    char path[PATH_MAX];
    long column = 1;
    if (split_file(e->value, path, sizeof path, &column) < 0)
        path[0] = '\0';
    bk_config_path_near(ld, path, buf, len);
}

/* Read the column of a file(...) profile: one value per line that is neither blank nor a
 * comment (#), in block order, as many as the scene has blocks.  0, or -1 reported. */
static int read_profile(loader *ld, entry *e)
{
    char path[PATH_MAX + 256];
    profile_path(ld, e, path, sizeof path);
    size_t column = (size_t)e->dist_a, n_blocks = ld->rows * ld->cols;
    FILE *f = bk_config_open_table(ld, e, path, MAX_PROFILE_BYTES, "profile");
    if (!f)
        return -1;
    e->profile = malloc((n_blocks ? n_blocks : 1) * sizeof *e->profile);
    e->profile_lines = malloc((n_blocks ? n_blocks : 1) * sizeof *e->profile_lines);
    if (!e->profile || !e->profile_lines) {
        fclose(f);
        bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return -1;
    }
    char *line = NULL;
    size_t cap = 0, count = 0;
    int number = 0, rc = 0;
    while (rc == 0 && getline(&line, &cap, f) >= 0) {
        ++number;
        char *save = NULL, *field = strtok_r(line, " \t\r\n", &save);
        if (!field || field[0] == '#')
            continue;
        for (size_t k = 1; field && k < column; ++k)
            field = strtok_r(NULL, " \t\r\n", &save);
        char *end = NULL;
        double value = field ? strtod(field, &end) : NAN;
        if (!field) {
            bk_config_report_entry(ld, e, "%s:%d: no column %zu (columns are separated by spaces or tabs)", path,
                                   number, column);
            rc = -1;
        } else if (end == field || *end || !isfinite(value)) {
            bk_config_report_entry(ld, e, "%s:%d: column %zu: not a finite number: \"%s\"", path, number, column,
                                   field);
            rc = -1;
        } else if (count == n_blocks) {
            bk_config_report_entry(ld, e, "%s:%d: more values than the scene's %zu blocks (one line per block, "
                                   "in block order)", path, number, n_blocks);
            rc = -1;
        } else {
            e->profile[count] = value;
            e->profile_lines[count++] = number;
        }
    }
    if (rc == 0 && ferror(f)) {
        bk_config_report_entry(ld, e, "%s: read error", path);
        rc = -1;
    }
    if (rc == 0 && count < n_blocks) {
        bk_config_report_entry(ld, e, "%s: %zu values in column %zu, the scene has %zu blocks (one line per block, "
                               "in block order; # starts a comment)", path, count, column, n_blocks);
        rc = -1;
    }
    free(line);
    fclose(f);
    e->profile_len = count;
    return rc;
}

/* Block i's value from a profile; NAN, reported, when its file cannot be read. */
static double profile_value(loader *ld, entry *e, size_t block)
{
    if (e->distribution == BK_PROFILE_FILE) {
        if (!e->profile && read_profile(ld, e) != 0)
            return NAN;
        return block < e->profile_len ? e->profile[block] : NAN;
    }
    size_t cols = ld->cols ? ld->cols : 1;
    size_t along = e->distribution == BK_PROFILE_LINEAR ? block % cols : block / cols;
    size_t span = (e->distribution == BK_PROFILE_LINEAR ? cols : ld->rows) - 1;
    if (span == 0)
        return e->dist_a;
    /* Weighted so that the ends are the given numbers exactly. */
    return (e->dist_a * (double)(span - along) + e->dist_b * (double)along) / (double)span;
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
    if (e->distribution >= BK_PROFILE_LINEAR) {
        double x = profile_value(ld, e, block);
        if (isnan(x) || bk_param_in_range(param, x))
            return x;
        if (e->rank < ld->error_rank) {
            char allowed[1536], where[PATH_MAX + 300] = "";
            bk_config_format_allowed(NULL, param, allowed, sizeof allowed);
            if (e->distribution == BK_PROFILE_FILE) {
                char path[PATH_MAX + 256];
                profile_path(ld, e, path, sizeof path);
                snprintf(where, sizeof where, "%s:%d: ", path, e->profile_lines[block]);
            }
            bk_config_report_entry(ld, e, "%s%.17g for block %zu is outside the allowed range (allowed: %s)", where,
                                   x, block, allowed);
        }
        return NAN;
    }
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
        double x = e->distribution == BK_DRAW_UNIFORM  ? e->dist_a + (e->dist_b - e->dist_a) * gsl_rng_uniform(rng)
                   : e->distribution == BK_DRAW_NORMAL ? e->dist_a + gsl_ran_gaussian_ziggurat(rng, e->dist_b)
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
    free(e->profile);
    free(e->profile_lines);
    e->profile = NULL;
    e->profile_lines = NULL;
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
