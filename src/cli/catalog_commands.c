/* The commands that read a run's output, for the bksim command line (cli/main.c dispatches):
 * export (time series and tables as text), stats (a catalog's statistics), compare (two
 * catalogs' distributions) and summary (a sweep's table). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "bksim/stats_compare.h"
#include "cli/cli.h"

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
    "                        [--bootstrap N] [--mainshock auto|M] [--window auto|T] [--json] [--tsv DIR]\n"
    "\n"
    "Statistics of an earthquake catalog in the HDF5 file FILE (a table with at least\n"
    "t_start and magnitude): magnitude-frequency distribution, completeness magnitude Mc,\n"
    "b-value (Aki-Utsu maximum likelihood, Shi & Bolt error) and its fit test, the GR law on\n"
    "the largest range [Mc, Mu] it fits (a size cutoff), b-positive, Mc by b-stability and\n"
    "by the KS method, potency exponent, event sizes, recurrence intervals, interevent times\n"
    "rescaled by the rate (Corral 2004), aftershock and foreshock sequences of mainshocks\n"
    "fitted by the Omori-Utsu law (Ogata 1983) with a residual check, potency against\n"
    "duration and length, and a KS test of the two halves of the run.  Events still\n"
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
    "  --bootstrap N     synthetic samples of the goodness-of-fit tests and resamples of the\n"
    "                    bootstrap errors (default 1000, seeded: reproducible); 0 skips both\n"
    "                    and reports the fits untested.  A fit the test rejects (p < 0.01)\n"
    "                    gives no b-value or exponent, and the report says why.  Fewer than\n"
    "                    10 events at or above Mc, or all in one bin, give no b-value either;\n"
    "                    fewer than 50 carry a small-sample warning.  The truncated GR\n"
    "                    range scan needs N >= 200\n"
    "  --mainshock auto|M  mainshocks: events of magnitude >= M (its bin) that are the\n"
    "                    largest within +-window (auto, the default: Mc + 2)\n"
    "  --window auto|T   the sequences' window, T > 0 s after (and before) each mainshock\n"
    "                    (auto, the default: the span over the number of events >= M)\n"
    "  --json            print one JSON object instead of the text report\n"
    "  --tsv DIR         also write tables for gnuplot to DIR (created if missing): mfd.tsv,\n"
    "                    gr_fit.tsv, gr_truncated_fit.tsv, sizes.tsv, sizes_log2.tsv,\n"
    "                    intervals.tsv, interevent.tsv, omori.tsv, omori_residuals.tsv,\n"
    "                    scaling_duration.tsv, scaling_length.tsv, potency_ccdf.tsv\n";

static const char *const compare_help =
    "usage: bksim compare A.h5 B.h5 [--table NAME] [--from T] [--to T] [--round R] [--level L]\n"
    "                               [--json]\n"
    "\n"
    "Do two catalogs (runs at another tolerance, back-end, seed or parameter) have the same\n"
    "statistics?  A chain is chaotic: two runs that differ at all part ways, so their\n"
    "catalogs differ event by event; their distributions are compared.  Two-sample\n"
    "Kolmogorov-Smirnov tests of log10 potency (the rupture-size distribution), of magnitude\n"
    "and of n_blocks (where both catalogs have the field) between the complete events of A\n"
    "and B, with their counts, spans and rates, and a verdict: told apart at the level when\n"
    "the potency test's p-value is below it (the magnitude test's for a catalog without\n"
    "potencies).  Two seeds of one scene show what no difference looks like.  The test takes\n"
    "events as independent; a chain's are not (large ruptures come in cycles), so a lone p\n"
    "near the level says little: repeat with other seeds (--set model.seed=N).  Exit status 0\n"
    "whatever the verdict; 1 when a file is no catalog (or has no event in the window).\n"
    "  --table NAME      the catalog table of both files, as for `bksim stats` (default\n"
    "                    /ruptures, else /events)\n"
    "  --from T, --to T  only events starting at t >= T, t < T (s): leave a spin-up out\n"
    "  --round R         round log10 potency and magnitude to multiples of R before the\n"
    "                    tests, 0 <= R <= 1 (default 1e-4; 0: as stored).  A chain's many\n"
    "                    one-block ruptures share one potency up to the integrator's error;\n"
    "                    unrounded, two tolerances would be told apart by that error alone.\n"
    "                    Ties are handled exactly; with them p is conservative\n"
    "  --level L         the verdict's level, 0 < L < 1 (default 0.01, the 1 % level)\n"
    "  --json            print one JSON object instead of the text\n";

static const char *const summary_help =
    "usage: bksim summary DIR [--table NAME] [--mc auto|VALUE] [--bin DM] [--from T] [--to T]\n"
    "                         [--bootstrap N]\n"
    "\n"
    "One row per finished run (complete *.h5 whose datasets verify) in DIR, in the grid's\n"
    "order (by the --set keys as the runs give them, numbers as numbers, then by file name):\n"
    "file, point (the sweep's grid point), a column per --set key of the runs (named by the\n"
    "key: the run's value), then events, mean_recurrence (s), largest_magnitude,\n"
    "largest_event_blocks, peak_slip_rate (m/s), b_value, b_error, mc, b_events (as `bksim\n"
    "stats` gives them), energy_residual, steps, rhs_evals, transitions, t_reached,\n"
    "wall_time, cpu_time (s), seed, method, host, catalog; nan where a run has none.  The\n"
    "catalog figures (events to b_events) count the rows of the run's /ruptures (else\n"
    "/events, as `bksim stats`), and catalog names the table.  Written to DIR/summary.tsv (a\n"
    "'#' line of units, a header line, tab-separated rows: scripts/plot_summary.sh draws any\n"
    "column against any other) and DIR/summary.h5 (compound dataset /summary).  Runs that did\n"
    "not finish (*.h5.part) are not summarised; other files left out (a damaged one, an HDF5\n"
    "file of another program) are named on stderr.\n"
    "  --table NAME                as for `bksim stats` (events: the time-window catalog);\n"
    "                              a run without that table is left out\n"
    "  --mc, --bin, --from, --to, --bootstrap   as for `bksim stats`: the catalog figures use them\n";

int bk_cli_export(int argc, char **argv)
{
    if (bk_cli_wants_help(argc, argv)) {
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
                return bk_cli_usage_error("export", "--block needs a block index >= 0, got '%s'", text);
        } else if (strcmp(a, "--transitions") == 0) {
            transitions = 1;
        } else if (strcmp(a, "--events") == 0) {
            events = 1;
        } else if (strcmp(a, "--table") == 0 && i + 1 < argc) {
            table = argv[++i];
        } else if (strncmp(a, "--table=", 8) == 0) {
            table = a + 8;
        } else if (a[0] == '-') {
            return bk_cli_usage_error("export", "unknown or incomplete option '%s'", a);
        } else if (!path) {
            path = a;
        } else {
            return bk_cli_usage_error("export", "unexpected argument '%s'", a);
        }
    }
    if (!path)
        return bk_cli_usage_error("export", "%s", "missing OUT.h5");
    if (events && (datasets || block >= 0 || transitions))
        return bk_cli_usage_error("export", "%s", "--events prints the whole catalog: it takes none "
                                           "of --datasets, --block, --transitions");
    if (table && (datasets || block >= 0 || transitions || events))
        return bk_cli_usage_error("export", "%s", "--table prints one whole table: it takes none of --datasets, "
                                           "--block, --transitions, --events");
    if (table && !*table)
        return bk_cli_usage_error("export", "%s", "--table needs a table name (ruptures, rupture_blocks, rupture_rate, "
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

/* The catalog options of stats and summary (--mc, --bin, --from, --to, --bootstrap, and for
 * stats --mainshock and --window, into opt; --table into *table) at argv[*i]: -1 when argv[*i]
 * is none of them, 0 when taken (*i advanced past a separate value), else the exit status of
 * a usage error.  Ranges (finite, a bin centre, ...)
 * are bk_stats_options_check's. */
