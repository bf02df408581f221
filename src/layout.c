/* The output layout table (see layout.h).  Units and descriptions are written verbatim as
 * the datasets' "units" and "description" attributes. */
#include "layout.h"

#include <stdio.h>

#include "bksim/config.h"

const bk_series_def bk_series[BK_N_SERIES] = {
    [BK_SERIES_TIME] = {"time", 0, BK_SHAPE_T, BK_KIND_F64, "s", "sample time"},
    [BK_SERIES_DRIVER] = {"driver", 0, BK_SHAPE_T, BK_KIND_F64, "m", "driver displacement D(t)"},
    [BK_SERIES_EVENT] = {"event", 0, BK_SHAPE_T, BK_KIND_U8, "1",
                         "0 = regular sample; at a transition instant two rows with the same time: "
                         "2 = the state just before its transitions, then 1 = just after"},
    [BK_SERIES_X] = {"x", BK_FIELD_X, BK_SHAPE_TN, BK_KIND_F64, "m",
                     "block displacement from the relaxed reference configuration"},
    [BK_SERIES_V] = {"v", BK_FIELD_V, BK_SHAPE_TN, BK_KIND_F64, "m/s", "block velocity"},
    [BK_SERIES_FRICTION] = {"friction", BK_FIELD_FRICTION, BK_SHAPE_TN, BK_KIND_F64, "N",
                            "interface shear force, positive when it resists +x motion "
                            "(the force on the block is -friction)"},
    [BK_SERIES_COF] = {"cof", BK_FIELD_COF, BK_SHAPE_TN, BK_KIND_F64, "1",
                       "apparent coefficient of friction: friction / normal force"},
    [BK_SERIES_MODE] = {"mode", BK_FIELD_MODE, BK_SHAPE_TN, BK_KIND_I8, "1",
                        "block mode: stick 0, slip+ 1, slip- -1"},
    [BK_SERIES_EKIN] = {"energy_kinetic", BK_FIELD_ENERGY, BK_SHAPE_T, BK_KIND_F64, "J",
                        "kinetic energy of all blocks"},
    [BK_SERIES_EEL] = {"energy_elastic", BK_FIELD_ENERGY, BK_SHAPE_T, BK_KIND_F64, "J",
                       "elastic energy stored in all springs"},
    [BK_SERIES_WORK] = {"work_driver", BK_FIELD_ENERGY, BK_SHAPE_T, BK_KIND_F64, "J",
                        "work done by the driver since t = 0"},
    [BK_SERIES_DISS] = {"dissipation", BK_FIELD_ENERGY, BK_SHAPE_T, BK_KIND_F64, "J",
                        "frictional dissipation since t = 0"},
    [BK_SERIES_DAMP] = {"damping_dissipation", BK_FIELD_ENERGY, BK_SHAPE_T, BK_KIND_F64, "J",
                        "energy dissipated by the dashpots ([block] damping, [model] coupling_damping) "
                        "since t = 0", 1},
    [BK_SERIES_STATE] = {"friction_state", BK_FIELD_STATE, BK_SHAPE_TS, BK_KIND_F64,
                         "law-specific",
                         "friction-law state variables; attribute 'block' gives each column's "
                         "block"},
};

const char *const bk_output_field_names[] = {"x", "v", "friction", "cof", "mode", "energy",
                                             "state", NULL};

/* A word for every bit of BK_FIELD_ALL, and no more. */
_Static_assert(sizeof bk_output_field_names / sizeof bk_output_field_names[0] - 1 == 7 &&
                   BK_FIELD_ALL == (1u << 7) - 1,
               "bk_output_field_names must name every BK_FIELD_* bit in order");

int bk_series_selected(const bk_series_def *def, unsigned fields, size_t n_state, int damped)
{
    if ((def->field && !(fields & def->field)) || (def->damped_only && !damped))
        return 0;
    return def->shape != BK_SHAPE_TS || n_state > 0;
}

size_t bk_series_columns(const bk_series_def *def, size_t n_blocks, size_t n_state)
{
    switch (def->shape) {
    case BK_SHAPE_TN:
        return n_blocks;
    case BK_SHAPE_TS:
        return n_state;
    case BK_SHAPE_T:
        break;
    }
    return 1;
}

size_t bk_series_value_size(bk_series_kind kind)
{
    return kind == BK_KIND_F64 ? sizeof(double) : 1;
}

double bk_output_row_bytes(unsigned fields, size_t n_blocks, size_t n_state, int damped)
{
    double bytes = 0.0;
    for (int i = 0; i < BK_N_SERIES; ++i)
        if (bk_series_selected(&bk_series[i], fields, n_state, damped))
            bytes += (double)bk_series_columns(&bk_series[i], n_blocks, n_state) *
                     (double)bk_series_value_size(bk_series[i].kind);
    return bytes;
}

void bk_output_dataset_names(unsigned fields, size_t n_state, int damped, int transitions, unsigned catalogs,
                             char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < BK_N_SERIES; ++i)
        if (bk_series_selected(&bk_series[i], fields, n_state, damped)) {
            int n = snprintf(buf + used, len - used, "%s%s", used ? "," : "", bk_series[i].name);
            if (n > 0 && (size_t)n < len - used)
                used += (size_t)n;
        }
    if (transitions) {
        int n = snprintf(buf + used, len - used, "%stransitions", used ? "," : "");
        if (n > 0 && (size_t)n < len - used)
            used += (size_t)n;
    }
    static const char *const catalog_names[] = {"events", "ruptures,rupture_blocks", "rupture_rate"};
    for (int k = 0; k < 3; ++k)
        if (catalogs & (1 << k)) {
            int n = snprintf(buf + used, len - used, "%s%s", used ? "," : "", catalog_names[k]);
            if (n > 0 && (size_t)n < len - used)
                used += (size_t)n;
        }
}
