/* Every registered back-end against exact answers.  Through the run loop: the paper's
 * Coulomb single block (cases A, B: every transition time against the closed form, at two
 * tolerances; case C: all 141 transitions, which needs correct last_step and interpolate
 * for the hidden-stop search), and the energy balance of a 10-block chain.  Directly: the
 * interface's root conventions.  Prints a table of cost and accuracy per back-end; nothing
 * here asserts on timing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "exact_single.h"
#include "recorder.h"
#include "scene_spec.h"

/* Cases A and B: every transition time within TIME_FACTOR * rtol of the closed form,
 * relative.  Measured worst over all back-ends: 12 rtol (cvode_bdf, case B, rtol 1e-10);
 * ida 11 rtol, gsl_msbdf 7 rtol, the Runge-Kutta back-ends below 1 rtol. */
#define TIME_FACTOR 30.0
/* 10-block chain: |energy residual| <= ENERGY_FACTOR * rtol (measured worst: 0.4 rtol). */
#define ENERGY_FACTOR 100.0
/* The damped single block: measured worst 24 rtol (cvode_bdf at zeta 0.7), the Runge-Kutta
 * back-ends below 1.2 rtol. */
#define DAMPED_TIME_FACTOR 60.0
/* The heterogeneous lattice against the exact stepper, absolute (transitions at 0.06-0.6 s). */
#define LATTICE_TIME_S 1e-6

static void run_config(bk_config *c, recorder *r, bk_run_stats *stats)
{
    bk_error err = {0};
    int rc = run_recorded(c, r, stats, &err);
    if (rc != BK_OK)
        print_error("%s: %s\n", c->solver.method, err.message);
    assert_int_equal(rc, BK_OK);
    assert_false(r->time_decreased);
}

static void row(const char *method, const char *label, double rtol, const bk_run_stats *s,
                const char *what, double value)
{
    print_message("%-12s %-8s %6.0e %7ld %8ld %8.4f  %-6s %.2e\n", method, label, rtol, s->steps,
                  s->rhs_evals, s->cpu_time, what, value);
}

static void header(void)
{
    print_message("%-12s %-8s %6s %7s %8s %8s  %s\n", "back-end", "case", "rtol", "steps",
                  "rhs", "CPU s", "max error");
}

/* The implicit back-ends, which also run with a band linear solver. */
static const char *const band_backends[] = {"cvode_bdf", "arkode_dirk", "arkode_imex", "ida"};
#define N_BAND_BACKENDS (sizeof band_backends / sizeof band_backends[0])

/* r's transitions are the reference's, block for block and mode for mode; returns the
 * largest gap between their times (s). */
static double transition_gap(const recorder *r, const recorder *reference, const char *method)
{
    if (r->n_transitions != reference->n_transitions)
        print_error("%s: %zu transitions, reference %zu\n", method, r->n_transitions, reference->n_transitions);
    assert_int_equal(r->n_transitions, reference->n_transitions);
    double worst = 0.0;
    for (size_t k = 0; k < reference->n_transitions; ++k) {
        const bk_transition *a = &r->transitions[k], *b = &reference->transitions[k];
        assert_int_equal(a->block, b->block);
        assert_int_equal(a->from, b->from);
        assert_int_equal(a->to, b->to);
        worst = fmax(worst, fabs(a->t - b->t));
    }
    return worst;
}

/* An asymmetric start and mixed mu_d, block by block, around the relaxed x_offset. */
static void heterogenise(bk_config *c, double x_offset)
{
    for (size_t i = 0; i < c->model->n_blocks; ++i) {
        c->model->blocks[i].x_init = x_offset + 1e-5 * sin(2.385 * (double)i);
        c->model->blocks[i].friction_params[1] = 0.45 + 0.01 * (double)(i % 5);
    }
}

/* --- the Coulomb single block against its closed form ---------------------------------- */

/* Run one back-end on case A or B; returns the worst relative transition-time error. */
static double transition_error(const char *method, double mu_d, bk_spring spring, double rtol,
                               const exact_solution *ex, const char *label)
{
    scene_spec spec = paper_case(mu_d, spring, rtol, method);
    bk_config *c = scene_config(&spec);
    recorder r = {0};
    bk_run_stats stats;
    run_config(c, &r, &stats);
    if (r.n_transitions != ex->n_events)
        print_error("%s %s rtol %g: %zu transitions, exact %zu\n", method, label, rtol,
                    r.n_transitions, ex->n_events);
    assert_int_equal(r.n_transitions, ex->n_events);
    double worst = 0.0;
    for (size_t k = 0; k < ex->n_events; ++k) {
        assert_int_equal(r.transitions[k].from, ex->events[k].from);
        assert_int_equal(r.transitions[k].to, ex->events[k].to);
        double e = fabs(r.transitions[k].t - ex->events[k].t) / ex->events[k].t;
        if (e > worst)
            worst = e;
    }
    row(method, label, rtol, &stats, "dt/t", worst);
    assert_true(worst <= TIME_FACTOR * rtol);
    recorder_free(&r);
    bk_config_free(c);
    return worst;
}

static void exact_case(double mu_d, bk_spring spring, exact_solution *ex)
{
    exact_params p = {1.0, 1e4, 9.81, 0.6, mu_d, 1e-3, spring == BK_SPRING_TENSION_ONLY};
    assert_int_equal(exact_solve(&p, 5.0, ex), 0);
}

/* Cases A and B (and A with a tension-only spring, whose slack/taut root can fire either
 * way) at rtol 1e-8 and 1e-10: every transition at the exact time, to a bound proportional
 * to rtol, and the error falls as rtol tightens. */
