/* `bksim info`: a file's parameters, stick and slip phases per block, solver statistics and
 * the verdict of the integrity check (h5_verify.c). */
#include "bksim/inspect.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "output/h5_impl.h"
#include "paths.h"

/* Unit of key in a "key: unit, key: unit" list; "" when not listed. */
static void unit_of(const char *units, const char *key, char *buf, size_t len)
{
    buf[0] = '\0';
    if (!units)
        return;
    size_t key_len = strlen(key);
    for (const char *p = units; *p;) {
        while (*p == ' ' || *p == ',')
            ++p;
        const char *end = strchr(p, ',');
        if (!end)
            end = p + strlen(p);
        if ((size_t)(end - p) > key_len + 1 && strncmp(p, key, key_len) == 0 &&
            p[key_len] == ':') {
            const char *u = p + key_len + 1;
            while (*u == ' ')
                ++u;
            snprintf(buf, len, "%.*s", (int)(end - u), u);
            return;
        }
        p = end;
    }
}

typedef struct stats_print {
    FILE *out;
    char *units;
} stats_print;

static herr_t print_stat(hid_t group, const char *name, const H5A_info_t *info, void *data)
{
    const stats_print *ctx = data;
    (void)info;
    if (strcmp(name, "units") == 0 || strcmp(name, "description") == 0)
        return 0;
    hid_t attr = H5Aopen(group, name, H5P_DEFAULT);
    hid_t type = attr >= 0 ? H5Aget_type(attr) : H5I_INVALID_HID;
    H5T_class_t cls = type >= 0 ? H5Tget_class(type) : H5T_NO_CLASS;
    CLOSE_IDS(0, type, attr);
    /* Counts carry unit "1"; printing it after every count would only be noise. */
    char unit[64];
    unit_of(ctx->units, name, unit, sizeof unit);
    if (strcmp(unit, "1") == 0)
        unit[0] = '\0';
    const char *sep = unit[0] ? " " : "";
    if (cls == H5T_STRING) {
        char *text = bk_h5_read_string_attr(group, name);
        fprintf(ctx->out, "    %-18s %s\n", name, text ? text : "?");
        free(text);
    } else if (cls == H5T_INTEGER) {
        long long value = 0;
        if (bk_h5_read_numeric_attr(group, name, H5T_NATIVE_LLONG, &value) >= 0)
            fprintf(ctx->out, "    %-18s %lld%s%s\n", name, value, sep, unit);
    } else if (cls == H5T_FLOAT) {
        double value = 0;
        if (bk_h5_read_numeric_attr(group, name, H5T_NATIVE_DOUBLE, &value) >= 0)
            fprintf(ctx->out, "    %-18s %.9g%s%s\n", name, value, sep, unit);
    }
    return 0;
}

static void print_stats(hid_t file, FILE *out)
{
    if (H5Lexists(file, "stats", H5P_DEFAULT) <= 0) {
        fprintf(out, "stats: none recorded\n");
        return;
    }
    hid_t group = H5Gopen2(file, "stats", H5P_DEFAULT);
    if (group < 0) {
        fprintf(out, "stats: unreadable\n");
        return;
    }
    stats_print ctx = {out, bk_h5_read_string_attr(group, "units")};
    fprintf(out, "stats:\n");
    hsize_t idx = 0;
    if (H5Aiterate2(group, H5_INDEX_CRT_ORDER, H5_ITER_INC, &idx, print_stat, &ctx) < 0 &&
        idx == 0) {
        /* Files whose /stats does not track creation order: alphabetical. */
        idx = 0;
        H5Aiterate2(group, H5_INDEX_NAME, H5_ITER_INC, &idx, print_stat, &ctx);
    }
    free(ctx.units);
    bk_h5_close_id(group);
}

static void print_indented(FILE *out, const char *text)
{
    const char *p = text;
    while (*p) {
        const char *end = strchr(p, '\n');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        fprintf(out, "    %.*s\n", (int)len, p);
        p += len + (end ? 1 : 0);
    }
}

