/* Reading output files: opening one with a message that says what is wrong, numeric series
 * and /transitions by blocks of rows, the list of datasets, the stored config, and the
 * whole-dataset readers of the public API (bk_h5_read_doubles, bk_h5_read_transitions). */
#include "bksim/inspect.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "capacity.h"
#include "output/h5_impl.h"
#include "paths.h"

int bk_h5_open_input(const char *path, hid_t *file, bk_error *err)
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
    htri_t is_hdf5 = bk_h5_has_signature(path);
    if (is_hdf5 == 0)
        return BK_FAIL(err, BK_ERR_HDF5, "%s: not an HDF5 file (no HDF5 signature found)",
                       path);
    if (is_hdf5 < 0)
        return H5_FAIL(err, "%s: cannot read", path);
    if (bk_output_write_locked(path))
        return BK_FAIL(err, BK_ERR_IO,
                       "%s: a run is still writing this file (it holds the file's lock): read it "
                       "when the run has finished; `bksim info` shows its progress now", path);
    *file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    int partial = bk_output_is_part(path);
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

void bk_h5_name_list_free(bk_h5_name_list *list)
{
    for (size_t i = 0; i < list->count; ++i)
        free(list->names[i]);
    free(list->names);
    list->names = NULL;
    list->count = 0;
}

/* Root datasets a time-series export can print (numeric, 1-D or 2-D), in creation order
 * when the file tracks it (ours do), else by name. */
int bk_h5_list_series(hid_t file, bk_h5_name_list *list)
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
            bk_h5_close_id(obj);
        }
        if (keep)
            list->names[list->count++] = name;
        else
            free(name);
    }
    return 0;
fail:
    bk_h5_name_list_free(list);
    return -1;
}

