/* YAML node tree for the scene loader, built from libyaml events (see scene_yaml.h). */
#define _POSIX_C_SOURCE 200809L

#include "scene_yaml.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

enum { RY_MAX_DEPTH = 64, RY_MAX_NODES = 1000000 };
/* The text of all scalars (keys included) after aliases are expanded: the node cap alone
 * lets a few lines of anchors and aliases copy one long string into gigabytes. */
#define RY_MAX_TEXT ((size_t)64 << 20)

/* ---- nodes ---------------------------------------------------------------------------- */

ry_node *ry_new(ry_kind kind, int origin, unsigned line, unsigned col) {
  ry_node *n = calloc(1, sizeof *n);
  if (!n)
    return NULL;
  n->kind = kind;
  n->origin = origin;
  n->line = line;
  n->col = col;
  return n;
}

ry_node *ry_new_scalar(const char *text, int origin, unsigned line, unsigned col) {
  ry_node *n = ry_new(RY_SCALAR, origin, line, col);
  if (!n)
    return NULL;
  n->text = strdup(text ? text : "");
  if (!n->text) {
    free(n);
    return NULL;
  }
  return n;
}

void ry_free(ry_node *n) {
  if (!n)
    return;
  for (unsigned i = 0; i < n->n; i++) {
    ry_free(n->items[i]);
    if (n->keys)
      ry_free(n->keys[i]);
  }
  free(n->items);
  free(n->keys);
  free(n->text);
  free(n);
}

static int grow(ry_node *c) {
  if (c->n < c->cap)
    return 0;
  unsigned cap = c->cap ? 2 * c->cap : 4;
  ry_node **items = realloc(c->items, cap * sizeof *items);
  if (!items)
    return -1;
  c->items = items;
  if (c->kind == RY_MAP) {
    ry_node **keys = realloc(c->keys, cap * sizeof *keys);
    if (!keys)
      return -1;
    c->keys = keys;
  }
  c->cap = cap;
  return 0;
}

int ry_seq_append(ry_node *seq, ry_node *value) {
  if (grow(seq))
    return -1;
  value->parent = seq;
  value->index = seq->n;
  seq->items[seq->n++] = value;
  return 0;
}

static int map_append(ry_node *map, ry_node *key, ry_node *value) {
  if (grow(map))
    return -1;
  key->parent = value->parent = map;
  key->index = value->index = map->n;
  key->is_key = 1;
  map->keys[map->n] = key;
  map->items[map->n++] = value;
  return 0;
}

ry_node *ry_map_key(const ry_node *map, const char *key) {
  if (!map || map->kind != RY_MAP)
    return NULL;
  for (unsigned i = 0; i < map->n; i++)
    if (strcmp(map->keys[i]->text, key) == 0)
      return map->keys[i];
  return NULL;
}

ry_node *ry_map_get(const ry_node *map, const char *key) {
  ry_node *k = ry_map_key(map, key);
  return k ? map->items[k->index] : NULL;
}

void ry_replace(ry_node *old, ry_node *value) {
  ry_node *p = old->parent;
  value->parent = p;
  value->index = old->index;
  if (p)
    p->items[old->index] = value;
  ry_free(old);
}

int ry_map_set(ry_node *map, const char *key, ry_node *value) {
  ry_node *old = ry_map_get(map, key);
  if (old) {
    ry_replace(old, value);
    return 0;
  }
  ry_node *k = ry_new_scalar(key, value->origin, value->line, value->col);
  if (!k)
    return -1;
  if (map_append(map, k, value)) {
    ry_free(k);
    return -1;
  }
  return 0;
}

/* ---- paths ---------------------------------------------------------------------------- */

static void path_append(char *buf, size_t len, const char *fmt, ...) {
  size_t used = strlen(buf);
  if (used + 1 >= len)
    return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf + used, len - used, fmt, ap);
  va_end(ap);
}

static void path_rec(const ry_node *n, char *buf, size_t len) {
  const ry_node *p = n->parent;
  if (!p)
    return;
  path_rec(p, buf, len);
  const char *dot = buf[0] ? "." : "";
  if (p->kind == RY_MAP)
    path_append(buf, len, "%s%s", dot, p->keys[n->index]->text);
  else
    path_append(buf, len, "%s%u", dot, n->index);
}

void ry_path(const ry_node *n, char *buf, size_t len) {
  if (!len)
    return;
  buf[0] = '\0';
  if (n)
    path_rec(n, buf, len);
}

