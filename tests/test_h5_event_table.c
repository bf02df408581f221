/* Reading an earthquake catalog from HDF5 (src/output/h5_event_table.c): /events tables
 * written here with plain HDF5 calls, bksim's own layout and another program's, come back
 * as the columns the statistics take (bk_event_table), and `bksim stats`'s entry point
 * (bk_stats_report_read) gives the report of those columns.  The table read is /ruptures by
 * default, /events in a file without it (said in the report), or the one named.  The report's
 * numbers are test_stats.c's. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <hdf5.h>

#include "bk_test.h"
#include "bksim/inspect.h"
#include "bksim/rupture.h"
#include "bksim/stats.h"
#include "files.h"

static char dir[128];

static int setup(void **state)
{
    (void)state;
    return make_temp_dir(dir, sizeof dir, "bksim_event_table");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(dir);
}

/* A row of bksim's /events, as the writer lays it out. */
typedef struct bk_row {
    double t_start, t_end;
    int32_t first_block, n_blocks, left, right;
    double potency, magnitude, stress_drop;
    int8_t complete;
} bk_row;

static hid_t bk_row_type(void)
{
    hid_t t = H5Tcreate(H5T_COMPOUND, sizeof(bk_row));
    H5Tinsert(t, "t_start", HOFFSET(bk_row, t_start), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "t_end", HOFFSET(bk_row, t_end), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "first_block", HOFFSET(bk_row, first_block), H5T_NATIVE_INT32);
    H5Tinsert(t, "n_blocks", HOFFSET(bk_row, n_blocks), H5T_NATIVE_INT32);
    H5Tinsert(t, "left", HOFFSET(bk_row, left), H5T_NATIVE_INT32);
    H5Tinsert(t, "right", HOFFSET(bk_row, right), H5T_NATIVE_INT32);
    H5Tinsert(t, "potency", HOFFSET(bk_row, potency), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "magnitude", HOFFSET(bk_row, magnitude), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "stress_drop", HOFFSET(bk_row, stress_drop), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "complete", HOFFSET(bk_row, complete), H5T_NATIVE_INT8);
    return t;
}

/* Table `name` of n rows of mem_type (file_type on disk) in a new file (add = 0) or added to
 * an existing one (add = 1); t_reached as a root attribute when >= 0. */
static void write_table(const char *path, int add, const char *name, hid_t file_type, hid_t mem_type,
                        const void *rows, size_t n, double t_reached)
{
    hid_t file = add ? H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT)
                     : H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(file >= 0);
    hsize_t dims = n;
    hid_t space = H5Screate_simple(1, &dims, NULL);
    hid_t dset = H5Dcreate2(file, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(dset >= 0);
    if (n > 0)
        assert_true(H5Dwrite(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) >= 0);
    if (t_reached >= 0.0) {
        hid_t scalar = H5Screate(H5S_SCALAR);
        hid_t attr = H5Acreate2(file, "t_reached", H5T_IEEE_F64LE, scalar, H5P_DEFAULT,
                                H5P_DEFAULT);
        H5Awrite(attr, H5T_NATIVE_DOUBLE, &t_reached);
        H5Aclose(attr);
        H5Sclose(scalar);
    }
    H5Dclose(dset);
    H5Sclose(space);
    H5Fclose(file);
}

/* /events of a new file. */
static void write_events(const char *path, hid_t file_type, hid_t mem_type, const void *rows,
                         size_t n, double t_reached)
{
    write_table(path, 0, "events", file_type, mem_type, rows, n, t_reached);
}

/* The report of path's catalog as text (json = 0) or JSON, malloc'ed. */
static char *report_text(const bk_stats_report *rep, int json)
{
    FILE *f = tmpfile();
    assert_non_null(f);
    bk_error err = {0};
    assert_int_equal(json ? bk_stats_report_json(rep, f, &err) : bk_stats_report_text(rep, f, &err), BK_OK);
    long size = ftell(f);
    assert_true(size > 0);
    char *text = calloc((size_t)size + 1, 1);
    assert_non_null(text);
    rewind(f);
    assert_int_equal(fread(text, 1, (size_t)size, f), (size_t)size);
    fclose(f);
    return text;
}

