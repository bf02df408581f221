/* `bksim summary DIR`: one row per finished run in DIR, its --set values beside its headline
 * figures, as DIR/summary.tsv (for gnuplot and shell tools) and DIR/summary.h5 (one compound
 * table).  Both are written to a temporary name and renamed, so neither is ever half written.
 * The catalog figures (events, mean_recurrence, largest_*, peak_slip_rate, the b-value) come
 * from one table of each run, /ruptures by default (else /events), named in column catalog;
 * the column names say "events" whichever table it is. */
#include "bksim/inspect.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bksim/config.h"
#include "bksim/friction.h"
#include "bksim/stats.h"
#include "capacity.h"
#include "output/h5_impl.h"

/* The headline figures, in column order.  NaN wherever a run cannot give one. */
enum {
    FIG_EVENTS,
    FIG_MEAN_RECURRENCE,
    FIG_LARGEST_MAGNITUDE,
    FIG_LARGEST_BLOCKS,
    FIG_PEAK_SLIP_RATE,
    FIG_B_VALUE,
    FIG_B_ERROR,
    FIG_MC,
    FIG_B_EVENTS,
    FIG_ENERGY_RESIDUAL,
    FIG_STEPS,
    FIG_RHS_EVALS,
    FIG_TRANSITIONS,
    FIG_T_REACHED,
    FIG_WALL_TIME,
    FIG_CPU_TIME,
    FIG_SEED,
    N_FIGURES
};

static const struct {
    const char *name, *unit;
} figures[N_FIGURES] = {
    {"events", "1"},               {"mean_recurrence", "s"}, {"largest_magnitude", "1"},
    {"largest_event_blocks", "1"}, {"peak_slip_rate", "m/s"}, {"b_value", "1"},
    {"b_error", "1"},              {"mc", "1"},               {"b_events", "1"},
    {"energy_residual", "1"},      {"steps", "1"},            {"rhs_evals", "1"},
    {"transitions", "1"},          {"t_reached", "s"},        {"wall_time", "s"},
    {"cpu_time", "s"},             {"seed", "1"},
};

/* The /stats attributes behind some figures. */
static const struct {
    int figure;
    const char *attr;
} stats_attrs[] = {
    {FIG_ENERGY_RESIDUAL, "energy_residual"}, {FIG_STEPS, "steps"},
    {FIG_RHS_EVALS, "rhs_evals"},             {FIG_TRANSITIONS, "transitions"},
    {FIG_T_REACHED, "t_reached"},             {FIG_WALL_TIME, "wall_time"},
    {FIG_CPU_TIME, "cpu_time"},
};

typedef struct run_row {
    char *file, *point, *method, *host;
    char *catalog;   /* the table behind the catalog figures; NULL: the run has no catalog */
    int fallback;    /* 1: no /ruptures, so the default read /events */
    char **values;   /* per key column; NULL where the run did not set that key */
    size_t n_values; /* entries allocated in values */
    double figure[N_FIGURES];
} run_row;

typedef struct summary {
    char **keys; /* the --set keys, in the order first met */
    size_t n_keys, keys_cap;
    run_row *runs;
    size_t n_runs, runs_cap;
} summary;

static void free_row(run_row *run)
{
    for (size_t k = 0; k < run->n_values; ++k)
        free(run->values[k]);
    free(run->values);
    free(run->file);
    free(run->point);
    free(run->method);
    free(run->host);
    free(run->catalog);
}

static void free_summary(summary *s)
{
    for (size_t r = 0; r < s->n_runs; ++r)
        free_row(&s->runs[r]);
    free(s->runs);
    for (size_t k = 0; k < s->n_keys; ++k)
        free(s->keys[k]);
    free(s->keys);
}

static char *join_path(const char *dir, const char *name)
{
    size_t len = strlen(dir) + strlen(name) + 2;
    char *path = malloc(len);
    if (path)
        snprintf(path, len, "%s/%s", dir, name);
    return path;
}

