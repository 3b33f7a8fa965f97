/* Private to the scene loader: the RHOD-SPH scheme's keys of a scene as libcyaml loads
 * them, their schema, checks and scene-as-run writer (scene_rs.c). Whole sections
 * (`refinement`) come as a field list; the keys rhodsph adds to a shared section (time,
 * particles, physics, scheme) as a struct embedded in the loader's struct of that
 * section and a macro that expands to their schema fields there. src/scene.c puts them
 * into its document schema and calls these, section by section, in the order the
 * loader always checked them (so that a scene with several errors reports the same). */
#ifndef RHOD_SCENE_RS_H
#define RHOD_SCENE_RS_H

#include "../scene_module.h"
#include "rhod/rhodsph/scene.h"
#include "rhod/scene.h"

#include <cyaml/cyaml.h>
#include <stdbool.h>

/* ---- the keys as libcyaml loads them (optional values are pointers: NULL = absent) -- */

typedef struct {
  double *cfl, *cfl_visc;
  bool *stiffness_limit;
} y_rs_time;

typedef struct {
  double *relax;
  int *relax_where;
} y_rs_particles;

typedef struct {
  double *rho0, *c0, *mu;
} y_rs_physics;

/* scheme.* but scheme.name (the loader's) */
typedef struct {
  bool *riemann, *reconstruction, *shifting;
  double *shifting_a, *shifting_b, *shifting_eps;
  bool *acoustic_damper;
  double *alpha_ad;
  bool *damper_step_limit;
  bool *tensile_control;
  int *shifting_switch;
  bool *free_surface;
  double *free_surface_lambda;
  double *shepard_threshold, *theta_threshold;
  int *viscosity;
} y_rs_scheme;

typedef struct {
  y_rect *rect;
  y_circle *circle;
  double (*polygon)[2];
  unsigned n_polygon;
  double level;
  bool *hold;
} y_rs_region;

typedef struct {
  int quantity;
  double *above, *below, *from;
  double *x0;
} y_rs_refine_field;

typedef struct {
  double *levels;
  y_rs_region *regions;
  unsigned n_regions;
  bool *dynamic, *free_surface, *walls, *coalesce, *absorb;
  double *surface_band, *crowding;
  int *pattern;
  y_rs_refine_field *field;
} y_rs_refinement;

/* ---- the schema -------------------------------------------------------------------- */

/* the enum names of rhodsph's keys */
extern const cyaml_strval_t rhod_rs_relax_where_names[2];
extern const cyaml_strval_t rhod_rs_shifting_switch_names[5];
extern const cyaml_strval_t rhod_rs_viscosity_names[2];

#define RHOD_RS_OPT_ (CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL)
#define RHOD_RS_NUM_(key, st, m) CYAML_FIELD_FLOAT_PTR(key, RHOD_RS_OPT_ | CYAML_FLAG_STRICT, st, m)
#define RHOD_RS_BOOL_(key, st, m) CYAML_FIELD_BOOL_PTR(key, RHOD_RS_OPT_, st, m)
#define RHOD_RS_ENUM_(key, st, m, strings)                                                         \
  CYAML_FIELD_ENUM_PTR(key, RHOD_RS_OPT_ | CYAML_FLAG_STRICT, st, m, strings,                      \
                       CYAML_ARRAY_LEN(strings))

/* The schema fields of rhodsph's keys in a shared section, for the loader's struct `st`
 * whose member `m` is the y_rs_* struct of that section. time holds two groups, so that
 * the section keeps its order (end, output_every, cfl, cfl_visc, integrator,
 * stiffness_limit). */
#define RHOD_RS_TIME_STEP_FIELDS(st, m)                                                            \
  RHOD_RS_NUM_("cfl", st, m.cfl), RHOD_RS_NUM_("cfl_visc", st, m.cfl_visc)
#define RHOD_RS_TIME_LIMIT_FIELDS(st, m) RHOD_RS_BOOL_("stiffness_limit", st, m.stiffness_limit)
#define RHOD_RS_PARTICLES_FIELDS(st, m)                                                            \
  RHOD_RS_NUM_("relax", st, m.relax),                                                              \
      RHOD_RS_ENUM_("relax_where", st, m.relax_where, rhod_rs_relax_where_names)
