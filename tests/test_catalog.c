/* The event catalog builder: events from transition streams written out by hand, so every
 * field is known in advance. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bksim/catalog.h"
#include "bksim/modes.h"
#include "bk_test.h"

enum { STICK = BK_MODE_STICK, SLIP = BK_MODE_SLIP_POS, BACK = BK_MODE_SLIP_NEG };

static double from_array(const void *user, size_t i)
{
    return ((const double *)user)[i];
}

static bk_transition tr(double t, int32_t block, int from, int to, double x, double force)
{
    return (bk_transition){t, block, (int8_t)from, (int8_t)to, x, 0.0, force};
}

/* Feeds the transitions; returns how many events completed, copied to events[]. */
static size_t feed(bk_catalog *c, const bk_transition *list, size_t n, bk_event *events)
{
    size_t done_count = 0;
    for (size_t k = 0; k < n; ++k) {
        int done = 0;
        assert_int_equal(bk_catalog_add(c, &list[k], &events[done_count], &done), BK_OK);
        done_count += (size_t)done;
    }
    return done_count;
}

/* Two blocks slip in one event, which ends when the second sticks; the next onset, later,
 * completes it. */
static void test_one_event(void **state)
{
    (void)state;
    bk_catalog *c = bk_catalog_create(10, 0, 0.0);
    assert_non_null(c);
    const bk_transition list[] = {
        tr(1.0, 2, STICK, SLIP, 0.10, 6.0), tr(1.5, 3, STICK, SLIP, 0.20, 5.8),
        tr(2.0, 2, SLIP, STICK, 0.13, 4.0), tr(2.5, 3, SLIP, STICK, 0.21, 5.0),
        tr(3.0, 5, STICK, SLIP, 0.50, 6.0),
    };
    bk_event e[2];
    assert_int_equal(feed(c, list, 4, e), 0); /* nothing later has come: it may go on */
    assert_int_equal(feed(c, list + 4, 1, e), 1);
    assert_close(e[0].t_start, 1.0, 0.0, 0.0);
    assert_close(e[0].t_end, 2.5, 0.0, 0.0);
    assert_int_equal(e[0].first_block, 2);
    assert_int_equal(e[0].n_blocks, 2);
    assert_int_equal(e[0].left, 2);
    assert_int_equal(e[0].right, 3);
    assert_int_equal(e[0].n_episodes, 2);
    assert_close(e[0].potency, 0.03 + 0.01, 0.0, 1e-15);
    assert_close(e[0].magnitude, 2.0 / 3.0 * log10(0.04), 0.0, 1e-15);
    assert_close(e[0].stress_drop, ((6.0 - 4.0) + (5.8 - 5.0)) / 2.0, 0.0, 1e-15);
    assert_int_equal(e[0].complete, 1);
    bk_catalog_free(c);
}

/* Ruptures at opposite ends of a chain that overlap in time are one event by the
 * definition (some block slips throughout); a stick and an onset at the same instant keep
 * an event going; a block that slips twice counts once in n_blocks, twice in episodes. */
static void test_overlap_and_instants(void **state)
{
    (void)state;
    bk_catalog *c = bk_catalog_create(100, 0, 1.5);
    const bk_transition list[] = {
        tr(1.0, 0, STICK, SLIP, 0.0, 6.0),    tr(1.2, 99, STICK, SLIP, 1.0, 6.1),
        tr(1.5, 0, SLIP, STICK, 0.002, 5.0),  tr(2.0, 99, SLIP, STICK, 1.001, 5.1),
        tr(2.0, 50, STICK, SLIP, 0.5, 6.0),   /* same instant as the stick before */
        tr(2.1, 50, SLIP, STICK, 0.503, 4.0), tr(2.1, 0, STICK, SLIP, 0.002, 6.0),
        tr(2.4, 0, SLIP, BACK, 0.004, 6.0),   /* a reversal: the episode goes on */
        tr(2.6, 0, BACK, STICK, 0.003, 3.0),  tr(9.0, 7, STICK, SLIP, 0.07, 6.0),
    };
    bk_event e[2];
    assert_int_equal(feed(c, list, sizeof list / sizeof *list, e), 1);
    assert_close(e[0].t_start, 1.0, 0.0, 0.0);
    assert_close(e[0].t_end, 2.6, 0.0, 0.0);
    assert_int_equal(e[0].n_blocks, 3);
    assert_int_equal(e[0].n_episodes, 4);
    assert_int_equal(e[0].left, 0);
    assert_int_equal(e[0].right, 99);
    assert_close(e[0].potency, 0.002 + 0.001 + 0.003 + 0.001, 0.0, 1e-15);
    assert_close(e[0].magnitude, 2.0 / 3.0 * log10(0.007) + 1.5, 0.0, 1e-14);
    /* block 0: 6.0 at its first onset, 3.0 at its last stick */
    assert_close(e[0].stress_drop, ((6.0 - 3.0) + (6.1 - 5.1) + (6.0 - 4.0)) / 3.0, 0.0, 1e-15);
    bk_catalog_free(c);
}

