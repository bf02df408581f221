/* A run that starts where another ended (`bksim run --init-from`): the blocks' positions,
 * velocities and friction states and the driver's position at the other run's end become this
 * run's state at t = 0, so that a loading phase and a rupture phase (or any two stages with
 * different keys) can be separate runs of one chain. */
#include <stdlib.h>
#include <string.h>

#include "bksim/checkpoint.h"
#include "bksim/run.h"

int bk_config_start_from(bk_config *config, const bk_config *source, const bk_checkpoint *end, bk_error *err)
{
    if (!config || !source || !end)
        return BK_FAIL(err, BK_ERR_INVALID, "bk_config_start_from: needs a config, a source config and a state");
    if (config->prescribed || source->prescribed)
        return BK_FAIL(err, BK_ERR_INVALID, "a prescribed-motion scene has no chain state to start from or to give");
    bk_model *model = config->model;
    const bk_model *from = source->model;
    if (model->rows != from->rows || model->cols != from->cols)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "the scene is %zu x %zu blocks, the run it would start from %zu x %zu (allowed: the same "
                       "shape)", model->rows, model->cols, from->rows, from->cols);
    if (end->n_blocks != model->n_blocks || end->n_state != model->n_friction_state)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "the state holds %zu blocks and %zu friction states, the scene has %zu and %zu",
                       end->n_blocks, end->n_state, model->n_blocks, model->n_friction_state);
    for (size_t i = 0; i < model->n_blocks; ++i)
        if (model->blocks[i].law != from->blocks[i].law)
            return BK_FAIL(err, BK_ERR_INVALID,
                           "block %zu has friction law %s here and %s in the run it would start from (allowed: the "
                           "same law on every block: a friction state means nothing to another law)",
                           i, model->blocks[i].law->name, from->blocks[i].law->name);
    double *state = NULL;
    if (model->n_friction_state > 0) {
        state = malloc(model->n_friction_state * sizeof *state);
        if (!state)
            return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu friction states", model->n_friction_state);
        memcpy(state, end->state, model->n_friction_state * sizeof *state);
    }
    for (size_t i = 0; i < model->n_blocks; ++i) {
        model->blocks[i].x_init = end->x[i];
        /* A block without mass has no velocity of its own: its force balance gives it. */
        model->blocks[i].v_init = model->blocks[i].mass > 0.0 ? end->v[i] : 0.0;
    }
    free(model->state_init);
    model->state_init = state;
    bk_driver_move_start(&model->driver, bk_driver_position(&from->driver, end->t));
    return BK_OK;
}
