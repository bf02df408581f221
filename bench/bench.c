/* Work-precision benchmark: every solver back-end on the paper's cases (Coulomb and
 * rate-and-state) and on Coulomb chains, over a sweep of rtol, timed in-process (median CPU
 * of repeated runs), with its error against a reference: the exact stepper for Coulomb, the
 * tightest run (rtol 1e-12) of gsl_rk8pd, the most accurate integrator per CPU second, for
 * rate-and-state; its own convergence (against rtol 1e-11) and its agreement with a
 * different method family (cvode_bdf at 1e-12) are reported as rows too.
 *
 *   error_x     max |x - x_ref| over the regular samples and blocks, m
 *   error_t     max |t - t_ref| over the transitions, s (when both runs have as many)
 *   energy      |energy residual|, the run's own balance (driver work = elastic + kinetic
 *               + dissipation), relative to the driver work
 *
 * Output: one TSV row per run on stdout (or --out FILE); `scripts/bench.sh` drives it and
 * plots.  Not part of CI (a --quick smoke run is). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bksim/bksim.h"

typedef struct run_record {
    size_t n_blocks;
    double *x;          /* regular samples only: rows x n_blocks */
    size_t rows, cap;
    double *t_tr;       /* transition times */
    size_t n_tr, cap_tr;
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
    if (r->n_tr == r->cap_tr) {
        r->cap_tr = r->cap_tr ? 2 * r->cap_tr : 256;
        double *grown = realloc(r->t_tr, r->cap_tr * sizeof *grown);
        if (!grown)
            return BK_ERR_NOMEM;
        r->t_tr = grown;
    }
    r->t_tr[r->n_tr++] = t->t;
    return BK_OK;
}

