/* Work-precision benchmark: every solver back-end on the paper's cases (Coulomb and
 * rate-and-state, plus a stiff rate-and-state variant) and on Coulomb chains (one of them
 * damped), over a sweep
 * of rtol, timed in-process (median CPU of repeated runs), with its error against a
 * reference: the exact stepper for Coulomb; for rate-and-state an integrator one decade
 * tighter than the sweep (rtol 1e-13), whose own uncertainty is measured against other
 * methods and families and written as rows (reference_vs_*) -- errors below it are not
 * resolved.
 *
 *   events      "same" when the run's transitions are the reference's (block, from, to, in
 *               order), else "differ": the run lost or invented stick-slip events
 *   matched     transitions that agree with the reference's before the first difference
 *   error_x     max |x - x_ref| over the regular samples and blocks, m
 *   error_t     max |t - t_ref| over the matched transitions, s
 *   energy      |energy residual|, the run's own balance (driver work = elastic + kinetic
 *               + dissipation), relative to the largest term (the driver work in a run
 *               that starts relaxed)
 *
 * Modes: the sweep (default) and --long-run (phase drift over 1e4 stick-slip cycles).
 * Output: TSV on stdout (or --out FILE); `scripts/bench.sh` drives both, the CLI runs of
 * scripts/bench_scaling.sh (cost and memory against chain length), and plots.  Not part of CI (a --quick smoke
 * run is). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bksim/bksim.h"

typedef struct event {
    double t;
    long block;
    int from, to;
} event;

typedef struct run_record {
    size_t n_blocks;
    double *x; /* regular samples only: rows x n_blocks */
    size_t rows, cap;
    event *events;
    size_t n_events, cap_events;
} run_record;

static int keep_sample(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    run_record *r = self;
    if (s->is_event)
        return BK_OK;
    if (r->rows == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 256;
        double *grown = realloc(r->x, r->cap * r->n_blocks * sizeof *grown);
        if (!grown)
            return BK_ERR_NOMEM;
        r->x = grown;
    }
    memcpy(r->x + r->rows * r->n_blocks, s->x, r->n_blocks * sizeof *s->x);
    r->rows++;
    return BK_OK;
}

static int keep_transition(void *self, const bk_transition *t, bk_error *err)
{
    (void)err;
    run_record *r = self;
    if (r->n_events == r->cap_events) {
        r->cap_events = r->cap_events ? 2 * r->cap_events : 256;
        event *grown = realloc(r->events, r->cap_events * sizeof *grown);
        if (!grown)
            return BK_ERR_NOMEM;
        r->events = grown;
    }
    r->events[r->n_events++] = (event){t->t, (long)t->block, t->from, t->to};
    return BK_OK;
}

