/* Internal to the exact stepper (exact.c: start, stepping and events; exact_work.c: its
 * memory; exact_matrices.c: reading K, D, P, Q and the forcing from the problem;
 * exact_modes.c: the clusters, their modes and the closed-form state; exact_damped.c: the
 * damped modes' basis functions; exact_rows.c: output rows of long clusters).  exact.c's
 * header says what it computes. */
#ifndef BKSIM_EXACT_BACKEND_H
#define BKSIM_EXACT_BACKEND_H

#include <float.h>
#include <stddef.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_roots.h>

#include "bksim/solver.h"
#include "capacity.h"

#define PI 3.14159265358979323846
#define SAMPLES_PER_PERIOD 16.0
/* An eigenvalue of S below this fraction of its cluster's largest is rounding: the mode is
 * free. */
#define ZERO_MODE (128.0 * DBL_EPSILON)
/* Relative size of a structural entry that must vanish (a quadrature's own dependence etc.). */
#define STRUCTURE_TOL 1e-9
/* A cluster's damping is proportional (M^-1/2 C M^-1/2 = alpha I + beta S) when no entry
 * misses by more than this fraction of the two matrices' scale: the rounding of the
 * entries' own products and sums, nowhere near a physical difference. */
#define PROPORTIONAL_TOL (256.0 * DBL_EPSILON)
/* An overdamped mode's fast exponential e^(l- tau) below e^-40 = 4e-18 of where it started
 * no longer limits the sampling step (see exact.c's header). */
#define FAST_DECAYED 40.0
/* A cluster whose damping couples its modes is solved by the eigenvectors of its 2p x 2p
 * state matrix (exact_coupled.c); their condition number (1-norm) beyond this is refused:
 * rounding grows with it, and it diverges where two damped modes merge, as 1 / (2 sqrt(|zeta
 * - 1|)) near a critically damped mode (1e4: within 2.5e-9 of it), and an undamped free mode
 * is a Jordan block (1.3e8 measured).  Healthy clusters measured 4 to 16. */
#define COUPLED_MAX_CONDITION 1e4
#define BRENT_MAX_ITER 200
#define MAX_HALVINGS 16
#define USE_INTEGRATOR "; use method = auto (it picks an integrator for such scenes), gsl_rk8pd or cvode_bdf"
/* Stiffness coupling K[row][col] (s^-2), or damping D[row][col] = (M^-1 C)[row][col] (s^-1),
 * between pairs, one Jacobian entry or probe column; entries for one (row, col) add up. */
typedef struct coupling {
    size_t row, col;
    double value;
} coupling;

/* What no instance needs between two calls, shared by the thread's instances (calls never
 * interleave, and a long chain keeps one instance per island alive): a start's work space
 * and the root finder.  Reference-counted; an instance stays in the thread that made it. */
typedef struct exact_shared {
    double *start;              /* f0, probe, scale, delta, predicted: n each */
    size_t start_cap;
    double *modes;              /* one cluster's work copy: largest^2 + 3 largest + 1 */
    size_t modes_cap;
    size_t *indices;            /* cluster_of, local, parent: p + 1 each */
    size_t indices_cap;
    coupling *couplings;
    size_t couplings_cap;
    coupling *dampings;
    size_t dampings_cap;
    gsl_root_fsolver *brent;
    size_t users;
} exact_shared;

/* A problem the Jacobian shows the stepper cannot solve (first offending entry). */
enum { JACOBIAN_OK, JACOBIAN_NOMEM, JACOBIAN_RANGE, JACOBIAN_QUADRATURE };

