/* bksim command line: a thin client of the library.  The only place that calls exit.
 *
 * Exit status: 0 success, 1 the run or the file failed (or is damaged), 2 bad usage or bad
 * config, 3 (info) an intact file of a run that did not finish. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bksim/bksim.h"

enum { EXIT_RUN_FAILED = 1, EXIT_USAGE = 2, EXIT_INCOMPLETE = 3 };

static const char *const usage_text =
    "usage: bksim <command> [options]\n"
    "\n"
    "commands:\n"
    "  run CONFIG [-o OUT] [--set section.key=value]... [--quiet] [--force|--resume]\n"
    "                       simulate the scene CONFIG describes, write HDF5 to OUT\n"
    "                       (default: [output] path)\n"
    "  run --restart OUT.h5[.part] [--quiet]\n"
    "                       continue a stopped run from its last checkpoint\n"
    "  check CONFIG [--set section.key=value]... [--strict]\n"
    "                       validate CONFIG without running\n"
    "  info OUT.h5 [--blocks]\n"
    "                       summarise an output file (or a running run's progress)\n"
    "  export OUT.h5 [--datasets a,b,...] [--block I] [--transitions]\n"
    "                       print columns for gnuplot and shell tools\n"
    "  export OUT.h5 --events\n"
    "                       print the event catalog /events as TSV\n"
    "  stats FILE [--table NAME] [--mc auto|VALUE] [--bin DM] [--from T] [--to T]\n"
    "        [--json] [--tsv DIR]\n"
    "                       earthquake statistics of the rupture catalog /ruptures in FILE\n"
    "                       (else /events; --table events: the time-window catalog)\n"
    "  summary DIR [--table NAME] [--mc auto|VALUE] [--bin DM] [--from T] [--to T]\n"
    "                       one row per finished run in DIR (a sweep): its --set values\n"
    "                       and headline figures, as DIR/summary.tsv and DIR/summary.h5\n"
    "  keys                 print the config key reference (Markdown)\n"
    "  --version            print the version\n"
    "\n"
    "`bksim <command> --help` describes one command.\n";

static const char *const run_help =
    "usage: bksim run CONFIG [-o OUT] [--set section.key=value]... [--quiet] [--force|--resume]\n"
    "                 [--point NAME] [--strict]\n"
    "       bksim run --restart OUT.h5[.part] [--quiet]\n"
    "\n"
    "Runs the scene described by the INI file CONFIG and writes an HDF5 time series.\n"
    "  --restart OUT      continue the stopped run whose output is OUT.part from its last\n"
    "                     checkpoint ([output] checkpoint_interval), with the config stored\n"
    "                     in the file; rows after the checkpoint are recomputed\n"
    "  -o, --output OUT   output path (overrides [output] path)\n"
    "  --set S.K=V        override key K of section S after reading CONFIG; S may be\n"
    "                     block.3 or friction.3 for one block (repeatable)\n"
    "  -q, --quiet        no progress indicator and no summary\n"
    "  --force            start over even when OUT.part holds a checkpoint to restart from\n"
    "                     (without it, run refuses to overwrite that progress)\n"
    "  --resume           continue OUT.part from its checkpoint when it holds one that\n"
    "                     verifies, else start over: what a batch script reruns\n"
    "  --point NAME       the sweep grid point this run is, recorded in OUT (attribute point)\n"
    "  --strict           refuse (exit 2) a config that draws a warning: a value far outside\n"
    "                     what the others make plausible (see `bksim check --help`)\n"
    "The file is written as OUT.part and renamed to OUT when the run completes; a failed\n"
    "or interrupted run leaves OUT.part marked complete = 0.\n";

static const char *const check_help =
    "usage: bksim check CONFIG [--set section.key=value]... [--strict]\n"
    "\n"
    "Validates CONFIG (and the overrides) exactly as `run` would, writes nothing.  Values\n"
    "within their ranges but far outside what the others make plausible get a warning on\n"
    "stderr naming the key and why (run prints them too): a driver faster than the blocks'\n"
    "own slip speeds, an [output] interval longer than a slip, a [solver] max_step longer\n"
    "than the fastest natural period.\n"
    "  --strict   make those warnings errors (exit 2), for batch scripts\n";

static const char *const info_help =
    "usage: bksim info OUT.h5 [--blocks]\n"
    "\n"
    "Prints the parameters, stick/slip phase counts and solver statistics, and checks the\n"
    "file: datasets present and equally long, time increasing (equal only for a transition\n"
    "instant's before and after rows), the complete flag.\n"
    "Chains of up to 20 blocks get one line per block; longer ones totals, the spread of\n"
    "slips per block and the most active blocks.\n"
    "  --blocks   one line per block whatever the chain's length\n"
    "On the .part of a run still going (it holds the file's lock) it reports the progress\n"
    "the run last committed (about once a second): in progress, t = ..., N transitions so\n"
    "far, and its last checkpoint.\n"
    "Exit status 0: intact and complete; 3: intact but the run did not finish (e.g.\n"
    "OUT.h5.part of an interrupted run) or is still running; 1: damaged or unreadable.\n";

static const char *const export_help =
    "usage: bksim export OUT.h5 [--datasets a,b,...] [--block I] [--transitions]\n"
    "       bksim export OUT.h5 --events\n"
    "       bksim export OUT.h5 --table NAME\n"
    "\n"
    "Prints whitespace-separated columns with a '#' header (names and units).\n"
    "  --datasets LIST   comma-separated dataset names (default time,event,driver,x,v,\n"
    "                    friction,cof,mode); per-block datasets give one column per block.\n"
    "                    A transition instant is two rows at one time: event 2, the state\n"
    "                    just before its transitions, then event 1, just after\n"
    "  --block I         only block I (0-based) of the per-block datasets\n"
    "  --transitions     print the /transitions table instead\n"
    "  --events          print the event catalog /events instead, tab-separated: one row\n"
    "                    per event, every field (t_start ... complete); on a ring\n"
    "                    left > right when the extent wraps past block 0\n"
    "  --table NAME      print any table of records as TSV, every field with its unit:\n"
    "                    ruptures, rupture_blocks, rupture_rate (README \"Ruptures\"),\n"
    "                    events, transitions\n";

static const char *const stats_help =
    "usage: bksim stats FILE [--table NAME] [--mc auto|VALUE] [--bin DM] [--from T] [--to T]\n"
    "                        [--json] [--tsv DIR]\n"
    "\n"
    "Statistics of an earthquake catalog in the HDF5 file FILE (a table with at least\n"
    "t_start and magnitude): magnitude-frequency distribution, completeness magnitude Mc,\n"
    "b-value (Aki-Utsu maximum likelihood, Shi & Bolt error), potency exponent, event\n"
    "sizes, recurrence intervals, and a KS test of the two halves of the run.  Events still\n"
    "running at the end (complete = 0) are left out.  The catalog is the rupture catalog\n"
    "/ruptures (connected slip episodes: one row per rupture); a file without it (an older\n"
    "bksim output, another program's catalog) falls back to /events, and the report says so\n"
    "(JSON: \"table\", \"table_fallback\").\n"
    "  --table NAME      the catalog table: events (the time-window catalog: maximal\n"
    "                    intervals during which some block slips), ruptures, or any 1-D\n"
    "                    table of FILE with fields t_start and magnitude; no fallback\n"
    "  --mc auto|VALUE   completeness magnitude: maximum curvature + 0.2 (auto, the\n"
    "                    default) or VALUE, a multiple of the bin width\n"
    "  --bin DM          magnitude bin width, 0 < DM <= 10 (default 0.1)\n"
    "  --from T, --to T  only events starting at t >= T, t < T (s): leave a spin-up out;\n"
    "                    rates, recurrence and the KS test use the window's span\n"
    "  --json            print one JSON object instead of the text report\n"
    "  --tsv DIR         also write tables for gnuplot to DIR (created if missing): mfd.tsv,\n"
    "                    gr_fit.tsv, sizes.tsv, sizes_log2.tsv, intervals.tsv,\n"
    "                    potency_ccdf.tsv\n";

static const char *const summary_help =
    "usage: bksim summary DIR [--table NAME] [--mc auto|VALUE] [--bin DM] [--from T] [--to T]\n"
    "\n"
    "One row per finished run (complete *.h5) in DIR, sorted by file name: file, point (the\n"
    "sweep's grid point), a column per --set key of the runs (named by the key: the run's\n"
    "value), then events, mean_recurrence (s), largest_magnitude, largest_event_blocks,\n"
    "peak_slip_rate (m/s), b_value, b_error, mc, b_events (as `bksim stats` gives them),\n"
    "energy_residual, steps, rhs_evals, transitions, t_reached, wall_time, cpu_time (s),\n"
    "seed, method, host, catalog; nan where a run has none.  The catalog figures (events\n"
    "to b_events) count the rows of the run's /ruptures (else /events, as `bksim stats`),\n"
    "and catalog names the table.  Written to DIR/summary.tsv (a '#' line of units, a\n"
    "header line, tab-separated rows: scripts/plot_summary.sh draws any column against any\n"
    "other) and DIR/summary.h5 (compound dataset /summary).  Runs that did not finish\n"
    "(*.h5.part) are not summarised; other files left out are named on stderr.\n"
    "  --table NAME                as for `bksim stats` (events: the time-window catalog);\n"
    "                              a run without that table is left out\n"
    "  --mc, --bin, --from, --to   as for `bksim stats`: the catalog figures use them\n";

static const char *const keys_help =
    "usage: bksim keys\n"
    "\n"
    "Prints every config key (section, unit, default, allowed range, meaning) as Markdown.\n";

static volatile sig_atomic_t stop_requested = 0;

/* A repeated SIGXCPU is the kernel's reminder once a second past the soft CPU limit, not
 * a second request: only SIGINT, SIGTERM and SIGHUP escalate. */
