/* The HDF5 writer (src/output/h5_writer.c): round trips through the sink, the .part/rename
 * protocol, field selection, chunking, and write failures with clear messages. */
#include "bk_test.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <dirent.h>
#include <time.h>
#include <unistd.h>

#include <hdf5.h>

#include "bksim/bksim.h"
#include "files.h"
#include "h5_raw.h"
#include "output_fixture.h"
#include "output_files.h"

static void test_roundtrip_all_fields(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(3, BK_FIELD_ALL, 1, 1);
    assert_int_equal(c->model->n_friction_state, 4);
    const size_t rows = 9000, count = 5;
    write_file(f->path, c, rows, count);
    assert_true(path_exists(f->path));
    assert_false(path_exists(part_path(f->path)));

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
    assert_string_equal(s, SYNTHETIC_CONFIG_TEXT);
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
    /* Chunks hold the rows the config foresees (t_end / interval + 2 = 1002, fewer than a
     * full 4096-row chunk); 9000 rows of 3 blocks span nine of them, unlimited in time. */
    hid_t dcpl = H5Dget_create_plist(d);
    hsize_t chunk[2];
    assert_int_equal(H5Pget_chunk(dcpl, 2, chunk), 2);
    assert_int_equal(chunk[0], 1002);
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
    bk_config_free(c);
}

static void test_abandon_keeps_part(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(3, BK_FIELD_ALL, 1, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    assert_true(path_exists(part_path(f->path)));
    bk_sink sink = bk_h5_writer_sink(w);
    /* One flushed chunk plus rows still in the buffer: both must reach the file. */
    write_rows(&sink, c, 4700);
    write_transitions(&sink, 3);
    bk_run_stats stats = example_stats();
    bk_h5_writer_abandon(w, "integrator failure at t = 7", &stats);

    assert_false(path_exists(f->path));
    const char *part = part_path(f->path);
    assert_true(path_exists(part));
    check_series(part, "time", 4700, 1, -1);
    check_series(part, "x", 4700, 3, W_X);
    bk_transition *tr;
    size_t n_tr;
    assert_int_equal(bk_h5_read_transitions(part, &tr, &n_tr, &err), BK_OK);
    assert_int_equal(n_tr, 3);
    free(tr);
    hid_t file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(attr_llong(file, "complete"), 0);
    assert_true(attr_double(file, "t_reached") == row_time(4699));
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
    bk_config_free(c);
}

static void test_abandon_without_stats(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_rows(&sink, c, 10);
    bk_h5_writer_abandon(w, NULL, NULL);
    assert_false(path_exists(f->path));
    hid_t file = H5Fopen(part_path(f->path), H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_false(has_link(file, "stats"));
    assert_int_equal(attr_llong(file, "complete"), 0);
    char *s = attr_string(file, "error");
    assert_string_equal(s, "run abandoned");
    free(s);
    H5Fclose(file);
    check_series(part_path(f->path), "x", 10, 2, W_X);
    bk_config_free(c);
}

static void test_fields_subset(void **state)
{
    output_fixture *f = *state;
    /* STATE is selected but no block has state: no /friction_state either. */
    bk_config *c = synthetic_config(4, BK_FIELD_X | BK_FIELD_MODE | BK_FIELD_STATE, 0, 0);
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
    bk_config_free(c);
}

static void test_energy_only(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_ENERGY, 1, 1);
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
    bk_config_free(c);
}

static void test_wide_chain_chunks_capped(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(1000, BK_FIELD_X, 0, 0);
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
    bk_config_free(c);
}

/* Open file descriptors of this process. */
static size_t open_descriptors(void)
{
    DIR *dir = opendir("/proc/self/fd");
    assert_non_null(dir);
    size_t count = 0;
    while (readdir(dir))
        count++;
    closedir(dir);
    return count;
}

/* Past 8 MiB appended the writer opens the .part once more to start the disk writing behind
 * the run: a 1000-block run of 1100 rows (8.8 MB of /x) takes that path, its rows read back
 * intact, and finishing leaves no descriptor open. */
static void test_write_behind_leaves_no_descriptor(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(1000, BK_FIELD_X, 0, 0);
    size_t before = open_descriptors();
    write_file(f->path, c, 1100, 0);
    assert_int_equal(open_descriptors(), before);
    check_series(f->path, "x", 1100, 1000, W_X);
    bk_config_free(c);
}

/* Keys given as distributions: /parameters/<section>.<key> holds every block's value, with units,
 * and `bksim info` still takes the file as intact. */
static void test_drawn_parameters(void **state)
{
    output_fixture *f = *state;
    const char *text = "[model]\nn_blocks = 3\n[block]\nmass = uniform(1, 2)\ndriver_stiffness = 1e4\n"
                       "[block.1]\nmass = 5\n[friction]\nlaw = coulomb\nmu_s = normal(0.6, 0.01)\nmu_d = 0.5\n"
                       "[driver]\nvelocity = 1e-3\n[run]\nt_end = 1\n";
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "drawn.ini", NULL, 0, &c, &err), BK_OK);
    bk_h5_writer *w;
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    bk_run_stats stats;
    assert_int_equal(bk_run(c, &sink, &stats, NULL, NULL, &err), BK_OK);
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    hid_t file = H5Fopen(f->path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    double data[3];
    hid_t dset = H5Dopen2(file, "parameters/block.mass", H5P_DEFAULT);
    assert_true(dset >= 0);
    assert_true(H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0);
    for (size_t i = 0; i < 3; ++i)
        assert_true(data[i] == c->model->blocks[i].mass);
    assert_true(data[0] >= 1.0 && data[0] <= 2.0 && data[1] == 5.0);
    char *units = attr_string(dset, "units");
    assert_string_equal(units, "kg");
    free(units);
    H5Dclose(dset);
    dset = H5Dopen2(file, "parameters/friction.mu_s", H5P_DEFAULT);
    assert_true(dset >= 0);
    assert_true(H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0);
    for (size_t i = 0; i < 3; ++i)
        assert_true(data[i] == c->model->blocks[i].friction_params[0]);
    H5Dclose(dset);
    assert_true(H5Lexists(file, "parameters/block.driver_stiffness", H5P_DEFAULT) == 0); /* not drawn */
    H5Fclose(file);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    bk_config_free(c);
}