static void test_cases_a_b(void **state)
{
    (void)state;
    const double mu_d[] = {0.1, 0.5, 0.1};
    const bk_spring spring[] = {BK_SPRING_LINEAR, BK_SPRING_LINEAR, BK_SPRING_TENSION_ONLY};
    const char *labels[] = {"A", "B", "A slack"};
    header();
    for (size_t k = 0; k < 3; ++k) {
        exact_solution ex;
        exact_case(mu_d[k], spring[k], &ex);
        for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
            double loose = transition_error((*b)->name, mu_d[k], spring[k], 1e-8, &ex, labels[k]);
            double tight = transition_error((*b)->name, mu_d[k], spring[k], 1e-10, &ex, labels[k]);
            assert_true(tight < loose || tight < 1e-13);
        }
        exact_free(&ex);
    }
}

/* Case C ends every slip by grazing (v dips through zero for ~0.2 ms); the run loop finds
 * these stops on the back-end's last step and dense output.  All 141 transitions. */
static void test_case_c(void **state)
{
    (void)state;
    exact_solution ex;
    exact_case(0.5999, BK_SPRING_LINEAR, &ex);
    assert_int_equal(ex.n_events, 141);
    header();
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        scene_spec spec = paper_case(0.5999, BK_SPRING_LINEAR, 1e-8, (*b)->name);
        bk_config *c = scene_config(&spec);
        recorder r = {0};
        bk_run_stats stats;
        run_config(c, &r, &stats);
        if (r.n_transitions != ex.n_events)
            print_error("%s: %zu transitions, exact %zu\n", (*b)->name, r.n_transitions, ex.n_events);
        assert_int_equal(r.n_transitions, ex.n_events);
        double worst = 0.0;
        for (size_t k = 0; k < ex.n_events; ++k)
            worst = fmax(worst, fabs(r.transitions[k].t - ex.events[k].t));
        row((*b)->name, "C", spec.rtol, &stats, "dt s", worst);
        /* Grazing stops: a velocity error dv moves the stop by dv / a, a = (mu_s - mu_d) g;
         * allow 1e3 rtol V / a = 1.0e-5 s (measured worst 5e-7 s, cvode_bdf). */
        assert_true(worst < 1e3 * spec.rtol * spec.velocity / ((0.6 - 0.5999) * 9.81));
        recorder_free(&r);
        bk_config_free(c);
    }
    exact_free(&ex);
}

/* --- a uniform lattice slides as one block ---------------------------------------------- */

/* Back-ends that factorise the coupling (Newton with pivoted LU): rounding there differs
 * from block to block, so a uniform lattice is uniform only to rounding, and its
 * synchronous cycle, unstable at the near-simultaneous stops, is lost after one cycle (a
 * uniform 12-block ring does the same, before lattices too: 475 transitions under ida for
 * the closed form's 121). */
static int factorises_coupling(const char *method)
{
    static const char *const names[] = {"cvode_bdf", "arkode_dirk", "ida", "gsl_msbdf"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k)
        if (strcmp(method, names[k]) == 0)
            return 1;
    return 0;
}

/* A uniform 3 x 4 lattice started relaxed (free rows, periodic columns) under case A's
 * friction: every block repeats the single block's closed-form cycle.  Without a factorised
 * coupling the lattice stays exactly uniform: each transition happens to all 12 blocks at
 * once, at the closed form's time (TIME_FACTOR rtol), for the whole run.  With one, the
 * first cycle (breakaway and stop) holds block by block to the same bound. */
static void test_uniform_lattice(void **state)
{
    (void)state;
    enum { ROWS = 3, COLS = 4, N = ROWS * COLS };
    exact_solution ex;
    exact_case(0.1, BK_SPRING_LINEAR, &ex);
    header();
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, 1e-10, (*b)->name);
        spec.n = N;
        spec.coupling = 2e4;
        bk_config *c = scene_config(&spec);
        c->model->rows = ROWS;
        c->model->cols = COLS;
        c->model->boundary_rows = BK_BOUNDARY_FREE;
        c->model->boundary_cols = BK_BOUNDARY_PERIODIC;
        recorder r = {0};
        bk_run_stats stats;
        bk_error err = {0};
        int rc = run_recorded(c, &r, &stats, &err);
        if (rc != BK_OK)
            print_error("%s: %s\n", c->solver.method, err.message);
        assert_int_equal(rc, BK_OK);
        int whole_run = !factorises_coupling((*b)->name);
        /* Stops a rounding apart may come in two instants at one time there (rows of equal time). */
        assert_true(!r.time_decreased || !whole_run);
        size_t checked = whole_run ? N * ex.n_events : 2 * N;
        if (whole_run && r.n_transitions != checked)
            print_error("%s: %zu transitions, %d blocks x %zu exact\n", (*b)->name, r.n_transitions, N, ex.n_events);
        assert_true(whole_run ? r.n_transitions == checked : r.n_transitions >= checked);
        double worst = 0.0;
        size_t seen[N] = {0};
        for (size_t k = 0; k < checked; ++k) {
            const bk_transition *tr = &r.transitions[k];
            assert_true(tr->block >= 0 && tr->block < N);
            const exact_event *e = &ex.events[seen[tr->block]++];
            if (whole_run) {
                assert_int_equal(tr->block, (int)(k % N)); /* an instant's transitions, in block order */
                assert_true(tr->t == r.transitions[k - k % N].t); /* all blocks at once */
            }
            assert_int_equal(tr->from, e->from);
            assert_int_equal(tr->to, e->to);
            worst = fmax(worst, fabs(tr->t - e->t) / e->t);
        }
        for (size_t i = 0; i < N; ++i)
            assert_int_equal(seen[i], checked / N);
        row((*b)->name, whole_run ? "3x4" : "3x4 1st", spec.rtol, &stats, "dt/t", worst);
        assert_true(worst <= TIME_FACTOR * spec.rtol);
        recorder_free(&r);
        bk_config_free(c);
    }
    exact_free(&ex);
}