static void on_signal(int signo)
{
    if (stop_requested && signo != SIGXCPU) {
        signal(signo, SIG_DFL); /* both async-signal-safe */
        raise(signo);
        return;
    }
    stop_requested = 1;
}

/* The first SIGINT, SIGTERM, SIGHUP (terminal gone) or SIGXCPU (a batch system's CPU limit)
 * asks the run to stop at the next step or row and leave a valid, incomplete file; a second
 * SIGINT, SIGTERM or SIGHUP (any of them) then stops the process at once. */
static void catch_stop_signals(void)
{
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = on_signal;
    action.sa_flags = SA_RESTART;
    sigemptyset(&action.sa_mask);
    const int signals[] = {SIGINT, SIGTERM, SIGHUP, SIGXCPU};
    for (size_t k = 0; k < sizeof signals / sizeof signals[0]; ++k)
        sigaction(signals[k], &action, NULL);
}

static int wants_help(int argc, char **argv)
{
    for (int i = 0; i < argc; ++i)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0)
            return 1;
    return 0;
}

static int usage_error(const char *command, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static int usage_error(const char *command, const char *fmt, ...)
{
    fprintf(stderr, "bksim %s: ", command);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(see `bksim %s --help`)\n", command);
    return EXIT_USAGE;
}

/* Options shared by run and check. */
typedef struct config_args {
    const char *config_path;
    const char *restart;
    const char *output;
    const char **overrides;
    size_t n_overrides;
    const char *point;
    int quiet;
    int force;
    int resume;
    int strict;
} config_args;

static int parse_config_args(const char *command, int argc, char **argv, config_args *args)
{
    memset(args, 0, sizeof *args);
    args->overrides = calloc((size_t)argc + 1, sizeof *args->overrides);
    if (!args->overrides) {
        fprintf(stderr, "bksim: out of memory\n");
        return EXIT_RUN_FAILED;
    }
    int allow_output = strcmp(command, "run") == 0;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "--set") == 0) {
            if (i + 1 >= argc)
                return usage_error(command, "%s needs section.key=value", a);
            args->overrides[args->n_overrides++] = argv[++i];
        } else if (strncmp(a, "--set=", 6) == 0) {
            args->overrides[args->n_overrides++] = a + 6;
        } else if (allow_output && (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0)) {
            if (i + 1 >= argc)
                return usage_error(command, "%s needs a path", a);
            args->output = argv[++i];
        } else if (strcmp(a, "--strict") == 0) {
            args->strict = 1;
        } else if (allow_output && (strcmp(a, "-q") == 0 || strcmp(a, "--quiet") == 0)) {
            args->quiet = 1;
        } else if (allow_output && strcmp(a, "--force") == 0) {
            args->force = 1;
        } else if (allow_output && strcmp(a, "--resume") == 0) {
            args->resume = 1;
        } else if (allow_output && strcmp(a, "--point") == 0) {
            if (i + 1 >= argc || !argv[i + 1][0])
                return usage_error(command, "%s needs a name", a);
            args->point = argv[++i];
        } else if (allow_output && strcmp(a, "--restart") == 0) {
            if (i + 1 >= argc)
                return usage_error(command, "%s needs the output file of the stopped run", a);
            args->restart = argv[++i];
        } else if (a[0] == '-' && a[1] != '\0') {
            return usage_error(command, "unknown option '%s'", a);
        } else if (!args->config_path) {
            args->config_path = a;
        } else {
            return usage_error(command, "unexpected argument '%s'", a);
        }
    }
    if (args->restart) {
        if (args->config_path || args->n_overrides || args->output || args->point || args->resume ||
            args->strict)
            return usage_error(command, "%s", "--restart takes no CONFIG, -o, --set, --point, "
                                              "--resume or --strict: the run continues with the "
                                              "config stored in its file");
        return 0;
    }
    if (args->force && args->resume)
        return usage_error(command, "%s", "--force starts over and --resume continues: give one");
    if (!args->config_path)
        return usage_error(command, "%s", "missing CONFIG");
    return 0;
}

