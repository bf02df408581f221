/* scripts/sweep.sh end to end, as a user on one machine meets it: a 64-point sweep killed
 * halfway is completed by the same command without redoing or touching finished points,
 * each point's output equals a direct `bksim run --set` of that point, and bad grids are
 * refused before anything runs.  Needs GNU parallel; runs from the repository root. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bk_test.h"
#include "command.h"
#include "files.h"
#include "same_output.h"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    return make_temp_dir(tmpdir, sizeof tmpdir, "bksim_sweep");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

#define N_MU 8
#define N_V 8
static const char *const mu_values[N_MU] = {"0.2", "0.25", "0.3", "0.35", "0.4", "0.45", "0.5", "0.55"};
static const char *const v_values[N_V] = {"5e-4", "7e-4", "1e-3", "1.4e-3", "2e-3", "2.8e-3", "4e-3", "5.6e-3"};
/* Rate-and-state case B (an integrator, so a restart must land on the checkpoint's state),
 * checkpoints every 0.5 s, so that a kill mid-run leaves something to continue from. */
static const char *const sweep_args =
    "configs/paper/case_b_rs.ini friction.mu_d=0.2,0.25,0.3,0.35,0.4,0.45,0.5,0.55 "
    "driver.velocity=5e-4,7e-4,1e-3,1.4e-3,2e-3,2.8e-3,4e-3,5.6e-3 "
    "output.checkpoint_interval=0.5 run.t_end=10";

static void point_name(char *name, size_t size, size_t mu, size_t v)
{
    snprintf(name, size, "friction.mu_d=%s,driver.velocity=%s", mu_values[mu], v_values[v]);
}

/* Files in dir ending in suffix (".h5" leaves out ".h5.part"; summary.h5 is not counted). */
static size_t count_suffix(const char *dir, const char *suffix)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    size_t n = 0, len = strlen(suffix);
    for (struct dirent *e; (e = readdir(d));) {
        size_t l = strlen(e->d_name);
        n += l > len && strcmp(e->d_name + l - len, suffix) == 0 && strcmp(e->d_name, "summary.h5") != 0;
    }
    closedir(d);
    return n;
}

/* The command as a child in a session of its own (so that the whole sweep, GNU parallel and
 * every bksim it started, can be killed at once); returns its pid = session id. */
static pid_t start_group(const char *command)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        setsid();
        execl("/bin/bash", "bash", "-c", command, (char *)NULL);
        _exit(127);
    }
    return pid;
}

static void sleep_ms(long ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static int count_lines(const char *path, const char *needle)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    char line[4096];
    int n = 0;
    while (fgets(line, sizeof line, f))
        n += strstr(line, needle) != NULL;
    fclose(f);
    return n;
}