/* Opens a numeric 1-D or 2-D dataset and reports its shape. */
int bk_h5_open_series(hid_t file, const char *path, const char *name, hid_t *dset,
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
        bk_h5_close_id(d);
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
herr_t bk_h5_read_block_xfer(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t col,
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

herr_t bk_h5_read_block(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t col,
                         hsize_t ncols, hid_t mem_type, void *buf)
{
    return bk_h5_read_block_xfer(dset, rank, start, count, col, ncols, mem_type, buf, H5P_DEFAULT);
}

/* First-dimension chunk size of a chunked dataset; 0 when not chunked. */
hsize_t bk_h5_chunk_rows(hid_t dset)
{
    hid_t dcpl = H5Dget_create_plist(dset);
    hsize_t chunk[2] = {0, 0};
    if (dcpl < 0 || H5Pget_layout(dcpl) != H5D_CHUNKED || H5Pget_chunk(dcpl, 2, chunk) < 1)
        chunk[0] = 0;
    CLOSE_IDS(0, dcpl);
    return chunk[0];
}

hsize_t bk_h5_slab_rows(hid_t dset, hsize_t cols)
{
    hsize_t chunk = bk_h5_chunk_rows(dset);
    if (chunk == 0)
        chunk = 1;
    hsize_t chunks = EXPORT_BUDGET / (chunk * (cols ? cols : 1));
    return chunk * (chunks ? chunks : 1);
}

int bk_h5_read_doubles(const char *path, const char *dataset, double **data, size_t *rows,
                       size_t *cols, bk_error *err)
{
    if (!data || !rows || !cols || !dataset)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_read_doubles: missing argument");
    *data = NULL;
    *rows = *cols = 0;
    hid_t file, dset;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    hsize_t r, c;
    int rank;
    rc = bk_h5_open_series(file, path, dataset, &dset, &r, &c, &rank, err);
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
        bk_h5_close_id(dset);
    }
    bk_h5_close_id(file);
    return rc;
}

/* Opens /transitions and its memory type; count = rows. */
int bk_h5_open_transitions(hid_t file, const char *path, hid_t *dset, hid_t *mem,
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
    else if ((*mem = bk_h5_transition_type(BK_H5_RECORD_STRUCT)) < 0)
        rc = H5_FAIL(err, "%s: cannot build the transition type", path);
    bk_h5_close_id(space);
    if (rc != BK_OK) {
        bk_h5_close_id(*dset);
        *dset = H5I_INVALID_HID;
        return rc;
    }
    *count = dims[0];
    return BK_OK;
}

/* Rows [0, count) of the 1-D table dset (`table` names it in messages), `buffer_rows` of
 * `row_size` bytes at a time through visit_row; closes mem and dset. */
typedef int (*row_visit)(const void *row, unsigned long long index, void *user, bk_error *err);

static int each_row(hid_t dset, hid_t mem, hsize_t count, size_t row_size, size_t buffer_rows,
                    const char *path, const char *table, row_visit visit_row, void *user,
                    bk_error *err)
{
    int rc = BK_OK;
    char *buf = malloc(buffer_rows * row_size);
    if (!buf)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    for (hsize_t start = 0; rc == BK_OK && start < count; start += buffer_rows) {
        size_t n = count - start < buffer_rows ? (size_t)(count - start) : buffer_rows;
        if (bk_h5_read_block(dset, 1, start, n, 0, 1, mem, buf) < 0) {
            rc = H5_DAMAGED(err, "%s: damaged: %s rows %llu..%llu cannot be read", path, table,
                            (unsigned long long)start, (unsigned long long)(start + n - 1));
            break;
        }
        for (size_t k = 0; rc == BK_OK && k < n; ++k)
            rc = visit_row(buf + k * row_size, (unsigned long long)(start + k), user, err);
    }
    free(buf);
    CLOSE_IDS(0, mem, dset);
    return rc;
}

typedef struct transition_visitor {
    bk_h5_transition_visit visit;
    void *user;
} transition_visitor;

static int visit_transition(const void *row, unsigned long long index, void *user, bk_error *err)
{
    const transition_visitor *v = user;
    return v->visit(row, index, v->user, err);
}

int bk_h5_each_transition(hid_t file, const char *path, bk_h5_transition_visit visit, void *user,
                          hsize_t *count, bk_error *err)
{
    hid_t dset, mem;
    int rc = bk_h5_open_transitions(file, path, &dset, &mem, count, err);
    if (rc != BK_OK)
        return rc;
    transition_visitor v = {visit, user};
    return each_row(dset, mem, *count, sizeof(bk_transition), TRANSITION_BUFFER, path,
                    "/transitions", visit_transition, &v, err);
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
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    rc = bk_h5_open_transitions(file, path, &dset, &mem, &n, err);
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
    bk_h5_close_id(file);
    return rc;
}

int bk_h5_read_n_blocks(hid_t file, const char *path, long long *n_blocks, bk_error *err)
{
    if (bk_h5_read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, n_blocks) < 0 || *n_blocks < 1)
        return BK_FAIL(err, BK_ERR_HDF5,
                       "%s: no valid root attribute n_blocks (not a bksim output file?)", path);
    return BK_OK;
}

/* The datasets the writer created, from the root attribute "datasets"; NULL for a file
 * written before it was recorded.  Malloc'ed, comma-separated. */
char *bk_h5_recorded_datasets(hid_t file)
{
    return bk_h5_read_string_attr(file, "datasets");
}

/* Every name in the comma-separated list is a link in file; else BK_ERR_DAMAGED. */
int bk_h5_require_datasets(hid_t file, const char *path, const char *names, bk_error *err)
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

int bk_h5_read_config(const char *path, bk_config **config, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    *config = NULL;
    if (bk_h5_has_signature(path) <= 0)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: no such HDF5 file", path);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0)
        return H5_FAIL(err, "%s: cannot open", path);
    int rc = bk_h5_load_stored_config(file, path, config, err);
    bk_h5_close_id(file);
    return rc;
}

int bk_h5_load_stored_config(hid_t file, const char *path, bk_config **config, bk_error *err)
{
    return bk_h5_load_stored_config_with(file, path, NULL, config, err);
}

/* The config a run stored (file text and --set overrides, any number of them), and extra
 * after them when given. */
