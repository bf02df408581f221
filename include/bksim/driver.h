/* The driver: the rigid support that pulls every block through its driver spring.
 * Its position is a function of time, so later scenes can prescribe holds and steps;
 * today it moves at constant velocity from start_position at t = 0. */
#ifndef BKSIM_DRIVER_H
#define BKSIM_DRIVER_H

typedef struct bk_driver {
    double velocity;       /* m/s, constant */
    double start_position; /* m, position at t = 0; default 0 (at the blocks) */
} bk_driver;

double bk_driver_position(const bk_driver *driver, double t);  /* m */
double bk_driver_velocity(const bk_driver *driver, double t);  /* m/s */
/* Driver displacement from t0 to t1, computed without cancellation of large positions. */
double bk_driver_displacement(const bk_driver *driver, double t0, double t1);
/* Earliest time >= t0 at which the driver is at `position`; +INFINITY if never. */
double bk_driver_time_at(const bk_driver *driver, double t0, double position);

#endif
