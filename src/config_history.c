/* The driver: a constant velocity, or a history of segments given by [driver] velocities and
 * durations, or by velocities_file, a table of any length: a protocol of hundreds of segments
 * is written by a script or taken from an experiment's log, not typed into one key.
 *
 * The table: '#' starts a comment, blank lines are skipped, columns are separated by blanks,
 * tabs or one comma.  Its first line names the two columns, `velocity` and either `duration`
 * (each segment's length, s) or `t` (each segment's start, s: the first 0, increasing; the
 * last segment lasts until [run] t_end, which must then be given); a unit in brackets after
 * a name (`t[s]`) is allowed.  Every failure names the table's file:line. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capacity.h"
#include "config_loader.h"

#define MAX_HISTORY_BYTES (512 << 20)

/* The next column of a table line: blanks, tabs or one comma separate them. */
static char *next_column(char **cursor)
{
    char *p = *cursor;
    while (*p == ' ' || *p == '\t')
        ++p;
    if (*p == ',')
        ++p;
    while (*p == ' ' || *p == '\t')
        ++p;
    if (!*p)
        return NULL;
    char *start = p;
    while (*p && *p != ' ' && *p != '\t' && *p != ',')
        ++p;
    if (*p)
        *p++ = '\0';
    *cursor = p;
    return start;
}

/* A column's name without its unit in brackets. */
static void column_name(const char *text, char *name, size_t len)
{
    size_t n = strcspn(text, "[");
    snprintf(name, len, "%.*s", (int)n, text);
}

typedef struct table {
    double *first, *second;
    int *lines;
    size_t n, cap;
} table;

static int table_push(table *t, double a, double b, int line)
{
    size_t cap = t->cap;
    double *first = bk_grow_array(t->first, &cap, t->n + 1, sizeof *first, 64);
    if (!first)
        return -1;
    t->first = first;
    cap = t->cap;
    double *second = bk_grow_array(t->second, &cap, t->n + 1, sizeof *second, 64);
    if (!second)
        return -1;
    t->second = second;
    cap = t->cap;
    int *lines = bk_grow_array(t->lines, &cap, t->n + 1, sizeof *lines, 64);
    if (!lines)
        return -1;
    t->lines = lines;
    t->cap = cap;
    t->first[t->n] = a;
    t->second[t->n] = b;
    t->lines[t->n++] = line;
    return 0;
}

/* Read the table's header and rows: velocity_column (0 or 1) and whether the other column is
 * times (by_time).  0, or -1 reported. */
static int read_table(loader *ld, entry *e, const char *path, FILE *f, table *t, int *velocity_column,
                      int *by_time)
{
    char *line = NULL;
    size_t cap = 0;
    int number = 0, header = 0, rc = 0;
    while (rc == 0 && getline(&line, &cap, f) >= 0) {
        ++number;
        line[strcspn(line, "#\r\n")] = '\0';
        char *cursor = line, *a = next_column(&cursor);
        if (!a)
            continue;
        char *b = next_column(&cursor), *extra = b ? next_column(&cursor) : NULL;
        if (!b || extra) {
            bk_config_report_entry(ld, e, "%s:%d: %s (allowed: two columns, separated by blanks, tabs or a comma)",
                                   path, number, b ? "more than two columns" : "one column");
            rc = -1;
            break;
        }
        if (!header) {
            char na[32], nb[32];
            column_name(a, na, sizeof na);
            column_name(b, nb, sizeof nb);
            *velocity_column = strcmp(na, "velocity") == 0 ? 0 : strcmp(nb, "velocity") == 0 ? 1 : -1;
            const char *other = *velocity_column == 0 ? nb : na;
            *by_time = strcmp(other, "t") == 0;
            if (*velocity_column < 0 || (!*by_time && strcmp(other, "duration") != 0)) {
                bk_config_report_entry(ld, e, "%s:%d: the first line names the columns: \"%s %s\" (allowed: "
                                       "velocity and duration, or velocity and t, in either order; a unit in "
                                       "brackets may follow a name)",
                                       path, number, a, b);
                rc = -1;
            }
            header = 1;
            continue;
        }
        char *end_a = NULL, *end_b = NULL;
        double x = strtod(a, &end_a), y = strtod(b, &end_b);
        if (end_a == a || *end_a || !isfinite(x) || end_b == b || *end_b || !isfinite(y)) {
            bk_config_report_entry(ld, e, "%s:%d: not a finite number: \"%s\"", path, number,
                                   end_a == a || *end_a || !isfinite(x) ? a : b);
            rc = -1;
        } else if (table_push(t, x, y, number) != 0) {
            bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
            rc = -1;
        }
    }
    if (rc == 0 && ferror(f)) {
        bk_config_report_entry(ld, e, "%s: read error: %s", path, strerror(errno));
        rc = -1;
    }
    if (rc == 0 && t->n == 0) {
        bk_config_report_entry(ld, e, "%s: %s (allowed: a line naming the columns, then one line per segment)",
                               path, header ? "no segments" : "empty");
        rc = -1;
    }
    free(line);
    return rc;
}