int bk_h5_load_stored_config_with(hid_t file, const char *path, const char *extra, bk_config **config,
                                  bk_error *err)
{
    *config = NULL;
    char *text = bk_h5_read_string_attr(file, "config_file");
    char *name = bk_h5_read_string_attr(file, "config_name");
    char *overrides = bk_h5_read_string_attr(file, "overrides");
    const char **list = NULL;
    size_t n_over = 0, cap = 0;
    int rc = BK_OK;
    if (!text || !name)
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: no stored config to restart with", path);
    char *save = NULL;
    for (char *line = rc == BK_OK && overrides ? strtok_r(overrides, "\n", &save) : NULL; line;
         line = strtok_r(NULL, "\n", &save)) {
        const char **grown = bk_grow_array(list, &cap, n_over + 1, sizeof *grown, 16);
        if (!grown) {
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for the stored overrides", path);
            break;
        }
        list = grown;
        list[n_over++] = line;
    }
    if (rc == BK_OK && extra) {
        const char **grown = bk_grow_array(list, &cap, n_over + 1, sizeof *grown, 16);
        if (grown) {
            list = grown;
            list[n_over++] = extra;
        } else {
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory for the stored overrides", path);
        }
    }
    if (rc == BK_OK)
        rc = bk_config_load_string(text, name, list, n_over, config, err);
    free(list);
    free(text);
    free(name);
    free(overrides);
    return rc;
}

int bk_h5_open_events(hid_t file, const char *path, hid_t *dset, hid_t *mem, hsize_t *count,
                      bk_error *err)
{
    *dset = *mem = H5I_INVALID_HID;
    htri_t exists = H5Lexists(file, "events", H5P_DEFAULT);
    if (exists < 0)
        return H5_FAIL(err, "%s: cannot look for /events", path);
    if (exists == 0)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: no /events table (the event catalog of a chain run with [output] "
                       "events = true, the default; prescribed scenes have none)",
                       path);
    hid_t d = H5Dopen2(file, "events", H5P_DEFAULT);
    if (d < 0)
        return H5_FAIL(err, "%s: /events is not a readable dataset", path);
    hid_t type = H5Dget_type(d), space = H5Dget_space(d);
    hsize_t dims[1] = {0};
    int rc = BK_OK;
    if (type < 0 || space < 0)
        rc = H5_DAMAGED(err, "%s: cannot read the type and shape of /events", path);
    else if (H5Tget_class(type) != H5T_COMPOUND || H5Sget_simple_extent_ndims(space) != 1 ||
             H5Sget_simple_extent_dims(space, dims, NULL) < 0)
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: /events is not a 1-D compound table", path);
    if (rc == BK_OK && (*mem = bk_h5_event_type(BK_H5_RECORD_STRUCT)) < 0)
        rc = H5_FAIL(err, "%s: cannot build the event type", path);
    /* Every field of bksim's catalog (the memory type's members) must be in the file. */
    int n_fields = rc == BK_OK ? H5Tget_nmembers(*mem) : 0;
    for (int k = 0; rc == BK_OK && k < n_fields; ++k) {
        char *name = H5Tget_member_name(*mem, (unsigned)k);
        if (!name || H5Tget_member_index(type, name) < 0)
            rc = BK_FAIL(err, BK_ERR_INVALID,
                         "%s: /events has no field '%s' (not a catalog written by bksim)", path,
                         name ? name : "?");
        H5free_memory(name);
    }
    CLOSE_IDS(0, space, type);
    if (rc != BK_OK) {
        bk_h5_close_id(*mem);
        *mem = H5I_INVALID_HID;
        bk_h5_close_id(d);
        return rc;
    }
    *dset = d;
    *count = dims[0];
    return BK_OK;
}

typedef struct event_visitor {
    bk_h5_event_visit visit;
    void *user;
} event_visitor;

static int visit_event(const void *row, unsigned long long index, void *user, bk_error *err)
{
    const event_visitor *v = user;
    return v->visit(row, index, v->user, err);
}