/* A heterogeneous 3 x 4 lattice (walls above and below, periodic columns, random start and
 * mu_d): its coupling forces are all non-zero, unlike the uniform lattice's.  The exact
 * stepper is the reference; every integrator, and the implicit ones with a band solver too,
 * gives its transitions block for block and mode for mode, each within LATTICE_TIME_S, and
 * closes the energy audit. */
static void heterogeneous_lattice(const char *method, const char *linear_solver, const recorder *reference,
                                  recorder *out)
{
    const double rtol = 1e-10;
    scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, rtol, method);
    spec.n = 12;
    spec.coupling = 2e4;
    spec.t_end = 0.6;
    bk_config *c = scene_config(&spec);
    c->model->rows = 3;
    c->model->cols = 4;
    c->model->boundary_rows = BK_BOUNDARY_FIXED;
    c->model->boundary_cols = BK_BOUNDARY_PERIODIC;
    snprintf(c->solver.linear_solver, sizeof c->solver.linear_solver, "%s", linear_solver);
    heterogenise(c, 5e-4);
    bk_run_stats stats;
    run_config(c, out, &stats);
    double worst = reference ? transition_gap(out, reference, method) : 0.0;
    row(method, linear_solver[0] == 'b' ? "3x4 band" : "3x4", rtol, &stats, "dt s", worst);
    assert_true(worst <= LATTICE_TIME_S);
    assert_true(fabs(stats.energy_residual) <= ENERGY_FACTOR * rtol);
    bk_config_free(c);
}

static void test_heterogeneous_lattice(void **state)
{
    (void)state;
    header();
    recorder reference = {0};
    heterogeneous_lattice("exact", "dense", NULL, &reference);
    /* Blocks slip more than once each, and at some moment two that are neighbours up and
     * down (a 2D island, coupled across rows) slip together. */
    assert_true(reference.n_transitions > 4 * 12);
    int slipping[12] = {0}, vertical = 0;
    for (size_t k = 0; k < reference.n_transitions; ++k) {
        const bk_transition *tr = &reference.transitions[k];
        slipping[tr->block] = tr->to != BK_MODE_STICK;
        for (int i = 0; i < 8; ++i)
            vertical |= slipping[i] && slipping[i + 4];
    }
    print_message("%zu transitions; a 2D island: %s\n", reference.n_transitions, vertical ? "yes" : "no");
    assert_true(vertical);
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        if (strcmp((*b)->name, "exact") == 0)
            continue;
        recorder r = {0};
        heterogeneous_lattice((*b)->name, "dense", &reference, &r);
        recorder_free(&r);
    }
    for (size_t k = 0; k < N_BAND_BACKENDS; ++k) {
        recorder r = {0};
        heterogeneous_lattice(band_backends[k], "band", &reference, &r);
        recorder_free(&r);
    }
    recorder_free(&reference);
}

/* --- the damped single block against its closed form ----------------------------------- */

#define PI_VALUE 3.14159265358979323846

/* The paper's block with a dashpot c to the substrate, case A friction.  From rest at
 * spring extension F_s / k it slips, m x'' = k (V t - x) - c x' - F_d, i.e. about the
 * particular solution x_p = V t - (F_d + c V) / k the deviation u = x - x_p rings down as
 * u'' + 2 zeta w u' + w^2 u = 0, and the slip ends where the underdamped velocity
 * V + u'(tau) first returns to zero.  Then the block sticks until the spring is back at
 * F_s: every cycle repeats the first, so one slip duration and slip length give every
 * transition time. */
typedef struct damped_cycle {
    double t_first;  /* s, first breakaway */
    double slip_time; /* s */
    double slip;     /* m */
    double stuck_time; /* s */
} damped_cycle;

static double damped_velocity(double V, double zw, double wd, double A, double B, double tau)
{
    double e = exp(-zw * tau);
    return V + e * ((-zw * A + wd * B) * cos(wd * tau) + (-zw * B - wd * A) * sin(wd * tau));
}

static damped_cycle damped_closed_form(double m, double k, double c, double V, double f_s, double f_d)
{
    double w = sqrt(k / m), zeta = c / (2.0 * m * w), zw = zeta * w, wd = w * sqrt(1.0 - zeta * zeta);
    double A = (f_d - f_s + c * V) / k, B = (-V + zw * A) / wd;
    /* v > 0 just after the breakaway (a = (F_s - F_d) / m); scan for its first sign change. */
    double h = 1e-3 * PI_VALUE / wd, lo = h, hi = 2.0 * h;
    while (damped_velocity(V, zw, wd, A, B, hi) > 0.0) {
        lo = hi;
        hi += h;
        assert_true(hi < 10.0 * PI_VALUE / wd);
    }
    for (int it = 0; it < 200; ++it) {
        double mid = 0.5 * (lo + hi);
        if (damped_velocity(V, zw, wd, A, B, mid) > 0.0)
            lo = mid;
        else
            hi = mid;
    }
    damped_cycle cycle = {.t_first = f_s / (k * V), .slip_time = 0.5 * (lo + hi)};
    double tau = cycle.slip_time, e = exp(-zw * tau);
    double u = e * (A * cos(wd * tau) + B * sin(wd * tau));
    /* Slip from x = x_p + u, measured from the position at breakaway (x_p(0) + A there). */
    cycle.slip = V * tau + u - A;
    double extension = f_s / k - cycle.slip + V * tau; /* D - x at the stop */
    cycle.stuck_time = (f_s / k - extension) / V;
    return cycle;
}

