/* HDF5 output: the streaming writer (a bk_sink that buffers a chunk's worth of rows and
 * appends them to extendable datasets of "<path>.part", renamed to <path> once the run is
 * complete) and the readers behind `bksim info` and `bksim export`.  The file layout is
 * described in include/bksim/output.h.
 *
 * Failures are reported through bk_error only: HDF5's automatic error printing is switched
 * off at every entry point, and the innermost message of HDF5's error stack is appended to
 * ours because it usually names the real cause (errno text, "file is truncated", ...). */
#include "bksim/output.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <hdf5.h>

#include "bksim/bksim.h"
#include "output/layout.h"

/* Rows buffered in memory before an append; also the row count of a 2-D chunk.  A chunk
 * of a T x N dataset is capped at CHUNK_BYTES so wide chains keep chunks (and the buffers,
 * one chunk per dataset) bounded. */
#define MAX_BUFFER_ROWS 512u
#define CHUNK_BYTES (1u << 20)
/* 1-D series are tiny per row; longer chunks keep the chunk index small on long runs.
 * Appends of fewer rows go through the per-dataset chunk cache (1 MiB by default). */
#define SERIES_1D_CHUNK 4096u
#define TRANSITION_BUFFER 512u
/* Shuffle + deflate at this level; 0 writes unfiltered chunks.  Off because it costs more
 * than it saves when output is dense: on stick-slip-like data level 1 shrank files to
 * ~0.35 of raw but cut write throughput from ~300-600 MB/s to ~40-95 MB/s (about 3.5 us
 * per row at N = 3 with 512-row chunks, 30 us per row at N = 100), the same order as the
 * integration itself.  `h5repack -f SHUF -f GZIP=1` compresses a finished file. */
#define DEFLATE_LEVEL 0u
/* Doubles held in memory per block of rows while exporting. */
#define EXPORT_BUDGET (1u << 20)

#define DETAIL_LEN 256

/* ---------------------------------------------------------------- error plumbing --- */

/* HDF5's file-driver messages carry timestamps, descriptors and buffer addresses; of
 * those only the operation and the system's error text help the user. */
static void condense(const char *desc, char *out, size_t len)
{
    const char *marker = "error message = '";
    const char *text = strstr(desc, marker);
    if (text) {
        text += strlen(marker);
        const char *text_end = strchr(text, '\'');
        const char *colon = strchr(desc, ':');
        int op_len = colon && colon < text ? (int)(colon - desc) : 0;
        int text_len = text_end ? (int)(text_end - text) : (int)strlen(text);
        if (op_len > 0)
            snprintf(out, len, "%.*s: %.*s", op_len, desc, text_len, text);
        else
            snprintf(out, len, "%.*s", text_len, text);
    } else {
        snprintf(out, len, "%s", desc);
    }
    for (char *p = out; *p; ++p)
        if (*p == '\n')
            *p = ' ';
}

static herr_t innermost_error(unsigned n, const H5E_error2_t *e, void *data)
{
    char *detail = data;
    (void)n;
    if (detail[0] == '\0' && e->desc && e->desc[0])
        condense(e->desc, detail, DETAIL_LEN);
    return 0;
}

/* Our message plus the most specific description on HDF5's error stack, which must still
 * hold the failure: call this before any further HDF5 call (closing ids clears it). */
static int h5_fail(bk_error *err, int status, const char *file, int line, const char *func,
                   const char *fmt, ...) __attribute__((format(printf, 6, 7)));
static int h5_fail(bk_error *err, int status, const char *file, int line, const char *func,
                   const char *fmt, ...)
{
    char detail[DETAIL_LEN] = "";
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost_error, detail);
    char message[BK_ERROR_MESSAGE_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    if (detail[0])
        return bk_error_set(err, status, file, line, func, "%s (HDF5: %s)", message, detail);
    return bk_error_set(err, status, file, line, func, "%s", message);
}

#define H5_FAIL(err, ...) h5_fail((err), BK_ERR_HDF5, __FILE__, __LINE__, __func__, __VA_ARGS__)
/* A read that failed inside a file that opened: the file is damaged (a Fletcher32 checksum
 * mismatch lands here), and HDF5's reason is kept. */
#define H5_DAMAGED(err, ...) \
    h5_fail((err), BK_ERR_DAMAGED, __FILE__, __LINE__, __func__, __VA_ARGS__)

static void close_id(hid_t id)
{
    if (id < 0)
        return;
    switch (H5Iget_type(id)) {
    case H5I_FILE:
        H5Fclose(id);
        break;
    case H5I_GROUP:
        H5Gclose(id);
        break;
    case H5I_DATASET:
        H5Dclose(id);
        break;
    case H5I_ATTR:
        H5Aclose(id);
        break;
    case H5I_DATATYPE:
        H5Tclose(id);
        break;
    case H5I_DATASPACE:
        H5Sclose(id);
        break;
    case H5I_GENPROP_LST:
        H5Pclose(id);
        break;
    default:
        break;
    }
}

/* Close ids after a helper finished.  Closing clears HDF5's error stack, so after a failure
 * the stack is saved first and restored, leaving it for h5_fail in the caller. */
static void close_ids(int failed, const hid_t *ids, size_t n)
{
    hid_t stack = failed ? H5Eget_current_stack() : H5I_INVALID_HID;
    for (size_t i = 0; i < n; ++i)
        close_id(ids[i]);
    if (stack >= 0)
        H5Eset_current_stack(stack);
}

#define CLOSE_IDS(status, ...)                                  \
    close_ids((status) < 0, (const hid_t[]){__VA_ARGS__},      \
              sizeof((const hid_t[]){__VA_ARGS__}) / sizeof(hid_t))

/* H5Fis_hdf5 is deprecated from HDF5 1.12 on. */
static htri_t has_hdf5_signature(const char *path)
{
#if H5_VERSION_GE(1, 12, 0)
    return H5Fis_accessible(path, H5P_DEFAULT);
#else
    return H5Fis_hdf5(path);
#endif
}

/* ------------------------------------------------------------------ attributes --- */

/* Create or overwrite a scalar attribute. */
static herr_t write_attr(hid_t obj, const char *name, hid_t file_type, hid_t mem_type,
                         const void *value)
{
    hid_t space = H5I_INVALID_HID, attr = H5I_INVALID_HID;
    herr_t rc = -1;
    htri_t exists = H5Aexists(obj, name);
    if (exists < 0)
        goto done;
    if (exists) {
        attr = H5Aopen(obj, name, H5P_DEFAULT);
    } else {
        space = H5Screate(H5S_SCALAR);
        if (space < 0)
            goto done;
        attr = H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT);
    }
    if (attr < 0)
        goto done;
    rc = H5Awrite(attr, mem_type, value);
done:
    CLOSE_IDS(rc, attr, space);
    return rc;
}

/* Variable-length UTF-8 strings: no size limit (the config text can be long), and h5py
 * reads them as str. */
static hid_t vlen_string_type(void)
{
    hid_t type = H5Tcopy(H5T_C_S1);
    if (type < 0)
        return type;
    if (H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0) {
        CLOSE_IDS(-1, type);
        return H5I_INVALID_HID;
    }
    return type;
}

static herr_t write_string_attr(hid_t obj, const char *name, const char *value)
{
    const char *text = value ? value : "";
    hid_t type = vlen_string_type();
    herr_t rc = type < 0 ? -1 : write_attr(obj, name, type, type, &text);
    CLOSE_IDS(rc, type);
    return rc;
}

/* A fixed-length UTF-8 string attribute, created or replaced.  Every string written after
 * the file is created is one of these: a variable-length string lives in HDF5's global
 * heap, and a kill while a rewrite of the heap is flushed can leave it in a state that
 * HDF5 1.10 reads in an endless loop (seen with the checkpoint's method string, rewritten at
 * every checkpoint: `bksim info` hung).  Fixed-length text sits in the attribute itself,
 * inside the object header, so after the first flush the heap is never written again. */
static herr_t write_fixed_string_attr(hid_t obj, const char *name, const char *value)
{
    const char *text = value ? value : "";
    size_t len = strlen(text);
    hid_t type = H5Tcopy(H5T_C_S1);
    herr_t rc = type < 0 || H5Tset_size(type, len ? len : 1) < 0 ||
                        H5Tset_cset(type, H5T_CSET_UTF8) < 0 ||
                        H5Tset_strpad(type, H5T_STR_NULLPAD) < 0
                    ? -1
                    : 0;
    htri_t exists = rc < 0 ? -1 : H5Aexists(obj, name);
    if (exists < 0)
        rc = -1;
    if (exists > 0) {
        /* Another length (or a variable-length attribute of an older file): replace it. */
        hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
        hid_t old = attr < 0 ? H5I_INVALID_HID : H5Aget_type(attr);
        int same = old >= 0 && H5Tequal(old, type) > 0;
        CLOSE_IDS(0, old, attr);
        if (!same && H5Adelete(obj, name) < 0)
            rc = -1;
    }
    if (rc >= 0)
        rc = write_attr(obj, name, type, type, text);
    CLOSE_IDS(rc, type);
    return rc;
}

