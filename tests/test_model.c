/* Chain and lattice forces and energies: hand-computed forces for every boundary, energy
 * gradients against forces, the frequency bound against GSL's eigenvalues, the step time
 * scale (damped period, else friction relaxation time) against closed forms. */
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_matrix.h>
#include <stdlib.h>

#include "bk_test.h"
#include "bksim/model.h"

static bk_model *make_chain(size_t n, bk_boundary boundary, bk_spring spring)
{
    bk_model *m = bk_model_create(n);
    assert_non_null(m);
    m->boundary_cols = boundary;
    m->spring = spring;
    m->coupling_stiffness = 2.385e3;
    for (size_t i = 0; i < n; ++i) {
        m->blocks[i].mass = 1.0 + 0.25 * (double)i;
        m->blocks[i].driver_stiffness = 1e4 * (1.0 + 0.1 * (double)i);
        m->blocks[i].normal_force = 9.81;
        m->blocks[i].law = &bk_friction_coulomb;
    }
    bk_model_finalize(m);
    return m;
}

static void test_forces_free(void **state)
{
    (void)state;
    bk_model *m = make_chain(3, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    double x[3] = {1e-3, -2e-3, 4e-3}, D = 5e-3, kc = m->coupling_stiffness;
    assert_close(bk_model_applied_force(m, 0, x, D), 1e4 * (D - x[0]) + kc * (x[1] - x[0]), 1e-15, 0);
    assert_close(bk_model_applied_force(m, 1, x, D),
                 1.1e4 * (D - x[1]) + kc * (x[0] - x[1]) + kc * (x[2] - x[1]), 1e-15, 0);
    assert_close(bk_model_applied_force(m, 2, x, D), 1.2e4 * (D - x[2]) + kc * (x[1] - x[2]), 1e-15, 0);
    assert_int_equal(bk_model_coupling_count(m, 0), 1);
    assert_int_equal(bk_model_coupling_count(m, 1), 2);
    bk_model_free(m);
}

static void test_forces_fixed_and_periodic(void **state)
{
    (void)state;
    double x[3] = {1e-3, -2e-3, 4e-3}, kc = 2.385e3;
    bk_model *fixed = make_chain(3, BK_BOUNDARY_FIXED, BK_SPRING_LINEAR);
    assert_close(bk_model_coupling_force(fixed, 0, x), kc * (0 - x[0]) + kc * (x[1] - x[0]), 1e-15, 0);
    assert_close(bk_model_coupling_force(fixed, 2, x), kc * (x[1] - x[2]) + kc * (0 - x[2]), 1e-15, 0);
    bk_model *ring = make_chain(3, BK_BOUNDARY_PERIODIC, BK_SPRING_LINEAR);
    assert_close(bk_model_coupling_force(ring, 0, x), kc * (x[2] - x[0]) + kc * (x[1] - x[0]), 1e-15, 0);
    assert_close(bk_model_coupling_force(ring, 2, x), kc * (x[1] - x[2]) + kc * (x[0] - x[2]), 1e-15, 0);
    /* A single block: periodic couples to nothing, fixed to both walls. */
    bk_model *one_ring = make_chain(1, BK_BOUNDARY_PERIODIC, BK_SPRING_LINEAR);
    assert_close(bk_model_coupling_force(one_ring, 0, x), 0.0, 0, 0);
    bk_model *one_fixed = make_chain(1, BK_BOUNDARY_FIXED, BK_SPRING_LINEAR);
    assert_close(bk_model_coupling_force(one_fixed, 0, x), -2.0 * kc * x[0], 1e-15, 0);
    long partners[BK_MAX_NEIGHBOURS];
    bk_model *two_ring = make_chain(2, BK_BOUNDARY_PERIODIC, BK_SPRING_LINEAR);
    bk_model_neighbours(two_ring, 0, partners);
    assert_int_equal(partners[BK_LEFT], 1);
    assert_int_equal(partners[BK_RIGHT], 1);
    assert_int_equal(partners[BK_UP], -1);
    assert_int_equal(partners[BK_DOWN], -1);
    bk_model_free(fixed);
    bk_model_free(ring);
    bk_model_free(one_ring);
    bk_model_free(one_fixed);
    bk_model_free(two_ring);
}

/* Dashpots: each block's own, and one beside every coupling spring (walls stand still);
 * their total power -sum v_i G_i is the sum over dashpots of eta dv^2, so it never feeds
 * energy in.  Which models count as damped. */
static void test_damping(void **state)
{
    (void)state;
    const double v[3] = {2e-3, -1e-3, 5e-3}, etac = 3.25;
    bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED, BK_BOUNDARY_PERIODIC};
    for (size_t b = 0; b < 3; ++b) {
        bk_model *m = make_chain(3, boundaries[b], BK_SPRING_LINEAR);
        assert_false(bk_model_is_damped(m));
        m->coupling_damping = etac;
        assert_true(bk_model_is_damped(m));
        for (size_t i = 0; i < 3; ++i)
            m->blocks[i].damping = 0.5 * (double)(i + 1);
        double power = 0.0, expected = 0.0;
        for (size_t i = 0; i < 3; ++i) {
            power -= v[i] * bk_model_damping_force(m, i, v);
            expected += m->blocks[i].damping * v[i] * v[i];
        }
        expected += etac * ((v[1] - v[0]) * (v[1] - v[0]) + (v[2] - v[1]) * (v[2] - v[1]));
        if (boundaries[b] == BK_BOUNDARY_FIXED)
            expected += etac * (v[0] * v[0] + v[2] * v[2]);
        if (boundaries[b] == BK_BOUNDARY_PERIODIC)
            expected += etac * (v[0] - v[2]) * (v[0] - v[2]);
        assert_close(power, expected, 1e-14, 0);
        assert_close(bk_model_damping_force(m, 1, v), -1.0 * v[1] + etac * (v[0] - v[1]) + etac * (v[2] - v[1]),
                     1e-15, 0);
        bk_model_free(m);
    }
    /* Coupling dashpots on a lone block exist only with walls to pull on. */
    bk_model *one = make_chain(1, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    one->coupling_damping = etac;
    assert_false(bk_model_is_damped(one));
    one->boundary_cols = BK_BOUNDARY_FIXED;
    assert_true(bk_model_is_damped(one));
    assert_close(bk_model_damping_force(one, 0, v), -2.0 * etac * v[0], 1e-15, 0);
    one->boundary_cols = BK_BOUNDARY_FREE;
    one->blocks[0].damping = 7.5;
    assert_true(bk_model_is_damped(one));
    assert_close(bk_model_damping_force(one, 0, v), -7.5 * v[0], 1e-15, 0);
    bk_model_free(one);
}

static void test_tension_only(void **state)
{
    (void)state;
    bk_model *m = make_chain(1, BK_BOUNDARY_FREE, BK_SPRING_TENSION_ONLY);
    assert_close(bk_model_driver_force(m, 0, 2e-3, 1e-3), 0.0, 0, 0);          /* ahead: slack */
    assert_close(bk_model_driver_force(m, 0, 1e-3, 3e-3), 1e4 * 2e-3, 1e-15, 0); /* behind: pulls */
    double x = 2e-3;
    assert_close(bk_model_elastic_energy(m, &x, 1e-3), 0.0, 0, 0);
    bk_model_free(m);
}

/* Each block's applied force is minus the elastic energy's derivative by its position. */
static void check_gradient(const bk_model *m)
{
    double x[9] = {1.1e-3, -2.3e-3, 4.7e-3, 0.3e-3, -0.9e-3, 2.2e-3, 3.1e-3, -1.7e-3, 0.6e-3}, D = 2e-3;
    assert_true(m->n_blocks <= 9);
    for (size_t i = 0; i < m->n_blocks; ++i) {
        double h = 1e-7, saved = x[i];
        x[i] = saved + h;
        double up = bk_model_elastic_energy(m, x, D);
        x[i] = saved - h;
        double down = bk_model_elastic_energy(m, x, D);
        x[i] = saved;
        assert_close(-(up - down) / (2 * h), bk_model_applied_force(m, i, x, D), 1e-6, 1e-9);
    }
}

/* The force is minus the gradient of the elastic energy, for every boundary and spring. */
static void test_energy_gradient(void **state)
{
    (void)state;
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED, BK_BOUNDARY_PERIODIC};
    const bk_spring springs[] = {BK_SPRING_LINEAR, BK_SPRING_TENSION_ONLY};
    for (size_t b = 0; b < 3; ++b)
        for (size_t s = 0; s < 2; ++s)
            for (size_t n = 1; n <= 4; ++n) {
                bk_model *m = make_chain(n, boundaries[b], springs[s]);
                check_gradient(m);
                bk_model_free(m);
            }
}

