/* The `open_boundaries` section of a scene (issue 52): straight segments through which fluid
 * enters (inflow) or leaves (outflow) by continuous mass insertion and deletion (paper 000
 * Sec. 3.3, Eqs. 11-17; paper 001 Sec. 3.1, Eqs. 20-28; docs/scene.md "open_boundaries").
 * Their schema, value checks, resolved defaults (name, normal, velocity, profile, dx,
 * phase; docs/choices.md), the placement checks (domain, fluid, each other, walls and
 * bodies, periodic axes) and their part of the scene as run. The mechanism (schema
 * validation, messages, `--set`, the scene as run) is src/scene.c's; the velocity law is
 * checked as the bodies' laws are (src/scene_bodies.c) and kept as text. */
#define _POSIX_C_SOURCE 200809L

#include "scene_open.h"

#include "rhod/sim.h"
#include "scene_bodies.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define OPT (CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL)
#define OPEN_NAME_MAX 64
#define OPEN_MAX_HALVINGS 30 /* dx = particles.dx / 2^k: k at most (multiphase) */

/* ---- schema --------------------------------------------------------------------------- */

static const cyaml_strval_t kind_names[] = {
    {"inflow", RHOD_OPEN_INFLOW},
    {"outflow", RHOD_OPEN_OUTFLOW},
};
static const cyaml_strval_t profile_names[] = {
    {"uniform", RHOD_PROFILE_UNIFORM},
    {"parabolic", RHOD_PROFILE_PARABOLIC},
};

static const cyaml_schema_field_t f_open[] = {
    CYAML_FIELD_STRING_PTR("name", OPT, y_open, name, 1, OPEN_NAME_MAX),
    CYAML_FIELD_ENUM("kind", CYAML_FLAG_STRICT, y_open, kind, kind_names,
                     CYAML_ARRAY_LEN(kind_names)),
    CYAML_FIELD_SEQUENCE_FIXED("from", CYAML_FLAG_POINTER | CYAML_FLAG_FLOW, y_open, from,
                               &rhod_sl_sch_float, 2),
    CYAML_FIELD_SEQUENCE_FIXED("to", CYAML_FLAG_POINTER | CYAML_FLAG_FLOW, y_open, to,
                               &rhod_sl_sch_float, 2),
    CYAML_FIELD_SEQUENCE_FIXED("normal", OPT | CYAML_FLAG_FLOW, y_open, normal, &rhod_sl_sch_float,
                               2),
    CYAML_FIELD_STRING_PTR("velocity", OPT, y_open, velocity, 1, CYAML_UNLIMITED),
    CYAML_FIELD_ENUM_PTR("profile", OPT | CYAML_FLAG_STRICT, y_open, profile, profile_names,
                         CYAML_ARRAY_LEN(profile_names)),
    CYAML_FIELD_FLOAT_PTR("surface", OPT | CYAML_FLAG_STRICT, y_open, surface),
    CYAML_FIELD_FLOAT_PTR("pressure", OPT | CYAML_FLAG_STRICT, y_open, pressure),
    CYAML_FIELD_FLOAT_PTR("dx", OPT | CYAML_FLAG_STRICT, y_open, dx),
    CYAML_FIELD_STRING_PTR("phase", OPT, y_open, phase, 1, OPEN_NAME_MAX),
    CYAML_FIELD_END,
};
const cyaml_schema_value_t rhod_ob_sch_open = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_open, f_open)};

/* ---- geometry --------------------------------------------------------------------------- */

static double cross(const double *a, const double *b, const double *p) {
  return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
}

/* A length below which two points count as one: 1e-9 of the domain's size. */
static double length_tol(const rhod_scene *s) {
  return 1e-9 *
         fmax(1.0, hypot(s->domain_max[0] - s->domain_min[0], s->domain_max[1] - s->domain_min[1]));
}

/* Whether segments a-b and p-q overlap: collinear (within tol) with extents overlapping by
 * more than tol, or meeting elsewhere than at a shared end. */
static int segments_overlap(const double *a, const double *b, const double *p, const double *q,
                            double tol) {
  const double L = hypot(b[0] - a[0], b[1] - a[1]);
  if (fabs(cross(a, b, p)) <= tol * L && fabs(cross(a, b, q)) <= tol * L) {
    /* collinear: the overlap of the extents along a-b */
    const double tx = (b[0] - a[0]) / L, ty = (b[1] - a[1]) / L;
    const double sp = (p[0] - a[0]) * tx + (p[1] - a[1]) * ty;
    const double sq = (q[0] - a[0]) * tx + (q[1] - a[1]) * ty;
    return fmin(L, fmax(sp, sq)) - fmax(0.0, fmin(sp, sq)) > tol;
  }
  const double *e1[2] = {a, b}, *e2[2] = {p, q};
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++)
      if (hypot(e1[i][0] - e2[j][0], e1[i][1] - e2[j][1]) <= tol)
        return 0; /* not collinear and sharing an end: they meet only there */
  return rhod_sl_segments_meet(a, b, p, q);
}