#define RHOD_RS_PHYSICS_FIELDS(st, m)                                                              \
  RHOD_RS_NUM_("rho0", st, m.rho0), RHOD_RS_NUM_("c0", st, m.c0), RHOD_RS_NUM_("mu", st, m.mu)
#define RHOD_RS_SCHEME_FIELDS(st, m)                                                               \
  RHOD_RS_BOOL_("riemann", st, m.riemann), RHOD_RS_BOOL_("reconstruction", st, m.reconstruction),  \
      RHOD_RS_BOOL_("shifting", st, m.shifting), RHOD_RS_NUM_("shifting_a", st, m.shifting_a),     \
      RHOD_RS_NUM_("shifting_b", st, m.shifting_b),                                                \
      RHOD_RS_NUM_("shifting_eps", st, m.shifting_eps),                                            \
      RHOD_RS_BOOL_("acoustic_damper", st, m.acoustic_damper),                                     \
      RHOD_RS_NUM_("alpha_ad", st, m.alpha_ad),                                                    \
      RHOD_RS_BOOL_("damper_step_limit", st, m.damper_step_limit),                                 \
      RHOD_RS_BOOL_("tensile_control", st, m.tensile_control),                                     \
      RHOD_RS_ENUM_("shifting_switch", st, m.shifting_switch, rhod_rs_shifting_switch_names),      \
      RHOD_RS_BOOL_("free_surface", st, m.free_surface),                                           \
      CYAML_FIELD_SEQUENCE_FIXED("free_surface_lambda", RHOD_RS_OPT_ | CYAML_FLAG_FLOW, st,        \
                                 m.free_surface_lambda, &rhod_sl_sch_float, 2),                    \
      RHOD_RS_NUM_("shepard_threshold", st, m.shepard_threshold),                                  \
      RHOD_RS_NUM_("theta_threshold", st, m.theta_threshold),                                      \
      RHOD_RS_ENUM_("viscosity", st, m.viscosity, rhod_rs_viscosity_names)

/* the fields of the refinement mapping */
extern const cyaml_schema_field_t rhod_rs_f_refinement[];

/* Whether section.key (a key of a top-level mapping) is rhodsph's: the keys a scene of
 * another scheme refuses. */
int rhod_rs_owns(const char *section, const char *key);

/* ---- checks and defaults, one call per section, in the loader's order -------------- */

/* Makes s->rs and fills time.cfl, cfl_visc, stiffness_limit (after time.end and
 * time.output_every are checked). */
int rhod_rs_load_time(lctx *c, const y_rs_time *y, rhod_scene *s);
/* particles.relax, relax_where (after particles.jitter) */
int rhod_rs_load_particles(lctx *c, const y_rs_particles *y, rhod_scene *s);
/* physics (required, with c0), after physics.gravity */
int rhod_rs_load_physics(lctx *c, const y_rs_physics *y, rhod_scene *s);
/* scheme.* (y NULL: the scheme section is absent) */
int rhod_rs_load_scheme(lctx *c, const y_rs_scheme *y, rhod_scene *s);
/* refinement (after the walls; y NULL: absent) */
int rhod_rs_load_refinement(lctx *c, const y_rs_refinement *y, rhod_scene *s);

/* Adds to *n the extra initial particles the refinement regions ask for in a block of
 * bounding box [lo, hi]: a region at level l puts 4^l particles in each coarse cell (of
 * area `cell`) of its overlap with the box (part of rhod_scene_particle_estimate). */
void rhod_rs_region_estimate(const rhod_rs_scene *rs, const double lo[2], const double hi[2],
                             double cell, double *n);

/* ---- the scene as run: rhodsph's keys under each section's node, in the order the
 * loader always wrote them ------------------------------------------------------------ */
void rhod_rs_tree_time_step(rhod_sl_tb *t, ry_node *time, const rhod_rs_scene *rs);
void rhod_rs_tree_time_limit(rhod_sl_tb *t, ry_node *time, const rhod_rs_scene *rs);
void rhod_rs_tree_particles(rhod_sl_tb *t, ry_node *particles, const rhod_rs_scene *rs);
void rhod_rs_tree_physics(rhod_sl_tb *t, ry_node *physics, const rhod_rs_scene *rs);
void rhod_rs_tree_scheme(rhod_sl_tb *t, ry_node *scheme, const rhod_rs_scene *rs);
void rhod_rs_tree_refinement(rhod_sl_tb *t, ry_node *root, const rhod_rs_scene *rs);

#endif