static void print_warning(void *user, const char *message)
{
    fprintf(stderr, "%s%s\n", *(const int *)user ? "error (--strict): " : "warning: ", message);
}

static int load_config(const config_args *args, bk_config **config)
{
    bk_error err = {0};
    int rc = bk_config_load_file(args->config_path, args->overrides, args->n_overrides, config, &err);
    if (rc != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return rc == BK_ERR_CONFIG ? EXIT_USAGE : EXIT_RUN_FAILED;
    }
    /* Plausible but suspicious values: said, and with --strict refused before any output. */
    int strict = args->strict;
    if (bk_config_warnings(*config, print_warning, &strict) > 0 && strict) {
        bk_config_free(*config);
        *config = NULL;
        return EXIT_USAGE;
    }
    return 0;
}

/* The shared start of run and check: help, arguments, the config.  Returns -1 when help
 * was printed (exit 0), else an exit status (0: go on with *config loaded). */
static int prepare(const char *command, const char *help, int argc, char **argv, config_args *args,
                   bk_config **config)
{
    *config = NULL;
    args->overrides = NULL;
    if (wants_help(argc, argv)) {
        fputs(help, stdout);
        return -1;
    }
    int status = parse_config_args(command, argc, argv, args);
    if (status == 0 && !args->restart)
        status = load_config(args, config);
    return status;
}

