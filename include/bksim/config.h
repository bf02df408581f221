/* A run described by one INI file (plus --set overrides): parsed with inih, every key
 * checked against one table of keys, every failure reported as
 *   file:line: [section] key: message (allowed range)
 * before anything is written.  See README "Config reference" (generated from the table
 * by `bksim keys`). */
#ifndef BKSIM_CONFIG_H
#define BKSIM_CONFIG_H

#include <stdio.h>

#include "bksim/model.h"
#include "bksim/solver.h"
#include "bksim/status.h"

/* Output fields beyond /time and /driver, which are always written. */
enum {
    BK_FIELD_X = 1u << 0,        /* /x  block positions, m */
    BK_FIELD_V = 1u << 1,        /* /v  block velocities, m/s */
    BK_FIELD_FRICTION = 1u << 2, /* /friction interface shear force, N */
    BK_FIELD_COF = 1u << 3,      /* /cof apparent coefficient of friction */
    BK_FIELD_MODE = 1u << 4,     /* /mode stick 0, slip+ 1, slip- -1 */
    BK_FIELD_ENERGY = 1u << 5,   /* /energy_* and /work_driver, /dissipation, J */
    BK_FIELD_STATE = 1u << 6,    /* /friction_state, per law */
    BK_FIELD_ALL = (1u << 7) - 1
};

/* The two full rows of a transition instant (before and after) cost 2 (17 + 33 N) bytes for
 * N blocks, against the 38 of the transition record: cheap on short chains, where figures
 * want them, an O(N) snapshot per event on long ones.  event_rows = auto turns them on up to
 * this many blocks. */
#define BK_EVENT_ROWS_AUTO_BLOCKS 16

/* s: by default a run writes a checkpoint about this often, so that any run longer than this
 * can be continued (REBOUND's simulation archives do the same by wall time). */
#define BK_CHECKPOINT_WALL_INTERVAL 300.0
/* Work between automatic restart points: a few seconds of CPU (a unit costs 0.2-0.6 us), and
 * per block 300 times the few units a restart of every integrator costs, so restarts add under
 * 1 % to a run and nothing to one that never does this much work. */
#define BK_CHECKPOINT_WORK 1e7
#define BK_CHECKPOINT_WORK_PER_BLOCK 300.0

typedef struct bk_output_options {
    char *path;        /* HDF5 output path, owned; default "<config stem>.h5" */
    double interval;   /* s between samples; 0 = transition rows only; default t_end/1000 */
    unsigned fields;   /* BK_FIELD_* mask; default all */
    int transitions;   /* write /transitions; default 1 */
    int events;        /* build the event catalog and write /events; default 1 (0 in a prescribed
                          scene) */
    int event_rows;    /* add two rows at every transition instant (bk_row_kind); default (auto): 1 for chains
                          of up to BK_EVENT_ROWS_AUTO_BLOCKS blocks, else 0 */
    double checkpoint_interval; /* s of simulated time between restart points, where a checkpoint
                                   may be written; 0 = none, or automatic by checkpoint_work
                                   (the default) */
    double checkpoint_work;     /* restart points after this much work (blocks advanced by
                                   integrator steps, transitions, blocks written in rows); 0 =
                                   by checkpoint_interval; default BK_CHECKPOINT_WORK +
                                   BK_CHECKPOINT_WORK_PER_BLOCK n_blocks */
    double checkpoint_wall_interval; /* s of wall-clock time: a restart point is written as a
                                        checkpoint once this has passed since the last one (or
                                        the start); 0 = every one; default
                                        BK_CHECKPOINT_WALL_INTERVAL, 0 when checkpoint_interval
                                        is given */
    long max_rows;     /* sample rows t_end / interval may ask for; default 1e8 */
    double max_bytes;  /* bytes the rows and transitions may take on disk: the sample rows
                          checked at load, everything written checked during the run;
                          default 1e10 (0 in a config built in code: no limit) */
} bk_output_options;

/* A prescribed-motion scene (no dynamics): one block slides at a piecewise-constant slip
 * rate, its friction state following the law's exact evolution.  Paper Figure 2. */
typedef struct bk_prescribed {
    size_t n_segments;
    double *slip_rate;        /* m/s per segment, >= 0 (0: a hold) */
    double *duration;         /* s per segment, > 0 */
} bk_prescribed;

