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
#define SERIES_TERMS 60 /* at most; bk_exact_inverse_factorial needs SERIES_TERMS + 4 */

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

/* 1 / n!, n = 0 .. 63, correctly rounded: the series' weights, so that a term costs
 * multiplications only (a division per sum and term was a third of a long damped chain's
 * CPU). */
const double bk_exact_inverse_factorial[64] = {
    0x1.0000000000000p+0, 0x1.0000000000000p+0, 0x1.0000000000000p-1,
    0x1.5555555555555p-3, 0x1.5555555555555p-5, 0x1.1111111111111p-7,
    0x1.6c16c16c16c17p-10, 0x1.a01a01a01a01ap-13, 0x1.a01a01a01a01ap-16,
    0x1.71de3a556c734p-19, 0x1.27e4fb7789f5cp-22, 0x1.ae64567f544e4p-26,
    0x1.1eed8eff8d898p-29, 0x1.6124613a86d09p-33, 0x1.93974a8c07c9dp-37,
    0x1.ae7f3e733b81fp-41, 0x1.ae7f3e733b81fp-45, 0x1.952c77030ad4ap-49,
    0x1.6827863b97d97p-53, 0x1.2f49b46814157p-57, 0x1.e542ba4020225p-62,
    0x1.71b8ef6dcf572p-66, 0x1.0ce396db7f853p-70, 0x1.761b41316381ap-75,
    0x1.f2cf01972f578p-80, 0x1.3f3ccdd165fa9p-84, 0x1.88e85fc6a4e5ap-89,
    0x1.d1ab1c2dccea3p-94, 0x1.0a18a2635085dp-98, 0x1.259f98b4358adp-103,
    0x1.3932c5047d60ep-108, 0x1.434d2e783f5bcp-113, 0x1.434d2e783f5bcp-118,
    0x1.3981254dd0d52p-123, 0x1.2710231c0fd7ap-128, 0x1.0dc59c716d91fp-133,
    0x1.df983290c2ca9p-139, 0x1.9ec8d1c94e85bp-144, 0x1.5d4acb9c0c3abp-149,
    0x1.1e99449a4bacep-154, 0x1.ca8ed42a12ae3p-160, 0x1.65e61c39d0241p-165,
    0x1.10af527530de8p-170, 0x1.95db45257e512p-176, 0x1.272b1b03fec6ap-181,
    0x1.a3cb872220648p-187, 0x1.240804f659510p-192, 0x1.8da8e0a127ebap-198,
    0x1.091b406b6ff26p-203, 0x1.5a42f0dfeb086p-209, 0x1.bb36f6e12cd78p-215,
    0x1.161872bf7b823p-220, 0x1.56457989358c9p-226, 0x1.9d4f1058674dfp-232,
    0x1.e9d8f6ed83eaap-238, 0x1.1d008faac5c50p-243, 0x1.45b77f9e98e12p-249,
    0x1.6db793c887b97p-255, 0x1.938cc661b03f6p-261, 0x1.b5bfc17fa97d3p-267,
    0x1.d2eeac43e7fcfp-273, 0x1.e9e56d649f768p-279, 0x1.f9b3059128bc7p-285,
    0x1.00dcf6a320e1cp-290,
};

/* phi_k(x) of the exponential integrators, k = 0..3, x <= 0: e^x, and
 * phi_k = (phi_{k-1} - 1/(k-1)!) / x; the series sum_i x^i / (i + k)! for |x| < 1, where the
 * recurrence would cancel. */
void bk_exact_exp_phis(double x, double out[4])
{
    out[0] = exp(x);
    if (fabs(x) < 1.0) {
        double sum[4] = {0.0, 0.0, 0.0, 0.0}, power = 1.0;
        for (int i = 0; i < 30; ++i) {
            const double *inv = &bk_exact_inverse_factorial[i];
            for (int k = 1; k < 4; ++k)
                sum[k] += power * inv[k];
            if (fabs(power) * inv[1] <= 0x1p-60 * fabs(sum[1]))
                break;
            power *= x;
        }
        for (int k = 1; k < 4; ++k)
            out[k] = sum[k];
        return;
    }
    out[1] = expm1(x) / x;
    out[2] = (out[1] - 1.0) / x;
    out[3] = (out[2] - 0.5) / x;
}