static void test_killed_sweep_completes(void **state)
{
    (void)state;
    char dir[512], cmd[2048], path[1024], name[256];
    snprintf(dir, sizeof dir, "%s/grid", tmpdir);
    snprintf(cmd, sizeof cmd, "exec scripts/sweep.sh -j 2 -o %s %s > %s/first.log 2>&1", dir, sweep_args,
             tmpdir);
    pid_t group = start_group(cmd);
    /* Halfway, with a run in flight (a .part on disk): kill -9 the whole session, as a power
     * cut or a scheduler's hard limit would.  GNU parallel puts each job in a process group of
     * its own; the session holds them all.  The sweep is frozen (SIGSTOP) while it is looked
     * at, so that a run cannot finish between the look and the kill. */
    char signal_cmd[128];
    size_t done = 0, parts = 0;
    for (int waited = 0; waited < 120000; waited += 5) {
        done = count_suffix(dir, ".h5");
        parts = count_suffix(dir, ".h5.part");
        if (done >= N_MU * N_V / 2 && parts > 0) {
            snprintf(signal_cmd, sizeof signal_cmd, "pkill -STOP -s %d", (int)group);
            assert_int_equal(system(signal_cmd), 0);
            if (count_suffix(dir, ".h5.part") > 0)
                break;
            snprintf(signal_cmd, sizeof signal_cmd, "pkill -CONT -s %d", (int)group);
            assert_int_equal(system(signal_cmd), 0);
        }
        sleep_ms(5);
    }
    char kill_cmd[128];
    snprintf(kill_cmd, sizeof kill_cmd, "pkill -KILL -s %d", (int)group);
    assert_int_equal(system(kill_cmd), 0);
    int status = 0;
    waitpid(group, &status, 0); /* our child, else a zombie that pkill would find forever */
    /* Again until none is left (zombies aside): a process forked while pkill scanned can
     * escape one pass. */
    snprintf(kill_cmd, sizeof kill_cmd,
             "for i in $(seq 100); do pkill -KILL -s %d -r R,S,D,T,t || exit 0; sleep 0.01; done; exit 1",
             (int)group);
    assert_int_equal(system(kill_cmd), 0);
    done = count_suffix(dir, ".h5");
    parts = count_suffix(dir, ".h5.part");
    print_message("killed with %zu points finished, %zu in flight\n", done, parts);
    assert_true(done >= N_MU * N_V / 2 && done < N_MU * N_V);
    assert_true(parts >= 1);

    /* What was finished before the second run. */
    struct stat before[N_MU][N_V];
    int finished[N_MU][N_V];
    for (size_t i = 0; i < N_MU; ++i)
        for (size_t j = 0; j < N_V; ++j) {
            point_name(name, sizeof name, i, j);
            snprintf(path, sizeof path, "%s/%s.h5", dir, name);
            finished[i][j] = stat(path, &before[i][j]) == 0;
        }

    snprintf(cmd, sizeof cmd, "scripts/sweep.sh -j 2 -o %s %s", dir, sweep_args);
    char *text = NULL;
    status = run_command(cmd, &text);
    if (status != 0) {
        print_message("%s", text);
        free(text);
        /* Why: the failed points' status lines and the end of their logs. */
        snprintf(cmd, sizeof cmd, "cd '%s' && grep FAILED sweep.log; for f in logs/*.log; do "
                 "grep -q -E 'Aborted|ERROR|error' \"$f\" && { echo \"== $f\"; tail -n 40 \"$f\"; }; done", dir);
        run_command(cmd, &text);
        print_message("%s", text);
    }
    free(text);
    assert_int_equal(status, 0);
    assert_int_equal(count_suffix(dir, ".h5"), N_MU * N_V);
    assert_int_equal(count_suffix(dir, ".h5.part"), 0);
    snprintf(path, sizeof path, "%s/sweep.log", dir);
    assert_int_equal(count_lines(path, "skipped: finished before"), (int)done);
    assert_int_equal(count_lines(path, "FAILED"), 0);
    int resumed = count_lines(path, "(continuing ");
    print_message("second run: %d points continued from a checkpoint\n", resumed);

    snprintf(path, sizeof path, "%s/direct.txt", tmpdir);
    FILE *direct_commands = fopen(path, "w");
    assert_non_null(direct_commands);
    for (size_t i = 0; i < N_MU; ++i)
        for (size_t j = 0; j < N_V; ++j) {
            point_name(name, sizeof name, i, j);
            char out[1024];
            snprintf(out, sizeof out, "%s/%s.h5", dir, name);
            struct stat after;
            assert_int_equal(stat(out, &after), 0);
            if (finished[i][j]) { /* never touched: the same inode, the same modification */
                assert_true(after.st_ino == before[i][j].st_ino);
                assert_true(after.st_mtim.tv_sec == before[i][j].st_mtim.tv_sec &&
                            after.st_mtim.tv_nsec == before[i][j].st_mtim.tv_nsec);
            }
            fprintf(direct_commands,
                    "%s run configs/paper/case_b_rs.ini -q --force -o %s/direct/%zu_%zu.h5 "
                    "--set friction.mu_d=%s --set driver.velocity=%s "
                    "--set output.checkpoint_interval=0.5 --set run.t_end=10\n",
                    bksim_binary(), tmpdir, i, j, mu_values[i], v_values[j]);
        }
    fclose(direct_commands);
    /* Every point against a direct run of it, two at a time. */
    snprintf(cmd, sizeof cmd, "mkdir -p %s/direct && parallel --will-cite -j 2 < %s/direct.txt", tmpdir,
             tmpdir);
    assert_int_equal(run_command(cmd, NULL), 0);
    size_t compared = 0;
    for (size_t i = 0; i < N_MU; ++i)
        for (size_t j = 0; j < N_V; ++j) {
            char out[1024], direct[1024];
            point_name(name, sizeof name, i, j);
            snprintf(out, sizeof out, "%s/%s.h5", dir, name);
            snprintf(direct, sizeof direct, "%s/direct/%zu_%zu.h5", tmpdir, i, j);
            assert_same_output(out, direct);
            ++compared;
        }
    print_message("%zu points compared with a direct run\n", compared);
    assert_int_equal(compared, N_MU * N_V);

    /* Each output names its point and seed (bksim info). */
    point_name(name, sizeof name, 3, 5);
    snprintf(cmd, sizeof cmd, "./bksim info '%s/%s.h5'", dir, name);
    char expected[300];
    snprintf(expected, sizeof expected, "point        %s\n", name);
    expect_command(cmd, 0, expected);
    expect_command(cmd, 0, "seed         1\n");

    /* The summary: a header, a units line, one row per point. */
    snprintf(path, sizeof path, "%s/summary.tsv", dir);
    assert_int_equal(count_lines(path, ".h5\t"), N_MU * N_V);
    snprintf(path, sizeof path, "%s/summary.h5", dir);
    assert_true(path_exists(path));

    /* Once more: nothing left to do, nothing touched. */
    snprintf(cmd, sizeof cmd, "scripts/sweep.sh -j 2 -o %s %s", dir, sweep_args);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(path, sizeof path, "%s/sweep.log", dir);
    assert_int_equal(count_lines(path, "skipped: finished before"), (int)done + N_MU * N_V);
}

