/* What a run hands on, and to what: the records (a time-series row, a transition, the run's
 * statistics) and the sink that takes them, with a checkpoint and the catalogs' events and
 * ruptures; and
 * its progress, to a callback that may stop it.
 * Everything that writes, reads or keeps a run's records includes this header rather than
 * the run loop's, which it need not see. */
#ifndef BKSIM_SINK_H
#define BKSIM_SINK_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/status.h"

/* One row of the time series: the state of every block at time t.  Arrays have n_blocks
 * entries and are valid only during the sink call. */
typedef struct bk_sample {
    double t;                 /* s */
    double driver;            /* driver position, m */
    size_t n_blocks;
    const double *x;          /* m */
    const double *v;          /* m/s */
    const double *friction;   /* interface shear force, N; positive when it resists +x motion
                                 (the force on the block is -friction) */
    const double *cof;        /* friction / normal force */
    const int8_t *mode;       /* bk_mode values */
    const double *friction_state; /* model->n_friction_state entries (may be NULL if 0) */
    double kinetic_energy;    /* J */
    double elastic_energy;    /* J */
    double work_driver;       /* J, work done by the driver since t = 0 */
    double dissipation;       /* J, frictional dissipation since t = 0 */
    double damping_dissipation; /* J, dissipated by the dashpots since t = 0 (0 without) */
    int is_event;             /* bk_row_kind */
} bk_sample;

/* What a row is.  A transition instant has two rows at the same time, the state just before
 * its transitions and just after (x, v, energies and friction state are continuous there; the
 * modes and the friction jump), so a series read row by row shows the jump and its peak. */
typedef enum bk_row_kind {
    BK_ROW_SAMPLE = 0,            /* a regular sample */
    BK_ROW_AFTER_TRANSITION = 1,  /* a transition instant, the state just after it */
    BK_ROW_BEFORE_TRANSITION = 2  /* the same instant just before it; the after row follows */
} bk_row_kind;

/* One block changing mode. */
typedef struct bk_transition {
    double t;      /* s */
    int32_t block; /* 0-based */
    int8_t from;   /* bk_mode */
    int8_t to;     /* bk_mode */
    double x;      /* m, position at the transition */
    double v;      /* m/s, velocity after it (0 when it sticks or starts from rest) */
    double force;  /* N, applied force (springs and dashpots) on the block at the transition */
} bk_transition;

/* A checkpoint (bksim/checkpoint.h): the state a run continues from. */
typedef struct bk_checkpoint bk_checkpoint;
/* An event of the catalog (bksim/catalog.h). */
typedef struct bk_event bk_event;
/* A rupture, its blocks and its moment-rate samples (bksim/rupture.h). */
typedef struct bk_rupture bk_rupture;
typedef struct bk_rupture_block bk_rupture_block;
typedef struct bk_rupture_rate bk_rupture_rate;

typedef struct bk_sink {
    void *self;
    int (*sample)(void *self, const bk_sample *sample, bk_error *err);
    int (*transition)(void *self, const bk_transition *transition, bk_error *err);
    /* At every [output] checkpoint_interval; may be NULL.  The arrays are valid only during
     * the call. */
    int (*checkpoint)(void *self, const bk_checkpoint *checkpoint, bk_error *err);
    /* Each event of the catalog as it completes ([output] events); may be NULL. */
    int (*event)(void *self, const bk_event *event, bk_error *err);
    /* Each rupture as it completes, with its blocks and its rate samples (n_rate = 0 when
     * [catalog] rupture_rate is off); may be NULL. */
    int (*rupture)(void *self, const bk_rupture *rupture, const bk_rupture_block *blocks, size_t n_blocks,
                   const bk_rupture_rate *rate, size_t n_rate, bk_error *err);
} bk_sink;

typedef struct bk_run_stats {
    char method[32];          /* back-end actually used */
    long steps;               /* integrator steps */
    long rhs_evals;
    long root_evals;          /* root-function evaluations */
    long err_test_fails;
    long nonlin_iters;
    long integrator_starts;   /* (re-)initialisations */
    long stuck_jumps;         /* all-stuck intervals crossed in closed form */
    long transitions;
    long rows;                /* time-series rows emitted */
    double t_reached;         /* s */
    double wall_time;         /* s */
    double cpu_time;          /* s */
    double work_driver;       /* J */
    double dissipation;       /* J, by friction */
    double damping_dissipation; /* J, by the dashpots */
    double elastic_change;    /* J, elastic energy at t_reached minus at 0 */
    double kinetic_change;    /* J */
    double energy_residual;   /* (W - dE_el - dE_kin - D - D_damping) / the largest term, dimensionless */
    long segments;            /* local time stepping: segments the chain is cut into (0: none) */
    double coupling_error;    /* local time stepping: the largest error of a ghost's extrapolation
                                 measured, over the integrator's tolerance (dimensionless) */
    long coupling_exceedances; /* such errors above 1 */
} bk_run_stats;

/* What a progress callback is told: how far the run is, and what it has produced. */
typedef struct bk_progress {
    double t, t_end;     /* s; t is the furthest any part of the chain has got (parts run apart) */
    double t_resumed;    /* s: where this call began (0, or the checkpoint it resumed) */
    long transitions;    /* so far, a resumed run's earlier ones included */
    long events;         /* completed events so far; -1 when the run keeps no catalog */
    long events_resumed; /* events completed before t_resumed */
} bk_progress;

/* Called now and then; return 0 to go on, BK_PROGRESS_STOP to stop the run at once, or
 * BK_PROGRESS_CHECKPOINT_AND_STOP to stop at its next restart point, written as a checkpoint
 * whatever the wall clock says, so that a restart continues exactly as if the run had never
 * stopped (what a batch system's SIGTERM asks for).  A run without restart points, or one
 * that has not reached its next within BK_STOP_GRACE seconds of wall-clock time after the
 * request, stops at once; either stop returns BK_ERR_INTERRUPTED. */
#define BK_PROGRESS_STOP 1
#define BK_PROGRESS_CHECKPOINT_AND_STOP 2
#define BK_STOP_GRACE 20.0
typedef int (*bk_progress_fn)(void *user, const bk_progress *progress);

#endif
