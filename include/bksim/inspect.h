/* HDF5 output, the read side: the summary and integrity check behind `bksim info`, the text
 * export behind `bksim export`, whole-dataset readers, the catalog behind `bksim stats` and
 * the sweep table behind `bksim summary` (/ruptures by default, or another table by name).
 * The file layout is described in bksim/output.h (the write side). */
#ifndef BKSIM_INSPECT_H
#define BKSIM_INSPECT_H

#include <stddef.h>
#include <stdio.h>

#include "bksim/config.h"
#include "bksim/sink.h"
#include "bksim/stats.h"
#include "bksim/status.h"

/* Summary of an output file: parameters, stick/slip phase counts, solver stats, and the
 * integrity check below.  Returns BK_OK for a complete, intact file, BK_INCOMPLETE for an
 * intact file of a run that did not finish, BK_ERR_DAMAGED (message says what) or another
 * negative code for a file that cannot be read. */
int bk_h5_info(const char *path, FILE *out, bk_error *err);
/* Up to this many blocks bk_h5_info lists the phases block by block; a longer chain gets
 * totals, the spread of slips per block and the most active blocks instead. */
#define BK_INFO_TABLE_BLOCKS 20
/* bk_h5_info with the per-block table whatever the chain's length when per_block != 0.
 * A file a run is writing now (another process holds its lock) is read without the lock:
 * its progress as last committed ("in progress, t = ..., N transitions so far"), no integrity
 * check, BK_INCOMPLETE. */
int bk_h5_info_blocks(const char *path, FILE *out, int per_block, bk_error *err);

/* Integrity: root attributes present; every dataset the writer created (root attribute
 * datasets; for older files, those the stored config selects) present; every time series as
 * long as /time with one column per block where per-block; every value read (so every
 * chunk's Fletcher32 checksum checked), a block of rows at a time: all finite, /mode in
 * {-1, 0, 1}, /event in {0, 1}, /time strictly increasing, t_reached its last value and, for
 * a complete run, /time ending at t_end; /transitions in time order within the run, of
 * existing blocks between valid modes; /events and /ruptures rows as bksim writes them,
 * /rupture_blocks and /rupture_rate rows of existing ruptures in order, as many block rows as
 * the ruptures have blocks; and a /checkpoint verifying as a restart requires.
 * Same returns as bk_h5_info. */
int bk_h5_verify(const char *path, bk_error *err);

/* Whitespace-separated columns on out, one row per time sample, after a '#' header naming
 * columns and units.  datasets: comma-separated names (NULL = "time,driver,x,v,friction,
 * cof,mode"); block: column of the T x N datasets to print, or -1 for all blocks.
 * With transitions != 0 prints the /transitions table instead. */
int bk_h5_export(const char *path, const char *datasets, long block, int transitions,
                 FILE *out, bk_error *err);

/* The /events catalog as TSV on out: a '#' header naming the twelve fields with units
 * (t_start[s] ... complete[1]), then one tab-separated row per event in table order, doubles
 * as %.17g (a zero-potency event's magnitude prints as -inf), integers as %d; read one
 * chunk of rows at a time.  A file without /events, or whose /events lacks one of bksim's
 * event fields, is an error that names the file and /events. */
int bk_h5_export_events(const char *path, FILE *out, bk_error *err);

/* Any 1-D table of records (/transitions, /events, /ruptures, /rupture_blocks,
 * /rupture_rate, or another program's) as TSV on out: a '#' header naming each field with
 * its unit from the table's units attribute ("1" when it names none), then one row per
 * record, floating-point fields as %.17g, integers as integers; read 4096 rows at a time. */
int bk_h5_export_table(const char *path, const char *table, FILE *out, bk_error *err);

/* Read a whole numeric dataset as doubles (row-major, rows x cols; cols = 1 for 1-D).
 * *data is malloc'ed. */
int bk_h5_read_doubles(const char *path, const char *dataset, double **data, size_t *rows,
                       size_t *cols, bk_error *err);
/* The config the run in path ran (its stored file text and --set overrides), loaded again;
 * free it with bk_config_free. */
int bk_h5_read_config(const char *path, bk_config **config, bk_error *err);
/* Read /transitions; *rows malloc'ed. */
int bk_h5_read_transitions(const char *path, bk_transition **rows, size_t *count,
                           bk_error *err);
