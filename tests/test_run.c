/* The run loop against exact answers: the Coulomb single block (paper cases A, B, C, both
 * spring variants) against its closed form, the hidden-stop and re-fire traps, energy
 * balance of chains, simultaneous transitions, and the chattering guard. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "exact_single.h"
#include "recorder.h"
#include "scene_spec.h"

/* --- the Coulomb single block against its closed form ---------------------------------- */

static void compare_with_exact(double mu_d, bk_spring spring)
{
    scene_spec spec = paper_case(mu_d, spring, 1e-10, "cvode_adams");
    exact_params p = {1.0, 1e4, 9.81, 0.6, mu_d, 1e-3, spring == BK_SPRING_TENSION_ONLY};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, spec.t_end, &ex), 0);
    recorder r = {0};
    r.exact = &ex;
    bk_run_stats stats;
    bk_error err = {0};
    assert_int_equal(run_spec(&spec, &r, &stats, &err), BK_OK);
    assert_int_equal(r.n_transitions, ex.n_events);
    assert_false(r.time_decreased);

    /* First slip: mu_s m g / (k V) = 0.5886 s. */
    assert_close(r.transitions[0].t, 0.5886, 1e-14, 0.0);
    assert_close(r.transitions[0].t, ex.events[0].t, 1e-14, 0.0);

    /* Every phase: slip durations and distances, stick durations, and each full cycle
     * (breakaway to breakaway). */
    double accel_at_stop = (0.6 - mu_d) * 9.81; /* A w = (mu_s - mu_d) g at a slip end, m/s^2 */
    for (size_t k = 0; k + 1 < ex.n_events; ++k) {
        assert_int_equal(r.transitions[k].from, ex.events[k].from);
        assert_int_equal(r.transitions[k].to, ex.events[k].to);
        double duration = r.transitions[k + 1].t - r.transitions[k].t;
        double exact_duration = ex.events[k + 1].t - ex.events[k].t;
        if (ex.events[k].to != BK_MODE_STICK) {
            double slip = r.transitions[k + 1].x - r.transitions[k].x;
            double exact_slip = ex.events[k + 1].x - ex.events[k].x;
            assert_close(slip, exact_slip, 1e-8, 0.0);
        } else {
            /* k is a stop; k - 1 and k + 1 are breakaways: one full cycle. */
            assert_close(r.transitions[k + 1].t - r.transitions[k - 1].t,
                         ex.events[k + 1].t - ex.events[k - 1].t, 1e-8, 0.0);
        }
        if (mu_d < 0.59) {
            assert_close(duration, exact_duration, 1e-8, 0.0);
        } else {
            /* Case C stops by grazing: v touches zero with a = -A w ~ -1e-3 m/s^2, so a
             * velocity error dv moves the stop by dv / (A w), about 1 s times the relative
             * velocity error.  Slips (63 ms) and sticks (0.2 ms) both start or end at such a
             * stop; they are held to that conditioning, the cycles above to 1e-8. */
            double bound = 100.0 * spec.rtol * spec.velocity / accel_at_stop;
            assert_close(duration, exact_duration, 0.0, bound);
        }
    }
    /* The time series follows the closed form everywhere (positions near an event move by
     * v dt with the event's tiny time error). */
    print_message("max position error %.3g m, energy residual %.3g\n", r.max_position_error,
                  stats.energy_residual);
    assert_true(r.max_position_error < 1e-7 * 0.6 * 9.81 / 1e4);
    assert_true(fabs(stats.energy_residual) < 1e-8);
    recorder_free(&r);
    exact_free(&ex);
}

static void test_case_a_linear(void **state)
{
    (void)state;
    compare_with_exact(0.1, BK_SPRING_LINEAR);
}
static void test_case_b_linear(void **state)
{
    (void)state;
    compare_with_exact(0.5, BK_SPRING_LINEAR);
}
static void test_case_c_linear(void **state)
{
    (void)state;
    compare_with_exact(0.5999, BK_SPRING_LINEAR);
}
static void test_case_a_tension_only(void **state)
{
    (void)state;
    compare_with_exact(0.1, BK_SPRING_TENSION_ONLY);
}
static void test_case_b_tension_only(void **state)
{
    (void)state;
    compare_with_exact(0.5, BK_SPRING_TENSION_ONLY);
}
static void test_case_c_tension_only(void **state)
{
    (void)state;
    compare_with_exact(0.5999, BK_SPRING_TENSION_ONLY);
}

/* The paper's case A numbers: first slip at 0.5886 s lasting 31.82 ms. */
static void test_case_a_paper_numbers(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, 1e-10, "cvode_adams");
    recorder r = {0};
    bk_error err = {0};
    assert_int_equal(run_spec(&spec, &r, NULL, &err), BK_OK);
    assert_true(r.n_transitions >= 2);
    assert_close(r.transitions[0].t, 0.5886, 1e-12, 0.0);
    double w = 100.0, V = 1e-3, A = (0.6 - 0.1) * 9.81 / 1e4 * w;
    double t_slip = 2.0 * (3.14159265358979323846 - atan(A / V)) / w;
    assert_close(r.transitions[1].t - r.transitions[0].t, t_slip, 1e-8, 0.0);
    assert_close(t_slip, 31.82e-3, 1e-3, 0.0);
    recorder_free(&r);
}

