/* Checkpoints: the field-descriptor tables, allocation and the checksum (see checkpoint.h).
 * Nothing here knows HDF5; src/output/h5_checkpoint.c frames the table into file slots. */
#include "bksim/checkpoint.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define ARRAY(name, member, type, extent) \
    {name, 0, BK_CHECKPOINT_##type, BK_CHECKPOINT_##extent, offsetof(bk_checkpoint, member), 0}
#define SCALAR(member, type) \
    {#member, 0, BK_CHECKPOINT_##type, BK_CHECKPOINT_SCALAR, offsetof(bk_checkpoint, member), 0}
/* The catalog builder's state: after the rest, so files without it hash as before. */
#define CATALOG_ARRAY(member, type) \
    {"catalog_" #member, 1, BK_CHECKPOINT_##type, BK_CHECKPOINT_PER_BLOCK, offsetof(bk_catalog_state, member), 0}
#define CATALOG_SCALAR(member, type) \
    {"catalog_" #member, 1, BK_CHECKPOINT_##type, BK_CHECKPOINT_SCALAR, offsetof(bk_catalog_state, member), 0}

const bk_checkpoint_field bk_checkpoint_fields[] = {
    ARRAY("mode", mode, I8, PER_BLOCK),
    ARRAY("x", x, F64, PER_BLOCK),
    ARRAY("v", v, F64, PER_BLOCK),
    ARRAY("friction_state", state, F64, PER_STATE),
    ARRAY("t_switch", t_switch, F64, PER_BLOCK),
    ARRAY("from_rest", from_rest, U8, PER_BLOCK),
    ARRAY("extremum_armed", extremum_armed, U8, PER_BLOCK),
    ARRAY("last_transition", last_transition, F64, PER_BLOCK),
    ARRAY("instant_count", instant_count, LONG, PER_BLOCK),
    SCALAR(t, F64),
    SCALAR(work_driver, F64),
    SCALAR(dissipation, F64),
    SCALAR(elastic_initial, F64),
    SCALAR(kinetic_initial, F64),
    SCALAR(t_last_row, F64),
    SCALAR(next_sample, LONG),
    SCALAR(steps_since_row, LONG),
    {"damping_dissipation", 0, BK_CHECKPOINT_F64, BK_CHECKPOINT_SCALAR, offsetof(bk_checkpoint, damping_dissipation), 1},
    CATALOG_ARRAY(x_onset, F64),
    CATALOG_ARRAY(first_force, F64),
    CATALOG_ARRAY(last_force, F64),
    CATALOG_ARRAY(involved, U8),
    CATALOG_ARRAY(slipping, U8),
    CATALOG_SCALAR(open, LONG),
    CATALOG_SCALAR(pending, LONG),
    CATALOG_SCALAR(t_pending, F64),
    CATALOG_SCALAR(t_start, F64),
    CATALOG_SCALAR(first_block, LONG),
    CATALOG_SCALAR(n_episodes, LONG),
    CATALOG_SCALAR(potency, F64),
    CATALOG_SCALAR(max_slip_rate, F64),
    CATALOG_SCALAR(events, LONG),
    {"catalog_rupture_state", 1, BK_CHECKPOINT_F64, BK_CHECKPOINT_VARIABLE, offsetof(bk_catalog_state, rupture_state), 0},
};
const size_t bk_checkpoint_n_fields = sizeof bk_checkpoint_fields / sizeof bk_checkpoint_fields[0];

#undef ARRAY
#undef SCALAR
#undef CATALOG_ARRAY
#undef CATALOG_SCALAR

#define STAT_L(member, units) {#member, 1, offsetof(bk_run_stats, member), units, 0}
#define STAT_D(member, units) {#member, 0, offsetof(bk_run_stats, member), units, 0}
const bk_stat_field bk_run_stats_fields[] = {
    STAT_L(steps, "1"),          STAT_L(rhs_evals, "1"),
    STAT_L(root_evals, "1"),     STAT_L(err_test_fails, "1"),
    STAT_L(nonlin_iters, "1"),   STAT_L(integrator_starts, "1"),
    STAT_L(stuck_jumps, "1"),    STAT_L(transitions, "1"),
    STAT_L(rows, "1"),           STAT_D(t_reached, "s"),
    STAT_D(wall_time, "s"),      STAT_D(cpu_time, "s"),
    STAT_D(work_driver, "J"),    STAT_D(dissipation, "J"),
    STAT_D(elastic_change, "J"), STAT_D(kinetic_change, "J"),
    STAT_D(energy_residual, "1"),
    {"damping_dissipation", 0, offsetof(bk_run_stats, damping_dissipation), "J", 1},
    {"segments", 1, offsetof(bk_run_stats, segments), "1", 1},
    {"coupling_error", 0, offsetof(bk_run_stats, coupling_error), "1", 1},
    {"coupling_exceedances", 1, offsetof(bk_run_stats, coupling_exceedances), "1", 1},
};
const size_t bk_run_stats_n_fields = sizeof bk_run_stats_fields / sizeof bk_run_stats_fields[0];
#undef STAT_L
#undef STAT_D

size_t bk_checkpoint_type_size(bk_checkpoint_type type)
{
    switch (type) {
    case BK_CHECKPOINT_I8:
        return sizeof(int8_t);
    case BK_CHECKPOINT_U8:
        return sizeof(uint8_t);
    case BK_CHECKPOINT_F64:
        return sizeof(double);
    case BK_CHECKPOINT_LONG:
        break;
    }
    return sizeof(long);
}

static char *field_base(const bk_checkpoint_field *field, const bk_checkpoint *cp);

size_t bk_checkpoint_field_count(const bk_checkpoint_field *field, const bk_checkpoint *cp)
{
    if (!bk_checkpoint_field_present(field, cp))
        return 0;
    switch (field->extent) {
    case BK_CHECKPOINT_PER_BLOCK:
        return cp->n_blocks;
    case BK_CHECKPOINT_PER_STATE:
        return cp->n_state;
    case BK_CHECKPOINT_VARIABLE: {
        long count;
        memcpy(&count, field_base(field, cp) + field->offset + sizeof(double *), sizeof count);
        return count > 0 ? (size_t)count : 0;
    }
    case BK_CHECKPOINT_SCALAR:
        break;
    }
    return 1;
}

int bk_stat_is_zero(const bk_run_stats *stats, const bk_stat_field *field)
{
    const char *member = (const char *)stats + field->offset;
    if (field->is_long) {
        long value;
        memcpy(&value, member, sizeof value);
        return value == 0;
    }
    double value;
    memcpy(&value, member, sizeof value);
    return value == 0.0;
}

int bk_checkpoint_field_present(const bk_checkpoint_field *field, const bk_checkpoint *cp)
{
    return !field->catalog || cp->catalog != NULL;
}

int bk_checkpoint_field_stored(const bk_checkpoint_field *field, const bk_checkpoint *cp)
{
    if (!bk_checkpoint_field_present(field, cp))
        return 0;
    if (field->extent == BK_CHECKPOINT_VARIABLE)
        return bk_checkpoint_field_count(field, cp) > 0;
    if (!field->if_nonzero)
        return 1;
    double value;
    memcpy(&value, bk_checkpoint_field_cdata(field, cp), sizeof value);
    return value != 0.0;
}

/* The struct a field is a member of. */
static char *field_base(const bk_checkpoint_field *field, const bk_checkpoint *cp)
{
    return field->catalog ? (char *)cp->catalog : (char *)(uintptr_t)cp;
}

const void *bk_checkpoint_field_cdata(const bk_checkpoint_field *field, const bk_checkpoint *cp)
{
    return bk_checkpoint_field_data(field, (bk_checkpoint *)(uintptr_t)cp);
}

void *bk_checkpoint_field_data(const bk_checkpoint_field *field, bk_checkpoint *cp)
{
    if (!bk_checkpoint_field_present(field, cp))
        return NULL;
    char *member = field_base(field, cp) + field->offset;
    if (field->extent == BK_CHECKPOINT_SCALAR)
        return member;
    void *array;
    memcpy(&array, member, sizeof array);
    return array;
}

/* The arrays of one part (0: the checkpoint, 1: its catalog). */
static int alloc_arrays(bk_checkpoint *cp, int catalog)
{
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
        const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
        if (f->extent == BK_CHECKPOINT_SCALAR || f->extent == BK_CHECKPOINT_VARIABLE || f->catalog != catalog)
            continue;
        size_t count = bk_checkpoint_field_count(f, cp);
        /* At least one element, so a chain without friction states still gets a pointer. */
        void *array = calloc(count ? count : 1, bk_checkpoint_type_size(f->type));
        memcpy(field_base(f, cp) + f->offset, &array, sizeof array);
        if (!array) {
            bk_checkpoint_free(cp);
            return BK_ERR_NOMEM;
        }
    }
    return BK_OK;
}

int bk_checkpoint_alloc(bk_checkpoint *cp, size_t n_blocks, size_t n_state)
{
    memset(cp, 0, sizeof *cp);
    cp->n_blocks = n_blocks;
    cp->n_state = n_state;
    return alloc_arrays(cp, 0);
}

int bk_checkpoint_alloc_catalog(bk_checkpoint *cp)
{
    if (cp->catalog)
        return BK_OK;
    cp->catalog = calloc(1, sizeof *cp->catalog);
    if (!cp->catalog) {
        bk_checkpoint_free(cp);
        return BK_ERR_NOMEM;
    }
    return alloc_arrays(cp, 1);
}

void bk_checkpoint_free(bk_checkpoint *cp)
{
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k)
        if (bk_checkpoint_fields[k].extent != BK_CHECKPOINT_SCALAR)
            free(bk_checkpoint_field_data(&bk_checkpoint_fields[k], cp));
    free(cp->catalog);
    memset(cp, 0, sizeof *cp);
}

/* FNV-1a (64 bit).  Counts and scalars go in little-endian byte order, so a file copied to a
 * machine of the other byte order still verifies; arrays go as they lie in memory. */
#define FNV_OFFSET UINT64_C(14695981039346656037)
#define FNV_PRIME UINT64_C(1099511628211)

static uint64_t hash_u64(uint64_t h, uint64_t v)
{
    for (unsigned k = 0; k < 8; ++k) {
        h ^= (v >> (8 * k)) & 0xffu;
        h *= FNV_PRIME;
    }
    return h;
}

static uint64_t hash_f64(uint64_t h, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    return hash_u64(h, bits);
}

static uint64_t hash_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i) {
        h ^= (uint64_t)p[i];
        h *= FNV_PRIME;
    }
    return h;
}

