/* Test support: two output files hold the same run, bit for bit. */
#ifndef BK_SAME_OUTPUT_H
#define BK_SAME_OUTPUT_H

/* Every time series either file has (read as doubles) and every /transitions row agree
 * bit for bit; a dataset present in one file only fails. */
void assert_same_output(const char *a, const char *b);

#endif