static int parse_catalog_option(const char *command, int argc, char **argv, int *i,
                                bk_stats_options *opt, const char **table)
{
    static const char *const names[] = {"--mc", "--bin", "--from", "--to", "--table", "--bootstrap", "--mainshock",
                                        "--window"};
    const char *a = argv[*i], *value = NULL;
    /* The mainshock sequences are the report's alone: summary has no column for them. */
    size_t which = 0, n_names = strcmp(command, "stats") == 0 ? 8 : 6;
    for (; which < n_names; ++which) {
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
            return bk_cli_usage_error(command, "%s", "--table needs a table name: ruptures, events, or "
                                              "another table with t_start and magnitude");
        *table = value;
    } else if (which == 0) {
        opt->mc_auto = strcmp(value, "auto") == 0;
        if (!opt->mc_auto) {
            opt->mc = strtod(value, &end);
            if (errno || end == value || *end)
                return bk_cli_usage_error(command, "--mc needs 'auto' or a magnitude, got '%s'", value);
        }
    } else if (which == 1) {
        opt->dm = strtod(value, &end);
        if (errno || end == value || *end)
            return bk_cli_usage_error(command, "--bin needs a bin width 0 < DM <= 10, got '%s'", value);
    } else if (which == 6 || which == 7) {
        int automatic = strcmp(value, "auto") == 0;
        double x = automatic ? 0.0 : strtod(value, &end);
        if (!automatic && (errno || end == value || *end || !isfinite(x) || (which == 7 && !(x > 0.0))))
            return bk_cli_usage_error(command, "%s needs 'auto' or %s, got '%s'", names[which],
                                      which == 6 ? "a magnitude" : "a time > 0 in s", value);
        if (which == 6) {
            opt->mainshock_auto = automatic;
            opt->mainshock = x;
        } else {
            opt->window = x; /* 0: auto */
        }
    } else if (which == 5) {
        unsigned long long count = value[0] == '-' ? 0 : strtoull(value, &end, 10);
        if (value[0] == '-' || errno || end == value || *end || count > BK_BOOTSTRAP_MAX)
            return bk_cli_usage_error(command, "--bootstrap needs a whole number of samples 0 .. %d, got '%s'",
                                      BK_BOOTSTRAP_MAX, value);
        opt->bootstrap = (size_t)count;
    } else {
        double t = strtod(value, &end);
        if (errno || end == value || *end || !isfinite(t))
            return bk_cli_usage_error(command, "%s needs a time in s, got '%s'", names[which], value);
        *(which == 2 ? &opt->t_from : &opt->t_to) = t;
    }
    return 0;
}

