/* An earthquake catalog read from any HDF5 file: a table's columns into memory
 * (bk_event_table) for the statistics (src/stats_report.c computes them).  The table is the
 * one named, else bksim's rupture catalog /ruptures, else (older bksim outputs, another
 * program's catalog) the time-window catalog /events.
 *
 * A catalog needs only t_start and magnitude; the other fields of bksim's own catalogs
 * (potency, n_blocks, complete, t_end, max_slip_rate) are read when present, and a bksim
 * output's root attribute t_reached gives the run's simulated span.  Each field is read on
 * its own through a one-member compound memory type, so HDF5 converts whatever numeric type
 * the file holds and the order and the other members of the table do not matter. */
#include "bksim/inspect.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/stats.h"
#include "output/h5_impl.h"

/* The member names of the compound file type, comma-separated, for a message. */
static void member_names(hid_t type, char *buf, size_t len)
{
    buf[0] = '\0';
    int members = H5Tget_nmembers(type);
    size_t used = 0;
    for (int i = 0; i < members && used + 1 < len; ++i) {
        char *name = H5Tget_member_name(type, (unsigned)i);
        if (!name)
            continue;
        int w = snprintf(buf + used, len - used, "%s%s", i ? ", " : "", name);
        H5free_memory(name);
        if (w < 0)
            break;
        used += (size_t)w;
    }
    if (used >= len && len > 4)
        strcpy(buf + len - 4, "...");
}

/* Field name of the table as mem_type values into a new array *out (NULL and BK_OK when
 * the table has no such field; an error when it is there but not numeric). */
