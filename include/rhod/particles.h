/* Particle store: structure of arrays with spare capacity, device-resident between
 * steps when the build offloads. The engine knows no physics: a scheme registers the
 * arrays it needs (rhod_particles_add_field) and the store allocates, maps, grows and
 * reorders them all alike.
 *
 * Layout: fluid particles at [0, n), ghost particles (mirrors and periodic images,
 * rebuilt every RK stage) at [n, n + ng). */
#ifndef RHOD_PARTICLES_H
#define RHOD_PARTICLES_H

#include "rhod/config.h"
#include "rhod/device.h"
#include <stdint.h>

#define RHOD_MAX_FIELDS 96
/* A field's `persistent` for a value that lives within one step: kept when the store grows
 * in the middle of a step (new ghosts), but not reordered, appended, copied to or from the
 * device as state, or checkpointed, since it holds nothing from one step to the next. */
#define RHOD_FIELD_STEP 2

typedef struct {
  const char *name;
  void **ptr;     /* address of the owner's pointer variable */
  size_t elem;    /* bytes per particle */
  int persistent; /* 1: carried across steps and reordered with the particles;
                     RHOD_FIELD_STEP: see there; 0: scratch */
} rhod_field_desc;

typedef struct {
  size_t n;   /* fluid particles */
  size_t ng;  /* ghosts after the fluid */
  size_t cap; /* allocated particles (fluid + ghosts) */
  /* persistent state */
  real *x, *y, *ux, *uy, *rho, *m, *dx;
  uint64_t *id;
  /* per-particle tags a scheme asks for (NULL until then, rhod_particles_add_tags):
   * the phase (index into the scene's phases), the kind (a scheme's role of the particle,
   * e.g. regular, guard, boundary) and the level of resolution; persistent, uint8 */
  uint8_t *phase, *kind, *level;
  /* ghost description, valid at [n, n + ng): source fluid particle, position
   * Jacobian J (x' = J x + c, row-major), velocity transform T, and the
   * displacement e used for the hydrostatic correction P' = P + rho g.e */
  int32_t *gsrc;
  real *gJ, *gT;   /* 4 per particle */
  real *gU;        /* 2 per particle: the moving wall's part of the ghost velocity,
                      u_g = T u_src + gU (boundary.h); 0 where no wall moves */
  real *ge;        /* 2 per particle */
  real *gA;        /* 2 per particle: a body's boundary acceleration at the mirror's foot
                      (the ghost pressure's g - a_w), 0 for walls; NULL without bodies */
  real *gTv, *gUv; /* 4 and 2 per particle: the viscous terms' map of a ghost's velocity,
                      u_g = Tv u_src + gUv, where a wall or body is no-slip (gT, gU are then
                      the free-slip map the other terms read: boundary.h); NULL without a
                      no-slip wall or body */
  int32_t *gbody;  /* the body a ghost mirrors (its index); -2 for a periodic image of a
                      fluid particle; -1 otherwise (a wall's mirror, an image of a mirror);
                      NULL without bodies */
  /* scratch for reordering */
  void *scratch;
  size_t scratch_elem;
  int32_t *perm;
  rhod_field_desc fields[RHOD_MAX_FIELDS];
  int nfields;
  uint64_t next_id;
} rhod_particles;

int rhod_particles_init(rhod_particles *p, size_t cap);
/* Registers an array of `elem` bytes per particle; allocated (and mapped) at once. */
int rhod_particles_add_field(rhod_particles *p, const char *name, void **ptr, size_t elem,
                             int persistent);
/* Registers the tags phase, kind and level (zero-filled, persistent). */
int rhod_particles_add_tags(rhod_particles *p);
/* Registers gTv and gUv (a scene with a no-slip wall or body). */
int rhod_particles_add_noslip_fields(rhod_particles *p);
/* The largest of v[0, n) (0 when n is 0): a reduction on the device, e.g. the largest
 * particle size, whose radius a gather over mixed sizes scans. */
real rhod_max_real(const real *v, long n);
/* Registers gA and gbody (scratch; rhod_ghosts_build fills them): a scene with bodies. */
int rhod_particles_add_body_fields(rhod_particles *p);
/* Grows every array to at least `cap` (keeps content of persistent ones). */
int rhod_particles_reserve(rhod_particles *p, size_t cap);
void rhod_particles_free(rhod_particles *p);
/* Copies the persistent arrays of the fluid [0, n) to the device, or back to the host
 * (a host-side fill or edit, an inspection). */
void rhod_particles_to_device(rhod_particles *p);
void rhod_particles_to_host(rhod_particles *p);
/* Reorders the persistent arrays of the fluid: new[k] = old[perm[k]], k < n.
 * perm lives on the device (p->perm). */
void rhod_particles_permute(rhod_particles *p);
/* Appends `count` fluid particles, copies of src[k] (< n, on the device) in every
 * persistent array, at [n, n + count), with new ids: particle n + k gets next_id + k, and
 * next_id grows by count. The caller has reserved room and fixes what differs
 * (refinement children). Ghosts are dropped (p->ng = 0). */
void rhod_particles_append(rhod_particles *p, const int32_t *src, size_t count);
/* Removes fluid particles, keeping the order of the others in every persistent array
 * (through p->perm and rhod_particles_permute): particle i < nflag stays where keep[i] is
 * not 0, the particles at [nflag, n) all stay (e.g. those appended since the flags were
 * set). keep: nflag + 1 int32 on the device, the flags at [0, nflag); overwritten (the
 * new slots, an exclusive scan). Ghosts are dropped. Returns the new n, or -1 when out
 * of memory (the scan's) or nflag > n, the store then unchanged. */
long rhod_particles_compact(rhod_particles *p, int32_t *keep, size_t nflag);

/* The hydrostatic head of ghost g over its source: (g - a_w) . e, (gx, gy) the body force, a_w
 * the acceleration of a moving body's boundary at the mirror's foot (gA, NULL without bodies)
 * and e = ge the ghost's displacement from its source (0 for a periodic image). Along a
 * hydrostatic profile dP = rho (g - a_w) . dx: both schemes continue their sources' state
 * into the ghosts with it (docs/choices.md "ghost values", "multiphase: ghosts"). Inline, so
 * that device loops can call it. */
static inline real rhod_ghost_head(const real *ge, const real *gA, real gx, real gy, long g) {
  if (gA)
    gx -= gA[2 * g], gy -= gA[2 * g + 1];
  return gx * ge[2 * g] + gy * ge[2 * g + 1];
}
#endif
