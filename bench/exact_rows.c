/* What an output row costs the exact stepper on one slipping cluster of p blocks (a
 * non-uniform chain, tests/support/linear_chain.c): the rows' path (sample: the Taylor series
 * about the last step end from SERIES_MIN_PAIRS pairs on, src/solver/exact_rows.c) against
 * the modal sum (interpolate: O(p^2)), side by side in one process, at the same times inside
 * each step, with the largest difference between the two in units of DBL_EPSILON times the
 * largest position or velocity.
 *
 *   exact_rows [--quick] [P ...]      (default 16 32 48 64 128 256 512 1024 2048)
 *
 * Each figure is the mean over STEPS steps, each timed for at least 0.2 s (--quick: 2 steps
 * of 0.01 s, a smoke run).
 * Prints a table: p, ns per row by each path, their ratio, the difference. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bksim/solver.h"
#include "linear_chain.h"

#define ROWS_PER_STEP 16

static int steps = 8;
static double min_seconds = 0.2;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef int (*dense_fn)(void *mem, double t, double *y, bk_error *err);

/* ns per call of f at ROWS_PER_STEP times of the last step, repeated for min_seconds. */
static double time_rows(dense_fn f, void *mem, double t_lo, double t_hi, double *y)
{
    bk_error err = {0};
    long calls = 0;
    double start = now(), elapsed = 0.0;
    do {
        for (int j = 0; j < ROWS_PER_STEP; ++j)
            if (f(mem, t_lo + (t_hi - t_lo) * (j + 0.5) / ROWS_PER_STEP, y, &err) != BK_OK) {
                fprintf(stderr, "exact_rows: %s\n", err.message);
                exit(1);
            }
        calls += ROWS_PER_STEP;
        elapsed = now() - start;
    } while (elapsed < min_seconds);
    return 1e9 * elapsed / (double)calls;
}

static int bench(size_t p)
{
    size_t n = 2 * p + 2;
    linear_chain *lc = linear_chain_new(p, 11u);
    double *y0 = malloc(n * sizeof *y0), *atol = malloc(n * sizeof *atol);
    double *y = malloc(n * sizeof *y), *ref = malloc(n * sizeof *ref);
    if (!lc || !y0 || !atol || !y || !ref) {
        fprintf(stderr, "exact_rows: out of memory for p = %zu\n", p);
        return 1;
    }
    bk_ode_problem problem = linear_chain_problem(lc);
    linear_chain_start(lc, y0);
    for (size_t k = 0; k < n; ++k)
        atol[k] = 1e-12;
    bk_solver_options options;
    memset(&options, 0, sizeof options);
    snprintf(options.method, sizeof options.method, "exact");
    options.max_step = NAN;
    const bk_solver_backend *b = bk_solver_backend_find("exact");
    void *mem = NULL;
    bk_error err = {0};
    if (b->create(&mem, &options, &err) != BK_OK || b->start(mem, &problem, 0.0, y0, atol, n, 100.0, &err) != BK_OK) {
        fprintf(stderr, "exact_rows: %s\n", err.message);
        return 1;
    }
    double series = 0.0, modal = 0.0, worst = 0.0;
    for (int s = 0; s < steps; ++s) {
        double t_reached, t_lo, t_hi;
        if (b->step(mem, &t_reached, y, &err) < 0) {
            fprintf(stderr, "exact_rows: %s\n", err.message);
            return 1;
        }
        b->last_step(mem, &t_lo, &t_hi);
        series += time_rows(b->sample, mem, t_lo, t_hi, y) / steps;
        modal += time_rows(b->interpolate, mem, t_lo, t_hi, ref) / steps;
        double scale[2] = {0.0, 0.0};
        for (size_t k = 0; k < 2 * p; ++k)
            scale[k % 2] = fmax(scale[k % 2], fabs(ref[k]));
        for (size_t k = 0; k < 2 * p; ++k)
            worst = fmax(worst, fabs(y[k] - ref[k]) / (DBL_EPSILON * scale[k % 2]));
    }
    printf("%zu\t%.0f\t%.0f\t%.2f\t%.1f\n", p, series, modal, modal / series, worst);
    b->destroy(mem);
    free(y0);
    free(atol);
    free(y);
    free(ref);
    linear_chain_free(lc);
    return 0;
}

int main(int argc, char **argv)
{
    static const size_t sizes[] = {16, 32, 48, 64, 128, 256, 512, 1024, 2048};
    printf("pairs\tns_per_row_rows_path\tns_per_row_modal\tmodal_over_rows_path\tdifference_eps\n");
    int first = 1;
    if (argc > 1 && strcmp(argv[1], "--quick") == 0) {
        steps = 2;
        min_seconds = 0.01;
        first = 2;
    }
    if (argc > first) {
        for (int a = first; a < argc; ++a)
            if (bench((size_t)strtoul(argv[a], NULL, 10)) != 0)
                return 1;
        return 0;
    }
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; ++k)
        if (bench(sizes[k]) != 0)
            return 1;
    return 0;
}
