/* A declarative parameter: one row drives parsing, validation and the documentation. */
#ifndef BKSIM_PARAM_H
#define BKSIM_PARAM_H

#include <stddef.h>

enum {
    BK_PARAM_REQUIRED = 1u << 0,      /* no default: the config must set it */
    BK_PARAM_MIN_EXCLUSIVE = 1u << 1, /* value must be > min (else >= min) */
    BK_PARAM_MAX_EXCLUSIVE = 1u << 2, /* value must be < max (else <= max) */
    BK_PARAM_DERIVED = 1u << 3        /* default computed from other values (doc says how) */
};

typedef struct bk_param {
    const char *key;      /* INI key */
    const char *unit;     /* SI unit, "1" for dimensionless */
    double default_value; /* used when absent and neither REQUIRED nor DERIVED */
    double min, max;      /* allowed range (inclusive unless flagged) */
    unsigned flags;
    const char *doc;      /* one-line meaning */
} bk_param;

/* 1 when value lies in the parameter's range (NaN and +-inf never do). */
int bk_param_in_range(const bk_param *param, double value);

/* Writes e.g. "0 < mass < inf kg" into buf. */
void bk_param_format_range(const bk_param *param, char *buf, size_t len);

#endif