/* Every back-end, the exact stepper included, against the closed form at two damping
 * ratios, every transition time to TIME_FACTOR * rtol. */
static void test_damped_single_block(void **state)
{
    (void)state;
    const double zetas[] = {0.1, 0.7};
    const double rtol = 1e-10, m = 1.0, k = 1e4, V = 1e-3, f_s = 0.6 * 9.81, f_d = 0.1 * 9.81;
    header();
    for (size_t z = 0; z < 2; ++z) {
        double c = 2.0 * zetas[z] * sqrt(k * m);
        damped_cycle cycle = damped_closed_form(m, k, c, V, f_s, f_d);
        for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
            scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, rtol, (*b)->name);
            spec.t_end = 3.0;
            bk_config *cfg = scene_config(&spec);
            cfg->model->blocks[0].damping = c;
            recorder r = {0};
            bk_run_stats stats;
            bk_error err = {0};
            int rc = run_recorded(cfg, &r, &stats, &err);
            if (rc != BK_OK)
                print_error("%s: %s\n", (*b)->name, err.message);
            assert_int_equal(rc, BK_OK);
            assert_false(r.time_decreased);
            assert_true(r.n_transitions >= 4);
            double worst = 0.0, period = cycle.slip_time + cycle.stuck_time;
            for (size_t j = 0; j < r.n_transitions; ++j) {
                size_t n_cycle = j / 2;
                int breakaway = j % 2 == 0;
                double t = cycle.t_first + (double)n_cycle * period + (breakaway ? 0.0 : cycle.slip_time);
                assert_int_equal(r.transitions[j].to, breakaway ? BK_MODE_SLIP_POS : BK_MODE_STICK);
                worst = fmax(worst, fabs(r.transitions[j].t - t) / t);
                if (!breakaway)
                    assert_close(r.transitions[j].x, (double)(n_cycle + 1) * cycle.slip, 1e3 * rtol, 0);
            }
            row((*b)->name, zetas[z] < 0.5 ? "zeta.1" : "zeta.7", rtol, &stats, "dt/t", worst);
            assert_true(worst <= DAMPED_TIME_FACTOR * rtol);
            /* The dashpots' share of the energy audit: work = dE + friction + dashpots. */
            assert_true(stats.damping_dissipation > 0.0);
            assert_true(fabs(stats.energy_residual) <= ENERGY_FACTOR * rtol);
            recorder_free(&r);
            bk_config_free(cfg);
        }
    }
}

/* --- a driver history against the closed form, piece by piece -------------------------- */

/* The paper's case A block under velocities V_j for durations d_j (linear spring).  In each
 * segment the driver is a line, so a slipping block's deviation u = x - (D(t) - F_d / k)
 * rings at w about it and the slip ends where V_j + u' first reaches zero; at a breakpoint
 * x and v carry over and only the line changes; a stuck block breaks away where k (D - x)
 * reaches F_s, or rests through the segment (a hold).  Transition times into out. */
#define HISTORY_SEGMENTS 4
static size_t history_closed_form(const double *velocities, const double *durations, double t_end,
                                  double *out, size_t cap)
{
    const double m = 1.0, k = 1e4, f_s = 0.6 * 9.81, f_d = 0.1 * 9.81, w = sqrt(k / m);
    double t = 0.0, x = 0.0, v = 0.0, seg_start = 0.0, d_start = 0.0;
    int slipping = 0;
    size_t n = 0;
    for (size_t j = 0; j < HISTORY_SEGMENTS && t < t_end; ++j) {
        double V = velocities[j], seg_end = fmin(seg_start + durations[j], t_end);
        while (t < seg_end) {
            double D = d_start + V * (t - seg_start);
            if (!slipping) {
                double t_break = V > 0.0 ? seg_start + (x + f_s / k - d_start) / V : INFINITY;
                if (t_break >= seg_end) {
                    t = seg_end;
                    break;
                }
                t = fmax(t_break, t);
                slipping = 1;
                v = 0.0;
                assert_true(n < cap);
                out[n++] = t;
                continue;
            }
            double u0 = x - D + f_d / k, du0 = v - V;
            /* The first zero of V + u'(tau) = V - u0 w sin(w tau) + du0 cos(w tau) after t. */
            double h = 1e-3 / w, lo = 0.0, hi = h, stop = INFINITY;
            while (t + lo < seg_end) {
                if (V - u0 * w * sin(w * hi) + du0 * cos(w * hi) <= 0.0) {
                    for (int it = 0; it < 200; ++it) {
                        double mid = 0.5 * (lo + hi);
                        if (V - u0 * w * sin(w * mid) + du0 * cos(w * mid) > 0.0)
                            lo = mid;
                        else
                            hi = mid;
                    }
                    stop = t + 0.5 * (lo + hi);
                    break;
                }
                lo = hi;
                hi += h;
            }
            double tau = (stop < seg_end ? stop : seg_end) - t;
            x = d_start + V * (t + tau - seg_start) - f_d / k + u0 * cos(w * tau) + du0 / w * sin(w * tau);
            v = V - u0 * w * sin(w * tau) + du0 * cos(w * tau);
            t += tau;
            if (stop < seg_end) {
                slipping = 0;
                v = 0.0;
                assert_true(n < cap);
                out[n++] = t;
            }
        }
        d_start += V * durations[j];
        seg_start += durations[j];
    }
    return n;
}

