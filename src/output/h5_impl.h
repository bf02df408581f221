/* What the HDF5 files of src/output/ share and nothing outside them sees: the writer's
 * state, the error plumbing, attribute helpers and the low-level readers.  Public entry
 * points are in include/bksim/output.h (write side) and include/bksim/inspect.h (read
 * side); the file layout itself is in layout.h, free of HDF5.
 *
 * Failures are reported through bk_error only: HDF5's automatic error printing is switched
 * off at every entry point, and the innermost message of HDF5's error stack is appended to
 * ours because it usually names the real cause (errno text, "file is truncated", ...). */
#ifndef BKSIM_OUTPUT_H5_IMPL_H
#define BKSIM_OUTPUT_H5_IMPL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <hdf5.h>

#include "bksim/checkpoint.h"
#include "bksim/config.h"
#include "bksim/output.h"
#include "bksim/rupture.h"
#include "layout.h"

/* Rows of a 2-D chunk, and of the buffer that fills one.  A chunk of a T x N dataset is
 * capped at CHUNK_BYTES so wide chains keep chunks (and the buffers, one chunk per
 * dataset) bounded. */
#define MAX_BUFFER_ROWS 4096u
#define CHUNK_BYTES (1u << 20)
/* 1-D series are tiny per row: their chunks (and buffers) hold this many rows, so that a
 * chunk is written once, whole, whatever the width of the 2-D ones. */
#define SERIES_1D_CHUNK 4096u
#define TRANSITION_BUFFER 512u
#define EVENT_BUFFER 256u
#define RUPTURE_BUFFER 256u
#define RUPTURE_BLOCK_BUFFER 1024u
#define RUPTURE_RATE_BUFFER 2048u
/* Wall-clock seconds between two commits (H5Fflush: what is on disk becomes a readable
 * file) while a run writes; a SIGKILL loses what came after the last one. */
#define COMMIT_INTERVAL 1.0
/* Records handed to the writer between two looks at the wall clock. */
#define COMMIT_CHECK_EVERY 64u
/* Doubles held in memory per block of rows while exporting or checking. */
#define EXPORT_BUDGET (1u << 20)

/* ------------------------------------------------------------------ the writer --- */

typedef struct bk_h5_series {
    hid_t dset;          /* H5I_INVALID_HID when the field is not written */
    int rank;            /* 1 for T, 2 for T x N and T x S */
    size_t cols;         /* values per row */
    size_t elem;         /* bytes per value in memory */
    size_t rows;         /* rows the buffer holds: one chunk */
    size_t buffered;     /* rows in the buffer, not yet appended */
    unsigned char *buf;  /* rows x cols values */
} bk_h5_series;

/* The record tables, in the order the writer creates them. */
typedef enum bk_h5_table_kind {
    BK_TABLE_TRANSITIONS, BK_TABLE_EVENTS, BK_TABLE_RUPTURES, BK_TABLE_RUPTURE_BLOCKS,
    BK_TABLE_RUPTURE_RATE, BK_N_TABLES
} bk_h5_table_kind;

/* What a table is: its dataset's name and attributes, its record on disk and in memory, and
 * the records its buffer (one chunk) holds. */
typedef struct bk_h5_table_def {
    const char *name, *units, *description;
    size_t record_bytes;  /* packed, on disk */
    size_t struct_bytes;  /* the C struct (bk_transition, bk_event, bk_rupture, ...) */
    size_t buffer;        /* records per chunk */
} bk_h5_table_def;

extern const bk_h5_table_def bk_h5_tables[BK_N_TABLES];

/* A table of packed records and its buffer. */
typedef struct bk_h5_table {
    hid_t dset;          /* H5I_INVALID_HID when the table is not written */
    hid_t mem;           /* the C struct's type, for reading back at a restart */
    hid_t packed;        /* the buffer's type: the file's row, native members */
    size_t record;       /* bytes per packed record */
    size_t capacity;     /* records the buffer holds */
    size_t buffered;
    hsize_t written;     /* records appended to the dataset */
    hsize_t committed;   /* records in the last commit */
    unsigned char *buf;
} bk_h5_table;