/* bksim's layout: every column comes back as written, t_reached with them, and the report
 * of the file is the report of those columns. */
static void test_bksim_catalog(void **state)
{
    (void)state;
    char path[256];
    snprintf(path, sizeof path, "%s/catalog.h5", dir);
    enum { N = 400 };
    bk_row *rows = calloc(N, sizeof *rows);
    assert_non_null(rows);
    for (size_t i = 0; i < N; ++i) {
        rows[i].t_start = 0.5 * (double)i + 0.125;
        rows[i].t_end = rows[i].t_start + 1e-3;
        /* N(>= m) = N 10^-(m + 2): a Gutenberg-Richter law with b = 1. */
        rows[i].magnitude = -2.0 + log10((double)N / (double)(i + 1));
        rows[i].potency = pow(10.0, 1.5 * rows[i].magnitude);
        rows[i].n_blocks = 1 + (int32_t)(i % 7);
        rows[i].first_block = rows[i].left = 3;
        rows[i].right = rows[i].left + rows[i].n_blocks - 1;
        rows[i].stress_drop = 0.1;
        rows[i].complete = (int8_t)(i + 1 < N);
    }
    double t_reached = 0.5 * N;
    hid_t type = bk_row_type();
    write_events(path, type, type, rows, N, t_reached);
    H5Tclose(type);

    bk_event_table table;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_OK);
    assert_int_equal(table.n, N);
    assert_non_null(table.t_end);
    assert_non_null(table.potency);
    assert_non_null(table.n_blocks);
    assert_non_null(table.complete);
    for (size_t i = 0; i < N; ++i) {
        assert_true(table.t_start[i] == rows[i].t_start);
        assert_true(table.t_end[i] == rows[i].t_end);
        assert_true(table.magnitude[i] == rows[i].magnitude);
        assert_true(table.potency[i] == rows[i].potency);
        assert_int_equal(table.n_blocks[i], rows[i].n_blocks);
        assert_int_equal(table.complete[i], rows[i].complete);
    }
    assert_true(table.t_reached == t_reached);
    /* Only /events in the file: the default falls back to it. */
    assert_string_equal(table.name, "events");
    assert_int_equal(table.fallback, 1);
    assert_null(table.max_slip_rate);

    bk_stats_options opt;
    bk_stats_options_default(&opt);
    bk_stats_report *from_file = NULL, *from_table = NULL;
    assert_int_equal(bk_stats_report_read(path, NULL, &opt, &from_file, &err), BK_OK);
    assert_int_equal(bk_stats_report_compute(&table, path, &opt, &from_table, &err), BK_OK);
    assert_string_equal(from_file->path, path);
    assert_int_equal(from_file->n_rows, N);
    assert_int_equal(from_file->n_incomplete, 1);
    assert_int_equal(from_file->n_events, N - 1);
    assert_int_equal(from_file->duration_from_run, 1);
    assert_true(from_file->duration == t_reached);
    assert_int_equal(from_file->have_b, from_table->have_b);
    assert_true(from_file->have_b);
    assert_true(from_file->b.b == from_table->b.b);
    assert_true(from_file->mc == from_table->mc);
    assert_int_equal(from_file->n_above_mc, from_table->n_above_mc);
    /* The report says which table, and that it is the fallback. */
    assert_string_equal(from_file->table, "events");
    assert_int_equal(from_file->table_fallback, 1);
    char *text = report_text(from_file, 0);
    assert_non_null(strstr(text, "/events (the time-window catalog: the file has no /ruptures): 400 rows"));
    free(text);
    text = report_text(from_file, 1);
    assert_non_null(strstr(text, "\"table\": \"events\", \"table_fallback\": true"));
    free(text);
    bk_stats_report_free(from_file);
    bk_stats_report_free(from_table);
    bk_event_table_free(&table);
    assert_null(table.t_start);
    free(rows);
}

