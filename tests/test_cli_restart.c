/* Runs that stop and go on, in real child processes: signals (SIGTERM, SIGINT, SIGKILL) and
 * the guards against a hang leave an intact, incomplete .part; a running run's .part is
 * reported and guarded; a stopped run says how to go on; restarted from its checkpoints, again
 * and again or after SIGKILL at arbitrary moments, a run ends with the very output of an
 * uninterrupted one; --restart's refusals.  Kills and wall clocks: run alone.  Runs ./bksim
 * from the repository root. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>
#include <time.h>

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
    return make_temp_dir(tmpdir, sizeof tmpdir, "bksim_cli_restart");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

/* A long run in a real child process, stopped by `signal` after a second. */
static int run_and_signal(const char *out, const char *signal_name, char **text)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/paper/case_c_coulomb.ini -o %s --quiet "
             "--set run.t_end=100000 --set output.interval=1e-3 & pid=$!; sleep 1; "
             "kill -%s $pid; wait $pid",
             out, signal_name);
    return run_command(cmd, text);
}

/* SIGTERM and SIGINT stop the run at the next step: the file stays "<out>.part", intact and
 * marked incomplete (complete = 0, t_reached); `bksim info` says so with exit status 3. */
static void test_interrupted_run_is_marked(void **state)
{
    (void)state;
    const char *signals[] = {"TERM", "INT"};
    for (size_t k = 0; k < 2; ++k) {
        char out[512], part[600], cmd[1024];
        snprintf(out, sizeof out, "%s/stopped_%s.h5", tmpdir, signals[k]);
        snprintf(part, sizeof part, "%s.part", out);
        char *text = NULL;
        assert_int_equal(run_and_signal(out, signals[k], &text), 1);
        assert_non_null(strstr(text, "interrupted"));
        free(text);
        assert_false(path_exists(out));
        assert_true(path_exists(part));
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE);
        snprintf(cmd, sizeof cmd, "./bksim info %s", part);
        assert_int_equal(run_command(cmd, &text), 3);
        assert_non_null(strstr(text, "complete     0 (run did not finish)"));
        assert_non_null(strstr(text, "error        run interrupted at t = "));
        free(text);
    }
}

/* SIGKILL leaves no chance to close: at most "<out>.part", which bksim reports as the output
 * of a run that did not finish, never as a complete file. */
static void test_killed_run_leaves_partial(void **state)
{
    (void)state;
    char out[512], part[600], cmd[1024];
    snprintf(out, sizeof out, "%s/killed.h5", tmpdir);
    snprintf(part, sizeof part, "%s.part", out);
    char *text = NULL;
    assert_int_equal(run_and_signal(out, "KILL", &text), 137);
    free(text);
    assert_false(path_exists(out));
    assert_true(path_exists(part));
    snprintf(cmd, sizeof cmd, "./bksim info %s", part);
    int status = run_command(cmd, &text);
    /* Readable (flushed chunk by chunk) and incomplete, or unreadable and said to be partial. */
    if (status == 3)
        assert_non_null(strstr(text, "did not finish"));
    else
        assert_true(status == 1 && strstr(text, "did not finish"));
    free(text);
}

/* While a run writes its .part: `bksim info` reports its progress (exit 3) instead of a
 * damaged file, and a second run with the same -o, a --restart and a reader are refused
 * with a message that names the owner, never HDF5's "Resource temporarily unavailable". */
