/* The stick/slip decision at zero velocity (paper Figure 3). */
#include "bksim/modes.h"

#include <math.h>

const char *bk_mode_name(bk_mode mode)
{
    switch (mode) {
    case BK_MODE_STICK:
        return "stick";
    case BK_MODE_SLIP_POS:
        return "slip+";
    case BK_MODE_SLIP_NEG:
        return "slip-";
    }
    return "?";
}

bk_mode bk_mode_at_rest(double applied_force, double static_threshold)
{
    if (fabs(applied_force) <= static_threshold)
        return BK_MODE_STICK;
    return applied_force > 0.0 ? BK_MODE_SLIP_POS : BK_MODE_SLIP_NEG;
}

bk_mode bk_mode_next(bk_mode current, bk_mode_event event, double applied_force,
                     double static_threshold)
{
    switch (event) {
    case BK_EVENT_STOP:
        return bk_mode_at_rest(applied_force, static_threshold);
    case BK_EVENT_BREAKAWAY:
        if (applied_force == 0.0)
            return current;
        return applied_force > 0.0 ? BK_MODE_SLIP_POS : BK_MODE_SLIP_NEG;
    }
    return current;
}
