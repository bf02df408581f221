/* The table of config keys: one row per key (section, unit, default, range, kind, meaning)
 * drives parsing, validation and the reference documentation alike, so a key added here is
 * read, checked and documented at once.  Each friction law's parameters live in the law's
 * own table and are documented from there. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bksim/solver.h"
#include "config_loader.h"
#include "layout.h"



/* --- the key table ---------------------------------------------------------------------- */

static const char *const boundary_names[] = {"free", "fixed", "periodic", NULL};
static const char *const spring_names[] = {"linear", "tension_only", NULL};
const char *const bk_config_linear_solver_names[] = {"auto", "dense", "band", NULL};
const char *const bk_config_local_stepping_names[] = {"auto", "on", "off", NULL};

/* "auto" (resolved by the run loop from the scene), then every registered back-end. */
const char *bk_config_method_name(size_t i)
{
    if (i == 0)
        return "auto";
    const bk_solver_backend *const *b = bk_solver_backends();
    for (size_t k = 0; b[k]; ++k)
        if (k + 1 == i)
            return b[k]->name;
    return NULL;
}

static const char *law_name(size_t i)
{
    const bk_friction_law *const *l = bk_friction_laws();
    for (size_t k = 0; l[k]; ++k)
        if (k == i)
            return l[k]->name;
    return NULL;
}

#define NUM(sec, k, unit, def, lo, hi, fl, doc) {sec, {k, unit, def, lo, hi, fl, doc}, BK_KEY_NUMBER, NULL, NULL, NULL}
#define INT(sec, k, def, lo, hi, fl, doc) {sec, {k, "1", def, lo, hi, fl, doc}, BK_KEY_INTEGER, NULL, NULL, NULL}