ry_node *ry_find_path(ry_node *root, const char *path) {
  ry_node *n = root;
  const char *s = path;
  while (n && *s) {
    const char *dot = strchr(s, '.');
    size_t seg = dot ? (size_t)(dot - s) : strlen(s);
    ry_node *next = NULL;
    if (n->kind == RY_MAP) {
      for (unsigned i = 0; i < n->n; i++)
        if (strlen(n->keys[i]->text) == seg && strncmp(n->keys[i]->text, s, seg) == 0) {
          next = n->items[i];
          break;
        }
    } else if (n->kind == RY_SEQ && seg > 0 && seg < 10 && strspn(s, "0123456789") >= seg) {
      unsigned long i = strtoul(s, NULL, 10);
      if (i < n->n)
        next = n->items[i];
    }
    if (!next)
      break;
    n = next;
    s += seg;
    if (*s == '.')
      s++;
  }
  return n;
}

/* ---- parsing -------------------------------------------------------------------------- */

typedef struct {
  ry_node *node;
  ry_node *pending_key; /* RY_MAP: a key read, its value not yet */
} frame;

typedef struct {
  char *name;
  ry_node *node;
} anchor;

typedef struct {
  frame st[RY_MAX_DEPTH];
  unsigned depth;
  anchor *anchors;
  unsigned n_anchors, cap_anchors;
  ry_node *root;
  size_t count, bytes; /* nodes and scalar bytes so far, aliases expanded */
  int origin, docs;
  ry_error *e;
} builder;

static void set_error(builder *b, unsigned line, unsigned col, const char *fmt, ...) {
  ry_error *e = b->e;
  e->line = line;
  e->col = col;
  e->path[0] = '\0';
  if (b->depth > 0) {
    frame *f = &b->st[b->depth - 1];
    ry_path(f->node, e->path, sizeof e->path);
    const char *dot = e->path[0] ? "." : "";
    if (f->node->kind == RY_MAP && f->pending_key)
      path_append(e->path, sizeof e->path, "%s%s", dot, f->pending_key->text);
    else if (f->node->kind == RY_SEQ)
      path_append(e->path, sizeof e->path, "%s%u", dot, f->node->n);
  }
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(e->msg, sizeof e->msg, fmt, ap);
  va_end(ap);
}

static void set_oom(builder *b) {
  b->e->oom = 1;
  set_error(b, 1, 1, "out of memory");
}

/* Counts a scalar's text against RY_MAX_TEXT; 0 when it still fits. */
static int count_text(builder *b, size_t len) {
  if (len > RY_MAX_TEXT - b->bytes) {
    b->bytes = RY_MAX_TEXT + 1;
    return -1;
  }
  b->bytes += len;
  return 0;
}

static ry_node *copy_tree(builder *b, const ry_node *src) {
  if (++b->count > RY_MAX_NODES)
    return NULL;
  if (src->kind == RY_SCALAR && count_text(b, strlen(src->text)))
    return NULL;
  ry_node *n = src->kind == RY_SCALAR ? ry_new_scalar(src->text, b->origin, src->line, src->col)
                                      : ry_new(src->kind, b->origin, src->line, src->col);
  if (!n)
    return NULL;
  n->quoted = src->quoted;
  n->flow = src->flow;
  for (unsigned i = 0; i < src->n; i++) {
    ry_node *v = copy_tree(b, src->items[i]);
    ry_node *k = src->kind == RY_MAP && v ? copy_tree(b, src->keys[i]) : NULL;
    int bad = !v || (src->kind == RY_MAP && !k);
    if (!bad)
      bad = src->kind == RY_MAP ? map_append(n, k, v) : ry_seq_append(n, v);
    if (bad) {
      ry_free(v);
      ry_free(k);
      ry_free(n);
      return NULL;
    }
  }
  return n;
}

/* Puts a new node into the container being read. Takes ownership of node. */
static int attach(builder *b, ry_node *node) {
  if (b->depth == 0) {
    b->root = node;
    return 0;
  }
  frame *f = &b->st[b->depth - 1];
  if (f->node->kind == RY_SEQ) {
    if (ry_seq_append(f->node, node)) {
      ry_free(node);
      set_oom(b);
      return -1;
    }
    return 0;
  }
  if (!f->pending_key) {
    if (node->kind != RY_SCALAR) {
      set_error(b, node->line, node->col, "a mapping key must be a plain name, not a %s",
                node->kind == RY_MAP ? "mapping" : "list");
      ry_free(node);
      return -1;
    }
    if (ry_map_key(f->node, node->text)) {
      f->pending_key = node; /* so that the error names the key */
      set_error(b, node->line, node->col, "duplicate key");
      f->pending_key = NULL;
      ry_free(node);
      return -1;
    }
    node->is_key = 1;
    f->pending_key = node;
    return 0;
  }
  if (map_append(f->node, f->pending_key, node)) {
    ry_free(node);
    set_oom(b);
    return -1;
  }
  f->pending_key = NULL;
  return 0;
}

