/* Reading output files (src/output/h5_read.c): missing, garbage, truncated files and
 * directories give a clear error naming the file from every reader, and whole datasets read
 * back with their shapes. */
#include "bk_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "files.h"
#include "output_fixture.h"
#include "output_files.h"

static void test_missing_and_garbage_files(void **state)
{
    output_fixture *f = *state;
    char missing[256], garbage[256], truncated[256];
    snprintf(missing, sizeof missing, "%s/missing.h5", f->dir);
    snprintf(garbage, sizeof garbage, "%s/garbage.h5", f->dir);
    snprintf(truncated, sizeof truncated, "%s/truncated.h5", f->dir);
    assert_int_equal(write_text(garbage, "this is not HDF5\n"), 0);
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

/* Whole datasets come back with their shapes and values (mode and event as doubles), the
 * transitions table as records; a table or a missing name is refused for what it is. */
static void test_read_whole_datasets(void **state)
{
    output_fixture *f = *state;
    write_small(f->path, 1);
    double *data = NULL;
    size_t r, cols;
    bk_error err;
    assert_int_equal(bk_h5_read_doubles(f->path, "time", &data, &r, &cols, &err), BK_OK);
    assert_int_equal(r, 3);
    assert_int_equal(cols, 1);
    for (size_t i = 0; i < 3; ++i)
        assert_true(data[i] == 0.1 * (double)i);
    free(data);
    assert_int_equal(bk_h5_read_doubles(f->path, "x", &data, &r, &cols, &err), BK_OK);
    assert_int_equal(r, 3);
    assert_int_equal(cols, 3);
    for (size_t i = 0; i < 3; ++i)
        for (size_t b = 0; b < 3; ++b)
            assert_true(data[3 * i + b] == 0.1 * (double)(i + 1) + (double)b);
    free(data);
    assert_int_equal(bk_h5_read_doubles(f->path, "friction_state", &data, &r, &cols, &err), BK_OK);
    assert_int_equal(cols, 4);
    assert_true(data[4 * 2 + 3] == 23.0);
    free(data);
    assert_int_equal(bk_h5_read_doubles(f->path, "mode", &data, &r, &cols, &err), BK_OK);
    assert_true(data[3 * 1 + 0] == -1.0 && data[3 * 1 + 2] == 1.0);
    free(data);

    bk_transition *tr = NULL;
    size_t n = 0;
    assert_int_equal(bk_h5_read_transitions(f->path, &tr, &n, &err), BK_OK);
    assert_int_equal(n, 5);
    for (size_t k = 0; k < n; ++k) {
        bk_transition e = transition_at(k);
        assert_true(tr[k].t == e.t && tr[k].x == e.x && tr[k].v == e.v && tr[k].force == e.force);
        assert_true(tr[k].block == e.block && tr[k].from == e.from && tr[k].to == e.to);
    }
    free(tr);

    data = NULL;
    assert_int_equal(bk_h5_read_doubles(f->path, "transitions", &data, &r, &cols, &err),
                     BK_ERR_HDF5);
    assert_non_null(strstr(err.message, "not numeric"));
    assert_int_equal(bk_h5_read_doubles(f->path, "nope", &data, &r, &cols, &err), BK_ERR_HDF5);
    assert_non_null(strstr(err.message, "no dataset 'nope'"));
    assert_null(data);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_missing_and_garbage_files),
        OUTPUT_TEST(test_read_whole_datasets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