/* A scalar field as a 64-bit value: doubles by their bits, integers by their value. */
static uint64_t hash_scalar(uint64_t h, bk_checkpoint_type type, const void *data)
{
    switch (type) {
    case BK_CHECKPOINT_F64: {
        double value;
        memcpy(&value, data, sizeof value);
        return hash_f64(h, value);
    }
    case BK_CHECKPOINT_I8:
        return hash_u64(h, (uint64_t)(int64_t)*(const int8_t *)data);
    case BK_CHECKPOINT_U8:
        return hash_u64(h, (uint64_t)*(const uint8_t *)data);
    case BK_CHECKPOINT_LONG:
        break;
    }
    long value;
    memcpy(&value, data, sizeof value);
    return hash_u64(h, (uint64_t)value);
}

uint64_t bk_checkpoint_hash(const bk_checkpoint *cp, const bk_checkpoint_record *rec)
{
    uint64_t h = FNV_OFFSET;
    h = hash_u64(h, (uint64_t)rec->sequence);
    h = hash_u64(h, (uint64_t)rec->rows);
    h = hash_u64(h, (uint64_t)rec->transition_rows);
    h = hash_f64(h, rec->last_transition_t);
    h = hash_u64(h, (uint64_t)cp->n_blocks);
    h = hash_u64(h, (uint64_t)cp->n_state);
    for (size_t k = 0; k < bk_checkpoint_n_fields; ++k) {
        const bk_checkpoint_field *f = &bk_checkpoint_fields[k];
        if (!bk_checkpoint_field_stored(f, cp))
            continue;
        const void *data = bk_checkpoint_field_cdata(f, cp);
        if (f->extent != BK_CHECKPOINT_SCALAR) {
            h = hash_bytes(h, data, bk_checkpoint_field_count(f, cp) * bk_checkpoint_type_size(f->type));
        } else {
            h = hash_scalar(h, f->type, data);
        }
    }
    for (size_t i = 0; i < bk_run_stats_n_fields; ++i) {
        const char *member = (const char *)&cp->stats + bk_run_stats_fields[i].offset;
        if (bk_run_stats_fields[i].if_nonzero && bk_stat_is_zero(&cp->stats, &bk_run_stats_fields[i]))
            continue;
        if (bk_run_stats_fields[i].is_long) {
            long value;
            memcpy(&value, member, sizeof value);
            h = hash_u64(h, (uint64_t)value);
        } else {
            double value;
            memcpy(&value, member, sizeof value);
            h = hash_f64(h, value);
        }
    }
    /* The method as read back: at most sizeof - 1 characters. */
    return hash_bytes(h, cp->stats.method, strnlen(cp->stats.method, sizeof cp->stats.method - 1));
}
