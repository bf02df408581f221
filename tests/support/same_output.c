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
