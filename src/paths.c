/* The file-system side of an output file: its ".part" name while a run writes it, the
 * directories it goes in, and the durable rename that publishes it.  Free of HDF5. */
#define _GNU_SOURCE /* sync_file_range */
#include "paths.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "bksim/output.h"

#define PART_SUFFIX ".part"

int bk_output_is_part(const char *path)
{
    size_t len = strlen(path), suffix = strlen(PART_SUFFIX);
    return len > suffix && strcmp(path + len - suffix, PART_SUFFIX) == 0;
}

char *bk_output_final_path(const char *path)
{
    return bk_output_is_part(path) ? strndup(path, strlen(path) - strlen(PART_SUFFIX)) : strdup(path);
}

char *bk_output_part_path(const char *path)
{
    char *part = malloc(strlen(path) + sizeof PART_SUFFIX);
    if (part)
        sprintf(part, "%s" PART_SUFFIX, path);
    return part;
}

char *bk_output_resolve(const char *path, const char *config_name)
{
    size_t len = strlen(path);
    struct stat st;
    int directory = (len > 0 && path[len - 1] == '/') || (stat(path, &st) == 0 && S_ISDIR(st.st_mode));
    if (!directory)
        return strdup(path);
    const char *base = config_name ? strrchr(config_name, '/') : NULL;
    base = base ? base + 1 : config_name && *config_name ? config_name : "bksim";
    const char *dot = strrchr(base, '.');
    size_t stem = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    char *resolved = malloc(len + stem + sizeof "/.h5");
    if (resolved)
        sprintf(resolved, "%s%s%.*s.h5", path, len > 0 && path[len - 1] == '/' ? "" : "/", (int)stem, base);
    return resolved;
}

/* mkdir -p for the directory part of path. */
int bk_output_make_parent_dirs(const char *path, bk_error *err)
{
    char *dir = strdup(path);
    if (!dir)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", path);
    int rc = BK_OK;
    char *slash = strrchr(dir, '/');
    if (slash && slash != dir) {
        *slash = '\0';
        for (char *p = dir + 1;; ++p) {
            if (*p != '/' && *p != '\0')
                continue;
            char saved = *p;
            *p = '\0';
            if (mkdir(dir, 0777) != 0) {
                /* EEXIST is not the only harmless failure: an existing directory may also
                 * answer EACCES or EROFS, so ask what is there. */
                int e = errno;
                struct stat st;
                if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
                    rc = e == EEXIST
                             ? BK_FAIL(err, BK_ERR_IO,
                                       "%s: cannot create directory %s: exists and is not a "
                                       "directory", path, dir)
                             : BK_FAIL(err, BK_ERR_IO, "%s: cannot create directory %s: %s",
                                       path, dir, strerror(e));
                    break;
                }
            }
            *p = saved;
            if (saved == '\0')
                break;
        }
    }
    free(dir);
    return rc;
}

/* Force a file (or directory) to disk; 0 or an errno.  EINVAL (a file system that cannot
 * sync, such as some FUSE mounts) passes: there is nothing more to be done. */
static int sync_path(const char *path)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return errno;
    int e = fsync(fd) == 0 || errno == EINVAL ? 0 : errno;
    close(fd);
    return e;
}

void bk_output_write_behind(int fd)
{
#ifdef SYNC_FILE_RANGE_WRITE
    /* Best effort: the final fsync still makes the file durable whatever happens here. */
    (void)sync_file_range(fd, 0, 0, SYNC_FILE_RANGE_WRITE);
#else
    (void)fd;
#endif
}

/* The rename of a finished file, made durable: H5Fclose leaves the data in the page cache,
 * and a power cut after the rename could otherwise leave a complete-looking OUT with
 * missing chunks.  The directory sync that makes the new name last is best effort. */
int bk_output_durable_rename(const char *part, const char *path, bk_error *err)
{
    int e = sync_path(part);
    if (e != 0)
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot sync to disk: %s", part, strerror(e));
    if (rename(part, path) != 0) {
        e = errno;
        return BK_FAIL(err, BK_ERR_IO, "%s: cannot rename to %s: %s", part, path, strerror(e));
    }
    char *dir = strdup(path);
    if (dir) {
        char *slash = strrchr(dir, '/');
        if (!slash)
            sync_path(".");
        else {
            slash[slash == dir ? 1 : 0] = '\0';
            sync_path(dir);
        }
        free(dir);
    }
    return BK_OK;
}

int bk_output_set_aside(const char *part, char **kept, bk_error *err)
{
    *kept = NULL;
    size_t size = strlen(part) + 32;
    char *name = malloc(size);
    if (!name)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: out of memory", part);
    struct stat st;
    snprintf(name, size, "%s.damaged", part);
    for (int k = 2; lstat(name, &st) == 0 && k < 1000; ++k)
        snprintf(name, size, "%s.damaged.%d", part, k);
    if (lstat(name, &st) == 0 || rename(part, name) != 0) {
        int e = errno;
        int rc = BK_FAIL(err, BK_ERR_IO, "%s: cannot move it aside to %s: %s", part, name,
                         lstat(name, &st) == 0 ? "999 earlier copies are there" : strerror(e));
        free(name);
        return rc;
    }
    *kept = name;
    return BK_OK;
}

int bk_output_write_locked(const char *path)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return 0;
    int held = flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    close(fd); /* and with it our shared lock */
    return held;
}
