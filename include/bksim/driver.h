/* The driver: the rigid support that pulls every block through its driver spring.  It moves
 * at a constant velocity from start_position at t = 0, or along a history of
 * piecewise-constant velocities ([driver] velocities and durations: velocity steps, holds,
 * slide-hold-slide).  A history's breakpoints are where the run restarts every integrator,
 * so between two of them the driver is linear in time and each segment's motion is smooth. */
#ifndef BKSIM_DRIVER_H
#define BKSIM_DRIVER_H

#include <stddef.h>

typedef struct bk_driver {
    double velocity;          /* m/s: the constant velocity; with a history its first non-zero
                                 speed, the scale for tolerances and defaults */
    double start_position;    /* m, position at t = 0; default 0 (at the blocks) */
    size_t n_segments;        /* 0: constant velocity; else the history's segments */
    double *segment_start;    /* s, n_segments + 1: segment k is [start[k], start[k + 1]); the
                                 last one continues past its end */
    double *segment_velocity; /* m/s, n_segments */
    double *segment_position; /* m, n_segments: the position at each segment's start */
} bk_driver;

/* Give the driver a history of n segments (velocities in m/s, durations in s, all > 0) from
 * start_position; velocity becomes the first non-zero speed (0 if none).  Returns 0, or -1
 * when out of memory (the driver unchanged). */
int bk_driver_set_history(bk_driver *driver, const double *velocities, const double *durations, size_t n);
/* Release a history (the driver keeps moving at velocity). */
void bk_driver_free_history(bk_driver *driver);
/* Move the whole schedule so that D(0) = position (a history's segment positions with it). */
void bk_driver_move_start(bk_driver *driver, double position);

/* The segment holding t (the later one at a breakpoint; 0 without a history). */
size_t bk_driver_segment(const bk_driver *driver, double t);
/* Position and velocity at t continuing segment k's straight line (what an integrator
 * between two breakpoints uses, so a step ending on one never sees the next segment). */
double bk_driver_segment_position(const bk_driver *driver, size_t segment, double t);
double bk_driver_segment_velocity(const bk_driver *driver, size_t segment);
/* The first breakpoint after t (s); +INFINITY if none. */
double bk_driver_next_breakpoint(const bk_driver *driver, double t);

double bk_driver_position(const bk_driver *driver, double t);  /* m */
double bk_driver_velocity(const bk_driver *driver, double t);  /* m/s */
/* Earliest time >= t0 at which the driver is at `position`; +INFINITY if never. */
double bk_driver_time_at(const bk_driver *driver, double t0, double position);

#endif