typedef struct foreign_row {
    float magnitude;
    long long t_start;
} foreign_row;

/* Another program's catalog: only magnitude (single precision, big-endian) and t_start
 * (64-bit integers), in that order, and no t_reached: HDF5 converts both to doubles, the
 * missing columns stay NULL and the run's span is unknown. */
static void test_foreign_catalog(void **state)
{
    (void)state;
    char path[256];
    snprintf(path, sizeof path, "%s/foreign.h5", dir);
    /* SeismoStats' UtsuBValueEstimator docstring example (test_stats.c): b = 1.1088369750721319
     * at mc = 2.0, dm = 0.1. */
    static const double utsu[] = {
        2.0, 2.5, 2.1, 2.2, 2.5, 2.2, 2.6, 2.3, 2.7, 2.2, 2.4, 2.0,
        2.7, 2.2, 2.3, 2.1, 2.4, 2.6, 2.2, 2.2, 2.7, 2.4, 2.2, 2.5,
    };
    enum { N = sizeof utsu / sizeof *utsu };
    foreign_row rows[N];
    for (size_t i = 0; i < N; ++i) {
        rows[i].magnitude = (float)utsu[i];
        rows[i].t_start = 100 + 10 * (long long)i;
    }
    hid_t file_type = H5Tcreate(H5T_COMPOUND, 12);
    H5Tinsert(file_type, "magnitude", 0, H5T_IEEE_F32BE);
    H5Tinsert(file_type, "t_start", 4, H5T_STD_I64BE);
    H5Tpack(file_type);
    hid_t mem_type = H5Tcreate(H5T_COMPOUND, sizeof(foreign_row));
    H5Tinsert(mem_type, "magnitude", HOFFSET(foreign_row, magnitude), H5T_NATIVE_FLOAT);
    H5Tinsert(mem_type, "t_start", HOFFSET(foreign_row, t_start), H5T_NATIVE_LLONG);
    write_events(path, file_type, mem_type, rows, N, -1.0);
    H5Tclose(file_type);
    H5Tclose(mem_type);

    bk_event_table table;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_OK);
    assert_int_equal(table.n, N);
    for (size_t i = 0; i < N; ++i) {
        assert_true(table.magnitude[i] == (double)(float)utsu[i]);
        assert_true(table.t_start[i] == (double)(100 + 10 * (long long)i));
    }
    assert_null(table.t_end);
    assert_null(table.potency);
    assert_null(table.n_blocks);
    assert_null(table.complete);
    assert_true(isnan(table.t_reached));
    bk_event_table_free(&table);

    bk_stats_options opt;
    bk_stats_options_default(&opt);
    opt.mc_auto = 0;
    opt.mc = 2.0;
    opt.bootstrap = 0; /* the estimator's value; tested, this sample fails the fit (test_stats.c) */
    bk_stats_report *rep = NULL;
    assert_int_equal(bk_stats_report_read(path, NULL, &opt, &rep, &err), BK_OK);
    assert_int_equal(rep->n_events, N);
    assert_false(rep->has_potency || rep->has_n_blocks || rep->has_complete || rep->has_t_end);
    assert_int_equal(rep->duration_from_run, 0);
    assert_close(rep->duration, 230.0, 0.0, 0.0);
    assert_true(rep->have_b);
    assert_close(rep->b.b, 1.1088369750721319, 1e-13, 0.0);
    bk_stats_report_free(rep);
}