/* Position error falls as rtol tightens. */
static void test_error_shrinks_with_rtol(void **state)
{
    (void)state;
    const double mu_d[] = {0.1, 0.5};
    for (size_t c = 0; c < 2; ++c) {
        exact_params p = {1.0, 1e4, 9.81, 0.6, mu_d[c], 1e-3, 0};
        exact_solution ex;
        assert_int_equal(exact_solve(&p, 5.0, &ex), 0);
        double previous = INFINITY;
        const double rtols[] = {1e-5, 1e-7, 1e-9, 1e-11};
        for (size_t k = 0; k < 4; ++k) {
            scene_spec spec = paper_case(mu_d[c], BK_SPRING_LINEAR, rtols[k], "cvode_adams");
            recorder r = {0};
            r.exact = &ex;
            bk_error err = {0};
            assert_int_equal(run_spec(&spec, &r, NULL, &err), BK_OK);
            print_message("case mu_d=%g rtol %g: max position error %.3g m\n", mu_d[c], rtols[k],
                          r.max_position_error);
            assert_true(r.max_position_error < 0.5 * previous);
            previous = r.max_position_error;
            recorder_free(&r);
        }
        exact_free(&ex);
    }
}

/* Case C ends every slip with a velocity dip through zero lasting ~0.2 ms: without the
 * slip-rate minimum roots the integrator steps over most of them; with them, every stop is
 * found. */
static void test_case_c_hidden_stops(void **state)
{
    (void)state;
    exact_params p = {1.0, 1e4, 9.81, 0.6, 0.5999, 1e-3, 0};
    exact_solution ex;
    assert_int_equal(exact_solve(&p, 5.0, &ex), 0);
    assert_int_equal(ex.n_events, 141);
    const double rtols[] = {1e-6, 1e-8};
    for (size_t k = 0; k < 2; ++k) {
        scene_spec spec = paper_case(0.5999, BK_SPRING_LINEAR, rtols[k], "cvode_adams");
        recorder with = {0}, without = {0};
        bk_error err = {0};
        assert_int_equal(run_spec(&spec, &with, NULL, &err), BK_OK);
        spec.detect_extrema = 0;
        assert_int_equal(run_spec(&spec, &without, NULL, &err), BK_OK);
        print_message("case C rtol %g: %zu transitions with extremum roots, %zu without, exact %zu\n",
                      rtols[k], with.n_transitions, without.n_transitions, ex.n_events);
        assert_int_equal(with.n_transitions, ex.n_events);
        assert_true(without.n_transitions < ex.n_events);
        for (size_t j = 0; j < ex.n_events; ++j)
            assert_close(with.transitions[j].t, ex.events[j].t, 0.0, 1e-4);
        recorder_free(&with);
        recorder_free(&without);
    }
    exact_free(&ex);
}

/* After a restart the root just handled must not fire again: transitions alternate
 * stick/slip, never repeat at one instant, and match the exact count. */
static void test_no_refire_after_restart(void **state)
{
    (void)state;
    const double mu_d[] = {0.1, 0.5, 0.5999};
    const char *methods[] = {"cvode_adams", "cvode_bdf"};
    for (size_t m = 0; m < 2; ++m)
        for (size_t c = 0; c < 3; ++c) {
            scene_spec spec = paper_case(mu_d[c], BK_SPRING_LINEAR, 1e-9, "cvode_adams");
            spec.method = methods[m];
            recorder r = {0};
            bk_error err = {0};
            assert_int_equal(run_spec(&spec, &r, NULL, &err), BK_OK);
            for (size_t k = 1; k < r.n_transitions; ++k) {
                assert_int_equal(r.transitions[k].from, r.transitions[k - 1].to);
                assert_true(r.transitions[k].t > r.transitions[k - 1].t);
            }
            recorder_free(&r);
        }
}

/* --- chains ---------------------------------------------------------------------------- */

static scene_spec chain(size_t n, double rtol)
{
    scene_spec s = paper_case(0.5, BK_SPRING_LINEAR, rtol, "cvode_adams");
    s.n = n;
    s.coupling = 2e4;
    s.t_end = 3.0;
    return s;
}

/* Driver work = elastic + kinetic energy change + frictional dissipation, to a residual
 * that tightens with rtol. */
