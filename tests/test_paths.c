/* The file-system side of output files (src/paths.c): the .part naming every caller
 * shares, directories made on the way, and the durable rename with clear failures. */
#include "bk_test.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bksim/bksim.h"
#include "files.h"
#include "paths.h"
#include "output_fixture.h"

static void test_part_names(void **state)
{
    (void)state;
    assert_true(bk_output_is_part("run.h5.part"));
    assert_true(bk_output_is_part("dir/x.part"));
    assert_false(bk_output_is_part("run.h5"));
    assert_false(bk_output_is_part(".part")); /* nothing before the suffix */
    assert_false(bk_output_is_part("run.h5.part.bak"));
    char *p = bk_output_part_path("out/run.h5");
    assert_string_equal(p, "out/run.h5.part");
    char *q = bk_output_final_path(p);
    assert_string_equal(q, "out/run.h5");
    char *r = bk_output_final_path(q);
    assert_string_equal(r, "out/run.h5"); /* not a .part: a copy */
    free(p);
    free(q);
    free(r);
}

static void test_parent_directories(void **state)
{
    output_fixture *f = *state;
    char path[256], blocker[256];
    bk_error err = {0};
    snprintf(path, sizeof path, "%s/a/b/c/run.h5", f->dir);
    assert_int_equal(bk_output_make_parent_dirs(path, &err), BK_OK);
    snprintf(path, sizeof path, "%s/a/b/c", f->dir);
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    assert_true(S_ISDIR(st.st_mode));
    /* Again: existing directories are fine; a bare name needs none. */
    snprintf(path, sizeof path, "%s/a/b/c/run.h5", f->dir);
    assert_int_equal(bk_output_make_parent_dirs(path, &err), BK_OK);
    assert_int_equal(bk_output_make_parent_dirs("run.h5", &err), BK_OK);

    snprintf(blocker, sizeof blocker, "%s/file", f->dir);
    assert_int_equal(write_text(blocker, ""), 0);
    snprintf(path, sizeof path, "%s/file/sub/run.h5", f->dir);
    assert_int_equal(bk_output_make_parent_dirs(path, &err), BK_ERR_IO);
    assert_non_null(strstr(err.message, path));
    assert_non_null(strstr(err.message, "cannot create directory"));
    assert_non_null(strstr(err.message, "not a directory"));
}

static void test_durable_rename(void **state)
{
    output_fixture *f = *state;
    bk_error err = {0};
    assert_int_equal(write_text(part_path(f->path), "finished\n"), 0);
    assert_int_equal(bk_output_durable_rename(part_path(f->path), f->path, &err), BK_OK);
    assert_false(path_exists(part_path(f->path)));
    assert_true(path_exists(f->path));

    /* Nothing to sync: the error names the file. */
    assert_int_equal(bk_output_durable_rename(part_path(f->path), f->path, &err), BK_ERR_IO);
    assert_non_null(strstr(err.message, "cannot sync to disk"));
    assert_non_null(strstr(err.message, part_path(f->path)));

    /* The final name taken by a directory that is not empty. */
    char target[256], inside[300];
    snprintf(target, sizeof target, "%s/taken", f->dir);
    snprintf(inside, sizeof inside, "%s/keep", target);
    assert_int_equal(mkdir(target, 0700), 0);
    assert_int_equal(write_text(inside, ""), 0);
    assert_int_equal(bk_output_durable_rename(f->path, target, &err), BK_ERR_IO);
    assert_non_null(strstr(err.message, "cannot rename to"));
    assert_true(path_exists(f->path));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_part_names),
        OUTPUT_TEST(test_parent_directories),
        OUTPUT_TEST(test_durable_rename),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