static void test_errors(void **state)
{
    (void)state;
    char path[256];
    bk_event_table table;
    bk_stats_report *rep = NULL;
    bk_error err = {0};

    /* No /events at all. */
    snprintf(path, sizeof path, "%s/empty.h5", dir);
    hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(file);
    assert_int_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_ERR_INVALID);
    assert_null(table.t_start);
    assert_non_null(strstr(err.message, path));
    assert_non_null(strstr(err.message, "no /ruptures table (the rupture catalog), and no /events"));
    assert_int_equal(bk_stats_report_read(path, NULL, NULL, &rep, &err), BK_ERR_INVALID);
    assert_null(rep);
    assert_non_null(strstr(err.message, "no /ruptures table"));
    /* Named: that table, no fallback. */
    assert_int_equal(bk_stats_report_read(path, "events", NULL, &rep, &err), BK_ERR_INVALID);
    assert_null(rep);
    assert_non_null(strstr(err.message, path));
    assert_non_null(strstr(err.message, "no /events table"));
    assert_int_equal(bk_h5_read_event_table(path, "", &table, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "no table name given"));

    /* /events without magnitude: the fields that are there are named. */
    snprintf(path, sizeof path, "%s/no_magnitude.h5", dir);
    hid_t type = H5Tcreate(H5T_COMPOUND, 2 * sizeof(double));
    H5Tinsert(type, "t_start", 0, H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "potency", sizeof(double), H5T_NATIVE_DOUBLE);
    const double two_rows[] = {1.0, 2.0, 3.0, 4.0};
    write_events(path, type, type, two_rows, 2, -1.0);
    H5Tclose(type);
    assert_int_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, path));
    assert_non_null(strstr(err.message, "/events has no field 'magnitude'"));
    assert_non_null(strstr(err.message, "fields present: t_start, potency"));

    /* A magnitude that is no number. */
    snprintf(path, sizeof path, "%s/text_magnitude.h5", dir);
    hid_t text = H5Tcopy(H5T_C_S1);
    H5Tset_size(text, 8);
    type = H5Tcreate(H5T_COMPOUND, sizeof(double) + 8);
    H5Tinsert(type, "t_start", 0, H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "magnitude", sizeof(double), text);
    unsigned char text_row[sizeof(double) + 8] = {0};
    write_events(path, type, type, text_row, 1, -1.0);
    H5Tclose(type);
    H5Tclose(text);
    assert_int_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "field 'magnitude' is not numeric"));

    /* Not HDF5. */
    snprintf(path, sizeof path, "%s/text.h5", dir);
    assert_int_equal(write_text(path, "t_start magnitude\n"), 0);
    assert_int_not_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_OK);
    assert_non_null(strstr(err.message, "not an HDF5 file"));

    /* An empty table is a catalog of no events. */
    snprintf(path, sizeof path, "%s/no_events.h5", dir);
    type = bk_row_type();
    write_events(path, type, type, NULL, 0, 5.0);
    H5Tclose(type);
    assert_int_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_OK);
    assert_int_equal(table.n, 0);
    assert_true(table.t_reached == 5.0);
    bk_event_table_free(&table);
    assert_int_equal(bk_stats_report_read(path, NULL, NULL, &rep, &err), BK_OK);
    assert_int_equal(rep->n_events, 0);
    bk_stats_report_free(rep);

    /* Options are checked before the file is read: a bad one is reported even for a path
     * that does not exist. */
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    opt.dm = -0.1;
    snprintf(path, sizeof path, "%s/missing.h5", dir);
    assert_int_equal(bk_stats_report_read(path, NULL, &opt, &rep, &err), BK_ERR_INVALID);
    assert_null(rep);
    assert_non_null(strstr(err.message, "0 < dm <= 10"));
}

