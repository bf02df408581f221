/* Exact single-block Coulomb motion; see exact_single.h. */
#include "exact_single.h"

#include <math.h>
#include <stdlib.h>

#define PI 3.14159265358979323846

/* Smallest theta > theta_min with P sin(theta) + Q cos(theta) = r, or INFINITY. */
static double first_angle(double P, double Q, double r, double theta_min)
{
    double M = hypot(P, Q);
    if (M == 0.0 || fabs(r) > M)
        return INFINITY;
    double gamma = atan2(Q, P); /* P sin + Q cos = M sin(theta + gamma) */
    const double base[2] = {asin(r / M), PI - asin(r / M)};
    double best = INFINITY;
    for (int b = 0; b < 2; ++b)
        for (int n = -2; n <= 3; ++n) {
            double theta = base[b] - gamma + 2.0 * PI * n;
            if (theta > theta_min && theta < best)
                best = theta;
        }
    return best;
}

static int push_phase(exact_solution *s, exact_phase ph)
{
    exact_phase *grown = realloc(s->phases, (s->n_phases + 1) * sizeof *grown);
    if (!grown)
        return -1;
    s->phases = grown;
    s->phases[s->n_phases++] = ph;
    return 0;
}

static int push_event(exact_solution *s, exact_event ev)
{
    exact_event *grown = realloc(s->events, (s->n_events + 1) * sizeof *grown);
    if (!grown)
        return -1;
    s->events = grown;
    s->events[s->n_events++] = ev;
    return 0;
}

static void harmonic(const exact_params *p, const exact_phase *ph, double tau, double *e, double *v)
{
    double w = sqrt(p->stiffness / p->mass);
    double c = p->mu_d * p->normal / p->stiffness;
    double V = p->velocity;
    double cw = cos(w * tau), sw = sin(w * tau);
    *e = c + (ph->e0 - c) * cw + (V - ph->v0) / w * sw;
    double de = -(ph->e0 - c) * w * sw + (V - ph->v0) * cw;
    *v = V - de;
}

void exact_state(const exact_solution *s, double t, double *x, double *v)
{
    size_t k = 0;
    while (k + 1 < s->n_phases && s->phases[k + 1].t0 <= t)
        ++k;
    const exact_phase *ph = &s->phases[k];
    const exact_params *p = &s->p;
    double tau = t - ph->t0;
    switch (ph->kind) {
    case EXACT_STUCK:
        *x = ph->x0;
        *v = 0.0;
        return;
    case EXACT_HARMONIC: {
        double e;
        harmonic(p, ph, tau, &e, v);
        *x = p->velocity * t - e;
        return;
    }
    default: {
        double decel = p->mu_d * p->normal / p->mass;
        *x = ph->x0 + ph->v0 * tau - 0.5 * decel * tau * tau;
        *v = ph->v0 - decel * tau;
        return;
    }
    }
}

int exact_solve(const exact_params *p, double t_end, exact_solution *out)
{
    exact_solution s = {*p, NULL, 0, NULL, 0};
    double w = sqrt(p->stiffness / p->mass);
    double V = p->velocity;
    double k = p->stiffness;
    double fs = p->mu_s * p->normal, fk = p->mu_d * p->normal;
    double c = fk / k;
    exact_phase ph = {EXACT_STUCK, 0.0, 0.0, 0.0, 0.0};
    if (push_phase(&s, ph))
        goto fail;
    while (ph.t0 < t_end) {
        exact_phase next;
        if (ph.kind == EXACT_STUCK) {
            double t1 = ph.t0 + (fs / k - ph.e0) / V;
            if (t1 >= t_end)
                break;
            next = (exact_phase){EXACT_HARMONIC, t1, ph.x0, 0.0, fs / k};
            if (push_event(&s, (exact_event){t1, 0, 1, ph.x0, fs}))
                goto fail;
        } else if (ph.kind == EXACT_HARMONIC) {
            /* stop: v = 0, i.e. (e0 - c) w sin + (v0 - V) cos = -V */
            double th_stop = first_angle((ph.e0 - c) * w, ph.v0 - V, -V, 1e-9);
            double th_slack = INFINITY;
            if (p->tension_only) /* e = 0: ((V - v0)/w) sin + (e0 - c) cos = -c */
                th_slack = first_angle((V - ph.v0) / w, ph.e0 - c, -c, 1e-9);
            if (!isfinite(th_stop) && !isfinite(th_slack))
                goto fail;
            double th = th_slack < th_stop ? th_slack : th_stop;
            double t1 = ph.t0 + th / w, e, v;
            if (t1 >= t_end)
                break;
            harmonic(p, &ph, th / w, &e, &v);
            double x1 = V * t1 - e;
            if (th_slack < th_stop) {
                next = (exact_phase){EXACT_SLACK, t1, x1, v, 0.0};
            } else {
                double force = k * (p->tension_only && e < 0 ? 0.0 : e);
                if (fabs(force) > fs)
                    goto fail; /* a reversal: not derived here */
                next = (exact_phase){EXACT_STUCK, t1, x1, 0.0, e};
                if (push_event(&s, (exact_event){t1, 1, 0, x1, force}))
                    goto fail;
            }
        } else {
            double decel = fk / p->mass;
            double t_stop = ph.v0 / decel;
            double t_taut = ph.v0 > V ? 2.0 * (ph.v0 - V) / decel : 0.0;
            if (t_taut > 0.0 && t_taut < t_stop) {
                double t1 = ph.t0 + t_taut;
                if (t1 >= t_end)
                    break;
                double x1 = ph.x0 + ph.v0 * t_taut - 0.5 * decel * t_taut * t_taut;
                next = (exact_phase){EXACT_HARMONIC, t1, x1, ph.v0 - decel * t_taut, 0.0};
            } else {
                double t1 = ph.t0 + t_stop;
                if (t1 >= t_end)
                    break;
                double x1 = ph.x0 + 0.5 * ph.v0 * t_stop;
                double e = V * t1 - x1;
                next = (exact_phase){EXACT_STUCK, t1, x1, 0.0, e};
                if (push_event(&s, (exact_event){t1, 1, 0, x1, e > 0 ? k * e : 0.0}))
                    goto fail;
            }
        }
        ph = next;
        if (push_phase(&s, ph))
            goto fail;
    }
    *out = s;
    return 0;
fail:
    exact_free(&s);
    return -1;
}

void exact_free(exact_solution *s)
{
    free(s->phases);
    free(s->events);
    s->phases = NULL;
    s->events = NULL;
    s->n_phases = s->n_events = 0;
}
