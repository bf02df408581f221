/* The HDF5 writer and readers: round trips through the sink, the .part/rename protocol,
 * field selection, export and info text, and failures with clear messages. */
#include "bk_test.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <hdf5.h>

#include "bksim/bksim.h"
#include "same_output.h"

/* Laws with state, so /friction_state has columns of uneven blocks: 1 + 2 + 1. */
static const bk_friction_law one_state = {.name = "one_state", .n_state = 1};
static const bk_friction_law two_states = {.name = "two_states", .n_state = 2};

static const char CONFIG_TEXT[] = "[run]\nt_end = 10\n\n[chain]\nblocks = 3\n";

typedef struct fixture {
    char dir[64];
    char path[128];
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    if (!f)
        return -1;
    snprintf(f->dir, sizeof f->dir, "/tmp/bksim_test_output_XXXXXX");
    if (!mkdtemp(f->dir)) {
        free(f);
        return -1;
    }
    snprintf(f->path, sizeof f->path, "%s/run.h5", f->dir);
    *state = f;
    return 0;
}

static void remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0)
        return;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        if (d) {
            struct dirent *e;
            while ((e = readdir(d)) != NULL) {
                if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                    continue;
                char child[512];
                snprintf(child, sizeof child, "%s/%s", path, e->d_name);
                remove_tree(child);
            }
            closedir(d);
        }
        rmdir(path);
    } else {
        unlink(path);
    }
}