/* On a ring the extent is the shorter arc that covers the blocks, wrapping past block 0. */
static void test_ring_extent(void **state)
{
    (void)state;
    bk_catalog *c = bk_catalog_create(10, 1, 0.0);
    const bk_transition list[] = {
        tr(1.0, 0, STICK, SLIP, 0.0, 1.0), tr(1.1, 9, STICK, SLIP, 0.0, 1.0),
        tr(1.2, 1, STICK, SLIP, 0.0, 1.0), tr(1.3, 0, SLIP, STICK, 0.1, 0.0),
        tr(1.3, 9, SLIP, STICK, 0.1, 0.0), tr(1.3, 1, SLIP, STICK, 0.1, 0.0),
        tr(2.0, 4, STICK, SLIP, 0.0, 1.0), tr(2.1, 6, STICK, SLIP, 0.0, 1.0),
        tr(2.2, 4, SLIP, STICK, 0.1, 0.0), tr(2.2, 6, SLIP, STICK, 0.1, 0.0),
        tr(3.0, 5, STICK, SLIP, 0.0, 1.0),
    };
    bk_event e[3];
    assert_int_equal(feed(c, list, sizeof list / sizeof *list, e), 2);
    assert_int_equal(e[0].left, 9); /* 9, 0, 1: wraps */
    assert_int_equal(e[0].right, 1);
    assert_int_equal(e[0].first_block, 0);
    assert_int_equal(e[1].left, 4); /* 4 and 6: the short way */
    assert_int_equal(e[1].right, 6);
    bk_catalog_free(c);
}

/* On a lattice the extent is the bounding box, left its top-left corner block and right its
 * bottom-right one; a periodic direction takes its shorter arc, as a ring does. */
static void test_lattice_extent(void **state)
{
    (void)state;
    /* 4 rows x 5 columns, periodic columns: block = 5 row + column. */
    bk_catalog *c = bk_catalog_create_lattice(4, 5, 0, 1, 0.0);
    const bk_transition list[] = {
        /* (1, 1), (2, 3), (3, 2): rows 1..3, columns 1..3 */
        tr(1.0, 6, STICK, SLIP, 0.0, 1.0), tr(1.1, 13, STICK, SLIP, 0.0, 1.0),
        tr(1.2, 17, STICK, SLIP, 0.0, 1.0), tr(1.3, 6, SLIP, STICK, 0.1, 0.0),
        tr(1.3, 13, SLIP, STICK, 0.1, 0.0), tr(1.3, 17, SLIP, STICK, 0.1, 0.0),
        /* (0, 4), (0, 0), (1, 0): row 0..1, columns 4 round to 0 */
        tr(2.0, 4, STICK, SLIP, 0.0, 1.0), tr(2.1, 0, STICK, SLIP, 0.0, 1.0),
        tr(2.1, 5, STICK, SLIP, 0.0, 1.0), tr(2.2, 4, SLIP, STICK, 0.1, 0.0),
        tr(2.2, 0, SLIP, STICK, 0.1, 0.0), tr(2.2, 5, SLIP, STICK, 0.1, 0.0),
        tr(3.0, 12, STICK, SLIP, 0.0, 1.0),
    };
    bk_event e[3];
    assert_int_equal(feed(c, list, sizeof list / sizeof *list, e), 2);
    assert_int_equal(e[0].n_blocks, 3);
    assert_int_equal(e[0].left, 1 * 5 + 1);
    assert_int_equal(e[0].right, 3 * 5 + 3);
    assert_int_equal(e[1].left, 0 * 5 + 4); /* columns wrap: left's column 4 > right's 0 */
    assert_int_equal(e[1].right, 1 * 5 + 0);
    bk_catalog_free(c);
    /* Without periodic columns the same blocks span columns 0..4. */
    c = bk_catalog_create_lattice(4, 5, 0, 0, 0.0);
    assert_int_equal(feed(c, list, sizeof list / sizeof *list, e), 2);
    assert_int_equal(e[1].left, 0);
    assert_int_equal(e[1].right, 1 * 5 + 4);
    bk_catalog_free(c);
    /* A torus: rows wrap too.  (3, 1), (0, 1), (0, 2): rows 3 round to 0, columns 1..2; and
     * (0, 0), (2, 0): rows 0..2 either way round on 4 rows, the first arc kept (no wrap). */
    c = bk_catalog_create_lattice(4, 5, 1, 1, 0.0);
    const bk_transition torus[] = {
        tr(1.0, 16, STICK, SLIP, 0.0, 1.0), tr(1.1, 1, STICK, SLIP, 0.0, 1.0),
        tr(1.1, 2, STICK, SLIP, 0.0, 1.0), tr(1.2, 16, SLIP, STICK, 0.1, 0.0),
        tr(1.2, 1, SLIP, STICK, 0.1, 0.0), tr(1.2, 2, SLIP, STICK, 0.1, 0.0),
        tr(2.0, 0, STICK, SLIP, 0.0, 1.0), tr(2.0, 10, STICK, SLIP, 0.0, 1.0),
        tr(2.1, 0, SLIP, STICK, 0.1, 0.0), tr(2.1, 10, SLIP, STICK, 0.1, 0.0),
        tr(3.0, 12, STICK, SLIP, 0.0, 1.0),
    };
    assert_int_equal(feed(c, torus, sizeof torus / sizeof *torus, e), 2);
    assert_int_equal(e[0].n_blocks, 3);
    assert_int_equal(e[0].left, 3 * 5 + 1); /* left's row 3 > right's row 0: wraps */
    assert_int_equal(e[0].right, 0 * 5 + 2);
    assert_int_equal(e[1].n_blocks, 2);
    assert_int_equal(e[1].left, 0);
    assert_int_equal(e[1].right, 2 * 5 + 0);
    bk_catalog_free(c);
}

