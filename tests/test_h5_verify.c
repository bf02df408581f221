/* The integrity check (src/output/h5_verify.c) on hand-damaged files: values that are not
 * finite or not modes, missing datasets, disordered or invalid transitions, bytes flipped
 * inside a chunk, and files from before the "datasets" record. */
#include "bk_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

#include "bksim/bksim.h"
#include "layout.h"
#include "h5_raw.h"
#include "output_fixture.h"
#include "output_files.h"
#include "stopping_sink.h"

static void test_verify_values(void **state)
{
    output_fixture *f = *state;
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

    uint8_t bad_event = 3;
    write_small(f->path, 0);
    poke(f->path, "event", 0, 0, H5T_NATIVE_UINT8, &bad_event);
    expect_damaged(f->path, "/event row 0 is 3, not 0, 1 or 2");
}

/* Two rows share a time only as a transition instant's before row (/event 2) and after row
 * (/event 1), in that order. */
static void test_verify_transition_pairs(void **state)
{
    output_fixture *f = *state;
    bk_error err = {0};
    uint8_t before = BK_ROW_BEFORE_TRANSITION, after = BK_ROW_AFTER_TRANSITION;
    double zero = 0.0;
    write_small(f->path, 0); /* rows at 0, 0.1, 0.2 s, all regular */
    poke(f->path, "event", 0, 0, H5T_NATIVE_UINT8, &before);
    poke(f->path, "event", 1, 0, H5T_NATIVE_UINT8, &after);
    poke(f->path, "time", 1, 0, H5T_NATIVE_DOUBLE, &zero);
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);

    write_small(f->path, 0); /* equal times, no pair */
    poke(f->path, "time", 1, 0, H5T_NATIVE_DOUBLE, &zero);
    expect_damaged(f->path, "/time is not strictly increasing at row 1");

    write_small(f->path, 0); /* a before row followed by a later row */
    poke(f->path, "event", 1, 0, H5T_NATIVE_UINT8, &before);
    expect_damaged(f->path, "row 2 (t = 0.20000000000000001 s, /event 0) is not the after row");

    write_small(f->path, 0); /* the pair in the wrong order */
    poke(f->path, "event", 0, 0, H5T_NATIVE_UINT8, &after);
    poke(f->path, "event", 1, 0, H5T_NATIVE_UINT8, &before);
    poke(f->path, "time", 1, 0, H5T_NATIVE_DOUBLE, &zero);
    expect_damaged(f->path, "/time is not strictly increasing at row 1");

    write_small(f->path, 0); /* a before row last */
    poke(f->path, "event", 2, 0, H5T_NATIVE_UINT8, &before);
    expect_damaged(f->path, "the last row (/event 2) is a transition instant's before row");
}

static void test_verify_required_datasets(void **state)
{
    output_fixture *f = *state;
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
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    c->t_end = row_time(2);
    write_file(f->path, c, 3, 0);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    bk_config_free(c);
}

static void test_verify_transitions(void **state)
{
    output_fixture *f = *state;
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

/* /events: read back whole, and each row checked (a catalog bksim writes is in time order,
 * inside the chain, with t_end >= t_start and potency >= 0). */
static void test_verify_events(void **state)
{
    output_fixture *f = *state;
    bk_event ok[2] = {{.t_start = 0.01, .t_end = 0.02, .first_block = 1, .n_blocks = 2, .left = 0, .right = 1,
                       .n_episodes = 2, .potency = 1e-4, .magnitude = -2.67, .max_slip_rate = 0.05,
                       .stress_drop = 1.0, .complete = 1},
                      {.t_start = 0.02, .t_end = 0.2, .first_block = 2, .n_blocks = 1, .left = 2, .right = 2,
                       .n_episodes = 1, .potency = 0.0, .magnitude = -INFINITY, .complete = 0}};
    write_small_with_events(f->path, NULL, 0, ok, 2);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);
    bk_event *back = NULL;
    size_t n = 0;
    assert_int_equal(bk_h5_read_events(f->path, &back, &n, &err), BK_OK);
    assert_int_equal(n, 2);
    assert_true(back[0].potency == 1e-4 && back[1].complete == 0 && back[1].magnitude == -INFINITY);
    free(back);

    bk_event swapped[2] = {ok[1], ok[0]};
    write_small_with_events(f->path, NULL, 0, swapped, 2);
    expect_damaged(f->path, "/events is not in time order at row 1");
    bk_event reversed = ok[0];
    reversed.t_end = 0.005;
    write_small_with_events(f->path, NULL, 0, &reversed, 1);
    expect_damaged(f->path, "/events row 0 has values no event has");
    bk_event outside = ok[0];
    outside.right = 3;
    write_small_with_events(f->path, NULL, 0, &outside, 1);
    expect_damaged(f->path, "/events row 0: first_block 1, left 0, right 3");
    write_small_with_events(f->path, NULL, 0, ok, 2);
    clobber_chunk(f->path, "events", 0, BK_EVENT_RECORD_BYTES);
    expect_damaged(f->path, "/events rows 0..1 cannot be read");
}