/* A row of bksim's /ruptures, as the writer lays it out (bk_rupture). */
static hid_t rupture_type(void)
{
    hid_t t = H5Tcreate(H5T_COMPOUND, sizeof(bk_rupture));
    H5Tinsert(t, "t_start", HOFFSET(bk_rupture, t_start), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "t_end", HOFFSET(bk_rupture, t_end), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "first_block", HOFFSET(bk_rupture, first_block), H5T_NATIVE_INT32);
    H5Tinsert(t, "n_blocks", HOFFSET(bk_rupture, n_blocks), H5T_NATIVE_INT32);
    H5Tinsert(t, "left", HOFFSET(bk_rupture, left), H5T_NATIVE_INT32);
    H5Tinsert(t, "right", HOFFSET(bk_rupture, right), H5T_NATIVE_INT32);
    H5Tinsert(t, "n_episodes", HOFFSET(bk_rupture, n_episodes), H5T_NATIVE_INT32);
    H5Tinsert(t, "potency", HOFFSET(bk_rupture, potency), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "magnitude", HOFFSET(bk_rupture, magnitude), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "max_slip_rate", HOFFSET(bk_rupture, max_slip_rate), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "stress_drop", HOFFSET(bk_rupture, stress_drop), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "duration", HOFFSET(bk_rupture, duration), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "front_speed_left", HOFFSET(bk_rupture, front_speed_left), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "front_speed_right", HOFFSET(bk_rupture, front_speed_right), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "complete", HOFFSET(bk_rupture, complete), H5T_NATIVE_INT8);
    return t;
}

/* A file with both catalogs, as a run writes them: 5 events in /events, the 12 ruptures inside
 * them in /ruptures (stored as they complete, so not in order of their starts), and a third
 * table of t_start and magnitude.  The default reads /ruptures, a name reads that table. */
