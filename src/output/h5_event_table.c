/* An earthquake catalog read from any HDF5 file: the /events table's columns into memory
 * (bk_event_table) for the statistics (src/stats_report.c computes them).
 *
 * A catalog needs only t_start and magnitude; the other fields of bksim's own catalogs
 * (potency, n_blocks, complete, t_end) are read when present, and a bksim output's root
 * attribute t_reached gives the run's simulated span.  Each field is read on its own through
 * a one-member compound memory type, so HDF5 converts whatever numeric type the file holds
 * and the order and the other members of the table do not matter. */
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
static int read_field(hid_t dset, hid_t file_type, const char *path, size_t n, const char *name,
                      hid_t mem_type, void **out, bk_error *err)
{
    *out = NULL;
    int index = H5Tget_member_index(file_type, name);
    if (index < 0) {
        H5Eclear2(H5E_DEFAULT);
        return BK_OK;
    }
    H5T_class_t cls = H5Tget_member_class(file_type, (unsigned)index);
    if (cls != H5T_INTEGER && cls != H5T_FLOAT)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: /events field '%s' is not numeric", path, name);
    size_t elem = H5Tget_size(mem_type);
    void *buf = malloc(n ? n * elem : 1);
    if (!buf)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for %zu /events rows", path, n);
    if (n > 0) {
        hid_t mem = H5Tcreate(H5T_COMPOUND, elem);
        herr_t rc = mem < 0 ? -1 : H5Tinsert(mem, name, 0, mem_type);
        if (rc >= 0)
            rc = H5Dread(dset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
        if (rc < 0) {
            int status = H5_DAMAGED(err, "%s: cannot read field '%s' of /events", path, name);
            CLOSE_IDS(-1, mem);
            free(buf);
            return status;
        }
        CLOSE_IDS(0, mem);
    }
    *out = buf;
    return BK_OK;
}

static int read_events(hid_t file, const char *path, bk_event_table *t, bk_error *err)
{
    memset(t, 0, sizeof *t);
    htri_t exists = H5Lexists(file, "events", H5P_DEFAULT);
    if (exists <= 0)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: no /events table (an earthquake catalog: a 1-D compound dataset "
                       "with at least the fields t_start and magnitude)",
                       path);
    hid_t dset = H5Dopen2(file, "events", H5P_DEFAULT);
    if (dset < 0)
        return H5_FAIL(err, "%s: /events is not a readable dataset", path);
    hid_t type = H5Dget_type(dset);
    hid_t space = H5Dget_space(dset);
    int rc = BK_OK;
    if (type < 0 || space < 0) {
        rc = H5_DAMAGED(err, "%s: cannot read the type and shape of /events", path);
        goto done;
    }
    if (H5Tget_class(type) != H5T_COMPOUND || H5Sget_simple_extent_ndims(space) != 1) {
        rc = BK_FAIL(err, BK_ERR_INVALID,
                     "%s: /events must be a 1-D compound dataset (a table with fields t_start, "
                     "magnitude, ...)",
                     path);
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
                         "%s: /events has no field '%s' (a catalog needs t_start and magnitude; "
                         "fields present: %s)",
                         path, required[k], names[0] ? names : "none");
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
        {"n_blocks", H5T_NATIVE_INT32, offsetof(bk_event_table, n_blocks)},
        {"complete", H5T_NATIVE_INT8, offsetof(bk_event_table, complete)},
    };
    for (size_t k = 0; k < sizeof columns / sizeof *columns; ++k) {
        void *column = NULL;
        rc = read_field(dset, type, path, t->n, columns[k].name, columns[k].memory_type, &column, err);
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

int bk_h5_read_event_table(const char *path, bk_event_table *table, bk_error *err)
{
    hid_t file;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK) {
        memset(table, 0, sizeof *table);
        return rc;
    }
    rc = read_events(file, path, table, err);
    table->t_reached = NAN;
    double t_reached = 0.0;
    if (rc == BK_OK && H5Aexists(file, "t_reached") > 0 &&
        bk_h5_read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &t_reached) >= 0)
        table->t_reached = t_reached;
    H5Eclear2(H5E_DEFAULT);
    CLOSE_IDS(rc, file);
    return rc;
}

int bk_stats_report_read(const char *path, const bk_stats_options *opt, bk_stats_report **out,
                         bk_error *err)
{
    *out = NULL;
    /* A bad option is refused before the file is opened, whatever is wrong with the file. */
    if (opt) {
        int rc = bk_stats_options_check(opt, err);
        if (rc != BK_OK)
            return rc;
    }
    bk_event_table table;
    int rc = bk_h5_read_event_table(path, &table, err);
    if (rc == BK_OK)
        rc = bk_stats_report_compute(&table, path, opt, out, err);
    bk_event_table_free(&table);
    return rc;
}