/* A velocity step inside the first slip, a hold, and a faster slide: every back-end's
 * transitions at the closed-form times (the exact stepper restarts on each segment's line,
 * to 1e-12 relative), nothing integrated through the hold, the driver row continuous. */
static void test_driver_history(void **state)
{
    (void)state;
    const double velocities[HISTORY_SEGMENTS] = {1e-3, 2e-3, 0.0, 3e-3};
    const double durations[HISTORY_SEGMENTS] = {0.6, 0.6, 0.5, 1.0};
    const double t_end = 2.7, rtol = 1e-10;
    double expected[64];
    size_t n_expected = history_closed_form(velocities, durations, t_end, expected, 64);
    assert_true(n_expected >= 8);
    /* The step at 0.6 s falls inside the first slip (0.5886 s to about 0.62 s). */
    assert_true(expected[0] < 0.6 && expected[1] > 0.6);
    header();
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, rtol, (*b)->name);
        spec.t_end = t_end;
        bk_config *c = scene_config(&spec);
        assert_int_equal(bk_driver_set_history(&c->model->driver, velocities, durations, HISTORY_SEGMENTS), 0);
        recorder r = {0};
        bk_run_stats stats;
        run_config(c, &r, &stats);
        assert_int_equal(r.n_transitions, n_expected);
        double worst = 0.0;
        for (size_t j = 0; j < n_expected; ++j) {
            assert_int_equal(r.transitions[j].to, j % 2 == 0 ? BK_MODE_SLIP_POS : BK_MODE_STICK);
            worst = fmax(worst, fabs(r.transitions[j].t - expected[j]) / expected[j]);
        }
        row((*b)->name, "history", rtol, &stats, "dt/t", worst);
        double bound = strcmp((*b)->name, "exact") == 0 ? 1e-12 : TIME_FACTOR * rtol;
        assert_true(worst <= bound);
        /* The hold (1.2 s to 1.7 s) passes with every block stuck: one closed-form jump. */
        assert_true(stats.stuck_jumps >= 1);
        assert_true(fabs(stats.energy_residual) <= ENERGY_FACTOR * rtol);
        recorder_free(&r);
        bk_config_free(c);
    }
}

/* A 10-block chain (coupled, asymmetric start, mixed mu_d): driver work = elastic +
 * kinetic energy change + dissipation, to ENERGY_FACTOR * rtol; every back-end with a
 * dense linear solver, and the implicit ones with a band solver too (the analytic Jacobian
 * keeps the energy quadratures' rows, which depend on every block, out of the band; a
 * band difference-quotient Jacobian would spill them into it: README, Solver back-ends). */
static void chain_energy(const char *method, const char *linear_solver, int damped)
{
    const double rtol = 1e-8;
    {
        scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, rtol, method);
        spec.n = 10;
        spec.coupling = 2e4;
        spec.t_end = damped ? 1.5 : 3.0;
        /* Damped: fixed ends, so the coupling dashpots pull on walls too. */
        if (damped)
            spec.boundary = BK_BOUNDARY_FIXED;
        bk_config *c = scene_config(&spec);
        snprintf(c->solver.linear_solver, sizeof c->solver.linear_solver, "%s", linear_solver);
        heterogenise(c, 0.0);
        if (damped) {
            for (size_t i = 0; i < spec.n; ++i)
                c->model->blocks[i].damping = 2.0 + 0.5 * (double)(i % 3);
            c->model->coupling_damping = 6.0;
        }
        recorder r = {0};
        bk_run_stats stats;
        run_config(c, &r, &stats);
        row(method, damped ? "damped10" : linear_solver[0] == 'b' ? "chain10b" : "chain10", rtol, &stats,
            "energy", fabs(stats.energy_residual));
        assert_true(r.n_transitions > 2 * spec.n);
        assert_true(stats.work_driver > 0.0);
        /* The dashpots take a share the audit must count: without it the residual would be
         * that share over the work. */
        if (damped)
            assert_true(stats.damping_dissipation > 1e3 * ENERGY_FACTOR * rtol * stats.work_driver);
        assert_true(fabs(stats.energy_residual) <= ENERGY_FACTOR * rtol);
        recorder_free(&r);
        bk_config_free(c);
    }
}

static void test_chain_energy(void **state)
{
    (void)state;
    header();
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b)
        chain_energy((*b)->name, "dense", 0);
    for (size_t k = 0; k < N_BAND_BACKENDS; ++k)
        chain_energy(band_backends[k], "band", 0);
    /* Dashpots to the substrate and beside the coupling springs; these differ from block
     * to block, out of proportion with the masses and springs (the exact stepper's coupled
     * modes, tests/test_exact_damped.c). */
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b)
        chain_energy((*b)->name, "dense", 1);
    chain_energy("ida", "band", 1);
}

/* Every Butcher table [solver] arkode_table offers, through arkode_erk or arkode_dirk:
 * case A's transitions at the closed-form times to TIME_FACTOR * rtol. */
