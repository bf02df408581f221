/* From checked entries to a bk_config: the chain (model, blocks, friction, driver) or a
 * prescribed-motion scene, then the solver, run and output options.  Each value comes from
 * the most specific section that gives it ([block.I] over [block], [friction.I] over
 * [friction]) or from the key's default; what no single value can show is checked here:
 * missing keys, a law's parameters against each other, derived defaults and initial energies
 * that overflow, the method against the scene, and the output's size guards. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_rng.h>

#include "bksim/solver.h"
#include "config_loader.h"
#include "layout.h"

/* Value of a key in [section] (checked), or the definition's default. */
static double value_of(loader *ld, const char *section, const char *key)
{
    entry *e = bk_config_lookup(ld, section, key);
    if (e)
        return e->number;
    const key_def *def = bk_config_find_key(section, key);
    if (def->type == BK_KEY_CHOICE && def->default_text)
        for (size_t i = 0; bk_config_enum_choice(def, i); ++i)
            if (strcmp(bk_config_enum_choice(def, i), def->default_text) == 0)
                return (double)i;
    if (def->type == BK_KEY_FIELDS)
        return (double)BK_FIELD_ALL;
    if (def->param.flags & BK_PARAM_REQUIRED)
        bk_config_report_missing(ld, section, &def->param, def);
    return def->param.default_value;
}

/* A block key: [block.I] over [block] over the default; a distribution draws block i's. */
static double block_value(loader *ld, size_t i, const key_def *def, int *given)
{
    const bk_param *param = &def->param;
    const char *key = param->key;
    entry *e = bk_config_lookup_block(ld, "block", i, key);
    if (!e)
        e = bk_config_lookup(ld, "block", key);
    *given = e != NULL;
    double value = !e ? param->default_value : e->distribution ? bk_config_draw(ld, e, i, param) : e->number;
    bk_config_record_parameter(ld, "block", key, param->unit, i, value);
    return value;
}

/* A block without mass (quasi-dynamic): its slip rate is the root of its force balance
 * A - eta v - F(v, theta) = 0 (island.c), which exists and is unique only for a law without a
 * stuck state and a dashpot to the substrate.  Returns 0 after reporting what is missing. */
static int check_quasi_dynamic(loader *ld, const bk_model *m, const bk_block *b, size_t i, int given_normal,
                               int given_v)
{
    entry *e = bk_config_lookup_block(ld, "block", i, "mass");
    if (!e)
        e = bk_config_lookup(ld, "block", "mass");
    if (!e)
        return 1; /* mass missing altogether: reported as such */
    if (b->law && b->law->static_threshold) {
        bk_config_report_entry(ld, e, "0 (a quasi-dynamic block) needs a law without a stuck state "
                               "(dieterich_ruina_aging, dieterich_ruina_slip); block %zu's law %s sticks, and a "
                               "force balance without inertia does not say when it breaks away (allowed: mass > 0 "
                               "kg)", i, b->law->name);
        return 0;
    }
    if (!(b->damping > 0.0)) {
        bk_config_report_entry(ld, e, "0 (a quasi-dynamic block) needs [block] damping > 0 N s/m on block %zu: "
                               "the radiation damping (eta = G / 2 c_s) that bounds its slip rate where friction "
                               "weakens (allowed: mass > 0 kg, or damping > 0)", i);
        return 0;
    }
    if (m->coupling_damping > 0.0) {
        bk_config_report_entry(ld, e, "0 (a quasi-dynamic block) cannot have [model] coupling_damping = %g N s/m: "
                               "dashpots between blocks without mass would tie their slip rates into one linear "
                               "system per evaluation, which bksim does not solve (allowed: coupling_damping = 0, "
                               "or mass > 0 kg)", m->coupling_damping);
        return 0;
    }
    if (!given_normal) {
        bk_config_report_entry(ld, e, "0 (a quasi-dynamic block) needs [block] normal_force on block %zu: its "
                               "default, mass * gravity, would be 0 N (allowed: normal_force > 0 N)", i);
        return 0;
    }
    if (given_v && b->v_init != 0.0) {
        bk_config_report_entry(ld, e, "0 (a quasi-dynamic block) takes no [block] v_init (block %zu has %g m/s): its "
                               "slip rate at t = 0 is the one its force balance gives; set the driver's "
                               "start_position or x_init for the stress you want (allowed: v_init left out)",
                               i, b->v_init);
        return 0;
    }
    return 1;
}