static const key_def keys[] = {
    {"model", {"n_blocks", "1", NAN, 1, BK_CONFIG_MAX_BLOCKS, 0, "number of blocks (rows * cols on a lattice)"},
     BK_KEY_INTEGER, NULL, NULL, "required, or rows and cols"},
    {"model", {"rows", "1", NAN, 1, BK_CONFIG_MAX_BLOCKS, 0,
               "rows of a 2D lattice (block i at row i / cols, column i % cols); 1 is a chain"},
     BK_KEY_INTEGER, NULL, NULL, "1, or n_blocks / cols"},
    {"model", {"cols", "1", NAN, 1, BK_CONFIG_MAX_BLOCKS, 0, "columns of a 2D lattice: blocks per row"},
     BK_KEY_INTEGER, NULL, NULL, "n_blocks / rows"},
    {"model", {"boundary", "", 0, 0, 0, 0,
               "edges: free, fixed (tied to walls at 0) or periodic (a ring, a torus); a chain's ends, or a "
               "lattice's four edges (each direction more than one block long; a 1 x N lattice is the chain)"},
     BK_KEY_CHOICE, boundary_names, NULL, "free"},
    {"model", {"boundary_cols", "", 0, 0, 0, 0,
               "the edges at the first and last column (a chain's ends); a column (cols = 1 < rows) has none "
               "unless given here"},
     BK_KEY_CHOICE, boundary_names, NULL, "boundary, or free if cols = 1 < rows"},
    {"model", {"boundary_rows", "", 0, 0, 0, 0,
               "the edges at the first and last row; a chain (rows = 1) has none unless given here"},
     BK_KEY_CHOICE, boundary_names, NULL, "boundary, or free if rows = 1"},
    NUM("model", "coupling_stiffness", "N/m", 0.0, 0.0, INFINITY, 0, "stiffness of the springs between neighbours"),
    NUM("model", "coupling_damping", "N s/m", 0.0, 0.0, INFINITY, 0,
        "dashpot in parallel with every coupling spring (Carlson-Langer viscosity): force coupling_damping * (v_j - v_i)"),
    NUM("model", "gravity", "m/s^2", 9.81, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
        "gravitational acceleration, for the default normal force"),
    INT("model", "seed", 1, 0, 4294967295.0, 0,
        "seed of the random numbers drawn at load time (x_init_random, distributions); same seed, same run"),

    NUM("block", "mass", "kg", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED,
        "block mass; 0: a quasi-dynamic block (no inertia: its force balance with [block] damping > 0 gives its "
        "slip rate; laws that never stick only)"),
    NUM("block", "driver_stiffness", "N/m", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED,
        "stiffness of the spring from the driver to the block"),
    {"block", {"normal_force", "N", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
               "normal force on the block"}, BK_KEY_NUMBER, NULL, NULL, "mass * gravity"},
    NUM("block", "x_init", "m", 0.0, -INFINITY, INFINITY, BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE,
        "initial displacement from the relaxed configuration"),
    NUM("block", "v_init", "m/s", 0.0, -INFINITY, INFINITY, BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE,
        "initial velocity (non-zero: the block starts slipping that way)"),
    NUM("block", "x_init_random", "m", 0.0, 0.0, INFINITY, 0,
        "adds a uniform random displacement in [-a, a] to x_init (heterogeneous chains; [model] seed)"),
    NUM("block", "damping", "N s/m", 0.0, 0.0, INFINITY, 0,
        "dashpot from the block to the substrate, force -damping * v (the radiation damping of quasi-dynamic models)"),
    NUM("block", "applied_force", "N", 0.0, -INFINITY, INFINITY, BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE,
        "constant tangential force on the block, signed (+: the driver's direction): a prestress; on one end "
        "block ([block.0]) an edge pushed with a constant force"),

    {"friction", {"law", "", NAN, 0, 0, BK_PARAM_REQUIRED, "friction law; its parameters follow in the same section"},
     BK_KEY_CHOICE, NULL, law_name, NULL},

    {"driver", {"velocity", "m/s", NAN, -INFINITY, INFINITY, BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE,
                "driver velocity (constant); give it or velocities"}, BK_KEY_NUMBER, NULL, NULL, "required, or velocities"},
    {"driver", {"velocities", "m/s", NAN, -INFINITY, INFINITY, BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE,
                  "a history instead of velocity: the velocity of each segment in order (0: a hold); velocity "
                  "steps and slide-hold-slide on any chain, every breakpoint a restart"},
     BK_KEY_LIST, NULL, NULL, "-"},
    {"driver", {"durations", "s", NAN, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
                 "with velocities: the duration of each segment, as many as velocities; [run] t_end defaults to "
                 "their sum and may not exceed it"},
     BK_KEY_LIST, NULL, NULL, "-"},
    {"driver", {"velocities_file", "", 0, 0, 0, 0,
                "a history from a table instead of velocities and durations: a first line naming the columns "
                "(velocity and duration, or velocity and t, the segments' start times from 0; the last then lasts "
                "until [run] t_end), one line per segment, # comments; a relative path is taken from the config "
                "file's directory"},
     BK_KEY_TEXT, NULL, NULL, "-"},
    {"driver", {"spring", "", 0, 0, 0, 0, "driver springs: linear, or tension_only (pull, never push; NOTES.md 3)"},
     BK_KEY_CHOICE, spring_names, NULL, "linear"},
    NUM("driver", "start_position", "m", 0.0, -INFINITY, INFINITY, BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE,
        "driver position at t = 0 (0: at the relaxed blocks)"),

    {"solver", {"method", "", 0, 0, 0, 0,
                "integrator back-end; auto: exact for Coulomb scenes, dashpots included when proportional to the masses and springs (open chains up to 1000 blocks, rings up to 100), cvode_bdf in segments for chains of 72 or more blocks that never stick (local_stepping), else gsl_rk8pd, or cvode_bdf when stiff (README \"Solver back-ends\")"},
     BK_KEY_CHOICE, NULL, bk_config_method_name, "auto"},
    {"solver", {"linear_solver", "", 0, 0, 0, 0, "linear solver of implicit methods: auto (band for long chains), dense, band"},
     BK_KEY_CHOICE, bk_config_linear_solver_names, NULL, "auto"},
    NUM("solver", "rtol", "1", 1e-8, 1e-15, 0.1, 0, "relative tolerance"),
    {"solver", {"atol_x", "m", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "absolute tolerance on positions"}, BK_KEY_NUMBER, NULL, NULL, "rtol * 1e-3 * max(F_s / k)"},
    {"solver", {"atol_v", "m/s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "absolute tolerance on velocities"}, BK_KEY_NUMBER, NULL, NULL,
     "rtol * 1e-3 * min(driver speed, max(F_s / k) * omega_max)"},
    {"solver", {"max_step", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "largest integrator step (keeps a slip-rate extremum from hiding inside a step)"},
     BK_KEY_NUMBER, NULL, NULL, "1/8 of the shortest time scale: the fastest damped oscillation, or a friction state's relaxation where no block oscillates"},
    INT("solver", "max_steps", 100000, 1, INT_MAX, 0, "integrator steps allowed between two output rows or transitions (a hang guard)"),
    {"solver", {"detect_velocity_extrema", "", 1, 0, 1, 0,
                "locate slip-rate minima to catch a stop hidden inside one step"}, BK_KEY_BOOLEAN, NULL, NULL, "true"},
    INT("solver", "max_transitions_per_instant", 100, 1, INT_MAX, 0,
        "transitions of one block within instant_window before the run stops as chattering"),
    {"solver", {"instant_window", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "transitions closer than this count as one instant"}, BK_KEY_NUMBER, NULL, NULL,
     "1e-6 of the fastest natural period"},

    {"solver", {"local_stepping", "", 0, 0, 0, 0,
                "local time stepping: the chain cut into segments of segment_blocks blocks, each integrated at "
                "its own pace and coupled through its edge blocks (README \"Local time stepping\"); auto: where "
                "method = auto picks it (long chains whose blocks never stick); on: needs method cvode_bdf or "
                "cvode_adams (or auto), every block's law without a stuck state, linear driver springs"},
     BK_KEY_CHOICE, bk_config_local_stepping_names, NULL, "auto"},
    INT("solver", "segment_blocks", 8, 2, INT_MAX, 0,
        "blocks per segment under local time stepping (a lattice's segments are runs of its rows)"),
    NUM("solver", "min_step", "s", 0.0, 0.0, INFINITY, 0,
        "a step size below this stops the run with an error (0: no limit)"),
    {"solver", {"arkode_table", "", 0, 0, 0, 0,
                "Butcher table of arkode_erk (an explicit ARKODE_* table) or arkode_dirk (a DIRK one); default: "
                "the method's own (Zonneveld 5_3_4, ESDIRK43I6L2SA 6_3_4)"},
     BK_KEY_CHOICE, NULL, bk_solver_arkode_table, "default"},

    {"output", {"path", "", 0, 0, 0, 0, "HDF5 output file (bksim run -o overrides)"}, BK_KEY_TEXT, NULL, NULL,
     "config file name, .ini replaced by .h5"},
    {"output", {"interval", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED,
                "time between samples, <= t_end; 0: rows only at transitions (and t = 0, t_end)"},
     BK_KEY_NUMBER, NULL, NULL, "t_end / 1000"},
    {"output", {"fields", "", 0, 0, 0, 0, "per-row datasets: all, or a list of x v friction cof mode energy state"},
     BK_KEY_FIELDS, bk_output_field_names, NULL, "all"},
    {"output", {"transitions", "", 1, 0, 1, 0, "write the /transitions table"}, BK_KEY_BOOLEAN, NULL, NULL, "true"},
    {"output", {"events", "", 1, 0, 1, 0,
                "build the event catalog during the run and write the /events table (README \"Earthquake catalogs and statistics\")"},
     BK_KEY_BOOLEAN, NULL, NULL, "true"},
    {"output", {"event_rows", "", NAN, 0, 1, 0,
                "add two full rows at every transition instant, the states just before and just after it "
                "(an O(n_blocks) snapshot per event; the /transitions table holds the changed block's state "
                "anyway); auto: true up to 16 blocks"},
     BK_KEY_BOOLEAN, NULL, NULL, "auto"},
    NUM("output", "max_bytes", "B", 1e10, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
        "largest size the output file may take on disk: the sample rows (t_end / interval, times the bytes "
        "per row for the fields and blocks) are checked at load, against a typo in interval or n_blocks; "
        "the file itself (event rows, transitions, catalogs, chunks and HDF5's metadata) before every write, "
        "and the run stops with an error there, its .part closed cleanly"),
    INT("output", "max_rows", 1e8, 1, 1e15, 0,
        "largest number of sample rows (t_end / interval) a run may write: a guard against a typo in interval"),
    {"output", {"checkpoint_interval", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED,
                "simulated time between restart points, where a checkpoint may be written for `bksim run "
                "--restart` to continue from (0: none); auto: a restart point after every checkpoint_work "
                "units of the run's work, none in a prescribed scene"},
     BK_KEY_NUMBER, NULL, NULL, "auto"},
    {"output", {"checkpoint_work", "1", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "with checkpoint_interval = auto: the work between restart points, counted as blocks "
                "advanced by integrator steps, transitions and blocks written in rows (0.2-0.6 us each "
                "on a 2-core EPYC); auto: 1e7 + 300 n_blocks, so a run of less work never restarts"},
     BK_KEY_NUMBER, NULL, NULL, "auto"},
    {"output", {"checkpoint_wall_interval", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED,
                "wall-clock time after which the next restart point is written as a checkpoint (0: every "
                "restart point); auto: 300 s, or 0 when checkpoint_interval is given"},
     BK_KEY_NUMBER, NULL, NULL, "auto"},

    NUM("catalog", "magnitude_offset", "1", 0.0, -100.0, 100.0, 0,
        "added to every magnitude (2/3) log10(potency / 1 m): differences are moment-magnitude differences"),
    {"catalog", {"slip_rate_threshold", "m/s", NAN, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
                 "for laws without a stuck state (dieterich_ruina_*): a block slips, for the catalog, while its "
                 "|slip rate| exceeds this; required for such laws when events are on"},
     BK_KEY_NUMBER, NULL, NULL, "none"},
    {"catalog", {"rupture_rate", "", 1, 0, 1, 0,
                 "write /rupture_rate, every rupture's moment-rate function (the sum of |v| over its slipping "
                 "blocks) sampled finely enough that it integrates to the rupture's potency to 1e-3; false keeps "
                 "/ruptures and /rupture_blocks only"},
     BK_KEY_BOOLEAN, NULL, NULL, "true"},

    NUM("run", "t_end", "s", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE,
        "end time (runs from 0); with a prescribed schedule or [driver] velocities optional, at most the "
        "schedule's length"),
    NUM("run", "wall_time_limit", "s", 0.0, 0.0, INFINITY, 0,
        "wall-clock time after which the run stops with an error, keeping what it wrote (0: no limit)"),

    {"prescribed", {"slip_rates", "m/s", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED,
                    "slip rate of each segment, in order (0: a hold)"}, BK_KEY_LIST, NULL, NULL, NULL},
    {"prescribed", {"durations", "s", NAN, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
                    "duration of each segment (give durations or distances)"}, BK_KEY_LIST, NULL, NULL, "-"},
    {"prescribed", {"distances", "m", NAN, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
                    "slip distance of each segment (not for holds)"}, BK_KEY_LIST, NULL, NULL, "-"},
};
#define N_KEYS (sizeof keys / sizeof keys[0])

const char *const bk_config_sections[] = {"model", "block", "friction", "driver", "solver", "output", "catalog",
                                          "run", "prescribed", NULL};

int bk_config_key(size_t i, bk_key_info *info)
{
    if (i >= N_KEYS)
        return -1;
    info->section = keys[i].section;
    info->param = &keys[i].param;
    info->kind = keys[i].type;
    return 0;
}

const key_def *bk_config_find_key(const char *section, const char *key)
{
    for (size_t i = 0; i < N_KEYS; ++i)
        if (strcmp(keys[i].section, section) == 0 && strcmp(keys[i].param.key, key) == 0)
            return &keys[i];
    return NULL;
}

const char *bk_config_enum_choice(const key_def *def, size_t i)
{
    return def->choice ? def->choice(i) : def->choices[i];
}

void bk_config_list_keys(const char *section, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < N_KEYS && used < len; ++i)
        if (strcmp(keys[i].section, section) == 0)
            used += (size_t)snprintf(buf + used, len - used, "%s%s", used ? ", " : "", keys[i].param.key);
}

