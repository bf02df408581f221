/* Checkpoint slots and restarts (src/output/h5_checkpoint.c) of real runs: torn slots fall
 * back to the other one, a damaged last chunk is repaired, restartable files are told from
 * others, every override comes back, and a .part written by an earlier version restarts. */
#include "bk_test.h"

#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

#include "bksim/bksim.h"
#include "files.h"
#include "h5_raw.h"
#include "output_fixture.h"
#include "output_files.h"
#include "same_output.h"
#include "stopping_sink.h"

/* A resumed run tells its progress callback where it resumed, and counts on from there. */
typedef struct resume_check {
    const bk_checkpoint *from;
    long calls;
} resume_check;

static int check_resumed(void *user, const bk_progress *p)
{
    resume_check *rc = user;
    rc->calls++;
    assert_true(p->t_resumed == rc->from->t && p->t >= p->t_resumed);
    long before = rc->from->catalog ? rc->from->catalog->events : 0;
    assert_int_equal(p->events_resumed, before);
    assert_true(p->events < 0 || p->events >= before);
    assert_true(p->transitions >= rc->from->stats.transitions);
    return 0;
}

/* Restart path.part and run it to the end; returns the checkpoint's t. */
static double restart_to_end(const char *path)
{
    bk_h5_writer *w;
    bk_config *config = NULL;
    bk_checkpoint cp;
    bk_error err = {0};
    int rc = bk_h5_writer_resume(&w, part_path(path), &config, &cp, &err);
    if (rc != BK_OK)
        fail_msg("resume: %s", err.message);
    bk_sink sink = bk_h5_writer_sink(w);
    bk_run_stats stats;
    resume_check check = {&cp, 0};
    rc = bk_run_from(config, &cp, &sink, &stats, check_resumed, &check, &err);
    if (rc != BK_OK)
        fail_msg("run: %s", err.message);
    assert_true(check.calls > 0);
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
    int rc = bk_h5_writer_resume(&w, part_path(path), &config, &cp, &err);
    if (rc != BK_ERR_DAMAGED || !strstr(err.message, needle) || !strstr(err.message, part_path(path)))
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
    output_fixture *f = *state;
    bk_config *config = checkpointed_paper_config(NULL, 0);
    char reference[256];
    snprintf(reference, sizeof reference, "%s/reference.h5", f->dir);
    run_into(config, reference, -1, 0);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(reference, &err), BK_OK);

    /* Three checkpoints (t = 0.25, 0.5, 0.75): slot a holds the third, b the second. */
    run_into(config, f->path, 3, 700);
    const char *part = part_path(f->path);
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
    output_fixture *f = *state;
    bk_config *config = checkpointed_paper_config(NULL, 0);
    char reference[256];
    snprintf(reference, sizeof reference, "%s/reference.h5", f->dir);
    run_into(config, reference, -1, 0);
    run_into(config, f->path, 2, 1200);
    const char *part = part_path(f->path);
    hid_t file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t slot = H5Gopen2(file, "checkpoint/b", H5P_DEFAULT);
    hsize_t rows = (hsize_t)attr_llong(slot, "rows");
    H5Gclose(slot);
    H5Fclose(file);
    /* Rows after the checkpoint in the same chunks of /time and /x (4096 rows each). */
    assert_true(rows % 4096 != 0 && rows % 4096 < 4096 - 2);
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
    output_fixture *f = *state;
    bk_error err = {0};
    double t = -1.0;
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0); /* no file */
    assert_int_equal(bk_h5_restartable(NULL, &t, &err), BK_ERR_INVALID);
    assert_int_equal(bk_h5_restartable("", &t, &err), BK_ERR_INVALID);

    /* A .part without checkpoints, and a complete output, are nothing to restart. */
    const char *none[] = {"output.checkpoint_interval=0"};
    bk_config *config = checkpointed_paper_config(none, 1);
    run_into(config, f->path, 0, 700);
    assert_true(path_exists(part_path(f->path)));
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0);
    bk_config_free(config);
    config = checkpointed_paper_config(NULL, 0);
    run_into(config, f->path, -1, 0);
    remove(part_path(f->path));
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0);
    assert_true(t == -1.0);

    /* Garbage under the .part name: nothing to restart, and not bksim's to replace. */
    assert_int_equal(write_text(part_path(f->path), "not HDF5\n"), 0);
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 0);
    bk_h5_writer *refused = NULL;
    assert_int_equal(bk_h5_writer_open(&refused, config, f->path, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, ".part: exists and is not a bksim output (not an HDF5 file)"));
    /* Empty (a run killed as it created it): bksim's working file, replaced. */
    assert_int_equal(write_text(part_path(f->path), ""), 0);

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
    output_fixture *f = *state;
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

