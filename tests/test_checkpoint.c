/* The checkpoint's field-descriptor tables: every member of bk_checkpoint and bk_run_stats
 * is described (so the slot writer, reader and checksum cannot miss one), the allocation
 * follows the table, and the checksum changes with every value a restart uses. */
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/checkpoint.h"

/* Marks bytes [offset, offset + size) of a struct as described; a byte described twice is
 * a table error too. */
static void cover(unsigned char *covered, size_t struct_size, size_t offset, size_t size,
                  const char *name)
{
    if (offset + size > struct_size)
        fail_msg("%s: bytes %zu..%zu lie outside the struct (%zu bytes)", name, offset,
                 offset + size, struct_size);
    for (size_t b = offset; b < offset + size; ++b) {
        if (covered[b])
            fail_msg("%s: byte %zu is described twice", name, b);
        covered[b] = 1;
    }
}

static void expect_all_covered(const unsigned char *covered, size_t struct_size, const char *what)
{
    for (size_t b = 0; b < struct_size; ++b)
        if (!covered[b])
            fail_msg("%s: byte %zu is described by no row of its field table: a member was "
                     "added to the struct but not to the table (or a narrow member left "
                     "padding; keep members 8 bytes wide)", what, b);
}

/* A member missing from bk_checkpoint_fields leaves bytes of the struct undescribed. */
static void test_every_checkpoint_member_described(void **state)
{
    (void)state;
    unsigned char covered[sizeof(bk_checkpoint)] = {0};
    unsigned char covered_catalog[sizeof(bk_catalog_state)] = {0};
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
        const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
        size_t size = f->extent == BK_CHECKPOINT_SCALAR     ? bk_checkpoint_type_size(f->type)
                      : f->extent == BK_CHECKPOINT_VARIABLE ? sizeof(void *) + sizeof(long)
                                                            : sizeof(void *);
        if (f->catalog)
            cover(covered_catalog, sizeof covered_catalog, f->offset, size, f->name);
        else
            cover(covered, sizeof covered, f->offset, size, f->name);
    }
    expect_all_covered(covered_catalog, sizeof covered_catalog, "bk_catalog_state");
    cover(covered, sizeof covered, offsetof(bk_checkpoint, catalog), sizeof(void *), "catalog");
    /* Framed outside the table: the counts that size the arrays, and the stats group. */
    cover(covered, sizeof covered, offsetof(bk_checkpoint, n_blocks), sizeof(size_t), "n_blocks");
    cover(covered, sizeof covered, offsetof(bk_checkpoint, n_state), sizeof(size_t), "n_state");
    cover(covered, sizeof covered, offsetof(bk_checkpoint, stats), sizeof(bk_run_stats), "stats");
    expect_all_covered(covered, sizeof covered, "bk_checkpoint");
}

static void test_every_stat_described(void **state)
{
    (void)state;
    unsigned char covered[sizeof(bk_run_stats)] = {0};
    for (size_t k = 0; k < bk_run_stats_n_fields; ++k) {
        const bk_stat_field *f = &bk_run_stats_fields[k];
        size_t size = sizeof(double);
        if (f->is_long)
            size = sizeof(long);
        cover(covered, sizeof covered, f->offset, size, f->name);
        assert_non_null(f->units);
    }
    cover(covered, sizeof covered, offsetof(bk_run_stats, method),
          sizeof(((bk_run_stats *)0)->method), "method");
    expect_all_covered(covered, sizeof covered, "bk_run_stats");
}

/* Names are dataset or attribute names of one slot group: unique, and not the names the
 * slot's frame uses. */
static void test_names_unique(void **state)
{
    (void)state;
    static const char *const framed[] = {"n_blocks", "n_state", "rows", "transition_rows",
                                         "last_transition_t", "sequence", "stats", "checksum", "catalog",
                                         "units", "description"};
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
        const char *name = bk_checkpoint_fields[k].name;
        assert_true(name && *name);
        for (size_t j = k + 1; j < bk_checkpoint_n_fields; ++j)
            if (strcmp(name, bk_checkpoint_fields[j].name) == 0)
                fail_msg("checkpoint field name '%s' used twice", name);
        for (size_t j = 0; j < sizeof framed / sizeof framed[0]; ++j)
            if (strcmp(name, framed[j]) == 0)
                fail_msg("checkpoint field name '%s' is taken by the slot's frame", name);
    }
}

