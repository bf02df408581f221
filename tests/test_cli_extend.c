/* Runs that go on past their end or start from another's end, in real child processes:
 * `bksim run --restart OUT --set run.t_end=T` makes a finished (or stopped) run longer,
 * bit-identical to one run with that t_end when the old end is a restart point of the longer
 * run; `bksim run --init-from DONE.h5` starts a scene where another ended; the refusals of
 * both.  Runs ./bksim from the repository root. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "command.h"
#include "files.h"
#include "same_output.h"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    return make_temp_dir(tmpdir, sizeof tmpdir, "bksim_cli_extend");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

/* A 10-block chain with a rupture catalog, restart points every 0.5 s. */
#define CHAIN "./bksim run configs/chains/bk10_coulomb.ini -q --set output.checkpoint_interval=0.5 "

/* Finished at 1 s (a restart point of the longer run), then made 2 s long: the very output of
 * one 2 s run, for the exact stepper and for an integrator; once more to 3 s; and a run
 * stopped at a checkpoint made longer as it continues. */
static void test_extend_bit_identical(void **state)
{
    (void)state;
    const char *methods[] = {"exact", "cvode_adams"};
    for (size_t m = 0; m < 2; ++m) {
        char cmd[2048], once[512], twice[512], part[600];
        snprintf(once, sizeof once, "%s/once_%s.h5", tmpdir, methods[m]);
        snprintf(twice, sizeof twice, "%s/twice_%s.h5", tmpdir, methods[m]);
        snprintf(part, sizeof part, "%s.part", twice);
        snprintf(cmd, sizeof cmd, CHAIN "--set solver.method=%s --set run.t_end=2 -o %s", methods[m], once);
        assert_int_equal(run_command(cmd, NULL), 0);
        snprintf(cmd, sizeof cmd, CHAIN "--set solver.method=%s --set run.t_end=1 -o %s", methods[m], twice);
        assert_int_equal(run_command(cmd, NULL), 0);
        snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set run.t_end=2", twice);
        char *text = NULL;
        int status = run_command(cmd, &text);
        char expected[700];
        snprintf(expected, sizeof expected, "bksim: %s: t_end 1 s -> 2 s", twice);
        if (status != 0 || !strstr(text, expected))
            print_error("%s\n", text);
        free(text);
        assert_int_equal(status, 0);
        assert_true(path_exists(twice) && !path_exists(part));
        assert_same_output(once, twice);
        snprintf(cmd, sizeof cmd, "./bksim info %s", twice);
        expect_command(cmd, 0, "; --set run.t_end=2");
    }
    /* Again, from the extended file, and from a run stopped after a checkpoint. */
    char cmd[2048], longest[512], again[512], stopped[512];
    snprintf(longest, sizeof longest, "%s/longest.h5", tmpdir);
    snprintf(again, sizeof again, "%s/twice_exact.h5", tmpdir);
    snprintf(cmd, sizeof cmd, CHAIN "--set solver.method=exact --set run.t_end=3 -o %s", longest);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set run.t_end=3 -q", again);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_same_output(longest, again);
    /* A stopped run (here by its wall-clock limit, after checkpoints) takes a later end too:
     * stored, and it continues (to be stopped by the same limit again). */
    snprintf(stopped, sizeof stopped, "%s/stopped.h5", tmpdir);
    snprintf(cmd, sizeof cmd, CHAIN "--set solver.method=exact --set run.t_end=1e4 --set output.interval=1 "
             "--set output.checkpoint_wall_interval=0 --set run.wall_time_limit=0.2 -o %s", stopped);
    assert_int_equal(run_command(cmd, NULL), 1);
    double t_checkpoint = 0.0, t_again = 0.0;
    bk_error err = {0};
    assert_int_equal(bk_h5_restartable(stopped, &t_checkpoint, &err), 1);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part --set run.t_end=2e4 -q", stopped);
    assert_int_equal(run_command(cmd, NULL), 1);
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", stopped);
    expect_command(cmd, 3, "t_end        20000 s");
    assert_int_equal(bk_h5_restartable(stopped, &t_again, &err), 1);
    print_message("stopped at its checkpoint t = %g s, made 2e4 s long, stopped again at t = %g s\n", t_checkpoint,
                  t_again);
    assert_true(t_again > t_checkpoint);
}

/* Where the old end is not a restart point of the longer run, the continuation is still the
 * motion from the exact state there, but the integrators step differently: the same
 * transitions, at times within the solver's tolerance of one run's. */
