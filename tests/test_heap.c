/* The indexed min-heap (src/heap.c) against a plain array, over random inserts, key
 * changes, removals and pops; ties come out by item number. */
#include <stdlib.h>

#include "bk_test.h"
#include "heap.h"

#define ITEMS 200

/* The smallest key among present items (ties: the smaller item), or ITEMS when none. */
static size_t reference_top(const double *key, const int *present)
{
    size_t best = ITEMS;
    for (size_t i = 0; i < ITEMS; ++i)
        if (present[i] && (best == ITEMS || key[i] < key[best]))
            best = i;
    return best;
}

static void test_against_reference(void **state)
{
    (void)state;
    bk_heap heap;
    assert_int_equal(bk_heap_init(&heap, 16), 0);
    assert_int_equal(bk_heap_reserve(&heap, ITEMS), 0);
    double key[ITEMS];
    int present[ITEMS] = {0};
    size_t count = 0;
    srand(2385);
    for (int op = 0; op < 20000; ++op) {
        size_t item = (size_t)rand() % ITEMS;
        int what = rand() % 4;
        /* Few distinct keys, so ties are frequent. */
        double value = (double)(rand() % 50) * 0.125;
        if (what <= 1) {
            count += !present[item];
            present[item] = 1;
            key[item] = value;
            bk_heap_set(&heap, item, value);
        } else if (what == 2) {
            count -= present[item] != 0;
            present[item] = 0;
            bk_heap_remove(&heap, item);
        } else if (count > 0) {
            size_t expected = reference_top(key, present);
            assert_int_equal(bk_heap_top(&heap), expected);
            assert_true(bk_heap_top_key(&heap) == key[expected]);
            assert_int_equal(bk_heap_pop(&heap), expected);
            present[expected] = 0;
            --count;
        }
        assert_int_equal(heap.count, count);
        assert_int_equal(bk_heap_contains(&heap, item), present[item]);
    }
    /* Draining gives nondecreasing keys, ties in item order. */
    double last = -1.0;
    size_t last_item = 0;
    while (!bk_heap_empty(&heap)) {
        double k = bk_heap_top_key(&heap);
        size_t i = bk_heap_pop(&heap);
        assert_true(k > last || (k == last && i > last_item));
        last = k;
        last_item = i;
    }
    bk_heap_clear(&heap);
    assert_true(bk_heap_empty(&heap));
    bk_heap_free(&heap);
}

/* Infinite keys (a block that never fails) sort last and can be updated like any other. */
static void test_infinite_keys(void **state)
{
    (void)state;
    bk_heap heap;
    assert_int_equal(bk_heap_init(&heap, 4), 0);
    bk_heap_set(&heap, 0, INFINITY);
    bk_heap_set(&heap, 1, 2.0);
    bk_heap_set(&heap, 2, INFINITY);
    assert_int_equal(bk_heap_top(&heap), 1);
    bk_heap_set(&heap, 2, 1.0);
    assert_int_equal(bk_heap_pop(&heap), 2);
    assert_int_equal(bk_heap_pop(&heap), 1);
    assert_true(isinf(bk_heap_top_key(&heap)));
    bk_heap_clear(&heap);
    assert_false(bk_heap_contains(&heap, 0));
    bk_heap_free(&heap);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_against_reference),
        cmocka_unit_test(test_infinite_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
