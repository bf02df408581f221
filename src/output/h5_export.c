/* `bksim export`: chosen time series (one column per block, or one block) or the
 * /transitions table as whitespace-separated text, or the /events catalog as TSV, read a
 * block of rows at a time. */
#include "bksim/inspect.h"

#include <stdlib.h>
#include <string.h>

#include "output/h5_impl.h"

static int name_list_contains(const bk_h5_name_list *list, const char *name)
{
    for (size_t i = 0; i < list->count; ++i)
        if (strcmp(list->names[i], name) == 0)
            return 1;
    return 0;
}

static void name_list_join(const bk_h5_name_list *list, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < list->count && used < len; ++i) {
        int n = snprintf(buf + used, len - used, "%s%s", i ? ", " : "", list->names[i]);
        if (n < 0)
            break;
        used += (size_t)n;
    }
    if (list->count == 0)
        snprintf(buf, len, "(none)");
}

typedef struct export_series {
    char *name;
    hid_t dset;
    int rank;
    hsize_t rows;
    hsize_t first_col; /* columns read: [first_col, first_col + n_read) */
    hsize_t n_read;
    size_t *print;     /* indices into a read row, in print order */
    size_t n_print;
    double *buf;
} export_series;

static void export_series_free(export_series *s, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        free(s[i].name);
        free(s[i].print);
        free(s[i].buf);
        bk_h5_close_id(s[i].dset);
    }
    free(s);
}

/* The friction_state column-to-block map, if the dataset has one. */
static int32_t *read_column_blocks(hid_t dset, hsize_t cols)
{
    if (H5Aexists(dset, "block") <= 0)
        return NULL;
    hid_t attr = H5Aopen(dset, "block", H5P_DEFAULT);
    hid_t space = attr >= 0 ? H5Aget_space(attr) : H5I_INVALID_HID;
    int32_t *blocks = NULL;
    if (space >= 0 && (hsize_t)H5Sget_simple_extent_npoints(space) == cols) {
        blocks = malloc((size_t)cols * sizeof *blocks);
        if (blocks && H5Aread(attr, H5T_NATIVE_INT32, blocks) < 0) {
            free(blocks);
            blocks = NULL;
        }
    }
    CLOSE_IDS(0, space, attr);
    return blocks;
}

/* Decide the columns of one dataset and print their header names. */
static int setup_export_series(hid_t file, const char *path, export_series *s, long block,
                               long long n_blocks, FILE *out, bk_error *err)
{
    hsize_t cols;
    int rc = bk_h5_open_series(file, path, s->name, &s->dset, &s->rows, &cols, &s->rank, err);
    if (rc != BK_OK)
        return rc;
    char *units = bk_h5_read_string_attr(s->dset, "units");
    char suffix[80] = "";
    if (units)
        snprintf(suffix, sizeof suffix, "[%s]", units);
    free(units);
    s->print = malloc((size_t)(cols ? cols : 1) * sizeof *s->print);
    if (!s->print)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    if (s->rank == 1) {
        s->n_read = 1;
        s->print[s->n_print++] = 0;
        fprintf(out, " %s%s", s->name, suffix);
        return BK_OK;
    }
    int32_t *map = read_column_blocks(s->dset, cols);
    if (map) {
        /* Per-law columns (friction_state): name them block_k, pick a block's columns. */
        s->n_read = cols;
        long k = 0, last = -2;
        for (hsize_t c = 0; c < cols; ++c) {
            k = map[c] == last ? k + 1 : 0;
            last = map[c];
            if (block >= 0 && map[c] != block)
                continue;
            s->print[s->n_print++] = (size_t)c;
            fprintf(out, " %s_%d_%ld%s", s->name, (int)map[c], k, suffix);
        }
        free(map);
    } else if ((long long)cols == n_blocks) {
        s->first_col = block >= 0 ? (hsize_t)block : 0;
        s->n_read = block >= 0 ? 1 : cols;
        for (hsize_t c = 0; c < s->n_read; ++c) {
            s->print[s->n_print++] = (size_t)c;
            fprintf(out, " %s_%llu%s", s->name, (unsigned long long)(s->first_col + c), suffix);
        }
    } else if (block < 0) {
        s->n_read = cols;
        for (hsize_t c = 0; c < cols; ++c) {
            s->print[s->n_print++] = (size_t)c;
            fprintf(out, " %s_%llu%s", s->name, (unsigned long long)c, suffix);
        }
    } else {
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: dataset '%s' has %llu columns, not one per block; export it with "
                       "all blocks (block -1)", path, s->name, (unsigned long long)cols);
    }
    return BK_OK;
}

