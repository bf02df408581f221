/* The state a finished run ended in (its checkpoint at t_end, which every run with restart
 * points writes as it finishes), with the config it ran, for `bksim run --init-from`. */
#include "bksim/output.h"

#include <math.h>
#include <string.h>
#include <sys/stat.h>

#include "bksim/bksim.h"
#include "output/h5_impl.h"

int bk_h5_read_end_state(const char *path, bk_checkpoint *end, bk_config **config, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (!path || !end || !config)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_h5_read_end_state: needs a path, a state and a config pointer");
    memset(end, 0, sizeof *end);
    *config = NULL;
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return BK_FAIL(err, BK_ERR_INVALID, "%s: no such file to start from", path);
    if (bk_output_is_part(path))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: the output of a run that did not finish: continue it (`bksim run --restart %s`), "
                       "then start from the finished file", path, path);
    if (bk_h5_has_signature(path) <= 0)
        return BK_FAIL(err, BK_ERR_INVALID, "%s: not an HDF5 file", path);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0)
        return H5_FAIL(err, "%s: cannot open", path);
    int rc = BK_OK, complete = 0;
    long long n_blocks = 0;
    double t_reached = NAN;
    if (bk_h5_read_numeric_attr(file, "n_blocks", H5T_NATIVE_LLONG, &n_blocks) < 0 || n_blocks < 1)
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: not a bksim output of a chain (no root attribute n_blocks)", path);
    else if (bk_h5_read_numeric_attr(file, "complete", H5T_NATIVE_INT, &complete) < 0 || !complete ||
             bk_h5_read_numeric_attr(file, "t_reached", H5T_NATIVE_DOUBLE, &t_reached) < 0)
        rc = BK_FAIL(err, BK_ERR_INVALID, "%s: not the output of a finished run (complete = 0)", path);
    bk_h5_slot slot;
    memset(&slot, 0, sizeof slot);
    if (rc == BK_OK) {
        rc = bk_h5_find_checkpoint(file, path, (size_t)n_blocks, &slot, err);
        if (rc == BK_ERR_INVALID)
            rc = BK_FAIL(err, BK_ERR_INVALID,
                         "%s: holds no checkpoint, so not the state it ended in (a run writes one at its end "
                         "unless [output] checkpoint_interval and checkpoint_work are both 0)", path);
    }
    if (rc == BK_OK && slot.checkpoint.t != t_reached)
        rc = BK_FAIL(err, BK_ERR_INVALID,
                     "%s: its last checkpoint is at t = %.17g s, before its end t = %.17g s: written by a bksim "
                     "that kept no state at the end; run it again to start from its end", path,
                     slot.checkpoint.t, t_reached);
    if (rc == BK_OK)
        rc = bk_h5_load_stored_config(file, path, config, err);
    bk_h5_close_id(file);
    if (rc != BK_OK) {
        bk_checkpoint_free(&slot.checkpoint);
        return rc;
    }
    *end = slot.checkpoint;
    return BK_OK;
}