static void test_running_output(void **state)
{
    (void)state;
    char out[512], cmd[2048];
    snprintf(out, sizeof out, "%s/running.h5", tmpdir);
    const char *scene = "configs/paper/case_b_coulomb.ini -q --set run.t_end=1e6 "
                        "--set solver.method=cvode_adams --set output.checkpoint_interval=2 "
                        "--set output.interval=0.01";
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s > /dev/null 2>&1 & echo $!", scene, out);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 0);
    long pid = strtol(text, NULL, 10);
    free(text);
    assert_true(pid > 0);
    /* Until a checkpoint has been flushed (a commit by the wall clock may show progress
     * before it, on a slow or loaded machine): then the progress and the checkpoint. */
    int status = -1, checkpointed = 0;
    double t = 0.0;
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    for (int tries = 0; tries < 600 && !checkpointed; ++tries) {
        nanosleep(&(struct timespec){0, 20000000L}, NULL);
        status = run_command(cmd, &text);
        const char *progress = strstr(text, "in progress, t = ");
        if (progress)
            t = strtod(progress + strlen("in progress, t = "), NULL);
        checkpointed = strstr(text, "checkpoint   t = ") != NULL;
        if (checkpointed) {
            assert_int_equal(status, 3);
            assert_true(t > 0.0);
            assert_non_null(strstr(text, "transitions so far"));
        }
        free(text);
    }
    assert_true(checkpointed);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, out);
    expect_command(cmd, 1, "another run owns this file");
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s --force", scene, out);
    expect_command(cmd, 1, "another run owns this file");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part", out);
    expect_command(cmd, 1, "another run owns this file");
    snprintf(cmd, sizeof cmd, "./bksim export %s.part --transitions", out);
    expect_command(cmd, 1, "a run is still writing this file");
    /* The run was not disturbed: stopped now, it leaves a .part to continue from. */
    snprintf(cmd, sizeof cmd, "kill -TERM %ld; while kill -0 %ld 2>/dev/null; do sleep 0.02; done; "
             "./bksim info %s.part", pid, pid, out);
    status = run_command(cmd, &text);
    assert_int_equal(status, 3);
    assert_non_null(strstr(text, "did not finish"));
    assert_null(strstr(text, "in progress"));
    free(text);
}

/* A stopped run says how to go on: the --restart command and its checkpoint's time, or that
 * without a checkpoint it can only be run again; `bksim info` says the same of the .part;
 * and running the same command again says that it starts over. */
static void test_stop_messages(void **state)
{
    (void)state;
    char out[512], cmd[2048];
    const char *scene = "configs/paper/case_b_coulomb.ini --set run.t_end=1e4 --set solver.method=cvode_adams "
                        "--set run.wall_time_limit=0.3";
    snprintf(out, sizeof out, "%s/with_checkpoint.h5", tmpdir);
    /* The output path from the config, not -o: --resume below must not read it from the
     * config it replaces by the stored one. */
    snprintf(cmd, sizeof cmd, "./bksim run %s -q --set output.path=%s --set output.checkpoint_interval=5",
             scene, out);
    char expected[1200], *text = NULL;
    assert_int_equal(run_command(cmd, &text), 1);
    snprintf(expected, sizeof expected, "; continue it from its checkpoint t = ");
    assert_non_null(strstr(text, expected));
    snprintf(expected, sizeof expected, "with `bksim run --restart %s.part`", out);
    assert_non_null(strstr(text, expected));
    free(text);
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    snprintf(expected, sizeof expected, "`bksim run --restart %s.part` continues from it", out);
    expect_command(cmd, 3, expected);
    snprintf(cmd, sizeof cmd, "./bksim run %s --set output.path=%s --set output.checkpoint_interval=5 --resume",
             scene, out);
    snprintf(expected, sizeof expected, "bksim: continuing %s.part from its checkpoint t = ", out);
    expect_command(cmd, 1, expected);

    snprintf(out, sizeof out, "%s/without_checkpoint.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -q -o %s", scene, out);
    expect_command(cmd, 1, "it holds no checkpoint, so it cannot be continued: running again starts over");
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    expect_command(cmd, 3, "checkpoint   none: this run cannot be continued, only run again");
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, out);
    snprintf(expected, sizeof expected, "starting over: %s.part is replaced (it holds no checkpoint", out);
    expect_command(cmd, 1, expected);
}

/* Every guard against a hang stops the run with a message naming its key, and keeps what
 * was written as an incomplete .part. */