/* Friction of block i: its law and parameters, completed and validated. */
static void build_friction(loader *ld, bk_block *b, size_t i, double driver_speed)
{
    entry *own_law = bk_config_lookup_block(ld, "friction", i, "law");
    entry *base_law = bk_config_lookup(ld, "friction", "law");
    entry *law_entry = own_law ? own_law : base_law;
    if (!law_entry) {
        bk_config_report_missing(ld, "friction", &bk_config_find_key("friction", "law")->param,
                       bk_config_find_key("friction", "law"));
        return;
    }
    const bk_friction_law *law = bk_friction_law_find(law_entry->value);
    if (!law)
        return; /* reported at its line */
    /* Parameters of [friction] apply unless this block names a different law. */
    int inherit = !own_law || (base_law && strcmp(own_law->value, base_law->value) == 0);
    const char *param_section = own_law ? own_law->section : "friction";
    entry *origin[BK_FRICTION_MAX_PARAMS] = {0};
    b->law = law;
    for (size_t p = 0; p < law->n_params; ++p) {
        const bk_param *param = &law->params[p];
        entry *e = bk_config_lookup_block(ld, "friction", i, param->key);
        if (!e && inherit)
            e = bk_config_lookup(ld, "friction", param->key);
        origin[p] = e;
        if (e) {
            b->friction_params[p] = e->distribution ? bk_config_draw(ld, e, i, param) : e->number;
            bk_config_record_parameter(ld, "friction", param->key, param->unit, i, b->friction_params[p]);
        } else if (param->flags & BK_PARAM_REQUIRED) {
            bk_config_report_missing(ld, param_section, param, NULL);
            b->friction_params[p] = NAN;
        } else {
            b->friction_params[p] = param->default_value;
        }
    }
    if (law->complete) {
        bk_friction_context ctx = {fabs(driver_speed), b->normal_force};
        law->complete(b->friction_params, &ctx);
        /* A default derived from other values (theta_init = L0 / driver speed) can overflow; a NaN
         * one is the law's to report (validate says which value it needs). */
        for (size_t p = 0; p < law->n_params; ++p)
            if (!origin[p] && isinf(b->friction_params[p]) && ld->error_rank == LONG_MAX) {
                bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [%s] %s: its default for block %zu is not finite (%g); "
                                 "set it (allowed: %g < %s < %g)", ld->name, param_section, law->params[p].key, i,
                                 b->friction_params[p], law->params[p].min, law->params[p].key, law->params[p].max);
                return;
            }
    }
    /* Once an error stands that no conflict of this block could precede, a long chain's
     * blocks skip formatting a message that would be dropped (1e6 of them took seconds). */
    long earliest = RANK_MISSING;
    for (size_t p = 0; p < law->n_params; ++p)
        if (origin[p] && origin[p]->rank < earliest)
            earliest = origin[p]->rank;
    if (law->validate && earliest < ld->error_rank) {
        char msg[256];
        int bad = law->validate(b->friction_params, msg, sizeof msg);
        entry *at = bad >= 0 ? origin[bad] : NULL;
        /* The same conflict in every block of a long chain is reported once: only an
         * earlier-ranked one is worth the message. */
        if (bad >= 0 && !(at && at->rank >= ld->error_rank)) {
            /* A conflict with this block's own value (from its [friction.I], index >= 0) is
             * reported at the shared key: name the block and where its value came from. */
            char block_note[640] = "";
            for (size_t q = 0; q < law->n_params && (!at || at->index < 0); ++q)
                if (origin[q] && origin[q]->index >= 0) {
                    char where[512];
                    bk_config_location(ld, origin[q], where, sizeof where);
                    if (snprintf(block_note, sizeof block_note, " (block %zu: %s sets [%s] %s = %s)", i,
                                 where, origin[q]->section, origin[q]->key, origin[q]->value) < 0)
                        block_note[0] = '\0';
                    break;
                }
            if (at && at->distribution && !block_note[0])
                snprintf(block_note, sizeof block_note, " (drawn for block %zu)", i);
            /* The other side of the conflict may be the drawn one (mu_d against a drawn mu_s). */
            for (size_t q = 0; q < law->n_params && !block_note[0]; ++q)
                if (origin[q] && origin[q]->distribution && q != (size_t)bad)
                    snprintf(block_note, sizeof block_note, " (block %zu: %s drew %.17g from %s)", i,
                             origin[q]->key, b->friction_params[q], origin[q]->value);
            if (at)
                bk_config_report_entry(ld, at, "%s%s", msg, block_note);
            else
                bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [%s] %s: %s%s", ld->name, param_section,
                                 law->params[bad].key, msg, block_note);
        }
    }
}

static char *default_output_path(const char *name)
{
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    size_t len = strlen(base);
    if (len > 4 && strcmp(base + len - 4, ".ini") == 0)
        len -= 4;
    char *path = malloc(len + 4);
    if (path)
        snprintf(path, len + 4, "%.*s.h5", (int)len, base);
    return path;
}

