/* Checkpoints: everything a run needs to continue from time t, independent of the solver
 * back-end (which restarts there anyway: a checkpoint is a forced restart, so a resumed run
 * computes exactly what the uninterrupted one did).
 *
 * One field-descriptor table (bk_checkpoint_fields) drives allocation, the checksum and the
 * HDF5 slot writer and reader, as REBOUND's binary field table drives its save, load and
 * compare.  Adding a field means: the struct member, its row in the table (src/checkpoint.c),
 * and its capture and restore in the run loop (src/run_restart.c) — nothing else. */
#ifndef BKSIM_CHECKPOINT_H
#define BKSIM_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/catalog.h"
#include "bksim/sink.h"

/* Arrays have n_blocks entries (state: n_state).  Keep every member 8 bytes wide (or an
 * array pointer): tests/test_checkpoint.c proves each byte of the struct is described by
 * the table, which padding would defeat. */
struct bk_checkpoint {
    double t;                  /* s */
    size_t n_blocks, n_state;
    int8_t *mode;              /* bk_mode */
    double *x, *v;             /* m, m/s */
    double *state;             /* friction states */
    double *t_switch;          /* s, when each block last started slipping */
    uint8_t *from_rest;        /* that slip started at rest */
    uint8_t *extremum_armed;   /* slip-rate minimum root live */
    double *last_transition;   /* s, chattering guard */
    long *instant_count;       /* chattering guard */
    long next_sample;          /* index of the next sample time */
    double work_driver, dissipation;         /* J, since t = 0 */
    double damping_dissipation;              /* J, since t = 0 */
    double elastic_initial, kinetic_initial; /* J, at t = 0 (for the energy residual) */
    double t_last_row;         /* s */
    long steps_since_row;
    bk_run_stats stats;        /* counters up to t */
    bk_catalog_state *catalog; /* the event catalog builder; NULL when the run keeps none */
};

/* Allocate the arrays of a checkpoint for n blocks and s states (free with
 * bk_checkpoint_free; variable fields are allocated by whoever fills them, with malloc);
 * BK_ERR_NOMEM on failure (nothing left allocated). */
int bk_checkpoint_alloc(bk_checkpoint *checkpoint, size_t n_blocks, size_t n_state);
/* Add the catalog part (its arrays for n_blocks); BK_ERR_NOMEM on failure. */
int bk_checkpoint_alloc_catalog(bk_checkpoint *checkpoint);
void bk_checkpoint_free(bk_checkpoint *checkpoint);

/* ---- the field-descriptor table ---- */

typedef enum bk_checkpoint_type {
    BK_CHECKPOINT_I8,   /* int8_t */
    BK_CHECKPOINT_U8,   /* uint8_t */
    BK_CHECKPOINT_F64,  /* double */
    BK_CHECKPOINT_LONG  /* long, stored as a 64-bit integer */
} bk_checkpoint_type;

typedef enum bk_checkpoint_extent {
    BK_CHECKPOINT_SCALAR,    /* the member itself */
    BK_CHECKPOINT_PER_BLOCK, /* a pointer to n_blocks values */
    BK_CHECKPOINT_PER_STATE, /* a pointer to n_state values */
    BK_CHECKPOINT_VARIABLE   /* a pointer to doubles and, right after it, a long holding their
                                count: stored (and hashed) only when the count is non-zero, so
                                files written without the field verify as they did */
} bk_checkpoint_extent;

typedef struct bk_checkpoint_field {
    const char *name; /* name in a checkpoint slot: a dataset for arrays, else an attribute */
    int catalog;      /* a member of *catalog (bk_catalog_state), present only with one */
    bk_checkpoint_type type;
    bk_checkpoint_extent extent;
    size_t offset;    /* offsetof(bk_checkpoint or bk_catalog_state, member) */
    int if_nonzero;   /* a scalar added after the format: written and hashed only when non-zero,
                         read as 0 where absent, so earlier files verify as they did */
} bk_checkpoint_field;

/* In the order written and hashed (part of the file format: files written by earlier
 * versions verify only in this order).  n_blocks, n_state and stats are framed separately:
 * the counts size the arrays before anything else can be read, and stats is a group of
 * its own (bk_run_stats_fields). */
extern const bk_checkpoint_field bk_checkpoint_fields[];
extern const size_t bk_checkpoint_n_fields;

size_t bk_checkpoint_type_size(bk_checkpoint_type type);
/* Whether this checkpoint has the field (a catalog field only with a catalog). */
int bk_checkpoint_field_present(const bk_checkpoint_field *field, const bk_checkpoint *cp);
/* Whether a slot holds the field: present, and non-zero if it is an if_nonzero one. */
int bk_checkpoint_field_stored(const bk_checkpoint_field *field, const bk_checkpoint *cp);
/* Values the field holds in this checkpoint: 1, n_blocks, n_state or a variable field's
 * count (0 when absent). */
size_t bk_checkpoint_field_count(const bk_checkpoint_field *field, const bk_checkpoint *cp);
/* Where the values are: the array for array fields, the member itself for scalars.  NULL when
 * absent. */
void *bk_checkpoint_field_data(const bk_checkpoint_field *field, bk_checkpoint *cp);
const void *bk_checkpoint_field_cdata(const bk_checkpoint_field *field, const bk_checkpoint *cp);

/* The counters of bk_run_stats, described the same way: a checkpoint's stats group and an
 * output file's /stats group hold one attribute each (the method string aside). */
typedef struct bk_stat_field {
    const char *name;
    int is_long;      /* long, else double */
    size_t offset;    /* offsetof(bk_run_stats, member) */
    const char *units;
    int if_nonzero;   /* as bk_checkpoint_field's */
} bk_stat_field;

extern const bk_stat_field bk_run_stats_fields[];
extern const size_t bk_run_stats_n_fields;
/* The counter is zero (what decides whether an if_nonzero one is written and hashed). */
int bk_stat_is_zero(const bk_run_stats *stats, const bk_stat_field *field);

/* ---- integrity ---- */

/* Where the output stood when a checkpoint was written, so that a restart can truncate
 * every dataset to it and check that the rows it counts are there. */
typedef struct bk_checkpoint_record {
    long long sequence;        /* 1 for a run's first checkpoint */
    long long rows;            /* rows of every time series at the checkpoint */
    long long transition_rows;
    double last_transition_t;  /* s, t of /transitions[transition_rows - 1]; 0 without */
} bk_checkpoint_record;

/* FNV-1a (64 bit) over the record, the counts, every table field, the stats and the method:
 * a slot whose checksum does not match was written only in part, or altered. */
uint64_t bk_checkpoint_hash(const bk_checkpoint *cp, const bk_checkpoint_record *record);

#endif