static int cmd_check(int argc, char **argv)
{
    config_args args;
    bk_config *config = NULL;
    int status = prepare("check", check_help, argc, argv, &args, &config);
    if (status < 0)
        return 0;
    if (status == 0) {
        const bk_model *m = config->model;
        char driver[96];
        if (m->driver.n_segments > 0)
            snprintf(driver, sizeof driver, "a history of %zu segments", m->driver.n_segments);
        else
            snprintf(driver, sizeof driver, "%g m/s", m->driver.velocity);
        static const char *const boundary_names[] = {"free", "fixed", "periodic"};
        char shape[160];
        if (bk_model_directions(m) == 2)
            snprintf(shape, sizeof shape, "%s boundary", boundary_names[m->boundary_cols]);
        else
            snprintf(shape, sizeof shape, "a %zu x %zu lattice, %s rows boundary, %s cols boundary", m->rows,
                     m->cols, boundary_names[m->boundary_rows], boundary_names[m->boundary_cols]);
        printf("%s: ok: %zu block%s, %s, %s driver spring, driver %s, t_end %g s, "
               "method %s, output %s\n",
               args.config_path, m->n_blocks, m->n_blocks == 1 ? "" : "s", shape,
               m->spring == BK_SPRING_LINEAR ? "linear" : "tension-only", driver,
               config->t_end, config->solver.method, config->output.path);
    }
    bk_config_free(config);
    free(args.overrides);
    return status;
}

/* Progress on a terminal, for runs longer than a second. */
typedef struct progress_state {
    int enabled;
    double start, last_print;
    int printed;
} progress_state;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A duration as a person reads it: "42 s", "12 min 05 s", "3 h 20 min", "2 d 04 h". */
static void format_duration(char *out, size_t size, double seconds)
{
    long s = seconds < 0.0 ? 0 : seconds > 9.9e8 ? 990000000L : (long)(seconds + 0.5);
    if (s < 60)
        snprintf(out, size, "%ld s", s);
    else if (s < 3600)
        snprintf(out, size, "%ld min %02ld s", s / 60, s % 60);
    else if (s < 86400)
        snprintf(out, size, "%ld h %02ld min", s / 3600, s % 3600 / 60);
    else
        snprintf(out, size, "%ld d %02ld h", s / 86400, s % 86400 / 3600);
}