static void test_empty_run(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_ALL, 1, 0);
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
    bk_config_free(c);
}

static void test_finish_replaces_old_output(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
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
    assert_false(path_exists(part_path(f->path)));
    bk_config_free(c);
}

static void test_sink_rejects_bad_input(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(3, BK_FIELD_X | BK_FIELD_V, 1, 0);
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
    bk_config_free(c);
}

/* A full disk, simulated with a file size limit: the writer stops before a write would
 * meet it (h5_room.c) and says so with the file name and the limit, the sink refuses more
 * data, finish fails and leaves no <path>, and the .part reads back intact (a write that
 * met the limit inside HDF5 could leave it unreadable).
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
    bk_config *c = synthetic_config(50, BK_FIELD_ALL, 1, 0);
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
    CHILD_CHECK(rc == BK_ERR_IO, err);
    CHILD_CHECK(strstr(err.message, ".part: no room for the next ") != NULL, err);
    CHILD_CHECK(strstr(err.message, "within the file-size limit (ulimit -f) of 204800 bytes") != NULL, err);

    if (scenario != FAIL_IN_FINISH) {
        CHILD_CHECK(sink.sample(sink.self, &sample, &err) == BK_ERR_HDF5, err);
        CHILD_CHECK(strstr(err.message, "an earlier write failed") != NULL, err);
        if (scenario == FAIL_IN_SINK_THEN_FINISH) {
            CHILD_CHECK(bk_h5_writer_finish(w, NULL, &err) == BK_ERR_HDF5, err);
            /* finish after a failure closes the .part as it stands. */
            CHILD_CHECK(strstr(err.message, "not completed") != NULL, err);
        } else {
            bk_h5_writer_abandon(w, "disk full", NULL);
        }
    }
    /* A failed close must not leave an id behind: H5close() at exit would crash on it. */
    CHILD_CHECK(H5Fget_obj_count((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL) == 0, err);
    bk_config_free(c);
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
    assert_false(path_exists(path));
    assert_true(path_exists(part_path(path)));
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(part_path(path), &err), BK_INCOMPLETE);
}

