/* The integrity check behind `bksim info` and `bksim run --restart`: every dataset the
 * writer created is there with the right shape, every value reads back (so every chunk's
 * Fletcher32 checksum is checked) and makes sense, /transitions is ordered and valid, and the
 * checkpoint verifies as a restart requires. */
#include "bksim/inspect.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "output/h5_impl.h"

/* What a check needs to know about the file as a whole. */
typedef struct verify_ctx {
    const char *path;
    long long n_blocks;
    double t_end, t_reached;
    int complete;
} verify_ctx;

/* Every value of one time series, streamed a block of rows at a time: finite, modes and
 * event flags from their sets, /time increasing up to t_reached (and t_end when complete),
 * strictly but for the two rows of a transition instant (/event 2 then 1, at one time).  A
 * chunk failing its checksum fails the read: damaged. */
static int scan_series(hid_t file, const verify_ctx *v, const char *name, bk_error *err)
{
    const char *path = v->path;
    hid_t dset;
    hsize_t rows, cols;
    int rank;
    if (bk_h5_open_series(file, path, name, &dset, &rows, &cols, &rank, err) != BK_OK)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s cannot be read", path, name);
    int is_time = strcmp(name, "time") == 0;
    int is_mode = strcmp(name, "mode") == 0;
    int is_event = strcmp(name, "event") == 0;
    hsize_t step = bk_h5_slab_rows(dset, cols);
    if (step > rows)
        step = rows ? rows : 1;
    double *buf = malloc((size_t)(step * cols) * sizeof *buf);
    /* /time is read with /event beside it: equal times are a transition instant's pair. */
    hid_t event_dset = H5I_INVALID_HID;
    hsize_t event_rows = 0, event_cols = 0;
    int event_rank = 0;
    double *kind = is_time ? malloc((size_t)step * sizeof *kind) : NULL;
    int rc = buf && (!is_time || kind) ? BK_OK : BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    if (rc == BK_OK && is_time &&
        (bk_h5_open_series(file, path, "event", &event_dset, &event_rows, &event_cols, &event_rank, err) != BK_OK ||
         event_rows != rows || event_rank != 1))
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /event does not match /time", path);
    double prev = NAN, before = NAN; /* the value before this one; the block's last */
    double prev_kind = NAN;
    for (hsize_t start = 0; rc == BK_OK && start < rows; start += step) {
        hsize_t count = rows - start < step ? rows - start : step;
        if (bk_h5_read_block(dset, rank, start, count, 0, cols, H5T_NATIVE_DOUBLE, buf) < 0 ||
            (is_time && bk_h5_read_block(event_dset, 1, start, count, 0, 1, H5T_NATIVE_DOUBLE, kind) < 0)) {
            rc = H5_DAMAGED(err, "%s: damaged: /%s rows %llu..%llu cannot be read", path, name,
                            (unsigned long long)start, (unsigned long long)(start + count - 1));
            break;
        }
        size_t values = (size_t)(count * cols);
        for (size_t k = 0; rc == BK_OK && k < values; ++k) {
            double x = buf[k];
            int pair = is_time && prev_kind == BK_ROW_BEFORE_TRANSITION;
            int in_order = !is_time || start + k == 0 ||
                           (pair ? x == prev && kind[k] == BK_ROW_AFTER_TRANSITION : x > prev);
            int valid = is_mode    ? x == -1.0 || x == 0.0 || x == 1.0
                        : is_event ? x == BK_ROW_SAMPLE || x == BK_ROW_AFTER_TRANSITION ||
                                         x == BK_ROW_BEFORE_TRANSITION
                                   : isfinite(x) && in_order;
            prev = x;
            if (is_time)
                prev_kind = kind[k];
            if (valid)
                continue;
            unsigned long long row = (unsigned long long)start + k / (size_t)cols;
            unsigned long long col = k % (size_t)cols;
            char where[64];
            if (rank == 2)
                snprintf(where, sizeof where, "row %llu column %llu", row, col);
            else
                snprintf(where, sizeof where, "row %llu", row);
            if (is_mode)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /mode %s is %g, not a mode "
                             "(stick 0, slip+ 1, slip- -1)", path, where, x);
            else if (is_event)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /event %s is %g, not 0, 1 or 2",
                             path, where, x);
            else if (!isfinite(x))
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s %s is %g, not finite", path,
                             name, where, x);
            else if (pair)
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: row %llu (t = %.17g s, /event %g) is not "
                             "the after row (/event 1, same time) of the before row %llu (t = %.17g s)",
                             path, row, x, kind[k], row - 1, k ? buf[k - 1] : before);
            else
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /time is not strictly increasing "
                             "at row %llu (%.17g after %.17g)", path, row, x, k ? buf[k - 1] : before);
        }
        before = buf[values - 1];
    }
    free(buf);
    free(kind);
    bk_h5_close_id(dset);
    if (event_dset != H5I_INVALID_HID)
        bk_h5_close_id(event_dset);
    if (rc != BK_OK || !is_time)
        return rc;
    if (rows > 0 && prev_kind == BK_ROW_BEFORE_TRANSITION)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: the last row (/event 2) is a transition "
                       "instant's before row without its after row", path);
    if (rows > 0 && prev != v->t_reached)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: t_reached (%.17g) is not the last time "
                       "(%.17g)", path, v->t_reached, prev);
    if (v->complete && (rows == 0 || fabs(prev - v->t_end) > 1e-9 * fabs(v->t_end)))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: marked complete but /time ends at %.17g, "
                       "not t_end = %.17g", path, rows ? prev : NAN, v->t_end);
    return BK_OK;
}

