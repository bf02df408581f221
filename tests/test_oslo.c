/* Parity with the Oslo group's public 1D model (issue 34 item 5): configs/fronts/oslo_front.ini
 * is their integrateSingleSystem.m (bokhylle/1dBurridgeKnopoffMatlab) in bksim's keys, the
 * mapping in the config.  The reference is tests/data/oslo/: their code run unmodified under
 * GNU Octave at dt = 1e-3 (theirs) down to dt / 8, each block's first unsticking time
 * (provenance in each file's header).  Their integrator is explicit Euler and their arrival
 * times are step times, the first at which a block's force is past its threshold: up to a
 * step late per block, and a steady front locks in, so that the lateness adds up along the
 * chain (the supershear front: 4.8e-5 per block at dt / 4 and at dt / 8 alike, the fraction of
 * a step its period leaves over).  So their error is O(dt) times the distance, and not
 * monotone in dt.  Checked per point, for every block i (its distance from the pushed edge):
 * the first forward onset in bksim's /transitions (rtol 1e-12) within (i + 5) dt of theirs at
 * the two finest dt, and within 5e-3 of theirs at the finest anywhere (arrivals run to 300). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "recorder.h"

#define SCENE "configs/fronts/oslo_front.ini"
#define MAX_BLOCKS 200

typedef struct point {
    const char *name;
    double tau, alpha;
    int n_blocks;
    double t_end;
    const char *dts[4]; /* file suffixes, coarsest first */
    double dt[4];
} point;

static const point points[] = {
    {"A_slow", 0.3, 3.0, 50, 300.0, {"0p001", "0p0005", "0p00025", "0p000125"}, {1e-3, 5e-4, 2.5e-4, 1.25e-4}},
    {"B_subsonic", 0.1, 0.1, 100, 150.0, {"0p001", "0p0005", "0p00025", "0p000125"}, {1e-3, 5e-4, 2.5e-4, 1.25e-4}},
    {"C_supershear", 0.8, 0.1, 100, 80.0, {"0p001", "0p0005", "0p00025", "0p000125"}, {1e-3, 5e-4, 2.5e-4, 1.25e-4}},
    {"D_arresting", 0.01, 0.1, 100, 100.0, {"0p001", "0p0005", "0p00025", "0p000125"}, {1e-3, 5e-4, 2.5e-4, 1.25e-4}},
};

/* The reference arrival of each block (index 0-based; NaN: never), n_blocks of them. */
static void read_reference(const char *path, double *t, int n_blocks)
{
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("%s: cannot open", path);
    for (int b = 0; b < n_blocks; ++b)
        t[b] = NAN;
    char line[512];
    int rows = 0;
    while (fgets(line, sizeof line, f)) {
        int block;
        char value[64];
        if (line[0] == '#' || sscanf(line, "%d %63s", &block, value) != 2)
            continue;
        assert_true(block >= 1 && block <= n_blocks);
        t[block - 1] = strcmp(value, "NaN") == 0 ? NAN : strtod(value, NULL);
        ++rows;
    }
    fclose(f);
    assert_int_equal(rows, n_blocks);
}

static void test_arrivals_converge(void **state)
{
    (void)state;
    for (size_t p = 0; p < sizeof points / sizeof points[0]; ++p) {
        const point *pt = &points[p];
        char sets[5][64];
        snprintf(sets[0], sizeof sets[0], "block.applied_force=%.17g", pt->tau + 1.0);
        snprintf(sets[1], sizeof sets[1], "block.damping=%.17g", pt->alpha);
        snprintf(sets[2], sizeof sets[2], "model.n_blocks=%d", pt->n_blocks);
        snprintf(sets[3], sizeof sets[3], "run.t_end=%.17g", pt->t_end);
        snprintf(sets[4], sizeof sets[4], "solver.rtol=1e-12");
        const char *overrides[] = {sets[0], sets[1], sets[2], sets[3], sets[4], "output.interval=0",
                                   "solver.method=gsl_rk8pd"};
        bk_config *c = NULL;
        bk_error err = {0};
        if (bk_config_load_file(SCENE, overrides, 7, &c, &err) != BK_OK)
            fail_msg("%s", err.message);
        recorder r = {0};
        bk_run_stats stats;
        assert_int_equal(run_recorded(c, &r, &stats, &err), BK_OK);
        double arrival[MAX_BLOCKS];
        for (int b = 0; b < pt->n_blocks; ++b)
            arrival[b] = NAN;
        arrival[0] = 0.0; /* started slipping at t = 0 (v_init), as theirs unsticks at their first step */
        for (size_t k = 0; k < r.n_transitions; ++k) {
            const bk_transition *t = &r.transitions[k];
            /* Theirs records the first forward unsticking only. */
            if (t->to == BK_MODE_SLIP_POS && isnan(arrival[t->block]))
                arrival[t->block] = t->t;
        }
        double worst[4];
        for (int d = 0; d < 4; ++d) {
            char path[256];
            snprintf(path, sizeof path, "tests/data/oslo/%s_dt%s.tsv", pt->name, pt->dts[d]);
            double ref[MAX_BLOCKS];
            read_reference(path, ref, pt->n_blocks);
            worst[d] = 0.0;
            int beyond = 0;
            for (int b = 0; b < pt->n_blocks; ++b) {
                /* Reached in both or in neither. */
                assert_true(isnan(ref[b]) == isnan(arrival[b]));
                if (isnan(ref[b]))
                    continue;
                double diff = fabs(arrival[b] - ref[b]);
                worst[d] = fmax(worst[d], diff);
                beyond += diff > ((double)b + 5.0) * pt->dt[d];
            }
            print_message("%s (tau_bar %g, alpha %g, %d blocks): dt = %g: largest |bksim - Euler| %.3g (%.2f dt)%s\n",
                          pt->name, pt->tau, pt->alpha, pt->n_blocks, pt->dt[d], worst[d], worst[d] / pt->dt[d],
                          beyond ? ", some block beyond (its distance + 5) dt" : "");
            if (d >= 2)
                assert_int_equal(beyond, 0);
        }
        assert_true(worst[3] < 5e-3);
        recorder_free(&r);
        bk_config_free(c);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_arrivals_converge),
    };
    return cmocka_run_group_tests_name("oslo", tests, NULL, NULL);
}