/* Whether segment a-b lies along p-q: collinear within tol and overlapping by more. */
static int segments_collinear_overlap(const double *a, const double *b, const double *p,
                                      const double *q, double tol) {
  const double L = hypot(b[0] - a[0], b[1] - a[1]);
  if (!(fabs(cross(a, b, p)) <= tol * L && fabs(cross(a, b, q)) <= tol * L))
    return 0;
  const double tx = (b[0] - a[0]) / L, ty = (b[1] - a[1]) / L;
  const double sp = (p[0] - a[0]) * tx + (p[1] - a[1]) * ty;
  const double sq = (q[0] - a[0]) * tx + (q[1] - a[1]) * ty;
  return fmin(L, fmax(sp, sq)) - fmax(0.0, fmin(sp, sq)) > tol;
}

/* The vertices of a rect or polygon, counter-clockwise, moved by pose (d_x, d_y, theta)
 * about G (a body where it stands at t = 0); NULL for a circle or when out of memory. */
static double (*edges_of(const rhod_shape *sh, const double *G, const double *pose,
                         unsigned *n))[2] {
  unsigned np;
  double(*p)[2] = rhod_sl_shape_vertices(sh, &np);
  *n = 0;
  if (!p)
    return NULL;
  if (pose && (pose[0] != 0 || pose[1] != 0 || pose[2] != 0)) {
    const double cs = cos(pose[2]), sn = sin(pose[2]);
    for (unsigned k = 0; k < np; k++) {
      const double rx = p[k][0] - G[0], ry = p[k][1] - G[1];
      p[k][0] = G[0] + pose[0] + cs * rx - sn * ry;
      p[k][1] = G[1] + pose[1] + sn * rx + cs * ry;
    }
  }
  *n = np;
  return p;
}

/* ---- checks and defaults ---------------------------------------------------------------- */

static const char *kind_word(rhod_open_kind k) {
  return rhod_sl_enum_name(kind_names, CYAML_ARRAY_LEN(kind_names), (int)k);
}

/* open_boundaries.N.phase: a phase's name, or its index as a whole number */
static int load_phase(lctx *c, const char *path, const rhod_ob_levels *lv, const char *text,
                      int *index) {
  for (unsigned k = 0; k < lv->n_phases; k++)
    if (strcmp(lv->phases[k], text) == 0)
      return *index = (int)k, RHOD_OK;
  const size_t n = strspn(text, "0123456789");
  if (n && n == strlen(text) && n < 4 && (unsigned)atoi(text) < lv->n_phases)
    return *index = atoi(text), RHOD_OK;
  return rhod_sl_fail(c, path, "unknown phase '%s' (a phase's name or index, 0 to %u)", text,
                      lv->n_phases - 1);
}

/* open_boundaries.N.dx: particles.dx / e^k, e the level ratio (2; rhodsph: its refinement
 * pattern's), k a whole number, below refinement.levels for rhodsph. */
static int load_dx(lctx *c, const char *path, const rhod_scene *s, const rhod_ob_levels *lv,
                   double dx, double *out) {
  const double e = lv->ratio;
  if (!(dx > 0))
    return rhod_sl_fail(c, path, "must be > 0, got %g", dx);
  const double k = round(log(s->dx / dx) / log(e));
  if (!(k >= 0 && k <= OPEN_MAX_HALVINGS && fabs(s->dx / pow(e, k) - dx) <= 1e-9 * dx))
    return rhod_sl_fail(c, path,
                        "%g m is not particles.dx (%g m) / %g^k for a whole k >= 0 (a particle "
                        "size of a refinement level)",
                        dx, s->dx, e);
  if (k > lv->max_level)
    return rhod_sl_fail(c, path,
                        "%g m is particles.dx / %g^%d, finer than the finest level (refinement."
                        "levels: %d)",
                        dx, e, (int)k, lv->max_level + 1);
  *out = dx;
  return RHOD_OK;
}