/* The energy audit needs finite energies: a start state whose energy overflows a double
 * is refused here rather than reported as a NaN residual after the run. */
static void check_initial_energy(loader *ld, const bk_model *m)
{
    double driver0 = bk_driver_position(&m->driver, 0.0);
    for (size_t i = 0; i < m->n_blocks; ++i) {
        const bk_block *b = &m->blocks[i];
        const char *key = NULL;
        double energy = 0.0;
        if (!isfinite(energy = 0.5 * b->mass * b->v_init * b->v_init))
            key = "v_init";
        else if (!isfinite(energy = 0.5 * b->driver_stiffness * (driver0 - b->x_init) * (driver0 - b->x_init)))
            key = "x_init";
        if (!key)
            continue;
        entry *e = bk_config_lookup_block(ld, "block", i, key);
        if (!e)
            e = bk_config_lookup(ld, "block", key);
        if (!e)
            e = bk_config_lookup(ld, "driver", "start_position");
        const char *what = strcmp(key, "v_init") == 0 ? "kinetic" : "elastic";
        if (e)
            bk_config_report_entry(ld, e, "block %zu's initial %s energy overflows a double (%g J; allowed: a "
                                   "finite energy)", i, what, energy);
        else
            bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: block %zu's initial %s energy overflows a double",
                             ld->name, i, what);
        return;
    }
    double *x = malloc(m->n_blocks * sizeof *x);
    if (!x) {
        bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return;
    }
    for (size_t i = 0; i < m->n_blocks; ++i)
        x[i] = m->blocks[i].x_init;
    if (!isfinite(bk_model_elastic_energy(m, x, driver0)))
        bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: the chain's initial elastic energy overflows a double "
                         "(check x_init, x_init_random and the stiffnesses)", ld->name);
    free(x);
}

/* The shape: n_blocks, rows and cols, any two of them implying the third (one alone: n_blocks,
 * a chain).  Returns 0 after an error, reported. */
static size_t build_shape(loader *ld, size_t *rows, size_t *cols)
{
    entry *n_entry = bk_config_lookup(ld, "model", "n_blocks");
    entry *r_entry = bk_config_lookup(ld, "model", "rows");
    entry *c_entry = bk_config_lookup(ld, "model", "cols");
    if (!n_entry && !(r_entry && c_entry)) {
        const key_def *def = bk_config_find_key("model", "n_blocks");
        bk_config_report_missing(ld, "model", &def->param, def);
        return 0;
    }
    size_t n = n_entry ? (size_t)n_entry->number : 0;
    *rows = r_entry ? (size_t)r_entry->number : 0;
    *cols = c_entry ? (size_t)c_entry->number : 0;
    if (!r_entry && !c_entry) {
        *rows = 1;
        *cols = n;
        return n;
    }
    if (r_entry && c_entry) {
        /* Both at most BK_CONFIG_MAX_BLOCKS: the product fits a double exactly. */
        double product = r_entry->number * c_entry->number;
        if (product > (double)BK_CONFIG_MAX_BLOCKS) {
            bk_config_report_entry(ld, c_entry, "rows * cols = %.0f blocks (allowed: at most %ld)", product,
                                   (long)BK_CONFIG_MAX_BLOCKS);
            return 0;
        }
        if (n_entry && product != n_entry->number) {
            bk_config_report_entry(ld, n_entry, "%zu blocks, but rows * cols = %zu * %zu = %.0f (allowed: n_blocks = "
                                   "rows * cols, or leave n_blocks out)", n, *rows, *cols, product);
            return 0;
        }
        return *rows * *cols;
    }
    entry *given = r_entry ? r_entry : c_entry;
    size_t per = (size_t)given->number;
    if (n % per != 0) {
        bk_config_report_entry(ld, given, "%zu does not divide n_blocks = %zu (allowed: a divisor of n_blocks, "
                               "or give both rows and cols)", per, n);
        return 0;
    }
    if (r_entry)
        *cols = n / per;
    else
        *rows = n / per;
    return n;
}

/* A boundary key's value: its own entry, else `boundary` for a direction the lattice extends
 * along, else free.  A single row's sides are the chain's ends, so a 1 x N lattice is the
 * chain and an N x 1 one the chain stood on end, whichever keys gave the shape. */
static bk_boundary boundary_of(loader *ld, const char *key, int extends)
{
    entry *own = bk_config_lookup(ld, "model", key);
    if (own)
        return (bk_boundary)(int)own->number;
    if (!extends)
        return BK_BOUNDARY_FREE;
    return (bk_boundary)(int)value_of(ld, "model", "boundary");
}

