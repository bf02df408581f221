/* `bksim run --restart`: reopen the output of a run that stopped, at its last checkpoint
 * that verifies (h5_checkpoint.c finds it), with every dataset cut back to the rows written
 * up to it, as a writer (h5_writer.c) that appends from there; and whether a .part holds
 * such a checkpoint at all, so that a new run refuses to overwrite restartable work. */
#include "bksim/output.h"

#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <sys/stat.h>

#include "bksim/bksim.h"
#include "output/h5_impl.h"
#include "paths.h"

/* Truncate dset to rows, dropping what was written after the checkpoint.  When the chunk
 * holding the last of those rows fails its checksum (see bk_h5_read_rows_lenient), its rows up to
 * the checkpoint are first written back over it, checks off for the read that write makes,
 * so that it is whole again.  The chunk is rewritten in place, never dropped and written
 * anew: a kill between dropping it and flushing its replacement could lose it from the
 * chunk index, and its rows would read back as zeros. */
static herr_t truncate_rows(hid_t dset, hsize_t rows, hid_t mem_type, size_t row_bytes)
{
    hid_t space = H5Dget_space(dset);
    hsize_t dims[2] = {0, 0};
    int rank = space < 0 ? -1 : H5Sget_simple_extent_dims(space, dims, NULL);
    CLOSE_IDS(rank, space);
    if (rank < 1 || rank > 2 || dims[0] < rows)
        return -1;
    hsize_t chunk = bk_h5_chunk_rows(dset);
    hsize_t start = chunk > 0 ? rows / chunk * chunk : rows;
    herr_t rc = 0;
    if (start < rows) {
        hsize_t count = rows - start;
        void *buf = malloc((size_t)count * row_bytes);
        int unchecked = 0;
        rc = buf ? bk_h5_read_rows_lenient(dset, rank, start, count, dims[1], mem_type, buf, &unchecked) : -1;
        if (rc >= 0 && unchecked) {
            hsize_t offset[2] = {start, 0}, counts[2] = {count, dims[1]};
            hid_t file_space = H5Dget_space(dset);
            hid_t mem_space = H5Screate_simple(rank, counts, NULL);
            hid_t dxpl = bk_h5_unchecked_xfer();
            rc = file_space < 0 || mem_space < 0 || dxpl < 0 ||
                         H5Sselect_hyperslab(file_space, H5S_SELECT_SET, offset, NULL, counts, NULL) < 0
                     ? -1
                     : H5Dwrite(dset, mem_type, mem_space, file_space, dxpl, buf);
            CLOSE_IDS(rc, dxpl, mem_space, file_space);
        }
        free(buf);
    }
    dims[0] = rows;
    return rc < 0 ? rc : H5Dset_extent(dset, dims);
}

