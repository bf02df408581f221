/* Internal: the run loop's state, shared by run.c (set-up and the scheduler) and the files
 * it calls down into, one job each (listed at the end of this header with what they export). */
#ifndef BKSIM_RUN_CTX_H
#define BKSIM_RUN_CTX_H

#include <stddef.h>
#include <stdint.h>

#include <gsl/gsl_roots.h>

#include "bksim/catalog.h"
#include "bksim/checkpoint.h"
#include "bksim/config.h"
#include "bksim/rupture.h"
#include "bksim/sink.h"
#include "bksim/solver.h"
#include "heap.h"
#include "scene.h"

/* ctx->mode_before of a block that has not changed in the open instant. */
#define BK_MODE_UNCHANGED INT8_MIN

/* An island with its own integrator (scene.h says what an island is). */
typedef struct run_island {
    bk_island island;        /* layout and ODE; the problem's user data */
    bk_ode_problem problem;
    void *solver;            /* an instance of the back-end, from the pool */
    size_t solver_peak;      /* the largest problem that instance has served */
    double *y, *y_probe, *atol;
    int *found;              /* root_info of the pending event */
    size_t capacity_y, capacity_roots;
    int live;
    int stepped;             /* stepped since its (re)start: else y holds the state at t_reached */
    double t_reached;        /* s, where the integrator is */
    double t_resume;         /* s, its (re)start, or the crossing it carried on through:
                                the steps before it are handled */
    /* The event the last step found, handled when its time comes. */
    int pending;
    int from_root;           /* a root fired (else a stop was missed at a step end) */
    double t_event;          /* s; a hidden stop rewinds it before the root */
    size_t hidden_block;     /* the block whose hidden stop it is, or SIZE_MAX */
} run_island;