/* The chain or lattice: model, blocks, friction, driver. */
static void build_chain(loader *ld, bk_config *c)
{
    size_t rows = 1, cols = 1;
    size_t n = build_shape(ld, &rows, &cols);
    if (n == 0)
        return; /* reported */
    bk_model *m = bk_model_create(n);
    if (!m) {
        bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory for %zu blocks", ld->name, n);
        return;
    }
    c->model = m;
    m->rows = ld->rows = rows;
    m->cols = ld->cols = cols;
    m->boundary_cols = boundary_of(ld, "boundary_cols", cols > 1 || rows == 1);
    m->boundary_rows = boundary_of(ld, "boundary_rows", rows > 1);
    m->coupling_stiffness = value_of(ld, "model", "coupling_stiffness");
    m->coupling_damping = value_of(ld, "model", "coupling_damping");
    m->gravity = value_of(ld, "model", "gravity");
    m->spring = (bk_spring)(int)value_of(ld, "driver", "spring");
    m->driver.start_position = value_of(ld, "driver", "start_position");
    double history = bk_config_build_driver(ld, m);

    /* The block keys' definitions, looked up once rather than per block. */
    enum { MASS, DRIVER_STIFFNESS, NORMAL_FORCE, X_INIT, X_INIT_RANDOM, V_INIT, DAMPING, APPLIED_FORCE, N_BLOCK_KEYS };
    static const char *const block_keys[N_BLOCK_KEYS] = {"mass", "driver_stiffness", "normal_force", "x_init",
                                                         "x_init_random", "v_init", "damping", "applied_force"};
    const key_def *def[N_BLOCK_KEYS];
    for (size_t k = 0; k < N_BLOCK_KEYS; ++k)
        def[k] = bk_config_find_key("block", block_keys[k]);
    if (bk_config_plan_parameters(ld, n) != 0)
        return;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng) {
        bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return;
    }
    gsl_rng_set(rng, ld->seed);
    for (size_t i = 0; i < n; ++i) {
        bk_block *b = &m->blocks[i];
        int given;
        for (size_t r = MASS; r <= DRIVER_STIFFNESS; ++r) {
            double value = block_value(ld, i, def[r], &given);
            if (!given)
                bk_config_report_missing(ld, "block", &def[r]->param, def[r]);
            if (r == MASS)
                b->mass = value;
            else
                b->driver_stiffness = value;
        }
        b->normal_force = block_value(ld, i, def[NORMAL_FORCE], &given);
        int given_normal = given;
        if (!given)
            b->normal_force = b->mass * m->gravity;
        if (!isfinite(b->normal_force) && ld->error_rank == LONG_MAX) {
            bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [block] normal_force: the default mass * gravity of block %zu "
                             "overflows (%g kg * %g m/s^2; allowed: 0 < normal_force < inf N)", ld->name, i, b->mass, m->gravity);
            break;
        }
        b->x_init = block_value(ld, i, def[X_INIT], &given);
        /* Drawn for every block, so a block's value does not depend on its neighbours' keys. */
        b->x_init += block_value(ld, i, def[X_INIT_RANDOM], &given) * (2.0 * gsl_rng_uniform(rng) - 1.0);
        b->v_init = block_value(ld, i, def[V_INIT], &given);
        int given_v = given;
        b->damping = block_value(ld, i, def[DAMPING], &given);
        b->applied_force = block_value(ld, i, def[APPLIED_FORCE], &given);
        build_friction(ld, b, i, m->driver.velocity);
        if (b->mass == 0.0 && ld->error_rank == LONG_MAX && !check_quasi_dynamic(ld, m, b, i, given_normal, given_v))
            break; /* one such block is enough */
        if (ld->error_rank != LONG_MAX && ld->error_rank >= RANK_MISSING)
            break; /* one missing key is enough; don't repeat it for every block */
    }
    gsl_rng_free(rng);
    bk_model_finalize(m);
    check_initial_energy(ld, m);
    entry *t_end = bk_config_lookup(ld, "run", "t_end");
    if (isnan(history)) {
        c->t_end = value_of(ld, "run", "t_end");
    } else {
        /* The history is the run's schedule: t_end defaults to its length, and may not pass it. */
        c->t_end = t_end ? t_end->number : history;
        if (t_end && t_end->number > history * (1 + 1e-12))
            bk_config_report_entry(ld, t_end, "must be <= the driver history's length (%.10g s), got %s", history,
                                   t_end->value);
    }
}

/* A prescribed-motion scene: the schedule and one block's friction.  The chain's keys are
 * optional here: normal_force defaults to mass * gravity, or 1 N without a mass. */
