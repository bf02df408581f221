/* method = auto (src/method_choice.c): the stiffness probe and the choice it drives. */
#include <stdlib.h>
#include <string.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "method_choice.h"
#include "scene.h"

static bk_config *load(const char *path, const char *const *overrides, size_t n_overrides)
{
    bk_config *c = NULL;
    bk_error err = {0};
    int rc = bk_config_load_file(path, overrides, n_overrides, &c, &err);
    if (rc != BK_OK)
        print_message("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    return c;
}

static const char *choice(bk_config *c)
{
    if (strcmp(c->solver.method, "ida") != 0) /* the one case that keeps its explicit method */
        snprintf(c->solver.method, sizeof c->solver.method, "auto");
    bk_scene scene;
    assert_int_equal(bk_scene_init(&scene, c->model, 0), 0);
    const char *method = bk_choose_method(c, &scene);
    bk_scene_free(&scene);
    return method;
}

/* The probe of the paper's law reads the state's relaxation rate, which scales as 1/L0 (the
 * state relaxes over a slip of L0), against the fixed oscillation frequency sqrt(k/m). */
static void test_rate_state_ratio_scales_with_L0(void **state)
{
    (void)state;
    double previous = 0.0;
    const char *values[] = {"friction.L0=2e-5", "friction.L0=2e-6", "friction.L0=6e-7", "friction.L0=2e-7", "friction.L0=2e-8"};
    for (size_t k = 0; k < 5; ++k) {
        const char *overrides[] = {values[k]};
        bk_config *c = load("configs/paper/case_b_rs.ini", overrides, 1);
        for (const char *const *other = (const char *const[]){"configs/paper/case_a_rs.ini", "configs/paper/case_c_rs.ini", NULL}; *other; ++other) {
            bk_config *o = load(*other, overrides, 1);
            print_message("%s, %s: stiffness ratio %.3g\n", *other, values[k], bk_stiffness_ratio(o->model));
            bk_config_free(o);
        }
        double ratio = bk_stiffness_ratio(c->model);
        print_message("case B rate-and-state, %s: stiffness ratio %.3g -> %s\n", values[k], ratio, choice(c));
        assert_true(isfinite(ratio) && ratio > 0.0);
        if (k > 0)
            assert_true(ratio > 2.0 * previous); /* ~ 1/L0 */
        previous = ratio;
        bk_config_free(c);
    }
}

static void test_choices(void **state)
{
    (void)state;
    static const struct {
        const char *config, *override, *method, *override2;
    } cases[] = {
        {"configs/paper/case_a_coulomb.ini", NULL, "exact", NULL},
        /* Open Coulomb chains up to 1000 blocks, rings up to 100 (see method_choice.c). */
        {"configs/chains/bk1000_coulomb.ini", NULL, "exact", NULL},
        {"configs/chains/bk1000_coulomb.ini", "model.n_blocks=1001", "gsl_rk8pd", NULL},
        {"configs/chains/bk1000_coulomb.ini", "model.boundary=periodic", "gsl_rk8pd", "model.n_blocks=101"},
        {"configs/chains/bk1000_coulomb.ini", "model.boundary=periodic", "exact", "model.n_blocks=100"},
        {"configs/paper/case_c_coulomb_tension_only.ini", NULL, "exact", NULL},
        {"configs/chains/bk10_coulomb.ini", NULL, "exact", NULL},
        /* Dashpots: exact when proportional to the masses and springs (uniform here, or
         * coupling dashpots in the springs' ratio), an integrator when they differ ... */
        {"configs/chains/bk10_coulomb.ini", "block.damping=20", "exact", "model.coupling_damping=40"},
        {"configs/chains/bk10_coulomb.ini", "block.damping=20", "gsl_rk8pd", "block.3.damping=50"},
        {"configs/chains/bk10_coulomb.ini", "block.3.mass=2", "gsl_rk8pd", "block.damping=20"},
        {"configs/chains/bk10_coulomb.ini", "block.3.driver_stiffness=2e4", "gsl_rk8pd", "model.coupling_damping=40"},
        /* ... and an integrator when they overdamp the fastest modes heavily */
        {"configs/chains/bk10_coulomb.ini", "block.damping=600", "exact", NULL},
        {"configs/chains/bk10_coulomb.ini", "block.damping=2000", "gsl_rk8pd", NULL},
        {"configs/chains/bk10_coulomb.ini", "model.coupling_damping=1000", "gsl_rk8pd", NULL},
        {"configs/paper/case_a_rs.ini", NULL, "gsl_rk8pd", NULL},
        {"configs/paper/case_b_rs.ini", NULL, "gsl_rk8pd", NULL},
        {"configs/paper/case_c_rs.ini", NULL, "gsl_rk8pd", NULL},
        {"configs/paper/case_b_rs.ini", "friction.L0=2e-6", "gsl_rk8pd", NULL},
        {"configs/paper/case_b_rs.ini", "friction.L0=2e-7", "cvode_bdf", NULL},
        {"configs/paper/case_b_rs.ini", "friction.L0=2e-8", "cvode_bdf", NULL},
        {"configs/paper/case_b_rs.ini", "solver.method=ida", "ida", NULL},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        const char *overrides[] = {cases[k].override, cases[k].override2};
        bk_config *c = load(cases[k].config, overrides, cases[k].override2 ? 2 : cases[k].override ? 1 : 0);
        const char *method = choice(c);
        if (strcmp(method, cases[k].method) != 0)
            print_message("%s %s: %s, expected %s\n", cases[k].config, cases[k].override ? cases[k].override : "",
                          method, cases[k].method);
        assert_string_equal(method, cases[k].method);
        bk_config_free(c);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rate_state_ratio_scales_with_L0),
        cmocka_unit_test(test_choices),
    };
    return cmocka_run_group_tests_name("method_choice", tests, NULL, NULL);
}
