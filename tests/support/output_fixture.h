/* Test support: the cmocka fixture of the output tests: a fresh temporary directory per
 * test, an output path in it, and a check at teardown that every HDF5 id was closed. */
#ifndef TEST_OUTPUT_FIXTURE_H
#define TEST_OUTPUT_FIXTURE_H

typedef struct output_fixture {
    char dir[64];
    char path[128]; /* <dir>/run.h5 */
} output_fixture;

/* cmocka setup and teardown: *state is an output_fixture. */
int output_fixture_setup(void **state);
int output_fixture_teardown(void **state);

/* A cmocka test that runs in its own output fixture. */
#define OUTPUT_TEST(test) cmocka_unit_test_setup_teardown(test, output_fixture_setup, output_fixture_teardown)

#endif