int bk_h5_writer_resume(bk_h5_writer **out, const char *path, bk_config **config_out,
                        bk_checkpoint *checkpoint, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (!out || !path || !config_out || !checkpoint)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "bk_h5_writer_resume: needs writer, path, config and checkpoint pointers");
    *out = NULL;
    *config_out = NULL;
    memset(checkpoint, 0, sizeof *checkpoint);
    char *final_path = bk_output_final_path(path);
    if (!final_path)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    bk_h5_writer *w;
    int rc = bk_h5_writer_new(&w, final_path, err);
    free(final_path);
    if (rc != BK_OK)
        return rc;
    struct stat st;
    /* The continued run ends by renaming onto the final name: never over a file not ours. */
    if (stat(w->part, &st) == 0 && (rc = bk_h5_output_replaceable(w->path, 0, err)) != BK_OK) {
        bk_h5_writer_free(w);
        return rc;
    }
    if (stat(w->part, &st) != 0) {
        int complete = 0;
        hid_t done = stat(w->path, &st) == 0 ? H5Fopen(w->path, H5F_ACC_RDONLY, H5P_DEFAULT) : H5I_INVALID_HID;
        if (done >= 0)
            bk_h5_read_numeric_attr(done, "complete", H5T_NATIVE_INT, &complete);
        CLOSE_IDS(0, done);
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: %s", w->part,
                         complete ? "no such file; the run is complete, nothing to restart"
                                  : "no such file to restart from");
        bk_h5_writer_free(w);
        return rc;
    }
    bk_config *config = NULL;
    bk_h5_slot slot;
    memset(&slot, 0, sizeof slot);
    const bk_checkpoint *cp = &slot.checkpoint;
    const bk_checkpoint_record *rec = &slot.record;
    if (bk_output_write_locked(w->part))
        rc = BK_FAIL(err, BK_ERR_IO, BK_OUTPUT_OWNED_MESSAGE, w->part);
    else
        w->file = H5Fopen(w->part, H5F_ACC_RDWR, H5P_DEFAULT);
    if (rc == BK_OK)
        rc = w->file < 0 ? H5_FAIL(err, "%s: cannot open for the restart", w->part) : BK_OK;
    /* HDF5 writes the superblock, which holds the end of allocated space (EOA), last in a
     * flush; a kill inside a flush can leave blocks written past the EOA it records.  Space
     * freed there (a chunk dropped by the truncation below) would then be handed out again
     * and every write to it fail ("addr overflow").  Nothing on disk lies past the end of the
     * file, so moving the EOA there is safe. */
    haddr_t eoa = 0;
    if (rc == BK_OK && H5Fget_eoa(w->file, &eoa) >= 0 && (haddr_t)st.st_size > eoa &&
        H5Fincrement_filesize(w->file, 0) < 0)
        rc = H5_FAIL(err, "%s: cannot extend the allocated space to the end of the file", w->part);
    /* The checkpoint before the config: it needs no variable-length string (see
     * bk_h5_write_fixed_string_attr), so a file without one is refused without reading any. */
    long long n_blocks = 0;
    if (rc == BK_OK && (bk_h5_read_numeric_attr(w->file, "n_blocks", H5T_NATIVE_LLONG, &n_blocks) < 0 ||
                        n_blocks < 1))
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: no valid root attribute n_blocks", w->part);
    if (rc == BK_OK)
        rc = bk_h5_find_checkpoint(w->file, w->part, (size_t)n_blocks, &slot, err);
    if (rc == BK_OK)
        rc = bk_h5_load_stored_config(w->file, w->part, &config, err);
    if (rc == BK_OK && (config->model->n_blocks != cp->n_blocks ||
                        config->model->n_friction_state != cp->n_state))
        rc = BK_FAIL(err, BK_ERR_DAMAGED,
                     "%s: damaged: the checkpoint holds %zu blocks and %zu friction states, the "
                     "stored config makes %zu and %zu", w->part, cp->n_blocks, cp->n_state,
                     config->model->n_blocks, config->model->n_friction_state);
    if (rc == BK_OK) {
        char *names = bk_h5_recorded_datasets(w->file);
        rc = bk_h5_require_datasets(w->file, w->part, names, err);
        free(names);
    }
    if (rc == BK_OK) {
        const bk_model *model = config->model;
        bk_h5_writer_size(w, model, 0.0);
        w->max_bytes = config->output.max_bytes > 0.0 ? config->output.max_bytes : INFINITY;
        hsize_t rows = (hsize_t)rec->rows;
        for (int i = 0; rc == BK_OK && i < BK_N_SERIES; ++i) {
            bk_h5_series *ser = &w->s[i];
            if (H5Lexists(w->file, bk_series[i].name, H5P_DEFAULT) <= 0)
                continue;
            ser->dset = H5Dopen2(w->file, bk_series[i].name, H5P_DEFAULT);
            /* Buffers of the dataset's own chunk rows (chosen for the run it began as). */
            hsize_t chunk[2] = {0, 0};
            hid_t dcpl = ser->dset >= 0 ? H5Dget_create_plist(ser->dset) : H5I_INVALID_HID;
            if (dcpl < 0 || H5Pget_chunk(dcpl, 2, chunk) < 1)
                chunk[0] = 0;
            CLOSE_IDS(0, dcpl);
            if (ser->dset < 0 || bk_h5_writer_series(w, i, model, (size_t)chunk[0]) < 0 ||
                truncate_rows(ser->dset, rows, bk_h5_kind_mem_type(bk_series[i].kind), ser->cols * ser->elem) < 0)
                rc = H5_FAIL(err, "%s: cannot reopen /%s at the checkpoint's %llu rows", w->part,
                             bk_series[i].name, (unsigned long long)rows);
        }
        /* Each table to the rows the checkpoint counts: /transitions by its record, /events
         * and the rupture tables by the catalog it carries (both or neither). */
        long long counts[BK_N_TABLES] = {rec->transition_rows, -1, -1, -1, -1};
        if (cp->catalog) {
            counts[BK_TABLE_EVENTS] = cp->catalog->events;
            long ruptures, block_rows, rate_rows;
            if (bk_ruptures_saved_counts(cp->catalog->rupture_state, (size_t)cp->catalog->rupture_state_count,
                                         &ruptures, &block_rows, &rate_rows) == BK_OK) {
                counts[BK_TABLE_RUPTURES] = ruptures;
                counts[BK_TABLE_RUPTURE_BLOCKS] = block_rows;
                counts[BK_TABLE_RUPTURE_RATE] = rate_rows;
            }
        }
        for (int k = 0; rc == BK_OK && k < BK_N_TABLES; ++k) {
            const char *name = bk_h5_tables[k].name;
            int exists = H5Lexists(w->file, name, H5P_DEFAULT) > 0;
            /* /transitions and /rupture_rate are optional; the other tables go with the
             * catalog the checkpoint carries, both or neither. */
            int optional = k == BK_TABLE_TRANSITIONS || k == BK_TABLE_RUPTURE_RATE;
            if (exists && counts[k] < 0) {
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: /%s exists but the checkpoint holds no "
                             "catalog for it", w->part, name);
                break;
            }
            if (!exists && counts[k] >= 0 && !optional) {
                rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: the checkpoint holds a catalog but there "
                             "is no /%s", w->part, name);
                break;
            }
            if (!exists)
                continue;
            bk_h5_table *t = &w->tables[k];
            int buffered = bk_h5_writer_table(t, (bk_h5_table_kind)k);
            t->dset = H5Dopen2(w->file, name, H5P_DEFAULT);
            if (buffered < 0 || t->dset < 0 ||
                truncate_rows(t->dset, (hsize_t)counts[k], t->mem, bk_h5_tables[k].struct_bytes) < 0)
                rc = H5_FAIL(err, "%s: cannot reopen /%s at the checkpoint", w->part, name);
            t->written = t->committed = (hsize_t)counts[k];
        }
        w->rows = w->committed_rows = rows;
        haddr_t end = 0;
        w->eoa_committed = H5Fget_eoa(w->file, &end) >= 0 ? (double)end : 0.0;
        w->trans_last_t = rec->last_transition_t;
        w->t_written = w->t_buffered = cp->t_last_row;
        /* The next checkpoint goes into the other slot: this one stays the fallback. */
        w->cp_sequence = rec->sequence;
        w->cp_slot = slot.index ^ 1;
        if (rc == BK_OK && (bk_h5_write_int_attr(w->file, "complete", 0) < 0 ||
                            bk_h5_write_double_attr(w->file, "t_reached", w->t_written) < 0 ||
                            (H5Aexists(w->file, "error") > 0 && H5Adelete(w->file, "error") < 0)))
            rc = H5_FAIL(err, "%s: cannot reset the root attributes for the restart", w->part);
    }
    if (rc != BK_OK) {
        bk_h5_writer_close(w);
        bk_h5_writer_free(w);
        bk_checkpoint_free(&slot.checkpoint);
        bk_config_free(config);
        return rc;
    }
    *out = w;
    *config_out = config;
    *checkpoint = slot.checkpoint;
    return BK_OK;
}

int bk_h5_restartable(const char *path, double *t_checkpoint, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (!path || !*path)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_restartable: no output path given");
    char *final_path = bk_output_final_path(path);
    char *part = final_path ? bk_output_part_path(final_path) : NULL;
    free(final_path);
    if (!part)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    struct stat st;
    hid_t file = H5I_INVALID_HID;
    int result = 0;
    if (stat(part, &st) == 0 && S_ISREG(st.st_mode) && bk_h5_has_signature(part) > 0)
        file = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    long long n_blocks = 0;
    if (file >= 0 && bk_h5_read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, &n_blocks) >= 0 &&
        n_blocks > 0 && H5Lexists(file, "checkpoint", H5P_DEFAULT) > 0) {
        bk_h5_slot slot;
        bk_error ignored;
        int found = bk_h5_find_checkpoint(file, part, (size_t)n_blocks, &slot, &ignored);
        if (found == BK_OK) {
            if (t_checkpoint)
                *t_checkpoint = slot.checkpoint.t;
            bk_checkpoint_free(&slot.checkpoint);
            result = 1;
        } else if (found == BK_ERR_NOMEM) {
            result = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory reading /checkpoint", part);
        }
    }
    bk_h5_close_id(file);
    free(part);
    return result;
}