/* Index of key in s->keys, added when new; -1 when out of memory. */
static long key_index(summary *s, const char *key)
{
    for (size_t k = 0; k < s->n_keys; ++k)
        if (strcmp(s->keys[k], key) == 0)
            return (long)k;
    char **grown = bk_grow_array(s->keys, &s->keys_cap, s->n_keys + 1, sizeof *grown, 8);
    if (!grown)
        return -1;
    s->keys = grown;
    if (!(s->keys[s->n_keys] = strdup(key)))
        return -1;
    return (long)s->n_keys++;
}

/* The run's --set overrides ("section.key=value" lines) as its key columns. */
static int take_overrides(summary *s, run_row *run, const char *overrides)
{
    for (const char *line = overrides; line && *line;) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) : strlen(line);
        const char *eq = memchr(line, '=', len);
        if (eq && eq > line) {
            char *key = strndup(line, (size_t)(eq - line));
            long k = key ? key_index(s, key) : -1;
            free(key);
            if (k < 0)
                return -1;
            if ((size_t)k >= run->n_values) {
                char **grown = realloc(run->values, ((size_t)k + 1) * sizeof *grown);
                if (!grown)
                    return -1;
                for (size_t j = run->n_values; j <= (size_t)k; ++j)
                    grown[j] = NULL;
                run->values = grown;
                run->n_values = (size_t)k + 1;
            }
            free(run->values[k]); /* the last --set of a key is the one that counts */
            if (!(run->values[k] = strndup(eq + 1, len - (size_t)(eq + 1 - line))))
                return -1;
        }
        line = end ? end + 1 : line + len;
    }
    return 0;
}

static int link_exists(hid_t file, const char *name)
{
    htri_t exists = H5Lexists(file, name, H5P_DEFAULT);
    if (exists < 0) /* a group on the way that is not there */
        H5Eclear2(H5E_DEFAULT);
    return exists > 0;
}

static double numeric_attr(hid_t obj, const char *name)
{
    double value = NAN;
    if (H5Aexists(obj, name) > 0 && bk_h5_read_numeric_attr(obj, name, H5T_NATIVE_DOUBLE, &value) < 0)
        value = NAN;
    return value;
}

/* The catalog's figures from its table (NULL: /ruptures, else /events): events in the window,
 * their mean recurrence, the largest, the peak slip rate; and the b-value of `bksim stats`
 * with the same options. */
static int catalog_figures(const char *path, const char *table, const bk_stats_options *opt,
                           run_row *run, bk_error *err)
{
    bk_event_table t;
    int rc = bk_h5_read_event_table(path, table, &t, err);
    if (rc != BK_OK)
        return rc;
    size_t counted = 0;
    double first = NAN, last = NAN, largest = -INFINITY, largest_blocks = NAN, peak = NAN;
    for (size_t i = 0; i < t.n; ++i) {
        if ((t.complete && !t.complete[i]) || !(t.t_start[i] >= opt->t_from && t.t_start[i] < opt->t_to))
            continue;
        /* Ruptures are stored as they complete, so their starts need not be in order. */
        if (counted++ == 0 || t.t_start[i] < first)
            first = t.t_start[i];
        if (!(t.t_start[i] <= last))
            last = t.t_start[i];
        if (t.magnitude[i] > largest) {
            largest = t.magnitude[i];
            largest_blocks = t.n_blocks ? (double)t.n_blocks[i] : NAN;
        }
        if (t.max_slip_rate && !(t.max_slip_rate[i] <= peak))
            peak = t.max_slip_rate[i];
    }
    run->figure[FIG_EVENTS] = (double)counted;
    /* The mean of the intervals between consecutive starts is the span's over their number. */
    run->figure[FIG_MEAN_RECURRENCE] = counted >= 2 ? (last - first) / (double)(counted - 1) : NAN;
    run->figure[FIG_LARGEST_MAGNITUDE] = counted ? largest : NAN;
    run->figure[FIG_LARGEST_BLOCKS] = largest_blocks;
    run->figure[FIG_PEAK_SLIP_RATE] = peak;
    run->fallback = t.fallback;
    if (!(run->catalog = strdup(t.name)))
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);

    bk_stats_report *report = NULL;
    bk_error ignored = {0};
    if (rc == BK_OK && counted && bk_stats_report_compute(&t, path, opt, &report, &ignored) == BK_OK &&
        report->have_b) {
        run->figure[FIG_B_VALUE] = report->b.b;
        run->figure[FIG_B_ERROR] = report->b.sigma;
        run->figure[FIG_MC] = report->b.mc;
        run->figure[FIG_B_EVENTS] = (double)report->b.n;
    }
    bk_stats_report_free(report);
    bk_event_table_free(&t);
    return rc;
}

