/* The partition into islands and quiet blocks (scene.h), rebuilt around the blocks whose
 * modes changed.  An island is a connected component of the graph whose edges join each
 * slipping block to its coupling partners: a stuck block next to two slipping ones joins
 * them, two stuck blocks side by side do not.  A stuck block with no slipping partner is
 * quiet.  On a chain this gives runs of blocks; on a lattice any shape.
 *
 * Why a rebuild around the changed blocks is enough: every slipping block lies in an island
 * together with all its partners, so the region made of the changed blocks, their partners
 * and every island those touch holds every slipping block whose component can have
 * changed, and all of its partners.  The cost is that of the region, never of the chain.
 *
 * An island's blocks are listed row by row from a corner chosen so that the island does
 * not straddle a periodic seam where it need not: on a chain its run from the first block,
 * as the chain's order is; on a lattice, coupled blocks at most a row apart in y. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "run_ctx.h"

int bk_run_partition_init(run_ctx *ctx)
{
    size_t n = ctx->scene.n, lines = ctx->model->rows > ctx->model->cols ? ctx->model->rows : ctx->model->cols;
    ctx->region = calloc(n, sizeof *ctx->region);
    ctx->region_pos = calloc(n, sizeof *ctx->region_pos);
    ctx->members = malloc(n * sizeof *ctx->members);
    ctx->visited = malloc(n * sizeof *ctx->visited);
    ctx->lines = malloc(lines * sizeof *ctx->lines);
    ctx->line_seen = calloc(lines, sizeof *ctx->line_seen);
    ctx->n_region = 0;
    return ctx->region && ctx->region_pos && ctx->members && ctx->visited && ctx->lines && ctx->line_seen ? 0 : -1;
}

void bk_run_partition_free(run_ctx *ctx)
{
    free(ctx->region);
    free(ctx->region_pos);
    free(ctx->members);
    free(ctx->visited);
    free(ctx->lines);
    free(ctx->line_seen);
}

/* Block i is in the region: a sparse set, so nothing is cleared between rebuilds. */
static int in_region(const run_ctx *ctx, size_t i)
{
    size_t k = ctx->region_pos[i];
    return k < ctx->n_region && ctx->region[k] == i;
}

static void region_add(run_ctx *ctx, size_t i)
{
    if (in_region(ctx, i))
        return;
    ctx->region_pos[i] = ctx->n_region;
    ctx->region[ctx->n_region++] = i;
}

/* Where the island's order starts along one periodic direction (columns, or rows) of `len`
 * lines: the first occupied line after the widest empty stretch.  When every line is
 * occupied, the first line no spring in the ODE joins to the one before (only stuck blocks
 * meet there, as where two stuck blocks split a ring), else 0. */
static size_t cut_of(run_ctx *ctx, size_t count, int columns, size_t len)
{
    const bk_scene *scene = &ctx->scene;
    uint8_t *seen = ctx->line_seen; /* zero between calls */
    size_t *lines = ctx->lines, cols = ctx->model->cols;
    size_t distinct = 0, starts = 0, start = 0;
    for (size_t k = 0; k < count; ++k) {
        size_t line = columns ? ctx->members[k] % cols : ctx->members[k] / cols;
        if (!seen[line]) {
            seen[line] = 1;
            lines[distinct++] = line;
        }
    }
    for (size_t k = 0; k < distinct; ++k)
        if (!seen[lines[k] == 0 ? len - 1 : lines[k] - 1]) {
            ++starts;
            start = lines[k];
        }
    if (starts > 1) {
        /* Several empty stretches (a lattice island's outline): the widest one ends the order. */
        qsort(lines, distinct, sizeof *lines, bk_compare_blocks);
        size_t widest = len - lines[distinct - 1] + lines[0];
        start = lines[0];
        for (size_t k = 1; k < distinct; ++k)
            if (lines[k] - lines[k - 1] > widest) {
                widest = lines[k] - lines[k - 1];
                start = lines[k];
            }
    }
    if (starts == 0) {
        for (size_t k = 0; k < count; ++k) {
            size_t b = ctx->members[k];
            long p = bk_scene_partners(scene, b)[columns ? BK_LEFT : BK_UP];
            if (p >= 0 && (!bk_scene_stuck(scene, b) || !bk_scene_stuck(scene, (size_t)p)))
                seen[columns ? b % cols : b / cols] = 2;
        }
        for (size_t line = 0; line < len; ++line)
            if (seen[line] == 1) {
                start = line;
                break;
            }
    }
    for (size_t k = 0; k < distinct; ++k)
        seen[lines[k]] = 0;
    return start;
}

/* The component's blocks (ctx->members[0 .. count)) into the island's order: row-major from
 * the cut corner.  Keys that are consecutive (every chain's) need no sort. */