static int teardown(void **state)
{
    fixture *f = *state;
    /* Every HDF5 id the library opened must be closed again, on every path. */
    ssize_t open_ids = H5Fget_obj_count((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL);
    if (open_ids > 0) {
        /* Close them so that one failing test (which skips its own closes) does not fail
         * every later teardown as well. */
        hid_t ids[64];
        ssize_t n = H5Fget_obj_ids((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL, 64, ids);
        for (ssize_t i = 0; i < n; ++i)
            H5Idec_ref(ids[i]);
    }
    remove_tree(f->dir);
    free(f);
    assert_int_equal(open_ids, 0);
    return 0;
}

static bk_config *make_config(size_t n, unsigned fields, int transitions, int with_state)
{
    bk_config *c = calloc(1, sizeof *c);
    assert_non_null(c);
    c->model = bk_model_create(n);
    assert_non_null(c->model);
    for (size_t i = 0; i < n; ++i) {
        c->model->blocks[i].mass = 1.0 + (double)i;
        c->model->blocks[i].normal_force = 9.81 * (1.0 + (double)i);
        c->model->blocks[i].driver_stiffness = 1.0;
        if (with_state)
            c->model->blocks[i].law = i % 3 == 1 ? &two_states : &one_state;
    }
    bk_model_finalize(c->model);
    c->t_end = 10.0;
    c->output.fields = fields;
    c->output.transitions = transitions;
    c->output.event_rows = 1;
    c->output.interval = 0.01;
    c->source_name = strdup("tests/run.ini");
    c->text = strdup(CONFIG_TEXT);
    assert_non_null(c->source_name);
    assert_non_null(c->text);
    return c;
}

static void free_config(bk_config *c)
{
    bk_model_free(c->model);
    free(c->source_name);
    free(c->text);
    free(c);
}

/* Deterministic, non-round values so exact equality means an exact round trip. */
static double value(size_t row, size_t col, int which)
{
    return sin(0.001 * (double)row * (which + 1) + (double)col) * pow(10.0, which - 3) +
           1.0 / 3.0;
}
static double row_time(size_t row) { return 0.01 * (double)row + 1e-13; }
static int8_t row_mode(size_t row, size_t col) { return (int8_t)((row / 100 + col) % 3) - 1; }

enum { W_X, W_V, W_FRICTION, W_COF, W_STATE, W_EKIN, W_EEL, W_WORK, W_DISS, W_DRIVER };

/* Send rows [0, rows) through the sink; row 7k is an event row. */
static void write_rows(bk_sink *sink, const bk_config *c, size_t rows)
{
    size_t n = c->model->n_blocks, s = c->model->n_friction_state;
    double *x = malloc(n * sizeof *x), *v = malloc(n * sizeof *v);
    double *fr = malloc(n * sizeof *fr), *cof = malloc(n * sizeof *cof);
    double *st = malloc((s ? s : 1) * sizeof *st);
    int8_t *mode = malloc(n);
    assert_true(x && v && fr && cof && st && mode);
    bk_error err;
    for (size_t r = 0; r < rows; ++r) {
        for (size_t b = 0; b < n; ++b) {
            x[b] = value(r, b, W_X);
            v[b] = value(r, b, W_V);
            fr[b] = value(r, b, W_FRICTION);
            cof[b] = value(r, b, W_COF);
            mode[b] = row_mode(r, b);
        }
        for (size_t k = 0; k < s; ++k)
            st[k] = value(r, k, W_STATE);
        bk_sample sample = {
            .t = row_time(r),
            .driver = value(r, 0, W_DRIVER),
            .n_blocks = n,
            .x = x,
            .v = v,
            .friction = fr,
            .cof = cof,
            .mode = mode,
            .friction_state = s ? st : NULL,
            .kinetic_energy = value(r, 0, W_EKIN),
            .elastic_energy = value(r, 0, W_EEL),
            .work_driver = value(r, 0, W_WORK),
            .dissipation = value(r, 0, W_DISS),
            .is_event = r % 7 == 0,
        };
        assert_int_equal(sink->sample(sink->self, &sample, &err), BK_OK);
    }
    free(x);
    free(v);
    free(fr);
    free(cof);
    free(st);
    free(mode);
}

static bk_transition transition_at(size_t k)
{
    static const int32_t blocks[] = {0, 0, 2, 1, 0};
    static const int8_t from[] = {0, 1, 0, 0, 0};
    static const int8_t to[] = {1, 0, -1, 1, -1};
    bk_transition t = {
        /* Within [0, 0.2]: write_small's run ends there, and a check wants transitions
         * inside the run. */
        .t = 0.03 * (double)(k + 1) + 1.0 / 700.0,
        .block = blocks[k % 5],
        .from = from[k % 5],
        .to = to[k % 5],
        .x = value(k, 1, W_X),
        .v = value(k, 2, W_V),
        .force = value(k, 3, W_FRICTION),
    };
    return t;
}

static void write_transitions(bk_sink *sink, size_t count)
{
    bk_error err;
    for (size_t k = 0; k < count; ++k) {
        bk_transition t = transition_at(k);
        assert_int_equal(sink->transition(sink->self, &t, &err), BK_OK);
    }
}

static bk_run_stats example_stats(void)
{
    bk_run_stats stats = {.method = "cvode_adams", .steps = 1234, .rhs_evals = 5678,
                          .root_evals = 91, .transitions = 5, .rows = 1500,
                          .t_reached = 14.99, .wall_time = 0.5, .cpu_time = 0.25,
                          .work_driver = 2.5, .dissipation = 2.25,
                          .energy_residual = 1e-12};
    return stats;
}

/* Write a file of `rows` rows and `count` transitions and finish it. */
static void write_file(const char *path, const bk_config *c, size_t rows, size_t count)
{
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_rows(&sink, c, rows);
    write_transitions(&sink, count);
    bk_run_stats stats = example_stats();
    int rc = bk_h5_writer_finish(w, &stats, &err);
    if (rc != BK_OK)
        print_error("finish: %s\n", err.message);
    assert_int_equal(rc, BK_OK);
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static char *part_of(const char *path)
{
    static char part[256];
    snprintf(part, sizeof part, "%s.part", path);
    return part;
}

/* ---- raw HDF5 helpers: the test checks the file with the plain API, not ours ---- */

static char *attr_string(hid_t obj, const char *name)
{
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(attr >= 0);
    hid_t type = H5Aget_type(attr);
    assert_int_equal(H5Tget_class(type), H5T_STRING);
    char *copy;
    if (H5Tis_variable_str(type) > 0) {
        char *text = NULL;
        assert_true(H5Aread(attr, type, &text) >= 0);
        copy = strdup(text);
        H5free_memory(text);
    } else {
        /* Text written after the file was created is fixed-length (see the writer). */
        size_t size = H5Tget_size(type);
        copy = calloc(size + 1, 1);
        assert_non_null(copy);
        assert_true(H5Aread(attr, type, copy) >= 0);
    }
    H5Tclose(type);
    H5Aclose(attr);
    return copy;
}

static double attr_double(hid_t obj, const char *name)
{
    double v = NAN;
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(attr >= 0);
    assert_true(H5Aread(attr, H5T_NATIVE_DOUBLE, &v) >= 0);
    H5Aclose(attr);
    return v;
}

static long long attr_llong(hid_t obj, const char *name)
{
    long long v = -1;
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(attr >= 0);
    assert_true(H5Aread(attr, H5T_NATIVE_LLONG, &v) >= 0);
    H5Aclose(attr);
    return v;
}

static int has_link(hid_t file, const char *name)
{
    return H5Lexists(file, name, H5P_DEFAULT) > 0;
}

/* Every dataset in the root group carries non-empty units and description strings. */
static size_t check_all_described(hid_t file)
{
    H5G_info_t info;
    assert_true(H5Gget_info(file, &info) >= 0);
    size_t datasets = 0;
    for (hsize_t i = 0; i < info.nlinks; ++i) {
        char name[64];
        assert_true(H5Lget_name_by_idx(file, ".", H5_INDEX_NAME, H5_ITER_INC, i, name,
                                       sizeof name, H5P_DEFAULT) > 0);
        hid_t obj = H5Oopen(file, name, H5P_DEFAULT);
        assert_true(obj >= 0);
        if (H5Iget_type(obj) == H5I_DATASET) {
            ++datasets;
            char *units = attr_string(obj, "units");
            char *description = attr_string(obj, "description");
            if (!units[0] || !description[0])
                fail_msg("/%s: empty units or description", name);
            free(units);
            free(description);
        }
        H5Oclose(obj);
    }
    return datasets;
}

/* ---------------------------------------------------------------------- tests --- */

static void check_series(const char *path, const char *name, size_t rows, size_t cols,
                         int which)
{
    double *data;
    size_t r, c;
    bk_error err;
    int rc = bk_h5_read_doubles(path, name, &data, &r, &c, &err);
    if (rc != BK_OK)
        fail_msg("%s: %s", name, err.message);
    assert_int_equal(r, rows);
    assert_int_equal(c, cols);
    for (size_t i = 0; i < rows; ++i)
        for (size_t j = 0; j < cols; ++j) {
            double expected = which < 0 ? row_time(i) : value(i, j, which);
            if (data[i * cols + j] != expected)
                fail_msg("%s[%zu][%zu] = %.17g, expected %.17g", name, i, j,
                         data[i * cols + j], expected);
        }
    free(data);
}

static void test_roundtrip_all_fields(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(3, BK_FIELD_ALL, 1, 1);
    assert_int_equal(c->model->n_friction_state, 4);
    const size_t rows = 1500, count = 5;
    write_file(f->path, c, rows, count);
    assert_true(exists(f->path));
    assert_false(exists(part_of(f->path)));

    check_series(f->path, "time", rows, 1, -1);
    check_series(f->path, "driver", rows, 1, W_DRIVER);
    check_series(f->path, "x", rows, 3, W_X);
    check_series(f->path, "v", rows, 3, W_V);
    check_series(f->path, "friction", rows, 3, W_FRICTION);
    check_series(f->path, "cof", rows, 3, W_COF);
    check_series(f->path, "friction_state", rows, 4, W_STATE);
    check_series(f->path, "energy_kinetic", rows, 1, W_EKIN);
    check_series(f->path, "energy_elastic", rows, 1, W_EEL);
    check_series(f->path, "work_driver", rows, 1, W_WORK);
    check_series(f->path, "dissipation", rows, 1, W_DISS);

    double *data;
    size_t r, cols;
    bk_error err;
    assert_int_equal(bk_h5_read_doubles(f->path, "mode", &data, &r, &cols, &err), BK_OK);
    assert_int_equal(r, rows);
    assert_int_equal(cols, 3);
    for (size_t i = 0; i < rows; ++i)
        for (size_t b = 0; b < 3; ++b)
            assert_true(data[i * 3 + b] == (double)row_mode(i, b));
    free(data);
    assert_int_equal(bk_h5_read_doubles(f->path, "event", &data, &r, &cols, &err), BK_OK);
    assert_int_equal(r, rows);
    for (size_t i = 0; i < rows; ++i)
        assert_true(data[i] == (i % 7 == 0 ? 1.0 : 0.0));
    free(data);

    bk_transition *tr;
    size_t n_tr;
    assert_int_equal(bk_h5_read_transitions(f->path, &tr, &n_tr, &err), BK_OK);
    assert_int_equal(n_tr, count);
    for (size_t k = 0; k < count; ++k) {
        bk_transition e = transition_at(k);
        assert_true(tr[k].t == e.t);
        assert_int_equal(tr[k].block, e.block);
        assert_int_equal(tr[k].from, e.from);
        assert_int_equal(tr[k].to, e.to);
        assert_true(tr[k].x == e.x);
        assert_true(tr[k].v == e.v);
        assert_true(tr[k].force == e.force);
    }
    free(tr);

    hid_t file = H5Fopen(f->path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(check_all_described(file), 14);
    assert_int_equal(attr_llong(file, "complete"), 1);
    assert_int_equal(attr_llong(file, "n_blocks"), 3);
    assert_true(attr_double(file, "t_end") == 10.0);
    assert_true(attr_double(file, "t_reached") == row_time(rows - 1));
    char *s = attr_string(file, "config");
    assert_string_equal(s, CONFIG_TEXT);
    free(s);
    s = attr_string(file, "config_name");
    assert_string_equal(s, "tests/run.ini");
    free(s);
    s = attr_string(file, "version");
    assert_string_equal(s, BKSIM_VERSION);
    free(s);
    assert_false(H5Aexists(file, "error") > 0);

    /* Mode coding and units where they matter most. */
    hid_t d = H5Dopen2(file, "mode", H5P_DEFAULT);
    s = attr_string(d, "description");
    assert_non_null(strstr(s, "stick 0, slip+ 1, slip- -1"));
    free(s);
    hid_t type = H5Dget_type(d);
    assert_true(H5Tequal(type, H5T_STD_I8LE) > 0);
    H5Tclose(type);
    H5Dclose(d);
    d = H5Dopen2(file, "v", H5P_DEFAULT);
    s = attr_string(d, "units");
    assert_string_equal(s, "m/s");
    free(s);
    /* 1500 rows of 3 blocks span three 512-row chunks, unlimited in time. */
    hid_t dcpl = H5Dget_create_plist(d);
    hsize_t chunk[2];
    assert_int_equal(H5Pget_chunk(dcpl, 2, chunk), 2);
    assert_int_equal(chunk[0], 512);
    assert_int_equal(chunk[1], 3);
    H5Pclose(dcpl);
    hid_t space = H5Dget_space(d);
    hsize_t dims[2], max_dims[2];
    H5Sget_simple_extent_dims(space, dims, max_dims);
    assert_true(max_dims[0] == H5S_UNLIMITED);
    H5Sclose(space);
    H5Dclose(d);
    d = H5Dopen2(file, "transitions", H5P_DEFAULT);
    s = attr_string(d, "units");
    assert_string_equal(s, "t: s, block: 1, from: 1, to: 1, x: m, v: m/s, force: N");
    free(s);
    H5Dclose(d);
    d = H5Dopen2(file, "friction_state", H5P_DEFAULT);
    int32_t blocks[4];
    hid_t attr = H5Aopen(d, "block", H5P_DEFAULT);
    assert_true(H5Aread(attr, H5T_NATIVE_INT32, blocks) >= 0);
    H5Aclose(attr);
    H5Dclose(d);
    assert_int_equal(blocks[0], 0);
    assert_int_equal(blocks[1], 1);
    assert_int_equal(blocks[2], 1);
    assert_int_equal(blocks[3], 2);

    hid_t stats = H5Gopen2(file, "stats", H5P_DEFAULT);
    assert_true(stats >= 0);
    s = attr_string(stats, "method");
    assert_string_equal(s, "cvode_adams");
    free(s);
    assert_int_equal(attr_llong(stats, "steps"), 1234);
    assert_int_equal(attr_llong(stats, "rhs_evals"), 5678);
    assert_int_equal(attr_llong(stats, "rows"), 1500);
    assert_true(attr_double(stats, "wall_time") == 0.5);
    assert_true(attr_double(stats, "energy_residual") == 1e-12);
    s = attr_string(stats, "units");
    assert_non_null(strstr(s, "wall_time: s"));
    assert_non_null(strstr(s, "cpu_time: s"));
    assert_non_null(strstr(s, "work_driver: J"));
    assert_non_null(strstr(s, "energy_residual: 1"));
    free(s);
    H5Gclose(stats);
    H5Fclose(file);
    free_config(c);
}

static void test_abandon_keeps_part(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(3, BK_FIELD_ALL, 1, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    assert_true(exists(part_of(f->path)));
    bk_sink sink = bk_h5_writer_sink(w);
    /* One flushed chunk plus rows still in the buffer: both must reach the file. */
    write_rows(&sink, c, 700);
    write_transitions(&sink, 3);
    bk_run_stats stats = example_stats();
    bk_h5_writer_abandon(w, "integrator failure at t = 7", &stats);

    assert_false(exists(f->path));
    const char *part = part_of(f->path);
    assert_true(exists(part));
    check_series(part, "time", 700, 1, -1);
    check_series(part, "x", 700, 3, W_X);
    bk_transition *tr;
    size_t n_tr;
    assert_int_equal(bk_h5_read_transitions(part, &tr, &n_tr, &err), BK_OK);
    assert_int_equal(n_tr, 3);
    free(tr);
    hid_t file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(attr_llong(file, "complete"), 0);
    assert_true(attr_double(file, "t_reached") == row_time(699));
    char *s = attr_string(file, "error");
    assert_string_equal(s, "integrator failure at t = 7");
    free(s);
    assert_true(has_link(file, "stats"));
    assert_false(has_link(file, "friction_state"));
    H5Fclose(file);

    /* info reads a .part too and says it is incomplete. */
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_int_equal(bk_h5_info(part, out, &err), BK_INCOMPLETE);
    fclose(out);
    assert_non_null(strstr(text, "complete     0 (run did not finish)\n"));
    assert_non_null(strstr(text, "error        integrator failure at t = 7\n"));
    free(text);
    free_config(c);
}

static void test_abandon_without_stats(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(2, BK_FIELD_X, 0, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_rows(&sink, c, 10);
    bk_h5_writer_abandon(w, NULL, NULL);
    assert_false(exists(f->path));
    hid_t file = H5Fopen(part_of(f->path), H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_false(has_link(file, "stats"));
    assert_int_equal(attr_llong(file, "complete"), 0);
    char *s = attr_string(file, "error");
    assert_string_equal(s, "run abandoned");
    free(s);
    H5Fclose(file);
    check_series(part_of(f->path), "x", 10, 2, W_X);
    free_config(c);
}

static void test_fields_subset(void **state)
{
    fixture *f = *state;
    /* STATE is selected but no block has state: no /friction_state either. */
    bk_config *c = make_config(4, BK_FIELD_X | BK_FIELD_MODE | BK_FIELD_STATE, 0, 0);
    write_file(f->path, c, 20, 2);
    hid_t file = H5Fopen(f->path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    static const char *const present[] = {"time", "driver", "event", "x", "mode"};
    static const char *const absent[] = {"v", "friction", "cof", "energy_kinetic",
                                         "energy_elastic", "work_driver", "dissipation",
                                         "friction_state", "transitions"};
    for (size_t i = 0; i < sizeof present / sizeof *present; ++i)
        if (!has_link(file, present[i]))
            fail_msg("/%s missing", present[i]);
    for (size_t i = 0; i < sizeof absent / sizeof *absent; ++i)
        if (has_link(file, absent[i]))
            fail_msg("/%s written although not selected", absent[i]);
    assert_int_equal(check_all_described(file), 5);
    H5Fclose(file);
    check_series(f->path, "x", 20, 4, W_X);

    bk_transition *tr = NULL;
    size_t n = 99;
    bk_error err;
    assert_int_equal(bk_h5_read_transitions(f->path, &tr, &n, &err), BK_ERR_HDF5);
    assert_null(tr);
    assert_non_null(strstr(err.message, "no /transitions"));
    free_config(c);
}

static void test_energy_only(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(2, BK_FIELD_ENERGY, 1, 1);
    write_file(f->path, c, 600, 0);
    hid_t file = H5Fopen(f->path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(has_link(file, "work_driver"));
    assert_false(has_link(file, "x"));
    assert_false(has_link(file, "friction_state"));
    assert_true(has_link(file, "transitions"));
    H5Fclose(file);
    check_series(f->path, "dissipation", 600, 1, W_DISS);
    bk_transition *tr;
    size_t n;
    bk_error err;
    assert_int_equal(bk_h5_read_transitions(f->path, &tr, &n, &err), BK_OK);
    assert_int_equal(n, 0);
    free(tr);
    free_config(c);
}

static void test_wide_chain_chunks_capped(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(1000, BK_FIELD_X, 0, 0);
    write_file(f->path, c, 300, 0);
    hid_t file = H5Fopen(f->path, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t d = H5Dopen2(file, "x", H5P_DEFAULT);
    hid_t dcpl = H5Dget_create_plist(d);
    hsize_t chunk[2];
    assert_int_equal(H5Pget_chunk(dcpl, 2, chunk), 2);
    assert_int_equal(chunk[1], 1000);
    assert_true(chunk[0] * chunk[1] * sizeof(double) <= (1u << 20));
    assert_true(chunk[0] < 300); /* so this run crosses chunk boundaries */
    H5Pclose(dcpl);
    H5Dclose(d);
    H5Fclose(file);
    check_series(f->path, "x", 300, 1000, W_X);
    free_config(c);
}

static void test_empty_run(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(2, BK_FIELD_ALL, 1, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    assert_int_equal(bk_h5_writer_finish(w, NULL, &err), BK_OK);
    double *data;
    size_t r, cols;
    assert_int_equal(bk_h5_read_doubles(f->path, "x", &data, &r, &cols, &err), BK_OK);
    assert_int_equal(r, 0);
    assert_int_equal(cols, 2);
    free(data);
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_int_equal(bk_h5_export(f->path, "time,x", -1, 0, out, &err), BK_OK);
    fclose(out);
    assert_string_equal(text, "# time[s] x_0[m] x_1[m]\n");
    free(text);
    free_config(c);
}

static void test_finish_replaces_old_output(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(2, BK_FIELD_X, 0, 0);
    write_file(f->path, c, 5, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_rows(&sink, c, 9);
    /* Until the new run completes, the previous output stays intact. */
    check_series(f->path, "x", 5, 2, W_X);
    assert_int_equal(bk_h5_writer_finish(w, NULL, &err), BK_OK);
    check_series(f->path, "x", 9, 2, W_X);
    assert_false(exists(part_of(f->path)));
    free_config(c);
}

static void test_sink_rejects_bad_input(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(3, BK_FIELD_X | BK_FIELD_V, 1, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    double x[3] = {1, 2, 3};
    bk_sample sample = {.t = 0, .n_blocks = 2, .x = x, .v = x};
    assert_int_equal(sink.sample(sink.self, &sample, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "sample has 2 blocks, the file 3"));
    sample.n_blocks = 3;
    sample.v = NULL;
    assert_int_equal(sink.sample(sink.self, &sample, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "/v"));
    bk_transition t = {.t = 1, .block = 3};
    assert_int_equal(sink.transition(sink.self, &t, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "0..2"));
    /* Rejected input leaves nothing behind; the file is still good. */
    write_rows(&sink, c, 4);
    assert_int_equal(bk_h5_writer_finish(w, NULL, &err), BK_OK);
    check_series(f->path, "x", 4, 3, W_X);
    free_config(c);
}

/* A full disk, simulated with a file size limit: the failing write is reported with the
 * file name and the system's reason, the sink refuses more data, finish fails and leaves
 * no <path>.
 *
 * This runs in a child process (this program re-run with --disk-full): HDF5 1.10 leaks the
 * chunk buffers and file structures it could not flush, which would drown the leak
 * checkers' view of this process, and the child's plain exit also proves that HDF5's
 * shutdown at exit does not crash on what the failure left behind.  The child is started
 * through the shell, so valgrind (not tracing children) runs it natively, and under
 * AddressSanitizer its leak check is switched off. */
enum { FAIL_IN_SINK_THEN_FINISH, FAIL_IN_SINK_THEN_ABANDON, FAIL_IN_FINISH };

static const char *self_path;

#define CHILD_CHECK(cond, err)                                                             \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            fprintf(stderr, "%s:%d: check failed: %s (last error: %s)\n", __FILE__,         \
                    __LINE__, #cond, (err).message);                                       \
            return 1;                                                                      \
        }                                                                                  \
    } while (0)

static int disk_full_child(int scenario, const char *path)
{
    bk_config *c = make_config(50, BK_FIELD_ALL, 1, 0);
    bk_h5_writer *w;
    bk_error err;
    bk_error_clear(&err);
    CHILD_CHECK(bk_h5_writer_open(&w, c, path, &err) == BK_OK, err);
    bk_sink sink = bk_h5_writer_sink(w);
    double x[50] = {0};
    int8_t mode[50] = {0};
    bk_sample sample = {.n_blocks = 50, .x = x, .v = x, .friction = x, .cof = x, .mode = mode};
    struct rlimit saved, small;
    CHILD_CHECK(getrlimit(RLIMIT_FSIZE, &saved) == 0, err);
    small = saved;
    small.rlim_cur = 200 * 1024;
    signal(SIGXFSZ, SIG_IGN);

    int rc = BK_OK;
    if (scenario == FAIL_IN_FINISH) {
        /* 300 rows stay in the buffer (512 per chunk); the limit then hits finish. */
        for (size_t row = 0; row < 300; ++row) {
            sample.t = (double)row;
            CHILD_CHECK(sink.sample(sink.self, &sample, &err) == BK_OK, err);
        }
        CHILD_CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0, err);
        rc = bk_h5_writer_finish(w, NULL, &err);
    } else {
        CHILD_CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0, err);
        for (size_t row = 0; row < 100000 && rc == BK_OK; ++row) {
            sample.t = (double)row;
            rc = sink.sample(sink.self, &sample, &err);
        }
    }
    /* Lifted before anything is printed: stderr may be a file past the limit. */
    CHILD_CHECK(setrlimit(RLIMIT_FSIZE, &saved) == 0, err);
    CHILD_CHECK(rc == BK_ERR_HDF5, err);
    CHILD_CHECK(strstr(err.message, ".part: cannot ") != NULL, err);
    CHILD_CHECK(strstr(err.message, "(HDF5: file write failed: File too large)") != NULL, err);

    if (scenario != FAIL_IN_FINISH) {
        CHILD_CHECK(sink.sample(sink.self, &sample, &err) == BK_ERR_HDF5, err);
        CHILD_CHECK(strstr(err.message, "an earlier write failed") != NULL, err);
        if (scenario == FAIL_IN_SINK_THEN_FINISH) {
            CHILD_CHECK(bk_h5_writer_finish(w, NULL, &err) == BK_ERR_HDF5, err);
            CHILD_CHECK(strstr(err.message, "not completed") != NULL, err);
        } else {
            bk_h5_writer_abandon(w, "disk full", NULL);
        }
    }
    /* A failed close must not leave an id behind: H5close() at exit would crash on it. */
    CHILD_CHECK(H5Fget_obj_count((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL) == 0, err);
    free_config(c);
    return 0;
}

static void run_out_of_space(const char *path, int scenario)
{
    char command[1024];
    snprintf(command, sizeof command,
             "ASAN_OPTIONS=detect_leaks=0 '%s' --disk-full %d '%s'", self_path, scenario, path);
    int status = system(command);
    if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        fail_msg("disk-full child failed (wait status %d): %s", status, command);
    assert_false(exists(path));
    assert_true(exists(part_of(path)));
}

static void test_write_failure_finish(void **state)
{
    fixture *f = *state;
    run_out_of_space(f->path, FAIL_IN_SINK_THEN_FINISH);
}

static void test_write_failure_abandon(void **state)
{
    fixture *f = *state;
    run_out_of_space(f->path, FAIL_IN_SINK_THEN_ABANDON);
}

static void test_write_failure_in_finish(void **state)
{
    fixture *f = *state;
    run_out_of_space(f->path, FAIL_IN_FINISH);
}

/* rename() fails (a directory took the name meanwhile): finish reports it, and the .part,
 * already marked complete, is marked incomplete again with the reason. */
static void test_rename_failure(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(2, BK_FIELD_X, 0, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_rows(&sink, c, 10);
    assert_int_equal(mkdir(f->path, 0700), 0);
    char inside[256];
    snprintf(inside, sizeof inside, "%s/keep", f->path);
    FILE *k = fopen(inside, "w");
    assert_non_null(k);
    fclose(k);
    assert_int_equal(bk_h5_writer_finish(w, NULL, &err), BK_ERR_IO);
    assert_non_null(strstr(err.message, "cannot rename to"));
    hid_t file = H5Fopen(part_of(f->path), H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(attr_llong(file, "complete"), 0);
    char *s = attr_string(file, "error");
    assert_non_null(strstr(s, "cannot rename to"));
    free(s);
    H5Fclose(file);
    check_series(part_of(f->path), "x", 10, 2, W_X);
    free_config(c);
}

/* ---- export and info ---- */

/* A small file with round-looking values whose %.17g forms are not round. */
static void write_small(const char *path, int with_state)
{
    bk_config *c = make_config(3, BK_FIELD_ALL, 1, with_state);
    c->t_end = 0.2; /* the last row's time: a complete run ends at t_end */
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    double x[3], v[3], fr[3], cof[3], st[4] = {0};
    int8_t mode[3];
    for (int r = 0; r < 3; ++r) {
        for (int b = 0; b < 3; ++b) {
            x[b] = 0.1 * (r + 1) + b;
            v[b] = -0.3 * b + r;
            fr[b] = 1.0 / 3.0 + b;
            cof[b] = 0.6;
            mode[b] = (int8_t)(r == 0 ? 0 : b - 1);
        }
        for (int k = 0; k < 4; ++k)
            st[k] = 10 * r + k;
        bk_sample sample = {.t = 0.1 * r, .driver = 0.7 * r, .n_blocks = 3, .x = x, .v = v,
                            .friction = fr, .cof = cof, .mode = mode,
                            .friction_state = with_state ? st : NULL};
        assert_int_equal(sink.sample(sink.self, &sample, &err), BK_OK);
    }
    write_transitions(&sink, 5);
    bk_run_stats stats = example_stats();
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    free_config(c);
}

static char *export_text(const char *path, const char *datasets, long block, int transitions)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_non_null(out);
    bk_error err;
    int rc = bk_h5_export(path, datasets, block, transitions, out, &err);
    fclose(out);
    if (rc != BK_OK)
        fail_msg("export: %s", err.message);
    return text;
}

static void append(char *buf, size_t size, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void append(char *buf, size_t size, const char *fmt, ...)
{
    size_t used = strlen(buf);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + used, size - used, fmt, ap);
    va_end(ap);
}

static void test_export_default_one_block(void **state)
{
    fixture *f = *state;
    write_small(f->path, 0);
    char *text = export_text(f->path, NULL, 1, 0);
    char expected[2048] =
        "# time[s] driver[m] x_1[m] v_1[m/s] friction_1[N] cof_1[1] mode_1[1]\n";
    for (int r = 0; r < 3; ++r)
        append(expected, sizeof expected, "%.17g %.17g %.17g %.17g %.17g %.17g %d\n", 0.1 * r,
               0.7 * r, 0.1 * (r + 1) + 1, -0.3 + r, 1.0 / 3.0 + 1, 0.6, 0);
    assert_string_equal(text, expected);
    /* %.17g round-trips: the printed x column parses back to the stored doubles. */
    const char *line = strchr(text, '\n') + 1;
    double t, d, x1;
    assert_int_equal(sscanf(line, "%lf %lf %lf", &t, &d, &x1), 3);
    assert_true(x1 == 0.1 * 1 + 1);
    free(text);
}

static void test_export_all_blocks(void **state)
{
    fixture *f = *state;
    write_small(f->path, 1);
    char *text = export_text(f->path, "time, x,mode", -1, 0);
    char expected[2048] = "# time[s] x_0[m] x_1[m] x_2[m] mode_0[1] mode_1[1] mode_2[1]\n";
    for (int r = 0; r < 3; ++r)
        append(expected, sizeof expected, "%.17g %.17g %.17g %.17g %d %d %d\n", 0.1 * r,
               0.1 * (r + 1), 0.1 * (r + 1) + 1, 0.1 * (r + 1) + 2, r ? -1 : 0, 0,
               r ? 1 : 0);
    assert_string_equal(text, expected);
    free(text);

    /* friction_state columns are named block_state and follow the block filter. */
    text = export_text(f->path, "friction_state", 1, 0);
    assert_string_equal(text, "# friction_state_1_0[law-specific] friction_state_1_1[law-specific]\n"
                              "1 2\n11 12\n21 22\n");
    free(text);
    text = export_text(f->path, "friction_state,work_driver", -1, 0);
    assert_non_null(strstr(text, "# friction_state_0_0[law-specific] "
                                 "friction_state_1_0[law-specific] "
                                 "friction_state_1_1[law-specific] "
                                 "friction_state_2_0[law-specific] work_driver[J]\n"
                                 "0 1 2 3 0\n"));
    free(text);
}

static void test_export_transitions(void **state)
{
    fixture *f = *state;
    write_small(f->path, 0);
    char header[] = "# t[s] block[1] from[1] to[1] x[m] v[m/s] force[N]\n";
    char all[2048], block0[2048];
    snprintf(all, sizeof all, "%s", header);
    snprintf(block0, sizeof block0, "%s", header);
    for (size_t k = 0; k < 5; ++k) {
        bk_transition t = transition_at(k);
        char line[256];
        snprintf(line, sizeof line, "%.17g %d %d %d %.17g %.17g %.17g\n", t.t, (int)t.block,
                 (int)t.from, (int)t.to, t.x, t.v, t.force);
        append(all, sizeof all, "%s", line);
        if (t.block == 0)
            append(block0, sizeof block0, "%s", line);
    }
    char *text = export_text(f->path, NULL, -1, 1);
    assert_string_equal(text, all);
    free(text);
    text = export_text(f->path, NULL, 0, 1);
    assert_string_equal(text, block0);
    free(text);
}

static void expect_export_error(const char *path, const char *datasets, long block,
                                int transitions, int status, const char *const *needles)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    bk_error err;
    bk_error_clear(&err);
    int rc = bk_h5_export(path, datasets, block, transitions, out, &err);
    fclose(out);
    free(text);
    if (rc != status)
        fail_msg("export returned %d (%s), expected %d", rc, err.message, status);
    for (; *needles; ++needles)
        if (!strstr(err.message, *needles))
            fail_msg("message \"%s\" lacks \"%s\"", err.message, *needles);
}

static void test_export_errors(void **state)
{
    fixture *f = *state;
    write_small(f->path, 0);
    expect_export_error(f->path, "time,bogus", -1, 0, BK_ERR_INVALID,
                        (const char *const[]){"no dataset 'bogus'",
                                              "available: time, driver, event, x, v, "
                                              "friction, cof, mode, energy_kinetic",
                                              NULL});
    expect_export_error(f->path, "transitions", -1, 0, BK_ERR_INVALID,
                        (const char *const[]){"no dataset 'transitions'", "available:", NULL});
    expect_export_error(f->path, "time,,x", -1, 0, BK_ERR_INVALID,
                        (const char *const[]){"empty dataset name", NULL});
    expect_export_error(f->path, NULL, 3, 0, BK_ERR_INVALID,
                        (const char *const[]){"block 3 out of range", "3 blocks (allowed: 0..2)", NULL});
    expect_export_error(f->path, NULL, -2, 0, BK_ERR_INVALID,
                        (const char *const[]){"block -2 out of range", "(allowed: 0..2)", NULL});
    expect_export_error(f->path, NULL, 7, 1, BK_ERR_INVALID,
                        (const char *const[]){"(allowed: 0..2)", NULL});

    bk_config *c = make_config(2, BK_FIELD_X, 0, 0);
    char other[256];
    snprintf(other, sizeof other, "%s/no_transitions.h5", f->dir);
    write_file(other, c, 3, 0);
    free_config(c);
    expect_export_error(other, NULL, -1, 1, BK_ERR_HDF5,
                        (const char *const[]){other, "no /transitions", NULL});

    double *data = NULL;
    size_t r, cols;
    bk_error err;
    assert_int_equal(bk_h5_read_doubles(f->path, "transitions", &data, &r, &cols, &err),
                     BK_ERR_HDF5);
    assert_non_null(strstr(err.message, "not numeric"));
    assert_int_equal(bk_h5_read_doubles(f->path, "nope", &data, &r, &cols, &err), BK_ERR_HDF5);
    assert_non_null(strstr(err.message, "no dataset 'nope'"));
    assert_null(data);
}

static void test_info(void **state)
{
    fixture *f = *state;
    write_small(f->path, 0);
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    bk_error err;
    assert_int_equal(bk_h5_info(f->path, out, &err), BK_OK);
    fclose(out);
    static const char *const needles[] = {
        "config name  tests/run.ini\n",
        "version      " BKSIM_VERSION "\n",
        "complete     1\n",
        "t_end        0.2 s\n",
        "t_reached    0.2 s\n",
        "n_blocks     3\n",
        "rows         3\n",
        "config:\n    [run]\n    t_end = 10\n    \n    [chain]\n    blocks = 3\nphases",
        /* Row 0 all stick; transitions to: block 0 slip+, stick, slip-; block 1 slip+;
         * block 2 slip-. */
        "    block 0: 2 stick, 2 slip\n",
        "    block 1: 1 stick, 1 slip\n",
        "    block 2: 1 stick, 1 slip\n",
        "transitions  5\n",
        "stats:\n    method             cvode_adams\n    steps              1234\n",
        "    wall_time          0.5 s\n",
        "    work_driver        2.5 J\n",
        "    energy_residual    1e-12\n",
    };
    for (size_t i = 0; i < sizeof needles / sizeof *needles; ++i)
        if (!strstr(text, needles[i]))
            fail_msg("info output lacks \"%s\":\n%s", needles[i], text);
    /* Times and statistics are printed for reading, to 9 significant digits. */
    double t_reached = NAN, residual = NAN;
    assert_int_equal(sscanf(strstr(text, "t_reached "), "t_reached %lf", &t_reached), 1);
    assert_int_equal(sscanf(strstr(text, "energy_residual "), "energy_residual %lf", &residual), 1);
    assert_close(t_reached, 0.1 * 2, 1e-9, 0.0);
    assert_close(residual, 1e-12, 1e-9, 0.0);
    free(text);
}

static void test_missing_and_garbage_files(void **state)
{
    fixture *f = *state;
    char missing[256], garbage[256], truncated[256];
    snprintf(missing, sizeof missing, "%s/missing.h5", f->dir);
    snprintf(garbage, sizeof garbage, "%s/garbage.h5", f->dir);
    snprintf(truncated, sizeof truncated, "%s/truncated.h5", f->dir);
    FILE *g = fopen(garbage, "w");
    assert_non_null(g);
    fputs("this is not HDF5\n", g);
    fclose(g);
    /* A real output cut short: signature present, the rest missing. */
    write_small(f->path, 0);
    FILE *in = fopen(f->path, "rb");
    FILE *cut = fopen(truncated, "wb");
    char buf[1500];
    size_t n = fread(buf, 1, sizeof buf, in);
    fwrite(buf, 1, n, cut);
    fclose(in);
    fclose(cut);

    struct {
        const char *path;
        int status;
        const char *needle;
    } cases[] = {
        {missing, BK_ERR_IO, "No such file or directory"},
        {garbage, BK_ERR_HDF5, "not an HDF5 file"},
        {truncated, BK_ERR_HDF5, "cannot open"},
        {f->dir, BK_ERR_IO, "is a directory"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        char *text = NULL;
        size_t len = 0;
        FILE *out = open_memstream(&text, &len);
        bk_error err;
        int rc[3];
        rc[0] = bk_h5_info(cases[i].path, out, &err);
        rc[1] = bk_h5_export(cases[i].path, NULL, -1, 0, out, &err);
        double *data = NULL;
        size_t r, cols;
        rc[2] = bk_h5_read_doubles(cases[i].path, "time", &data, &r, &cols, &err);
        fclose(out);
        assert_string_equal(text, "");
        free(text);
        assert_null(data);
        for (int k = 0; k < 3; ++k)
            if (rc[k] != cases[i].status)
                fail_msg("%s: call %d returned %d, expected %d", cases[i].path, k, rc[k],
                         cases[i].status);
        if (!strstr(err.message, cases[i].path) || !strstr(err.message, cases[i].needle))
            fail_msg("message \"%s\" should name %s and say \"%s\"", err.message,
                     cases[i].path, cases[i].needle);
    }
}

static void test_open_creates_directories(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(2, BK_FIELD_X, 0, 0);
    char path[256];
    snprintf(path, sizeof path, "%s/a/b/c/run.h5", f->dir);
    write_file(path, c, 3, 0);
    check_series(path, "x", 3, 2, W_X);
    free_config(c);
}

static void test_open_fails_cleanly(void **state)
{
    fixture *f = *state;
    bk_config *c = make_config(2, BK_FIELD_X, 0, 0);
    char blocker[256], path[300];
    snprintf(blocker, sizeof blocker, "%s/blocker", f->dir);
    FILE *b = fopen(blocker, "w");
    assert_non_null(b);
    fclose(b);
    snprintf(path, sizeof path, "%s/sub/run.h5", blocker);
    char not_null;
    bk_h5_writer *w = (bk_h5_writer *)(void *)&not_null; /* open must reset it to NULL */
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_ERR_IO);
    assert_null(w);
    assert_non_null(strstr(err.message, "cannot create directory"));
    assert_non_null(strstr(err.message, blocker));
    assert_non_null(strstr(err.message, "not a directory"));

    /* The output path names an existing directory. */
    assert_int_equal(bk_h5_writer_open(&w, c, f->dir, &err), BK_ERR_IO);
    assert_non_null(strstr(err.message, "is a directory"));

    /* Creation itself fails (the .part name is taken by a directory): nothing is left. */
    char part[320];
    snprintf(path, sizeof path, "%s/taken.h5", f->dir);
    snprintf(part, sizeof part, "%s.part", path);
    assert_int_equal(mkdir(part, 0700), 0);
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_ERR_HDF5);
    assert_non_null(strstr(err.message, "cannot create file"));
    assert_false(exists(path));
    free_config(c);
}

/* ---- integrity (bk_h5_verify) on hand-damaged files ---- */

/* write_small with these transitions instead of the usual five. */
static void write_small_with(const char *path, const bk_transition *transitions, size_t n)
{
    bk_config *c = make_config(3, BK_FIELD_ALL, 1, 0);
    c->t_end = 0.2;
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    double x[3] = {0.1, 0.2, 0.3}, v[3] = {0}, fr[3] = {1, 2, 3}, cof[3] = {0.6, 0.6, 0.6};
    int8_t mode[3] = {0, 1, -1};
    for (int r = 0; r < 3; ++r) {
        bk_sample sample = {.t = 0.1 * r, .driver = 0.7 * r, .n_blocks = 3, .x = x, .v = v,
                            .friction = fr, .cof = cof, .mode = mode};
        assert_int_equal(sink.sample(sink.self, &sample, &err), BK_OK);
    }
    for (size_t k = 0; k < n; ++k)
        assert_int_equal(sink.transition(sink.self, &transitions[k], &err), BK_OK);
    bk_run_stats stats = example_stats();
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    free_config(c);
}

/* Overwrite one value of a 1-D or 2-D dataset through the plain HDF5 API. */
static void poke(const char *path, const char *name, hsize_t row, hsize_t col, hid_t mem_type,
                 const void *value)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t dset = H5Dopen2(file, name, H5P_DEFAULT);
    assert_true(dset >= 0);
    hid_t space = H5Dget_space(dset);
    int rank = H5Sget_simple_extent_ndims(space);
    hsize_t offset[2] = {row, col}, count[2] = {1, 1};
    assert_true(H5Sselect_hyperslab(space, H5S_SELECT_SET, offset, NULL, count, NULL) >= 0);
    hid_t mem = H5Screate_simple(rank, count, NULL);
    assert_true(H5Dwrite(dset, mem_type, mem, space, H5P_DEFAULT, value) >= 0);
    H5Sclose(mem);
    H5Sclose(space);
    H5Dclose(dset);
    H5Fclose(file);
}

/* Eight bytes of 0xff written over the stored chunk of dataset name that holds row, at that
 * row (row_bytes per row): what a disk or a careless tool might do. */
static void clobber_chunk(const char *path, const char *name, hsize_t row, size_t row_bytes)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t dset = H5Dopen2(file, name, H5P_DEFAULT);
    assert_true(dset >= 0);
    hid_t dcpl = H5Dget_create_plist(dset);
    hsize_t chunk[2] = {0, 0};
    assert_true(H5Pget_chunk(dcpl, 2, chunk) >= 1);
    H5Pclose(dcpl);
    hsize_t origin[2] = {row / chunk[0] * chunk[0], 0};
    unsigned mask = 0;
    haddr_t addr = HADDR_UNDEF;
    hsize_t size = 0;
    assert_true(H5Dget_chunk_info_by_coord(dset, origin, &mask, &addr, &size) >= 0);
    assert_true(addr != HADDR_UNDEF && size > 0);
    H5Dclose(dset);
    H5Fclose(file);
    off_t at = (off_t)(addr + (row - origin[0]) * row_bytes);
    assert_true((hsize_t)(row - origin[0]) * row_bytes + 8 <= size);
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    assert_int_equal(fseeko(f, at, SEEK_SET), 0);
    static const unsigned char ff[8] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
    assert_int_equal(fwrite(ff, 1, 8, f), 8);
    fclose(f);
}

static void expect_damaged(const char *path, const char *needle)
{
    bk_error err = {0};
    int rc = bk_h5_verify(path, &err);
    if (rc != BK_ERR_DAMAGED || !strstr(err.message, needle))
        fail_msg("verify returned %d \"%s\", expected damaged with \"%s\"", rc, err.message, needle);
    if (!strstr(err.message, path))
        fail_msg("message \"%s\" does not name %s", err.message, path);
    /* info prints its summary, says DAMAGED, and returns the same. */
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_int_equal(bk_h5_info(path, out, &err), BK_ERR_DAMAGED);
    fclose(out);
    assert_non_null(strstr(text, "integrity    DAMAGED: "));
    assert_non_null(strstr(text, needle));
    free(text);
}

static void test_verify_values(void **state)
{
    fixture *f = *state;
    bk_error err = {0};
    write_small(f->path, 0);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);

    double nan = NAN, inf = INFINITY, huge = 1e30;
    write_small(f->path, 0);
    poke(f->path, "x", 1, 2, H5T_NATIVE_DOUBLE, &nan);
    expect_damaged(f->path, "/x row 1 column 2 is nan, not finite");

    /* A large finite driver position is allowed; a non-finite one is not. */
    write_small(f->path, 0);
    poke(f->path, "driver", 2, 0, H5T_NATIVE_DOUBLE, &huge);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    poke(f->path, "driver", 2, 0, H5T_NATIVE_DOUBLE, &inf);
    expect_damaged(f->path, "/driver row 2 is inf, not finite");

    int8_t bad_mode = 77;
    write_small(f->path, 0);
    poke(f->path, "mode", 2, 1, H5T_NATIVE_INT8, &bad_mode);
    expect_damaged(f->path, "/mode row 2 column 1 is 77, not a mode");

    uint8_t bad_event = 2;
    write_small(f->path, 0);
    poke(f->path, "event", 0, 0, H5T_NATIVE_UINT8, &bad_event);
    expect_damaged(f->path, "/event row 0 is 2, not 0 or 1");
}

static void test_verify_required_datasets(void **state)
{
    fixture *f = *state;
    const char *names[] = {"x", "v", "transitions", "energy_kinetic", "driver"};
    for (size_t k = 0; k < sizeof names / sizeof *names; ++k) {
        write_small(f->path, 0);
        hid_t file = H5Fopen(f->path, H5F_ACC_RDWR, H5P_DEFAULT);
        assert_true(file >= 0);
        char *recorded = attr_string(file, "datasets");
        assert_string_equal(recorded, "time,driver,event,x,v,friction,cof,mode,energy_kinetic,"
                                      "energy_elastic,work_driver,dissipation,transitions");
        free(recorded);
        assert_true(H5Ldelete(file, names[k], H5P_DEFAULT) >= 0);
        H5Fclose(file);
        char needle[64];
        snprintf(needle, sizeof needle, "no /%s", names[k]);
        expect_damaged(f->path, needle);
    }
    /* Datasets a run did not select are not required. */
    bk_config *c = make_config(2, BK_FIELD_X, 0, 0);
    c->t_end = row_time(2);
    write_file(f->path, c, 3, 0);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    free_config(c);
}

static void test_verify_transitions(void **state)
{
    fixture *f = *state;
    bk_transition ok[2] = {{.t = 0.05, .block = 0, .from = 0, .to = 1},
                           {.t = 0.05, .block = 1, .from = 0, .to = -1}};
    write_small_with(f->path, ok, 2);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK); /* equal times are in order */

    bk_transition backwards[2] = {{.t = 0.05, .block = 0, .from = 0, .to = 1},
                                  {.t = 0.03, .block = 0, .from = 1, .to = 0}};
    write_small_with(f->path, backwards, 2);
    expect_damaged(f->path, "/transitions is not in time order at row 1");

    bk_transition late[1] = {{.t = 0.5, .block = 2, .from = 0, .to = 1}};
    write_small_with(f->path, late, 1);
    expect_damaged(f->path, "/transitions row 0 is at t = 0.5 s, after the end of the run");

    bk_transition early[1] = {{.t = -0.01, .block = 2, .from = 0, .to = 1}};
    write_small_with(f->path, early, 1);
    expect_damaged(f->path, "/transitions is not in time order at row 0");

    bk_transition bad_mode[1] = {{.t = 0.1, .block = 1, .from = 0, .to = 3}};
    write_small_with(f->path, bad_mode, 1);
    expect_damaged(f->path, "/transitions row 0 goes from mode 0 to 3");

    bk_transition nan_x[1] = {{.t = 0.1, .block = 1, .from = 0, .to = 1, .x = NAN}};
    write_small_with(f->path, nan_x, 1);
    expect_damaged(f->path, "/transitions row 0 has a value that is not finite");
}

/* Bytes damaged inside a chunk: the chunk's Fletcher32 checksum fails the read. */
static void test_verify_flipped_chunk_bytes(void **state)
{
    fixture *f = *state;
    write_small(f->path, 0);
    clobber_chunk(f->path, "x", 1, 3 * sizeof(double));
    expect_damaged(f->path, "/x rows 0..2 cannot be read");
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(f->path, &err), BK_ERR_DAMAGED);
    assert_non_null(strstr(err.message, "HDF5:"));

    write_small(f->path, 0);
    clobber_chunk(f->path, "transitions", 2, 38);
    expect_damaged(f->path, "/transitions");
}

/* ---- checkpoints and restarts of real runs ---- */

/* A sink that passes everything to inner and stops the run `samples` rows after its
 * `checkpoints`-th checkpoint, as a kill would (here cleanly, through abandon). */
typedef struct stopping_sink {
    bk_sink inner;
    int checkpoints;
    int samples;
} stopping_sink;

static int stopping_sample(void *self, const bk_sample *sample, bk_error *err)
{
    stopping_sink *s = self;
    if (s->checkpoints == 0 && s->samples-- == 0)
        return BK_FAIL(err, BK_ERR_INTERRUPTED, "stopped by the test");
    return s->inner.sample(s->inner.self, sample, err);
}

static int stopping_transition(void *self, const bk_transition *t, bk_error *err)
{
    stopping_sink *s = self;
    return s->inner.transition(s->inner.self, t, err);
}

static int stopping_checkpoint(void *self, const bk_checkpoint *cp, bk_error *err)
{
    stopping_sink *s = self;
    int rc = s->inner.checkpoint(s->inner.self, cp, err);
    if (rc == BK_OK && s->checkpoints > 0)
        --s->checkpoints;
    return rc;
}

static bk_config *paper_config(const char *const *extra, size_t n_extra)
{
    const char *overrides[8] = {"output.checkpoint_interval=0.25", "run.t_end=1.2"};
    size_t n = 2;
    for (size_t k = 0; k < n_extra && n < 8; ++k)
        overrides[n++] = extra[k];
    bk_config *config = NULL;
    bk_error err = {0};
    int rc = bk_config_load_file("configs/paper/case_b_coulomb.ini", overrides, n, &config, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    return config;
}

/* Run config into path: whole (checkpoints < 0) or stopped `samples` rows after that many
 * checkpoints, leaving path.part. */
static void run_into(const bk_config *config, const char *path, int checkpoints, int samples)
{
    bk_h5_writer *w;
    bk_error err = {0};
    assert_int_equal(bk_h5_writer_open(&w, config, path, &err), BK_OK);
    bk_sink inner = bk_h5_writer_sink(w);
    stopping_sink stop = {inner, checkpoints < 0 ? -1 : checkpoints, samples};
    bk_sink sink = {&stop, stopping_sample, stopping_transition, stopping_checkpoint};
    bk_run_stats stats;
    int rc = bk_run(config, checkpoints < 0 ? &inner : &sink, &stats, NULL, NULL, &err);
    if (checkpoints < 0) {
        if (rc != BK_OK)
            fail_msg("%s", err.message);
        assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    } else {
        assert_int_equal(rc, BK_ERR_INTERRUPTED);
        bk_h5_writer_abandon(w, err.message, &stats);
    }
}

/* Restart path.part and run it to the end; returns the checkpoint's t. */
static double restart_to_end(const char *path)
{
    bk_h5_writer *w;
    bk_config *config = NULL;
    bk_checkpoint cp;
    bk_error err = {0};
    int rc = bk_h5_writer_resume(&w, part_of(path), &config, &cp, &err);
    if (rc != BK_OK)
        fail_msg("resume: %s", err.message);
    bk_sink sink = bk_h5_writer_sink(w);
    bk_run_stats stats;
    rc = bk_run_from(config, &cp, &sink, &stats, NULL, NULL, &err);
    if (rc != BK_OK)
        fail_msg("run: %s", err.message);
    double t = cp.t;
    bk_checkpoint_free(&cp);
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    bk_config_free(config);
    return t;
}


/* The slot of /checkpoint with the higher sequence number ("a" or "b"). */
static const char *newest_slot(const char *path)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t a = H5Gopen2(file, "checkpoint/a", H5P_DEFAULT), b = H5Gopen2(file, "checkpoint/b", H5P_DEFAULT);
    assert_true(a >= 0 && b >= 0);
    const char *newest = attr_llong(a, "sequence") > attr_llong(b, "sequence") ? "a" : "b";
    H5Gclose(a);
    H5Gclose(b);
    H5Fclose(file);
    return newest;
}

static void set_slot_double_attr(const char *path, const char *slot, const char *name, double value)
{
    char group_name[64];
    snprintf(group_name, sizeof group_name, "checkpoint/%s", slot);
    hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t group = H5Gopen2(file, group_name, H5P_DEFAULT);
    hid_t attr = H5Aopen(group, name, H5P_DEFAULT);
    assert_true(file >= 0 && group >= 0 && attr >= 0);
    assert_true(H5Awrite(attr, H5T_NATIVE_DOUBLE, &value) >= 0);
    H5Aclose(attr);
    H5Gclose(group);
    H5Fclose(file);
}

static void expect_resume_refused(const char *path, const char *needle)
{
    bk_h5_writer *w = NULL;
    bk_config *config = NULL;
    bk_checkpoint cp;
    bk_error err = {0};
    int rc = bk_h5_writer_resume(&w, part_of(path), &config, &cp, &err);
    if (rc != BK_ERR_DAMAGED || !strstr(err.message, needle) || !strstr(err.message, part_of(path)))
        fail_msg("resume returned %d \"%s\", expected damaged with \"%s\"", rc, err.message, needle);
    assert_null(w);
    assert_null(config);
    double t = -1.0;
    assert_int_equal(bk_h5_restartable(path, &t, &err), 0);
    assert_true(t == -1.0);
}

/* A checkpoint written only in part (a kill between its arrays and its attributes) fails
 * its checksum: a restart falls back to the slot before it and still ends with the output
 * of an uninterrupted run; with both slots damaged it refuses, naming each fault. */
static void test_restart_from_torn_checkpoint(void **state)
{
    fixture *f = *state;
    bk_config *config = paper_config(NULL, 0);
    char reference[256];
    snprintf(reference, sizeof reference, "%s/reference.h5", f->dir);
    run_into(config, reference, -1, 0);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(reference, &err), BK_OK);

    /* Three checkpoints (t = 0.25, 0.5, 0.75): slot a holds the third, b the second. */
    run_into(config, f->path, 3, 700);
    const char *part = part_of(f->path);
    assert_string_equal(newest_slot(part), "a");
    assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE);
    double t = 0;
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 1);
    assert_true(t == 0.75);
    assert_int_equal(bk_h5_restartable(part, &t, &err), 1);

    /* New positions reached the disk, the attributes did not (the auditor's case). */
    double x = 0.123;
    poke(part, "checkpoint/a/x", 0, 0, H5T_NATIVE_DOUBLE, &x);
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 1);
    assert_true(t == 0.5);
    assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE); /* a verified slot remains */
    assert_true(restart_to_end(f->path) == 0.5);
    assert_same_output(reference, f->path);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);

    /* Both slots damaged, one in an array and one in an attribute: refused. */
    run_into(config, f->path, 3, 700);
    poke(part, "checkpoint/a/x", 0, 0, H5T_NATIVE_DOUBLE, &x);
    set_slot_double_attr(part, "b", "t", 0.55);
    expect_resume_refused(f->path, "no checkpoint verifies, so a restart would continue from an "
                                   "inconsistent state (/checkpoint/a: checksum mismatch");
    expect_resume_refused(f->path, "/checkpoint/b: checksum mismatch");
    expect_damaged(part, "no checkpoint verifies");

    /* A slot that verifies but does not match the data: refused too. */
    run_into(config, f->path, 1, 700);
    double wrong_t = 0.2501;
    hid_t file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t slot = H5Gopen2(file, "checkpoint/a", H5P_DEFAULT);
    hsize_t rows = (hsize_t)attr_llong(slot, "rows");
    H5Gclose(slot);
    H5Fclose(file);
    poke(part, "time", rows - 1, 0, H5T_NATIVE_DOUBLE, &wrong_t);
    expect_resume_refused(f->path, "/checkpoint/a: its last row is at t = ");
    expect_resume_refused(f->path, "/checkpoint/b: not written");

    /* Stopped while writing its first checkpoint: no restart point, but no damage either. */
    run_into(config, f->path, 1, 700);
    poke(part, "checkpoint/a/x", 0, 0, H5T_NATIVE_DOUBLE, &x);
    assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE);
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0);
    bk_config *resumed = NULL;
    bk_checkpoint cp;
    bk_h5_writer *w = NULL;
    assert_int_equal(bk_h5_writer_resume(&w, part, &resumed, &cp, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "the run stopped while writing its first one"));
    bk_config_free(config);
}

