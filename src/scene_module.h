/* Private to the scene loader and the scheme modules that own sections of a scene
 * (src/multiphase/scene_mp.c, src/rhodsph/scene_rs.c): the loader's mechanism
 * (src/scene.c) lends each module its messages, its shapes and its writer of the scene as
 * run, so that a module's checks report "file:line:col: key: reason" (or the `--set`
 * override) exactly like the loader's own. */
#ifndef RHOD_SCENE_MODULE_H
#define RHOD_SCENE_MODULE_H

#include "rhod/scene.h"
#include "scene_yaml.h"

#include <cyaml/cyaml.h>
#include <stdbool.h>

/* The loading context of src/scene.c (the file, the overrides, the document's tree). */
typedef struct lctx lctx;

/* Returns the status of expr when it is not RHOD_OK. */
#define TRY(expr)                                                                                  \
  do {                                                                                             \
    int rc_ = (expr);                                                                              \
    if (rc_)                                                                                       \
      return rc_;                                                                                  \
  } while (0)

/* An optional number's value, or its default when absent. */
static inline double opt(const double *p, double def) { return p ? *p : def; }
/* An optional boolean's value (1 or 0), or its default when absent. */
static inline int opt_bool(const bool *p, int def) { return p ? (*p ? 1 : 0) : def; }

/* Shapes as libcyaml loads them: one of rect, circle, polygon (RHOD_SL_SHAPE_FIELDS). */
typedef struct {
  double min[2], max[2];
} y_rect;

typedef struct {
  double center[2];
  double radius;
} y_circle;

extern const cyaml_schema_value_t rhod_sl_sch_float; /* a finite number */
extern const cyaml_schema_value_t rhod_sl_sch_vec;   /* [x, y] */
extern const cyaml_schema_field_t rhod_sl_f_rect[], rhod_sl_f_circle[];

/* The shape keys of an entry of struct `st`, whose members rect, circle, polygon and
 * n_polygon are as in y_rect, y_circle and a counted list of [x, y]. */
#define RHOD_SL_SHAPE_FIELDS(st)                                                                   \
  CYAML_FIELD_MAPPING_PTR("rect", CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL | CYAML_FLAG_FLOW, st,  \
                          rect, rhod_sl_f_rect),                                                   \
      CYAML_FIELD_MAPPING_PTR("circle",                                                            \
                              CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL | CYAML_FLAG_FLOW, st,      \
                              circle, rhod_sl_f_circle),                                           \
      CYAML_FIELD_SEQUENCE_COUNT("polygon",                                                        \
                                 CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL | CYAML_FLAG_FLOW, st,   \
                                 polygon, n_polygon, &rhod_sl_sch_vec, 3, CYAML_UNLIMITED)

/* An error about the value at a dotted path, located at the deepest node of the path the
 * document holds; returns RHOD_ERR_SCENE. */
int rhod_sl_fail(lctx *c, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* "path.key: missing required key", at the key that names the mapping at `path`
 * ("" for the top level). */
int rhod_sl_fail_missing(lctx *c, const char *path, const char *key, const char *why);
int rhod_sl_fail_oom(lctx *c);
/* Where the node at a dotted path starts in the scene file: its line and column, 0 and 0
 * when an override supplied it or the document lacks it. */
void rhod_sl_where(lctx *c, const char *path, unsigned *line, unsigned *col);
/* Whether the document (after the overrides) holds the top-level key `section`. */
int rhod_sl_given(lctx *c, const char *section);
/* One of rect / circle / polygon of the entry at path `base`, checked and copied into out
 * (polygons counter-clockwise). */
int rhod_sl_load_shape(lctx *c, const char *base, const y_rect *rect, const y_circle *circle,
                       double (*poly)[2], unsigned np, rhod_shape *out);
/* A shape's bounding box and area. */
void rhod_sl_shape_bbox(const rhod_shape *sh, double lo[2], double hi[2]);
double rhod_sl_shape_area(const rhod_shape *sh);
/* Whether segments a-b and p-q meet (cross or touch). */
int rhod_sl_segments_meet(const double *a, const double *b, const double *p, const double *q);
/* A rect's or polygon's vertices, counter-clockwise (a rect's from its lower-left corner),
 * malloc'd, n of them; NULL for a circle or when out of memory. */
double (*rhod_sl_shape_vertices(const rhod_shape *sh, unsigned *n))[2];
/* Whether a string is a valid identifier: [A-Za-z_][A-Za-z0-9_]*, at most 64 characters. */
int rhod_sl_identifier(const char *s);
/* The name of entry i of a list section at `base` (bodies.N, open_boundaries.N): `given`
 * when it is an identifier (else the one-line error "'x' is not WHAT name ..."), or prefix
 * followed by i; strdup'd into *out. path gets the key a message about it names. */
int rhod_sl_list_name(lctx *c, const char *base, const char *given, const char *what,
                      const char *prefix, unsigned i, char **out, char *path, size_t pathlen);

/* Writing the scene as run: a tree of ry_nodes; an allocation failure sets oom and every
 * later call does nothing. */
typedef struct {
  int oom;
} rhod_sl_tb;
ry_node *rhod_sl_coll(rhod_sl_tb *t, ry_node *parent, const char *key, ry_kind kind, int flow);
void rhod_sl_num(rhod_sl_tb *t, ry_node *parent, const char *key, double v);
void rhod_sl_bool(rhod_sl_tb *t, ry_node *parent, const char *key, int v);
void rhod_sl_word(rhod_sl_tb *t, ry_node *parent, const char *key, const char *v);
void rhod_sl_vec(rhod_sl_tb *t, ry_node *parent, const char *key, const double v[2]);
/* the shape's key (rect, circle or polygon) and its values, under an entry */
void rhod_sl_shape(rhod_sl_tb *t, ry_node *entry, const rhod_shape *sh);
/* The name of enum value v in a libcyaml string table ("?" when none). */
const char *rhod_sl_enum_name(const cyaml_strval_t *sv, size_t n, int v);

#endif
