/* The streaming writer: a bk_sink that buffers a chunk's worth of rows and appends them to
 * extendable datasets of "<path>.part", renamed to <path> once the run is complete.  The
 * datasets come from the layout table (layout.h); checkpoint slots are written by
 * h5_checkpoint.c, which also reopens a stopped run's file to continue it. */
#include "bksim/output.h"

#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bksim/bksim.h"
#include "output/h5_impl.h"
#include "paths.h"

/* Shuffle + deflate at this level; 0 writes unfiltered chunks.  Off because it costs more
 * than it saves when output is dense: on stick-slip-like data level 1 shrank files to
 * ~0.35 of raw but cut write throughput from ~300-600 MB/s to ~40-95 MB/s (about 3.5 us
 * per row at N = 3 with 512-row chunks, 30 us per row at N = 100), the same order as the
 * integration itself.  `h5repack -f SHUF -f GZIP=1` compresses a finished file. */
#define DEFLATE_LEVEL 0u
/* Appended bytes between two write-behinds: the final fsync of case B's 41 MB took 20 ms
 * of a 0.13 s run; with the disk writing behind the run it waits for the last few MB. */
#define WRITE_BEHIND_BYTES ((size_t)8 << 20)

static double wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
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

/* /parameters/<section>.<key>: every block's value of a key given as a distribution, so that
 * the run can be analysed, and its heterogeneity seen, without the config and its seed. */
