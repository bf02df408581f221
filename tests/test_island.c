/* An island's compact ODE (src/island.c): only slipping blocks are integrated, stateless
 * laws carry no state, and every root function of a block that just switched starts clearly
 * away from zero.  IDA's full layout: stuck blocks stay in, pinned by an algebraic row whose
 * residual is v.  Islands that are part of a chain: blocks outside stay fixed ends. */
#include <stdint.h>
#include <stdlib.h>

#include "bk_test.h"
#include "bksim/model.h"
#include "scene.h"

static bk_model *make_chain(size_t n, bk_spring spring)
{
    bk_model *m = bk_model_create(n);
    assert_non_null(m);
    m->coupling_stiffness = 2e4;
    m->spring = spring;
    m->driver.velocity = 1e-3;
    for (size_t i = 0; i < n; ++i) {
        m->blocks[i].mass = 1.0;
        m->blocks[i].driver_stiffness = 1e4;
        m->blocks[i].normal_force = 9.81;
        m->blocks[i].law = &bk_friction_coulomb;
        m->blocks[i].friction_params[0] = 0.6;
        m->blocks[i].friction_params[1] = 0.5;
    }
    bk_model_finalize(m);
    return m;
}

/* An island over blocks [start, start + len) of the scene's chain. */
static bk_island island_of(bk_scene *s, size_t id, size_t start, size_t len)
{
    bk_island island = {.scene = s, .id = id, .len = len};
    assert_int_equal(bk_island_reserve(&island, len), 0);
    for (size_t k = 0; k < len; ++k)
        island.blocks[k] = (start + k) % s->n;
    return island;
}

static void test_layout(void **state)
{
    (void)state;
    bk_model *m = make_chain(4, BK_SPRING_LINEAR);
    assert_int_equal(m->n_friction_state, 0); /* Coulomb carries no state */
    bk_scene s;
    assert_int_equal(bk_scene_init(&s, m, 1), 0);
    s.mode[1] = BK_MODE_SLIP_POS;
    s.mode[3] = BK_MODE_SLIP_NEG;
    s.v[1] = 0.01;
    s.v[3] = -0.02;
    s.v[0] = 0.5; /* a stuck block's velocity is forced to zero */
    double y[16];
    bk_island isl = island_of(&s, 0, 0, 4);
    bk_island_restart(&isl, 0.3, y);
    assert_int_equal(isl.n_y, 2 * 2 + 2); /* two slipping blocks, plus two energy increments */
    assert_int_equal(isl.n_active, 2);
    assert_true(s.slot[0] == SIZE_MAX && s.slot[2] == SIZE_MAX);
    assert_close(y[s.slot[1]], 0.0, 0, 0);
    assert_close(y[s.slot[1] + 1], 0.01, 0, 0);
    assert_close(y[s.slot[3] + 1], -0.02, 0, 0);
    assert_close(s.v[0], 0.0, 0, 0);
    /* Unpacking returns slip since the restart on top of the reference positions. */
    y[s.slot[1]] = 2.5e-5;
    y[isl.n_y - 2] = 0.125;
    y[isl.n_y - 1] = 0.0625;
    bk_energy increments;
    bk_island_unpack(&isl, 0.31, y, &increments);
    assert_close(s.x[1], 2.5e-5, 1e-15, 0);
    assert_close(s.x[0], 0.0, 0, 0);
    assert_close(increments.work, 0.125, 0, 0);
    assert_close(increments.friction, 0.0625, 0, 0);
    assert_close(increments.damping, 0.0, 0, 0);
    bk_island_free(&isl);
    bk_scene_free(&s);
    bk_model_free(m);
}

/* The full layout keeps a stuck block's (xi, v): xi' = v is differential, the residual
 * diag(id) y' - f of its velocity row is exactly v with id 0, and the slipping blocks'
 * rows, energy rates and roots are those of the compact ODE. */