static herr_t write_double_attr(hid_t obj, const char *name, double value)
{
    return write_attr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

static herr_t write_int_attr(hid_t obj, const char *name, int value)
{
    return write_attr(obj, name, H5T_STD_I32LE, H5T_NATIVE_INT, &value);
}

static herr_t write_long_attr(hid_t obj, const char *name, long long value)
{
    return write_attr(obj, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, &value);
}

/* A string attribute written as variable- or fixed-length; NULL when absent or not a
 * scalar string.  Malloc'ed. */
static char *read_string_attr(hid_t obj, const char *name)
{
    hid_t attr = H5I_INVALID_HID, type = H5I_INVALID_HID, space = H5I_INVALID_HID;
    hid_t mem = H5I_INVALID_HID;
    char *result = NULL;
    if (H5Aexists(obj, name) <= 0)
        return NULL;
    attr = H5Aopen(obj, name, H5P_DEFAULT);
    if (attr < 0)
        goto done;
    type = H5Aget_type(attr);
    space = H5Aget_space(attr);
    if (type < 0 || space < 0 || H5Tget_class(type) != H5T_STRING ||
        H5Sget_simple_extent_npoints(space) != 1)
        goto done;
    htri_t variable = H5Tis_variable_str(type);
    if (variable > 0) {
        mem = vlen_string_type();
        char *text = NULL;
        if (mem >= 0 && H5Aread(attr, mem, &text) >= 0 && text) {
            result = strdup(text);
            H5free_memory(text);
        }
    } else if (variable == 0) {
        size_t size = H5Tget_size(type);
        result = size > 0 ? calloc(size + 1, 1) : NULL;
        if (result && H5Aread(attr, type, result) < 0) {
            free(result);
            result = NULL;
        }
    }
done:
    CLOSE_IDS(result ? 0 : -1, mem, space, type, attr);
    return result;
}

/* A numeric scalar attribute converted to the native type mem_type; -1 when absent. */
static herr_t read_numeric_attr(hid_t obj, const char *name, hid_t mem_type, void *value)
{
    hid_t attr = H5I_INVALID_HID, type = H5I_INVALID_HID, space = H5I_INVALID_HID;
    herr_t rc = -1;
    if (H5Aexists(obj, name) <= 0)
        return -1;
    attr = H5Aopen(obj, name, H5P_DEFAULT);
    if (attr < 0)
        goto done;
    type = H5Aget_type(attr);
    space = H5Aget_space(attr);
    if (type < 0 || space < 0 || H5Sget_simple_extent_npoints(space) != 1)
        goto done;
    H5T_class_t cls = H5Tget_class(type);
    if (cls != H5T_INTEGER && cls != H5T_FLOAT)
        goto done;
    rc = H5Aread(attr, mem_type, value);
done:
    CLOSE_IDS(rc, space, type, attr);
    return rc;
}

/* --------------------------------------------------------------------- layout --- */

static hid_t kind_file_type(bk_series_kind kind)
{
    switch (kind) {
    case BK_KIND_U8:
        return H5T_STD_U8LE;
    case BK_KIND_I8:
        return H5T_STD_I8LE;
    case BK_KIND_F64:
        break;
    }
    return H5T_IEEE_F64LE;
}

static hid_t kind_mem_type(bk_series_kind kind)
{
    switch (kind) {
    case BK_KIND_U8:
        return H5T_NATIVE_UINT8;
    case BK_KIND_I8:
        return H5T_NATIVE_INT8;
    case BK_KIND_F64:
        break;
    }
    return H5T_NATIVE_DOUBLE;
}

typedef struct stat_def {
    const char *name;
    int is_long; /* long, else double */
    size_t offset;
    const char *units;
} stat_def;

#define STAT_L(field, units) {#field, 1, offsetof(bk_run_stats, field), units}
#define STAT_D(field, units) {#field, 0, offsetof(bk_run_stats, field), units}
static const stat_def STATS[] = {
    STAT_L(steps, "1"),          STAT_L(rhs_evals, "1"),
    STAT_L(root_evals, "1"),     STAT_L(err_test_fails, "1"),
    STAT_L(nonlin_iters, "1"),   STAT_L(integrator_starts, "1"),
    STAT_L(stuck_jumps, "1"),    STAT_L(transitions, "1"),
    STAT_L(rows, "1"),           STAT_D(t_reached, "s"),
    STAT_D(wall_time, "s"),      STAT_D(cpu_time, "s"),
    STAT_D(work_driver, "J"),    STAT_D(dissipation, "J"),
    STAT_D(elastic_change, "J"), STAT_D(kinetic_change, "J"),
    STAT_D(energy_residual, "1"),
};
#undef STAT_L
#undef STAT_D
#define N_STATS (sizeof STATS / sizeof STATS[0])

/* The transition record in memory (bk_transition) and on disk (packed little-endian). */
static hid_t transition_type(int on_disk)
{
    hid_t type = H5Tcreate(H5T_COMPOUND, on_disk ? 38 : sizeof(bk_transition));
    if (type < 0)
        return type;
    herr_t rc;
    if (on_disk)
        rc = (H5Tinsert(type, "t", 0, H5T_IEEE_F64LE) < 0 ||
              H5Tinsert(type, "block", 8, H5T_STD_I32LE) < 0 ||
              H5Tinsert(type, "from", 12, H5T_STD_I8LE) < 0 ||
              H5Tinsert(type, "to", 13, H5T_STD_I8LE) < 0 ||
              H5Tinsert(type, "x", 14, H5T_IEEE_F64LE) < 0 ||
              H5Tinsert(type, "v", 22, H5T_IEEE_F64LE) < 0 ||
              H5Tinsert(type, "force", 30, H5T_IEEE_F64LE) < 0)
                 ? -1
                 : 0;
    else
        rc = (H5Tinsert(type, "t", offsetof(bk_transition, t), H5T_NATIVE_DOUBLE) < 0 ||
              H5Tinsert(type, "block", offsetof(bk_transition, block), H5T_NATIVE_INT32) < 0 ||
              H5Tinsert(type, "from", offsetof(bk_transition, from), H5T_NATIVE_INT8) < 0 ||
              H5Tinsert(type, "to", offsetof(bk_transition, to), H5T_NATIVE_INT8) < 0 ||
              H5Tinsert(type, "x", offsetof(bk_transition, x), H5T_NATIVE_DOUBLE) < 0 ||
              H5Tinsert(type, "v", offsetof(bk_transition, v), H5T_NATIVE_DOUBLE) < 0 ||
              H5Tinsert(type, "force", offsetof(bk_transition, force), H5T_NATIVE_DOUBLE) < 0)
                 ? -1
                 : 0;
    if (rc < 0) {
        CLOSE_IDS(-1, type);
        return H5I_INVALID_HID;
    }
    return type;
}

/* ---------------------------------------------------------------------- writer --- */

typedef struct series {
    hid_t dset;          /* H5I_INVALID_HID when the field is not written */
    int rank;            /* 1 for T, 2 for T x N and T x S */
    size_t cols;         /* values per row */
    size_t elem;         /* bytes per value in memory */
    unsigned char *buf;  /* buffer_rows x cols values */
} series;

struct bk_h5_writer {
    char *path;
    char *part;
    hid_t file;
    size_t n_blocks;
    series s[BK_N_SERIES];
    size_t buffer_rows;
    size_t buffered;
    hsize_t rows_written;
    double t_buffered;   /* time of the last row handed to the sink */
    double t_written;    /* time of the last row on disk */
    hid_t trans_dset;
    hid_t trans_mem;
    bk_transition *trans_buf;
    size_t trans_buffered;
    hsize_t trans_written;
    double trans_last_t; /* t of the last transition on disk */
    long long cp_sequence; /* of the last checkpoint written (0: none) */
    int cp_slot;         /* slot of /checkpoint the next checkpoint goes to */
    int failed;          /* a write failed: rows on disk may be ragged, accept no more */
};

/* mkdir -p for the directory part of path. */
static int make_parent_dirs(const char *path, bk_error *err)
{
    char *dir = strdup(path);
    if (!dir)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    int rc = BK_OK;
    char *slash = strrchr(dir, '/');
    if (slash && slash != dir) {
        *slash = '\0';
        for (char *p = dir + 1;; ++p) {
            if (*p != '/' && *p != '\0')
                continue;
            char saved = *p;
            *p = '\0';
            if (mkdir(dir, 0777) != 0) {
                /* EEXIST is not the only harmless failure: an existing directory may also
                 * answer EACCES or EROFS, so ask what is there. */
                int e = errno;
                struct stat st;
                if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
                    rc = e == EEXIST
                             ? BK_FAIL(err, BK_ERR_IO,
                                       "%s: cannot create directory %s: exists and is not a "
                                       "directory", path, dir)
                             : BK_FAIL(err, BK_ERR_IO, "%s: cannot create directory %s: %s",
                                       path, dir, strerror(e));
                    break;
                }
            }
            *p = saved;
            if (saved == '\0')
                break;
        }
    }
    free(dir);
    return rc;
}

static hid_t create_extendable(hid_t file, const char *name, hid_t type, int rank,
                               hsize_t cols, hsize_t chunk_rows)
{
    hsize_t dims[2] = {0, cols};
    hsize_t max_dims[2] = {H5S_UNLIMITED, cols};
    hsize_t chunk[2] = {chunk_rows, cols};
    hid_t space = H5I_INVALID_HID, dcpl = H5I_INVALID_HID, dset = H5I_INVALID_HID;
    space = H5Screate_simple(rank, dims, max_dims);
    dcpl = H5Pcreate(H5P_DATASET_CREATE);
    if (space < 0 || dcpl < 0 || H5Pset_chunk(dcpl, rank, chunk) < 0)
        goto done;
    if (DEFLATE_LEVEL > 0 && H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0 &&
        (H5Pset_shuffle(dcpl) < 0 || H5Pset_deflate(dcpl, DEFLATE_LEVEL) < 0))
        goto done;
    /* A checksum per chunk: bytes damaged on disk make the read fail instead of returning
     * plausible numbers, and `bksim info` reads every chunk. */
    if (H5Pset_fletcher32(dcpl) < 0)
        goto done;
    dset = H5Dcreate2(file, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
done:
    CLOSE_IDS(dset, dcpl, space);
    return dset;
}

static herr_t describe(hid_t obj, const char *units, const char *description)
{
    if (write_string_attr(obj, "units", units) < 0)
        return -1;
    return write_string_attr(obj, "description", description);
}

/* The same for objects written after the file was created (see write_fixed_string_attr). */
static herr_t describe_fixed(hid_t obj, const char *units, const char *description)
{
    if (write_fixed_string_attr(obj, "units", units) < 0)
        return -1;
    return write_fixed_string_attr(obj, "description", description);
}

/* Which block each friction-state column belongs to (-1 when no block claims it). */
static herr_t write_state_blocks(hid_t dset, const bk_model *model)
{
    size_t n_state = model->n_friction_state;
    int32_t *blocks = malloc(n_state * sizeof *blocks);
    if (!blocks)
        return -1;
    for (size_t c = 0; c < n_state; ++c)
        blocks[c] = -1;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        const bk_block *b = &model->blocks[i];
        size_t n = b->law ? b->law->n_state : 0;
        for (size_t k = 0; k < n && b->state_offset + k < n_state; ++k)
            blocks[b->state_offset + k] = (int32_t)i;
    }
    hsize_t dims[1] = {n_state};
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t attr = space < 0 ? H5I_INVALID_HID
                           : H5Acreate2(dset, "block", H5T_STD_I32LE, space, H5P_DEFAULT,
                                        H5P_DEFAULT);
    herr_t rc = attr < 0 ? -1 : H5Awrite(attr, H5T_NATIVE_INT32, blocks);
    CLOSE_IDS(rc, attr, space);
    free(blocks);
    return rc;
}

static int create_layout(bk_h5_writer *w, const bk_config *config, bk_error *err)
{
    const bk_model *model = config->model;
    size_t n_state = model->n_friction_state;
    unsigned fields = config->output.fields;
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    /* Tracking link creation order lets readers list datasets in the order written here. */
    if (fcpl < 0 ||
        H5Pset_link_creation_order(fcpl, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED) < 0) {
        int rc = H5_FAIL(err, "%s: cannot set up file creation properties", w->part);
        CLOSE_IDS(-1, fcpl);
        return rc;
    }
    w->file = H5Fcreate(w->part, H5F_ACC_TRUNC, fcpl, H5P_DEFAULT);
    if (w->file < 0) {
        int rc = H5_FAIL(err, "%s: cannot create file", w->part);
        CLOSE_IDS(-1, fcpl);
        return rc;
    }
    CLOSE_IDS(0, fcpl);

    if (write_string_attr(w->file, "config", config->text) < 0 ||
        write_string_attr(w->file, "config_name", config->source_name) < 0 ||
        write_string_attr(w->file, "version", BKSIM_VERSION) < 0 ||
        write_long_attr(w->file, "n_blocks", (long long)model->n_blocks) < 0 ||
        write_double_attr(w->file, "t_end", config->t_end) < 0 ||
        write_int_attr(w->file, "complete", 0) < 0 ||
        write_double_attr(w->file, "t_reached", 0.0) < 0 ||
        write_string_attr(w->file, "attribute_units", "t_end: s, t_reached: s") < 0)
        return H5_FAIL(err, "%s: cannot write root attributes", w->part);
    /* What a restart needs to load the same config again: the file as read and the --set
     * overrides (the `config` attribute shows them only as comments). */
    size_t len = 1;
    for (size_t k = 0; k < config->n_overrides; ++k)
        len += strlen(config->overrides[k]) + 1;
    char *overrides = calloc(len, 1);
    if (!overrides)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", w->part);
    for (size_t k = 0; k < config->n_overrides; ++k) {
        strcat(overrides, config->overrides[k]);
        strcat(overrides, "\n");
    }
    herr_t stored = write_string_attr(w->file, "config_file", config->file_text ? config->file_text : config->text);
    if (stored >= 0)
        stored = write_string_attr(w->file, "overrides", overrides);
    free(overrides);
    char names[BK_DATASET_LIST_LEN];
    bk_output_dataset_names(fields, n_state, config->output.transitions, names, sizeof names);
    if (stored >= 0)
        stored = write_string_attr(w->file, "datasets", names);
    if (stored < 0)
        return H5_FAIL(err, "%s: cannot write root attributes", w->part);

    size_t widest = model->n_blocks > n_state ? model->n_blocks : n_state;
    size_t rows = CHUNK_BYTES / (widest * sizeof(double));
    w->buffer_rows = rows < 1 ? 1 : rows > MAX_BUFFER_ROWS ? MAX_BUFFER_ROWS : rows;

    for (int i = 0; i < BK_N_SERIES; ++i) {
        const bk_series_def *def = &bk_series[i];
        series *s = &w->s[i];
        if (!bk_series_selected(def, fields, n_state))
            continue;
        s->rank = def->shape == BK_SHAPE_T ? 1 : 2;
        s->cols = def->shape == BK_SHAPE_T ? 1 : def->shape == BK_SHAPE_TN ? model->n_blocks : n_state;
        s->elem = bk_series_value_size(def->kind);
        s->buf = malloc(w->buffer_rows * s->cols * s->elem);
        if (!s->buf)
            return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for the /%s buffer", w->part,
                           def->name);
        hsize_t chunk_rows = s->rank == 1 ? SERIES_1D_CHUNK : (hsize_t)w->buffer_rows;
        s->dset = create_extendable(w->file, def->name, kind_file_type(def->kind), s->rank,
                                    (hsize_t)s->cols, chunk_rows);
        if (s->dset < 0)
            return H5_FAIL(err, "%s: cannot create dataset /%s", w->part, def->name);
        if (describe(s->dset, def->units, def->description) < 0)
            return H5_FAIL(err, "%s: cannot write attributes of /%s", w->part, def->name);
        if (i == BK_SERIES_STATE && write_state_blocks(s->dset, model) < 0)
            return H5_FAIL(err, "%s: cannot write attribute /friction_state/block", w->part);
    }

    if (config->output.transitions) {
        w->trans_buf = malloc(TRANSITION_BUFFER * sizeof *w->trans_buf);
        if (!w->trans_buf)
            return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for the transition buffer",
                           w->part);
        w->trans_mem = transition_type(0);
        hid_t disk = transition_type(1);
        if (w->trans_mem >= 0 && disk >= 0)
            w->trans_dset = create_extendable(w->file, "transitions", disk, 1, 1,
                                              TRANSITION_BUFFER);
        CLOSE_IDS(w->trans_dset, disk);
        if (w->trans_dset < 0)
            return H5_FAIL(err, "%s: cannot create dataset /transitions", w->part);
        if (describe(w->trans_dset, BK_TRANSITIONS_UNITS, BK_TRANSITIONS_DESCRIPTION) < 0)
            return H5_FAIL(err, "%s: cannot write attributes of /transitions", w->part);
    }
    /* The variable-length strings above go to disk now, once: nothing rewrites them later
     * (see write_fixed_string_attr). */
    if (H5Fflush(w->file, H5F_SCOPE_LOCAL) < 0)
        return H5_FAIL(err, "%s: cannot flush", w->part);
    return BK_OK;
}

/* Close every id the writer holds; -1 if any close failed.
 *
 * The file id goes first, while the datasets still hold the file open, so that H5Fclose
 * only drops the id and the real close (the final flush) happens in the last H5Dclose.
 * HDF5 1.10 keeps a file id whose close failed (disk full) pointing at freed memory and
 * crashes when H5close() tries it again at exit; H5Dclose always releases its id.  Write
 * errors are caught before this by an explicit H5Fflush. */
