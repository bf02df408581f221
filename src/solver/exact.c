/* Exact piecewise-analytic stepper for affine problems (Coulomb friction, linear or frozen
 * tension-only springs, a constant-velocity driver, dashpots).
 *
 * What it computes.  Between two (re)starts the problem handed over is
 *
 *     xi'' = -K xi - D v + a(t)    p pairs (xi, v = xi'), K = M^-1 (stiffness),
 *                                  D = M^-1 C (dashpots), constant
 *     q'   = P xi + Q v + r(t)     quadratures (energy increments)
 *     q_last' = v^T C v            the dashpots' dissipation, when the problem declares it
 *
 * with a and r affine in t.  start() reads K, D, P, Q and the affine forcing (measured from
 * the starting state, so that u = xi - xi0 starts at 0), splits the pairs into clusters (the
 * connected components of K's and D's coupling), symmetrises each cluster's
 * S = M^(1/2) K M^(-1/2) and diagonalises it, S = U diag(w_k^2) U^T (GSL).  When the
 * cluster's damping is proportional, M^(1/2) D M^(-1/2) = alpha I + beta S (uniform masses
 * and substrate dashpots; coupling dashpots in the ratio of the coupling springs on uniform
 * driver springs; no dashpots at all), U diagonalises it too, with gamma_k = alpha +
 * beta w_k^2, and in the modal coordinates eta = U^T M^(1/2) u each mode is a damped
 * oscillator with a ramp force, tau = t - t0:
 *
 *     eta_k'' + gamma_k eta_k' + w_k^2 eta_k = f_k + d_k tau,  eta_k(0) = 0,  eta_k'(0) = c_k,
 *     f_k = g_k + gamma_k c_k (g_k: the mode's acceleration at the start)
 *     eta_k = c_k phi1 + f_k phi2 + d_k phi3,  eta_k' - c_k = -w_k^2 c_k phi2 + g_k phi1 + d_k phi2
 *
 * where phi1 is the mode's impulse response (phi1(0) = 0, phi1'(0) = 1) and phi_{j+1} is the
 * integral of phi_j from 0; eta' - c keeps its undamped form because phi0 = phi1' =
 * 1 - gamma phi1 - w^2 phi2.  Undamped, phi0 = cos(w tau), phi1 = sin(w tau)/w,
 * phi2 = (1 - cos)/w^2 = 2 sin^2(w tau / 2)/w^2, phi3 = (tau - phi1)/w^2,
 * phi4 = (tau^2/2 - phi2)/w^2; for w tau < 2 phi3 and phi4 come from their power series, and
 * w = 0 (or w^2 within rounding of zero relative to the cluster's largest) gives tau^j / j!.
 * Damped (underdamped, critical, overdamped alike), exact_damped.c: the ODE's power series
 * where the largest characteristic root times tau is below 2, the divided difference of the
 * two real roots where clearly overdamped, else e^(-gamma tau / 2) times sin or the expm1
 * form of sinh of the half-difference over the frequency, and the ODE's integrated
 * identities upward.  The quadratures are the integrals of their affine rates along this
 * solution, again sums of phi2..phi4, in closed form; the dissipation is each damped mode's
 * energy balance, gamma int eta'^2 = -(eta'^2 - c^2)/2 - w^2 eta^2/2 + int (f + d tau) eta'.
 * Damping that is not proportional couples the modes (their motion is no sum of real
 * damped oscillators): such a cluster is solved in its 2p-dimensional state space instead,
 * by the eigenvectors of [0 I; -S -Cs] (LAPACK dgeev; complex pairs in real form) and the
 * exponential integrators' phi-functions of each eigenvalue (exact_coupled.c), with its
 * dissipation from its energy balance; it is refused, with the reason, only where those
 * eigenvectors are too ill-conditioned to be accurate (two modes merging: within ~1e-9 of
 * critical damping, or an undamped free mode).  It is no faster than gsl_rk8pd there (a
 * 2p x 2p eigenproblem per restart, 4 p^2 per probe), so method = auto gives such scenes an
 * integrator (bk_model_damping_proportional).  Every evaluation of y(t) is exact up to
 * rounding; nothing is integrated, so there is no truncation error at all.
 *
 * Root functions are sampled along the exact solution at most every 1/16 of the shortest
 * modal period (and max_step); a sign change is located by GSL's Brent on the exact solution
 * to the last few representable doubles and reported with the state just after the crossing,
 * as CVODE does.  With dashpots a mode varies on the time scale of its largest
 * characteristic root: |root| = w for an oscillating one (so 1/16 of its undamped period,
 * shorter than 1/16 of its damped one), and for an overdamped one the slow root, and the
 * fast root l- too until e^(l- tau) fell below e^-40 (bk_exact_sampling_step): a sampling
 * step over which every exponential changes by at most e^(-2 pi / 16) = 0.68, as an
 * oscillation turns by 22.5 degrees, so a sum of them cannot cross and cross back unseen any
 * more than an undamped one can.  A function exactly zero over a stretch (a damped block's
 * acceleration once it slides steadily, rounded to zeros) is located at its earliest zero
 * by bisection.  A function exactly zero at the start stays inactive until it moves away
 * from zero (CVODE's convention).  A long island can have several transitions per sampling
 * step, and every probe evaluates all its root functions, so the number of probes per
 * transition is what must stay bounded: a step with several crossings is first halved toward
 * the earliest, then one function is located and the others sorted by two evaluations
 * around its root (find_roots).
 *
 * Why.  It is the accuracy yardstick for the integrators (transition times to ~1e-15
 * relative, including case C's grazing stops that no tolerance-driven integrator resolves)
 * and, with a few dozen root evaluations per slip, the fastest method for Coulomb scenes.
 *
 * Why clusters.  Stuck blocks are fixed, so the slipping blocks an island integrates form
 * independent short stretches even when many slip at once.  Decomposing the whole p x p
 * matrix would cost O(p^3) per restart and every root probe O(p^2); per cluster the
 * decomposition costs sum p_i^2 and a probe sum p_i^2 + O(p), and the eigenvectors are
 * exactly those of the block-diagonal matrix, so nothing is approximated.  A chain stretch's
 * S is tridiagonal, and LAPACK's dstevr (relatively robust representations) diagonalises it
 * in O(p^2); only a ring slipping all round (cyclic S) goes through GSL's dense symmv, p^3.
 * K, D, P and Q come from the problem's exact Jacobian when it has one (O(p) entries, checked
 * against the right-hand side by one combined probe) instead of one right-hand-side probe
 * per component, which is O(p^2).
 *
 * Why uniform clusters are special.  Blocks of equal mass, equal velocity and equal
 * acceleration whose stiffness rows sum alike and damping rows too (a uniform chain slipping
 * together, its couplings exactly balanced) move as one: their motion is the single
 * (damped) oscillator of those row sums.  The eigenvectors of such a cluster are exact only
 * up to rounding, and summing the modes back would give each block a slightly different
 * motion, so a uniform chain that physically slides as one would break into sub-events
 * (seen: 3,393 transitions where the integrators give 41 synchronous slips of 16 blocks).
 * So a uniform cluster is solved as that one oscillator and every member gets the same
 * numbers: symmetric inputs give symmetric outputs, and the cost is O(p) however long the
 * cluster. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "exact_backend.h"

static int create(void **mem, const bk_solver_options *options, bk_error *err)
{
    exact_backend *eb = calloc(1, sizeof *eb);
    if (!eb)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory");
    eb->max_step = options->max_step;
    eb->shared = bk_exact_shared_acquire();
    if (!eb->shared) {
        free(eb);
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the root finder");
    }
    *mem = eb;
    return BK_OK;
}

static void destroy(void *mem)
{
    exact_backend *eb = mem;
    if (!eb)
        return;
    if (eb->eigen)
        gsl_eigen_symmv_free(eb->eigen);
    bk_exact_shared_release(eb->shared);
    free(eb->arena);
    free(eb->indices);
    free(eb->matrices);
    free(eb->row_col);
    free(eb->row_value);
    free(eb->damp_col);
    free(eb->damp_value);
    free(eb->coupled_data);
    free(eb->coupled_work);
    free(eb->direction);
    free(eb->sign);
    free(eb->found);
    free(eb->g_hi);
    free(eb);
}

static int call_roots(exact_backend *eb, double t, double *g, bk_error *err)
{
    if (eb->n_roots == 0)
        return BK_OK;
    bk_exact_state(eb, t, eb->scratch);
    eb->counters.root_evals++;
    int rc = eb->problem.roots(t, eb->scratch, g, eb->problem.user);
    if (rc != 0)
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "exact stepper: the root functions failed (code %d) at t = %.17g s", rc, t);
    for (size_t i = 0; i < eb->n_roots; ++i)
        if (isnan(g[i]))
            return BK_FAIL(err, BK_ERR_NUMERIC,
                           "exact stepper: root function %zu is NaN at t = %.17g s", i, t);
    return BK_OK;
}

/* A position's rate must be its velocity. */
static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    (void)atol; /* exact: no tolerance to meet */
    exact_backend *eb = mem;
    eb->problem = *problem;
    if (!problem->affine)
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact needs Coulomb friction (constant sliding force, no friction "
                       "state) and blocks with mass" USE_INTEGRATOR);
    size_t p = problem->n_pairs;
    if (problem->dissipation_last && 2 * p >= n)
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact: the dashpots' dissipation is declared the last component, "
                       "but there is no quadrature after the %zu pairs (n = %zu)", p, n);
    if (2 * p > n || (p > 0 && !problem->pair_mass))
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact needs the state as (position, velocity) pairs followed only "
                       "by quadratures (n = %zu, n_pairs = %zu)" USE_INTEGRATOR,
                       n, p);
    if (!isfinite(t0) || !(t_stop >= t0))
        return BK_FAIL(err, BK_ERR_INVALID, "exact stepper: bad interval [%.17g, %.17g] s", t0, t_stop);
    int rc = bk_exact_reserve(eb, n, p, n - 2 * p, problem->n_roots, err);
    if (rc != BK_OK)
        return rc;
    eb->n = n;
    eb->p = p;
    eb->m = n - 2 * p;
    eb->n_roots = problem->n_roots;
    eb->t0 = eb->t_now = eb->t_lo = eb->t_hi = t0;
    eb->t_stop = t_stop;
    eb->g_try_time = NAN;
    eb->n_couplings = 0;
    eb->n_dampings = 0;
    eb->dissipation = problem->dissipation_last != 0;
    eb->n_clusters = 0;
    memcpy(eb->y0, y0, n * sizeof *y0);
    memset(eb->P, 0, eb->m * p * sizeof *eb->P);
    memset(eb->Q, 0, eb->m * p * sizeof *eb->Q);

    if ((rc = bk_exact_read_problem(eb, err)) == BK_OK && (rc = bk_exact_modes(eb, err)) == BK_OK)
        rc = bk_exact_rows_prepare(eb, err);
    /* the shared work space now serves other instances */
    eb->f0 = eb->probe = eb->scale = eb->delta = eb->predicted = eb->work = NULL;
    eb->cluster_of = eb->local = eb->parent = NULL;
    if (rc != BK_OK)
        return rc;
    if (eb->n_series > 0) {
        memcpy(eb->yc, y0, 2 * p * sizeof *y0);
        eb->tc = t0;
    }

    if (eb->n_roots > 0) {
        memcpy(eb->direction, problem->root_direction, eb->n_roots * sizeof *eb->direction);
        if ((rc = call_roots(eb, t0, eb->g_hi, err)) != BK_OK)
            return rc;
        for (size_t i = 0; i < eb->n_roots; ++i)
            eb->sign[i] = (signed char)(eb->g_hi[i] > 0.0 ? 1 : eb->g_hi[i] < 0.0 ? -1 : 0);
    }
    return BK_OK;
}

