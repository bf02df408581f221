/* Stability at the extremes: every back-end on extreme scenes, each under a wall-clock limit
 * (a hang fails the test).  Every back-end must give the correct result (checked against the
 * closed form where one exists, else a converged reference); the only refusal allowed is the
 * exact stepper's, of non-affine scenes, with its message.  Prints the back-end x extreme
 * table the README's "extremes" section is made from. */
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "exact_single.h"
#include "recorder.h"

typedef struct extreme {
    const char *name;
    const char *text;  /* config; the method comes as an override */
    int coulomb_single;         /* compare with the closed form */
    double mass, k, mu_d, velocity;
} extreme;

#define SINGLE(mass, k, mu_d, v, t_end, interval)                                                \
    "[model]\nn_blocks = 1\n[block]\nmass = " #mass "\ndriver_stiffness = " #k "\n"              \
    "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = " #mu_d "\n[driver]\nvelocity = " #v "\n"      \
    "[solver]\nrtol = 1e-8\n[output]\ninterval = " #interval "\n[run]\nt_end = " #t_end "\n"

/* The paper's case B single block under its rate-and-state law, with extra friction keys. */
#define RATE_STATE(extra)                                                                        \
    "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n[friction]\n"             \
    "law = rate_state\nmu_s = 0.6\nmu_d = 0.5\n" extra "[driver]\nvelocity = 1e-3\n"             \
    "[solver]\nrtol = 1e-8\n[output]\ninterval = 1e-3\n[run]\nt_end = 1\n"

static const extreme extremes[] = {
    {"mu_d = 0.5999 (case C)", SINGLE(1, 1e4, 0.5999, 1e-3, 2, 1e-3), 1, 1, 1e4, 0.5999, 1e-3},
    {"mu_d = 0.599999", SINGLE(1, 1e4, 0.599999, 1e-3, 2, 1e-3), 1, 1, 1e4, 0.599999, 1e-3},
    {"k = 1e9 N/m", SINGLE(1, 1e9, 0.5, 1e-3, 0.01, 1e-5), 1, 1, 1e9, 0.5, 1e-3},
    {"k = 1 N/m", SINGLE(1, 1, 0.5, 1e-3, 1.5e4, 10), 1, 1, 1, 0.5, 1e-3},
    {"m = 1e-6 kg", SINGLE(1e-6, 1e4, 0.5, 1e-3, 0.005, 1e-6), 1, 1e-6, 1e4, 0.5, 1e-3},
    {"V = 1e-9 m/s", SINGLE(1, 1e4, 0.5, 1e-9, 2e6, 1e3), 1, 1, 1e4, 0.5, 1e-9},
    {"V = 1 m/s", SINGLE(1, 1e4, 0.5, 1, 0.5, 1e-4), 1, 1, 1e4, 0.5, 1},
    {"rate-state 1/m = 1000 (paper)", RATE_STATE("m = 1e-3\n"), 0, 0, 0, 0, 0},
    {"rate-state 1/m = 10000", RATE_STATE("m = 1e-4\n"), 0, 0, 0, 0, 0},
    {"rate-state L0 = 2e-7 m", RATE_STATE("L0 = 2e-7\n"), 0, 0, 0, 0, 0},
};

#define WALL_LIMIT 2.0 /* s per run (a hang guard: the slowest cell takes ~0.2 s alone, more on a loaded machine); $BK_TEST_TIME_SCALE stretches it under sanitizers/valgrind */
#define RTOL 1e-8

static double scaled_wall_limit(void)
{
    const char *scale = getenv("BK_TEST_TIME_SCALE");
    double factor = scale ? strtod(scale, NULL) : 1.0;
    return WALL_LIMIT * (factor >= 1.0 ? factor : 1.0);
}

/* With exact: its parameters solved to the scene's t_end, and r tracking the distance from it. */
static int run_scene(const char *text, const char *method, double rtol, double wall_limit, exact_solution *exact,
                     recorder *r, bk_run_stats *stats, bk_error *err)
{
    char set_method[64], set_rtol[64];
    snprintf(set_method, sizeof set_method, "solver.method=%s", method);
    snprintf(set_rtol, sizeof set_rtol, "solver.rtol=%g", rtol);
    const char *overrides[] = {set_method, set_rtol};
    bk_config *c = NULL;
    int rc = bk_config_load_string(text, "extreme.ini", overrides, 2, &c, err);
    if (rc != BK_OK)
        return rc;
    c->wall_time_limit = wall_limit;
    if (exact) {
        assert_int_equal(exact_solve(&exact->p, c->t_end, exact), 0);
        r->exact = exact;
    }
    rc = run_recorded(c, r, stats, err);
    bk_config_free(c);
    assert_false(r->non_finite);
    return rc;
}

