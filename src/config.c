/* INI -> validated bk_config.  One table of keys (plus each friction law's parameter table)
 * drives parsing, validation and the reference documentation.
 *
 * Parsing goes through inih with our own line reader, which counts lines (Debian's inih
 * gives the handler none), strips leading whitespace (an indented line would otherwise be
 * glued to the previous value as a continuation) and rejects over-long lines (inih would
 * silently cut them).  Every entry is collected first, then checked; the error reported is
 * the earliest in file order (then --set order), so a user fixes errors top to bottom. */
#include "bksim/config.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <gsl/gsl_rng.h>
#include <ini.h>

#include "bksim/solver.h"
#include "output/layout.h"

#define MAX_LINE_CHARS 190
#define MAX_FILE_BYTES (1 << 20)
#define MAX_BLOCKS 1000000L
#define SECTION_LEN 64
#define KEY_LEN 64

/* --- the key table ---------------------------------------------------------------------- */



static const char *const boundary_names[] = {"free", "fixed", "periodic", NULL};
static const char *const spring_names[] = {"linear", "tension_only", NULL};
static const char *const linear_solver_names[] = {"auto", "dense", "band", NULL};

/* "auto" (resolved by the run loop from the scene), then every registered back-end. */
static const char *method_name(size_t i)
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

typedef struct key_def {
    const char *section;
    bk_param param;               /* key, unit, default, range, flags, doc */
    bk_key_kind type;
    const char *const *choices;   /* BK_KEY_CHOICE with fixed words */
    const char *(*choice)(size_t); /* BK_KEY_CHOICE with registered names */
    const char *default_text;     /* for the reference when the default is not a number */
} key_def;

#define NUM(sec, k, unit, def, lo, hi, fl, doc) {sec, {k, unit, def, lo, hi, fl, doc}, BK_KEY_NUMBER, NULL, NULL, NULL}
#define INT(sec, k, def, lo, hi, fl, doc) {sec, {k, "1", def, lo, hi, fl, doc}, BK_KEY_INTEGER, NULL, NULL, NULL}