static int show_progress(void *user, const bk_progress *r)
{
    progress_state *p = user;
    if (stop_requested)
        return 1;
    if (!p->enabled)
        return 0;
    double now = now_seconds();
    if (now - p->start < 1.0 || now - p->last_print < 0.1)
        return 0;
    double elapsed = now - p->start;
    p->last_print = now;
    p->printed = 1;
    char produced[96], spent[32], eta[40] = "";
    if (r->events >= 0)
        snprintf(produced, sizeof produced, "%ld events (%.3g per s)", r->events,
                 (double)(r->events - r->events_resumed) / elapsed);
    else
        snprintf(produced, sizeof produced, "%ld transitions", r->transitions);
    format_duration(spent, sizeof spent, elapsed);
    /* Simulated time per wall-clock second since this run began: a stick-slip run's pace
     * varies from event to event, and the whole run's average is the steadier forecast. */
    if (r->t > r->t_resumed) {
        char left[32];
        format_duration(left, sizeof left, elapsed * (r->t_end - r->t) / (r->t - r->t_resumed));
        snprintf(eta, sizeof eta, ", ETA %s", left);
    }
    /* \033[K clears what a longer previous line left. */
    fprintf(stderr, "\rbksim: t = %.6g s of %g s (%.0f%%), %s, %s elapsed%s\033[K", r->t, r->t_end,
            100.0 * r->t / r->t_end, produced, spent, eta);
    fflush(stderr);
    return 0;
}

