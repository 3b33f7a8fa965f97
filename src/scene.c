/* Scene loading: YAML file -> node tree (libyaml, with positions) -> `--set` overrides ->
 * libcyaml schema validation and load -> value checks, defaults -> rhod_scene.
 *
 * libcyaml validates the document against the schema below (unknown keys, missing keys,
 * types, list lengths, enum names) and reports through its log callback the reason and the
 * line/column, in the text it was handed, of the event where it stopped. That text is the
 * tree re-emitted (so that overrides are validated like the file), so the position is
 * mapped back to the tree node, whose dotted path and position in the scene file (or the
 * override that supplied it) make the user's one-line message. Every key is documented in
 * docs/scene.md. */
#define _POSIX_C_SOURCE 200809L

#include "rhod/scene.h"
#include "rhod/io.h"

#include "multiphase/scene_mp.h"
#include "rhodsph/scene_rs.h"
#include "scene_bodies.h"
#include "scene_module.h"
#include "scene_open.h"
#include "scene_yaml.h"

#include <ctype.h>
#include <cyaml/cyaml.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- the document as libcyaml loads it (optional values are pointers: NULL = absent) -- */

typedef struct {
  double U, L;
} y_taylor_green;

typedef struct {
  double omega;
  double *center;
} y_rotation;

typedef struct {
  double U, UI, y[2], width, spread, L;
} y_shear_layer;

typedef struct {
  double U, R;
  double *center;
} y_droplet;

typedef struct {
  y_taylor_green *taylor_green;
  y_rotation *rotation;
  y_shear_layer *shear_layer;
  y_droplet *droplet_oscillation;
} y_initial;

typedef struct {
  y_rect *rect;
  y_circle *circle;
  double (*polygon)[2];
  unsigned n_polygon;
  double *velocity;
  int *pressure;
  double *surface;
  double *ambient_pressure;
  y_initial *initial;
  char *phase;
} y_fluid;

typedef struct {
  y_rect *rect;
  y_circle *circle;
  double (*polygon)[2];
  unsigned n_polygon;
  int *slip;
  bool *fluid_inside;
  double *velocity;
  double *edges;
  unsigned n_edges;
  bool *refine;
} y_wall;

/* rs: the rhodsph scheme's keys in the shared sections (src/rhodsph/scene_rs.h) */
typedef struct {
  double end, output_every;
  int *integrator;
  y_rs_time rs;
} y_time;

typedef struct {
  double dx;
  double *radius_ratio;
  int *kernel;
  double *jitter;
  y_rs_particles rs;
} y_particles;

typedef struct {
  double *gravity;
  y_rs_physics rs;
} y_physics;

typedef struct {
  int *name;
  y_rs_scheme rs;
} y_scheme;

typedef struct {
  double *min, *max;
  bool *periodic;
} y_domain;

typedef struct {
  char *name;
  double at[2];
} y_probe_point;

typedef struct {
  char *name;
} y_probe_sum;

typedef struct {
  char *name;
  double *direction;
} y_probe_front;

typedef struct {
  char *name;
  double *at;
} y_probe_angular;

typedef struct {
  y_probe_point *pressure;
  y_probe_sum *kinetic_energy, *potential_energy;
  y_probe_front *front;
  y_probe_sum *mass, *momentum;
  y_probe_angular *angular_momentum;
  y_probe_sum *elastic_energy;
  y_probe_angular *torque_budget;
} y_probe;

typedef struct {
  double *every;
  y_probe *list;
  unsigned n_list;
} y_probes;

typedef struct {
  int *field;
  double *width;
  double *range;
  y_rect *box;
  bool *size_panel;
} y_picture;

typedef struct {
  y_picture *picture;
  char **fields;
  unsigned n_fields;
} y_output;

typedef struct {
  char *name;
  y_time time;
  y_particles particles;
  y_physics physics;
  y_scheme *scheme;
  y_domain *domain;
  y_fluid *fluid;
  unsigned n_fluid;
  y_wall *walls;
  unsigned n_walls;
  y_body *bodies; /* src/scene_bodies.c */
  unsigned n_bodies;
  y_open *open; /* src/scene_open.c */
  unsigned n_open;
  y_probes *probes;
  y_output *output;
  y_rs_refinement *refinement; /* the rhodsph scheme's section (src/rhodsph/scene_rs.c) */
  y_mp_phase *phases;          /* the multiphase scheme's sections (src/multiphase/scene_mp.c) */
  unsigned n_phases;
  y_mp_section *multiphase;
} y_doc;

/* ---- the schema ------------------------------------------------------------------------ */

#define OPT (CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL)
#define NAME_MAX_LEN 64

const cyaml_schema_value_t rhod_sl_sch_float = {CYAML_VALUE_FLOAT(CYAML_FLAG_STRICT, double)};
static const cyaml_schema_value_t sch_bool = {CYAML_VALUE_BOOL(CYAML_FLAG_DEFAULT, bool)};
const cyaml_schema_value_t rhod_sl_sch_vec = {
    CYAML_VALUE_SEQUENCE_FIXED(CYAML_FLAG_FLOW, double, &rhod_sl_sch_float, 2)};

#define VEC(key, flags, st, member)                                                                \
  CYAML_FIELD_SEQUENCE_FIXED(key, (flags) | CYAML_FLAG_FLOW, st, member, &rhod_sl_sch_float, 2)
#define NUM(key, st, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_STRICT, st, member)
#define NUM_OPT(key, st, member) CYAML_FIELD_FLOAT_PTR(key, OPT | CYAML_FLAG_STRICT, st, member)
#define BOOL_OPT(key, st, member) CYAML_FIELD_BOOL_PTR(key, OPT, st, member)
#define ENUM_OPT(key, st, member, strings)                                                         \
  CYAML_FIELD_ENUM_PTR(key, OPT | CYAML_FLAG_STRICT, st, member, strings, CYAML_ARRAY_LEN(strings))
#define NAME_OPT(st) CYAML_FIELD_STRING_PTR("name", OPT, st, name, 1, NAME_MAX_LEN)

static const cyaml_strval_t kernel_names[] = {
    {"wendland_c2", RHOD_KERNEL_WENDLAND_C2},
    {"wendland_c4", RHOD_KERNEL_WENDLAND_C4},
    {"quintic", RHOD_KERNEL_QUINTIC},
};
static const cyaml_strval_t integrator_names[] = {
    {"rk4", RHOD_INTEGRATOR_RK4},
    {"rk2", RHOD_INTEGRATOR_RK2},
    {"midpoint", RHOD_INTEGRATOR_MIDPOINT},
};
static const cyaml_strval_t scheme_names[] = {
    {"rhodsph", RHOD_SCHEME_RHODSPH},
    {"multiphase", RHOD_SCHEME_MULTIPHASE},
};
static const cyaml_strval_t init_names[] = {
    {"uniform", RHOD_INIT_UNIFORM},
    {"hydrostatic", RHOD_INIT_HYDROSTATIC},
};
static const cyaml_strval_t slip_names[] = {
    {"free", RHOD_SLIP_FREE},
    {"no", RHOD_SLIP_NO},
};
static const cyaml_strval_t field_names[] = {
    {"pressure", RHOD_FIELD_PRESSURE},         {"velocity", RHOD_FIELD_VELOCITY},
    {"density", RHOD_FIELD_DENSITY},           {"size", RHOD_FIELD_SIZE},
    {"free_surface", RHOD_FIELD_FREE_SURFACE}, {"phase", RHOD_FIELD_PHASE},
    {"vorticity", RHOD_FIELD_VORTICITY},
};
static const char *const probe_kind_names[] = {
    "pressure", "kinetic_energy",   "potential_energy", "front",         "mass",
    "momentum", "angular_momentum", "elastic_energy",   "torque_budget",
};
#define N_PROBE_KINDS 9

/* Each section's keys in the order they always had; RHOD_RS_*_FIELDS are the rhodsph
 * scheme's (src/rhodsph/scene_rs.h). */