static void test_limits(void **state)
{
    (void)state;
    const struct {
        const char *sets, *message;
    } cases[] = {
        {"--set solver.method=cvode_adams --set solver.min_step=1e-3", "[solver] min_step = 0.001 s at t = 0.5886"},
        {"--set solver.method=arkode_dp45 --set solver.min_step=1e-3", "below [solver] min_step = 0.001 s, at t = 0.58"},
        {"--set run.wall_time_limit=0.05 --set run.t_end=1e3", "[run] wall_time_limit = 0.05 s reached at t = "},
        {"--set solver.method=cvode_adams --set solver.max_steps=5", "more than 5 solver steps since the last output row"},
        {"--set friction.mu_d=0.5999 --set solver.max_transitions_per_instant=1 --set solver.instant_window=1e-3",
         "block 0: more than 1 transitions within 0.001 s at t = 0.6514"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char out[512], part[600], cmd[2048];
        snprintf(out, sizeof out, "%s/limit%zu.h5", tmpdir, k);
        snprintf(part, sizeof part, "%s.part", out);
        snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -o %s -q %s", out, cases[k].sets);
        char *text = NULL;
        int status = run_command(cmd, &text);
        if (status != 1 || !strstr(text, cases[k].message))
            print_error("case %zu: status %d\n%s\nexpected: %s\n", k, status, text, cases[k].message);
        assert_int_equal(status, 1);
        assert_non_null(strstr(text, cases[k].message));
        free(text);
        assert_false(path_exists(out));
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(part, &err), BK_INCOMPLETE);
    }
}

/* A run stopped again and again and restarted from its checkpoints each time ends with the
 * very output of an uninterrupted run: every row and transition bit-identical. */
static void test_restart_equivalence(void **state)
{
    (void)state;
    /* gsl_rk8pd resets its stepper when a size repeats instead of making a new one: the
     * resumed run's fresh instances must compute what the reused ones do.  The damped runs
     * (an integrator's and the exact stepper's) carry their dashpot dissipation through the
     * checkpoints; the slide-hold-slide chain
     * resumes between and at its driver's breakpoints. */
    const char *methods[] = {"cvode_adams", "exact", "gsl_rk8pd", "gsl_rk8pd", "gsl_rk8pd", "exact"};
    const char *extra[] = {"", "", "", "--set block.damping=20", "", "--set block.damping=20"};
    const char *configs[] = {"paper/case_b_coulomb", "paper/case_b_coulomb", "paper/case_b_coulomb",
                             "paper/case_b_coulomb", "chains/slide_hold_slide_10", "paper/case_b_coulomb"};
    for (size_t m = 0; m < 6; ++m) {
        char reference[512], stopped[512], part[600], cmd[2048];
        snprintf(reference, sizeof reference, "%s/reference_%s_%zu.h5", tmpdir, methods[m], m);
        snprintf(stopped, sizeof stopped, "%s/stopped_%s_%zu.h5", tmpdir, methods[m], m);
        snprintf(part, sizeof part, "%s.part", stopped);
        char common[512];
        snprintf(common, sizeof common, "configs/%s.ini --quiet --set output.checkpoint_interval=0.1 %s",
                 configs[m], extra[m]);
        snprintf(cmd, sizeof cmd, "./bksim run %s --set solver.method=%s -o %s", common, methods[m], reference);
        assert_int_equal(run_command(cmd, NULL), 0);
        /* The same run under a wall-clock limit so short that it stops many times (each
         * invocation still passes a checkpoint, or it could not progress). */
        snprintf(cmd, sizeof cmd, "./bksim run %s --set solver.method=%s --set run.wall_time_limit=0.02 -o %s",
                 common, methods[m], stopped);
        int status = run_command(cmd, NULL);
        int restarts = 0;
        while (status == 1 && restarts < 500) {
            snprintf(cmd, sizeof cmd, "./bksim run --restart %s --quiet", part);
            status = run_command(cmd, NULL);
            ++restarts;
        }
        print_message("%s: finished after %d restarts\n", methods[m], restarts);
        assert_int_equal(status, 0);
        assert_true(restarts >= 1);
        assert_false(path_exists(part));
        assert_same_output(reference, stopped);
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(stopped, &err), BK_OK);
    }
}

/* SIGKILL at arbitrary moments, then --restart, again and again until the run completes:
 * the output is bit-identical to an uninterrupted run's.  Checkpoints are dense, so that
 * many kills land inside one.  (A checkpoint once was overwritten in place, and a kill
 * inside that write left positions of one time with attributes of another, from which a
 * restart went on: half of such chains ended with wrong output.) */
