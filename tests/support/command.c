/* Shell commands for the CLI tests; see command.h. */
#include "command.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "bk_test.h"

const char *bksim_binary(void)
{
    const char *bin = getenv("BKSIM");
    return bin && *bin ? bin : "./bksim";
}

int run_command(const char *command, char **output)
{
    char replaced[4096], full[4200];
    const char *bin = bksim_binary();
    size_t used = 0;
    for (const char *c = command; *c && used + 1 < sizeof replaced;) {
        if (strncmp(c, "./bksim", 7) == 0 && (c[7] == ' ' || c[7] == '\0')) {
            used += (size_t)snprintf(replaced + used, sizeof replaced - used, "%s", bin);
            c += 7;
        } else {
            replaced[used++] = *c++;
        }
    }
    assert_true(used + 1 < sizeof replaced);
    replaced[used] = '\0';
    snprintf(full, sizeof full, "{ %s; } 2>&1", replaced);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    assert_non_null(buf);
    size_t got;
    while ((got = fread(buf + len, 1, cap - len - 1, p)) > 0) {
        len += got;
        if (cap - len < 2) {
            cap *= 2;
            char *grown = realloc(buf, cap);
            assert_non_null(grown);
            buf = grown;
        }
    }
    buf[len] = '\0';
    int status = pclose(p);
    if (output)
        *output = buf;
    else
        free(buf);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void expect_command(const char *command, int status, const char *message)
{
    char *text = NULL;
    int got = run_command(command, &text);
    if (got != status || !strstr(text, message))
        print_error("%s\n-> exit %d, expected %d with \"%s\":\n%s\n", command, got, status, message, text);
    assert_int_equal(got, status);
    assert_non_null(strstr(text, message));
    free(text);
}