/* A run killed while it rewrote the chunk that holds the checkpoint's last row leaves that
 * chunk with a wrong checksum (its rows up to the checkpoint intact): info calls it damaged,
 * and a restart rewrites the chunk and ends with the uninterrupted run's output. */
static void test_restart_repairs_last_chunk(void **state)
{
    fixture *f = *state;
    bk_config *config = paper_config(NULL, 0);
    char reference[256];
    snprintf(reference, sizeof reference, "%s/reference.h5", f->dir);
    run_into(config, reference, -1, 0);
    run_into(config, f->path, 2, 1200);
    const char *part = part_of(f->path);
    hid_t file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t slot = H5Gopen2(file, "checkpoint/b", H5P_DEFAULT);
    hsize_t rows = (hsize_t)attr_llong(slot, "rows");
    H5Gclose(slot);
    H5Fclose(file);
    /* Rows after the checkpoint in the same chunks of /time (4096 rows) and /x (512). */
    assert_true(rows % 4096 != 0 && rows % 4096 < 4096 - 2 && rows % 512 < 512 - 2);
    clobber_chunk(part, "time", rows + 1, sizeof(double));
    clobber_chunk(part, "x", rows + 1, sizeof(double));
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(part, &err), BK_ERR_DAMAGED);
    assert_non_null(strstr(err.message, "/time rows"));
    double t = 0;
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 1);
    assert_true(t == 0.5);
    assert_true(restart_to_end(f->path) == 0.5);
    assert_same_output(reference, f->path);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    bk_config_free(config);
}