struct bk_h5_writer {
    char *path;
    char *part;
    hid_t file;
    size_t n_blocks;
    bk_h5_series s[BK_N_SERIES];
    size_t buffer_rows;  /* rows of a 2-D chunk */
    double expected_rows; /* of the run, for its chunks: small runs get small files */
    double max_bytes;    /* [output] max_bytes: the file on disk stays within it (+inf: no bound) */
    hsize_t rows;        /* rows accepted; every series holds them, on disk or buffered */
    hsize_t committed_rows; /* rows in the last commit */
    double t_buffered;   /* time of the last row accepted */
    double t_written;    /* time of the last row in the last commit */
    bk_h5_table tables[BK_N_TABLES]; /* dset invalid for a table the run does not write */
    double trans_last_t; /* t of the last transition accepted */
    double last_commit;  /* wall clock (s) of the last commit */
    int part_fd;         /* the .part opened for write-behind (-1: not yet) */
    size_t unsynced;     /* bytes appended since the last write-behind */
    unsigned uncounted;  /* records since the wall clock was last read */
    long long cp_sequence; /* of the last checkpoint written (0: none) */
    int cp_slot;         /* slot of /checkpoint the next checkpoint goes to */
    int failed;          /* a write failed: rows on disk may be ragged, accept no more */
    int out_of_room;     /* failed because bk_h5_writer_room said no: every write so far succeeded */
    double unflushed;    /* chunk bytes appended since the last flush: HDF5's chunk cache may hold
                            them, not yet allocated in the file */
    double eoa_committed; /* the file's allocated end at the last flush */
};

/* Whether bytes more (and HDF5's metadata) fit on the .part's disk and under the file-size
 * limit: BK_OK, or BK_ERR_IO saying which and marking the writer failed and out of room
 * (h5_room.c). */
int bk_h5_writer_room(bk_h5_writer *w, double bytes, bk_error *err);

/* The one set-up shared by a new run (bk_h5_writer_open) and a resumed one
 * (bk_h5_writer_resume): a writer for the final name path, its .part name, every id
 * invalid.  BK_ERR_NOMEM on failure (message names path). */
int bk_h5_writer_new(bk_h5_writer **out, const char *path, bk_error *err);
/* Size the row buffers for this chain and a run of about expected_rows rows: how many rows a
 * buffer (and a chunk of a new dataset) holds. */
void bk_h5_writer_size(bk_h5_writer *w, const bk_model *model, double expected_rows);
/* Shape series i for this chain and allocate its row buffer of chunk_rows rows (0: as
 * bk_h5_writer_size decided, for a new dataset); -1 when out of memory. */
int bk_h5_writer_series(bk_h5_writer *w, int i, const bk_model *model, size_t chunk_rows);
/* The buffer and memory types of a table; -1 on failure. */
int bk_h5_writer_table(bk_h5_table *table, bk_h5_table_kind kind);
/* Close every id the writer holds; -1 if any close failed. */
herr_t bk_h5_writer_close(bk_h5_writer *w);
void bk_h5_writer_free(bk_h5_writer *w);
/* Commit: append everything buffered, record t_reached and flush HDF5's metadata, so that
 * the file on disk is readable and consistent up to here (see h5_writer.c). */
int bk_h5_writer_flush(bk_h5_writer *w, bk_error *err);

/* ------------------------------------------------------------ error plumbing --- */

/* Our message plus the most specific description on HDF5's error stack, which must still
 * hold the failure: call this before any further HDF5 call (closing ids clears it). */
int bk_h5_fail(bk_error *err, int status, const char *file, int line, const char *func,
               const char *fmt, ...) __attribute__((format(printf, 6, 7)));

#define H5_FAIL(err, ...) bk_h5_fail((err), BK_ERR_HDF5, __FILE__, __LINE__, __func__, __VA_ARGS__)
/* A read that failed inside a file that opened: the file is damaged (a Fletcher32 checksum
 * mismatch lands here), and HDF5's reason is kept. */
#define H5_DAMAGED(err, ...) \
    bk_h5_fail((err), BK_ERR_DAMAGED, __FILE__, __LINE__, __func__, __VA_ARGS__)

void bk_h5_close_id(hid_t id);
/* Close ids after a helper finished.  Closing clears HDF5's error stack, so after a failure
 * the stack is saved first and restored, leaving it for bk_h5_fail in the caller. */
void bk_h5_close_ids(int failed, const hid_t *ids, size_t n);