/* A point stopped after a checkpoint continues from it when the sweep is run again. */
static void test_stopped_point_continues(void **state)
{
    (void)state;
    char dir[512], cmd[2048], path[1024];
    snprintf(dir, sizeof dir, "%s/resume", tmpdir);
    const char *grid = "configs/paper/case_b_rs.ini friction.mu_d=0.3,0.4 run.t_end=1000 "
                       "output.checkpoint_interval=10 output.interval=0.1";
    snprintf(cmd, sizeof cmd, "scripts/sweep.sh --plan -o %s %s", dir, grid);
    assert_int_equal(run_command(cmd, NULL), 0);
    /* One point as a batch system runs it, stopped (SIGTERM) well past its first checkpoint. */
    snprintf(cmd, sizeof cmd,
             "scripts/sweep_point.sh %s friction.mu_d=0.3 >> %s/sweep.log & sleep 0.4; "
             "pkill -TERM -f '[r]un %s/base.ini'; wait", dir, dir, dir);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(path, sizeof path, "%s/friction.mu_d=0.3.h5.part", dir);
    assert_true(path_exists(path));
    /* --resume with other values than the stopped run's is refused, and leaves it resumable. */
    snprintf(cmd, sizeof cmd,
             "./bksim run %s/base.ini -o %s/friction.mu_d=0.3.h5 --resume --set friction.mu_d=0.35 "
             "--set run.t_end=1000 --set output.checkpoint_interval=10 --set output.interval=0.1",
             dir, dir);
    expect_command(cmd, 2, "was started with another config");
    snprintf(cmd, sizeof cmd, "./bksim run %s/base.ini -o %s/x.h5 --resume --force", dir, dir);
    expect_command(cmd, 2, "--force starts over and --resume continues");
    snprintf(cmd, sizeof cmd, "scripts/sweep.sh -o %s %s", dir, grid);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(path, sizeof path, "%s/sweep.log", dir);
    assert_int_equal(count_lines(path, "friction.mu_d=0.3\tFAILED (exit 1"), 1);
    assert_int_equal(count_lines(path, "friction.mu_d=0.3\tdone in"), 1);
    assert_int_equal(count_lines(path, "(continuing "), 1);
    char out[1024], direct[1024];
    snprintf(out, sizeof out, "%s/friction.mu_d=0.3.h5", dir);
    snprintf(direct, sizeof direct, "%s/direct_resumed.h5", tmpdir);
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/paper/case_b_rs.ini -q --force -o %s --set friction.mu_d=0.3 "
             "--set run.t_end=1000 --set output.checkpoint_interval=10 --set output.interval=0.1",
             direct);
    assert_int_equal(run_command(cmd, NULL), 0);
    assert_same_output(out, direct);
}