/* --- step: sample, bracket, locate ------------------------------------------------------ */

/* Has function i crossed, in a direction it listens to, from its last sign to value g? */
static int crossed(const exact_backend *eb, size_t i, double g)
{
    int s = eb->sign[i];
    if (s == 0 || g * s > 0.0)
        return 0;
    return eb->direction[i] == 0 || eb->direction[i] == -s;
}

/* All root functions at t into g_try, unless they are there already. */
static int roots_at(exact_backend *eb, double t, bk_error *err)
{
    if (eb->g_try_time == t)
        return BK_OK;
    eb->g_try_time = NAN;
    int rc = call_roots(eb, t, eb->g_try, err);
    if (rc == BK_OK)
        eb->g_try_time = t;
    return rc;
}

/* Every probe evaluates all root functions on the whole state, so a locate remembers the
 * values of its function it has seen: Brent asks again for the bracket's ends. */
#define ROOT_MEMO 8

typedef struct root_probe {
    exact_backend *eb;
    size_t index;
    bk_error *err;
    int status;
    size_t seen;                /* values remembered, the last ROOT_MEMO of them in the ring */
    double seen_t[ROOT_MEMO], seen_g[ROOT_MEMO];
} root_probe;

static void remember(root_probe *rp, double t, double g)
{
    rp->seen_t[rp->seen % ROOT_MEMO] = t;
    rp->seen_g[rp->seen % ROOT_MEMO] = g;
    rp->seen++;
}

