/* Local time stepping (src/run_segments.c): the Dieterich-Ruina ring of
 * configs/chains/dieterich_ruina_30.ini at 64 blocks, cut into 8 segments of 8, against the
 * whole ring integrated at once.
 *
 * A short window is deterministic at tight tolerance (the ring's chaos amplifies differences
 * only over seconds): at rtol 1e-10 to t = 2.1 s both hold the same 19 ruptures (epicentre
 * and size), onsets within ONSET_S and potencies within POTENCY_REL of each other (measured
 * worst: 1.7e-8 s, 3.2e-6).  The run reports its segments and the largest coupling error it
 * measured (ghost extrapolation against the neighbour's later solution, over the tolerance:
 * measured 4-6 at rtol 1e-8 and 1e-10, each excess halving that edge's lookahead); a run
 * resumed from a checkpoint ends bit for bit as the uninterrupted one; a lattice with
 * dashpots and a driver history, and a ring with coupling dashpots, give the same ruptures in
 * segments as whole; and a back-end without a predictor, or a ring too short to gain, is
 * left whole.
 *
 * The rupture statistics of long chaotic runs (KS) are tests/long/test_local_statistics.c.
 * Runtime: about 7 s. */
#include "bk_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "files.h"
#include "output_fixture.h"
#include "rupture_log.h"
#include "same_output.h"
#include "stopping_sink.h"

#define SCENE "configs/chains/dieterich_ruina_30.ini"
#define N_RUPTURES 19
#define ONSET_S 1e-7
#define POTENCY_REL 2e-5
#define COUPLING_ERROR_MAX 50.0

static bk_config *ring(const char *local, const char *rtol, const char *t_end, const char *extra)
{
    char set_local[64], set_rtol[64], set_end[64];
    /* Rows only at the ends, unless checkpoints (whose runs are stopped rows after one, and
     * compared with their transitions: the threshold crossings). */
    snprintf(set_local, sizeof set_local, "solver.local_stepping=%s", local);
    snprintf(set_rtol, sizeof set_rtol, "solver.rtol=%s", rtol);
    snprintf(set_end, sizeof set_end, "run.t_end=%s", t_end);
    const char *overrides[] = {"model.n_blocks=64", "solver.segment_blocks=8",
                               extra ? "output.interval=0.1" : "output.interval=0",
                               set_local, set_rtol, set_end, extra, "output.transitions=true"};
    bk_config *c = NULL;
    bk_error err = {0};
    if (bk_config_load_file(SCENE, overrides, extra ? 8 : 6, &c, &err) != BK_OK)
        fail_msg("%s", err.message);
    return c;
}

static void run_logged(const bk_config *c, rupture_log *log, bk_run_stats *stats)
{
    bk_sink sink = rupture_log_sink(log);
    bk_error err = {0};
    if (bk_run(c, &sink, stats, NULL, NULL, &err) != BK_OK)
        fail_msg("%s", err.message);
}

static void test_window_reproduces_whole_chain(void **state)
{
    (void)state;
    static rupture_log whole, local;
    bk_run_stats whole_stats, local_stats;
    bk_config *c = ring("off", "1e-10", "2.1", NULL);
    run_logged(c, &whole, &whole_stats);
    bk_config_free(c);
    c = ring("on", "1e-10", "2.1", NULL);
    run_logged(c, &local, &local_stats);
    bk_config_free(c);

    assert_int_equal(whole_stats.segments, 0);
    assert_int_equal(local_stats.segments, 8);
    assert_true(local_stats.coupling_error > 0.0 && local_stats.coupling_error < COUPLING_ERROR_MAX);
    assert_int_equal(whole.n, N_RUPTURES);
    assert_int_equal(local.n, N_RUPTURES);
    double onset = 0.0, potency = 0.0;
    for (size_t k = 0; k < N_RUPTURES; ++k) {
        const bk_rupture *a = &whole.r[k], *b = &local.r[k];
        assert_int_equal(a->first_block, b->first_block);
        assert_int_equal(a->n_blocks, b->n_blocks);
        onset = fmax(onset, fabs(a->t_start - b->t_start));
        potency = fmax(potency, fabs(a->potency - b->potency) / a->potency);
    }
    print_message("onsets within %.3g s, potencies within %.3g; coupling error %.3g (%ld over 1)\n", onset,
                  potency, local_stats.coupling_error, local_stats.coupling_exceedances);
    assert_true(onset < ONSET_S);
    assert_true(potency < POTENCY_REL);
}