typedef struct exact_backend {
    double max_step;            /* s, [solver] max_step: all the stepper reads of its options */
    bk_ode_problem problem;
    size_t n, p, m, n_roots;    /* state size, pairs, quadratures, root functions */
    double t0, t_stop, h;       /* start, stop, sampling step (of the step under way) */
    double h_slow;              /* the sampling step once every fast exponential decayed */
    double *fast;               /* 2 p: overdamped modes' fast decay rates, descending */
    size_t n_fast, fast_live;   /* how many, and the first not yet decayed */
    double t_now;               /* time reached by the last step */
    double t_lo, t_hi;          /* the last step */

    /* One arena for everything sized by p, m and n; reallocated only when it does not fit. */
    double *arena;
    size_t arena_cap;
    double *y0;                 /* n: the starting state */
    double *scratch;            /* n: the state where the root functions are evaluated */
    /* During a start only, in the shared work space: rates at the start, work space. */
    double *f0, *probe, *scale, *delta, *predicted; /* n each */
    double *sqrt_mass;          /* p */
    double *omega2, *omega;     /* p, by mode (a cluster's modes follow its first's) */
    double *gamma;              /* p: modal damping rate (s^-1), 0 for an undamped mode */
    double *root, *radius;      /* p: bk_exact_damped_root's */
    double *mode_mass;          /* p: the mode's mass in the dissipation's energy balance */
    double *c, *g, *d;          /* p: modal initial velocity, forcing, forcing rate */
    double *eta, *deta, *ieta, *idv; /* p: eta, eta' - c, their integrals */
    double *accel0, *accel_rate;/* p: accelerations at t0 and their time rate */
    double *row_sum, *row_scale;/* p: sum and largest magnitude of each row of K */
    double *damp_sum, *damp_scale; /* p: the same of D */
    double *P, *Q;              /* m*p: quadrature rates' position and velocity coefficients */
    double *P_modal, *Q_modal;  /* m*p: the same in modal coordinates */
    double *qdot0, *q_rate;     /* m: quadrature rates at t0 and their time rate */

    /* Clusters: cluster k holds pairs members[first[k] .. first[k + 1]) in ascending order,
     * its modes are first[k] .. first[k + 1], its matrices start at offset[k]. */
    size_t *indices;
    size_t indices_cap;
    size_t *members, *first, *offset; /* p (+1) each */
    size_t *cluster_of, *local, *parent; /* p (+1) each, during a start only (shared) */
    size_t *uniform;            /* per cluster: it moves as one (see the top of the file) */
    size_t *coupled;            /* per cluster: 0, or 1 + the offset of its state-space modes
                                   in coupled_data (its damping couples its modes) */
    size_t n_coupled;
    double *coupled_data;       /* exact_coupled.c's layout, per coupled cluster */
    size_t coupled_cap;
    double *coupled_work;       /* a start's work space for the largest coupled cluster */
    size_t coupled_work_cap;
    size_t n_clusters;
    size_t n_couplings;         /* K's entries (in the shared work space) */
    size_t n_dampings;          /* D's entries (in the shared work space) */
    int dissipation;            /* the last component is the dashpots' dissipation v^T C v */
    double *matrices;           /* S of each cluster (in place), then T = M^(-1/2) U of each */
    size_t matrices_cap;
    double *S, *T;
    double *work;               /* one cluster's work copy, during a start only (shared) */
    gsl_eigen_symmv_workspace *eigen;
    int jacobian_status;
    size_t bad_row, bad_col;

    /* Output rows of large clusters from the Taylor series about the last step end
     * (exact_rows.c): K of their pairs as compressed rows, the state at that step end, the
     * series' work vectors. */
    size_t *series;             /* per cluster: its rows come from the series (2: damped) */
    size_t n_series;            /* clusters whose rows do */
    double *cluster_omega;      /* per cluster: its largest angular frequency; when damped, a
                                   bound on every rate of its motion (exact_rows.c) */
    size_t *row_start, *row_col;/* p + 1; one per coupling of those clusters */
    double *row_value;
    size_t row_col_cap, row_value_cap;
    size_t *damp_start, *damp_col; /* D's rows of those clusters, the same way */
    double *damp_value;
    size_t damp_col_cap, damp_value_cap;
    double *yc, tc;             /* 2 p: the pairs at the last step end, and its time */
    double *even, *odd, *next_even, *next_odd; /* p each */

    /* Root functions. */
    size_t roots_cap;
    int *direction;
    signed char *sign;          /* last non-zero sign seen; 0 = inactive (zero so far) */
    int *found;
    double *g_hi, *g_try, *root_t;
    double g_try_time;          /* when g_try was evaluated (NAN: not since the start) */
    exact_shared *shared;

    bk_solver_counters counters;
} exact_backend;


