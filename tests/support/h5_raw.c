/* Plain-HDF5 checks and damage; see h5_raw.h. */
#include "h5_raw.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include "bk_test.h"

char *attr_string(hid_t obj, const char *name)
{
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(attr >= 0);
    hid_t type = H5Aget_type(attr);
    assert_int_equal(H5Tget_class(type), H5T_STRING);
    char *copy;
    if (H5Tis_variable_str(type) > 0) {
        char *text = NULL;
        assert_true(H5Aread(attr, type, &text) >= 0);
        copy = strdup(text);
        H5free_memory(text);
    } else {
        /* Text written after the file was created is fixed-length (see the writer). */
        size_t size = H5Tget_size(type);
        copy = calloc(size + 1, 1);
        assert_non_null(copy);
        assert_true(H5Aread(attr, type, copy) >= 0);
    }
    H5Tclose(type);
    H5Aclose(attr);
    return copy;
}

double attr_double(hid_t obj, const char *name)
{
    double v = NAN;
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(attr >= 0);
    assert_true(H5Aread(attr, H5T_NATIVE_DOUBLE, &v) >= 0);
    H5Aclose(attr);
    return v;
}

long long attr_llong(hid_t obj, const char *name)
{
    long long v = -1;
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(attr >= 0);
    assert_true(H5Aread(attr, H5T_NATIVE_LLONG, &v) >= 0);
    H5Aclose(attr);
    return v;
}

int has_link(hid_t file, const char *name)
{
    return H5Lexists(file, name, H5P_DEFAULT) > 0;
}

/* Every dataset in the root group carries non-empty units and description strings. */
size_t check_all_described(hid_t file)
{
    H5G_info_t info;
    assert_true(H5Gget_info(file, &info) >= 0);
    size_t datasets = 0;
    for (hsize_t i = 0; i < info.nlinks; ++i) {
        char name[64];
        assert_true(H5Lget_name_by_idx(file, ".", H5_INDEX_NAME, H5_ITER_INC, i, name,
                                       sizeof name, H5P_DEFAULT) > 0);
        hid_t obj = H5Oopen(file, name, H5P_DEFAULT);
        assert_true(obj >= 0);
        if (H5Iget_type(obj) == H5I_DATASET) {
            ++datasets;
            char *units = attr_string(obj, "units");
            char *description = attr_string(obj, "description");
            if (!units[0] || !description[0])
                fail_msg("/%s: empty units or description", name);
            free(units);
            free(description);
        }
        H5Oclose(obj);
    }
    return datasets;
}

/* Overwrite one value of a 1-D or 2-D dataset through the plain HDF5 API. */
void poke(const char *path, const char *name, hsize_t row, hsize_t col, hid_t mem_type,
                 const void *value)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t dset = H5Dopen2(file, name, H5P_DEFAULT);
    assert_true(dset >= 0);
    hid_t space = H5Dget_space(dset);
    int rank = H5Sget_simple_extent_ndims(space);
    hsize_t offset[2] = {row, col}, count[2] = {1, 1};
    assert_true(H5Sselect_hyperslab(space, H5S_SELECT_SET, offset, NULL, count, NULL) >= 0);
    hid_t mem = H5Screate_simple(rank, count, NULL);
    assert_true(H5Dwrite(dset, mem_type, mem, space, H5P_DEFAULT, value) >= 0);
    H5Sclose(mem);
    H5Sclose(space);
    H5Dclose(dset);
    H5Fclose(file);
}

/* Eight bytes of 0xff written over the stored chunk of dataset name that holds row, at that
 * row (row_bytes per row): what a disk or a careless tool might do. */
void clobber_chunk(const char *path, const char *name, hsize_t row, size_t row_bytes)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t dset = H5Dopen2(file, name, H5P_DEFAULT);
    assert_true(dset >= 0);
    hid_t dcpl = H5Dget_create_plist(dset);
    hsize_t chunk[2] = {0, 0};
    assert_true(H5Pget_chunk(dcpl, 2, chunk) >= 1);
    H5Pclose(dcpl);
    hsize_t origin[2] = {row / chunk[0] * chunk[0], 0};
    unsigned mask = 0;
    haddr_t addr = HADDR_UNDEF;
    hsize_t size = 0;
    assert_true(H5Dget_chunk_info_by_coord(dset, origin, &mask, &addr, &size) >= 0);
    assert_true(addr != HADDR_UNDEF && size > 0);
    H5Dclose(dset);
    H5Fclose(file);
    off_t at = (off_t)(addr + (row - origin[0]) * row_bytes);
    assert_true((hsize_t)(row - origin[0]) * row_bytes + 8 <= size);
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    assert_int_equal(fseeko(f, at, SEEK_SET), 0);
    static const unsigned char ff[8] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
    assert_int_equal(fwrite(ff, 1, 8, f), 8);
    fclose(f);
}