static int add_anchor(builder *b, const yaml_char_t *name, ry_node *node) {
  if (!name)
    return 0;
  if (b->n_anchors == b->cap_anchors) {
    unsigned cap = b->cap_anchors ? 2 * b->cap_anchors : 8;
    anchor *a = realloc(b->anchors, cap * sizeof *a);
    if (!a)
      return -1;
    b->anchors = a;
    b->cap_anchors = cap;
  }
  char *copy = strdup((const char *)name);
  if (!copy)
    return -1;
  b->anchors[b->n_anchors].name = copy;
  b->anchors[b->n_anchors].node = node;
  b->n_anchors++;
  return 0;
}

static int on_event(builder *b, const yaml_event_t *ev) {
  unsigned line = (unsigned)ev->start_mark.line + 1, col = (unsigned)ev->start_mark.column + 1;
  ry_node *node = NULL;
  const yaml_char_t *anchor_name = NULL;
  switch (ev->type) {
  case YAML_DOCUMENT_START_EVENT:
    if (++b->docs > 1) {
      set_error(b, line, col, "a scene file holds one YAML document, found a second one");
      return -1;
    }
    return 0;
  case YAML_SCALAR_EVENT:
    /* an escaped NUL ("a\0b") would silently cut the text at the NUL */
    if (memchr(ev->data.scalar.value, '\0', ev->data.scalar.length)) {
      set_error(b, line, col, "a NUL character (\\0) in a string");
      return -1;
    }
    if (count_text(b, ev->data.scalar.length)) {
      set_error(b, line, col, "more than %zu MiB of text", RY_MAX_TEXT >> 20);
      return -1;
    }
    node = ry_new(RY_SCALAR, b->origin, line, col);
    if (node) {
      node->text = malloc(ev->data.scalar.length + 1);
      if (node->text) {
        memcpy(node->text, ev->data.scalar.value, ev->data.scalar.length);
        node->text[ev->data.scalar.length] = '\0';
      } else {
        ry_free(node);
        node = NULL;
      }
    }
    if (node)
      node->quoted = ev->data.scalar.style != YAML_PLAIN_SCALAR_STYLE;
    anchor_name = ev->data.scalar.anchor;
    break;
  case YAML_SEQUENCE_START_EVENT:
    node = ry_new(RY_SEQ, b->origin, line, col);
    if (node)
      node->flow = ev->data.sequence_start.style == YAML_FLOW_SEQUENCE_STYLE;
    anchor_name = ev->data.sequence_start.anchor;
    break;
  case YAML_MAPPING_START_EVENT:
    node = ry_new(RY_MAP, b->origin, line, col);
    if (node)
      node->flow = ev->data.mapping_start.style == YAML_FLOW_MAPPING_STYLE;
    anchor_name = ev->data.mapping_start.anchor;
    break;
  case YAML_ALIAS_EVENT: {
    const char *name = (const char *)ev->data.alias.anchor;
    const ry_node *target = NULL;
    for (unsigned i = b->n_anchors; i-- > 0;)
      if (strcmp(b->anchors[i].name, name) == 0) {
        target = b->anchors[i].node;
        break;
      }
    if (!target) {
      set_error(b, line, col, "unknown alias '*%s'", name);
      return -1;
    }
    node = copy_tree(b, target);
    if (!node && b->count > RY_MAX_NODES) {
      set_error(b, line, col, "aliases expand to more than %d nodes", RY_MAX_NODES);
      return -1;
    }
    if (!node && b->bytes > RY_MAX_TEXT) {
      set_error(b, line, col, "aliases expand to more than %zu MiB of text", RY_MAX_TEXT >> 20);
      return -1;
    }
    if (node) {
      node->line = line;
      node->col = col;
    }
    break;
  }
  case YAML_SEQUENCE_END_EVENT:
  case YAML_MAPPING_END_EVENT:
    b->depth--;
    return 0;
  default:
    return 0;
  }
  if (!node || ++b->count > RY_MAX_NODES) {
    if (node) {
      ry_free(node);
      set_error(b, line, col, "more than %d nodes", RY_MAX_NODES);
    } else {
      set_oom(b);
    }
    return -1;
  }
  if (add_anchor(b, anchor_name, node)) {
    ry_free(node);
    set_oom(b);
    return -1;
  }
  if (attach(b, node))
    return -1;
  if (ev->type == YAML_SEQUENCE_START_EVENT || ev->type == YAML_MAPPING_START_EVENT) {
    if (b->depth == RY_MAX_DEPTH) {
      set_error(b, line, col, "nested deeper than %d levels", RY_MAX_DEPTH);
      return -1;
    }
    b->st[b->depth].node = node;
    b->st[b->depth].pending_key = NULL;
    b->depth++;
  }
  return 0;
}

