/* Private to the scene loader: a YAML node tree built from libyaml events, which keeps the
 * source position of every node so that errors found by libcyaml (in the text it was
 * handed) or by the value checks can be reported at the line and column of the scene file,
 * or against the `--set` override that supplied the value. */
#ifndef RHOD_SCENE_YAML_H
#define RHOD_SCENE_YAML_H

#include <stddef.h>

typedef enum { RY_SCALAR = 0, RY_SEQ, RY_MAP } ry_kind;

typedef struct ry_node ry_node;
struct ry_node {
  ry_kind kind;
  char *text;           /* RY_SCALAR and key nodes: the value, NUL-terminated */
  int quoted;           /* RY_SCALAR: written quoted or as a block scalar, not plain */
  int flow;             /* RY_SEQ, RY_MAP: flow style ([...], {...}) */
  int is_key;           /* a mapping key (a scalar); index is its pair */
  int origin;           /* -1: the scene file; k >= 0: override number k */
  unsigned line, col;   /* 1-based start position in the text it was parsed from */
  unsigned eline, ecol; /* 1-based start position in the text handed to libcyaml */
  const void *schema;   /* the libcyaml schema value it was matched to, or NULL */
  ry_node *parent;
  unsigned index;  /* position in the parent's items (or keys) */
  ry_node **items; /* RY_SEQ: entries; RY_MAP: values */
  ry_node **keys;  /* RY_MAP: key scalars, parallel to items */
  unsigned n, cap;
};

/* A parse failure: where, the dotted key being read there ("" for the top level) and why. */
typedef struct {
  unsigned line, col;
  char path[256];
  char msg[256];
  int oom;
} ry_error;

/* Parses one YAML document from text. *root is NULL for an empty document. Aliases are
 * expanded (copied), duplicate and non-scalar keys refused. Returns 0 or -1 (see e). */
int ry_parse(const char *text, size_t len, int origin, ry_node **root, ry_error *e);

ry_node *ry_new(ry_kind kind, int origin, unsigned line, unsigned col);
ry_node *ry_new_scalar(const char *text, int origin, unsigned line, unsigned col);
void ry_free(ry_node *n);

/* Mapping and sequence editing; return 0 or -1 when out of memory. ry_map_set replaces
 * (and frees) an existing value of that key. */
int ry_map_set(ry_node *map, const char *key, ry_node *value);
int ry_seq_append(ry_node *seq, ry_node *value);
void ry_replace(ry_node *old, ry_node *value); /* puts value in old's place, frees old */
ry_node *ry_map_get(const ry_node *map, const char *key);
ry_node *ry_map_key(const ry_node *map, const char *key); /* the key node */

/* Writes the tree as a YAML document (libyaml emitter). *out is malloc'ed, NUL-terminated.
 * A NULL root is written as an empty mapping. Returns 0 or -1. */
int ry_emit(const ry_node *root, char **out, size_t *len);

/* Copies the positions of `emitted` (the tree parsed back from ry_emit's text) into
 * eline/ecol of `n`; the two trees have the same shape. */
void ry_set_emitted_marks(ry_node *n, const ry_node *emitted);

/* The node that starts at (line, col) of the emitted text, preferring values to keys;
 * else the last node that starts before it. */
ry_node *ry_find_emitted(ry_node *root, unsigned line, unsigned col);

/* Deepest existing node along a dotted path ("fluid.0.rect.min"). */
ry_node *ry_find_path(ry_node *root, const char *path);

/* Dotted path of a node (a key node gives the path of its value). */
void ry_path(const ry_node *n, char *buf, size_t len);

#endif
