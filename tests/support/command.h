/* Test support: running shell commands, and the bksim binary under test, as a user or a
 * batch script would. */
#ifndef TEST_COMMAND_H
#define TEST_COMMAND_H

/* The binary under test: $BKSIM (make test-asan sets the sanitizer build), else ./bksim. */
const char *bksim_binary(void);
/* Run a shell command, with "./bksim" standing for the binary under test; return its exit
 * status, with stdout+stderr in *output (malloc'ed) unless output is NULL. */
int run_command(const char *command, char **output);
/* Run command and require exit status `status` and `message` somewhere in its output. */
void expect_command(const char *command, int status, const char *message);

#endif
