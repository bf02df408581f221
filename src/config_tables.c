/* The files a config names beside itself (a per-block profile, a driver history): where they
 * are and how they are opened.  Below config_random.c and config_history.c, which read them. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "config_loader.h"

void bk_config_path_near(const loader *ld, const char *path, char *buf, size_t len)
{
    const char *slash = strrchr(ld->name, '/');
    if (path[0] == '/' || !slash)
        snprintf(buf, len, "%s", path);
    else
        snprintf(buf, len, "%.*s/%s", (int)(slash - ld->name), ld->name, path);
}

FILE *bk_config_open_table(loader *ld, const entry *e, const char *path, long max_bytes, const char *what)
{
    struct stat st;
    if (stat(path, &st) == 0 && (!S_ISREG(st.st_mode) || st.st_size > max_bytes)) {
        bk_config_report_entry(ld, e, "%s: %s (allowed: a regular file of at most %ld MB)", path,
                               S_ISREG(st.st_mode) ? "too large" : "not a regular file", max_bytes >> 20);
        return NULL;
    }
    FILE *f = fopen(path, "r");
    if (!f)
        bk_config_report_entry(ld, e, "%s: cannot open the %s: %s (a relative path is taken from the config file's "
                               "directory)", path, what, strerror(errno));
    return f;
}