static herr_t close_writer(bk_h5_writer *w)
{
    herr_t rc = 0;
    if (w->file >= 0 && H5Fclose(w->file) < 0)
        rc = -1;
    for (int i = 0; i < BK_N_SERIES; ++i) {
        if (w->s[i].dset >= 0 && H5Dclose(w->s[i].dset) < 0)
            rc = -1;
        w->s[i].dset = H5I_INVALID_HID;
    }
    if (w->trans_dset >= 0 && H5Dclose(w->trans_dset) < 0)
        rc = -1;
    if (w->trans_mem >= 0 && H5Tclose(w->trans_mem) < 0)
        rc = -1;
    w->trans_dset = w->trans_mem = w->file = H5I_INVALID_HID;
    return rc;
}

static void free_writer(bk_h5_writer *w)
{
    for (int i = 0; i < BK_N_SERIES; ++i)
        free(w->s[i].buf);
    free(w->trans_buf);
    free(w->path);
    free(w->part);
    free(w);
}

int bk_h5_writer_open(bk_h5_writer **out, const bk_config *config, const char *path,
                      bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (out)
        *out = NULL;
    if (!out || !config || !config->model || config->model->n_blocks == 0 || !path || !*path)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "bk_h5_writer_open: needs a writer pointer, a config with a model and "
                       "an output path");
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return BK_FAIL(err, BK_ERR_IO, "%s: is a directory; give an output file name", path);

    bk_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    w->file = w->trans_dset = w->trans_mem = H5I_INVALID_HID;
    for (int i = 0; i < BK_N_SERIES; ++i)
        w->s[i].dset = H5I_INVALID_HID;
    w->n_blocks = config->model->n_blocks;
    w->path = strdup(path);
    w->part = malloc(strlen(path) + sizeof ".part");
    if (!w->path || !w->part) {
        free_writer(w);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    }
    sprintf(w->part, "%s.part", path);

    int rc = make_parent_dirs(path, err);
    if (rc != BK_OK) {
        free_writer(w);
        return rc;
    }
    rc = create_layout(w, config, err);
    if (rc != BK_OK) {
        int created = w->file >= 0;
        close_writer(w);
        if (created)
            remove(w->part);
        free_writer(w);
        return rc;
    }
    *out = w;
    return BK_OK;
}

/* Extend dset by count rows and write them from buf. */
static herr_t append(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t cols,
                     hid_t mem_type, const void *buf)
{
    hsize_t dims[2] = {start + count, cols};
    hsize_t offset[2] = {start, 0};
    hsize_t counts[2] = {count, cols};
    hid_t file_space = H5I_INVALID_HID, mem_space = H5I_INVALID_HID;
    herr_t rc = -1;
    if (H5Dset_extent(dset, dims) < 0)
        goto done;
    file_space = H5Dget_space(dset);
    if (file_space < 0 ||
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, offset, NULL, counts, NULL) < 0)
        goto done;
    mem_space = H5Screate_simple(rank, counts, NULL);
    if (mem_space < 0)
        goto done;
    rc = H5Dwrite(dset, mem_type, mem_space, file_space, H5P_DEFAULT, buf);
done:
    CLOSE_IDS(rc, mem_space, file_space);
    return rc;
}

static int flush_transitions(bk_h5_writer *w, bk_error *err)
{
    if (w->trans_buffered == 0)
        return BK_OK;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (append(w->trans_dset, 1, w->trans_written, (hsize_t)w->trans_buffered, 1, w->trans_mem,
               w->trans_buf) < 0) {
        w->failed = 1;
        return H5_FAIL(err, "%s: cannot append to /transitions", w->part);
    }
    w->trans_written += w->trans_buffered;
    w->trans_last_t = w->trans_buf[w->trans_buffered - 1].t;
    w->trans_buffered = 0;
    return BK_OK;
}

/* Write buffered rows and transitions, then flush HDF5's metadata so that a run killed
 * later still leaves a readable .part holding everything up to here. */
static int flush_all(bk_h5_writer *w, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (w->buffered > 0) {
        for (int i = 0; i < BK_N_SERIES; ++i) {
            series *s = &w->s[i];
            if (s->dset < 0)
                continue;
            if (append(s->dset, s->rank, w->rows_written, (hsize_t)w->buffered,
                       (hsize_t)s->cols, kind_mem_type(bk_series[i].kind), s->buf) < 0) {
                w->failed = 1;
                return H5_FAIL(err, "%s: cannot append rows to /%s", w->part, bk_series[i].name);
            }
        }
        w->rows_written += w->buffered;
        w->buffered = 0;
        w->t_written = w->t_buffered;
    }
    int rc = flush_transitions(w, err);
    if (rc != BK_OK)
        return rc;
    if (write_double_attr(w->file, "t_reached", w->t_written) < 0 ||
        H5Fflush(w->file, H5F_SCOPE_LOCAL) < 0) {
        w->failed = 1;
        return H5_FAIL(err, "%s: cannot flush", w->part);
    }
    return BK_OK;
}

static void put(series *s, size_t row, const void *values)
{
    if (s->dset >= 0)
        memcpy(s->buf + row * s->cols * s->elem, values, s->cols * s->elem);
}

static int sink_sample(void *self, const bk_sample *sample, bk_error *err)
{
    bk_h5_writer *w = self;
    if (w->failed)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: an earlier write failed; no more rows accepted",
                       w->part);
    if (sample->n_blocks != w->n_blocks)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: sample has %zu blocks, the file %zu",
                       w->part, sample->n_blocks, w->n_blocks);
    const void *arrays[BK_N_SERIES] = {
        [BK_SERIES_X] = sample->x,
        [BK_SERIES_V] = sample->v,
        [BK_SERIES_FRICTION] = sample->friction,
        [BK_SERIES_COF] = sample->cof,
        [BK_SERIES_MODE] = sample->mode,
        [BK_SERIES_STATE] = sample->friction_state,
    };
    /* Check before copying anything so a rejected sample leaves no partial row. */
    for (int i = 0; i < BK_N_SERIES; ++i)
        if (bk_series[i].shape != BK_SHAPE_T && w->s[i].dset >= 0 && !arrays[i])
            return BK_FAIL(err, BK_ERR_INVALID, "%s: sample lacks the values of /%s",
                           w->part, bk_series[i].name);
    size_t row = w->buffered;
    uint8_t event = sample->is_event ? 1 : 0;
    put(&w->s[BK_SERIES_TIME], row, &sample->t);
    put(&w->s[BK_SERIES_DRIVER], row, &sample->driver);
    put(&w->s[BK_SERIES_EVENT], row, &event);
    put(&w->s[BK_SERIES_EKIN], row, &sample->kinetic_energy);
    put(&w->s[BK_SERIES_EEL], row, &sample->elastic_energy);
    put(&w->s[BK_SERIES_WORK], row, &sample->work_driver);
    put(&w->s[BK_SERIES_DISS], row, &sample->dissipation);
    for (int i = 0; i < BK_N_SERIES; ++i)
        if (bk_series[i].shape != BK_SHAPE_T)
            put(&w->s[i], row, arrays[i]);
    w->buffered = row + 1;
    w->t_buffered = sample->t;
    return w->buffered == w->buffer_rows ? flush_all(w, err) : BK_OK;
}

static int sink_transition(void *self, const bk_transition *transition, bk_error *err)
{
    bk_h5_writer *w = self;
    if (w->failed)
        return BK_FAIL(err, BK_ERR_HDF5,
                       "%s: an earlier write failed; no more transitions accepted", w->part);
    if (transition->block < 0 || (size_t)transition->block >= w->n_blocks)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: transition of block %d, allowed 0..%zu",
                       w->part, (int)transition->block, w->n_blocks - 1);
    if (w->trans_dset < 0)
        return BK_OK;
    w->trans_buf[w->trans_buffered++] = *transition;
    return w->trans_buffered == TRANSITION_BUFFER ? flush_transitions(w, err) : BK_OK;
}

/* ------------------------------------------------------------------- checkpoints --- */

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
 * (see write_fixed_string_attr). */
static const char *const SLOT_NAMES[2] = {"a", "b"};

typedef struct checkpoint_record {
    long long sequence;        /* 1 for a run's first checkpoint */
    long long rows;            /* rows of every time series at the checkpoint */
    long long transition_rows;
    double last_transition_t;  /* s, t of /transitions[transition_rows - 1]; 0 without */
} checkpoint_record;

/* FNV-1a (64 bit) over values in little-endian byte order, so a file copied to a machine of
 * the other byte order still verifies. */
#define FNV_OFFSET UINT64_C(14695981039346656037)
#define FNV_PRIME UINT64_C(1099511628211)

static uint64_t hash_u64(uint64_t h, uint64_t v)
{
    for (unsigned k = 0; k < 8; ++k) {
        h ^= (v >> (8 * k)) & 0xffu;
        h *= FNV_PRIME;
    }
    return h;
}

static uint64_t hash_f64(uint64_t h, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    return hash_u64(h, bits);
}

static uint64_t hash_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i) {
        h ^= (uint64_t)p[i];
        h *= FNV_PRIME;
    }
    return h;
}

static herr_t write_stats(hid_t file, const bk_run_stats *stats);
static herr_t read_block_xfer(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t col,
                              hsize_t ncols, hid_t mem_type, void *buf, hid_t dxpl);

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

#define CHECKPOINT_ARRAYS(X)                                                               \
    X("mode", H5T_STD_I8LE, H5T_NATIVE_INT8, n, mode)                                       \
    X("x", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, x)                                         \
    X("v", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, v)                                         \
    X("friction_state", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, cp->n_state, state)              \
    X("t_switch", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, t_switch)                           \
    X("from_rest", H5T_STD_U8LE, H5T_NATIVE_UINT8, n, from_rest)                            \
    X("extremum_armed", H5T_STD_U8LE, H5T_NATIVE_UINT8, n, extremum_armed)                  \
    X("last_transition", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, last_transition)             \
    X("instant_count", H5T_STD_I64LE, H5T_NATIVE_LONG, n, instant_count)

#define CHECKPOINT_SCALARS(X)                                                              \
    X("t", t) X("work_driver", work_driver) X("dissipation", dissipation)                  \
    X("elastic_initial", elastic_initial) X("kinetic_initial", kinetic_initial)            \
    X("t_last_row", t_last_row)

/* Everything a restart reads from a slot, and where the datasets stood. */
static uint64_t checkpoint_hash(const bk_checkpoint *cp, const checkpoint_record *rec)
{
    size_t n = cp->n_blocks;
    uint64_t h = FNV_OFFSET;
    h = hash_u64(h, (uint64_t)rec->sequence);
    h = hash_u64(h, (uint64_t)rec->rows);
    h = hash_u64(h, (uint64_t)rec->transition_rows);
    h = hash_f64(h, rec->last_transition_t);
    h = hash_u64(h, (uint64_t)n);
    h = hash_u64(h, (uint64_t)cp->n_state);
    /* The same field lists as the writer and the reader, so no field escapes the checksum. */
#define HASH(name, file_type, mem_type, count, field) h = hash_bytes(h, cp->field, (count) * sizeof *cp->field);
    CHECKPOINT_ARRAYS(HASH)
#undef HASH
#define HASH(name, field) h = hash_f64(h, cp->field);
    CHECKPOINT_SCALARS(HASH)
#undef HASH
    h = hash_u64(h, (uint64_t)cp->next_sample);
    h = hash_u64(h, (uint64_t)cp->steps_since_row);
    for (size_t i = 0; i < N_STATS; ++i) {
        const char *field = (const char *)&cp->stats + STATS[i].offset;
        if (STATS[i].is_long) {
            long value;
            memcpy(&value, field, sizeof value);
            h = hash_u64(h, (uint64_t)value);
        } else {
            double value;
            memcpy(&value, field, sizeof value);
            h = hash_f64(h, value);
        }
    }
    /* The method as read back: at most sizeof - 1 characters. */
    return hash_bytes(h, cp->stats.method, strnlen(cp->stats.method, sizeof cp->stats.method - 1));
}

#define CHECKPOINT_UNITS                                                                   \
    "t: s, x: m, v: m/s, t_switch: s, last_transition: s, energies: J, t_last_row: s, "    \
    "last_transition_t: s"