static void test_arkode_tables(void **state)
{
    (void)state;
    exact_solution ex;
    exact_case(0.1, BK_SPRING_LINEAR, &ex);
    header();
    size_t tables = 0;
    for (size_t i = 1; bk_solver_arkode_table(i); ++i, ++tables) {
        const char *name = bk_solver_arkode_table(i);
        bk_solver_options options = {.arkode_table = ""};
        snprintf(options.arkode_table, sizeof options.arkode_table, "%s", name);
        char message[1024];
        const char *method = bk_solver_arkode_erk.check_options(&options, message, sizeof message) == 0
                                 ? "arkode_erk"
                                 : "arkode_dirk";
        assert_int_equal(bk_solver_backend_find(method)->check_options(&options, message, sizeof message), 0);
        scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, 1e-7, method);
        bk_config *c = scene_config(&spec);
        c->solver.arkode_table[0] = '\0';
        strncat(c->solver.arkode_table, name, sizeof c->solver.arkode_table - 1);
        recorder r = {0};
        bk_run_stats stats;
        run_config(c, &r, &stats);
        assert_int_equal(r.n_transitions, ex.n_events);
        double worst = 0.0;
        for (size_t k = 0; k < ex.n_events; ++k)
            worst = fmax(worst, fabs(r.transitions[k].t - ex.events[k].t) / ex.events[k].t);
        print_message("%-12s %-30s %7ld %8ld  dt/t %.2e\n", method, name, stats.steps, stats.rhs_evals, worst);
        assert_true(worst <= TIME_FACTOR * spec.rtol);
        recorder_free(&r);
        bk_config_free(c);
    }
    assert_int_equal(tables, 14 + 23);
    exact_free(&ex);
}

/* --- ida's algebraic formulation on the chain configs ---------------------------------- */

/* Watches stuck blocks in the rows: in ida's full layout a stuck block's x and v are read
 * back from IDA's state, where v = 0 is an algebraic row. */
typedef struct stuck_watch {
    recorder transitions;
    size_t n;
    double x_seen[16];         /* m, position in the first row of the current stuck spell */
    long transitions_seen[16]; /* the block's transition count at that row, -1: slipping */
    long transitions_of[16];   /* transitions of the block so far */
    long stuck_rows, moving_rows; /* rows with a stuck block, those where its v != 0 */
    double drift;                 /* m, largest move of a stuck block between two rows */
} stuck_watch;

static int watch_sample(void *self, const bk_sample *s, bk_error *err)
{
    stuck_watch *w = self;
    for (size_t i = 0; i < s->n_blocks; ++i) {
        if (s->mode[i] != BK_MODE_STICK) {
            w->transitions_seen[i] = -1;
            continue;
        }
        w->stuck_rows++;
        if (s->v[i] != 0.0)
            w->moving_rows++;
        if (w->transitions_seen[i] == w->transitions_of[i]) {
            w->drift = fmax(w->drift, fabs(s->x[i] - w->x_seen[i]));
        } else { /* the first row of this stuck spell */
            w->x_seen[i] = s->x[i];
            w->transitions_seen[i] = w->transitions_of[i];
        }
    }
    return record_sample(&w->transitions, s, err);
}

static int watch_transition(void *self, const bk_transition *t, bk_error *err)
{
    stuck_watch *w = self;
    w->transitions_of[t->block]++;
    return record_transition(&w->transitions, t, err);
}

static void run_chain(const char *path, const char *method, double t_end, double rtol,
                      stuck_watch *w, bk_run_stats *stats)
{
    char set_method[64], set_t_end[64], set_rtol[64];
    snprintf(set_method, sizeof set_method, "solver.method=%s", method);
    snprintf(set_t_end, sizeof set_t_end, "run.t_end=%g", t_end);
    snprintf(set_rtol, sizeof set_rtol, "solver.rtol=%g", rtol);
    const char *overrides[] = {set_method, set_t_end, set_rtol, "run.wall_time_limit=60"};
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_file(path, overrides, 4, &c, &err), BK_OK);
    assert_true(c->model->n_blocks <= 16);
    memset(w, 0, sizeof *w);
    w->n = c->model->n_blocks;
    for (size_t i = 0; i < w->n; ++i)
        w->transitions_seen[i] = -1; /* no position seen yet */
    bk_sink sink = {.self = w, .sample = watch_sample, .transition = watch_transition};
    int rc = bk_run(c, &sink, stats, NULL, NULL, &err);
    if (rc != BK_OK)
        print_error("%s %s: %s\n", path, method, err.message);
    assert_int_equal(rc, BK_OK);
    assert_false(w->transitions.time_decreased);
    bk_config_free(c);
}

/* ida against cvode_adams on a chain at rtol 1e-8 and 1e-10: the same transitions (block,
 * from, to) in the same order, times within time_factor * rtol seconds and closer at the
 * tighter rtol; in every ida row a stuck block has v exactly 0 (IDA's state: the scene
 * reads it back in the full layout) and stays put; the energy balance holds to
 * ENERGY_FACTOR * rtol.  Windows end before the chains' sensitive
 * dependence lets the back-ends' event sequences part (two_block near 2.7 s, bk10 near
 * 1.7 s at rtol 1e-10).  Measured worst |dt| at 1e-8, 1e-10: two_block (2.5 s, 56
 * transitions) 1.1e-5 s, 3.0e-7 s; bk10 (1 s, 105 transitions) 3.0e-7 s, 3.0e-9 s. */
