/* README's "Layout and development" section against the tree: its file list (the first code
 * block of the section, one line per file, "name  what it holds", nested by indentation
 * under "folder/" lines) names every source, header, script and test program, and names
 * nothing that is not there.  Runs from the repository root, as every test does. */
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "files.h"

#define MAX_NAMES 512
#define MAX_DEPTH 8

typedef struct name_list {
    char *name[MAX_NAMES];
    size_t count;
} name_list;

static void add_name(name_list *list, const char *name)
{
    assert_true(list->count < MAX_NAMES);
    list->name[list->count] = strdup(name);
    assert_non_null(list->name[list->count]);
    list->count++;
}

static int has_name(const name_list *list, const char *name)
{
    for (size_t i = 0; i < list->count; ++i)
        if (strcmp(list->name[i], name) == 0)
            return 1;
    return 0;
}

static void free_names(name_list *list)
{
    for (size_t i = 0; i < list->count; ++i)
        free(list->name[i]);
    list->count = 0;
}

/* The paths the layout block names, folders with their trailing '/'.  A line is
 * "<indent><name>  <description>"; a name ending in '/' opens a folder for the lines indented
 * deeper below it.  Fails on a line that is no such entry (text run on from the line above). */
static void read_layout(const char *readme, name_list *listed)
{
    FILE *f = fopen(readme, "r");
    assert_non_null(f);
    char line[512];
    int in_section = 0, in_block = 0, done = 0, number = 0;
    char folder[MAX_DEPTH][512];
    int folder_indent[MAX_DEPTH];
    int depth = 0;
    while (!done && fgets(line, sizeof line, f)) {
        ++number;
        if (!in_section) {
            in_section = strncmp(line, "## Layout and development", 25) == 0;
            continue;
        }
        if (strncmp(line, "```", 3) == 0) {
            done = in_block;
            in_block = 1;
            continue;
        }
        if (!in_block)
            continue;
        int indent = (int)strspn(line, " ");
        char name[256];
        if (sscanf(line + indent, "%255s", name) != 1)
            fail_msg("README.md:%d: an empty line in the layout block", number);
        /* The name and its description are two spaces apart at least. */
        const char *after = line + indent + strlen(name);
        if (*after != '\n' && strncmp(after, "  ", 2) != 0)
            fail_msg("README.md:%d: '%s' is not \"name  what it holds\" (one line per file)", number, name);
        if (strchr("+-(", name[0]) || strstr(name, "...") != NULL)
            fail_msg("README.md:%d: '%s' continues the line above: give each file its own line", number,
                     name);
        while (depth > 0 && folder_indent[depth - 1] >= indent)
            --depth;
        char path[512];
        int written = snprintf(path, sizeof path, "%s%s", depth > 0 ? folder[depth - 1] : "", name);
        assert_true(written > 0 && (size_t)written < sizeof path);
        add_name(listed, path);
        size_t len = strlen(path);
        if (path[len - 1] == '/') {
            assert_true(depth < MAX_DEPTH);
            memcpy(folder[depth], path, len + 1);
            folder_indent[depth++] = indent;
        }
    }
    fclose(f);
    if (!in_section)
        fail_msg("README.md has no \"## Layout and development\" section");
    if (!done)
        fail_msg("README.md: the layout section's code block is missing or not closed");
}

/* Whether a file in a checked folder must be listed: sources, headers, scripts, the CI
 * script (data, plots and results are described by their folder). */
static int is_listed_kind(const char *name)
{
    const char *dot = strrchr(name, '.');
    if (strcmp(name, "run") == 0)
        return 1; /* .ci/run */
    return dot && (strcmp(dot, ".c") == 0 || strcmp(dot, ".h") == 0 || strcmp(dot, ".sh") == 0 ||
                   strcmp(dot, ".sbatch") == 0);
}

/* Every such file under folder (recursively when deep) into found, as "folder/name". */
static void list_tree(const char *folder, int deep, name_list *found)
{
    DIR *dir = opendir(folder);
    if (!dir)
        fail_msg("cannot open %s", folder);
    struct dirent *entry;
    while ((entry = readdir(dir)) != NULL) {
        if (entry->d_name[0] == '.')
            continue;
        char path[512];
        int written = snprintf(path, sizeof path, "%s%s/", folder, entry->d_name);
        assert_true(written > 0 && (size_t)written < sizeof path);
        path[written - 1] = '\0'; /* the '/' is put back for a folder */
        struct stat st;
        assert_int_equal(stat(path, &st), 0);
        if (S_ISDIR(st.st_mode)) {
            if (deep) {
                path[written - 1] = '/';
                list_tree(path, deep, found);
            }
        } else if (is_listed_kind(entry->d_name)) {
            add_name(found, path);
        }
    }
    closedir(dir);
}

static void test_layout_names_every_file(void **state)
{
    (void)state;
    name_list listed = {0}, found = {0};
    read_layout("README.md", &listed);
    list_tree("src/", 1, &found);
    list_tree("include/bksim/", 0, &found);
    list_tree("scripts/", 1, &found);
    list_tree("tests/", 0, &found);
    list_tree("tests/support/", 0, &found);
    list_tree("tests/long/", 0, &found);
    list_tree("tests/fuzz/", 0, &found);
    list_tree("bench/", 0, &found);
    list_tree(".ci/", 0, &found);
    size_t missing = 0;
    for (size_t i = 0; i < found.count; ++i)
        if (!has_name(&listed, found.name[i])) {
            print_error("README.md's layout section does not name %s\n", found.name[i]);
            ++missing;
        }
    assert_true(found.count > 100);
    assert_int_equal(missing, 0);
    free_names(&listed);
    free_names(&found);
}

static void test_layout_names_nothing_else(void **state)
{
    (void)state;
    name_list listed = {0};
    read_layout("README.md", &listed);
    size_t stale = 0;
    for (size_t i = 0; i < listed.count; ++i)
        if (!path_exists(listed.name[i])) {
            print_error("README.md's layout section names %s, which is not there\n", listed.name[i]);
            ++stale;
        }
    assert_int_equal(stale, 0);
    free_names(&listed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layout_names_every_file),
        cmocka_unit_test(test_layout_names_nothing_else),
    };
    return cmocka_run_group_tests_name("readme", tests, NULL, NULL);
}