/* Split the comma-separated list into datasets to print; NULL = the default list,
 * restricted to what the file holds. */
static int parse_dataset_list(hid_t file, const char *path, const char *datasets,
                              export_series **out, size_t *count, bk_error *err)
{
    static const char *const defaults = "time,event,driver,x,v,friction,cof,mode";
    bk_h5_name_list available;
    *out = NULL;
    *count = 0;
    if (bk_h5_list_series(file, &available) < 0)
        return H5_FAIL(err, "%s: cannot list datasets", path);
    const char *spec = datasets ? datasets : defaults;
    size_t max = 1;
    for (const char *p = spec; *p; ++p)
        max += *p == ',';
    export_series *s = calloc(max, sizeof *s);
    int rc = s ? BK_OK : BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    size_t n = 0;
    for (const char *p = spec; rc == BK_OK && *p;) {
        const char *end = strchr(p, ',');
        if (!end)
            end = p + strlen(p);
        const char *a = p, *b = end;
        while (a < b && (*a == ' ' || *a == '\t'))
            ++a;
        while (b > a && (b[-1] == ' ' || b[-1] == '\t'))
            --b;
        p = *end ? end + 1 : end;
        if (a == b) {
            rc = BK_FAIL(err, BK_ERR_INVALID, "empty dataset name in '%s'", spec);
            break;
        }
        char *name = malloc((size_t)(b - a) + 1);
        if (!name) {
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
            break;
        }
        memcpy(name, a, (size_t)(b - a));
        name[b - a] = '\0';
        if (!name_list_contains(&available, name)) {
            if (!datasets) {
                free(name);
                continue;
            }
            char list[768];
            name_list_join(&available, list, sizeof list);
            rc = BK_FAIL(err, BK_ERR_INVALID, "%s: no dataset '%s'%s; available: %s", path,
                         name,
                         strcmp(name, "transitions") == 0 ? " to export as columns (use the "
                                                            "transitions table option)"
                                                          : "",
                         list);
            free(name);
            break;
        }
        s[n].name = name;
        s[n].dset = H5I_INVALID_HID;
        ++n;
    }
    if (rc == BK_OK && n == 0) {
        char list[768];
        name_list_join(&available, list, sizeof list);
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: nothing to export; available: %s", path, list);
    }
    bk_h5_name_list_free(&available);
    if (rc != BK_OK) {
        export_series_free(s, n);
        return rc;
    }
    *out = s;
    *count = n;
    return BK_OK;
}

static int export_series_table(hid_t file, const char *path, const char *datasets, long block,
                               long long n_blocks, FILE *out, bk_error *err)
{
    export_series *s;
    size_t n;
    int rc = parse_dataset_list(file, path, datasets, &s, &n, err);
    if (rc != BK_OK)
        return rc;
    fprintf(out, "#");
    hsize_t rows = 0, width = 0;
    for (size_t i = 0; rc == BK_OK && i < n; ++i) {
        rc = setup_export_series(file, path, &s[i], block, n_blocks, out, err);
        if (rc == BK_OK) {
            /* A .part cut short mid-append may be ragged: print the rows all datasets have. */
            rows = i == 0 || s[i].rows < rows ? s[i].rows : rows;
            width += s[i].n_read;
        }
    }
    if (rc == BK_OK) {
        fprintf(out, "\n");
        hsize_t step = EXPORT_BUDGET / (width ? width : 1);
        if (step < 1)
            step = 1;
        if (step > rows)
            step = rows ? rows : 1;
        for (size_t i = 0; rc == BK_OK && i < n; ++i) {
            s[i].buf = malloc((size_t)(step * s[i].n_read) * sizeof *s[i].buf);
            if (!s[i].buf)
                rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
        }
        for (hsize_t start = 0; rc == BK_OK && start < rows; start += step) {
            hsize_t count = rows - start < step ? rows - start : step;
            for (size_t i = 0; i < n; ++i) {
                if (bk_h5_read_block(s[i].dset, s[i].rank, start, count, s[i].first_col, s[i].n_read,
                               H5T_NATIVE_DOUBLE, s[i].buf) < 0) {
                    rc = H5_FAIL(err, "%s: cannot read dataset '%s'", path, s[i].name);
                    break;
                }
            }
            for (size_t r = 0; rc == BK_OK && r < (size_t)count; ++r) {
                const char *sep = "";
                for (size_t i = 0; i < n; ++i) {
                    const double *row = s[i].buf + r * (size_t)s[i].n_read;
                    for (size_t k = 0; k < s[i].n_print; ++k) {
                        fprintf(out, "%s%.17g", sep, row[s[i].print[k]]);
                        sep = " ";
                    }
                }
                fputc('\n', out);
            }
        }
    }
    export_series_free(s, n);
    return rc;
}

