/* Test support: two output files hold the same run, bit for bit. */
#ifndef BK_SAME_OUTPUT_H
#define BK_SAME_OUTPUT_H

#include "bksim/catalog.h"

/* Every time series either file has (read as doubles), every /transitions row, every
 * /events row and the rupture tables agree bit for bit; a dataset present in one file only
 * fails. */
void assert_same_output(const char *a, const char *b);
/* Two events agree bit for bit, field by field (the struct has padding). */
void assert_same_event(const bk_event *a, const bk_event *b);
/* /ruptures, /rupture_blocks and /rupture_rate agree bit for bit (or neither file has them). */
void assert_same_ruptures(const char *a, const char *b);

#endif