static void check_energy(size_t n, bk_spring spring, bk_boundary boundary)
{
    double previous = INFINITY;
    const double rtols[] = {1e-6, 1e-8, 1e-10};
    for (size_t k = 0; k < 3; ++k) {
        scene_spec spec = chain(n, rtols[k]);
        spec.spring = spring;
        spec.boundary = boundary;
        bk_config *c = scene_config(&spec);
        /* Break the symmetry so blocks slip at different times. */
        for (size_t i = 0; i < n; ++i) {
            c->model->blocks[i].x_init = 1e-5 * sin(2.385 * (double)i);
            c->model->blocks[i].friction_params[1] = 0.45 + 0.01 * (double)(i % 5);
        }
        recorder r = {0};
        bk_run_stats stats;
        bk_error err = {0};
        assert_int_equal(run_recorded(c, &r, &stats, &err), BK_OK);
        double residual = fabs(stats.energy_residual);
        print_message("%zu blocks rtol %g: %zu transitions, energy residual %.3g, work %.4g J\n", n,
                      rtols[k], r.n_transitions, residual, stats.work_driver);
        assert_true(r.n_transitions > 2 * n);
        assert_true(stats.work_driver > 0.0);
        assert_true(residual < 100.0 * rtols[k]);
        assert_true(r.max_balance_error <= 100.0 * rtols[k] * stats.work_driver);
        assert_true(residual < previous || residual < 1e-12);
        previous = residual;
        recorder_free(&r);
        bk_config_free(c);
    }
}

static void test_energy_two_blocks(void **state)
{
    (void)state;
    check_energy(2, BK_SPRING_LINEAR, BK_BOUNDARY_FREE);
}

static void test_energy_ten_blocks(void **state)
{
    (void)state;
    check_energy(10, BK_SPRING_LINEAR, BK_BOUNDARY_FREE);
    check_energy(10, BK_SPRING_TENSION_ONLY, BK_BOUNDARY_FIXED);
    check_energy(10, BK_SPRING_LINEAR, BK_BOUNDARY_PERIODIC);
}

/* Identical uncoupled twins move identically: each breakaway and each stop is found for
 * both blocks at one instant, in one event. */
static void test_simultaneous_transitions(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, 1e-10, "cvode_adams");
    spec.n = 2;
    spec.coupling = 3e3; /* coupled, but symmetric: the coupling never stretches */
    recorder r = {0};
    bk_error err = {0};
    assert_int_equal(run_spec(&spec, &r, NULL, &err), BK_OK);
    assert_int_equal(r.n_transitions, 20);
    for (size_t k = 0; k + 1 < r.n_transitions; k += 2) {
        assert_true(r.transitions[k].t == r.transitions[k + 1].t);
        assert_int_equal(r.transitions[k].block, 0);
        assert_int_equal(r.transitions[k + 1].block, 1);
        assert_int_equal(r.transitions[k].to, r.transitions[k + 1].to);
    }
    recorder_free(&r);
}

/* A block whose stop finds the spring force beyond the threshold reverses at once
 * (slip+ -> slip-), recorded as one transition. */
static void test_reversal(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.05, BK_SPRING_LINEAR, 1e-10, "cvode_adams");
    spec.velocity = 0.0;
    spec.t_end = 0.2;
    bk_config *c = scene_config(&spec);
    /* Start sliding fast with no driver motion: the spring swings it back past its threshold. */
    c->model->blocks[0].v_init = 0.5;
    recorder r = {0};
    bk_error err = {0};
    assert_int_equal(run_recorded(c, &r, NULL, &err), BK_OK);
    assert_true(r.n_transitions >= 2);
    assert_int_equal(r.transitions[0].from, BK_MODE_SLIP_POS);
    assert_int_equal(r.transitions[0].to, BK_MODE_SLIP_NEG);
    assert_true(fabs(r.transitions[0].force) > 0.6 * 9.81);
    /* Energy bookkeeping covers the reversal. */
    assert_true(r.max_balance_error < 1e-8);
    recorder_free(&r);
    bk_config_free(c);
}

/* Transitions piling up at one instant stop the run with a message naming block and time. */
static void test_chattering_guard(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.5999, BK_SPRING_LINEAR, 1e-8, "cvode_adams");
    spec.max_per_instant = 1;
    bk_config *c = scene_config(&spec);
    /* Stop and breakaway 0.2 ms apart count as one instant in a 1 ms window. */
    c->solver.instant_window = 1e-3;
    recorder r = {0};
    bk_error err = {0};
    assert_int_equal(run_recorded(c, &r, NULL, &err), BK_ERR_ZENO);
    assert_non_null(strstr(err.message, "block 0"));
    assert_non_null(strstr(err.message, "t = 0.6514"));
    recorder_free(&r);
    bk_config_free(c);
}

/* A progress callback can stop a run. */
static int stop_at_one_second(void *user, const bk_progress *progress)
{
    (void)user;
    return progress->t > 1.0;
}