static int write_parameters(bk_h5_writer *w, const bk_config *config, bk_error *err)
{
    if (config->n_parameters == 0)
        return BK_OK;
    hid_t group = H5Gcreate2(w->file, "parameters", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int rc = group >= 0 ? BK_OK : H5_FAIL(err, "%s: cannot create group /parameters", w->part);
    for (size_t k = 0; rc == BK_OK && k < config->n_parameters; ++k) {
        const bk_block_parameter *p = &config->parameters[k];
        hsize_t n = (hsize_t)p->n_blocks;
        hid_t space = H5Screate_simple(1, &n, NULL);
        hid_t dset = space >= 0 ? H5Dcreate2(group, p->name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT,
                                             H5P_DEFAULT)
                                : -1;
        char description[BK_PARAMETER_NAME_LEN + 256];
        snprintf(description, sizeof description, "the value of %s of every block, where the config gives a "
                 "distribution (drawn at load time from [model] seed) or a profile (linear, file) (NaN: the "
                 "block's law has no such key)",
                 p->name);
        if (dset < 0 || H5Dwrite(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, p->values) < 0 ||
            bk_h5_describe(dset, p->unit, description) < 0)
            rc = H5_FAIL(err, "%s: cannot write /parameters/%s", w->part, p->name);
        CLOSE_IDS(rc == BK_OK ? 0 : -1, dset, space);
    }
    CLOSE_IDS(rc == BK_OK ? 0 : -1, group);
    return rc;
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

/* The catalog tables a run of this config writes (BK_CATALOG_*). */
static unsigned catalog_mask(const bk_config *config)
{
    if (!config->output.events)
        return 0u;
    return BK_CATALOG_EVENTS | BK_CATALOG_RUPTURES | (config->catalog.rupture_rate ? BK_CATALOG_RUPTURE_RATE : 0u);
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

    if (bk_h5_write_string_attr(w->file, "config", config->text) < 0 ||
        bk_h5_write_string_attr(w->file, "config_name", config->source_name) < 0 ||
        bk_h5_write_string_attr(w->file, "version", BKSIM_VERSION) < 0 ||
        bk_h5_write_long_attr(w->file, "n_blocks", (long long)model->n_blocks) < 0 ||
        bk_h5_write_long_attr(w->file, "rows", (long long)model->rows) < 0 ||
        bk_h5_write_long_attr(w->file, "cols", (long long)model->cols) < 0 ||
        bk_h5_write_double_attr(w->file, "t_end", config->t_end) < 0 ||
        bk_h5_write_int_attr(w->file, "complete", 0) < 0 ||
        bk_h5_write_double_attr(w->file, "t_reached", 0.0) < 0 ||
        bk_h5_write_string_attr(w->file, "attribute_units", "t_end: s, t_reached: s") < 0)
        return H5_FAIL(err, "%s: cannot write root attributes", w->part);
    /* Where and from which numbers a run came, so that one point of a sweep can be rerun. */
    char host[256] = "";
    if (gethostname(host, sizeof host - 1) != 0)
        snprintf(host, sizeof host, "unknown");
    if (bk_h5_write_string_attr(w->file, "host", host) < 0 ||
        bk_h5_write_long_attr(w->file, "seed", (long long)config->seed) < 0)
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
    herr_t stored = bk_h5_write_string_attr(w->file, "config_file", config->file_text ? config->file_text : config->text);
    if (stored >= 0)
        stored = bk_h5_write_string_attr(w->file, "overrides", overrides);
    free(overrides);
    char names[BK_DATASET_LIST_LEN];
    bk_output_dataset_names(fields, n_state, bk_model_is_damped(model), config->output.transitions,
                            catalog_mask(config), names,
                            sizeof names);
    if (stored >= 0)
        stored = bk_h5_write_string_attr(w->file, "datasets", names);
    if (stored < 0)
        return H5_FAIL(err, "%s: cannot write root attributes", w->part);

    w->max_bytes = config->output.max_bytes > 0.0 ? config->output.max_bytes : INFINITY;
    /* The sample rows bksim check announces; event rows cannot be foreseen. */
    double rows = 0.0, row_bytes = 0.0, per_second = 0.0, transition_bytes = 0.0;
    bk_config_output_estimate(config, &rows, &row_bytes, &per_second, &transition_bytes);
    bk_h5_writer_size(w, model, rows);
    for (int i = 0; i < BK_N_SERIES; ++i) {
        const bk_series_def *def = &bk_series[i];
        bk_h5_series *s = &w->s[i];
        if (!bk_series_selected(def, fields, n_state, bk_model_is_damped(model)))
            continue;
        if (bk_h5_writer_series(w, i, model, 0) < 0)
            return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for the /%s buffer", w->part,
                           def->name);
        s->dset = create_extendable(w->file, def->name, bk_h5_kind_file_type(def->kind), s->rank,
                                    (hsize_t)s->cols, (hsize_t)s->rows);
        if (s->dset < 0)
            return H5_FAIL(err, "%s: cannot create dataset /%s", w->part, def->name);
        if (bk_h5_describe(s->dset, def->units, def->description) < 0)
            return H5_FAIL(err, "%s: cannot write attributes of /%s", w->part, def->name);
        if (i == BK_SERIES_STATE && write_state_blocks(s->dset, model) < 0)
            return H5_FAIL(err, "%s: cannot write attribute /friction_state/block", w->part);
    }

    unsigned catalogs = catalog_mask(config);
    const int wanted[BK_N_TABLES] = {config->output.transitions, (catalogs & BK_CATALOG_EVENTS) != 0,
                                     (catalogs & BK_CATALOG_RUPTURES) != 0, (catalogs & BK_CATALOG_RUPTURES) != 0,
                                     (catalogs & BK_CATALOG_RUPTURE_RATE) != 0};
    for (int k = 0; k < BK_N_TABLES; ++k) {
        bk_h5_table *t = &w->tables[k];
        const bk_h5_table_def *def = &bk_h5_tables[k];
        if (!wanted[k])
            continue;
        if (bk_h5_writer_table(t, (bk_h5_table_kind)k) < 0)
            return t->buf ? H5_FAIL(err, "%s: cannot create dataset /%s", w->part, def->name)
                          : BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for the /%s buffer",
                                    w->part, def->name);
        hid_t disk = bk_h5_table_type((bk_h5_table_kind)k, BK_H5_RECORD_FILE);
        if (disk >= 0)
            t->dset = create_extendable(w->file, def->name, disk, 1, 1, (hsize_t)t->capacity);
        CLOSE_IDS(t->dset, disk);
        if (t->dset < 0)
            return H5_FAIL(err, "%s: cannot create dataset /%s", w->part, def->name);
        if (bk_h5_describe(t->dset, def->units, def->description) < 0)
            return H5_FAIL(err, "%s: cannot write attributes of /%s", w->part, def->name);
    }
    int rc = write_parameters(w, config, err);
    if (rc != BK_OK)
        return rc;
    /* The variable-length strings above go to disk now, once: nothing rewrites them later
     * (see bk_h5_write_fixed_string_attr). */
    if (H5Fflush(w->file, H5F_SCOPE_LOCAL) < 0)
        return H5_FAIL(err, "%s: cannot flush", w->part);
    haddr_t eoa = 0;
    w->eoa_committed = H5Fget_eoa(w->file, &eoa) >= 0 ? (double)eoa : 0.0;
    return BK_OK;
}

