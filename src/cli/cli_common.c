/* What the bksim commands share: help requests and usage errors. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"

int bk_cli_wants_help(int argc, char **argv)
{
    for (int i = 0; i < argc; ++i)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0)
            return 1;
    return 0;
}

int bk_cli_usage_error(const char *command, const char *fmt, ...)
{
    fprintf(stderr, "bksim %s: ", command);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(see `bksim %s --help`)\n", command);
    return EXIT_USAGE;
}

