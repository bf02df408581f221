/* Internal to the bksim command line: exit statuses, the helpers every command uses
 * (cli_common.c) and the commands that read outputs (catalog_commands.c). */
#ifndef BKSIM_CLI_H
#define BKSIM_CLI_H

/* Exit statuses: 0 success, 1 the run or the file failed (or is damaged), 2 bad usage or
 * bad config, 3 (info) an intact file of a run that did not finish. */
enum { EXIT_RUN_FAILED = 1, EXIT_USAGE = 2, EXIT_INCOMPLETE = 3 };

/* ---- cli_common.c ---- */
/* argv holds --help or -h. */
int bk_cli_wants_help(int argc, char **argv);
/* "bksim COMMAND: message" and a pointer to its --help on stderr; returns EXIT_USAGE. */
int bk_cli_usage_error(const char *command, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* ---- catalog_commands.c ---- */
/* bksim export, stats, compare and summary with their arguments (after the command word);
 * the exit status. */
int bk_cli_export(int argc, char **argv);
int bk_cli_stats(int argc, char **argv);
int bk_cli_compare(int argc, char **argv);
int bk_cli_summary(int argc, char **argv);

/* ---- fronts_command.c ---- */
/* bksim fronts with its arguments (after the command word); the exit status. */
int bk_cli_fronts(int argc, char **argv);

#endif