static void test_interrupt(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.5, BK_SPRING_LINEAR, 1e-8, "cvode_adams");
    bk_config *c = scene_config(&spec);
    recorder r = {0};
    bk_sink sink = recorder_sink(&r);
    bk_error err = {0};
    assert_int_equal(bk_run(c, &sink, NULL, stop_at_one_second, NULL, &err), BK_ERR_INTERRUPTED);
    assert_true(r.last_t < 1.2);
    recorder_free(&r);
    bk_config_free(c);
    /* Also while every block is stuck and the run only writes rows (1e7 of them here, the
     * first breakaway at 5.9e6 s): the request is seen at the next row. */
    spec.velocity = 1e-9;
    spec.t_end = 1e5;
    spec.interval = 0.01;
    c = scene_config(&spec);
    recorder stuck = {0};
    sink.self = &stuck;
    assert_int_equal(bk_run(c, &sink, NULL, stop_at_one_second, NULL, &err), BK_ERR_INTERRUPTED);
    assert_int_equal(stuck.n_transitions, 0);
    assert_true(stuck.last_t > 0.99 && stuck.last_t < 1.02);
    recorder_free(&stuck);
    bk_config_free(c);
}

/* Rows: one per sample time plus two per transition instant (before and after, at its
 * time), otherwise strictly increasing in time, the last at t_end. */
static void test_rows(void **state)
{
    (void)state;
    scene_spec spec = paper_case(0.1, BK_SPRING_LINEAR, 1e-8, "cvode_adams");
    spec.interval = 0.01;
    recorder r = {0};
    bk_run_stats stats;
    bk_error err = {0};
    assert_int_equal(run_spec(&spec, &r, &stats, &err), BK_OK);
    assert_false(r.time_decreased);
    assert_int_equal(r.before_rows, r.n_transitions); /* one block: one transition an instant */
    assert_int_equal(r.after_rows, r.n_transitions);
    assert_int_equal(r.rows, 501 + 2 * r.n_transitions);
    assert_int_equal(stats.rows, (long)r.rows);
    assert_close(r.last_t, 5.0, 0.0, 0.0);
    assert_close(stats.t_reached, 5.0, 0.0, 0.0);
    recorder_free(&r);
}

/* Block 0's rows and breakaways, as a reader of /cof and /transitions sees them. */
typedef struct cof_rows {
    double normal_force;      /* N */
    double peak, peak_before; /* the largest /cof, and the largest of the before rows */
    int last_kind;
    double last_t;
    long pairs, breakaways;
    double breakaway_t, breakaway_cof; /* the last breakaway: its time and force / N */
    double worst_breakaway;   /* the largest |before row's COF - force / N| at a breakaway */
    int disorder;
} cof_rows;

static int keep_cof(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    cof_rows *r = self;
    if (r->last_kind == BK_ROW_BEFORE_TRANSITION && (s->is_event != BK_ROW_AFTER_TRANSITION || s->t != r->last_t))
        r->disorder = 1;
    r->pairs += s->is_event == BK_ROW_AFTER_TRANSITION && r->last_kind == BK_ROW_BEFORE_TRANSITION;
    r->peak = fmax(r->peak, s->cof[0]);
    if (s->is_event == BK_ROW_BEFORE_TRANSITION) {
        r->peak_before = fmax(r->peak_before, s->cof[0]);
        if (s->t == r->breakaway_t)
            r->worst_breakaway = fmax(r->worst_breakaway, fabs(s->cof[0] - r->breakaway_cof));
    }
    r->last_kind = s->is_event;
    r->last_t = s->t;
    return BK_OK;
}

/* An instant's transitions reach the sink before its two rows. */
static int keep_breakaway(void *self, const bk_transition *t, bk_error *err)
{
    (void)err;
    cof_rows *r = self;
    if (t->from == BK_MODE_STICK) {
        r->breakaways++;
        r->breakaway_t = t->t;
        r->breakaway_cof = fabs(t->force) / r->normal_force;
    }
    return BK_OK;
}

/* Every paper case's /cof shows its breakaways: the row just before each one holds the static
 * threshold that gave way (the force in /transitions).  With Coulomb friction that is mu_s,
 * the peak of /cof.  With rate-and-state friction the threshold mu(0, theta) heals towards
 * mu_s during a stick, and while sliding the direct effect (1 + v/v0)^(1/m) lifts the
 * friction above mu_s: there the peak is not mu_s, and the breakaways stay below it. */
static void test_transition_rows_show_breakaway(void **state)
{
    (void)state;
    static const char *const cases[] = {"a", "b", "c"};
    static const char *const laws[] = {"coulomb", "rs"};
    static const char *const springs[] = {"", "_tension_only"};
    for (size_t c = 0; c < 3; ++c)
        for (size_t l = 0; l < 2; ++l)
            for (size_t sp = 0; sp < 2; ++sp) {
                char path[128];
                snprintf(path, sizeof path, "configs/paper/case_%s_%s%s.ini", cases[c], laws[l], springs[sp]);
                bk_config *config = NULL;
                bk_error err = {0};
                assert_int_equal(bk_config_load_file(path, NULL, 0, &config, &err), BK_OK);
                cof_rows r = {.normal_force = config->model->blocks[0].normal_force, .peak = -INFINITY,
                              .peak_before = -INFINITY, .last_kind = -1, .breakaway_t = NAN};
                bk_sink sink = {.self = &r, .sample = keep_cof, .transition = keep_breakaway};
                assert_int_equal(bk_run(config, &sink, NULL, NULL, NULL, &err), BK_OK);
                print_message("%s: peak /cof %.17g, before rows' peak %.17g, %ld pairs, %ld breakaways "
                              "(before row - force / N: %.2g at most)\n",
                              path, r.peak, r.peak_before, r.pairs, r.breakaways, r.worst_breakaway);
                assert_false(r.disorder);
                assert_true(r.breakaways >= 1 && r.pairs >= r.breakaways);
                assert_true(r.worst_breakaway <= 1e-12);
                if (l == 0) {
                    assert_close(r.peak, 0.6, 1e-12, 0);
                    assert_close(r.peak_before, 0.6, 1e-12, 0);
                } else {
                    assert_true(r.peak_before <= 0.6 * (1 + 1e-12));
                    assert_true(r.peak > 0.6);
                }
                bk_config_free(config);
            }
}