static void check_ida_chain(const char *path, double t_end, double time_factor)
{
    const double rtols[2] = {1e-8, 1e-10};
    double worst[2] = {0.0, 0.0};
    header();
    for (size_t r = 0; r < 2; ++r) {
        stuck_watch ida, reference;
        bk_run_stats ida_stats, reference_stats;
        run_chain(path, "ida", t_end, rtols[r], &ida, &ida_stats);
        run_chain(path, "cvode_adams", t_end, rtols[r], &reference, &reference_stats);
        assert_true(reference.transitions.n_transitions > 2 * reference.n);
        worst[r] = transition_gap(&ida.transitions, &reference.transitions, "ida");
        row("ida", path + strlen("configs/chains/"), rtols[r], &ida_stats, "dt s", worst[r]);
        assert_true(worst[r] <= time_factor * rtols[r]);
        print_message("%ld rows with a stuck block; its largest drift %.3g m\n", ida.stuck_rows, ida.drift);
        assert_true(ida.stuck_rows > 0);
        assert_int_equal(ida.moving_rows, 0);
        /* Its position moves only by the roundoff of IDA's Newton solve, which couples it to
         * the slipping neighbours (measured 2.2e-27 m on bk10 at 1e-8, where atol_x is
         * 1.2e-15 m; 0 elsewhere). */
        assert_true(ida.drift <= 1e-20);
        assert_true(fabs(ida_stats.energy_residual) <= ENERGY_FACTOR * rtols[r]);
        recorder_free(&ida.transitions);
        recorder_free(&reference.transitions);
    }
    assert_true(worst[1] < 0.1 * worst[0]);
}

static void test_ida_two_block_chain(void **state)
{
    (void)state;
    check_ida_chain("configs/chains/two_block_coulomb.ini", 2.5, 1e4);
}

static void test_ida_ten_block_chain(void **state)
{
    (void)state;
    check_ida_chain("configs/chains/bk10_coulomb.ini", 1.0, 300.0);
}

/* --- the interface's root conventions, without the run loop ---------------------------- */

static const double omega = 2.385;

static int oscillator(double t, const double *y, double *ydot, void *user)
{
    (void)t;
    (void)user;
    ydot[0] = y[1];
    ydot[1] = -omega * omega * y[0];
    return 0;
}

/* y0 = cos(w t), y1 = -w sin(w t). */
static int five_roots(double t, const double *y, double *g, void *user)
{
    (void)t;
    (void)user;
    g[0] = y[0] - 0.5;         /* falling only: at w t = pi/3 (and not at 5 pi/3) */
    g[1] = y[0];               /* rising only: at 3 pi/2, not at pi/2 */
    g[2] = y[1];               /* exactly 0 at the start: inactive until non-zero; rises at pi */
    g[3] = 2.0 * (y[0] - 0.5); /* the same instant as g[0]: reported together */
    g[4] = y[0] - 0.49;        /* falling 0.0115 / w later, in the same step */
    return 0;
}

/* Every back-end, stepping on after each root without a restart (as CVODE allows): the
 * roots in order, directions honoured, a function zero at the start inactive, two
 * functions crossing together reported together, a second root later in the same step
 * found on the next call, max_step respected, state at each root just past the crossing. */
static void test_root_conventions(void **state)
{
    (void)state;
    const double PI = 3.14159265358979323846;
    const struct { double wt; int found[5]; } expected[] = {
        {PI / 3.0, {-1, 0, 0, -1, 0}},
        {acos(0.49), {0, 0, 0, 0, -1}},
        {PI, {0, 0, +1, 0, 0}},
        {1.5 * PI, {0, +1, 0, 0, 0}},
    };
    const size_t n_expected = sizeof expected / sizeof *expected;
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        bk_solver_options o;
        memset(&o, 0, sizeof o);
        o.rtol = 1e-10;
        o.max_step = 0.05;
        o.max_steps = 100000;
        snprintf(o.linear_solver, sizeof o.linear_solver, "dense");
        void *mem = NULL;
        bk_error err = {0};
        assert_int_equal((*b)->create(&mem, &o, &err), BK_OK);
        const int direction[5] = {-1, +1, 0, -1, -1};
        static const double unit_mass[1] = {1.0};
        bk_ode_problem p = {.rhs = oscillator, .roots = five_roots, .n_roots = 5,
                            .root_direction = direction, .half_bandwidth = 1,
                            .n_pairs = 1, .pair_mass = unit_mass, .affine = 1};
        double y0[2] = {1.0, 0.0}, atol[2] = {1e-14, 1e-14}, y[2], t = 0.0;
        double t_stop = 1.9 * PI / omega;
        assert_int_equal((*b)->start(mem, &p, 0.0, y0, atol, 2, t_stop, &err), BK_OK);
        size_t k = 0;
        int rc;
        while ((rc = (*b)->step(mem, &t, y, &err)) == BK_STEP_OK || rc == BK_STEP_ROOT) {
            double lo, hi;
            (*b)->last_step(mem, &lo, &hi);
            assert_true(hi - lo <= 0.05 * (1.0 + 1e-12));
            if (rc != BK_STEP_ROOT)
                continue;
            if (k >= n_expected)
                print_error("%s: unexpected root at w t = %.17g\n", (*b)->name, omega * t);
            assert_true(k < n_expected);
            assert_close(omega * t, expected[k].wt, 1e-9, 0.0);
            int found[5];
            assert_int_equal((*b)->root_info(mem, found), BK_OK);
            for (int j = 0; j < 5; ++j) {
                if (found[j] != expected[k].found[j])
                    print_error("%s: root %zu, function %d: found %d, expected %d\n", (*b)->name,
                                k, j, found[j], expected[k].found[j]);
                assert_int_equal(found[j], expected[k].found[j]);
            }
            /* Just past the crossing: the crossed function has changed sign already. */
            double g[5];
            five_roots(t, y, g, NULL);
            for (int j = 0; j < 5; ++j)
                if (expected[k].found[j] != 0)
                    assert_true((double)expected[k].found[j] * g[j] >= 0.0);
            ++k;
        }
        if (rc < 0)
            print_error("%s: %s\n", (*b)->name, err.message);
        assert_int_equal(rc, BK_STEP_STOP);
        assert_int_equal(k, n_expected);
        assert_true(t == t_stop);
        (*b)->destroy(mem);
    }
}

