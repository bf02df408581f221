/* Synthetic output files; see output_files.h. */
#include "output_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"

/* Laws with state, so /friction_state has columns of uneven blocks: 1 + 2 + 1. */
static const bk_friction_law one_state = {.name = "one_state", .n_state = 1};
static const bk_friction_law two_states = {.name = "two_states", .n_state = 2};

const char SYNTHETIC_CONFIG_TEXT[] = "[run]\nt_end = 10\n\n[chain]\nblocks = 3\n";

bk_config *synthetic_config(size_t n, unsigned fields, int transitions, int with_state)
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
    c->text = strdup(SYNTHETIC_CONFIG_TEXT);
    assert_non_null(c->source_name);
    assert_non_null(c->text);
    return c;
}

/* Deterministic, non-round values so exact equality means an exact round trip. */
double value(size_t row, size_t col, int which)
{
    return sin(0.001 * (double)row * (which + 1) + (double)col) * pow(10.0, which - 3) +
           1.0 / 3.0;
}

double row_time(size_t row) { return 0.01 * (double)row + 1e-13; }

int8_t row_mode(size_t row, size_t col) { return (int8_t)((row / 100 + col) % 3) - 1; }

void write_rows(bk_sink *sink, const bk_config *c, size_t rows)
{
    write_row_range(sink, c, 0, rows);
}

/* Send rows [first, first + rows) through the sink; row 7k is an event row. */
void write_row_range(bk_sink *sink, const bk_config *c, size_t first, size_t rows)
{
    size_t n = c->model->n_blocks, s = c->model->n_friction_state;
    double *x = malloc(n * sizeof *x), *v = malloc(n * sizeof *v);
    double *fr = malloc(n * sizeof *fr), *cof = malloc(n * sizeof *cof);
    double *st = malloc((s ? s : 1) * sizeof *st);
    int8_t *mode = malloc(n);
    assert_true(x && v && fr && cof && st && mode);
    bk_error err;
    for (size_t r = first; r < first + rows; ++r) {
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

bk_transition transition_at(size_t k)
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

void write_transitions(bk_sink *sink, size_t count)
{
    bk_error err;
    for (size_t k = 0; k < count; ++k) {
        bk_transition t = transition_at(k);
        assert_int_equal(sink->transition(sink->self, &t, &err), BK_OK);
    }
}

bk_run_stats example_stats(void)
{
    bk_run_stats stats = {.method = "cvode_adams", .steps = 1234, .rhs_evals = 5678,
                          .root_evals = 91, .transitions = 5, .rows = 1500,
                          .t_reached = 14.99, .wall_time = 0.5, .cpu_time = 0.25,
                          .work_driver = 2.5, .dissipation = 2.25,
                          .energy_residual = 1e-12};
    return stats;
}

/* Write a file of `rows` rows and `count` transitions and finish it. */
void write_file(const char *path, const bk_config *c, size_t rows, size_t count)
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

/* A small file with round-looking values whose %.17g forms are not round. */
void write_small(const char *path, int with_state)
{
    bk_config *c = synthetic_config(3, BK_FIELD_ALL, 1, with_state);
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
    bk_config_free(c);
}

/* write_small with these transitions instead of the usual five. */
void write_small_with(const char *path, const bk_transition *transitions, size_t n)
{
    write_small_with_events(path, transitions, n, NULL, 0);
}

/* The three rows of the 3-block files below, at t = 0, 0.1, 0.2 s. */
static void write_three_rows(const bk_sink *sink)
{
    bk_error err;
    double x[3] = {0.1, 0.2, 0.3}, v[3] = {0}, fr[3] = {1, 2, 3}, cof[3] = {0.6, 0.6, 0.6};
    int8_t mode[3] = {0, 1, -1};
    for (int r = 0; r < 3; ++r) {
        bk_sample sample = {.t = 0.1 * r, .driver = 0.7 * r, .n_blocks = 3, .x = x, .v = v,
                            .friction = fr, .cof = cof, .mode = mode};
        assert_int_equal(sink->sample(sink->self, &sample, &err), BK_OK);
    }
}

void write_small_with_events(const char *path, const bk_transition *transitions, size_t n,
                             const bk_event *events, size_t n_events)
{
    bk_config *c = synthetic_config(3, BK_FIELD_ALL, 1, 0);
    c->t_end = 0.2;
    c->output.events = events != NULL;
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_three_rows(&sink);
    for (size_t k = 0; k < n; ++k)
        assert_int_equal(sink.transition(sink.self, &transitions[k], &err), BK_OK);
    for (size_t k = 0; k < n_events; ++k)
        assert_int_equal(sink.event(sink.self, &events[k], &err), BK_OK);
    bk_run_stats stats = example_stats();
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    bk_config_free(c);
}

void write_small_with_rupture(const char *path, const bk_rupture *rupture, const bk_rupture_block *blocks,
                              size_t n_blocks, const bk_rupture_rate *rate, size_t n_rate)
{
    bk_config *c = synthetic_config(3, BK_FIELD_ALL, 0, 0);
    c->t_end = 0.2;
    c->output.events = 1;
    c->catalog.rupture_rate = 1;
    bk_h5_writer *w;
    bk_error err;
    assert_int_equal(bk_h5_writer_open(&w, c, path, &err), BK_OK);
    bk_sink sink = bk_h5_writer_sink(w);
    write_three_rows(&sink);
    assert_int_equal(sink.rupture(sink.self, rupture, blocks, n_blocks, rate, n_rate, &err), BK_OK);
    bk_run_stats stats = example_stats();
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    bk_config_free(c);
}

void check_series(const char *path, const char *name, size_t rows, size_t cols,
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

void expect_damaged(const char *path, const char *needle)
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
