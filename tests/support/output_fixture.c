/* The output tests' fixture; see output_fixture.h. */
#include "output_fixture.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/types.h>

#include <hdf5.h>

#include "bk_test.h"
#include "files.h"

int output_fixture_setup(void **state)
{
    output_fixture *f = calloc(1, sizeof *f);
    if (!f)
        return -1;
    if (make_temp_dir(f->dir, sizeof f->dir, "bksim_test_output") != 0) {
        free(f);
        return -1;
    }
    snprintf(f->path, sizeof f->path, "%s/run.h5", f->dir);
    *state = f;
    return 0;
}

int output_fixture_teardown(void **state)
{
    output_fixture *f = *state;
    /* Every HDF5 id the library opened must be closed again, on every path. */
    ssize_t open_ids = H5Fget_obj_count((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL);
    if (open_ids > 0) {
        /* Close them so that one failing test (which skips its own closes) does not fail
         * every later teardown as well. */
        hid_t ids[64];
        ssize_t n = H5Fget_obj_ids((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL, 64, ids);
        for (ssize_t i = 0; i < n; ++i)
            H5Idec_ref(ids[i]);
    }
    remove_tree(f->dir);
    free(f);
    assert_int_equal(open_ids, 0);
    return 0;
}