static double root_value(double t, void *user)
{
    root_probe *rp = user;
    if (rp->status != BK_OK)
        return NAN;
    size_t known = rp->seen < ROOT_MEMO ? rp->seen : ROOT_MEMO;
    // cppcheck-suppress knownConditionTrueFalse ; seen grows through fn.params across calls
    for (size_t k = 0; k < known; ++k)
        if (rp->seen_t[k] == t)
            return rp->seen_g[k];
    rp->status = roots_at(rp->eb, t, rp->err);
    if (rp->status != BK_OK)
        return NAN;
    double g = rp->eb->g_try[rp->index];
    remember(rp, t, g);
    return g;
}

/* Function rp->index is exactly zero at hi: it may have been so since well before, where a
 * motion settles (a damped block's acceleration once it slides steadily rounds to exact
 * zeros), and Brent has no sign change to work with.  Bisect for the earliest time it holds
 * zero or its new sign, to the last few doubles. */
static int earliest_zero(root_probe *rp, int old, double lo, double hi, double *t_root)
{
    while (hi - lo > 2.0 * DBL_EPSILON * fmax(fabs(lo), fabs(hi))) {
        double mid = lo + 0.5 * (hi - lo);
        if (mid <= lo || mid >= hi)
            break;
        double g = root_value(mid, rp);
        if (rp->status != BK_OK)
            return rp->status;
        if (g * old <= 0.0)
            hi = mid;
        else
            lo = mid;
    }
    *t_root = hi;
    return BK_OK;
}