static void test_write_failure_finish(void **state)
{
    output_fixture *f = *state;
    run_out_of_space(f->path, FAIL_IN_SINK_THEN_FINISH);
}

static void test_write_failure_abandon(void **state)
{
    output_fixture *f = *state;
    run_out_of_space(f->path, FAIL_IN_SINK_THEN_ABANDON);
}

static void test_write_failure_in_finish(void **state)
{
    output_fixture *f = *state;
    run_out_of_space(f->path, FAIL_IN_FINISH);
}

/* Something took the final name while the run wrote (a directory, a file of the user's):
 * finish refuses to replace it, leaves it as it was, and the .part, already marked complete,
 * is marked incomplete again with the reason. */
static void finish_refused(const char *path, const bk_config *c, const char *reason)
{
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_rows(&sink, c, 10);
    if (reason[0] == 'd') {
        assert_int_equal(mkdir(path, 0700), 0);
        char inside[256];
        snprintf(inside, sizeof inside, "%s/keep", path);
        assert_int_equal(write_text(inside, ""), 0);
    } else {
        assert_int_equal(write_text(path, "the user's notes\n"), 0);
    }
    assert_int_equal(bk_h5_writer_finish(w, NULL, &err), BK_ERR_INVALID);
    const char *said = reason[0] == 'd' ? "is a directory" : "exists and is not a bksim output (not an HDF5 file)";
    assert_non_null(strstr(err.message, said));
    hid_t file = H5Fopen(part_path(path), H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(attr_llong(file, "complete"), 0);
    char *s = attr_string(file, "error");
    assert_non_null(strstr(s, said));
    free(s);
    H5Fclose(file);
    check_series(part_path(path), "x", 10, 2, W_X);
    if (reason[0] != 'd') {
        char *text = file_contents(path);
        assert_non_null(text);
        assert_string_equal(text, "the user's notes\n");
        free(text);
    }
}

static void test_name_taken_meanwhile(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    finish_refused(f->path, c, "directory");
    char other[512];
    snprintf(other, sizeof other, "%s.notes", f->path);
    finish_refused(other, c, "file");
    remove(other);
    remove(part_path(other));
    bk_config_free(c);
}

/* Opening never truncates a file that is not bksim's, at OUT or at OUT.part, and says what
 * is there; an HDF5 file of another program is not bksim's either. */
static void test_open_refuses_others_files(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(write_text(f->path, "a config, say\n"), 0);
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "exists and is not a bksim output (not an HDF5 file)"));
    assert_false(path_exists(part_path(f->path)));
    remove(f->path);
    assert_int_equal(write_text(part_path(f->path), "notes\n"), 0);
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, ".part: exists and is not a bksim output"));
    remove(part_path(f->path));
    hid_t other = H5Fcreate(f->path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(other >= 0);
    H5Fclose(other);
    assert_int_equal(bk_h5_writer_open(&w, c, f->path, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "an HDF5 file without bksim's root attributes"));
    remove(f->path);
    /* A bksim output is replaced (test_finish_replaces_old_output). */
    bk_config_free(c);
}

static void test_open_creates_directories(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    char path[256];
    snprintf(path, sizeof path, "%s/a/b/c/run.h5", f->dir);
    write_file(path, c, 3, 0);
    check_series(path, "x", 3, 2, W_X);
    bk_config_free(c);
}

