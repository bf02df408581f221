/* Test support: the small valid config the CLI tests start from (case A's block under
 * Coulomb friction, driven at 1 mm/s for 0.7 s), written whole or with one line changed. */
#ifndef TEST_GOOD_CONFIG_H
#define TEST_GOOD_CONFIG_H

/* Write the config to path with `line` replaced by `replacement` (NULL: dropped; a
 * replacement may hold several lines); line NULL writes it as it is. */
void write_good_config(const char *path, const char *line, const char *replacement);

#endif
