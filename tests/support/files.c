/* Files and directories for tests; see files.h. */
#include "files.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    int failed = fputs(text, f) == EOF && *text != '\0';
    return fclose(f) != 0 || failed ? -1 : 0;
}

int path_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

char *part_path(const char *path)
{
    static char part[256];
    snprintf(part, sizeof part, "%s.part", path);
    return part;
}

int make_temp_dir(char *dir, size_t size, const char *prefix)
{
    int len = snprintf(dir, size, "/tmp/%s_XXXXXX", prefix);
    if (len < 0 || (size_t)len >= size)
        return -1;
    return mkdtemp(dir) ? 0 : -1;
}

int copy_file(const char *src, const char *dst)
{
    FILE *in = fopen(src, "rb");
    FILE *out = in ? fopen(dst, "wb") : NULL;
    int rc = in && out ? 0 : -1;
    char buf[1 << 16];
    size_t n;
    while (rc == 0 && (n = fread(buf, 1, sizeof buf, in)) > 0)
        if (fwrite(buf, 1, n, out) != n)
            rc = -1;
    if (in && ferror(in))
        rc = -1;
    if (in)
        fclose(in);
    if (out && fclose(out) != 0)
        rc = -1;
    return rc;
}

int remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0)
        return errno == ENOENT ? 0 : -1;
    if (!S_ISDIR(st.st_mode))
        return unlink(path) == 0 ? 0 : -1;
    int rc = 0;
    DIR *d = opendir(path);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            char child[512];
            int len = snprintf(child, sizeof child, "%s/%s", path, e->d_name);
            if (len < 0 || (size_t)len >= sizeof child || remove_tree(child) != 0)
                rc = -1;
        }
        closedir(d);
    } else {
        rc = -1;
    }
    return rmdir(path) == 0 ? rc : -1;
}

char *written_text(FILE *f)
{
    long size = ftell(f);
    if (size < 0 || fseek(f, 0, SEEK_SET) != 0)
        return NULL;
    char *text = calloc((size_t)size + 1, 1);
    if (text && fread(text, 1, (size_t)size, f) != (size_t)size) {
        free(text);
        return NULL;
    }
    return text;
}

char *file_contents(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *text = fseek(f, 0, SEEK_END) == 0 ? written_text(f) : NULL;
    fclose(f);
    return text;
}