static void test_full_layout(void **state)
{
    (void)state;
    bk_model *m = make_chain(4, BK_SPRING_LINEAR);
    bk_scene compact, full;
    assert_int_equal(bk_scene_init(&compact, m, 1), 0);
    assert_int_equal(bk_scene_init(&full, m, 1), 0);
    full.full_layout = 1;
    bk_island islands[2] = {island_of(&compact, 0, 0, 4), island_of(&full, 0, 0, 4)};
    double y[2][16], ydot[2][16], g[2][8], t = 0.3;
    for (size_t k = 0; k < 2; ++k) {
        bk_scene *s = islands[k].scene;
        s->x[0] = 1e-4;
        s->x[2] = -0.5e-4;
        s->mode[1] = BK_MODE_SLIP_POS;
        s->mode[3] = BK_MODE_SLIP_NEG;
        s->v[1] = 0.01;
        s->v[3] = -0.02;
        s->v[0] = 0.5; /* a stuck block's velocity is forced to zero */
        bk_island_restart(&islands[k], t, y[k]);
    }
    const bk_island *fi = &islands[1], *ci = &islands[0];
    assert_int_equal(fi->n_y, 4 * 2 + 2);
    assert_int_equal(fi->n_active, 2);
    for (size_t i = 0; i < 4; ++i) {
        size_t s = full.slot[i];
        assert_true(s != SIZE_MAX);
        assert_close(fi->differential_id[s], 1.0, 0, 0);
        assert_close(fi->differential_id[s + 1], i % 2 == 0 ? 0.0 : 1.0, 0, 0);
    }
    assert_close(fi->differential_id[fi->n_y - 2], 1.0, 0, 0);
    assert_close(fi->differential_id[fi->n_y - 1], 1.0, 0, 0);
    size_t stuck = full.slot[2];
    assert_close(y[1][stuck], 0.0, 0, 0);
    assert_close(y[1][stuck + 1], 0.0, 0, 0);
    for (size_t k = 0; k < 2; ++k) {
        bk_island_rhs(t + 1e-3, y[k], ydot[k], &islands[k]);
        bk_island_roots(t + 1e-3, y[k], g[k], &islands[k]);
    }
    for (size_t i = 1; i < 4; i += 2)
        for (size_t c = 0; c < 2; ++c)
            assert_close(ydot[1][full.slot[i] + c], ydot[0][compact.slot[i] + c], 0, 0);
    for (size_t c = 1; c <= 2; ++c)
        assert_close(ydot[1][fi->n_y - c], ydot[0][ci->n_y - c], 0, 0);
    for (size_t r = 0; r < 4 * compact.roots_per_block; ++r)
        assert_close(g[1][r], g[0][r], 0, 0);
    /* Off the constraint (a Newton iterate), the residual of the velocity row reads v. */
    y[1][stuck + 1] = 0.25;
    bk_island_rhs(t, y[1], ydot[1], &islands[1]);
    double yp_stuck_v = 123.0; /* any: an algebraic row has no y' term */
    double residual = fi->differential_id[stuck + 1] * yp_stuck_v - ydot[1][stuck + 1];
    assert_close(residual, 0.25, 0, 0);
    assert_close(ydot[1][stuck], 0.25, 0, 0); /* xi' = v */
    bk_island_free(&islands[0]);
    bk_island_free(&islands[1]);
    bk_scene_free(&compact);
    bk_scene_free(&full);
    bk_model_free(m);
}

/* dv/dt of a slipping block is (applied force - s f_k) / m; the island's energy rates are
 * its slipping blocks' (the driver's work on a stuck block is counted in closed form by the
 * run loop). */