/* Close every id the writer holds; -1 if any close failed.
 *
 * The file id goes first, while the datasets still hold the file open, so that H5Fclose
 * only drops the id and the real close (the final flush) happens in the last H5Dclose.
 * HDF5 1.10 keeps a file id whose close failed (disk full) pointing at freed memory and
 * crashes when H5close() tries it again at exit; H5Dclose always releases its id.  Write
 * errors are caught before this by an explicit H5Fflush. */
herr_t bk_h5_writer_close(bk_h5_writer *w)
{
    herr_t rc = 0;
    if (w->file >= 0 && H5Fclose(w->file) < 0)
        rc = -1;
    w->file = H5I_INVALID_HID;
    if (w->part_fd >= 0)
        close(w->part_fd);
    w->part_fd = -1;
    for (int i = 0; i < BK_N_SERIES; ++i) {
        if (w->s[i].dset >= 0 && H5Dclose(w->s[i].dset) < 0)
            rc = -1;
        w->s[i].dset = H5I_INVALID_HID;
    }
    for (int k = 0; k < BK_N_TABLES; ++k) {
        bk_h5_table *t = &w->tables[k];
        if (t->dset >= 0 && H5Dclose(t->dset) < 0)
            rc = -1;
        if (t->mem >= 0 && H5Tclose(t->mem) < 0)
            rc = -1;
        if (t->packed >= 0 && H5Tclose(t->packed) < 0)
            rc = -1;
        t->dset = t->mem = t->packed = H5I_INVALID_HID;
    }
    return rc;
}

void bk_h5_writer_free(bk_h5_writer *w)
{
    if (w->part_fd >= 0)
        close(w->part_fd);
    for (int i = 0; i < BK_N_SERIES; ++i)
        free(w->s[i].buf);
    for (int k = 0; k < BK_N_TABLES; ++k)
        free(w->tables[k].buf);
    free(w->path);
    free(w->part);
    free(w);
}

int bk_h5_writer_new(bk_h5_writer **out, const char *path, bk_error *err)
{
    *out = NULL;
    bk_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    w->file = H5I_INVALID_HID;
    w->part_fd = -1;
    w->max_bytes = INFINITY;
    for (int k = 0; k < BK_N_TABLES; ++k)
        w->tables[k].dset = w->tables[k].mem = w->tables[k].packed = H5I_INVALID_HID;
    for (int i = 0; i < BK_N_SERIES; ++i)
        w->s[i].dset = H5I_INVALID_HID;
    w->last_commit = wall_seconds();
    w->path = strdup(path);
    w->part = bk_output_part_path(path);
    if (!w->path || !w->part) {
        bk_h5_writer_free(w);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    }
    *out = w;
    return BK_OK;
}

void bk_h5_writer_size(bk_h5_writer *w, const bk_model *model, double expected_rows)
{
    size_t n_state = model->n_friction_state;
    size_t widest = model->n_blocks > n_state ? model->n_blocks : n_state;
    size_t rows = CHUNK_BYTES / (widest * sizeof(double));
    w->n_blocks = model->n_blocks;
    w->buffer_rows = rows < 1 ? 1 : rows > MAX_BUFFER_ROWS ? MAX_BUFFER_ROWS : rows;
    w->expected_rows = expected_rows;
}

/* HDF5 allocates whole chunks: a chunk of a series holds the run's expected rows when they
 * are fewer than a full chunk, but at least MIN_CHUNK_BYTES, so that event rows the estimate
 * could not count do not split a long run into a multitude of tiny chunks. */
#define MIN_CHUNK_BYTES (16u << 10)

int bk_h5_writer_series(bk_h5_writer *w, int i, const bk_model *model, size_t chunk_rows)
{
    const bk_series_def *def = &bk_series[i];
    bk_h5_series *s = &w->s[i];
    s->rank = def->shape == BK_SHAPE_T ? 1 : 2;
    s->cols = bk_series_columns(def, model->n_blocks, model->n_friction_state);
    s->elem = bk_series_value_size(def->kind);
    size_t full = s->rank == 1 ? SERIES_1D_CHUNK : w->buffer_rows;
    size_t row_bytes = s->cols * s->elem, floor_rows = (MIN_CHUNK_BYTES + row_bytes - 1) / row_bytes;
    double wanted = fmax(w->expected_rows, (double)floor_rows);
    s->rows = chunk_rows ? chunk_rows : wanted < (double)full ? (size_t)wanted : full;
    s->buffered = 0;
    s->buf = malloc(s->rows * s->cols * s->elem);
    return s->buf ? 0 : -1;
}

