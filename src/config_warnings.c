/* Values that pass every range check but are far outside what the config's other values
 * make plausible, the typos a range cannot catch (velocity = 1 meant as 1e-3 m/s).  They
 * are warnings, not errors: `bksim check --strict` and `run --strict` make them errors.
 *
 * The scales come from the blocks on their own, each a spring-mass oscillator of stiffness
 * k_i = driver stiffness + coupling springs and frequency w_i = sqrt(k_i / m_i): a slip
 * lasts about half a period, pi / w_i, and a block released from its full static load F_s
 * moves at up to F_s / k_i * w_i. */
#include "bksim/config.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "bksim/model.h"

#define BK_PI 3.14159265358979323846

static void say(bk_warning_fn warn, void *user, size_t *count, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static void say(bk_warning_fn warn, void *user, size_t *count, const char *fmt, ...)
{
    char message[BK_ERROR_MESSAGE_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    ++*count;
    if (warn)
        warn(user, message);
}

/* The fastest a block moves when released from its full static load F_s by its own spring,
 * F_s / k * w, the largest over the blocks; 0 when no block has a static threshold (a law
 * without a stuck state creeps instead).  A driver faster than this drags the blocks along
 * (slips still start from rest, so with a small force drop they are slower still). */
static double fastest_slip_speed(const bk_model *m)
{
    double speed = 0.0;
    for (size_t i = 0; i < m->n_blocks; ++i) {
        const bk_block *b = &m->blocks[i];
        const bk_friction_law *law = b->law;
        double k = bk_model_block_stiffness(m, i);
        if (!law || !law->static_threshold || !(k > 0.0))
            continue;
        double state[BK_FRICTION_MAX_STATE] = {0};
        if (law->n_state > 0 && law->state_init)
            law->state_init(b->friction_params, state);
        double v = law->static_threshold(b->friction_params, b->normal_force, state) / k * sqrt(k / b->mass);
        if (v > speed)
            speed = v;
    }
    return speed;
}

/* Half the natural period of the slowest block that sticks and slips: about how long its
 * slips last, which rows must not step over; 0 when no block has a stuck state (a law that
 * creeps has no such scale) and INFINITY when such a block has no spring at all. */
static double slowest_half_period(const bk_model *m)
{
    double half = 0.0;
    for (size_t i = 0; i < m->n_blocks; ++i) {
        const bk_block *b = &m->blocks[i];
        if (!b->law || !b->law->static_threshold)
            continue;
        double k = bk_model_block_stiffness(m, i);
        double t = k > 0.0 ? BK_PI / sqrt(k / b->mass) : INFINITY;
        if (t > half)
            half = t;
    }
    return half;
}

size_t bk_config_warnings(const bk_config *config, bk_warning_fn warn, void *user)
{
    size_t count = 0;
    if (!config || !config->model || config->prescribed)
        return 0;
    const bk_model *m = config->model;
    const char *name = config->source_name ? config->source_name : "config";

    double v_driver = fabs(m->driver.velocity), v_slip = fastest_slip_speed(m);
    if (v_slip > 0.0 && v_driver > v_slip)
        say(warn, user, &count,
            "%s: [driver] velocity = %g m/s is faster than the blocks' own slip speeds (at most "
            "%.3g m/s, a block released from its full static load: F_s / k * natural frequency): "
            "the driver drags them along instead of loading them for stick-slip (mm/s meant?)",
            name, m->driver.velocity, v_slip);

    double slip = slowest_half_period(m), interval = config->output.interval;
    if (interval > 0.0 && slip > 0.0 && isfinite(slip) && interval > slip)
        say(warn, user, &count,
            "%s: [output] interval = %g s is longer than a slip (about %.3g s, half the slowest "
            "block's natural period): the rows can step over whole slips (/transitions still "
            "holds every one)",
            name, interval, slip);

    /* Only an oscillation hides an extremum or a slip inside a step: a block that cannot
     * oscillate (overdamped, or without mass) moves on its friction's time scale, which the
     * error control resolves, so a long max_step there is no mistake. */
    double period = bk_model_damped_period(m);
    if (isfinite(config->solver.max_step) && config->solver.max_step > period)
        say(warn, user, &count,
            "%s: [solver] max_step = %g s is longer than the fastest damped oscillation's period "
            "(%.3g s): a slip-rate extremum, or a whole slip, can hide inside one step (default: "
            "1/8 of it)",
            name, config->solver.max_step, period);
    return count;
}