static void test_extend_off_grid(void **state)
{
    (void)state;
    char cmd[2048], once[512], twice[512];
    snprintf(once, sizeof once, "%s/off_once.h5", tmpdir);
    snprintf(twice, sizeof twice, "%s/off_twice.h5", tmpdir);
    const char *scene = "./bksim run configs/paper/case_b_coulomb.ini -q --set solver.method=cvode_adams "
                        "--set solver.rtol=1e-10";
    snprintf(cmd, sizeof cmd, "%s --set run.t_end=4 -o %s", scene, once);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "%s --set run.t_end=1.2345 -o %s && ./bksim run --restart %s --set run.t_end=4 -q",
             scene, twice, twice);
    assert_int_equal(run_command(cmd, NULL), 0);
    bk_transition *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_transitions(once, &a, &na, &err), BK_OK);
    assert_int_equal(bk_h5_read_transitions(twice, &b, &nb, &err), BK_OK);
    assert_int_equal(na, nb);
    double worst = 0.0;
    for (size_t k = 0; k < na; ++k) {
        assert_int_equal(a[k].block, b[k].block);
        assert_int_equal(a[k].to, b[k].to);
        worst = fmax(worst, fabs(a[k].t - b[k].t));
    }
    print_message("t_end 1.2345 s made 4 s: %zu transitions, largest time difference %.3g s from one run\n", na,
                  worst);
    assert_true(worst < 1e-7);
    free(a);
    free(b);
}

/* What a longer run is refused, and nothing is changed by a refusal. */
static void test_extend_refusals(void **state)
{
    (void)state;
    char cmd[2048], out[512], part[600];
    snprintf(out, sizeof out, "%s/refused.h5", tmpdir);
    snprintf(part, sizeof part, "%s.part", out);
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -q -o %s --set run.t_end=1", out);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set run.t_end=1", out);
    expect_command(cmd, 2, "a restart may only make the run longer than its t_end = 1 s");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set run.t_end=soon", out);
    expect_command(cmd, 2, "--set run.t_end=soon: [run] t_end: not a number");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set solver.rtol=1e-9", out);
    expect_command(cmd, 2, "no --set but run.t_end=T (a later end)");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set run.t_end=2 --set run.t_end=3", out);
    expect_command(cmd, 2, "no --set but run.t_end=T (a later end)");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s", out);
    expect_command(cmd, 2, "the run is complete, nothing to restart");
    assert_true(path_exists(out) && !path_exists(part));
    /* A driver history ends where it ends. */
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/slide_hold_slide_10.ini -q -o %s --force --set run.t_end=4",
             out);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set run.t_end=30", out);
    expect_command(cmd, 2, "[run] t_end: must be <= the driver history's length (26 s), got 30");
    assert_true(path_exists(out) && !path_exists(part));
    /* A file without a checkpoint (as an older bksim wrote them). */
    hid_t file = H5Fopen(out, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(file >= 0 && H5Ldelete(file, "checkpoint", H5P_DEFAULT) >= 0);
    H5Fclose(file);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s --set run.t_end=2", out);
    expect_command(cmd, 2, "holds no checkpoint to continue from");
    assert_true(path_exists(out) && !path_exists(part));
}

/* A loading phase, then a second run from its end: the state carries over exactly (the
 * second run's transitions are the one long run's after the first's end, shifted in time), the
 * output says where it started, and incompatible or unfinished sources are refused. */