/* Locate the crossing of function i in [lo, hi] (its old sign at or before lo, its new sign
 * or zero at hi, value g_hi): *t_root is the earliest time found where it holds its new
 * sign or zero, within a few doubles of the zero. */
static int locate(exact_backend *eb, size_t i, double lo, double hi, double g_hi, double *t_root,
                  bk_error *err)
{
    root_probe rp = {.eb = eb, .index = i, .err = err, .status = BK_OK};
    gsl_function fn = {root_value, &rp};
    int old = eb->sign[i];
    if (hi <= lo) {
        *t_root = hi;
        return BK_OK;
    }
    remember(&rp, hi, g_hi);
    if (g_hi == 0.0)
        return earliest_zero(&rp, old, lo, hi, t_root);
    /* lo's value differs from the last sign seen only when it is exactly zero there: the
     * crossing is at lo. */
    double g_lo = root_value(lo, &rp);
    if (rp.status != BK_OK)
        return rp.status;
    if (g_lo * old <= 0.0) {
        *t_root = lo;
        return BK_OK;
    }
    for (int attempt = 0; attempt < 64; ++attempt) {
        if (hi <= lo) {
            *t_root = hi;
            return BK_OK;
        }
        if (g_hi == 0.0)
            return earliest_zero(&rp, old, lo, hi, t_root);
        int rc = gsl_root_fsolver_set(eb->shared->brent, &fn, lo, hi);
        if (rp.status != BK_OK)
            return rp.status;
        if (rc != GSL_SUCCESS)
            return BK_FAIL(err, BK_ERR_SOLVER,
                           "exact stepper: cannot bracket root function %zu in [%.17g, %.17g] s: %s",
                           i, lo, hi, gsl_strerror(rc));
        double a = lo, b = hi;
        for (int iter = 0; iter < BRENT_MAX_ITER; ++iter) {
            rc = gsl_root_fsolver_iterate(eb->shared->brent);
            // cppcheck-suppress knownConditionTrueFalse ; set through fn.params by the callback
            if (rp.status != BK_OK)
                return rp.status;
            if (rc != GSL_SUCCESS)
                return BK_FAIL(err, BK_ERR_SOLVER,
                               "exact stepper: locating root function %zu failed: %s", i,
                               gsl_strerror(rc));
            a = gsl_root_fsolver_x_lower(eb->shared->brent);
            b = gsl_root_fsolver_x_upper(eb->shared->brent);
            if (b - a <= 2.0 * DBL_EPSILON * fmax(fabs(a), fabs(b)))
                break;
        }
        double g_b = root_value(b, &rp);
        if (rp.status != BK_OK)
            return rp.status;
        if (g_b * old <= 0.0) {
            *t_root = b;
            return BK_OK;
        }
        /* Brent closed on a later crossing back: an earlier one lies in [lo, a]. */
        hi = a;
        g_hi = root_value(a, &rp);
        if (rp.status != BK_OK)
            return rp.status;
    }
    return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: root function %zu oscillates too fast to locate "
                   "near t = %.17g s", i, lo);
}

