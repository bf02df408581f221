/* `bksim run --restart OUT --set run.t_end=T`: a finished or stopped run made longer.  The
 * file gets the later t_end as one more stored --set override (so that the restart loads the
 * config the longer run has), and a finished file goes back to OUT.part, which the restart
 * then continues from its last checkpoint (a finished run's is at its end). */
#include "bksim/output.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bksim/bksim.h"
#include "output/h5_impl.h"
#include "paths.h"

/* The stored overrides with "run.t_end=T" after them, as the "overrides" attribute holds
 * them (one per line); malloc'ed, NULL when out of memory. */
static char *with_t_end(const char *overrides, double t_end)
{
    const char *before = overrides ? overrides : "";
    size_t len = strlen(before) + 64;
    char *text = malloc(len);
    if (text)
        snprintf(text, len, "%s%srun.t_end=%.17g\n", before,
                 *before && before[strlen(before) - 1] != '\n' ? "\n" : "", t_end);
    return text;
}

/* The run's own t_end (root attribute t_end) into *old_t_end, and the stored config loaded
 * with the later one, to check it (a driver history may be shorter than t_end, say). */
static int check_longer(hid_t file, const char *path, double t_end, double *old_t_end, bk_error *err)
{
    if (bk_h5_read_numeric_attr(file, "t_end", H5T_NATIVE_DOUBLE, old_t_end) < 0)
        return BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: no root attribute t_end", path);
    if (!(t_end > *old_t_end))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: --set run.t_end=%.17g: a restart may only make the run longer than its t_end = %.17g s",
                       path, t_end, *old_t_end);
    char setting[64];
    snprintf(setting, sizeof setting, "run.t_end=%.17g", t_end);
    bk_config *config = NULL;
    int rc = bk_h5_load_stored_config_with(file, path, setting, &config, err);
    bk_config_free(config);
    return rc;
}

int bk_h5_extend_to(const char *path, double t_end, double *old_t_end, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (!path || !isfinite(t_end))
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_extend_to: needs a path and a finite t_end");
    char *final_path = bk_output_final_path(path);
    char *part = final_path ? bk_output_part_path(final_path) : NULL;
    if (!part) {
        free(final_path);
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    }
    struct stat st;
    int finished = stat(part, &st) != 0;
    const char *file_path = finished ? final_path : part;
    int rc = BK_OK;
    hid_t file = H5I_INVALID_HID;
    if (stat(file_path, &st) != 0)
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: no such file to restart from", part);
    else if (bk_output_write_locked(file_path))
        rc = BK_FAIL(err, BK_ERR_IO, BK_OUTPUT_OWNED_MESSAGE, file_path);
    else if ((file = H5Fopen(file_path, H5F_ACC_RDONLY, H5P_DEFAULT)) < 0)
        rc = H5_FAIL(err, "%s: cannot open", file_path);
    char *overrides = NULL;
    long long n_blocks = 0;
    if (rc == BK_OK && (bk_h5_read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, &n_blocks) < 0 || n_blocks < 1))
        rc = BK_FAIL(err, BK_ERR_DAMAGED, "%s: damaged: no valid root attribute n_blocks", file_path);
    if (rc == BK_OK) {
        /* Something to continue from: else the longer run is better run from the start. */
        bk_h5_slot slot;
        rc = bk_h5_find_checkpoint(file, file_path, (size_t)n_blocks, &slot, err);
        if (rc == BK_OK)
            bk_checkpoint_free(&slot.checkpoint);
        else if (rc == BK_ERR_INVALID)
            rc = BK_FAIL(err, BK_ERR_INVALID,
                         "%s: holds no checkpoint to continue from (its run had [output] checkpoint_interval "
                         "and checkpoint_work 0): run the longer scene from the start", file_path);
    }
    if (rc == BK_OK) {
        overrides = bk_h5_read_string_attr(file, "overrides");
        rc = check_longer(file, file_path, t_end, old_t_end, err);
    }
    bk_h5_close_id(file);
    /* The finished file becomes a .part before it is changed: a kill in between leaves a .part
     * that continues to the old t_end, never an OUT that is not what its config says. */
    if (rc == BK_OK && finished && rename(final_path, part) != 0)
        rc = BK_FAIL(err, BK_ERR_IO, "%s: cannot rename to %s: %s", final_path, part, strerror(errno));
    char *longer = rc == BK_OK ? with_t_end(overrides, t_end) : NULL;
    if (rc == BK_OK && !longer)
        rc = BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", part);
    if (rc == BK_OK) {
        file = H5Fopen(part, H5F_ACC_RDWR, H5P_DEFAULT);
        /* The config as shown (`bksim info`), with the new override as a comment line, as
         * every override is shown there. */
        char *shown = file >= 0 ? bk_h5_read_string_attr(file, "config") : NULL;
        size_t len = shown ? strlen(shown) + 64 : 0;
        char *config = shown ? malloc(len) : NULL;
        if (config)
            snprintf(config, len, "%s%s; --set run.t_end=%.17g\n", shown,
                     *shown && shown[strlen(shown) - 1] != '\n' ? "\n" : "", t_end);
        if (file < 0 || bk_h5_write_fixed_string_attr(file, "overrides", longer) < 0 ||
            bk_h5_write_double_attr(file, "t_end", t_end) < 0 ||
            (config && bk_h5_write_fixed_string_attr(file, "config", config) < 0) ||
            H5Fflush(file, H5F_SCOPE_LOCAL) < 0)
            rc = H5_FAIL(err, "%s: cannot store the later t_end", part);
        free(config);
        free(shown);
        bk_h5_close_id(file);
    }
    free(longer);
    free(overrides);
    free(part);
    free(final_path);
    return rc;
}