typedef struct run_ctx {
    const bk_config *config;
    const bk_model *model;
    const bk_sink *sink;
    bk_error *err;
    bk_run_stats *stats;
    bk_progress_fn progress;
    void *progress_user;

    bk_scene scene;
    const bk_solver_backend *backend;
    bk_solver_options options; /* with auto values resolved */
    double atol_x, atol_v, atol_state, atol_energy;

    /* Islands, by id; ids of dissolved islands are reused. */
    run_island **islands;
    size_t islands_capacity, islands_used;
    size_t *free_ids;
    size_t n_free;
    size_t live_islands;
    bk_heap island_queue;    /* live islands by their pending event's time, else t_reached */
    /* Idle back-end instances, reused; the pool holds small ones only, within a budget in
     * proportion to the chain, so memory follows the chain and not the run's history. */
    void **idle;
    size_t *idle_len;        /* the problem size each idle instance last served */
    size_t *idle_peak;       /* the largest problem each one served: what it holds */
    size_t n_idle, idle_capacity;
    size_t idle_held;        /* the sum of idle_peak */
    size_t idle_budget;
    bk_solver_counters retired; /* counters of the instances destroyed */
    /* Quiet stuck blocks by failure time (closed form, no integrator). */
    bk_heap quiet;
    gsl_root_fsolver *brent; /* hidden stops and aging breakaways, one at a time */
    size_t *batch;           /* blocks failing at one instant, scratch */
    /* The partition's scratch (run_partition.c): the region rebuilt, as a sparse set of
     * blocks, a component's blocks, and the lines (rows or columns) an island occupies. */
    size_t *region, *region_pos, n_region;
    size_t *members;
    uint8_t *visited;        /* by region position */
    size_t *lines;           /* max(rows, cols) */
    uint8_t *line_seen;      /* max(rows, cols), zero between uses */

    /* Energy bookkeeping: what finished, and each stuck block's driver-spring energy when its
     * stuck interval began (the driver's work on a stuck block is that spring's gain). */
    bk_energy closed;        /* J */
    double *spring_energy_ref;             /* J, per block */
    bk_energy total;         /* J, totals at the last unpack_all */

    /* Transitions of the current instant, flushed in block order when it ends. */
    bk_transition *instant;
    size_t n_instant, instant_capacity;
    double t_instant;
    /* An event row owed for the instant at t_row_due (NAN: none), and the blocks changed in
     * it with each one's mode before its first transition there (only with event rows). */
    double t_row_due;
    int8_t *mode_before;     /* per block; BK_MODE_UNCHANGED when not changed */
    size_t *changed;
    size_t n_changed;

    /* What the rows and transitions take on disk, against [output] max_bytes. */
    double bytes_written, row_bytes, max_bytes;

    /* Row buffers. */
    double *friction, *cof, *state_out;

    /* Output schedule. */
    double t_end;
    double interval;
    long next_sample;     /* index k of the next sample time k * interval; -1 when done */
    double t_last_row;
    long steps_since_row; /* integrator steps since the last row or transition */
    int event_rows;

    /* Chattering guard. */
    double instant_window;
    double *last_transition;
    long *instant_count;

    double elastic0, kinetic0;
    double wall_start;    /* s, monotonic clock at the start */
    double cpu0;          /* clock() at the start */

    /* Restart points, at multiples of checkpoint_interval or (when it is automatic) after
     * checkpoint_work units of work; written as checkpoints when the wall clock says. */
    double checkpoint_interval;
    long next_checkpoint; /* index k of the next checkpoint time k * interval */
    double checkpoint_work;          /* 0: restart points by the interval, or none */
    double restart_work;             /* block-steps, transitions and row blocks since the last */
    double t_restart;                /* s, the next automatic restart point; +inf: not yet due */
    double t_breakpoint;             /* s, the driver history's next breakpoint, a restart; +inf: none */
    double t_settled;                /* s, the time of the scheduler's last action */
    double checkpoint_wall_interval; /* s: write a restart point once this has passed */
    double wall_checkpoint;          /* s, monotonic clock at the last one written (or the start) */
    int stop_at_restart;             /* the progress callback asked to stop at the next one */
    double wall_stop_asked;          /* s, monotonic clock when it asked */
    bk_run_stats base;    /* counters of the run this one resumed, if any */

    /* The event catalog (run_catalog.c); NULL when the run keeps none. */
    bk_catalog *catalog;
    long events;          /* events completed */
    long events_resumed;  /* events completed before this call began */
    double t_resumed;     /* s, where this call began */
    double t_progress;    /* s, the furthest time reported to the progress callback */
    double t_catalog;     /* s, where the builder's force callback evaluates */
    double *rate_v, *rate_a; /* per block: v and d|v|/dt at its island's last step end */
    bk_catalog_state catalog_state; /* what a checkpoint saves (arrays only with checkpoints) */

    /* The rupture catalog (run_ruptures.c); NULL when the run keeps none. */
    bk_ruptures *ruptures;
    double *rupture_v, *rupture_a; /* per block: v and d|v|/dt at its island's last step end */
    double t_rupture_force;  /* s, where the builder's force callback evaluates */
    double *rupture_saved;   /* the builder's state for a checkpoint */
    size_t rupture_saved_capacity;
    void *rupture_steps;     /* scratch: a step's slipping blocks */
    size_t rupture_steps_capacity;

    /* Local time stepping (run_segments.c): blocks per segment (0: islands whole), each
     * block's segment in the cut being made, and the tracks handed out. */
    size_t segment_blocks;
    size_t *segment_of;
    size_t n_tracks, tracks_capacity;
    int ghost_velocities;    /* ghosts' velocities enter the forces (checked as positions are) */
} run_ctx;

/* qsort's order of block indices (size_t). */
/* Whether the run has restart points: a checkpoint interval, or work between them, and a
 * sink that keeps checkpoints. */
static inline int bk_run_has_restart_points(const run_ctx *ctx)
{
    return ctx->sink && ctx->sink->checkpoint && (ctx->checkpoint_interval > 0.0 || ctx->checkpoint_work > 0.0);
}

