/* bksim: Burridge-Knopoff spring-block chains with stick-slip friction.  Umbrella header. */
#ifndef BKSIM_BKSIM_H
#define BKSIM_BKSIM_H

#define BKSIM_VERSION "0.1.0"

#include "bksim/catalog.h"
#include "bksim/checkpoint.h"
#include "bksim/config.h"
#include "bksim/driver.h"
#include "bksim/friction.h"
#include "bksim/fronts.h"
#include "bksim/inspect.h"
#include "bksim/model.h"
#include "bksim/modes.h"
#include "bksim/output.h"
#include "bksim/param.h"
#include "bksim/rupture.h"
#include "bksim/run.h"
#include "bksim/sink.h"
#include "bksim/solver.h"
#include "bksim/stats.h"
#include "bksim/status.h"

#endif
