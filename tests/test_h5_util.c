/* HDF5 plumbing (src/output/h5_util.c): attributes written and read back in every form the
 * files use, error messages that keep HDF5's own reason even after ids are closed, and the
 * transition record's layouts. */
#include "bk_test.h"

#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "output/h5_impl.h"
#include "output_fixture.h"

/* A fixed-length string attribute replaces one of another length, and a variable-length one
 * (an older file's): both read back through the same reader. */
static void test_string_attributes(void **state)
{
    output_fixture *f = *state;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t file = H5Fcreate(f->path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_true(bk_h5_write_string_attr(file, "text", "variable-length, at creation") >= 0);
    char *s = bk_h5_read_string_attr(file, "text");
    assert_string_equal(s, "variable-length, at creation");
    free(s);
    assert_true(bk_h5_write_fixed_string_attr(file, "text", "short") >= 0);
    s = bk_h5_read_string_attr(file, "text");
    assert_string_equal(s, "short");
    free(s);
    assert_true(bk_h5_write_fixed_string_attr(file, "text", "a longer text than before") >= 0);
    s = bk_h5_read_string_attr(file, "text");
    assert_string_equal(s, "a longer text than before");
    free(s);
    assert_true(bk_h5_write_fixed_string_attr(file, "empty", "") >= 0);
    s = bk_h5_read_string_attr(file, "empty");
    assert_string_equal(s, "");
    free(s);
    assert_null(bk_h5_read_string_attr(file, "absent"));
    assert_true(bk_h5_write_double_attr(file, "number", 2.385) >= 0);
    assert_null(bk_h5_read_string_attr(file, "number"));
    H5Fclose(file);
}

static void test_numeric_attributes(void **state)
{
    output_fixture *f = *state;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t file = H5Fcreate(f->path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_true(bk_h5_write_int_attr(file, "flag", 1) >= 0);
    assert_true(bk_h5_write_long_attr(file, "count", 1LL << 40) >= 0);
    assert_true(bk_h5_write_double_attr(file, "t", 0.1) >= 0);
    assert_true(bk_h5_write_double_attr(file, "t", 0.7) >= 0); /* overwritten in place */
    double d = 0;
    long long n = 0;
    assert_true(bk_h5_read_numeric_attr(file, "flag", H5T_NATIVE_DOUBLE, &d) >= 0);
    assert_true(d == 1.0);
    assert_true(bk_h5_read_numeric_attr(file, "count", H5T_NATIVE_LLONG, &n) >= 0);
    assert_true(n == 1LL << 40);
    assert_true(bk_h5_read_numeric_attr(file, "t", H5T_NATIVE_DOUBLE, &d) >= 0);
    assert_true(d == 0.7);
    assert_true(bk_h5_read_numeric_attr(file, "absent", H5T_NATIVE_DOUBLE, &d) < 0);
    assert_true(bk_h5_write_string_attr(file, "word", "seven") >= 0);
    assert_true(bk_h5_read_numeric_attr(file, "word", H5T_NATIVE_DOUBLE, &d) < 0);
    assert_true(bk_h5_describe(file, "s", "what it is") >= 0);
    char *s = bk_h5_read_string_attr(file, "units");
    assert_string_equal(s, "s");
    free(s);
    H5Fclose(file);
}

/* HDF5's innermost reason (here the system's) is appended to our message, also when ids
 * were closed between the failure and the report. */
static void test_fail_keeps_hdf5_reason(void **state)
{
    output_fixture *f = *state;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t plist = H5Pcreate(H5P_FILE_ACCESS);
    assert_true(plist >= 0);
    char missing[256];
    snprintf(missing, sizeof missing, "%s/missing.h5", f->dir);
    hid_t file = H5Fopen(missing, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file < 0);
    CLOSE_IDS(-1, plist);
    bk_error err = {0};
    assert_int_equal(H5_FAIL(&err, "%s: cannot open", missing), BK_ERR_HDF5);
    assert_non_null(strstr(err.message, "cannot open (HDF5: "));
    assert_non_null(strstr(err.message, "No such file or directory"));
    assert_int_equal(err.status, BK_ERR_HDF5);
    /* With nothing on HDF5's stack, only our message. */
    H5Eclear2(H5E_DEFAULT);
    assert_int_equal(H5_DAMAGED(&err, "plain"), BK_ERR_DAMAGED);
    assert_string_equal(err.message, "plain");
}

static void test_transition_types(void **state)
{
    (void)state;
    hid_t mem = bk_h5_transition_type(BK_H5_RECORD_STRUCT), disk = bk_h5_transition_type(BK_H5_RECORD_FILE);
    assert_true(mem >= 0 && disk >= 0);
    assert_int_equal(H5Tget_size(mem), sizeof(bk_transition));
    assert_int_equal(H5Tget_size(disk), 38); /* packed: 8 + 4 + 1 + 1 + 3 x 8 */
    assert_int_equal(H5Tget_nmembers(disk), 7);
    assert_true(H5Tequal(bk_h5_kind_file_type(BK_KIND_I8), H5T_STD_I8LE) > 0);
    assert_int_equal(H5Tget_size(bk_h5_kind_mem_type(BK_KIND_F64)), bk_series_value_size(BK_KIND_F64));
    assert_int_equal(H5Tget_size(bk_h5_kind_mem_type(BK_KIND_U8)), bk_series_value_size(BK_KIND_U8));
    H5Tclose(mem);
    H5Tclose(disk);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_string_attributes),
        OUTPUT_TEST(test_numeric_attributes),
        OUTPUT_TEST(test_fail_keeps_hdf5_reason),
        OUTPUT_TEST(test_transition_types),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
