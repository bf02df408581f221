/* method = auto: the cheapest adequate back-end for the scene, from bench/ measurements.
 *
 * A Coulomb scene is linear with constant coefficients between transitions, so the exact
 * stepper is both exact and the fastest (up to AUTO_EXACT_MAX_BLOCKS blocks, see there), with
 * dashpots too as long as they are proportional to the masses and springs (each slipping
 * stretch's modes then decouple) and do not overdamp the fastest modes heavily (see
 * AUTO_EXACT_MAX_OVERDAMPING).  Other dashpots it solves in each stretch's state space,
 * no faster than gsl_rk8pd (1e3-block random chain, [block] damping = uniform(10, 30): 2.0 s
 * against 1.9 s for 4e4 transitions) and refused where two modes merge, so those scenes get
 * an integrator.  Otherwise an
 * explicit Runge-Kutta pair is cheapest unless the problem is stiff.  The stiffness measure
 * is the fastest decay rate of the linearised problem over its fastest oscillation
 * frequency, on a probe state (every block sliding at the driver speed, initial friction
 * state); for the paper's law it scales as 1/L0 (the state relaxes over a slip of L0), 2.3 at
 * the paper's L0 = 2e-5 m.  CPU of
 * gsl_rk8pd / cvode_bdf at rtol 1e-8 on cases A, B, C (5 s) as L0 shrinks:
 *   ratio 2.3: 0.33, 0.23, 0.38;  23: 0.8, 0.56, 0.35;  77: 1.9, 0.92, 0.57;
 *   230: 3.8, 1.5, 0.81;  2300: 28, 8.6, 3.1
 * so the switch at STIFF_RATIO = 50 costs at most 1.8x against the better of the two, where
 * always-BDF costs 4x on the paper's own cases and always-RK 28x on a stiff state. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/driver.h"
#include "method_choice.h"

/* Largest Coulomb chain auto gives the exact stepper; measured per transition, exact vs
 * gsl_rk8pd at default tolerances (bench/ machine):
 *   random chain (bk1000_coulomb.ini), 2 s:  1e3 blocks 9.6 vs 18 us, 1e5 blocks 18 vs 27 us;
 *   uniform chain (slides as one):           1e3 blocks 6.5 vs 8 us;
 *   nearly uniform (x_init_random = 1e-9, slips spread over one growing cluster, each
 *   transition restarting it: O(p^2) for exact's eigen-solver, O(p) for the integrator):
 *   1e3 blocks 1.1 ms vs 0.35 ms, 3e3 blocks 3.8 vs 0.9 ms.
 * So exact up to 1e3 blocks (2x faster on the usual heterogeneous chain, 3x slower at
 * worst); beyond, the worst case grows with N and the integrator is the safe default.
 * Dashpots ([block] damping = 20 N s/m, damping ratio 0.1 on the driver spring) change
 * neither side of that: random chain, 1e3 blocks, 2 s: exact 24 vs gsl_rk8pd 45 us per
 * transition (0.5 s at equal error, bench/ chain1000_damped: 9.8 ms against 28 ms at rtol
 * 1e-10); with coupling dashpots as well (coupling_damping = 100): 16 vs 35 us; nearly
 * uniform: 1.5 ms vs 0.35 ms at 1e3 blocks, 0.26 vs 0.15 ms at 300 (the damped modes cost
 * an exponential more per probe).  So the same limits.  A
 * ring that slips all round is one cyclic cluster, dense and p^3 per restart (1e3 nearly
 * uniform blocks: 4.9 ms vs 0.37 ms per transition), so rings keep the earlier 100; so do
 * lattices of more than one row and column, whose clusters are never tridiagonal either. */
#define AUTO_EXACT_MAX_BLOCKS 1000
#define AUTO_EXACT_MAX_RING 100
/* Heavily overdamped fast modes cost the exact stepper samples (each restart samples at 16
 * per 2 pi of their decay rate until they have decayed, 40 decay times) that an explicit
 * integrator, bounded by its stability on the same rate, spends as steps; the random
 * 1000-block chain, 0.5 s, CPU exact vs gsl_rk8pd at rtol 1e-10, against the estimate below:
 *   [block] damping 200: 0.33, 0.019 vs 0.043 s;  600: 1.0, 0.033 vs 0.038;  2000: 3.3, 0.044
 *   vs 0.038;  coupling_damping 100: 0.7, 0.017 vs 0.041;  300: 2.0, 0.042 vs 0.055;  1000:
 *   6.7, 0.076 vs 0.048;  2000: 13, 0.092 vs 0.068.
 * So exact up to an estimated damping ratio of 2.5. */
#define AUTO_EXACT_MAX_OVERDAMPING 2.5
#define STIFF_RATIO 50.0
/* The fewest blocks for which method = auto cuts a chain that never sticks into segments:
 * CPU per rupture on the Dieterich-Ruina ring (bench/rs_chains.tsv, rtol 1e-8), whole vs in
 * segments of 8: 30 vs 39 ms at N = 30, 46 vs 41 ms at N = 100, 0.25 vs 0.047 s at 3000;
 * the two cross near N = 70. */
#define AUTO_LOCAL_MIN_BLOCKS 72

typedef struct probe_matrix {
    const bk_scene *scene;
    double *diagonal;   /* n_y: d f_r / d y_r */
    double *omega2;     /* n blocks: -d accel_i / d xi_i, (rad/s)^2 */
    size_t *velocity_row_block; /* n_y: block whose velocity sits in row r, or SIZE_MAX */
} probe_matrix;