int bk_cli_stats(int argc, char **argv)
{
    if (bk_cli_wants_help(argc, argv)) {
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
            return bk_cli_usage_error("stats", "unknown or incomplete option '%s'", a);
        } else if (!path) {
            path = a;
        } else {
            return bk_cli_usage_error("stats", "unexpected argument '%s'", a);
        }
    }
    if (!path)
        return bk_cli_usage_error("stats", "%s", "missing FILE");
    bk_error err = {0};
    if (bk_stats_options_check(&opt, &err) != BK_OK)
        return bk_cli_usage_error("stats", "%s", err.message);
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

/* A number for option `name` of compare into *value; else the exit status of a usage error. */
static int parse_number(const char *name, const char *text, const char *what, double *value)
{
    char *end = NULL;
    errno = 0;
    double x = strtod(text, &end);
    if (errno || end == text || *end || !isfinite(x))
        return bk_cli_usage_error("compare", "%s needs %s, got '%s'", name, what, text);
    *value = x;
    return 0;
}

int bk_cli_compare(int argc, char **argv)
{
    if (bk_cli_wants_help(argc, argv)) {
        fputs(compare_help, stdout);
        return 0;
    }
    bk_compare_options opt;
    bk_compare_options_default(&opt);
    const char *path[2] = {NULL, NULL}, *table = NULL;
    int json = 0;
    static const char *const names[] = {"--table", "--from", "--to", "--round", "--level"};
    static const char *const what[] = {"", "a time in s", "a time in s", "a rounding 0 <= R <= 1",
                                       "a level 0 < L < 1"};
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i], *value = NULL;
        size_t which = 0;
        for (; which < 5; ++which) {
            size_t len = strlen(names[which]);
            if (strcmp(a, names[which]) == 0 && i + 1 < argc) {
                value = argv[++i];
                break;
            }
            if (strncmp(a, names[which], len) == 0 && a[len] == '=') {
                value = a + len + 1;
                break;
            }
        }
        if (value) {
            int status = 0;
            if (which == 0) {
                if (!*value || strcmp(value, "/") == 0)
                    return bk_cli_usage_error("compare", "%s", "--table needs a table name: ruptures, events, or "
                                                                 "another table with t_start and magnitude");
                table = value;
            } else {
                double *target[] = {NULL, &opt.t_from, &opt.t_to, &opt.round, &opt.level};
                status = parse_number(names[which], value, what[which], target[which]);
            }
            if (status)
                return status;
        } else if (strcmp(a, "--json") == 0) {
            json = 1;
        } else if (a[0] == '-') {
            return bk_cli_usage_error("compare", "unknown or incomplete option '%s'", a);
        } else if (!path[0]) {
            path[0] = a;
        } else if (!path[1]) {
            path[1] = a;
        } else {
            return bk_cli_usage_error("compare", "unexpected argument '%s': give two catalogs, A and B", a);
        }
    }
    if (!path[1])
        return bk_cli_usage_error("compare", "%s", path[0] ? "missing B.h5: give two catalogs, A and B"
                                                           : "missing A.h5 and B.h5");
    bk_error err = {0};
    if (bk_compare_options_check(&opt, &err) != BK_OK)
        return bk_cli_usage_error("compare", "%s", err.message);
    bk_event_table tables[2];
    memset(tables, 0, sizeof tables);
    bk_compare_result result;
    memset(&result, 0, sizeof result);
    int rc = bk_h5_read_event_table(path[0], table, &tables[0], &err);
    if (rc == BK_OK)
        rc = bk_h5_read_event_table(path[1], table, &tables[1], &err);
    if (rc == BK_OK)
        rc = bk_compare_tables(&tables[0], path[0], &tables[1], path[1], &opt, &result, &err);
    bk_event_table_free(&tables[0]);
    bk_event_table_free(&tables[1]);
    if (rc == BK_OK)
        rc = json ? bk_compare_json(&result, stdout, &err) : bk_compare_text(&result, stdout, &err);
    bk_compare_free(&result);
    if (rc != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return EXIT_RUN_FAILED;
    }
    return 0;
}

int bk_cli_summary(int argc, char **argv)
{
    if (bk_cli_wants_help(argc, argv)) {
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
            return bk_cli_usage_error("summary", "unknown or incomplete option '%s'", argv[i]);
        if (dir)
            return bk_cli_usage_error("summary", "unexpected argument '%s'", argv[i]);
        dir = argv[i];
    }
    if (!dir)
        return bk_cli_usage_error("summary", "%s", "missing DIR");
    bk_error err = {0};
    if (bk_stats_options_check(&opt, &err) != BK_OK)
        return bk_cli_usage_error("summary", "%s", err.message);
    size_t runs = 0;
    if (bk_h5_summary(dir, table, &opt, stderr, &runs, &err) != BK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return EXIT_RUN_FAILED;
    }
    printf("%s/summary.tsv, %s/summary.h5: %zu run%s\n", dir, dir, runs, runs == 1 ? "" : "s");
    return 0;
}

