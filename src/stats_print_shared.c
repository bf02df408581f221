/* What every part of the `bksim stats` printer shares (src/stats_print_impl.h): JSON values
 * and the TSV tables' opening and closing. */
#include "stats_print_impl.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The shortest text that reads back as the same double (0.1, not 0.10000000000000001);
 * JSON has no NaN or infinity: null. */
void bk_json_number(FILE *out, const char *key, double value, int last)
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

void bk_json_count(FILE *out, const char *key, size_t value)
{
    fprintf(out, "\"%s\": %zu, ", key, value);
}

void bk_json_string(FILE *out, const char *s)
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

void bk_json_note(FILE *out, const char *key, int have, const char *note)
{
    if (have)
        return;
    fprintf(out, "\"%s\": ", key);
    bk_json_string(out, note);
    fprintf(out, ", ");
}

/* "key": {"n": .., "ks_distance": .., "p_value": .., "synthetic_samples": .., "consistent": ..}
 * or null when the fit was not tested. */
void bk_json_gof(FILE *out, const char *key, int have, const bk_gof *g)
{
    fprintf(out, "\"%s\": ", key);
    if (!have) {
        fprintf(out, "null, ");
        return;
    }
    fprintf(out, "{\"n\": %zu, ", g->n);
    bk_json_number(out, "ks_distance", g->d, 0);
    bk_json_number(out, "p_value", g->p, 0);
    fprintf(out, "\"synthetic_samples\": %zu, \"consistent\": %s}, ", g->n_synthetic,
            g->p < BK_GOF_LEVEL ? "false" : "true");
}

FILE *bk_stats_open_table(const char *dir, const char *name, char *path, size_t len, const char *header,
                          bk_error *err)
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

int bk_stats_close_table(FILE *f, const char *path, bk_error *err)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return BK_FAIL(err, BK_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return BK_OK;
}

int bk_stats_write_failed(FILE *out, const char *what, bk_error *err)
{
    if (ferror(out))
        return BK_FAIL(err, BK_ERR_IO, "writing the %s failed: %s", what, strerror(errno));
    return BK_OK;
}

const char *bk_stats_table_note(const char *table, int fallback)
{
    if (table && fallback)
        return " (the time-window catalog: the file has no /ruptures)";
    if (table && strcmp(table, "ruptures") == 0)
        return " (the rupture catalog)";
    if (table && strcmp(table, "events") == 0)
        return " (the time-window catalog)";
    return "";
}
