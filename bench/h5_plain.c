/* The yardstick for bksim's writer: a plain HDF5 program that writes the datasets of a
 * bksim output file from memory, each with the same type, shape, chunking and filters
 * (its dataset creation property list, copied), one H5Dwrite per dataset, nothing else.
 *
 *   h5_plain SOURCE.h5 DEST.h5
 *
 * Reads every dataset of SOURCE's root group into memory first, then times H5Fcreate ..
 * H5Fclose and an fsync of DEST, as bksim makes its output durable before renaming it.
 * Prints one line: rows (of /time), bytes written, seconds (the writing), read_seconds
 * (main's start to the data in memory), so that a caller timing the whole process can take
 * the reading out and keep what a program holding the data would pay: start-up, HDF5's
 * initialisation, the writing, exit. */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <hdf5.h>

typedef struct dataset {
    char name[64];
    hid_t type, space, dcpl;
    void *data;
    size_t bytes;
} dataset;

typedef struct collection {
    dataset items[64];
    size_t n;
    int failed;
} collection;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static herr_t load(hid_t group, const char *name, const H5L_info_t *info, void *user)
{
    (void)info;
    collection *c = user;
    H5O_info_t object;
    if (H5Oget_info_by_name2(group, name, &object, H5O_INFO_BASIC, H5P_DEFAULT) < 0 ||
        object.type != H5O_TYPE_DATASET)
        return 0;
    if (c->n == sizeof c->items / sizeof c->items[0] || strlen(name) >= sizeof c->items[0].name) {
        c->failed = 1;
        return -1;
    }
    dataset *d = &c->items[c->n];
    hid_t dset = H5Dopen2(group, name, H5P_DEFAULT);
    if (dset < 0) {
        c->failed = 1;
        return -1;
    }
    strcpy(d->name, name);
    d->type = H5Dget_type(dset);
    d->space = H5Dget_space(dset);
    d->dcpl = H5Dget_create_plist(dset);
    hssize_t n = H5Sget_simple_extent_npoints(d->space);
    d->bytes = (size_t)n * H5Tget_size(d->type);
    d->data = malloc(d->bytes ? d->bytes : 1);
    if (!d->data || (n > 0 && H5Dread(dset, d->type, H5S_ALL, H5S_ALL, H5P_DEFAULT, d->data) < 0))
        c->failed = 1;
    H5Dclose(dset);
    c->n++;
    return c->failed ? -1 : 0;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s SOURCE.h5 DEST.h5\n", argv[0]);
        return 2;
    }
    double entered = now();
    static collection c;
    hid_t source = H5Fopen(argv[1], H5F_ACC_RDONLY, H5P_DEFAULT);
    if (source < 0 || H5Literate(source, H5_INDEX_NAME, H5_ITER_INC, NULL, load, &c) < 0 || c.failed) {
        fprintf(stderr, "%s: cannot read the datasets\n", argv[1]);
        return 1;
    }
    H5Fclose(source);

    double start = now();
    hid_t dest = H5Fcreate(argv[2], H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (dest < 0) {
        fprintf(stderr, "%s: cannot create\n", argv[2]);
        return 1;
    }
    size_t bytes = 0;
    long long rows = 0;
    for (size_t k = 0; k < c.n; ++k) {
        dataset *d = &c.items[k];
        hid_t dset = H5Dcreate2(dest, d->name, d->type, d->space, H5P_DEFAULT, d->dcpl, H5P_DEFAULT);
        if (dset < 0 || H5Dwrite(dset, d->type, H5S_ALL, H5S_ALL, H5P_DEFAULT, d->data) < 0) {
            fprintf(stderr, "%s: cannot write /%s\n", argv[2], d->name);
            return 1;
        }
        H5Dclose(dset);
        bytes += d->bytes;
        if (strcmp(d->name, "time") == 0)
            rows = (long long)H5Sget_simple_extent_npoints(d->space);
    }
    if (H5Fclose(dest) < 0) {
        fprintf(stderr, "%s: cannot close\n", argv[2]);
        return 1;
    }
    int fd = open(argv[2], O_RDONLY);
    if (fd < 0 || fsync(fd) != 0) {
        fprintf(stderr, "%s: cannot fsync\n", argv[2]);
        return 1;
    }
    close(fd);
    double seconds = now() - start;
    printf("rows %lld bytes %zu seconds %.6f read_seconds %.6f\n", rows, bytes, seconds,
           start - entered);
    for (size_t k = 0; k < c.n; ++k) {
        free(c.items[k].data);
        H5Tclose(c.items[k].type);
        H5Sclose(c.items[k].space);
        H5Pclose(c.items[k].dcpl);
    }
    return 0;
}