static int cmd_run(int argc, char **argv)
{
    config_args args;
    bk_config *config = NULL;
    int status = prepare("run", run_help, argc, argv, &args, &config);
    if (status < 0)
        return 0;
    if (status != 0) {
        free(args.overrides);
        return status;
    }
    bk_error err = {0};
    bk_h5_writer *writer = NULL;
    bk_checkpoint checkpoint;
    memset(&checkpoint, 0, sizeof checkpoint);
    const char *path = args.output ? args.output : config ? config->output.path : NULL;
    char *restart_path = NULL;
    int opened;
    if (args.restart) {
        opened = bk_h5_writer_resume(&writer, args.restart, &config, &checkpoint, &err);
        restart_path = bk_output_final_path(args.restart);
        path = restart_path;
    } else {
        /* A stopped run's progress is not thrown away by running the same command again. */
        double t_checkpoint = 0.0;
        int restartable = !args.force && path ? bk_h5_restartable(path, &t_checkpoint, &err) : 0;
        if (restartable < 0) {
            fprintf(stderr, "%s\n", err.message);
            bk_config_free(config);
            free(args.overrides);
            return EXIT_RUN_FAILED;
        }
        if (restartable == 1 && args.resume) {
            /* The stored config is the one the run began with; this command's must match.  A
             * copy of path: it may live in the config replaced here. */
            restart_path = strdup(path);
            bk_config *given = config;
            config = NULL;
            opened = restart_path ? bk_h5_writer_resume(&writer, restart_path, &config, &checkpoint, &err)
                                  : BK_FAIL(&err, BK_ERR_NOMEM, "bksim: out of memory");
            if (opened == BK_OK && strcmp(given->text, config->text) != 0) {
                /* Cut to its checkpoint, which stays: a later --restart still continues it. */
                bk_h5_writer_abandon(writer, "a run with another config was refused its --resume", NULL);
                bk_checkpoint_free(&checkpoint);
                writer = NULL;
                opened = BK_FAIL(&err, BK_ERR_INVALID,
                                 "%s.part was started with another config (or other --set values) "
                                 "than this command's: pass --force to start over",
                                 path);
            }
            bk_config_free(given);
            path = args.restart = restart_path; /* from here on, a restarted run */
            if (!args.quiet && opened == BK_OK)
                fprintf(stderr, "bksim: continuing %s.part from its checkpoint t = %.17g s\n", path,
                        t_checkpoint);
        } else if (restartable == 1) {
            fprintf(stderr,
                    "%s.part holds a run stopped at its checkpoint t = %.17g s: continue it with "
                    "`bksim run --restart %s.part`, or pass --force to start over\n",
                    path, t_checkpoint, path);
            bk_config_free(config);
            free(args.overrides);
            return EXIT_USAGE;
        } else {
            /* Never silently: a stopped run's .part without a checkpoint is replaced. */
            char *part = bk_output_part_path(path);
            struct stat st;
            if (part && stat(part, &st) == 0 && !args.quiet)
                fprintf(stderr, "bksim: starting over: %s is replaced (%s)\n", part,
                        args.force ? "--force" : "it holds no checkpoint to continue from");
            free(part);
            opened = bk_h5_writer_open(&writer, config, path, &err);
            if (opened == BK_OK && args.point && bk_h5_writer_set_point(writer, args.point, &err) != BK_OK) {
                bk_h5_writer_abandon(writer, err.message, NULL);
                writer = NULL;
                opened = BK_ERR_IO;
            }
        }
    }
    if (opened != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        bk_config_free(config);
        free(args.overrides);
        free(restart_path);
        return opened == BK_ERR_INVALID || opened == BK_ERR_CONFIG ? EXIT_USAGE : EXIT_RUN_FAILED;
    }
    catch_stop_signals();
    progress_state progress = {!args.quiet && isatty(STDERR_FILENO), now_seconds(), 0.0, 0};
    bk_sink sink = bk_h5_writer_sink(writer);
    bk_run_stats stats;
    int rc = bk_run_from(config, args.restart ? &checkpoint : NULL, &sink, &stats, show_progress,
                         &progress, &err);
    bk_checkpoint_free(&checkpoint);
    if (progress.printed)
        fputs("\n", stderr);
    if (rc != BK_OK) {
        fprintf(stderr, "%s: %s\n", args.restart ? args.restart : args.config_path, err.message);
        bk_h5_writer_abandon(writer, err.message, &stats);
        /* Say how to go on: from the last checkpoint, or (none) only by starting over. */
        double t_checkpoint = 0.0;
        bk_error ignored = {0};
        fprintf(stderr, "bksim: partial output left in %s.part (complete = 0); ", path);
        if (bk_h5_restartable(path, &t_checkpoint, &ignored) == 1)
            fprintf(stderr, "continue it from its checkpoint t = %.17g s with `bksim run --restart %s.part`\n",
                    t_checkpoint, path);
        else if (config->output.checkpoint_interval > 0.0 || config->output.checkpoint_work > 0.0)
            fprintf(stderr, "it holds no checkpoint, so it cannot be continued: running again starts over "
                            "(the run writes its first at the restart point after [output] "
                            "checkpoint_wall_interval = %g s)\n",
                    config->output.checkpoint_wall_interval);
        else
            fprintf(stderr, "it holds no checkpoint, so it cannot be continued: running again starts over "
                            "([output] checkpoint_interval = 0 writes none)\n");
        status = EXIT_RUN_FAILED;
    } else if (bk_h5_writer_finish(writer, &stats, &err) != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        status = EXIT_RUN_FAILED;
    } else if (!args.quiet) {
        printf("%s: %ld rows, %ld transitions, t = %g s, %ld steps, %ld RHS evaluations, "
               "energy residual %.2g, %.3f s CPU\n",
               path, stats.rows, stats.transitions, stats.t_reached, stats.steps, stats.rhs_evals,
               stats.energy_residual, stats.cpu_time);
    }
    bk_config_free(config);
    free(args.overrides);
    free(restart_path);
    return status;
}

static int cmd_info(int argc, char **argv)
{
    if (wants_help(argc, argv)) {
        fputs(info_help, stdout);
        return 0;
    }
    const char *path = NULL;
    int per_block = 0;
    for (int i = 0; i < argc; ++i) {
        if (strcmp(argv[i], "--blocks") == 0)
            per_block = 1;
        else if (argv[i][0] == '-')
            return usage_error("info", "unknown option '%s'", argv[i]);
        else if (path)
            return usage_error("info", "%s", "expects exactly one file");
        else
            path = argv[i];
    }
    if (!path)
        return usage_error("info", "%s", "missing OUT.h5");
    bk_error err = {0};
    int rc = bk_h5_info_blocks(path, stdout, per_block, &err);
    if (rc == BK_INCOMPLETE)
        return EXIT_INCOMPLETE;
    if (rc != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return EXIT_RUN_FAILED;
    }
    return 0;
}

