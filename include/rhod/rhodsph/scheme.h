/* RHOD-SPH (paper 002) as a scheme of the engine's driver (include/rhod/scheme.h): the
 * passes of rhod_sph.c and the adaptive particle refinement of rhod_apr.c behind the
 * driver's hooks. */
#ifndef RHOD_RHODSPH_SCHEME_H
#define RHOD_RHODSPH_SCHEME_H

#include "rhod/rhodsph/apr.h"
#include "rhod/rhodsph/sph.h"
#include "rhod/scheme.h"
#include "rhod/sim.h"

/* Steps between two searches for coalescing groups (refinement.coalesce). */
#define RHOD_COALESCE_EVERY 10

/* The scheme's state in a run (rhod_sim.sch). */
typedef struct {
  rhod_sph sph;
  rhod_apr apr;
  long damper_limited;    /* steps of this process whose dt the damper step limit set */
  long stiffness_limited; /* ... and those whose dt the stiffness limit set */
} rhod_rhodsph;

extern const rhod_scheme_ops rhod_rhodsph_ops;

/* The RHOD-SPH state of a run made with it (tests, benchmarks). */
static inline rhod_rhodsph *rhod_rs(const rhod_sim *s) { return (rhod_rhodsph *)s->sch; }

#endif