static const key_def keys[] = {
    INT("model", "n_blocks", NAN, 1, MAX_BLOCKS, BK_PARAM_REQUIRED, "number of blocks in the chain"),
    {"model", {"boundary", "", 0, 0, 0, 0, "chain ends: free, fixed (tied to walls at 0) or periodic (a ring)"},
     BK_KEY_CHOICE, boundary_names, NULL, "free"},
    NUM("model", "coupling_stiffness", "N/m", 0.0, 0.0, INFINITY, 0, "stiffness of the springs between neighbours"),
    NUM("model", "gravity", "m/s^2", 9.81, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
        "gravitational acceleration, for the default normal force"),
    INT("model", "seed", 1, 0, 4294967295.0, 0,
        "seed of the random numbers drawn at load time (x_init_random); same seed, same run"),

    NUM("block", "mass", "kg", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE, "block mass"),
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

    {"friction", {"law", "", NAN, 0, 0, BK_PARAM_REQUIRED, "friction law; its parameters follow in the same section"},
     BK_KEY_CHOICE, NULL, law_name, NULL},

    NUM("driver", "velocity", "m/s", NAN, -INFINITY, INFINITY,
        BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE, "driver velocity (constant)"),
    {"driver", {"spring", "", 0, 0, 0, 0, "driver springs: linear, or tension_only (pull, never push; NOTES.md 3)"},
     BK_KEY_CHOICE, spring_names, NULL, "linear"},
    NUM("driver", "start_position", "m", 0.0, -INFINITY, INFINITY, BK_PARAM_MIN_EXCLUSIVE | BK_PARAM_MAX_EXCLUSIVE,
        "driver position at t = 0 (0: at the relaxed blocks)"),

    {"solver", {"method", "", 0, 0, 0, 0,
                "integrator back-end; auto: exact for Coulomb scenes (short chains), else gsl_rk8pd, or cvode_bdf when stiff (README \"Solver back-ends\")"},
     BK_KEY_CHOICE, NULL, method_name, "auto"},
    {"solver", {"linear_solver", "", 0, 0, 0, 0, "linear solver of implicit methods: auto (band for long chains), dense, band"},
     BK_KEY_CHOICE, linear_solver_names, NULL, "auto"},
    NUM("solver", "rtol", "1", 1e-8, 1e-15, 0.1, 0, "relative tolerance"),
    {"solver", {"atol_x", "m", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "absolute tolerance on positions"}, BK_KEY_NUMBER, NULL, NULL, "rtol * 1e-3 * max(F_s / k)"},
    {"solver", {"atol_v", "m/s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "absolute tolerance on velocities"}, BK_KEY_NUMBER, NULL, NULL,
     "rtol * 1e-3 * min(driver speed, max(F_s / k) * omega_max)"},
    {"solver", {"max_step", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "largest integrator step (keeps a slip-rate extremum from hiding inside a step)"},
     BK_KEY_NUMBER, NULL, NULL, "1/8 of the fastest natural period"},
    INT("solver", "max_steps", 100000, 1, INT_MAX, 0, "integrator steps allowed between two output rows"),
    {"solver", {"detect_velocity_extrema", "", 1, 0, 1, 0,
                "locate slip-rate minima to catch a stop hidden inside one step"}, BK_KEY_BOOLEAN, NULL, NULL, "true"},
    INT("solver", "max_transitions_per_instant", 100, 1, INT_MAX, 0,
        "transitions of one block within instant_window before the run stops as chattering"),
    {"solver", {"instant_window", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED | BK_PARAM_MIN_EXCLUSIVE,
                "transitions closer than this count as one instant"}, BK_KEY_NUMBER, NULL, NULL,
     "1e-6 of the fastest natural period"},

    NUM("solver", "min_step", "s", 0.0, 0.0, INFINITY, 0,
        "a step size below this stops the run with an error (0: no limit)"),
    {"solver", {"arkode_table", "", 0, 0, 0, 0,
                "Butcher table of arkode_erk (an explicit ARKODE_* table) or arkode_dirk (a DIRK one); default: "
                "the method's own (Zonneveld 5_3_4, SDIRK 5_3_4)"},
     BK_KEY_CHOICE, NULL, bk_solver_arkode_table, "default"},

    {"output", {"path", "", 0, 0, 0, 0, "HDF5 output file (bksim run -o overrides)"}, BK_KEY_TEXT, NULL, NULL,
     "config file name, .ini replaced by .h5"},
    {"output", {"interval", "s", NAN, 0.0, INFINITY, BK_PARAM_DERIVED,
                "time between samples, <= t_end; 0: rows only at transitions (and t = 0, t_end)"},
     BK_KEY_NUMBER, NULL, NULL, "t_end / 1000"},
    {"output", {"fields", "", 0, 0, 0, 0, "per-row datasets: all, or a list of x v friction cof mode energy state"},
     BK_KEY_FIELDS, bk_output_field_names, NULL, "all"},
    {"output", {"transitions", "", 1, 0, 1, 0, "write the /transitions table"}, BK_KEY_BOOLEAN, NULL, NULL, "true"},
    {"output", {"event_rows", "", 1, 0, 1, 0, "add a row at every transition instant"}, BK_KEY_BOOLEAN, NULL, NULL, "true"},
    NUM("output", "max_bytes", "B", 1e10, 0.0, INFINITY, BK_PARAM_MIN_EXCLUSIVE,
        "largest size the sample rows (t_end / interval, times the bytes per row for the fields and blocks) "
        "may take: a guard against a typo in interval or n_blocks"),
    INT("output", "max_rows", 1e8, 1, 1e15, 0,
        "largest number of sample rows (t_end / interval) a run may write: a guard against a typo in interval"),
    NUM("output", "checkpoint_interval", "s", 0.0, 0.0, INFINITY, 0,
        "time between checkpoints, from which `bksim run --restart` continues (0: none)"),

    NUM("run", "t_end", "s", NAN, 0.0, INFINITY, BK_PARAM_REQUIRED | BK_PARAM_MIN_EXCLUSIVE,
        "end time (runs from 0); in a prescribed scene optional, at most the schedule's length"),
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

static const char *const sections[] = {"model", "block", "friction", "driver", "solver", "output", "run",
                                       "prescribed", NULL};

int bk_config_key(size_t i, bk_key_info *info)
{
    if (i >= N_KEYS)
        return -1;
    info->section = keys[i].section;
    info->param = &keys[i].param;
    info->kind = keys[i].type;
    return 0;
}

static const key_def *find_key(const char *section, const char *key)
{
    for (size_t i = 0; i < N_KEYS; ++i)
        if (strcmp(keys[i].section, section) == 0 && strcmp(keys[i].param.key, key) == 0)
            return &keys[i];
    return NULL;
}

static const char *enum_choice(const key_def *def, size_t i)
{
    return def->choice ? def->choice(i) : def->choices[i];
}

/* --- collected entries ------------------------------------------------------------------ */

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
} entry;

typedef struct loader {
    const char *name;          /* config file name for messages */
    entry *entries;
    size_t n, cap;
    long error_rank;           /* rank of the recorded error, LONG_MAX when none */
    bk_error *err;
    int status;
    /* reader state */
    const char *cursor;
    int line;
    int section_line;          /* line of the last [section] header read */
    int oom;
    /* (section, key) -> the last live entry, so that lookups (per block, per key) cost O(1)
     * and a config with many [block.I] sections loads in linear time. */
    size_t *slots;             /* entry index + 1, 0 for an empty slot */
    size_t n_slots;            /* a power of two, at least twice the entries */
} loader;

#define RANK_MISSING (LONG_MAX - 1)

/* Record a failure at `rank` unless an earlier one is already recorded. */
static void report(loader *ld, long rank, int status, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static void report(loader *ld, long rank, int status, const char *fmt, ...)
{
    if (rank >= ld->error_rank)
        return;
    ld->error_rank = rank;
    ld->status = status;
    char buf[BK_ERROR_MESSAGE_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    BK_FAIL(ld->err, status, "%s", buf);
}

/* "file:12" or "--set block.mass=0". */
static void location(const loader *ld, const entry *e, char *buf, size_t len)
{
    if (e->override)
        snprintf(buf, len, "--set %s", e->override);
    else
        snprintf(buf, len, "%s:%d", ld->name, e->line);
}

/* Where a section was opened: its header line, or the entry's own location. */
static void section_location(const loader *ld, const entry *e, char *buf, size_t len)
{
    if (e->override || !e->section_line)
        location(ld, e, buf, len);
    else
        snprintf(buf, len, "%s:%d", ld->name, e->section_line);
}

static void report_entry(loader *ld, const entry *e, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void report_entry(loader *ld, const entry *e, const char *fmt, ...)
{
    if (e->rank >= ld->error_rank)
        return;
    char where[512], what[1792];
    location(ld, e, where, sizeof where);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    report(ld, e->rank, BK_ERR_CONFIG, "%s: [%s] %s: %s", where, e->section, e->key, what);
}

/* Split "block.3" into base "block" and index 3; -1 for plain sections, -2 if malformed. */
static long split_section(const char *section, char *base, size_t len)
{
    const char *dot = strchr(section, '.');
    if (!dot) {
        snprintf(base, len, "%s", section);
        return -1;
    }
    snprintf(base, len, "%.*s", (int)(dot - section), section);
    const char *digits = dot + 1;
    if (!*digits || (digits[0] == '0' && digits[1] != '\0'))
        return -2; /* [block.00] would alias [block.0] */
    for (const char *p = digits; *p; ++p)
        if (!isdigit((unsigned char)*p))
            return -2;
    errno = 0;
    long index = strtol(digits, NULL, 10);
    return errno ? -2 : index;
}

static int add_entry(loader *ld, const char *section, const char *key, const char *value, int line,
                     const char *override, long rank)
{
    if (ld->n == ld->cap) {
        size_t cap = ld->cap ? 2 * ld->cap : 32;
        entry *grown = realloc(ld->entries, cap * sizeof *grown);
        if (!grown)
            return -1;
        ld->entries = grown;
        ld->cap = cap;
    }
    entry *e = &ld->entries[ld->n];
    memset(e, 0, sizeof *e);
    e->value = strdup(value);
    if (!e->value)
        return -1;
    ld->n++;
    snprintf(e->section, sizeof e->section, "%s", section);
    snprintf(e->key, sizeof e->key, "%s", key);
    e->index = split_section(section, e->base, sizeof e->base);
    e->line = line;
    e->override = override;
    e->rank = rank;
    return 0;
}

/* fgets-style reader over the text in memory (see the file comment). */
static char *read_line(char *str, int num, void *stream)
{
    loader *ld = stream;
    if (!*ld->cursor)
        return NULL;
    const char *start = ld->cursor;
    /* Lines end in LF, CRLF or a lone CR (old Mac files). */
    const char *eol = strpbrk(start, "\r\n");
    size_t content = eol ? (size_t)(eol - start) : strlen(start);
    size_t len = content + (eol ? (eol[0] == '\r' && eol[1] == '\n' ? 2 : 1) : 0);
    ld->cursor = start + len;
    ld->line++;
    if (content > MAX_LINE_CHARS) {
        char where[300];
        snprintf(where, sizeof where, "%s:%d", ld->name, ld->line);
        report(ld, ld->line, BK_ERR_CONFIG, "%s: line longer than %d characters (%zu); split it",
               where, MAX_LINE_CHARS, content);
        content = 0;
    }
    while (content > 0 && (*start == ' ' || *start == '\t')) {
        ++start;
        --content;
    }
    if (content > 0 && *start == '[')
        ld->section_line = ld->line;
    if ((int)content + 2 > num)
        content = (size_t)num - 2;
    memcpy(str, start, content);
    str[content] = '\n';
    str[content + 1] = '\0';
    return str;
}

static int on_pair(void *user, const char *section, const char *key, const char *value)
{
    loader *ld = user;
    if (add_entry(ld, section, key, value, ld->line, NULL, ld->line) != 0)
        ld->oom = 1;
    else
        ld->entries[ld->n - 1].section_line = ld->section_line;
    return 1;
}

/* --- values ----------------------------------------------------------------------------- */

static void format_allowed(const key_def *def, const bk_param *param, char *buf, size_t len)
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
        snprintf(buf, len, "true, false, yes, no, on, off, 1, 0");
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
    for (size_t i = 0; enum_choice(def, i) && used < len; ++i)
        used += (size_t)snprintf(buf + used, len - used, "%s%s", i ? ", " : "", enum_choice(def, i));
}

static int parse_number(const char *text, double *out)
{
    if (!*text || strpbrk(text, "xX")) /* decimal only: strtod would take hex floats too */
        return -1;
    char *end = NULL;
    errno = 0;
    double value = strtod(text, &end);
    while (end && isspace((unsigned char)*end))
        ++end;
    /* ERANGE on underflow (1e-320) is a tiny number, which the ranges then judge. */
    if (end == text || *end != '\0' || (errno == ERANGE && fabs(value) >= 1.0) || !isfinite(value))
        return -1;
    *out = value;
    return 0;
}

static int parse_integer(const char *text, double *out)
{
    const char *p = text;
    if (*p == '+' || *p == '-')
        ++p;
    if (!isdigit((unsigned char)*p))
        return -1;
    for (const char *q = p; *q; ++q)
        if (!isdigit((unsigned char)*q))
            return -1;
    errno = 0;
    long long value = strtoll(text, NULL, 10);
    if (errno == ERANGE)
        return -1;
    *out = (double)value;
    return 0;
}

static int parse_bool(const char *text, double *out)
{
    static const char *const yes[] = {"true", "yes", "on", "1"}, *const no[] = {"false", "no", "off", "0"};
    for (size_t i = 0; i < 4; ++i) {
        if (strcasecmp(text, yes[i]) == 0) {
            *out = 1;
            return 0;
        }
        if (strcasecmp(text, no[i]) == 0) {
            *out = 0;
            return 0;
        }
    }
    return -1;
}

/* Parse a "fields" list into a BK_FIELD_* mask; -1 and the bad word on failure. */
static int parse_fields(const char *text, double *out, char *bad, size_t bad_len)
{
    unsigned mask = 0;
    const char *p = text;
    int words = 0;
    while (*p) {
        while (*p == ',' || isspace((unsigned char)*p))
            ++p;
        if (!*p)
            break;
        const char *start = p;
        while (*p && *p != ',' && !isspace((unsigned char)*p))
            ++p;
        size_t len = (size_t)(p - start);
        ++words;
        if (len == 3 && strncmp(start, "all", 3) == 0) {
            mask = BK_FIELD_ALL;
            continue;
        }
        size_t i = 0;
        for (; bk_output_field_names[i]; ++i)
            if (strlen(bk_output_field_names[i]) == len &&
                strncmp(bk_output_field_names[i], start, len) == 0)
                break;
        if (!bk_output_field_names[i]) {
            snprintf(bad, bad_len, "%.*s", (int)len, start);
            return -1;
        }
        mask |= 1u << i;
    }
    if (!words) {
        snprintf(bad, bad_len, "(empty)");
        return -1;
    }
    *out = (double)mask;
    return 0;
}

/* Parse and range-check an entry's value against its definition; reports on failure. */
static int check_value(loader *ld, entry *e, const key_def *def, const bk_param *param)
{
    char allowed[1536];
    format_allowed(def, param, allowed, sizeof allowed);
    bk_key_kind type = def ? def->type : BK_KEY_NUMBER;
    const char *v = e->value;
    switch (type) {
    case BK_KEY_NUMBER:
    case BK_KEY_INTEGER: {
        int bad = type == BK_KEY_INTEGER ? parse_integer(v, &e->number) : parse_number(v, &e->number);
        if (bad) {
            const char *hint = strchr(v, '#') ? " (inline comments start with ';')" : "";
            report_entry(ld, e, "%s \"%s\"%s (allowed: %s)",
                         type == BK_KEY_INTEGER ? "not an integer:" : "not a number:", v, hint, allowed);
            return -1;
        }
        if (!bk_param_in_range(param, e->number)) {
            report_entry(ld, e, "out of range, got %s (allowed: %s)", v, allowed);
            return -1;
        }
        return 0;
    }
    case BK_KEY_BOOLEAN:
        if (parse_bool(v, &e->number)) {
            report_entry(ld, e, "not a boolean: \"%s\" (allowed: %s)", v, allowed);
            return -1;
        }
        return 0;
    case BK_KEY_CHOICE:
        for (size_t i = 0; enum_choice(def, i); ++i)
            if (strcmp(enum_choice(def, i), v) == 0) {
                e->number = (double)i;
                return 0;
            }
        report_entry(ld, e, "unknown value \"%s\" (allowed: %s)", v, allowed);
        return -1;
    case BK_KEY_TEXT:
        if (!*v) {
            report_entry(ld, e, "empty value (allowed: %s)", allowed);
            return -1;
        }
        return 0;
    case BK_KEY_LIST: {
        size_t count = 0, cap = 8;
        e->list = malloc(cap * sizeof *e->list);
        if (!e->list) {
            ld->oom = 1;
            return -1;
        }
        for (const char *p = v;;) {
            while (*p == ',' || isspace((unsigned char)*p))
                ++p;
            if (!*p)
                break;
            const char *start = p;
            while (*p && *p != ',' && !isspace((unsigned char)*p))
                ++p;
            char word[64];
            snprintf(word, sizeof word, "%.*s", (int)(p - start), start);
            double x;
            if (parse_number(word, &x) || !bk_param_in_range(param, x)) {
                report_entry(ld, e, "bad value \"%s\" (item %zu) (allowed: %s)", word, count + 1, allowed);
                return -1;
            }
            if (count == cap) {
                double *grown = realloc(e->list, 2 * cap * sizeof *grown);
                if (!grown) {
                    ld->oom = 1;
                    return -1;
                }
                e->list = grown;
                cap *= 2;
            }
            e->list[count++] = x;
        }
        if (count == 0) {
            report_entry(ld, e, "empty list (allowed: %s)", allowed);
            return -1;
        }
        e->number = (double)count;
        return 0;
    }
    case BK_KEY_FIELDS: {
        char bad[64];
        if (parse_fields(v, &e->number, bad, sizeof bad)) {
            report_entry(ld, e, "unknown field \"%s\" (allowed: %s)", bad, allowed);
            return -1;
        }
        return 0;
    }
    }
    return -1;
}

static size_t hash_key(const char *section, const char *key)
{
    uint64_t h = 1469598103934665603u; /* FNV-1a */
    for (const char *p = section; *p; ++p)
        h = (h ^ (unsigned char)*p) * 1099511628211u;
    h = (h ^ '\n') * 1099511628211u;
    for (const char *p = key; *p; ++p)
        h = (h ^ (unsigned char)*p) * 1099511628211u;
    return (size_t)h;
}

/* The slot holding section/key, or the empty slot where it would go. */
static size_t *find_slot(const loader *ld, const char *section, const char *key)
{
    size_t mask = ld->n_slots - 1;
    for (size_t i = hash_key(section, key) & mask;; i = (i + 1) & mask) {
        size_t *slot = &ld->slots[i];
        if (*slot == 0)
            return slot;
        const entry *e = &ld->entries[*slot - 1];
        if (strcmp(e->section, section) == 0 && strcmp(e->key, key) == 0)
            return slot;
    }
}

/* Index the live entries, in order, so each slot ends at the last one of its key; note a
 * key given twice in the file (not by an override). */
static int build_index(loader *ld)
{
    ld->n_slots = 16;
    while (ld->n_slots < 2 * ld->n)
        ld->n_slots *= 2;
    ld->slots = calloc(ld->n_slots, sizeof *ld->slots);
    if (!ld->slots)
        return -1;
    for (size_t i = 0; i < ld->n; ++i) {
        entry *e = &ld->entries[i];
        e->first_of_key = -1;
        if (e->superseded)
            continue;
        size_t *slot = find_slot(ld, e->section, e->key);
        if (*slot != 0 && !e->override && !ld->entries[*slot - 1].override) {
            const entry *earlier = &ld->entries[*slot - 1];
            e->first_of_key = earlier->first_of_key >= 0 ? earlier->first_of_key : (long)(*slot - 1);
        }
        *slot = i + 1;
    }
    return 0;
}

/* The last (not superseded) entry for section/key, or NULL. */
static entry *lookup(loader *ld, const char *section, const char *key)
{
    size_t slot = *find_slot(ld, section, key);
    return slot ? &ld->entries[slot - 1] : NULL;
}

static void list_keys(const char *section, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < N_KEYS && used < len; ++i)
        if (strcmp(keys[i].section, section) == 0)
            used += (size_t)snprintf(buf + used, len - used, "%s%s", used ? ", " : "", keys[i].param.key);
}

static void list_law_params(const bk_friction_law *law, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < law->n_params && used < len; ++i)
        used += (size_t)snprintf(buf + used, len - used, "%s%s", i ? ", " : "", law->params[i].key);
}

/* The law a friction section uses: its own `law` entry, or for [friction.I] the base's. */
static const bk_friction_law *section_law(loader *ld, const entry *e)
{
    entry *own = lookup(ld, e->section, "law");
    if (!own && e->index >= 0)
        own = lookup(ld, "friction", "law");
    return own ? bk_friction_law_find(own->value) : NULL;
}

/* --- checks ----------------------------------------------------------------------------- */

/* Sections, keys, duplicates and every value on its own. */
static void check_entries(loader *ld, long n_blocks)
{
    char allowed[1536];
    for (size_t i = 0; i < ld->n; ++i) {
        entry *e = &ld->entries[i];
        if (e->superseded)
            continue;
        int known_section = 0;
        for (size_t s = 0; sections[s]; ++s)
            known_section |= strcmp(sections[s], e->base) == 0;
        int per_block_ok = strcmp(e->base, "block") == 0 || strcmp(e->base, "friction") == 0;
        if (!known_section || e->index == -2 || (e->index >= 0 && !per_block_ok)) {
            char where[512];
            section_location(ld, e, where, sizeof where);
            report(ld, e->section_line ? e->section_line : e->rank, BK_ERR_CONFIG,
                   "%s: [%s]: unknown section (allowed: model, block, block.I, friction, friction.I, "
                   "driver, solver, output, run; I is a block index from 0)",
                   where, e->section);
            continue;
        }
        if (e->index >= 0 && n_blocks > 0 && e->index >= n_blocks) {
            char where[512];
            section_location(ld, e, where, sizeof where);
            report(ld, e->section_line ? e->section_line : e->rank, BK_ERR_CONFIG, "%s: [%s]: block index out of range (allowed: 0..%ld)",
                   where, e->section, n_blocks - 1);
            continue;
        }
        /* A key given twice in one section of the file. */
        if (e->first_of_key >= 0)
            report_entry(ld, e, "duplicate key (first set at line %d)", ld->entries[e->first_of_key].line);
        const key_def *def = find_key(e->base, e->key);
        if (def) {
            check_value(ld, e, def, &def->param);
            continue;
        }
        if (strcmp(e->base, "friction") == 0) {
            const bk_friction_law *law = section_law(ld, e);
            if (!law)
                continue; /* the missing or unknown law is reported at its own line */
            int p = bk_friction_param_index(law, e->key);
            if (p < 0) {
                list_law_params(law, allowed, sizeof allowed);
                report_entry(ld, e, "not a parameter of law '%s' (known: law, %s)", law->name, allowed);
                continue;
            }
            check_value(ld, e, NULL, &law->params[p]);
            continue;
        }
        list_keys(e->base, allowed, sizeof allowed);
        report_entry(ld, e, "unknown key (allowed: %s)", allowed);
    }
}

static void report_missing(loader *ld, const char *section, const bk_param *param, const key_def *def)
{
    char allowed[1536];
    format_allowed(def, param, allowed, sizeof allowed);
    report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [%s] %s: required key missing (allowed: %s)", ld->name,
           section, param->key, allowed);
}

