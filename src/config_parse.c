/* From text to checked entries: every "key = value" of the file and of the --set overrides
 * is collected first, then indexed, then each is checked on its own (section, key, value,
 * duplicates).  Errors carry their file:line (or --set) location and are ranked so that the
 * one reported is the earliest in file order, then --set order: a user fixes errors top to
 * bottom.
 *
 * Parsing goes through inih with our own line reader, which counts lines (Debian's inih
 * gives the handler none), strips leading whitespace (an indented line would otherwise be
 * glued to the previous value as a continuation), joins lines ending in a backslash, and
 * holds aside values longer than inih's 200-character buffer (inih would silently cut them):
 * a driver history of hundreds of segments is one key. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "capacity.h"
#include "config_loader.h"
#include "layout.h"

/* --- collected entries ------------------------------------------------------------------ */

/* Where a section was opened: its header line, or the entry's own location. */
static void section_location(const loader *ld, const entry *e, char *buf, size_t len)
{
    if (e->override || !e->section_line)
        bk_config_location(ld, e, buf, len);
    else
        snprintf(buf, len, "%s:%d", ld->name, e->section_line);
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

int bk_config_add_entry(loader *ld, const char *section, const char *key, const char *value, int line,
                        const char *override, long rank)
{
    entry *entries = bk_grow_array(ld->entries, &ld->cap, ld->n + 1, sizeof *entries, 32);
    if (!entries)
        return -1;
    ld->entries = entries;
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

/* Append len bytes to the logical line; -1 when out of memory. */
static int logical_append(loader *ld, size_t *used, const char *text, size_t len)
{
    char *grown = bk_grow_array(ld->logical, &ld->logical_cap, *used + len + 1, 1, 256);
    if (!grown)
        return -1;
    ld->logical = grown;
    memcpy(ld->logical + *used, text, len);
    *used += len;
    ld->logical[*used] = '\0';
    return 0;
}

/* The next physical line (LF, CRLF or a lone CR ends it: old Mac files), its leading blanks
 * dropped, appended to the logical line; 1 when it ends in a backslash that continues it. */
static int read_physical(loader *ld, size_t *used)
{
    const char *start = ld->cursor;
    const char *eol = strpbrk(start, "\r\n");
    size_t content = eol ? (size_t)(eol - start) : strlen(start);
    ld->cursor = start + content + (eol ? (eol[0] == '\r' && eol[1] == '\n' ? 2 : 1) : 0);
    ld->physical++;
    if (ld->physical == 1 && content >= 3 && memcmp(start, "\xEF\xBB\xBF", 3) == 0) {
        start += 3; /* a UTF-8 byte order mark */
        content -= 3;
    }
    while (content > 0 && (*start == ' ' || *start == '\t')) {
        ++start;
        --content;
    }
    size_t before = *used;
    if (logical_append(ld, used, start, content) != 0) {
        ld->oom = 1;
        return 0;
    }
    while (*used > before && (ld->logical[*used - 1] == ' ' || ld->logical[*used - 1] == '\t'))
        ld->logical[--*used] = '\0';
    int comment = ld->logical[0] == ';' || ld->logical[0] == '#';
    if (comment || *used == before || ld->logical[*used - 1] != '\\' || !*ld->cursor)
        return 0;
    ld->logical[*used - 1] = ' '; /* the backslash: the pieces are joined by a blank */
    return 1;
}

/* A value too long for inih's buffer: its inline comment (";" after a blank) and blanks
 * dropped, held aside; inih gets "key = \1" and bk_config_on_pair puts it back.  0, or -1
 * when the line is none of inih's (a section header). */
static int hold_long_value(loader *ld, char *str, int num)
{
    char *text = ld->logical;
    if (text[0] == ';' || text[0] == '#') { /* a comment: nothing to hand over */
        snprintf(str, (size_t)num, "\n");
        return 0;
    }
    char *sep = strpbrk(text, "=:");
    if (text[0] == '[' || !sep || (size_t)(sep - text) + 8 > (size_t)num)
        return -1;
    char *value = sep + 1;
    while (*value == ' ' || *value == '\t')
        ++value;
    for (char *c = value; *c; ++c)
        if (*c == ';' && c > value && (c[-1] == ' ' || c[-1] == '\t')) {
            *c = '\0';
            break;
        }
    size_t len = strlen(value);
    while (len > 0 && (value[len - 1] == ' ' || value[len - 1] == '\t'))
        value[--len] = '\0';
    char **grown = bk_grow_array(ld->long_values, &ld->long_cap, ld->n_long + 1, sizeof *grown, 8);
    char *kept = grown ? strdup(value) : NULL;
    if (!kept) {
        ld->oom = 1;
        snprintf(str, (size_t)num, "\n");
        return 0;
    }
    ld->long_values = grown;
    ld->long_values[ld->n_long++] = kept;
    ld->long_line = ld->line;
    snprintf(str, (size_t)num, "%.*s= \001\n", (int)(sep - text), text);
    return 0;
}

/* fgets-style reader over the text in memory (see the file comment): one logical line per
 * call, continuation lines (ending in a backslash) joined. */
char *bk_config_read_line(char *str, int num, void *stream)
{
    loader *ld = stream;
    if (!*ld->cursor)
        return NULL;
    size_t used = 0;
    if (logical_append(ld, &used, "", 0) != 0) {
        ld->oom = 1;
        return NULL;
    }
    ld->line = ld->physical + 1;
    while (read_physical(ld, &used))
        ;
    int *lines = bk_grow_array(ld->call_lines, &ld->calls_cap, ld->calls + 1, sizeof *lines, 64);
    if (!lines) {
        ld->oom = 1;
        return NULL;
    }
    ld->call_lines = lines;
    ld->call_lines[ld->calls++] = ld->line;
    if (used > 0 && ld->logical[0] == '[')
        ld->section_line = ld->line;
    if ((int)used + 2 <= num) {
        memcpy(str, ld->logical, used);
        str[used] = '\n';
        str[used + 1] = '\0';
    } else if (hold_long_value(ld, str, num) != 0) {
        char where[300];
        snprintf(where, sizeof where, "%s:%d", ld->name, ld->line);
        bk_config_report(ld, ld->line, BK_ERR_CONFIG,
                         "%s: a line of %zu characters that is no \"key = value\" with a key of at most %d "
                         "characters (allowed: only values may be longer than a line of %d)",
                         where, used, num - 8, num - 2);
        snprintf(str, (size_t)num, "\n");
    }
    return str;
}

int bk_config_reader_line(const loader *ld, int inih_line)
{
    return inih_line >= 1 && (size_t)inih_line <= ld->calls ? ld->call_lines[inih_line - 1] : inih_line;
}

void bk_config_free_reader(loader *ld)
{
    free(ld->logical);
    free(ld->call_lines);
    for (size_t k = 0; k < ld->n_long; ++k)
        free(ld->long_values[k]);
    free(ld->long_values);
}

int bk_config_on_pair(void *user, const char *section, const char *key, const char *value)
{
    loader *ld = user;
    /* A long line's value, held aside by the reader. */
    if (value[0] == '\001' && value[1] == '\0' && ld->long_line == ld->line && ld->n_long > 0)
        value = ld->long_values[ld->n_long - 1];
    if (bk_config_add_entry(ld, section, key, value, ld->line, NULL, ld->line) != 0)
        ld->oom = 1;
    else
        ld->entries[ld->n - 1].section_line = ld->section_line;
    return 1;
}

/* --- values ----------------------------------------------------------------------------- */

static int parse_number(const char *text, double *out)
{
    if (!*text || strpbrk(text, "xX")) /* decimal only: strtod would take hex floats too */
        return -1;
    char *end = NULL;
    errno = 0;
    double value = strtod(text, &end);
    while (end && isspace((unsigned char)*end))
        ++end;
    /* ERANGE on underflow (1e-320) is a tiny number, which the ranges then judge; one below
     * every double (1e-400) would silently be 0. */
    if (end == text || *end != '\0' || (errno == ERANGE && fabs(value) >= 1.0) || !isfinite(value))
        return -1;
    if (errno == ERANGE && value == 0.0)
        return -2;
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

/* The next word of a list separated by commas and/or blanks: 1 with *start and *len, 0 at
 * the end; *p moves past it. */
static int next_word(const char **p, const char **start, size_t *len)
{
    while (**p == ',' || isspace((unsigned char)**p))
        ++*p;
    if (!**p)
        return 0;
    *start = *p;
    while (**p && **p != ',' && !isspace((unsigned char)**p))
        ++*p;
    *len = (size_t)(*p - *start);
    return 1;
}

/* The position (1-based) of the first empty item of a list whose items are separated by
 * commas and/or blanks: "1e-3,,0" has an empty item 2, and a comma first or last one too;
 * 0 when there is none.  Blanks alone never make an empty item. */
static size_t empty_item(const char *text)
{
    size_t items = 0;
    int after_comma = 1; /* the start is like a comma: "," first is an empty item 1 */
    int seen_any = 0;
    for (const char *p = text; *p;) {
        if (isspace((unsigned char)*p)) {
            ++p;
        } else if (*p == ',') {
            if (after_comma)
                return items + 1;
            after_comma = 1;
            ++p;
        } else {
            ++items;
            seen_any = 1;
            after_comma = 0;
            while (*p && *p != ',' && !isspace((unsigned char)*p))
                ++p;
        }
    }
    return after_comma && seen_any ? items + 1 : 0;
}

/* Parse a "fields" list into a BK_FIELD_* mask; -1 and the bad word on failure. */
static int parse_fields(const char *text, double *out, char *bad, size_t bad_len)
{
    unsigned mask = 0;
    const char *p = text, *start;
    size_t len;
    int words = 0;
    while (next_word(&p, &start, &len)) {
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
int bk_config_check_value(loader *ld, entry *e, const key_def *def, const bk_param *param)
{
    char allowed[1536];
    bk_config_format_allowed(def, param, allowed, sizeof allowed);
    bk_key_kind type = def ? def->type : BK_KEY_NUMBER;
    const char *v = e->value;
    switch (type) {
    case BK_KEY_NUMBER:
    case BK_KEY_INTEGER: {
        int drawn = type == BK_KEY_NUMBER ? bk_config_parse_distribution(ld, e, param, allowed) : 0;
        if (drawn != 0)
            return drawn < 0 ? -1 : 0;
        int bad = type == BK_KEY_INTEGER ? parse_integer(v, &e->number) : parse_number(v, &e->number);
        if (bad == -2) {
            bk_config_report_entry(ld, e, "%s is smaller than any double (it would be read as 0; write 0 if that is "
                                   "meant) (allowed: %s)", v, allowed);
            return -1;
        }
        if (bad) {
            const char *hint = strchr(v, '#') ? " (inline comments start with ';')" : "";
            bk_config_report_entry(ld, e, "%s \"%s\"%s (allowed: %s)",
                                   type == BK_KEY_INTEGER ? "not an integer:" : "not a number:", v, hint, allowed);
            return -1;
        }
        if (!bk_param_in_range(param, e->number)) {
            bk_config_report_entry(ld, e, "out of range, got %s (allowed: %s)", v, allowed);
            return -1;
        }
        return 0;
    }
    case BK_KEY_BOOLEAN:
        /* A boolean whose default is decided per scene takes that decision by name. */
        if (isnan(param->default_value) && strcmp(v, "auto") == 0) {
            e->number = NAN;
            return 0;
        }
        if (parse_bool(v, &e->number)) {
            bk_config_report_entry(ld, e, "not a boolean: \"%s\" (allowed: %s)", v, allowed);
            return -1;
        }
        return 0;
    case BK_KEY_CHOICE:
        for (size_t i = 0; bk_config_enum_choice(def, i); ++i)
            if (strcmp(bk_config_enum_choice(def, i), v) == 0) {
                e->number = (double)i;
                return 0;
            }
        bk_config_report_entry(ld, e, "unknown value \"%s\" (allowed: %s)", v, allowed);
        return -1;
    case BK_KEY_TEXT:
        if (!*v) {
            bk_config_report_entry(ld, e, "empty value (allowed: %s)", allowed);
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
        const char *p = v, *start;
        size_t len;
        size_t empty = empty_item(v);
        if (empty > 0) {
            bk_config_report_entry(ld, e, "item %zu is empty (two commas, or a comma at an end) (allowed: %s)",
                                   empty, allowed);
            return -1;
        }
        while (next_word(&p, &start, &len)) {
            char word[64];
            snprintf(word, sizeof word, "%.*s", (int)len, start);
            double x;
            if (len >= sizeof word || parse_number(word, &x) != 0 || !bk_param_in_range(param, x)) {
                bk_config_report_entry(ld, e, "bad value \"%s\" (item %zu) (allowed: %s)", word, count + 1, allowed);
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
            bk_config_report_entry(ld, e, "empty list (allowed: %s)", allowed);
            return -1;
        }
        e->number = (double)count;
        return 0;
    }
    case BK_KEY_FIELDS: {
        char bad[64];
        if (parse_fields(v, &e->number, bad, sizeof bad)) {
            bk_config_report_entry(ld, e, "unknown field \"%s\" (allowed: %s)", bad, allowed);
            return -1;
        }
        return 0;
    }
    }
    return -1;
}

/* --- the index -------------------------------------------------------------------------- */

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
int bk_config_build_index(loader *ld)
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
        ld->per_block_sections |= e->index >= 0;
    }
    return 0;
}

/* The last (not superseded) entry for section/key, or NULL. */
entry *bk_config_lookup(loader *ld, const char *section, const char *key)
{
    size_t slot = *find_slot(ld, section, key);
    return slot ? &ld->entries[slot - 1] : NULL;
}

entry *bk_config_lookup_block(loader *ld, const char *base, size_t i, const char *key)
{
    if (!ld->per_block_sections)
        return NULL;
    char section[SECTION_LEN];
    snprintf(section, sizeof section, "%s.%zu", base, i);
    return bk_config_lookup(ld, section, key);
}

/* --- checks ----------------------------------------------------------------------------- */

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
    entry *own = bk_config_lookup(ld, e->section, "law");
    if (!own && e->index >= 0)
        own = bk_config_lookup(ld, "friction", "law");
    return own ? bk_friction_law_find(own->value) : NULL;
}

/* Sections, keys, duplicates and every value on its own. */
void bk_config_check_entries(loader *ld, long n_blocks)
{
    char allowed[1536];
    for (size_t i = 0; i < ld->n; ++i) {
        entry *e = &ld->entries[i];
        if (e->superseded)
            continue;
        int known_section = 0;
        for (size_t s = 0; bk_config_sections[s]; ++s)
            known_section |= strcmp(bk_config_sections[s], e->base) == 0;
        int per_block_ok = strcmp(e->base, "block") == 0 || strcmp(e->base, "friction") == 0;
        if (!known_section || e->index == -2 || (e->index >= 0 && !per_block_ok)) {
            char where[512], sections[256] = "";
            section_location(ld, e, where, sizeof where);
            /* From the table, so that no section is left out of the list. */
            size_t used = 0;
            for (size_t s = 0; bk_config_sections[s] && used < sizeof sections; ++s) {
                int per_block = strcmp(bk_config_sections[s], "block") == 0 || strcmp(bk_config_sections[s], "friction") == 0;
                used += (size_t)snprintf(sections + used, sizeof sections - used, "%s%s%s%s", s ? ", " : "",
                                         bk_config_sections[s], per_block ? ", " : "",
                                         per_block ? (strcmp(bk_config_sections[s], "block") == 0 ? "block.I" : "friction.I") : "");
            }
            bk_config_report(ld, e->section_line ? e->section_line : e->rank, BK_ERR_CONFIG,
                             "%s: [%s]: unknown section (allowed: %s; I is a block index from 0)", where, e->section,
                             sections);
            continue;
        }
        if (e->index >= 0 && n_blocks > 0 && e->index >= n_blocks) {
            char where[512];
            section_location(ld, e, where, sizeof where);
            bk_config_report(ld, e->section_line ? e->section_line : e->rank, BK_ERR_CONFIG, "%s: [%s]: block index out of range (allowed: 0..%ld)",
                             where, e->section, n_blocks - 1);
            continue;
        }
        /* A key given twice in one section of the file. */
        if (e->first_of_key >= 0)
            bk_config_report_entry(ld, e, "duplicate key (first set at line %d)", ld->entries[e->first_of_key].line);
        const key_def *def = bk_config_find_key(e->base, e->key);
        if (def) {
            bk_config_check_value(ld, e, def, &def->param);
            continue;
        }
        if (strcmp(e->base, "friction") == 0) {
            const bk_friction_law *law = section_law(ld, e);
            if (!law)
                continue; /* the missing or unknown law is reported at its own line */
            int p = bk_friction_param_index(law, e->key);
            if (p < 0) {
                list_law_params(law, allowed, sizeof allowed);
                bk_config_report_entry(ld, e, "not a parameter of law '%s' (known: law, %s)", law->name, allowed);
                continue;
            }
            bk_config_check_value(ld, e, NULL, &law->params[p]);
            continue;
        }
        bk_config_list_keys(e->base, allowed, sizeof allowed);
        bk_config_report_entry(ld, e, "unknown key (allowed: %s)", allowed);
    }
}
