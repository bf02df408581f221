/* INI -> validated bk_config: the public entry points.  A load collects every entry of the
 * file and of the --set overrides and checks each on its own (config_parse.c); only when all
 * are valid does it build the config, with the checks across keys (config_build.c).  Both
 * work from one table of keys (config_keys.c, which also writes the reference).  The error
 * reported is the earliest in file order (then --set order), so a user fixes errors top to
 * bottom. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <ini.h>

#include "config_loader.h"
#include "layout.h"

#define MAX_FILE_BYTES (1 << 20)

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
    bk_config_free_parameters(config->parameters, config->n_parameters);
    free(config);
}

static void free_loader(loader *ld)
{
    for (size_t i = 0; i < ld->n; ++i) {
        free(ld->entries[i].value);
        free(ld->entries[i].list);
        bk_config_free_draws(&ld->entries[i]);
    }
    free(ld->entries);
    free(ld->slots);
    bk_config_free_parameters(ld->parameters, ld->n_parameters);
    bk_config_free_reader(ld);
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
            bk_config_report(ld, rank, BK_ERR_CONFIG,
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
        if (bk_config_add_entry(ld, section, key, value, 0, text, rank) != 0)
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
    int first_bad = ini_parse_stream(bk_config_read_line, &ld, bk_config_on_pair, &ld);
    if (first_bad > 0)
        bk_config_report(&ld, bk_config_reader_line(&ld, first_bad), BK_ERR_CONFIG,
                         "%s:%d: syntax error: expected \"[section]\", \"key = value\" or a comment", name,
                         bk_config_reader_line(&ld, first_bad));
    add_overrides(&ld, overrides, n_overrides);
    if (ld.oom || first_bad < 0 || bk_config_build_index(&ld) != 0) {
        free_loader(&ld);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory while parsing", name);
    }
    /* The number of blocks first: block indices are checked against it (n_blocks, else
     * rows * cols; 0 when neither is known, and the build reports why). */
    long shape[3] = {0, 0, 0};
    static const char *const shape_keys[] = {"n_blocks", "rows", "cols"};
    for (size_t k = 0; k < 3; ++k) {
        entry *e = bk_config_lookup(&ld, "model", shape_keys[k]);
        const key_def *def = bk_config_find_key("model", shape_keys[k]);
        if (e && bk_config_check_value(&ld, e, def, &def->param) == 0)
            shape[k] = (long)e->number;
    }
    long n_blocks = shape[0] ? shape[0] : shape[1] * shape[2];
    bk_config_check_entries(&ld, n_blocks);
    bk_config *c = NULL;
    if (ld.error_rank == LONG_MAX)
        c = bk_config_build(&ld);
    if (c && ld.error_rank == LONG_MAX) {
        c->source_name = strdup(name);
        c->text = config_text(text, overrides, n_overrides);
        c->file_text = strdup(text);
        c->overrides = calloc(n_overrides ? n_overrides : 1, sizeof *c->overrides);
        int ok = c->source_name && c->text && c->file_text && c->overrides;
        for (size_t k = 0; ok && k < n_overrides; ++k, ++c->n_overrides)
            ok = (c->overrides[k] = strdup(overrides[k])) != NULL;
        if (!ok)
            bk_config_report(&ld, 0, BK_ERR_NOMEM, "%s: out of memory", name);
    } else if (!c && ld.error_rank == LONG_MAX) {
        bk_config_report(&ld, 0, BK_ERR_NOMEM, "%s: out of memory", name);
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
    struct stat st; /* a pipe (bksim run <(generate)) is read as any file */
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return BK_FAIL(err, BK_ERR_CONFIG, "%s: is a directory (allowed: a config file)", path);
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

void bk_config_output_estimate(const bk_config *config, double *rows, double *row_bytes, double *per_second,
                               double *transition_bytes)
{
    *transition_bytes = config->output.transitions ? BK_TRANSITION_RECORD_BYTES : 0.0;
    const bk_model *m = config->model;
    double interval = config->output.interval;
    *row_bytes = m ? bk_output_row_bytes(config->output.fields, m->n_blocks, m->n_friction_state,
                                         bk_model_is_damped(m))
                   : 0.0;
    *rows = interval > 0.0 ? floor(config->t_end / interval) + 2.0 : 2.0;
    *per_second = interval > 0.0 ? *row_bytes / interval : 0.0;
}