int bk_h5_writer_table(bk_h5_table *table, bk_h5_table_kind kind)
{
    table->record = bk_h5_tables[kind].record_bytes;
    table->capacity = bk_h5_tables[kind].buffer;
    table->buffered = 0;
    table->buf = malloc(table->capacity * table->record);
    if (!table->buf)
        return -1;
    table->mem = bk_h5_table_type(kind, BK_H5_RECORD_STRUCT);
    table->packed = bk_h5_table_type(kind, BK_H5_RECORD_PACKED);
    return table->mem >= 0 && table->packed >= 0 ? 0 : -1;
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
    bk_h5_writer *w;
    int rc = bk_h5_writer_new(&w, path, err);
    if (rc != BK_OK)
        return rc;
    /* Creating truncates before HDF5 would see the other run's lock: ask first. */
    if (bk_output_write_locked(w->part))
        rc = BK_FAIL(err, BK_ERR_IO, BK_OUTPUT_OWNED_MESSAGE, w->part);
    if (rc == BK_OK && (rc = bk_h5_output_replaceable(path, 0, err)) == BK_OK)
        rc = bk_h5_output_replaceable(w->part, 1, err);
    if (rc != BK_OK) {
        bk_h5_writer_free(w);
        return rc;
    }
    rc = bk_output_make_parent_dirs(path, err);
    if (rc != BK_OK) {
        bk_h5_writer_free(w);
        return rc;
    }
    rc = create_layout(w, config, err);
    if (rc != BK_OK) {
        int created = w->file >= 0;
        bk_h5_writer_close(w);
        if (created)
            remove(w->part);
        bk_h5_writer_free(w);
        return rc;
    }
    *out = w;
    return BK_OK;
}

int bk_h5_writer_set_point(bk_h5_writer *writer, const char *point, bk_error *err)
{
    if (!writer || !point || !*point)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_writer_set_point: needs a writer and a non-empty name");
    /* Fixed-length: written after the file was created (see bk_h5_write_fixed_string_attr). */
    if (bk_h5_write_fixed_string_attr(writer->file, "point", point) < 0)
        return H5_FAIL(err, "%s: cannot write the root attribute point", writer->part);
    return BK_OK;
}

