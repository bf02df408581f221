/* Maps [friction] law names to law tables. */
#include <string.h>

#include "bksim/friction.h"

static const bk_friction_law *const registered_laws[] = {
    &bk_friction_coulomb,
    &bk_friction_rate_state,
    &bk_friction_carlson_langer,
    &bk_friction_dieterich_ruina_aging,
    &bk_friction_dieterich_ruina_slip,
    NULL,
};

const bk_friction_law *const *bk_friction_laws(void) { return registered_laws; }

const bk_friction_law *bk_friction_law_find(const char *name)
{
    for (const bk_friction_law *const *law = registered_laws; *law; ++law)
        if (strcmp((*law)->name, name) == 0)
            return *law;
    return NULL;
}

int bk_friction_param_index(const bk_friction_law *law, const char *key)
{
    for (size_t i = 0; i < law->n_params; ++i)
        if (strcmp(law->params[i].key, key) == 0)
            return (int)i;
    return -1;
}
