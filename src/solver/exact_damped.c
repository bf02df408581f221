/* The exact stepper's damped modal basis: phi_1 .. phi_4 of one damped mode
 *
 *     eta'' + gamma eta' + w^2 eta = f(tau),   phi_1 its impulse response (phi_1(0) = 0,
 *     phi_1'(0) = 1), phi_{j+1}(tau) = integral of phi_j from 0,
 *
 * so that (exact.c's header) eta = c phi1 + (g + gamma c) phi2 + d phi3 for eta(0) = 0,
 * eta'(0) = c, eta''(0) = g and a forcing rate d.  With sigma = gamma / 2 the roots of the
 * characteristic polynomial are -sigma +- i nu (underdamped, nu^2 = w^2 - sigma^2),
 * -sigma +- mu (overdamped, mu^2 = sigma^2 - w^2) or -sigma twice (critical).
 *
 * Why three formulations.  Each closed form loses digits somewhere, and the motion is
 * continuous across critical damping, so the choice goes by where each is accurate, with
 * x = |largest root| tau:
 *   - x <= SERIES_RADIUS: the power series of the ODE itself (phi_1's Taylor coefficients
 *     h_{n+2} = -gamma h_{n+1} - w^2 h_n), whose terms shrink like x^n / n!.  It is the same
 *     function on both sides of critical damping, so zeta = 1 and 1 +- 1e-9 are no special
 *     case, and it has none of the cancellation that the closed forms have at small x;
 *   - clearly overdamped (mu >= sigma / 4): phi_j = (E_{j-1}(l+) - E_{j-1}(l-)) / (2 mu),
 *     E_k(l) = tau^k phi_k(l tau) with the exponential integrators' phi_k, a divided
 *     difference of two roots at least 5/3 apart (it cancels by (sigma + mu) / (2 mu) <=
 *     2.5 at most), the slow root l+ = -w^2 / (sigma + mu) formed without the cancellation
 *     of -sigma + mu;
 *   - otherwise w tau > SERIES_RADIUS / 1.29: phi_0 and phi_1 in closed form (e^{-sigma tau}
 *     times sin(nu tau) / nu or the expm1 form of sinh(mu tau) / mu, which cannot overflow)
 *     and the ODE's integrated identities phi_{j-1} + gamma phi_j + w^2 phi_{j+1} =
 *     tau^{j-1} / (j-1)! upward, as the undamped basis does for w tau >= 2.
 * Against 80-digit references over zeta = 0 .. 1e4 (1 +- 1e-9 and 1 exactly included) and
 * w tau = 2^-10 .. 2^12.5, the worst error is 13 eps of max(|phi_j|, min(tau^j / j!,
 * |root|^-j)) (phi_4 at zeta = 1.1, x = 2.6), apart from the eps w tau that rounding the
 * phase costs any closed form of an oscillation; test_exact.c's damped oscillator checks
 * the regimes against long double. */
#include <math.h>

#include "exact_backend.h"

/* Below this x the series (its terms shrink as x^n / n!; at x = 1 the upward recurrence
 * cost phi_4 250 eps near zeta = 1.1, against 13 eps with the switch at 2). */
#define SERIES_RADIUS 2.0
#define SERIES_TERMS 60

void bk_exact_damped_root(double w2, double gamma, double *root, double *radius)
{
    double sigma = 0.5 * gamma, w = sqrt(w2);
    if (w > sigma) {
        *root = sqrt((w - sigma) * (w + sigma));
        *radius = w;
    } else if (sigma > w) {
        double mu = sqrt((sigma - w) * (sigma + w));
        *root = -mu;
        *radius = sigma + mu;
    } else {
        *root = 0.0;
        *radius = sigma;
    }
}

/* phi_k(x) of the exponential integrators, k = 0..3, x <= 0: e^x, and
 * phi_k = (phi_{k-1} - 1/(k-1)!) / x; the series sum_i x^i / (i + k)! for |x| < 1, where the
 * recurrence would cancel. */