static void test_sigkill_restart_loop(void **state)
{
    (void)state;
    const char *common = "configs/paper/case_b_coulomb.ini --quiet --set solver.method=cvode_adams "
                         "--set output.checkpoint_interval=0.0005 --set run.t_end=1";
    char reference[512], cmd[2048];
    snprintf(reference, sizeof reference, "%s/kill_reference.h5", tmpdir);
    /* Kill times are fractions of the uninterrupted run's wall time, so that they fall
     * inside the run for the plain and the sanitizer build alike. */
    snprintf(cmd, sizeof cmd, "s=$(date +%%s%%N); ./bksim run %s -o %s && echo $(( $(date +%%s%%N) - s ))",
             common, reference);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 0);
    double wall = strtod(text, NULL) * 1e-9;
    free(text);
    assert_true(wall > 0.0);
    unsigned long long lcg = 20250101; /* fixed: the same kill times on every run of the test */
    int kills = 0, restarts = 0, fresh_starts = 0, finished_by_restart = 0;
    for (int chain = 0; chain < 4; ++chain) {
        char out[512];
        snprintf(out, sizeof out, "%s/killed_%d.h5", tmpdir, chain);
        int have_part = 0, status = -1;
        for (int attempt = 0; attempt < 300 && status != 0; ++attempt) {
            lcg = lcg * 6364136223846793005ull + 1442695040888963407ull;
            double u = (double)(lcg >> 11) / 9007199254740992.0;
            /* Later attempts wait longer, so that even a slow build gets past a checkpoint. */
            double delay = wall * (0.03 + 0.17 * u) * (1.0 + attempt / 20.0);
            if (have_part)
                snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part --quiet & pid=$!; sleep %.3f; "
                         "kill -9 $pid 2>/dev/null; wait $pid", out, delay);
            else
                snprintf(cmd, sizeof cmd, "rm -f %s.part; ./bksim run %s -o %s & pid=$!; sleep %.3f; "
                         "kill -9 $pid 2>/dev/null; wait $pid", out, common, out, delay);
            restarts += have_part;
            int was_restart = have_part;
            status = run_command(cmd, &text);
            finished_by_restart += status == 0 && was_restart;
            if (status == 137) {
                ++kills;
                have_part = 1;
            } else if (status != 0) {
                /* Killed before its first checkpoint (nothing to restart from), or, rarely,
                 * inside HDF5's own flush in a way that left the .part unreadable: refused
                 * loudly either way, and a fresh run is what a user would do. */
                print_message("chain %d attempt %d: exit %d: %s", chain, attempt, status, text);
                have_part = 0;
                ++fresh_starts;
            }
            free(text);
        }
        assert_int_equal(status, 0);
        assert_true(path_exists(out));
        assert_same_output(reference, out);
        bk_error err = {0};
        assert_int_equal(bk_h5_verify(out, &err), BK_OK);
    }
    print_message("4 runs of %.2f s: %d kills, %d restarts, %d fresh starts, %d runs finished by a restart\n",
                  wall, kills, restarts, fresh_starts, finished_by_restart);
    assert_true(kills >= 4);
    /* The restarts must work, not only fresh starts that happen to outrun the kills. */
    assert_true(finished_by_restart >= 2);
}

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* SIGTERM (what SLURM sends KillWait before its SIGKILL) at random moments: the run goes on to
 * its next restart point, writes it as a checkpoint and stops there, well within the grace
 * time; --restart then ends with the very output of an uninterrupted run.  Restart points
 * every 2e4 units of work (some 45 in the run), no wall-clock checkpoints (300 s never
 * passes): only the request makes one. */
