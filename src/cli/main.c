/* bksim command line: a thin client of the library, the only place that calls exit; this
 * file runs and checks configs and dispatches, cli/catalog_commands.c reads outputs
 * (export, stats, compare, summary).
 *
 * Exit status: 0 success, 1 the run or the file failed (or is damaged), 2 bad usage or bad
 * config, 3 (info) an intact file of a run that did not finish. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bksim/bksim.h"
#include "cli/cli.h"

static const char *const usage_text =
    "usage: bksim <command> [options]\n"
    "\n"
    "commands:\n"
    "  run CONFIG [-o OUT] [--set section.key=value]... [--quiet] [--force|--resume]\n"
    "                       simulate the scene CONFIG describes, write HDF5 to OUT\n"
    "                       (default: [output] path)\n"
    "  run --restart OUT.h5[.part] [--set run.t_end=T] [--quiet]\n"
    "                       continue a stopped run from its last checkpoint, or a\n"
    "                       finished or stopped one to a later t_end\n"
    "  check CONFIG [--set section.key=value]... [--strict]\n"
    "                       validate CONFIG without running\n"
    "  info OUT.h5 [--blocks]\n"
    "                       summarise an output file (or a running run's progress)\n"
    "  export OUT.h5 [--datasets a,b,...] [--block I] [--transitions]\n"
    "                       print columns for gnuplot and shell tools\n"
    "  export OUT.h5 --events\n"
    "                       print the event catalog /events as TSV\n"
    "  stats FILE [--table NAME] [--mc auto|VALUE] [--bin DM] [--from T] [--to T] [--bootstrap N]\n"
    "        [--mainshock auto|M] [--window auto|T] [--json] [--tsv DIR]\n"
    "                       earthquake statistics of the rupture catalog /ruptures in FILE\n"
    "                       (else /events; --table events: the time-window catalog)\n"
    "  compare A.h5 B.h5 [--table NAME] [--from T] [--to T] [--round R] [--level L] [--json]\n"
    "                       do two catalogs have the same statistics? KS tests of their\n"
    "                       rupture sizes (log10 potency), magnitudes and n_blocks\n"
    "  summary DIR [--table NAME] [--mc auto|VALUE] [--bin DM] [--from T] [--to T]\n"
    "                       one row per finished run in DIR (a sweep): its --set values\n"
    "                       and headline figures, as DIR/summary.tsv and DIR/summary.h5\n"
    "  fronts FILE [--edge left|right] [--rupture K] [--window W] [--min-blocks N]\n"
    "                       fronts on a chain loaded from one edge: arrest length, edge\n"
    "                       force and speed per rupture (precursors), or one front\n"
    "  keys                 print the config key reference (Markdown)\n"
    "  --version            print the version\n"
    "\n"
    "`bksim <command> --help` describes one command.\n";

static const char *const run_help =
    "usage: bksim run CONFIG [-o OUT] [--set section.key=value]... [--quiet] [--force|--resume]\n"
    "                 [--point NAME] [--strict] [--init-from DONE.h5]\n"
    "       bksim run --restart OUT.h5[.part] [--set run.t_end=T] [--quiet]\n"
    "\n"
    "Runs the scene described by the INI file CONFIG and writes an HDF5 time series.\n"
    "  --restart OUT      continue the stopped run whose output is OUT.part from its last\n"
    "                     checkpoint ([output] checkpoint_interval), with the config stored\n"
    "                     in the file; rows after the checkpoint are recomputed.  With\n"
    "                     --set run.t_end=T (the one --set it takes) a finished or stopped\n"
    "                     run goes on to a later T: OUT becomes OUT.part again, continued\n"
    "                     from its last checkpoint (a finished run's is at its end)\n"
    "  -o, --output OUT   output path (overrides [output] path); OUT ending in / or an\n"
    "                     existing directory means OUT/<config name>.h5.  Only a bksim\n"
    "                     output is ever replaced: any other file there is refused\n"
    "  --set S.K=V        override key K of section S after reading CONFIG; S may be\n"
    "                     block.3 or friction.3 for one block (repeatable)\n"
    "  -q, --quiet        no progress indicator and no summary\n"
    "  --force            start over even when OUT.part holds a checkpoint to restart from\n"
    "                     (without it, run refuses to overwrite that progress)\n"
    "  --resume           continue OUT.part from its checkpoint when it holds one that\n"
    "                     verifies, else start over (a .part whose datasets do not reopen\n"
    "                     at its checkpoint is kept as OUT.part.damaged): what a batch\n"
    "                     script reruns\n"
    "  --point NAME       the sweep grid point this run is, recorded in OUT (attribute point)\n"
    "  --init-from DONE   start where the finished run DONE.h5 ended: its blocks' positions,\n"
    "                     velocities and friction states and its driver's position become\n"
    "                     this run's at t = 0 (same shape and laws; a loading phase, then a\n"
    "                     rupture phase with other keys); recorded in OUT (attribute init_from)\n"
    "  --strict           refuse (exit 2) a config that draws a warning: a value far outside\n"
    "                     what the others make plausible (see `bksim check --help`)\n"
    "The file is written as OUT.part and renamed to OUT when the run completes; a failed\n"
    "or interrupted run leaves OUT.part marked complete = 0.\n"
    "A first SIGTERM, SIGINT or SIGHUP stops the run at its next restart point, written as\n"
    "a checkpoint for --restart (at once when there is none within 20 s); a second stops it\n"
    "at once.\n";

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

static const char *const keys_help =
    "usage: bksim keys\n"
    "\n"
    "Prints every config key (section, unit, default, allowed range, meaning) as Markdown.\n";

static volatile sig_atomic_t stop_requested = 0;
static volatile sig_atomic_t stop_requested_at = 0; /* s on the monotonic clock, at the first signal */

