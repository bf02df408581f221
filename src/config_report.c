/* How the config loader reports a failure: where (file:line, or the --set text) and what,
 * keeping only the earliest in the order a user fixes them (config_loader.h: ranks).  Every
 * other config file reports through these and none of them is called from here. */
#include <stdarg.h>
#include <stdio.h>

#include "config_loader.h"

/* Record a failure at `rank` unless an earlier one is already recorded. */
void bk_config_report(loader *ld, long rank, int status, const char *fmt, ...)
{
    if (rank >= ld->error_rank)
        return;
    ld->error_rank = rank;
    ld->status = status;
    char buf[BK_ERROR_MESSAGE_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    BK_FAIL(ld->err, status, "%s", buf);
}

/* "file:12" or "--set block.mass=0". */
void bk_config_location(const loader *ld, const entry *e, char *buf, size_t len)
{
    if (e->override)
        snprintf(buf, len, "--set %s", e->override);
    else
        snprintf(buf, len, "%s:%d", ld->name, e->line);
}

void bk_config_report_entry(loader *ld, const entry *e, const char *fmt, ...)
{
    if (e->rank >= ld->error_rank)
        return;
    char where[512], what[1792];
    bk_config_location(ld, e, where, sizeof where);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    bk_config_report(ld, e->rank, BK_ERR_CONFIG, "%s: [%s] %s: %s", where, e->section, e->key, what);
}

void bk_config_report_missing(loader *ld, const char *section, const bk_param *param, const key_def *def)
{
    if (RANK_MISSING >= ld->error_rank)
        return; /* an earlier error stands: skip formatting, once per block of a long chain */
    char allowed[1536];
    bk_config_format_allowed(def, param, allowed, sizeof allowed);
    bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [%s] %s: required key missing (allowed: %s)", ld->name,
                     section, param->key, allowed);
}