static inline int bk_compare_blocks(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* The run loop's files call one another downward only, in the order they are listed below:
 * run.c (set-up and the scheduler) on top, then restarts, island events, the partition, the
 * islands, segments, quiet blocks, rows, transitions, the event catalog, the rupture catalog,
 * the energy books, probes and the clock.  A file calls only files listed after it, never one before: no circle of calls
 * (make lint checks it on the objects, scripts/lint_calls.sh). */

/* ---- run_restart.c ---- */
/* Every island restarted at t (islands stopped there), as a resumed run starts.  At a restart
 * point (restart_point) the state is first recorded as a checkpoint when the wall-clock
 * interval has passed; otherwise (a driver breakpoint) only the restart. */
int bk_run_restart_all(run_ctx *ctx, double t, int restart_point);
/* Write the state at t, every island unpacked there, as a checkpoint through the sink (which
 * must take them), with next_sample the first sample a continuation emits. */
int bk_run_write_checkpoint(run_ctx *ctx, double t, long next_sample);
/* The state of a checkpoint, back into the chain. */
int bk_run_resume(run_ctx *ctx, const bk_checkpoint *cp);
/* Statistics so far, the resumed run's included. */
void bk_run_collect_stats(const run_ctx *ctx, bk_run_stats *stats, double cpu0);

/* ---- run_events.c ---- */
/* One step of island id; records the event it finds (pending). */
int bk_run_island_step(run_ctx *ctx, size_t id);
/* Apply the machine to block i at t (the chain's arrays unpacked there): the transition and
 * the energy books.  Returns 1 when its mode changed, 0 when not, < 0 on failure. */
int bk_run_apply_event(run_ctx *ctx, double t, size_t i, bk_mode_event event);
/* Handle the pending event of island id at its t_event. */
int bk_run_island_event(run_ctx *ctx, size_t id);
/* Every quiet block failing at t (to rounding) breaks away. */
int bk_run_quiet_failures(run_ctx *ctx, double t);

/* ---- run_partition.c ---- */
int bk_run_partition_init(run_ctx *ctx);
void bk_run_partition_free(run_ctx *ctx);
/* Dissolve every island and rebuild the whole partition at t (the chain's arrays hold the
 * state there): at the start, at checkpoints and on resuming. */
int bk_run_partition_all(run_ctx *ctx, double t);
/* Rebuild the partition at t around the seed blocks, whose modes changed: they, their
 * partners and every island those touch (dissolved at t; `taken`: the one whose increments
 * were already taken, or BK_NO_ISLAND). */
int bk_run_repartition(run_ctx *ctx, const size_t *seeds, size_t n_seeds, double t, size_t taken);

/* ---- run_islands.c ---- */
int bk_run_islands_init(run_ctx *ctx);
void bk_run_islands_free(run_ctx *ctx);
/* Dissolve island id at t: its state into the chain (unless `taken`: already there) and its
 * energy increments into the closed totals. */
int bk_run_dissolve(run_ctx *ctx, size_t id, double t, int taken);
/* A new island over these blocks (in the island's order), started at t. */
int bk_run_found_island(run_ctx *ctx, const size_t *blocks, size_t len, double t);
/* (Re)start island id at t on its blocks' current state. */
int bk_run_start_island(run_ctx *ctx, size_t id, double t);
/* The island's state at t into the chain's arrays: its own vector where it stands at t,
 * else dense output (t lies in its last step: see the scheduler in run.c); for an output
 * row (for_row), the back-end's output-row interpolant where it has one.  Its energy
 * increments since its start go to *increments. */
int bk_run_unpack_island(run_ctx *ctx, run_island *isl, double t, int for_row, bk_energy *increments);
/* Fill the chain's arrays with every island's state at t (interpolated, or the island's
 * own vector where it stands at t), and ctx->total with the totals. */
int bk_run_unpack_all(run_ctx *ctx, double t);
/* Counters of every back-end instance so far. */
void bk_run_solver_counters(const run_ctx *ctx, bk_solver_counters *total);
/* Destroy the idle back-end instances (their counters kept).  A restarted instance need not
 * step as a new one does (CVODE's does not, to the last bit), so at a restart of everything
 * the islands start on new instances, as in a run resumed there. */
void bk_run_drain_pool(run_ctx *ctx);

/* ---- run_segments.c ---- */
/* Tracks and scratch when ctx->segment_blocks is set (the scene becomes segmented). */
int bk_run_segments_init(run_ctx *ctx);
void bk_run_segments_free(run_ctx *ctx);
/* A component (members, in the island's order) about to be founded as `pieces` segments of
 * consecutive members: its edge blocks get tracks, set from the chain's arrays at t. */
int bk_run_segments_prepare(run_ctx *ctx, const size_t *members, size_t count, size_t pieces, double t);
/* A segment (re)started: its edge blocks' tracks from its start. */
int bk_run_segment_started(run_ctx *ctx, run_island *isl);
/* Before a segment's step: it may go only as far as its ghosts' tracks are trusted. */
int bk_run_segment_stop(run_ctx *ctx, run_island *isl);
/* After a segment's step: its edge blocks' tracks from its integrator, and the coupling
 * error of the tracks they replace. */
int bk_run_segment_stepped(run_ctx *ctx, run_island *isl);

/* ---- run_quiet.c ---- */
/* Block i (stuck, next to no slipping block) leaves the integrators at t; its breakaway
 * time goes into the quiet queue. */
void bk_run_make_quiet(run_ctx *ctx, size_t i, double t);

/* ---- run_rows.c ---- */
/* A regular sample row from the chain's arrays at t (bk_run_unpack_all first). */
int bk_run_emit_sample(run_ctx *ctx, double t);
/* The two rows of a transition instant at t (unpacked there): the state just before its
 * transitions, then just after. */
int bk_run_emit_event_rows(run_ctx *ctx, double t);

/* ---- run_transitions.c ---- */
/* A mode change of block i at t with the applied force then: chattering guard, statistics,
 * and the transition, buffered until its instant ends. */
int bk_run_record_transition(run_ctx *ctx, double t, size_t i, bk_mode from, bk_mode to,
                             double applied_force);
/* Block i (a law without a stuck state, unpacked at t) crosses the slip-rate threshold: a
 * transition for the catalog only. */
int bk_run_record_crossing(run_ctx *ctx, double t, size_t i, int rising);
/* Send the buffered transitions of the instant, in block order. */
int bk_run_flush_instant(run_ctx *ctx);

/* ---- run_catalog.c ---- */
/* The builder, begun at t = 0 from the chain's arrays or restored from a checkpoint (none
 * when [output] events is off, or the checkpoint predates catalogs). */
int bk_run_catalog_init(run_ctx *ctx, const bk_checkpoint *from);
void bk_run_catalog_free(run_ctx *ctx);
/* A transition, as it happens; a completed event goes to the sink. */
int bk_run_catalog_transition(run_ctx *ctx, const bk_transition *transition);
/* The end of the run at t (the chain's arrays unpacked there): the last event. */
int bk_run_catalog_finish(run_ctx *ctx, double t);
/* The builders' state for a checkpoint (*state NULL without a catalog); BK_ERR_NOMEM when the
 * rupture catalog's cannot be copied. */
int bk_run_catalog_save(run_ctx *ctx, bk_catalog_state **state);
/* Slip rates of an island just (re)started, and of its last step (maxima inside it too). */
void bk_run_catalog_island_start(run_ctx *ctx, const run_island *isl);
int bk_run_catalog_island_step(run_ctx *ctx, run_island *isl);

/* ---- run_ruptures.c ---- */
/* The builder, begun at t = 0 from the chain's arrays or restored from a checkpoint (none
 * without the event catalog, or from a checkpoint written before ruptures). */
int bk_run_ruptures_init(run_ctx *ctx, const bk_checkpoint *from);
void bk_run_ruptures_free(run_ctx *ctx);
/* A transition, as it happens; completed ruptures go to the sink. */
int bk_run_ruptures_transition(run_ctx *ctx, const bk_transition *transition);
/* The end of the run at t (the chain's arrays unpacked there): the ruptures left. */
int bk_run_ruptures_finish(run_ctx *ctx, double t);
/* The builder's state into a checkpoint's catalog part (nothing without ruptures). */
int bk_run_ruptures_save(run_ctx *ctx, bk_catalog_state *state);
/* Speed samples of an island just (re)started, and of its last step. */
int bk_run_ruptures_island_start(run_ctx *ctx, const run_island *isl);
/* Block i crossed the slip-rate threshold at t and its island carries on through: the
 * sample island_start would have taken. */
int bk_run_ruptures_crossed(run_ctx *ctx, size_t i, double t);
int bk_run_ruptures_island_step(run_ctx *ctx, run_island *isl);

/* ---- run_books.c ---- */
/* Block i changes between stuck and slipping at t (the chain's arrays unpacked): the
 * driver's work on it while it was stuck is closed, or its stuck interval opens. */
void bk_run_leave_stuck(run_ctx *ctx, size_t i, double t);
void bk_run_enter_stuck(run_ctx *ctx, size_t i, double t);
/* Driver work and dissipation at t from the closed totals, the islands' increments and the
 * stuck blocks' springs (J); the islands' increments are given. */
void bk_run_energy_totals(run_ctx *ctx, double t, const bk_energy *islands);
/* Close every stuck interval's books at t: the closed totals take everything so far and the
 * stuck blocks' references restart at t (a checkpoint, or a resumed run's start). */
void bk_run_rebase_energy(run_ctx *ctx, double t);

/* ---- run_probe.c ---- */
/* The zero of f in [lo, hi] (opposite signs at the ends) located by Brent to rounding: the
 * upper end of the final bracket, past the zero as at a root an integrator reports; hi when
 * GSL refuses the bracket. */
double bk_run_zero_after(run_ctx *ctx, gsl_function *f, double lo, double hi);
/* A function of one block on an island's last-step interpolant, as Brent evaluates it. */
typedef struct bk_block_probe {
    run_ctx *ctx;
    run_island *isl;
    size_t block;
    int status; /* the first failure of the back-end's interpolation */
} bk_block_probe;
/* The island's vector at t (in isl->y_probe); NULL, with status set, when the back-end fails. */
const double *bk_run_probe_state(bk_block_probe *probe, double t);
/* The island's last step as its trajectory stands: [*lo, *hi] from its (re)start on, ended
 * by an event found inside it, and the island's vector at *hi (*y: isl->y, or isl->y_probe
 * interpolated there). */
int bk_run_last_step(run_ctx *ctx, run_island *isl, double *lo, double *hi, const double **y);
/* d|v|/dt of slipping block i for the island's vector y at t (from rest: along its mode). */
double bk_run_speed_rate(const run_island *isl, size_t i, double t, const double *y);
/* The same on the island's last-step interpolant (a bk_block_probe), for Brent. */
double bk_run_speed_rate_probe(double t, void *probe);
/* The largest value of the cubic Hermite interpolant with values u0, u1 and slopes d0 > 0 >
 * d1 at 0 and h: a speed's maximum inside a step, estimated from the step's ends. */
double bk_run_hermite_peak(double u0, double d0, double u1, double d1, double h);

/* ---- run_clock.c ---- */
double bk_run_wall_seconds(void);
/* The progress callback (which may stop the run) and the wall-clock limit, checked at every
 * step and row. */
int bk_run_report_progress(run_ctx *ctx, double t);
/* Next checkpoint time (+inf without checkpoints); always < t_end or +inf. */
double bk_run_checkpoint_time(const run_ctx *ctx);
/* Where every island's integrator stops: the next checkpoint, a driver breakpoint or t_end. */
double bk_run_stop_time(const run_ctx *ctx);
/* Count bytes written (rows, transitions, events) against [output] max_bytes at t. */
int bk_run_count_bytes(run_ctx *ctx, double bytes, double t);

#endif