/* Rows up to the checkpoint are flushed first, so the row counts it records are on disk. */
static int sink_checkpoint(void *self, const bk_checkpoint *cp, bk_error *err)
{
    bk_h5_writer *w = self;
    if (w->failed)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: an earlier write failed; no checkpoint", w->part);
    int rc = flush_all(w, err);
    if (rc != BK_OK)
        return rc;
    size_t n = cp->n_blocks;
    checkpoint_record rec = {w->cp_sequence + 1, (long long)w->rows_written,
                             (long long)w->trans_written, w->trans_last_t};
    uint64_t checksum = checkpoint_hash(cp, &rec);
    int created = 0, slot_created = 0;
    hid_t top = open_or_create_group(w->file, "checkpoint", &created);
    herr_t ok = top < 0 ? -1 : 0;
    if (ok >= 0 && created)
        ok = describe_fixed(top, "a, b: checkpoint slots",
                            "the state a restart (bksim run --restart) continues from: two "
                            "slots written in turn, the newest that verifies (sequence, "
                            "checksum) is used");
    hid_t group = ok < 0 ? H5I_INVALID_HID
                         : open_or_create_group(top, SLOT_NAMES[w->cp_slot], &slot_created);
    if (group < 0)
        ok = -1;
#define PUT(name, file_type, mem_type, count, field)                                       \
    if (ok >= 0)                                                                           \
        ok = put_array(group, name, file_type, mem_type, count, cp->field);
    CHECKPOINT_ARRAYS(PUT)
#undef PUT
#define PUT(name, field)                                                                   \
    if (ok >= 0)                                                                           \
        ok = write_double_attr(group, name, cp->field);
    CHECKPOINT_SCALARS(PUT)
#undef PUT
    if (ok >= 0)
        ok = write_long_attr(group, "next_sample", cp->next_sample);
    if (ok >= 0)
        ok = write_long_attr(group, "steps_since_row", cp->steps_since_row);
    if (ok >= 0)
        ok = write_long_attr(group, "n_blocks", (long long)n);
    if (ok >= 0)
        ok = write_long_attr(group, "n_state", (long long)cp->n_state);
    if (ok >= 0)
        ok = write_long_attr(group, "rows", rec.rows);
    if (ok >= 0)
        ok = write_long_attr(group, "transition_rows", rec.transition_rows);
    if (ok >= 0)
        ok = write_double_attr(group, "last_transition_t", rec.last_transition_t);
    if (ok >= 0)
        ok = write_long_attr(group, "sequence", rec.sequence);
    if (ok >= 0)
        ok = write_stats(group, &cp->stats);
    if (ok >= 0)
        ok = write_attr(group, "checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &checksum);
    if (ok >= 0 && slot_created)
        ok = describe_fixed(group, CHECKPOINT_UNITS,
                            "one checkpoint; checksum: FNV-1a over sequence, rows, "
                            "transition_rows, last_transition_t, the arrays, the scalars and "
                            "stats");
    CLOSE_IDS(ok, group, top);
    if (ok < 0 || H5Fflush(w->file, H5F_SCOPE_LOCAL) < 0) {
        w->failed = 1;
        return H5_FAIL(err, "%s: cannot write /checkpoint/%s", w->part, SLOT_NAMES[w->cp_slot]);
    }
    w->cp_sequence = rec.sequence;
    w->cp_slot ^= 1;
    return BK_OK;
}

/* The counters a checkpoint carries, from its stats group. */
static herr_t read_stats(hid_t group, bk_run_stats *stats)
{
    hid_t g = H5Gopen2(group, "stats", H5P_DEFAULT);
    if (g < 0)
        return -1;
    herr_t rc = 0;
    for (size_t i = 0; rc >= 0 && i < N_STATS; ++i) {
        char *field = (char *)stats + STATS[i].offset;
        if (STATS[i].is_long) {
            long long value = 0;
            rc = read_numeric_attr(g, STATS[i].name, H5T_NATIVE_LLONG, &value);
            long as_long = (long)value;
            memcpy(field, &as_long, sizeof as_long);
        } else {
            rc = read_numeric_attr(g, STATS[i].name, H5T_NATIVE_DOUBLE, field);
        }
    }
    char *method = read_string_attr(g, "method");
    if (method)
        snprintf(stats->method, sizeof stats->method, "%s", method);
    free(method);
    CLOSE_IDS(rc, g);
    return rc;
}

/* A dataset transfer that skips Fletcher32 checks; H5P_DEFAULT-like otherwise. */
static hid_t unchecked_xfer(void)
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
static herr_t read_rows_lenient(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t cols,
                                hid_t mem_type, void *buf, int *unchecked)
{
    if (unchecked)
        *unchecked = 0;
    if (read_block_xfer(dset, rank, start, count, 0, cols, mem_type, buf, H5P_DEFAULT) >= 0)
        return 0;
    if (unchecked)
        *unchecked = 1;
    hid_t dxpl = unchecked_xfer();
    herr_t rc = dxpl < 0 ? -1 : read_block_xfer(dset, rank, start, count, 0, cols, mem_type, buf, dxpl);
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
static int slot_matches_data(hid_t file, const bk_checkpoint *cp, const checkpoint_record *rec,
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
               (read_rows_lenient(time, 1, (hsize_t)(rec->rows - 1), 1, 1, H5T_NATIVE_DOUBLE, &t, NULL) < 0 ||
                t != cp->t_last_row)) {
        snprintf(why, why_len, "its last row is at t = %.17g s, /time[%lld] = %.17g s",
                 cp->t_last_row, rec->rows - 1, t);
        rc = -1;
    }
    close_id(time);
    if (rc < 0 || rec->transition_rows == 0)
        return rc;
    hid_t table = H5Lexists(file, "transitions", H5P_DEFAULT) > 0
                      ? H5Dopen2(file, "transitions", H5P_DEFAULT)
                      : H5I_INVALID_HID;
    hid_t mem = table < 0 ? H5I_INVALID_HID : transition_type(0);
    long long count = mem < 0 ? -1 : leading_dim(table);
    bk_transition last;
    last.t = NAN;
    if (count < rec->transition_rows) {
        snprintf(why, why_len, "records %lld transitions, /transitions has %lld",
                 rec->transition_rows, count < 0 ? 0 : count);
        rc = -1;
    } else if (read_rows_lenient(table, 1, (hsize_t)(rec->transition_rows - 1), 1, 1, mem, &last, NULL) < 0 ||
               last.t != rec->last_transition_t) {
        snprintf(why, why_len, "its last transition is at t = %.17g s, /transitions[%lld] at %.17g s",
                 rec->last_transition_t, rec->transition_rows - 1, last.t);
        rc = -1;
    }
    CLOSE_IDS(0, mem, table);
    return rc;
}

/* Read one slot of /checkpoint into cp (allocated here; freed again unless BK_OK) and check
 * it: its sizes (n_state SIZE_MAX: any), its checksum and its agreement with the datasets.
 * BK_OK; BK_ERR_NOMEM; BK_ERR_INVALID for a slot never written; SLOT_TORN for one whose own
 * contents do not hold together (a write cut short); or BK_ERR_DAMAGED (it disagrees with the
 * data); why filled (no path: the caller adds it). */
#define SLOT_TORN 1
static int read_slot(hid_t file, hid_t top, const char *name, size_t n_blocks, size_t n_state,
                     bk_checkpoint *cp, checkpoint_record *rec, char *why, size_t why_len)
{
    memset(cp, 0, sizeof *cp);
    memset(rec, 0, sizeof *rec);
    if (H5Lexists(top, name, H5P_DEFAULT) <= 0) {
        snprintf(why, why_len, "not written");
        return BK_ERR_INVALID;
    }
    hid_t group = H5Gopen2(top, name, H5P_DEFAULT);
    long long nb = -1, ns = -1;
    if (group < 0 || read_numeric_attr(group, "n_blocks", H5T_NATIVE_LLONG, &nb) < 0 ||
        read_numeric_attr(group, "n_state", H5T_NATIVE_LLONG, &ns) < 0) {
        CLOSE_IDS(-1, group);
        snprintf(why, why_len, "cannot be read (written only in part)");
        return SLOT_TORN;
    }
    /* The counts size the arrays, so they are checked before the checksum can be. */
    int fits = nb == (long long)n_blocks && ns >= 0 && ns <= (long long)(SIZE_MAX / 64) &&
               (n_state == SIZE_MAX || ns == (long long)n_state);
    if (!fits) {
        CLOSE_IDS(0, group);
        snprintf(why, why_len, "holds %lld blocks and %lld friction states, the run %zu blocks", nb, ns,
                 n_blocks);
        return BK_ERR_DAMAGED;
    }
    size_t n = n_blocks;
    if (bk_checkpoint_alloc(cp, n, (size_t)ns) != BK_OK) {
        CLOSE_IDS(0, group);
        snprintf(why, why_len, "out of memory");
        return BK_ERR_NOMEM;
    }
    herr_t ok = 0;
#define GET(name, file_type, mem_type, count, field)                                       \
    if (ok >= 0)                                                                           \
        ok = get_array(group, name, mem_type, count, cp->field);
    CHECKPOINT_ARRAYS(GET)
#undef GET
#define GET(name, field)                                                                   \
    if (ok >= 0)                                                                           \
        ok = read_numeric_attr(group, name, H5T_NATIVE_DOUBLE, &cp->field);
    CHECKPOINT_SCALARS(GET)
#undef GET
    long long next_sample = 0, steps = 0;
    uint64_t stored = 0;
    if (ok >= 0)
        ok = read_numeric_attr(group, "next_sample", H5T_NATIVE_LLONG, &next_sample);
    if (ok >= 0)
        ok = read_numeric_attr(group, "steps_since_row", H5T_NATIVE_LLONG, &steps);
    if (ok >= 0)
        ok = read_numeric_attr(group, "rows", H5T_NATIVE_LLONG, &rec->rows);
    if (ok >= 0)
        ok = read_numeric_attr(group, "transition_rows", H5T_NATIVE_LLONG, &rec->transition_rows);
    if (ok >= 0)
        ok = read_numeric_attr(group, "last_transition_t", H5T_NATIVE_DOUBLE, &rec->last_transition_t);
    if (ok >= 0)
        ok = read_numeric_attr(group, "sequence", H5T_NATIVE_LLONG, &rec->sequence);
    if (ok >= 0)
        ok = read_stats(group, &cp->stats);
    if (ok >= 0)
        ok = read_numeric_attr(group, "checksum", H5T_NATIVE_UINT64, &stored);
    CLOSE_IDS(ok, group);
    cp->next_sample = (long)next_sample;
    cp->steps_since_row = (long)steps;
    int rc = BK_OK;
    if (ok < 0) {
        snprintf(why, why_len, "cannot be read (written only in part)");
        rc = SLOT_TORN;
    } else if (checkpoint_hash(cp, rec) != stored) {
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

/* The newest slot of /checkpoint that verifies, into cp; *slot says which.  BK_ERR_INVALID
 * when the file has no /checkpoint; BK_ERR_DAMAGED when no slot verifies (the message gives
 * each slot's fault), or when /checkpoint was written without a consistency record (*legacy
 * set: an older bksim's, which cannot be verified). */
static int find_checkpoint(hid_t file, const char *path, size_t n_blocks, size_t n_state,
                           bk_checkpoint *cp, checkpoint_record *rec, int *slot, int *legacy,
                           bk_error *err)
{
    memset(cp, 0, sizeof *cp);
    *legacy = 0;
    if (H5Lexists(file, "checkpoint", H5P_DEFAULT) <= 0)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: no checkpoint to restart from (run with [output] "
                       "checkpoint_interval > 0)", path);
    hid_t top = H5Gopen2(file, "checkpoint", H5P_DEFAULT);
    if (top < 0)
        return H5_DAMAGED(err, "%s: damaged: /checkpoint cannot be opened", path);
    if (H5Lexists(top, "x", H5P_DEFAULT) > 0) {
        *legacy = 1;
        close_id(top);
        return BK_FAIL(err, BK_ERR_DAMAGED,
                       "%s: /checkpoint was written by an older bksim without a consistency "
                       "record, so it cannot be verified; not restarting from it (run again "
                       "from the start)", path);
    }
    bk_checkpoint found[2];
    checkpoint_record recs[2];
    char why[2][200];
    int status[2];
    for (int k = 0; k < 2; ++k)
        status[k] = read_slot(file, top, SLOT_NAMES[k], n_blocks, n_state, &found[k], &recs[k],
                              why[k], sizeof why[k]);
    close_id(top);
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
    *cp = found[best];
    *rec = recs[best];
    *slot = best;
    return BK_OK;
}

/* First-dimension chunk size of a chunked dataset; 0 when not chunked. */
static hsize_t chunk_rows_of(hid_t dset)
{
    hid_t dcpl = H5Dget_create_plist(dset);
    hsize_t chunk[2] = {0, 0};
    if (dcpl < 0 || H5Pget_layout(dcpl) != H5D_CHUNKED || H5Pget_chunk(dcpl, 2, chunk) < 1)
        chunk[0] = 0;
    CLOSE_IDS(0, dcpl);
    return chunk[0];
}

/* Truncate dset to rows, dropping what was written after the checkpoint.  When the chunk
 * holding the last of those rows fails its checksum (see read_rows_lenient), its rows up to
 * the checkpoint are first written back over it, checks off for the read that write makes,
 * so that it is whole again.  The chunk is rewritten in place, never dropped and written
 * anew: a kill between dropping it and flushing its replacement could lose it from the
 * chunk index, and its rows would read back as zeros. */
static herr_t truncate_rows(hid_t dset, hsize_t rows, hid_t mem_type, size_t row_bytes)
{
    hid_t space = H5Dget_space(dset);
    hsize_t dims[2] = {0, 0};
    int rank = space < 0 ? -1 : H5Sget_simple_extent_dims(space, dims, NULL);
    CLOSE_IDS(rank, space);
    if (rank < 1 || rank > 2 || dims[0] < rows)
        return -1;
    hsize_t chunk = chunk_rows_of(dset);
    hsize_t start = chunk > 0 ? rows / chunk * chunk : rows;
    herr_t rc = 0;
    if (start < rows) {
        hsize_t count = rows - start;
        void *buf = malloc((size_t)count * row_bytes);
        int unchecked = 0;
        rc = buf ? read_rows_lenient(dset, rank, start, count, dims[1], mem_type, buf, &unchecked) : -1;
        if (rc >= 0 && unchecked) {
            hsize_t offset[2] = {start, 0}, counts[2] = {count, dims[1]};
            hid_t file_space = H5Dget_space(dset);
            hid_t mem_space = H5Screate_simple(rank, counts, NULL);
            hid_t dxpl = unchecked_xfer();
            rc = file_space < 0 || mem_space < 0 || dxpl < 0 ||
                         H5Sselect_hyperslab(file_space, H5S_SELECT_SET, offset, NULL, counts, NULL) < 0
                     ? -1
                     : H5Dwrite(dset, mem_type, mem_space, file_space, dxpl, buf);
            CLOSE_IDS(rc, dxpl, mem_space, file_space);
        }
        free(buf);
    }
    dims[0] = rows;
    return rc < 0 ? rc : H5Dset_extent(dset, dims);
}

/* The config a run stored (file text and --set overrides, any number of them). */
static int load_stored_config(hid_t file, const char *path, bk_config **config, bk_error *err)
{
    *config = NULL;
    char *text = read_string_attr(file, "config_file");
    char *name = read_string_attr(file, "config_name");
    char *overrides = read_string_attr(file, "overrides");
    const char **list = NULL;
    size_t n_over = 0, cap = 0;
    int rc = BK_OK;
    if (!text || !name)
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: no stored config to restart with", path);
    char *save = NULL;
    for (char *line = rc == BK_OK && overrides ? strtok_r(overrides, "\n", &save) : NULL; line;
         line = strtok_r(NULL, "\n", &save)) {
        if (n_over == cap) {
            size_t grown_cap = cap ? 2 * cap : 16;
            const char **grown = realloc(list, grown_cap * sizeof *grown);
            if (!grown) {
                rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for the stored overrides", path);
                break;
            }
            list = grown;
            cap = grown_cap;
        }
        list[n_over++] = line;
    }
    if (rc == BK_OK)
        rc = bk_config_load_string(text, name, list, n_over, config, err);
    free(list);
    free(text);
    free(name);
    free(overrides);
    return rc;
}

/* The datasets the writer created, from the root attribute "datasets"; NULL for a file
 * written before it was recorded.  Malloc'ed, comma-separated. */
static char *recorded_datasets(hid_t file)
{
    return read_string_attr(file, "datasets");
}

/* Every name in the comma-separated list is a link in file; else BK_ERR_DAMAGED. */
static int require_datasets(hid_t file, const char *path, const char *names, bk_error *err)
{
    for (const char *p = names; p && *p;) {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        char name[64];
        if (len > 0 && len < sizeof name) {
            memcpy(name, p, len);
            name[len] = '\0';
            if (H5Lexists(file, name, H5P_DEFAULT) <= 0)
                return BK_FAIL(err, BK_ERR_DAMAGED,
                               "%s: damaged: no /%s, which the run wrote (root attribute "
                               "datasets: %s)", path, name, names);
        }
        p = end ? end + 1 : p + len;
    }
    return BK_OK;
}

int bk_h5_writer_resume(bk_h5_writer **out, const char *path, bk_config **config_out,
                        bk_checkpoint *checkpoint, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (!out || !path || !config_out || !checkpoint)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "bk_h5_writer_resume: needs writer, path, config and checkpoint pointers");
    *out = NULL;
    *config_out = NULL;
    memset(checkpoint, 0, sizeof *checkpoint);
    size_t len = strlen(path);
    int is_part = len > 5 && strcmp(path + len - 5, ".part") == 0;
    bk_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    w->file = w->trans_dset = w->trans_mem = H5I_INVALID_HID;
    for (int i = 0; i < BK_N_SERIES; ++i)
        w->s[i].dset = H5I_INVALID_HID;
    w->path = is_part ? strndup(path, len - 5) : strdup(path);
    w->part = malloc(len + sizeof ".part");
    if (!w->path || !w->part) {
        free_writer(w);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    }
    sprintf(w->part, "%s.part", w->path);
    struct stat st;
    if (stat(w->part, &st) != 0) {
        int complete = 0;
        hid_t done = stat(w->path, &st) == 0 ? H5Fopen(w->path, H5F_ACC_RDONLY, H5P_DEFAULT) : H5I_INVALID_HID;
        if (done >= 0)
            read_numeric_attr(done, "complete", H5T_NATIVE_INT, &complete);
        CLOSE_IDS(0, done);
        int rc = BK_FAIL(err, BK_ERR_INVALID, "%s: %s", w->part,
                         complete ? "no such file; the run is complete, nothing to restart"
                                  : "no such file to restart from");
        free_writer(w);
        return rc;
    }
    bk_config *config = NULL;
    bk_checkpoint *cp = checkpoint;
    checkpoint_record rec = {0, 0, 0, 0.0};
    int slot = 0, legacy = 0;
    w->file = H5Fopen(w->part, H5F_ACC_RDWR, H5P_DEFAULT);
    int rc = w->file < 0 ? H5_FAIL(err, "%s: cannot open for the restart", w->part) : BK_OK;
    /* HDF5 writes the superblock, which holds the end of allocated space (EOA), last in a
     * flush; a kill inside a flush can leave blocks written past the EOA it records.  Space
     * freed there (a chunk dropped by the truncation below) would then be handed out again
     * and every write to it fail ("addr overflow").  Nothing on disk lies past the end of the
     * file, so moving the EOA there is safe. */
    haddr_t eoa = 0;
    if (rc == BK_OK && H5Fget_eoa(w->file, &eoa) >= 0 && (haddr_t)st.st_size > eoa &&
        H5Fincrement_filesize(w->file, 0) < 0)
        rc = H5_FAIL(err, "%s: cannot extend the allocated space to the end of the file", w->part);
    /* The checkpoint before the config: it needs no variable-length string (see
     * write_fixed_string_attr), so a file without one is refused without reading any. */
    long long n_blocks = 0;
    if (rc == BK_OK && (read_numeric_attr(w->file, "n_blocks", H5T_NATIVE_LLONG, &n_blocks) < 0 ||
                        n_blocks < 1))
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: no valid root attribute n_blocks", w->part);
    if (rc == BK_OK)
        rc = find_checkpoint(w->file, w->part, (size_t)n_blocks, SIZE_MAX, cp, &rec, &slot,
                             &legacy, err);
    if (rc == BK_OK)
        rc = load_stored_config(w->file, w->part, &config, err);
    if (rc == BK_OK && (config->model->n_blocks != cp->n_blocks ||
                        config->model->n_friction_state != cp->n_state))
        rc = BK_FAIL(err, BK_ERR_DAMAGED,
                     "%s: damaged: the checkpoint holds %zu blocks and %zu friction states, the "
                     "stored config makes %zu and %zu", w->part, cp->n_blocks, cp->n_state,
                     config->model->n_blocks, config->model->n_friction_state);
    if (rc == BK_OK) {
        char *names = recorded_datasets(w->file);
        rc = require_datasets(w->file, w->part, names, err);
        free(names);
    }
    if (rc == BK_OK) {
        const bk_model *model = config->model;
        size_t n_state = model->n_friction_state;
        size_t widest = model->n_blocks > n_state ? model->n_blocks : n_state;
        size_t buffer_rows = CHUNK_BYTES / (widest * sizeof(double));
        w->buffer_rows = buffer_rows < 1 ? 1 : buffer_rows > MAX_BUFFER_ROWS ? MAX_BUFFER_ROWS : buffer_rows;
        w->n_blocks = model->n_blocks;
        hsize_t rows = (hsize_t)rec.rows;
        for (int i = 0; rc == BK_OK && i < BK_N_SERIES; ++i) {
            series *ser = &w->s[i];
            if (H5Lexists(w->file, bk_series[i].name, H5P_DEFAULT) <= 0)
                continue;
            ser->dset = H5Dopen2(w->file, bk_series[i].name, H5P_DEFAULT);
            ser->rank = bk_series[i].shape == BK_SHAPE_T ? 1 : 2;
            ser->cols = bk_series[i].shape == BK_SHAPE_T ? 1 : bk_series[i].shape == BK_SHAPE_TN ? model->n_blocks : n_state;
            ser->elem = bk_series_value_size(bk_series[i].kind);
            ser->buf = malloc(w->buffer_rows * ser->cols * ser->elem);
            if (ser->dset < 0 || !ser->buf ||
                truncate_rows(ser->dset, rows, kind_mem_type(bk_series[i].kind), ser->cols * ser->elem) < 0)
                rc = H5_FAIL(err, "%s: cannot reopen /%s at the checkpoint's %llu rows", w->part,
                             bk_series[i].name, (unsigned long long)rows);
        }
        if (rc == BK_OK && H5Lexists(w->file, "transitions", H5P_DEFAULT) > 0) {
            w->trans_buf = malloc(TRANSITION_BUFFER * sizeof *w->trans_buf);
            w->trans_mem = transition_type(0);
            w->trans_dset = H5Dopen2(w->file, "transitions", H5P_DEFAULT);
            if (!w->trans_buf || w->trans_mem < 0 || w->trans_dset < 0 ||
                truncate_rows(w->trans_dset, (hsize_t)rec.transition_rows, w->trans_mem,
                              sizeof(bk_transition)) < 0)
                rc = H5_FAIL(err, "%s: cannot reopen /transitions at the checkpoint", w->part);
        }
        w->rows_written = rows;
        w->trans_written = (hsize_t)rec.transition_rows;
        w->trans_last_t = rec.last_transition_t;
        w->t_written = w->t_buffered = cp->t_last_row;
        /* The next checkpoint goes into the other slot: this one stays the fallback. */
        w->cp_sequence = rec.sequence;
        w->cp_slot = slot ^ 1;
        if (rc == BK_OK && (write_int_attr(w->file, "complete", 0) < 0 ||
                            write_double_attr(w->file, "t_reached", w->t_written) < 0 ||
                            (H5Aexists(w->file, "error") > 0 && H5Adelete(w->file, "error") < 0)))
            rc = H5_FAIL(err, "%s: cannot reset the root attributes for the restart", w->part);
    }
    if (rc != BK_OK) {
        close_writer(w);
        free_writer(w);
        bk_checkpoint_free(cp);
        bk_config_free(config);
        return rc;
    }
    *out = w;
    *config_out = config;
    return BK_OK;
}

int bk_h5_restartable(const char *path, double *t_checkpoint, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (!path || !*path)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_restartable: no output path given");
    size_t len = strlen(path);
    int is_part = len > 5 && strcmp(path + len - 5, ".part") == 0;
    char *part = malloc(len + sizeof ".part");
    if (!part)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    if (is_part)
        memcpy(part, path, len + 1);
    else
        sprintf(part, "%s.part", path);
    struct stat st;
    hid_t file = H5I_INVALID_HID;
    int result = 0;
    if (stat(part, &st) == 0 && S_ISREG(st.st_mode) && has_hdf5_signature(part) > 0)
        file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    long long n_blocks = 0;
    if (file >= 0 && read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, &n_blocks) >= 0 &&
        n_blocks > 0 && H5Lexists(file, "checkpoint", H5P_DEFAULT) > 0) {
        bk_checkpoint cp;
        checkpoint_record rec;
        int slot, legacy;
        bk_error ignored;
        int found = find_checkpoint(file, part, (size_t)n_blocks, SIZE_MAX, &cp, &rec, &slot,
                                    &legacy, &ignored);
        if (found == BK_OK) {
            if (t_checkpoint)
                *t_checkpoint = cp.t;
            bk_checkpoint_free(&cp);
            result = 1;
        } else if (found == BK_ERR_NOMEM) {
            result = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory reading /checkpoint", part);
        }
    }
    close_id(file);
    free(part);
    return result;
}

bk_sink bk_h5_writer_sink(bk_h5_writer *writer)
{
    bk_sink sink = {writer, sink_sample, sink_transition, sink_checkpoint};
    return sink;
}

static herr_t write_stats(hid_t file, const bk_run_stats *stats)
{
    hid_t gcpl = H5I_INVALID_HID, group = H5I_INVALID_HID;
    herr_t rc = -1;
    htri_t exists = H5Lexists(file, "stats", H5P_DEFAULT);
    if (exists < 0)
        goto done;
    if (exists) {
        group = H5Gopen2(file, "stats", H5P_DEFAULT);
    } else {
        /* Creation order lets `bksim info` list the statistics in this table's order. */
        gcpl = H5Pcreate(H5P_GROUP_CREATE);
        if (gcpl < 0 ||
            H5Pset_attr_creation_order(gcpl, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED) < 0)
            goto done;
        group = H5Gcreate2(file, "stats", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    }
    if (group < 0)
        goto done;
    char method[sizeof stats->method + 1];
    memcpy(method, stats->method, sizeof stats->method);
    method[sizeof stats->method] = '\0';
    if (write_fixed_string_attr(group, "method", method) < 0)
        goto done;
    char units[1024] = "";
    size_t used = 0;
    for (size_t i = 0; i < N_STATS; ++i) {
        const char *field = (const char *)stats + STATS[i].offset;
        herr_t ok;
        if (STATS[i].is_long) {
            long value;
            memcpy(&value, field, sizeof value);
            ok = write_long_attr(group, STATS[i].name, value);
        } else {
            double value;
            memcpy(&value, field, sizeof value);
            ok = write_double_attr(group, STATS[i].name, value);
        }
        if (ok < 0)
            goto done;
        int n = snprintf(units + used, sizeof units - used, "%s%s: %s", i ? ", " : "",
                         STATS[i].name, STATS[i].units);
        if (n > 0 && (size_t)n < sizeof units - used)
            used += (size_t)n;
    }
    rc = describe_fixed(group, units, "solver statistics of the run");
done:
    CLOSE_IDS(rc, group, gcpl);
    return rc;
}

/* After a failure that followed complete = 1: take the mark back, so a .part never claims
 * to be complete.  Best effort: the file may be what failed.  /time is held open across
 * H5Fclose for the reason given at close_writer. */
static void mark_incomplete(const char *part, const char *reason)
{
    hid_t file = H5Fopen(part, H5F_ACC_RDWR, H5P_DEFAULT);
    if (file < 0)
        return;
    hid_t hold = H5Dopen2(file, "time", H5P_DEFAULT);
    write_int_attr(file, "complete", 0);
    write_fixed_string_attr(file, "error", reason);
    H5Fclose(file);
    if (hold >= 0)
        H5Dclose(hold);
}

/* Force a file (or directory) to disk; 0 or an errno.  EINVAL (a file system that cannot
 * sync, such as some FUSE mounts) passes: there is nothing more to be done. */
static int sync_path(const char *path)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return errno;
    int e = fsync(fd) == 0 || errno == EINVAL ? 0 : errno;
    close(fd);
    return e;
}

/* The rename of a finished file, made durable: H5Fclose leaves the data in the page cache,
 * and a power cut after the rename could otherwise leave a complete-looking OUT with
 * missing chunks.  The directory sync that makes the new name last is best effort. */
static int durable_rename(const char *part, const char *path, bk_error *err)
{
    int e = sync_path(part);
    if (e != 0)
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot sync to disk: %s", part, strerror(e));
    if (rename(part, path) != 0) {
        e = errno;
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot rename to %s: %s", part, path, strerror(e));
    }
    char *dir = strdup(path);
    if (dir) {
        char *slash = strrchr(dir, '/');
        if (!slash)
            sync_path(".");
        else {
            slash[slash == dir ? 1 : 0] = '\0';
            sync_path(dir);
        }
        free(dir);
    }
    return BK_OK;
}

int bk_h5_writer_finish(bk_h5_writer *writer, const bk_run_stats *stats, bk_error *err)
{
    bk_h5_writer *w = writer;
    if (!w)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_writer_finish: no writer");
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    int rc = BK_OK;
    int marked = 0;
    if (w->failed)
        rc = BK_FAIL(err, BK_ERR_HDF5, "%s: not completed: an earlier write failed", w->part);
    if (rc == BK_OK)
        rc = flush_all(w, err);
    if (rc == BK_OK && stats && write_stats(w->file, stats) < 0)
        rc = H5_FAIL(err, "%s: cannot write /stats", w->part);
    if (rc == BK_OK) {
        marked = 1;
        /* Flushed here rather than at close, where a failure could not be told apart. */
        if (write_int_attr(w->file, "complete", 1) < 0 ||
            H5Fflush(w->file, H5F_SCOPE_LOCAL) < 0)
            rc = H5_FAIL(err, "%s: cannot write the complete flag", w->part);
    }
    if (close_writer(w) < 0 && rc == BK_OK)
        rc = H5_FAIL(err, "%s: cannot close", w->part);
    if (rc == BK_OK)
        rc = durable_rename(w->part, w->path, err);
    if (rc != BK_OK && marked)
        mark_incomplete(w->part, err ? err->message : "finishing the output failed");
    free_writer(w);
    return rc;
}

void bk_h5_writer_abandon(bk_h5_writer *writer, const char *reason, const bk_run_stats *stats)
{
    bk_h5_writer *w = writer;
    if (!w)
        return;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    bk_error ignored;
    /* After a failed append the datasets may be ragged; appending again would misalign. */
    if (!w->failed)
        flush_all(w, &ignored);
    if (stats)
        write_stats(w->file, stats);
    write_int_attr(w->file, "complete", 0);
    write_double_attr(w->file, "t_reached", w->t_written);
    write_fixed_string_attr(w->file, "error", reason ? reason : "run abandoned");
    close_writer(w);
    free_writer(w);
}

/* ---------------------------------------------------------------------- readers --- */

static int open_input(const char *path, hid_t *file, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    *file = H5I_INVALID_HID;
    if (!path || !*path)
        return BK_FAIL(err, BK_ERR_INVALID, "no input file given");
    struct stat st;
    if (stat(path, &st) != 0)
        return BK_FAIL(err, BK_ERR_IO, "%s: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode))
        return BK_FAIL(err, BK_ERR_IO, "%s: is a directory, not an HDF5 file", path);
    htri_t is_hdf5 = has_hdf5_signature(path);
    if (is_hdf5 == 0)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: not an HDF5 file (no HDF5 signature found)",
                       path);
    if (is_hdf5 < 0)
        return H5_FAIL(err, "%s: cannot read", path);
    *file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    size_t len = strlen(path);
    int partial = len > 5 && strcmp(path + len - 5, ".part") == 0;
    if (*file < 0)
        return H5_FAIL(err, "%s: cannot open (truncated or corrupt HDF5 file?%s)", path,
                       partial ? " a .part file is the output of a run that did not finish, "
                                 "here killed before it could close it" : "");
    return BK_OK;
}

static int is_numeric_class(H5T_class_t cls)
{
    return cls == H5T_INTEGER || cls == H5T_FLOAT;
}

typedef struct name_list {
    char **names;
    size_t count;
} name_list;

static void name_list_free(name_list *list)
{
    for (size_t i = 0; i < list->count; ++i)
        free(list->names[i]);
    free(list->names);
    list->names = NULL;
    list->count = 0;
}

/* Root datasets a time-series export can print (numeric, 1-D or 2-D), in creation order
 * when the file tracks it (ours do), else by name. */
static int list_series(hid_t file, name_list *list)
{
    H5G_info_t info;
    list->names = NULL;
    list->count = 0;
    if (H5Gget_info(file, &info) < 0)
        return -1;
    H5_index_t index = H5_INDEX_CRT_ORDER;
    list->names = calloc(info.nlinks ? info.nlinks : 1, sizeof *list->names);
    if (!list->names)
        return -1;
    for (hsize_t i = 0; i < info.nlinks; ++i) {
        ssize_t len = H5Lget_name_by_idx(file, ".", index, H5_ITER_INC, i, NULL, 0, H5P_DEFAULT);
        if (len < 0 && index == H5_INDEX_CRT_ORDER && i == 0) {
            index = H5_INDEX_NAME;
            len = H5Lget_name_by_idx(file, ".", index, H5_ITER_INC, i, NULL, 0, H5P_DEFAULT);
        }
        if (len < 0)
            goto fail;
        char *name = malloc((size_t)len + 1);
        if (!name)
            goto fail;
        if (H5Lget_name_by_idx(file, ".", index, H5_ITER_INC, i, name, (size_t)len + 1,
                               H5P_DEFAULT) < 0) {
            free(name);
            goto fail;
        }
        /* Soft and external links are not ours: only hard links to numeric datasets. */
        H5L_info_t link;
        int keep = 0;
        if (H5Lget_info(file, name, &link, H5P_DEFAULT) >= 0 && link.type == H5L_TYPE_HARD) {
            hid_t obj = H5Oopen(file, name, H5P_DEFAULT);
            if (obj >= 0 && H5Iget_type(obj) == H5I_DATASET) {
                hid_t type = H5Dget_type(obj), space = H5Dget_space(obj);
                if (type >= 0 && space >= 0) {
                    int rank = H5Sget_simple_extent_ndims(space);
                    keep = is_numeric_class(H5Tget_class(type)) && (rank == 1 || rank == 2);
                }
                CLOSE_IDS(0, space, type);
            }
            close_id(obj);
        }
        if (keep)
            list->names[list->count++] = name;
        else
            free(name);
    }
    return 0;
fail:
    name_list_free(list);
    return -1;
}

static int name_list_contains(const name_list *list, const char *name)
{
    for (size_t i = 0; i < list->count; ++i)
        if (strcmp(list->names[i], name) == 0)
            return 1;
    return 0;
}

static void name_list_join(const name_list *list, char *buf, size_t len)
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

/* Opens a numeric 1-D or 2-D dataset and reports its shape. */
static int open_series(hid_t file, const char *path, const char *name, hid_t *dset,
                       hsize_t *rows, hsize_t *cols, int *rank, bk_error *err)
{
    *dset = H5I_INVALID_HID;
    htri_t exists = H5Lexists(file, name, H5P_DEFAULT);
    if (exists <= 0)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: no dataset '%s'", path, name);
    hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
    if (d < 0)
        return H5_FAIL(err, "%s: '%s' is not a readable dataset", path, name);
    hid_t type = H5Dget_type(d);
    hid_t space = H5Dget_space(d);
    hsize_t dims[2] = {0, 1};
    int r = space >= 0 ? H5Sget_simple_extent_ndims(space) : -1;
    int rc = BK_OK;
    if (type < 0 || space < 0 || r < 0)
        rc = H5_FAIL(err, "%s: cannot inspect dataset '%s'", path, name);
    else if (!is_numeric_class(H5Tget_class(type)))
        rc = BK_FAIL(err, BK_ERR_HDF5, "%s: dataset '%s' is not numeric%s", path, name,
                     strcmp(name, "transitions") == 0 ? " (it is the transitions table)" : "");
    else if (r != 1 && r != 2)
        rc = BK_FAIL(err, BK_ERR_HDF5, "%s: dataset '%s' has rank %d, expected 1 or 2", path,
                     name, r);
    else if (H5Sget_simple_extent_dims(space, dims, NULL) < 0)
        rc = H5_FAIL(err, "%s: cannot read the shape of '%s'", path, name);
    CLOSE_IDS(rc == BK_OK ? 0 : -1, space, type);
    if (rc != BK_OK) {
        close_id(d);
        return rc;
    }
    *dset = d;
    *rows = dims[0];
    *cols = r == 2 ? dims[1] : 1;
    *rank = r;
    return BK_OK;
}

/* Rows [start, start + count) and columns [col, col + ncols) as mem_type, read with the
 * transfer properties dxpl. */
static herr_t read_block_xfer(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t col,
                              hsize_t ncols, hid_t mem_type, void *buf, hid_t dxpl)
{
    hsize_t offset[2] = {start, col};
    hsize_t counts[2] = {count, ncols};
    hid_t file_space = H5Dget_space(dset), mem_space = H5I_INVALID_HID;
    herr_t rc = -1;
    if (file_space < 0 ||
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, offset, NULL, counts, NULL) < 0)
        goto done;
    mem_space = H5Screate_simple(rank, counts, NULL);
    if (mem_space >= 0)
        rc = H5Dread(dset, mem_type, mem_space, file_space, dxpl, buf);
done:
    CLOSE_IDS(rc, mem_space, file_space);
    return rc;
}

