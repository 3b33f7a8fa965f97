/* The multiphase scheme of paper 000 (regular particles, one resolution) as a scheme of
 * the engine's driver (include/rhod/scheme.h): the passes of kernels/multiphase/mp.c behind
 * the driver's hooks. */
#ifndef RHOD_MULTIPHASE_SCHEME_H
#define RHOD_MULTIPHASE_SCHEME_H

#include "rhod/multiphase/mp.h"
#include "rhod/scheme.h"
#include "rhod/sim.h"

/* The scheme's state in a run (rhod_sim.sch). */
typedef struct {
  rhod_mp mp;
  double us_max; /* the run's largest |u_s| dt / dx */
  long dt_by[4]; /* steps of this process whose dt each limit set (RHOD_MP_DT_*) */
} rhod_mps_state;

extern const rhod_scheme_ops rhod_multiphase_ops;

static inline rhod_mps_state *rhod_mps_of(const rhod_sim *s) { return (rhod_mps_state *)s->sch; }
static inline rhod_mp *rhod_mps(const rhod_sim *s) { return &rhod_mps_of(s)->mp; }

#endif