/* The same at z = re + i im (re <= 0): a coupled cluster's complex modes.  The series below
 * |z| = 1 (terms |z|^i / (i + k)!), else the recurrence from e^z; written out in real and
 * imaginary parts. */
void bk_exact_exp_phis_complex(double re, double im, double out_re[4], double out_im[4])
{
    double scale = exp(re);
    out_re[0] = scale * cos(im);
    out_im[0] = scale * sin(im);
    if (re * re + im * im < 1.0) {
        /* one pass for the three: term i of phi_k is z^i / (i + k)! */
        double s_re[4] = {0.0, 0.0, 0.0, 0.0}, s_im[4] = {0.0, 0.0, 0.0, 0.0}, p_re = 1.0, p_im = 0.0;
        for (int i = 0; i < 30; ++i) {
            const double *inv = &bk_exact_inverse_factorial[i];
            for (int k = 1; k < 4; ++k) {
                s_re[k] += p_re * inv[k];
                s_im[k] += p_im * inv[k];
            }
            /* |term| <= 2^-60 |sum| for phi_1 (the others' terms shrink faster), squared */
            if ((p_re * p_re + p_im * p_im) * inv[1] * inv[1] <= 0x1p-120 * (s_re[1] * s_re[1] + s_im[1] * s_im[1]))
                break;
            double next_re = p_re * re - p_im * im;
            p_im = p_re * im + p_im * re;
            p_re = next_re;
        }
        for (int k = 1; k < 4; ++k) {
            out_re[k] = s_re[k];
            out_im[k] = s_im[k];
        }
        return;
    }
    /* (a + i b) / (re + i im) */
    double norm = re * re + im * im;
    double a = expm1(re) * cos(im) - 2.0 * sin(0.5 * im) * sin(0.5 * im), b = out_im[0]; /* e^z - 1 */
    const double minus[4] = {0.0, 1.0, 0.5, 0.0};
    for (int k = 1; k < 4; ++k) {
        if (k > 1) {
            a = out_re[k - 1] - minus[k - 1];
            b = out_im[k - 1];
        }
        out_re[k] = (a * re + b * im) / norm;
        out_im[k] = (b * re - a * im) / norm;
    }
}

static void series(double w2, double gamma, double tau, double phi[5])
{
    /* H_n = h_n tau^(n-1): H_1 = 1, H_2 = -gamma tau, H_{n+2} = -gamma tau H_{n+1} - w^2 tau^2 H_n;
     * phi_j = tau^j sum_{n>=1} H_n / (n + j - 1)!. */
    double a = gamma * tau, b = w2 * tau * tau;
    double s1 = 0.0, s2 = 0.0, s3 = 0.0, s4 = 0.0;
    double h_prev = 0.0, h = 1.0;
    for (int n = 1; n <= SERIES_TERMS; ++n) {
        const double *inv = &bk_exact_inverse_factorial[n];
        s1 += h * inv[0];
        s2 += h * inv[1];
        s3 += h * inv[2];
        s4 += h * inv[3];
        double next = -a * h - b * h_prev;
        /* this term and the next below 2^-60 of the sum: the rest is smaller still (the
         * coefficients grow at most like 2.5^n against n!) */
        if (fabs(h) * inv[0] <= 0x1p-60 * fabs(s1) && fabs(next) * inv[0] <= 0x1p-60 * fabs(s1))
            break;
        h_prev = h;
        h = next;
    }
    double tau2 = tau * tau;
    phi[1] = tau * s1;
    phi[2] = tau2 * s2;
    phi[3] = tau2 * tau * s3;
    phi[4] = tau2 * tau2 * s4;
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
        bk_exact_exp_phis(slow * tau, es);
        bk_exact_exp_phis(fast * tau, ef);
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
