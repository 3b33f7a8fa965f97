/* Private to the scene loader: the `open_boundaries` section of a scene (inflows and
 * outflows, issue 52) as libcyaml loads it, its schema, checks, defaults and scene-as-run
 * writer (scene_open.c). src/scene.c puts the schema into its document and calls these. */
#ifndef RHOD_SCENE_OPEN_H
#define RHOD_SCENE_OPEN_H

#include "rhod/scene.h"
#include "scene_module.h"

#include <cyaml/cyaml.h>

/* open_boundaries.N (optional values are pointers: NULL = absent) */
typedef struct {
  char *name;
  int kind;
  double *from, *to; /* required: [x, y] */
  double *normal;
  char *velocity;
  int *profile;
  double *surface;
  double *pressure;
  double *dx;
  char *phase;
} y_open;

/* the schema of one open_boundaries entry */
extern const cyaml_schema_value_t rhod_ob_sch_open;

/* What the schemes' sections say about open boundaries (src/scene.c fills it from them:
 * this module includes no scheme header): the size ratio of two refinement levels (2;
 * rhodsph: its pattern's), the finest level a dx may take (rhodsph: refinement.levels - 1)
 * and the phases' names (multiphase; none for rhodsph). */
typedef struct {
  double ratio;
  int max_level;
  const char *const *phases;
  unsigned n_phases;
} rhod_ob_levels;

/* Checks each entry's own keys and fills s->open (all but the normal): after the walls,
 * the bodies, the phases and the refinement are loaded, before the default domain
 * (which takes the segments' ends, rhod_ob_bbox). */
int rhod_ob_load(lctx *c, const y_open *open, unsigned n, const rhod_ob_levels *lv, rhod_scene *s);

/* The bounding box of open boundary o's segment (for the default domain). */
void rhod_ob_bbox(const rhod_open_boundary *o, double lo[2], double hi[2]);

/* Resolves the normals (their default points toward the domain's centre) and checks where
 * the open boundaries lie: in the domain, not inside the fluid, not over one another, not
 * on a wall's or body's edge, not across a periodic axis. After the domain is known; open
 * holds the s->n_open entries rhod_ob_load took. */
int rhod_ob_place(lctx *c, const y_open *open, rhod_scene *s);

/* Writes `open_boundaries` of the scene as run under root (nothing when there are none). */
void rhod_ob_tree(rhod_sl_tb *t, ry_node *root, const rhod_scene *s, const rhod_ob_levels *lv);

void rhod_ob_free(rhod_scene *s);

#endif
