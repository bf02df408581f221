/* bksim fronts: the precursor table of a chain loaded from one edge, and one rupture's front
 * block by block (bksim/fronts.h), from a run's rupture catalog. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "bksim/fronts.h"
#include "cli/cli.h"

static const char *const fronts_help =
    "usage: bksim fronts FILE [--edge left|right] [--rupture K] [--window W] [--min-blocks N]\n"
    "\n"
    "Fronts on a chain loaded from one edge, from FILE's rupture catalog (/ruptures,\n"
    "/rupture_blocks; /transitions for the edge force).  Prints one tab-separated row per\n"
    "rupture in order of its start: rupture (row of /ruptures), t_start [s], edge_force [N]\n"
    "(the loaded edge block's driver-spring plus applied force as the rupture began: the\n"
    "shear load of Rubinstein et al.'s precursor plots; nan when the edge block was slipping\n"
    "then, or /transitions is not kept), first_block, n_blocks, arrest_length [blocks] (from\n"
    "the loaded edge to the farthest block reached, both counted), from_edge (it began at the\n"
    "edge block), crossed (it reached the far edge), mean_speed [blocks/s] (least-squares,\n"
    "distance from the edge against arrival time; nan with fewer than 3 blocks, inf when all\n"
    "arrive at once) and duration [s].\n"
    "  --edge left|right  the loaded edge: block 0 (left, the default) or the last block\n"
    "  --rupture K        instead, rupture K's front block by block: block, distance from\n"
    "                     the edge [blocks], t_onset [s] (the front's arrival), t_stop [s],\n"
    "                     slip [m] and the local front speed [blocks/s] (least-squares over\n"
    "                     the blocks within W/2)\n"
    "  --window W         blocks in a local speed fit, W >= 2 (default 8)\n"
    "  --min-blocks N     only ruptures of at least N blocks (default 1)\n";

typedef struct fronts_args {
    const char *path;
    int edge_right;
    long rupture;
    size_t window, min_blocks;
} fronts_args;

static int parse_size(const char *option, const char *text, size_t min, size_t *out)
{
    char *end = NULL;
    errno = 0;
    long long v = strtoll(text, &end, 10);
    if (end == text || *end || errno || v < (long long)min)
        return bk_cli_usage_error("fronts", "%s %s: not a whole number >= %zu", option, text, min);
    *out = (size_t)v;
    return 0;
}

static int parse_fronts_args(int argc, char **argv, fronts_args *a)
{
    *a = (fronts_args){NULL, 0, -1, 8, 1};
    for (int i = 0; i < argc; ++i) {
        const char *o = argv[i];
        int takes = strcmp(o, "--edge") == 0 || strcmp(o, "--rupture") == 0 || strcmp(o, "--window") == 0 ||
                    strcmp(o, "--min-blocks") == 0;
        if (takes && i + 1 >= argc)
            return bk_cli_usage_error("fronts", "%s needs a value", o);
        int rc = 0;
        if (strcmp(o, "--edge") == 0) {
            const char *v = argv[++i];
            if (strcmp(v, "left") != 0 && strcmp(v, "right") != 0)
                return bk_cli_usage_error("fronts", "--edge %s: allowed: left, right", v);
            a->edge_right = strcmp(v, "right") == 0;
        } else if (strcmp(o, "--rupture") == 0) {
            size_t k = 0;
            rc = parse_size(o, argv[++i], 0, &k);
            a->rupture = (long)k;
        } else if (strcmp(o, "--window") == 0) {
            rc = parse_size(o, argv[++i], 2, &a->window);
        } else if (strcmp(o, "--min-blocks") == 0) {
            rc = parse_size(o, argv[++i], 1, &a->min_blocks);
        } else if (o[0] == '-') {
            return bk_cli_usage_error("fronts", "unknown option '%s'", o);
        } else if (a->path) {
            return bk_cli_usage_error("fronts", "%s", "expects exactly one file");
        } else {
            a->path = o;
        }
        if (rc != 0)
            return rc;
    }
    if (!a->path)
        return bk_cli_usage_error("fronts", "%s", "missing FILE");
    return 0;
}

static int print_profile(const fronts_args *a, const bk_rupture_block *rows, size_t n_rows, size_t n_ruptures,
                         size_t n_blocks, bk_error *err)
{
    if ((size_t)a->rupture >= n_ruptures) {
        fprintf(stderr, "bksim fronts: %s: --rupture %ld: it holds %zu ruptures (allowed: 0 .. %zu)\n", a->path,
                a->rupture, n_ruptures, n_ruptures ? n_ruptures - 1 : 0);
        return EXIT_USAGE;
    }
    size_t first = 0;
    while (first < n_rows && rows[first].rupture != a->rupture)
        ++first;
    size_t count = 0;
    while (first + count < n_rows && rows[first + count].rupture == a->rupture)
        ++count;
    double *distance = malloc((count ? count : 1) * sizeof *distance);
    double *speed = malloc((count ? count : 1) * sizeof *speed);
    int rc = !distance || !speed ? BK_FAIL(err, BK_ERR_NOMEM, "out of memory")
                                 : bk_front_profile(rows + first, count, n_blocks, a->edge_right, a->window,
                                                    distance, speed, err);
    if (rc == BK_OK) {
        printf("# rupture %ld of %s, loaded edge %s, local speed over %zu blocks\n", a->rupture, a->path,
               a->edge_right ? "right" : "left", a->window);
        printf("# block[1]\tdistance[blocks]\tt_onset[s]\tt_stop[s]\tslip[m]\tspeed[blocks/s]\n");
        for (size_t k = 0; k < count; ++k) {
            const bk_rupture_block *b = &rows[first + k];
            printf("%d\t%.0f\t%.17g\t%.17g\t%.17g\t%.17g\n", (int)b->block, distance[k], b->t_onset, b->t_stop,
                   b->slip, speed[k]);
        }
    }
    free(distance);
    free(speed);
    if (rc != BK_OK)
        fprintf(stderr, "bksim fronts: %s\n", err->message);
    return rc == BK_OK ? 0 : EXIT_RUN_FAILED;
}

static int by_start(const void *a, const void *b)
{
    const bk_front *x = a, *y = b;
    return x->t_start < y->t_start ? -1 : x->t_start > y->t_start ? 1 : (x->rupture > y->rupture) - (x->rupture < y->rupture);
}

int bk_cli_fronts(int argc, char **argv)
{
    if (bk_cli_wants_help(argc, argv)) {
        fputs(fronts_help, stdout);
        return 0;
    }
    fronts_args a;
    int status = parse_fronts_args(argc, argv, &a);
    if (status != 0)
        return status;
    bk_error err = {0};
    bk_config *config = NULL;
    bk_rupture *ruptures = NULL;
    bk_rupture_block *rows = NULL;
    bk_transition *transitions = NULL;
    size_t n_ruptures = 0, n_rows = 0, n_transitions = 0;
    double *edge_force = NULL;
    bk_front *fronts = NULL;
    int rc = bk_h5_read_config(a.path, &config, &err);
    if (rc == BK_OK && (config->prescribed || config->model->rows != 1))
        rc = BK_FAIL(&err, BK_ERR_INVALID, "%s: fronts are measured along a chain (one row of blocks); this is %s",
                     a.path, config->prescribed ? "a prescribed-motion scene" : "a lattice");
    if (rc == BK_OK)
        rc = bk_h5_read_ruptures(a.path, &ruptures, &n_ruptures, &err);
    if (rc == BK_OK)
        rc = bk_h5_read_rupture_blocks(a.path, &rows, &n_rows, &err);
    size_t n_blocks = rc == BK_OK ? config->model->n_blocks : 0;
    if (rc == BK_OK && a.rupture >= 0) {
        status = print_profile(&a, rows, n_rows, n_ruptures, n_blocks, &err);
        goto done;
    }
    if (rc == BK_OK) {
        edge_force = malloc((n_ruptures ? n_ruptures : 1) * sizeof *edge_force);
        fronts = malloc((n_ruptures ? n_ruptures : 1) * sizeof *fronts);
        if (!edge_force || !fronts)
            rc = BK_FAIL(&err, BK_ERR_NOMEM, "out of memory for %zu ruptures", n_ruptures);
    }
    /* Without /transitions the edge force is not known: the table says nan. */
    int have_transitions = rc == BK_OK && bk_h5_read_transitions(a.path, &transitions, &n_transitions, &err) == BK_OK;
    if (rc == BK_OK && have_transitions)
        rc = bk_fronts_edge_force(config->model, transitions, n_transitions, ruptures, n_ruptures, a.edge_right,
                                  edge_force, &err);
    if (rc == BK_OK)
        rc = bk_fronts(ruptures, n_ruptures, rows, n_rows, n_blocks, a.edge_right, have_transitions ? edge_force : NULL,
                       fronts, &err);
    if (rc == BK_OK) {
        qsort(fronts, n_ruptures, sizeof *fronts, by_start);
        printf("# fronts of %s (%zu blocks), loaded edge %s%s\n", a.path, n_blocks, a.edge_right ? "right" : "left",
               have_transitions ? "" : "; no /transitions, so no edge force");
        printf("# rupture[1]\tt_start[s]\tedge_force[N]\tfirst_block[1]\tn_blocks[1]\tarrest_length[blocks]\t"
               "from_edge[1]\tcrossed[1]\tmean_speed[blocks/s]\tduration[s]\n");
        for (size_t k = 0; k < n_ruptures; ++k) {
            const bk_front *f = &fronts[k];
            if ((size_t)f->n_blocks < a.min_blocks)
                continue;
            printf("%lld\t%.17g\t%.17g\t%d\t%d\t%d\t%d\t%d\t%.17g\t%.17g\n", (long long)f->rupture, f->t_start,
                   f->edge_force, (int)f->first_block, (int)f->n_blocks, (int)f->arrest_length, (int)f->from_edge,
                   (int)f->crossed, f->mean_speed, f->duration);
        }
    }
    status = rc == BK_OK ? 0 : rc == BK_ERR_INVALID ? EXIT_USAGE : EXIT_RUN_FAILED;
done:
    if (rc != BK_OK)
        fprintf(stderr, "bksim fronts: %s\n", err.message);
    free(fronts);
    free(edge_force);
    free(transitions);
    free(rows);
    free(ruptures);
    bk_config_free(config);
    return status;
}