static void exp_phis(double x, double out[4])
{
    if (fabs(x) < 1.0) {
        out[0] = exp(x);
        for (int k = 1; k < 4; ++k) {
            double term = 1.0, sum = 0.0;
            for (int i = 1; i <= k; ++i)
                term /= (double)i; /* 1 / k! */
            for (int i = 0; i < 40 && term != 0.0; ++i) {
                sum += term;
                term *= x / (double)(i + k + 1);
                if (fabs(term) <= 0x1p-60 * fabs(sum))
                    break;
            }
            out[k] = sum;
        }
        return;
    }
    out[0] = exp(x);
    out[1] = expm1(x) / x;
    out[2] = (out[1] - 1.0) / x;
    out[3] = (out[2] - 0.5) / x;
}

static void series(double w2, double gamma, double tau, double phi[5])
{
    /* H_n = h_n tau^(n-1): H_1 = 1, H_2 = -gamma tau, H_{n+2} = -gamma tau H_{n+1} - w^2 tau^2 H_n;
     * phi_j = tau^j sum_{n>=1} H_n / (n + j - 1)!. */
    double a = gamma * tau, b = w2 * tau * tau;
    double sum[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    double h_prev = 0.0, h = 1.0;
    double inv = 1.0; /* 1 / n! */
    for (int n = 1; n <= SERIES_TERMS; ++n) {
        inv /= (double)n;
        double f = inv; /* 1 / (n + j - 1)! for j = 1, 2, ... */
        for (int j = 1; j <= 4; ++j) {
            sum[j] += h * f;
            f /= (double)(n + j);
        }
        double next = -a * h - b * h_prev;
        /* this term and the next below 2^-60 of the sum: the rest is smaller still (the
         * coefficients grow at most like 2.5^n against n!) */
        if (fabs(h) * inv <= 0x1p-60 * fabs(sum[1]) && fabs(next) * inv <= 0x1p-60 * fabs(sum[1]))
            break;
        h_prev = h;
        h = next;
    }
    double power = tau;
    for (int j = 1; j <= 4; ++j) {
        phi[j] = power * sum[j];
        power *= tau;
    }
}

void bk_exact_damped_basis(double w2, double gamma, double root, double radius, double tau, double phi[5])
{
    if (radius * tau <= SERIES_RADIUS) {
        series(w2, gamma, tau, phi);
        return;
    }
    double sigma = 0.5 * gamma;
    if (root < 0.0 && -root >= 0.25 * sigma) {
        double mu = -root, slow = -w2 / (sigma + mu), fast = -(sigma + mu);
        double es[4], ef[4];
        exp_phis(slow * tau, es);
        exp_phis(fast * tau, ef);
        /* phi_1 = e^(slow tau) (1 - e^(-2 mu tau)) / (2 mu), no overflow, no cancellation */
        phi[1] = -es[0] * expm1(-2.0 * mu * tau) / (2.0 * mu);
        double power = tau;
        for (int j = 2; j <= 4; ++j) {
            phi[j] = power * (es[j - 1] - ef[j - 1]) / (2.0 * mu);
            power *= tau;
        }
        return;
    }
    double decay = exp(-sigma * tau), phi0;
    if (root > 0.0) {
        phi[1] = decay * sin(root * tau) / root;
        phi0 = decay * cos(root * tau) - sigma * phi[1];
    } else if (root < 0.0) {
        double mu = -root, slow = -w2 / (sigma + mu);
        double e_slow = exp(slow * tau), x = 2.0 * mu * tau;
        phi[1] = e_slow * tau * (-expm1(-x) / x);
        phi0 = e_slow - (sigma + mu) * phi[1];
    } else {
        phi[1] = decay * tau;
        phi0 = decay - sigma * phi[1];
    }
    phi[2] = (1.0 - phi0 - gamma * phi[1]) / w2;
    phi[3] = (tau - phi[1] - gamma * phi[2]) / w2;
    phi[4] = (0.5 * tau * tau - phi[2] - gamma * phi[3]) / w2;
}