static void update_signs(exact_backend *eb, const double *g)
{
    for (size_t i = 0; i < eb->n_roots; ++i)
        if (g[i] != 0.0)
            eb->sign[i] = (signed char)(g[i] > 0.0 ? 1 : -1);
}

static size_t count_crossed(const exact_backend *eb, const double *g)
{
    size_t count = 0;
    for (size_t i = 0; i < eb->n_roots; ++i)
        count += (size_t)crossed(eb, i, g[i]);
    return count;
}

/* On a long chain many functions cross within one sampling step, and locating each to the
 * last double (a few dozen probes) only to report the first made the cost per transition
 * grow with the chain.  Halve (lo, hi] (values g_hi at hi) toward the earliest crossing
 * until one function crosses in it, each halving one probe; crossings closer than
 * h / 2^MAX_HALVINGS (simultaneous ones) are left to find_roots. */
static int isolate_first(exact_backend *eb, double *lo, double *hi, bk_error *err)
{
    size_t crossing = count_crossed(eb, eb->g_hi);
    for (int halving = 0; halving < MAX_HALVINGS && crossing > 1; ++halving) {
        double mid = *lo + 0.5 * (*hi - *lo);
        int rc = roots_at(eb, mid, err);
        if (rc != BK_OK)
            return rc;
        size_t early = count_crossed(eb, eb->g_try);
        if (early > 0) {
            *hi = mid;
            memcpy(eb->g_hi, eb->g_try, eb->n_roots * sizeof *eb->g_hi);
            crossing = early;
        } else {
            /* Nothing listened to crossed by mid: the signs there are the new reference. */
            update_signs(eb, eb->g_try);
            *lo = mid;
            crossing = count_crossed(eb, eb->g_hi);
        }
    }
    return BK_OK;
}

/* Look for crossings in (lo, hi] (values g at hi).  Returns 1 with *t_root and found[] when
 * some function crossed, 0 when none did, < 0 on failure.  Everything crossing within the
 * root tolerance of the first crossing is one event, reported at the latest of their
 * located times so that each has crossed there.  Only one function is located per round:
 * the rest are sorted by evaluating all of them just before and just after its root, so a
 * uniform stretch of p blocks stopping together costs one location, not p (each a few
 * dozen probes of all p functions). */
static int find_roots(exact_backend *eb, double lo, double hi, double *t_root, bk_error *err)
{
    size_t nr = eb->n_roots;
    double *g = eb->g_hi;
    for (size_t round = 0; round < nr + 64; ++round) {
        size_t pick = nr;
        for (size_t i = 0; i < nr && pick == nr; ++i)
            if (crossed(eb, i, g[i]))
                pick = i;
        if (pick == nr)
            return 0;
        double first;
        int rc = locate(eb, pick, lo, hi, g[pick], &first, err);
        if (rc != BK_OK)
            return rc;
        double tol = 100.0 * DBL_EPSILON * (fabs(first) + eb->h);
        /* Another function crossed before this one's window: that crossing comes first.  The
         * located one itself crossed there too only when it flickers about zero at its
         * rounding (a slip acceleration that has decayed to 1e-12 of the forces on a chain
         * sliding steadily): no earlier zero of it means more than this one, and moving the
         * window back for it would creep toward lo by one tolerance per round. */
        double before = first - tol;
        if (before > lo) {
            if ((rc = roots_at(eb, before, err)) != BK_OK)
                return rc;
            size_t others = count_crossed(eb, eb->g_try) - (size_t)crossed(eb, pick, eb->g_try[pick]);
            if (others > 0) {
                hi = before;
                memcpy(g, eb->g_try, nr * sizeof *g);
                continue;
            }
        }
        /* Functions crossing just after it belong to the same event: locate those. */
        double t = first, after = fmin(first + tol, hi);
        if (after > first) {
            if ((rc = roots_at(eb, after, err)) != BK_OK)
                return rc;
            memcpy(eb->root_t, eb->g_try, nr * sizeof *eb->root_t); /* values at after */
            if ((rc = roots_at(eb, first, err)) != BK_OK)
                return rc;
            for (size_t i = 0; i < nr; ++i) {
                if (!crossed(eb, i, eb->root_t[i]) || crossed(eb, i, eb->g_try[i]))
                    continue;
                double t_i;
                if ((rc = locate(eb, i, first, after, eb->root_t[i], &t_i, err)) != BK_OK)
                    return rc;
                t = fmax(t, t_i);
                /* locate probed elsewhere: the values at first are wanted again below. */
                if ((rc = roots_at(eb, first, err)) != BK_OK)
                    return rc;
            }
        }
        if ((rc = roots_at(eb, t, err)) != BK_OK)
            return rc;
        for (size_t i = 0; i < nr; ++i)
            eb->found[i] = crossed(eb, i, eb->g_try[i]) ? -eb->sign[i] : 0;
        eb->found[pick] = -eb->sign[pick];
        update_signs(eb, eb->g_try);
        for (size_t i = 0; i < nr; ++i)
            if (eb->found[i])
                eb->sign[i] = (signed char)eb->found[i];
        *t_root = t;
        return 1;
    }
    return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: cannot separate the roots near t = %.17g s", lo);
}

