/* Private to the config loader, shared by its files: config_keys.c (the key table and the
 * reference), config_report.c (failures with their location), config_parse.c (text to
 * checked entries), config_random.c (values drawn per block), config_history.c (the
 * driver, its history from keys or a table), config_tables.c (the files they read), config_build.c (entries to a
 * bk_config, with the cross-key checks), config_warnings.c (plausibility warnings) and
 * config.c (the public entry points).  Not installed: the public API is
 * include/bksim/config.h. */
#ifndef BKSIM_CONFIG_LOADER_H
#define BKSIM_CONFIG_LOADER_H

#include <limits.h>
#include <stddef.h>
#include <stdio.h>

#include "bksim/config.h"

#define SECTION_LEN 64
#define BK_CONFIG_MAX_BLOCKS 1000000L
#define KEY_LEN 64

/* --- the key table (config_keys.c) ------------------------------------------------------ */

typedef struct key_def {
    const char *section;
    bk_param param;               /* key, unit, default, range, flags, doc */
    bk_key_kind type;
    const char *const *choices;   /* BK_KEY_CHOICE with fixed words */
    const char *(*choice)(size_t); /* BK_KEY_CHOICE with registered names */
    const char *default_text;     /* for the reference when the default is not a number */
} key_def;

extern const char *const bk_config_sections[];           /* NULL-terminated, in reference order */
extern const char *const bk_config_linear_solver_names[]; /* [solver] linear_solver words */
extern const char *const bk_config_local_stepping_names[]; /* [solver] local_stepping words */
const char *bk_config_method_name(size_t i);              /* [solver] method words; NULL past the end */
const key_def *bk_config_find_key(const char *section, const char *key);
const char *bk_config_enum_choice(const key_def *def, size_t i);
void bk_config_list_keys(const char *section, char *buf, size_t len);
void bk_config_format_allowed(const key_def *def, const bk_param *param, char *buf, size_t len);

/* --- collected entries (config_parse.c) ------------------------------------------------- */

typedef struct entry {
    char section[SECTION_LEN]; /* as written, e.g. "block.3" */
    char base[SECTION_LEN];    /* "block" */
    long index;                /* block index of a per-block section, -1 otherwise */
    char key[KEY_LEN];
    char *value;
    int line;                  /* file line, or 0 for an override */
    int section_line;          /* line of the section's header (0: none, or an override) */
    const char *override;      /* the --set text, or NULL */
    long rank;                 /* position for "first error" */
    int superseded;            /* replaced by a later override */
    long first_of_key;         /* an earlier file entry of the same section and key, or -1 */
    double number;             /* parsed value (numbers, bools, enum index, list length) */
    double *list;              /* BK_KEY_LIST values, owned */
    /* A value per block (config_random.c): drawn (BK_DRAW_UNIFORM .. LOGNORMAL) or a profile
     * (BK_PROFILE_LINEAR, _ROWS, _FILE); 0 (BK_DRAW_NONE) for one value. */
    int distribution;
    double dist_a, dist_b;
    double *profile;           /* BK_PROFILE_FILE: the column's values, owned, read at the first block */
    int *profile_lines;        /* and the file line of each, for messages */
    size_t profile_len;
    void *rng;                 /* the entry's stream (gsl_rng), owned */
    size_t drawn;              /* numbers drawn so far, and the last */
    double last_draw;
} entry;

enum {
    BK_DRAW_NONE = 0,
    BK_DRAW_UNIFORM = 1,
    BK_DRAW_NORMAL = 2,
    BK_DRAW_LOGNORMAL = 3,
    BK_PROFILE_LINEAR = 4,      /* linear(first, last): along a row (a chain's blocks), by column */
    BK_PROFILE_LINEAR_ROWS = 5, /* linear_rows(first, last): along a column, by row */
    BK_PROFILE_FILE = 6         /* file(path[, column]): one line per block */
};

typedef struct loader {
    const char *name;          /* config file name for messages */
    entry *entries;
    size_t n, cap;
    long error_rank;           /* rank of the recorded error, LONG_MAX when none */
    bk_error *err;
    int status;
    /* reader state */
    const char *cursor;
    int line;                  /* the first physical line of the logical line read last */
    int physical;              /* physical lines read */
    int section_line;          /* line of the last [section] header read */
    int oom;
    char *logical;             /* the logical line being read (continuations joined), owned */
    size_t logical_cap;
    int *call_lines;           /* the line of each logical line handed to inih, in order */
    size_t calls, calls_cap;
    char **long_values;        /* values of lines longer than inih's buffer, owned */
    size_t n_long, long_cap;
    int long_line;             /* the line whose value is long_values[n_long - 1], else 0 */
    /* (section, key) -> the last live entry, so that lookups (per block, per key) cost O(1)
     * and a config with many [block.I] sections loads in linear time. */
    size_t *slots;             /* entry index + 1, 0 for an empty slot */
    size_t n_slots;            /* a power of two, at least twice the entries */
    int per_block_sections;    /* any [block.I] or [friction.I] entry: else blocks skip those lookups */
    unsigned long seed;        /* [model] seed, once building begins */
    size_t rows, cols;         /* the shape, once building begins (profiles need it) */
    bk_block_parameter *parameters; /* keys given as a distribution, until the config takes them */
    size_t n_parameters;
} loader;