/* The rupture tables: each row as bksim writes it, blocks and rate rows of existing ruptures
 * in order, and as many block rows as the ruptures have blocks. */
static void test_verify_ruptures(void **state)
{
    output_fixture *f = *state;
    const bk_rupture ok = {.t_start = 0.01, .t_end = 0.05, .first_block = 1, .n_blocks = 2, .left = 1,
                           .right = 2, .n_episodes = 2, .potency = 3e-4, .magnitude = -2.35,
                           .max_slip_rate = 0.02, .stress_drop = 1.0, .duration = 0.05 - 0.01,
                           .front_speed_left = NAN, .front_speed_right = NAN, .complete = 1};
    const bk_rupture_block blocks[2] = {{0, 1, 0.01, 0.05, 2e-4}, {0, 2, 0.02, 0.04, 1e-4}};
    const bk_rupture_rate rate[3] = {{0, 0.01, 0.0}, {0, 0.03, 0.02}, {0, 0.05, 0.0}};
    write_small_with_rupture(f->path, &ok, blocks, 2, rate, 3);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(f->path, &err), BK_OK);

    bk_rupture outside = ok;
    outside.n_blocks = 4; /* of 3 blocks */
    write_small_with_rupture(f->path, &outside, blocks, 2, rate, 3);
    expect_damaged(f->path, "/ruptures row 0 has values no rupture has");
    bk_rupture stale = ok;
    stale.duration = 0.03; /* not t_end - t_start */
    write_small_with_rupture(f->path, &stale, blocks, 2, rate, 3);
    expect_damaged(f->path, "/ruptures row 0 has values no rupture has");
    write_small_with_rupture(f->path, &ok, blocks, 1, rate, 3);
    expect_damaged(f->path, "/rupture_blocks has 1 rows, the ruptures of /ruptures 2 blocks");
    bk_rupture_block later[2] = {blocks[0], blocks[1]};
    later[1].rupture = 1; /* a rupture that is not there */
    write_small_with_rupture(f->path, &ok, later, 2, rate, 3);
    expect_damaged(f->path, "/rupture_blocks row 1: rupture 1 (of 1, in order)");
    bk_rupture_rate back[3] = {rate[0], rate[2], rate[1]};
    write_small_with_rupture(f->path, &ok, blocks, 2, back, 3);
    expect_damaged(f->path, "/rupture_rate row 2: rupture 0 (of 1), t 0.029999999999999999 s");
}

/* Bytes damaged inside a chunk: the chunk's Fletcher32 checksum fails the read. */
static void test_verify_flipped_chunk_bytes(void **state)
{
    output_fixture *f = *state;
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

/* A file from before the "datasets" record: what must be there follows from its config. */
static void test_verify_file_without_dataset_record(void **state)
{
    output_fixture *f = *state;
    const char *fields[] = {"output.fields=x mode"};
    bk_config *config = checkpointed_paper_config(fields, 1);
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_verify_values),
        OUTPUT_TEST(test_verify_transition_pairs),
        OUTPUT_TEST(test_verify_required_datasets),
        OUTPUT_TEST(test_verify_transitions),
        OUTPUT_TEST(test_verify_events),
        OUTPUT_TEST(test_verify_ruptures),
        OUTPUT_TEST(test_verify_flipped_chunk_bytes),
        OUTPUT_TEST(test_verify_file_without_dataset_record),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