static void test_rhs(void **state)
{
    (void)state;
    bk_model *m = make_chain(2, BK_SPRING_LINEAR);
    bk_scene s;
    assert_int_equal(bk_scene_init(&s, m, 1), 0);
    s.x[0] = 1e-4;
    s.x[1] = -2e-4;
    s.mode[0] = BK_MODE_SLIP_POS;
    s.v[0] = 3e-3;
    double y[8], ydot[8];
    bk_island isl = island_of(&s, 0, 0, 2);
    bk_island_restart(&isl, 0.5, y);
    bk_island_rhs(0.5, y, ydot, &isl);
    double D = 0.5e-3;
    double applied = 1e4 * (D - 1e-4) + 2e4 * (-2e-4 - 1e-4);
    assert_close(ydot[s.slot[0]], 3e-3, 0, 0);
    assert_close(ydot[s.slot[0] + 1], applied - 0.5 * 9.81, 1e-14, 0);
    double driver_power = 1e-3 * (1e4 * (D - 1e-4));
    assert_close(ydot[isl.n_y - 2], driver_power, 1e-14, 0);
    assert_close(ydot[isl.n_y - 1], 0.5 * 9.81 * 3e-3, 1e-14, 0);
    bk_island_free(&isl);
    bk_scene_free(&s);
    bk_model_free(m);
}

/* Dashpots: a slipping block feels its own damping and the coupling dashpot to its stuck
 * neighbour, the stuck neighbour's breakaway root feels the same dashpot's pull, and the
 * dashpots dissipate (eta + etac) v^2 in an energy increment of their own. */
static void test_damped_rhs(void **state)
{
    (void)state;
    bk_model *m = make_chain(2, BK_SPRING_LINEAR);
    m->blocks[0].damping = 1.5;
    m->coupling_damping = 4.25;
    bk_scene s;
    assert_int_equal(bk_scene_init(&s, m, 1), 0);
    assert_true(s.damped);
    assert_int_equal(s.n_energy, 3);
    s.x[0] = 1e-4;
    s.x[1] = -2e-4;
    s.mode[0] = BK_MODE_SLIP_POS;
    s.v[0] = 3e-3;
    double y[8], ydot[8], g[4];
    bk_island isl = island_of(&s, 0, 0, 2);
    bk_island_restart(&isl, 0.5, y);
    assert_int_equal(isl.n_y, 5);
    bk_island_rhs(0.5, y, ydot, &isl);
    double D = 0.5e-3, v = 3e-3;
    double applied = 1e4 * (D - 1e-4) + 2e4 * (-2e-4 - 1e-4) - 1.5 * v - 4.25 * v;
    assert_close(ydot[s.slot[0] + 1], applied - 0.5 * 9.81, 1e-14, 0);
    assert_close(ydot[isl.n_y - 3], 1e-3 * (1e4 * (D - 1e-4)), 1e-14, 0);
    assert_close(ydot[isl.n_y - 2], 0.5 * 9.81 * v, 1e-14, 0);
    assert_close(ydot[isl.n_y - 1], (1.5 + 4.25) * v * v, 1e-14, 0);
    bk_island_roots(0.5, y, g, &isl);
    double on_stuck = 1e4 * (D + 2e-4) + 2e4 * (1e-4 + 2e-4) + 4.25 * v;
    assert_close(g[s.roots_per_block + BK_ROOT_MAIN], 0.6 * 9.81 - fabs(on_stuck), 1e-14, 0);
    /* The chain's own view of the same force, from the unpacked velocities. */
    bk_island_unpack(&isl, 0.5, y, NULL);
    assert_close(bk_scene_applied_force(&s, 1, D), on_stuck, 1e-14, 0);
    bk_island_free(&isl);
    bk_scene_free(&s);
    bk_model_free(m);
}

/* Right after a switch, each of the block's root functions is clearly non-zero, so a
 * restarted integrator cannot see the handled root again. */