static void record_free(run_record *r)
{
    free(r->x);
    free(r->t_tr);
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

typedef struct bench_case {
    const char *name;
    const char *config;
    double t_end, interval;
    const char *reference_method; /* exact, or an integrator at rtol 1e-12 */
} bench_case;

typedef struct outcome {
    int status;
    double cpu;
    bk_run_stats stats;
    run_record record;
    char message[BK_ERROR_MESSAGE_LEN];
} outcome;

/* Load the case with method and rtol, run it repeats times, keep the last record. */
static outcome run_case(const bench_case *bc, const char *method, double rtol, int repeats, double wall_limit)
{
    outcome o;
    memset(&o, 0, sizeof o);
    char set_method[64], set_rtol[64], set_t_end[64], set_interval[64], set_wall[64];
    snprintf(set_method, sizeof set_method, "solver.method=%s", method);
    snprintf(set_rtol, sizeof set_rtol, "solver.rtol=%.3g", rtol);
    snprintf(set_t_end, sizeof set_t_end, "run.t_end=%.17g", bc->t_end);
    snprintf(set_interval, sizeof set_interval, "output.interval=%.17g", bc->interval);
    snprintf(set_wall, sizeof set_wall, "run.wall_time_limit=%g", wall_limit);
    const char *overrides[] = {set_method, set_rtol, set_t_end, set_interval, set_wall};
    bk_config *config = NULL;
    bk_error err = {0};
    o.status = bk_config_load_file(bc->config, overrides, 5, &config, &err);
    if (o.status != BK_OK) {
        snprintf(o.message, sizeof o.message, "%s", err.message);
        return o;
    }
    double times[16] = {0};
    int n_times = 0;
    for (int k = 0; k < repeats && k < 16; ++k) {
        record_free(&o.record);
        o.record.n_blocks = config->model->n_blocks;
        bk_sink sink = {.self = &o.record, .sample = keep_sample, .transition = keep_transition};
        double start = cpu_seconds();
        o.status = bk_run(config, &sink, &o.stats, NULL, NULL, &err);
        times[n_times++] = cpu_seconds() - start;
        if (o.status != BK_OK) {
            snprintf(o.message, sizeof o.message, "%s", err.message);
            break;
        }
    }
    qsort(times, (size_t)n_times, sizeof *times, compare_doubles);
    o.cpu = times[n_times / 2];
    bk_config_free(config);
    return o;
}

static void errors(const run_record *run, const run_record *ref, double *error_x, double *error_t)
{
    *error_x = NAN;
    *error_t = NAN;
    if (run->rows == ref->rows && run->n_blocks == ref->n_blocks) {
        double worst = 0.0;
        for (size_t k = 0; k < run->rows * run->n_blocks; ++k)
            worst = fmax(worst, fabs(run->x[k] - ref->x[k]));
        *error_x = worst;
    }
    if (run->n_tr == ref->n_tr) {
        double worst = 0.0;
        for (size_t k = 0; k < run->n_tr; ++k)
            worst = fmax(worst, fabs(run->t_tr[k] - ref->t_tr[k]));
        *error_t = worst;
    }
}

static void row(FILE *out, const char *case_name, const char *method, double rtol, const outcome *o,
                double error_x, double error_t, size_t ref_transitions)
{
    fprintf(out, "%s\t%s\t%.3g\t%s\t%.6g\t%ld\t%ld\t%zu\t%zu\t%.3g\t%.3g\t%.3g\t%s\n", case_name, method, rtol,
            o->status == BK_OK ? "ok" : "failed", o->cpu, o->stats.steps, o->stats.rhs_evals, o->record.n_tr,
            ref_transitions, error_x, error_t, fabs(o->stats.energy_residual),
            o->status == BK_OK ? "-" : o->message);
    fflush(out);
}

/* CPU per transition against chain length: the 1000-block chain's config cut to N blocks. */
static void scaling(FILE *out, int quick)
{
    static const size_t sizes[] = {10, 30, 100, 300, 1000};
    static const char *const methods[] = {"cvode_adams", "cvode_bdf", "gsl_rk8pd", "exact"};
    fprintf(out, "n_blocks\tmethod\tstatus\tcpu_s\ttransitions\tcpu_per_transition_s\tsteps\n");
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; ++k) {
        if (quick && k > 0)
            break;
        for (size_t m = 0; m < sizeof methods / sizeof methods[0]; ++m) {
            char name[64];
            snprintf(name, sizeof name, "chain%zu", sizes[k]);
            bench_case bc = {name, "configs/chains/bk1000_coulomb.ini", 0.5, 1e-2, NULL};
            /* The same chain cut to n blocks, through a copy of its config. */
            char path[] = "/tmp/bksim_scaling_XXXXXX";
            int fd = mkstemp(path);
            FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
            FILE *in = fopen(bc.config, "r");
            if (!f || !in) {
                if (f)
                    fclose(f);
                if (in)
                    fclose(in);
                continue;
            }
            char line[256];
            while (fgets(line, sizeof line, in))
                fputs(strncmp(line, "n_blocks", 8) == 0 ? "" : line, f);
            fprintf(f, "[model]\nn_blocks = %zu\n", sizes[k]);
            fclose(in);
            fclose(f);
            bc.config = path;
            outcome o = run_case(&bc, methods[m], 1e-8, 1, 600.0);
            fprintf(out, "%zu\t%s\t%s\t%.6g\t%zu\t%.6g\t%ld\n", sizes[k], methods[m],
                    o.status == BK_OK ? "ok" : "failed", o.cpu, o.record.n_tr,
                    o.record.n_tr ? o.cpu / (double)o.record.n_tr : NAN, o.stats.steps);
            fflush(out);
            record_free(&o.record);
            remove(path);
        }
    }
}