#define CLOSE_IDS(status, ...)                                  \
    bk_h5_close_ids((status) < 0, (const hid_t[]){__VA_ARGS__}, \
                    sizeof((const hid_t[]){__VA_ARGS__}) / sizeof(hid_t))

htri_t bk_h5_has_signature(const char *path);

/* ---------------------------------------------------------------- attributes --- */

herr_t bk_h5_write_attr(hid_t obj, const char *name, hid_t file_type, hid_t mem_type,
                        const void *value);
herr_t bk_h5_write_string_attr(hid_t obj, const char *name, const char *value);
herr_t bk_h5_write_fixed_string_attr(hid_t obj, const char *name, const char *value);
herr_t bk_h5_write_double_attr(hid_t obj, const char *name, double value);
herr_t bk_h5_write_int_attr(hid_t obj, const char *name, int value);
herr_t bk_h5_write_long_attr(hid_t obj, const char *name, long long value);
/* "units" and "description" attributes: variable-length (at creation) or fixed-length (on
 * objects written later; see bk_h5_write_fixed_string_attr). */
herr_t bk_h5_describe(hid_t obj, const char *units, const char *description);
herr_t bk_h5_describe_fixed(hid_t obj, const char *units, const char *description);
char *bk_h5_read_string_attr(hid_t obj, const char *name);
herr_t bk_h5_read_numeric_attr(hid_t obj, const char *name, hid_t mem_type, void *value);
/* The solver statistics as attributes of group "stats" in obj. */
herr_t bk_h5_write_stats(hid_t obj, const bk_run_stats *stats);

/* --------------------------------------------------------------------- types --- */

hid_t bk_h5_kind_file_type(bk_series_kind kind);
hid_t bk_h5_kind_mem_type(bk_series_kind kind);
/* Where a record's members sit: the C struct (bk_transition, bk_event: for reading), the
 * file's packed little-endian row, or that packed row with native members, which the writer
 * fills (bk_h5_pack_*) so that on a little-endian machine HDF5 has nothing to convert. */
typedef enum { BK_H5_RECORD_STRUCT, BK_H5_RECORD_FILE, BK_H5_RECORD_PACKED } bk_h5_record_layout;
hid_t bk_h5_transition_type(bk_h5_record_layout layout);
hid_t bk_h5_event_type(bk_h5_record_layout layout);
/* Any table's record type. */
hid_t bk_h5_table_type(bk_h5_table_kind kind, bk_h5_record_layout layout);
/* The record as a packed row (record_bytes at row). */
void bk_h5_pack_record(bk_h5_table_kind kind, const void *record, unsigned char *row);
void bk_h5_pack_transition(const bk_transition *transition, unsigned char *row);
void bk_h5_pack_event(const bk_event *event, unsigned char *row);

/* ------------------------------------------------------------------- readers --- */

/* Open path read-only with a message that says what is wrong (missing, a directory, not
 * HDF5, a .part cut short). */
int bk_h5_open_input(const char *path, hid_t *file, bk_error *err);
int bk_h5_read_n_blocks(hid_t file, const char *path, long long *n_blocks, bk_error *err);
/* Opens a numeric 1-D or 2-D dataset and reports its shape. */
int bk_h5_open_series(hid_t file, const char *path, const char *name, hid_t *dset,
                      hsize_t *rows, hsize_t *cols, int *rank, bk_error *err);
/* Opens /transitions and its memory type; count = rows. */
int bk_h5_open_transitions(hid_t file, const char *path, hid_t *dset, hid_t *mem,
                           hsize_t *count, bk_error *err);
/* Every /transitions record in order (read TRANSITION_BUFFER at a time) through visit, which
 * returns BK_OK to go on; *count gets the table's length. */
/* Opens /events, a 1-D compound table with every field of bksim's catalog, and its memory
 * type; count = rows.  BK_ERR_INVALID when there is none or it is another program's. */
int bk_h5_open_events(hid_t file, const char *path, hid_t *dset, hid_t *mem, hsize_t *count,
                      bk_error *err);
/* Every /events record in order (EVENT_BUFFER at a time) through visit, which returns BK_OK to
 * go on; *count gets the table's length. */
typedef int (*bk_h5_event_visit)(const bk_event *event, unsigned long long row, void *user,
                                 bk_error *err);
int bk_h5_each_event(hid_t file, const char *path, bk_h5_event_visit visit, void *user,
                     hsize_t *count, bk_error *err);
