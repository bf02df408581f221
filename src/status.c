/* bk_strerror and the error record. */
#include "bksim/status.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

const char *bk_strerror(int status)
{
    switch (status) {
#define BK_STATUS_CASE(name, value, text) \
    case value:                           \
        return text;
        BK_STATUS_LIST(BK_STATUS_CASE)
#undef BK_STATUS_CASE
    default:
        return status > 0 ? "informative status" : "unknown error";
    }
}

void bk_error_clear(bk_error *err)
{
    if (!err)
        return;
    memset(err, 0, sizeof *err);
}

int bk_error_set(bk_error *err, int status, const char *src_file, int src_line,
                 const char *src_func, const char *fmt, ...)
{
    if (!err)
        return status;
    err->status = status;
    err->src_file = src_file;
    err->src_line = src_line;
    err->src_func = src_func;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return status;
}
