/* Test support: files and directories of tests that write output (temporary directories,
 * the .part name of an unfinished output). */
#ifndef TEST_FILES_H
#define TEST_FILES_H

#include <stddef.h>
#include <stdio.h>

/* 1 when path names anything (file or directory), else 0. */
int path_exists(const char *path);
/* "<path>.part", where bksim writes until a run finishes; one static buffer, overwritten by
 * the next call. */
char *part_path(const char *path);
/* A fresh directory /tmp/<prefix>_XXXXXX, its name in dir; returns 0, or -1. */
int make_temp_dir(char *dir, size_t size, const char *prefix);
/* A file holding exactly text (replaced if it exists; "" makes it empty); returns 0, or -1. */
int write_text(const char *path, const char *text);
/* cp src dst (dst replaced); returns 0, or -1. */
int copy_file(const char *src, const char *dst);
/* rm -rf path: returns 0 when nothing of it is left (or there was none), else -1. */
int remove_tree(const char *path);
/* Everything written to f so far (a tmpfile()), as a string to free; NULL on failure. */
char *written_text(FILE *f);
/* The whole of the file at path (malloc'ed), NULL when it cannot be read. */
char *file_contents(const char *path);

#endif