int bk_h5_writer_set_init_from(bk_h5_writer *writer, const char *source, double t_source, bk_error *err)
{
    if (!writer || !source)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_writer_set_init_from: needs a writer and a source");
    size_t len = strlen(source) + 96;
    char *text = malloc(len);
    if (!text)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", writer->part);
    snprintf(text, len, "%s, its state at its end t = %.17g s", source, t_source);
    herr_t rc = bk_h5_write_fixed_string_attr(writer->file, "init_from", text);
    free(text);
    return rc < 0 ? H5_FAIL(err, "%s: cannot write the root attribute init_from", writer->part) : BK_OK;
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

/* bytes more reached the page cache: past WRITE_BEHIND_BYTES, the disk starts on them. */
static void appended(bk_h5_writer *w, size_t bytes)
{
    w->unsynced += bytes;
    if (w->unsynced < WRITE_BEHIND_BYTES)
        return;
    w->unsynced = 0;
    if (w->part_fd < 0)
        w->part_fd = open(w->part, O_RDONLY | O_CLOEXEC);
    if (w->part_fd >= 0)
        bk_output_write_behind(w->part_fd);
}

/* The file space count rows appended at row start take: HDF5 allocates whole chunks of
 * chunk_rows rows, the first time a row of one is written. */
static double chunk_bytes_added(hsize_t start, hsize_t count, size_t chunk_rows, size_t row_bytes)
{
    hsize_t allocated = (start + chunk_rows - 1) / chunk_rows, needed = (start + count + chunk_rows - 1) / chunk_rows;
    return (double)(needed - allocated) * (double)chunk_rows * (double)row_bytes;
}

/* Series i's buffered rows to its dataset. */
static int append_series(bk_h5_writer *w, int i, bk_error *err)
{
    bk_h5_series *s = &w->s[i];
    if (s->buffered == 0)
        return BK_OK;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hsize_t start = w->rows - (hsize_t)s->buffered;
    int room = bk_h5_writer_room(w, chunk_bytes_added(start, (hsize_t)s->buffered, s->rows, s->cols * s->elem), err);
    if (room != BK_OK)
        return room;
    if (append(s->dset, s->rank, start, (hsize_t)s->buffered, (hsize_t)s->cols,
               bk_h5_kind_mem_type(bk_series[i].kind), s->buf) < 0) {
        w->failed = 1;
        return H5_FAIL(err, "%s: cannot append rows to /%s", w->part, bk_series[i].name);
    }
    appended(w, s->buffered * s->cols * s->elem);
    s->buffered = 0;
    return BK_OK;
}

static int append_table(bk_h5_writer *w, bk_h5_table *t, const char *name, bk_error *err)
{
    if (t->buffered == 0)
        return BK_OK;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    int room = bk_h5_writer_room(w, chunk_bytes_added(t->written, (hsize_t)t->buffered, t->capacity, t->record), err);
    if (room != BK_OK)
        return room;
    if (append(t->dset, 1, t->written, (hsize_t)t->buffered, 1, t->packed, t->buf) < 0) {
        w->failed = 1;
        return H5_FAIL(err, "%s: cannot append to /%s", w->part, name);
    }
    appended(w, t->buffered * t->record);
    t->written += t->buffered;
    t->buffered = 0;
    return BK_OK;
}

/* Append everything buffered, then flush HDF5's metadata so that a run killed later still
 * leaves a readable .part holding everything up to here, every dataset as long as /time
 * says. */
int bk_h5_writer_flush(bk_h5_writer *w, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    int rc = BK_OK;
    for (int i = 0; rc == BK_OK && i < BK_N_SERIES; ++i)
        if (w->s[i].dset >= 0)
            rc = append_series(w, i, err);
    for (int k = 0; rc == BK_OK && k < BK_N_TABLES; ++k)
        if (w->tables[k].dset >= 0)
            rc = append_table(w, &w->tables[k], bk_h5_tables[k].name, err);
    if (rc != BK_OK)
        return rc;
    w->t_written = w->t_buffered;
    if (bk_h5_write_double_attr(w->file, "t_reached", w->t_written) < 0 ||
        H5Fflush(w->file, H5F_SCOPE_LOCAL) < 0) {
        w->failed = 1;
        return H5_FAIL(err, "%s: cannot flush", w->part);
    }
    w->last_commit = wall_seconds();
    w->uncounted = 0;
    w->unflushed = 0.0;
    haddr_t eoa = 0;
    w->eoa_committed = H5Fget_eoa(w->file, &eoa) >= 0 ? (double)eoa : 0.0;
    w->committed_rows = w->rows;
    for (int k = 0; k < BK_N_TABLES; ++k)
        w->tables[k].committed = w->tables[k].written;
    return BK_OK;
}

/* A commit once COMMIT_INTERVAL of wall-clock time has passed since the last one: what a
 * SIGKILL can lose is bounded in time, and a fast run pays for a handful of commits, not
 * one per chunk.  The clock is read every COMMIT_CHECK_EVERY records. */
static int maybe_commit(bk_h5_writer *w, bk_error *err)
{
    if (++w->uncounted < COMMIT_CHECK_EVERY)
        return BK_OK;
    w->uncounted = 0;
    if (wall_seconds() - w->last_commit < COMMIT_INTERVAL)
        return BK_OK;
    return bk_h5_writer_flush(w, err);
}

/* One value or row of values into series s's buffer (a no-op for a field not written). */
static inline void put_double(bk_h5_series *s, double value)
{
    if (s->dset >= 0)
        ((double *)(void *)s->buf)[s->buffered] = value;
}

static inline void put_row(bk_h5_series *s, const void *values)
{
    if (s->dset < 0)
        return;
    size_t bytes = s->cols * s->elem;
    if (bytes == sizeof(double)) /* one block: a move, not a call */
        memcpy(s->buf + s->buffered * bytes, values, sizeof(double));
    else
        memcpy(s->buf + s->buffered * bytes, values, bytes);
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
    /* Checked before copying anything so a rejected sample leaves no partial row (the
     * scalars are always there). */
    const void *rows[] = {sample->x, sample->v, sample->friction, sample->cof, sample->mode,
                          sample->friction_state};
    static const int row_series[] = {BK_SERIES_X, BK_SERIES_V, BK_SERIES_FRICTION,
                                     BK_SERIES_COF, BK_SERIES_MODE, BK_SERIES_STATE};
    for (size_t k = 0; k < sizeof rows / sizeof *rows; ++k)
        if (w->s[row_series[k]].dset >= 0 && !rows[k])
            return BK_FAIL(err, BK_ERR_INVALID, "%s: sample lacks the values of /%s", w->part,
                           bk_series[row_series[k]].name);
    w->rows++;
    w->t_buffered = sample->t;
    /* Typed stores, field by field: a generic copy per value was a tenth of a dense run. */
    bk_h5_series *s = w->s;
    put_double(&s[BK_SERIES_TIME], sample->t);
    put_double(&s[BK_SERIES_DRIVER], sample->driver);
    if (s[BK_SERIES_EVENT].dset >= 0)
        s[BK_SERIES_EVENT].buf[s[BK_SERIES_EVENT].buffered] = (unsigned char)sample->is_event;
    put_double(&s[BK_SERIES_EKIN], sample->kinetic_energy);
    put_double(&s[BK_SERIES_EEL], sample->elastic_energy);
    put_double(&s[BK_SERIES_WORK], sample->work_driver);
    put_double(&s[BK_SERIES_DISS], sample->dissipation);
    put_double(&s[BK_SERIES_DAMP], sample->damping_dissipation);
    for (size_t k = 0; k < sizeof rows / sizeof *rows; ++k)
        put_row(&s[row_series[k]], rows[k]);
    int rc = BK_OK;
    for (int i = 0; i < BK_N_SERIES; ++i) {
        /* A failed append stops the run; the rows of the other buffers die with it. */
        if (s[i].dset >= 0 && ++s[i].buffered == s[i].rows && rc == BK_OK)
            rc = append_series(w, i, err);
    }
    return rc == BK_OK ? maybe_commit(w, err) : rc;
}

/* One record into table kind's buffer, appended when the buffer is full (maybe_commit:
 * commit decides after the record, so a caller with several records passes commit = 0 for
 * all but the last). */
static int buffer_record(bk_h5_writer *w, bk_h5_table_kind kind, const void *record, int commit, bk_error *err)
{
    bk_h5_table *t = &w->tables[kind];
    bk_h5_pack_record(kind, record, t->buf + t->buffered * t->record);
    int rc = ++t->buffered == t->capacity ? append_table(w, t, bk_h5_tables[kind].name, err) : BK_OK;
    return rc == BK_OK && commit ? maybe_commit(w, err) : rc;
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
    if (w->tables[BK_TABLE_TRANSITIONS].dset < 0)
        return BK_OK;
    w->trans_last_t = transition->t;
    return buffer_record(w, BK_TABLE_TRANSITIONS, transition, 1, err);
}

static int sink_event(void *self, const bk_event *event, bk_error *err)
{
    bk_h5_writer *w = self;
    if (w->failed)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: an earlier write failed; no more events accepted", w->part);
    if (w->tables[BK_TABLE_EVENTS].dset < 0)
        return BK_OK;
    return buffer_record(w, BK_TABLE_EVENTS, event, 1, err);
}

/* A rupture's three parts, its row last: a reader that finds the row finds its blocks and
 * rate (a commit falls only after the whole rupture). */
static int sink_rupture(void *self, const bk_rupture *rupture, const bk_rupture_block *blocks, size_t n_blocks,
                        const bk_rupture_rate *rate, size_t n_rate, bk_error *err)
{
    bk_h5_writer *w = self;
    if (w->failed)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: an earlier write failed; no more ruptures accepted", w->part);
    if (w->tables[BK_TABLE_RUPTURES].dset < 0)
        return BK_OK;
    int rc = BK_OK;
    for (size_t k = 0; rc == BK_OK && k < n_blocks; ++k)
        rc = buffer_record(w, BK_TABLE_RUPTURE_BLOCKS, &blocks[k], 0, err);
    for (size_t k = 0; rc == BK_OK && k < n_rate && w->tables[BK_TABLE_RUPTURE_RATE].dset >= 0; ++k)
        rc = buffer_record(w, BK_TABLE_RUPTURE_RATE, &rate[k], 0, err);
    return rc == BK_OK ? buffer_record(w, BK_TABLE_RUPTURES, rupture, 1, err) : rc;
}

/* Rows up to the checkpoint are flushed first, so the row counts it records are on disk. */
static int sink_checkpoint(void *self, const bk_checkpoint *cp, bk_error *err)
{
    bk_h5_writer *w = self;
    if (w->failed)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: an earlier write failed; no checkpoint", w->part);
    int rc = bk_h5_writer_flush(w, err);
    if (rc != BK_OK)
        return rc;
    /* Its arrays: a few per block, the friction states, the open events' and ruptures'. */
    double bytes = 256.0 * (double)cp->n_blocks + 8.0 * (double)cp->n_state + 64.0 * 1024.0;
    if ((rc = bk_h5_writer_room(w, bytes, err)) != BK_OK)
        return rc;
    bk_checkpoint_record rec = {w->cp_sequence + 1, (long long)w->rows,
                                (long long)w->tables[BK_TABLE_TRANSITIONS].written, w->trans_last_t};
    rc = bk_h5_write_checkpoint(w->file, w->part, w->cp_slot, cp, &rec, err);
    if (rc != BK_OK) {
        w->failed = 1;
        return rc;
    }
    w->cp_sequence = rec.sequence;
    w->cp_slot ^= 1;
    return BK_OK;
}

bk_sink bk_h5_writer_sink(bk_h5_writer *writer)
{
    bk_sink sink = {writer, sink_sample, sink_transition, sink_checkpoint, sink_event, sink_rupture};
    return sink;
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
    bk_h5_write_int_attr(file, "complete", 0);
    bk_h5_write_fixed_string_attr(file, "error", reason);
    H5Fclose(file);
    if (hold >= 0)
        H5Dclose(hold);
}

/* Every dataset back to its length at the last commit (shrinking only writes metadata). */
static void cut_to_commit(bk_h5_writer *w)
{
    for (int i = 0; i < BK_N_SERIES; ++i) {
        hsize_t dims[2] = {w->committed_rows, (hsize_t)w->s[i].cols};
        if (w->s[i].dset >= 0)
            H5Dset_extent(w->s[i].dset, dims);
    }
    for (int k = 0; k < BK_N_TABLES; ++k) {
        hsize_t dims[1] = {w->tables[k].committed};
        if (w->tables[k].dset >= 0)
            H5Dset_extent(w->tables[k].dset, dims);
    }
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
        rc = bk_h5_writer_flush(w, err);
    if (rc == BK_OK && stats && bk_h5_write_stats(w->file, stats) < 0)
        rc = H5_FAIL(err, "%s: cannot write /stats", w->part);
    if (rc == BK_OK) {
        marked = 1;
        /* Flushed here rather than at close, where a failure could not be told apart. */
        if (bk_h5_write_int_attr(w->file, "complete", 1) < 0 ||
            H5Fflush(w->file, H5F_SCOPE_LOCAL) < 0)
            rc = H5_FAIL(err, "%s: cannot write the complete flag", w->part);
    }
    if (rc != BK_OK && w->out_of_room) {
        /* Refused room for its last rows: left as abandon leaves it, at its last commit,
         * incomplete, with the reason. */
        cut_to_commit(w);
        if (stats)
            bk_h5_write_stats(w->file, stats);
        bk_h5_write_double_attr(w->file, "t_reached", w->t_written);
        bk_h5_write_fixed_string_attr(w->file, "error", err ? err->message : "no room for the last rows");
    }
    if (bk_h5_writer_close(w) < 0 && rc == BK_OK)
        rc = H5_FAIL(err, "%s: cannot close", w->part);
    /* Something may have been put at the final name while the run went on. */
    if (rc == BK_OK)
        rc = bk_h5_output_replaceable(w->path, 0, err);
    if (rc == BK_OK)
        rc = bk_output_durable_rename(w->part, w->path, err);
    if (rc != BK_OK && marked)
        mark_incomplete(w->part, err ? err->message : "finishing the output failed");
    bk_h5_writer_free(w);
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
        bk_h5_writer_flush(w, &ignored);
    /* Stopped for room, every write succeeded but the datasets stand where each last
     * appended: back to the last commit, as a reader and a restart expect them. */
    if (w->out_of_room)
        cut_to_commit(w);
    if (stats)
        bk_h5_write_stats(w->file, stats);
    bk_h5_write_int_attr(w->file, "complete", 0);
    bk_h5_write_double_attr(w->file, "t_reached", w->t_written);
    bk_h5_write_fixed_string_attr(w->file, "error", reason ? reason : "run abandoned");
    bk_h5_writer_close(w);
    bk_h5_writer_free(w);
}
