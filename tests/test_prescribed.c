/* The prescribed-motion scene: Figure 2's spike, dip and steady states; the state follows
 * eq. 5 exactly; holds heal the state; the schedule's config errors. */
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"

typedef struct rows {
    double *t, *x, *v, *cof, *theta;
    int *event;
    size_t n, cap;
    size_t transitions;
} rows;

static int keep(void *self, const bk_sample *s, bk_error *err)
{
    (void)err;
    rows *r = self;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 1024;
        r->t = realloc(r->t, r->cap * sizeof *r->t);
        r->x = realloc(r->x, r->cap * sizeof *r->x);
        r->v = realloc(r->v, r->cap * sizeof *r->v);
        r->cof = realloc(r->cof, r->cap * sizeof *r->cof);
        r->theta = realloc(r->theta, r->cap * sizeof *r->theta);
        r->event = realloc(r->event, r->cap * sizeof *r->event);
        assert_true(r->t && r->x && r->v && r->cof && r->theta && r->event);
    }
    r->t[r->n] = s->t;
    r->x[r->n] = s->x[0];
    r->v[r->n] = s->v[0];
    r->cof[r->n] = s->cof[0];
    r->theta[r->n] = s->friction_state ? s->friction_state[0] : NAN;
    r->event[r->n] = s->is_event;
    r->n++;
    return BK_OK;
}

static int count_transition(void *self, const bk_transition *tr, bk_error *err)
{
    (void)tr;
    (void)err;
    ((rows *)self)->transitions++;
    return BK_OK;
}

static void rows_free(rows *r)
{
    free(r->t);
    free(r->x);
    free(r->v);
    free(r->cof);
    free(r->theta);
    free(r->event);
}

static int run_text(const char *text, rows *r, bk_error *err)
{
    bk_config *c = NULL;
    int rc = bk_config_load_string(text, "p.ini", NULL, 0, &c, err);
    if (rc != BK_OK)
        return rc;
    bk_sink sink = {.self = r, .sample = keep, .transition = count_transition};
    rc = bk_run(c, &sink, NULL, NULL, NULL, err);
    bk_config_free(c);
    return rc;
}

static const char *const figure2 =
    "[prescribed]\nslip_rates = 1e-3, 1e-2, 1e-3\ndistances = 2e-4 2e-4 2e-4\n"
    "[friction]\nlaw = rate_state\nmu_s = 0.6\nmu_d = 0.5\n"
    "[output]\ninterval = 1e-5\n";

/* The paper's Figure 2: spike to ~0.587, dip to ~0.457, steady 0.500 and 0.537. */
static void test_figure2(void **state)
{
    (void)state;
    rows r = {0};
    bk_error err = {0};
    assert_int_equal(run_text(figure2, &r, &err), BK_OK);
    assert_close(r.t[r.n - 1], 0.42, 1e-12, 0);
    assert_close(r.x[r.n - 1], 6e-4, 1e-12, 0);
    /* Each step is two rows at one time, the states just before and just after it: slip and
     * state continuous, the rate and the friction jumping. */
    size_t up = 0, down = 0;
    for (size_t i = 1; i < r.n; ++i) {
        if (r.event[i] == BK_ROW_AFTER_TRANSITION && r.v[i] > r.v[i - 1])
            up = i;
        if (r.event[i] == BK_ROW_AFTER_TRANSITION && r.v[i] < r.v[i - 1])
            down = i;
        if (r.event[i] == BK_ROW_AFTER_TRANSITION) {
            assert_int_equal(r.event[i - 1], BK_ROW_BEFORE_TRANSITION);
            assert_true(r.t[i] == r.t[i - 1] && r.x[i] == r.x[i - 1] && r.theta[i] == r.theta[i - 1]);
        } else {
            assert_true(r.t[i] > r.t[i - 1]);
        }
    }
    assert_true(up > 1 && down > up);
    double f_fast = exp(1000.0 * log1p(1e-2 / 100.0)), f_slow = exp(1000.0 * log1p(1e-3 / 100.0));
    double g_slow = (0.5 + 0.1 * exp(-1.0)) / f_slow;               /* at theta = L0 / 1 mm/s */
    double g_fast = (0.5 + 0.1 * exp(-pow(10.0, 1.2))) / f_fast;    /* at theta = L0 / 10 mm/s */
    assert_close(r.cof[up], f_fast * g_slow, 1e-12, 0);             /* the spike */
    assert_close(r.cof[down], f_slow * g_fast, 1e-12, 0);           /* the dip */
    assert_close(r.cof[up], 0.587, 0, 5e-4);
    assert_close(r.cof[down], 0.457, 0, 5e-4);
    /* Settled: just before each step and at the end. */
    assert_close(r.cof[up - 1], 0.5 + 0.1 * exp(-1.0), 1e-9, 0);
    assert_close(r.cof[down - 1], 0.5 + 0.1 * exp(-pow(10.0, 1.2)), 1e-9, 0);
    assert_close(r.cof[r.n - 1], 0.5 + 0.1 * exp(-1.0), 1e-9, 0);
    /* After the spike the friction only falls; after the dip it only rises. */
    for (size_t i = up + 1; i < down; ++i)
        assert_true(r.cof[i] <= r.cof[i - 1] + 1e-15);
    for (size_t i = down + 1; i < r.n; ++i)
        assert_true(r.cof[i] >= r.cof[i - 1] - 1e-15);
    rows_free(&r);
}