/* What a value of the key must look like: one text for the error messages and the reference. */
void bk_config_format_allowed(const key_def *def, const bk_param *param, char *buf, size_t len)
{
    if (def && def->type == BK_KEY_LIST) {
        char range[256];
        bk_param_format_range(param, range, sizeof range);
        snprintf(buf, len, "numbers separated by commas or spaces, each %s", range);
        return;
    }
    if (!def || def->type == BK_KEY_NUMBER || def->type == BK_KEY_INTEGER) {
        bk_param_format_range(param, buf, len);
        if (def && def->type == BK_KEY_INTEGER) {
            size_t used = strlen(buf);
            snprintf(buf + used, len - used, ", an integer");
        }
        return;
    }
    if (def->type == BK_KEY_BOOLEAN) {
        snprintf(buf, len, "%strue, false, yes, no, on, off, 1, 0", isnan(param->default_value) ? "auto, " : "");
        return;
    }
    if (def->type == BK_KEY_TEXT) {
        snprintf(buf, len, "a non-empty text");
        return;
    }
    size_t used = 0;
    buf[0] = '\0';
    if (def->type == BK_KEY_FIELDS)
        used += (size_t)snprintf(buf, len, "all, or a list of ");
    for (size_t i = 0; bk_config_enum_choice(def, i) && used < len; ++i)
        used += (size_t)snprintf(buf + used, len - used, "%s%s", i ? ", " : "", bk_config_enum_choice(def, i));
}