static void test_roots_clear_of_zero_after_switch(void **state)
{
    (void)state;
    const bk_spring springs[] = {BK_SPRING_LINEAR, BK_SPRING_TENSION_ONLY};
    for (size_t sp = 0; sp < 2; ++sp) {
        bk_model *m = make_chain(3, springs[sp]);
        bk_scene s;
        assert_int_equal(bk_scene_init(&s, m, 1), 0);
        size_t R = s.roots_per_block;
        double t = 0.7, D = 0.7e-3;
        /* Block 1 just broke away at its threshold; block 2 just stopped below it. */
        m->coupling_stiffness = 0.0;
        s.x[1] = D - 0.6 * 9.81 / 1e4;          /* driver spring at mu_s N */
        s.x[0] = s.x[2] = D - 0.3 * 9.81 / 1e4; /* at half their threshold */
        s.mode[1] = BK_MODE_SLIP_POS;
        s.t_switch[1] = t;
        s.from_rest[1] = 1;
        s.v[1] = 0.0;
        double y[16], g[12];
        bk_island isl = island_of(&s, 0, 0, 3);
        bk_island_restart(&isl, t, y);
        bk_island_roots(t, y, g, &isl);
        double accel = (0.6 - 0.5) * 9.81;               /* (F_s - f_k) / m */
        assert_close(g[R * 1 + BK_ROOT_MAIN], accel, 1e-9, 0); /* stop: s v / (t - t_switch) -> s a */
        /* The minimum root waits for a deceleration: it reads +1 until then. */
        assert_close(g[R * 1 + BK_ROOT_EXTREMUM], 1.0, 0, 0);
        /* A moment later the stop function is s v / dt, still about s a. */
        double ydot[16];
        bk_island_rhs(t, y, ydot, &isl);
        double y1[16];
        for (size_t k = 0; k < isl.n_y; ++k)
            y1[k] = y[k] + 1e-9 * ydot[k];
        bk_island_roots(t + 1e-9, y1, g, &isl);
        assert_close(g[R * 1 + BK_ROOT_MAIN], accel, 1e-6, 0);
        /* The stuck neighbours sit well inside their thresholds. */
        assert_true(g[R * 0 + BK_ROOT_MAIN] > 0.1);
        if (R > 2)
            assert_true(g[R * 1 + BK_ROOT_SLACK] > 1e-4);
        bk_island_free(&isl);
        bk_scene_free(&s);
        bk_model_free(m);
    }
}

/* The minimum root arms once the block is seen decelerating, and then reads s a. */
static void test_minimum_root_arming(void **state)
{
    (void)state;
    bk_model *m = make_chain(1, BK_SPRING_LINEAR);
    bk_scene s;
    assert_int_equal(bk_scene_init(&s, m, 1), 0);
    s.mode[0] = BK_MODE_SLIP_POS;
    s.v[0] = 0.02;
    s.x[0] = 0.0; /* driver at 0: the spring is relaxed, friction decelerates the block */
    double y[8], g[4];
    bk_island isl = island_of(&s, 0, 0, 1);
    bk_island_restart(&isl, 0.0, y);
    assert_int_equal(s.extremum_armed[0], 1); /* decelerating already */
    bk_island_roots(0.0, y, g, &isl);
    assert_close(g[BK_ROOT_EXTREMUM], -0.5 * 9.81, 1e-12, 0);
    s.extremum_armed[0] = 0; /* as after a minimum */
    bk_island_roots(0.0, y, g, &isl);
    assert_close(g[BK_ROOT_EXTREMUM], 1.0, 0, 0);
    bk_island_arm(&isl, 0.0, y);
    assert_int_equal(s.extremum_armed[0], 1);
    bk_island_free(&isl);
    bk_scene_free(&s);
    bk_model_free(m);
}

/* A slack tension-only spring stays slack in the right-hand side until the restart at the
 * slack/taut root flips it: the integrator sees a smooth problem. */
static void test_tension_only_frozen(void **state)
{
    (void)state;
    bk_model *m = make_chain(1, BK_SPRING_TENSION_ONLY);
    bk_scene s;
    assert_int_equal(bk_scene_init(&s, m, 1), 0);
    s.mode[0] = BK_MODE_SLIP_POS;
    s.v[0] = 0.05;
    s.x[0] = 1.2e-3; /* ahead of the driver at 1e-3: slack */
    double y[8], ydot[8];
    bk_island isl = island_of(&s, 0, 0, 1);
    bk_island_restart(&isl, 1.0, y);
    assert_int_equal(s.taut[0], 0);
    y[s.slot[0]] = -0.5e-3; /* a trial state behind the driver: still treated as slack */
    bk_island_rhs(1.0, y, ydot, &isl);
    assert_close(ydot[s.slot[0] + 1], -0.5 * 9.81, 1e-14, 0);
    bk_island_free(&isl);
    bk_scene_free(&s);
    bk_model_free(m);
}