static int valid_mode(int8_t mode)
{
    return mode == -1 || mode == 0 || mode == 1;
}

/* /transitions in time order, each of an existing block, between modes, at a time the run
 * reached, with finite values.  The bound is t_reached for a complete run; an unfinished
 * run may have flushed transitions after its last row (with event_rows off there is no row
 * at a transition), so there it is t_end. */
/* Restate the error just recorded as damage to path; its message is copied first, since
 * BK_FAIL formats into the same buffer. */
static int mark_damaged(bk_error *err, const char *path, const char *fallback)
{
    char reason[BK_ERROR_MESSAGE_LEN];
    snprintf(reason, sizeof reason, "%s", err && err->message[0] ? err->message : fallback);
    return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: %s", path, reason);
}

typedef struct transition_check {
    const verify_ctx *v;
    double bound; /* s: no transition after this */
    double prev;  /* s: the last row's time */
} transition_check;

static int check_transition(const bk_transition *t, unsigned long long row, void *user, bk_error *err)
{
    transition_check *c = user;
    const verify_ctx *v = c->v;
    const char *path = v->path;
    int rc = BK_OK;
    if (!isfinite(t->t) || !isfinite(t->x) || !isfinite(t->v) || !isfinite(t->force))
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu has a value "
                     "that is not finite (t %g, x %g, v %g, force %g)", path, row, t->t,
                     t->x, t->v, t->force);
    else if (t->t < c->prev)
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions is not in time order "
                     "at row %llu (t = %.17g s after %.17g s)", path, row, t->t, c->prev);
    else if (t->t > c->bound)
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu is at "
                     "t = %.17g s, after the %s (%.17g s)", path, row, t->t,
                     v->complete ? "end of the run" : "run's t_end",
                     v->complete ? v->t_reached : v->t_end);
    else if (t->block < 0 || t->block >= v->n_blocks)
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu names block "
                     "%d, outside 0..%lld", path, row, (int)t->block, v->n_blocks - 1);
    else if (!valid_mode(t->from) || !valid_mode(t->to))
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu goes from "
                     "mode %d to %d; modes are stick 0, slip+ 1, slip- -1", path, row,
                     (int)t->from, (int)t->to);
    c->prev = t->t;
    return rc;
}

static int scan_transitions(hid_t file, const verify_ctx *v, bk_error *err)
{
    double bound = v->complete ? v->t_reached : v->t_end;
    transition_check check = {v, bound + 1e-9 * fabs(bound), 0.0};
    hsize_t count = 0;
    int rc = bk_h5_each_transition(file, v->path, check_transition, &check, &count, err);
    /* A table that does not open is damage too (the file says it wrote one). */
    if (rc == BK_ERR_HDF5)
        return mark_damaged(err, v->path, "/transitions cannot be read");
    return rc;
}

typedef struct event_check {
    const verify_ctx *v;
    double prev; /* s, the end of the row before */
} event_check;