static void offset_to_mark(const char *text, size_t len, size_t off, unsigned *line,
                           unsigned *col) {
  *line = 1;
  *col = 1;
  for (size_t i = 0; i < off && i < len; i++) {
    if (text[i] == '\n') {
      (*line)++;
      *col = 1;
    } else {
      (*col)++;
    }
  }
}

int ry_parse(const char *text, size_t len, int origin, ry_node **root, ry_error *e) {
  memset(e, 0, sizeof *e);
  *root = NULL;
  builder *b = calloc(1, sizeof *b);
  if (!b) {
    e->oom = 1;
    snprintf(e->msg, sizeof e->msg, "out of memory");
    return -1;
  }
  b->origin = origin;
  b->e = e;
  yaml_parser_t p;
  int rc = 0;
  if (!yaml_parser_initialize(&p)) {
    set_oom(b);
    free(b);
    return -1;
  }
  yaml_parser_set_input_string(&p, (const unsigned char *)text, len);
  for (;;) {
    yaml_event_t ev;
    if (!yaml_parser_parse(&p, &ev)) {
      unsigned line = (unsigned)p.problem_mark.line + 1, col = (unsigned)p.problem_mark.column + 1;
      if (p.error == YAML_READER_ERROR)
        offset_to_mark(text, len, p.problem_offset, &line, &col);
      if (p.error == YAML_MEMORY_ERROR)
        set_oom(b);
      else if (p.context)
        set_error(b, line, col, "YAML syntax: %s %s (line %u)", p.problem ? p.problem : "error",
                  p.context, (unsigned)p.context_mark.line + 1);
      else
        set_error(b, line, col, "YAML syntax: %s", p.problem ? p.problem : "error");
      rc = -1;
      break;
    }
    int done = ev.type == YAML_STREAM_END_EVENT;
    if (on_event(b, &ev))
      rc = -1;
    yaml_event_delete(&ev);
    if (rc || done)
      break;
  }
  yaml_parser_delete(&p);
  /* pending keys of unfinished mappings are not in the tree yet */
  for (unsigned i = 0; i < b->depth; i++)
    ry_free(b->st[i].pending_key);
  for (unsigned i = 0; i < b->n_anchors; i++)
    free(b->anchors[i].name);
  free(b->anchors);
  if (rc)
    ry_free(b->root);
  else
    *root = b->root;
  free(b);
  return rc;
}

/* ---- emitting ------------------------------------------------------------------------- */

typedef struct {
  char *buf;
  size_t len, cap;
} sbuf;

static int write_handler(void *data, unsigned char *buffer, size_t size) {
  sbuf *s = data;
  if (s->len + size + 1 > s->cap) {
    size_t cap = s->cap ? s->cap : 1024;
    while (cap < s->len + size + 1)
      cap *= 2;
    char *nb = realloc(s->buf, cap);
    if (!nb)
      return 0;
    s->buf = nb;
    s->cap = cap;
  }
  memcpy(s->buf + s->len, buffer, size);
  s->len += size;
  s->buf[s->len] = '\0';
  return 1;
}

static int emit_scalar(yaml_emitter_t *em, const char *text, int quoted) {
  yaml_event_t ev;
  yaml_scalar_style_t style = quoted ? YAML_DOUBLE_QUOTED_SCALAR_STYLE : YAML_ANY_SCALAR_STYLE;
  if (!yaml_scalar_event_initialize(&ev, NULL, NULL, (yaml_char_t *)text, (int)strlen(text), 1, 1,
                                    style))
    return -1;
  return yaml_emitter_emit(em, &ev) ? 0 : -1;
}

