/* HDF5 output: a bk_sink that streams a run to disk, and the readers behind
 * `bksim info` and `bksim export`.
 *
 * Layout (rows are time-major, datasets extendable and chunked; units in a "units"
 * attribute on every dataset):
 *   /time (T) s, /driver (T) m, /event (T) 1 = row at a transition instant,
 *   /x /v (T x N) m, m/s, /friction (T x N) N, /cof (T x N) 1, /mode (T x N) int8,
 *   /energy_kinetic /energy_elastic /work_driver /dissipation (T) J,
 *   /friction_state (T x S) per law,
 *   /transitions compound {t, block, from, to, x, v, force}.
 * Root attributes: config (full text), config_name, version, n_blocks, complete (0 until the
 * run finished), t_end, t_reached; group /stats holds solver statistics as attributes.
 * The file is written as "<path>.part" and renamed to <path> only when complete. */
#ifndef BKSIM_OUTPUT_H
#define BKSIM_OUTPUT_H

#include <stdio.h>

#include "bksim/config.h"
#include "bksim/run.h"
#include "bksim/status.h"

typedef struct bk_h5_writer bk_h5_writer;

/* Create "<path>.part" (parent directories are created as needed) and the datasets that
 * config->output.fields selects.  On failure nothing is left on disk. */
int bk_h5_writer_open(bk_h5_writer **out, const bk_config *config, const char *path,
                      bk_error *err);
/* The sink that appends to this writer. */
bk_sink bk_h5_writer_sink(bk_h5_writer *writer);
/* Flush, write stats, set complete = 1, close and rename "<path>.part" to <path>.
 * Frees the writer whatever the outcome. */
int bk_h5_writer_finish(bk_h5_writer *writer, const bk_run_stats *stats, bk_error *err);
/* After a failed run: flush what was written, record complete = 0 and error = reason,
 * close, and leave it as "<path>.part".  Frees the writer.  stats may be NULL. */
void bk_h5_writer_abandon(bk_h5_writer *writer, const char *reason, const bk_run_stats *stats);

/* Reopen the output of a run that stopped (<path>.part, or path given as the .part itself)
 * to continue it from its last checkpoint: reloads the config it stored (file text and
 * --set overrides), reads the checkpoint into *checkpoint (free with bk_checkpoint_free),
 * truncates every dataset to the rows written up to the checkpoint, and returns a writer
 * that appends from there and renames to <path> when finished.  On failure nothing is
 * returned and the file is unchanged. */
int bk_h5_writer_resume(bk_h5_writer **out, const char *path, bk_config **config,
                        bk_checkpoint *checkpoint, bk_error *err);

/* Summary of an output file: parameters, stick/slip phase counts, solver stats, and the
 * integrity check below.  Returns BK_OK for a complete, intact file, BK_INCOMPLETE for an
 * intact file of a run that did not finish, BK_ERR_DAMAGED (message says what) or another
 * negative code for a file that cannot be read. */
int bk_h5_info(const char *path, FILE *out, bk_error *err);

/* Integrity: root attributes present, /time /driver /event present, every time series as
 * long as /time with one column per block where per-block, /time finite and strictly
 * increasing, t_reached its last value, and for a complete run /time ending at t_end.
 * Same returns as bk_h5_info. */
int bk_h5_verify(const char *path, bk_error *err);

/* Whitespace-separated columns on out, one row per time sample, after a '#' header naming
 * columns and units.  datasets: comma-separated names (NULL = "time,driver,x,v,friction,
 * cof,mode"); block: column of the T x N datasets to print, or -1 for all blocks.
 * With transitions != 0 prints the /transitions table instead. */
int bk_h5_export(const char *path, const char *datasets, long block, int transitions,
                 FILE *out, bk_error *err);

/* Read a whole numeric dataset as doubles (row-major, rows x cols; cols = 1 for 1-D).
 * *data is malloc'ed. */
int bk_h5_read_doubles(const char *path, const char *dataset, double **data, size_t *rows,
                       size_t *cols, bk_error *err);
/* Read /transitions; *rows malloc'ed. */
int bk_h5_read_transitions(const char *path, bk_transition **rows, size_t *count,
                           bk_error *err);

#endif