static void test_open_fails_cleanly(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    char blocker[256], path[300];
    snprintf(blocker, sizeof blocker, "%s/blocker", f->dir);
    assert_int_equal(write_text(blocker, ""), 0);
    snprintf(path, sizeof path, "%s/sub/run.h5", blocker);
    char not_null;
    bk_h5_writer *w = (bk_h5_writer *)(void *)&not_null; /* open must reset it to NULL */
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_ERR_IO);
    assert_null(w);
    assert_non_null(strstr(err.message, "cannot create directory"));
    assert_non_null(strstr(err.message, blocker));
    assert_non_null(strstr(err.message, "not a directory"));

    /* The output path names an existing directory (the CLI puts its file in it instead:
     * bk_output_resolve). */
    assert_int_equal(bk_h5_writer_open(&w, c, f->dir, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "is a directory"));

    /* The .part name is taken by a directory: refused before anything is created. */
    char part[320];
    snprintf(path, sizeof path, "%s/taken.h5", f->dir);
    snprintf(part, sizeof part, "%s.part", path);
    assert_int_equal(mkdir(part, 0700), 0);
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, ".part: is a directory"));
    assert_false(path_exists(path));
    bk_config_free(c);
}

/* What a SIGKILL leaves: the last commit, made once a second of wall-clock time has passed
 * (within COMMIT_CHECK_EVERY records), not one per chunk.  A child writes 100 rows and 3
 * transitions, waits 1.2 s, writes 200 more rows and is killed (SIGKILL); the .part holds
 * every dataset cut at the same committed row, its transitions and a matching t_reached. */
static void test_commit_by_wall_clock(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(3, BK_FIELD_ALL, 1, 0);
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        bk_h5_writer *w;
        bk_error err;
        if (bk_h5_writer_open(&w, c, f->path, &err) != BK_OK)
            _exit(3);
        bk_sink sink = bk_h5_writer_sink(w);
        write_rows(&sink, c, 100);
        write_transitions(&sink, 3);
        nanosleep(&(struct timespec){1, 200000000}, NULL);
        write_row_range(&sink, c, 100, 200);
        raise(SIGKILL);
    }
    int status;
    assert_int_equal(waitpid(child, &status, 0), child);
    assert_true(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    const char *part = part_path(f->path);
    hid_t file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t d = H5Dopen2(file, "time", H5P_DEFAULT);
    hid_t space = H5Dget_space(d);
    hsize_t dims[1];
    H5Sget_simple_extent_dims(space, dims, NULL);
    size_t rows = (size_t)dims[0];
    H5Sclose(space);
    H5Dclose(d);
    assert_true(rows > 100 && rows <= 100 + 64);
    assert_true(attr_double(file, "t_reached") == row_time(rows - 1));
    H5Fclose(file);
    check_series(part, "time", rows, 1, -1);
    check_series(part, "x", rows, 3, W_X);
    check_series(part, "cof", rows, 3, W_COF);
    bk_transition *tr;
    size_t n_tr;
    bk_error err;
    assert_int_equal(bk_h5_read_transitions(part, &tr, &n_tr, &err), BK_OK);
    assert_int_equal(n_tr, 3);
    free(tr);
    bk_config_free(c);
}

int main(int argc, char **argv)
{
    self_path = argv[0];
    if (argc == 4 && strcmp(argv[1], "--disk-full") == 0)
        return disk_full_child(atoi(argv[2]), argv[3]);
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_roundtrip_all_fields),
        OUTPUT_TEST(test_abandon_keeps_part),
        OUTPUT_TEST(test_commit_by_wall_clock),
        OUTPUT_TEST(test_abandon_without_stats),
        OUTPUT_TEST(test_fields_subset),
        OUTPUT_TEST(test_energy_only),
        OUTPUT_TEST(test_wide_chain_chunks_capped),
        OUTPUT_TEST(test_write_behind_leaves_no_descriptor),
        OUTPUT_TEST(test_empty_run),
        OUTPUT_TEST(test_drawn_parameters),
        OUTPUT_TEST(test_finish_replaces_old_output),
        OUTPUT_TEST(test_sink_rejects_bad_input),
        OUTPUT_TEST(test_write_failure_finish),
        OUTPUT_TEST(test_write_failure_abandon),
        OUTPUT_TEST(test_write_failure_in_finish),
        OUTPUT_TEST(test_name_taken_meanwhile),
        OUTPUT_TEST(test_open_refuses_others_files),
        OUTPUT_TEST(test_open_creates_directories),
        OUTPUT_TEST(test_open_fails_cleanly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
