/* HDF5 plumbing shared by the writer, the checkpoint slots and the readers: error messages
 * that keep HDF5's own reason, closing ids without losing it, scalar attributes, and the
 * HDF5 types of the layout's value kinds and of the transition record. */
#include "output/h5_impl.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

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

int bk_h5_fail(bk_error *err, int status, const char *file, int line, const char *func,
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

void bk_h5_close_id(hid_t id)
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

void bk_h5_close_ids(int failed, const hid_t *ids, size_t n)
{
    hid_t stack = failed ? H5Eget_current_stack() : H5I_INVALID_HID;
    for (size_t i = 0; i < n; ++i)
        bk_h5_close_id(ids[i]);
    if (stack >= 0)
        H5Eset_current_stack(stack);
}

/* H5Fis_hdf5 is deprecated from HDF5 1.12 on. */
htri_t bk_h5_has_signature(const char *path)
{
#if H5_VERSION_GE(1, 12, 0)
    return H5Fis_accessible(path, H5P_DEFAULT);
#else
    return H5Fis_hdf5(path);
#endif
}

/* ------------------------------------------------------------------ attributes --- */

/* Create or overwrite a scalar attribute. */
herr_t bk_h5_write_attr(hid_t obj, const char *name, hid_t file_type, hid_t mem_type,
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

herr_t bk_h5_write_string_attr(hid_t obj, const char *name, const char *value)
{
    const char *text = value ? value : "";
    hid_t type = vlen_string_type();
    herr_t rc = type < 0 ? -1 : bk_h5_write_attr(obj, name, type, type, &text);
    CLOSE_IDS(rc, type);
    return rc;
}

/* A fixed-length UTF-8 string attribute, created or replaced.  Every string written after
 * the file is created is one of these: a variable-length string lives in HDF5's global
 * heap, and a kill while a rewrite of the heap is flushed can leave it in a state that
 * HDF5 1.10 reads in an endless loop (seen with the checkpoint's method string, rewritten at
 * every checkpoint: `bksim info` hung).  Fixed-length text sits in the attribute itself,
 * inside the object header, so after the first flush the heap is never written again. */
herr_t bk_h5_write_fixed_string_attr(hid_t obj, const char *name, const char *value)
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
        rc = bk_h5_write_attr(obj, name, type, type, text);
    CLOSE_IDS(rc, type);
    return rc;
}

herr_t bk_h5_write_double_attr(hid_t obj, const char *name, double value)
{
    return bk_h5_write_attr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

herr_t bk_h5_write_int_attr(hid_t obj, const char *name, int value)
{
    return bk_h5_write_attr(obj, name, H5T_STD_I32LE, H5T_NATIVE_INT, &value);
}

herr_t bk_h5_write_long_attr(hid_t obj, const char *name, long long value)
{
    return bk_h5_write_attr(obj, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, &value);
}

herr_t bk_h5_describe(hid_t obj, const char *units, const char *description)
{
    if (bk_h5_write_string_attr(obj, "units", units) < 0)
        return -1;
    return bk_h5_write_string_attr(obj, "description", description);
}

/* The same for objects written after the file was created (see bk_h5_write_fixed_string_attr). */
herr_t bk_h5_describe_fixed(hid_t obj, const char *units, const char *description)
{
    if (bk_h5_write_fixed_string_attr(obj, "units", units) < 0)
        return -1;
    return bk_h5_write_fixed_string_attr(obj, "description", description);
}

/* A string attribute written as variable- or fixed-length; NULL when absent or not a
 * scalar string.  Malloc'ed. */
char *bk_h5_read_string_attr(hid_t obj, const char *name)
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
herr_t bk_h5_read_numeric_attr(hid_t obj, const char *name, hid_t mem_type, void *value)
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

/* ----------------------------------------------------------------------- types --- */

hid_t bk_h5_kind_file_type(bk_series_kind kind)
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

hid_t bk_h5_kind_mem_type(bk_series_kind kind)
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

/* A record's members: where each sits in the C struct and in the packed file row. */
typedef struct record_field {
    const char *name;
    size_t offset, packed_offset;
    int kind; /* 0: double, 1: int32, 2: int8, 3: int64 */
} record_field;

static const record_field transition_fields[] = {
    {"t", offsetof(bk_transition, t), 0, 0},
    {"block", offsetof(bk_transition, block), 8, 1},
    {"from", offsetof(bk_transition, from), 12, 2},
    {"to", offsetof(bk_transition, to), 13, 2},
    {"x", offsetof(bk_transition, x), 14, 0},
    {"v", offsetof(bk_transition, v), 22, 0},
    {"force", offsetof(bk_transition, force), 30, 0},
};

static const record_field event_fields[] = {
    {"t_start", offsetof(bk_event, t_start), 0, 0},
    {"t_end", offsetof(bk_event, t_end), 8, 0},
    {"first_block", offsetof(bk_event, first_block), 16, 1},
    {"n_blocks", offsetof(bk_event, n_blocks), 20, 1},
    {"left", offsetof(bk_event, left), 24, 1},
    {"right", offsetof(bk_event, right), 28, 1},
    {"n_episodes", offsetof(bk_event, n_episodes), 32, 1},
    {"potency", offsetof(bk_event, potency), 36, 0},
    {"magnitude", offsetof(bk_event, magnitude), 44, 0},
    {"max_slip_rate", offsetof(bk_event, max_slip_rate), 52, 0},
    {"stress_drop", offsetof(bk_event, stress_drop), 60, 0},
    {"complete", offsetof(bk_event, complete), 68, 2},
};

static const record_field rupture_fields[] = {
    {"t_start", offsetof(bk_rupture, t_start), 0, 0},
    {"t_end", offsetof(bk_rupture, t_end), 8, 0},
    {"first_block", offsetof(bk_rupture, first_block), 16, 1},
    {"n_blocks", offsetof(bk_rupture, n_blocks), 20, 1},
    {"left", offsetof(bk_rupture, left), 24, 1},
    {"right", offsetof(bk_rupture, right), 28, 1},
    {"n_episodes", offsetof(bk_rupture, n_episodes), 32, 1},
    {"potency", offsetof(bk_rupture, potency), 36, 0},
    {"magnitude", offsetof(bk_rupture, magnitude), 44, 0},
    {"max_slip_rate", offsetof(bk_rupture, max_slip_rate), 52, 0},
    {"stress_drop", offsetof(bk_rupture, stress_drop), 60, 0},
    {"duration", offsetof(bk_rupture, duration), 68, 0},
    {"front_speed_left", offsetof(bk_rupture, front_speed_left), 76, 0},
    {"front_speed_right", offsetof(bk_rupture, front_speed_right), 84, 0},
    {"complete", offsetof(bk_rupture, complete), 92, 2},
};

static const record_field rupture_block_fields[] = {
    {"rupture", offsetof(bk_rupture_block, rupture), 0, 3},
    {"block", offsetof(bk_rupture_block, block), 8, 1},
    {"t_onset", offsetof(bk_rupture_block, t_onset), 12, 0},
    {"t_stop", offsetof(bk_rupture_block, t_stop), 20, 0},
    {"slip", offsetof(bk_rupture_block, slip), 28, 0},
};

static const record_field rupture_rate_fields[] = {
    {"rupture", offsetof(bk_rupture_rate, rupture), 0, 3},
    {"t", offsetof(bk_rupture_rate, t), 8, 0},
    {"rate", offsetof(bk_rupture_rate, rate), 16, 0},
};

#define N_FIELDS(table) (sizeof table / sizeof table[0])

const bk_h5_table_def bk_h5_tables[BK_N_TABLES] = {
    {"transitions", BK_TRANSITIONS_UNITS, BK_TRANSITIONS_DESCRIPTION, BK_TRANSITION_RECORD_BYTES,
     sizeof(bk_transition), TRANSITION_BUFFER},
    {"events", BK_EVENTS_UNITS, BK_EVENTS_DESCRIPTION, BK_EVENT_RECORD_BYTES, sizeof(bk_event), EVENT_BUFFER},
    {"ruptures", BK_RUPTURES_UNITS, BK_RUPTURES_DESCRIPTION, BK_RUPTURE_RECORD_BYTES, sizeof(bk_rupture),
     RUPTURE_BUFFER},
    {"rupture_blocks", BK_RUPTURE_BLOCKS_UNITS, BK_RUPTURE_BLOCKS_DESCRIPTION, BK_RUPTURE_BLOCK_RECORD_BYTES,
     sizeof(bk_rupture_block), RUPTURE_BLOCK_BUFFER},
    {"rupture_rate", BK_RUPTURE_RATE_UNITS, BK_RUPTURE_RATE_DESCRIPTION, BK_RUPTURE_RATE_RECORD_BYTES,
     sizeof(bk_rupture_rate), RUPTURE_RATE_BUFFER},
};

/* Each table's fields, by bk_h5_table_kind. */
static const struct {
    const record_field *fields;
    size_t n;
} table_fields[BK_N_TABLES] = {
    {transition_fields, N_FIELDS(transition_fields)},
    {event_fields, N_FIELDS(event_fields)},
    {rupture_fields, N_FIELDS(rupture_fields)},
    {rupture_block_fields, N_FIELDS(rupture_block_fields)},
    {rupture_rate_fields, N_FIELDS(rupture_rate_fields)},
};

static const size_t kind_size[] = {8, 4, 1, 8};

static hid_t record_type(const record_field *fields, size_t n, size_t struct_size,
                         size_t packed_size, bk_h5_record_layout layout)
{
    int packed = layout != BK_H5_RECORD_STRUCT;
    hid_t type = H5Tcreate(H5T_COMPOUND, packed ? packed_size : struct_size);
    herr_t rc = type < 0 ? -1 : 0;
    for (size_t k = 0; rc >= 0 && k < n; ++k) {
        int file = layout == BK_H5_RECORD_FILE;
        hid_t member = fields[k].kind == 0 ? (file ? H5T_IEEE_F64LE : H5T_NATIVE_DOUBLE)
                       : fields[k].kind == 1 ? (file ? H5T_STD_I32LE : H5T_NATIVE_INT32)
                       : fields[k].kind == 3 ? (file ? H5T_STD_I64LE : H5T_NATIVE_INT64)
                                             : (file ? H5T_STD_I8LE : H5T_NATIVE_INT8);
        rc = H5Tinsert(type, fields[k].name, packed ? fields[k].packed_offset : fields[k].offset, member);
    }
    if (rc < 0) {
        CLOSE_IDS(-1, type);
        return H5I_INVALID_HID;
    }
    return type;
}

static void pack(const record_field *fields, size_t n, const void *record, unsigned char *row)
{
    for (size_t k = 0; k < n; ++k)
        memcpy(row + fields[k].packed_offset, (const char *)record + fields[k].offset,
               kind_size[fields[k].kind]);
}

hid_t bk_h5_transition_type(bk_h5_record_layout layout)
{
    return record_type(transition_fields, N_FIELDS(transition_fields), sizeof(bk_transition),
                       BK_TRANSITION_RECORD_BYTES, layout);
}

hid_t bk_h5_event_type(bk_h5_record_layout layout)
{
    return record_type(event_fields, N_FIELDS(event_fields), sizeof(bk_event), BK_EVENT_RECORD_BYTES,
                       layout);
}

hid_t bk_h5_table_type(bk_h5_table_kind kind, bk_h5_record_layout layout)
{
    return record_type(table_fields[kind].fields, table_fields[kind].n, bk_h5_tables[kind].struct_bytes,
                       bk_h5_tables[kind].record_bytes, layout);
}

void bk_h5_pack_record(bk_h5_table_kind kind, const void *record, unsigned char *row)
{
    pack(table_fields[kind].fields, table_fields[kind].n, record, row);
}

void bk_h5_pack_transition(const bk_transition *transition, unsigned char *row)
{
    pack(transition_fields, N_FIELDS(transition_fields), transition, row);
}

void bk_h5_pack_event(const bk_event *event, unsigned char *row)
{
    pack(event_fields, N_FIELDS(event_fields), event, row);
}

herr_t bk_h5_write_stats(hid_t file, const bk_run_stats *stats)
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
    if (bk_h5_write_fixed_string_attr(group, "method", method) < 0)
        goto done;
    char units[1024] = "";
    size_t used = 0;
    for (size_t i = 0; i < bk_run_stats_n_fields; ++i) {
        const char *field = (const char *)stats + bk_run_stats_fields[i].offset;
        herr_t ok;
        if (bk_run_stats_fields[i].if_nonzero && bk_stat_is_zero(stats, &bk_run_stats_fields[i]))
            continue;
        if (bk_run_stats_fields[i].is_long) {
            long value;
            memcpy(&value, field, sizeof value);
            ok = bk_h5_write_long_attr(group, bk_run_stats_fields[i].name, value);
        } else {
            double value;
            memcpy(&value, field, sizeof value);
            ok = bk_h5_write_double_attr(group, bk_run_stats_fields[i].name, value);
        }
        if (ok < 0)
            goto done;
        int n = snprintf(units + used, sizeof units - used, "%s%s: %s", i ? ", " : "",
                         bk_run_stats_fields[i].name, bk_run_stats_fields[i].units);
        if (n > 0 && (size_t)n < sizeof units - used)
            used += (size_t)n;
    }
    rc = bk_h5_describe_fixed(group, units, "solver statistics of the run");
done:
    CLOSE_IDS(rc, group, gcpl);
    return rc;
}