typedef struct export_filter {
    long block; /* < 0: all */
    FILE *out;
} export_filter;

static void transitions_header(FILE *out)
{
    fprintf(out, "# t[s] block[1] from[1] to[1] x[m] v[m/s] force[N]\n");
}

static int print_transition(const bk_transition *t, unsigned long long row, void *user, bk_error *err)
{
    (void)err;
    const export_filter *f = user;
    if (row == 0)
        transitions_header(f->out); /* once the table opened */
    if (f->block < 0 || t->block == f->block)
        fprintf(f->out, "%.17g %d %d %d %.17g %.17g %.17g\n", t->t, (int)t->block, (int)t->from,
                (int)t->to, t->x, t->v, t->force);
    return BK_OK;
}

static int export_transitions(hid_t file, const char *path, long block, FILE *out,
                              bk_error *err)
{
    export_filter filter = {block, out};
    hsize_t count = 0;
    int rc = bk_h5_each_transition(file, path, print_transition, &filter, &count, err);
    if (rc == BK_OK && count == 0)
        transitions_header(out);
    return rc;
}

int bk_h5_export(const char *path, const char *datasets, long block, int transitions,
                 FILE *out, bk_error *err)
{
    if (!out)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_export: no output stream");
    hid_t file;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    long long n_blocks;
    rc = bk_h5_read_n_blocks(file, path, &n_blocks, err);
    if (rc == BK_OK && (block < -1 || block >= n_blocks))
        rc = BK_FAIL(err, BK_ERR_INVALID,
                     "block %ld out of range: %s has %lld block%s (allowed: 0..%lld)",
                     block, path, n_blocks, n_blocks == 1 ? "" : "s", n_blocks - 1);
    if (rc == BK_OK)
        rc = transitions ? export_transitions(file, path, block, out, err)
                         : export_series_table(file, path, datasets, block, n_blocks, out, err);
    bk_h5_close_id(file);
    if (rc == BK_OK && (fflush(out) != 0 || ferror(out)))
        rc = BK_FAIL(err, BK_ERR_IO, "%s: writing the export failed", path);
    return rc;
}

/* ------------------------------------------------------------------ /events --- */

static void events_header(FILE *out)
{
    fputs("# t_start[s]\tt_end[s]\tfirst_block[1]\tn_blocks[1]\tleft[1]\tright[1]\t"
          "n_episodes[1]\tpotency[m]\tmagnitude[1]\tmax_slip_rate[m/s]\tstress_drop[N]\t"
          "complete[1]\n",
          out);
}

static int print_event(const bk_event *e, unsigned long long row, void *user, bk_error *err)
{
    (void)err;
    FILE *out = user;
    if (row == 0)
        events_header(out);
    fprintf(out, "%.17g\t%.17g\t%d\t%d\t%d\t%d\t%d\t%.17g\t%.17g\t%.17g\t%.17g\t%d\n", e->t_start,
            e->t_end, (int)e->first_block, (int)e->n_blocks, (int)e->left, (int)e->right,
            (int)e->n_episodes, e->potency, e->magnitude, e->max_slip_rate, e->stress_drop,
            (int)e->complete);
    return BK_OK;
}

int bk_h5_export_events(const char *path, FILE *out, bk_error *err)
{
    if (!out)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_export_events: no output stream");
    hid_t file;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    hsize_t count = 0;
    rc = bk_h5_each_event(file, path, print_event, out, &count, err);
    if (rc == BK_OK && count == 0)
        events_header(out); /* an empty catalog: the header alone */
    bk_h5_close_id(file);
    if (rc == BK_OK && (fflush(out) != 0 || ferror(out)))
        rc = BK_FAIL(err, BK_ERR_IO, "%s: writing the export failed", path);
    return rc;
}

/* ------------------------------------------------------- any record table --- */

/* The unit of member name in a "name: unit, name: unit" list; "" when not listed. */
static void unit_of(const char *units, const char *name, char *out, size_t len)
{
    out[0] = '\0';
    size_t n = strlen(name);
    for (const char *p = units; p && *p;) {
        while (*p == ' ' || *p == ',')
            p++;
        if (strncmp(p, name, n) == 0 && p[n] == ':') {
            p += n + 1;
            while (*p == ' ')
                p++;
            size_t k = 0;
            while (p[k] && p[k] != ',' && k + 1 < len) {
                out[k] = p[k];
                k++;
            }
            out[k] = '\0';
            return;
        }
        p = strchr(p, ',');
    }
}