/* Ranks put errors in the order a user fixes them: 0 (out of memory) first, then file lines,
 * then the --set overrides (INT_MAX + k), then keys that are missing altogether. */
#define RANK_MISSING (LONG_MAX - 1)

/* --- reporting failures (config_report.c) ---------------------------------------------- */

/* Record a failure at `rank` unless an earlier one is already recorded. */
void bk_config_report(loader *ld, long rank, int status, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* The same for entry e: "file:line: [section] key: " and the message, at the entry's rank. */
void bk_config_report_entry(loader *ld, const entry *e, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* "[section] key: required key missing", with what is allowed, at RANK_MISSING. */
void bk_config_report_missing(loader *ld, const char *section, const bk_param *param, const key_def *def);
/* "file:12" or "--set block.mass=0". */
void bk_config_location(const loader *ld, const entry *e, char *buf, size_t len);

/* --- text to checked entries (config_parse.c) ------------------------------------------- */

int bk_config_add_entry(loader *ld, const char *section, const char *key, const char *value, int line,
                        const char *override, long rank);
/* inih's reader and handler (ini_parse_stream(bk_config_read_line, ld, bk_config_on_pair, ld)).
 * The reader joins continuation lines and hands inih lines longer than its buffer with their
 * value held aside; bk_config_reader_line maps inih's line count back to the file's line. */
char *bk_config_read_line(char *str, int num, void *stream);
int bk_config_on_pair(void *user, const char *section, const char *key, const char *value);
int bk_config_reader_line(const loader *ld, int inih_line);
void bk_config_free_reader(loader *ld);
int bk_config_build_index(loader *ld);
/* The entry of [base.i] key, or NULL; O(1) without formatting when no such section exists. */
entry *bk_config_lookup_block(loader *ld, const char *base, size_t i, const char *key);
entry *bk_config_lookup(loader *ld, const char *section, const char *key);
int bk_config_check_value(loader *ld, entry *e, const key_def *def, const bk_param *param);
void bk_config_check_entries(loader *ld, long n_blocks);

/* --- per-block random values (config_random.c) ----------------------------------------- */

/* 1 and the entry set up when its value is a distribution or a profile, 0 when it is
 * neither, -1 reported. */
int bk_config_parse_distribution(loader *ld, entry *e, const bk_param *param, const char *allowed);
/* The entry's value for block i, drawn or from its profile (blocks in increasing order);
 * NAN, reported, when it falls outside param's range (or the profile's file fails). */
double bk_config_draw(loader *ld, entry *e, size_t block, const bk_param *param);
void bk_config_free_draws(entry *e);
/* A /parameters array for every key some entry draws (-1, reported, when out of memory); the
 * values blocks end with go in by bk_config_record_parameter (a key without one is ignored). */
int bk_config_plan_parameters(loader *ld, size_t n_blocks);
void bk_config_record_parameter(loader *ld, const char *base, const char *key, const char *unit, size_t block,
                                double value);
void bk_config_free_parameters(bk_block_parameter *parameters, size_t n);

/* --- files a config names (config_tables.c) -------------------------------------------- */

/* path as a config names it: relative to the config file's directory, unless absolute. */
void bk_config_path_near(const loader *ld, const char *path, char *buf, size_t len);
/* Open the table (a profile, a history) that entry e names at path: a regular file of at most
 * max_bytes (a device or a FIFO could be read for ever); NULL, reported, otherwise. */
FILE *bk_config_open_table(loader *ld, const entry *e, const char *path, long max_bytes, const char *what);

/* --- the driver (config_history.c) ----------------------------------------------------- */

/* The driver of [driver]: a constant velocity, or a history of velocities and durations (in
 * keys, or a table: velocities_file, errors with its file:line; with a t column the last
 * segment lasts until [run] t_end).  Returns the history's length (s), or NAN for a constant
 * velocity (or an error, reported). */
double bk_config_build_driver(loader *ld, bk_model *m);

/* --- building (config_build.c) ---------------------------------------------------------- */

bk_config *bk_config_build(loader *ld);

#endif