static int read_history(loader *ld, entry *e, double t_end, double **velocities, double **durations, size_t *n)
{
    *velocities = *durations = NULL;
    *n = 0;
    char path[PATH_MAX + 256];
    bk_config_path_near(ld, e->value, path, sizeof path);
    FILE *f = bk_config_open_table(ld, e, path, MAX_HISTORY_BYTES, "history");
    if (!f)
        return -1;
    table t = {0};
    int velocity_column = 0, by_time = 0;
    int rc = read_table(ld, e, path, f, &t, &velocity_column, &by_time);
    fclose(f);
    double *v = t.first, *other = t.second;
    if (velocity_column == 1) {
        v = t.second;
        other = t.first;
    }
    for (size_t k = 0; rc == 0 && k < t.n; ++k) {
        if (!by_time && !(other[k] > 0.0)) {
            bk_config_report_entry(ld, e, "%s:%d: duration %.17g (allowed: > 0 s)", path, t.lines[k], other[k]);
            rc = -1;
        } else if (by_time && k == 0 && other[0] != 0.0) {
            bk_config_report_entry(ld, e, "%s:%d: the first segment starts at t = %.17g s (allowed: 0)", path,
                                   t.lines[0], other[0]);
            rc = -1;
        } else if (by_time && k > 0 && !(other[k] > other[k - 1])) {
            bk_config_report_entry(ld, e, "%s:%d: t = %.17g s after t = %.17g s (allowed: increasing times)", path,
                                   t.lines[k], other[k], other[k - 1]);
            rc = -1;
        }
    }
    if (rc == 0 && by_time && !(t_end > other[t.n - 1])) {
        bk_config_report_entry(ld, e, "%s:%d: the last segment starts at t = %.17g s; with a t column it lasts "
                               "until [run] t_end, which must be given and later (t_end: %.17g s, nan: not given)",
                               path, t.lines[t.n - 1], other[t.n - 1], t_end);
        rc = -1;
    }
    if (rc == 0 && by_time) { /* start times to durations, in place */
        for (size_t k = 0; k + 1 < t.n; ++k)
            other[k] = other[k + 1] - other[k];
        other[t.n - 1] = t_end - other[t.n - 1];
    }
    free(t.lines);
    if (rc != 0) {
        free(t.first);
        free(t.second);
        return -1;
    }
    *velocities = v;
    *durations = other;
    *n = t.n;
    return 0;
}

/* Give the driver n segments; their total length (s), or NAN reported when it is not finite
 * (at entry at) or memory runs out. */
static double set_history(loader *ld, bk_model *m, const entry *at, const double *v, const double *d, size_t n)
{
    double total = 0.0;
    for (size_t k = 0; k < n; ++k) {
        total += d[k];
        if (!isfinite(total)) {
            bk_config_report_entry(ld, at, "segment %zu makes the history longer than any finite time "
                                   "(allowed: a finite total duration)", k + 1);
            return NAN;
        }
    }
    if (bk_driver_set_history(&m->driver, v, d, n) != 0) {
        bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return NAN;
    }
    return total;
}

/* The driver: a constant velocity, or a history of velocities and durations (in keys, or a
 * table: velocities_file).  Returns the
 * history's length (s), or NAN for a constant velocity (or an error, reported). */
double bk_config_build_driver(loader *ld, bk_model *m)
{
    entry *velocity = bk_config_lookup(ld, "driver", "velocity");
    entry *velocities = bk_config_lookup(ld, "driver", "velocities");
    entry *durations = bk_config_lookup(ld, "driver", "durations");
    entry *file = bk_config_lookup(ld, "driver", "velocities_file");
    if (file) {
        entry *other = velocity ? velocity : velocities ? velocities : durations;
        if (other) {
            bk_config_report_entry(ld, other, "give velocities_file (a history from a table) or %s, not both "
                                   "(velocities_file is %s)", other->key, file->value);
            return NAN;
        }
        entry *t_end = bk_config_lookup(ld, "run", "t_end");
        double *v = NULL, *d = NULL;
        size_t n = 0;
        if (read_history(ld, file, t_end ? t_end->number : NAN, &v, &d, &n) != 0)
            return NAN;
        double total = set_history(ld, m, file, v, d, n);
        free(v);
        free(d);
        return total;
    }
    if (velocity && velocities) {
        bk_config_report_entry(ld, velocities, "give velocity (constant) or velocities (a history), not both "
                               "(velocity is set at %s)", velocity->value);
        return NAN;
    }
    if (!velocities) {
        if (durations)
            bk_config_report_entry(ld, durations, "applies with [driver] velocities, which is not given");
        else if (!velocity)
            bk_config_report_missing(ld, "driver", &bk_config_find_key("driver", "velocity")->param,
                           bk_config_find_key("driver", "velocity"));
        m->driver.velocity = velocity ? velocity->number : NAN;
        return NAN;
    }
    if (!durations) {
        bk_config_report_entry(ld, velocities, "needs [driver] durations, one per velocity");
        return NAN;
    }
    size_t n = (size_t)velocities->number;
    if ((size_t)durations->number != n) {
        bk_config_report_entry(ld, durations, "has %zu values, velocities has %zu (allowed: one duration per "
                               "velocity)", (size_t)durations->number, n);
        return NAN;
    }
    return set_history(ld, m, durations, velocities->list, durations->list, n);
}