/* Blocks slipping at the start open an event; one still running at the end of the run is
 * returned marked incomplete, its open episodes counted to the end; a pending end is
 * completed by the finish. */
static void test_begin_and_finish(void **state)
{
    (void)state;
    bk_catalog *c = bk_catalog_create(4, 0, 0.0);
    const int8_t mode[4] = {STICK, SLIP, SLIP, STICK};
    const double x0[4] = {0.0, 0.5, 0.7, 0.0}, f0[4] = {0.0, 6.0, 6.5, 0.0};
    assert_int_equal(bk_catalog_begin(c, 0.0, mode, x0, NULL, from_array, f0), BK_OK);
    const bk_transition list[] = {tr(0.5, 1, SLIP, STICK, 0.6, 5.0)};
    bk_event e;
    assert_int_equal(feed(c, list, 1, &e), 0);
    const double x1[4] = {0.0, 0.6, 0.75, 0.0}, f1[4] = {0.0, 5.0, 6.0, 0.0};
    assert_int_equal(bk_catalog_finish(c, 1.0, x1, from_array, f1, &e), 1);
    assert_int_equal(e.complete, 0);
    assert_close(e.t_start, 0.0, 0.0, 0.0);
    assert_close(e.t_end, 1.0, 0.0, 0.0);
    assert_int_equal(e.first_block, 1); /* both at t = 0: the lower index */
    assert_int_equal(e.n_blocks, 2);
    assert_close(e.potency, 0.1 + 0.05, 0.0, 1e-15);
    assert_close(e.stress_drop, ((6.0 - 5.0) + (6.5 - 6.0)) / 2.0, 0.0, 1e-15);
    assert_int_equal(bk_catalog_finish(c, 1.0, x1, from_array, f1, &e), 0); /* nothing left */
    bk_catalog_free(c);

    c = bk_catalog_create(4, 0, 0.0);
    const bk_transition pair[] = {tr(0.2, 3, STICK, SLIP, 0.0, 6.0), tr(0.4, 3, SLIP, STICK, 0.2, 4.0)};
    assert_int_equal(feed(c, pair, 2, &e), 0);
    assert_int_equal(bk_catalog_finish(c, 1.0, x1, from_array, f1, &e), 1);
    assert_int_equal(e.complete, 1);
    assert_close(e.t_end, 0.4, 0.0, 0.0);
    bk_catalog_free(c);
}

static void test_bad_block(void **state)
{
    (void)state;
    bk_catalog *c = bk_catalog_create(4, 0, 0.0);
    bk_transition bad = tr(1.0, 4, STICK, SLIP, 0.0, 0.0);
    bk_event e;
    int done = 0;
    assert_int_equal(bk_catalog_add(c, &bad, &e, &done), BK_ERR_INVALID);
    bad.block = -1;
    assert_int_equal(bk_catalog_add(c, &bad, &e, &done), BK_ERR_INVALID);
    assert_int_equal(done, 0);
    bk_catalog_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_event),
        cmocka_unit_test(test_overlap_and_instants),
        cmocka_unit_test(test_ring_extent),
        cmocka_unit_test(test_lattice_extent),
        cmocka_unit_test(test_begin_and_finish),
        cmocka_unit_test(test_bad_block),
    };
    return cmocka_run_group_tests_name("catalog", tests, NULL, NULL);
}
