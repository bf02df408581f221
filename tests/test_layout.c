/* The output layout table (src/layout.c): the datasets, the [output] fields words,
 * the bytes per row and the dataset list, and that the config's max_bytes guard counts
 * exactly what the table describes. */
#include "bk_test.h"

#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "layout.h"

static void test_table_well_formed(void **state)
{
    (void)state;
    unsigned seen_fields = 0;
    for (int i = 0; i < BK_N_SERIES; ++i) {
        const bk_series_def *def = &bk_series[i];
        assert_true(def->name && def->name[0]);
        assert_true(def->units && def->units[0]);
        assert_true(def->description && def->description[0]);
        /* Names other parts of the file use are not available to series. */
        assert_true(strcmp(def->name, "transitions") != 0 && strcmp(def->name, "checkpoint") != 0 &&
                    strcmp(def->name, "stats") != 0);
        for (int j = i + 1; j < BK_N_SERIES; ++j)
            if (strcmp(def->name, bk_series[j].name) == 0)
                fail_msg("dataset /%s listed twice", def->name);
        /* A series is always written or selected by exactly one field bit. */
        assert_true(def->field == 0 || (def->field & (def->field - 1)) == 0);
        assert_true((def->field & ~(unsigned)BK_FIELD_ALL) == 0);
        seen_fields |= def->field;
    }
    /* Every field word selects at least one dataset. */
    assert_int_equal(seen_fields, BK_FIELD_ALL);
    assert_string_equal(bk_series[BK_SERIES_TIME].name, "time");
    assert_string_equal(bk_series[BK_SERIES_STATE].name, "friction_state");
}

/* Word i of [output] fields is the word the config loader accepts for bit 1 << i. */
static void test_field_words_parse_to_their_bits(void **state)
{
    (void)state;
    size_t i = 0;
    for (; bk_output_field_names[i]; ++i) {
        char over[64];
        snprintf(over, sizeof over, "output.fields=%s", bk_output_field_names[i]);
        const char *overrides[] = {over};
        bk_config *config = NULL;
        bk_error err = {0};
        int rc = bk_config_load_file("configs/paper/case_a_coulomb.ini", overrides, 1, &config, &err);
        if (rc != BK_OK)
            fail_msg("%s: %s", over, err.message);
        assert_int_equal(config->output.fields, 1u << i);
        bk_config_free(config);
    }
    assert_int_equal(1u << i, BK_FIELD_ALL + 1u);
}

static void test_row_bytes(void **state)
{
    (void)state;
    /* time 8 + driver 8 + event 1; per block x v friction cof 8 each and mode 1; four
     * energies 8 each (five with dashpots); each friction state 8. */
    assert_close(bk_output_row_bytes(BK_FIELD_ALL, 3, 4, 0), 17.0 + 3 * 33.0 + 32.0 + 32.0, 0, 0);
    assert_close(bk_output_row_bytes(BK_FIELD_ALL, 3, 4, 1), 17.0 + 3 * 33.0 + 40.0 + 32.0, 0, 0);
    assert_close(bk_output_row_bytes(BK_FIELD_X | BK_FIELD_MODE, 1000, 0, 1), 17.0 + 9000.0, 0, 0);
    assert_close(bk_output_row_bytes(0, 1000, 5, 0), 17.0, 0, 0);
    /* State selected but no block has any: nothing for it. */
    assert_close(bk_output_row_bytes(BK_FIELD_STATE, 7, 0, 0), 17.0, 0, 0);
    assert_close(bk_output_row_bytes(BK_FIELD_STATE, 7, 2, 0), 33.0, 0, 0);
}

static void test_dataset_names(void **state)
{
    (void)state;
    char names[BK_DATASET_LIST_LEN];
    bk_output_dataset_names(BK_FIELD_ALL, 0, 0, 1, 0, names, sizeof names);
    assert_string_equal(names, "time,driver,event,x,v,friction,cof,mode,energy_kinetic,"
                               "energy_elastic,work_driver,dissipation,transitions");
    bk_output_dataset_names(BK_FIELD_ALL, 2, 0, 0, 1, names, sizeof names);
    assert_string_equal(names, "time,driver,event,x,v,friction,cof,mode,energy_kinetic,"
                               "energy_elastic,work_driver,dissipation,friction_state,events");
    bk_output_dataset_names(BK_FIELD_ALL, 0, 0, 1, 1, names, sizeof names);
    assert_string_equal(names, "time,driver,event,x,v,friction,cof,mode,energy_kinetic,"
                               "energy_elastic,work_driver,dissipation,transitions,events");
    bk_output_dataset_names(BK_FIELD_ALL, 0, 1, 1, 1, names, sizeof names);
    assert_string_equal(names, "time,driver,event,x,v,friction,cof,mode,energy_kinetic,"
                               "energy_elastic,work_driver,dissipation,damping_dissipation,transitions,events");
    bk_output_dataset_names(BK_FIELD_V, 0, 0, 0, BK_CATALOG_EVENTS | BK_CATALOG_RUPTURES | BK_CATALOG_RUPTURE_RATE,
                            names, sizeof names);
    assert_string_equal(names, "time,driver,event,v,events,ruptures,rupture_blocks,rupture_rate");
    bk_output_dataset_names(BK_FIELD_V, 0, 0, 1, BK_CATALOG_EVENTS | BK_CATALOG_RUPTURES, names, sizeof names);
    assert_string_equal(names, "time,driver,event,v,transitions,events,ruptures,rupture_blocks");
    bk_output_dataset_names(BK_FIELD_V | BK_FIELD_STATE, 0, 1, 0, 0, names, sizeof names);
    assert_string_equal(names, "time,driver,event,v");
}

/* The max_bytes guard counts the table's bytes: 1,001 rows of 17 + 8 x 1000 bytes is
 * 8,025,017 bytes, refused under 8.02e6 and accepted under 8.03e6. */
static void test_max_bytes_guard_counts_the_table(void **state)
{
    (void)state;
    const char *overrides[] = {"model.n_blocks=1000", "output.fields=x", "run.t_end=1",
                               "output.interval=1e-3", "output.max_bytes=8.02e6"};
    bk_config *config = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_file("configs/chains/bk10_coulomb.ini", overrides, 5, &config,
                                         &err),
                     BK_ERR_CONFIG);
    assert_null(config);
    assert_non_null(strstr(err.message, "[output] max_bytes"));
    assert_non_null(strstr(err.message, "8.02e+03 bytes for 1000 blocks"));
    overrides[4] = "output.max_bytes=8.03e6";
    int rc = bk_config_load_file("configs/chains/bk10_coulomb.ini", overrides, 5, &config, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    assert_close((double)(1000 + 1) * bk_output_row_bytes(config->output.fields, 1000, 0, 0),
                 8025017.0, 0, 0);
    bk_config_free(config);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_well_formed),
        cmocka_unit_test(test_field_words_parse_to_their_bits),
        cmocka_unit_test(test_row_bytes),
        cmocka_unit_test(test_dataset_names),
        cmocka_unit_test(test_max_bytes_guard_counts_the_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