static int cmd_export(int argc, char **argv)
{
    if (wants_help(argc, argv)) {
        fputs(export_help, stdout);
        return 0;
    }
    const char *path = NULL, *datasets = NULL, *table = NULL;
    long block = -1;
    int transitions = 0, events = 0;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "--datasets") == 0 && i + 1 < argc) {
            datasets = argv[++i];
        } else if (strncmp(a, "--datasets=", 11) == 0) {
            datasets = a + 11;
        } else if ((strcmp(a, "--block") == 0 && i + 1 < argc) || strncmp(a, "--block=", 8) == 0) {
            const char *text = a[7] == '=' ? a + 8 : argv[++i];
            char *end = NULL;
            errno = 0;
            block = strtol(text, &end, 10);
            if (errno || end == text || *end != '\0' || block < 0)
                return usage_error("export", "--block needs a block index >= 0, got '%s'", text);
        } else if (strcmp(a, "--transitions") == 0) {
            transitions = 1;
        } else if (strcmp(a, "--events") == 0) {
            events = 1;
        } else if (strcmp(a, "--table") == 0 && i + 1 < argc) {
            table = argv[++i];
        } else if (strncmp(a, "--table=", 8) == 0) {
            table = a + 8;
        } else if (a[0] == '-') {
            return usage_error("export", "unknown or incomplete option '%s'", a);
        } else if (!path) {
            path = a;
        } else {
            return usage_error("export", "unexpected argument '%s'", a);
        }
    }
    if (!path)
        return usage_error("export", "%s", "missing OUT.h5");
    if (events && (datasets || block >= 0 || transitions))
        return usage_error("export", "%s", "--events prints the whole catalog: it takes none "
                                           "of --datasets, --block, --transitions");
    if (table && (datasets || block >= 0 || transitions || events))
        return usage_error("export", "%s", "--table prints one whole table: it takes none of --datasets, "
                                           "--block, --transitions, --events");
    if (table && !*table)
        return usage_error("export", "%s", "--table needs a table name (ruptures, rupture_blocks, rupture_rate, "
                                           "events, transitions)");
    bk_error err = {0};
    int rc = table    ? bk_h5_export_table(path, table, stdout, &err)
             : events ? bk_h5_export_events(path, stdout, &err)
                      : bk_h5_export(path, datasets, block, transitions, stdout, &err);
    if (rc != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return EXIT_RUN_FAILED;
    }
    return 0;
}

/* The catalog options of stats and summary (--mc, --bin, --from, --to into opt, --table into
 * *table) at argv[*i]: -1 when argv[*i] is none of them, 0 when taken (*i advanced past a
 * separate value), else the exit status of a usage error.  Ranges (finite, a bin centre, ...)
 * are bk_stats_options_check's. */
static int parse_catalog_option(const char *command, int argc, char **argv, int *i,
                                bk_stats_options *opt, const char **table)
{
    static const char *const names[] = {"--mc", "--bin", "--from", "--to", "--table"};
    const char *a = argv[*i], *value = NULL;
    size_t which = 0;
    for (; which < 5; ++which) {
        size_t len = strlen(names[which]);
        if (strcmp(a, names[which]) == 0 && *i + 1 < argc) {
            value = argv[++*i];
            break;
        }
        if (strncmp(a, names[which], len) == 0 && a[len] == '=') {
            value = a + len + 1;
            break;
        }
    }
    if (!value)
        return -1;
    char *end = NULL;
    errno = 0;
    if (which == 4) {
        if (!*value || strcmp(value, "/") == 0)
            return usage_error(command, "%s", "--table needs a table name: ruptures, events, or "
                                              "another table with t_start and magnitude");
        *table = value;
    } else if (which == 0) {
        opt->mc_auto = strcmp(value, "auto") == 0;
        if (!opt->mc_auto) {
            opt->mc = strtod(value, &end);
            if (errno || end == value || *end)
                return usage_error(command, "--mc needs 'auto' or a magnitude, got '%s'", value);
        }
    } else if (which == 1) {
        opt->dm = strtod(value, &end);
        if (errno || end == value || *end)
            return usage_error(command, "--bin needs a bin width 0 < DM <= 10, got '%s'", value);
    } else {
        double t = strtod(value, &end);
        if (errno || end == value || *end || !isfinite(t))
            return usage_error(command, "%s needs a time in s, got '%s'", names[which], value);
        *(which == 2 ? &opt->t_from : &opt->t_to) = t;
    }
    return 0;
}