typedef struct phase_counts {
    const char *path;
    size_t n_blocks;
    long *stick, *slip;
} phase_counts;

static int count_phase(const bk_transition *t, unsigned long long row, void *user, bk_error *err)
{
    const phase_counts *c = user;
    if (t->block < 0 || (size_t)t->block >= c->n_blocks)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /transitions row %llu names block %d, outside 0..%zu",
                       c->path, row, (int)t->block, c->n_blocks - 1);
    ++*(t->to == 0 ? &c->stick[t->block] : &c->slip[t->block]);
    return BK_OK;
}

/* Stick and slip phases per block: each transition starts a phase of its `to` mode, and
 * row 0 of /mode starts the first one. */
static int count_phases(hid_t file, const char *path, size_t n_blocks, long *stick, long *slip,
                        long *total, int *have_transitions, bk_error *err)
{
    hid_t dset;
    hsize_t rows, cols;
    int rank;
    *total = 0;
    *have_transitions = 0;
    if (H5Lexists(file, "mode", H5P_DEFAULT) > 0 &&
        bk_h5_open_series(file, path, "mode", &dset, &rows, &cols, &rank, NULL) == BK_OK) {
        if (rows > 0 && rank == 2 && cols == n_blocks) {
            int8_t *first = malloc(n_blocks);
            if (first && bk_h5_read_block(dset, 2, 0, 1, 0, cols, H5T_NATIVE_INT8, first) >= 0)
                for (size_t i = 0; i < n_blocks; ++i)
                    ++*(first[i] == 0 ? &stick[i] : &slip[i]);
            free(first);
        }
        bk_h5_close_id(dset);
    }
    if (H5Lexists(file, "transitions", H5P_DEFAULT) <= 0)
        return BK_OK;
    *have_transitions = 1;
    phase_counts counts = {path, n_blocks, stick, slip};
    hsize_t count = 0;
    int rc = bk_h5_each_transition(file, path, count_phase, &counts, &count, err);
    *total = (long)count;
    return rc;
}

