/* Room on disk before every write: a full disk or a file-size limit (EFBIG) met inside one
 * of HDF5's writes can leave chunk indexes and object headers half updated, and then nothing
 * of the .part reads back.  So the writer asks first, with what it is about to write and
 * HDF5's own bookkeeping as a margin, and stops while every write so far has succeeded: the
 * .part then closes cleanly with what was committed and its last checkpoint, which `bksim
 * info` reads and `--restart` continues from.  Room is the file-size limit (RLIMIT_FSIZE)
 * and the free space of the file system (statvfs); another program filling the disk between
 * two looks can still beat it, and the failed write is then reported as before.  The same
 * look keeps the file within [output] max_bytes, chunks and HDF5's metadata included. */
#include <errno.h>
#include <math.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>

#include "h5_impl.h"

/* HDF5's metadata written at a flush or close (object headers, chunk index nodes, the
 * attributes of the file and of /stats): per dataset a few kB, bounded generously. */
static double metadata_margin(void)
{
    return (double)(1u << 20) + 64.0 * 1024.0 * (double)(BK_N_SERIES + BK_N_TABLES);
}

/* What HDF5 adds to a file at a flush or close beyond the chunks it is given, for the
 * [output] max_bytes bound (a soft limit: the file may not pass it, but nothing breaks if a
 * close adds a little). */
#define SOFT_MARGIN (16.0 * 1024.0) /* a close adds 3.5 kB to a 100-block run (stats, error, t_reached) */

int bk_h5_writer_room(bk_h5_writer *w, double bytes, bk_error *err)
{
    haddr_t allocated = 0;
    if (w->file < 0 || H5Fget_eoa(w->file, &allocated) < 0)
        return BK_OK; /* cannot tell: HDF5's own write reports a failure */
    /* What the chunk cache still holds goes to the end of the file at the next flush; what
     * it evicted since is in the allocated end already, so it is counted once. */
    double eoa = fmax((double)allocated, w->eoa_committed + w->unflushed);
    if (eoa + bytes + SOFT_MARGIN > w->max_bytes) {
        w->failed = 1;
        w->out_of_room = 1;
        return BK_FAIL(err, BK_ERR_LIMIT,
                       "%s: [output] max_bytes = %.3g B: the next %.0f bytes would take the file (%.0f bytes now) "
                       "past it, so the run stops here with everything committed up to t = %.17g s (raise "
                       "max_bytes, sample less often, or write fewer fields)",
                       w->part, w->max_bytes, bytes, eoa, w->t_written);
    }
    double margin = metadata_margin();
    /* Twice the margin: one for this write's metadata, one kept for the close that follows
     * a refusal (its attributes and the metadata of everything written so far). */
    double end = eoa + bytes + 2.0 * margin;
    double limit = INFINITY, free_bytes = INFINITY, size = eoa;
    struct rlimit lim;
    if (getrlimit(RLIMIT_FSIZE, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY)
        limit = (double)lim.rlim_cur;
    struct stat st;
    if (stat(w->part, &st) == 0)
        size = (double)st.st_size;
    struct statvfs vfs;
    if (statvfs(w->part, &vfs) == 0)
        free_bytes = (double)vfs.f_bavail * (double)vfs.f_frsize;
    if (end <= limit && end - size <= free_bytes) {
        w->unflushed += bytes; /* the caller writes them now */
        return BK_OK;
    }
    w->failed = 1;
    w->out_of_room = 1;
    char why[160];
    if (end > limit)
        snprintf(why, sizeof why, "the file-size limit (ulimit -f) of %.0f bytes", limit);
    else
        snprintf(why, sizeof why, "the %.0f bytes free on its file system", free_bytes);
    return BK_FAIL(err, BK_ERR_IO,
                   "%s: no room for the next %.0f bytes within %s (the file holds %.0f): stopped before "
                   "writing them, so the .part keeps everything committed up to t = %.17g s and its last "
                   "checkpoint",
                   w->part, bytes + 2.0 * margin, why, size, w->t_written);
}