/* Without a catalog the peak slip rate is the time series' largest |v|, read a slab of
 * rows at a time (a long chain's /v need not fit in memory). */
static int series_peak_slip_rate(hid_t file, const char *path, run_row *run, bk_error *err)
{
    hid_t dset = H5I_INVALID_HID;
    hsize_t rows = 0, cols = 0;
    int rank = 0;
    int rc = bk_h5_open_series(file, path, "v", &dset, &rows, &cols, &rank, err);
    if (rc != BK_OK)
        return rc;
    hsize_t slab = bk_h5_slab_rows(dset, cols);
    double *v = malloc((size_t)(slab * cols) * sizeof *v);
    if (!v)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for /v", path);
    double peak = NAN;
    for (hsize_t start = 0; rc == BK_OK && start < rows; start += slab) {
        hsize_t count = rows - start < slab ? rows - start : slab;
        if (bk_h5_read_block(dset, rank, start, count, 0, cols, H5T_NATIVE_DOUBLE, v) < 0) {
            rc = H5_DAMAGED(err, "%s: cannot read /v", path);
            break;
        }
        for (size_t i = 0; i < (size_t)(count * cols); ++i)
            if (!(fabs(v[i]) <= peak))
                peak = fabs(v[i]);
    }
    free(v);
    CLOSE_IDS(rc == BK_OK ? 0 : -1, dset);
    run->figure[FIG_PEAK_SLIP_RATE] = peak;
    return rc;
}

/* One output file into a row, its catalog figures from table (NULL: the default).
 * BK_INCOMPLETE for a run that did not finish and BK_ERR_INVALID for an HDF5 file that is no
 * bksim output or has no such table: each is left out, with a note. */
static int read_run(summary *s, const char *dir, const char *name, const char *table,
                    const bk_stats_options *opt, bk_error *err)
{
    char *path = join_path(dir, name);
    if (!path)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", dir);
    hid_t file = H5I_INVALID_HID, stats = H5I_INVALID_HID;
    int rc = bk_h5_open_input(path, &file, err);
    run_row run;
    memset(&run, 0, sizeof run);
    for (int f = 0; f < N_FIGURES; ++f)
        run.figure[f] = NAN;
    char *version = NULL, *overrides = NULL;
    int has_catalog = 0;
    if (rc == BK_OK) {
        version = bk_h5_read_string_attr(file, "version");
        if (!version)
            rc = BK_FAIL(err, BK_ERR_INVALID, "%s: not a bksim output (no root attribute version)", path);
    }
    if (rc == BK_OK && numeric_attr(file, "complete") != 1.0)
        rc = BK_FAIL(err, BK_INCOMPLETE, "%s: the run did not finish (complete = 0)", path);
    /* A finished file whose datasets are damaged would put wrong figures in the table. */
    if (rc == BK_OK) {
        bk_error why = {0};
        if (bk_h5_verify(path, &why) == BK_ERR_DAMAGED)
            rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s", why.message);
    }
    if (rc == BK_OK) {
        run.point = bk_h5_read_string_attr(file, "point");
        run.host = bk_h5_read_string_attr(file, "host");
        run.figure[FIG_SEED] = numeric_attr(file, "seed");
        overrides = bk_h5_read_string_attr(file, "overrides");
        has_catalog = table ? link_exists(file, table)
                            : link_exists(file, BK_CATALOG_DEFAULT_TABLE) ||
                                  link_exists(file, BK_CATALOG_FALLBACK_TABLE);
        if (table && !has_catalog)
            rc = BK_FAIL(err, BK_ERR_INVALID, "%s: no /%s table (--table %s)", path, table, table);
        else if (!has_catalog && H5Lexists(file, "v", H5P_DEFAULT) > 0)
            rc = series_peak_slip_rate(file, path, &run, err);
        if (H5Lexists(file, "stats", H5P_DEFAULT) > 0 &&
            (stats = H5Gopen2(file, "stats", H5P_DEFAULT)) >= 0) {
            for (size_t a = 0; a < sizeof stats_attrs / sizeof stats_attrs[0]; ++a)
                run.figure[stats_attrs[a].figure] = numeric_attr(stats, stats_attrs[a].attr);
            run.method = bk_h5_read_string_attr(stats, "method");
        }
    }
    CLOSE_IDS(rc == BK_OK ? 0 : -1, stats, file);
    if (rc == BK_OK && has_catalog)
        rc = catalog_figures(path, table, opt, &run, err);
    if (rc == BK_OK && !(run.file = strdup(name)))
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    /* Last: a run left out adds no key column. */
    if (rc == BK_OK && take_overrides(s, &run, overrides) != 0)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for its overrides", path);
    free(version);
    free(overrides);
    free(path);
    run_row *grown = rc == BK_OK ? bk_grow_array(s->runs, &s->runs_cap, s->n_runs + 1, sizeof *grown, 16) : NULL;
    if (rc == BK_OK && !grown)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", dir);
    if (rc != BK_OK) {
        free_row(&run);
        return rc;
    }
    s->runs = grown;
    s->runs[s->n_runs++] = run;
    return BK_OK;
}

