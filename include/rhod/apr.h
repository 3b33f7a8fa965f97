/* Adaptive particle refinement of paper 002 (Michel et al. 2025), Sec. V: the
 * refinement criteria (Sec. V B), evaluated during the last stage of a step, and the
 * 1 -> 4 split (Sec. V A) applied before the next one: mark, scan, append, then the
 * engine re-sorts at the next step. Sizes are particles.dx / 2^l, l < levels. */
#ifndef RHOD_APR_H
#define RHOD_APR_H

#include "rhod/boundary.h"
#include "rhod/cells.h"
#include "rhod/particles.h"
#include "rhod/scene.h"
#include "rhod/sph.h"

typedef struct {
  int active;       /* dynamic refinement on */
  real dx_min;      /* no particle is split below this size */
  int free_surface; /* criterion 3 */
  int walls;        /* criterion 4 */
  int field;        /* criterion 5 */
  rhod_quantity qty;
  real above, below, from;
  /* Own buffers, not fields of the store: they must survive the store's growth
   * between marking and splitting. */
  size_t cap;
  uint8_t *mark; /* cap: 1 = split at the end of the step */
  uint8_t *near; /* cap: criterion 4 (support reaches a wall) */
  int32_t *cnt;  /* cap + 1: children written per particle, scanned */
  real *sd;      /* 4 cap: split data: grad P (Eq. 14), unit vector to the nearest neighbour */
  long split_last, split_total; /* particles split by the last call and by the run */
} rhod_apr;

int rhod_apr_init(rhod_apr *a, const rhod_scene *sc, double dx_min);
void rhod_apr_free(rhod_apr *a);

/* Criteria 1-5 for every fluid particle, from the neighbour structure and the
 * scheme's fields of the right-hand side just computed (call it after the last
 * stage's rhod_sph_rhs, before the update). Time t gates criterion 5. */
int rhod_apr_mark(rhod_apr *a, const rhod_sph *s, const rhod_particles *p, const rhod_cells *c,
                  const rhod_boundary *b, double t);

/* Splits the marked fluid particles (Sec. V A) at their current state; returns how
 * many were split, or < 0 when memory ran out. Children are kept off the walls of b
 * (half their size). Ghosts and cells are stale after it. */
long rhod_apr_split(rhod_apr *a, const rhod_sph *s, rhod_particles *p, const rhod_boundary *b);

#endif
