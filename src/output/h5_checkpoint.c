/* Checkpoint slots in the output file: written in turn, read back and verified (the restart
 * that continues from them is h5_resume.c).
 *
 * The slot writer and reader loop over the checkpoint's field table (bksim/checkpoint.h):
 * arrays become datasets of the slot, scalars attributes, in the table's order. */
#include "bksim/output.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "output/h5_impl.h"

/* A checkpoint has to survive a crash while the next one is written.  HDF5 writes raw data
 * when asked but keeps attributes in its metadata cache until a flush, so a checkpoint
 * overwritten in place could be left half old, half new (seen: the attributes of t = 5.88 s
 * with the positions of t = 5.89 s, and a restart that went on from that mix).  So /checkpoint
 * holds two slots, /checkpoint/a and /checkpoint/b, written in turn: while one is written the
 * other is the last complete checkpoint, untouched on disk.  Each slot records a sequence
 * number and a checksum over everything a restart uses; a restart takes the newest slot that
 * verifies and agrees with the datasets, and refuses when none does.  A slot is overwritten
 * in place rather than created anew and linked in, so that writing one changes no link of
 * the root group and frees no space the other one still occupies; its text is fixed-length
 * (see bk_h5_write_fixed_string_attr). */
static const char *const SLOT_NAMES[2] = {"a", "b"};