static herr_t read_block(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t col,
                         hsize_t ncols, hid_t mem_type, void *buf)
{
    return read_block_xfer(dset, rank, start, count, col, ncols, mem_type, buf, H5P_DEFAULT);
}

int bk_h5_read_doubles(const char *path, const char *dataset, double **data, size_t *rows,
                       size_t *cols, bk_error *err)
{
    if (!data || !rows || !cols || !dataset)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_read_doubles: missing argument");
    *data = NULL;
    *rows = *cols = 0;
    hid_t file, dset;
    int rc = open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    hsize_t r, c;
    int rank;
    rc = open_series(file, path, dataset, &dset, &r, &c, &rank, err);
    if (rc == BK_OK) {
        if (c != 0 && r > SIZE_MAX / sizeof(double) / c) {
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: dataset '%s' is too large to read", path,
                         dataset);
        } else {
            size_t n = (size_t)(r * c);
            double *values = malloc((n ? n : 1) * sizeof *values);
            if (!values)
                rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory reading '%s'", path, dataset);
            else if (n > 0 && H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                                      values) < 0)
                rc = H5_FAIL(err, "%s: cannot read dataset '%s'", path, dataset);
            if (rc == BK_OK) {
                *data = values;
                *rows = (size_t)r;
                *cols = (size_t)c;
            } else {
                free(values);
            }
        }
        close_id(dset);
    }
    close_id(file);
    return rc;
}