/* Value of a key in [section] (checked), or the definition's default. */
static double value_of(loader *ld, const char *section, const char *key)
{
    entry *e = lookup(ld, section, key);
    if (e)
        return e->number;
    const key_def *def = find_key(section, key);
    if (def->type == BK_KEY_CHOICE && def->default_text)
        for (size_t i = 0; enum_choice(def, i); ++i)
            if (strcmp(enum_choice(def, i), def->default_text) == 0)
                return (double)i;
    if (def->type == BK_KEY_FIELDS)
        return (double)BK_FIELD_ALL;
    if (def->param.flags & BK_PARAM_REQUIRED)
        report_missing(ld, section, &def->param, def);
    return def->param.default_value;
}

/* A block key: [block.I] over [block] over the default. */
static double block_value(loader *ld, size_t i, const char *key, int *given)
{
    char section[SECTION_LEN];
    snprintf(section, sizeof section, "block.%zu", i);
    entry *e = lookup(ld, section, key);
    if (!e)
        e = lookup(ld, "block", key);
    *given = e != NULL;
    return e ? e->number : find_key("block", key)->param.default_value;
}

/* Friction of block i: its law and parameters, completed and validated. */
static void build_friction(loader *ld, bk_block *b, size_t i, double driver_speed)
{
    char section[SECTION_LEN];
    snprintf(section, sizeof section, "friction.%zu", i);
    entry *own_law = lookup(ld, section, "law");
    entry *base_law = lookup(ld, "friction", "law");
    entry *law_entry = own_law ? own_law : base_law;
    if (!law_entry) {
        report_missing(ld, "friction", &find_key("friction", "law")->param, find_key("friction", "law"));
        return;
    }
    const bk_friction_law *law = bk_friction_law_find(law_entry->value);
    if (!law)
        return; /* reported at its line */
    /* Parameters of [friction] apply unless this block names a different law. */
    int inherit = !own_law || (base_law && strcmp(own_law->value, base_law->value) == 0);
    const char *param_section = own_law ? section : "friction";
    entry *origin[BK_FRICTION_MAX_PARAMS] = {0};
    b->law = law;
    for (size_t p = 0; p < law->n_params; ++p) {
        const bk_param *param = &law->params[p];
        entry *e = lookup(ld, section, param->key);
        if (!e && inherit)
            e = lookup(ld, "friction", param->key);
        origin[p] = e;
        if (e) {
            b->friction_params[p] = e->number;
        } else if (param->flags & BK_PARAM_REQUIRED) {
            report_missing(ld, param_section, param, NULL);
            b->friction_params[p] = NAN;
        } else {
            b->friction_params[p] = param->default_value;
        }
    }
    if (law->complete) {
        bk_friction_context ctx = {fabs(driver_speed), b->normal_force};
        law->complete(b->friction_params, &ctx);
        /* A default derived from other values (theta_init = L0 / driver speed) can overflow; a NaN
         * one is the law's to report (validate says which value it needs). */
        for (size_t p = 0; p < law->n_params; ++p)
            if (!origin[p] && isinf(b->friction_params[p]) && ld->error_rank == LONG_MAX) {
                report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [%s] %s: its default for block %zu is not finite (%g); "
                       "set it (allowed: %g < %s < %g)", ld->name, param_section, law->params[p].key, i,
                       b->friction_params[p], law->params[p].min, law->params[p].key, law->params[p].max);
                return;
            }
    }
    if (law->validate) {
        char msg[256];
        int bad = law->validate(b->friction_params, msg, sizeof msg);
        entry *at = bad >= 0 ? origin[bad] : NULL;
        /* The same conflict in every block of a long chain is reported once: only an
         * earlier-ranked one is worth the message. */
        if (bad >= 0 && !(at && at->rank >= ld->error_rank)) {
            /* A conflict with this block's own value is reported at the shared key: name the
             * block and where its value came from. */
            char block_note[640] = "";
            for (size_t q = 0; q < law->n_params && (!at || strcmp(at->section, section) != 0); ++q)
                if (origin[q] && strcmp(origin[q]->section, section) == 0) {
                    char where[512];
                    location(ld, origin[q], where, sizeof where);
                    if (snprintf(block_note, sizeof block_note, " (block %zu: %s sets [%s] %s = %s)", i,
                                 where, section, origin[q]->key, origin[q]->value) < 0)
                        block_note[0] = '\0';
                    break;
                }
            if (at)
                report_entry(ld, at, "%s%s", msg, block_note);
            else
                report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [%s] %s: %s%s", ld->name, param_section,
                       law->params[bad].key, msg, block_note);
        }
    }
}