static int load_open(lctx *c, const y_open *y, unsigned i, const rhod_ob_levels *lv,
                     rhod_scene *s) {
  rhod_open_boundary *o = &s->open[i];
  char base[32], path[96];
  snprintf(base, sizeof base, "open_boundaries.%u", i);
  rhod_sl_where(c, base, &o->line, &o->col);
  o->kind = (rhod_open_kind)y->kind;
  memcpy(o->from, y->from, sizeof o->from);
  memcpy(o->to, y->to, sizeof o->to);
  o->phase = -1;
  /* name: an identifier, unique among the open boundaries */
  TRY(rhod_sl_list_name(c, base, y->name, "an open boundary", "open", i, &o->name, path,
                        sizeof path));
  for (unsigned j = 0; j < i; j++)
    if (strcmp(o->name, s->open[j].name) == 0)
      return rhod_sl_fail(c, path, "the name '%s' is also open_boundaries.%u's (names must differ)",
                          o->name, j);
  snprintf(path, sizeof path, "%s.to", base);
  const double L = hypot(o->to[0] - o->from[0], o->to[1] - o->from[1]);
  if (!(L > 0))
    return rhod_sl_fail(c, path, "[%g, %g] is the same point as from: the segment has no length",
                        o->to[0], o->to[1]);
  /* the inflow's keys */
  const int in = o->kind == RHOD_OPEN_INFLOW;
  if (!in && (y->velocity || y->profile)) {
    snprintf(path, sizeof path, "%s.%s", base, y->velocity ? "velocity" : "profile");
    return rhod_sl_fail(c, path,
                        "only for kind: inflow (an outflow's fluid leaves with its own "
                        "velocity)");
  }
  if (in) {
    const char *text = y->velocity ? y->velocity : "0";
    double v0;
    snprintf(path, sizeof path, "%s.velocity", base);
    TRY(rhod_bd_check_law(c, path, text, &v0));
    if (!(o->velocity = strdup(text)))
      return rhod_sl_fail_oom(c);
    o->profile = y->profile ? (rhod_profile_kind)*y->profile : RHOD_PROFILE_UNIFORM;
  }
  /* surface: the level along -g (as fluid.N.surface) below which the segment is wet */
  if (y->surface) {
    snprintf(path, sizeof path, "%s.surface", base);
    const double g = hypot(s->gravity[0], s->gravity[1]);
    if (!(g > 0))
      return rhod_sl_fail(c, path,
                          "has no effect without physics.gravity (it is a level along "
                          "-g)");
    const double e[2] = {-s->gravity[0] / g, -s->gravity[1] / g};
    const double h0 = o->from[0] * e[0] + o->from[1] * e[1];
    const double h1 = o->to[0] * e[0] + o->to[1] * e[1];
    if (*y->surface < fmin(h0, h1))
      return rhod_sl_fail(c, path,
                          "%g m lies below both ends (levels %g and %g m along -g): negative "
                          "depth, the segment would be dry",
                          *y->surface, h0, h1);
    o->surface_set = 1;
    o->surface = *y->surface;
  }
  /* pressure: an outflow's ambient pressure at its surface (everywhere without gravity) */
  if (y->pressure) {
    snprintf(path, sizeof path, "%s.pressure", base);
    if (in)
      return rhod_sl_fail(c, path,
                          "only for kind: outflow (an inflow's pressure is the fluid's, "
                          "extrapolated)");
    if ((s->gravity[0] != 0 || s->gravity[1] != 0) && !o->surface_set)
      return rhod_sl_fail(c, path,
                          "needs surface under gravity (the level where the ambient pressure "
                          "holds; the hydrostatic part is added below it)");
    o->pressure = *y->pressure;
  }
  o->dx = s->dx;
  if (y->dx) {
    snprintf(path, sizeof path, "%s.dx", base);
    TRY(load_dx(c, path, s, lv, *y->dx, &o->dx));
  }
  /* phase: the multiphase scheme's */
  if (y->phase) {
    snprintf(path, sizeof path, "%s.phase", base);
    if (s->scheme != RHOD_SCHEME_MULTIPHASE)
      return rhod_sl_fail(c, path, "belongs to the multiphase scheme (scheme.name: multiphase)");
    TRY(load_phase(c, path, lv, y->phase, &o->phase));
  } else if (s->scheme == RHOD_SCHEME_MULTIPHASE) {
    o->phase = 0;
  }
  return RHOD_OK;
}