/* Opens /transitions and its memory type; count = rows. */
static int open_transitions(hid_t file, const char *path, hid_t *dset, hid_t *mem,
                            hsize_t *count, bk_error *err)
{
    *dset = *mem = H5I_INVALID_HID;
    if (H5Lexists(file, "transitions", H5P_DEFAULT) <= 0)
        return BK_FAIL(err, BK_ERR_HDF5,
                       "%s: no /transitions table (the run was written with transitions "
                       "off)", path);
    *dset = H5Dopen2(file, "transitions", H5P_DEFAULT);
    hid_t space = *dset >= 0 ? H5Dget_space(*dset) : H5I_INVALID_HID;
    hsize_t dims[1] = {0};
    int rc = BK_OK;
    if (space < 0 || H5Sget_simple_extent_ndims(space) != 1 ||
        H5Sget_simple_extent_dims(space, dims, NULL) < 0)
        rc = H5_FAIL(err, "%s: /transitions is not a 1-D table", path);
    else if ((*mem = transition_type(0)) < 0)
        rc = H5_FAIL(err, "%s: cannot build the transition type", path);
    close_id(space);
    if (rc != BK_OK) {
        close_id(*dset);
        *dset = H5I_INVALID_HID;
        return rc;
    }
    *count = dims[0];
    return BK_OK;
}