/* bk_h5_restartable: only a .part with a checkpoint that verifies counts. */
static void test_restartable(void **state)
{
    fixture *f = *state;
    bk_error err = {0};
    double t = -1.0;
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0); /* no file */
    assert_int_equal(bk_h5_restartable(NULL, &t, &err), BK_ERR_INVALID);
    assert_int_equal(bk_h5_restartable("", &t, &err), BK_ERR_INVALID);

    /* A .part without checkpoints, and a complete output, are nothing to restart. */
    const char *none[] = {"output.checkpoint_interval=0"};
    bk_config *config = paper_config(none, 1);
    run_into(config, f->path, 0, 700);
    assert_true(exists(part_of(f->path)));
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0);
    bk_config_free(config);
    config = paper_config(NULL, 0);
    run_into(config, f->path, -1, 0);
    remove(part_of(f->path));
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0);
    assert_true(t == -1.0);

    /* Garbage under the .part name. */
    FILE *g = fopen(part_of(f->path), "w");
    assert_non_null(g);
    fputs("not HDF5\n", g);
    fclose(g);
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0);

    run_into(config, f->path, 2, 10);
    assert_int_equal(bk_h5_restartable(f->path, NULL, &err), 1);
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 1);
    assert_true(t == 0.5);
    bk_config_free(config);
}

