/* Internal: what the parts of the `bksim stats` report printer share (stats_print.c holds the
 * report's frame and its magnitude statistics; the satellites below one section each). */
#ifndef BKSIM_STATS_PRINT_IMPL_H
#define BKSIM_STATS_PRINT_IMPL_H

#include <stdio.h>

#include "bksim/stats.h"

/* JSON (src/stats_print_shared.c).  Each writes "key": value and a ", " unless last. */
/* The shortest text that reads back as the same double; null for NaN and infinities. */
void bk_json_number(FILE *out, const char *key, double value, int last);
void bk_json_count(FILE *out, const char *key, size_t value);
/* A quoted, escaped string (no key, no separator). */
void bk_json_string(FILE *out, const char *s);
/* "key": "note", only when have is 0. */
void bk_json_note(FILE *out, const char *key, int have, const char *note);
/* "key": {n, ks_distance, p_value, synthetic_samples, consistent} or null. */
void bk_json_gof(FILE *out, const char *key, int have, const bk_gof *g);

/* TSV tables: open one in dir with its header line (NULL and err set on failure), close it
 * reporting a failed write (src/stats_print_shared.c). */
FILE *bk_stats_open_table(const char *dir, const char *name, char *path, size_t len, const char *header,
                          bk_error *err);
int bk_stats_close_table(FILE *f, const char *path, bk_error *err);

/* BK_ERR_IO naming what was written when out has seen a write error. */
int bk_stats_write_failed(FILE *out, const char *what, bk_error *err);
/* What a catalog table is, after its name: " (the rupture catalog)", " (the time-window
 * catalog)", or its fallback note; "" for another table or none. */
const char *bk_stats_table_note(const char *table, int fallback);

/* Mainshock sequences and the Omori-Utsu law (src/stats_print_sequences.c). */
void bk_stats_text_sequences(const bk_stats_report *r, FILE *out);
void bk_stats_json_sequences(const bk_stats_report *r, FILE *out);
int bk_stats_tsv_sequences(const bk_stats_report *r, const char *dir, bk_error *err);

/* Potency against duration and length (src/stats_print_scaling.c). */
void bk_stats_text_scaling(const bk_stats_report *r, FILE *out);
void bk_stats_json_scaling(const bk_stats_report *r, FILE *out);
int bk_stats_tsv_scaling(const bk_stats_report *r, const char *dir, bk_error *err);

#endif
