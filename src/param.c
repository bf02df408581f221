/* Range checks and range text for declarative parameters. */
#include "bksim/param.h"

#include <math.h>
#include <stdio.h>

int bk_param_in_range(const bk_param *param, double value)
{
    if (!isfinite(value))
        return 0;
    if (param->flags & BK_PARAM_MIN_EXCLUSIVE ? !(value > param->min) : !(value >= param->min))
        return 0;
    if (param->flags & BK_PARAM_MAX_EXCLUSIVE ? !(value < param->max) : !(value <= param->max))
        return 0;
    return 1;
}

void bk_param_format_range(const bk_param *param, char *buf, size_t len)
{
    const char *lo_op = param->flags & BK_PARAM_MIN_EXCLUSIVE ? "<" : "<=";
    const char *hi_op = param->flags & BK_PARAM_MAX_EXCLUSIVE ? "<" : "<=";
    const char *unit = param->unit && param->unit[0] && param->unit[0] != '1' ? param->unit : "";
    if (isinf(param->max))
        snprintf(buf, len, "%.10g %s %s < inf%s%s", param->min, lo_op, param->key,
                 unit[0] ? " " : "", unit);
    else
        snprintf(buf, len, "%.10g %s %s %s %.10g%s%s", param->min, lo_op, param->key, hi_op,
                 param->max, unit[0] ? " " : "", unit);
}