/* Rows [0, rows) of dataset name agree bit for bit in files a and b. */
static void expect_same_rows(const char *a, const char *b, const char *name, size_t rows)
{
    double *x, *y;
    size_t ra, ca, rb, cb;
    bk_error err;
    assert_int_equal(bk_h5_read_doubles(a, name, &x, &ra, &ca, &err), BK_OK);
    assert_int_equal(bk_h5_read_doubles(b, name, &y, &rb, &cb, &err), BK_OK);
    assert_true(ra >= rows && rb >= rows && ca == cb);
    if (memcmp(x, y, rows * ca * sizeof *x) != 0)
        fail_msg("/%s: the rows before the checkpoint changed", name);
    free(x);
    free(y);
}

static int by_time(const void *a, const void *b)
{
    const bk_transition *x = a, *y = b;
    return (x->t > y->t) - (x->t < y->t);
}

/* A .part written by bksim before the output module was split (tests/data/README.md)
 * verifies and restarts from its newest checkpoint: the rows and transitions it holds up to
 * there are kept as they are, and the run ends with the transitions of an uninterrupted run
 * of the config it stores, to the method's accuracy (the algorithm has changed since that
 * version, so not bit for bit: the file format is what holds). */
static void test_restart_file_of_earlier_version(void **state)
{
    output_fixture *f = *state;
    const char *fixture = "tests/data/chain3_rs_d9ab1a6.h5.part";
    assert_int_equal(copy_file(fixture, part_path(f->path)), 0);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(part_path(f->path), &err), BK_INCOMPLETE);
    double t = 0;
    assert_int_equal(bk_h5_restartable(f->path, &t, &err), 1);
    assert_true(t == 1.0);
    hid_t file = H5Fopen(fixture, H5F_ACC_RDONLY, H5P_DEFAULT);
    char slot_name[32];
    snprintf(slot_name, sizeof slot_name, "checkpoint/%s", newest_slot(fixture));
    hid_t slot = H5Gopen2(file, slot_name, H5P_DEFAULT);
    size_t rows = (size_t)attr_llong(slot, "rows"), transition_rows = (size_t)attr_llong(slot, "transition_rows");
    H5Gclose(slot);
    H5Fclose(file);

    bk_h5_writer *w;
    bk_config *config = NULL;
    bk_checkpoint cp;
    int rc = bk_h5_writer_resume(&w, part_path(f->path), &config, &cp, &err);
    if (rc != BK_OK)
        fail_msg("resume: %s", err.message);
    assert_int_equal(config->model->n_blocks, 3);
    assert_int_equal(cp.n_state, 3);
    bk_sink sink = bk_h5_writer_sink(w);
    bk_run_stats stats;
    rc = bk_run_from(config, &cp, &sink, &stats, NULL, NULL, &err);
    if (rc != BK_OK)
        fail_msg("run: %s", err.message);
    bk_checkpoint_free(&cp);
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    static const char *const kept[] = {"time", "x", "v", "friction_state", "mode", "work_driver"};
    for (size_t k = 0; k < sizeof kept / sizeof *kept; ++k)
        expect_same_rows(fixture, f->path, kept[k], rows);

    char reference[256];
    snprintf(reference, sizeof reference, "%s/reference.h5", f->dir);
    run_into(config, reference, -1, 0);
    bk_transition *restarted, *uninterrupted, *old;
    size_t n_restarted, n_uninterrupted, n_old;
    assert_int_equal(bk_h5_read_transitions(f->path, &restarted, &n_restarted, &err), BK_OK);
    assert_int_equal(bk_h5_read_transitions(reference, &uninterrupted, &n_uninterrupted, &err), BK_OK);
    assert_int_equal(bk_h5_read_transitions(fixture, &old, &n_old, &err), BK_OK);
    assert_true(n_old >= transition_rows && n_restarted >= transition_rows);
    for (size_t k = 0; k < transition_rows; ++k)
        assert_true(old[k].t == restarted[k].t && old[k].block == restarted[k].block &&
                    old[k].from == restarted[k].from && old[k].to == restarted[k].to &&
                    old[k].x == restarted[k].x && old[k].v == restarted[k].v &&
                    old[k].force == restarted[k].force);
    /* Blocks 0 and 2 mirror each other: their simultaneous transitions may come out in
     * either order at rounding level, so the times are compared in time order. */
    assert_int_equal(n_restarted, n_uninterrupted);
    qsort(restarted, n_restarted, sizeof *restarted, by_time);
    qsort(uninterrupted, n_uninterrupted, sizeof *uninterrupted, by_time);
    for (size_t k = 0; k < n_restarted; ++k)
        assert_close(restarted[k].t, uninterrupted[k].t, 0, 1e-8); /* rtol 1e-8, t ~ 1 s */
    free(restarted);
    free(uninterrupted);
    free(old);
    bk_config_free(config);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_restart_from_torn_checkpoint),
        OUTPUT_TEST(test_restart_repairs_last_chunk),
        OUTPUT_TEST(test_restartable),
        OUTPUT_TEST(test_restart_keeps_all_overrides),
        OUTPUT_TEST(test_restart_file_of_earlier_version),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