/* Any block can use any law; only blocks whose law has state carry state variables, and
 * the mixed chain keeps its energy balance. */
static void test_per_block_laws(void **state)
{
    (void)state;
    const char *text =
        "[model]\nn_blocks = 4\ncoupling_stiffness = 2e4\n"
        "[block]\nmass = 1\ndriver_stiffness = 1e4\n"
        "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n"
        "[friction.1]\nlaw = rate_state\nmu_s = 0.6\nmu_d = 0.45\n"
        "[friction.2]\nlaw = carlson_langer\nF0 = 5.5\nsigma = 0.15\nalpha = 2\n"
        "[friction.3]\nlaw = dieterich_ruina_aging\na = 0.05\nb = 0.06\nDc = 1e-5\nV0 = 1e-3\nf0 = 0.45\n"
        "[driver]\nvelocity = 1e-3\n[solver]\nmethod = cvode_bdf\nrtol = 1e-9\n[run]\nt_end = 2\n"
        "[catalog]\nslip_rate_threshold = 1e-4\n";
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "mixed.ini", NULL, 0, &c, &err), BK_OK);
    const bk_model *m = c->model;
    assert_ptr_equal(m->blocks[0].law, &bk_friction_coulomb);
    assert_ptr_equal(m->blocks[1].law, &bk_friction_rate_state);
    assert_ptr_equal(m->blocks[2].law, &bk_friction_carlson_langer);
    assert_ptr_equal(m->blocks[3].law, &bk_friction_dieterich_ruina_aging);
    assert_int_equal(m->n_friction_state, 2); /* rate_state and dieterich_ruina: one each */
    assert_int_equal(m->blocks[1].state_offset, 0);
    assert_int_equal(m->blocks[3].state_offset, 1);
    recorder r = {0};
    bk_run_stats stats;
    int rc = run_recorded(c, &r, &stats, &err);
    if (rc != BK_OK)
        print_error("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    print_message("mixed chain: %zu transitions, energy residual %.2g\n", r.n_transitions,
                  stats.energy_residual);
    assert_true(r.n_transitions > 4);
    assert_true(fabs(stats.energy_residual) < 1e-6);
    for (size_t k = 0; k < r.n_transitions; ++k)
        assert_int_not_equal(r.transitions[k].block, 3); /* it creeps, it never sticks */
    recorder_free(&r);
    bk_config_free(c);
}

/* method = auto picks the exact stepper for Coulomb scenes, BDF with friction state, Adams
 * otherwise, and says so in the statistics. */