static int cmd_stats(int argc, char **argv)
{
    if (wants_help(argc, argv)) {
        fputs(stats_help, stdout);
        return 0;
    }
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    const char *path = NULL, *tsv_dir = NULL, *table = NULL;
    int json = 0;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        int taken = parse_catalog_option("stats", argc, argv, &i, &opt, &table);
        if (taken > 0)
            return taken;
        if (taken == 0)
            continue;
        if (strcmp(a, "--tsv") == 0 && i + 1 < argc) {
            tsv_dir = argv[++i];
        } else if (strncmp(a, "--tsv=", 6) == 0) {
            tsv_dir = a + 6;
        } else if (strcmp(a, "--json") == 0) {
            json = 1;
        } else if (a[0] == '-') {
            return usage_error("stats", "unknown or incomplete option '%s'", a);
        } else if (!path) {
            path = a;
        } else {
            return usage_error("stats", "unexpected argument '%s'", a);
        }
    }
    if (!path)
        return usage_error("stats", "%s", "missing FILE");
    bk_error err = {0};
    if (bk_stats_options_check(&opt, &err) != BK_OK)
        return usage_error("stats", "%s", err.message);
    bk_stats_report *report = NULL;
    int rc = bk_stats_report_read(path, table, &opt, &report, &err);
    /* Tables first: a directory that cannot be written fails before anything is printed. */
    if (rc == BK_OK && tsv_dir)
        rc = bk_stats_report_tsv(report, tsv_dir, &err);
    if (rc == BK_OK)
        rc = json ? bk_stats_report_json(report, stdout, &err)
                  : bk_stats_report_text(report, stdout, &err);
    bk_stats_report_free(report);
    if (rc != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return EXIT_RUN_FAILED;
    }
    return 0;
}

static int cmd_summary(int argc, char **argv)
{
    if (wants_help(argc, argv)) {
        fputs(summary_help, stdout);
        return 0;
    }
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    const char *dir = NULL, *table = NULL;
    for (int i = 0; i < argc; ++i) {
        int taken = parse_catalog_option("summary", argc, argv, &i, &opt, &table);
        if (taken > 0)
            return taken;
        if (taken == 0)
            continue;
        if (argv[i][0] == '-')
            return usage_error("summary", "unknown or incomplete option '%s'", argv[i]);
        if (dir)
            return usage_error("summary", "unexpected argument '%s'", argv[i]);
        dir = argv[i];
    }
    if (!dir)
        return usage_error("summary", "%s", "missing DIR");
    bk_error err = {0};
    if (bk_stats_options_check(&opt, &err) != BK_OK)
        return usage_error("summary", "%s", err.message);
    size_t runs = 0;
    if (bk_h5_summary(dir, table, &opt, stderr, &runs, &err) != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return EXIT_RUN_FAILED;
    }
    printf("%s/summary.tsv, %s/summary.h5: %zu run%s\n", dir, dir, runs, runs == 1 ? "" : "s");
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    const char *command = argv[1];
    int rest = argc - 2;
    char **rest_argv = argv + 2;
    if (strcmp(command, "run") == 0)
        return cmd_run(rest, rest_argv);
    if (strcmp(command, "check") == 0)
        return cmd_check(rest, rest_argv);
    if (strcmp(command, "info") == 0)
        return cmd_info(rest, rest_argv);
    if (strcmp(command, "export") == 0)
        return cmd_export(rest, rest_argv);
    if (strcmp(command, "stats") == 0)
        return cmd_stats(rest, rest_argv);
    if (strcmp(command, "summary") == 0)
        return cmd_summary(rest, rest_argv);
    if (strcmp(command, "keys") == 0) {
        if (wants_help(rest, rest_argv)) {
            fputs(keys_help, stdout);
            return 0;
        }
        bk_config_write_reference(stdout);
        return 0;
    }
    if (strcmp(command, "--version") == 0 || strcmp(command, "version") == 0) {
        printf("bksim %s\n", BKSIM_VERSION);
        return 0;
    }
    if (strcmp(command, "--help") == 0 || strcmp(command, "-h") == 0 || strcmp(command, "help") == 0) {
        fputs(usage_text, stdout);
        return 0;
    }
    fprintf(stderr, "bksim: unknown command '%s'\n\n", command);
    fputs(usage_text, stderr);
    return EXIT_USAGE;
}