/* --- reference -------------------------------------------------------------------------- */

static void write_default(FILE *out, const key_def *def, const bk_param *param)
{
    if (def && def->default_text)
        fprintf(out, "%s", def->default_text);
    else if (param->flags & BK_PARAM_REQUIRED)
        fprintf(out, "required");
    else if (def && def->type == BK_KEY_BOOLEAN)
        fprintf(out, "%s", param->default_value != 0 ? "true" : "false");
    else
        fprintf(out, "%g", param->default_value);
}

static void write_row(FILE *out, const key_def *def, const bk_param *param)
{
    char allowed[1536];
    bk_config_format_allowed(def, param, allowed, sizeof allowed);
    const char *unit = param->unit && param->unit[0] ? param->unit : "-";
    fprintf(out, "| `%s` | %s | ", param->key, unit);
    write_default(out, def, param);
    fprintf(out, " | %s | %s |\n", allowed, param->doc);
}

void bk_config_write_reference(FILE *out)
{
    static const char *const notes[] = {
        "model", "The chain, or the 2D lattice.",
        "block", "Defaults for every block; a `[block.I]` section (I = 0 .. n_blocks-1) overrides them for block I. "
                 "Any numeric key here or in `[friction]` may be a distribution drawn per block at load time from "
                 "`[model] seed`: `uniform(a, b)`, `normal(mean, sd)` or `lognormal(mu, sigma)` (of the log); or a "
                 "profile across the blocks: `linear(first, last)` from the first column to the last (a chain's "
                 "first block to its last), `linear_rows(first, last)` from the first row to the last, or "
                 "`file(path, column)`: one line per block in block order (row by row on a lattice), columns "
                 "separated by spaces or tabs, `#` comments and blank lines skipped, the path relative to the "
                 "config's directory (read again by `--restart`: keep it). A value outside the key's range is an "
                 "error naming the block (and the file's line), and every block's value is written to "
                 "`/parameters/<section>.<key>`.",
        "friction", "The friction law of every block and its parameters (tables below); `[friction.I]` overrides "
                    "them for block I. A `[friction.I]` naming a different law takes none of `[friction]`'s "
                    "parameters. Numeric parameters may be distributions, as in `[block]`.",
        "driver", "The driver that pulls every block through its driver spring.",
        "solver", "Integration.",
        "output", "The HDF5 file.",
        "catalog", "The rupture catalog (/ruptures, /rupture_blocks, /rupture_rate: connected sets of slip episodes, "
                   "README \"Ruptures\") and the time-window catalog (/events: maximal intervals during which some "
                   "block slips).",
        "run", "The time span.",
        "prescribed", "A prescribed-motion scene instead of the chain's dynamics (paper Figure 2, slide-hold-slide): "
                      "one block slides at a piecewise-constant slip rate and its friction state follows the law's "
                      "exact evolution. The presence of this section selects it; `[model]`, `[block]` and `[driver]` "
                      "keys are then optional (normal_force defaults to mass * gravity, or 1 N without a mass).",
    };
    fprintf(out, "Units are SI. Keys are case-sensitive; `;` starts a comment (also after a value).\n");
    for (size_t s = 0; bk_config_sections[s]; ++s) {
        fprintf(out, "\n### [%s]\n\n%s\n\n", bk_config_sections[s], notes[2 * s + 1]);
        fprintf(out, "| key | unit | default | allowed | meaning |\n| --- | --- | --- | --- | --- |\n");
        for (size_t i = 0; i < N_KEYS; ++i)
            if (strcmp(keys[i].section, bk_config_sections[s]) == 0)
                write_row(out, &keys[i], &keys[i].param);
    }
    for (const bk_friction_law *const *law = bk_friction_laws(); *law; ++law) {
        fprintf(out, "\n### [friction] law = %s\n\n%s\n\n", (*law)->name, (*law)->doc);
        fprintf(out, "| key | unit | default | allowed | meaning |\n| --- | --- | --- | --- | --- |\n");
        for (size_t p = 0; p < (*law)->n_params; ++p)
            write_row(out, NULL, &(*law)->params[p]);
    }
}
