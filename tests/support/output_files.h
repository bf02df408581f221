/* Test support: synthetic output files for the output tests.  A chain whose rows and
 * transitions hold deterministic, non-round values (so exact equality means an exact round
 * trip), written through the writer's sink, and checks that read them back. */
#ifndef TEST_OUTPUT_FILES_H
#define TEST_OUTPUT_FILES_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/bksim.h"

/* The config text stored in synthetic files' "config" attribute. */
extern const char SYNTHETIC_CONFIG_TEXT[];

/* A chain of n blocks (masses, normal forces 1, 2, ...) with these output fields, t_end 10 s,
 * interval 0.01 s; with_state gives blocks laws of 1, 2, 1, ... state variables (so
 * /friction_state has columns of uneven blocks).  Free with bk_config_free. */
bk_config *synthetic_config(size_t n, unsigned fields, int transitions, int with_state);

/* The value of column col of row row in series `which` (W_*), the time of a row, a mode. */
enum { W_X, W_V, W_FRICTION, W_COF, W_STATE, W_EKIN, W_EEL, W_WORK, W_DISS, W_DRIVER };
double value(size_t row, size_t col, int which);
double row_time(size_t row);
int8_t row_mode(size_t row, size_t col);

/* Send rows [0, rows) through the sink; row 7k is an event row. */
void write_rows(bk_sink *sink, const bk_config *c, size_t rows);
/* Rows [first, first + rows), as write_rows writes them. */
void write_row_range(bk_sink *sink, const bk_config *c, size_t first, size_t rows);
/* Transition k of the synthetic sequence (times within [0, 0.2]), and the first count of
 * them through the sink. */
bk_transition transition_at(size_t k);
void write_transitions(bk_sink *sink, size_t count);
bk_run_stats example_stats(void);
/* Write a file of `rows` rows and `count` transitions and finish it. */
void write_file(const char *path, const bk_config *c, size_t rows, size_t count);
/* A small complete file (3 blocks, 3 rows, 5 transitions, t_end = 0.2 s) with round-looking
 * values whose %.17g forms are not round; with_state adds 4 friction-state columns. */
void write_small(const char *path, int with_state);
/* write_small with these transitions instead of the usual five. */
void write_small_with(const char *path, const bk_transition *transitions, size_t n);
/* The same with /events holding these events (none written when events is NULL). */
void write_small_with_events(const char *path, const bk_transition *transitions, size_t n,
                             const bk_event *events, size_t n_events);

/* The same with /events empty and one rupture: its row, its blocks and its rate rows. */
void write_small_with_rupture(const char *path, const bk_rupture *rupture, const bk_rupture_block *blocks,
                              size_t n_blocks, const bk_rupture_rate *rate, size_t n_rate);

/* Series `name` of path holds rows x cols values of series `which` (-1: row_time). */
void check_series(const char *path, const char *name, size_t rows, size_t cols, int which);
/* bk_h5_verify calls path damaged with a message naming path and containing needle, and
 * bk_h5_info says the same. */
void expect_damaged(const char *path, const char *needle);

#endif