static bk_model *make_lattice(size_t rows, size_t cols, bk_boundary boundary_rows, bk_boundary boundary_cols)
{
    bk_model *m = make_chain(rows * cols, boundary_cols, BK_SPRING_LINEAR);
    m->rows = rows;
    m->cols = cols;
    m->boundary_rows = boundary_rows;
    return m;
}

/* Partners on a 3 x 4 lattice by direction, at a corner, an edge and inside, for each
 * boundary; a 2-row periodic direction couples twice to the other row. */
static void test_lattice_neighbours(void **state)
{
    (void)state;
    long p[BK_MAX_NEIGHBOURS];
    bk_model *free_lattice = make_lattice(3, 4, BK_BOUNDARY_FREE, BK_BOUNDARY_FREE);
    assert_int_equal(bk_model_directions(free_lattice), 4);
    bk_model_neighbours(free_lattice, 0, p); /* top-left corner */
    assert_int_equal(p[BK_LEFT], -1);
    assert_int_equal(p[BK_RIGHT], 1);
    assert_int_equal(p[BK_UP], -1);
    assert_int_equal(p[BK_DOWN], 4);
    bk_model_neighbours(free_lattice, 5, p); /* inside: row 1, column 1 */
    assert_int_equal(p[BK_LEFT], 4);
    assert_int_equal(p[BK_RIGHT], 6);
    assert_int_equal(p[BK_UP], 1);
    assert_int_equal(p[BK_DOWN], 9);
    assert_int_equal(bk_model_coupling_count(free_lattice, 5), 4);
    assert_int_equal(bk_model_coupling_count(free_lattice, 11), 2);
    bk_model *torus = make_lattice(3, 4, BK_BOUNDARY_PERIODIC, BK_BOUNDARY_PERIODIC);
    bk_model_neighbours(torus, 0, p);
    assert_int_equal(p[BK_LEFT], 3);
    assert_int_equal(p[BK_UP], 8);
    bk_model_neighbours(torus, 11, p); /* bottom-right corner */
    assert_int_equal(p[BK_RIGHT], 8);
    assert_int_equal(p[BK_DOWN], 3);
    bk_model *walls = make_lattice(3, 4, BK_BOUNDARY_FIXED, BK_BOUNDARY_FREE);
    bk_model_neighbours(walls, 9, p); /* bottom row: a wall below, none to the right of column 3 */
    assert_int_equal(p[BK_DOWN], -2);
    assert_int_equal(p[BK_UP], 5);
    bk_model_neighbours(walls, 11, p);
    assert_int_equal(p[BK_RIGHT], -1);
    bk_model *two_rows = make_lattice(2, 3, BK_BOUNDARY_PERIODIC, BK_BOUNDARY_FREE);
    bk_model_neighbours(two_rows, 1, p);
    assert_int_equal(p[BK_UP], 4);
    assert_int_equal(p[BK_DOWN], 4);
    /* One row between fixed walls: partners up and down are walls; a chain has none. */
    bk_model *strip = make_lattice(1, 3, BK_BOUNDARY_FIXED, BK_BOUNDARY_FREE);
    assert_int_equal(bk_model_directions(strip), 4);
    assert_int_equal(bk_model_coupling_count(strip, 1), 4);
    bk_model *chain = make_chain(3, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    assert_int_equal(bk_model_directions(chain), 2);
    double x[12] = {1e-3, -2e-3, 4e-3, 0.5e-3, 2e-3, -1e-3, 3e-3, 0.0, -4e-3, 1.5e-3, 0.7e-3, -0.2e-3};
    double kc = free_lattice->coupling_stiffness;
    assert_close(bk_model_coupling_force(free_lattice, 5, x),
                 kc * (x[4] - x[5]) + kc * (x[6] - x[5]) + kc * (x[1] - x[5]) + kc * (x[9] - x[5]), 1e-15, 0);
    assert_close(bk_model_coupling_force(walls, 9, x),
                 kc * (x[8] - x[9]) + kc * (x[10] - x[9]) + kc * (x[5] - x[9]) + kc * (0.0 - x[9]), 1e-15, 0);
    bk_model *models[] = {free_lattice, torus, walls, two_rows, strip, chain};
    for (size_t k = 0; k < sizeof models / sizeof models[0]; ++k)
        bk_model_free(models[k]);
}

/* On lattices too the force is minus the energy's gradient (each spring counted once, the
 * doubled springs of a two-line periodic direction twice), for every pair of boundaries. */
static void test_lattice_energy_gradient(void **state)
{
    (void)state;
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED, BK_BOUNDARY_PERIODIC};
    const size_t shapes[][2] = {{2, 3}, {3, 3}, {1, 4}, {4, 1}, {3, 2}};
    for (size_t br = 0; br < 3; ++br)
        for (size_t bc = 0; bc < 3; ++bc)
            for (size_t sh = 0; sh < sizeof shapes / sizeof shapes[0]; ++sh) {
                bk_model *m = make_lattice(shapes[sh][0], shapes[sh][1], boundaries[br], boundaries[bc]);
                check_gradient(m);
                bk_model_free(m);
            }
}