/* Coulomb: against the closed form.  Breakaways are well conditioned, so each must sit
 * within 1e-5 of the exact cycle times.  A stop that grazes zero velocity for less than a
 * step is invisible at this rtol; missing it is a position error far below the stick-slip
 * amplitude (the force drop over the stiffness) and is reported as ok*, whereas a block
 * that slid through a real stick would be off by the amplitude itself.  At mu_d = 0.599999
 * the amplitude (2 nm) is below what rtol resolves on the distance slid, hence the floor. */
static const char *judge_coulomb(const extreme *e, const recorder *r, char *detail, size_t len)
{
    const exact_solution *ex = r->exact;
    /* Every breakaway the run reports must be one of the exact ones, in order, even when
     * grazing stops (and the breakaways after them) were missed. */
    double worst_t = 0.0;
    size_t next = 0, breakaways = 0;
    for (size_t k = 0; k < r->n_transitions; ++k) {
        if (r->transitions[k].from != BK_MODE_STICK)
            continue;
        ++breakaways;
        double t = r->transitions[k].t;
        while (next < ex->n_events && (ex->events[next].from != BK_MODE_STICK || ex->events[next].t < t * (1.0 - 1e-5)))
            ++next; /* stops, and breakaways the run skipped by sliding through a grazing stop */
        worst_t = fmax(worst_t, next < ex->n_events ? fabs(t - ex->events[next].t) / ex->events[next].t : INFINITY);
        ++next;
    }
    assert_true(breakaways > 0);
    double amplitude = 2.0 * (0.6 - e->mu_d) * e->mass * 9.81 / e->k;
    double rtol_floor = 10.0 * RTOL * e->velocity * ex->phases[ex->n_phases - 1].t0;
    snprintf(detail, len, "%zu/%zu transitions, breakaway time error %.1e, position error %.1e of the amplitude",
             r->n_transitions, ex->n_events, worst_t, r->max_position_error_regular / amplitude);
    if (!(worst_t < 1e-5 && r->max_position_error_regular < 0.05 * amplitude + rtol_floor))
        print_message("%s: %s\n", e->name, detail);
    assert_true(worst_t < 1e-5);
    assert_true(r->max_position_error_regular < 0.05 * amplitude + rtol_floor);
    /* Missing stops is only excusable where every stop grazes (mu_s - mu_d = 1e-6). */
    if (r->n_transitions != ex->n_events)
        assert_true(0.6 - e->mu_d < 1e-5);
    return r->n_transitions == ex->n_events ? "ok" : "ok*";
}

/* Rate-and-state: against cvode_bdf converged at rtol 1e-11, transition by transition. */
static const char *judge_reference(const extreme *e, const recorder *r, const recorder *reference,
                                   const bk_run_stats *stats, char *detail, size_t len)
{
    double worst_t = 0.0;
    int same_count = r->n_transitions == reference->n_transitions;
    for (size_t k = 0; same_count && k < r->n_transitions; ++k)
        worst_t = fmax(worst_t, fabs(r->transitions[k].t - reference->transitions[k].t) / reference->transitions[k].t);
    snprintf(detail, len, "%zu/%zu transitions, time error %.1e, energy residual %.1e", r->n_transitions,
             reference->n_transitions, worst_t, stats->energy_residual);
    if (!(same_count && worst_t < 1e-5 && fabs(stats->energy_residual) < 1e-6))
        print_message("%s: %s\n", e->name, detail);
    assert_int_equal(r->n_transitions, reference->n_transitions);
    assert_true(worst_t < 1e-5);
    assert_true(fabs(stats->energy_residual) < 1e-6);
    return "ok";
}

/* One table cell: the verdict and the right-hand-side evaluations it took (the cost). */
static void outcome(const extreme *e, const char *method, const recorder *reference, char *cell, size_t cell_len)
{
    recorder r = {0};
    exact_solution ex = {.p = {e->mass, e->k, e->mass * 9.81, 0.6, e->mu_d, e->velocity, 0}};
    bk_run_stats stats = {0};
    bk_error err = {0};
    char detail[BK_ERROR_MESSAGE_LEN + 64];
    const char *verdict;
    int rc = run_scene(e->text, method, RTOL, scaled_wall_limit(), e->coulomb_single ? &ex : NULL, &r, &stats,
                       &err);
    if (rc != BK_OK) {
        /* The exact stepper refuses non-affine scenes at load time; nothing else may fail. */
        verdict = "n/a";
        snprintf(detail, sizeof detail, "%s", err.message);
        if (!(rc == BK_ERR_CONFIG && strcmp(method, "exact") == 0 && !e->coulomb_single))
            print_error("%s / %s: %s\n", e->name, method, err.message);
        assert_int_equal(rc, BK_ERR_CONFIG);
        assert_string_equal(method, "exact");
        assert_false(e->coulomb_single);
        assert_non_null(strstr(err.message, "needs Coulomb friction"));
    } else if (e->coulomb_single) {
        verdict = judge_coulomb(e, &r, detail, sizeof detail);
    } else {
        verdict = judge_reference(e, &r, reference, &stats, detail, sizeof detail);
    }
    if (rc == BK_OK)
        snprintf(cell, cell_len, "%s %ld", verdict, stats.rhs_evals);
    else
        snprintf(cell, cell_len, "%s", verdict);
    if (getenv("BK_EXTREMES_VERBOSE"))
        print_message("  %s / %s: %s\n", e->name, method, detail);
    exact_free(&ex);
    recorder_free(&r);
}