/* An 8 x 8 lattice with dashpots and a driver history (a hold from 1.2 s: its breakpoints
 * restart every segment), in segments of two rows; and the 64-block ring with coupling
 * dashpots (the ghosts' velocities enter the forces).  The same ruptures as whole, onsets
 * within VARIANT_ONSET_S (measured worst 1.9e-9 and 1.8e-8 s at rtol 1e-9). */
static const char lattice_scene[] = "[model]\nrows = 8\ncols = 8\nboundary = free\ncoupling_stiffness = 4e3\n"
                                    "seed = 7\n[block]\nmass = 1\ndriver_stiffness = 2e3\ndamping = 5\n"
                                    "v_init = 1e-3\nx_init_random = 2e-6\n[friction]\nlaw = dieterich_ruina_aging\n"
                                    "a = 0.01\nb = 0.015\nDc = 1e-5\nV0 = 1e-3\nf0 = 0.6\ntheta_init = 0.01\n"
                                    "[driver]\nvelocities = 1e-3, 0, 2e-3\ndurations = 1.2, 0.3, 1.0\n"
                                    "start_position = 2.943e-3\n[solver]\nmethod = cvode_bdf\nrtol = 1e-9\n"
                                    "segment_blocks = 16\n[output]\ninterval = 0\ntransitions = false\n"
                                    "[catalog]\nslip_rate_threshold = 1e-2\n[run]\nt_end = 1.7\n";
#define VARIANT_ONSET_S 1e-7

static void expect_same_ruptures(const bk_config *whole_config, const bk_config *local_config, size_t expected)
{
    rupture_log *whole = calloc(1, sizeof *whole), *local = calloc(1, sizeof *local);
    assert_true(whole && local);
    bk_run_stats whole_stats, local_stats;
    run_logged(whole_config, whole, &whole_stats);
    run_logged(local_config, local, &local_stats);
    assert_int_equal(whole_stats.segments, 0);
    assert_true(local_stats.segments > 1);
    assert_int_equal(whole->n, expected);
    assert_int_equal(local->n, expected);
    double onset = 0.0;
    for (size_t k = 0; k < expected; ++k) {
        assert_int_equal(whole->r[k].first_block, local->r[k].first_block);
        assert_int_equal(whole->r[k].n_blocks, local->r[k].n_blocks);
        onset = fmax(onset, fabs(whole->r[k].t_start - local->r[k].t_start));
    }
    print_message("%zu ruptures, onsets within %.3g s; %ld segments, coupling error %.3g\n", expected, onset,
                  local_stats.segments, local_stats.coupling_error);
    assert_true(onset < VARIANT_ONSET_S);
    free(whole);
    free(local);
}

static void test_lattice_dashpots_history(void **state)
{
    (void)state;
    bk_config *whole = NULL, *local = NULL;
    bk_error err = {0};
    const char *off[] = {"solver.local_stepping=off"}, *on[] = {"solver.local_stepping=on"};
    assert_int_equal(bk_config_load_string(lattice_scene, "lattice.ini", off, 1, &whole, &err), BK_OK);
    assert_int_equal(bk_config_load_string(lattice_scene, "lattice.ini", on, 1, &local, &err), BK_OK);
    expect_same_ruptures(whole, local, 3);
    bk_config_free(whole);
    bk_config_free(local);
    const char *damped_off[] = {"model.n_blocks=64", "output.interval=0", "solver.rtol=1e-9", "run.t_end=1.2",
                                "model.coupling_damping=2", "solver.local_stepping=off"};
    const char *damped_on[] = {"model.n_blocks=64", "output.interval=0", "solver.rtol=1e-9", "run.t_end=1.2",
                               "model.coupling_damping=2", "solver.local_stepping=on"};
    assert_int_equal(bk_config_load_file(SCENE, damped_off, 6, &whole, &err), BK_OK);
    assert_int_equal(bk_config_load_file(SCENE, damped_on, 6, &local, &err), BK_OK);
    expect_same_ruptures(whole, local, 3);
    bk_config_free(whole);
    bk_config_free(local);
}