int bk_h5_read_transitions(const char *path, bk_transition **rows, size_t *count,
                           bk_error *err)
{
    if (!rows || !count)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_read_transitions: missing argument");
    *rows = NULL;
    *count = 0;
    hid_t file, dset, mem;
    hsize_t n;
    int rc = open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    rc = open_transitions(file, path, &dset, &mem, &n, err);
    if (rc == BK_OK) {
        bk_transition *values = n > SIZE_MAX / sizeof *values
                                    ? NULL
                                    : malloc((n ? (size_t)n : 1) * sizeof *values);
        if (!values)
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory reading /transitions", path);
        else if (n > 0 && H5Dread(dset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) < 0)
            rc = H5_FAIL(err, "%s: cannot read /transitions", path);
        if (rc == BK_OK) {
            *rows = values;
            *count = (size_t)n;
        } else {
            free(values);
        }
        CLOSE_IDS(0, mem, dset);
    }
    close_id(file);
    return rc;
}

static int read_n_blocks(hid_t file, const char *path, long long *n_blocks, bk_error *err)
{
    if (read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, n_blocks) < 0 || *n_blocks < 1)
        return BK_FAIL(err, BK_ERR_HDF5,
                       "%s: no valid root attribute n_blocks (not a bksim output file?)", path);
    return BK_OK;
}

/* ------------------------------------------------------------------------- info --- */

/* Unit of key in a "key: unit, key: unit" list; "" when not listed. */
static void unit_of(const char *units, const char *key, char *buf, size_t len)
{
    buf[0] = '\0';
    if (!units)
        return;
    size_t key_len = strlen(key);
    for (const char *p = units; *p;) {
        while (*p == ' ' || *p == ',')
            ++p;
        const char *end = strchr(p, ',');
        if (!end)
            end = p + strlen(p);
        if ((size_t)(end - p) > key_len + 1 && strncmp(p, key, key_len) == 0 &&
            p[key_len] == ':') {
            const char *u = p + key_len + 1;
            while (*u == ' ')
                ++u;
            snprintf(buf, len, "%.*s", (int)(end - u), u);
            return;
        }
        p = end;
    }
}

typedef struct stats_print {
    FILE *out;
    char *units;
} stats_print;

static herr_t print_stat(hid_t group, const char *name, const H5A_info_t *info, void *data)
{
    const stats_print *ctx = data;
    (void)info;
    if (strcmp(name, "units") == 0 || strcmp(name, "description") == 0)
        return 0;
    hid_t attr = H5Aopen(group, name, H5P_DEFAULT);
    hid_t type = attr >= 0 ? H5Aget_type(attr) : H5I_INVALID_HID;
    H5T_class_t cls = type >= 0 ? H5Tget_class(type) : H5T_NO_CLASS;
    CLOSE_IDS(0, type, attr);
    /* Counts carry unit "1"; printing it after every count would only be noise. */
    char unit[64];
    unit_of(ctx->units, name, unit, sizeof unit);
    if (strcmp(unit, "1") == 0)
        unit[0] = '\0';
    const char *sep = unit[0] ? " " : "";
    if (cls == H5T_STRING) {
        char *text = read_string_attr(group, name);
        fprintf(ctx->out, "    %-18s %s\n", name, text ? text : "?");
        free(text);
    } else if (cls == H5T_INTEGER) {
        long long value = 0;
        if (read_numeric_attr(group, name, H5T_NATIVE_LLONG, &value) >= 0)
            fprintf(ctx->out, "    %-18s %lld%s%s\n", name, value, sep, unit);
    } else if (cls == H5T_FLOAT) {
        double value = 0;
        if (read_numeric_attr(group, name, H5T_NATIVE_DOUBLE, &value) >= 0)
            fprintf(ctx->out, "    %-18s %.9g%s%s\n", name, value, sep, unit);
    }
    return 0;
}

static void print_stats(hid_t file, FILE *out)
{
    if (H5Lexists(file, "stats", H5P_DEFAULT) <= 0) {
        fprintf(out, "stats: none recorded\n");
        return;
    }
    hid_t group = H5Gopen2(file, "stats", H5P_DEFAULT);
    if (group < 0) {
        fprintf(out, "stats: unreadable\n");
        return;
    }
    stats_print ctx = {out, read_string_attr(group, "units")};
    fprintf(out, "stats:\n");
    hsize_t idx = 0;
    if (H5Aiterate2(group, H5_INDEX_CRT_ORDER, H5_ITER_INC, &idx, print_stat, &ctx) < 0 &&
        idx == 0) {
        /* Files whose /stats does not track creation order: alphabetical. */
        idx = 0;
        H5Aiterate2(group, H5_INDEX_NAME, H5_ITER_INC, &idx, print_stat, &ctx);
    }
    free(ctx.units);
    close_id(group);
}

static void print_indented(FILE *out, const char *text)
{
    const char *p = text;
    while (*p) {
        const char *end = strchr(p, '\n');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        fprintf(out, "    %.*s\n", (int)len, p);
        p += len + (end ? 1 : 0);
    }
}

/* Stick and slip phases per block: each transition starts a phase of its `to` mode, and
 * row 0 of /mode starts the first one. */
static int count_phases(hid_t file, const char *path, size_t n_blocks, long *stick, long *slip,
                        long *total, int *have_transitions, bk_error *err)
{
    hid_t dset, mem;
    hsize_t rows, cols;
    int rank;
    *total = 0;
    *have_transitions = 0;
    if (H5Lexists(file, "mode", H5P_DEFAULT) > 0 &&
        open_series(file, path, "mode", &dset, &rows, &cols, &rank, NULL) == BK_OK) {
        if (rows > 0 && rank == 2 && cols == n_blocks) {
            int8_t *first = malloc(n_blocks);
            if (first && read_block(dset, 2, 0, 1, 0, cols, H5T_NATIVE_INT8, first) >= 0)
                for (size_t i = 0; i < n_blocks; ++i)
                    ++*(first[i] == 0 ? &stick[i] : &slip[i]);
            free(first);
        }
        close_id(dset);
    }
    if (H5Lexists(file, "transitions", H5P_DEFAULT) <= 0)
        return BK_OK;
    hsize_t count;
    int rc = open_transitions(file, path, &dset, &mem, &count, err);
    if (rc != BK_OK)
        return rc;
    *have_transitions = 1;
    bk_transition *buf = malloc(TRANSITION_BUFFER * sizeof *buf);
    if (!buf)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    for (hsize_t start = 0; rc == BK_OK && start < count; start += TRANSITION_BUFFER) {
        size_t n = (size_t)(count - start);
        if (n > TRANSITION_BUFFER)
            n = TRANSITION_BUFFER;
        if (read_block(dset, 1, start, n, 0, 1, mem, buf) < 0) {
            rc = H5_DAMAGED(err, "%s: damaged: /transitions cannot be read", path);
            break;
        }
        for (size_t k = 0; k < n; ++k) {
            if (buf[k].block < 0 || (size_t)buf[k].block >= n_blocks) {
                rc = BK_FAIL(err, BK_ERR_DAMAGED,
                             "%s: damaged: /transitions row %llu names block %d, outside 0..%zu", path,
                             (unsigned long long)(start + k), (int)buf[k].block, n_blocks - 1);
                break;
            }
            ++*(buf[k].to == 0 ? &stick[buf[k].block] : &slip[buf[k].block]);
        }
    }
    *total = (long)count;
    free(buf);
    CLOSE_IDS(0, mem, dset);
    return rc;
}

/* What a check needs to know about the file as a whole. */
typedef struct verify_ctx {
    const char *path;
    long long n_blocks;
    double t_end, t_reached;
    int complete;
} verify_ctx;

/* Rows read at a time while checking: whole chunks (a partial chunk would be read and its
 * checksum computed once per piece), about EXPORT_BUDGET values. */
static hsize_t scan_step(hid_t dset, hsize_t cols)
{
    hsize_t chunk = chunk_rows_of(dset);
    if (chunk == 0)
        chunk = 1;
    hsize_t chunks = EXPORT_BUDGET / (chunk * (cols ? cols : 1));
    return chunk * (chunks ? chunks : 1);
}

/* Every value of one time series, streamed a block of rows at a time: finite, modes and
 * event flags from their sets, /time strictly increasing up to t_reached (and t_end when
 * complete).  A chunk failing its checksum fails the read: damaged. */
static int scan_series(hid_t file, const verify_ctx *v, const char *name, bk_error *err)
{
    const char *path = v->path;
    hid_t dset;
    hsize_t rows, cols;
    int rank;
    if (open_series(file, path, name, &dset, &rows, &cols, &rank, err) != BK_OK)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s cannot be read", path, name);
    int is_time = strcmp(name, "time") == 0;
    int is_mode = strcmp(name, "mode") == 0;
    int is_event = strcmp(name, "event") == 0;
    hsize_t step = scan_step(dset, cols);
    if (step > rows)
        step = rows ? rows : 1;
    double *buf = malloc((size_t)(step * cols) * sizeof *buf);
    int rc = buf ? BK_OK : BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    double prev = NAN, before = NAN; /* the value before this one; the block's last */
    for (hsize_t start = 0; rc == BK_OK && start < rows; start += step) {
        hsize_t count = rows - start < step ? rows - start : step;
        if (read_block(dset, rank, start, count, 0, cols, H5T_NATIVE_DOUBLE, buf) < 0) {
            rc = H5_DAMAGED(err, "%s: damaged: /%s rows %llu..%llu cannot be read", path, name,
                            (unsigned long long)start, (unsigned long long)(start + count - 1));
            break;
        }
        size_t values = (size_t)(count * cols);
        for (size_t k = 0; rc == BK_OK && k < values; ++k) {
            double x = buf[k];
            int valid = is_mode    ? x == -1.0 || x == 0.0 || x == 1.0
                        : is_event ? x == 0.0 || x == 1.0
                                   : isfinite(x) && (!is_time || start + k == 0 || x > prev);
            prev = x;
            if (valid)
                continue;
            unsigned long long row = (unsigned long long)start + k / (size_t)cols;
            unsigned long long col = k % (size_t)cols;
            char where[64];
            if (rank == 2)
                snprintf(where, sizeof where, "row %llu column %llu", row, col);
            else
                snprintf(where, sizeof where, "row %llu", row);
            if (is_mode)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /mode %s is %g, not a mode "
                             "(stick 0, slip+ 1, slip- -1)", path, where, x);
            else if (is_event)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /event %s is %g, not 0 or 1",
                             path, where, x);
            else if (!isfinite(x))
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s %s is %g, not finite", path,
                             name, where, x);
            else
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /time is not strictly increasing "
                             "at row %llu (%.17g after %.17g)", path, row, x, k ? buf[k - 1] : before);
        }
        before = buf[values - 1];
    }
    free(buf);
    close_id(dset);
    if (rc != BK_OK || !is_time)
        return rc;
    if (rows > 0 && prev != v->t_reached)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: t_reached (%.17g) is not the last time "
                       "(%.17g)", path, v->t_reached, prev);
    if (v->complete && (rows == 0 || fabs(prev - v->t_end) > 1e-9 * fabs(v->t_end)))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: marked complete but /time ends at %.17g, "
                       "not t_end = %.17g", path, rows ? prev : NAN, v->t_end);
    return BK_OK;
}

static int valid_mode(int8_t mode)
{
    return mode == -1 || mode == 0 || mode == 1;
}

/* /transitions in time order, each of an existing block, between modes, at a time the run
 * reached, with finite values.  The bound is t_reached for a complete run; an unfinished
 * run may have flushed transitions after its last row (with event_rows off there is no row
 * at a transition), so there it is t_end. */
/* Restate the error just recorded as damage to path; its message is copied first, since
 * BK_FAIL formats into the same buffer. */
static int mark_damaged(bk_error *err, const char *path, const char *fallback)
{
    char reason[BK_ERROR_MESSAGE_LEN];
    snprintf(reason, sizeof reason, "%s", err && err->message[0] ? err->message : fallback);
    return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: %s", path, reason);
}