/* ------------------------------------------------------------------ columns --- */

enum { TEXT_FILE, TEXT_POINT, TEXT_METHOD, TEXT_HOST, TEXT_CATALOG };

typedef struct column {
    const char *name;
    const char *unit;
    int text;      /* 1: a string column */
    long key;      /* key column index, else -1 */
    int figure;    /* figure index, else -1 */
    int field;     /* TEXT_* of a text column that is not a key */
    size_t width;  /* HDF5 string size (longest value + 1) */
    size_t offset; /* in the HDF5 record */
} column;

/* The unit of a --set key ("friction.mu_d", "block.3.mass"), from the key tables. */
static const char *key_unit(const char *key)
{
    const char *dot = strchr(key, '.');
    const char *name = strrchr(key, '.');
    if (!dot || !name)
        return "-";
    size_t section_len = (size_t)(dot - key);
    ++name;
    bk_key_info info;
    for (size_t i = 0; bk_config_key(i, &info) == 0; ++i)
        if (strlen(info.section) == section_len && strncmp(info.section, key, section_len) == 0 &&
            strcmp(info.param->key, name) == 0)
            return info.param->unit;
    if (section_len == 8 && strncmp(key, "friction", 8) == 0)
        for (const bk_friction_law *const *law = bk_friction_laws(); *law; ++law) {
            int p = bk_friction_param_index(*law, name);
            if (p >= 0)
                return (*law)->params[p].unit;
        }
    return "-";
}

static int parses_as_number(const char *text, double *value)
{
    char *end = NULL;
    errno = 0;
    *value = strtod(text, &end);
    return end != text && *end == '\0' && errno == 0 && isfinite(*value);
}

static const char *row_text(const run_row *run, const column *c)
{
    if (c->key >= 0)
        return (size_t)c->key < run->n_values ? run->values[c->key] : NULL;
    const char *texts[] = {run->file, run->point, run->method, run->host, run->catalog};
    return texts[c->field];
}

static double row_number(const run_row *run, const column *c)
{
    if (c->figure >= 0)
        return run->figure[c->figure];
    const char *text = row_text(run, c);
    double value;
    return text && parses_as_number(text, &value) ? value : NAN;
}

/* file, point, one column per key (numeric when every value given is a number), the
 * figures, method, host, catalog (last: a column added later goes at the end).  *n_columns
 * set; NULL when out of memory. */