/* One /events row as a catalog bksim wrote holds it. */
static int check_event(const bk_event *e, unsigned long long row, void *user, bk_error *err)
{
    event_check *c = user;
    const char *path = c->v->path;
    long long n = c->v->n_blocks;
    int blocks_ok = e->first_block >= 0 && e->first_block < n && e->left >= 0 && e->left < n &&
                    e->right >= 0 && e->right < n && e->n_blocks >= 1 && e->n_blocks <= n &&
                    e->n_episodes >= e->n_blocks;
    if (!isfinite(e->t_start) || !isfinite(e->t_end) || !(e->t_end >= e->t_start) || !(e->potency >= 0.0) ||
        isnan(e->magnitude) || !isfinite(e->stress_drop) || !(e->max_slip_rate >= 0.0))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /events row %llu has values no event has "
                       "(t_start %g, t_end %g, potency %g, magnitude %g, max_slip_rate %g, stress_drop %g)",
                       path, row, e->t_start, e->t_end, e->potency, e->magnitude, e->max_slip_rate,
                       e->stress_drop);
    if (!blocks_ok || (e->complete != 0 && e->complete != 1))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /events row %llu: first_block %d, left %d, "
                       "right %d, n_blocks %d, n_episodes %d, complete %d (blocks 0..%lld)", path, row,
                       (int)e->first_block, (int)e->left, (int)e->right, (int)e->n_blocks,
                       (int)e->n_episodes, (int)e->complete, n - 1);
    if (e->t_start < c->prev)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /events is not in time order at row %llu "
                       "(t_start = %.17g s after an event that ended at %.17g s)", path, row, e->t_start, c->prev);
    c->prev = e->t_end;
    return BK_OK;
}

/* Every /events row read (the chunk checksums) and checked; a table that does not open is
 * damage too (the file says it wrote one). */
static int scan_events(hid_t file, const verify_ctx *v, bk_error *err)
{
    event_check check = {v, -INFINITY};
    hsize_t count = 0;
    int rc = bk_h5_each_event(file, v->path, check_event, &check, &count, err);
    if (rc == BK_ERR_HDF5 || rc == BK_ERR_INVALID)
        return mark_damaged(err, v->path, "/events cannot be read");
    return rc;
}

/* ------------------------------------------------------------ the rupture tables --- */

typedef struct rupture_check {
    const verify_ctx *v;
    long long ruptures;       /* rows of /ruptures */
    long long limit;          /* the largest rupture a block or rate row may name: the last row,
                                 or in a run cut short the one whose row was still to come */
    long long block_rows;     /* the sum of their n_blocks: the rows /rupture_blocks must have */
    long long last;           /* rupture of the row before (blocks and rate), -1 at first */
    double t_last;            /* s, t of the rate row before */
} rupture_check;

static int check_rupture(const void *record, unsigned long long row, rupture_check *c, bk_error *err)
{
    const bk_rupture *r = record;
    long long n = c->v->n_blocks;
    int blocks_ok = r->first_block >= 0 && r->first_block < n && r->left >= 0 && r->left < n && r->right >= 0 &&
                    r->right < n && r->n_blocks >= 1 && r->n_blocks <= n && r->n_episodes >= r->n_blocks &&
                    (r->complete == 0 || r->complete == 1);
    if (!isfinite(r->t_start) || !(r->t_end >= r->t_start) || !isfinite(r->t_end) || !isfinite(r->potency) ||
        isnan(r->magnitude) || !(r->max_slip_rate >= 0.0) || !isfinite(r->stress_drop) ||
        !(r->duration == r->t_end - r->t_start) || !blocks_ok)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /ruptures row %llu has values no rupture has "
                       "(t_start %g, t_end %g, duration %g, potency %g, first_block %d, n_blocks %d, "
                       "n_episodes %d, complete %d; blocks 0..%lld)", c->v->path, row, r->t_start, r->t_end,
                       r->duration, r->potency, (int)r->first_block, (int)r->n_blocks, (int)r->n_episodes,
                       (int)r->complete, n - 1);
    c->block_rows += r->n_blocks;
    return BK_OK;
}

static int check_rupture_block(const void *record, unsigned long long row, rupture_check *c, bk_error *err)
{
    const bk_rupture_block *b = record;
    if (b->rupture < 0 || b->rupture > c->limit || b->rupture < c->last || b->block < 0 ||
        b->block >= c->v->n_blocks || !isfinite(b->t_onset) || !(b->t_stop >= b->t_onset) || !isfinite(b->slip))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /rupture_blocks row %llu: rupture %lld (of %lld, "
                       "in order), block %d, t_onset %g, t_stop %g, slip %g", c->v->path, row,
                       (long long)b->rupture, c->ruptures, (int)b->block, b->t_onset, b->t_stop, b->slip);
    c->last = b->rupture;
    return BK_OK;
}

static int check_rupture_rate(const void *record, unsigned long long row, rupture_check *c, bk_error *err)
{
    const bk_rupture_rate *q = record;
    int in_order = q->rupture > c->last || (q->rupture == c->last && q->t > c->t_last);
    if (q->rupture < 0 || q->rupture > c->limit || !in_order || !isfinite(q->t) || !(q->rate >= 0.0) ||
        !isfinite(q->rate))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /rupture_rate row %llu: rupture %lld (of %lld), "
                       "t %.17g s (after %.17g s), rate %g m/s", c->v->path, row, (long long)q->rupture,
                       c->ruptures, q->t, c->t_last, q->rate);
    c->last = q->rupture;
    c->t_last = q->t;
    return BK_OK;
}