/* exact_matrices.c: the affine forcing at t0 and K, P, Q (from the Jacobian when the problem
 * has one, else one probe per column); the right-hand side checked for finite values. */
int bk_exact_read_problem(exact_backend *eb, bk_error *err);
/* exact_work.c: the thread's shared work space, taken by every instance (NULL: out of
 * memory) and given back when it is destroyed. */
exact_shared *bk_exact_shared_acquire(void);
void bk_exact_shared_release(exact_shared *s);
/* exact_work.c: room for a start of n components (p pairs, m quadratures, n_roots root
 * functions): the shared work space and the instance's own arena, pointers set into both. */
int bk_exact_reserve(exact_backend *eb, size_t n, size_t p, size_t m, size_t n_roots, bk_error *err);
/* exact_work.c: room for n_couplings + 1 couplings in shared->couplings (n_dampings + 1 in
 * shared->dampings); -1: out of memory. */
int bk_exact_reserve_coupling(exact_backend *eb);
int bk_exact_reserve_damping(exact_backend *eb);
/* exact_work.c: the shared work copy for a cluster of `largest` pairs into eb->work. */
int bk_exact_reserve_work(exact_backend *eb, size_t largest, bk_error *err);
/* exact_modes.c: clusters and their modes (after bk_exact_read_problem); the exact state at t. */
int bk_exact_modes(exact_backend *eb, bk_error *err);
void bk_exact_state(exact_backend *eb, double t, double *y);
/* exact_modes.c, bk_exact_state's three parts: the modes' amplitudes at tau = t - t0 (O(p)),
 * one cluster's pairs from them (O(size^2), O(size) when uniform), the quadratures (O(m p)). */
void bk_exact_modal_amplitudes(exact_backend *eb, double tau);
void bk_exact_cluster_state(const exact_backend *eb, size_t cl, double *y);
void bk_exact_quadratures(const exact_backend *eb, double tau, double *y);
/* exact_damped.c: a damped mode's characteristic roots, -gamma / 2 +- i root (root > 0,
 * underdamped), -gamma / 2 +- |root| (root < 0, overdamped) or -gamma / 2 twice (root = 0),
 * and radius, the largest root's modulus (1 / s); its basis phi[1..4] at tau. */
void bk_exact_damped_root(double w2, double gamma, double *root, double *radius);
void bk_exact_damped_basis(double w2, double gamma, double root, double radius, double tau, double phi[5]);
/* exact_damped.c: phi_0 .. phi_3 of the exponential integrators at x <= 0 (e^x, and
 * phi_k = (phi_{k-1} - 1/(k-1)!) / x), and at complex z with Re z <= 0; 1 / n!, n < 64. */
void bk_exact_exp_phis(double x, double out[4]);
void bk_exact_exp_phis_complex(double re, double im, double out_re[4], double out_im[4]);
extern const double bk_exact_inverse_factorial[64];
/* exact_modes.c: the sampling step for a step starting at t. */
double bk_exact_sampling_step(exact_backend *eb, double t);
/* exact_coupled.c: the state-space modes of every cluster marked coupled (after the other
 * clusters' modes, while S and the symmetrised damping are in place; *rate_max grows to
 * their oscillations' rates, their decays join the fast list); the amplitudes at tau, a
 * coupled cluster's pairs, the coupled clusters' shares of quadrature j and of the
 * dissipation. */
int bk_exact_coupled_modes(exact_backend *eb, double *rate_max, bk_error *err);
void bk_exact_coupled_amplitudes(exact_backend *eb, double tau);
void bk_exact_coupled_state(const exact_backend *eb, size_t cl, double *y);
double bk_exact_coupled_quadrature(const exact_backend *eb, size_t j);
double bk_exact_coupled_dissipation(const exact_backend *eb, double tau);
/* exact_rows.c: which clusters' rows come from the series, and their K (after
 * bk_exact_modes, while the couplings are in the shared work space); the state at t for an
 * output row, every cluster in O(its size). */
int bk_exact_rows_prepare(exact_backend *eb, bk_error *err);
void bk_exact_row_state(exact_backend *eb, double t, double *y);

#endif
