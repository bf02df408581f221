/* Bit-for-bit comparison of two output files (restart equivalence, crash-restart loops). */
#include "same_output.h"

#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "layout.h"

void assert_same_output(const char *a, const char *b)
{
    /* Every series of the layout table, so a dataset added there is compared too. */
    bk_error err = {0};
    for (int k = 0; k < BK_N_SERIES; ++k) {
        const char *const name = bk_series[k].name;
        double *da = NULL, *db = NULL;
        size_t ra, ca, rb, cb;
        int in_a = bk_h5_read_doubles(a, name, &da, &ra, &ca, &err) == BK_OK;
        int in_b = bk_h5_read_doubles(b, name, &db, &rb, &cb, &err) == BK_OK;
        assert_int_equal(in_a, in_b);
        if (in_a) {
            assert_int_equal(ra, rb);
            assert_int_equal(ca, cb);
            assert_memory_equal(da, db, ra * ca * sizeof *da);
        }
        free(da);
        free(db);
    }
    bk_transition *ta = NULL, *tb = NULL;
    size_t na, nb;
    assert_int_equal(bk_h5_read_transitions(a, &ta, &na, &err), BK_OK);
    assert_int_equal(bk_h5_read_transitions(b, &tb, &nb, &err), BK_OK);
    assert_int_equal(na, nb);
    for (size_t k = 0; k < na; ++k) { /* field by field: the struct has padding */
        assert_true(memcmp(&ta[k].t, &tb[k].t, sizeof ta[k].t) == 0);
        assert_true(memcmp(&ta[k].x, &tb[k].x, sizeof ta[k].x) == 0);
        assert_true(memcmp(&ta[k].v, &tb[k].v, sizeof ta[k].v) == 0);
        assert_true(memcmp(&ta[k].force, &tb[k].force, sizeof ta[k].force) == 0);
        assert_true(ta[k].block == tb[k].block && ta[k].from == tb[k].from && ta[k].to == tb[k].to);
    }
    free(ta);
    free(tb);
    bk_event *ea = NULL, *eb = NULL;
    size_t ma = 0, mb = 0;
    int events_a = bk_h5_read_events(a, &ea, &ma, &err) == BK_OK;
    int events_b = bk_h5_read_events(b, &eb, &mb, &err) == BK_OK;
    assert_int_equal(events_a, events_b);
    assert_int_equal(ma, mb);
    for (size_t k = 0; k < ma; ++k)
        assert_same_event(&ea[k], &eb[k]);
    free(ea);
    free(eb);
    assert_same_ruptures(a, b);
}

/* Field by field (the structs have padding), bit for bit. */
#define SAME_BITS(x, y) assert_memory_equal(&(x), &(y), sizeof(x))

void assert_same_ruptures(const char *a, const char *b)
{
    bk_error err = {0};
    bk_rupture *ra = NULL, *rb = NULL;
    size_t na = 0, nb = 0;
    int in_a = bk_h5_read_ruptures(a, &ra, &na, &err) == BK_OK;
    int in_b = bk_h5_read_ruptures(b, &rb, &nb, &err) == BK_OK;
    assert_int_equal(in_a, in_b);
    assert_int_equal(na, nb);
    for (size_t k = 0; k < na; ++k) {
        SAME_BITS(ra[k].t_start, rb[k].t_start);
        SAME_BITS(ra[k].t_end, rb[k].t_end);
        SAME_BITS(ra[k].potency, rb[k].potency);
        SAME_BITS(ra[k].magnitude, rb[k].magnitude);
        SAME_BITS(ra[k].max_slip_rate, rb[k].max_slip_rate);
        SAME_BITS(ra[k].stress_drop, rb[k].stress_drop);
        SAME_BITS(ra[k].duration, rb[k].duration);
        SAME_BITS(ra[k].front_speed_left, rb[k].front_speed_left);
        SAME_BITS(ra[k].front_speed_right, rb[k].front_speed_right);
        assert_true(ra[k].first_block == rb[k].first_block && ra[k].n_blocks == rb[k].n_blocks &&
                    ra[k].left == rb[k].left && ra[k].right == rb[k].right &&
                    ra[k].n_episodes == rb[k].n_episodes && ra[k].complete == rb[k].complete);
    }
    free(ra);
    free(rb);
    bk_rupture_block *ba = NULL, *bb = NULL;
    in_a = bk_h5_read_rupture_blocks(a, &ba, &na, &err) == BK_OK;
    in_b = bk_h5_read_rupture_blocks(b, &bb, &nb, &err) == BK_OK;
    assert_int_equal(in_a, in_b);
    assert_int_equal(na, nb);
    for (size_t k = 0; k < na; ++k) {
        SAME_BITS(ba[k].t_onset, bb[k].t_onset);
        SAME_BITS(ba[k].t_stop, bb[k].t_stop);
        SAME_BITS(ba[k].slip, bb[k].slip);
        assert_true(ba[k].rupture == bb[k].rupture && ba[k].block == bb[k].block);
    }
    free(ba);
    free(bb);
    bk_rupture_rate *qa = NULL, *qb = NULL;
    in_a = bk_h5_read_rupture_rate(a, &qa, &na, &err) == BK_OK;
    in_b = bk_h5_read_rupture_rate(b, &qb, &nb, &err) == BK_OK;
    assert_int_equal(in_a, in_b);
    assert_int_equal(na, nb);
    for (size_t k = 0; k < na; ++k) {
        SAME_BITS(qa[k].t, qb[k].t);
        SAME_BITS(qa[k].rate, qb[k].rate);
        assert_true(qa[k].rupture == qb[k].rupture);
    }
    free(qa);
    free(qb);
}

void assert_same_event(const bk_event *a, const bk_event *b)
{
    const double fa[] = {a->t_start, a->t_end, a->potency, a->magnitude, a->max_slip_rate, a->stress_drop};
    const double fb[] = {b->t_start, b->t_end, b->potency, b->magnitude, b->max_slip_rate, b->stress_drop};
    assert_memory_equal(fa, fb, sizeof fa);
    assert_int_equal(a->first_block, b->first_block);
    assert_int_equal(a->n_blocks, b->n_blocks);
    assert_int_equal(a->left, b->left);
    assert_int_equal(a->right, b->right);
    assert_int_equal(a->n_episodes, b->n_episodes);
    assert_int_equal(a->complete, b->complete);
}
