/* Private to the scene loader: the multiphase scheme's sections of a scene as libcyaml
 * loads them (`phases`, `multiphase`), their schema, checks and scene-as-run writer
 * (scene_mp.c). src/scene.c puts them into its document schema and calls these. */
#ifndef RHOD_SCENE_MP_H
#define RHOD_SCENE_MP_H

#include "../scene_module.h"
#include "rhod/multiphase/scene.h"
#include "rhod/scene.h"

#include <cyaml/cyaml.h>
#include <stdbool.h>

/* phases.N (optional values are pointers: NULL = absent) */
typedef struct {
  char *name;
  double rho0, c;
  double *gamma, *mu, *colour;
} y_mp_phase;

/* multiphase.sigma_pairs.N */
typedef struct {
  char *phases[2];
  double sigma;
} y_mp_pair;

/* multiphase */
typedef struct {
  double *sigma;
  y_mp_pair *sigma_pairs;
  unsigned n_sigma_pairs;
  double *delta, *shifting, *repulsion, *repulsion_power, *interface_force, *viscosity_eta;
  bool *tensile_control;
  double *cfl, *cfl_visc, *cfl_force, *cfl_surface;
} y_mp_section;

/* the schema of one phases entry and of the multiphase mapping's fields */
extern const cyaml_schema_value_t rhod_mp_sch_phase;
extern const cyaml_schema_field_t rhod_mp_f_section[];

/* Checks the phases and the multiphase section of a multiphase scene and fills s->mp.
 * `phases` is NULL when the document has none. */
int rhod_mp_load(lctx *c, const y_mp_phase *phases, unsigned n_phases, const y_mp_section *sec,
                 rhod_scene *s);

/* fluid.N.phase of a multiphase scene: the phase's index into s->mp->phases. */
int rhod_mp_fluid_phase(lctx *c, const rhod_scene *s, unsigned block, const char *phase,
                        int *index);

/* Writes `phases` and `multiphase` of the scene as run under root. */
void rhod_mp_tree(rhod_sl_tb *t, ry_node *root, const rhod_mp_scene *mp);

#endif