enum { CHAIN, LATTICE_WALLS, TORUS };
#define MAX_N 9
#define MAX_Y (MAX_N * 3 + 3)

typedef struct dense {
    size_t n;
    double *a;
} dense;

static void put_dense(void *matrix, size_t row, size_t col, double value)
{
    dense *d = matrix;
    d->a[row * d->n + col] += value;
}

/* The whole right-hand side, or the implicit (friction) part of its IMEX split. */
static void evaluate(bk_island *island, int implicit_part, double t, const double *y, double *out)
{
    if (implicit_part) {
        double rest[MAX_Y];
        assert_int_equal(bk_island_rhs_split(t, y, rest, out, island), 0);
    } else {
        assert_int_equal(bk_island_rhs(t, y, out, island), 0);
    }
}

/* The analytic Jacobian matches central differences of the right-hand side, for a chain
 * mixing Coulomb and the paper's rate-and-state law, tension-only springs, a periodic
 * wrap, slipping and stuck blocks; in the compact and the full layout; and the same for
 * the friction part of the IMEX split, whose two parts add up to the right-hand side.  On
 * a 3 x 3 lattice (walls above and below, or a torus) the same; with walls, every entry
 * off the energy rows lies within the declared half bandwidth, a row apart. */
static void check_jacobian(int full_layout, int implicit_part, int damped, int shape)
{
    size_t nb = shape == CHAIN ? 4 : 9;
    bk_model *m = make_chain(nb, BK_SPRING_TENSION_ONLY);
    m->boundary_cols = BK_BOUNDARY_PERIODIC;
    if (shape != CHAIN) {
        m->rows = m->cols = 3;
        m->boundary_rows = shape == TORUS ? BK_BOUNDARY_PERIODIC : BK_BOUNDARY_FIXED;
        m->boundary_cols = shape == TORUS ? BK_BOUNDARY_PERIODIC : BK_BOUNDARY_FREE;
    }
    if (damped) {
        m->coupling_damping = 3.5;
        for (size_t i = 0; i < nb; ++i)
            m->blocks[i].damping = 0.75 + 0.5 * (double)i;
    }
    m->blocks[1].law = &bk_friction_rate_state;
    m->blocks[2].law = &bk_friction_rate_state;
    for (size_t i = 1; i <= 2; ++i) {
        const bk_friction_law *law = m->blocks[i].law;
        for (size_t k = 0; k < law->n_params; ++k)
            m->blocks[i].friction_params[k] = law->params[k].default_value;
        bk_friction_context ctx = {1e-3, 9.81};
        law->complete(m->blocks[i].friction_params, &ctx);
    }
    bk_model_finalize(m);
    bk_scene s;
    assert_int_equal(bk_scene_init(&s, m, 1), 0);
    s.full_layout = full_layout;
    const double x[MAX_N] = {1e-4, -2e-4, 3e-4, 0.5e-4, -1e-4, 2.5e-4, 0.2e-4, -0.7e-4, 1.3e-4};
    const double v[MAX_N] = {3e-3, -2e-3, 0.0, 1e-3, 2e-3, 0.0, 4e-3, -1e-3, 1.5e-3};
    const int8_t modes[MAX_N] = {BK_MODE_SLIP_POS, BK_MODE_SLIP_NEG, BK_MODE_STICK, BK_MODE_SLIP_POS,
                                 BK_MODE_SLIP_POS, BK_MODE_STICK,    BK_MODE_SLIP_POS, BK_MODE_SLIP_NEG,
                                 BK_MODE_SLIP_POS};
    for (size_t i = 0; i < nb; ++i) {
        s.x[i] = x[i];
        s.v[i] = v[i];
        s.mode[i] = modes[i];
    }
    double y[MAX_Y], t = 0.4;
    bk_island isl = island_of(&s, 0, 0, nb);
    bk_island_restart(&isl, t, y);
    size_t n = isl.n_y;
    dense jac = {n, calloc(n * n, sizeof(double))};
    assert_non_null(jac.a);
    if (implicit_part) {
        assert_int_equal(bk_island_jacobian_implicit(t, y, &isl, put_dense, &jac), 0);
        double whole[MAX_Y], f_explicit[MAX_Y], f_implicit[MAX_Y];
        bk_island_rhs(t, y, whole, &isl);
        bk_island_rhs_split(t, y, f_explicit, f_implicit, &isl);
        for (size_t r = 0; r < n; ++r)
            assert_close(f_explicit[r] + f_implicit[r], whole[r], 1e-15, 1e-300);
        /* Friction only: positions and the energy quadratures are all explicit. */
        for (size_t i = 0; i < nb; ++i)
            if (s.slot[i] != SIZE_MAX)
                assert_true(f_implicit[s.slot[i]] == 0.0);
        for (size_t e = n - s.n_energy; e < n; ++e)
            assert_true(f_implicit[e] == 0.0);
        assert_true(f_implicit[s.state_slot[1]] != 0.0);
    } else {
        assert_int_equal(bk_island_jacobian(t, y, &isl, put_dense, &jac), 0);
    }
    double up[MAX_Y], down[MAX_Y];
    for (size_t c = 0; c < n; ++c) {
        double saved = y[c], h = 1e-7 * fmax(fabs(saved), 1e-2); /* 1e-2: not below rounding where y is 0 */
        y[c] = saved + h;
        evaluate(&isl, implicit_part, t, y, up);
        y[c] = saved - h;
        evaluate(&isl, implicit_part, t, y, down);
        y[c] = saved;
        for (size_t r = 0; r < n; ++r) {
            double fd = (up[r] - down[r]) / (2 * h);
            double scale = fmax(fabs(fd), fabs(jac.a[r * n + c]));
            if (fabs(fd - jac.a[r * n + c]) > 1e-5 * scale + 1e-9)
                fail_msg("J[%zu][%zu] = %.10g, difference quotient %.10g", r, c, jac.a[r * n + c], fd);
            size_t distance = r > c ? r - c : c - r;
            if (shape == LATTICE_WALLS && r < n - s.n_energy && distance > isl.half_bandwidth && jac.a[r * n + c] != 0.0)
                fail_msg("J[%zu][%zu] = %.10g outside the half bandwidth %zu", r, c, jac.a[r * n + c],
                         isl.half_bandwidth);
        }
    }
    if (shape == LATTICE_WALLS) /* a row apart: more than a chain's neighbours */
        assert_true(isl.half_bandwidth > 3 + s.max_block_state);
    free(jac.a);
    bk_island_free(&isl);
    bk_scene_free(&s);
    bk_model_free(m);
}

static void test_jacobian(void **state)
{
    (void)state;
    for (int shape = CHAIN; shape <= TORUS; ++shape)
        for (int damped = 0; damped < 2; ++damped) {
            check_jacobian(0, 0, damped, shape);
            check_jacobian(1, 0, damped, shape);
            check_jacobian(0, 1, damped, shape);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layout),
        cmocka_unit_test(test_full_layout),
        cmocka_unit_test(test_rhs),
        cmocka_unit_test(test_damped_rhs),
        cmocka_unit_test(test_roots_clear_of_zero_after_switch),
        cmocka_unit_test(test_minimum_root_arming),
        cmocka_unit_test(test_tension_only_frozen),
        cmocka_unit_test(test_jacobian),
    };
    return cmocka_run_group_tests_name("island", tests, NULL, NULL);
}
