/* Whether a run may write over a path: only bksim's own outputs are ever replaced.  A run
 * told `-o c.ini` or `-o notes.txt` would otherwise turn the user's file into HDF5 at its
 * end (the .part is renamed over it), whatever the flags. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "h5_impl.h"

/* The root attributes every bksim output has from its first flush on (h5_writer.c). */
static int has_bksim_root(const char *path)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    /* A finished output has no writer; no lock is needed to look at its attributes. */
    hid_t file = fapl >= 0 && H5Pset_file_locking(fapl, 0, 1) >= 0 ? H5Fopen(path, H5F_ACC_RDONLY, fapl)
                                                                    : H5I_INVALID_HID;
    CLOSE_IDS(0, fapl);
    if (file < 0)
        return 0;
    int ours = H5Aexists(file, "config") > 0 && H5Aexists(file, "version") > 0 &&
               H5Aexists(file, "n_blocks") > 0;
    CLOSE_IDS(0, file);
    return ours;
}

/* A .part is bksim's working name: one a run was killed in while creating it may be empty, or
 * hold HDF5's signature and not yet the attributes; it is replaced like a stopped run's. */
static int working_file_of_ours(const char *path, off_t size)
{
    if (size == 0)
        return 1;
    static const unsigned char signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8];
    FILE *f = fopen(path, "rb");
    size_t got = f ? fread(head, 1, sizeof head, f) : 0;
    if (f)
        fclose(f);
    return got == sizeof head && memcmp(head, signature, sizeof head) == 0;
}

int bk_h5_output_replaceable(const char *path, int working, bk_error *err)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    struct stat st;
    if (lstat(path, &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) /* nothing there (making the directories says more) */
            return BK_OK;
        int e = errno;
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot look at what is there: %s", path, strerror(e));
    }
    if (S_ISLNK(st.st_mode) && stat(path, &st) != 0)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: is a dangling symbolic link, not a bksim output: bksim replaces only its own "
                       "outputs (choose another -o, or remove it)",
                       path);
    if (S_ISDIR(st.st_mode))
        return BK_FAIL(err, BK_ERR_INVALID, "%s: is a directory; give an output file name", path);
    if (!S_ISREG(st.st_mode))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s: is not a regular file: bksim replaces only its own outputs (choose another -o)",
                       path);
    if (has_bksim_root(path) || (working && working_file_of_ours(path, st.st_size)))
        return BK_OK;
    return BK_FAIL(err, BK_ERR_INVALID,
                   "%s: exists and is not a bksim output (%s): bksim replaces only its own outputs, "
                   "whatever the flags (choose another -o, or move the file away)",
                   path,
                   H5Fis_hdf5(path) > 0 ? "an HDF5 file without bksim's root attributes" : "not an HDF5 file");
}