/* Output rows come from each back-end's output-row dense output (sample, else interpolate)
 * at no cost in steps; stepped sampling would end a step at the row's time instead.  Every
 * back-end, on the oscillator with steps as long as rtol = 1e-8 allows: at 1/8 .. 7/8 of
 * every step, the row's value and that of a fresh integration from the step's start to the
 * row's time (stepped sampling), both against the exact solution.  The rows' worst error
 * must stay within SAMPLE_FACTOR times stepped sampling's worst, plus one tolerance unit
 * (the exact stepper's errors are rounding).  Measured (printed): 0.94 - 1.01 for every
 * back-end; a cubic Hermite polynomial on gsl_rk8pd's steps, the obvious cheap choice,
 * gives far more. */
#define SAMPLE_FACTOR 1.5

static int run_to(const bk_solver_backend *b, void *mem, const bk_ode_problem *p, double t0,
                  const double *y0, const double *atol, double t, double *y, bk_error *err)
{
    int rc = b->start(mem, p, t0, y0, atol, 2, t, err);
    double reached = t0;
    while (rc == BK_STEP_OK) /* BK_OK from start is BK_STEP_OK too */
        rc = b->step(mem, &reached, y, err);
    return rc == BK_STEP_STOP && reached == t ? BK_OK : -1;
}

static void test_samples_match_stepped(void **state)
{
    (void)state;
    const double rtol = 1e-8, abs_tol = 1e-12;
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        bk_solver_options o;
        memset(&o, 0, sizeof o);
        o.rtol = rtol;
        o.max_steps = 100000;
        snprintf(o.linear_solver, sizeof o.linear_solver, "dense");
        void *mem = NULL, *fresh = NULL;
        bk_error err = {0};
        assert_int_equal((*b)->create(&mem, &o, &err), BK_OK);
        assert_int_equal((*b)->create(&fresh, &o, &err), BK_OK);
        static const double unit_mass[1] = {1.0};
        bk_ode_problem p = {.rhs = oscillator, .half_bandwidth = 1, .n_pairs = 1,
                            .pair_mass = unit_mass, .affine = 1};
        double y0[2] = {1.0, 0.0}, atol[2] = {abs_tol, abs_tol}, y[2], lo_y[2], t = 0.0;
        double t_stop = 6.0 * 3.14159265358979323846 / omega, worst_row = 0.0, worst_stepped = 0.0;
        assert_int_equal((*b)->start(mem, &p, 0.0, y0, atol, 2, t_stop, &err), BK_OK);
        memcpy(lo_y, y0, sizeof lo_y);
        int rc;
        size_t rows = 0;
        while ((rc = (*b)->step(mem, &t, y, &err)) == BK_STEP_OK || rc == BK_STEP_STOP) {
            double lo, hi;
            (*b)->last_step(mem, &lo, &hi);
            for (int j = 1; j < 8; ++j) {
                double ts = lo + (hi - lo) * j / 8.0, dense[2] = {0.0, 0.0}, stepped[2] = {0.0, 0.0};
                assert_int_equal(((*b)->sample ? (*b)->sample : (*b)->interpolate)(mem, ts, dense, &err),
                                 BK_OK);
                assert_int_equal(run_to(*b, fresh, &p, lo, lo_y, atol, ts, stepped, &err), BK_OK);
                const double exact[2] = {cos(omega * ts), -omega * sin(omega * ts)};
                for (int i = 0; i < 2; ++i) {
                    worst_row = fmax(worst_row, fabs(dense[i] - exact[i]));
                    worst_stepped = fmax(worst_stepped, fabs(stepped[i] - exact[i]));
                }
                rows++;
            }
            memcpy(lo_y, y, sizeof lo_y);
            if (rc == BK_STEP_STOP)
                break;
        }
        if (rc < 0)
            print_error("%s: %s\n", (*b)->name, err.message);
        assert_int_equal(rc, BK_STEP_STOP);
        print_message("%-12s %5zu rows: worst error %.3e, stepped sampling's %.3e (ratio %.2f)\n",
                      (*b)->name, rows, worst_row, worst_stepped, worst_row / worst_stepped);
        assert_true(worst_row <= SAMPLE_FACTOR * worst_stepped + abs_tol + rtol);
        (*b)->destroy(mem);
        (*b)->destroy(fresh);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_root_conventions),
        cmocka_unit_test(test_samples_match_stepped),
        cmocka_unit_test(test_cases_a_b),
        cmocka_unit_test(test_case_c),
        cmocka_unit_test(test_uniform_lattice),
        cmocka_unit_test(test_heterogeneous_lattice),
        cmocka_unit_test(test_damped_single_block),
        cmocka_unit_test(test_driver_history),
        cmocka_unit_test(test_chain_energy),
        cmocka_unit_test(test_arkode_tables),
        cmocka_unit_test(test_ida_two_block_chain),
        cmocka_unit_test(test_ida_ten_block_chain),
    };
    return cmocka_run_group_tests_name("backends", tests, NULL, NULL);
}