static int read_field(hid_t dset, hid_t file_type, const char *path, const char *table, size_t n,
                      const char *name, hid_t mem_type, void **out, bk_error *err)
{
    *out = NULL;
    int index = H5Tget_member_index(file_type, name);
    if (index < 0) {
        H5Eclear2(H5E_DEFAULT);
        return BK_OK;
    }
    H5T_class_t cls = H5Tget_member_class(file_type, (unsigned)index);
    if (cls != H5T_INTEGER && cls != H5T_FLOAT)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: /%s field '%s' is not numeric", path, table, name);
    size_t elem = H5Tget_size(mem_type);
    void *buf = malloc(n ? n * elem : 1);
    if (!buf)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for %zu /%s rows", path, n, table);
    if (n > 0) {
        hid_t mem = H5Tcreate(H5T_COMPOUND, elem);
        herr_t rc = mem < 0 ? -1 : H5Tinsert(mem, name, 0, mem_type);
        if (rc >= 0)
            rc = H5Dread(dset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
        if (rc < 0) {
            int status = H5_DAMAGED(err, "%s: cannot read field '%s' of /%s", path, name, table);
            CLOSE_IDS(-1, mem);
            free(buf);
            return status;
        }
        CLOSE_IDS(0, mem);
    }
    *out = buf;
    return BK_OK;
}

/* What a catalog is, for messages. */
#define CATALOG_SHAPE "an earthquake catalog: a 1-D compound dataset with at least the fields t_start and magnitude"

static int link_exists(hid_t file, const char *name)
{
    htri_t exists = H5Lexists(file, name, H5P_DEFAULT);
    if (exists < 0) /* e.g. a group on the way that is not there */
        H5Eclear2(H5E_DEFAULT);
    return exists > 0;
}

/* The table `name` (no leading '/') of file into t. */
static int read_table(hid_t file, const char *path, const char *name, bk_event_table *t, bk_error *err)
{
    if (!link_exists(file, name))
        return BK_FAIL(err, BK_ERR_INVALID, "%s: no /%s table (" CATALOG_SHAPE ")", path, name);
    hid_t dset = H5Dopen2(file, name, H5P_DEFAULT);
    if (dset < 0)
        return H5_FAIL(err, "%s: /%s is not a readable dataset", path, name);
    hid_t type = H5Dget_type(dset);
    hid_t space = H5Dget_space(dset);
    int rc = BK_OK;
    if (type < 0 || space < 0) {
        rc = H5_DAMAGED(err, "%s: cannot read the type and shape of /%s", path, name);
        goto done;
    }
    if (H5Tget_class(type) != H5T_COMPOUND || H5Sget_simple_extent_ndims(space) != 1) {
        rc = BK_FAIL(err, BK_ERR_INVALID,
                     "%s: /%s must be a 1-D compound dataset (a table with fields t_start, "
                     "magnitude, ...)",
                     path, name);
        goto done;
    }
    hsize_t rows = 0;
    H5Sget_simple_extent_dims(space, &rows, NULL);
    t->n = (size_t)rows;
    const char *required[] = {"t_start", "magnitude"};
    for (size_t k = 0; k < 2; ++k)
        if (H5Tget_member_index(type, required[k]) < 0) {
            H5Eclear2(H5E_DEFAULT);
            char names[512];
            member_names(type, names, sizeof names);
            rc = BK_FAIL(err, BK_ERR_INVALID,
                         "%s: /%s has no field '%s' (a catalog needs t_start and magnitude; "
                         "fields present: %s)",
                         path, name, required[k], names[0] ? names : "none");
            goto done;
        }
    /* Each column through its own one-member memory type (absent optional ones stay NULL). */
    const struct {
        const char *name;
        hid_t memory_type;
        size_t offset; /* of the column's pointer in bk_event_table */
    } columns[] = {
        {"t_start", H5T_NATIVE_DOUBLE, offsetof(bk_event_table, t_start)},
        {"magnitude", H5T_NATIVE_DOUBLE, offsetof(bk_event_table, magnitude)},
        {"t_end", H5T_NATIVE_DOUBLE, offsetof(bk_event_table, t_end)},
        {"potency", H5T_NATIVE_DOUBLE, offsetof(bk_event_table, potency)},
        {"max_slip_rate", H5T_NATIVE_DOUBLE, offsetof(bk_event_table, max_slip_rate)},
        {"n_blocks", H5T_NATIVE_INT32, offsetof(bk_event_table, n_blocks)},
        {"complete", H5T_NATIVE_INT8, offsetof(bk_event_table, complete)},
    };
    for (size_t k = 0; k < sizeof columns / sizeof *columns; ++k) {
        void *column = NULL;
        rc = read_field(dset, type, path, name, t->n, columns[k].name, columns[k].memory_type, &column,
                        err);
        if (rc != BK_OK)
            goto done;
        memcpy((char *)t + columns[k].offset, &column, sizeof column);
    }
done:
    CLOSE_IDS(rc, space, type, dset);
    if (rc != BK_OK)
        bk_event_table_free(t);
    return rc;
}

int bk_h5_read_event_table(const char *path, const char *table, bk_event_table *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    out->t_reached = NAN;
    const char *name = table && table[0] == '/' ? table + 1 : table;
    if (name && !*name)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: no table name given (ruptures, events, or any table "
                       "of the file that is %s)", path, CATALOG_SHAPE);
    hid_t file;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    int fallback = 0;
    if (!name) {
        name = BK_CATALOG_DEFAULT_TABLE;
        if (!link_exists(file, name) && link_exists(file, BK_CATALOG_FALLBACK_TABLE)) {
            name = BK_CATALOG_FALLBACK_TABLE;
            fallback = 1;
        } else if (!link_exists(file, name)) {
            rc = BK_FAIL(err, BK_ERR_INVALID, "%s: no /%s table (the rupture catalog), and no /%s "
                         "(the time-window catalog) to fall back on (%s)",
                         path, BK_CATALOG_DEFAULT_TABLE, BK_CATALOG_FALLBACK_TABLE, CATALOG_SHAPE);
        }
    }
    if (rc == BK_OK)
        rc = read_table(file, path, name, out, err);
    if (rc == BK_OK && !(out->name = strdup(name)))
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    if (rc == BK_OK) {
        out->fallback = fallback;
        out->t_reached = NAN;
        double t_reached = 0.0;
        if (H5Aexists(file, "t_reached") > 0 &&
            bk_h5_read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &t_reached) >= 0)
            out->t_reached = t_reached;
    } else {
        bk_event_table_free(out);
        out->t_reached = NAN;
    }
    H5Eclear2(H5E_DEFAULT);
    CLOSE_IDS(rc, file);
    return rc;
}

int bk_stats_report_read(const char *path, const char *table, const bk_stats_options *opt,
                         bk_stats_report **out, bk_error *err)
{
    *out = NULL;
    /* A bad option is refused before the file is opened, whatever is wrong with the file. */
    if (opt) {
        int rc = bk_stats_options_check(opt, err);
        if (rc != BK_OK)
            return rc;
    }
    bk_event_table columns;
    int rc = bk_h5_read_event_table(path, table, &columns, err);
    if (rc == BK_OK)
        rc = bk_stats_report_compute(&columns, path, opt, out, err);
    bk_event_table_free(&columns);
    return rc;
}