static void test_table_choice(void **state)
{
    (void)state;
    char path[256];
    snprintf(path, sizeof path, "%s/both.h5", dir);
    enum { N_EVENTS = 5, N_RUPTURES = 12 };
    bk_row events[N_EVENTS];
    memset(events, 0, sizeof events);
    for (size_t i = 0; i < N_EVENTS; ++i) {
        events[i].t_start = 10.0 * (double)i;
        events[i].t_end = events[i].t_start + 1.0;
        events[i].magnitude = 1.0 + 0.1 * (double)i;
        events[i].potency = pow(10.0, 1.5 * events[i].magnitude);
        events[i].n_blocks = 10;
        events[i].complete = 1;
    }
    bk_rupture ruptures[N_RUPTURES];
    memset(ruptures, 0, sizeof ruptures);
    for (size_t i = 0; i < N_RUPTURES; ++i) {
        /* Starts 0.5 s apart, stored in the order 1, 0, 3, 2, ... */
        ruptures[i].t_start = 0.5 * (double)(i ^ 1u);
        ruptures[i].t_end = ruptures[i].t_start + 0.25;
        ruptures[i].magnitude = 0.5 + 0.05 * (double)i;
        ruptures[i].potency = pow(10.0, 1.5 * ruptures[i].magnitude);
        ruptures[i].max_slip_rate = 0.01 * (double)(i + 1);
        ruptures[i].n_blocks = 1 + (int32_t)i;
        ruptures[i].complete = (int8_t)(i + 1 < N_RUPTURES);
    }
    hid_t type = bk_row_type();
    write_table(path, 0, "events", type, type, events, N_EVENTS, 60.0);
    H5Tclose(type);
    type = rupture_type();
    write_table(path, 1, "ruptures", type, type, ruptures, N_RUPTURES, -1.0);
    H5Tclose(type);
    type = H5Tcreate(H5T_COMPOUND, 2 * sizeof(double));
    H5Tinsert(type, "t_start", 0, H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "magnitude", sizeof(double), H5T_NATIVE_DOUBLE);
    const double three[] = {1.0, 2.0, 3.0, 2.5, 5.0, 2.0};
    write_table(path, 1, "mine", type, type, three, 3, -1.0);
    H5Tclose(type);

    bk_event_table table;
    bk_error err = {0};
    /* Default: the ruptures, every column (max_slip_rate too), with the run's span. */
    assert_int_equal(bk_h5_read_event_table(path, NULL, &table, &err), BK_OK);
    assert_string_equal(table.name, "ruptures");
    assert_int_equal(table.fallback, 0);
    assert_int_equal(table.n, N_RUPTURES);
    assert_non_null(table.max_slip_rate);
    assert_non_null(table.complete);
    for (size_t i = 0; i < N_RUPTURES; ++i) {
        assert_true(table.t_start[i] == ruptures[i].t_start);
        assert_true(table.magnitude[i] == ruptures[i].magnitude);
        assert_true(table.max_slip_rate[i] == ruptures[i].max_slip_rate);
        assert_int_equal(table.n_blocks[i], ruptures[i].n_blocks);
        assert_int_equal(table.complete[i], ruptures[i].complete);
    }
    assert_true(table.t_reached == 60.0);
    bk_event_table_free(&table);
    assert_null(table.name);
    /* Named: /events, with or without the leading '/'. */
    const char *names[] = {"events", "/events"};
    for (size_t k = 0; k < 2; ++k) {
        assert_int_equal(bk_h5_read_event_table(path, names[k], &table, &err), BK_OK);
        assert_string_equal(table.name, "events");
        assert_int_equal(table.fallback, 0);
        assert_int_equal(table.n, N_EVENTS);
        assert_true(table.magnitude[4] == events[4].magnitude);
        assert_null(table.max_slip_rate); /* this /events has none */
        bk_event_table_free(&table);
    }
    /* Another table of the file: only its two fields. */
    assert_int_equal(bk_h5_read_event_table(path, "mine", &table, &err), BK_OK);
    assert_string_equal(table.name, "mine");
    assert_int_equal(table.n, 3);
    assert_true(table.magnitude[2] == 2.0);
    assert_null(table.complete);
    bk_event_table_free(&table);
    /* A table the file does not have: the file and the table named. */
    assert_int_equal(bk_h5_read_event_table(path, "rupture_rate", &table, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, path));
    assert_non_null(strstr(err.message, "no /rupture_rate table"));
    assert_null(table.t_start);
    assert_null(table.name);
    assert_int_equal(bk_h5_read_event_table(path, "group/events", &table, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "no /group/events table"));

    /* The reports: the ruptures' (11 complete), the events' (5); each names its table. */
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    bk_stats_report *rep = NULL;
    assert_int_equal(bk_stats_report_read(path, NULL, &opt, &rep, &err), BK_OK);
    assert_string_equal(rep->table, "ruptures");
    assert_int_equal(rep->table_fallback, 0);
    assert_int_equal(rep->n_rows, N_RUPTURES);
    assert_int_equal(rep->n_events, N_RUPTURES - 1);
    assert_true(rep->t_first == 0.0 && rep->t_last == 5.5); /* rows 1 and 10 */
    char *text = report_text(rep, 0);
    assert_non_null(strstr(text, "/ruptures (the rupture catalog): 12 rows"));
    free(text);
    text = report_text(rep, 1);
    assert_non_null(strstr(text, "\"table\": \"ruptures\", \"table_fallback\": false"));
    free(text);
    bk_stats_report_free(rep);
    assert_int_equal(bk_stats_report_read(path, "events", &opt, &rep, &err), BK_OK);
    assert_string_equal(rep->table, "events");
    assert_int_equal(rep->table_fallback, 0);
    assert_int_equal(rep->n_events, N_EVENTS);
    text = report_text(rep, 0);
    assert_non_null(strstr(text, "/events (the time-window catalog): 5 rows"));
    free(text);
    bk_stats_report_free(rep);
    assert_int_equal(bk_stats_report_read(path, "nothing", &opt, &rep, &err), BK_ERR_INVALID);
    assert_null(rep);
    assert_non_null(strstr(err.message, path));
    assert_non_null(strstr(err.message, "no /nothing table"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bksim_catalog),
        cmocka_unit_test(test_foreign_catalog),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_table_choice),
    };
    return cmocka_run_group_tests_name("h5_event_table", tests, setup, teardown);
}