static void build_prescribed(loader *ld, bk_config *c)
{
    entry *rates = bk_config_lookup(ld, "prescribed", "slip_rates");
    entry *durations = bk_config_lookup(ld, "prescribed", "durations");
    entry *distances = bk_config_lookup(ld, "prescribed", "distances");
    if (!rates) {
        bk_config_report_missing(ld, "prescribed", &bk_config_find_key("prescribed", "slip_rates")->param,
                       bk_config_find_key("prescribed", "slip_rates"));
        return;
    }
    if (!durations == !distances) {
        bk_config_report_entry(ld, durations ? distances : rates, "give exactly one of durations and distances");
        return;
    }
    entry *lengths = durations ? durations : distances;
    if (!lengths)
        return; /* reported above */
    size_t n = (size_t)rates->number;
    if ((size_t)lengths->number != n) {
        bk_config_report_entry(ld, lengths, "has %zu values, slip_rates has %zu", (size_t)lengths->number, n);
        return;
    }
    static const char *const shape[] = {"n_blocks", "rows", "cols"};
    for (size_t k = 0; k < sizeof shape / sizeof shape[0]; ++k) {
        entry *e = bk_config_lookup(ld, "model", shape[k]);
        if (e && e->number != 1.0)
            bk_config_report_entry(ld, e, "a prescribed scene has one block, got %s (allowed: 1)", e->value);
    }
    /* The slip rate is imposed, so a dashpot would change nothing a prescribed run reports. */
    static const char *const dashpots[][2] = {{"block", "damping"}, {"block.0", "damping"}, {"model", "coupling_damping"}};
    for (size_t d = 0; d < sizeof dashpots / sizeof dashpots[0]; ++d) {
        entry *e = bk_config_lookup(ld, dashpots[d][0], dashpots[d][1]);
        if (e)
            bk_config_report_entry(ld, e, "a prescribed scene imposes the slip rate, which no dashpot changes "
                                   "(allowed: remove the key)");
    }
    bk_prescribed *pr = calloc(1, sizeof *pr);
    bk_model *m = bk_model_create(1);
    if (pr) {
        pr->slip_rate = calloc(n, sizeof *pr->slip_rate);
        pr->duration = calloc(n, sizeof *pr->duration);
    }
    c->prescribed = pr;
    c->model = m;
    if (!pr || !pr->slip_rate || !pr->duration || !m) {
        bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
        return;
    }
    pr->n_segments = n;
    double total = 0.0, first_rate = 0.0;
    for (size_t k = 0; k < n; ++k) {
        double rate = rates->list[k];
        pr->slip_rate[k] = rate;
        if (distances && rate == 0.0) {
            bk_config_report_entry(ld, distances, "segment %zu is a hold (slip rate 0): give durations", k + 1);
            return;
        }
        pr->duration[k] = durations ? durations->list[k] : distances->list[k] / rate;
        total += pr->duration[k];
        if (!isfinite(total)) {
            bk_config_report_entry(ld, lengths, "segment %zu makes the schedule longer than any finite time "
                                   "(allowed: a finite total duration)", k + 1);
            return;
        }
        if (first_rate == 0.0)
            first_rate = rate;
    }
    m->gravity = value_of(ld, "model", "gravity");
    m->driver.velocity = first_rate;
    if (bk_config_plan_parameters(ld, 1) != 0)
        return;
    bk_block *b = &m->blocks[0];
    int given_mass, given_normal;
    double mass = block_value(ld, 0, bk_config_find_key("block", "mass"), &given_mass);
    b->mass = given_mass ? mass : 1.0;
    b->normal_force = block_value(ld, 0, bk_config_find_key("block", "normal_force"), &given_normal);
    if (!given_normal)
        b->normal_force = given_mass ? b->mass * m->gravity : 1.0;
    build_friction(ld, b, 0, first_rate);
    bk_model_finalize(m);
    entry *t_end = bk_config_lookup(ld, "run", "t_end");
    c->t_end = total;
    if (t_end && t_end->number <= total * (1 + 1e-12))
        c->t_end = t_end->number;
    else if (t_end)
        bk_config_report_entry(ld, t_end, "must be <= the schedule's length (%.10g s), got %s", total, t_end->value);
}

/* arkode_imex treats the springs explicitly and friction and dashpots implicitly.  On a block
 * with mass that friction and dashpots overdamp (damping ratio zeta > 1, counting the law's
 * direct effect dF/dv at the driver's speed), the slip rate relaxes onto its force balance at
 * a rate the explicit springs must follow: steps of about 30 sqrt(rtol m / k) for motion whose
 * own time scale is far longer (QDYN's spring-block: 1e10 steps at m = 1e-3 kg).  Refused up
 * front; a block that sticks is left alone (its stuck phases are exact, its slips short). */