/* The event catalog ([catalog]; bksim/catalog.h). */
typedef struct bk_catalog_options {
    double magnitude_offset;    /* added to (2/3) log10(potency / 1 m); default 0 */
    double slip_rate_threshold; /* m/s: a block of a law without a stuck state slips (for the
                                   catalog) while |v| exceeds it; NaN = none given */
    int rupture_rate;              /* write /rupture_rate, each rupture's moment-rate function;
                                      default 1 */
} bk_catalog_options;

/* A key given as a distribution ([block] mass = normal(1, 0.1)): the value every block ended
 * with, drawn or set by its own section, written to the output as /parameters/<name>. */
#define BK_PARAMETER_NAME_LEN 128
typedef struct bk_block_parameter {
    char name[BK_PARAMETER_NAME_LEN]; /* "<section>.<key>": "block.mass", "friction.mu_s" */
    char unit[16];
    size_t n_blocks;
    double *values;                   /* one per block; NaN where the block's law has no such key */
} bk_block_parameter;

typedef struct bk_config {
    bk_model *model;          /* owned */
    bk_prescribed *prescribed; /* owned; NULL for the chain's dynamics */
    bk_solver_options solver;
    bk_output_options output;
    bk_catalog_options catalog;
    double t_end;             /* s, > 0 */
    unsigned long seed;       /* [model] seed of the numbers drawn at load time */
    double wall_time_limit;   /* s of wall-clock time before the run stops with an error;
                                 0 = no limit (default) */
    char *source_name;        /* config file path (or the name given to load_string), owned */
    char *text;               /* config text with the --set overrides appended, owned */
    char **overrides;         /* the --set overrides, owned (kept to reload the same config) */
    size_t n_overrides;
    char *file_text;          /* the config as read, without the overrides, owned */
    bk_block_parameter *parameters; /* the keys given as a distribution, owned */
    size_t n_parameters;
} bk_config;

/* Load and validate a config file.  overrides are "section.key=value" strings applied after
 * the file (section may be "block.3").  On success *out owns a config (free with
 * bk_config_free).  On failure returns BK_ERR_CONFIG (or BK_ERR_IO / BK_ERR_NOMEM), *out is
 * NULL and err->message reads "file:line: [section] key: message (allowed range)". */
int bk_config_load_file(const char *path, const char *const *overrides, size_t n_overrides,
                        bk_config **out, bk_error *err);
/* Same from text in memory; `name` stands in for the file name in messages. */
int bk_config_load_string(const char *text, const char *name, const char *const *overrides,
                          size_t n_overrides, bk_config **out, bk_error *err);
void bk_config_free(bk_config *config);

/* What a run of config writes as sample rows: *rows of *row_bytes each over t_end (the
 * regular samples and the last), *per_second bytes per simulated second (0 with interval = 0).
 * Transitions (*transition_bytes each), event rows and the catalogs come on top, as many as
 * the run makes. */
void bk_config_output_estimate(const bk_config *config, double *rows, double *row_bytes, double *per_second,
                               double *transition_bytes);

/* Values that pass every range check but are far outside what the other values make
 * plausible (src/config_warnings.c): a driver faster than the blocks' own slip speeds, a
 * sampling interval longer than a slip, a max_step longer than the fastest natural period.
 * Calls warn(user, message) once per warning (each message names the file, the key and
 * why; warn may be NULL) and returns how many there were. */
typedef void (*bk_warning_fn)(void *user, const char *message);
size_t bk_config_warnings(const bk_config *config, bk_warning_fn warn, void *user);

/* Write the key reference (every section and key: meaning, unit, default, range) as
 * Markdown tables. */
void bk_config_write_reference(FILE *out);

/* The table of keys, for tools and tests: what a value of each key must look like. */
typedef enum bk_key_kind {
    BK_KEY_NUMBER,  /* a finite number in the param's range */
    BK_KEY_INTEGER, /* an integer in the param's range */
    BK_KEY_BOOLEAN,
    BK_KEY_CHOICE,  /* one word of a fixed or registered list */
    BK_KEY_TEXT,    /* non-empty text */
    BK_KEY_FIELDS,  /* a list of output field names */
    BK_KEY_LIST     /* numbers separated by commas or spaces, each in the param's range */
} bk_key_kind;

typedef struct bk_key_info {
    const char *section;    /* "model", "block", ...; per-law friction keys are in the laws' tables */
    const bk_param *param;  /* key, unit, default, range, flags, doc */
    bk_key_kind kind;
} bk_key_info;

/* The i-th key; returns 0 and fills *info, or -1 past the end. */
int bk_config_key(size_t i, bk_key_info *info);

#endif