int bk_h5_export_table(const char *path, const char *name, FILE *out, bk_error *err)
{
    if (!out || !name || !*name)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_export_table: needs a table name and an output stream");
    hid_t file;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    hid_t dset = H5I_INVALID_HID, type = H5I_INVALID_HID, space = H5I_INVALID_HID, mem = H5I_INVALID_HID;
    int members = 0;
    hsize_t rows = 0;
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0 || (dset = H5Dopen2(file, name, H5P_DEFAULT)) < 0) {
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: no table /%s (bksim writes transitions, events, ruptures, "
                     "rupture_blocks, rupture_rate)", path, name);
    } else {
        type = H5Dget_type(dset);
        space = H5Dget_space(dset);
        if (type < 0 || space < 0 || H5Tget_class(type) != H5T_COMPOUND || H5Sget_simple_extent_ndims(space) != 1 ||
            H5Sget_simple_extent_dims(space, &rows, NULL) < 0 || (members = H5Tget_nmembers(type)) < 1)
            rc = BK_FAIL(err, BK_ERR_INVALID, "%s: /%s is not a 1-D table of records", path, name);
    }
    /* Every member read as a double or a 64-bit integer, in a packed row of 8-byte cells. */
    int *is_int = NULL;
    char **names = NULL;
    if (rc == BK_OK) {
        is_int = calloc((size_t)members, sizeof *is_int);
        names = calloc((size_t)members, sizeof *names);
        mem = H5Tcreate(H5T_COMPOUND, 8 * (size_t)members);
        if (!is_int || !names || mem < 0)
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory exporting /%s", path, name);
    }
    char *units = rc == BK_OK ? bk_h5_read_string_attr(dset, "units") : NULL;
    for (int k = 0; rc == BK_OK && k < members; ++k) {
        names[k] = H5Tget_member_name(type, (unsigned)k);
        is_int[k] = H5Tget_member_class(type, (unsigned)k) == H5T_INTEGER;
        if (!names[k] || H5Tinsert(mem, names[k], 8 * (size_t)k, is_int[k] ? H5T_NATIVE_LLONG : H5T_NATIVE_DOUBLE) < 0)
            rc = H5_FAIL(err, "%s: cannot read the fields of /%s", path, name);
    }
    if (rc == BK_OK) {
        fputc('#', out);
        for (int k = 0; k < members; ++k) {
            char unit[32];
            unit_of(units, names[k], unit, sizeof unit);
            fprintf(out, "%s%s[%s]", k ? "\t" : " ", names[k], unit[0] ? unit : "1");
        }
        fputc('\n', out);
    }
    const hsize_t chunk = 4096;
    unsigned char *buf = rc == BK_OK ? malloc((size_t)chunk * 8 * (size_t)members) : NULL;
    if (rc == BK_OK && !buf)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory exporting /%s", path, name);
    for (hsize_t start = 0; rc == BK_OK && start < rows; start += chunk) {
        hsize_t n = rows - start < chunk ? rows - start : chunk;
        if (bk_h5_read_block(dset, 1, start, n, 0, 1, mem, buf) < 0) {
            rc = H5_DAMAGED(err, "%s: damaged: /%s rows %llu..%llu cannot be read", path, name,
                            (unsigned long long)start, (unsigned long long)(start + n - 1));
            break;
        }
        for (hsize_t r = 0; r < n; ++r)
            for (int k = 0; k < members; ++k) {
                const unsigned char *cell = buf + ((size_t)r * (size_t)members + (size_t)k) * 8;
                if (is_int[k]) {
                    long long v;
                    memcpy(&v, cell, sizeof v);
                    fprintf(out, "%lld%c", v, k + 1 < members ? '\t' : '\n');
                } else {
                    double v;
                    memcpy(&v, cell, sizeof v);
                    fprintf(out, "%.17g%c", v, k + 1 < members ? '\t' : '\n');
                }
            }
    }
    free(buf);
    free(units);
    for (int k = 0; names && k < members; ++k)
        H5free_memory(names[k]);
    free(names);
    free(is_int);
    CLOSE_IDS(rc, mem, space, type, dset, file);
    if (rc == BK_OK && (fflush(out) != 0 || ferror(out)))
        rc = BK_FAIL(err, BK_ERR_IO, "%s: writing the export failed", path);
    return rc;
}