static void check_imex(loader *ld, entry *method, const bk_model *m, double rtol)
{
    double speed = fabs(m->driver.velocity);
    for (size_t i = 0; i < m->n_blocks; ++i) {
        const bk_block *b = &m->blocks[i];
        if (!(b->mass > 0.0) || !b->law || b->law->static_threshold)
            continue;
        double stiffness = bk_model_block_stiffness(m, i);
        double eta = b->damping + bk_model_coupling_count(m, i) * m->coupling_damping;
        if (b->law->sliding_force_derivatives && speed > 0.0) {
            double state[BK_FRICTION_MAX_STATE] = {0}, d_rate, d_state;
            if (b->law->state_init)
                b->law->state_init(b->friction_params, state);
            b->law->sliding_force_derivatives(b->friction_params, b->normal_force, speed, state, &d_rate, &d_state);
            eta += d_rate;
        }
        double zeta = stiffness > 0.0 ? eta / (2.0 * sqrt(stiffness * b->mass)) : INFINITY;
        if (zeta > 1.0) {
            double step = 30.0 * sqrt(rtol * b->mass / fmax(stiffness, DBL_MIN));
            bk_config_report_entry(ld, method,
                                   "integrates the springs explicitly, and block %zu is overdamped (damping ratio "
                                   "%.3g with its dashpots and its friction's dF/dv at the driver's speed): its steps "
                                   "stay near 30 sqrt(rtol m / k) = %.3g s however slowly it creeps (allowed: "
                                   "arkode_dirk, cvode_bdf or gsl_msbdf; or [block] mass = 0, quasi-dynamic)",
                                   i, zeta, step);
            return;
        }
    }
}

/* local_stepping = on: a back-end that can move its stop time and publish its predictor,
 * and a chain that stays one island (no block sticks, no spring goes slack), which the
 * segments cut (run_segments.c). */
static void check_local_stepping(loader *ld, const bk_config *c)
{
    entry *local = bk_config_lookup(ld, "solver", "local_stepping");
    if (!local || strcmp(local->value, "on") != 0 || ld->error_rank != LONG_MAX)
        return;
    const bk_solver_backend *b = bk_solver_backend_find(c->solver.method);
    if (strcmp(c->solver.method, "auto") != 0 && (!b || !b->set_stop || !b->predictor)) {
        bk_config_report_entry(ld, local, "needs method cvode_bdf, cvode_adams or auto; method is %s",
                               c->solver.method);
        return;
    }
    if (c->prescribed || !c->model) {
        bk_config_report_entry(ld, local, "applies to a chain or lattice of blocks, not a prescribed scene "
                               "(allowed: auto, off)");
        return;
    }
    const bk_model *m = c->model;
    for (size_t i = 0; i < m->n_blocks; ++i)
        if (m->blocks[i].law && (m->blocks[i].law->flags & BK_FRICTION_STATIC_THRESHOLD)) {
            bk_config_report_entry(ld, local,
                                   "needs laws without a stuck state on every block (such as rate-and-state); "
                                   "block %zu uses law %s, whose stuck blocks already split the chain into "
                                   "islands (allowed: auto, off)",
                                   i, m->blocks[i].law->name);
            return;
        }
    if (m->spring == BK_SPRING_TENSION_ONLY)
        bk_config_report_entry(ld, local, "needs linear driver springs; [driver] spring = tension_only "
                               "(allowed: auto, off)");
}

/* The method fits the scene and takes the options given: method = exact solves only
 * affine scenes, arkode_table needs a method with tables.  Said here, before any output. */
static void check_method_fits(loader *ld, const bk_config *c)
{
    entry *method = bk_config_lookup(ld, "solver", "method");
    entry *table = bk_config_lookup(ld, "solver", "arkode_table");
    if (table && strcmp(table->value, "default") != 0 && ld->error_rank == LONG_MAX) {
        const bk_solver_backend *b = bk_solver_backend_find(c->solver.method);
        char message[768];
        if (!b || !b->check_options)
            bk_config_report_entry(ld, table, "applies to method arkode_erk or arkode_dirk, not %s", c->solver.method);
        else if (b->check_options(&c->solver, message, sizeof message) != 0)
            bk_config_report_entry(ld, table, "%s", message);
    }
    if (method && strcmp(method->value, "arkode_imex") == 0 && c->model && !c->prescribed &&
        ld->error_rank == LONG_MAX)
        check_imex(ld, method, c->model, c->solver.rtol);
    if (!method || strcmp(method->value, "exact") != 0 || !c->model || c->prescribed ||
        ld->error_rank != LONG_MAX)
        return;
    size_t i = bk_model_first_non_affine_block(c->model);
    if (i < c->model->n_blocks)
        bk_config_report_entry(ld, method,
                               "needs Coulomb friction (a constant sliding force, no friction state) on every "
                               "block; block %zu uses law %s (allowed: auto, or an integrator such as gsl_rk8pd "
                               "or cvode_bdf)",
                               i, c->model->blocks[i].law->name);
}

