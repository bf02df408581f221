/* The output layout, described once and free of HDF5: which datasets a run writes, what each
 * holds (shape, element type, units), the [output] fields words that select them, and the
 * bytes a row takes on disk (what the [output] max_bytes guard estimates).  The writer, the
 * verifier, the exporter and the config loader all read this table, so a dataset added here
 * is created, checked and counted in the size guard at once. */
#ifndef BKSIM_LAYOUT_H
#define BKSIM_LAYOUT_H

#include <stddef.h>

/* Rows are time-major: T (one value per row), T x N (one per block), T x S (one per
 * friction-state variable). */
typedef enum bk_series_shape { BK_SHAPE_T, BK_SHAPE_TN, BK_SHAPE_TS } bk_series_shape;
typedef enum bk_series_kind { BK_KIND_F64, BK_KIND_U8, BK_KIND_I8 } bk_series_kind;

typedef struct bk_series_def {
    const char *name;        /* dataset name under the root group */
    unsigned field;          /* BK_FIELD_* that selects it; 0 = always written */
    bk_series_shape shape;
    bk_series_kind kind;
    const char *units;
    const char *description;
    int damped_only;         /* written only when the model has dashpots (bk_model_is_damped) */
} bk_series_def;

/* Indices into bk_series, in the order the datasets are created. */
enum {
    BK_SERIES_TIME, BK_SERIES_DRIVER, BK_SERIES_EVENT, BK_SERIES_X, BK_SERIES_V,
    BK_SERIES_FRICTION, BK_SERIES_COF, BK_SERIES_MODE, BK_SERIES_EKIN, BK_SERIES_EEL,
    BK_SERIES_WORK, BK_SERIES_DISS, BK_SERIES_DAMP, BK_SERIES_STATE, BK_N_SERIES
};

extern const bk_series_def bk_series[BK_N_SERIES];

/* The words of [output] fields, NULL-terminated: word i selects BK_FIELD bit 1 << i. */
extern const char *const bk_output_field_names[];

/* Bytes of one /transitions record on disk (packed: t, block, from, to, x, v, force). */
#define BK_TRANSITION_RECORD_BYTES 38

#define BK_TRANSITIONS_UNITS "t: s, block: 1, from: 1, to: 1, x: m, v: m/s, force: N"
#define BK_TRANSITIONS_DESCRIPTION                                                         \
    "mode transitions: time, block (0-based), from/to mode (stick 0, slip+ 1, slip- -1), " \
    "position, velocity after the transition, applied force (springs and dashpots)"

/* Bytes of one /events record on disk (packed: t_start, t_end, first_block, n_blocks, left,
 * right, n_episodes, potency, magnitude, max_slip_rate, stress_drop, complete). */
#define BK_EVENT_RECORD_BYTES 69

#define BK_EVENTS_UNITS                                                                      \
    "t_start: s, t_end: s, first_block: 1, n_blocks: 1, left: 1, right: 1, n_episodes: 1, " \
    "potency: m, magnitude: 1, max_slip_rate: m/s, stress_drop: N, complete: 1"
#define BK_EVENTS_DESCRIPTION                                                                     \
    "slip events: maximal intervals during which some block slips (ruptures that overlap in "  \
    "time are one event). first_block: the first to slip; left..right: the extent (on a ring "  \
    "the shorter arc covering the blocks, left > right when it wraps past block 0); potency: "  \
    "sum of the slip of every episode; magnitude: (2/3) log10(potency / 1 m) + "              \
    "magnitude_offset; stress_drop: mean drop of the applied force over the blocks; "          \
    "complete: 0 for an event still running at the end of the run"

/* Bytes of one record of /ruptures (packed: t_start, t_end, first_block, n_blocks, left,
 * right, n_episodes, potency, magnitude, max_slip_rate, stress_drop, duration,
 * front_speed_left, front_speed_right, complete), of /rupture_blocks (rupture, block,
 * t_onset, t_stop, slip) and of /rupture_rate (rupture, t, rate). */
#define BK_RUPTURE_RECORD_BYTES 93
#define BK_RUPTURE_BLOCK_RECORD_BYTES 36
#define BK_RUPTURE_RATE_RECORD_BYTES 24

#define BK_RUPTURES_UNITS                                                                    \
    "t_start: s, t_end: s, first_block: 1, n_blocks: 1, left: 1, right: 1, n_episodes: 1, " \
    "potency: m, magnitude: 1, max_slip_rate: m/s, stress_drop: N, duration: s, "          \
    "front_speed_left: 1/s, front_speed_right: 1/s, complete: 1"
#define BK_RUPTURES_DESCRIPTION                                                                    \
    "ruptures: connected sets of slip episodes, two episodes linked when their blocks are the "   \
    "same or neighbours and their closed time intervals meet (README \"Ruptures\"), in the order " \
    "they complete (by t_end, then t_start, then first_block). first_block: the epicentre; "     \
    "left..right: the extent as in /events; potency: sum of |slip| over the episodes; "         \
    "front_speed_left/right: blocks per second from a least-squares fit of arrival time "       \
    "against distance from the epicentre on each side (NaN with fewer than 3 points, inf when " \
    "simultaneous); complete: 0 for a rupture still running at the end of the run"
#define BK_RUPTURE_BLOCKS_UNITS "rupture: 1, block: 1, t_onset: s, t_stop: s, slip: m"
#define BK_RUPTURE_BLOCKS_DESCRIPTION                                                         \
    "the blocks of each rupture (rupture: row of /ruptures), in block order: t_onset its first " \
    "onset in the rupture (the front's arrival), t_stop its last stop, slip its net displacement"
#define BK_RUPTURE_RATE_UNITS "rupture: 1, t: s, rate: m/s"
#define BK_RUPTURE_RATE_DESCRIPTION                                                            \
    "moment-rate (potency-rate) function of each rupture (rupture: row of /ruptures): the sum "  \
    "of |v| over its slipping blocks, sampled from the integrator's dense output finely enough " \
    "that its trapezoid integral is the rupture's potency to 1e-3"

/* Whether a run with these output fields and friction states, and dashpots or not (damped),
 * writes this series: the one rule behind the layout, the list of datasets a reader must find
 * and the size estimate. */
int bk_series_selected(const bk_series_def *def, unsigned fields, size_t n_state, int damped);

/* Values per row of a series in a chain of n_blocks blocks and n_state friction states. */
size_t bk_series_columns(const bk_series_def *def, size_t n_blocks, size_t n_state);

/* Bytes per value in memory and on disk. */
size_t bk_series_value_size(bk_series_kind kind);

/* Bytes one time-series row takes on disk (chunk overhead aside). */
double bk_output_row_bytes(unsigned fields, size_t n_blocks, size_t n_state, int damped);

/* The datasets a run of this layout writes, comma-separated (recorded in the root attribute
 * "datasets" so that a check needs no config to know what must be there). */
#define BK_DATASET_LIST_LEN 320
/* The catalog tables written (catalogs: a mask of these). */
#define BK_CATALOG_EVENTS 1u       /* /events */
#define BK_CATALOG_RUPTURES 2u     /* /ruptures and /rupture_blocks */
#define BK_CATALOG_RUPTURE_RATE 4u /* /rupture_rate */
void bk_output_dataset_names(unsigned fields, size_t n_state, int damped, int transitions, unsigned catalogs,
                             char *buf, size_t len);

#endif