int main(int argc, char **argv)
{
    int quick = 0, repeats = 3, scale = 0;
    const char *only = NULL;
    FILE *out = stdout;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--scaling") == 0)
            scale = 1;
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
            fprintf(stderr, "usage: %s [--quick] [--scaling] [--repeats N] [--case NAME] [--out FILE]\n", argv[0]);
            return 2;
        }
    }
    if (scale) {
        scaling(out, quick);
        if (out != stdout)
            fclose(out);
        return 0;
    }
    static const bench_case cases[] = {
        {"A_coulomb", "configs/paper/case_a_coulomb.ini", 5.0, 1e-3, "exact"},
        {"B_coulomb", "configs/paper/case_b_coulomb.ini", 5.0, 1e-3, "exact"},
        {"C_coulomb", "configs/paper/case_c_coulomb.ini", 5.0, 1e-3, "exact"},
        {"A_rs", "configs/paper/case_a_rs.ini", 5.0, 1e-3, "gsl_rk8pd"},
        {"B_rs", "configs/paper/case_b_rs.ini", 5.0, 1e-3, "gsl_rk8pd"},
        {"C_rs", "configs/paper/case_c_rs.ini", 5.0, 1e-3, "gsl_rk8pd"},
        {"chain10", "configs/chains/bk10_coulomb.ini", 1.0, 1e-2, "exact"},
        {"chain1000", "configs/chains/bk1000_coulomb.ini", 0.5, 1e-2, "exact"},
    };
    static const double rtols[] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
    fprintf(out, "case\tmethod\trtol\tstatus\tcpu_s\tsteps\trhs_evals\ttransitions\tref_transitions\t"
                 "error_x_m\terror_t_s\tenergy_residual\tmessage\n");
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const bench_case *bc = &cases[c];
        if (only ? strcmp(only, bc->name) != 0 : quick && c != 1)
            continue;
        int big = strcmp(bc->name, "chain1000") == 0;
        /* The reference, and for an integrator reference its own convergence. */
        outcome ref = run_case(bc, bc->reference_method, 1e-12, 1, 3600.0);
        if (ref.status != BK_OK) {
            fprintf(stderr, "%s: reference failed: %s\n", bc->name, ref.message);
            record_free(&ref.record);
            continue;
        }
        row(out, bc->name, "reference", 1e-12, &ref, 0.0, 0.0, ref.record.n_tr);
        if (strcmp(bc->reference_method, "exact") != 0) {
            outcome check = run_case(bc, bc->reference_method, 1e-11, 1, 3600.0);
            double ex, et;
            errors(&check.record, &ref.record, &ex, &et);
            row(out, bc->name, "reference_vs_1e-11", 1e-11, &check, ex, et, ref.record.n_tr);
            record_free(&check.record);
            /* and against a different method family at its tightest */
            outcome other = run_case(bc, "cvode_bdf", 1e-12, 1, 3600.0);
            errors(&other.record, &ref.record, &ex, &et);
            row(out, bc->name, "reference_vs_cvode_bdf", 1e-12, &other, ex, et, ref.record.n_tr);
            record_free(&other.record);
        }
        for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
            const char *method = (*b)->name;
            int is_exact = strcmp(method, "exact") == 0;
            for (size_t r = 0; r < sizeof rtols / sizeof rtols[0]; ++r) {
                if (is_exact && r > 0)
                    break; /* tolerance-free: one row */
                if (!is_exact && quick && r % 4 != 1)
                    continue;
                if (!is_exact && big && !(r == 3 || r == 5 || r == 7))
                    continue; /* 1e-6, 1e-8, 1e-10 on the 1000-block chain */
                outcome o = run_case(bc, method, rtols[r], big ? 1 : repeats, 60.0);
                double ex, et;
                errors(&o.record, &ref.record, &ex, &et);
                row(out, bc->name, method, is_exact ? 0.0 : rtols[r], &o, ex, et, ref.record.n_tr);
                record_free(&o.record);
                if (o.status != BK_OK && strstr(o.message, "needs Coulomb"))
                    break; /* exact on a non-affine scene: once is enough */
            }
        }
        record_free(&ref.record);
    }
    if (out != stdout)
        fclose(out);
    return 0;
}