static column *make_columns(const summary *s, size_t *n_columns)
{
    size_t n = 2 + s->n_keys + N_FIGURES + 3, k = 0;
    column *cols = calloc(n, sizeof *cols);
    if (!cols)
        return NULL;
    static const char *const text_names[] = {"file", "point", "method", "host", "catalog"};
    for (int f = TEXT_FILE; f <= TEXT_POINT; ++f)
        cols[k++] = (column){text_names[f], "-", 1, -1, -1, f, 0, 0};
    for (size_t key = 0; key < s->n_keys; ++key) {
        column c = {s->keys[key], key_unit(s->keys[key]), 0, (long)key, -1, 0, 0, 0};
        for (size_t r = 0; r < s->n_runs && !c.text; ++r) {
            const char *text = row_text(&s->runs[r], &c);
            double value;
            c.text = text && !parses_as_number(text, &value);
        }
        cols[k++] = c;
    }
    for (int f = 0; f < N_FIGURES; ++f)
        cols[k++] = (column){figures[f].name, figures[f].unit, 0, -1, f, 0, 0, 0};
    for (int f = TEXT_METHOD; f <= TEXT_CATALOG; ++f)
        cols[k++] = (column){text_names[f], "-", 1, -1, -1, f, 0, 0};
    *n_columns = k;
    return cols;
}

/* "name unit, ..." of the columns whose unit is not "-" (TSV header comment), or the
 * /stats style "name: unit, ..." of every column (HDF5). */
static char *units_text(const column *cols, size_t n, int hdf5)
{
    size_t len = 1;
    for (size_t c = 0; c < n; ++c)
        len += strlen(cols[c].name) + strlen(cols[c].unit) + 4;
    char *text = calloc(len, 1);
    if (!text)
        return NULL;
    size_t used = 0;
    for (size_t c = 0; c < n; ++c) {
        if (!hdf5 && strcmp(cols[c].unit, "-") == 0)
            continue;
        used += (size_t)snprintf(text + used, len - used, "%s%s%s %s", used ? ", " : "",
                                 cols[c].name, hdf5 ? ":" : "", cols[c].unit);
    }
    return text;
}

/* --------------------------------------------------------------------- files --- */