static char *default_output_path(const char *name)
{
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    size_t len = strlen(base);
    if (len > 4 && strcmp(base + len - 4, ".ini") == 0)
        len -= 4;
    char *path = malloc(len + 4);
    if (path)
        snprintf(path, len + 4, "%.*s.h5", (int)len, base);
    return path;
}

/* The energy audit needs finite energies: a start state whose energy overflows a double
 * is refused here rather than reported as a NaN residual after the run. */
static void check_initial_energy(loader *ld, const bk_model *m)
{
    double driver0 = bk_driver_position(&m->driver, 0.0);
    for (size_t i = 0; i < m->n_blocks; ++i) {
        const bk_block *b = &m->blocks[i];
        const char *key = NULL;
        double energy = 0.0;
        if (!isfinite(energy = 0.5 * b->mass * b->v_init * b->v_init))
            key = "v_init";
        else if (!isfinite(energy = 0.5 * b->driver_stiffness * (driver0 - b->x_init) * (driver0 - b->x_init)))
            key = "x_init";
        if (!key)
            continue;
        char section[SECTION_LEN];
        snprintf(section, sizeof section, "block.%zu", i);
        entry *e = lookup(ld, section, key);
        if (!e)
            e = lookup(ld, "block", key);
        if (!e)
            e = lookup(ld, "driver", "start_position");
        const char *what = strcmp(key, "v_init") == 0 ? "kinetic" : "elastic";
        if (e)
            report_entry(ld, e, "block %zu's initial %s energy overflows a double (%g J; allowed: a "
                         "finite energy)", i, what, energy);
        else
            report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: block %zu's initial %s energy overflows a double",
                   ld->name, i, what);
        return;
    }
    double *x = malloc(m->n_blocks * sizeof *x);
    if (!x) {
        report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return;
    }
    for (size_t i = 0; i < m->n_blocks; ++i)
        x[i] = m->blocks[i].x_init;
    if (!isfinite(bk_model_elastic_energy(m, x, driver0)))
        report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: the chain's initial elastic energy overflows a double "
               "(check x_init, x_init_random and the stiffnesses)", ld->name);
    free(x);
}

