/* The small valid config of the CLI tests; see good_config.h. */
#include "good_config.h"

#include <stdio.h>
#include <string.h>

#include "bk_test.h"

static const char *const good_config =
    "[model]\n"
    "n_blocks = 1\n"
    "[block]\n"
    "mass = 1\n"
    "driver_stiffness = 1e4\n"
    "[friction]\n"
    "law = coulomb\n"
    "mu_s = 0.6\n"
    "mu_d = 0.5\n"
    "[driver]\n"
    "velocity = 1e-3\n"
    "[run]\n"
    "t_end = 0.7\n";

void write_good_config(const char *path, const char *line, const char *replacement)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    const char *p = good_config;
    while (*p) {
        const char *eol = strchr(p, '\n');
        size_t len = (size_t)(eol - p);
        if (line && strlen(line) == len && strncmp(p, line, len) == 0) {
            if (replacement)
                fprintf(f, "%s\n", replacement);
        } else {
            fprintf(f, "%.*s\n", (int)len, p);
        }
        p = eol + 1;
    }
    fclose(f);
}