static void record_free(run_record *r)
{
    free(r->x);
    free(r->events);
    memset(r, 0, sizeof *r);
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct check {
    const char *method;
    double rtol;
} check;

typedef struct bench_case {
    const char *name;
    const char *config;
    const char *extra; /* one more --set override, or NULL */
    double t_end, interval;
    check reference;   /* exact, or an integrator at rtol 1e-13 */
    check checks[3];   /* the reference's uncertainty: other runs against it */
    const char *const *methods; /* the methods swept (NULL: every back-end) */
    double loosest;    /* the loosest rtol swept (0: the sweep's own, 1e-3) */
} bench_case;

/* A method of the sweep: a back-end's name, or "cvode_bdf+segments", cvode_bdf with local
 * time stepping in segments of 8 blocks. */
#define SEGMENTS_SUFFIX "+segments"

typedef struct outcome {
    int status;
    double cpu, cpu_min, cpu_max;
    int repeats;
    bk_run_stats stats;
    run_record record;
    char message[BK_ERROR_MESSAGE_LEN];
} outcome;

#define MAX_REPEATS 25
#define MIN_TOTAL_CPU 0.3 /* s: short runs repeat until they add up to this */

/* Load the case with method and rtol and run it at least min_repeats times (short runs
 * more, up to MAX_REPEATS, until MIN_TOTAL_CPU); keep the last record, the median CPU. */
static outcome run_case(const bench_case *bc, const char *method, double rtol, int min_repeats, double wall_limit)
{
    outcome o;
    memset(&o, 0, sizeof o);
    char set_method[64], set_rtol[64], set_t_end[64], set_interval[64], set_wall[64];
    const char *suffix = strstr(method, SEGMENTS_SUFFIX);
    snprintf(set_method, sizeof set_method, "solver.method=%.*s", suffix ? (int)(suffix - method) : 32, method);
    snprintf(set_rtol, sizeof set_rtol, "solver.rtol=%.3g", rtol);
    snprintf(set_t_end, sizeof set_t_end, "run.t_end=%.17g", bc->t_end);
    snprintf(set_interval, sizeof set_interval, "output.interval=%.17g", bc->interval);
    snprintf(set_wall, sizeof set_wall, "run.wall_time_limit=%g", wall_limit);
    /* rtol 0: the exact stepper, which has none.  No restart points: this measures the
     * integrators, and README ("Resumable by default") what the restart grid adds. */
    const char *overrides[9] = {set_method, set_t_end, set_interval, set_wall, "output.checkpoint_interval=0"};
    size_t n_overrides = 5;
    overrides[n_overrides++] = suffix ? "solver.local_stepping=on" : "solver.local_stepping=off";
    if (suffix)
        overrides[n_overrides++] = "solver.segment_blocks=8";
    if (rtol > 0.0)
        overrides[n_overrides++] = set_rtol;
    if (bc->extra)
        overrides[n_overrides++] = bc->extra;
    bk_config *config = NULL;
    bk_error err = {0};
    o.status = bk_config_load_file(bc->config, overrides, n_overrides, &config, &err);
    if (o.status != BK_OK) {
        snprintf(o.message, sizeof o.message, "%s", err.message);
        o.cpu = o.cpu_min = o.cpu_max = NAN;
        return o;
    }
    double times[MAX_REPEATS] = {0}, total = 0.0;
    int n = 0;
    while (n < MAX_REPEATS && (n < min_repeats || (total < MIN_TOTAL_CPU && min_repeats > 1))) {
        record_free(&o.record);
        o.record.n_blocks = config->model->n_blocks;
        bk_sink sink = {.self = &o.record, .sample = keep_sample, .transition = keep_transition};
        double start = cpu_seconds();
        o.status = bk_run(config, &sink, &o.stats, NULL, NULL, &err);
        times[n] = cpu_seconds() - start;
        total += times[n++];
        if (o.status != BK_OK) {
            snprintf(o.message, sizeof o.message, "%s", err.message);
            break;
        }
    }
    qsort(times, (size_t)n, sizeof *times, compare_doubles);
    o.cpu = n % 2 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]);
    o.cpu_min = times[0];
    o.cpu_max = times[n - 1];
    o.repeats = n;
    bk_config_free(config);
    return o;
}

typedef struct comparison {
    double error_x, error_t;
    size_t matched;
    int same_events;
} comparison;

static comparison compare(const run_record *run, const run_record *ref)
{
    comparison c = {NAN, NAN, 0, 0};
    if (run->rows == ref->rows && run->n_blocks == ref->n_blocks) {
        double worst = 0.0;
        for (size_t k = 0; k < run->rows * run->n_blocks; ++k)
            worst = fmax(worst, fabs(run->x[k] - ref->x[k]));
        c.error_x = worst;
    }
    double worst = 0.0;
    while (c.matched < run->n_events && c.matched < ref->n_events) {
        const event *a = &run->events[c.matched], *b = &ref->events[c.matched];
        if (a->block != b->block || a->from != b->from || a->to != b->to)
            break;
        worst = fmax(worst, fabs(a->t - b->t));
        c.matched++;
    }
    c.error_t = c.matched > 0 ? worst : NAN;
    c.same_events = c.matched == run->n_events && c.matched == ref->n_events;
    return c;
}

static void header(FILE *out)
{
    fprintf(out, "case\tmethod\trtol\tstatus\tcpu_s\tcpu_min_s\tcpu_max_s\trepeats\tsteps\trhs_evals\t"
                 "transitions\tref_transitions\tevents\tmatched\terror_x_m\terror_t_s\tenergy_residual\tmessage\n");
}

static void row(FILE *out, const char *case_name, const char *method, double rtol, const outcome *o,
                const comparison *c, size_t ref_transitions)
{
    fprintf(out, "%s\t%s\t%.3g\t%s\t%.6g\t%.6g\t%.6g\t%d\t%ld\t%ld\t%zu\t%zu\t%s\t%zu\t%.3g\t%.3g\t%.3g\t%s\n",
            case_name, method, rtol, o->status == BK_OK ? "ok" : "failed", o->cpu, o->cpu_min, o->cpu_max,
            o->repeats, o->stats.steps, o->stats.rhs_evals, o->record.n_events, ref_transitions,
            c->same_events ? "same" : "differ", c->matched, c->error_x, c->error_t, fabs(o->stats.energy_residual),
            o->status == BK_OK ? "-" : o->message);
    fflush(out);
}

/* 1e4 stick-slip cycles of case B's block (2300 s, transition rows only): every back-end's
 * transition times against the exact stepper's, over the first and the last 100 cycles. */