/* A repeated SIGXCPU is the kernel's reminder once a second past the soft CPU limit, not
 * a second request: only SIGINT, SIGTERM and SIGHUP escalate. */
static void on_signal(int signo)
{
    if (stop_requested && signo != SIGXCPU) {
        signal(signo, SIG_DFL); /* both async-signal-safe */
        raise(signo);
        return;
    }
    struct timespec ts; /* clock_gettime is async-signal-safe too */
    if (!stop_requested && clock_gettime(CLOCK_MONOTONIC, &ts) == 0)
        stop_requested_at = (sig_atomic_t)ts.tv_sec;
    stop_requested = 1;
}

/* The first SIGINT, SIGTERM, SIGHUP (terminal gone) or SIGXCPU (a batch system's CPU limit)
 * asks the run to stop at its next restart point, written as a checkpoint (within
 * BK_STOP_GRACE s, else at once; at once without restart points), and leave a valid,
 * incomplete file that --restart continues; a second SIGINT, SIGTERM or SIGHUP (any of
 * them) then stops the process at once. */
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
    /* Past the file-size limit (ulimit -f) a write fails with EFBIG instead of killing the
     * process: the writer stops before that (h5_room.c), and a write that still meets it
     * leaves the .part to be closed and reported like any other failed write. */
    signal(SIGXFSZ, SIG_IGN);
}

