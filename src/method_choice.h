/* Internal: what method = auto picks (src/method_choice.c). */
#ifndef BKSIM_METHOD_CHOICE_H
#define BKSIM_METHOD_CHOICE_H

#include "bksim/config.h"
#include "scene.h"

/* Fastest decay rate over fastest oscillation frequency of the chain linearised with every
 * block sliding at the driver speed (its initial friction state): > 1 means a component
 * relaxes faster than the blocks oscillate.  NaN when the probe cannot be built. */
double bk_stiffness_ratio(const bk_model *model);
/* config->solver.method, or for "auto" the back-end the scene should use. */
const char *bk_choose_method(const bk_config *config, const bk_scene *scene);
/* Blocks per segment of local time stepping (run_segments.c) for the scene on this back-end,
 * or 0: every island whole.  [solver] local_stepping = on asks for it (the config checked
 * that it applies); auto gives it where method = auto picked the back-end and it wins. */
size_t bk_choose_segments(const bk_config *config, const bk_scene *scene, const bk_solver_backend *backend);

#endif