typedef int (*bk_h5_transition_visit)(const bk_transition *t, unsigned long long row, void *user,
                                      bk_error *err);
int bk_h5_each_transition(hid_t file, const char *path, bk_h5_transition_visit visit, void *user,
                          hsize_t *count, bk_error *err);
/* Rows [start, start + count) and columns [col, col + ncols) as mem_type. */
herr_t bk_h5_read_block(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t col,
                        hsize_t ncols, hid_t mem_type, void *buf);
herr_t bk_h5_read_block_xfer(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t col,
                             hsize_t ncols, hid_t mem_type, void *buf, hid_t dxpl);
/* First-dimension chunk size of a chunked dataset; 0 when not chunked. */
hsize_t bk_h5_chunk_rows(hid_t dset);
/* Rows to read at a time when streaming a series of cols columns: whole chunks (a partial
 * chunk would be read and its checksum computed once per piece), about EXPORT_BUDGET values. */
hsize_t bk_h5_slab_rows(hid_t dset, hsize_t cols);

typedef struct bk_h5_name_list {
    char **names;
    size_t count;
} bk_h5_name_list;

/* Root datasets a time-series export can print (numeric, 1-D or 2-D), in creation order
 * when the file tracks it (ours do), else by name; -1 on failure. */
int bk_h5_list_series(hid_t file, bk_h5_name_list *list);
void bk_h5_name_list_free(bk_h5_name_list *list);

/* The datasets the writer created, from the root attribute "datasets"; NULL for a file
 * written before it was recorded.  Malloc'ed, comma-separated. */
char *bk_h5_recorded_datasets(hid_t file);
/* Every name in the comma-separated list is a link in file; else BK_ERR_DAMAGED. */
int bk_h5_require_datasets(hid_t file, const char *path, const char *names, bk_error *err);
/* The config a run stored (file text and --set overrides, any number of them). */
int bk_h5_load_stored_config(hid_t file, const char *path, bk_config **config, bk_error *err);
/* The same with one more --set override after the stored ones (NULL: none). */
int bk_h5_load_stored_config_with(hid_t file, const char *path, const char *extra, bk_config **config,
                                  bk_error *err);

/* --------------------------------------------------------------- checkpoints --- */

/* Write cp into slot 0 (/checkpoint/a) or 1 (/checkpoint/b) of file (named part in a
 * message) with its consistency record and checksum, and flush: the rows it counts must be
 * on disk already. */
int bk_h5_write_checkpoint(hid_t file, const char *part, int slot, const bk_checkpoint *cp,
                           const bk_checkpoint_record *rec, bk_error *err);
/* A dataset transfer that skips Fletcher32 checks; H5P_DEFAULT-like otherwise. */
hid_t bk_h5_unchecked_xfer(void);
/* Rows [start, start + count) of a dataset, reading a chunk whose checksum fails as it is;
 * *unchecked (may be NULL) tells whether that was needed (h5_checkpoint.c says when that is
 * safe). */
herr_t bk_h5_read_rows_lenient(hid_t dset, int rank, hsize_t start, hsize_t count, hsize_t cols,
                               hid_t mem_type, void *buf, int *unchecked);

/* A checkpoint read back from a slot of /checkpoint. */
typedef struct bk_h5_slot {
    bk_checkpoint checkpoint;   /* owned: bk_checkpoint_free */
    bk_checkpoint_record record;
    int index;                  /* 0: /checkpoint/a, 1: /checkpoint/b */
    int legacy;                 /* /checkpoint is an older bksim's, without a record */
} bk_h5_slot;

/* The newest slot of /checkpoint that verifies (checksum, row counts on disk, /time at its
 * last row), for a run of n_blocks blocks.  BK_ERR_INVALID when the file has no
 * /checkpoint, or only a first one cut short; BK_ERR_DAMAGED when no slot verifies (the
 * message gives each slot's fault), or when /checkpoint was written without a consistency
 * record (legacy set: an older bksim's, which cannot be verified). */
int bk_h5_find_checkpoint(hid_t file, const char *path, size_t n_blocks, bk_h5_slot *found,
                          bk_error *err);

/* ------------------------------------------------------------------- verify --- */

/* The integrity check on an open file (see bk_h5_verify). */
int bk_h5_verify_open(hid_t file, const char *path, bk_error *err);

#endif
