/* HDF5 output, the write side: a bk_sink that streams a run to disk, checkpoints in it, and
 * the restart that continues a stopped run.  The read side (`bksim info`, `bksim export`,
 * the integrity check and the readers) is bksim/inspect.h.
 *
 * Layout (rows are time-major, datasets extendable and chunked; units in a "units"
 * attribute on every dataset):
 *   /time (T) s, /driver (T) m, /event (T) 1 = row at a transition instant,
 *   /x /v (T x N) m, m/s, /friction (T x N) N, /cof (T x N) 1, /mode (T x N) int8,
 *   /energy_kinetic /energy_elastic /work_driver /dissipation (T) J,
 *   /friction_state (T x S) per law,
 *   /transitions compound {t, block, from, to, x, v, force},
 *   /events compound, one row per slip event (bksim/catalog.h; [output] events).
 * Every chunked dataset carries Fletcher32 checksums, so damaged chunk bytes fail the read.
 * Root attributes: config (full text), config_file and overrides (what a restart reloads),
 * config_name, version, n_blocks, complete (0 until the run finished), t_end, t_reached, and
 * datasets (the comma-separated names of the datasets the writer created); group /stats
 * holds solver statistics as attributes.
 * Group /checkpoint (with [output] checkpoint_interval) holds two slots, /checkpoint/a and
 * /checkpoint/b, written in turn so that a crash while one is written leaves the other
 * whole; each has a sequence number, the row counts of the datasets at the checkpoint and an
 * FNV-1a checksum over all of it, and the newest slot that verifies is the checkpoint.
 * The file is written as "<path>.part", synced to disk and renamed to <path> only when
 * complete. */
#ifndef BKSIM_OUTPUT_H
#define BKSIM_OUTPUT_H

#include "bksim/checkpoint.h"
#include "bksim/config.h"
#include "bksim/sink.h"
#include "bksim/status.h"

typedef struct bk_h5_writer bk_h5_writer;

/* Create "<path>.part" (parent directories are created as needed) and the datasets that
 * config->output.fields selects.  On failure nothing is left on disk. */
int bk_h5_writer_open(bk_h5_writer **out, const bk_config *config, const char *path,
                      bk_error *err);
/* Record the name of the sweep grid point this run is (root attribute `point`). */
int bk_h5_writer_set_point(bk_h5_writer *writer, const char *point, bk_error *err);
/* Record (root attribute init_from) the finished run whose end this run started from. */
int bk_h5_writer_set_init_from(bk_h5_writer *writer, const char *source, double t_source, bk_error *err);
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
 * --set overrides), reads the newest checkpoint slot that verifies (checksum, row counts on
 * disk, /time at its last row equal to the time it records) into *checkpoint (free with
 * bk_checkpoint_free), truncates every dataset to the rows written up to the checkpoint, and
 * returns a writer that appends from there and renames to <path> when finished.  Refuses
 * with BK_ERR_DAMAGED when no checkpoint verifies (the message says what is wrong with each
 * slot), BK_ERR_INVALID when there is no checkpoint (none yet, or only a first one cut
 * short) or no .part.  On failure nothing is returned; the rows before the checkpoint are
 * never changed, but a failure after the checkpoint verified may leave the file's recorded
 * size extended, a torn last chunk rewritten, or datasets already cut to the checkpoint. */
int bk_h5_writer_resume(bk_h5_writer **out, const char *path, bk_config **config,
                        bk_checkpoint *checkpoint, bk_error *err);

/* Whether "<path>.part" (path may also name the .part itself) holds the output of an
 * unfinished run that `bksim run --restart` can continue: 1 when it has a checkpoint that
 * verifies as bk_h5_writer_resume requires, with *t_checkpoint (may be NULL) set to that
 * checkpoint's time; 0 when there is no such file, or it is unreadable, has no checkpoint or
 * none that verifies (then err is left alone: overwriting it loses nothing a restart could
 * use); negative with err filled only for a missing path or lack of memory.  Meant for
 * refusing to overwrite restartable work. */
int bk_h5_restartable(const char *path, double *t_checkpoint, bk_error *err);

/* Whether a run may write over path: BK_OK when nothing is there or it is a bksim output
 * (an HDF5 file with bksim's root attributes config, version and n_blocks), or, for a
 * working file (working = 1: a .part), an empty file or one with HDF5's signature (a run
 * killed while creating it); else BK_ERR_INVALID naming what is there (a file of the user's,
 * a directory, a device).  The writer asks it for OUT and OUT.part when it opens and again
 * before the rename that publishes OUT, so no flag ever replaces a file that is not bksim's. */
int bk_h5_output_replaceable(const char *path, int working, bk_error *err);

/* Make the run in path (finished: OUT, or stopped: OUT.part) longer, to t_end: checked
 * (later than its own t_end, which goes to *old_t_end; the stored config loads with it; a
 * checkpoint to continue from), stored as one more --set override, and a finished OUT
 * renamed to OUT.part; bk_h5_writer_resume then continues it.  Nothing is changed on
 * failure (BK_ERR_INVALID or BK_ERR_CONFIG say why). */
int bk_h5_extend_to(const char *path, double t_end, double *old_t_end, bk_error *err);

/* The state the finished run in path ended in (its checkpoint at t_end, written by every run
 * that has restart points), and the config it ran (free both: bk_checkpoint_free,
 * bk_config_free).  BK_ERR_INVALID says why a file gives none: missing, a .part, not a
 * finished bksim output, or no checkpoint at its end. */
int bk_h5_read_end_state(const char *path, bk_checkpoint *end, bk_config **config, bk_error *err);

/* While a run writes OUT it is "OUT.part".  bk_output_is_part: whether path ends in
 * ".part"; bk_output_part_path: path + ".part"; bk_output_final_path: path without its
 * ".part" (or a copy of path).  Malloc'ed; NULL when out of memory. */
int bk_output_is_part(const char *path);
char *bk_output_part_path(const char *path);
char *bk_output_final_path(const char *path);
/* An output path that names a directory (it ends in '/' or is one) means the file
 * "<dir>/<stem>.h5" in it, stem being config_name's base name without its extension (c.ini
 * -> c.h5), as `cp file dir/` does; any other path is itself.  Malloc'ed; NULL when out of
 * memory. */
char *bk_output_resolve(const char *path, const char *config_name);
/* Move a .part that cannot be continued out of the way, to "<part>.damaged" (or
 * "<part>.damaged.2", ... when that exists), so that starting over does not destroy it;
 * *kept (malloc'd) gets the new name. */
int bk_output_set_aside(const char *part, char **kept, bk_error *err);

#endif