/* Every --set override comes back on a restart, however many (once cut at 256: the restart
 * then ran with the wrong t_end). */
static void test_restart_keeps_all_overrides(void **state)
{
    fixture *f = *state;
    enum { N = 300 };
    const char **overrides = calloc(N, sizeof *overrides);
    assert_non_null(overrides);
    overrides[0] = "output.checkpoint_interval=0.25";
    for (size_t k = 1; k < N - 1; ++k)
        overrides[k] = "run.t_end=2";
    overrides[N - 1] = "run.t_end=0.9";
    bk_config *config = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_file("configs/paper/case_b_coulomb.ini", overrides, N, &config, &err),
                     BK_OK);
    assert_true(config->t_end == 0.9);
    run_into(config, f->path, 1, 10);
    bk_config_free(config);
    bk_h5_writer *w;
    bk_checkpoint cp;
    assert_int_equal(bk_h5_writer_resume(&w, f->path, &config, &cp, &err), BK_OK);
    assert_int_equal(config->n_overrides, N);
    assert_true(config->t_end == 0.9);
    bk_sink sink = bk_h5_writer_sink(w);
    bk_run_stats stats;
    assert_int_equal(bk_run_from(config, &cp, &sink, &stats, NULL, NULL, &err), BK_OK);
    bk_checkpoint_free(&cp);
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    bk_config_free(config);
    free(overrides);
    hid_t file = H5Fopen(f->path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(attr_double(file, "t_end") == 0.9);
    H5Fclose(file);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
}