/* A fixed 1-D array in group, created on first use and overwritten in place after. */
static herr_t put_array(hid_t group, const char *name, hid_t file_type, hid_t mem_type, size_t n,
                        const void *data)
{
    hid_t dset;
    if (H5Lexists(group, name, H5P_DEFAULT) > 0) {
        dset = H5Dopen2(group, name, H5P_DEFAULT);
    } else {
        hsize_t dims[1] = {n ? n : 1};
        hid_t space = H5Screate_simple(1, dims, NULL);
        dset = space < 0 ? H5I_INVALID_HID
                         : H5Dcreate2(group, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        CLOSE_IDS(0, space);
    }
    herr_t rc = dset < 0 ? -1 : n ? H5Dwrite(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) : 0;
    CLOSE_IDS(rc, dset);
    return rc;
}

static herr_t get_array(hid_t group, const char *name, hid_t mem_type, size_t n, void *data)
{
    if (n == 0)
        return 0;
    hid_t dset = H5Dopen2(group, name, H5P_DEFAULT);
    hid_t space = dset < 0 ? H5I_INVALID_HID : H5Dget_space(dset);
    herr_t rc = -1;
    if (space >= 0 && (size_t)H5Sget_simple_extent_npoints(space) == n)
        rc = H5Dread(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    CLOSE_IDS(rc, space, dset);
    return rc;
}

/* A variable field's values in group: a chunked dataset resized to them on every write (a
 * slot is overwritten in place, and the count changes from one checkpoint to the next). */
static herr_t put_variable(hid_t group, const char *name, const double *values, size_t n)
{
    hid_t dset;
    hsize_t dims[1] = {n};
    if (H5Lexists(group, name, H5P_DEFAULT) > 0) {
        dset = H5Dopen2(group, name, H5P_DEFAULT);
        if (dset >= 0 && H5Dset_extent(dset, dims) < 0) {
            CLOSE_IDS(-1, dset);
            return -1;
        }
    } else {
        hsize_t max_dims[1] = {H5S_UNLIMITED}, chunk[1] = {4096};
        hid_t space = H5Screate_simple(1, dims, max_dims);
        hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
        dset = space < 0 || dcpl < 0 || H5Pset_chunk(dcpl, 1, chunk) < 0
                   ? H5I_INVALID_HID
                   : H5Dcreate2(group, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
        CLOSE_IDS(0, dcpl, space);
    }
    herr_t rc = dset < 0 ? -1 : n ? H5Dwrite(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) : 0;
    CLOSE_IDS(rc, dset);
    return rc;
}

/* A variable field back: its values malloc'ed into the checkpoint, with their count. */
static herr_t get_variable(hid_t group, const bk_checkpoint_field *f, bk_checkpoint *cp)
{
    hid_t dset = H5Dopen2(group, f->name, H5P_DEFAULT);
    hid_t space = dset < 0 ? H5I_INVALID_HID : H5Dget_space(dset);
    hssize_t n = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
    double *values = n > 0 && (size_t)n <= SIZE_MAX / sizeof(double) ? malloc((size_t)n * sizeof *values) : NULL;
    herr_t rc = values && H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) >= 0 ? 0 : -1;
    CLOSE_IDS(rc, space, dset);
    if (rc < 0) {
        free(values);
        return -1;
    }
    char *member = (f->catalog ? (char *)cp->catalog : (char *)cp) + f->offset;
    long count = (long)n;
    memcpy(member, &values, sizeof values);
    memcpy(member + sizeof values, &count, sizeof count);
    return 0;
}

/* The group name in parent, created when missing; *created tells which. */
static hid_t open_or_create_group(hid_t parent, const char *name, int *created)
{
    htri_t exists = H5Lexists(parent, name, H5P_DEFAULT);
    *created = exists == 0;
    if (exists < 0)
        return H5I_INVALID_HID;
    return exists ? H5Gopen2(parent, name, H5P_DEFAULT)
                  : H5Gcreate2(parent, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
}

#define CHECKPOINT_UNITS                                                                   \
    "t: s, x: m, v: m/s, t_switch: s, last_transition: s, energies: J, t_last_row: s, "    \
    "last_transition_t: s"

/* The HDF5 types of a checkpoint field: on disk (fixed little-endian) and in memory. */
static hid_t field_file_type(bk_checkpoint_type type)
{
    switch (type) {
    case BK_CHECKPOINT_I8:
        return H5T_STD_I8LE;
    case BK_CHECKPOINT_U8:
        return H5T_STD_U8LE;
    case BK_CHECKPOINT_F64:
        return H5T_IEEE_F64LE;
    case BK_CHECKPOINT_LONG:
        break;
    }
    return H5T_STD_I64LE;
}

static hid_t field_mem_type(bk_checkpoint_type type)
{
    switch (type) {
    case BK_CHECKPOINT_I8:
        return H5T_NATIVE_INT8;
    case BK_CHECKPOINT_U8:
        return H5T_NATIVE_UINT8;
    case BK_CHECKPOINT_F64:
        return H5T_NATIVE_DOUBLE;
    case BK_CHECKPOINT_LONG:
        break;
    }
    return H5T_NATIVE_LONG;
}

/* One table field into a slot: an array as a dataset, a scalar as an attribute (integers as
 * 64-bit, whatever their width in memory). */
static herr_t put_field(hid_t group, const bk_checkpoint_field *f, const bk_checkpoint *cp)
{
    const void *data = bk_checkpoint_field_cdata(f, cp);
    if (f->extent == BK_CHECKPOINT_VARIABLE)
        return put_variable(group, f->name, data, bk_checkpoint_field_count(f, cp));
    if (f->extent != BK_CHECKPOINT_SCALAR)
        return put_array(group, f->name, field_file_type(f->type), field_mem_type(f->type),
                         bk_checkpoint_field_count(f, cp), data);
    switch (f->type) {
    case BK_CHECKPOINT_F64:
        return bk_h5_write_double_attr(group, f->name, *(const double *)data);
    case BK_CHECKPOINT_I8:
        return bk_h5_write_long_attr(group, f->name, *(const int8_t *)data);
    case BK_CHECKPOINT_U8:
        return bk_h5_write_long_attr(group, f->name, *(const uint8_t *)data);
    case BK_CHECKPOINT_LONG:
        break;
    }
    return bk_h5_write_long_attr(group, f->name, *(const long *)data);
}

/* The same field back from a slot into cp (its arrays allocated for the slot's counts). */
static herr_t get_field(hid_t group, const bk_checkpoint_field *f, bk_checkpoint *cp)
{
    if (f->extent == BK_CHECKPOINT_VARIABLE)
        return get_variable(group, f, cp);
    void *data = bk_checkpoint_field_data(f, cp);
    if (f->extent != BK_CHECKPOINT_SCALAR)
        return get_array(group, f->name, field_mem_type(f->type), bk_checkpoint_field_count(f, cp),
                         data);
    if (f->type == BK_CHECKPOINT_F64)
        return bk_h5_read_numeric_attr(group, f->name, H5T_NATIVE_DOUBLE, data);
    long long value = 0;
    herr_t rc = bk_h5_read_numeric_attr(group, f->name, H5T_NATIVE_LLONG, &value);
    if (f->type == BK_CHECKPOINT_I8)
        *(int8_t *)data = (int8_t)value;
    else if (f->type == BK_CHECKPOINT_U8)
        *(uint8_t *)data = (uint8_t)value;
    else
        *(long *)data = (long)value;
    return rc;
}

int bk_h5_write_checkpoint(hid_t file, const char *part, int slot, const bk_checkpoint *cp,
                           const bk_checkpoint_record *rec, bk_error *err)
{
    uint64_t checksum = bk_checkpoint_hash(cp, rec);
    int created = 0, slot_created = 0;
    hid_t top = open_or_create_group(file, "checkpoint", &created);
    herr_t ok = top < 0 ? -1 : 0;
    if (ok >= 0 && created)
        ok = bk_h5_describe_fixed(top, "a, b: checkpoint slots",
                                  "the state a restart (bksim run --restart) continues from: two "
                                  "slots written in turn, the newest that verifies (sequence, "
                                  "checksum) is used");
    hid_t group = ok < 0 ? H5I_INVALID_HID
                         : open_or_create_group(top, SLOT_NAMES[slot], &slot_created);
    if (group < 0)
        ok = -1;
    for (size_t k = 0; ok >= 0 && k < bk_checkpoint_n_fields; ++k)
        if (bk_checkpoint_field_stored(&bk_checkpoint_fields[k], cp))
            ok = put_field(group, &bk_checkpoint_fields[k], cp);
    /* Whether the slot holds a catalog: read before its fields, as the counts are. */
    if (ok >= 0)
        ok = bk_h5_write_long_attr(group, "catalog", cp->catalog != NULL);
    if (ok >= 0)
        ok = bk_h5_write_long_attr(group, "n_blocks", (long long)cp->n_blocks);
    if (ok >= 0)
        ok = bk_h5_write_long_attr(group, "n_state", (long long)cp->n_state);
    if (ok >= 0)
        ok = bk_h5_write_long_attr(group, "rows", rec->rows);
    if (ok >= 0)
        ok = bk_h5_write_long_attr(group, "transition_rows", rec->transition_rows);
    if (ok >= 0)
        ok = bk_h5_write_double_attr(group, "last_transition_t", rec->last_transition_t);
    if (ok >= 0)
        ok = bk_h5_write_long_attr(group, "sequence", rec->sequence);
    if (ok >= 0)
        ok = bk_h5_write_stats(group, &cp->stats);
    if (ok >= 0)
        ok = bk_h5_write_attr(group, "checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &checksum);
    if (ok >= 0 && slot_created)
        ok = bk_h5_describe_fixed(group, CHECKPOINT_UNITS,
                                  "one checkpoint; checksum: FNV-1a over sequence, rows, "
                                  "transition_rows, last_transition_t, the arrays, the scalars and "
                                  "stats");
    CLOSE_IDS(ok, group, top);
    if (ok < 0 || H5Fflush(file, H5F_SCOPE_LOCAL) < 0)
        return H5_FAIL(err, "%s: cannot write /checkpoint/%s", part, SLOT_NAMES[slot]);
    return BK_OK;
}

/* The counters a checkpoint carries, from its stats group. */
static herr_t read_stats(hid_t group, bk_run_stats *stats)
{
    hid_t g = H5Gopen2(group, "stats", H5P_DEFAULT);
    if (g < 0)
        return -1;
    herr_t rc = 0;
    for (size_t i = 0; rc >= 0 && i < bk_run_stats_n_fields; ++i) {
        char *field = (char *)stats + bk_run_stats_fields[i].offset;
        if (bk_run_stats_fields[i].if_nonzero && H5Aexists(g, bk_run_stats_fields[i].name) <= 0)
            continue; /* written only when non-zero (stats arrive zeroed) */
        if (bk_run_stats_fields[i].is_long) {
            long long value = 0;
            rc = bk_h5_read_numeric_attr(g, bk_run_stats_fields[i].name, H5T_NATIVE_LLONG, &value);
            long as_long = (long)value;
            memcpy(field, &as_long, sizeof as_long);
        } else {
            rc = bk_h5_read_numeric_attr(g, bk_run_stats_fields[i].name, H5T_NATIVE_DOUBLE, field);
        }
    }
    char *method = bk_h5_read_string_attr(g, "method");
    if (method)
        snprintf(stats->method, sizeof stats->method, "%s", method);
    free(method);
    CLOSE_IDS(rc, g);
    return rc;
}

/* A dataset transfer that skips Fletcher32 checks; H5P_DEFAULT-like otherwise. */
hid_t bk_h5_unchecked_xfer(void)
{
    hid_t dxpl = H5Pcreate(H5P_DATASET_XFER);
    if (dxpl >= 0 && H5Pset_edc_check(dxpl, H5Z_DISABLE_EDC) < 0) {
        CLOSE_IDS(-1, dxpl);
        return H5I_INVALID_HID;
    }
    return dxpl;
}

/* Rows [start, start + count) of a dataset, reading a chunk whose checksum fails as it is;
 * *unchecked (may be NULL) tells whether that was needed.  Only for the chunk at a
 * checkpoint's last row: a run killed while appending to that chunk may have left it half
 * rewritten, and both versions hold the same bytes in the rows up to the checkpoint, so those
 * rows are intact even though the chunk's checksum is not. */
herr_t bk_h5_read_rows_lenient(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t cols,
                               hid_t mem_type, void *buf, int *unchecked)
{
    if (unchecked)
        *unchecked = 0;
    if (bk_h5_read_block_xfer(dset, rank, start, count, 0, cols, mem_type, buf, H5P_DEFAULT) >= 0)
        return 0;
    if (unchecked)
        *unchecked = 1;
    hid_t dxpl = bk_h5_unchecked_xfer();
    herr_t rc = dxpl < 0 ? -1 : bk_h5_read_block_xfer(dset, rank, start, count, 0, cols, mem_type, buf, dxpl);
    CLOSE_IDS(rc, dxpl);
    return rc;
}

/* Length of a dataset's first dimension; -1 when it cannot be read. */
static long long leading_dim(hid_t dset)
{
    hid_t space = H5Dget_space(dset);
    hsize_t dims[2] = {0, 0};
    int rank = space < 0 ? -1 : H5Sget_simple_extent_dims(space, dims, NULL);
    CLOSE_IDS(rank, space);
    return rank < 1 ? -1 : (long long)dims[0];
}

/* The checkpoint agrees with the datasets: the rows it counts are there and the last of them
 * is the row it records.  Returns 0, or -1 with why filled. */
static int slot_matches_data(hid_t file, const bk_checkpoint *cp, const bk_checkpoint_record *rec,
                             char *why, size_t why_len)
{
    hid_t time = H5Lexists(file, "time", H5P_DEFAULT) > 0 ? H5Dopen2(file, "time", H5P_DEFAULT)
                                                          : H5I_INVALID_HID;
    long long rows = time < 0 ? -1 : leading_dim(time);
    double t = NAN;
    int rc = 0;
    if (rows < 0) {
        snprintf(why, why_len, "/time cannot be read");
        rc = -1;
    } else if (rows < rec->rows) {
        snprintf(why, why_len, "records %lld rows, /time has %lld", rec->rows, rows);
        rc = -1;
    } else if (rec->rows > 0 &&
               (bk_h5_read_rows_lenient(time, 1, (hsize_t)(rec->rows - 1), 1, 1, H5T_NATIVE_DOUBLE, &t, NULL) < 0 ||
                t != cp->t_last_row)) {
        snprintf(why, why_len, "its last row is at t = %.17g s, /time[%lld] = %.17g s",
                 cp->t_last_row, rec->rows - 1, t);
        rc = -1;
    }
    bk_h5_close_id(time);
    if (rc == 0 && cp->catalog && cp->catalog->events > 0) {
        hid_t events = H5Lexists(file, "events", H5P_DEFAULT) > 0 ? H5Dopen2(file, "events", H5P_DEFAULT)
                                                                : H5I_INVALID_HID;
        long long count = events < 0 ? -1 : leading_dim(events);
        bk_h5_close_id(events);
        if (count < cp->catalog->events) {
            snprintf(why, why_len, "records %ld events, /events has %lld", cp->catalog->events,
                     count < 0 ? 0 : count);
            rc = -1;
        }
    }
    if (rc < 0 || rec->transition_rows == 0)
        return rc;
    hid_t table = H5Lexists(file, "transitions", H5P_DEFAULT) > 0
                      ? H5Dopen2(file, "transitions", H5P_DEFAULT)
                      : H5I_INVALID_HID;
    hid_t mem = table < 0 ? H5I_INVALID_HID : bk_h5_transition_type(BK_H5_RECORD_STRUCT);
    long long count = mem < 0 ? -1 : leading_dim(table);
    bk_transition last;
    last.t = NAN;
    if (count < rec->transition_rows) {
        snprintf(why, why_len, "records %lld transitions, /transitions has %lld",
                 rec->transition_rows, count < 0 ? 0 : count);
        rc = -1;
    } else if (bk_h5_read_rows_lenient(table, 1, (hsize_t)(rec->transition_rows - 1), 1, 1, mem, &last, NULL) < 0 ||
               last.t != rec->last_transition_t) {
        snprintf(why, why_len, "its last transition is at t = %.17g s, /transitions[%lld] at %.17g s",
                 rec->last_transition_t, rec->transition_rows - 1, last.t);
        rc = -1;
    }
    CLOSE_IDS(0, mem, table);
    return rc;
}

/* Read one slot of /checkpoint into cp (allocated here; freed again unless BK_OK) and check
 * it: its block count, its checksum and its agreement with the datasets.  BK_OK;
 * BK_ERR_NOMEM; BK_ERR_INVALID for a slot never written; SLOT_TORN for one whose own
 * contents do not hold together (a write cut short); or BK_ERR_DAMAGED (it disagrees with the
 * data); why filled (no path: the caller adds it). */
#define SLOT_TORN 1
static int read_slot(hid_t file, hid_t top, const char *name, size_t n_blocks,
                     bk_checkpoint *cp, bk_checkpoint_record *rec, char *why, size_t why_len)
{
    memset(cp, 0, sizeof *cp);
    memset(rec, 0, sizeof *rec);
    if (H5Lexists(top, name, H5P_DEFAULT) <= 0) {
        snprintf(why, why_len, "not written");
        return BK_ERR_INVALID;
    }
    hid_t group = H5Gopen2(top, name, H5P_DEFAULT);
    long long nb = -1, ns = -1;
    if (group < 0 || bk_h5_read_numeric_attr(group, "n_blocks", H5T_NATIVE_LLONG, &nb) < 0 ||
        bk_h5_read_numeric_attr(group, "n_state", H5T_NATIVE_LLONG, &ns) < 0) {
        CLOSE_IDS(-1, group);
        snprintf(why, why_len, "cannot be read (written only in part)");
        return SLOT_TORN;
    }
    /* The counts size the arrays, so they are checked before the checksum can be. */
    if (nb != (long long)n_blocks || ns < 0 || ns > (long long)(SIZE_MAX / 64)) {
        CLOSE_IDS(0, group);
        snprintf(why, why_len, "holds %lld blocks and %lld friction states, the run %zu blocks", nb, ns,
                 n_blocks);
        return BK_ERR_DAMAGED;
    }
    if (bk_checkpoint_alloc(cp, n_blocks, (size_t)ns) != BK_OK) {
        CLOSE_IDS(0, group);
        snprintf(why, why_len, "out of memory");
        return BK_ERR_NOMEM;
    }
    /* Slots written before catalogs have no "catalog" attribute, and none. */
    long long has_catalog = 0;
    if (H5Aexists(group, "catalog") > 0 &&
        bk_h5_read_numeric_attr(group, "catalog", H5T_NATIVE_LLONG, &has_catalog) < 0)
        has_catalog = -1;
    if (has_catalog == 1 && bk_checkpoint_alloc_catalog(cp) != BK_OK) {
        CLOSE_IDS(0, group);
        snprintf(why, why_len, "out of memory");
        return BK_ERR_NOMEM;
    }
    herr_t ok = has_catalog == 0 || has_catalog == 1 ? 0 : -1;
    for (size_t k = 0; ok >= 0 && k < bk_checkpoint_n_fields; ++k) {
        const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
        int present = f->extent == BK_CHECKPOINT_VARIABLE
                          ? bk_checkpoint_field_present(f, cp) && H5Lexists(group, f->name, H5P_DEFAULT) > 0
                      : f->if_nonzero ? H5Aexists(group, f->name) > 0
                                      : bk_checkpoint_field_present(f, cp);
        if (present)
            ok = get_field(group, f, cp);
    }
    uint64_t stored = 0;
    if (ok >= 0)
        ok = bk_h5_read_numeric_attr(group, "rows", H5T_NATIVE_LLONG, &rec->rows);
    if (ok >= 0)
        ok = bk_h5_read_numeric_attr(group, "transition_rows", H5T_NATIVE_LLONG, &rec->transition_rows);
    if (ok >= 0)
        ok = bk_h5_read_numeric_attr(group, "last_transition_t", H5T_NATIVE_DOUBLE, &rec->last_transition_t);
    if (ok >= 0)
        ok = bk_h5_read_numeric_attr(group, "sequence", H5T_NATIVE_LLONG, &rec->sequence);
    if (ok >= 0)
        ok = read_stats(group, &cp->stats);
    if (ok >= 0)
        ok = bk_h5_read_numeric_attr(group, "checksum", H5T_NATIVE_UINT64, &stored);
    CLOSE_IDS(ok, group);
    int rc = BK_OK;
    if (ok < 0) {
        snprintf(why, why_len, "cannot be read (written only in part)");
        rc = SLOT_TORN;
    } else if (bk_checkpoint_hash(cp, rec) != stored) {
        snprintf(why, why_len, "checksum mismatch (written only in part, or altered)");
        rc = SLOT_TORN;
    } else if (rec->rows < 0 || rec->transition_rows < 0 ||
               slot_matches_data(file, cp, rec, why, why_len) < 0) {
        if (rec->rows < 0 || rec->transition_rows < 0)
            snprintf(why, why_len, "negative row counts");
        rc = BK_ERR_DAMAGED;
    }
    if (rc != BK_OK)
        bk_checkpoint_free(cp);
    return rc;
}

int bk_h5_find_checkpoint(hid_t file, const char *path, size_t n_blocks, bk_h5_slot *slot,
                          bk_error *err)
{
    memset(slot, 0, sizeof *slot);
    if (H5Lexists(file, "checkpoint", H5P_DEFAULT) <= 0)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: no checkpoint to restart from (a run writes its first "
                       "once [output] checkpoint_wall_interval has passed, %g s by default, unless "
                       "checkpoint_interval = 0)", path, BK_CHECKPOINT_WALL_INTERVAL);
    hid_t top = H5Gopen2(file, "checkpoint", H5P_DEFAULT);
    if (top < 0)
        return H5_DAMAGED(err, "%s: damaged: /checkpoint cannot be opened", path);
    if (H5Lexists(top, "x", H5P_DEFAULT) > 0) {
        slot->legacy = 1;
        bk_h5_close_id(top);
        return BK_FAIL(err, BK_ERR_DAMAGED,
                       "%s: /checkpoint was written by an older bksim without a consistency "
                       "record, so it cannot be verified; not restarting from it (run again "
                       "from the start)", path);
    }
    bk_checkpoint found[2];
    bk_checkpoint_record recs[2];
    char why[2][200];
    int status[2];
    for (int k = 0; k < 2; ++k)
        status[k] = read_slot(file, top, SLOT_NAMES[k], n_blocks, &found[k], &recs[k], why[k],
                              sizeof why[k]);
    bk_h5_close_id(top);
    int best = -1;
    for (int k = 0; k < 2; ++k)
        if (status[k] == BK_OK && (best < 0 || recs[k].sequence > recs[best].sequence))
            best = k;
    for (int k = 0; k < 2; ++k)
        if (k != best && status[k] == BK_OK)
            bk_checkpoint_free(&found[k]);
    if (best < 0) {
        if (status[0] == BK_ERR_NOMEM || status[1] == BK_ERR_NOMEM)
            return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory reading /checkpoint", path);
        /* One slot never written, the other cut short: the run was stopped while writing
         * its first checkpoint.  The data are fine; there is just no restart point yet. */
        if ((status[0] == BK_ERR_INVALID || status[1] == BK_ERR_INVALID) &&
            status[0] != BK_ERR_DAMAGED && status[1] != BK_ERR_DAMAGED)
            return BK_FAIL(err, BK_ERR_INVALID,
                           "%s: no complete checkpoint to restart from (the run stopped while "
                           "writing its first one: /checkpoint/a: %s; /checkpoint/b: %s)",
                           path, why[0], why[1]);
        return BK_FAIL(err, BK_ERR_DAMAGED,
                       "%s: damaged: no checkpoint verifies, so a restart would continue from "
                       "an inconsistent state (/checkpoint/a: %s; /checkpoint/b: %s)",
                       path, why[0], why[1]);
    }
    slot->checkpoint = found[best];
    slot->record = recs[best];
    slot->index = best;
    return BK_OK;
}