/* The chain: model, blocks, friction, driver. */
static void build_chain(loader *ld, bk_config *c)
{
    double n_value = value_of(ld, "model", "n_blocks");
    if (!(n_value >= 1))
        return; /* reported */
    size_t n = (size_t)n_value;
    bk_model *m = bk_model_create(n);
    if (!m) {
        report(ld, 0, BK_ERR_NOMEM, "%s: out of memory for %zu blocks", ld->name, n);
        return;
    }
    c->model = m;
    m->boundary = (bk_boundary)(int)value_of(ld, "model", "boundary");
    m->coupling_stiffness = value_of(ld, "model", "coupling_stiffness");
    m->gravity = value_of(ld, "model", "gravity");
    m->spring = (bk_spring)(int)value_of(ld, "driver", "spring");
    m->driver.velocity = value_of(ld, "driver", "velocity");
    m->driver.start_position = value_of(ld, "driver", "start_position");

    static const char *const required[] = {"mass", "driver_stiffness"};
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng) {
        report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return;
    }
    gsl_rng_set(rng, (unsigned long)value_of(ld, "model", "seed"));
    for (size_t i = 0; i < n; ++i) {
        bk_block *b = &m->blocks[i];
        int given;
        for (size_t r = 0; r < 2; ++r) {
            double value = block_value(ld, i, required[r], &given);
            if (!given)
                report_missing(ld, "block", &find_key("block", required[r])->param, find_key("block", required[r]));
            if (r == 0)
                b->mass = value;
            else
                b->driver_stiffness = value;
        }
        b->normal_force = block_value(ld, i, "normal_force", &given);
        if (!given)
            b->normal_force = b->mass * m->gravity;
        if (!isfinite(b->normal_force) && ld->error_rank == LONG_MAX) {
            report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [block] normal_force: the default mass * gravity of block %zu "
                   "overflows (%g kg * %g m/s^2; allowed: 0 < normal_force < inf N)", ld->name, i, b->mass, m->gravity);
            break;
        }
        b->x_init = block_value(ld, i, "x_init", &given);
        /* Drawn for every block, so a block's value does not depend on its neighbours' keys. */
        b->x_init += block_value(ld, i, "x_init_random", &given) * (2.0 * gsl_rng_uniform(rng) - 1.0);
        b->v_init = block_value(ld, i, "v_init", &given);
        build_friction(ld, b, i, m->driver.velocity);
        if (ld->error_rank != LONG_MAX && ld->error_rank >= RANK_MISSING)
            break; /* one missing key is enough; don't repeat it for every block */
    }
    gsl_rng_free(rng);
    bk_model_finalize(m);
    check_initial_energy(ld, m);
    c->t_end = value_of(ld, "run", "t_end");
}