static void put_entry(void *matrix, size_t row, size_t col, double value)
{
    probe_matrix *m = matrix;
    if (row == col)
        m->diagonal[row] += value;
    size_t i = m->velocity_row_block[row];
    if (i != SIZE_MAX && col == m->scene->slot[i])
        m->omega2[i] -= value;
}

double bk_stiffness_ratio(const bk_model *model)
{
    bk_scene probe;
    if (bk_scene_init(&probe, model, 0) != 0)
        return NAN;
    /* Every block slipping: one island, the whole chain. */
    size_t n = model->n_blocks, n_max = bk_island_max_y(&probe, n);
    bk_island island = {.scene = &probe, .id = 0, .len = n};
    double *y = calloc(n_max, sizeof *y);
    double *diagonal = calloc(n_max, sizeof *diagonal);
    double *omega2 = calloc(n, sizeof *omega2);
    size_t *velocity_row_block = malloc(n_max * sizeof *velocity_row_block);
    double ratio = NAN;
    if (y && diagonal && omega2 && velocity_row_block && bk_island_reserve(&island, n) == 0) {
        for (size_t i = 0; i < n; ++i)
            island.blocks[i] = i;
        double speed = fabs(model->driver.velocity); /* a history's first non-zero speed */
        for (size_t i = 0; i < n; ++i) {
            probe.mode[i] = BK_MODE_SLIP_POS;
            probe.v[i] = speed;
        }
        bk_island_restart(&island, 0.0, y);
        for (size_t r = 0; r < n_max; ++r)
            velocity_row_block[r] = SIZE_MAX;
        for (size_t i = 0; i < n; ++i)
            velocity_row_block[probe.slot[i] + 1] = i;
        probe_matrix m = {&probe, diagonal, omega2, velocity_row_block};
        if (bk_island_jacobian(0.0, y, &island, put_entry, &m) == 0) {
            double decay = 0.0, omega2_max = 0.0;
            for (size_t r = 0; r < island.n_y; ++r)
                decay = fmax(decay, -diagonal[r]);
            for (size_t i = 0; i < n; ++i)
                omega2_max = fmax(omega2_max, omega2[i]);
            ratio = omega2_max > 0.0 ? decay / sqrt(omega2_max) : (decay > 0.0 ? INFINITY : 0.0);
        }
    }
    free(y);
    free(diagonal);
    free(omega2);
    free(velocity_row_block);
    bk_island_free(&island);
    bk_scene_free(&probe);
    return ratio;
}

/* The damping ratio of the fastest modes, from Gershgorin bounds: the largest row sum of
 * M^-1 C over twice the largest angular frequency (0 without dashpots). */
static double overdamping(const bk_model *model)
{
    double gamma = 0.0;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        const bk_block *b = &model->blocks[i];
        if (!(b->mass > 0.0))
            continue;
        double row = b->damping + 2.0 * bk_model_coupling_count(model, i) * model->coupling_damping;
        gamma = fmax(gamma, row / b->mass);
    }
    double omega = bk_model_max_angular_frequency(model);
    return omega > 0.0 ? gamma / (2.0 * omega) : (gamma > 0.0 ? INFINITY : 0.0);
}

/* The scene stays one island whatever happens (no block sticks, no spring goes slack), and
 * local stepping is not switched off. */
static int local_stepping_applies(const bk_config *config, const bk_scene *scene)
{
    if (strcmp(config->solver.local_stepping, "off") == 0 || scene->model->spring != BK_SPRING_LINEAR)
        return 0;
    for (size_t i = 0; i < scene->n; ++i)
        if (scene->can_stick[i])
            return 0;
    return 1;
}

const char *bk_choose_method(const bk_config *config, const bk_scene *scene)
{
    if (strcmp(config->solver.method, "auto") != 0)
        return config->solver.method;
    const bk_model *m = config->model;
    /* A single row or column is a chain (walls beside it only stiffen the diagonal); its
     * clusters are tridiagonal unless it closes into a ring. */
    int line = m->rows == 1 || m->cols == 1;
    bk_boundary along = m->rows == 1 ? m->boundary_cols : m->boundary_rows;
    int dense_clusters = !line || along == BK_BOUNDARY_PERIODIC;
    size_t exact_max = dense_clusters ? AUTO_EXACT_MAX_RING : AUTO_EXACT_MAX_BLOCKS;
    if (scene->affine && scene->n <= exact_max &&
        (!scene->damped || (bk_model_damping_proportional(m) && overdamping(m) <= AUTO_EXACT_MAX_OVERDAMPING)))
        return "exact";
    /* A long chain that never sticks is cut into segments, which need CVODE's predictor. */
    if (local_stepping_applies(config, scene) && scene->n >= AUTO_LOCAL_MIN_BLOCKS)
        return "cvode_bdf";
    double ratio = bk_stiffness_ratio(config->model);
    return ratio <= STIFF_RATIO ? "gsl_rk8pd" : "cvode_bdf"; /* NaN (no probe): the safe one */
}

size_t bk_choose_segments(const bk_config *config, const bk_scene *scene, const bk_solver_backend *backend)
{
    const char *local = config->solver.local_stepping;
    int on = strcmp(local, "on") == 0;
    int automatic = strcmp(local, "auto") == 0 && strcmp(config->solver.method, "auto") == 0;
    if (!on && !automatic)
        return 0;
    if (!backend->set_stop || !backend->predictor || backend->wants_full_layout ||
        !local_stepping_applies(config, scene))
        return 0;
    size_t segment = config->solver.segment_blocks > 1 ? (size_t)config->solver.segment_blocks : 8;
    if (automatic && (scene->n < AUTO_LOCAL_MIN_BLOCKS || scene->n < 2 * segment))
        return 0;
    return scene->n > segment ? segment : 0;
}