int rhod_ob_load(lctx *c, const y_open *open, unsigned n, const rhod_ob_levels *lv, rhod_scene *s) {
  if (!n)
    return RHOD_OK;
  if (!(s->open = calloc(n, sizeof *s->open)))
    return rhod_sl_fail_oom(c);
  s->n_open = n;
  for (unsigned i = 0; i < n; i++)
    TRY(load_open(c, &open[i], i, lv, s));
  return RHOD_OK;
}

void rhod_ob_bbox(const rhod_open_boundary *o, double lo[2], double hi[2]) {
  for (int a = 0; a < 2; a++)
    lo[a] = fmin(o->from[a], o->to[a]), hi[a] = fmax(o->from[a], o->to[a]);
}

/* The unit normal: the perpendicular of the segment on the side of the given normal, or
 * toward the domain's centre (docs/choices.md "open boundary: default normal"). */
static int resolve_normal(lctx *c, const char *base, const rhod_scene *s, const double *given,
                          rhod_open_boundary *o) {
  char path[96];
  const double L = hypot(o->to[0] - o->from[0], o->to[1] - o->from[1]);
  const double t[2] = {(o->to[0] - o->from[0]) / L, (o->to[1] - o->from[1]) / L};
  const double p[2] = {-t[1], t[0]};
  double side;
  if (given) {
    snprintf(path, sizeof path, "%s.normal", base);
    const double n = hypot(given[0], given[1]);
    if (!(n > 0))
      return rhod_sl_fail(c, path, "[%g, %g] is a zero vector", given[0], given[1]);
    if (fabs(given[0] * t[0] + given[1] * t[1]) > 0.99 * n)
      return rhod_sl_fail(c, path,
                          "[%g, %g] lies along the segment (from [%g, %g] to [%g, %g]): it "
                          "names the side the fluid is on",
                          given[0], given[1], o->from[0], o->from[1], o->to[0], o->to[1]);
    side = given[0] * p[0] + given[1] * p[1];
  } else {
    const double C[2] = {0.5 * (s->domain_min[0] + s->domain_max[0]),
                         0.5 * (s->domain_min[1] + s->domain_max[1])};
    side = (C[0] - o->from[0]) * p[0] + (C[1] - o->from[1]) * p[1];
    if (fabs(side) <= length_tol(s))
      return rhod_sl_fail(c, base,
                          "the domain's centre [%g, %g] lies on the segment's line: give normal "
                          "(the side the fluid is on)",
                          C[0], C[1]);
  }
  o->normal[0] = (side > 0 ? p[0] : -p[0]) + 0.0; /* + 0.0: no -0 */
  o->normal[1] = (side > 0 ? p[1] : -p[1]) + 0.0;
  return RHOD_OK;
}

/* Open boundary i against the domain, the fluid, the earlier open boundaries, the walls,
 * the bodies and the periodic axes. */