/* A prescribed-motion scene: the schedule and one block's friction.  The chain's keys are
 * optional here: normal_force defaults to mass * gravity, or 1 N without a mass. */
static void build_prescribed(loader *ld, bk_config *c)
{
    entry *rates = lookup(ld, "prescribed", "slip_rates");
    entry *durations = lookup(ld, "prescribed", "durations");
    entry *distances = lookup(ld, "prescribed", "distances");
    if (!rates) {
        report_missing(ld, "prescribed", &find_key("prescribed", "slip_rates")->param,
                       find_key("prescribed", "slip_rates"));
        return;
    }
    if (!durations == !distances) {
        report_entry(ld, durations ? distances : rates, "give exactly one of durations and distances");
        return;
    }
    entry *lengths = durations ? durations : distances;
    if (!lengths)
        return; /* reported above */
    size_t n = (size_t)rates->number;
    if ((size_t)lengths->number != n) {
        report_entry(ld, lengths, "has %zu values, slip_rates has %zu", (size_t)lengths->number, n);
        return;
    }
    entry *n_blocks = lookup(ld, "model", "n_blocks");
    if (n_blocks && n_blocks->number != 1.0)
        report_entry(ld, n_blocks, "a prescribed scene has one block, got %s", n_blocks->value);
    bk_prescribed *pr = calloc(1, sizeof *pr);
    bk_model *m = bk_model_create(1);
    if (pr) {
        pr->slip_rate = calloc(n, sizeof *pr->slip_rate);
        pr->duration = calloc(n, sizeof *pr->duration);
    }
    c->prescribed = pr;
    c->model = m;
    if (!pr || !pr->slip_rate || !pr->duration || !m) {
        report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return;
    }
    pr->n_segments = n;
    double total = 0.0, first_rate = 0.0;
    for (size_t k = 0; k < n; ++k) {
        double rate = rates->list[k];
        pr->slip_rate[k] = rate;
        if (distances && rate == 0.0) {
            report_entry(ld, distances, "segment %zu is a hold (slip rate 0): give durations", k + 1);
            return;
        }
        pr->duration[k] = durations ? durations->list[k] : distances->list[k] / rate;
        total += pr->duration[k];
        if (!isfinite(total)) {
            report_entry(ld, lengths, "segment %zu makes the schedule longer than any finite time "
                         "(allowed: a finite total duration)", k + 1);
            return;
        }
        if (first_rate == 0.0)
            first_rate = rate;
    }
    m->gravity = value_of(ld, "model", "gravity");
    m->driver.velocity = first_rate;
    bk_block *b = &m->blocks[0];
    int given_mass, given_normal;
    double mass = block_value(ld, 0, "mass", &given_mass);
    b->mass = given_mass ? mass : 1.0;
    b->normal_force = block_value(ld, 0, "normal_force", &given_normal);
    if (!given_normal)
        b->normal_force = given_mass ? b->mass * m->gravity : 1.0;
    build_friction(ld, b, 0, first_rate);
    bk_model_finalize(m);
    entry *t_end = lookup(ld, "run", "t_end");
    c->t_end = total;
    if (t_end && t_end->number <= total * (1 + 1e-12))
        c->t_end = t_end->number;
    else if (t_end)
        report_entry(ld, t_end, "must be <= the schedule's length (%.10g s), got %s", total, t_end->value);
}

/* The method fits the scene and takes the options given: method = exact solves only
 * affine scenes, arkode_table needs a method with tables.  Said here, before any output. */
static void check_method_fits(loader *ld, const bk_config *c)
{
    entry *method = lookup(ld, "solver", "method");
    entry *table = lookup(ld, "solver", "arkode_table");
    if (table && strcmp(table->value, "default") != 0 && ld->error_rank == LONG_MAX) {
        const bk_solver_backend *b = bk_solver_backend_find(c->solver.method);
        char message[768];
        if (!b || !b->check_options)
            report_entry(ld, table, "applies to method arkode_erk or arkode_dirk, not %s", c->solver.method);
        else if (b->check_options(&c->solver, message, sizeof message) != 0)
            report_entry(ld, table, "%s", message);
    }
    if (!method || strcmp(method->value, "exact") != 0 || !c->model || c->prescribed ||
        ld->error_rank != LONG_MAX)
        return;
    size_t i = bk_model_first_non_affine_block(c->model);
    if (i < c->model->n_blocks)
        report_entry(ld, method,
                     "needs Coulomb friction (a constant sliding force, no friction state) on every "
                     "block; block %zu uses law %s (allowed: auto, or an integrator such as gsl_rk8pd "
                     "or cvode_bdf)",
                     i, c->model->blocks[i].law->name);
}

static int has_section(loader *ld, const char *section)
{
    for (size_t i = 0; i < ld->n; ++i)
        if (!ld->entries[i].superseded && strcmp(ld->entries[i].base, section) == 0)
            return 1;
    return 0;
}