int bk_h5_each_event(hid_t file, const char *path, bk_h5_event_visit visit, void *user,
                     hsize_t *count, bk_error *err)
{
    hid_t dset, mem;
    int rc = bk_h5_open_events(file, path, &dset, &mem, count, err);
    if (rc != BK_OK)
        return rc;
    event_visitor v = {visit, user};
    return each_row(dset, mem, *count, sizeof(bk_event), EVENT_BUFFER, path, "/events",
                    visit_event, &v, err);
}

int bk_h5_read_events(const char *path, bk_event **rows, size_t *count, bk_error *err)
{
    if (!rows || !count)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_read_events: missing argument");
    *rows = NULL;
    *count = 0;
    hid_t file, dset = H5I_INVALID_HID, mem = H5I_INVALID_HID;
    hsize_t n = 0;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    rc = bk_h5_open_events(file, path, &dset, &mem, &n, err);
    bk_event *values = NULL;
    if (rc == BK_OK && !(values = n > SIZE_MAX / sizeof *values ? NULL : calloc(n ? (size_t)n : 1, sizeof *values)))
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory reading /events", path);
    else if (rc == BK_OK && n > 0 && H5Dread(dset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) < 0)
        rc = H5_FAIL(err, "%s: cannot read /events", path);
    if (rc == BK_OK) {
        *rows = values;
        *count = (size_t)n;
    } else {
        free(values);
    }
    CLOSE_IDS(rc, mem, dset, file);
    return rc;
}

/* A whole rupture table of kind (its C records); BK_ERR_INVALID when the file has none. */
static int read_rupture_table(const char *path, bk_h5_table_kind kind, void **rows, size_t *count, bk_error *err)
{
    const char *name = bk_h5_tables[kind].name;
    if (!rows || !count)
        return BK_FAIL(err, BK_ERR_INVALID, "reading /%s: missing argument", name);
    *rows = NULL;
    *count = 0;
    hid_t file, dset = H5I_INVALID_HID, mem = H5I_INVALID_HID, space = H5I_INVALID_HID;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0)
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: no /%s table (the rupture catalog of a chain run with [output] "
                     "events = true%s)", path, name,
                     kind == BK_TABLE_RUPTURE_RATE ? " and [catalog] rupture_rate = true" : "");
    hsize_t n = 0;
    if (rc == BK_OK) {
        dset = H5Dopen2(file, name, H5P_DEFAULT);
        space = dset < 0 ? H5I_INVALID_HID : H5Dget_space(dset);
        mem = bk_h5_table_type(kind, BK_H5_RECORD_STRUCT);
        if (space < 0 || mem < 0 || H5Sget_simple_extent_ndims(space) != 1 ||
            H5Sget_simple_extent_dims(space, &n, NULL) < 0)
            rc = H5_DAMAGED(err, "%s: damaged: /%s cannot be read", path, name);
    }
    size_t size = bk_h5_tables[kind].struct_bytes;
    void *values = NULL;
    if (rc == BK_OK && !(values = n > SIZE_MAX / size ? NULL : calloc(n ? (size_t)n : 1, size)))
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory reading /%s", path, name);
    else if (rc == BK_OK && n > 0 && H5Dread(dset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) < 0)
        rc = H5_DAMAGED(err, "%s: damaged: /%s cannot be read (not bksim's rupture table?)", path, name);
    if (rc == BK_OK) {
        *rows = values;
        *count = (size_t)n;
    } else {
        free(values);
    }
    CLOSE_IDS(rc, space, mem, dset, file);
    return rc;
}

int bk_h5_read_ruptures(const char *path, bk_rupture **rows, size_t *count, bk_error *err)
{
    return read_rupture_table(path, BK_TABLE_RUPTURES, (void **)rows, count, err);
}

int bk_h5_read_rupture_blocks(const char *path, bk_rupture_block **rows, size_t *count, bk_error *err)
{
    return read_rupture_table(path, BK_TABLE_RUPTURE_BLOCKS, (void **)rows, count, err);
}

int bk_h5_read_rupture_rate(const char *path, bk_rupture_rate **rows, size_t *count, bk_error *err)
{
    return read_rupture_table(path, BK_TABLE_RUPTURE_RATE, (void **)rows, count, err);
}