/* The step ends at t with state y: the centre of the rows' series. */
static void reached(exact_backend *eb, double t, const double *y)
{
    eb->t_now = eb->t_hi = t;
    if (eb->n_series > 0) {
        memcpy(eb->yc, y, 2 * eb->p * sizeof *y);
        eb->tc = t;
    }
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    exact_backend *eb = mem;
    double lo = eb->t_now;
    if (lo >= eb->t_stop) {
        eb->t_lo = eb->t_stop;
        bk_exact_state(eb, eb->t_stop, y);
        reached(eb, eb->t_stop, y);
        *t_reached = eb->t_stop;
        return BK_STEP_STOP;
    }
    eb->h = bk_exact_sampling_step(eb, lo);
    double hi = lo + eb->h;
    /* Never leave a sliver before the stop time. */
    if (!(hi < eb->t_stop - 1e-3 * eb->h))
        hi = eb->t_stop;
    eb->counters.steps++;
    int rc = call_roots(eb, hi, eb->g_hi, err);
    if (rc != BK_OK)
        return rc;
    double from = lo;
    if (eb->n_roots > 0 && (rc = isolate_first(eb, &from, &hi, err)) != BK_OK)
        return rc;
    double t_root = hi;
    int status = eb->n_roots > 0 ? find_roots(eb, from, hi, &t_root, err) : 0;
    if (status < 0)
        return status;
    eb->t_lo = lo;
    if (status == 1) {
        bk_exact_state(eb, t_root, y);
        reached(eb, t_root, y);
        *t_reached = t_root;
        return BK_STEP_ROOT;
    }
    update_signs(eb, eb->g_hi);
    bk_exact_state(eb, hi, y);
    reached(eb, hi, y);
    *t_reached = hi;
    return hi == eb->t_stop ? BK_STEP_STOP : BK_STEP_OK;
}

/* The state at t: exact everywhere; for an output row (rows = 1) every cluster in O(its
 * size), else by the modal sum events and merges continue from. */
static int dense_state(void *mem, double t, double *y, int rows, bk_error *err)
{
    exact_backend *eb = mem;
    if (!(t >= eb->t0 && t <= eb->t_stop))
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "exact stepper: t = %.17g s is outside the solution [%.17g, %.17g] s", t,
                       eb->t0, eb->t_stop);
    if (rows)
        bk_exact_row_state(eb, t, y);
    else
        bk_exact_state(eb, t, y);
    return BK_OK;
}

static int interpolate(void *mem, double t, double *y, bk_error *err)
{
    return dense_state(mem, t, y, 0, err);
}

static int sample(void *mem, double t, double *y, bk_error *err)
{
    return dense_state(mem, t, y, 1, err);
}

static void last_step(void *mem, double *t_lo, double *t_hi)
{
    exact_backend *eb = mem;
    *t_lo = eb->t_lo;
    *t_hi = eb->t_hi;
}

static int root_info(void *mem, int *found)
{
    exact_backend *eb = mem;
    if (eb->n_roots > 0)
        memcpy(found, eb->found, eb->n_roots * sizeof *found);
    return BK_OK;
}

static void counters(void *mem, bk_solver_counters *c)
{
    exact_backend *eb = mem;
    *c = eb->counters;
}

const bk_solver_backend bk_solver_exact = {
    .name = "exact",
    .doc = "exact piecewise-analytic (modal) stepper for Coulomb friction; roots to ~1e-15",
    .create = create,
    .start = start,
    .step = step,
    .interpolate = interpolate,
    .sample = sample,
    .last_step = last_step,
    .root_info = root_info,
    .counters = counters,
    .destroy = destroy,
};