/* A point that fails is named with its reason; the others finish; exit 1. */
static void test_failed_point_is_reported(void **state)
{
    (void)state;
    char dir[512], cmd[1024], path[600];
    snprintf(dir, sizeof dir, "%s/failing", tmpdir);
    /* mu_d = 0.7 > mu_s = 0.6: refused when that point loads, not when the grid is planned. */
    snprintf(cmd, sizeof cmd, "scripts/sweep.sh -j 2 -o %s configs/paper/case_a_coulomb.ini "
             "friction.mu_d=0.1,0.7 run.t_end=1", dir);
    char *text = NULL;
    assert_int_equal(run_command(cmd, &text), 1);
    assert_non_null(strstr(text, "1 of 2 points finished"));
    free(text);
    snprintf(path, sizeof path, "%s/sweep.log", dir);
    assert_int_equal(count_lines(path, "friction.mu_d=0.7\tFAILED (exit 2"), 1);
    assert_int_equal(count_lines(path, "mu_d"), 3); /* the failure says which key and why */
    snprintf(path, sizeof path, "%s/friction.mu_d=0.1.h5", dir);
    assert_true(path_exists(path));
    snprintf(path, sizeof path, "%s/friction.mu_d=0.7.h5", dir);
    assert_false(path_exists(path));
}

/* Bad grids: exit 2, a message naming what is wrong, nothing run. */
static void test_bad_grids(void **state)
{
    (void)state;
    char cmd[1024];
    static const struct {
        const char *args, *message;
    } cases[] = {
        {"", "missing BASE.ini"},
        {"configs/none.ini friction.mu_d=0.1", "no such config file"},
        {"configs/paper/case_a_coulomb.ini mu_d=0.1,0.2", "is not a section.key"},
        {"configs/paper/case_a_coulomb.ini friction.mu_d", "is not KEY=V1,V2"},
        {"configs/paper/case_a_coulomb.ini friction.mu_d=0.1,,0.2", "every value must be non-empty"},
        {"configs/paper/case_a_coulomb.ini friction.mu_d=0.1 friction.mu_d=0.2", "given twice"},
        {"configs/paper/case_a_coulomb.ini friction.mu_d=0.1,0.1", "share the name"},
        {"configs/paper/case_a_coulomb.ini friction.mu_dd=0.1,0.2", "mu_dd"},
        {"-j 0 configs/paper/case_a_coulomb.ini friction.mu_d=0.1", "-j needs a whole number"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char dir[512];
        snprintf(dir, sizeof dir, "%s/bad_%zu", tmpdir, k);
        snprintf(cmd, sizeof cmd, "scripts/sweep.sh -o %s %s", dir, cases[k].args);
        expect_command(cmd, 2, cases[k].message);
        char points[600];
        snprintf(points, sizeof points, "%s/points.tsv", dir);
        assert_false(path_exists(points));
    }
    /* The same DIR with another grid or another config is refused, not mixed. */
    char dir[512];
    snprintf(dir, sizeof dir, "%s/mixed", tmpdir);
    snprintf(cmd, sizeof cmd, "scripts/sweep.sh -o %s configs/paper/case_a_coulomb.ini "
             "friction.mu_d=0.1,0.2 run.t_end=0.5", dir);
    assert_int_equal(run_command(cmd, NULL), 0);
    snprintf(cmd, sizeof cmd, "scripts/sweep.sh -o %s configs/paper/case_a_coulomb.ini "
             "friction.mu_d=0.1,0.2 run.t_end=1", dir);
    expect_command(cmd, 2, "another grid");
    snprintf(cmd, sizeof cmd, "scripts/sweep.sh -o %s configs/paper/case_b_coulomb.ini "
             "friction.mu_d=0.1,0.2 run.t_end=0.5", dir);
    expect_command(cmd, 2, "another config");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_killed_sweep_completes),
        cmocka_unit_test(test_stopped_point_continues),
        cmocka_unit_test(test_failed_point_is_reported),
        cmocka_unit_test(test_bad_grids),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