static void test_init_from(void **state)
{
    (void)state;
    char cmd[2048], whole[512], first[512], second[512];
    snprintf(whole, sizeof whole, "%s/whole.h5", tmpdir);
    snprintf(first, sizeof first, "%s/first.h5", tmpdir);
    snprintf(second, sizeof second, "%s/second.h5", tmpdir);
    snprintf(cmd, sizeof cmd, CHAIN "--set solver.method=exact --set run.t_end=2 -o %s", whole);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, CHAIN "--set solver.method=exact --set run.t_end=1 -o %s", first);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk10_coulomb.ini --set solver.method=exact "
             "--set run.t_end=1 -o %s --init-from %s", second, first);
    char *text = NULL;
    int status = run_command(cmd, &text);
    char expected[700];
    snprintf(expected, sizeof expected, "bksim: starting from the end of %s (t = 1 s)", first);
    if (status != 0 || !strstr(text, expected))
        print_error("%s\n", text);
    free(text);
    assert_int_equal(status, 0);
    snprintf(cmd, sizeof cmd, "./bksim info %s", second);
    snprintf(expected, sizeof expected, "started from %s, its state at its end t = 1 s", first);
    expect_command(cmd, 0, expected);

    bk_transition *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    bk_error err = {0};
    assert_int_equal(bk_h5_read_transitions(whole, &a, &na, &err), BK_OK);
    assert_int_equal(bk_h5_read_transitions(second, &b, &nb, &err), BK_OK);
    size_t skip = 0;
    while (skip < na && a[skip].t <= 1.0)
        ++skip;
    /* The second run's t = 0: blocks that were slipping go on; a block at rest gets the
     * at-rest rule, as at any start, and emits no transition unless it starts slipping. */
    size_t first_b = 0;
    while (first_b < nb && b[first_b].t == 0.0)
        ++first_b;
    assert_int_equal(na - skip, nb - first_b);
    double worst_t = 0.0, worst_x = 0.0;
    for (size_t j = first_b; j < nb; ++j) {
        const bk_transition *p = &a[skip + (j - first_b)], *q = &b[j];
        assert_int_equal(p->block, q->block);
        assert_int_equal(p->to, q->to);
        worst_t = fmax(worst_t, fabs((p->t - 1.0) - q->t));
        worst_x = fmax(worst_x, fabs(p->x - q->x));
    }
    print_message("second half from the first's end: %zu transitions, within %.3g s and %.3g m of the one run's\n",
                  nb - first_b, worst_t, worst_x);
    assert_true(nb - first_b > 10);
    /* Rounding apart (the second run's clock starts at 0): the chain amplifies it. */
    assert_true(worst_t < 1e-8 && worst_x < 1e-11);
    free(a);
    free(b);

    /* Refusals: what differs, or why the file gives no end state. */
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk1000_coulomb.ini -q -o %s/x.h5 --init-from %s", tmpdir,
             first);
    expect_command(cmd, 2, "the scene is 1 x 1000 blocks, the run it would start from 1 x 10");
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk10_coulomb.ini -q -o %s/x.h5 --init-from %s "
             "--set friction.0.law=carlson_langer --set friction.0.F0=5 --set friction.0.sigma=0.2 "
             "--set friction.0.alpha=1", tmpdir, first);
    expect_command(cmd, 2, "block 0 has friction law carlson_langer here and coulomb in the run it would start from");
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk10_coulomb.ini -q -o %s/x.h5 --init-from %s/none.h5",
             tmpdir, tmpdir);
    expect_command(cmd, 2, "none.h5: no such file to start from");
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/bk10_coulomb.ini -q -o %s/x.h5 --init-from "
             "configs/chains/bk10_coulomb.ini", tmpdir);
    expect_command(cmd, 2, "not an HDF5 file");
    snprintf(cmd, sizeof cmd, CHAIN "-o %s/cut.h5 --set run.wall_time_limit=1e-9 --set run.t_end=100; "
             "./bksim run configs/chains/bk10_coulomb.ini -q -o %s/x.h5 --init-from %s/cut.h5.part", tmpdir, tmpdir,
             tmpdir);
    expect_command(cmd, 2, "the output of a run that did not finish");
    assert_false(path_exists("x.h5"));
}

/* A run killed after it wrote its end's checkpoint but before it finished (the .part holds
 * everything, marked incomplete): --restart continues from that checkpoint at t_end and ends
 * with the very output of the uninterrupted run, its last row not written twice. */
static void test_restart_at_the_end(void **state)
{
    (void)state;
    char cmd[4096], reference[300], out[300], part[320];
    snprintf(reference, sizeof reference, "%s/end_reference.h5", tmpdir);
    snprintf(out, sizeof out, "%s/end_killed.h5", tmpdir);
    snprintf(part, sizeof part, "%s.part", out);
    snprintf(cmd, sizeof cmd, CHAIN "--set solver.method=cvode_adams --set run.t_end=1 -o %s && "
             CHAIN "--set solver.method=cvode_adams --set run.t_end=1 -o %s && mv %s %s", reference, out, out, part);
    assert_int_equal(run_command(cmd, NULL), 0);
    hid_t file = H5Fopen(part, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t attr = file >= 0 ? H5Aopen(file, "complete", H5P_DEFAULT) : -1;
    int zero = 0;
    assert_true(attr >= 0 && H5Awrite(attr, H5T_NATIVE_INT, &zero) >= 0);
    H5Aclose(attr);
    H5Fclose(file);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s -q", part);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_same_output(reference, out);
    bk_error err = {0};
    assert_int_equal(bk_h5_verify(out, &err), BK_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_extend_bit_identical),
        cmocka_unit_test(test_extend_off_grid),
        cmocka_unit_test(test_extend_refusals),
        cmocka_unit_test(test_init_from),
        cmocka_unit_test(test_restart_at_the_end),
    };
    return cmocka_run_group_tests_name("cli_extend", tests, setup, teardown);
}