/* Every array the table names is allocated with its count (the sanitizer build catches a
 * short one when the last element is written), and free leaves nothing behind. */
static void test_alloc_follows_table(void **state)
{
    (void)state;
    const size_t sizes[][2] = {{1, 0}, {7, 3}, {1000, 2000}};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
        bk_checkpoint cp;
        assert_int_equal(bk_checkpoint_alloc(&cp, sizes[s][0], sizes[s][1]), BK_OK);
        assert_int_equal(bk_checkpoint_alloc_catalog(&cp), BK_OK);
        assert_int_equal(cp.n_blocks, sizes[s][0]);
        assert_int_equal(cp.n_state, sizes[s][1]);
        for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
            const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
            void *data = bk_checkpoint_field_data(f, &cp);
            if (f->extent == BK_CHECKPOINT_VARIABLE) { /* filled by whoever has values */
                assert_null(data);
                assert_int_equal(bk_checkpoint_field_count(f, &cp), 0);
                continue;
            }
            assert_non_null(data);
            size_t count = bk_checkpoint_field_count(f, &cp);
            if (count > 0)
                memset(data, 0x5a, count * bk_checkpoint_type_size(f->type));
        }
        bk_checkpoint_free(&cp);
        assert_null(cp.x);
        assert_null(cp.catalog);
        assert_int_equal(cp.n_blocks, 0);
    }
}

/* Value i of a field, set from a double (integers take its integer part). */
static void set_value(const bk_checkpoint_field *f, bk_checkpoint *cp, size_t i, double value)
{
    char *data = bk_checkpoint_field_data(f, cp);
    size_t size = bk_checkpoint_type_size(f->type);
    int8_t i8 = (int8_t)value;
    uint8_t u8 = (uint8_t)value;
    long l = (long)value;
    const void *from = &value;
    if (f->type == BK_CHECKPOINT_I8)
        from = &i8;
    else if (f->type == BK_CHECKPOINT_U8)
        from = &u8;
    else if (f->type == BK_CHECKPOINT_LONG)
        from = &l;
    memcpy(data + i * size, from, size);
}

static double get_value(const bk_checkpoint_field *f, bk_checkpoint *cp, size_t i)
{
    const char *data = bk_checkpoint_field_data(f, cp);
    size_t size = bk_checkpoint_type_size(f->type);
    int8_t i8;
    uint8_t u8;
    long l;
    double d;
    switch (f->type) {
    case BK_CHECKPOINT_I8:
        memcpy(&i8, data + i * size, size);
        return i8;
    case BK_CHECKPOINT_U8:
        memcpy(&u8, data + i * size, size);
        return u8;
    case BK_CHECKPOINT_LONG:
        memcpy(&l, data + i * size, size);
        return (double)l;
    case BK_CHECKPOINT_F64:
        break;
    }
    memcpy(&d, data + i * size, size);
    return d;
}

/* A checkpoint with distinct values everywhere (high-entropy, not round numbers). */
static void fill(bk_checkpoint *cp)
{
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
        const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
        size_t count = bk_checkpoint_field_count(f, cp);
        for (size_t i = 0; i < count; ++i) {
            double value = 2.385 * (double)(k + 1) + 0.173 * (double)i;
            if (f->type == BK_CHECKPOINT_I8)
                value = (double)((int)(k + i) % 3 - 1);
            else if (f->type == BK_CHECKPOINT_U8)
                value = (double)((k + i) % 2);
            else if (f->type == BK_CHECKPOINT_LONG)
                value = (double)(17 * k + 3 * i + 5);
            set_value(f, cp, i, value);
        }
    }
    for (size_t k = 0; k < bk_run_stats_n_fields; ++k) {
        char *member = (char *)&cp->stats + bk_run_stats_fields[k].offset;
        if (bk_run_stats_fields[k].is_long) {
            long value = (long)(31 * k + 7);
            memcpy(member, &value, sizeof value);
        } else {
            double value = 1.618 * (double)(k + 1);
            memcpy(member, &value, sizeof value);
        }
    }
    snprintf(cp->stats.method, sizeof cp->stats.method, "cvode_bdf");
}