static void test_sigterm_keeps_the_work(void **state)
{
    (void)state;
    const char *scene = "configs/chains/bk10_coulomb.ini --quiet --set run.t_end=20 --set output.checkpoint_work=2e4";
    char reference[512], out[512], cmd[2048], *text = NULL;
    snprintf(reference, sizeof reference, "%s/term_reference.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, reference);
    double t0 = seconds_now();
    assert_int_equal(run_command(cmd, NULL), 0);
    double wall = seconds_now() - t0;
    unsigned long long lcg = 20261128; /* fixed: the same signal times on every run of the test */
    int stopped = 0;
    for (int k = 0; k < 8 && stopped < 3; ++k) {
        lcg = lcg * 6364136223846793005ull + 1442695040888963407ull;
        double u = (double)(lcg >> 11) / 9007199254740992.0;
        snprintf(out, sizeof out, "%s/term_%d.h5", tmpdir, k);
        /* The time from the signal to the exit, in ns, after the exit status. */
        snprintf(cmd, sizeof cmd, "./bksim run %s -o %s & pid=$!; sleep %.3f; s=$(date +%%s%%N); kill -TERM $pid; "
                 "wait $pid; rc=$?; echo \"exit $rc after $(( $(date +%%s%%N) - s ))\"", scene, out, wall * (0.1 + 0.7 * u));
        assert_int_equal(run_command(cmd, &text), 0);
        const char *said = strstr(text, "exit ");
        assert_non_null(said);
        int status = -1;
        long long ns = -1;
        assert_int_equal(sscanf(said, "exit %d after %lld", &status, &ns), 2);
        if (status == 0) { /* the run was done before the signal came */
            free(text);
            continue;
        }
        assert_int_equal(status, 1);
        assert_non_null(strstr(text, "its restart point, written as a checkpoint"));
        assert_non_null(strstr(text, "continue it from its checkpoint t = "));
        print_message("SIGTERM %.3f s in: stopped %.3f s later at its next restart point\n", wall * (0.1 + 0.7 * u),
                      (double)ns * 1e-9);
        assert_true((double)ns * 1e-9 < BK_STOP_GRACE);
        free(text);
        snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
        expect_command(cmd, 3, "continues from it");
        snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part --quiet", out);
        assert_int_equal(run_command(cmd, NULL), 0);
        assert_same_output(reference, out);
        ++stopped;
    }
    assert_int_equal(stopped, 3);

    /* Without restart points ([output] checkpoint_interval = 0) it stops at once, and says
     * that the .part cannot be continued. */
    snprintf(out, sizeof out, "%s/term_none.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_c_coulomb.ini -o %s --quiet --set run.t_end=100000 "
             "--set output.interval=1e-3 --set output.checkpoint_interval=0 & pid=$!; sleep 0.5; kill -TERM $pid; "
             "wait $pid", out);
    assert_int_equal(run_command(cmd, &text), 1);
    assert_non_null(strstr(text, "it holds no checkpoint, so it cannot be continued"));
    free(text);
}

/* A full disk, stood in for by a file-size limit (ulimit -f) at three sizes: the run stops
 * before a write would meet it, says so (exit 1), and leaves a .part that `bksim info` reads
 * with its last checkpoint; --restart (with room again) ends with the very output of an
 * uninterrupted run.  Without the writer's look ahead, the first write past the limit
 * killed the run (SIGXFSZ) and left a .part of no rows and no checkpoint. */
static void test_file_size_limit(void **state)
{
    (void)state;
    const char *scene = "configs/chains/bk10_coulomb.ini --quiet --set run.t_end=30 --set output.checkpoint_work=2e4 "
                        "--set output.checkpoint_wall_interval=0";
    char reference[512], out[512], cmd[2048], *text = NULL;
    snprintf(reference, sizeof reference, "%s/limit_reference.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, reference);
    assert_int_equal(run_command(cmd, NULL), 0);
    static const long limits[] = {8000000, 14000000, 20000000}; /* bytes; the whole output is 23 MB */
    for (size_t k = 0; k < 3; ++k) {
        snprintf(out, sizeof out, "%s/limited_%zu.h5", tmpdir, k);
        /* prlimit, not the shell's ulimit -f: its unit is 512 bytes in sh, 1024 in bash. */
        snprintf(cmd, sizeof cmd, "prlimit --fsize=%ld ./bksim run %s -o %s", limits[k], scene, out);
        int status = run_command(cmd, &text);
        if (status != 1 || !strstr(text, "continue it from its checkpoint t = "))
            print_error("file-size limit %ld: exit %d: %s\n", limits[k], status, text);
        assert_int_equal(status, 1);
        assert_non_null(strstr(text, ".part: no room for the next "));
        assert_non_null(strstr(text, "within the file-size limit (ulimit -f)"));
        assert_non_null(strstr(text, "continue it from its checkpoint t = "));
        free(text);
        snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
        assert_int_equal(run_command(cmd, &text), 3);
        const char *at = strstr(text, "checkpoint   t = ");
        assert_non_null(at);
        print_message("file-size limit %ld bytes: stopped with a checkpoint at t = %.6g s of 30 s\n", limits[k],
                      strtod(at + strlen("checkpoint   t = "), NULL));
        free(text);
        snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part --quiet", out);
        assert_int_equal(run_command(cmd, NULL), 0);
        assert_same_output(reference, out);
    }
}

/* A run with the default checkpoint settings, scaled down (restart points every 2e4 units of
 * work instead of 1e7, some 45 in the run; the wall-clock interval a quarter of the run),
 * writes a checkpoint once that interval has passed; killed then and restarted, it ends with
 * the very output of an uninterrupted run that wrote no checkpoint but at its end: the restart
 * points are where the run's own work puts them, the same in every run, and the wall clock
 * only decides which of them are written. */
static void test_wall_clock_checkpoint(void **state)
{
    (void)state;
    /* A chain of 10: chaotic, so any perturbation of a restart would show in every dataset. */
    const char *scene = "configs/chains/bk10_coulomb.ini --quiet --set run.t_end=20 --set output.checkpoint_work=2e4";
    char reference[512], out[512], cmd[2048], *text = NULL;
    snprintf(reference, sizeof reference, "%s/wall_reference.h5", tmpdir);
    snprintf(out, sizeof out, "%s/wall_killed.h5", tmpdir);
    snprintf(cmd, sizeof cmd, "./bksim run %s -o %s", scene, reference);
    double t0 = seconds_now();
    assert_int_equal(run_command(cmd, NULL), 0);
    double wall = seconds_now() - t0;
    hid_t file = H5Fopen(reference, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    /* 300 s never passed: no checkpoint but the one every run writes at its end. */
    double t_slot = 0.0;
    hid_t slot = H5Gopen2(file, "checkpoint/a", H5P_DEFAULT);
    assert_true(slot >= 0 && H5Lexists(file, "checkpoint/b", H5P_DEFAULT) == 0);
    hid_t attr = H5Aopen(slot, "t", H5P_DEFAULT);
    assert_true(attr >= 0 && H5Aread(attr, H5T_NATIVE_DOUBLE, &t_slot) >= 0);
    assert_true(t_slot == 20.0);
    H5Aclose(attr);
    H5Gclose(slot);
    H5Fclose(file);

    double interval = 0.25 * wall;
    snprintf(cmd, sizeof cmd, "./bksim run %s --set output.checkpoint_wall_interval=%.3f -o %s "
             "> /dev/null 2>&1 & echo $!", scene, interval, out);
    t0 = seconds_now();
    assert_int_equal(run_command(cmd, &text), 0);
    long pid = strtol(text, NULL, 10);
    free(text);
    assert_true(pid > 0);
    int written = 0;
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    for (int tries = 0; tries < 2000 && !written; ++tries) {
        nanosleep(&(struct timespec){0, 5000000L}, NULL);
        run_command(cmd, &text);
        written = strstr(text, "checkpoint   t = ") != NULL;
        free(text);
    }
    double killed_after = seconds_now() - t0;
    snprintf(cmd, sizeof cmd, "kill -KILL %ld", pid);
    assert_int_equal(run_command(cmd, NULL), 0);
    print_message("run of %.2f s, wall-clock interval %.3f s: killed %.3f s in, after its first checkpoint\n",
                  wall, interval, killed_after);
    assert_true(written);
    assert_true(killed_after >= interval);
    /* Dead once the file is no longer locked (a zombie may linger, unreaped). */
    snprintf(cmd, sizeof cmd, "./bksim info %s.part", out);
    int status = 3;
    for (int tries = 0; tries < 1000; ++tries) {
        status = run_command(cmd, &text);
        int running = strstr(text, "in progress") != NULL;
        free(text);
        if (!running)
            break;
        nanosleep(&(struct timespec){0, 5000000L}, NULL);
    }
    assert_int_equal(status, 3);
    double t_checkpoint = 0.0;
    bk_error err = {0};
    assert_int_equal(bk_h5_restartable(out, &t_checkpoint, &err), 1);
    assert_true(t_checkpoint > 0.0 && t_checkpoint < 20.0);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part --quiet", out);
    assert_int_equal(run_command(cmd, NULL), 0);
    /* The rupture tables are among what must agree: many ruptures, some of several blocks,
     * so that ruptures open across the checkpoint were carried over. */
    bk_rupture *ruptures = NULL;
    size_t n_ruptures = 0, multi = 0;
    assert_int_equal(bk_h5_read_ruptures(reference, &ruptures, &n_ruptures, &err), BK_OK);
    for (size_t k = 0; k < n_ruptures; ++k)
        multi += ruptures[k].n_blocks > 1;
    free(ruptures);
    print_message("%zu ruptures, %zu of several blocks\n", n_ruptures, multi);
    assert_true(n_ruptures > 100 && multi > 10);
    assert_same_output(reference, out);
    assert_int_equal(bk_h5_verify(out, &err), BK_OK);
}

static void test_restart_errors(void **state)
{
    (void)state;
    char out[512], cmd[2048];
    char *text = NULL;
    snprintf(out, sizeof out, "%s/no_checkpoint.h5", tmpdir);
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/paper/case_b_coulomb.ini -o %s -q --set run.wall_time_limit=1e-4", out);
    assert_int_equal(run_command(cmd, NULL), 1);
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s.part", out);
    expect_command(cmd, 2, "no checkpoint to restart from (a run writes its first once [output] "
                           "checkpoint_wall_interval has passed, 300 s by default");
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -q -o %s/finished.h5 "
                              "--set output.checkpoint_interval=1 && ./bksim run --restart %s/finished.h5",
             tmpdir, tmpdir);
    expect_command(cmd, 2, "the run is complete, nothing to restart");
    snprintf(cmd, sizeof cmd, "./bksim run --restart %s/nothing.h5", tmpdir);
    expect_command(cmd, 2, "no such file to restart from");
    expect_command("./bksim run configs/paper/case_b_coulomb.ini --restart x.h5", 2, "--restart takes no CONFIG");
    /* Running the same command again does not throw a restartable run's progress away. */
    snprintf(out, sizeof out, "%s/stopped.h5", tmpdir);
#define STOPPED_RUN "./bksim run configs/paper/case_b_coulomb.ini -q -o %s --set solver.method=cvode_bdf " \
                    "--set output.checkpoint_interval=0.01 --set run.wall_time_limit=%s"
    snprintf(cmd, sizeof cmd, STOPPED_RUN, out, "0.01");
    assert_int_equal(run_command(cmd, NULL), 1);
    char part[600];
    snprintf(part, sizeof part, "%s.part", out);
    double t_checkpoint = 0.0;
    bk_error err = {0};
    assert_int_equal(bk_h5_restartable(out, &t_checkpoint, &err), 1);
    snprintf(cmd, sizeof cmd, STOPPED_RUN, out, "0");
#undef STOPPED_RUN
    assert_int_equal(run_command(cmd, &text), 2);
    assert_non_null(strstr(text, "holds a run stopped at its checkpoint"));
    assert_non_null(strstr(text, "--force to start over"));
    free(text);
    double t_again = 0.0;
    assert_int_equal(bk_h5_restartable(out, &t_again, &err), 1);
    assert_true(t_again == t_checkpoint);
    strncat(cmd, " --force", sizeof cmd - strlen(cmd) - 1);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_true(path_exists(out) && !path_exists(part));
}

/* --resume on a .part whose checkpoint verifies but whose datasets do not reopen at it (what
 * a kill inside one of HDF5's flushes can leave: a chunk index half written, seen once in a
 * killed sweep) starts over and keeps the damaged file aside, never replacing it; the run
 * ends as a fresh one does.  --restart, which asks for that checkpoint, still refuses. */
static void test_resume_sets_damaged_aside(void **state)
{
    (void)state;
    const char *damages[] = {"ruptures deleted", "x cut to 0 rows"};
    char fresh[512], cmd[2048];
#define DAMAGED_RUN "./bksim run configs/paper/case_b_coulomb.ini -q -o %s --set solver.method=cvode_bdf " \
                    "--set output.checkpoint_interval=0.01 --set run.wall_time_limit=%s"
    snprintf(fresh, sizeof fresh, "%s/undamaged.h5", tmpdir);
    snprintf(cmd, sizeof cmd, DAMAGED_RUN, fresh, "0");
    assert_int_equal(run_command(cmd, NULL), 0);
    for (size_t k = 0; k < sizeof damages / sizeof damages[0]; ++k) {
        char out[512], part[600], kept[700], expected[1500];
        snprintf(out, sizeof out, "%s/damaged%zu.h5", tmpdir, k);
        snprintf(part, sizeof part, "%s.part", out);
        snprintf(kept, sizeof kept, "%s.damaged", part);
        snprintf(cmd, sizeof cmd, DAMAGED_RUN, out, "0.01");
        assert_int_equal(run_command(cmd, NULL), 1);
        hid_t file = H5Fopen(part, H5F_ACC_RDWR, H5P_DEFAULT);
        assert_true(file >= 0);
        if (k == 0) {
            assert_true(H5Ldelete(file, "ruptures", H5P_DEFAULT) >= 0);
        } else {
            hid_t dset = H5Dopen2(file, "x", H5P_DEFAULT);
            hsize_t dims[2] = {0, 1};
            assert_true(dset >= 0 && H5Dset_extent(dset, dims) >= 0);
            H5Dclose(dset);
        }
        H5Fclose(file);
        double t_checkpoint = 0.0;
        bk_error err = {0};
        assert_int_equal(bk_h5_restartable(out, &t_checkpoint, &err), 1);

        snprintf(cmd, sizeof cmd, "./bksim run --restart %s", part);
        char *text = NULL;
        int status = run_command(cmd, &text);
        if (status == 0 || !path_exists(part))
            print_error("%s: --restart gave %d\n%s\n", damages[k], status, text);
        free(text);
        assert_int_not_equal(status, 0);
        assert_true(path_exists(part) && !path_exists(out));

        snprintf(cmd, sizeof cmd, DAMAGED_RUN " --resume", out, "0");
        status = run_command(cmd, &text);
        snprintf(expected, sizeof expected, "bksim: starting over: %s cannot be continued (", part);
        int said = strstr(text, expected) != NULL;
        snprintf(expected, sizeof expected, "; it is kept as %s\n", kept);
        said = said && strstr(text, expected) != NULL;
        if (status != 0 || !said)
            print_error("%s: --resume gave %d\n%s\n", damages[k], status, text);
        free(text);
        assert_int_equal(status, 0);
        assert_true(said);
        assert_true(path_exists(out) && !path_exists(part) && path_exists(kept));
        assert_same_output(fresh, out);
    }
#undef DAMAGED_RUN
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_interrupted_run_is_marked),
        cmocka_unit_test(test_killed_run_leaves_partial),
        cmocka_unit_test(test_running_output),
        cmocka_unit_test(test_stop_messages),
        cmocka_unit_test(test_limits),
        cmocka_unit_test(test_restart_equivalence),
        cmocka_unit_test(test_sigkill_restart_loop),
        cmocka_unit_test(test_wall_clock_checkpoint),
        cmocka_unit_test(test_sigterm_keeps_the_work),
        cmocka_unit_test(test_file_size_limit),
        cmocka_unit_test(test_restart_errors),
        cmocka_unit_test(test_resume_sets_damaged_aside),
    };
    return cmocka_run_group_tests_name("cli_restart", tests, setup, teardown);
}