static int by_value(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

/* A long chain's phases in a few lines: totals, the spread of slips per block, the most
 * active blocks.  -1 when out of memory. */
static int print_phase_summary(FILE *out, const char *path, size_t n, const long *stick,
                               const long *slip)
{
    long *sorted = malloc(n * sizeof *sorted);
    if (!sorted)
        return -1;
    long stick_total = 0, slip_total = 0;
    size_t never = 0;
    for (size_t i = 0; i < n; ++i) {
        stick_total += stick[i];
        slip_total += slip[i];
        never += slip[i] == 0;
        sorted[i] = slip[i];
    }
    qsort(sorted, n, sizeof *sorted, by_value);
    fprintf(out, "phases per block: %zu blocks, %ld stick and %ld slip phases in all\n", n, stick_total,
            slip_total);
    fprintf(out, "    slips per block: min %ld, lower quartile %ld, median %ld, upper quartile %ld, "
                 "max %ld; %zu block%s never slipped\n",
            sorted[0], sorted[n / 4], sorted[n / 2], sorted[3 * n / 4], sorted[n - 1], never,
            never == 1 ? "" : "s");
    free(sorted);
    /* The five most active, by slips (the lower index first on a tie): one pass, each block
     * inserted into the sorted top five. */
    size_t top[5];
    size_t n_top = 0;
    for (size_t i = 0; i < n; ++i) {
        size_t at = n_top;
        while (at > 0 && slip[i] > slip[top[at - 1]])
            --at;
        if (at == 5)
            continue;
        if (n_top < 5)
            ++n_top;
        memmove(&top[at + 1], &top[at], (n_top - 1 - at) * sizeof *top);
        top[at] = i;
    }
    fprintf(out, "    most active:");
    for (size_t k = 0; k < n_top; ++k)
        fprintf(out, "%s block %zu (%ld slips)", k ? "," : "", top[k], slip[top[k]]);
    fprintf(out, "\n    (one line per block: bksim info %s --blocks)\n", path);
    return 0;
}

/* Rows of a dataset as the file last flushed it; 0 when it cannot be read. */
static unsigned long long flushed_rows(hid_t file, const char *name)
{
    hsize_t dims[2] = {0, 0};
    hid_t dset = H5Lexists(file, name, H5P_DEFAULT) > 0 ? H5Dopen2(file, name, H5P_DEFAULT)
                                                          : H5I_INVALID_HID;
    hid_t space = dset >= 0 ? H5Dget_space(dset) : H5I_INVALID_HID;
    if (space < 0 || H5Sget_simple_extent_dims(space, dims, NULL) < 0)
        dims[0] = 0;
    CLOSE_IDS(0, space, dset);
    return (unsigned long long)dims[0];
}

/* The time of the newest checkpoint slot of file (by its sequence); NaN when none. */
static double newest_checkpoint(hid_t file)
{
    static const char *const slots[] = {"checkpoint/a", "checkpoint/b"};
    double t_newest = NAN, newest = -1.0;
    if (H5Lexists(file, "checkpoint", H5P_DEFAULT) <= 0)
        return NAN;
    for (int k = 0; k < 2; ++k) {
        if (H5Lexists(file, slots[k], H5P_DEFAULT) <= 0)
            continue;
        hid_t slot = H5Gopen2(file, slots[k], H5P_DEFAULT);
        double sequence = NAN, t = NAN;
        if (slot >= 0 && bk_h5_read_numeric_attr(slot, "sequence", H5T_NATIVE_DOUBLE, &sequence) >= 0 &&
            bk_h5_read_numeric_attr(slot, "t", H5T_NATIVE_DOUBLE, &t) >= 0 && sequence > newest) {
            newest = sequence;
            t_newest = t;
        }
        CLOSE_IDS(0, slot);
    }
    return t_newest;
}

/* A file a run is writing now: what it last committed (about once a second), read without
 * taking the lock the writer holds.  No integrity check: the file is not finished. */
static int info_in_progress(const char *path, FILE *out, bk_error *err)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    hid_t file = fapl >= 0 && H5Pset_file_locking(fapl, 0, 1) >= 0
                     ? H5Fopen(path, H5F_ACC_RDONLY, fapl)
                     : H5I_INVALID_HID;
    CLOSE_IDS(0, fapl);
    fprintf(out, "file         %s\n", path);
    if (file < 0) {
        fprintf(out, "status       in progress: a run is writing this file (it holds its lock); "
                     "nothing it has flushed can be read yet\n");
        return BK_INCOMPLETE;
    }
    char *name = bk_h5_read_string_attr(file, "config_name");
    double t_end = NAN, t_reached = NAN;
    bk_h5_read_numeric_attr(file, "t_end", H5T_NATIVE_DOUBLE, &t_end);
    bk_h5_read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &t_reached);
    unsigned long long transitions = flushed_rows(file, "transitions");
    unsigned long long events = flushed_rows(file, "events");
    unsigned long long rows = flushed_rows(file, "time");
    /* Rows may be sparse (interval = 0): the last checkpoint can be later than the last row. */
    double t_checkpoint = newest_checkpoint(file);
    if (t_checkpoint > t_reached)
        t_reached = t_checkpoint;
    if (H5Lexists(file, "transitions", H5P_DEFAULT) > 0)
        fprintf(out, "status       in progress, t = %.9g s of %.9g s, %llu transitions so far\n",
                t_reached, t_end, transitions);
    else
        fprintf(out, "status       in progress, t = %.9g s of %.9g s (transitions not recorded)\n",
                t_reached, t_end);
    fprintf(out, "             (a run is writing this file: this is what it last committed; it "
                 "commits about once a second and at each checkpoint)\n");
    fprintf(out, "config name  %s\n", name ? name : "?");
    if (isfinite(t_checkpoint))
        fprintf(out, "checkpoint   t = %.17g s (if the run stops, `bksim run --restart %s` "
                     "continues from it)\n", t_checkpoint, path);
    else
        fprintf(out, "checkpoint   none yet\n");
    fprintf(out, "rows         %llu so far\n", rows);
    if (H5Lexists(file, "ruptures", H5P_DEFAULT) > 0)
        fprintf(out, "ruptures     %llu so far\n", flushed_rows(file, "ruptures"));
    if (H5Lexists(file, "events", H5P_DEFAULT) > 0)
        fprintf(out, "events       %llu so far\n", events);
    free(name);
    bk_h5_close_id(file);
    if (ferror(out))
        return BK_FAIL(err, BK_ERR_IO, "cannot write the summary");
    return BK_INCOMPLETE;
}

