/* Constant-velocity driver, D(t) = D0 + V t. */
#include "bksim/driver.h"

#include <math.h>

double bk_driver_position(const bk_driver *driver, double t)
{
    return driver->start_position + driver->velocity * t;
}

double bk_driver_velocity(const bk_driver *driver, double t)
{
    (void)t;
    return driver->velocity;
}

double bk_driver_displacement(const bk_driver *driver, double t0, double t1)
{
    return driver->velocity * (t1 - t0);
}

double bk_driver_time_at(const bk_driver *driver, double t0, double position)
{
    double here = bk_driver_position(driver, t0);
    if (position == here)
        return t0;
    if (driver->velocity == 0.0 || (position - here) * driver->velocity < 0.0)
        return INFINITY;
    double t = (position - driver->start_position) / driver->velocity;
    return t < t0 ? t0 : t;
}