static const cyaml_schema_field_t f_time[] = {
    NUM("end", y_time, end),
    NUM("output_every", y_time, output_every),
    RHOD_RS_TIME_STEP_FIELDS(y_time, rs),
    ENUM_OPT("integrator", y_time, integrator, integrator_names),
    RHOD_RS_TIME_LIMIT_FIELDS(y_time, rs),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_particles[] = {
    NUM("dx", y_particles, dx),
    NUM_OPT("radius_ratio", y_particles, radius_ratio),
    NUM_OPT("jitter", y_particles, jitter),
    RHOD_RS_PARTICLES_FIELDS(y_particles, rs),
    ENUM_OPT("kernel", y_particles, kernel, kernel_names),
    CYAML_FIELD_END,
};

/* physics and its c0 are required for rhodsph only (rhod_rs_load_physics) */
static const cyaml_schema_field_t f_physics[] = {
    RHOD_RS_PHYSICS_FIELDS(y_physics, rs),
    VEC("gravity", OPT, y_physics, gravity),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_scheme[] = {
    ENUM_OPT("name", y_scheme, name, scheme_names),
    RHOD_RS_SCHEME_FIELDS(y_scheme, rs),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_domain[] = {
    VEC("min", OPT, y_domain, min),
    VEC("max", OPT, y_domain, max),
    CYAML_FIELD_SEQUENCE_FIXED("periodic", OPT | CYAML_FLAG_FLOW, y_domain, periodic, &sch_bool, 2),
    CYAML_FIELD_END,
};

const cyaml_schema_field_t rhod_sl_f_rect[] = {
    VEC("min", 0, y_rect, min),
    VEC("max", 0, y_rect, max),
    CYAML_FIELD_END,
};

const cyaml_schema_field_t rhod_sl_f_circle[] = {
    VEC("center", 0, y_circle, center),
    NUM("radius", y_circle, radius),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_taylor_green[] = {
    NUM("U", y_taylor_green, U),
    NUM("L", y_taylor_green, L),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_rotation[] = {
    NUM("omega", y_rotation, omega),
    VEC("center", OPT, y_rotation, center),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_shear_layer[] = {
    NUM("U", y_shear_layer, U),
    NUM("UI", y_shear_layer, UI),
    VEC("y", 0, y_shear_layer, y),
    NUM("width", y_shear_layer, width),
    NUM("spread", y_shear_layer, spread),
    NUM("L", y_shear_layer, L),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_droplet[] = {
    NUM("U", y_droplet, U),
    NUM("R", y_droplet, R),
    VEC("center", OPT, y_droplet, center),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_initial[] = {
    CYAML_FIELD_MAPPING_PTR("taylor_green", OPT | CYAML_FLAG_FLOW, y_initial, taylor_green,
                            f_taylor_green),
    CYAML_FIELD_MAPPING_PTR("rotation", OPT | CYAML_FLAG_FLOW, y_initial, rotation, f_rotation),
    CYAML_FIELD_MAPPING_PTR("shear_layer", OPT | CYAML_FLAG_FLOW, y_initial, shear_layer,
                            f_shear_layer),
    CYAML_FIELD_MAPPING_PTR("droplet_oscillation", OPT | CYAML_FLAG_FLOW, y_initial,
                            droplet_oscillation, f_droplet),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_fluid[] = {
    RHOD_SL_SHAPE_FIELDS(y_fluid),
    VEC("velocity", OPT, y_fluid, velocity),
    ENUM_OPT("pressure", y_fluid, pressure, init_names),
    NUM_OPT("surface", y_fluid, surface),
    NUM_OPT("ambient_pressure", y_fluid, ambient_pressure),
    CYAML_FIELD_MAPPING_PTR("initial", OPT, y_fluid, initial, f_initial),
    CYAML_FIELD_STRING_PTR("phase", OPT, y_fluid, phase, 1, NAME_MAX_LEN),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t sch_fluid = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_fluid, f_fluid)};

static const cyaml_schema_field_t f_wall[] = {
    RHOD_SL_SHAPE_FIELDS(y_wall),
    ENUM_OPT("slip", y_wall, slip, slip_names),
    BOOL_OPT("fluid_inside", y_wall, fluid_inside),
    VEC("velocity", OPT, y_wall, velocity),
    CYAML_FIELD_SEQUENCE_COUNT("edges", OPT | CYAML_FLAG_FLOW, y_wall, edges, n_edges,
                               &rhod_sl_sch_float, 1, CYAML_UNLIMITED),
    BOOL_OPT("refine", y_wall, refine),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t sch_wall = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_wall, f_wall)};

static const cyaml_schema_field_t f_probe_point[] = {
    NAME_OPT(y_probe_point),
    VEC("at", 0, y_probe_point, at),
    CYAML_FIELD_END,
};
static const cyaml_schema_field_t f_probe_sum[] = {
    NAME_OPT(y_probe_sum),
    CYAML_FIELD_END,
};
static const cyaml_schema_field_t f_probe_front[] = {
    NAME_OPT(y_probe_front),
    VEC("direction", OPT, y_probe_front, direction),
    CYAML_FIELD_END,
};
static const cyaml_schema_field_t f_probe_angular[] = {
    NAME_OPT(y_probe_angular),
    VEC("at", OPT, y_probe_angular, at),
    CYAML_FIELD_END,
};

#define PROBE(key, member, fields)                                                                 \
  CYAML_FIELD_MAPPING_PTR(key, OPT | CYAML_FLAG_FLOW, y_probe, member, fields)
static const cyaml_schema_field_t f_probe[] = {
    PROBE("pressure", pressure, f_probe_point),
    PROBE("kinetic_energy", kinetic_energy, f_probe_sum),
    PROBE("potential_energy", potential_energy, f_probe_sum),
    PROBE("front", front, f_probe_front),
    PROBE("mass", mass, f_probe_sum),
    PROBE("momentum", momentum, f_probe_sum),
    PROBE("angular_momentum", angular_momentum, f_probe_angular),
    PROBE("elastic_energy", elastic_energy, f_probe_sum),
    PROBE("torque_budget", torque_budget, f_probe_angular),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t sch_probe = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_probe, f_probe)};

static const cyaml_schema_field_t f_probes[] = {
    NUM_OPT("every", y_probes, every),
    CYAML_FIELD_SEQUENCE_COUNT("list", OPT, y_probes, list, n_list, &sch_probe, 0, CYAML_UNLIMITED),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_picture[] = {
    ENUM_OPT("field", y_picture, field, field_names),
    NUM_OPT("width", y_picture, width),
    VEC("range", OPT, y_picture, range),
    CYAML_FIELD_MAPPING_PTR("box", OPT | CYAML_FLAG_FLOW, y_picture, box, rhod_sl_f_rect),
    BOOL_OPT("size_panel", y_picture, size_panel),
    CYAML_FIELD_END,
};

static const cyaml_schema_value_t sch_output_field = {
    CYAML_VALUE_STRING(CYAML_FLAG_POINTER, char, 1, NAME_MAX_LEN)};

static const cyaml_schema_field_t f_output[] = {
    CYAML_FIELD_MAPPING_PTR("picture", OPT, y_output, picture, f_picture),
    CYAML_FIELD_SEQUENCE_COUNT("fields", OPT, y_output, fields, n_fields, &sch_output_field, 0,
                               RHOD_MAX_OUTPUT_FIELDS),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_doc[] = {
    CYAML_FIELD_STRING_PTR("name", OPT, y_doc, name, 1, NAME_MAX_LEN),
    CYAML_FIELD_MAPPING("time", CYAML_FLAG_DEFAULT, y_doc, time, f_time),
    CYAML_FIELD_MAPPING("particles", CYAML_FLAG_DEFAULT, y_doc, particles, f_particles),
    /* required for rhodsph (convert): the multiphase scheme may leave it out */
    CYAML_FIELD_MAPPING("physics", CYAML_FLAG_OPTIONAL, y_doc, physics, f_physics),
    CYAML_FIELD_MAPPING_PTR("scheme", OPT, y_doc, scheme, f_scheme),
    CYAML_FIELD_MAPPING_PTR("domain", OPT, y_doc, domain, f_domain),
    CYAML_FIELD_SEQUENCE_COUNT("fluid", CYAML_FLAG_POINTER, y_doc, fluid, n_fluid, &sch_fluid, 1,
                               CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE_COUNT("walls", OPT, y_doc, walls, n_walls, &sch_wall, 0, CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE_COUNT("bodies", OPT, y_doc, bodies, n_bodies, &rhod_bd_sch_body, 0,
                               CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE_COUNT("open_boundaries", OPT, y_doc, open, n_open, &rhod_ob_sch_open, 0,
                               CYAML_UNLIMITED),
    CYAML_FIELD_MAPPING_PTR("probes", OPT, y_doc, probes, f_probes),
    CYAML_FIELD_MAPPING_PTR("output", OPT, y_doc, output, f_output),
    CYAML_FIELD_MAPPING_PTR("refinement", OPT, y_doc, refinement, rhod_rs_f_refinement),
    CYAML_FIELD_SEQUENCE_COUNT("phases", OPT, y_doc, phases, n_phases, &rhod_mp_sch_phase, 1,
                               RHOD_MP_MAX_PHASES),
    CYAML_FIELD_MAPPING_PTR("multiphase", OPT, y_doc, multiphase, rhod_mp_f_section),
    CYAML_FIELD_END,
};

static const cyaml_schema_value_t sch_doc = {CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, y_doc, f_doc)};

/* ---- loading context and messages ------------------------------------------------------ */

struct lctx {
  const char *file;
  const char *const *ov;
  int n_ov;
  ry_node *root;
  char *err;
  size_t errlen;
  int picture_off; /* output.picture: false */
};

/* Every message is one line: the control characters of the user's text it quotes (keys,
 * values, overrides, the file's path) are written as \n, \t, \r or \xNN. */
static void put_msg(lctx *c, const char *fmt, ...) {
  if (!c->err || !c->errlen)
    return;
  char raw[2048];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(raw, sizeof raw, fmt, ap);
  va_end(ap);
  size_t o = 0;
  for (const unsigned char *p = (const unsigned char *)raw; *p && o + 1 < c->errlen; p++) {
    char esc[8] = "";
    if (*p == '\n' || *p == '\t' || *p == '\r')
      snprintf(esc, sizeof esc, "\\%c", *p == '\n' ? 'n' : *p == '\t' ? 't' : 'r');
    else if (*p < 0x20 || *p == 0x7f)
      snprintf(esc, sizeof esc, "\\x%02X", *p);
    if (!esc[0]) {
      c->err[o++] = (char)*p;
      continue;
    }
    const size_t n = strlen(esc);
    if (o + n >= c->errlen)
      break;
    memcpy(c->err + o, esc, n);
    o += n;
  }
  c->err[o] = '\0';
}

/* At most CLIP_MAX bytes of user text for a message, "..." when cut (never inside a UTF-8
 * character): a 100000-character value must not push the reason out of the message. */
#define CLIP_MAX 80
typedef struct {
  char s[CLIP_MAX + 4];
} clip_buf;
static const char *clip(clip_buf *b, const char *s) {
  size_t n = strlen(s);
  if (n <= CLIP_MAX)
    return s;
  n = CLIP_MAX;
  while (n > 0 && ((unsigned char)s[n] & 0xC0) == 0x80)
    n--;
  memcpy(b->s, s, n);
  memcpy(b->s + n, "...", 4);
  return b->s;
}

static const char *shown(const char *path) { return path && path[0] ? path : "(top level)"; }

/* "FILE:LINE:COL: path: reason", or "--set K=V: path: reason" when node came from an
 * override. Returns RHOD_ERR_SCENE. */
static int vfail_at(lctx *c, const ry_node *n, const char *path, const char *fmt, va_list ap) {
  char reason[768];
  clip_buf cb;
  vsnprintf(reason, sizeof reason, fmt, ap);
  if (n && n->origin >= 0 && n->origin < c->n_ov)
    put_msg(c, "--set %s: %s: %s", clip(&cb, c->ov[n->origin] ? c->ov[n->origin] : ""), shown(path),
            reason);
  else
    put_msg(c, "%s:%u:%u: %s: %s", c->file, n ? n->line : 1u, n ? n->col : 1u, shown(path), reason);
  return RHOD_ERR_SCENE;
}

static int fail_at(lctx *c, const ry_node *n, const char *path, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int rc = vfail_at(c, n, path, fmt, ap);
  va_end(ap);
  return rc;
}

/* An error about the value at a dotted path: located at the deepest node of the path that
 * the document holds (the value itself, or where it would go). */
static int fail(lctx *c, const char *path, const char *fmt, ...) {
  const ry_node *n = ry_find_path(c->root, path);
  va_list ap;
  va_start(ap, fmt);
  int rc = vfail_at(c, n, path, fmt, ap);
  va_end(ap);
  return rc;
}

static int fail_ov(lctx *c, int k, const char *path, const char *fmt, ...) {
  char reason[768];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(reason, sizeof reason, fmt, ap);
  va_end(ap);
  clip_buf cb;
  put_msg(c, "--set %s: %s: %s", clip(&cb, c->ov[k] ? c->ov[k] : ""), shown(path), reason);
  return RHOD_ERR_SCENE;
}

static int fail_oom(lctx *c) {
  put_msg(c, "%s: out of memory", c->file);
  return RHOD_ERR_MEMORY;
}

static void node_path(const ry_node *n, char *buf, size_t len) { ry_path(n, buf, len); }

/* "path.key: missing required key", reported at the key naming the mapping at `path` (the
 * document's start for the top level), as libcyaml's missing keys are (cyaml_failure). */
static int fail_missing(lctx *c, const char *path, const char *key, const char *why) {
  const ry_node *m = path[0] ? ry_find_path(c->root, path) : c->root;
  const ry_node *where =
      m && m->parent && m->parent->kind == RY_MAP ? m->parent->keys[m->index] : m;
  char want[256];
  snprintf(want, sizeof want, "%s%s%s", path, path[0] ? "." : "", key);
  return fail_at(c, where, want, "missing required key%s%s%s", why ? " (" : "", why ? why : "",
                 why ? ")" : "");
}

/* ---- the loader's mechanism lent to the scheme modules (scene_module.h) ---------------- */

int rhod_sl_fail(lctx *c, const char *path, const char *fmt, ...) {
  const ry_node *n = ry_find_path(c->root, path);
  va_list ap;
  va_start(ap, fmt);
  int rc = vfail_at(c, n, path, fmt, ap);
  va_end(ap);
  return rc;
}

int rhod_sl_fail_missing(lctx *c, const char *path, const char *key, const char *why) {
  return fail_missing(c, path, key, why);
}

int rhod_sl_fail_oom(lctx *c) { return fail_oom(c); }

void rhod_sl_where(lctx *c, const char *path, unsigned *line, unsigned *col) {
  const ry_node *n = ry_find_path(c->root, path);
  const int file = n && n->origin < 0;
  *line = file ? n->line : 0;
  *col = file ? n->col : 0;
}

int rhod_sl_given(lctx *c, const char *section) {
  return c->root->kind == RY_MAP && ry_map_get(c->root, section);
}

/* A shape's vertices, counter-clockwise (a rect's from its lower-left corner); NULL for a
 * circle or when out of memory. */
double (*rhod_sl_shape_vertices(const rhod_shape *sh, unsigned *n))[2] {
  *n = 0;
  if (sh->kind == RHOD_SHAPE_CIRCLE)
    return NULL;
  const unsigned np = sh->kind == RHOD_SHAPE_RECT ? 4 : sh->n_points;
  double(*p)[2] = malloc(np * sizeof *p);
  if (!p)
    return NULL;
  if (sh->kind == RHOD_SHAPE_RECT) {
    const double q[4][2] = {{sh->min[0], sh->min[1]},
                            {sh->max[0], sh->min[1]},
                            {sh->max[0], sh->max[1]},
                            {sh->min[0], sh->max[1]}};
    memcpy(p, q, sizeof q);
  } else {
    memcpy(p, sh->points, np * sizeof *p);
  }
  *n = np;
  return p;
}

int rhod_sl_identifier(const char *s) {
  static const char alpha[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_";
  if (!s || !s[0] || !strchr(alpha, s[0]) || strlen(s) > NAME_MAX_LEN)
    return 0;
  return strspn(s, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") == strlen(s);
}

int rhod_sl_list_name(lctx *c, const char *base, const char *given, const char *what,
                      const char *prefix, unsigned i, char **out, char *path, size_t pathlen) {
  if (given) {
    snprintf(path, pathlen, "%s.name", base);
    if (!rhod_sl_identifier(given))
      return rhod_sl_fail(
          c, path, "'%s' is not %s name (a letter or '_', then letters, digits, '_')", given, what);
    *out = strdup(given);
  } else {
    snprintf(path, pathlen, "%s", base);
    char def[48];
    snprintf(def, sizeof def, "%s%u", prefix, i);
    *out = strdup(def);
  }
  return *out ? RHOD_OK : rhod_sl_fail_oom(c);
}

/* ---- schema helpers -------------------------------------------------------------------- */

static int is_seq_schema(const cyaml_schema_value_t *s) {
  return s && (s->type == CYAML_SEQUENCE || s->type == CYAML_SEQUENCE_FIXED);
}

static const cyaml_schema_field_t *schema_field(const cyaml_schema_value_t *s, const char *key) {
  if (!s || s->type != CYAML_MAPPING)
    return NULL;
  for (const cyaml_schema_field_t *f = s->mapping.fields; f->key; f++)
    if (strcmp(f->key, key) == 0)
      return f;
  return NULL;
}

static void annotate(ry_node *n, const cyaml_schema_value_t *s) {
  n->schema = s;
  for (unsigned i = 0; i < n->n; i++) {
    const cyaml_schema_value_t *child = NULL;
    if (n->kind == RY_MAP) {
      const cyaml_schema_field_t *f = schema_field(s, n->keys[i]->text);
      child = f ? &f->value : NULL;
    } else if (is_seq_schema(s)) {
      child = s->sequence.entry;
    }
    annotate(n->items[i], child);
  }
}

static void describe_schema(const cyaml_schema_value_t *s, char *buf, size_t len) {
  if (!s) {
    snprintf(buf, len, "nothing");
    return;
  }
  switch (s->type) {
  case CYAML_MAPPING:
    snprintf(buf, len, "a mapping");
    break;
  case CYAML_SEQUENCE_FIXED:
    snprintf(buf, len, "a list of %u %s", (unsigned)s->sequence.max,
             s->sequence.entry->type == CYAML_BOOL     ? "booleans"
             : s->sequence.entry->type == CYAML_STRING ? "names"
                                                       : "numbers");
    break;
  case CYAML_SEQUENCE:
    snprintf(buf, len, "a list");
    break;
  case CYAML_FLOAT:
    snprintf(buf, len, "a number");
    break;
  case CYAML_INT:
  case CYAML_UINT:
    snprintf(buf, len, "an integer");
    break;
  case CYAML_BOOL:
    snprintf(buf, len, "true or false");
    break;
  case CYAML_STRING:
    snprintf(buf, len, "a string");
    break;
  case CYAML_ENUM: {
    size_t used = (size_t)snprintf(buf, len, "one of");
    for (uint32_t i = 0; i < s->enumeration.count && used < len; i++)
      used += (size_t)snprintf(buf + used, len - used, "%s %s", i ? "," : ":",
                               s->enumeration.strings[i].str);
    break;
  }
  default:
    snprintf(buf, len, "another type");
    break;
  }
}

static void describe_node(const ry_node *n, char *buf, size_t len) {
  clip_buf cb;
  if (n->kind == RY_SCALAR)
    snprintf(buf, len, "'%s'", clip(&cb, n->text));
  else
    snprintf(buf, len, "%s", n->kind == RY_MAP ? "a mapping" : "a list");
}

/* ---- libcyaml's report ----------------------------------------------------------------- */

typedef struct {
  char text[4096];
  size_t len;
} cy_log;

/* Each logged line is cut to 256 bytes: a long value quoted in the reason must not push
 * the backtrace's "(line: L, column: C)", which places the error, out of the log. */
static void cy_log_fn(cyaml_log_t level, void *ctx, const char *fmt, va_list args) {
  cy_log *l = ctx;
  if (level < CYAML_LOG_ERROR || l->len + 1 >= sizeof l->text)
    return;
  char line[256];
  int n = vsnprintf(line, sizeof line, fmt, args);
  if (n < 0)
    return;
  if ((size_t)n >= sizeof line) /* cut: keep the line's end */
    memcpy(line + sizeof line - 5, "...\n", 5);
  n = snprintf(l->text + l->len, sizeof l->text - l->len, "%s", line);
  if (n > 0)
    l->len += (size_t)n < sizeof l->text - l->len ? (size_t)n : sizeof l->text - l->len - 1;
}

static ry_node *find_unknown_key(ry_node *n, const char *key) {
  if (n->kind == RY_MAP && n->schema &&
      ((const cyaml_schema_value_t *)n->schema)->type == CYAML_MAPPING) {
    ry_node *k = ry_map_key(n, key);
    if (k && !schema_field(n->schema, key))
      return k;
  }
  for (unsigned i = 0; i < n->n; i++) {
    ry_node *k = find_unknown_key(n->items[i], key);
    if (k)
      return k;
  }
  return NULL;
}

/* The first key, in document order, that the schema does not know (libcyaml stops at
 * the first one): for a key whose name the log cannot carry (a line break in it). */
static ry_node *first_unknown_key(ry_node *n) {
  const cyaml_schema_value_t *s = n->schema;
  for (unsigned i = 0; i < n->n; i++) {
    if (n->kind == RY_MAP && s && s->type == CYAML_MAPPING && !schema_field(s, n->keys[i]->text))
      return n->keys[i];
    ry_node *k = first_unknown_key(n->items[i]);
    if (k)
      return k;
  }
  return NULL;
}

static int lacks_required(const ry_node *m, const char *key) {
  const cyaml_schema_field_t *f = m->kind == RY_MAP ? schema_field(m->schema, key) : NULL;
  return f && !(f->value.flags & CYAML_FLAG_OPTIONAL) && !ry_map_key(m, key);
}

static ry_node *find_missing(ry_node *n, const char *key) {
  for (unsigned i = 0; i < n->n; i++) {
    ry_node *m = find_missing(n->items[i], key);
    if (m)
      return m;
  }
  return lacks_required(n, key) ? n : NULL;
}

static int count_bad(const ry_node *n) {
  const cyaml_schema_value_t *s = n->schema;
  return n->kind == RY_SEQ && is_seq_schema(s) &&
         (n->n < s->sequence.min || n->n > s->sequence.max);
}

static ry_node *find_bad_count(ry_node *n) {
  if (count_bad(n))
    return n;
  for (unsigned i = 0; i < n->n; i++) {
    ry_node *m = find_bad_count(n->items[i]);
    if (m)
      return m;
  }
  return NULL;
}

/* Builds the user's message from libcyaml's log: the reason from its first line, the place
 * from the innermost "(line: L, column: C)" of its backtrace. */
static int cyaml_failure(lctx *c, cyaml_err_t cerr, const cy_log *log) {
  if (cerr == CYAML_ERR_OOM)
    return fail_oom(c);
  char reason[512] = "";
  unsigned line = 0, col = 0;
  for (const char *p = log->text; *p;) {
    const char *eol = strchr(p, '\n');
    size_t n = eol ? (size_t)(eol - p) : strlen(p);
    const char *mk = memchr(p, '(', n);
    if (!reason[0] && strncmp(p, "Load: ", 6) == 0 && strncmp(p, "Load: Backtrace:", 16) != 0)
      snprintf(reason, sizeof reason, "%.*s", (int)(n - 6), p + 6);
    else if (!line && mk && sscanf(mk, "(line: %u, column: %u)", &line, &col) != 2)
      line = col = 0;
    p += n + (eol ? 1 : 0);
  }
  size_t rl = strlen(reason);
  while (rl && (reason[rl - 1] == '.' || reason[rl - 1] == ' '))
    reason[--rl] = '\0';
  if (!reason[0])
    snprintf(reason, sizeof reason, "%s", cyaml_strerror(cerr));

  ry_node *at = line ? ry_find_emitted(c->root, line, col) : c->root;
  char path[256], want[600], got[256];
  node_path(at, path, sizeof path);
  const char *arg = strstr(reason, ": ");
  arg = arg ? arg + 2 : "";

  if (strncmp(reason, "Unexpected key: ", 16) == 0) {
    ry_node *k = NULL;
    for (ry_node *m = at->is_key ? at->parent : at; m && !k; m = m->parent) {
      ry_node *cand = m->kind == RY_MAP ? ry_map_key(m, arg) : NULL;
      if (cand && !schema_field(m->schema, arg))
        k = cand;
    }
    if (!k)
      k = find_unknown_key(c->root, arg);
    if (!k)
      k = first_unknown_key(c->root);
    if (!k)
      return fail_at(c, at, path, "unknown key '%s'", arg);
    node_path(k, path, sizeof path);
    return fail_at(c, k, path, "unknown key");
  }
  if (strncmp(reason, "Missing required mapping field: ", 32) == 0) {
    ry_node *m = at->is_key ? at->parent : at;
    while (m && !lacks_required(m, arg))
      m = m->parent;
    if (!m)
      m = find_missing(c->root, arg);
    if (!m)
      return fail_at(c, at, path, "missing required key '%s'", arg);
    node_path(m, path, sizeof path);
    snprintf(want, sizeof want, "%s%s%s", path, path[0] ? "." : "", arg);
    /* a block mapping starts at its first key: point at the key that names it instead */
    const ry_node *where = m->parent && m->parent->kind == RY_MAP ? m->parent->keys[m->index] : m;
    return fail_at(c, where, want, "missing required key");
  }
  if (strncmp(reason, "Insufficient entries", 20) == 0 ||
      strncmp(reason, "Excessive entries", 17) == 0) {
    ry_node *s = at;
    while (s && !count_bad(s))
      s = s->parent;
    if (!s)
      s = find_bad_count(c->root);
    if (!s)
      return fail_at(c, at, path, "%s", reason);
    const cyaml_schema_value_t *sch = s->schema;
    node_path(s, path, sizeof path);
    if (sch->type == CYAML_SEQUENCE_FIXED)
      return fail_at(c, s, path, "expected %u entries, got %u", (unsigned)sch->sequence.min, s->n);
    if (s->n < sch->sequence.min)
      return fail_at(c, s, path, "expected at least %u entr%s, got %u", (unsigned)sch->sequence.min,
                     sch->sequence.min == 1 ? "y" : "ies", s->n);
    return fail_at(c, s, path, "expected at most %u entries, got %u", (unsigned)sch->sequence.max,
                   s->n);
  }
  if (at->is_key) { /* value errors name the value, never a key */
    at = at->parent->items[at->index];
    node_path(at, path, sizeof path);
  }
  const cyaml_schema_value_t *sch = at->schema;
  describe_schema(sch, want, sizeof want);
  describe_node(at, got, sizeof got);
  if (strncmp(reason, "Expecting ", 10) == 0)
    return fail_at(c, at, path, "expected %s, got %s", want, got);
  clip_buf cb;
  const char *text = clip(&cb, at->kind == RY_SCALAR ? at->text : arg);
  if (strncmp(reason, "Invalid FLOAT", 13) == 0)
    return fail_at(c, at, path, "invalid number '%s'", text);
  if (strncmp(reason, "FLOAT", 5) == 0)
    return fail_at(c, at, path, "number out of range '%s'", text);
  if (strncmp(reason, "Invalid BOOL", 12) == 0)
    return fail_at(c, at, path, "invalid boolean '%s' (true or false)", text);
  if (strncmp(reason, "Invalid ENUM", 12) == 0)
    return fail_at(c, at, path, "invalid value '%s' (%s)", text, want);
  if (strncmp(reason, "Invalid INT", 11) == 0 || strncmp(reason, "Invalid UINT", 12) == 0)
    return fail_at(c, at, path, "invalid integer '%s'", text);
  if (strncmp(reason, "STRING length <", 15) == 0)
    return fail_at(c, at, path, "must not be empty");
  if (strncmp(reason, "STRING length >", 15) == 0)
    return fail_at(c, at, path, "longer than %d characters", NAME_MAX_LEN);
  return fail_at(c, at, path, "%s", reason);
}

/* ---- strict scalars: libcyaml reads "1.5x" as 1.5 and any word but false/no/off as true -- */

static int parse_number(const char *s, double *v) {
  if (!s[0] || strchr(" \t\n\r\f\v", s[0]))
    return 0;
  char *end;
  errno = 0;
  *v = strtod(s, &end);
  return *end == '\0';
}

static int parse_bool(const char *s, bool *v) {
  static const char *const yes[] = {"true", "yes", "on"}, *const no[] = {"false", "no", "off"};
  for (int i = 0; i < 3; i++) {
    if (strcasecmp(s, yes[i]) == 0)
      return *v = true, 1;
    if (strcasecmp(s, no[i]) == 0)
      return *v = false, 1;
  }
  return 0;
}

static int check_scalars(lctx *c, const ry_node *n) {
  const cyaml_schema_value_t *s = n->schema;
  if (n->kind == RY_SCALAR && s) {
    char path[256];
    double v;
    bool b;
    clip_buf cb;
    if (s->type == CYAML_FLOAT) {
      if (!parse_number(n->text, &v)) {
        node_path(n, path, sizeof path);
        return fail_at(c, n, path, "invalid number '%s'", clip(&cb, n->text));
      }
      if (!isfinite(v)) {
        node_path(n, path, sizeof path);
        return fail_at(c, n, path, "must be a finite number, got '%s'", clip(&cb, n->text));
      }
    } else if (s->type == CYAML_BOOL && !parse_bool(n->text, &b)) {
      node_path(n, path, sizeof path);
      return fail_at(c, n, path, "invalid boolean '%s' (true or false)", clip(&cb, n->text));
    }
  }
  for (unsigned i = 0; i < n->n; i++) {
    int rc = check_scalars(c, n->items[i]);
    if (rc)
      return rc;
  }
  return RHOD_OK;
}

/* ---- `--set` overrides ------------------------------------------------------------------ */

/* " (FILE:LINE:COL)" or " (from --set OVERRIDE)": where a node that an override runs
 * into came from, for the override's message. */
typedef struct {
  char s[4300];
} where_buf;
static const char *where_from(const lctx *c, const ry_node *n, where_buf *b) {
  clip_buf cb;
  if (n->origin >= 0 && n->origin < c->n_ov)
    snprintf(b->s, sizeof b->s, " (from --set %s)",
             clip(&cb, c->ov[n->origin] ? c->ov[n->origin] : ""));
  else
    snprintf(b->s, sizeof b->s, " (%s:%u:%u)", c->file, n->line, n->col);
  return b->s;
}

/* Every error here names the override (never only a line of the scene file). */
static int apply_override(lctx *c, int k) {
  where_buf wbuf;
  const char *ov = c->ov[k] ? c->ov[k] : "";
  const char *eq = strchr(ov, '=');
  if (!eq || eq == ov)
    return fail_ov(c, k, "", "expected dotted.key=value");
  size_t klen = (size_t)(eq - ov);
  char key[256];
  if (klen >= sizeof key)
    return fail_ov(c, k, "", "key longer than %zu characters", sizeof key - 1);
  memcpy(key, ov, klen);
  key[klen] = '\0';
  const char *text = eq + 1;

  ry_node *val = NULL;
  ry_error ye;
  if (ry_parse(text, strlen(text), k, &val, &ye)) {
    if (ye.oom)
      return fail_oom(c);
    return fail_ov(c, k, key, "invalid YAML value: %s", ye.msg);
  }
  if (!val && !(val = ry_new_scalar("", k, 1, 1)))
    return fail_oom(c);

  const cyaml_schema_value_t *s = &sch_doc;
  ry_node *cur = c->root;
  char path[600] = "";
  int rc = RHOD_OK;
  for (char *seg = key, *next; seg; seg = next) {
    next = strchr(seg, '.');
    if (next)
      *next++ = '\0';
    size_t used = strlen(path);
    snprintf(path + used, sizeof path - used, "%s%s", used ? "." : "", seg);
    if (!seg[0]) {
      rc = fail_ov(c, k, path, "empty key");
      break;
    }
    const cyaml_schema_value_t *child_schema;
    ry_node *child;
    char got[256];
    if (s->type == CYAML_MAPPING) {
      const cyaml_schema_field_t *f = schema_field(s, seg);
      if (!f) {
        rc = fail_ov(c, k, path, "unknown key");
        break;
      }
      if (cur->kind != RY_MAP) {
        char parent[256];
        node_path(cur, parent, sizeof parent);
        describe_node(cur, got, sizeof got);
        rc = fail_ov(c, k, parent, "expected a mapping, got %s%s", got, where_from(c, cur, &wbuf));
        break;
      }
      child_schema = &f->value;
      if (!next) {
        if (ry_map_set(cur, seg, val))
          rc = fail_oom(c);
        val = NULL;
        break;
      }
      child = ry_map_get(cur, seg);
      if (!child && (child_schema->type == CYAML_MAPPING || is_seq_schema(child_schema))) {
        child =
            ry_new(child_schema->type == CYAML_MAPPING ? RY_MAP : RY_SEQ, k, cur->line, cur->col);
        if (!child || ry_map_set(cur, seg, child)) {
          ry_free(child);
          rc = fail_oom(c);
          break;
        }
      }
    } else if (is_seq_schema(s)) {
      if (!seg[0] || strspn(seg, "0123456789") != strlen(seg) || strlen(seg) > 6) {
        rc = fail_ov(c, k, path, "expected a list index, got '%s'", seg);
        break;
      }
      unsigned idx = (unsigned)strtoul(seg, NULL, 10);
      if (cur->kind != RY_SEQ) {
        char parent[256];
        node_path(cur, parent, sizeof parent);
        describe_node(cur, got, sizeof got);
        rc = fail_ov(c, k, parent, "expected a list, got %s%s", got, where_from(c, cur, &wbuf));
        break;
      }
      child_schema = s->sequence.entry;
      int append = idx == cur->n && s->type == CYAML_SEQUENCE;
      if (idx > cur->n || (idx == cur->n && !append)) {
        rc = fail_ov(c, k, path, "index %u out of range (the list has %u entr%s)", idx, cur->n,
                     cur->n == 1 ? "y" : "ies");
        break;
      }
      if (!next) {
        if (append) {
          if (ry_seq_append(cur, val)) {
            rc = fail_oom(c);
            break;
          }
        } else {
          ry_replace(cur->items[idx], val);
        }
        val = NULL;
        break;
      }
      child = append ? NULL : cur->items[idx];
      if (!child && (child_schema->type == CYAML_MAPPING || is_seq_schema(child_schema))) {
        child =
            ry_new(child_schema->type == CYAML_MAPPING ? RY_MAP : RY_SEQ, k, cur->line, cur->col);
        if (!child || ry_seq_append(cur, child)) {
          ry_free(child);
          rc = fail_oom(c);
          break;
        }
      }
    } else {
      rc = fail_ov(c, k, path, "unknown key");
      break;
    }
    if (!child) { /* a scalar in the schema: the next segment cannot exist */
      size_t u = strlen(path);
      snprintf(path + u, sizeof path - u, ".%s", next);
      rc = fail_ov(c, k, path, "unknown key");
      break;
    }
    s = child_schema;
    cur = child;
  }
  ry_free(val);
  return rc;
}

/* ---- value checks and defaults ---------------------------------------------------------- */

static int check_positive(lctx *c, const char *path, double v) {
  return v > 0 ? RHOD_OK : fail(c, path, "must be > 0, got %g", v);
}

static int check_range(lctx *c, const char *path, double v, double lo, int lo_open, double hi,
                       int hi_open) {
  int ok = (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  if (ok)
    return RHOD_OK;
  return fail(c, path, "must be in %s%g, %g%s, got %g", lo_open ? "(" : "[", lo, hi,
              hi_open ? ")" : "]", v);
}

static double polygon_area(const double (*p)[2], unsigned n) {
  double a = 0;
  for (unsigned i = 0; i < n; i++) {
    const double *u = p[i], *v = p[(i + 1) % n];
    a += u[0] * v[1] - v[0] * u[1];
  }
  return 0.5 * a;
}

static double orient(const double *a, const double *b, const double *p) {
  return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
}

static int on_segment(const double *a, const double *b, const double *p) {
  return fmin(a[0], b[0]) <= p[0] && p[0] <= fmax(a[0], b[0]) && fmin(a[1], b[1]) <= p[1] &&
         p[1] <= fmax(a[1], b[1]);
}

static int segments_meet(const double *a, const double *b, const double *p, const double *q) {
  double d1 = orient(p, q, a), d2 = orient(p, q, b), d3 = orient(a, b, p), d4 = orient(a, b, q);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 1;
  return (d1 == 0 && on_segment(p, q, a)) || (d2 == 0 && on_segment(p, q, b)) ||
         (d3 == 0 && on_segment(a, b, p)) || (d4 == 0 && on_segment(a, b, q));
}

int rhod_sl_segments_meet(const double *a, const double *b, const double *p, const double *q) {
  return segments_meet(a, b, p, q);
}

void rhod_sl_shape_bbox(const rhod_shape *sh, double lo[2], double hi[2]) {
  for (int d = 0; d < 2; d++) {
    switch (sh->kind) {
    case RHOD_SHAPE_RECT:
      lo[d] = sh->min[d];
      hi[d] = sh->max[d];
      break;
    case RHOD_SHAPE_CIRCLE:
      lo[d] = sh->center[d] - sh->radius;
      hi[d] = sh->center[d] + sh->radius;
      break;
    case RHOD_SHAPE_POLYGON:
      lo[d] = hi[d] = sh->points[0][d];
      for (unsigned i = 1; i < sh->n_points; i++) {
        lo[d] = fmin(lo[d], sh->points[i][d]);
        hi[d] = fmax(hi[d], sh->points[i][d]);
      }
      break;
    }
  }
}

double rhod_sl_shape_area(const rhod_shape *sh) {
  switch (sh->kind) {
  case RHOD_SHAPE_RECT:
    return (sh->max[0] - sh->min[0]) * (sh->max[1] - sh->min[1]);
  case RHOD_SHAPE_CIRCLE:
    return M_PI * sh->radius * sh->radius;
  case RHOD_SHAPE_POLYGON:
    return fabs(polygon_area((const double(*)[2])sh->points, sh->n_points));
  }
  return 0;
}

/* One of rect / circle / polygon, checked and copied into out (polygons counter-clockwise). */
int rhod_sl_load_shape(lctx *c, const char *base, const y_rect *rect, const y_circle *circle,
                       double (*poly)[2], unsigned np, rhod_shape *out) {
  char path[128];
  const char *given[3];
  int n = 0;
  if (rect)
    given[n++] = "rect";
  if (circle)
    given[n++] = "circle";
  if (poly)
    given[n++] = "polygon";
  if (n == 0)
    return fail(c, base, "needs a shape: one of rect, circle, polygon");
  if (n > 1) {
    snprintf(path, sizeof path, "%s.%s", base, given[1]);
    return fail(c, path, "one shape per entry, but %s is also given", given[0]);
  }
  if (rect) {
    out->kind = RHOD_SHAPE_RECT;
    memcpy(out->min, rect->min, sizeof out->min);
    memcpy(out->max, rect->max, sizeof out->max);
    if (!(rect->min[0] < rect->max[0] && rect->min[1] < rect->max[1])) {
      snprintf(path, sizeof path, "%s.rect.max", base);
      return fail(c, path, "must exceed rect.min in both axes (min [%g, %g], max [%g, %g])",
                  rect->min[0], rect->min[1], rect->max[0], rect->max[1]);
    }
  } else if (circle) {
    out->kind = RHOD_SHAPE_CIRCLE;
    memcpy(out->center, circle->center, sizeof out->center);
    out->radius = circle->radius;
    snprintf(path, sizeof path, "%s.circle.radius", base);
    TRY(check_positive(c, path, circle->radius));
  } else {
    out->kind = RHOD_SHAPE_POLYGON;
    snprintf(path, sizeof path, "%s.polygon", base);
    for (unsigned i = 0; i < np; i++) {
      const double *a = poly[i], *b = poly[(i + 1) % np];
      if (a[0] == b[0] && a[1] == b[1])
        return fail(c, path, "points %u and %u coincide", i, (i + 1) % np);
    }
    for (unsigned i = 0; i < np; i++)
      for (unsigned j = i + 2; j < np; j++) {
        if (i == 0 && j == np - 1)
          continue; /* adjacent through the closing edge */
        if (segments_meet(poly[i], poly[i + 1], poly[j], poly[(j + 1) % np]))
          return fail(c, path, "edges %u-%u and %u-%u cross: the polygon must be simple", i, i + 1,
                      j, (j + 1) % np);
      }
    double area = polygon_area((const double(*)[2])poly, np);
    if (area == 0)
      return fail(c, path, "has zero area");
    out->points = malloc(np * sizeof *out->points);
    if (!out->points)
      return fail_oom(c);
    out->n_points = np;
    for (unsigned i = 0; i < np; i++) { /* counter-clockwise */
      const double *src = area > 0 ? poly[i] : poly[np - 1 - i];
      out->points[i][0] = src[0];
      out->points[i][1] = src[1];
    }
  }
  return RHOD_OK;
}

static int valid_name(const char *s) {
  if (!s[0] || s[0] == '.' || strlen(s) > NAME_MAX_LEN)
    return 0;
  return strspn(s, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") ==
         strlen(s);
}

/* Default scene name: the file's base name without extension, or the name of its folder
 * when the file is called scene.*; characters outside [A-Za-z0-9_.-] become '_'. */
static char *default_name(const char *file) {
  const char *base = strrchr(file, '/');
  base = base ? base + 1 : file;
  size_t len = strcspn(base, ".");
  const char *start = base;
  if (len == 5 && strncmp(base, "scene", 5) == 0 && base != file) {
    const char *end = base - 1; /* the '/' */
    const char *dir = end;
    while (dir > file && dir[-1] != '/')
      dir--;
    if (end > dir && !(end - dir == 1 && dir[0] == '.') && !(end - dir == 2 && dir[0] == '.')) {
      start = dir;
      len = (size_t)(end - dir);
    }
  }
  if (len == 0) {
    start = "scene";
    len = 5;
  }
  if (len > NAME_MAX_LEN)
    len = NAME_MAX_LEN;
  char *name = malloc(len + 1);
  if (!name)
    return NULL;
  for (size_t i = 0; i < len; i++)
    name[i] = strchr("_.-", start[i]) || (start[i] >= '0' && start[i] <= '9') ||
                      (start[i] >= 'a' && start[i] <= 'z') || (start[i] >= 'A' && start[i] <= 'Z')
                  ? start[i]
                  : '_';
  name[len] = '\0';
  if (name[0] == '.')
    name[0] = '_';
  return name;
}

static int inside_box(const double lo[2], const double hi[2], const double bmin[2],
                      const double bmax[2]) {
  for (int d = 0; d < 2; d++) {
    double tol = 1e-9 * fmax(1.0, bmax[d] - bmin[d]);
    if (lo[d] < bmin[d] - tol || hi[d] > bmax[d] + tol)
      return 0;
  }
  return 1;
}

static int load_probe(lctx *c, const y_probe *y, unsigned i, rhod_probe *p, char *kind_path,
                      size_t kpl) {
  char base[64];
  snprintf(base, sizeof base, "probes.list.%u", i);
  const void *given[N_PROBE_KINDS] = {
      y->pressure, y->kinetic_energy,   y->potential_energy, y->front,        y->mass,
      y->momentum, y->angular_momentum, y->elastic_energy,   y->torque_budget};
  int first = -1;
  for (int k = 0; k < N_PROBE_KINDS; k++) {
    if (!given[k])
      continue;
    if (first >= 0) {
      char path[128];
      snprintf(path, sizeof path, "%s.%s", base, probe_kind_names[k]);
      return fail(c, path, "one probe per entry, but %s is also given", probe_kind_names[first]);
    }
    first = k;
  }
  if (first < 0) {
    char kinds[256] = "";
    for (int k = 0; k < N_PROBE_KINDS; k++)
      snprintf(kinds + strlen(kinds), sizeof kinds - strlen(kinds), "%s%s", k ? ", " : "",
               probe_kind_names[k]);
    return fail(c, base, "needs a probe kind: one of %s", kinds);
  }
  p->kind = (rhod_probe_kind)first;
  snprintf(kind_path, kpl, "%s.%s", base, probe_kind_names[first]);
  const char *name = NULL;
  switch (p->kind) {
  case RHOD_PROBE_PRESSURE:
    name = y->pressure->name;
    memcpy(p->at, y->pressure->at, sizeof p->at);
    break;
  case RHOD_PROBE_KINETIC_ENERGY:
    name = y->kinetic_energy->name;
    break;
  case RHOD_PROBE_POTENTIAL_ENERGY:
    name = y->potential_energy->name;
    break;
  case RHOD_PROBE_FRONT: {
    name = y->front->name;
    double dir[2] = {1, 0};
    if (y->front->direction)
      memcpy(dir, y->front->direction, sizeof dir);
    double len = hypot(dir[0], dir[1]);
    if (!(len > 0)) {
      char path[128];
      snprintf(path, sizeof path, "%s.direction", kind_path);
      return fail(c, path, "must not be zero");
    }
    p->direction[0] = dir[0] / len;
    p->direction[1] = dir[1] / len;
    break;
  }
  case RHOD_PROBE_MASS:
    name = y->mass->name;
    break;
  case RHOD_PROBE_MOMENTUM:
    name = y->momentum->name;
    break;
  case RHOD_PROBE_ANGULAR_MOMENTUM:
    name = y->angular_momentum->name;
    if (y->angular_momentum->at)
      memcpy(p->at, y->angular_momentum->at, sizeof p->at);
    break;
  case RHOD_PROBE_ELASTIC_ENERGY:
    name = y->elastic_energy->name;
    break;
  case RHOD_PROBE_TORQUE_BUDGET:
    name = y->torque_budget->name;
    if (y->torque_budget->at)
      memcpy(p->at, y->torque_budget->at, sizeof p->at);
    break;
  }
  if (!name)
    name = probe_kind_names[first];
  if (!valid_name(name)) {
    char path[160];
    snprintf(path, sizeof path, "%s.name", kind_path);
    return fail(c, path, "'%s' is not a valid name (letters, digits, '_', '.', '-')", name);
  }
  p->name = strdup(name);
  return p->name ? RHOD_OK : fail_oom(c);
}

/* the torque budget's columns, in the order of rhod_sph_torque_budget's terms */
static const char *const torque_suffixes[RHOD_PROBE_MAX_COLUMNS] = {
    "_pressure", "_viscous", "_riemann", "_damper", "_shifting", "_body", "_motion"};

unsigned rhod_probe_ncolumns(rhod_probe_kind kind) {
  return kind == RHOD_PROBE_MOMENTUM        ? 2
         : kind == RHOD_PROBE_TORQUE_BUDGET ? RHOD_PROBE_MAX_COLUMNS
                                            : 1;
}

const char *rhod_probe_suffix(rhod_probe_kind kind, unsigned column) {
  if (kind == RHOD_PROBE_MOMENTUM)
    return column ? "_y" : "_x";
  if (kind == RHOD_PROBE_TORQUE_BUDGET && column < RHOD_PROBE_MAX_COLUMNS)
    return torque_suffixes[column];
  return "";
}

/* CSV column names of a probe */
static unsigned probe_columns(const rhod_probe *p,
                              char cols[RHOD_PROBE_MAX_COLUMNS][NAME_MAX_LEN + 16]) {
  const unsigned nc = rhod_probe_ncolumns(p->kind);
  for (unsigned a = 0; a < nc; a++)
    snprintf(cols[a], sizeof cols[a], "%s%s", p->name, rhod_probe_suffix(p->kind, a));
  return nc;
}

/* Extent of one shape along the unit vector e: [lo, hi] of x.e. */
static void shape_extent(const rhod_shape *sh, const double e[2], double *lo, double *hi) {
  *lo = INFINITY;
  *hi = -INFINITY;
  switch (sh->kind) {
  case RHOD_SHAPE_RECT:
    for (int cx = 0; cx < 2; cx++)
      for (int cy = 0; cy < 2; cy++) {
        double x = (cx ? sh->max[0] : sh->min[0]) * e[0] + (cy ? sh->max[1] : sh->min[1]) * e[1];
        *lo = fmin(*lo, x);
        *hi = fmax(*hi, x);
      }
    break;
  case RHOD_SHAPE_CIRCLE: {
    double x = sh->center[0] * e[0] + sh->center[1] * e[1];
    *lo = x - sh->radius;
    *hi = x + sh->radius;
    break;
  }
  case RHOD_SHAPE_POLYGON:
    for (unsigned k = 0; k < sh->n_points; k++) {
      double x = sh->points[k][0] * e[0] + sh->points[k][1] * e[1];
      *lo = fmin(*lo, x);
      *hi = fmax(*hi, x);
    }
    break;
  }
}

double rhod_scene_particle_estimate(const rhod_scene *s) {
  if (!s || !(s->dx > 0))
    return 0;
  const double cell = s->dx * s->dx;
  double n = 0;
  for (unsigned i = 0; i < s->n_fluid; i++) {
    n += rhod_sl_shape_area(&s->fluid[i].shape) / cell;
    /* the rhodsph scheme's refinement regions: their finer lattices */
    double lo[2], hi[2];
    rhod_sl_shape_bbox(&s->fluid[i].shape, lo, hi);
    rhod_rs_region_estimate(s->rs, lo, hi, cell, &n);
  }
  return n;
}

/* What a run would write or hold, checked before anything is written (docs/choices.md
 * "load-time limits"): the picture's size, the snapshot and probe-row counts, the steps
 * time.end needs, the initial particle count. */
static int check_limits(lctx *c, rhod_scene *s) {
  /* the picture: laid out as src/picture.c lays it out (frame, axes, colour bar), at
   * most RHOD_PICTURE_MAX_SIDE pixels a side */
  if (s->picture_enabled) {
    const double *lo = s->picture_box_set ? s->picture_box_min : s->domain_min;
    const double *hi = s->picture_box_set ? s->picture_box_max : s->domain_max;
    const double ex = hi[0] - lo[0], ey = hi[1] - lo[1];
    const int panels = s->picture_size_panel && s->picture_field != RHOD_FIELD_SIZE ? 2 : 1;
    rhod_picture_geometry g;
    if (rhod_picture_layout(s->picture_width, panels, lo, hi, &g) != 0)
      return fail(c, "output.picture.width",
                  "%u pixels wide makes the picture about %.0f pixels high (the %s is %g m x %g "
                  "m%s), more than %u: lower the width or draw a smaller output.picture.box",
                  s->picture_width, floor(s->picture_width * ey / ex + 0.5) * panels,
                  s->picture_box_set ? "box" : "domain", ex, ey, panels == 2 ? ", two panels" : "",
                  RHOD_PICTURE_MAX_SIDE);
  }
  /* time: every step is at most the acoustic bound at the coarsest size: Eq. 11 of paper
   * 002 for rhodsph, paper 001 Eq. 16 (h_s < R) with the fastest phase for multiphase */
  double c_max = s->rs ? s->rs->c0 : 0, cfl = s->rs ? s->rs->cfl : 0;
  if (s->mp) {
    cfl = s->mp->cfl;
    c_max = 0;
    for (unsigned k = 0; k < s->mp->n_phases; k++)
      c_max = fmax(c_max, s->mp->phases[k].c);
  }
  const double dt_max = cfl * s->radius_ratio * s->dx / c_max;
  const double steps = s->t_end / dt_max;
  if (!(steps <= RHOD_MAX_STEPS))
    return fail(c, "time.end",
                "%g s needs at least %.3g steps (dt <= cfl R/c0 = %.3g s, %s), more than "
                "%.0e: in double precision t + dt would keep too few of dt's digits",
                s->t_end, steps, dt_max, s->mp ? "paper 001 Eq. 16" : "Eq. 11", RHOD_MAX_STEPS);
  const double snaps = s->t_end / s->output_every;
  if (!(snaps <= RHOD_MAX_SNAPSHOTS))
    return fail(c, "time.output_every",
                "%g s against time.end = %g s would write %.3g snapshots, more than %.0e",
                s->output_every, s->t_end, snaps, RHOD_MAX_SNAPSHOTS);
  /* a probe row per sample, at most one per step */
  if (!(s->probe_every >= 1e-9 * s->t_end))
    return fail(c, "probes.every",
                "%g s is below 1e-9 time.end (%g s), the run's time tolerance: samples that "
                "close cannot be told apart",
                s->probe_every, 1e-9 * s->t_end);
  const double rows = s->t_end / fmax(s->probe_every, dt_max);
  if (!(rows <= RHOD_MAX_PROBE_ROWS))
    return fail(c, "probes.every",
                "%g s against time.end = %g s would write at least %.3g rows to probes.csv (one "
                "per step at most, each step at most %.3g s), more than %.0e",
                s->probe_every, s->t_end, rows, dt_max, RHOD_MAX_PROBE_ROWS);
  /* particles: counted before anything is allocated, the lattice is not walked */
  const double n = rhod_scene_particle_estimate(s);
  if (!(n <= RHOD_MAX_PARTICLES))
    return fail(c, "particles.dx",
                "%g m makes about %.3g particles (the fluid's area over dx^2%s), more than the "
                "%.0e a run can index",
                s->dx, n, s->rs && s->rs->n_regions ? " and the refinement regions" : "",
                RHOD_MAX_PARTICLES);
  return RHOD_OK;
}

/* ---- the two schemes' keys ------------------------------------------------------------- */

/* Where a key's error points: the key in the file, or the override that set its value. */
static const ry_node *key_at(const ry_node *map, unsigned j) {
  return map->items[j]->origin >= 0 ? map->items[j] : map->keys[j];
}

/* The first key, in document order, that belongs to the other scheme. */
static int refuse_other_scheme(lctx *c, rhod_scheme_kind scheme) {
  const ry_node *r = c->root;
  char path[600];
  for (unsigned i = 0; r->kind == RY_MAP && i < r->n; i++) {
    const char *sec = r->keys[i]->text;
    const ry_node *m = r->items[i];
    if (scheme == RHOD_SCHEME_RHODSPH) {
      if (strcmp(sec, "phases") == 0 || strcmp(sec, "multiphase") == 0)
        return fail_at(c, key_at(r, i), sec,
                       "belongs to the multiphase scheme (scheme.name: multiphase)");
      for (unsigned k = 0; strcmp(sec, "fluid") == 0 && m->kind == RY_SEQ && k < m->n; k++) {
        const ry_node *b = m->items[k];
        for (unsigned j = 0; b->kind == RY_MAP && j < b->n; j++)
          if (strcmp(b->keys[j]->text, "phase") == 0) {
            snprintf(path, sizeof path, "fluid.%u.phase", k);
            return fail_at(c, key_at(b, j), path,
                           "belongs to the multiphase scheme (scheme.name: multiphase)");
          }
      }
      continue;
    }
    if (strcmp(sec, "refinement") == 0 && (m->kind != RY_MAP || m->n == 0))
      return fail_at(c, key_at(r, i), sec,
                     "belongs to the rhodsph scheme, not to scheme.name: multiphase");
    for (unsigned j = 0; m->kind == RY_MAP && j < m->n; j++)
      if (rhod_rs_owns(sec, m->keys[j]->text)) {
        snprintf(path, sizeof path, "%s.%s", sec, m->keys[j]->text);
        return fail_at(c, key_at(m, j), path,
                       "belongs to the rhodsph scheme, not to scheme.name: multiphase");
      }
  }
  return RHOD_OK;
}

/* Edge j of a wall's shape in the stored order (rect: bottom, right, top, left, as
 * src/boundary.c builds them; polygon: points[j] to points[j + 1], counter-clockwise). */
static void wall_edge(const rhod_shape *sh, unsigned j, double a[2], double b[2]) {
  if (sh->kind == RHOD_SHAPE_RECT) {
    const double pts[4][2] = {{sh->min[0], sh->min[1]},
                              {sh->max[0], sh->min[1]},
                              {sh->max[0], sh->max[1]},
                              {sh->min[0], sh->max[1]}};
    memcpy(a, pts[j], sizeof pts[j]);
    memcpy(b, pts[(j + 1) % 4], sizeof pts[j]);
  } else {
    memcpy(a, sh->points[j], sizeof sh->points[j]);
    memcpy(b, sh->points[(j + 1) % sh->n_points], sizeof sh->points[j]);
  }
}

/* walls.N.velocity and walls.N.edges: which edges move, each along itself. Polygon edge
 * indices are the file's; a polygon written clockwise is stored reversed, its edge k
 * (points k to k + 1) then being stored edge n - 2 - k (mod n). */
static int load_wall_motion(lctx *c, const y_wall *y, unsigned i, rhod_wall *w,
                            const int periodic[2]) {
  char path[160];
  if (!y->velocity && !y->edges)
    return RHOD_OK;
  if (w->shape.kind == RHOD_SHAPE_CIRCLE) {
    snprintf(path, sizeof path, "walls.%u.%s", i, y->velocity ? "velocity" : "edges");
    return fail(c, path, "a circle wall cannot move (only the edges of a rect or polygon)");
  }
  const unsigned ne = w->shape.kind == RHOD_SHAPE_RECT ? 4 : w->shape.n_points;
  const int reversed = w->shape.kind == RHOD_SHAPE_POLYGON &&
                       polygon_area((const double(*)[2])y->polygon, y->n_polygon) < 0;
  if (y->velocity)
    memcpy(w->velocity, y->velocity, sizeof w->velocity);
  const int moves = w->velocity[0] != 0 || w->velocity[1] != 0;
  unsigned bits = 0;
  for (unsigned k = 0; k < (y->edges ? y->n_edges : 0); k++) {
    const double e = y->edges[k];
    snprintf(path, sizeof path, "walls.%u.edges.%u", i, k);
    if (!(e >= 0 && e == floor(e)))
      return fail(c, path, "must be a whole edge index, got %g", e);
    if (e >= ne)
      return w->shape.kind == RHOD_SHAPE_RECT
                 ? fail(c, path,
                        "edge %g out of range: a rect has 4 edges (0 bottom, 1 right, 2 top, "
                        "3 left)",
                        e)
                 : fail(c, path,
                        "edge %g out of range: the polygon has %u edges (0 to %u, edge k from "
                        "point k to k + 1)",
                        e, ne, ne - 1);
    const unsigned j = reversed ? (2 * ne - 2 - (unsigned)e) % ne : (unsigned)e;
    if (j >= 32 && moves)
      return fail(c, path, "edge %g: only the first 32 edges of a polygon can move", e);
    if (j < 32)
      bits |= 1u << j;
  }
  if (!moves) /* at rest: nothing moves, whatever edges says */
    return RHOD_OK;
  if (!y->edges) {
    if (ne > 32) {
      snprintf(path, sizeof path, "walls.%u.velocity", i);
      return fail(c, path,
                  "a polygon of %u edges cannot move all of them (at most 32 edges move): "
                  "name them in walls.%u.edges",
                  ne, i);
    }
    bits = ne == 32 ? 0xffffffffu : (1u << ne) - 1;
  }
  snprintf(path, sizeof path, "walls.%u.velocity", i);
  const double *v = w->velocity, speed = hypot(v[0], v[1]);
  for (unsigned j = 0; j < ne; j++) {
    if (!((bits >> j) & 1u))
      continue;
    double a[2], b[2];
    wall_edge(&w->shape, j, a, b);
    const double tx = b[0] - a[0], ty = b[1] - a[1], len = hypot(tx, ty);
    const unsigned user = reversed ? (2 * ne - 2 - j) % ne : j;
    if (fabs(tx * v[1] - ty * v[0]) > 1e-9 * len * speed)
      return fail(c, path,
                  "[%g, %g] is not along edge %u (from [%g, %g] to [%g, %g]): a moving edge "
                  "slides along itself (name the moving edges in walls.%u.edges)",
                  v[0], v[1], user, a[0], a[1], b[0], b[1], i);
    /* the edge's normal (-ty, tx)/len along a periodic axis */
    for (int ax = 0; ax < 2; ax++)
      if (periodic[ax] && fabs(ax ? ty : tx) <= 1e-9 * len)
        return fail(c, path,
                    "a wall velocity on a periodic axis: edge %u's normal lies along %c, "
                    "which domain.periodic wraps",
                    user, ax ? 'y' : 'x');
  }
  w->moving_edges = bits;
  return RHOD_OK;
}

int rhod_scene_walls_move(const rhod_scene *s) {
  for (unsigned i = 0; s && i < s->n_bodies; i++)
    if (s->bodies[i].motion != RHOD_MOTION_FIXED)
      return 1;
  for (unsigned i = 0; s && i < s->n_walls; i++)
    if (s->walls[i].moving_edges)
      return 1;
  for (unsigned i = 0; s && i < s->n_open; i++)
    if (s->open[i].kind == RHOD_OPEN_INFLOW)
      return 1;
  return 0;
}

/* What the schemes' sections say about open boundaries (scene_open.h): the level ratio and
 * finest level of rhodsph's refinement, the multiphase scheme's phase names (names has
 * room for RHOD_MP_MAX_PHASES). */
static rhod_ob_levels open_levels(const rhod_scene *s, const char **names) {
  rhod_ob_levels lv = {2.0, 30, names, 0};
  if (s->rs) {
    lv.ratio = rhod_pattern_ratio(s->rs->pattern);
    lv.max_level = s->rs->levels > 1 ? s->rs->levels - 1 : 0;
  }
  for (unsigned k = 0; s->mp && k < s->mp->n_phases && k < RHOD_MP_MAX_PHASES; k++)
    names[lv.n_phases++] = s->mp->phases[k].name;
  return lv;
}

static int convert(lctx *c, const y_doc *d, rhod_scene *s) {
  char path[128];
  /* the scheme first: it decides which keys belong, and some defaults */
  s->scheme =
      d->scheme && d->scheme->name ? (rhod_scheme_kind)*d->scheme->name : RHOD_SCHEME_RHODSPH;
  const int mpx = s->scheme == RHOD_SCHEME_MULTIPHASE;
  TRY(refuse_other_scheme(c, s->scheme));
  if (mpx)
    TRY(rhod_mp_load(c, d->phases, d->n_phases, d->multiphase, s));
  /* time */
  s->t_end = d->time.end;
  s->output_every = d->time.output_every;
  s->integrator = d->time.integrator ? (rhod_integrator_kind)*d->time.integrator
                  : mpx              ? RHOD_INTEGRATOR_MIDPOINT
                                     : RHOD_INTEGRATOR_RK4;
  TRY(check_positive(c, "time.end", s->t_end));
  TRY(check_positive(c, "time.output_every", s->output_every));
  /* the rhodsph scheme's keys, section by section where they were always checked (a
   * multiphase scene has none of them: refuse_other_scheme) */
  if (!mpx)
    TRY(rhod_rs_load_time(c, &d->time.rs, s));
  /* particles */
  s->dx = d->particles.dx;
  s->radius_ratio = opt(d->particles.radius_ratio, 4);
  s->kernel = d->particles.kernel ? (rhod_kernel_kind)*d->particles.kernel
              : mpx               ? RHOD_KERNEL_WENDLAND_C4
                                  : RHOD_KERNEL_WENDLAND_C2;
  TRY(check_positive(c, "particles.dx", s->dx));
  TRY(check_range(c, "particles.radius_ratio", s->radius_ratio, 2, 0, 8, 0));
  s->jitter = opt(d->particles.jitter, 0);
  TRY(check_range(c, "particles.jitter", s->jitter, 0, 0, 0.5, 0));
  if (!mpx)
    TRY(rhod_rs_load_particles(c, &d->particles.rs, s));
  /* physics: rho0, c0, mu are rhodsph's (the multiphase scheme's are its phases') */
  if (d->physics.gravity)
    memcpy(s->gravity, d->physics.gravity, sizeof s->gravity);
  if (!mpx)
    TRY(rhod_rs_load_physics(c, &d->physics.rs, s));
  /* scheme */
  if (!mpx)
    TRY(rhod_rs_load_scheme(c, d->scheme ? &d->scheme->rs : NULL, s));
  /* domain */
  const y_domain *dm = d->domain;
  if (dm && (!dm->min) != (!dm->max))
    return fail(c, dm->min ? "domain.min" : "domain.max",
                "domain.min and domain.max are given together");
  s->has_domain = dm && dm->min;
  if (s->has_domain) {
    memcpy(s->domain_min, dm->min, sizeof s->domain_min);
    memcpy(s->domain_max, dm->max, sizeof s->domain_max);
    if (!(s->domain_min[0] < s->domain_max[0] && s->domain_min[1] < s->domain_max[1]))
      return fail(c, "domain.max", "must exceed domain.min in both axes");
  }
  if (dm && dm->periodic) {
    s->periodic[0] = dm->periodic[0];
    s->periodic[1] = dm->periodic[1];
    if ((s->periodic[0] || s->periodic[1]) && !s->has_domain)
      return fail(c, "domain.periodic", "a periodic axis needs domain.min and domain.max");
  }
  /* fluid */
  s->fluid = calloc(d->n_fluid, sizeof *s->fluid);
  if (!s->fluid)
    return fail_oom(c);
  s->n_fluid = d->n_fluid;
  for (unsigned i = 0; i < d->n_fluid; i++) {
    const y_fluid *y = &d->fluid[i];
    rhod_fluid_block *b = &s->fluid[i];
    snprintf(path, sizeof path, "fluid.%u", i);
    TRY(rhod_sl_load_shape(c, path, y->rect, y->circle, y->polygon, y->n_polygon, &b->shape));
    if (y->velocity)
      memcpy(b->velocity, y->velocity, sizeof b->velocity);
    b->pressure = y->pressure ? (rhod_init_kind)*y->pressure : RHOD_INIT_HYDROSTATIC;
    /* where the block starts, for the messages of the particle set-up (rhod_sim_init) */
    const ry_node *bn = ry_find_path(c->root, path);
    if (bn && bn->origin < 0)
      b->line = bn->line, b->col = bn->col;
    b->phase = -1;
    if (mpx)
      TRY(rhod_mp_fluid_phase(c, s, i, y->phase, &b->phase));
    if (y->surface) {
      char sp[160];
      snprintf(sp, sizeof sp, "%s.surface", path);
      if (b->pressure != RHOD_INIT_HYDROSTATIC)
        return fail(c, sp,
                    "needs pressure: hydrostatic (it is the level of that start's free "
                    "surface)");
      if (!(s->gravity[0] != 0 || s->gravity[1] != 0))
        return fail(c, sp, "has no effect without physics.gravity (no hydrostatic pressure)");
      b->surface_set = 1;
      b->surface = *y->surface;
    }
    if (y->ambient_pressure)
      b->ambient_pressure = *y->ambient_pressure;
    double lo[2], hi[2];
    rhod_sl_shape_bbox(&b->shape, lo, hi);
    if (y->initial) {
      const y_initial *in = y->initial;
      char ip[192];
      snprintf(ip, sizeof ip, "%s.initial", path);
      if (!!in->taylor_green + !!in->rotation + !!in->shear_layer + !!in->droplet_oscillation != 1)
        return fail(c, ip,
                    "needs exactly one of taylor_green, rotation, shear_layer, "
                    "droplet_oscillation");
      if (in->shear_layer) {
        const y_shear_layer *k = in->shear_layer;
        const double len[3] = {k->width, k->spread, k->L};
        const char *const key[3] = {"width", "spread", "L"};
        for (int j = 0; j < 3; j++)
          if (!(len[j] > 0)) {
            snprintf(ip, sizeof ip, "%s.initial.shear_layer.%s", path, key[j]);
            return fail(c, ip, "must be > 0");
          }
        b->flow = RHOD_FLOW_SHEAR_LAYER;
        b->flow_U = k->U, b->flow_UI = k->UI, b->flow_L = k->L;
        b->flow_y[0] = k->y[0], b->flow_y[1] = k->y[1];
        b->flow_width = k->width, b->flow_spread = k->spread;
      } else if (in->droplet_oscillation) {
        const y_droplet *k = in->droplet_oscillation;
        snprintf(ip, sizeof ip, "%s.initial.droplet_oscillation.R", path);
        if (!(k->R > 0))
          return fail(c, ip, "must be > 0");
        b->flow = RHOD_FLOW_DROPLET;
        b->flow_U = k->U, b->flow_R = k->R;
        if (k->center)
          memcpy(b->flow_center, k->center, sizeof b->flow_center);
        else
          b->flow_center[0] = 0.5 * (lo[0] + hi[0]), b->flow_center[1] = 0.5 * (lo[1] + hi[1]);
      } else if (in->taylor_green) {
        snprintf(ip, sizeof ip, "%s.initial.taylor_green.L", path);
        if (!(in->taylor_green->L > 0))
          return fail(c, ip, "must be > 0");
        b->flow = RHOD_FLOW_TAYLOR_GREEN;
        b->flow_U = in->taylor_green->U;
        b->flow_L = in->taylor_green->L;
      } else {
        if (b->shape.kind != RHOD_SHAPE_RECT)
          return fail(c, ip,
                      "rotation needs a rect block (its pressure is the series of paper "
                      "002 Eq. 30 for a rectangle)");
        b->flow = RHOD_FLOW_ROTATION;
        b->flow_omega = in->rotation->omega;
        if (in->rotation->center)
          memcpy(b->flow_center, in->rotation->center, sizeof b->flow_center);
        else
          b->flow_center[0] = 0.5 * (lo[0] + hi[0]), b->flow_center[1] = 0.5 * (lo[1] + hi[1]);
      }
    }
    if (s->has_domain && !inside_box(lo, hi, s->domain_min, s->domain_max))
      return fail(c, path,
                  "lies outside the domain [%g, %g]-[%g, %g] (block spans [%g, %g]-[%g, %g])",
                  s->domain_min[0], s->domain_min[1], s->domain_max[0], s->domain_max[1], lo[0],
                  lo[1], hi[0], hi[1]);
    double area = rhod_sl_shape_area(&b->shape), w = fmin(hi[0] - lo[0], hi[1] - lo[1]);
    if (area < s->dx * s->dx * (1 - 1e-9) || w < s->dx * (1 - 1e-9))
      return fail(c, "particles.dx",
                  "%g m is too coarse for fluid.%u (%g m wide, area %g m^2): a block must hold "
                  "at least one particle",
                  s->dx, i, w, area);
  }
  /* walls */
  if (d->n_walls) {
    s->walls = calloc(d->n_walls, sizeof *s->walls);
    if (!s->walls)
      return fail_oom(c);
    s->n_walls = d->n_walls;
  }
  for (unsigned i = 0; i < d->n_walls; i++) {
    const y_wall *y = &d->walls[i];
    rhod_wall *w = &s->walls[i];
    snprintf(path, sizeof path, "walls.%u", i);
    TRY(rhod_sl_load_shape(c, path, y->rect, y->circle, y->polygon, y->n_polygon, &w->shape));
    w->slip = y->slip ? (rhod_slip)*y->slip : RHOD_SLIP_FREE;
    w->fluid_inside = opt_bool(y->fluid_inside, 1);
    w->refine = opt_bool(y->refine, 1);
    TRY(load_wall_motion(c, y, i, w, s->periodic));
  }
  /* bodies (src/scene_bodies.c): after the domain and the walls, which they are checked
   * against */
  TRY(rhod_bd_load(c, d->bodies, d->n_bodies, s));
  /* refinement (paper 002 Sec. V) */
  if (!mpx)
    TRY(rhod_rs_load_refinement(c, d->refinement, s));
  /* open boundaries (src/scene_open.c): their own keys, after the phases and the
   * refinement levels (their dx and phase) */
  const char *phase_names[RHOD_MP_MAX_PHASES];
  const rhod_ob_levels lv = open_levels(s, phase_names);
  TRY(rhod_ob_load(c, d->open, d->n_open, &lv, s));
  /* the default domain: bounding box of walls, fluid, the bodies where they stand at t = 0
   * and the open boundaries' segments */
  if (!s->has_domain) {
    const unsigned nb = s->n_fluid + s->n_walls + s->n_bodies;
    for (unsigned i = 0; i < nb + s->n_open; i++) {
      double lo[2], hi[2];
      if (i < s->n_fluid + s->n_walls)
        rhod_sl_shape_bbox(i < s->n_fluid ? &s->fluid[i].shape : &s->walls[i - s->n_fluid].shape,
                           lo, hi);
      else if (i < nb)
        rhod_bd_bbox(&s->bodies[i - s->n_fluid - s->n_walls], lo, hi);
      else
        rhod_ob_bbox(&s->open[i - nb], lo, hi);
      for (int a = 0; a < 2; a++) {
        s->domain_min[a] = i ? fmin(s->domain_min[a], lo[a]) : lo[a];
        s->domain_max[a] = i ? fmax(s->domain_max[a], hi[a]) : hi[a];
      }
    }
  }
  /* the open boundaries' normals (toward the domain's centre by default) and placement */
  TRY(rhod_ob_place(c, d->open, s));
  /* probes */
  const y_probes *pr = d->probes;
  s->probe_every = pr && pr->every ? *pr->every : s->output_every / 10;
  TRY(check_positive(c, "probes.every", s->probe_every));
  if (pr && pr->n_list) {
    s->probes = calloc(pr->n_list, sizeof *s->probes);
    if (!s->probes)
      return fail_oom(c);
    s->n_probes = pr->n_list;
  }
  unsigned ncols = 0;
  for (unsigned i = 0; i < s->n_probes; i++) {
    char kind_path[96];
    TRY(load_probe(c, &pr->list[i], i, &s->probes[i], kind_path, sizeof kind_path));
    if (s->probes[i].kind == RHOD_PROBE_PRESSURE && s->has_domain) {
      double *at = s->probes[i].at;
      if (!inside_box(at, at, s->domain_min, s->domain_max)) {
        snprintf(path, sizeof path, "%s.at", kind_path);
        return fail(c, path, "[%g, %g] lies outside the domain", at[0], at[1]);
      }
    }
    char mine[RHOD_PROBE_MAX_COLUMNS][NAME_MAX_LEN + 16],
        other[RHOD_PROBE_MAX_COLUMNS][NAME_MAX_LEN + 16];
    unsigned nm = probe_columns(&s->probes[i], mine);
    if ((ncols += nm) > RHOD_PROBE_COLUMNS_TOTAL)
      return fail(c, "probes.list",
                  "%u or more columns, at most %d (momentum gives 2, torque_budget %d)", ncols,
                  RHOD_PROBE_COLUMNS_TOTAL, RHOD_PROBE_MAX_COLUMNS);
    for (unsigned a = 0; a < nm; a++)
      if (strcmp(mine[a], "t") == 0) {
        snprintf(path, sizeof path, "%s.name", kind_path);
        return fail(c, path, "'t' is the time column of the probes file");
      }
    for (unsigned j = 0; j < i; j++) {
      unsigned no = probe_columns(&s->probes[j], other);
      for (unsigned a = 0; a < nm; a++)
        for (unsigned b = 0; b < no; b++)
          if (strcmp(mine[a], other[b]) == 0) {
            snprintf(path, sizeof path, "%s.name", kind_path);
            return fail(c, path, "duplicate probe column '%s' (also from probes.list.%u)", mine[a],
                        j);
          }
    }
  }
  /* output */
  const y_picture *pic = d->output ? d->output->picture : NULL;
  s->picture_enabled = !c->picture_off;
  s->picture_field = pic && pic->field ? (rhod_field)*pic->field : RHOD_FIELD_PRESSURE;
  double width = pic && pic->width ? *pic->width : 800;
  if (!(width >= 64 && width <= 8192 && width == floor(width)))
    return fail(c, "output.picture.width", "must be a whole number of pixels in [64, 8192], got %g",
                width);
  s->picture_width = (unsigned)width;
  /* with refinement, the sizes beside the field unless the field is the size */
  s->picture_size_panel = opt_bool(pic ? pic->size_panel : NULL, s->rs && s->rs->levels > 1) &&
                          s->picture_field != RHOD_FIELD_SIZE;
  if (pic && pic->range) {
    s->picture_range_set = 1;
    s->picture_range[0] = pic->range[0];
    s->picture_range[1] = pic->range[1];
    if (!(pic->range[0] < pic->range[1]))
      return fail(c, "output.picture.range", "low (%g) must be below high (%g)", pic->range[0],
                  pic->range[1]);
  }
  if (pic && pic->box) {
    s->picture_box_set = 1;
    memcpy(s->picture_box_min, pic->box->min, sizeof s->picture_box_min);
    memcpy(s->picture_box_max, pic->box->max, sizeof s->picture_box_max);
    if (!(s->picture_box_min[0] < s->picture_box_max[0] &&
          s->picture_box_min[1] < s->picture_box_max[1]))
      return fail(c, "output.picture.box.max", "must exceed output.picture.box.min in both axes");
  }
  /* output.fields: identifiers, each once (which the run has: rhod_sim_init) */
  const unsigned nof = d->output ? d->output->n_fields : 0;
  if (nof) {
    s->output_fields = calloc(nof, sizeof *s->output_fields);
    if (!s->output_fields)
      return fail_oom(c);
  }
  for (unsigned i = 0; i < nof; i++) {
    const char *f = d->output->fields[i];
    char key[48];
    snprintf(key, sizeof key, "output.fields.%u", i);
    if (!(isalpha((unsigned char)f[0]) || f[0] == '_') ||
        strspn(f, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != strlen(f))
      return fail(c, key, "'%s' is not a field name (a letter or '_', then letters, digits, '_')",
                  f);
    for (unsigned j = 0; j < i; j++)
      if (!strcmp(f, s->output_fields[j]))
        return fail(c, key, "'%s' is named twice (also output.fields.%u)", f, j);
    if (!(s->output_fields[i] = strdup(f)))
      return fail_oom(c);
    s->n_output_fields = i + 1;
  }
  TRY(check_limits(c, s));
  /* name */
  if (d->name) {
    if (!valid_name(d->name))
      return fail(c, "name", "'%s' is not a valid name (letters, digits, '_', '.', '-')", d->name);
    s->name = strdup(d->name);
  } else {
    s->name = default_name(c->file);
  }
  if (!s->name)
    return fail_oom(c);
  return RHOD_OK;
}

/* ---- the scene as run, as a tree -------------------------------------------------------- */

/* Shortest text that reads back as v; plain decimals between 1e-4 and 1e15. */
static void fmt_num(double v, char *buf, size_t len) {
  int p = 1;
  for (; p < 17; p++) {
    snprintf(buf, len, "%.*g", p, v);
    if (strtod(buf, NULL) == v)
      break;
  }
  if (p == 17)
    snprintf(buf, len, "%.17g", v);
  if (strchr(buf, 'e') && fabs(v) >= 1e-4 && fabs(v) < 1e15) {
    int decimals = p - 1 - (int)floor(log10(fabs(v)));
    char fixed[64];
    snprintf(fixed, sizeof fixed, "%.*f", decimals > 0 ? decimals : 0, v);
    if (strtod(fixed, NULL) == v && strlen(fixed) < len)
      memcpy(buf, fixed, strlen(fixed) + 1);
  }
}

typedef rhod_sl_tb tb;

static ry_node *tb_add(tb *t, ry_node *parent, const char *key, ry_node *n) {
  if (!n)
    t->oom = 1;
  if (t->oom || !parent) {
    if (parent)
      ry_free(n);
    return t->oom ? NULL : n;
  }
  if (parent->kind == RY_MAP ? ry_map_set(parent, key, n) : ry_seq_append(parent, n)) {
    ry_free(n);
    t->oom = 1;
    return NULL;
  }
  return n;
}

static ry_node *tb_coll(tb *t, ry_node *parent, const char *key, ry_kind kind, int flow) {
  if (t->oom)
    return NULL;
  ry_node *n = ry_new(kind, -1, 0, 0);
  if (n)
    n->flow = flow;
  return tb_add(t, parent, key, n);
}

/* Text that YAML readers would take for a boolean, a null or a number is quoted, so that
 * e.g. slip: "no" stays a word for a Python reader of the scene as run. */
static int looks_typed(const char *v) {
  static const char *const words[] = {"y",   "n",    "yes",   "no",   "on",
                                      "off", "true", "false", "null", "~"};
  double num;
  if (!v[0] || parse_number(v, &num))
    return 1;
  for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
    if (strcasecmp(v, words[i]) == 0)
      return 1;
  return 0;
}

static void tb_word(tb *t, ry_node *parent, const char *key, const char *v) {
  if (t->oom)
    return;
  ry_node *n = tb_add(t, parent, key, ry_new_scalar(v, -1, 0, 0));
  if (n)
    n->quoted = looks_typed(v);
}

static void tb_str(tb *t, ry_node *parent, const char *key, const char *v) {
  if (!t->oom)
    tb_add(t, parent, key, ry_new_scalar(v, -1, 0, 0));
}

static void tb_num(tb *t, ry_node *parent, const char *key, double v) {
  char buf[40];
  fmt_num(v, buf, sizeof buf);
  tb_str(t, parent, key, buf);
}

static void tb_bool(tb *t, ry_node *parent, const char *key, int v) {
  tb_str(t, parent, key, v ? "true" : "false");
}

static void tb_vec(tb *t, ry_node *parent, const char *key, const double v[2]) {
  ry_node *seq = tb_coll(t, parent, key, RY_SEQ, 1);
  tb_num(t, seq, NULL, v[0]);
  tb_num(t, seq, NULL, v[1]);
}

ry_node *rhod_sl_coll(rhod_sl_tb *t, ry_node *parent, const char *key, ry_kind kind, int flow) {
  return tb_coll(t, parent, key, kind, flow);
}
void rhod_sl_num(rhod_sl_tb *t, ry_node *parent, const char *key, double v) {
  tb_num(t, parent, key, v);
}
void rhod_sl_bool(rhod_sl_tb *t, ry_node *parent, const char *key, int v) {
  tb_bool(t, parent, key, v);
}
void rhod_sl_word(rhod_sl_tb *t, ry_node *parent, const char *key, const char *v) {
  tb_word(t, parent, key, v);
}

void rhod_sl_vec(rhod_sl_tb *t, ry_node *parent, const char *key, const double v[2]) {
  tb_vec(t, parent, key, v);
}

void rhod_sl_shape(rhod_sl_tb *t, ry_node *entry, const rhod_shape *sh) {
  ry_node *m;
  switch (sh->kind) {
  case RHOD_SHAPE_RECT:
    m = tb_coll(t, entry, "rect", RY_MAP, 1);
    tb_vec(t, m, "min", sh->min);
    tb_vec(t, m, "max", sh->max);
    break;
  case RHOD_SHAPE_CIRCLE:
    m = tb_coll(t, entry, "circle", RY_MAP, 1);
    tb_vec(t, m, "center", sh->center);
    tb_num(t, m, "radius", sh->radius);
    break;
  case RHOD_SHAPE_POLYGON:
    m = tb_coll(t, entry, "polygon", RY_SEQ, 1);
    for (unsigned i = 0; i < sh->n_points; i++)
      tb_vec(t, m, NULL, sh->points[i]);
    break;
  }
}

const char *rhod_sl_enum_name(const cyaml_strval_t *sv, size_t n, int v) {
  for (size_t i = 0; i < n; i++)
    if (sv[i].val == v)
      return sv[i].str;
  return "?";
}

static ry_node *scene_tree(const rhod_scene *s) {
  tb t = {0};
  ry_node *root = tb_coll(&t, NULL, NULL, RY_MAP, 0), *m, *e;
  if (s->name)
    tb_word(&t, root, "name", s->name);
  /* each scheme's keys where they always were: rhodsph's (s->rs) in time, particles,
   * physics, scheme and refinement; the multiphase scheme's (s->mp) in scheme.name,
   * phases and multiphase */
  const rhod_rs_scene *rs = s->rs;
  m = tb_coll(&t, root, "time", RY_MAP, 0);
  tb_num(&t, m, "end", s->t_end);
  tb_num(&t, m, "output_every", s->output_every);
  if (rs)
    rhod_rs_tree_time_step(&t, m, rs);
  tb_word(
      &t, m, "integrator",
      rhod_sl_enum_name(integrator_names, CYAML_ARRAY_LEN(integrator_names), (int)s->integrator));
  if (rs)
    rhod_rs_tree_time_limit(&t, m, rs);
  m = tb_coll(&t, root, "particles", RY_MAP, 0);
  tb_num(&t, m, "dx", s->dx);
  tb_num(&t, m, "radius_ratio", s->radius_ratio);
  tb_num(&t, m, "jitter", s->jitter);
  if (rs)
    rhod_rs_tree_particles(&t, m, rs);
  tb_word(&t, m, "kernel",
          rhod_sl_enum_name(kernel_names, CYAML_ARRAY_LEN(kernel_names), (int)s->kernel));
  m = tb_coll(&t, root, "physics", RY_MAP, 0);
  if (rs)
    rhod_rs_tree_physics(&t, m, rs);
  tb_vec(&t, m, "gravity", s->gravity);
  m = tb_coll(&t, root, "scheme", RY_MAP, 0);
  if (s->scheme == RHOD_SCHEME_MULTIPHASE) { /* scheme.name is absent for rhodsph, its
                                                default, so checkpoints made before the key
                                                resume */
    tb_word(&t, m, "name",
            rhod_sl_enum_name(scheme_names, CYAML_ARRAY_LEN(scheme_names), (int)s->scheme));
    rhod_mp_tree(&t, root, s->mp);
  }
  if (rs)
    rhod_rs_tree_scheme(&t, m, rs);
  m = tb_coll(&t, root, "domain", RY_MAP, 0);
  if (s->has_domain) {
    tb_vec(&t, m, "min", s->domain_min);
    tb_vec(&t, m, "max", s->domain_max);
  }
  e = tb_coll(&t, m, "periodic", RY_SEQ, 1);
  tb_bool(&t, e, NULL, s->periodic[0]);
  tb_bool(&t, e, NULL, s->periodic[1]);
  m = tb_coll(&t, root, "fluid", RY_SEQ, 0);
  for (unsigned i = 0; i < s->n_fluid; i++) {
    e = tb_coll(&t, m, NULL, RY_MAP, 0);
    rhod_sl_shape(&t, e, &s->fluid[i].shape);
    tb_vec(&t, e, "velocity", s->fluid[i].velocity);
    tb_word(&t, e, "pressure",
            rhod_sl_enum_name(init_names, CYAML_ARRAY_LEN(init_names), (int)s->fluid[i].pressure));
    if (s->fluid[i].surface_set) /* absent at its default, so older checkpoints resume */
      tb_num(&t, e, "surface", s->fluid[i].surface);
    if (s->fluid[i].ambient_pressure != 0) /* likewise */
      tb_num(&t, e, "ambient_pressure", s->fluid[i].ambient_pressure);
    if (s->mp)
      tb_word(&t, e, "phase", s->mp->phases[s->fluid[i].phase].name);
    const rhod_fluid_block *fb = &s->fluid[i];
    if (fb->flow != RHOD_FLOW_NONE) {
      ry_node *in = tb_coll(&t, e, "initial", RY_MAP, 0);
      if (fb->flow == RHOD_FLOW_TAYLOR_GREEN) {
        ry_node *k = tb_coll(&t, in, "taylor_green", RY_MAP, 1);
        tb_num(&t, k, "U", fb->flow_U);
        tb_num(&t, k, "L", fb->flow_L);
      } else if (fb->flow == RHOD_FLOW_ROTATION) {
        ry_node *k = tb_coll(&t, in, "rotation", RY_MAP, 1);
        tb_num(&t, k, "omega", fb->flow_omega);
        tb_vec(&t, k, "center", fb->flow_center);
      } else if (fb->flow == RHOD_FLOW_SHEAR_LAYER) {
        ry_node *k = tb_coll(&t, in, "shear_layer", RY_MAP, 1);
        tb_num(&t, k, "U", fb->flow_U);
        tb_num(&t, k, "UI", fb->flow_UI);
        tb_vec(&t, k, "y", fb->flow_y);
        tb_num(&t, k, "width", fb->flow_width);
        tb_num(&t, k, "spread", fb->flow_spread);
        tb_num(&t, k, "L", fb->flow_L);
      } else {
        ry_node *k = tb_coll(&t, in, "droplet_oscillation", RY_MAP, 1);
        tb_num(&t, k, "U", fb->flow_U);
        tb_num(&t, k, "R", fb->flow_R);
        tb_vec(&t, k, "center", fb->flow_center);
      }
    }
  }
  m = tb_coll(&t, root, "walls", RY_SEQ, s->n_walls == 0);
  for (unsigned i = 0; i < s->n_walls; i++) {
    e = tb_coll(&t, m, NULL, RY_MAP, 0);
    rhod_sl_shape(&t, e, &s->walls[i].shape);
    tb_word(&t, e, "slip",
            rhod_sl_enum_name(slip_names, CYAML_ARRAY_LEN(slip_names), (int)s->walls[i].slip));
    tb_bool(&t, e, "fluid_inside", s->walls[i].fluid_inside);
    const rhod_wall *w = &s->walls[i];
    if (w->moving_edges) { /* absent at rest, so older checkpoints resume */
      tb_vec(&t, e, "velocity", w->velocity);
      ry_node *edges = tb_coll(&t, e, "edges", RY_SEQ, 1);
      for (unsigned k = 0; k < 32; k++)
        if ((w->moving_edges >> k) & 1u)
          tb_num(&t, edges, NULL, k);
    }
    if (!w->refine) /* absent at its default, so older checkpoints resume */
      tb_bool(&t, e, "refine", 0);
  }
  rhod_bd_tree(&t, root, s);
  const char *phase_names[RHOD_MP_MAX_PHASES];
  const rhod_ob_levels lv = open_levels(s, phase_names);
  rhod_ob_tree(&t, root, s, &lv);
  m = tb_coll(&t, root, "probes", RY_MAP, 0);
  tb_num(&t, m, "every", s->probe_every);
  m = tb_coll(&t, m, "list", RY_SEQ, s->n_probes == 0);
  for (unsigned i = 0; i < s->n_probes; i++) {
    const rhod_probe *p = &s->probes[i];
    e = tb_coll(&t, m, NULL, RY_MAP, 0);
    unsigned kind = (unsigned)p->kind < N_PROBE_KINDS ? (unsigned)p->kind : 0;
    ry_node *b = tb_coll(&t, e, probe_kind_names[kind], RY_MAP, 1);
    if (p->name)
      tb_word(&t, b, "name", p->name);
    if (p->kind == RHOD_PROBE_PRESSURE || p->kind == RHOD_PROBE_ANGULAR_MOMENTUM ||
        p->kind == RHOD_PROBE_TORQUE_BUDGET)
      tb_vec(&t, b, "at", p->at);
    if (p->kind == RHOD_PROBE_FRONT)
      tb_vec(&t, b, "direction", p->direction);
  }
  if (rs)
    rhod_rs_tree_refinement(&t, root, rs);
  m = tb_coll(&t, root, "output", RY_MAP, 0);
  if (s->n_output_fields) { /* written when given (none: the key is left out) */
    e = tb_coll(&t, m, "fields", RY_SEQ, 1);
    for (unsigned i = 0; i < s->n_output_fields; i++)
      tb_word(&t, e, NULL, s->output_fields[i]);
  }
  if (!s->picture_enabled) {
    tb_bool(&t, m, "picture", 0);
    goto done;
  }
  m = tb_coll(&t, m, "picture", RY_MAP, 0);
  tb_word(&t, m, "field",
          rhod_sl_enum_name(field_names, CYAML_ARRAY_LEN(field_names), (int)s->picture_field));
  tb_num(&t, m, "width", s->picture_width);
  tb_bool(&t, m, "size_panel", s->picture_size_panel);
  if (s->picture_range_set)
    tb_vec(&t, m, "range", s->picture_range);
  if (s->picture_box_set) {
    ry_node *b = tb_coll(&t, m, "box", RY_MAP, 1);
    tb_vec(&t, b, "min", s->picture_box_min);
    tb_vec(&t, b, "max", s->picture_box_max);
  }
done:
  if (t.oom) {
    ry_free(root);
    return NULL;
  }
  return root;
}

/* ---- public API ------------------------------------------------------------------------ */

void rhod_scene_free(rhod_scene *s) {
  if (!s)
    return;
  for (unsigned i = 0; i < s->n_fluid; i++)
    free(s->fluid[i].shape.points);
  for (unsigned i = 0; i < s->n_walls; i++)
    free(s->walls[i].shape.points);
  for (unsigned i = 0; i < s->n_probes; i++)
    free(s->probes[i].name);
  rhod_bd_free(s);
  rhod_ob_free(s);
  rhod_rs_scene_free(s->rs);
  rhod_mp_scene_free(s->mp);
  free(s->fluid);
  free(s->walls);
  free(s->probes);
  for (unsigned i = 0; i < s->n_output_fields; i++)
    free(s->output_fields[i]);
  free(s->output_fields);
  free(s->name);
  free(s->path);
  free(s->yaml);
  free(s);
}

/* output.picture is a mapping or a switch: true (the defaults) or false (no pictures).
 * A switch becomes an empty mapping for libcyaml, remembered in c->picture_off. */
static int picture_switch(lctx *c) {
  ry_node *o = c->root->kind == RY_MAP ? ry_map_get(c->root, "output") : NULL;
  ry_node *pic = o && o->kind == RY_MAP ? ry_map_get(o, "picture") : NULL;
  if (!pic || pic->kind != RY_SCALAR)
    return RHOD_OK;
  bool on;
  if (!parse_bool(pic->text, &on))
    return fail_at(c, pic, "output.picture", "expected a mapping, true or false, got '%s'",
                   pic->text);
  ry_node *empty = ry_new(RY_MAP, pic->origin, pic->line, pic->col);
  if (!empty)
    return fail_oom(c);
  empty->flow = 1;
  ry_replace(pic, empty);
  c->picture_off = !on;
  return RHOD_OK;
}

static int load_document(lctx *c, rhod_scene **out) {
  int rc;
  for (int k = 0; k < c->n_ov; k++)
    if ((rc = apply_override(c, k)))
      return rc;
  if ((rc = picture_switch(c)))
    return rc;
  annotate(c->root, &sch_doc);

  /* the text libcyaml reads, and where each node sits in it */
  char *text = NULL;
  size_t len = 0;
  if (ry_emit(c->root, &text, &len))
    return fail_oom(c);
  ry_node *emitted = NULL;
  ry_error ye;
  if (ry_parse(text, len, -1, &emitted, &ye)) {
    free(text);
    return ye.oom ? fail_oom(c) : fail_at(c, c->root, "", "internal: %s", ye.msg);
  }
  ry_set_emitted_marks(c->root, emitted);
  ry_free(emitted);

  cy_log log = {.len = 0};
  cyaml_config_t cfg = {
      .log_fn = cy_log_fn,
      .log_ctx = &log,
      .mem_fn = cyaml_mem,
      .log_level = CYAML_LOG_ERROR,
      .flags = CYAML_CFG_NO_ALIAS,
  };
  y_doc *doc = NULL;
  log.text[0] = '\0';
  cyaml_err_t cerr =
      cyaml_load_data((const uint8_t *)text, len, &cfg, &sch_doc, (void **)&doc, NULL);
  free(text);
  if (cerr != CYAML_OK)
    return cyaml_failure(c, cerr, &log);
  if (!doc)
    return fail_at(c, c->root, "time", "missing required key");

  rc = check_scalars(c, c->root);
  rhod_scene *s = NULL;
  if (!rc) {
    s = calloc(1, sizeof *s);
    rc = s ? convert(c, doc, s) : fail_oom(c);
  }
  cyaml_free(&cfg, &sch_doc, doc, 0);
  if (!rc) {
    ry_node *tree = scene_tree(s);
    s->path = strdup(c->file);
    if (!tree || !s->path || ry_emit(tree, &s->yaml, NULL))
      rc = fail_oom(c);
    ry_free(tree);
  }
  if (rc) {
    rhod_scene_free(s);
    return rc;
  }
  *out = s;
  return RHOD_OK;
}

int rhod_scene_load(const char *path, const char *const *overrides, int n_overrides,
                    rhod_scene **out, char *err, size_t errlen) {
  if (err && errlen)
    err[0] = '\0';
  if (!out)
    return RHOD_ERR_USAGE;
  *out = NULL;
  lctx c = {
      .file = path ? path : "(no file)",
      .ov = overrides,
      .n_ov = overrides ? (n_overrides > 0 ? n_overrides : 0) : 0,
      .err = err,
      .errlen = errlen,
  };
  if (!path) {
    put_msg(&c, "%s: cannot read: no file given", c.file);
    return RHOD_ERR_READ;
  }
  char *text = NULL;
  size_t len = 0;
  int e = rhod_read_file(path, RHOD_SCENE_MAX_BYTES, &text, &len);
  if (e) {
    if (e == ENOMEM)
      return fail_oom(&c);
    if (e == RHOD_READ_TOO_LARGE)
      put_msg(&c, "%s: cannot read: larger than %zu MiB, the limit for a scene", path,
              RHOD_SCENE_MAX_BYTES >> 20);
    else
      put_msg(&c, "%s: cannot read: %s", path, rhod_read_strerror(e));
    return RHOD_ERR_READ;
  }
  ry_error ye;
  int rc;
  if (ry_parse(text, len, -1, &c.root, &ye)) {
    if (ye.oom)
      rc = fail_oom(&c);
    else
      rc = (put_msg(&c, "%s:%u:%u: %s: %s", path, ye.line, ye.col, shown(ye.path), ye.msg),
            RHOD_ERR_SCENE);
  } else if (!c.root && !(c.root = ry_new(RY_MAP, -1, 1, 1))) {
    rc = fail_oom(&c);
  } else {
    rc = load_document(&c, out);
  }
  ry_free(c.root);
  free(text);
  return rc;
}

/* ---- parameters ------------------------------------------------------------------------- */

static int inline_only(const ry_node *n) {
  if (n->kind == RY_MAP)
    return 0;
  for (unsigned i = 0; i < n->n; i++)
    if (!inline_only(n->items[i]))
      return 0;
  return 1;
}

/* Appends the flow-style text of n at buf + *used; with buf NULL only counts. */
static void inline_text(const ry_node *n, char *buf, size_t len, size_t *used) {
#define INLINE_PUT(...)                                                                            \
  (*used +=                                                                                        \
   (size_t)snprintf(buf ? buf + *used : NULL, buf && *used < len ? len - *used : 0, __VA_ARGS__))
  if (n->kind == RY_SCALAR) {
    INLINE_PUT("%s", n->text);
    return;
  }
  INLINE_PUT("[");
  for (unsigned i = 0; i < n->n; i++) {
    if (i)
      INLINE_PUT(", ");
    inline_text(n->items[i], buf, len, used);
  }
  INLINE_PUT("]");
#undef INLINE_PUT
}

static int param_push(rhod_param_list *p, unsigned *cap, const char *key, const char *value) {
  if (p->n == *cap) {
    unsigned nc = *cap ? 2 * *cap : 64;
    char **k = realloc(p->keys, nc * sizeof *k);
    if (!k)
      return -1;
    p->keys = k;
    char **v = realloc(p->values, nc * sizeof *v);
    if (!v)
      return -1;
    p->values = v;
    *cap = nc;
  }
  p->keys[p->n] = strdup(key);
  p->values[p->n] = strdup(value);
  if (!p->keys[p->n] || !p->values[p->n]) {
    free(p->keys[p->n]);
    free(p->values[p->n]);
    return -1;
  }
  p->n++;
  return 0;
}

static int flatten(const ry_node *n, const char *path, rhod_param_list *p, unsigned *cap) {
  if (n->kind == RY_SCALAR)
    return param_push(p, cap, path, n->text);
  if (n->kind == RY_SEQ && inline_only(n)) {
    size_t used = 0;
    inline_text(n, NULL, 0, &used);
    char *buf = malloc(used + 1);
    if (!buf)
      return -1;
    const size_t size = used + 1;
    used = 0;
    inline_text(n, buf, size, &used);
    int rc = param_push(p, cap, path, buf);
    free(buf);
    return rc;
  }
  if (n->kind == RY_MAP && n->n == 0)
    return param_push(p, cap, path, "{}");
  for (unsigned i = 0; i < n->n; i++) {
    char idx[16];
    const char *seg =
        n->kind == RY_MAP ? n->keys[i]->text : (snprintf(idx, sizeof idx, "%u", i), idx);
    size_t len = strlen(path) + strlen(seg) + 2;
    char *child = malloc(len);
    if (!child)
      return -1;
    snprintf(child, len, "%s%s%s", path, path[0] ? "." : "", seg);
    int rc = flatten(n->items[i], child, p, cap);
    free(child);
    if (rc)
      return rc;
  }
  return 0;
}

int rhod_scene_params(const rhod_scene *s, rhod_param_list *out) {
  if (!out)
    return RHOD_ERR_USAGE;
  memset(out, 0, sizeof *out);
  if (!s)
    return RHOD_ERR_USAGE;
  ry_node *tree = scene_tree(s);
  if (!tree)
    return RHOD_ERR_MEMORY;
  unsigned cap = 0;
  int rc = flatten(tree, "", out, &cap);
  ry_free(tree);
  if (rc) {
    rhod_param_list_free(out);
    return RHOD_ERR_MEMORY;
  }
  return RHOD_OK;
}

void rhod_param_list_free(rhod_param_list *p) {
  if (!p)
    return;
  for (unsigned i = 0; i < p->n; i++) {
    free(p->keys[i]);
    free(p->values[i]);
  }
  free(p->keys);
  free(p->values);
  memset(p, 0, sizeof *p);
}

/* ---- warnings --------------------------------------------------------------------------- */

void rhod_warn(rhod_warn_buf *w, const char *fmt, ...) {
  if (w->buf && w->len && w->used + 1 < w->len) {
    if (w->count)
      w->used += (size_t)snprintf(w->buf + w->used, w->len - w->used, "\n");
    if (w->used + 1 < w->len) {
      va_list ap;
      va_start(ap, fmt);
      int n = vsnprintf(w->buf + w->used, w->len - w->used, fmt, ap);
      va_end(ap);
      if (n > 0)
        w->used += (size_t)n;
      if (w->used >= w->len)
        w->used = w->len - 1;
    }
  }
  w->count++;
}

/* Extent of all fluid blocks along the unit vector e: [lo, hi] of x.e. */
static void fluid_extent(const rhod_scene *s, const double e[2], double *lo, double *hi) {
  *lo = INFINITY;
  *hi = -INFINITY;
  for (unsigned i = 0; i < s->n_fluid; i++) {
    double a, b;
    shape_extent(&s->fluid[i].shape, e, &a, &b);
    *lo = fmin(*lo, a);
    *hi = fmax(*hi, b);
  }
}

int rhod_scene_warnings(const rhod_scene *s, char *buf, size_t len) {
  rhod_warn_buf w = {buf, len, 0, 0};
  if (buf && len)
    buf[0] = '\0';
  if (!s)
    return 0;
  const char *file = s->path ? s->path : "(scene)";

  /* Eq. 2 of paper 002 */
  double g = hypot(s->gravity[0], s->gravity[1]), H = 0, umax = 0;
  if (g > 0 && s->n_fluid) {
    double e[2] = {s->gravity[0] / g, s->gravity[1] / g}, lo, hi;
    fluid_extent(s, e, &lo, &hi);
    H = hi - lo;
  }
  for (unsigned i = 0; i < s->n_fluid; i++) {
    const rhod_fluid_block *b = &s->fluid[i];
    double flow = 0; /* the initial flow's largest speed */
    if (b->flow == RHOD_FLOW_TAYLOR_GREEN || b->flow == RHOD_FLOW_DROPLET)
      flow = fabs(b->flow_U); /* Eqs. 28-29 stay below U (paper 000) */
    else if (b->flow == RHOD_FLOW_SHEAR_LAYER)
      flow = hypot(b->flow_U, 2 * b->flow_UI); /* |tanh - tanh - 1| <= 1 for y1 < y2 */
    else if (b->flow == RHOD_FLOW_ROTATION) {
      double lo[2], hi[2];
      rhod_sl_shape_bbox(&b->shape, lo, hi);
      const double dx = fmax(fabs(lo[0] - b->flow_center[0]), fabs(hi[0] - b->flow_center[0]));
      const double dy = fmax(fabs(lo[1] - b->flow_center[1]), fabs(hi[1] - b->flow_center[1]));
      flow = fabs(b->flow_omega) * hypot(dx, dy);
    }
    umax = fmax(umax, hypot(b->velocity[0], b->velocity[1]) + flow);
  }
  const rhod_rs_scene *rs = s->rs; /* physics.c0 and rho0 are rhodsph's */
  const double rho0 = rs ? rs->rho0 : 0;
  double du = sqrt(2 * g * H) + umax, dp = rho0 * g * H;
  double bound = 10 * fmax(du, rho0 > 0 ? sqrt(dp / rho0) : 0);
  if (rs && rs->c0 < bound * (1 - 1e-12))
    rhod_warn(
        &w,
        "%s: physics.c0: %g m/s is below the bound %.4g m/s of paper 002 Eq. 2, "
        "c0 >= 10 max(dU_max, sqrt(dP_max/rho0)), with dU_max = sqrt(2|g|H) + max|u0| = %.4g m/s, "
        "dP_max = rho0|g|H = %.4g Pa, H = %.4g m: the flow is not weakly compressible",
        file, rs->c0, bound, du, dp, H);

  if (s->output_every > s->t_end)
    rhod_warn(&w,
              "%s: time.output_every: %g s exceeds time.end = %g s: two snapshots are written, at "
              "t = 0 and at the end",
              file, s->output_every, s->t_end);

  /* a free-surface level below the block's top: the particles above it start in tension */
  for (unsigned i = 0; i < s->n_fluid && g > 0; i++) {
    const rhod_fluid_block *b = &s->fluid[i];
    if (!b->surface_set)
      continue;
    const double up[2] = {-s->gravity[0] / g, -s->gravity[1] / g};
    double lo, hi;
    shape_extent(&b->shape, up, &lo, &hi);
    if (b->surface < hi - 1e-9 * fmax(1, fabs(hi)))
      rhod_warn(
          &w,
          "%s: fluid.%u.surface: %g m is below the block's top (%g m along -g): the particles "
          "above it start with a negative (tensile) pressure",
          file, i, b->surface, hi);
  }

  if (s->picture_range_set && s->picture_field == RHOD_FIELD_FREE_SURFACE)
    rhod_warn(&w, "%s: output.picture.range: ignored for field free_surface (a flag, not a scale)",
              file);

  for (int a = 0; a < 2; a++) {
    if (!s->periodic[a] || !(s->dx > 0))
      continue;
    double L = s->domain_max[a] - s->domain_min[a], n = L / s->dx;
    if (fabs(n - nearbyint(n)) > 1e-6 * fmax(1, n))
      rhod_warn(&w,
                "%s: domain.periodic: the domain length along %c (%g m) is not a multiple of "
                "particles.dx (%g m): the lattice will not tile across the periodic boundary",
                file, a ? 'y' : 'x', L, s->dx);
  }
  return w.count;
}