static void order_members(run_ctx *ctx, size_t count)
{
    const bk_model *model = ctx->model;
    size_t rows = model->rows, cols = model->cols, *members = ctx->members;
    size_t row_cut = model->boundary_rows == BK_BOUNDARY_PERIODIC && rows > 1 ? cut_of(ctx, count, 0, rows) : 0;
    size_t col_cut = model->boundary_cols == BK_BOUNDARY_PERIODIC && cols > 1 ? cut_of(ctx, count, 1, cols) : 0;
    size_t lo = SIZE_MAX, hi = 0;
    for (size_t k = 0; k < count; ++k) {
        size_t row = members[k] / cols, col = members[k] % cols;
        size_t key = (row + rows - row_cut) % rows * cols + (col + cols - col_cut) % cols;
        members[k] = key;
        lo = key < lo ? key : lo;
        hi = key > hi ? key : hi;
    }
    if (hi - lo + 1 == count)
        for (size_t k = 0; k < count; ++k)
            members[k] = lo + k;
    else
        qsort(members, count, sizeof *members, bk_compare_blocks);
    for (size_t k = 0; k < count; ++k) {
        size_t row = (members[k] / cols + row_cut) % rows, col = (members[k] % cols + col_cut) % cols;
        members[k] = row * cols + col;
    }
}

/* The component in ctx->members as one island, or under local time stepping as segments of
 * about segment_blocks consecutive blocks of its order (a lattice's: runs of its rows). */
static int found_segments(run_ctx *ctx, size_t count, double t)
{
    size_t size = ctx->segment_blocks;
    if (size == 0 || count <= size)
        return bk_run_found_island(ctx, ctx->members, count, t);
    size_t pieces = (count + size - 1) / size;
    int rc = bk_run_segments_prepare(ctx, ctx->members, count, pieces, t);
    for (size_t p = 0; p < pieces && rc == BK_OK; ++p) {
        size_t first = p * count / pieces, last = (p + 1) * count / pieces;
        rc = bk_run_found_island(ctx, ctx->members + first, last - first, t);
    }
    return rc;
}

/* Islands and quiet blocks over the region (no block of it in an island; see the top). */
static int rebuild(run_ctx *ctx, double t)
{
    const bk_scene *scene = &ctx->scene;
    uint8_t *visited = ctx->visited; /* by region position */
    memset(visited, 0, ctx->n_region * sizeof *visited);
    for (size_t k = 0; k < ctx->n_region; ++k) {
        if (visited[k] || bk_scene_stuck(scene, ctx->region[k]))
            continue;
        /* The component of this slipping block: breadth first, through slipping blocks only. */
        size_t count = 0;
        ctx->members[count++] = ctx->region[k];
        visited[k] = 1;
        for (size_t q = 0; q < count; ++q) {
            size_t b = ctx->members[q];
            int slipping = !bk_scene_stuck(scene, b);
            const long *partner = bk_scene_partners(scene, b);
            for (size_t d = 0; d < scene->n_directions; ++d) {
                long p = partner[d];
                if (p < 0 || (!slipping && bk_scene_stuck(scene, (size_t)p)))
                    continue;
                if (!in_region(ctx, (size_t)p))
                    return BK_FAIL(ctx->err, BK_ERR_INTERNAL, "partition: block %zu's partner %ld lies outside "
                                   "the region rebuilt at t = %.17g s", b, p, t);
                size_t pk = ctx->region_pos[p];
                if (!visited[pk]) {
                    visited[pk] = 1;
                    ctx->members[count++] = (size_t)p;
                }
            }
        }
        order_members(ctx, count);
        int rc = found_segments(ctx, count, t);
        if (rc != BK_OK)
            return rc;
    }
    for (size_t k = 0; k < ctx->n_region; ++k)
        if (!visited[k])
            bk_run_make_quiet(ctx, ctx->region[k], t);
    return BK_OK;
}

int bk_run_repartition(run_ctx *ctx, const size_t *seeds, size_t n_seeds, double t, size_t taken)
{
    const bk_scene *scene = &ctx->scene;
    ctx->n_region = 0;
    for (size_t k = 0; k < n_seeds; ++k) {
        region_add(ctx, seeds[k]);
        const long *partner = bk_scene_partners(scene, seeds[k]);
        for (size_t d = 0; d < scene->n_directions; ++d)
            if (partner[d] >= 0)
                region_add(ctx, (size_t)partner[d]);
    }
    /* Every island the region touches dissolves into it (the region grows as it goes). */
    for (size_t k = 0; k < ctx->n_region; ++k) {
        size_t id = scene->island_of[ctx->region[k]];
        if (id == BK_NO_ISLAND)
            continue;
        const bk_island *island = &ctx->islands[id]->island;
        for (size_t m = 0; m < island->len; ++m)
            region_add(ctx, island->blocks[m]);
        int rc = bk_run_dissolve(ctx, id, t, id == taken);
        if (rc != BK_OK)
            return rc;
    }
    return rebuild(ctx, t);
}

static int descending(const void *a, const void *b)
{
    return bk_compare_blocks(b, a);
}

int bk_run_partition_all(run_ctx *ctx, double t)
{
    for (size_t id = 0; id < ctx->islands_used; ++id)
        if (ctx->islands[id]->live) {
            int rc = bk_run_dissolve(ctx, id, t, 1);
            if (rc != BK_OK)
                return rc;
        }
    bk_heap_clear(&ctx->quiet);
    bk_run_drain_pool(ctx);
    /* Ids handed out smallest first, as in a run that starts here: the scheduler breaks ties
     * between islands by id, and segments at one time are not independent of the order in
     * which they step, so a resumed run must number them as the uninterrupted one. */
    if (ctx->n_free > 1)
        qsort(ctx->free_ids, ctx->n_free, sizeof *ctx->free_ids, descending);
    ctx->n_region = 0;
    for (size_t i = 0; i < ctx->scene.n; ++i)
        region_add(ctx, i);
    return rebuild(ctx, t);
}