/* Every row of a rupture table read (the chunk checksums), 4096 at a time, and checked;
 * *rows gets the table's length. */
static int scan_rupture_table(hid_t file, bk_h5_table_kind kind, rupture_check *c,
                              int (*check)(const void *, unsigned long long, rupture_check *, bk_error *),
                              hsize_t *rows, bk_error *err)
{
    const char *name = bk_h5_tables[kind].name;
    size_t size = bk_h5_tables[kind].struct_bytes;
    const hsize_t slab = 4096;
    hid_t dset = H5Dopen2(file, name, H5P_DEFAULT);
    hid_t mem = bk_h5_table_type(kind, BK_H5_RECORD_STRUCT);
    hid_t space = dset < 0 ? H5I_INVALID_HID : H5Dget_space(dset);
    unsigned char *buf = malloc((size_t)slab * size);
    int rc = BK_OK;
    *rows = 0;
    if (dset < 0 || mem < 0 || space < 0 || H5Sget_simple_extent_ndims(space) != 1 ||
        H5Sget_simple_extent_dims(space, rows, NULL) < 0)
        rc = H5_DAMAGED(err, "%s: damaged: /%s cannot be opened", c->v->path, name);
    else if (!buf)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory checking /%s", c->v->path, name);
    for (hsize_t start = 0; rc == BK_OK && start < *rows; start += slab) {
        hsize_t n = *rows - start < slab ? *rows - start : slab;
        if (bk_h5_read_block(dset, 1, start, n, 0, 1, mem, buf) < 0) {
            rc = H5_DAMAGED(err, "%s: damaged: /%s rows %llu..%llu cannot be read", c->v->path, name,
                            (unsigned long long)start, (unsigned long long)(start + n - 1));
            break;
        }
        for (hsize_t k = 0; rc == BK_OK && k < n; ++k)
            rc = check(buf + (size_t)k * size, (unsigned long long)(start + k), c, err);
    }
    free(buf);
    CLOSE_IDS(rc == BK_OK ? 0 : -1, space, mem, dset);
    return rc;
}

/* The three tables of the rupture catalog: each row as bksim writes it, the blocks and rate
 * rows of existing ruptures in rupture order, and as many block rows as the ruptures have
 * blocks.  A rupture's blocks and rate go out before its row, so a run cut short may hold
 * those of one rupture more. */
static int scan_ruptures(hid_t file, const verify_ctx *v, bk_error *err)
{
    rupture_check c = {v, 0, 0, 0, -1, -INFINITY};
    hsize_t rows = 0, block_rows = 0, rate_rows = 0;
    int rc = scan_rupture_table(file, BK_TABLE_RUPTURES, &c, check_rupture, &rows, err);
    c.ruptures = (long long)rows;
    c.limit = v->complete ? c.ruptures - 1 : c.ruptures;
    if (rc == BK_OK && H5Lexists(file, "rupture_blocks", H5P_DEFAULT) <= 0)
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /ruptures without /rupture_blocks", v->path);
    if (rc == BK_OK)
        rc = scan_rupture_table(file, BK_TABLE_RUPTURE_BLOCKS, &c, check_rupture_block, &block_rows, err);
    if (rc == BK_OK && (v->complete ? (long long)block_rows != c.block_rows : (long long)block_rows < c.block_rows))
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /rupture_blocks has %llu rows, the ruptures of "
                     "/ruptures %lld blocks", v->path, (unsigned long long)block_rows, c.block_rows);
    c.last = -1;
    if (rc == BK_OK && H5Lexists(file, "rupture_rate", H5P_DEFAULT) > 0)
        rc = scan_rupture_table(file, BK_TABLE_RUPTURE_RATE, &c, check_rupture_rate, &rate_rows, err);
    return rc;
}

/* The datasets a file must hold: those its writer recorded, or for a file written before
 * that record, those its stored config selects (time, driver, event if it does not load).
 * Malloc'ed, comma-separated; NULL when out of memory. */
static char *expected_datasets(hid_t file)
{
    char *names = bk_h5_recorded_datasets(file);
    if (names)
        return names;
    bk_config *config = NULL;
    bk_error ignored;
    char list[BK_DATASET_LIST_LEN] = "time,driver,event";
    if (bk_h5_load_stored_config(file, "", &config, &ignored) == BK_OK)
        bk_output_dataset_names(config->output.fields, config->model->n_friction_state,
                                bk_model_is_damped(config->model), config->output.transitions,
                                /* files without the record predate the rupture tables */
                                config->output.events ? BK_CATALOG_EVENTS : 0u, list, sizeof list);
    bk_config_free(config);
    return strdup(list);
}