static int check_place(lctx *c, const rhod_scene *s, unsigned i) {
  const rhod_open_boundary *o = &s->open[i];
  char path[32];
  snprintf(path, sizeof path, "open_boundaries.%u", i);
  const double tol = length_tol(s);
  /* both ends in the domain box */
  for (int e = 0; e < 2; e++) {
    const double *x = e ? o->to : o->from;
    for (int a = 0; a < 2; a++) {
      const double ta = 1e-9 * fmax(1.0, s->domain_max[a] - s->domain_min[a]);
      if (x[a] < s->domain_min[a] - ta || x[a] > s->domain_max[a] + ta)
        return rhod_sl_fail(c, path, "%s [%g, %g] lies outside the domain [%g, %g]-[%g, %g]",
                            e ? "to" : "from", x[0], x[1], s->domain_min[0], s->domain_min[1],
                            s->domain_max[0], s->domain_max[1]);
    }
  }
  /* a periodic axis across it: the normal must be perpendicular to every periodic axis */
  for (int a = 0; a < 2; a++)
    if (s->periodic[a] && fabs(o->normal[a]) > 1e-9)
      return rhod_sl_fail(c, path,
                          "a periodic axis across it: its normal [%g, %g] has a component "
                          "along %c, which domain.periodic wraps",
                          o->normal[0], o->normal[1], a ? 'y' : 'x');
  /* the earlier open boundaries */
  for (unsigned j = 0; j < i; j++)
    if (segments_overlap(o->from, o->to, s->open[j].from, s->open[j].to, tol))
      return rhod_sl_fail(c, path, "overlaps open_boundaries.%u (%s)", j, s->open[j].name);
  /* the walls' and bodies' edges (at t = 0) */
  for (unsigned w = 0; w < s->n_walls + s->n_bodies; w++) {
    const int body = w >= s->n_walls;
    const rhod_body *B = body ? &s->bodies[w - s->n_walls] : NULL;
    const rhod_shape *sh = body ? &B->shape : &s->walls[w].shape;
    if (sh->kind == RHOD_SHAPE_CIRCLE)
      continue;
    unsigned n;
    double(*p)[2] = edges_of(sh, body ? B->center : NULL, body ? B->pose0 : NULL, &n);
    if (!p)
      return rhod_sl_fail_oom(c);
    unsigned hit = n;
    for (unsigned k = 0; k < n && hit == n; k++)
      if (segments_collinear_overlap(o->from, o->to, p[k], p[(k + 1) % n], tol))
        hit = k;
    free(p);
    if (hit < n) {
      if (body)
        return rhod_sl_fail(c, path,
                            "lies on bodies.%u (along its outline at t = 0): move the open "
                            "boundary off the body",
                            w - s->n_walls);
      return rhod_sl_fail(c, path,
                          "lies on walls.%u: remove that wall edge (a polygon wall) or the open "
                          "boundary",
                          w);
    }
  }
  /* the fluid behind it: points every particles.dx/2 along it, one dx behind */
  const double L = hypot(o->to[0] - o->from[0], o->to[1] - o->from[1]);
  const unsigned np = (unsigned)fmin(ceil(L / (0.5 * s->dx)), 1e6);
  for (unsigned k = 0; k < (np ? np : 1); k++) {
    const double f = (k + 0.5) / (np ? np : 1);
    const double x = o->from[0] + f * (o->to[0] - o->from[0]) - s->dx * o->normal[0];
    const double y = o->from[1] + f * (o->to[1] - o->from[1]) - s->dx * o->normal[1];
    for (unsigned b = 0; b < s->n_fluid; b++)
      if (rhod_shape_contains(&s->fluid[b].shape, x, y))
        return rhod_sl_fail(c, path,
                            "the fluid (fluid.%u) extends behind it: an open boundary lies on the "
                            "fluid's edge, its normal pointing into the fluid (normal [%g, %g])",
                            b, o->normal[0], o->normal[1]);
  }
  return RHOD_OK;
}

int rhod_ob_place(lctx *c, const y_open *open, rhod_scene *s) {
  for (unsigned i = 0; i < s->n_open; i++) {
    char base[32];
    snprintf(base, sizeof base, "open_boundaries.%u", i);
    TRY(resolve_normal(c, base, s, open[i].normal, &s->open[i]));
    TRY(check_place(c, s, i));
  }
  return RHOD_OK;
}

/* ---- the scene as run --------------------------------------------------------------------- */

void rhod_ob_tree(rhod_sl_tb *t, ry_node *root, const rhod_scene *s, const rhod_ob_levels *lv) {
  if (!s->n_open) /* absent without open boundaries, so older checkpoints resume */
    return;
  ry_node *list = rhod_sl_coll(t, root, "open_boundaries", RY_SEQ, 0);
  for (unsigned i = 0; i < s->n_open; i++) {
    const rhod_open_boundary *o = &s->open[i];
    ry_node *e = rhod_sl_coll(t, list, NULL, RY_MAP, 0);
    rhod_sl_word(t, e, "name", o->name);
    rhod_sl_word(t, e, "kind", kind_word(o->kind));
    rhod_sl_vec(t, e, "from", o->from);
    rhod_sl_vec(t, e, "to", o->to);
    rhod_sl_vec(t, e, "normal", o->normal);
    if (o->kind == RHOD_OPEN_INFLOW) {
      rhod_sl_word(t, e, "velocity", o->velocity);
      rhod_sl_word(t, e, "profile",
                   rhod_sl_enum_name(profile_names, CYAML_ARRAY_LEN(profile_names), o->profile));
    }
    if (o->surface_set)
      rhod_sl_num(t, e, "surface", o->surface);
    if (o->pressure != 0) /* absent at its default, so older checkpoints resume */
      rhod_sl_num(t, e, "pressure", o->pressure);
    rhod_sl_num(t, e, "dx", o->dx);
    if (s->scheme == RHOD_SCHEME_MULTIPHASE)
      rhod_sl_word(t, e, "phase", lv->phases[o->phase]);
  }
}

void rhod_ob_free(rhod_scene *s) {
  for (unsigned i = 0; i < s->n_open; i++) {
    free(s->open[i].name);
    free(s->open[i].velocity);
  }
  free(s->open);
  s->open = NULL;
  s->n_open = 0;
}