static void test_kinetic_energy(void **state)
{
    (void)state;
    bk_model *m = make_chain(2, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    double v[2] = {0.3, -0.2};
    assert_close(bk_model_kinetic_energy(m, v), 0.5 * 1.0 * 0.09 + 0.5 * 1.25 * 0.04, 1e-15, 0);
    bk_model_free(m);
}

/* The Gershgorin bound is above the largest eigenfrequency and within a factor 2 of it. */
static void test_frequency_bound(void **state)
{
    (void)state;
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED, BK_BOUNDARY_PERIODIC};
    for (size_t b = 0; b < 3; ++b) {
        size_t n = 6;
        bk_model *m = make_chain(n, boundaries[b], BK_SPRING_LINEAR);
        /* Symmetric form M^-1/2 K M^-1/2 from unit displacements. */
        gsl_matrix *a = gsl_matrix_alloc(n, n);
        double x[6];
        for (size_t j = 0; j < n; ++j) {
            for (size_t i = 0; i < n; ++i)
                x[i] = i == j ? 1.0 : 0.0;
            for (size_t i = 0; i < n; ++i) {
                double k_ij = -bk_model_applied_force(m, i, x, 0.0);
                gsl_matrix_set(a, i, j, k_ij / sqrt(m->blocks[i].mass * m->blocks[j].mass));
            }
        }
        gsl_vector *eval = gsl_vector_alloc(n);
        gsl_eigen_symm_workspace *w = gsl_eigen_symm_alloc(n);
        gsl_eigen_symm(a, eval, w);
        double max_eval = gsl_vector_max(eval);
        double bound = bk_model_max_angular_frequency(m);
        assert_true(bound >= sqrt(max_eval) * (1 - 1e-12));
        assert_true(bound <= 2.0 * sqrt(max_eval));
        gsl_eigen_symm_free(w);
        gsl_vector_free(eval);
        gsl_matrix_free(a);
        bk_model_free(m);
    }
}