/* Read /events (a catalog written by bksim: every bk_event field); *rows malloc'ed. */
int bk_h5_read_events(const char *path, bk_event **rows, size_t *count, bk_error *err);
/* Read /ruptures, /rupture_blocks, /rupture_rate (bksim/rupture.h); *rows malloc'ed.
 * BK_ERR_INVALID when the file has no such table. */
int bk_h5_read_ruptures(const char *path, bk_rupture **rows, size_t *count, bk_error *err);
int bk_h5_read_rupture_blocks(const char *path, bk_rupture_block **rows, size_t *count, bk_error *err);
int bk_h5_read_rupture_rate(const char *path, bk_rupture_rate **rows, size_t *count, bk_error *err);

/* The catalog tables `bksim stats` and `bksim summary` read: by default the rupture catalog
 * (connected slip episodes, bksim/rupture.h), and, in a file without it (an older bksim
 * output, another program's catalog), the time-window catalog /events. */
#define BK_CATALOG_DEFAULT_TABLE "ruptures"
#define BK_CATALOG_FALLBACK_TABLE "events"

/* An earthquake catalog table of any HDF5 file (a 1-D compound dataset with at least t_start
 * and magnitude; potency, n_blocks, complete, t_end and max_slip_rate read when present, in
 * any numeric type) into *out (bk_event_table_free), with the root attribute t_reached of a
 * bksim output (NaN without one).  table names the dataset ("events", "ruptures", a leading
 * '/' allowed); NULL reads /ruptures, else /events when the file has no /ruptures (then
 * out->fallback = 1).  out->name is the table read.  Fails (BK_ERR_INVALID, the message
 * naming the file and the table) on a file without that table, or without either for NULL,
 * on a table that lacks t_start or magnitude, and on a file that cannot be read; *out is
 * then empty. */
int bk_h5_read_event_table(const char *path, const char *table, bk_event_table *out,
                           bk_error *err);
/* `bksim stats FILE [--table NAME]`: bk_h5_read_event_table(path, table, ...), then
 * bk_stats_report_compute with the file's path as the source (the report names the table
 * and says when the default fell back to /events).  Options are checked first. */
int bk_stats_report_read(const char *path, const char *table, const bk_stats_options *opt,
                         bk_stats_report **out, bk_error *err);

/* `bksim summary DIR [--table NAME]`: one row per finished run (complete *.h5, every dataset
 * verifying) in dir, in the grid's order (by the --set keys in the order the runs give them,
 * numbers as numbers, then by file name): file, point (the sweep's grid point), one column per --set key any
 * run used (named by the key, holding that run's value), then its headline figures from its
 * catalog table (table as for bk_h5_read_event_table: NULL for /ruptures, else /events):
 * events (the table's complete rows, ruptures by default, starting in [opt->t_from,
 * opt->t_to)), mean_recurrence (s, between their starts), largest_magnitude and
 * largest_event_blocks (the n_blocks of the largest), peak_slip_rate (m/s: the catalog's
 * largest max_slip_rate, else the largest |v| of /v), b_value, b_error, mc and b_events (as
 * `bksim stats` with opt gives them), energy_residual, steps, rhs_evals, transitions,
 * t_reached, wall_time, cpu_time, seed, method, host and catalog (the table the figures came
 * from, "-" for a run without a catalog); NaN where a run has no such figure.  With table
 * NULL a run without any catalog is summarised without the catalog figures; a run without a
 * table named by table is left out.  Written as dir/summary.tsv (a '#' line with the units, a
 * header of column names, tab-separated rows) and dir/summary.h5 (compound dataset /summary
 * with units), each via a temporary name and a rename.  Files left out (a run that did not
 * finish, an HDF5 file that is no bksim output, a damaged file, a run without the named
 * table) are named on notes (may be NULL), and so, in one line, are the runs whose default
 * fell back to /events.  *n_runs (may be NULL) gets the row count.  BK_ERR_INVALID when dir
 * holds no finished run (with the named table). */
int bk_h5_summary(const char *dir, const char *table, const bk_stats_options *opt, FILE *notes,
                  size_t *n_runs, bk_error *err);

#endif
