/* Test support: reading and damaging output files through the plain HDF5 API, so that tests
 * check the files with the library's own code out of the loop. */
#ifndef TEST_H5_RAW_H
#define TEST_H5_RAW_H

#include <stddef.h>

#include <hdf5.h>

/* Scalar attributes (strings variable- or fixed-length; malloc'ed); fail the test when
 * absent. */
char *attr_string(hid_t obj, const char *name);
double attr_double(hid_t obj, const char *name);
long long attr_llong(hid_t obj, const char *name);
int has_link(hid_t file, const char *name);
/* Every dataset in the root group carries non-empty units and description strings; returns
 * how many datasets there are. */
size_t check_all_described(hid_t file);
/* Overwrite one value of a 1-D or 2-D dataset. */
void poke(const char *path, const char *name, hsize_t row, hsize_t col, hid_t mem_type,
          const void *value);
/* Eight bytes of 0xff over the stored chunk of dataset name that holds row, at that row
 * (row_bytes per row): what a disk or a careless tool might do. */
void clobber_chunk(const char *path, const char *name, hsize_t row, size_t row_bytes);

#endif