static int has_section(loader *ld, const char *section)
{
    for (size_t i = 0; i < ld->n; ++i)
        if (!ld->entries[i].superseded && strcmp(ld->entries[i].base, section) == 0)
            return 1;
    return 0;
}

/* [output] events and [catalog]: the catalog needs a notion of slipping for every block. */
static void build_catalog(loader *ld, bk_config *c)
{
    bk_output_options *o = &c->output;
    o->events = (int)value_of(ld, "output", "events");
    c->catalog.magnitude_offset = value_of(ld, "catalog", "magnitude_offset");
    c->catalog.slip_rate_threshold = value_of(ld, "catalog", "slip_rate_threshold");
    c->catalog.rupture_rate = (int)value_of(ld, "catalog", "rupture_rate");
    entry *events = bk_config_lookup(ld, "output", "events");
    entry *threshold = bk_config_lookup(ld, "catalog", "slip_rate_threshold");
    if (c->prescribed) {
        if (events && o->events)
            bk_config_report_entry(ld, events, "a prescribed scene has no slip events (allowed: false)");
        /* Never silently: a [catalog] key would describe a catalog this scene does not keep. */
        for (size_t i = 0; i < ld->n; ++i)
            if (!ld->entries[i].superseded && strcmp(ld->entries[i].base, "catalog") == 0) {
                bk_config_report_entry(ld, &ld->entries[i], "a prescribed scene keeps no catalog (allowed: no "
                                       "[catalog] section)");
                break;
            }
        o->events = 0;
        return;
    }
    if (!c->model || ld->error_rank != LONG_MAX)
        return;
    size_t creeping = c->model->n_blocks;
    for (size_t i = 0; i < c->model->n_blocks && creeping == c->model->n_blocks; ++i)
        if (!(c->model->blocks[i].law->flags & BK_FRICTION_STATIC_THRESHOLD))
            creeping = i;
    if (threshold && creeping == c->model->n_blocks)
        bk_config_report_entry(ld, threshold, "applies to laws without a stuck state (dieterich_ruina_aging, "
                               "dieterich_ruina_slip); every block here sticks, and slips when it does not "
                               "(allowed: remove the key)");
    else if (o->events && !threshold && creeping < c->model->n_blocks)
        bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG,
                         "%s: [catalog] slip_rate_threshold: required for the event catalog, as block %zu's law "
                         "%s never sticks (allowed: a slip rate > 0 m/s well above the creep rate and below "
                         "the slip rates of events, e.g. 1e-3 m/s; or [output] events = false)",
                         ld->name, creeping, c->model->blocks[creeping].law->name);
}