/* Options shared by run and check. */
typedef struct config_args {
    const char *config_path;
    const char *restart;
    const char *output;
    const char **overrides;
    size_t n_overrides;
    const char *point;
    const char *init_from;
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
                return bk_cli_usage_error(command, "%s needs section.key=value", a);
            args->overrides[args->n_overrides++] = argv[++i];
        } else if (strncmp(a, "--set=", 6) == 0) {
            args->overrides[args->n_overrides++] = a + 6;
        } else if (allow_output && (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0)) {
            if (i + 1 >= argc)
                return bk_cli_usage_error(command, "%s needs a path", a);
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
                return bk_cli_usage_error(command, "%s needs a name", a);
            args->point = argv[++i];
        } else if (allow_output && strcmp(a, "--init-from") == 0) {
            if (i + 1 >= argc || !argv[i + 1][0])
                return bk_cli_usage_error(command, "%s needs the output file of a finished run", a);
            args->init_from = argv[++i];
        } else if (allow_output && strcmp(a, "--restart") == 0) {
            if (i + 1 >= argc)
                return bk_cli_usage_error(command, "%s needs the output file of the stopped run", a);
            args->restart = argv[++i];
        } else if (a[0] == '-' && a[1] != '\0') {
            return bk_cli_usage_error(command, "unknown option '%s'", a);
        } else if (!args->config_path) {
            args->config_path = a;
        } else {
            return bk_cli_usage_error(command, "unexpected argument '%s'", a);
        }
    }
    if (args->restart) {
        /* One change only: a later end. */
        int longer = args->n_overrides == 1 && strncmp(args->overrides[0], "run.t_end=", 10) == 0;
        if (args->config_path || (args->n_overrides && !longer) || args->output || args->point || args->resume ||
            args->strict || args->init_from)
            return bk_cli_usage_error(command, "%s", "--restart takes no CONFIG, -o, --point, --resume, "
                                              "--init-from or --strict, and no --set but run.t_end=T (a "
                                              "later end): the run continues with the config stored in its file");
        return 0;
    }
    if (args->force && args->resume)
        return bk_cli_usage_error(command, "%s", "--force starts over and --resume continues: give one");
    if (!args->config_path)
        return bk_cli_usage_error(command, "%s", "missing CONFIG");
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
    if (bk_cli_wants_help(argc, argv)) {
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
        /* What the output will weigh, before a long run fills a disk. */
        double rows = 0.0, row_bytes = 0.0, per_second = 0.0, transition_bytes = 0.0;
        bk_config_output_estimate(config, &rows, &row_bytes, &per_second, &transition_bytes);
        char rate[96] = "";
        if (per_second > 0.0)
            snprintf(rate, sizeof rate, ", %.3g B per simulated second", per_second);
        printf("%s: output: about %.3g B of sample rows (%.0f rows of %.0f B%s), plus %.0f B per transition and "
               "the catalog's rows, as many as the run makes; [output] max_bytes = %.3g B bounds the file\n",
               args.config_path, rows * row_bytes, rows, row_bytes, rate, transition_bytes, config->output.max_bytes);
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
    /* SLURM's SIGTERM comes KillWait (30 s by default) before its SIGKILL: on to the next
     * restart point, which is written, so that nothing computed is lost. */
    /* The grace counts from the signal, not from the run's next look at it. */
    if (stop_requested)
        return now_seconds() - (double)stop_requested_at > BK_STOP_GRACE ? BK_PROGRESS_STOP
                                                                         : BK_PROGRESS_CHECKPOINT_AND_STOP;
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

/* Where a run started from (--init-from): the file and the time of its end, said when the
 * run starts there (not when it continues its own .part instead). */
typedef struct start_record {
    const char *path;
    double t;
    int quiet;
} start_record;

/* A new output at path (its .part, written from the start), marked as a sweep's point and
 * with the run it started from when there are. */
static int open_new_output(bk_h5_writer **writer, const bk_config *config, const char *path, const char *point,
                           const start_record *start, bk_error *err)
{
    int opened = bk_h5_writer_open(writer, config, path, err);
    if (opened == BK_OK && ((point && bk_h5_writer_set_point(*writer, point, err) != BK_OK) ||
                            (start->path && bk_h5_writer_set_init_from(*writer, start->path, start->t, err) != BK_OK))) {
        bk_h5_writer_abandon(*writer, err->message, NULL);
        *writer = NULL;
        opened = BK_ERR_IO;
    }
    if (opened == BK_OK && start->path && !start->quiet)
        fprintf(stderr, "bksim: starting from the end of %s (t = %.17g s): its blocks' positions, velocities and "
                        "friction states and its driver's position; %s's [block] x_init, v_init and [driver] "
                        "start_position are not used\n",
                start->path, start->t, config->source_name);
    return opened;
}

/* --init-from: config starts where the finished run in source ended.  0, or an exit status
 * after saying why not. */
static int start_from(bk_config *config, const char *source, start_record *start)
{
    bk_error err = {0};
    bk_checkpoint end;
    bk_config *from = NULL;
    int rc = bk_h5_read_end_state(source, &end, &from, &err);
    if (rc == BK_OK) {
        rc = bk_config_start_from(config, from, &end, &err);
        if (rc == BK_OK) {
            start->path = source;
            start->t = end.t;
        }
        bk_checkpoint_free(&end);
        bk_config_free(from);
    }
    if (rc == BK_OK)
        return 0;
    fprintf(stderr, "bksim run --init-from %s: %s\n", source, err.message);
    return rc == BK_ERR_INVALID || rc == BK_ERR_CONFIG ? EXIT_USAGE : EXIT_RUN_FAILED;
}

/* --restart OUT --set run.t_end=T: the run made longer first. */
static int extend_run(const char *path, const char *setting, int quiet, bk_error *err)
{
    const char *value = setting + strlen("run.t_end=");
    char *end = NULL;
    double t_end = strtod(value, &end);
    if (end == value || *end || !isfinite(t_end))
        return BK_FAIL(err, BK_ERR_INVALID, "--set %s: [run] t_end: not a number", setting);
    double before = 0.0;
    int rc = bk_h5_extend_to(path, t_end, &before, err);
    if (rc == BK_OK && !quiet)
        fprintf(stderr, "bksim: %s: t_end %.17g s -> %.17g s\n", path, before, t_end);
    return rc;
}

/* After a run stopped short: how to go on from OUT.part, from its last checkpoint, or (none)
 * only by starting over; a stop at [output] max_bytes says that a restart keeps it. */
static void say_how_to_go_on(const bk_config *config, const char *path, int rc)
{
    double t_checkpoint = 0.0;
    bk_error ignored = {0};
    fprintf(stderr, "bksim: partial output left in %s.part (complete = 0); ", path);
    if (rc == BK_ERR_LIMIT)
        fprintf(stderr, "a --restart keeps the stored [output] max_bytes = %.3g B and would stop again: run it "
                        "again with a larger one (or fewer fields, or a longer interval)\n",
                config->output.max_bytes);
    else if (bk_h5_restartable(path, &t_checkpoint, &ignored) == 1)
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
    /* -o DIR/ (or an existing directory) puts the output in it, named after the config. */
    char *resolved_path = NULL;
    const char *given_path = args.output ? args.output : config ? config->output.path : NULL;
    if (given_path && !args.restart && !(resolved_path = bk_output_resolve(given_path, config ? config->source_name : NULL))) {
        fprintf(stderr, "bksim: out of memory\n");
        bk_config_free(config);
        free(args.overrides);
        return EXIT_RUN_FAILED;
    }
    const char *path = resolved_path ? resolved_path : given_path;
    char *restart_path = NULL;
    int opened;
    start_record start = {NULL, 0.0, args.quiet};
    if (args.init_from && (status = start_from(config, args.init_from, &start)) != 0) {
        bk_config_free(config);
        free(resolved_path);
        free(args.overrides);
        return status;
    }
    if (args.restart) {
        /* Refused before the .part is touched: a later t_end is written into it. */
        char *final = bk_output_final_path(args.restart);
        opened = final ? bk_h5_output_replaceable(final, 0, &err) : BK_FAIL(&err, BK_ERR_NOMEM, "bksim: out of memory");
        free(final);
        if (opened == BK_OK && args.n_overrides)
            opened = extend_run(args.restart, args.overrides[0], args.quiet, &err);
        if (opened == BK_OK)
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
            free(resolved_path);
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
            if (opened == BK_ERR_DAMAGED || opened == BK_ERR_HDF5) {
                /* A kill inside one of HDF5's flushes can leave a .part whose checkpoint
                 * verifies but whose datasets no longer reopen at it (a chunk index half
                 * written).  --resume continues what can be continued and runs the rest:
                 * the .part is kept aside, never replaced, and the run starts over. */
                char *part = bk_output_part_path(path), *kept = NULL;
                bk_error moved = {0};
                if (!part || bk_output_set_aside(part, &kept, &moved) != BK_OK) {
                    fprintf(stderr, "%s\n", err.message);
                    err = moved;
                } else {
                    fprintf(stderr, "bksim: starting over: %s cannot be continued (%s); it is kept as %s\n",
                            part, err.message, kept);
                    config = given;
                    given = NULL;
                    free(restart_path);
                    restart_path = NULL;
                    opened = open_new_output(&writer, config, path, args.point, &start, &err);
                }
                free(part);
                free(kept);
            }
            bk_config_free(given);
            if (restart_path)
                path = args.restart = restart_path; /* from here on, a restarted run */
            if (!args.quiet && opened == BK_OK && args.restart)
                fprintf(stderr, "bksim: continuing %s.part from its checkpoint t = %.17g s\n", path,
                        t_checkpoint);
        } else if (restartable == 1) {
            fprintf(stderr,
                    "%s.part holds a run stopped at its checkpoint t = %.17g s: continue it with "
                    "`bksim run --restart %s.part`, or pass --force to start over\n",
                    path, t_checkpoint, path);
            bk_config_free(config);
            free(resolved_path);
            free(args.overrides);
            return EXIT_USAGE;
        } else {
            /* Never silently: a stopped run's .part without a checkpoint is replaced. */
            char *part = bk_output_part_path(path);
            struct stat st;
            int replaced = part && stat(part, &st) == 0;
            opened = open_new_output(&writer, config, path, args.point, &start, &err);
            /* Said once it is true: a .part another run writes, or a file not bksim's, is
             * refused instead. */
            if (replaced && opened == BK_OK && !args.quiet)
                fprintf(stderr, "bksim: starting over: %s is replaced (%s)\n", part,
                        args.force ? "--force" : "it holds no checkpoint to continue from");
            free(part);
        }
    }
    if (opened != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        bk_config_free(config);
        free(args.overrides);
        free(restart_path);
        free(resolved_path);
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
        say_how_to_go_on(config, path, rc);
        status = EXIT_RUN_FAILED;
    } else if ((rc = bk_h5_writer_finish(writer, &stats, &err)) != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        struct stat st;
        char *part = bk_output_part_path(path);
        if (part && stat(part, &st) == 0) {
            if (rc == BK_ERR_INVALID) /* its name was taken meanwhile */
                fprintf(stderr, "bksim: the finished run is kept in %s: move %s away, then `bksim run --restart %s` "
                                "publishes it from its end\n", part, path, part);
            else
                say_how_to_go_on(config, path, rc);
        }
        free(part);
        status = EXIT_RUN_FAILED;
    } else if (!args.quiet) {
        printf("%s: %ld rows, %ld transitions, t = %g s, %ld steps, %ld RHS evaluations, "
               "energy residual %.2g, %.3f s CPU\n",
               path, stats.rows, stats.transitions, stats.t_reached, stats.steps, stats.rhs_evals,
               stats.energy_residual, stats.cpu_time);
        if (stats.segments > 0)
            printf("%s: local time stepping in %ld segments; largest coupling error %.3g of the "
                   "tolerance (%ld above it)\n",
                   path, stats.segments, stats.coupling_error, stats.coupling_exceedances);
    }
    bk_config_free(config);
    free(args.overrides);
    free(restart_path);
    free(resolved_path);
    return status;
}

static int cmd_info(int argc, char **argv)
{
    if (bk_cli_wants_help(argc, argv)) {
        fputs(info_help, stdout);
        return 0;
    }
    const char *path = NULL;
    int per_block = 0;
    for (int i = 0; i < argc; ++i) {
        if (strcmp(argv[i], "--blocks") == 0)
            per_block = 1;
        else if (argv[i][0] == '-')
            return bk_cli_usage_error("info", "unknown option '%s'", argv[i]);
        else if (path)
            return bk_cli_usage_error("info", "%s", "expects exactly one file");
        else
            path = argv[i];
    }
    if (!path)
        return bk_cli_usage_error("info", "%s", "missing OUT.h5");
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
        return bk_cli_export(rest, rest_argv);
    if (strcmp(command, "stats") == 0)
        return bk_cli_stats(rest, rest_argv);
    if (strcmp(command, "compare") == 0)
        return bk_cli_compare(rest, rest_argv);
    if (strcmp(command, "summary") == 0)
        return bk_cli_summary(rest, rest_argv);
    if (strcmp(command, "fronts") == 0)
        return bk_cli_fronts(rest, rest_argv);
    if (strcmp(command, "keys") == 0) {
        if (bk_cli_wants_help(rest, rest_argv)) {
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