static void long_run(FILE *out, int quick)
{
    bench_case bc = {"long_B", "configs/paper/case_b_coulomb.ini", NULL, quick ? 230.0 : 2300.0, 0.0,
                     {NULL, 0}, {{NULL, 0}}, NULL, 0};
    outcome ref = run_case(&bc, "exact", 0.0, 1, 3600.0);
    fprintf(out, "method\trtol\tstatus\tcpu_s\tcycles\tevents\tphase_error_first_100_s\tphase_error_last_100_s\t"
                 "growth\tmessage\n");
    if (ref.status != BK_OK) {
        fprintf(stderr, "long run: the exact stepper failed: %s\n", ref.message);
        record_free(&ref.record);
        return;
    }
    size_t cycles = ref.record.n_events / 2, window = 2 * 100;
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        outcome o = run_case(&bc, (*b)->name, 1e-8, 1, 600.0);
        comparison c = compare(&o.record, &ref.record);
        double early = 0.0, late = 0.0;
        for (size_t k = 0; c.same_events && k < o.record.n_events; ++k) {
            double e = fabs(o.record.events[k].t - ref.record.events[k].t);
            if (k < window)
                early = fmax(early, e);
            else if (k + window >= o.record.n_events)
                late = fmax(late, e);
        }
        if (!c.same_events)
            early = late = NAN;
        fprintf(out, "%s\t%.3g\t%s\t%.6g\t%zu\t%s\t%.3g\t%.3g\t%.3g\t%s\n", (*b)->name, 1e-8,
                o.status == BK_OK ? "ok" : "failed", o.cpu, cycles, c.same_events ? "same" : "differ", early, late,
                early > 0.0 ? late / early : NAN, o.status == BK_OK ? "-" : o.message);
        fflush(out);
        record_free(&o.record);
    }
    record_free(&ref.record);
}