int bk_h5_info(const char *path, FILE *out, bk_error *err)
{
    return bk_h5_info_blocks(path, out, 0, err);
}

int bk_h5_info_blocks(const char *path, FILE *out, int per_block, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (path && bk_output_write_locked(path))
        return info_in_progress(path, out, err);
    hid_t file;
    int rc = bk_h5_open_input(path, &file, err);
    if (rc != BK_OK)
        return rc;
    long long n_blocks = 0;
    rc = bk_h5_read_n_blocks(file, path, &n_blocks, err);
    long *stick = NULL, *slip = NULL;
    long total = 0;
    int have_transitions = 0;
    if (rc == BK_OK) {
        stick = calloc((size_t)n_blocks, sizeof *stick);
        slip = calloc((size_t)n_blocks, sizeof *slip);
        if (!stick || !slip)
            rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    }
    /* Phases that cannot be counted (a damaged /transitions) still leave a summary; the
     * integrity check below names the damage. */
    bk_error phase_err = {0};
    int phases = rc == BK_OK ? count_phases(file, path, (size_t)n_blocks, stick, slip, &total,
                                            &have_transitions, &phase_err)
                             : rc;
    if (phases == BK_ERR_NOMEM) {
        rc = phases;
        if (err)
            *err = phase_err;
    }
    if (rc != BK_OK) {
        free(stick);
        free(slip);
        bk_h5_close_id(file);
        return rc;
    }

    char *name = bk_h5_read_string_attr(file, "config_name");
    char *version = bk_h5_read_string_attr(file, "version");
    char *config = bk_h5_read_string_attr(file, "config");
    char *error = bk_h5_read_string_attr(file, "error");
    char *host = bk_h5_read_string_attr(file, "host");
    char *point = bk_h5_read_string_attr(file, "point");
    char *init_from = bk_h5_read_string_attr(file, "init_from");
    long long seed = -1;
    int have_seed = H5Aexists(file, "seed") > 0 &&
                    bk_h5_read_numeric_attr(file, "seed", H5T_NATIVE_LLONG, &seed) >= 0;
    int complete = 0;
    double t_end = NAN, t_reached = NAN;
    int have_complete = bk_h5_read_numeric_attr(file, "complete", H5T_NATIVE_INT, &complete) >= 0;
    bk_h5_read_numeric_attr(file, "t_end", H5T_NATIVE_DOUBLE, &t_end);
    bk_h5_read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &t_reached);
    hsize_t rows = 0, cols;
    int rank;
    hid_t time;
    int have_rows = H5Lexists(file, "time", H5P_DEFAULT) > 0 &&
                    bk_h5_open_series(file, path, "time", &time, &rows, &cols, &rank, NULL) == BK_OK;
    if (have_rows)
        bk_h5_close_id(time);

    fprintf(out, "file         %s\n", path);
    fprintf(out, "config name  %s\n", name ? name : "?");
    fprintf(out, "version      %s\n", version ? version : "?");
    if (host)
        fprintf(out, "host         %s\n", host);
    if (have_seed)
        fprintf(out, "seed         %lld\n", seed);
    if (point)
        fprintf(out, "point        %s\n", point);
    if (init_from)
        fprintf(out, "started from %s\n", init_from);
    if (have_complete)
        fprintf(out, "complete     %d%s\n", complete, complete ? "" : " (run did not finish)");
    else
        fprintf(out, "complete     ?\n");
    if (error)
        fprintf(out, "error        %s\n", error);
    if (have_complete && !complete) {
        /* The checkpoint a restart would use: the newest slot that verifies. */
        bk_h5_slot slot;
        bk_error why = {0};
        if (n_blocks > 0 && bk_h5_find_checkpoint(file, path, (size_t)n_blocks, &slot, &why) == BK_OK) {
            fprintf(out, "checkpoint   t = %.17g s: `bksim run --restart %s` continues from it\n",
                    slot.checkpoint.t, path);
            bk_checkpoint_free(&slot.checkpoint);
        } else {
            fprintf(out, "checkpoint   none: this run cannot be continued, only run again\n");
        }
    }
    fprintf(out, "t_end        %.9g s\n", t_end);
    fprintf(out, "t_reached    %.9g s\n", t_reached);
    fprintf(out, "n_blocks     %lld\n", n_blocks);
    /* Files from before lattices have no shape: a chain. */
    long long lattice_rows = 1, lattice_cols = n_blocks;
    if (bk_h5_read_numeric_attr(file, "rows", H5T_NATIVE_LLONG, &lattice_rows) >= 0 &&
        bk_h5_read_numeric_attr(file, "cols", H5T_NATIVE_LLONG, &lattice_cols) >= 0 && lattice_rows > 1)
        fprintf(out, "lattice      %lld x %lld blocks (block i at lattice row i / %lld, column i %% %lld)\n",
                lattice_rows, lattice_cols, lattice_cols, lattice_cols);
    if (have_rows)
        fprintf(out, "rows         %llu\n", (unsigned long long)rows);
    else
        fprintf(out, "rows         ? (no /time)\n");
    fprintf(out, "config:\n");
    print_indented(out, config ? config : "(not stored)");
    if (phases != BK_OK) {
        fprintf(out, "phases per block: not counted (%s)\n", phase_err.message);
    } else if (per_block || n_blocks <= BK_INFO_TABLE_BLOCKS) {
        fprintf(out, "phases per block:\n");
        for (long long i = 0; i < n_blocks; ++i)
            fprintf(out, "    block %lld: %ld stick, %ld slip\n", i, stick[i], slip[i]);
    } else if (print_phase_summary(out, path, (size_t)n_blocks, stick, slip) != 0) {
        fprintf(out, "phases per block: not summarised (out of memory; --blocks lists them)\n");
    }
    if (phases != BK_OK && have_transitions)
        fprintf(out, "transitions  %ld (not all readable)\n", total);
    else if (have_transitions)
        fprintf(out, "transitions  %ld\n", total);
    else
        fprintf(out, "transitions  not recorded\n");
    hid_t events, event_type;
    hsize_t n_events = 0;
    int have_events = bk_h5_open_events(file, path, &events, &event_type, &n_events, NULL) == BK_OK;
    CLOSE_IDS(0, event_type, events);
    if (H5Lexists(file, "ruptures", H5P_DEFAULT) > 0) {
        unsigned long long n_ruptures = flushed_rows(file, "ruptures");
        fprintf(out, "ruptures     %llu (the rupture catalog: bksim stats %s; bksim export %s --table ruptures)\n",
                n_ruptures, path, path);
    } else {
        fprintf(out, "ruptures     not recorded\n");
    }
    if (have_events)
        fprintf(out, "events       %llu (time windows: bksim stats %s --table events)\n", (unsigned long long)n_events,
                path);
    else
        fprintf(out, "events       not recorded\n");
    print_stats(file, out);
    bk_error check = {0};
    int integrity = bk_h5_verify_open(file, path, &check);
    if (integrity == BK_OK)
        fprintf(out, "integrity    ok\n");
    else if (integrity == BK_INCOMPLETE)
        fprintf(out, "integrity    intact, but the run did not finish (complete = 0)\n");
    else
        fprintf(out, "integrity    DAMAGED: %s\n", check.message);

    free(name);
    free(version);
    free(config);
    free(error);
    free(host);
    free(point);
    free(init_from);
    free(stick);
    free(slip);
    bk_h5_close_id(file);
    if (ferror(out))
        return BK_FAIL(err, BK_ERR_IO, "%s: writing the summary failed", path);
    if (integrity < 0 && err)
        *err = check;
    return integrity;
}