/* Everything checked: build the config.  Reports missing and cross-key errors. */
static bk_config *build(loader *ld)
{
    bk_config *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->t_end = NAN; /* unknown until read: no cross-check against it before then */
    if (has_section(ld, "prescribed"))
        build_prescribed(ld, c);
    else
        build_chain(ld, c);

    bk_solver_options *s = &c->solver;
    snprintf(s->method, sizeof s->method, "%s", method_name((size_t)value_of(ld, "solver", "method")));
    snprintf(s->linear_solver, sizeof s->linear_solver, "%s",
             linear_solver_names[(size_t)value_of(ld, "solver", "linear_solver")]);
    s->rtol = value_of(ld, "solver", "rtol");
    s->atol_x = value_of(ld, "solver", "atol_x");
    s->atol_v = value_of(ld, "solver", "atol_v");
    s->max_step = value_of(ld, "solver", "max_step");
    s->max_steps = (long)value_of(ld, "solver", "max_steps");
    s->detect_velocity_extrema = (int)value_of(ld, "solver", "detect_velocity_extrema");
    s->max_transitions_per_instant = (long)value_of(ld, "solver", "max_transitions_per_instant");
    s->instant_window = value_of(ld, "solver", "instant_window");
    s->min_step = value_of(ld, "solver", "min_step");
    snprintf(s->arkode_table, sizeof s->arkode_table, "%s",
             bk_solver_arkode_table((size_t)value_of(ld, "solver", "arkode_table")));
    check_method_fits(ld, c);
    c->wall_time_limit = value_of(ld, "run", "wall_time_limit");

    bk_output_options *o = &c->output;
    entry *path = lookup(ld, "output", "path");
    o->path = path ? strdup(path->value) : default_output_path(ld->name);
    if (!o->path)
        report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
    entry *interval = lookup(ld, "output", "interval");
    o->interval = interval ? interval->number : c->t_end / 1000.0;
    if (interval && isfinite(c->t_end) && interval->number > c->t_end)
        report_entry(ld, interval, "must be <= t_end (%g s), got %s", c->t_end, interval->value);
    o->fields = (unsigned)value_of(ld, "output", "fields");
    if (c->prescribed)
        o->fields &= ~(unsigned)BK_FIELD_ENERGY; /* no dynamics, no energies */
    o->transitions = (int)value_of(ld, "output", "transitions");
    o->event_rows = (int)value_of(ld, "output", "event_rows");
    o->checkpoint_interval = value_of(ld, "output", "checkpoint_interval");
    entry *checkpoints = lookup(ld, "output", "checkpoint_interval");
    if (c->prescribed && checkpoints && o->checkpoint_interval > 0.0)
        report_entry(ld, checkpoints, "a prescribed scene has no dynamics to checkpoint (allowed: 0)");
    o->max_rows = (long)value_of(ld, "output", "max_rows");
    double samples = o->interval > 0.0 ? c->t_end / o->interval : 0.0;
    if (samples > (double)o->max_rows) {
        if (interval)
            report_entry(ld, interval, "gives %.3g rows over t_end = %g s, more than [output] max_rows = %ld "
                         "(allowed: >= %g s, or raise max_rows)", samples, c->t_end, o->max_rows,
                         c->t_end / (double)o->max_rows);
        else
            report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [output] interval: the default t_end / 1000 gives "
                   "more than [output] max_rows = %ld rows", ld->name, o->max_rows);
    }
    o->max_bytes = value_of(ld, "output", "max_bytes");
    if (c->model && ld->error_rank == LONG_MAX) {
        double per_row = bk_output_row_bytes(o->fields, c->model->n_blocks, c->model->n_friction_state);
        double bytes = (samples + 1.0) * per_row;
        if (bytes > o->max_bytes) {
            entry *at = interval ? interval : lookup(ld, "output", "max_bytes");
            if (!at)
                at = lookup(ld, "model", "n_blocks");
            char where[512];
            if (at)
                location(ld, at, where, sizeof where);
            else
                snprintf(where, sizeof where, "%s", ld->name);
            report(ld, at ? at->rank : RANK_MISSING, BK_ERR_CONFIG,
                   "%s: [output] max_bytes: the sample rows would take about %.3g bytes (%.3g rows of %.3g "
                   "bytes for %zu blocks), more than max_bytes = %.3g (allowed: a longer interval, fewer "
                   "fields, or raise max_bytes)",
                   where, bytes, samples + 1.0, per_row, c->model->n_blocks, o->max_bytes);
        }
    }
    return c;
}

/* --- public ----------------------------------------------------------------------------- */

void bk_config_free(bk_config *config)
{
    if (!config)
        return;
    bk_model_free(config->model);
    if (config->prescribed) {
        free(config->prescribed->slip_rate);
        free(config->prescribed->duration);
        free(config->prescribed);
    }
    free(config->output.path);
    free(config->source_name);
    free(config->text);
    free(config->file_text);
    for (size_t k = 0; k < config->n_overrides; ++k)
        free(config->overrides[k]);
    free(config->overrides);
    free(config);
}

static void free_loader(loader *ld)
{
    for (size_t i = 0; i < ld->n; ++i) {
        free(ld->entries[i].value);
        free(ld->entries[i].list);
    }
    free(ld->entries);
    free(ld->slots);
}

/* Strip surrounding whitespace in place. */
static void trim(char *s)
{
    size_t len = strlen(s), start = 0;
    while (len > 0 && isspace((unsigned char)s[len - 1]))
        s[--len] = '\0';
    while (isspace((unsigned char)s[start]))
        ++start;
    memmove(s, s + start, len - start + 1);
}

/* Append "section.key=value" overrides; malformed ones are reported. */
static void add_overrides(loader *ld, const char *const *overrides, size_t n_overrides)
{
    for (size_t k = 0; k < n_overrides; ++k) {
        const char *text = overrides[k];
        long rank = (long)INT_MAX + (long)k;
        const char *eq = strchr(text, '=');
        const char *dot = eq ? text : NULL;
        for (const char *p = text; eq && p < eq; ++p)
            if (*p == '.')
                dot = p;
        if (!eq || dot == text || dot + 1 >= eq || (size_t)(dot - text) >= SECTION_LEN ||
            (size_t)(eq - dot - 1) >= KEY_LEN) {
            report(ld, rank, BK_ERR_CONFIG,
                   "--set %s: expected section.key=value (e.g. block.mass=2 or block.3.mass=2)", text);
            continue;
        }
        char section[SECTION_LEN], key[KEY_LEN];
        snprintf(section, sizeof section, "%.*s", (int)(dot - text), text);
        snprintf(key, sizeof key, "%.*s", (int)(eq - dot - 1), dot + 1);
        trim(section);
        trim(key);
        const char *value = eq + 1;
        while (isspace((unsigned char)*value))
            ++value;
        for (size_t i = 0; i < ld->n; ++i)
            if (strcmp(ld->entries[i].section, section) == 0 && strcmp(ld->entries[i].key, key) == 0)
                ld->entries[i].superseded = 1;
        if (add_entry(ld, section, key, value, 0, text, rank) != 0)
            ld->oom = 1;
    }
}

