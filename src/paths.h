/* File-system helpers of the writer (paths.c); the .part naming is public (output.h). */
#ifndef BKSIM_PATHS_H
#define BKSIM_PATHS_H

#include "bksim/status.h"

/* mkdir -p for the directory part of path. */
int bk_output_make_parent_dirs(const char *path, bk_error *err);
/* Sync part to disk, rename it to path, and sync the directory (best effort). */
int bk_output_durable_rename(const char *part, const char *path, bk_error *err);
/* Start writing the dirty pages of the open file fd to disk, without waiting (Linux's
 * sync_file_range; nothing elsewhere): a long run's output then reaches the disk behind
 * the run, not all in the final fsync, and dirty memory stays bounded. */
void bk_output_write_behind(int fd);

/* 1 when another process holds path's write lock, else 0 (also when path cannot be
 * opened).  HDF5 1.10 takes flock(LOCK_EX) on a file it writes and keeps it until the file
 * is closed, so this is "a run is writing path now".  Call it before opening path here:
 * flock conflicts between descriptors of one process too. */
int bk_output_write_locked(const char *path);
/* The refusal when it is (one argument: the path). */
#define BK_OUTPUT_OWNED_MESSAGE                                                               \
    "%s: another run owns this file: it is writing it now (it holds the file's lock); wait " \
    "for it to finish (`bksim info` shows its progress), or write elsewhere with -o"

#endif