static void test_auto_method(void **state)
{
    (void)state;
    const struct {
        const char *friction, *chosen;
    } cases[] = {
        {"law = coulomb\nmu_s = 0.6\nmu_d = 0.5\n", "exact (auto)"},
        {"law = rate_state\nmu_s = 0.6\nmu_d = 0.5\n", "gsl_rk8pd (auto)"},
        {"law = rate_state\nmu_s = 0.6\nmu_d = 0.5\nL0 = 2e-8\n", "cvode_bdf (auto)"}, /* stiff state */
        {"law = carlson_langer\nF0 = 5.5\nsigma = 0.2\nalpha = 3\n", "gsl_rk8pd (auto)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char text[1024];
        snprintf(text, sizeof text,
                 "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n[friction]\n%s"
                 "[driver]\nvelocity = 1e-3\n[run]\nt_end = 1\n",
                 cases[k].friction);
        bk_config *c = NULL;
        bk_error err = {0};
        assert_int_equal(bk_config_load_string(text, "auto.ini", NULL, 0, &c, &err), BK_OK);
        assert_string_equal(c->solver.method, "auto");
        bk_run_stats stats;
        assert_int_equal(bk_run(c, NULL, &stats, NULL, NULL, &err), BK_OK);
        assert_string_equal(stats.method, cases[k].chosen);
        bk_config_free(c);
    }
}

/* --- islands ---------------------------------------------------------------------------- */

/* A uniform 60-block chain with blocks 10-12 pulled back (and, in the second run, blocks
 * 45-47 as well): the first group fails early and slips while everything else holds.  Its
 * transitions come out the same to the last bit whether or not the far group slips at the
 * same times, with every back-end family: islands do not force each other's steps. */
static bk_config *two_groups_config(const char *method, int both)
{
    scene_spec spec = {.n = 60, .mass = 1.0, .stiffness = 1e4, .coupling = 2e4, .mu_s = 0.6,
                       .mu_d = 0.5, .velocity = 1e-3, .t_end = 0.58, .rtol = 1e-8,
                       .interval = 0.0, .spring = BK_SPRING_LINEAR,
                       .boundary = BK_BOUNDARY_FREE, .method = method, .detect_extrema = 1,
                       .max_per_instant = 100};
    bk_config *c = scene_config(&spec);
    /* Before t_end every unperturbed block stays stuck: they fail at 0.5886 s. */
    const double pulled_back[3] = {-1.3e-5, -2.1e-5, -0.7e-5};
    for (size_t k = 0; k < 3; ++k) {
        c->model->blocks[10 + k].x_init = pulled_back[k];
        if (both)
            c->model->blocks[45 + k].x_init = pulled_back[k];
    }
    return c;
}

static void test_distant_groups_independent(void **state)
{
    (void)state;
    const char *methods[] = {"exact", "gsl_rk8pd", "cvode_adams", "cvode_bdf"};
    for (size_t m = 0; m < sizeof methods / sizeof *methods; ++m) {
        recorder alone = {0}, together = {0};
        bk_error err = {0};
        bk_config *c = two_groups_config(methods[m], 0);
        int rc = run_recorded(c, &alone, NULL, &err);
        bk_config_free(c);
        if (rc != BK_OK)
            fail_msg("%s: %s", methods[m], err.message);
        c = two_groups_config(methods[m], 1);
        rc = run_recorded(c, &together, NULL, &err);
        bk_config_free(c);
        if (rc != BK_OK)
            fail_msg("%s: %s", methods[m], err.message);
        size_t near = 0, far = 0, between = 0;
        for (size_t k = 0; k < together.n_transitions; ++k) {
            int32_t b = together.transitions[k].block;
            far += b >= 40;
            between += b >= 25 && b < 35;
        }
        assert_int_equal(between, 0); /* the groups never met */
        assert_true(far > 4);
        for (size_t k = 0; k < together.n_transitions; ++k) {
            const bk_transition *t = &together.transitions[k];
            if (t->block >= 30)
                continue;
            if (near >= alone.n_transitions)
                fail_msg("%s: more near transitions with the far group slipping", methods[m]);
            const bk_transition *a = &alone.transitions[near++];
            if (a->t != t->t || a->block != t->block || a->from != t->from || a->to != t->to ||
                a->x != t->x || a->v != t->v || a->force != t->force)
                fail_msg("%s: transition %zu differs: block %d at %.17g s alone, block %d at "
                         "%.17g s with the far group", methods[m], near - 1, (int)a->block, a->t,
                         (int)t->block, t->t);
        }
        assert_int_equal(near, alone.n_transitions);
        assert_true(near > 4);
        print_message("%s: %zu near transitions identical, %zu far ones alongside\n", methods[m],
                      near, far);
        recorder_free(&alone);
        recorder_free(&together);
    }
}

/* A uniform 40-block chain slides as one island of 82 unknowns, too large to be kept idle:
 * its back-end instance is destroyed when the chain sticks and a new one made at the next
 * slip.  The run's counters still add up every instance's work: four times the cycles make
 * about four times the steps (counting only the instances kept would count none). */
static void test_counters_outlive_instances(void **state)
{
    (void)state;
    const char *methods[] = {"exact", "gsl_rk8pd"};
    for (size_t m = 0; m < sizeof methods / sizeof *methods; ++m) {
        long steps[2], starts[2];
        const double t_end[2] = {1.0, 2.6}; /* first slip at 0.59 s, then one every 0.2 s */
        for (size_t k = 0; k < 2; ++k) {
            scene_spec spec = {.n = 40, .mass = 1.0, .stiffness = 1e4, .coupling = 2e4,
                               .mu_s = 0.6, .mu_d = 0.5, .velocity = 1e-3, .t_end = t_end[k],
                               .rtol = 1e-8, .interval = 0.0, .spring = BK_SPRING_LINEAR,
                               .boundary = BK_BOUNDARY_FREE, .method = methods[m],
                               .detect_extrema = 1, .max_per_instant = 100};
            bk_config *c = scene_config(&spec);
            bk_run_stats stats;
            bk_error err = {0};
            recorder r = {0};
            int rc = run_recorded(c, &r, &stats, &err);
            recorder_free(&r);
            bk_config_free(c);
            if (rc != BK_OK)
                fail_msg("%s: %s", methods[m], err.message);
            steps[k] = stats.steps;
            starts[k] = stats.integrator_starts;
        }
        print_message("%s: %ld and %ld starts, %ld and %ld steps\n", methods[m], starts[0],
                      starts[1], steps[0], steps[1]);
        assert_true(steps[0] >= 5 * starts[0]); /* a slip takes many steps */
        assert_true(starts[1] >= 3 * starts[0]);
        assert_true(steps[1] >= 3 * steps[0]);
        assert_true(steps[1] <= 5 * steps[0]);
    }
}

/* [output] max_bytes counts everything written: full event rows on a 20-block chain pass
 * the limit that the transitions table alone stays under. */
static void test_output_limit_counts_event_rows(void **state)
{
    (void)state;
    scene_spec spec = {.n = 20, .mass = 1.0, .stiffness = 1e4, .coupling = 2e4, .mu_s = 0.6,
                       .mu_d = 0.5, .velocity = 1e-3, .t_end = 0.8, .rtol = 1e-8,
                       .interval = 0.0, .spring = BK_SPRING_LINEAR,
                       .boundary = BK_BOUNDARY_FREE, .method = "exact", .detect_extrema = 1,
                       .max_per_instant = 100};
    for (int rows = 0; rows < 2; ++rows) {
        bk_config *c = scene_config(&spec);
        for (size_t i = 0; i < 20; ++i)
            c->model->blocks[i].x_init = 1e-6 * (double)((i * 7) % 5);
        c->output.event_rows = rows;
        c->output.max_bytes = 2e4;
        recorder r = {0};
        bk_error err = {0};
        bk_run_stats stats;
        int rc = run_recorded(c, &r, &stats, &err);
        if (rows) {
            assert_int_equal(rc, BK_ERR_LIMIT);
            assert_non_null(strstr(err.message, "[output] max_bytes = 2e+04 B reached"));
            assert_non_null(strstr(err.message, "event_rows = false"));
        } else {
            if (rc != BK_OK)
                fail_msg("%s", err.message);
            /* 2 rows of 17 + 33 x 20 + 32 bytes and 38 per transition fit. */
            assert_true(stats.transitions > 50);
            assert_true(2.0 * 709.0 + 38.0 * (double)stats.transitions <= 2e4);
        }
        recorder_free(&r);
        bk_config_free(c);
    }
}

/* A resting rate-and-state block ages (theta = theta0 + B t, so its threshold grows) while
 * the driver loads it: its breakaway, found in closed form without an integrator, is the
 * first zero of threshold(theta(t)) - k V t, computed here by bisection. */
static void test_aging_breakaway(void **state)
{
    (void)state;
    const char *text = "[model]\nn_blocks = 1\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"
                       "[friction]\nlaw = rate_state\nmu_s = 0.6\nmu_d = 0.5\n"
                       "[driver]\nvelocity = 1e-3\n[output]\ninterval = 0\n[run]\nt_end = 1\n";
    bk_config *c = NULL;
    bk_error err = {0};
    assert_int_equal(bk_config_load_string(text, "aging.ini", NULL, 0, &c, &err), BK_OK);
    const bk_block *b = &c->model->blocks[0];
    const bk_friction_law *law = b->law;
    double theta0, rate;
    law->state_init(b->friction_params, &theta0);
    law->state_rate(b->friction_params, 0.0, &theta0, &rate);
    double lo = 0.0, hi = 1.0;
    for (int iter = 0; iter < 200; ++iter) {
        double mid = 0.5 * (lo + hi), theta = theta0 + rate * mid;
        double margin = law->static_threshold(b->friction_params, b->normal_force, &theta) -
                        b->driver_stiffness * 1e-3 * mid;
        *(margin > 0.0 ? &lo : &hi) = mid;
    }
    recorder r = {0};
    int rc = run_recorded(c, &r, NULL, &err);
    if (rc != BK_OK)
        fail_msg("%s", err.message);
    assert_true(r.n_transitions >= 1);
    assert_int_equal(r.transitions[0].to, BK_MODE_SLIP_POS);
    assert_close(r.transitions[0].t, hi, 1e-14, 0.0);
    /* The aging made it later than the fresh contact's threshold would. */
    double fresh = law->static_threshold(b->friction_params, b->normal_force, &theta0) /
                   (b->driver_stiffness * 1e-3);
    assert_true(r.transitions[0].t > fresh * (1.0 + 1e-6));
    recorder_free(&r);
    bk_config_free(c);
}

/* --- a constant applied force ---------------------------------------------------------- */

#define APPLIED_SCENE                                                                                  \
    "[model]\nn_blocks = 8\ncoupling_stiffness = 2e4\n[block]\nmass = 1\ndriver_stiffness = 1e4\n"     \
    "[block.3]\nx_init = -2e-5\n[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = linear(0.45, 0.55)\n"    \
    "[driver]\nvelocity = 1e-3\n[run]\nt_end = 1\n[output]\ninterval = 0\n"

static bk_config *applied_config(const char *method, const char *set)
{
    char solver[64];
    snprintf(solver, sizeof solver, "solver.method=%s", method);
    const char *overrides[] = {solver, "solver.rtol=1e-12", "solver.atol_x=1e-15", set};
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = bk_config_load_string(APPLIED_SCENE, "applied.ini", overrides, 4, &c, &err);
    if (rc != BK_OK)
        print_error("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    return c;
}

/* With equal driver springs k, a constant force F on every block is the driver moved ahead by
 * F / k: the same transitions at the same times (over 1 s: the chain is chaotic, and later the
 * two roundings part, 1e-8 s apart by 2 s), and the energy balance still closes (the
 * force's potential -F x counts with the elastic energy).  Alone, a force above a block's
 * threshold starts it at t = 0 and one below never moves it. */
static void test_applied_force(void **state)
{
    (void)state;
    const char *methods[] = {"exact", "gsl_rk8pd", "cvode_bdf"};
    const double tolerance[] = {1e-11, 1e-9, 1e-7};
    for (size_t m = 0; m < sizeof methods / sizeof *methods; ++m) {
        bk_config *pushed = applied_config(methods[m], "block.applied_force=1.5");
        bk_config *ahead = applied_config(methods[m], "driver.start_position=1.5e-4");
        recorder a = {0}, b = {0};
        bk_run_stats stats_a, stats_b;
        bk_error err = {0};
        assert_int_equal(run_recorded(pushed, &a, &stats_a, &err), BK_OK);
        assert_int_equal(run_recorded(ahead, &b, &stats_b, &err), BK_OK);
        double worst = 0.0;
        assert_int_equal(a.n_transitions, b.n_transitions);
        for (size_t k = 0; k < a.n_transitions; ++k) {
            assert_int_equal(a.transitions[k].block, b.transitions[k].block);
            assert_int_equal(a.transitions[k].to, b.transitions[k].to);
            worst = fmax(worst, fabs(a.transitions[k].t - b.transitions[k].t));
        }
        print_message("%s: %zu transitions, largest time difference %.3g s; energy residual %.3g J (work %.3g J)\n",
                      methods[m], a.n_transitions, worst, stats_a.energy_residual, stats_a.work_driver);
        assert_true(a.n_transitions > 16);
        assert_true(worst <= tolerance[m]);
        assert_true(fabs(stats_a.energy_residual) <= 1e-6 * stats_a.work_driver);
        assert_true(a.max_balance_error <= 1e-6 * stats_a.work_driver);
        recorder_free(&a);
        recorder_free(&b);
        bk_config_free(pushed);
        bk_config_free(ahead);
    }

    /* No driver: 6 N against a threshold of 0.6 * 9.81 = 5.886 N breaks away at once; 5.8 N
     * holds for ever. */
    const double forces[] = {6.0, 5.8};
    for (size_t k = 0; k < 2; ++k) {
        char set[64];
        snprintf(set, sizeof set, "block.applied_force=%g", forces[k]);
        bk_config *c = applied_config("exact", set);
        c->model->blocks[3].x_init = 0.0;
        for (size_t i = 0; i < c->model->n_blocks; ++i)
            c->model->blocks[i].driver_stiffness = 0.0;
        c->model->coupling_stiffness = 0.0;
        recorder r = {0};
        bk_run_stats stats;
        bk_error err = {0};
        assert_int_equal(run_recorded(c, &r, &stats, &err), BK_OK);
        if (k == 0) {
            assert_int_equal(r.n_transitions, 8);
            for (size_t j = 0; j < 8; ++j) {
                assert_true(r.transitions[j].t == 0.0);
                assert_int_equal(r.transitions[j].to, BK_MODE_SLIP_POS);
            }
        } else {
            assert_int_equal(r.n_transitions, 0);
        }
        recorder_free(&r);
        bk_config_free(c);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_case_a_linear),
        cmocka_unit_test(test_case_b_linear),
        cmocka_unit_test(test_case_c_linear),
        cmocka_unit_test(test_case_a_tension_only),
        cmocka_unit_test(test_case_b_tension_only),
        cmocka_unit_test(test_case_c_tension_only),
        cmocka_unit_test(test_case_a_paper_numbers),
        cmocka_unit_test(test_error_shrinks_with_rtol),
        cmocka_unit_test(test_case_c_hidden_stops),
        cmocka_unit_test(test_no_refire_after_restart),
        cmocka_unit_test(test_energy_two_blocks),
        cmocka_unit_test(test_energy_ten_blocks),
        cmocka_unit_test(test_simultaneous_transitions),
        cmocka_unit_test(test_reversal),
        cmocka_unit_test(test_chattering_guard),
        cmocka_unit_test(test_interrupt),
        cmocka_unit_test(test_rows),
        cmocka_unit_test(test_transition_rows_show_breakaway),
        cmocka_unit_test(test_per_block_laws),
        cmocka_unit_test(test_auto_method),
        cmocka_unit_test(test_distant_groups_independent),
        cmocka_unit_test(test_counters_outlive_instances),
        cmocka_unit_test(test_output_limit_counts_event_rows),
        cmocka_unit_test(test_aging_breakaway),
        cmocka_unit_test(test_applied_force),
    };
    return cmocka_run_group_tests_name("run", tests, NULL, NULL);
}