/* The integrity check on an open file (see bk_h5_verify). */
int bk_h5_verify_open(hid_t file, const char *path, bk_error *err)
{
    verify_ctx v = {path, 0, NAN, NAN, 0};
    if (bk_h5_read_numeric_attr(file, "complete", H5T_NATIVE_INT, &v.complete) < 0 ||
        bk_h5_read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, &v.n_blocks) < 0 ||
        bk_h5_read_numeric_attr(file, "t_end", H5T_NATIVE_DOUBLE, &v.t_end) < 0 ||
        bk_h5_read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &v.t_reached) < 0)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: a root attribute (complete, n_blocks, t_end, "
                       "t_reached) is missing", path);
    if (v.n_blocks < 1 || !isfinite(v.t_end) || !(v.t_end > 0.0))
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: root attributes n_blocks = %lld, t_end = %g "
                       "are not a run's", path, v.n_blocks, v.t_end);
    int rc = bk_h5_require_datasets(file, path, "time,driver,event", err);
    if (rc != BK_OK)
        return rc;
    char *expected = expected_datasets(file);
    if (!expected)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    rc = bk_h5_require_datasets(file, path, expected, err);
    free(expected);
    if (rc != BK_OK)
        return rc;
    hid_t time;
    hsize_t rows, cols;
    int rank;
    rc = bk_h5_open_series(file, path, "time", &time, &rows, &cols, &rank, err);
    if (rc != BK_OK)
        return mark_damaged(err, path, "/time");
    bk_h5_close_id(time);
    if (rank != 1)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /time has rank %d, not 1", path, rank);
    bk_h5_name_list list;
    if (bk_h5_list_series(file, &list) != 0)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: cannot list the datasets", path);
    /* Shapes first: a short series is named as such rather than as a read error. */
    for (size_t k = 0; rc == BK_OK && k < list.count; ++k) {
        hid_t d;
        hsize_t r, c;
        int rk;
        if (bk_h5_open_series(file, path, list.names[k], &d, &r, &c, &rk, err) != BK_OK) {
            rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s cannot be read", path, list.names[k]);
            continue;
        }
        bk_h5_close_id(d);
        int per_block = rk == 2 && strcmp(list.names[k], "friction_state") != 0;
        if (r != rows)
            rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s has %llu rows, /time has %llu", path,
                         list.names[k], (unsigned long long)r, (unsigned long long)rows);
        else if (per_block && (long long)c != v.n_blocks)
            rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s has %llu columns for %lld blocks", path,
                         list.names[k], (unsigned long long)c, v.n_blocks);
    }
    /* /time before the others, so that its own faults are named first. */
    if (rc == BK_OK)
        rc = scan_series(file, &v, "time", err);
    for (size_t k = 0; rc == BK_OK && k < list.count; ++k)
        if (strcmp(list.names[k], "time") != 0)
            rc = scan_series(file, &v, list.names[k], err);
    bk_h5_name_list_free(&list);
    if (rc == BK_OK && H5Lexists(file, "transitions", H5P_DEFAULT) > 0)
        rc = scan_transitions(file, &v, err);
    if (rc == BK_OK && H5Lexists(file, "events", H5P_DEFAULT) > 0)
        rc = scan_events(file, &v, err);
    if (rc == BK_OK && H5Lexists(file, "ruptures", H5P_DEFAULT) > 0)
        rc = scan_ruptures(file, &v, err);
    if (rc == BK_OK && H5Lexists(file, "checkpoint", H5P_DEFAULT) > 0) {
        bk_h5_slot slot;
        bk_error why = {0};
        int found = bk_h5_find_checkpoint(file, path, (size_t)v.n_blocks, &slot, &why);
        if (found == BK_OK)
            bk_checkpoint_free(&slot.checkpoint);
        else if (!slot.legacy && found != BK_ERR_INVALID) /* no damage: an older bksim's checkpoint
                                                        cannot be verified; a first one torn */
            rc = BK_FAIL(err, found, "%s", why.message);
    }
    if (rc != BK_OK)
        return rc;
    return v.complete ? BK_OK : BK_INCOMPLETE;
}

int bk_h5_verify(const char *path, bk_error *err)
{
    hid_t file;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    rc = bk_h5_verify_open(file, path, err);
    bk_h5_close_id(file);
    return rc;
}
