/* The seam between the engine's driver (src/sim.c) and a scheme: host-side hooks the
 * driver calls at fixed points of a run. The engine fills the lattice, builds ghosts and
 * cells, integrates the variables a scheme registered (rhod_rk_add), checks the state and
 * reads the probes and output fields every scheme shares; the scheme computes its
 * right-hand side and time step and does its own end-of-step work (RHOD-SPH's split and
 * merge). Kernels never see these pointers: each hook calls the scheme's own passes.
 *
 * A scheme is one const rhod_scheme_ops; src/schemes.c (the application's registry, the
 * one file that names every scheme) picks it from the scene (scheme.name). */
#ifndef RHOD_SCHEME_H
#define RHOD_SCHEME_H

#include "rhod/checkpoint.h"
#include "rhod/config.h"
#include "rhod/io.h"
#include "rhod/scene.h"
#include <stddef.h>

struct rhod_sim;

/* A run statistic a scheme reports: a summary.json key and its value (integer or not). */
typedef struct {
  const char *key;
  double value;
  int integer;
} rhod_stat;
#define RHOD_MAX_STATS 16

/* A field of the particle store that a scene may have written (output.fields): its name in
 * the store (rhod_particles.fields[].name, which output.fields names), the dataset it
 * becomes (/PartType0/<dataset>) and its unit. The store's entry gives the type: uint8
 * (1 byte), or 1 or 2 reals per particle. Only where it is registered in the run. */
typedef struct {
  const char *field, *dataset, *units;
} rhod_output_field;

typedef struct rhod_scheme_ops {
  const char *name; /* scheme.name */
  /* Before the fill (s->sc, s->lo, s->hi set): the finest particle size the scene allows,
   * and how far wall mirrors reach, in units of a particle's kernel radius R_i. A status,
   * with a one-line message in err, when the scene is not one the scheme can run (a scene
   * built by hand without the scheme's keys or with values the loader refuses). */
  int (*geometry)(const rhod_scene *sc, double *dx_min, double *mirror_reach, char *err,
                  size_t errlen);
  /* The fill's initial levels (may be NULL: one level): the finest level asked at (x, y),
   * 0 for particles.dx. The fill puts one particle in a lattice cell of level l (size
   * particles.dx / 2^l) where the level asked at the cell's centre is at most l, else
   * its four quarter cells of level l + 1, each refined again where asked: the lattices
   * nest as a quadtree. */
  int (*fill_level)(const rhod_scene *sc, double x, double y);
  /* Whether the fill leaves particles.jitter to the scheme (may be NULL: it does not): the
   * lattice is then filled unjittered, and the scheme jitters it itself in `start`
   * (rhod_sim_restate). */
  int (*fill_unjittered)(const rhod_scene *sc);
  /* The initial state of particle k of fluid block b at (x, y), size dx: every persistent
   * field the scheme's variables need (the engine has set nothing but the id). Called on
   * the host during the fill and by rhod_sim_restate. */
  void (*initial_state)(struct rhod_sim *s, unsigned b, size_t k, double x, double y, double dx);
  /* After the fill, before anything is on the device: the scheme's state (s->sch), its
   * fields, its integrated variables (s->rk, made by the engine with the scene's method)
   * and the pressure and volume arrays the engine's probes read (s->P, s->V). */
  int (*init)(struct rhod_sim *s, char *err, size_t errlen);
  /* After the first prepare (ghosts and cells built): initial work before t = 0 (RHOD-SPH:
   * the initial refinement and relaxation). May be NULL. */
  int (*start)(struct rhod_sim *s, char *err, size_t errlen);
  void (*free)(struct rhod_sim *s);
  /* After the ghosts are built and before any gather: the ghosts' values from their
   * sources and the fluid's equation of state. */
  void (*ghost_state)(struct rhod_sim *s);
  /* The right-hand side of stage `stage` of the step from t of size dt (ghosts and cells
   * current): fills the derivatives of the registered variables. Stage work (RHOD-SPH's
   * stiffness measure and refinement criteria) belongs here. Returns a status. */
  int (*rhs)(struct rhod_sim *s, int stage, double t, real dt);
  /* Sets s->dt for the next step (may call rhod_sim_prepare). */
  int (*dt)(struct rhod_sim *s);
  /* After a step that passed the state check: end-of-step work. May be NULL. */
  int (*end_step)(struct rhod_sim *s);
  /* A probe the engine does not read itself (rhod_probe_values): its columns into out.
   * RHOD_ERR_SCENE when the scheme has no such probe. */
  int (*probe)(struct rhod_sim *s, const rhod_probe *pr, double *out);
  /* The scheme's output fields for the prepared state, on the host, into v (pressure,
   * free surface, phase ...); the engine adds the particles' own. */
  void (*output)(struct rhod_sim *s, rhod_snapshot_view *v);
  /* The store's fields output.fields may name, ended by a { NULL } entry (NULL: none): only
   * those whose values mean something at output time, i.e. persistent ones, or ones that
   * `output` computes for the prepared state. When the scene names one, `output` runs with
   * fresh ghosts and cells (rhod_sim_fetch rebuilds them, unsorted, after a step). */
  const rhod_output_field *outputs;
  /* Statistics for the summary (count returned) and log lines for the end of a run
   * (rhod_warn into w). Either may be NULL. */
  int (*stats)(const struct rhod_sim *s, rhod_stat *out, int max);
  void (*report)(const struct rhod_sim *s, long steps, rhod_warn_buf *w);
  /* Checkpoint extras: the scheme's scalars a run carries on (ck->extra), saved into a
   * checkpoint and taken back from one on resume (after the particles are applied).
   * Either may be NULL. */
  void (*save)(const struct rhod_sim *s, rhod_checkpoint *ck);
  int (*load)(struct rhod_sim *s, const rhod_checkpoint *ck, char *err, size_t errlen);
} rhod_scheme_ops;

/* The scheme a scene asks for (src/schemes.c); NULL when the build has none by that name. */
const rhod_scheme_ops *rhod_scheme_for(const rhod_scene *sc);

#endif
