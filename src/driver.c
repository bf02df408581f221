/* The driver's position: D(t) = D0 + V t, or along a history of piecewise-constant
 * velocities, D(t) = D_k + V_k (t - t_k) in segment k (see bksim/driver.h). */
#include "bksim/driver.h"

#include <math.h>
#include <stdlib.h>

int bk_driver_set_history(bk_driver *driver, const double *velocities, const double *durations, size_t n)
{
    /* One block: the starts (n + 1), then velocities and positions (n each). */
    double *block = malloc((3 * n + 1) * sizeof *block);
    if (!block || n == 0) {
        free(block);
        return -1;
    }
    bk_driver_free_history(driver);
    driver->n_segments = n;
    driver->segment_start = block;
    driver->segment_velocity = block + n + 1;
    driver->segment_position = block + 2 * n + 1;
    driver->segment_start[0] = 0.0;
    driver->segment_position[0] = driver->start_position;
    driver->velocity = 0.0;
    for (size_t k = 0; k < n; ++k) {
        driver->segment_velocity[k] = velocities[k];
        driver->segment_start[k + 1] = driver->segment_start[k] + durations[k];
        if (k + 1 < n)
            driver->segment_position[k + 1] = driver->segment_position[k] + velocities[k] * durations[k];
        if (driver->velocity == 0.0)
            driver->velocity = velocities[k];
    }
    return 0;
}

void bk_driver_free_history(bk_driver *driver)
{
    free(driver->segment_start);
    driver->segment_start = driver->segment_velocity = driver->segment_position = NULL;
    driver->n_segments = 0;
}

void bk_driver_move_start(bk_driver *driver, double position)
{
    double shift = position - driver->start_position;
    driver->start_position = position;
    for (size_t k = 0; k < driver->n_segments; ++k)
        driver->segment_position[k] += shift;
    if (driver->n_segments > 0)
        driver->segment_position[0] = position; /* exactly, not by the sum */
}

size_t bk_driver_segment(const bk_driver *driver, double t)
{
    size_t n = driver->n_segments;
    if (n <= 1)
        return 0;
    /* The last k < n with start[k] <= t: binary search, a history may be long. */
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (driver->segment_start[mid] <= t)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

double bk_driver_segment_position(const bk_driver *driver, size_t segment, double t)
{
    if (driver->n_segments == 0)
        return driver->start_position + driver->velocity * t;
    return driver->segment_position[segment] +
           driver->segment_velocity[segment] * (t - driver->segment_start[segment]);
}

double bk_driver_segment_velocity(const bk_driver *driver, size_t segment)
{
    return driver->n_segments == 0 ? driver->velocity : driver->segment_velocity[segment];
}

double bk_driver_next_breakpoint(const bk_driver *driver, double t)
{
    if (driver->n_segments <= 1)
        return INFINITY;
    size_t k = bk_driver_segment(driver, t);
    return k + 1 < driver->n_segments ? driver->segment_start[k + 1] : INFINITY;
}

double bk_driver_position(const bk_driver *driver, double t)
{
    return bk_driver_segment_position(driver, bk_driver_segment(driver, t), t);
}

double bk_driver_velocity(const bk_driver *driver, double t)
{
    return bk_driver_segment_velocity(driver, bk_driver_segment(driver, t));
}

/* Earliest time in [t0, t_end) when the straight line through (t0, here) at velocity v
 * reaches position; +INFINITY if not before t_end. */
static double time_on_line(double t0, double here, double v, double position, double t_end)
{
    if (position == here)
        return t0;
    if (v == 0.0 || (position - here) * v < 0.0)
        return INFINITY;
    double t = t0 + (position - here) / v;
    return t < t_end ? t : INFINITY;
}

double bk_driver_time_at(const bk_driver *driver, double t0, double position)
{
    if (driver->n_segments == 0) {
        double here = bk_driver_position(driver, t0);
        if (position == here)
            return t0;
        if (driver->velocity == 0.0 || (position - here) * driver->velocity < 0.0)
            return INFINITY;
        double t = (position - driver->start_position) / driver->velocity;
        return t < t0 ? t0 : t;
    }
    size_t first = bk_driver_segment(driver, t0);
    for (size_t k = first; k < driver->n_segments; ++k) {
        double from = k == first ? t0 : driver->segment_start[k];
        double end = k + 1 < driver->n_segments ? driver->segment_start[k + 1] : INFINITY;
        double t = time_on_line(from, bk_driver_segment_position(driver, k, from), driver->segment_velocity[k],
                                position, end);
        if (t < INFINITY)
            return t;
    }
    return INFINITY;
}