static int emit_node(yaml_emitter_t *em, const ry_node *n) {
  yaml_event_t ev;
  switch (n->kind) {
  case RY_SCALAR:
    return emit_scalar(em, n->text, n->quoted);
  case RY_SEQ:
    if (!yaml_sequence_start_event_initialize(
            &ev, NULL, NULL, 1, n->flow ? YAML_FLOW_SEQUENCE_STYLE : YAML_BLOCK_SEQUENCE_STYLE) ||
        !yaml_emitter_emit(em, &ev))
      return -1;
    for (unsigned i = 0; i < n->n; i++)
      if (emit_node(em, n->items[i]))
        return -1;
    if (!yaml_sequence_end_event_initialize(&ev) || !yaml_emitter_emit(em, &ev))
      return -1;
    return 0;
  case RY_MAP:
    if (!yaml_mapping_start_event_initialize(
            &ev, NULL, NULL, 1, n->flow ? YAML_FLOW_MAPPING_STYLE : YAML_BLOCK_MAPPING_STYLE) ||
        !yaml_emitter_emit(em, &ev))
      return -1;
    for (unsigned i = 0; i < n->n; i++)
      if (emit_scalar(em, n->keys[i]->text, n->keys[i]->quoted) || emit_node(em, n->items[i]))
        return -1;
    if (!yaml_mapping_end_event_initialize(&ev) || !yaml_emitter_emit(em, &ev))
      return -1;
    return 0;
  }
  return -1;
}

int ry_emit(const ry_node *root, char **out, size_t *len) {
  *out = NULL;
  if (len)
    *len = 0;
  yaml_emitter_t em;
  if (!yaml_emitter_initialize(&em))
    return -1;
  sbuf s = {0};
  yaml_emitter_set_output(&em, write_handler, &s);
  yaml_emitter_set_unicode(&em, 1);
  yaml_emitter_set_width(&em, -1);
  yaml_emitter_set_indent(&em, 2);
  yaml_event_t ev;
  int rc = -1;
  ry_node empty = {.kind = RY_MAP, .flow = 1};
  if (!yaml_stream_start_event_initialize(&ev, YAML_UTF8_ENCODING) || !yaml_emitter_emit(&em, &ev))
    goto done;
  if (!yaml_document_start_event_initialize(&ev, NULL, NULL, NULL, 1) ||
      !yaml_emitter_emit(&em, &ev))
    goto done;
  if (emit_node(&em, root ? root : &empty))
    goto done;
  if (!yaml_document_end_event_initialize(&ev, 1) || !yaml_emitter_emit(&em, &ev))
    goto done;
  if (!yaml_stream_end_event_initialize(&ev) || !yaml_emitter_emit(&em, &ev))
    goto done;
  if (!yaml_emitter_flush(&em))
    goto done;
  rc = 0;
done:
  yaml_emitter_delete(&em);
  if (rc || !s.buf) {
    free(s.buf);
    return -1;
  }
  *out = s.buf;
  if (len)
    *len = s.len;
  return 0;
}

/* ---- positions in the emitted text ---------------------------------------------------- */

void ry_set_emitted_marks(ry_node *n, const ry_node *emitted) {
  if (!n || !emitted)
    return;
  n->eline = emitted->line;
  n->ecol = emitted->col;
  for (unsigned i = 0; i < n->n && i < emitted->n; i++) {
    ry_set_emitted_marks(n->items[i], emitted->items[i]);
    if (n->kind == RY_MAP && emitted->kind == RY_MAP)
      ry_set_emitted_marks(n->keys[i], emitted->keys[i]);
  }
}

typedef struct {
  unsigned line, col;
  ry_node *exact_value, *exact_key, *before;
} find_state;

static int mark_le(unsigned l1, unsigned c1, unsigned l2, unsigned c2) {
  return l1 < l2 || (l1 == l2 && c1 <= c2);
}

static void find_rec(ry_node *n, find_state *f) {
  if (n->eline == f->line && n->ecol == f->col) {
    if (n->is_key) {
      if (!f->exact_key)
        f->exact_key = n;
    } else if (!f->exact_value) {
      f->exact_value = n;
    }
  }
  if (!n->is_key && mark_le(n->eline, n->ecol, f->line, f->col))
    f->before = n;
  for (unsigned i = 0; i < n->n; i++) {
    if (n->kind == RY_MAP)
      find_rec(n->keys[i], f);
    find_rec(n->items[i], f);
  }
}

ry_node *ry_find_emitted(ry_node *root, unsigned line, unsigned col) {
  if (!root)
    return NULL;
  find_state f = {line, col, NULL, NULL, NULL};
  find_rec(root, &f);
  if (f.exact_value)
    return f.exact_value;
  if (f.exact_key)
    return f.exact_key;
  return f.before ? f.before : root;
}