static char *config_text(const char *text, const char *const *overrides, size_t n_overrides)
{
    size_t len = strlen(text) + 2;
    for (size_t k = 0; k < n_overrides; ++k)
        len += strlen(overrides[k]) + 10;
    char *out = malloc(len);
    if (!out)
        return NULL;
    size_t used = (size_t)snprintf(out, len, "%s", text);
    if (used > 0 && out[used - 1] != '\n' && n_overrides)
        used += (size_t)snprintf(out + used, len - used, "\n");
    for (size_t k = 0; k < n_overrides; ++k)
        used += (size_t)snprintf(out + used, len - used, "; --set %s\n", overrides[k]);
    return out;
}

int bk_config_load_string(const char *text, const char *name, const char *const *overrides,
                          size_t n_overrides, bk_config **out, bk_error *err)
{
    *out = NULL;
    loader ld = {.name = name, .error_rank = LONG_MAX, .err = err, .status = BK_OK, .cursor = text};
    int first_bad = ini_parse_stream(read_line, &ld, on_pair, &ld);
    if (first_bad > 0)
        report(&ld, first_bad, BK_ERR_CONFIG,
               "%s:%d: syntax error: expected \"[section]\", \"key = value\" or a comment", name, first_bad);
    add_overrides(&ld, overrides, n_overrides);
    if (ld.oom || first_bad < 0 || build_index(&ld) != 0) {
        free_loader(&ld);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory while parsing", name);
    }
    /* n_blocks first: block indices are checked against it. */
    entry *n_entry = lookup(&ld, "model", "n_blocks");
    long n_blocks = 0;
    if (n_entry && check_value(&ld, n_entry, find_key("model", "n_blocks"), &find_key("model", "n_blocks")->param) == 0)
        n_blocks = (long)n_entry->number;
    check_entries(&ld, n_blocks);
    bk_config *c = NULL;
    if (ld.error_rank == LONG_MAX)
        c = build(&ld);
    if (c && ld.error_rank == LONG_MAX) {
        c->source_name = strdup(name);
        c->text = config_text(text, overrides, n_overrides);
        c->file_text = strdup(text);
        c->overrides = calloc(n_overrides ? n_overrides : 1, sizeof *c->overrides);
        int ok = c->source_name && c->text && c->file_text && c->overrides;
        for (size_t k = 0; ok && k < n_overrides; ++k, ++c->n_overrides)
            ok = (c->overrides[k] = strdup(overrides[k])) != NULL;
        if (!ok)
            report(&ld, 0, BK_ERR_NOMEM, "%s: out of memory", name);
    } else if (!c && ld.error_rank == LONG_MAX) {
        report(&ld, 0, BK_ERR_NOMEM, "%s: out of memory", name);
    }
    free_loader(&ld);
    if (ld.error_rank != LONG_MAX) {
        bk_config_free(c);
        return ld.status;
    }
    *out = c;
    return BK_OK;
}

int bk_config_load_file(const char *path, const char *const *overrides, size_t n_overrides,
                        bk_config **out, bk_error *err)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char *text = malloc(MAX_FILE_BYTES + 1);
    if (!text) {
        fclose(f);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    }
    size_t len = fread(text, 1, MAX_FILE_BYTES + 1, f);
    int read_error = ferror(f);
    fclose(f);
    int rc;
    if (read_error)
        rc = BK_FAIL(err, BK_ERR_IO, "%s: read error", path);
    else if (len > MAX_FILE_BYTES)
        rc = BK_FAIL(err, BK_ERR_CONFIG, "%s: larger than %d bytes; not a config file?", path, MAX_FILE_BYTES);
    else if (memchr(text, '\0', len))
        rc = BK_FAIL(err, BK_ERR_CONFIG, "%s: contains NUL bytes; not a text file", path);
    else {
        text[len] = '\0';
        rc = bk_config_load_string(text, path, overrides, n_overrides, out, err);
    }
    free(text);
    return rc;
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
    format_allowed(def, param, allowed, sizeof allowed);
    const char *unit = param->unit && param->unit[0] ? param->unit : "-";
    fprintf(out, "| `%s` | %s | ", param->key, unit);
    write_default(out, def, param);
    fprintf(out, " | %s | %s |\n", allowed, param->doc);
}

void bk_config_write_reference(FILE *out)
{
    static const char *const notes[] = {
        "model", "The chain.",
        "block", "Defaults for every block; a `[block.I]` section (I = 0 .. n_blocks-1) overrides them for block I.",
        "friction", "The friction law of every block and its parameters (tables below); `[friction.I]` overrides "
                    "them for block I. A `[friction.I]` naming a different law takes none of `[friction]`'s parameters.",
        "driver", "The driver that pulls every block through its driver spring.",
        "solver", "Integration.",
        "output", "The HDF5 file.",
        "run", "The time span.",
        "prescribed", "A prescribed-motion scene instead of the chain's dynamics (paper Figure 2, slide-hold-slide): "
                      "one block slides at a piecewise-constant slip rate and its friction state follows the law's "
                      "exact evolution. The presence of this section selects it; `[model]`, `[block]` and `[driver]` "
                      "keys are then optional (normal_force defaults to mass * gravity, or 1 N without a mass).",
    };
    fprintf(out, "Units are SI. Keys are case-sensitive; `;` starts a comment (also after a value).\n");
    for (size_t s = 0; sections[s]; ++s) {
        fprintf(out, "\n### [%s]\n\n%s\n\n", sections[s], notes[2 * s + 1]);
        fprintf(out, "| key | unit | default | allowed | meaning |\n| --- | --- | --- | --- | --- |\n");
        for (size_t i = 0; i < N_KEYS; ++i)
            if (strcmp(keys[i].section, sections[s]) == 0)
                write_row(out, &keys[i], &keys[i].param);
    }
    for (const bk_friction_law *const *law = bk_friction_laws(); *law; ++law) {
        fprintf(out, "\n### [friction] law = %s\n\n%s\n\n", (*law)->name, (*law)->doc);
        fprintf(out, "| key | unit | default | allowed | meaning |\n| --- | --- | --- | --- | --- |\n");
        for (size_t p = 0; p < (*law)->n_params; ++p)
            write_row(out, NULL, &(*law)->params[p]);
    }
}