static int scan_transitions(hid_t file, const verify_ctx *v, bk_error *err)
{
    const char *path = v->path;
    hid_t dset, mem;
    hsize_t count;
    if (open_transitions(file, path, &dset, &mem, &count, err) != BK_OK)
        return mark_damaged(err, path, "/transitions cannot be read");
    double bound = v->complete ? v->t_reached : v->t_end;
    bound += 1e-9 * fabs(bound);
    bk_transition *buf = malloc(TRANSITION_BUFFER * sizeof *buf);
    int rc = buf ? BK_OK : BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    double prev = 0.0;
    for (hsize_t start = 0; rc == BK_OK && start < count; start += TRANSITION_BUFFER) {
        size_t n = count - start < TRANSITION_BUFFER ? (size_t)(count - start) : TRANSITION_BUFFER;
        if (read_block(dset, 1, start, n, 0, 1, mem, buf) < 0) {
            rc = H5_DAMAGED(err, "%s: damaged: /transitions rows %llu..%llu cannot be read", path,
                            (unsigned long long)start, (unsigned long long)(start + n - 1));
            break;
        }
        for (size_t k = 0; rc == BK_OK && k < n; ++k) {
            const bk_transition *t = &buf[k];
            unsigned long long row = (unsigned long long)(start + k);
            if (!isfinite(t->t) || !isfinite(t->x) || !isfinite(t->v) || !isfinite(t->force))
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu has a value "
                             "that is not finite (t %g, x %g, v %g, force %g)", path, row, t->t,
                             t->x, t->v, t->force);
            else if (t->t < prev)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions is not in time order "
                             "at row %llu (t = %.17g s after %.17g s)", path, row, t->t, prev);
            else if (t->t > bound)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu is at "
                             "t = %.17g s, after the %s (%.17g s)", path, row, t->t,
                             v->complete ? "end of the run" : "run's t_end",
                             v->complete ? v->t_reached : v->t_end);
            else if (t->block < 0 || t->block >= v->n_blocks)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu names block "
                             "%d, outside 0..%lld", path, row, (int)t->block, v->n_blocks - 1);
            else if (!valid_mode(t->from) || !valid_mode(t->to))
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu goes from "
                             "mode %d to %d; modes are stick 0, slip+ 1, slip- -1", path, row,
                             (int)t->from, (int)t->to);
            prev = t->t;
        }
    }
    free(buf);
    CLOSE_IDS(0, mem, dset);
    return rc;
}

/* The datasets a file must hold: those its writer recorded, or for a file written before
 * that record, those its stored config selects (time, driver, event if it does not load).
 * Malloc'ed, comma-separated; NULL when out of memory. */
static char *expected_datasets(hid_t file)
{
    char *names = recorded_datasets(file);
    if (names)
        return names;
    bk_config *config = NULL;
    bk_error ignored;
    char list[BK_DATASET_LIST_LEN] = "time,driver,event";
    if (load_stored_config(file, "", &config, &ignored) == BK_OK)
        bk_output_dataset_names(config->output.fields, config->model->n_friction_state,
                     config->output.transitions, list, sizeof list);
    bk_config_free(config);
    return strdup(list);
}

/* The integrity check on an open file (see bk_h5_verify). */
static int verify_open(hid_t file, const char *path, bk_error *err)
{
    verify_ctx v = {path, 0, NAN, NAN, 0};
    if (read_numeric_attr(file, "complete", H5T_NATIVE_INT, &v.complete) < 0 ||
        read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, &v.n_blocks) < 0 ||
        read_numeric_attr(file, "t_end", H5T_NATIVE_DOUBLE, &v.t_end) < 0 ||
        read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &v.t_reached) < 0)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: a root attribute (complete, n_blocks, t_end, "
                       "t_reached) is missing", path);
    if (v.n_blocks < 1 || !isfinite(v.t_end) || !(v.t_end > 0.0))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: root attributes n_blocks = %lld, t_end = %g "
                       "are not a run's", path, v.n_blocks, v.t_end);
    int rc = require_datasets(file, path, "time,driver,event", err);
    if (rc != BK_OK)
        return rc;
    char *expected = expected_datasets(file);
    if (!expected)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    rc = require_datasets(file, path, expected, err);
    free(expected);
    if (rc != BK_OK)
        return rc;
    hid_t time;
    hsize_t rows, cols;
    int rank;
    rc = open_series(file, path, "time", &time, &rows, &cols, &rank, err);
    if (rc != BK_OK)
        return mark_damaged(err, path, "/time");
    close_id(time);
    if (rank != 1)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /time has rank %d, not 1", path, rank);
    name_list list;
    if (list_series(file, &list) != 0)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: cannot list the datasets", path);
    /* Shapes first: a short series is named as such rather than as a read error. */
    for (size_t k = 0; rc == BK_OK && k < list.count; ++k) {
        hid_t d;
        hsize_t r, c;
        int rk;
        if (open_series(file, path, list.names[k], &d, &r, &c, &rk, err) != BK_OK) {
            rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s cannot be read", path, list.names[k]);
            continue;
        }
        close_id(d);
        int per_block = rk == 2 && strcmp(list.names[k], "friction_state") != 0;
        if (r != rows)
            rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s has %llu rows, /time has %llu", path,
                         list.names[k], (unsigned long long)r, (unsigned long long)rows);
        else if (per_block && (long long)c != v.n_blocks)
            rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s has %llu columns for %lld blocks", path,
                         list.names[k], (unsigned long long)c, v.n_blocks);
    }
    /* /time before the others, so that its own faults are named first. */
    if (rc == BK_OK)
        rc = scan_series(file, &v, "time", err);
    for (size_t k = 0; rc == BK_OK && k < list.count; ++k)
        if (strcmp(list.names[k], "time") != 0)
            rc = scan_series(file, &v, list.names[k], err);
    name_list_free(&list);
    if (rc == BK_OK && H5Lexists(file, "transitions", H5P_DEFAULT) > 0)
        rc = scan_transitions(file, &v, err);
    if (rc == BK_OK && H5Lexists(file, "checkpoint", H5P_DEFAULT) > 0) {
        bk_checkpoint cp;
        checkpoint_record rec;
        int slot, legacy;
        bk_error why = {0};
        int found = find_checkpoint(file, path, (size_t)v.n_blocks, SIZE_MAX, &cp, &rec, &slot,
                                    &legacy, &why);
        if (found == BK_OK)
            bk_checkpoint_free(&cp);
        else if (!legacy && found != BK_ERR_INVALID) /* no damage: an older bksim's checkpoint
                                                        cannot be verified; a first one torn */
            rc = BK_FAIL(err, found, "%s", why.message);
    }
    if (rc != BK_OK)
        return rc;
    return v.complete ? BK_OK : BK_INCOMPLETE;
}

int bk_h5_verify(const char *path, bk_error *err)
{
    hid_t file;
    int rc = open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    rc = verify_open(file, path, err);
    close_id(file);
    return rc;
}

int bk_h5_info(const char *path, FILE *out, bk_error *err)
{
    hid_t file;
    int rc = open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    long long n_blocks = 0;
    rc = read_n_blocks(file, path, &n_blocks, err);
    long *stick = NULL, *slip = NULL;
    long total = 0;
    int have_transitions = 0;
    if (rc == BK_OK) {
        stick = calloc((size_t)n_blocks, sizeof *stick);
        slip = calloc((size_t)n_blocks, sizeof *slip);
        if (!stick || !slip)
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    }
    /* Phases that cannot be counted (a damaged /transitions) still leave a summary; the
     * integrity check below names the damage. */
    bk_error phase_err = {0};
    int phases = rc == BK_OK ? count_phases(file, path, (size_t)n_blocks, stick, slip, &total,
                                            &have_transitions, &phase_err)
                             : rc;
    if (phases == BK_ERR_NOMEM) {
        rc = phases;
        if (err)
            *err = phase_err;
    }
    if (rc != BK_OK) {
        free(stick);
        free(slip);
        close_id(file);
        return rc;
    }

    char *name = read_string_attr(file, "config_name");
    char *version = read_string_attr(file, "version");
    char *config = read_string_attr(file, "config");
    char *error = read_string_attr(file, "error");
    int complete = 0;
    double t_end = NAN, t_reached = NAN;
    int have_complete = read_numeric_attr(file, "complete", H5T_NATIVE_INT, &complete) >= 0;
    read_numeric_attr(file, "t_end", H5T_NATIVE_DOUBLE, &t_end);
    read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &t_reached);
    hsize_t rows = 0, cols;
    int rank;
    hid_t time;
    int have_rows = H5Lexists(file, "time", H5P_DEFAULT) > 0 &&
                    open_series(file, path, "time", &time, &rows, &cols, &rank, NULL) == BK_OK;
    if (have_rows)
        close_id(time);

    fprintf(out, "file         %s\n", path);
    fprintf(out, "config name  %s\n", name ? name : "?");
    fprintf(out, "version      %s\n", version ? version : "?");
    if (have_complete)
        fprintf(out, "complete     %d%s\n", complete, complete ? "" : " (run did not finish)");
    else
        fprintf(out, "complete     ?\n");
    if (error)
        fprintf(out, "error        %s\n", error);
    fprintf(out, "t_end        %.9g s\n", t_end);
    fprintf(out, "t_reached    %.9g s\n", t_reached);
    fprintf(out, "n_blocks     %lld\n", n_blocks);
    if (have_rows)
        fprintf(out, "rows         %llu\n", (unsigned long long)rows);
    else
        fprintf(out, "rows         ? (no /time)\n");
    fprintf(out, "config:\n");
    print_indented(out, config ? config : "(not stored)");
    if (phases != BK_OK) {
        fprintf(out, "phases per block: not counted (%s)\n", phase_err.message);
    } else {
        fprintf(out, "phases per block:\n");
        for (long long i = 0; i < n_blocks; ++i)
            fprintf(out, "    block %lld: %ld stick, %ld slip\n", i, stick[i], slip[i]);
    }
    if (phases != BK_OK && have_transitions)
        fprintf(out, "transitions  %ld (not all readable)\n", total);
    else if (have_transitions)
        fprintf(out, "transitions  %ld\n", total);
    else
        fprintf(out, "transitions  not recorded\n");
    print_stats(file, out);
    bk_error check = {0};
    int integrity = verify_open(file, path, &check);
    if (integrity == BK_OK)
        fprintf(out, "integrity    ok\n");
    else if (integrity == BK_INCOMPLETE)
        fprintf(out, "integrity    intact, but the run did not finish (complete = 0)\n");
    else
        fprintf(out, "integrity    DAMAGED: %s\n", check.message);

    free(name);
    free(version);
    free(config);
    free(error);
    free(stick);
    free(slip);
    close_id(file);
    if (ferror(out))
        return BK_FAIL(err, BK_ERR_IO, "%s: writing the summary failed", path);
    if (integrity < 0 && err)
        *err = check;
    return integrity;
}

/* ----------------------------------------------------------------------- export --- */

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
        close_id(s[i].dset);
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
    int rc = open_series(file, path, s->name, &s->dset, &s->rows, &cols, &s->rank, err);
    if (rc != BK_OK)
        return rc;
    char *units = read_string_attr(s->dset, "units");
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
    static const char *const defaults = "time,driver,x,v,friction,cof,mode";
    name_list available;
    *out = NULL;
    *count = 0;
    if (list_series(file, &available) < 0)
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
    name_list_free(&available);
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
                if (read_block(s[i].dset, s[i].rank, start, count, s[i].first_col, s[i].n_read,
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

static int export_transitions(hid_t file, const char *path, long block, FILE *out,
                              bk_error *err)
{
    hid_t dset, mem;
    hsize_t count;
    int rc = open_transitions(file, path, &dset, &mem, &count, err);
    if (rc != BK_OK)
        return rc;
    bk_transition *buf = malloc(TRANSITION_BUFFER * sizeof *buf);
    if (!buf)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    else
        fprintf(out, "# t[s] block[1] from[1] to[1] x[m] v[m/s] force[N]\n");
    for (hsize_t start = 0; rc == BK_OK && start < count; start += TRANSITION_BUFFER) {
        size_t n = (size_t)(count - start);
        if (n > TRANSITION_BUFFER)
            n = TRANSITION_BUFFER;
        if (read_block(dset, 1, start, n, 0, 1, mem, buf) < 0) {
            rc = H5_FAIL(err, "%s: cannot read /transitions", path);
            break;
        }
        for (size_t k = 0; k < n; ++k) {
            const bk_transition *t = &buf[k];
            if (block >= 0 && t->block != block)
                continue;
            fprintf(out, "%.17g %d %d %d %.17g %.17g %.17g\n", t->t, (int)t->block,
                    (int)t->from, (int)t->to, t->x, t->v, t->force);
        }
    }
    free(buf);
    CLOSE_IDS(0, mem, dset);
    return rc;
}

int bk_h5_export(const char *path, const char *datasets, long block, int transitions,
                 FILE *out, bk_error *err)
{
    if (!out)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_export: no output stream");
    hid_t file;
    int rc = open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    long long n_blocks;
    rc = read_n_blocks(file, path, &n_blocks, err);
    if (rc == BK_OK && (block < -1 || block >= n_blocks))
        rc = BK_FAIL(err, BK_ERR_INVALID,
                     "block %ld out of range: %s has %lld block%s (allowed: 0..%lld)",
                     block, path, n_blocks, n_blocks == 1 ? "" : "s", n_blocks - 1);
    if (rc == BK_OK)
        rc = transitions ? export_transitions(file, path, block, out, err)
                         : export_series_table(file, path, datasets, block, n_blocks, out, err);
    close_id(file);
    if (rc == BK_OK && (fflush(out) != 0 || ferror(out)))
        rc = BK_FAIL(err, BK_ERR_IO, "%s: writing the export failed", path);
    return rc;
}