/* Everything checked: build the config.  Reports missing and cross-key errors. */
bk_config *bk_config_build(loader *ld)
{
    bk_config *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->t_end = NAN; /* unknown until read: no cross-check against it before then */
    ld->seed = (unsigned long)value_of(ld, "model", "seed");
    if (has_section(ld, "prescribed"))
        build_prescribed(ld, c);
    else
        build_chain(ld, c);
    c->parameters = ld->parameters;
    c->n_parameters = ld->n_parameters;
    ld->parameters = NULL;
    ld->n_parameters = 0;

    bk_solver_options *s = &c->solver;
    snprintf(s->method, sizeof s->method, "%s", bk_config_method_name((size_t)value_of(ld, "solver", "method")));
    snprintf(s->linear_solver, sizeof s->linear_solver, "%s",
             bk_config_linear_solver_names[(size_t)value_of(ld, "solver", "linear_solver")]);
    s->rtol = value_of(ld, "solver", "rtol");
    s->atol_x = value_of(ld, "solver", "atol_x");
    s->atol_v = value_of(ld, "solver", "atol_v");
    s->max_step = value_of(ld, "solver", "max_step");
    s->max_steps = (long)value_of(ld, "solver", "max_steps");
    s->detect_velocity_extrema = (int)value_of(ld, "solver", "detect_velocity_extrema");
    s->max_transitions_per_instant = (long)value_of(ld, "solver", "max_transitions_per_instant");
    s->instant_window = value_of(ld, "solver", "instant_window");
    s->min_step = value_of(ld, "solver", "min_step");
    snprintf(s->arkode_table, sizeof s->arkode_table, "%s",
             bk_solver_arkode_table((size_t)value_of(ld, "solver", "arkode_table")));
    snprintf(s->local_stepping, sizeof s->local_stepping, "%s",
             bk_config_local_stepping_names[(size_t)value_of(ld, "solver", "local_stepping")]);
    s->segment_blocks = (long)value_of(ld, "solver", "segment_blocks");
    check_method_fits(ld, c);
    check_local_stepping(ld, c);
    c->wall_time_limit = value_of(ld, "run", "wall_time_limit");
    c->seed = ld->seed;

    bk_output_options *o = &c->output;
    entry *path = bk_config_lookup(ld, "output", "path");
    o->path = path ? strdup(path->value) : default_output_path(ld->name);
    if (!o->path)
        bk_config_report(ld, 0, BK_ERR_NOMEM, "%s: out of memory", ld->name);
    entry *interval = bk_config_lookup(ld, "output", "interval");
    o->interval = interval ? interval->number : c->t_end / 1000.0;
    if (interval && isfinite(c->t_end) && interval->number > c->t_end)
        bk_config_report_entry(ld, interval, "must be <= t_end (%g s), got %s", c->t_end, interval->value);
    o->fields = (unsigned)value_of(ld, "output", "fields");
    if (c->prescribed)
        o->fields &= ~(unsigned)BK_FIELD_ENERGY; /* no dynamics, no energies */
    o->transitions = (int)value_of(ld, "output", "transitions");
    build_catalog(ld, c);
    double event_rows = value_of(ld, "output", "event_rows");
    o->event_rows = isnan(event_rows) ? c->model && c->model->n_blocks <= BK_EVENT_ROWS_AUTO_BLOCKS
                                      : (int)event_rows;
    /* Restart points where the run's own time or work says, the same in every run of a config,
     * so that whether the wall clock had a checkpoint written at one never changes a result. */
    entry *checkpoints = bk_config_lookup(ld, "output", "checkpoint_interval");
    entry *work = bk_config_lookup(ld, "output", "checkpoint_work");
    o->checkpoint_interval = checkpoints ? checkpoints->number : 0.0;
    if (c->prescribed && checkpoints && o->checkpoint_interval > 0.0)
        bk_config_report_entry(ld, checkpoints, "a prescribed scene has no dynamics to checkpoint (allowed: 0)");
    if (work && checkpoints)
        bk_config_report_entry(ld, work, "applies only with checkpoint_interval = auto (not set); "
                               "checkpoint_interval = %s is given", checkpoints->value);
    double blocks = c->model ? (double)c->model->n_blocks : 1.0;
    if (!checkpoints && !c->prescribed)
        o->checkpoint_work = work ? work->number : BK_CHECKPOINT_WORK + BK_CHECKPOINT_WORK_PER_BLOCK * blocks;
    entry *wall = bk_config_lookup(ld, "output", "checkpoint_wall_interval");
    o->checkpoint_wall_interval = wall ? wall->number : checkpoints ? 0.0 : BK_CHECKPOINT_WALL_INTERVAL;
    o->max_rows = (long)value_of(ld, "output", "max_rows");
    double samples = o->interval > 0.0 ? c->t_end / o->interval : 0.0;
    if (samples > (double)o->max_rows) {
        if (interval)
            bk_config_report_entry(ld, interval, "gives %.3g rows over t_end = %g s, more than [output] max_rows = %ld "
                                   "(allowed: >= %g s, or raise max_rows)", samples, c->t_end, o->max_rows,
                                   c->t_end / (double)o->max_rows);
        else
            bk_config_report(ld, RANK_MISSING, BK_ERR_CONFIG, "%s: [output] interval: the default t_end / 1000 gives "
                             "more than [output] max_rows = %ld rows", ld->name, o->max_rows);
    }
    o->max_bytes = value_of(ld, "output", "max_bytes");
    if (c->model && ld->error_rank == LONG_MAX) {
        double per_row = bk_output_row_bytes(o->fields, c->model->n_blocks, c->model->n_friction_state,
                                             bk_model_is_damped(c->model));
        double bytes = (samples + 1.0) * per_row;
        if (bytes > o->max_bytes) {
            entry *at = interval ? interval : bk_config_lookup(ld, "output", "max_bytes");
            if (!at)
                at = bk_config_lookup(ld, "model", "n_blocks");
            char where[512];
            if (at)
                bk_config_location(ld, at, where, sizeof where);
            else
                snprintf(where, sizeof where, "%s", ld->name);
            bk_config_report(ld, at ? at->rank : RANK_MISSING, BK_ERR_CONFIG,
                             "%s: [output] max_bytes: the sample rows would take about %.3g bytes (%.3g rows of %.3g "
                             "bytes for %zu blocks), more than max_bytes = %.3g (allowed: a longer interval, fewer "
                             "fields, or raise max_bytes)",
                             where, bytes, samples + 1.0, per_row, c->model->n_blocks, o->max_bytes);
        }
    }
    return c;
}
