/* Test support: two output files hold the same run, bit for bit. */
#ifndef BK_SAME_OUTPUT_H
#define BK_SAME_OUTPUT_H

#include "bksim/catalog.h"

/* Every time series either file has (read as doubles), every /transitions row and every
 * /events row agree bit for bit; a dataset present in one file only fails. */
void assert_same_output(const char *a, const char *b);
/* Two events agree bit for bit, field by field (the struct has padding). */
void assert_same_event(const bk_event *a, const bk_event *b);

#endif
