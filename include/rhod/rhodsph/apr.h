/* Adaptive particle refinement of paper 002 (Michel et al. 2025), Sec. V: the
 * refinement criteria (Sec. V B), evaluated during the last stage of a step, and the
 * 1 -> 4 split (Sec. V A; or 1 -> 3, Appendix) applied before the next one: mark,
 * scan, append, then the engine re-sorts at the next step. Sizes are particles.dx /
 * e^l, l < levels, e = 2 (square pattern) or sqrt 3 (triangle).
 *
 * Coalescing (not in paper 002, which leaves it to future work; paper 004 Sec. 2.3
 * merges the nearest small particles at their centre of mass): four (triangle: three)
 * particles of a level where no criterion would refine their parent any more merge
 * back into one of the next coarser size, conserving mass, momentum and volume. A candidate
 * that can be in no group (too few particles of its size near it) is absorbed instead:
 * shared out among its neighbours of the next coarser size, with the same sums kept.
 * Marked in the same pass (candidates, groups, absorptions), applied after the split:
 * combine, scan, compact. */
#ifndef RHOD_APR_H
#define RHOD_APR_H

#include "rhod/boundary.h"
#include "rhod/cells.h"
#include "rhod/particles.h"
#include "rhod/rhodsph/scene.h"
#include "rhod/rhodsph/sph.h"

#define RHOD_HOLD_STRIDE 6

typedef struct {
  int active;       /* dynamic refinement on */
  real dx_min;      /* no particle is split below this size */
  int free_surface; /* criterion 3 */
  real band;        /* criterion 3's reach over R_i (refinement.surface_band; 1: the paper) */
  real crowd;       /* refinement.crowding: split where a finer particle is nearer than crowd
                       times the mean of the two sizes (ours; 0: off) */
  int walls;        /* criterion 4 */
  int field;        /* criterion 5 */
  real fc[5];       /* its field, fc . (P, rho |u|^2 / 2, x, y, 1) (rhod_apr.c FIELD_OF) */
  real above, below, from;
  int nsplit;     /* children per split: 4 (square pattern) or 3 (triangle) */
  real eps, ieps; /* size ratio of adjacent levels (2 or sqrt 3) and its inverse */
  int coalesce;   /* refinement.coalesce */
  int absorb;     /* refinement.absorb: stragglers absorbed (absorb in rhod_apr.c) */
  real dx_max;    /* no particle grows beyond this size (particles.dx) */
  /* the held regions (refinement.regions.N.hold, ours): a particle whose centre is in
   * one splits down to its level during the run; none coarser is merged within one
   * merged size of it. Records of RHOD_HOLD_STRIDE reals on the device: kind (a
   * rhod_shape_kind), the region's size dx / e^level, then rect: min x, min y, max x,
   * max y; circle: centre x, y, radius; polygon: first vertex and vertex count in hp */
  int nhold;
  real *hr, *hp; /* nhold records; the polygons' vertices (x, y), nhp of them */
  long nhp;
  /* Own buffers, not fields of the store: they must survive the store's growth
   * between marking and splitting. */
  size_t cap;
  uint8_t *mark;  /* cap: 1 = split at the end of the step; coalescing: 2 candidate,
                     3 merges its group into itself, 4 merged into another, 5 a
                     straggler shared out among its coarser neighbours, 6 one of them */
  uint8_t *near;  /* cap: criterion 4 (support reaches a wall) */
  int32_t *cnt;   /* cap + 1: children written per particle, scanned */
  real *sd;       /* 4 cap: split data: grad P (Eq. 14), unit vector to the nearest neighbour */
  uint8_t *near2; /* cap: criterion 4 for the coalesced particle (wider support) */
  int32_t *grp;   /* 4 cap: the group a candidate proposes (itself first; -1 pads a
                     group of three) */
  int32_t *claim; /* cap: the winning group containing a candidate, or -1 */
  uint8_t *acc;   /* cap: 1 = the candidate's proposed group was accepted */
  real *sp;       /* cap: the proposal's spread (smaller wins), or 1e30 for none */
  long n_marked;  /* fluid particles when marked (coalescing indices are below it) */
  long groups;    /* groups the last marking accepted, for rhod_apr_coalesce */
  long absorbed;  /* stragglers the last marking shared out (marks 5, receivers 6) */
  long split_last, split_total;       /* particles split by the last call and by the run */
  long merged_last, merged_total;     /* groups coalesced by the last call and by the run */
  long absorbed_last, absorbed_total; /* stragglers absorbed by the last call and the run */
  double ke_merged, ke_absorbed;      /* kinetic energy the merges and the absorptions of the run
                                         took out (motion about the mean), J per unit depth */
} rhod_apr;

int rhod_apr_init(rhod_apr *a, const rhod_scene *sc, double dx_min);
void rhod_apr_free(rhod_apr *a);

/* Criteria 1-5 for every fluid particle, from the neighbour structure and the
 * scheme's fields of the right-hand side just computed (call it after the last
 * stage's rhod_sph_rhs, before the update). Time t gates criterion 5. With coalesce
 * (and a->coalesce) it also forms the groups that rhod_apr_coalesce merges. */
int rhod_apr_mark(rhod_apr *a, const rhod_sph *s, const rhod_particles *p, const rhod_cells *c,
                  const rhod_boundary *b, double t, int coalesce);

/* Splits the marked fluid particles (Sec. V A) at their current state; returns how
 * many were split, or < 0 when memory ran out. Children are kept off the walls of b
 * (a quarter of their size). Ghosts and cells are stale after it. */
long rhod_apr_split(rhod_apr *a, const rhod_sph *s, rhod_particles *p, const rhod_boundary *b);

/* Merges the groups formed by the last rhod_apr_mark and the absorbed stragglers into
 * their receivers (call it after rhod_apr_split, whose children it keeps) and removes
 * the merged and absorbed particles; returns the number of groups merged, or < 0 when
 * memory ran out (the removal's scan; the merged particles are then left in place). Ghosts and
 * cells are stale after it. */
long rhod_apr_coalesce(rhod_apr *a, rhod_particles *p);

#endif