/* --- the default step limit's time scale ---------------------------------------------- */

#define TWO_PI (2.0 * 3.14159265358979323846)

/* Give block i a stateful law with its defaults and the keys given (NULL-terminated). */
static void set_law(bk_block *b, const bk_friction_law *law, const char *const *keys, const double *values)
{
    b->law = law;
    for (size_t k = 0; k < law->n_params; ++k)
        b->friction_params[k] = law->params[k].default_value;
    for (size_t k = 0; keys[k]; ++k) {
        int i = bk_friction_param_index(law, keys[k]);
        assert_true(i >= 0);
        b->friction_params[i] = values[k];
    }
}

static const char *const dr_keys[] = {"a", "b", "Dc", "V0", "f0", "theta_init", NULL};

/* Undamped: exactly 2 pi / bk_model_max_angular_frequency (and bk_model_damped_period), for
 * chains and lattices of every boundary; dashpots beside the coupling springs do not change it. */
static void test_step_time_scale_undamped(void **state)
{
    (void)state;
    const bk_boundary boundaries[] = {BK_BOUNDARY_FREE, BK_BOUNDARY_FIXED, BK_BOUNDARY_PERIODIC};
    const size_t shapes[][2] = {{1, 1}, {1, 2}, {1, 5}, {3, 4}, {2, 3}};
    size_t checked = 0;
    for (size_t br = 0; br < 3; ++br)
        for (size_t bc = 0; bc < 3; ++bc)
            for (size_t sh = 0; sh < sizeof shapes / sizeof shapes[0]; ++sh) {
                bk_model *m = make_lattice(shapes[sh][0], shapes[sh][1], boundaries[br], boundaries[bc]);
                double expected = TWO_PI / bk_model_max_angular_frequency(m);
                double got = bk_model_step_time_scale(m);
                if (got != expected)
                    print_error("%zu x %zu: %.17g != %.17g\n", shapes[sh][0], shapes[sh][1], got, expected);
                assert_true(got == expected);
                assert_true(bk_model_damped_period(m) == expected);
                m->coupling_damping = 1e3;
                assert_true(bk_model_step_time_scale(m) == expected);
                bk_model_free(m);
                checked++;
            }
    bk_model *one = make_chain(1, BK_BOUNDARY_FREE, BK_SPRING_LINEAR); /* no coupling: sqrt(k / m) */
    assert_close(bk_model_step_time_scale(one), TWO_PI / sqrt(1e4 / 1.0), 1e-15, 0);
    bk_model_free(one);
    print_message("%zu undamped models: step time scale == 2 pi / max angular frequency, bit for bit\n", checked);
}