static void sweep(FILE *out, int quick, int repeats, const char *only)
{
    /* The integrator references: gsl_rk8pd (most accurate per CPU second in earlier runs)
     * one decade past the sweep, checked against itself a decade looser and against
     * different families; the stiff variant's reference is cvode_bdf. */
#define RS_CHECKS {{"gsl_rk8pd", 1e-12}, {"cvode_bdf", 1e-12}, {"arkode_dp45", 1e-13}}
    /* The Dieterich-Ruina ring at 64 blocks over its first 2 s (19 ruptures) and at 256 over
     * its first 1.5 s, deterministic at tight tolerance (the chaos amplifies differences only
     * over seconds), whole and in segments (README "Long chains"); the reference is the whole
     * ring at rtol 1e-12.  Below about 70 blocks segments do not pay; at 256 they do. */
    static const char *const ring_methods[] = {"cvode_bdf", "cvode_bdf" SEGMENTS_SUFFIX, NULL};
    static const bench_case cases[] = {
        {"A_coulomb", "configs/paper/case_a_coulomb.ini", NULL, 5.0, 1e-3, {"exact", 0}, {{NULL, 0}}, NULL, 0},
        {"B_coulomb", "configs/paper/case_b_coulomb.ini", NULL, 5.0, 1e-3, {"exact", 0}, {{NULL, 0}}, NULL, 0},
        {"C_coulomb", "configs/paper/case_c_coulomb.ini", NULL, 5.0, 1e-3, {"exact", 0}, {{NULL, 0}}, NULL, 0},
        {"A_rs", "configs/paper/case_a_rs.ini", NULL, 5.0, 1e-3, {"gsl_rk8pd", 1e-13}, RS_CHECKS, NULL, 0},
        {"B_rs", "configs/paper/case_b_rs.ini", NULL, 5.0, 1e-3, {"gsl_rk8pd", 1e-13}, RS_CHECKS, NULL, 0},
        {"C_rs", "configs/paper/case_c_rs.ini", NULL, 5.0, 1e-3, {"gsl_rk8pd", 1e-13}, RS_CHECKS, NULL, 0},
        {"B_rs_stiff", "configs/paper/case_b_rs.ini", "friction.L0=2e-8", 1.0, 1e-3, {"cvode_bdf", 1e-13},
         {{"cvode_bdf", 1e-12}, {"gsl_rk8pd", 1e-12}, {"ida", 1e-12}}, NULL, 0},
        {"chain10", "configs/chains/bk10_coulomb.ini", NULL, 1.0, 1e-2, {"exact", 0}, {{NULL, 0}}, NULL, 0},
        {"chain1000", "configs/chains/bk1000_coulomb.ini", NULL, 0.5, 1e-2, {"exact", 0}, {{NULL, 0}}, NULL, 0},
        /* The same chain with dashpots to the substrate (damping ratio 0.1 of a block on its
         * driver spring), which the exact stepper solves mode by mode as damped oscillators. */
        {"chain1000_damped", "configs/chains/bk1000_coulomb.ini", "block.damping=20", 0.5, 1e-2, {"exact", 0},
         {{NULL, 0}}, NULL, 0},
        {"ring64_rs", "configs/chains/dieterich_ruina_30.ini", "model.n_blocks=64", 2.0, 1e-2, {"cvode_bdf", 1e-12},
         {{"cvode_bdf", 1e-11}, {"cvode_bdf" SEGMENTS_SUFFIX, 1e-12}}, ring_methods, 1e-5},
        {"ring256_rs", "configs/chains/dieterich_ruina_30.ini", "model.n_blocks=256", 1.5, 1e-2, {"cvode_bdf", 1e-12},
         {{"cvode_bdf", 1e-11}, {"cvode_bdf" SEGMENTS_SUFFIX, 1e-12}}, ring_methods, 1e-5},
    };
#undef RS_CHECKS
    static const double rtols[] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
    header(out);
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const bench_case *bc = &cases[c];
        if (only ? strcmp(only, bc->name) != 0 : quick && c != 1)
            continue;
        int big = strncmp(bc->name, "chain1000", 9) == 0;
        outcome ref = run_case(bc, bc->reference.method, bc->reference.rtol, 1, 3600.0);
        if (ref.status != BK_OK) {
            fprintf(stderr, "%s: reference failed: %s\n", bc->name, ref.message);
            record_free(&ref.record);
            continue;
        }
        comparison self = {0.0, 0.0, ref.record.n_events, 1};
        row(out, bc->name, "reference", bc->reference.rtol, &ref, &self, ref.record.n_events);
        for (size_t k = 0; k < 3 && bc->checks[k].method; ++k) {
            outcome o = run_case(bc, bc->checks[k].method, bc->checks[k].rtol, 1, 3600.0);
            comparison cmp = compare(&o.record, &ref.record);
            char label[64];
            snprintf(label, sizeof label, "reference_vs_%s", bc->checks[k].method);
            row(out, bc->name, label, bc->checks[k].rtol, &o, &cmp, ref.record.n_events);
            record_free(&o.record);
        }
        const bk_solver_backend *const *b = bk_solver_backends();
        for (size_t m = 0; bc->methods ? bc->methods[m] != NULL : b[m] != NULL; ++m) {
            const char *method = bc->methods ? bc->methods[m] : b[m]->name;
            int is_exact = strcmp(method, "exact") == 0;
            for (size_t r = 0; r < sizeof rtols / sizeof rtols[0]; ++r) {
                if (is_exact && r > 0)
                    break; /* tolerance-free: one row */
                if (bc->loosest > 0.0 && rtols[r] > bc->loosest)
                    continue;
                if (!is_exact && quick && r % 4 != 1)
                    continue;
                if (!is_exact && big && !(r == 3 || r == 5 || r == 7))
                    continue; /* 1e-6, 1e-8, 1e-10 on the 1000-block chain */
                outcome o = run_case(bc, method, rtols[r], big ? 1 : repeats, 60.0);
                comparison cmp = compare(&o.record, &ref.record);
                row(out, bc->name, method, is_exact ? 0.0 : rtols[r], &o, &cmp, ref.record.n_events);
                record_free(&o.record);
                if (o.status != BK_OK && strstr(o.message, "needs Coulomb"))
                    break; /* exact on a non-affine scene: once is enough */
            }
        }
        record_free(&ref.record);
    }
}

int main(int argc, char **argv)
{
    int quick = 0, repeats = 3, long_run_mode = 0;
    const char *only = NULL;
    FILE *out = stdout;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--long-run") == 0)
            long_run_mode = 1;
        else if (strcmp(argv[i], "--repeats") == 0 && i + 1 < argc)
            repeats = atoi(argv[++i]);
        else if (strcmp(argv[i], "--case") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
            out = fopen(argv[++i], "w");
            if (!out) {
                perror(argv[i]);
                return 1;
            }
        } else {
            fprintf(stderr,
                    "usage: %s [--quick] [--long-run] [--repeats N] [--case NAME] [--out FILE]\n"
                    "  (default) every back-end x rtol 1e-3..1e-12 on every case, TSV\n"
                    "  --long-run  phase drift over 1e4 stick-slip cycles, every back-end\n"
                    "  --repeats N at least N timed runs each (short runs repeat up to %d, to %.1f s)\n",
                    argv[0], MAX_REPEATS, MIN_TOTAL_CPU);
            return 2;
        }
    }
    if (repeats < 1 || repeats > MAX_REPEATS) {
        fprintf(stderr, "--repeats: 1..%d\n", MAX_REPEATS);
        return 2;
    }
    if (long_run_mode)
        long_run(out, quick);
    else
        sweep(out, quick, repeats, only);
    if (out != stdout)
        fclose(out);
    return 0;
}