/* A file from before the "datasets" record: what must be there follows from its config. */
static void test_verify_file_without_dataset_record(void **state)
{
    fixture *f = *state;
    const char *fields[] = {"output.fields=x mode"};
    bk_config *config = paper_config(fields, 1);
    run_into(config, f->path, -1, 0);
    bk_config_free(config);
    hid_t file = H5Fopen(f->path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_true(H5Adelete(file, "datasets") >= 0);
    H5Fclose(file);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    file = H5Fopen(f->path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(H5Ldelete(file, "mode", H5P_DEFAULT) >= 0);
    H5Fclose(file);
    expect_damaged(f->path, "no /mode");
}

int main(int argc, char **argv)
{
    self_path = argv[0];
    if (argc == 4 && strcmp(argv[1], "--disk-full") == 0)
        return disk_full_child(atoi(argv[2]), argv[3]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_roundtrip_all_fields, setup, teardown),
        cmocka_unit_test_setup_teardown(test_abandon_keeps_part, setup, teardown),
        cmocka_unit_test_setup_teardown(test_abandon_without_stats, setup, teardown),
        cmocka_unit_test_setup_teardown(test_fields_subset, setup, teardown),
        cmocka_unit_test_setup_teardown(test_energy_only, setup, teardown),
        cmocka_unit_test_setup_teardown(test_wide_chain_chunks_capped, setup, teardown),
        cmocka_unit_test_setup_teardown(test_empty_run, setup, teardown),
        cmocka_unit_test_setup_teardown(test_finish_replaces_old_output, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sink_rejects_bad_input, setup, teardown),
        cmocka_unit_test_setup_teardown(test_write_failure_finish, setup, teardown),
        cmocka_unit_test_setup_teardown(test_write_failure_abandon, setup, teardown),
        cmocka_unit_test_setup_teardown(test_write_failure_in_finish, setup, teardown),
        cmocka_unit_test_setup_teardown(test_rename_failure, setup, teardown),
        cmocka_unit_test_setup_teardown(test_export_default_one_block, setup, teardown),
        cmocka_unit_test_setup_teardown(test_export_all_blocks, setup, teardown),
        cmocka_unit_test_setup_teardown(test_export_transitions, setup, teardown),
        cmocka_unit_test_setup_teardown(test_export_errors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_info, setup, teardown),
        cmocka_unit_test_setup_teardown(test_missing_and_garbage_files, setup, teardown),
        cmocka_unit_test_setup_teardown(test_open_creates_directories, setup, teardown),
        cmocka_unit_test_setup_teardown(test_open_fails_cleanly, setup, teardown),
        cmocka_unit_test_setup_teardown(test_verify_values, setup, teardown),
        cmocka_unit_test_setup_teardown(test_verify_required_datasets, setup, teardown),
        cmocka_unit_test_setup_teardown(test_verify_transitions, setup, teardown),
        cmocka_unit_test_setup_teardown(test_verify_flipped_chunk_bytes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_verify_file_without_dataset_record, setup, teardown),
        cmocka_unit_test_setup_teardown(test_restart_from_torn_checkpoint, setup, teardown),
        cmocka_unit_test_setup_teardown(test_restart_repairs_last_chunk, setup, teardown),
        cmocka_unit_test_setup_teardown(test_restartable, setup, teardown),
        cmocka_unit_test_setup_teardown(test_restart_keeps_all_overrides, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