/* Underdamped blocks: 2 pi / max_i sqrt((k_i + 2 count_i kc) / m_i - (eta_i / 2 m_i)^2). */
static void test_step_time_scale_underdamped(void **state)
{
    (void)state;
    /* One block, m = 2 kg, k = 1e4 N/m, eta = 50 N s/m: 2 pi / sqrt(5000 - 12.5^2). */
    bk_model *one = make_chain(1, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    one->blocks[0].mass = 2.0;
    one->blocks[0].damping = 50.0;
    double expected = TWO_PI / sqrt(1e4 / 2.0 - (50.0 / 4.0) * (50.0 / 4.0));
    assert_close(bk_model_step_time_scale(one), expected, 1e-15, 0);
    assert_true(bk_model_damped_period(one) == bk_model_step_time_scale(one));
    print_message("underdamped block: %.17g s, closed form %.17g s\n", bk_model_step_time_scale(one), expected);
    /* Nearly critical: eta = 199 on m = 1, k = 1e4 leaves sqrt(1e4 - 99.5^2) = sqrt(99.75). */
    one->blocks[0].mass = 1.0;
    one->blocks[0].damping = 199.0;
    assert_close(bk_model_step_time_scale(one), TWO_PI / sqrt(99.75), 1e-12, 0);
    bk_model_free(one);
    /* Three blocks between walls (two couplings each): rows 19540 / 1, 20540 / 1.25 = 16432,
     * 21540 / 1.5 = 14360 per s^2.  Damping block 0 by eta = 200 takes 100^2 off its row,
     * leaving 9540: the fastest oscillation is now block 1's, undamped. */
    bk_model *m = make_chain(3, BK_BOUNDARY_FIXED, BK_SPRING_LINEAR);
    double kc = m->coupling_stiffness;
    assert_close(bk_model_step_time_scale(m), TWO_PI / sqrt(1e4 + 4.0 * kc), 1e-15, 0);
    m->blocks[0].damping = 200.0;
    assert_close(bk_model_step_time_scale(m), TWO_PI / sqrt((1.1e4 + 4.0 * kc) / 1.25), 1e-15, 0);
    /* Damping block 1 by eta = 100: 16432 - (100 / 2.5)^2 = 14832, still above block 2's. */
    m->blocks[1].damping = 100.0;
    double rate1 = (1.1e4 + 4.0 * kc) / 1.25 - (100.0 / 2.5) * (100.0 / 2.5);
    assert_close(bk_model_step_time_scale(m), TWO_PI / sqrt(rate1), 1e-15, 0);
    /* And by eta = 150: 16432 - 60^2 = 12832, below block 2's undamped 14360. */
    m->blocks[1].damping = 150.0;
    assert_close(bk_model_step_time_scale(m), TWO_PI / sqrt((1.2e4 + 4.0 * kc) / 1.5), 1e-15, 0);
    bk_model_free(m);
}

/* Blocks without mass never oscillate: skipped, however stiff. */
static void test_step_time_scale_massless(void **state)
{
    (void)state;
    bk_model *m = make_chain(2, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    m->blocks[0].mass = 0.0;
    m->blocks[0].driver_stiffness = 1e12;
    double kc = m->coupling_stiffness;
    /* Block 1: m = 1.25, k = 1.1e4, one coupling. */
    assert_close(bk_model_step_time_scale(m), TWO_PI / sqrt((1.1e4 + 2.0 * kc) / 1.25), 1e-15, 0);
    m->blocks[0].damping = 5.0;
    assert_close(bk_model_step_time_scale(m), TWO_PI / sqrt((1.1e4 + 2.0 * kc) / 1.25), 1e-15, 0);
    bk_model_free(m);
    /* All massless, Coulomb: no scale at all. */
    bk_model *none = make_chain(2, BK_BOUNDARY_FIXED, BK_SPRING_LINEAR);
    none->blocks[0].mass = none->blocks[1].mass = 0.0;
    none->driver.velocity = 1e-3;
    assert_true(isinf(bk_model_step_time_scale(none)) && bk_model_step_time_scale(none) > 0.0);
    /* With a state law, the massless block's relaxation time Dc / |V|. */
    const double dr[] = {0.01, 0.015, 4e-6, 1e-6, 0.6, 1.0};
    set_law(&none->blocks[1], &bk_friction_dieterich_ruina_aging, dr_keys, dr);
    bk_model_finalize(none);
    assert_close(bk_model_step_time_scale(none), 4e-6 / 1e-3, 1e-15, 0);
    bk_model_free(none);
}

/* Every block overdamped by its own dashpot (or critically damped): the shortest relaxation
 * time of a friction state at |driver velocity|: Dc / |V| (Dieterich-Ruina), L0 / (B |V|)
 * (the paper's law); INFINITY without a state law or with the driver at rest. */
static void test_step_time_scale_overdamped(void **state)
{
    (void)state;
    /* One block, m = 1, k = 1e4: critical damping is eta = 2 sqrt(k m) = 200. */
    bk_model *one = make_chain(1, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    one->driver.velocity = -2.5e-3;
    one->blocks[0].damping = 300.0;
    assert_true(isinf(bk_model_step_time_scale(one)) && bk_model_step_time_scale(one) > 0.0); /* Coulomb */
    const double dr[] = {0.01, 0.015, 1e-5, 1e-6, 0.6, 1.0};
    set_law(&one->blocks[0], &bk_friction_dieterich_ruina_slip, dr_keys, dr);
    bk_model_finalize(one);
    assert_close(bk_model_step_time_scale(one), 1e-5 / 2.5e-3, 1e-15, 0);
    assert_true(isinf(bk_model_damped_period(one)));
    print_message("overdamped block, slip law: %.17g s, Dc / |V| = %.17g s\n", bk_model_step_time_scale(one),
                  1e-5 / 2.5e-3);
    one->blocks[0].damping = 200.0; /* critical: k / m - (eta / 2m)^2 = 0, no oscillation */
    assert_true(isinf(bk_model_damped_period(one)));
    assert_close(bk_model_step_time_scale(one), 1e-5 / 2.5e-3, 1e-15, 0);
    one->blocks[0].damping = 199.0; /* just under: it oscillates, slowly */
    assert_close(bk_model_step_time_scale(one), TWO_PI / sqrt(99.75), 1e-12, 0);
    one->blocks[0].damping = 300.0;
    one->driver.velocity = 0.0; /* a driver at rest sets no relaxation time */
    assert_true(isinf(bk_model_step_time_scale(one)) && bk_model_step_time_scale(one) > 0.0);
    bk_model_free(one);
    /* Three blocks, all overdamped: the shortest of Dc / |V| (aging), L0 / (B |V|) (paper's
     * law), and nothing from a Coulomb block. */
    bk_model *m = make_chain(3, BK_BOUNDARY_FREE, BK_SPRING_LINEAR);
    m->driver.velocity = 1e-3;
    for (size_t i = 0; i < 3; ++i)
        m->blocks[i].damping = 1e4;
    set_law(&m->blocks[0], &bk_friction_dieterich_ruina_aging, dr_keys, dr);
    const char *const rs_keys[] = {"L0", "B", "v_theta_ref", "theta_init", NULL};
    const double rs[] = {2e-5, 4.6, 100.0, 0.02};
    set_law(&m->blocks[1], &bk_friction_rate_state, rs_keys, rs);
    bk_model_finalize(m);
    assert_close(bk_model_step_time_scale(m), 2e-5 / (4.6 * 1e-3), 1e-15, 0); /* 4.35e-3 < 1e-2 */
    const double rs_slow[] = {2e-4, 4.6, 100.0, 0.2};
    set_law(&m->blocks[1], &bk_friction_rate_state, rs_keys, rs_slow);
    assert_close(bk_model_step_time_scale(m), 1e-5 / 1e-3, 1e-15, 0); /* 1e-2 < 4.35e-2 */
    /* One block back under its critical damping: the oscillation wins again. */
    m->blocks[2].damping = 0.0;
    double kc = m->coupling_stiffness;
    assert_close(bk_model_step_time_scale(m), TWO_PI / sqrt((1.2e4 + 2.0 * kc) / 1.5), 1e-15, 0);
    bk_model_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_forces_free),
        cmocka_unit_test(test_forces_fixed_and_periodic),
        cmocka_unit_test(test_damping),
        cmocka_unit_test(test_tension_only),
        cmocka_unit_test(test_energy_gradient),
        cmocka_unit_test(test_lattice_neighbours),
        cmocka_unit_test(test_lattice_energy_gradient),
        cmocka_unit_test(test_kinetic_energy),
        cmocka_unit_test(test_frequency_bound),
        cmocka_unit_test(test_step_time_scale_undamped),
        cmocka_unit_test(test_step_time_scale_underdamped),
        cmocka_unit_test(test_step_time_scale_massless),
        cmocka_unit_test(test_step_time_scale_overdamped),
    };
    return cmocka_run_group_tests_name("model", tests, NULL, NULL);
}
