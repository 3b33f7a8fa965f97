/* Private to the scene loader and the scheme modules that own sections of a scene
 * (src/multiphase/scene_mp.c): the loader's mechanism (src/scene.c) lends each module
 * its messages and its writer of the scene as run, so that a module's checks report
 * "file:line:col: key: reason" (or the `--set` override) exactly like the loader's own. */
#ifndef RHOD_SCENE_MODULE_H
#define RHOD_SCENE_MODULE_H

#include "scene_yaml.h"

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

/* An error about the value at a dotted path, located at the deepest node of the path the
 * document holds; returns RHOD_ERR_SCENE. */
int rhod_sl_fail(lctx *c, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* "path.key: missing required key", at the key that names the mapping at `path`
 * ("" for the top level). */
int rhod_sl_fail_missing(lctx *c, const char *path, const char *key, const char *why);
int rhod_sl_fail_oom(lctx *c);
/* Whether a string is a valid identifier: [A-Za-z_][A-Za-z0-9_]*, at most 64 characters. */
int rhod_sl_identifier(const char *s);

/* Writing the scene as run: a tree of ry_nodes; an allocation failure sets oom and every
 * later call does nothing. */
typedef struct {
  int oom;
} rhod_sl_tb;
ry_node *rhod_sl_coll(rhod_sl_tb *t, ry_node *parent, const char *key, ry_kind kind, int flow);
void rhod_sl_num(rhod_sl_tb *t, ry_node *parent, const char *key, double v);
void rhod_sl_bool(rhod_sl_tb *t, ry_node *parent, const char *key, int v);
void rhod_sl_word(rhod_sl_tb *t, ry_node *parent, const char *key, const char *v);

#endif