/* Stopped after its second checkpoint and resumed: the same file as one run. */
static void test_resume_bit_identical(void **state)
{
    output_fixture *f = *state;
    bk_config *c = ring("on", "1e-8", "1.2", "output.checkpoint_interval=0.4");
    char reference[256];
    snprintf(reference, sizeof reference, "%s/reference.h5", f->dir);
    run_into(c, reference, -1, 0);
    run_into(c, f->path, 2, 1);
    bk_config_free(c);

    bk_h5_writer *w;
    bk_config *resumed = NULL;
    bk_checkpoint cp;
    bk_error err = {0};
    char *part = part_path(f->path);
    if (bk_h5_writer_resume(&w, part, &resumed, &cp, &err) != BK_OK)
        fail_msg("resume: %s", err.message);
    assert_true(cp.t == 0.8);
    bk_sink sink = bk_h5_writer_sink(w);
    bk_run_stats stats;
    if (bk_run_from(resumed, &cp, &sink, &stats, NULL, NULL, &err) != BK_OK)
        fail_msg("run: %s", err.message);
    assert_int_equal(bk_h5_writer_finish(w, &stats, &err), BK_OK);
    assert_int_equal(stats.segments, 8);
    bk_checkpoint_free(&cp);
    bk_config_free(resumed);
    assert_same_output(reference, f->path);
}

/* Where the chain does not stay one island, or the back-end cannot publish its predictor,
 * local_stepping = auto leaves islands whole; method = auto picks it for a long ring. */
static void test_where_it_applies(void **state)
{
    (void)state;
    bk_error err = {0};
    bk_run_stats stats;
    rupture_log *log = calloc(1, sizeof *log);
    assert_non_null(log);
    /* method = auto on an 80-block ring: cvode_bdf, cut into segments. */
    const char *auto_ring[] = {"model.n_blocks=80", "solver.method=auto", "run.t_end=0.2", "output.interval=0"};
    bk_config *c = NULL;
    assert_int_equal(bk_config_load_file(SCENE, auto_ring, 4, &c, &err), BK_OK);
    run_logged(c, log, &stats);
    assert_string_equal(stats.method, "cvode_bdf (auto)");
    assert_int_equal(stats.segments, 10); /* the default segment_blocks, 8 */
    bk_config_free(c);
    /* The same ring with gsl_msbdf: no predictor to publish, whole. */
    const char *msbdf[] = {"model.n_blocks=64", "solver.method=gsl_msbdf", "run.t_end=0.05", "output.interval=0"};
    assert_int_equal(bk_config_load_file(SCENE, msbdf, 4, &c, &err), BK_OK);
    run_logged(c, log, &stats);
    assert_int_equal(stats.segments, 0);
    bk_config_free(c);
    /* Under 72 blocks auto keeps the ring whole (it costs more in segments there). */
    const char *short_ring[] = {"model.n_blocks=64", "solver.method=auto", "run.t_end=0.05", "output.interval=0"};
    assert_int_equal(bk_config_load_file(SCENE, short_ring, 4, &c, &err), BK_OK);
    run_logged(c, log, &stats);
    assert_int_equal(stats.segments, 0);
    bk_config_free(c);
    free(log);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_window_reproduces_whole_chain),
        cmocka_unit_test(test_lattice_dashpots_history),
        OUTPUT_TEST(test_resume_bit_identical),
        cmocka_unit_test(test_where_it_applies),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