/* A checkpoint of 5 blocks and 4 states with a catalog: every field present, a variable
 * one with 6 values (freed by bk_checkpoint_free, as one read from a file). */
static void alloc_full(bk_checkpoint *cp)
{
    assert_int_equal(bk_checkpoint_alloc(cp, 5, 4), BK_OK);
    assert_int_equal(bk_checkpoint_alloc_catalog(cp), BK_OK);
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
        const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
        if (f->extent != BK_CHECKPOINT_VARIABLE)
            continue;
        double *values = calloc(6, sizeof *values);
        long count = 6;
        assert_non_null(values);
        char *member = (f->catalog ? (char *)cp->catalog : (char *)cp) + f->offset;
        memcpy(member, &values, sizeof values);
        memcpy(member + sizeof values, &count, sizeof count);
    }
}

/* Perturb value i of field f by the smallest change its type allows. */
static void nudge(const bk_checkpoint_field *f, bk_checkpoint *cp, size_t i)
{
    double value = get_value(f, cp, i);
    if (f->type == BK_CHECKPOINT_F64)
        set_value(f, cp, i, nextafter(value, INFINITY));
    else if (f->type == BK_CHECKPOINT_LONG)
        set_value(f, cp, i, value + 1.0);
    else /* modes and flags: a valid other value */
        set_value(f, cp, i, value == 1.0 ? 0.0 : 1.0);
}

/* No value a restart uses escapes the checksum: changing any one of them (the last entry of
 * an array, each scalar, each counter, the method, the record) changes the hash. */
static void test_checksum_covers_every_value(void **state)
{
    (void)state;
    bk_checkpoint cp;
    alloc_full(&cp);
    fill(&cp);
    bk_checkpoint_record rec = {3, 1234, 56, 7.25};
    uint64_t base = bk_checkpoint_hash(&cp, &rec);
    assert_true(base == bk_checkpoint_hash(&cp, &rec)); /* deterministic */
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
        const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
        size_t last = bk_checkpoint_field_count(f, &cp) - 1;
        nudge(f, &cp, last);
        if (bk_checkpoint_hash(&cp, &rec) == base)
            fail_msg("checkpoint field '%s' is not covered by the checksum", f->name);
        bk_checkpoint_free(&cp);
        alloc_full(&cp);
        fill(&cp);
        assert_true(bk_checkpoint_hash(&cp, &rec) == base);
    }
    for (size_t k = 0; k < bk_run_stats_n_fields; ++k) {
        bk_checkpoint_free(&cp);
        alloc_full(&cp);
        fill(&cp);
        char *member = (char *)&cp.stats + bk_run_stats_fields[k].offset;
        member[0] ^= 1;
        if (bk_checkpoint_hash(&cp, &rec) == base)
            fail_msg("stat '%s' is not covered by the checksum", bk_run_stats_fields[k].name);
    }
    bk_checkpoint_free(&cp);
    alloc_full(&cp);
    fill(&cp);
    cp.stats.method[0] = 'C';
    assert_true(bk_checkpoint_hash(&cp, &rec) != base);
    cp.stats.method[0] = 'c';
    const bk_checkpoint_record changed[] = {
        {4, 1234, 56, 7.25}, {3, 1235, 56, 7.25}, {3, 1234, 57, 7.25}, {3, 1234, 56, 7.5}};
    for (size_t k = 0; k < sizeof changed / sizeof changed[0]; ++k)
        assert_true(bk_checkpoint_hash(&cp, &changed[k]) != base);
    bk_checkpoint_free(&cp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_checkpoint_member_described),
        cmocka_unit_test(test_every_stat_described),
        cmocka_unit_test(test_names_unique),
        cmocka_unit_test(test_alloc_follows_table),
        cmocka_unit_test(test_checksum_covers_every_value),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
