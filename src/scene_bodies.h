/* Private to the scene loader: the `bodies` section of a scene (rigid bodies, issue 51) as
 * libcyaml loads it, its schema, checks, defaults and scene-as-run writer
 * (scene_bodies.c). src/scene.c puts the schema into its document and calls these. */
#ifndef RHOD_SCENE_BODIES_H
#define RHOD_SCENE_BODIES_H

#include "rhod/scene.h"
#include "scene_module.h"

#include <cyaml/cyaml.h>
#include <stdbool.h>

/* bodies.N.law: expressions of t, NULL where not given */
typedef struct {
  char *x, *y, *theta;
} y_body_law;

/* bodies.N (optional values are pointers: NULL = absent) */
typedef struct {
  char *name;
  y_rect *rect;
  y_circle *circle;
  double (*polygon)[2];
  unsigned n_polygon;
  int *slip;
  bool *refine;
  int *motion;
  double *center;
  y_body_law *law;
  double *mass, *density, *inertia, *added_mass;
  int *lock;
  unsigned n_lock;
  double *velocity, *omega;
} y_body;

/* the schema of one bodies entry */
extern const cyaml_schema_value_t rhod_bd_sch_body;

/* Checks the bodies and fills s->bodies: after the domain and the walls are loaded (the
 * placement checks need them). */
int rhod_bd_load(lctx *c, const y_body *bodies, unsigned n, rhod_scene *s);

/* Checks a law: an expression of t alone in libmatheval syntax, whose value and first two
 * derivatives are finite at t = 0 (*v0 its value there); else the one-line error at path. */
int rhod_bd_check_law(lctx *c, const char *path, const char *text, double *v0);

/* The bounding box of body b where it stands at t = 0 (for the default domain). */
void rhod_bd_bbox(const rhod_body *b, double lo[2], double hi[2]);

/* Writes `bodies` of the scene as run under root (nothing when there are none). */
void rhod_bd_tree(rhod_sl_tb *t, ry_node *root, const rhod_scene *s);

void rhod_bd_free(rhod_scene *s);

#endif