static void test_extremes(void **state)
{
    (void)state;
    char header[1024] = "| extreme |";
    for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
        strcat(header, " ");
        strcat(header, (*b)->name);
        strcat(header, " |");
    }
    print_message("%s\n", header);
    for (size_t k = 0; k < sizeof extremes / sizeof extremes[0]; ++k) {
        recorder reference = {0};
        if (!extremes[k].coulomb_single) {
            bk_error err = {0};
            assert_int_equal(run_scene(extremes[k].text, "cvode_bdf", 1e-11, 600.0, NULL, &reference, NULL, &err),
                             BK_OK);
        }
        char line[1024];
        snprintf(line, sizeof line, "| %s |", extremes[k].name);
        for (const bk_solver_backend *const *b = bk_solver_backends(); *b; ++b) {
            char cell[64];
            outcome(&extremes[k], (*b)->name, &reference, cell, sizeof cell);
            strcat(line, " ");
            strcat(line, cell);
            strcat(line, " |");
        }
        print_message("%s\n", line);
        recorder_free(&reference);
    }
}

/* 1e4 stick-slip cycles.  The exact solution's phase is neutral: a timing error made in one
 * cycle is carried, not damped, so an integrator's transition times drift by about
 * rtol x period per cycle, linearly in the number of cycles.  The exact stepper stays on
 * the closed form.  (Every back-end's drift is in the benchmark, `bksim_bench --long-run`.) */
static void test_long_run_phase(void **state)
{
    (void)state;
    const char *methods[] = {"exact", "cvode_adams", "gsl_rk8pd"};
    exact_params p = {1, 1e4, 9.81, 0.6, 0.5, 1e-3, 0};
    exact_solution ex;
    double t_end = 2300.0; /* ~1e4 cycles */
    assert_int_equal(exact_solve(&p, t_end, &ex), 0);
    size_t cycles = ex.n_events / 2;
    assert_true(cycles >= 10000);
    double period = ex.events[3].t - ex.events[1].t;
    const size_t window = 100; /* cycles compared at each end */
    for (size_t m = 0; m < sizeof methods / sizeof methods[0]; ++m) {
        char set_method[64];
        snprintf(set_method, sizeof set_method, "solver.method=%s", methods[m]);
        const char *overrides[] = {set_method};
        bk_config *c = NULL;
        bk_error err = {0};
        assert_int_equal(bk_config_load_string(SINGLE(1, 1e4, 0.5, 1e-3, 2300, 0), "long.ini", overrides, 1, &c, &err), BK_OK);
        recorder r = {0};
        assert_int_equal(run_recorded(c, &r, NULL, &err), BK_OK);
        assert_int_equal(r.n_transitions, ex.n_events);
        double early = 0.0, late = 0.0;
        for (size_t k = 0; k < r.n_transitions; ++k) {
            double e = fabs(r.transitions[k].t - ex.events[k].t);
            if (k < 2 * window)
                early = fmax(early, e);
            else if (k + 2 * window >= r.n_transitions)
                late = fmax(late, e);
        }
        print_message("%s: %zu cycles, phase error %.2g s over the first %zu cycles, %.2g s over the last "
                      "(rtol x period x cycles = %.2g s)\n",
                      methods[m], cycles, early, window, late, RTOL * period * (double)cycles);
        if (m == 0) {
            assert_true(late < 1e-12 * t_end);
        } else {
            /* Linear drift: within a few rtol x period per cycle, and growing no faster than
             * the cycle count (quadratic growth would make late / early ~ 1e4). */
            assert_true(early < 10.0 * RTOL * period * (double)window);
            assert_true(late < 10.0 * RTOL * period * (double)cycles);
            assert_true(late < 3.0 * (double)cycles / (double)window * fmax(early, 1e-3 * RTOL * period));
        }
        recorder_free(&r);
        bk_config_free(c);
    }
    exact_free(&ex);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_extremes),
        cmocka_unit_test(test_long_run_phase),
    };
    return cmocka_run_group_tests_name("extremes", tests, NULL, NULL);
}