/* The state follows eq. 5 at every row: theta = (theta_n - L0/v) exp(-(v/L0) B (t - t_n)) + L0/v. */
static void test_state_is_eq5(void **state)
{
    (void)state;
    rows r = {0};
    bk_error err = {0};
    assert_int_equal(run_text(figure2, &r, &err), BK_OK);
    const double L0 = 2e-5, B = 4.6;
    double t_n = 0.0, theta_n = L0 / 1e-3;
    for (size_t i = 0; i < r.n; ++i) {
        if (r.event[i] == BK_ROW_AFTER_TRANSITION) { /* a new segment: restart eq. 5 from here */
            t_n = r.t[i];
            theta_n = r.theta[i];
        }
        double v = r.v[i];
        if (v == 0.0) { /* the block at rest before the first segment: the state it starts with */
            assert_true(i == 0 && r.event[i] == BK_ROW_BEFORE_TRANSITION && r.theta[i] == theta_n);
            continue;
        }
        double expected = (theta_n - L0 / v) * exp(-(v / L0) * B * (r.t[i] - t_n)) + L0 / v;
        assert_close(r.theta[i], expected, 1e-12, 0);
    }
    rows_free(&r);
}

/* Slide-hold-slide: the state heals at rate B during the hold; the friction peaks when
 * sliding resumes, the more the longer the hold. */
static void test_slide_hold_slide(void **state)
{
    (void)state;
    double peaks[2];
    const double holds[2] = {0.1, 1.0};
    for (size_t k = 0; k < 2; ++k) {
        char text[1024];
        snprintf(text, sizeof text,
                 "[prescribed]\nslip_rates = 1e-3 0 1e-3\ndurations = 0.1 %g 0.05\n"
                 "[friction]\nlaw = rate_state\nmu_s = 0.6\nmu_d = 0.5\n[output]\ninterval = 1e-3\n",
                 holds[k]);
        rows r = {0};
        bk_error err = {0};
        assert_int_equal(run_text(text, &r, &err), BK_OK);
        assert_int_equal(r.transitions, 3); /* from rest at t = 0, then slip -> stick -> slip */
        size_t resume = 0;
        for (size_t i = 1; i < r.n; ++i)
            if (r.event[i] && r.v[i] > 0.0 && r.v[i - 1] == 0.0)
                resume = i;
        assert_true(resume > 0);
        /* theta grew by B * hold from its steady value. */
        assert_close(r.theta[resume], 2e-2 + 4.6 * holds[k], 1e-12, 0);
        peaks[k] = r.cof[resume];
        rows_free(&r);
    }
    assert_true(peaks[1] > peaks[0]);
    assert_true(peaks[0] > 0.5 + 0.1 * exp(-1.0));
}

/* Stateless laws run too: Coulomb gives mu_d while sliding, mu_s during a hold. */
static void test_coulomb_schedule(void **state)
{
    (void)state;
    rows r = {0};
    bk_error err = {0};
    assert_int_equal(run_text("[prescribed]\nslip_rates = 1e-3 0\ndurations = 1 1\n"
                              "[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n[output]\ninterval = 0.1\n",
                              &r, &err),
                     BK_OK);
    assert_close(r.cof[1], 0.5, 0, 0);
    assert_close(r.cof[r.n - 1], 0.6, 0, 0);
    assert_true(isnan(r.theta[0]));
    rows_free(&r);
}

static void test_schedule_errors(void **state)
{
    (void)state;
    const struct {
        const char *prescribed, *message;
    } cases[] = {
        {"slip_rates = 1e-3\n", "p.ini:2: [prescribed] slip_rates: give exactly one of durations and distances"},
        {"slip_rates = 1e-3\ndurations = 1\ndistances = 1\n", "give exactly one of durations and distances"},
        {"slip_rates = 1e-3 2e-3\ndurations = 1\n", "p.ini:3: [prescribed] durations: has 1 values, slip_rates has 2"},
        {"slip_rates = 1e-3 0\ndistances = 1 1\n", "[prescribed] distances: segment 2 is a hold (slip rate 0): give durations"},
        {"slip_rates = 1e-3 -1\ndurations = 1 1\n", "[prescribed] slip_rates: bad value \"-1\" (item 2)"},
        {"slip_rates = 1e-3 fast\ndurations = 1 1\n", "[prescribed] slip_rates: bad value \"fast\" (item 2)"},
        {"slip_rates = 1e-3\ndurations = 0\n", "[prescribed] durations: bad value \"0\" (item 1)"},
        {"slip_rates =\ndurations = 1\n", "[prescribed] slip_rates: empty list"},
        {"durations = 1\n", "p.ini: [prescribed] slip_rates: required key missing"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        char text[1024];
        snprintf(text, sizeof text, "[prescribed]\n%s[friction]\nlaw = coulomb\nmu_s = 0.6\nmu_d = 0.5\n",
                 cases[k].prescribed);
        bk_config *c = NULL;
        bk_error err = {0};
        int rc = bk_config_load_string(text, "p.ini", NULL, 0, &c, &err);
        if (rc != BK_ERR_CONFIG || !strstr(err.message, cases[k].message))
            print_error("case %zu: %s\nexpected: %s\n", k, err.message, cases[k].message);
        assert_int_equal(rc, BK_ERR_CONFIG);
        assert_non_null(strstr(err.message, cases[k].message));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_figure2),
        cmocka_unit_test(test_state_is_eq5),
        cmocka_unit_test(test_slide_hold_slide),
        cmocka_unit_test(test_coulomb_schedule),
        cmocka_unit_test(test_schedule_errors),
    };
    return cmocka_run_group_tests_name("prescribed", tests, NULL, NULL);
}