static int write_tsv(const summary *s, column *cols, size_t n_cols, const char *dir,
                     const char *path, bk_error *err)
{
    FILE *out = fopen(path, "w");
    if (!out)
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    char *units = units_text(cols, n_cols, 0);
    fprintf(out, "# bksim summary of %s: %zu finished runs, one per row; key columns hold each "
            "run's --set values; events and the figures after it count the rows of the table in "
            "column catalog (ruptures by default); units: %s\n", dir, s->n_runs, units ? units : "?");
    free(units);
    for (size_t c = 0; c < n_cols; ++c)
        fprintf(out, "%s%s", c ? "\t" : "", cols[c].name);
    fputc('\n', out);
    for (size_t r = 0; r < s->n_runs; ++r) {
        for (size_t c = 0; c < n_cols; ++c) {
            const char *text = cols[c].text ? row_text(&s->runs[r], &cols[c]) : NULL;
            if (c)
                fputc('\t', out);
            if (cols[c].text && text && *text)
                for (const char *ch = text; *ch; ++ch) /* a tab or newline would break the row */
                    fputc(*ch == '\t' || *ch == '\n' ? ' ' : *ch, out);
            else if (cols[c].text)
                fputc('-', out);
            else
                fprintf(out, "%.12g", row_number(&s->runs[r], &cols[c]));
        }
        fputc('\n', out);
    }
    int failed = ferror(out) | fflush(out) | fsync(fileno(out));
    if (fclose(out) != 0 || failed)
        return BK_FAIL(err, BK_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return BK_OK;
}

static int write_table(const summary *s, column *cols, size_t n_cols, const char *dir,
                       const char *path, bk_error *err)
{
    size_t record = 0;
    for (size_t c = 0; c < n_cols; ++c) {
        cols[c].width = 2;
        for (size_t r = 0; cols[c].text && r < s->n_runs; ++r) {
            const char *text = row_text(&s->runs[r], &cols[c]);
            size_t len = text ? strlen(text) + 1 : 2;
            if (len > cols[c].width)
                cols[c].width = len;
        }
        cols[c].offset = record;
        record += cols[c].text ? cols[c].width : sizeof(double);
    }
    unsigned char *rows = calloc(s->n_runs ? s->n_runs : 1, record);
    if (!rows)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    for (size_t r = 0; r < s->n_runs; ++r)
        for (size_t c = 0; c < n_cols; ++c) {
            unsigned char *cell = rows + r * record + cols[c].offset;
            if (cols[c].text) {
                const char *text = row_text(&s->runs[r], &cols[c]);
                memcpy(cell, text && *text ? text : "-", text && *text ? strlen(text) : 1);
            } else {
                double value = row_number(&s->runs[r], &cols[c]);
                memcpy(cell, &value, sizeof value);
            }
        }
    hid_t type = H5Tcreate(H5T_COMPOUND, record), file = H5I_INVALID_HID;
    hid_t space = H5I_INVALID_HID, dset = H5I_INVALID_HID;
    herr_t ok = type < 0 ? -1 : 0;
    for (size_t c = 0; c < n_cols && ok >= 0; ++c) {
        hid_t member = cols[c].text ? H5Tcopy(H5T_C_S1) : H5Tcopy(H5T_NATIVE_DOUBLE);
        if (member < 0 || (cols[c].text && H5Tset_size(member, cols[c].width) < 0) ||
            H5Tinsert(type, cols[c].name, cols[c].offset, member) < 0)
            ok = -1;
        CLOSE_IDS(ok, member);
    }
    hsize_t dims[1] = {s->n_runs};
    char *units = units_text(cols, n_cols, 1);
    char description[512];
    snprintf(description, sizeof description,
             "bksim summary of %s: one row per finished run, its --set values and headline "
             "figures (NaN where a run has none; the catalog figures from the table in column "
             "catalog)", dir);
    if (ok >= 0)
        file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file >= 0)
        space = H5Screate_simple(1, dims, NULL);
    if (space >= 0)
        dset = H5Dcreate2(file, "summary", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ok = dset < 0 || !units ? -1 : H5Dwrite(dset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows);
    if (ok >= 0)
        ok = bk_h5_describe(dset, units, description);
    if (ok >= 0)
        ok = bk_h5_write_long_attr(file, "runs", (long long)s->n_runs);
    int rc = ok < 0 ? H5_FAIL(err, "%s: cannot write the summary table", path) : BK_OK;
    CLOSE_IDS(ok, dset, space, type);
    if (file >= 0 && H5Fclose(file) < 0 && rc == BK_OK)
        rc = H5_FAIL(err, "%s: cannot close", path);
    free(units);
    free(rows);
    return rc;
}

/* The keys the rows are ordered by (qsort has no context argument). */
static size_t order_keys;

/* A key's value as a number, when the whole of it is one (not NaN, which orders nothing). */
static int as_number(const char *text, double *x)
{
    char *end = NULL;
    *x = text ? strtod(text, &end) : NAN;
    return text && end != text && *end == '\0' && !isnan(*x);
}

/* The grid's order: by the swept keys in the order the runs give them (the first slowest),
 * numbers as numbers (1e-3 before 0.5, as the sweep lists them; file names sort them the
 * other way), then by file name. */
static int by_grid(const void *pa, const void *pb)
{
    const run_row *a = pa, *b = pb;
    for (size_t k = 0; k < order_keys; ++k) {
        const char *va = k < a->n_values ? a->values[k] : NULL, *vb = k < b->n_values ? b->values[k] : NULL;
        if (!va || !vb) {
            if (va != vb)
                return va ? 1 : -1;
            continue;
        }
        /* A total order: numbers by value, before any text, text by its bytes. */
        double x, y;
        int na = as_number(va, &x), nb = as_number(vb, &y);
        int c = na && nb ? (x > y) - (x < y) : na != nb ? (na ? -1 : 1) : strcmp(va, vb);
        if (c != 0)
            return c;
    }
    return strcmp(a->file, b->file);
}

static int is_run_output(const char *name)
{
    size_t len = strlen(name);
    return len > 3 && strcmp(name + len - 3, ".h5") == 0 && strcmp(name, "summary.h5") != 0 &&
           name[0] != '.';
}

/* Write via a temporary name, then rename: a reader never sees half a file. */
typedef int (*summary_writer)(const summary *s, column *cols, size_t n_cols, const char *dir,
                              const char *path, bk_error *err);

static int write_atomically(const summary *s, column *cols, size_t n_cols, const char *dir,
                            const char *name, summary_writer write, bk_error *err)
{
    char *path = join_path(dir, name);
    char *tmp = path ? malloc(strlen(path) + sizeof ".tmp") : NULL;
    int rc = tmp ? BK_OK : BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", dir);
    if (rc == BK_OK) {
        sprintf(tmp, "%s.tmp", path);
        rc = write(s, cols, n_cols, dir, tmp, err);
    }
    if (rc == BK_OK && rename(tmp, path) != 0)
        rc = BK_FAIL(err, BK_ERR_IO, "%s: cannot rename to %s: %s", tmp, path, strerror(errno));
    if (rc != BK_OK && tmp)
        remove(tmp);
    free(tmp);
    free(path);
    return rc;
}

int bk_h5_summary(const char *dir, const char *table, const bk_stats_options *opt, FILE *notes,
                  size_t *n_runs, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (n_runs)
        *n_runs = 0;
    if (table && table[0] == '/')
        ++table;
    if (table && !*table)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: no table name given (ruptures, events, ...)",
                       dir ? dir : "(null)");
    DIR *d = dir ? opendir(dir) : NULL;
    if (!d)
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot read the directory: %s", dir ? dir : "(null)",
                       dir ? strerror(errno) : "no directory given");
    summary s;
    memset(&s, 0, sizeof s);
    int rc = BK_OK;
    size_t left_out = 0;
    for (struct dirent *entry; rc == BK_OK && (entry = readdir(d));) {
        if (!is_run_output(entry->d_name))
            continue;
        bk_error why = {0};
        int read = read_run(&s, dir, entry->d_name, table, opt, &why);
        if (read == BK_ERR_NOMEM) {
            *err = why;
            rc = read;
        } else if (read != BK_OK) {
            ++left_out;
            if (notes)
                fprintf(notes, "bksim summary: left out %s\n", why.message);
        }
    }
    closedir(d);
    if (rc == BK_OK && s.n_runs == 0)
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: no finished bksim output (*.h5)%s%s%s to summarise%s", dir,
                     table ? " with a /" : "", table ? table : "", table ? " table" : "",
                     left_out ? " (see the notes above)" : "");
    size_t fell_back = 0;
    for (size_t r = 0; r < s.n_runs; ++r)
        fell_back += s.runs[r].fallback != 0;
    if (rc == BK_OK && fell_back && notes)
        fprintf(notes, "bksim summary: %zu of %zu runs have no /%s table: their catalog figures are "
                "from /%s (column catalog)\n", fell_back, s.n_runs, BK_CATALOG_DEFAULT_TABLE,
                BK_CATALOG_FALLBACK_TABLE);
    size_t n_cols = 0;
    column *cols = NULL;
    if (rc == BK_OK) {
        order_keys = s.n_keys;
        qsort(s.runs, s.n_runs, sizeof *s.runs, by_grid);
        cols = make_columns(&s, &n_cols);
        if (!cols)
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", dir);
    }
    if (rc == BK_OK)
        rc = write_atomically(&s, cols, n_cols, dir, "summary.tsv", write_tsv, err);
    if (rc == BK_OK)
        rc = write_atomically(&s, cols, n_cols, dir, "summary.h5", write_table, err);
    if (rc == BK_OK && n_runs)
        *n_runs = s.n_runs;
    free(cols);
    free_summary(&s);
    return rc;
}
