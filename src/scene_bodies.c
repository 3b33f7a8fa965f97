/* The `bodies` section of a scene (issue 51): rigid bodies whose boundary the engine models
 * by ghost particles (paper 002 Sec. IV A; docs/scene.md "bodies"). Their schema, value
 * checks, resolved defaults (centre, mass, inertia; docs/choices.md), the placement checks
 * (domain, other bodies, walls) and their part of the scene as run. The mechanism (schema
 * validation, messages, `--set`, the scene as run) is src/scene.c's. Motion laws are
 * libmatheval expressions of t, validated here and kept as text. */
#define _POSIX_C_SOURCE 200809L

#include "scene_bodies.h"
#include "rhod/boundary.h"

#include <math.h>
#include <matheval.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define OPT (CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL)
#define NUM_OPT(key, st, member) CYAML_FIELD_FLOAT_PTR(key, OPT | CYAML_FLAG_STRICT, st, member)
#define VEC_OPT(key, st, member)                                                                   \
  CYAML_FIELD_SEQUENCE_FIXED(key, OPT | CYAML_FLAG_FLOW, st, member, &rhod_sl_sch_float, 2)
#define BODY_NAME_MAX 64

/* ---- schema --------------------------------------------------------------------------- */

static const cyaml_strval_t slip_names[] = {
    {"free", RHOD_SLIP_FREE},
    {"no", RHOD_SLIP_NO},
};
static const cyaml_strval_t motion_names[] = {
    {"fixed", RHOD_MOTION_FIXED},
    {"imposed", RHOD_MOTION_IMPOSED},
    {"free", RHOD_MOTION_FREE},
};
static const cyaml_strval_t dof_names[] = {
    {"x", RHOD_DOF_X},
    {"y", RHOD_DOF_Y},
    {"theta", RHOD_DOF_THETA},
};
static const char *const dof_keys[RHOD_NDOF] = {"x", "y", "theta"};

static const cyaml_schema_value_t sch_dof = {
    CYAML_VALUE_ENUM(CYAML_FLAG_STRICT, int, dof_names, CYAML_ARRAY_LEN(dof_names))};

static const cyaml_schema_field_t f_law[] = {
    CYAML_FIELD_STRING_PTR("x", OPT, y_body_law, x, 1, CYAML_UNLIMITED),
    CYAML_FIELD_STRING_PTR("y", OPT, y_body_law, y, 1, CYAML_UNLIMITED),
    CYAML_FIELD_STRING_PTR("theta", OPT, y_body_law, theta, 1, CYAML_UNLIMITED),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t f_body[] = {
    CYAML_FIELD_STRING_PTR("name", OPT, y_body, name, 1, BODY_NAME_MAX),
    RHOD_SL_SHAPE_FIELDS(y_body),
    CYAML_FIELD_ENUM_PTR("slip", OPT | CYAML_FLAG_STRICT, y_body, slip, slip_names,
                         CYAML_ARRAY_LEN(slip_names)),
    CYAML_FIELD_BOOL_PTR("refine", OPT, y_body, refine),
    CYAML_FIELD_ENUM_PTR("motion", OPT | CYAML_FLAG_STRICT, y_body, motion, motion_names,
                         CYAML_ARRAY_LEN(motion_names)),
    VEC_OPT("center", y_body, center),
    CYAML_FIELD_MAPPING_PTR("law", OPT | CYAML_FLAG_FLOW, y_body, law, f_law),
    NUM_OPT("mass", y_body, mass),
    NUM_OPT("density", y_body, density),
    NUM_OPT("inertia", y_body, inertia),
    NUM_OPT("added_mass", y_body, added_mass),
    CYAML_FIELD_SEQUENCE_COUNT("lock", OPT | CYAML_FLAG_FLOW, y_body, lock, n_lock, &sch_dof, 0,
                               RHOD_NDOF),
    VEC_OPT("velocity", y_body, velocity),
    NUM_OPT("omega", y_body, omega),
    CYAML_FIELD_END,
};
const cyaml_schema_value_t rhod_bd_sch_body = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_body, f_body)};

/* ---- geometry --------------------------------------------------------------------------- */

/* Centroid of a simple counter-clockwise polygon (area-weighted), about its first vertex
 * for round-off. */
static void polygon_centroid(const double (*p)[2], unsigned n, double G[2]) {
  double a = 0, cx = 0, cy = 0;
  for (unsigned i = 0; i < n; i++) {
    const double x0 = p[i][0] - p[0][0], y0 = p[i][1] - p[0][1];
    const double x1 = p[(i + 1) % n][0] - p[0][0], y1 = p[(i + 1) % n][1] - p[0][1];
    const double cr = x0 * y1 - x1 * y0;
    a += cr;
    cx += (x0 + x1) * cr;
    cy += (y0 + y1) * cr;
  }
  G[0] = p[0][0] + cx / (3 * a);
  G[1] = p[0][1] + cy / (3 * a);
}

/* Polar second moment of area of a simple counter-clockwise polygon about the point c:
 * the integral of |x - c|^2 over it, (1/12) sum (x_i y_{i+1} - x_{i+1} y_i)
 * (x_i^2 + x_i x_{i+1} + x_{i+1}^2 + y_i^2 + y_i y_{i+1} + y_{i+1}^2) with x taken from c. */
static double polygon_polar_moment(const double (*p)[2], unsigned n, const double c[2]) {
  double J = 0;
  for (unsigned i = 0; i < n; i++) {
    const double x0 = p[i][0] - c[0], y0 = p[i][1] - c[1];
    const double x1 = p[(i + 1) % n][0] - c[0], y1 = p[(i + 1) % n][1] - c[1];
    J += (x0 * y1 - x1 * y0) * (x0 * x0 + x0 * x1 + x1 * x1 + y0 * y0 + y0 * y1 + y1 * y1);
  }
  return J / 12;
}

/* A body's or wall's outline where it stands: a circle, or a counter-clockwise polygon
 * (a rect's four corners). */
typedef struct {
  int circle;
  double c[2], r;
  double (*p)[2];
  unsigned n;
  double lo[2], hi[2];
} outline;

/* The outline of shape sh moved by pose (d_x, d_y, theta) about G: x' = G + d + R(theta)
 * (x - G); exactly the shape at pose zero. Returns 0 when out of memory. */
static int make_outline(const rhod_shape *sh, const double G[2], const double pose[RHOD_NDOF],
                        outline *o) {
  const int moved = pose[0] != 0 || pose[1] != 0 || pose[2] != 0;
  const double cs = cos(pose[2]), sn = sin(pose[2]);
  memset(o, 0, sizeof *o);
  if (sh->kind == RHOD_SHAPE_CIRCLE) {
    o->circle = 1;
    o->r = sh->radius;
    o->c[0] = sh->center[0], o->c[1] = sh->center[1];
    if (moved) {
      const double rx = sh->center[0] - G[0], ry = sh->center[1] - G[1];
      o->c[0] = G[0] + pose[0] + cs * rx - sn * ry;
      o->c[1] = G[1] + pose[1] + sn * rx + cs * ry;
    }
    for (int a = 0; a < 2; a++)
      o->lo[a] = o->c[a] - o->r, o->hi[a] = o->c[a] + o->r;
    return 1;
  }
  if (!(o->p = rhod_sl_shape_vertices(sh, &o->n)))
    return 0;
  for (unsigned k = 0; k < o->n; k++) {
    if (moved) {
      const double rx = o->p[k][0] - G[0], ry = o->p[k][1] - G[1];
      o->p[k][0] = G[0] + pose[0] + cs * rx - sn * ry;
      o->p[k][1] = G[1] + pose[1] + sn * rx + cs * ry;
    }
    for (int a = 0; a < 2; a++) {
      o->lo[a] = k ? fmin(o->lo[a], o->p[k][a]) : o->p[k][a];
      o->hi[a] = k ? fmax(o->hi[a], o->p[k][a]) : o->p[k][a];
    }
  }
  return 1;
}

static void body_outline_pose(const rhod_body *b, outline *o, int *ok) {
  *ok = make_outline(&b->shape, b->center, b->pose0, o);
}

static double seg_dist(const double *p, const double *a, const double *b) {
  const double ux = b[0] - a[0], uy = b[1] - a[1], wx = p[0] - a[0], wy = p[1] - a[1];
  const double L2 = ux * ux + uy * uy;
  double s = L2 > 0 ? (wx * ux + wy * uy) / L2 : 0;
  s = s < 0 ? 0 : s > 1 ? 1 : s;
  return hypot(wx - s * ux, wy - s * uy);
}

/* Whether the point lies inside the outline or on it (even-odd rule for polygons). */
static int outline_holds(const outline *o, const double *q) {
  if (o->circle)
    return hypot(q[0] - o->c[0], q[1] - o->c[1]) <= o->r;
  int in = 0;
  for (unsigned a = 0, b = o->n - 1; a < o->n; b = a++) {
    const double *P = o->p[a], *Q = o->p[b];
    if (seg_dist(q, P, Q) == 0)
      return 1;
    if (RHOD_RAY_CROSSES(P[0], P[1], Q[0], Q[1], q[0], q[1]))
      in = !in;
  }
  return in;
}

/* Whether the two outlines (the boundaries) meet: cross or touch. */
static int outlines_meet(const outline *A, const outline *B) {
  if (A->circle && B->circle) {
    const double d = hypot(A->c[0] - B->c[0], A->c[1] - B->c[1]);
    return d <= A->r + B->r && d >= fabs(A->r - B->r);
  }
  if (A->circle || B->circle) {
    const outline *C = A->circle ? A : B, *P = A->circle ? B : A;
    for (unsigned k = 0; k < P->n; k++) {
      const double *a = P->p[k], *b = P->p[(k + 1) % P->n];
      const double far =
          fmax(hypot(a[0] - C->c[0], a[1] - C->c[1]), hypot(b[0] - C->c[0], b[1] - C->c[1]));
      if (seg_dist(C->c, a, b) <= C->r && far >= C->r)
        return 1;
    }
    return 0;
  }
  for (unsigned i = 0; i < A->n; i++)
    for (unsigned j = 0; j < B->n; j++)
      if (rhod_sl_segments_meet(A->p[i], A->p[(i + 1) % A->n], B->p[j], B->p[(j + 1) % B->n]))
        return 1;
  return 0;
}

/* A point of the outline itself. */
static void outline_point(const outline *o, double q[2]) {
  if (o->circle)
    q[0] = o->c[0] + o->r, q[1] = o->c[1];
  else
    q[0] = o->p[0][0], q[1] = o->p[0][1];
}

/* Whether A lies inside B, when the outlines do not meet. */
static int outline_inside(const outline *A, const outline *B) {
  double q[2];
  outline_point(A, q);
  return outline_holds(B, q);
}

void rhod_bd_bbox(const rhod_body *b, double lo[2], double hi[2]) {
  outline o;
  int ok;
  body_outline_pose(b, &o, &ok);
  if (!ok) { /* out of memory: the shape at rest, which the later checks refuse anyway */
    rhod_sl_shape_bbox(&b->shape, lo, hi);
    return;
  }
  memcpy(lo, o.lo, sizeof o.lo);
  memcpy(hi, o.hi, sizeof o.hi);
  free(o.p);
}

/* ---- checks and defaults ---------------------------------------------------------------- */

static const char *motion_word(rhod_motion_kind m) {
  return rhod_sl_enum_name(motion_names, CYAML_ARRAY_LEN(motion_names), (int)m);
}

/* ---- the laws' syntax ------------------------------------------------------------------- */

/* libmatheval's parser leaks its nodes on a syntax error and its scanner echoes a character
 * it has no rule for to stdout, so a law is parsed here first, by libmatheval's grammar
 * (GNU libmatheval 1.1: expression ::= NUMBER | CONSTANT | VARIABLE | FUNCTION ( expr ) |
 * ( expr ) | - expr | expr {+ - * / ^} expr; its scanner's longest match), and handed to
 * evaluator_create only when it parses. */
static const char *const law_functions[] = {
    "exp",   "log",   "sqrt",  "sin",  "cos",  "tan",   "cot",      "sec",
    "csc",   "asin",  "acos",  "atan", "acot", "asec",  "acsc",     "sinh",
    "cosh",  "tanh",  "coth",  "sech", "csch", "asinh", "acosh",    "atanh",
    "acoth", "asech", "acsch", "abs",  "step", "delta", "nandelta", "erf"};
/* the constants whose names start with a digit (the others scan as identifiers) */
static const char *const law_digit_constants[] = {"1_pi", "2_pi", "2_sqrtpi"};
#define LAW_MAX_LEN 1000 /* characters of a law */
#define LAW_MAX_DEPTH 64 /* nested parentheses */

enum { TK_END, TK_ATOM, TK_FUNC, TK_OP, TK_MINUS, TK_LP, TK_RP, TK_BAD };

static size_t digits(const char *p) {
  size_t n = 0;
  while (p[n] >= '0' && p[n] <= '9')
    n++;
  return n;
}

static int ident_char(char ch, int first) {
  return ch == '_' || (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
         (!first && ch >= '0' && ch <= '9');
}

/* The token at text[*i] (spaces and tabs skipped; *at its start), *i moved past it. */
static int law_token(const char *s, size_t *i, size_t *at) {
  while (s[*i] == ' ' || s[*i] == '\t')
    (*i)++;
  *at = *i;
  const char *p = s + *i;
  if (!*p)
    return TK_END;
  if ((*p >= '0' && *p <= '9') || *p == '.') {
    /* number: {d}+ | {d}+.{d}* | {d}*.{d}+, then ([Ee][+-]?{d}+)? */
    size_t n = digits(p), len = n;
    if (p[n] == '.') {
      const size_t m = digits(p + n + 1);
      len = n || m ? n + 1 + m : 0;
    }
    if (len && (p[len] == 'e' || p[len] == 'E')) {
      size_t j = len + 1 + (p[len + 1] == '+' || p[len + 1] == '-');
      if (digits(p + j))
        len = j + digits(p + j);
    }
    for (size_t k = 0; k < sizeof law_digit_constants / sizeof law_digit_constants[0]; k++) {
      const size_t cl = strlen(law_digit_constants[k]);
      if (cl > len && strncmp(p, law_digit_constants[k], cl) == 0)
        len = cl;
    }
    *i += len;
    return len ? TK_ATOM : TK_BAD;
  }
  if (ident_char(*p, 1)) {
    size_t n = 1;
    while (ident_char(p[n], 0))
      n++;
    *i += n;
    for (size_t k = 0; k < sizeof law_functions / sizeof law_functions[0]; k++)
      if (strlen(law_functions[k]) == n && strncmp(p, law_functions[k], n) == 0)
        return TK_FUNC;
    return TK_ATOM; /* a constant or a variable */
  }
  (*i)++;
  switch (*p) {
  case '+':
  case '*':
  case '/':
  case '^':
    return TK_OP;
  case '-':
    return TK_MINUS;
  case '(':
    return TK_LP;
  case ')':
    return TK_RP;
  default:
    return TK_BAD;
  }
}

/* expr ::= unary ({+ - * / ^} unary)*, unary ::= -* primary, primary ::= ATOM |
 * FUNC ( expr ) | ( expr ). Returns 1 when it parses; else 0 with *bad the offending
 * token's offset. */
static int law_expr(const char *s, size_t *i, int depth, size_t *bad) {
  size_t at;
  for (;;) {
    int tk;
    while ((tk = law_token(s, i, &at)) == TK_MINUS)
      ;
    if (tk == TK_FUNC) {
      tk = law_token(s, i, &at);
      if (tk != TK_LP)
        return *bad = at, 0;
    }
    if (tk == TK_LP) {
      if (depth >= LAW_MAX_DEPTH || !law_expr(s, i, depth + 1, bad))
        return depth >= LAW_MAX_DEPTH ? (*bad = at, 0) : 0;
      if (law_token(s, i, &at) != TK_RP)
        return *bad = at, 0;
    } else if (tk != TK_ATOM) {
      return *bad = at, 0;
    }
    const size_t before = *i;
    tk = law_token(s, i, &at);
    if (tk != TK_OP && tk != TK_MINUS) {
      *i = before; /* the caller's token */
      return 1;
    }
  }
}

/* Whether text parses as libmatheval would parse it; else *bad is where it stops. */
static int law_parses(const char *text, size_t *bad) {
  size_t i = 0, at;
  if (!law_expr(text, &i, 0, bad))
    return 0;
  if (law_token(text, &i, &at) != TK_END)
    return *bad = at, 0;
  return 1;
}

/* bodies.N.law.K (and open_boundaries.N.velocity, src/scene_open.c): an expression of t
 * alone (libmatheval), whose value, first and second derivatives are finite at t = 0; *v0
 * its value there. */
int rhod_bd_check_law(lctx *c, const char *path, const char *text, double *v0) {
  const int cut = strlen(text) > 80;
  if (strlen(text) > LAW_MAX_LEN)
    return rhod_sl_fail(c, path, "longer than %d characters", LAW_MAX_LEN);
  size_t bad = 0;
  if (!law_parses(text, &bad)) {
    char near[16];
    snprintf(near, sizeof near, "%.8s", text + bad);
    return rhod_sl_fail(c, path,
                        "'%.80s%s' is not an expression of t (libmatheval syntax, e.g. "
                        "0.1*sin(2*pi*t)): %s%s%s at character %zu",
                        text, cut ? "..." : "", near[0] ? "unexpected '" : "it ends early", near,
                        near[0] ? "'" : "", bad + 1);
  }
  char *copy = strdup(text);
  if (!copy)
    return rhod_sl_fail_oom(c);
  void *ev = evaluator_create(copy);
  free(copy);
  if (!ev) /* parsed above: only when out of memory */
    return rhod_sl_fail(c, path, "'%.80s%s': libmatheval cannot read it", text, cut ? "..." : "");
  char **names = NULL;
  int count = 0;
  evaluator_get_variables(ev, &names, &count);
  for (int i = 0; i < count; i++)
    if (strcmp(names[i], "t") != 0) {
      int rc =
          rhod_sl_fail(c, path, "unknown variable '%.64s' in '%.80s%s' (only t, the time in s)",
                       names[i], text, cut ? "..." : "");
      evaluator_destroy(ev);
      return rc;
    }
  static const char *const what[3] = {"its value", "its first derivative", "its second derivative"};
  void *f[3] = {ev, NULL, NULL};
  f[1] = evaluator_derivative(ev, "t");
  f[2] = f[1] ? evaluator_derivative(f[1], "t") : NULL;
  int rc = f[1] && f[2] ? RHOD_OK : rhod_sl_fail_oom(c);
  char t_name[] = "t";
  char *vn[1] = {t_name};
  for (int k = 0; k < 3 && rc == RHOD_OK; k++) {
    double t0[1] = {0};
    const double v = evaluator_evaluate(f[k], 1, vn, t0);
    if (k == 0)
      *v0 = v;
    if (!isfinite(v))
      rc = rhod_sl_fail(c, path, "'%.80s%s': %s at t = 0 is %g, not finite", text, cut ? "..." : "",
                        what[k], v);
  }
  for (int k = 0; k < 3; k++)
    if (f[k])
      evaluator_destroy(f[k]);
  return rc;
}

/* Whether an outline leaves the domain box along a non-periodic axis (a body may cross a
 * periodic boundary). */
static int outside_domain(const rhod_scene *s, const outline *o) {
  for (int a = 0; a < 2; a++) {
    if (s->periodic[a])
      continue;
    const double tol = 1e-9 * fmax(1.0, s->domain_max[a] - s->domain_min[a]);
    if (o->lo[a] < s->domain_min[a] - tol || o->hi[a] > s->domain_max[a] + tol)
      return 1;
  }
  return 0;
}

/* Body i where it stands at t = 0 against the domain, the earlier bodies and the walls. */
static int check_place(lctx *c, const rhod_scene *s, unsigned i) {
  char path[32];
  snprintf(path, sizeof path, "bodies.%u", i);
  outline A, B;
  int ok, rc = RHOD_OK;
  body_outline_pose(&s->bodies[i], &A, &ok);
  if (!ok)
    return rhod_sl_fail_oom(c);
  if (s->has_domain && outside_domain(s, &A))
    rc = rhod_sl_fail(c, path,
                      "lies outside the domain [%g, %g]-[%g, %g] (at t = 0 the body spans [%g, "
                      "%g]-[%g, %g])",
                      s->domain_min[0], s->domain_min[1], s->domain_max[0], s->domain_max[1],
                      A.lo[0], A.lo[1], A.hi[0], A.hi[1]);
  for (unsigned j = 0; j < i && rc == RHOD_OK; j++) {
    body_outline_pose(&s->bodies[j], &B, &ok);
    if (!ok) {
      rc = rhod_sl_fail_oom(c);
      break;
    }
    if (outlines_meet(&A, &B))
      rc = rhod_sl_fail(c, path, "overlaps bodies.%u at t = 0 (their outlines meet)", j);
    else if (outline_inside(&A, &B) || outline_inside(&B, &A))
      rc = rhod_sl_fail(c, path, "overlaps bodies.%u at t = 0 (one lies inside the other)", j);
    free(B.p);
  }
  static const double rest[RHOD_NDOF] = {0, 0, 0};
  for (unsigned w = 0; w < s->n_walls && rc == RHOD_OK; w++) {
    const rhod_wall *W = &s->walls[w];
    if (!make_outline(&W->shape, W->shape.center, rest, &B)) {
      rc = rhod_sl_fail_oom(c);
      break;
    }
    if (outlines_meet(&A, &B))
      rc = rhod_sl_fail(c, path, "crosses the boundary of walls.%u at t = 0 (their outlines meet)",
                        w);
    else if (W->fluid_inside && !outline_inside(&A, &B))
      rc = rhod_sl_fail(c, path, "lies outside the container walls.%u at t = 0", w);
    else if (!W->fluid_inside && (outline_inside(&A, &B) || outline_inside(&B, &A)))
      rc = rhod_sl_fail(c, path, "overlaps the obstacle walls.%u at t = 0", w);
    free(B.p);
  }
  free(A.p);
  return rc;
}

/* The keys of one motion kind given to a body of another: "only for motion: K". */
static int check_only_for(lctx *c, const char *base, const y_body *y, rhod_motion_kind m) {
  char path[96];
  if (y->law && m != RHOD_MOTION_IMPOSED) {
    snprintf(path, sizeof path, "%s.law", base);
    return rhod_sl_fail(c, path, "only for motion: imposed (this body's motion is %s)",
                        motion_word(m));
  }
  const struct {
    const void *given;
    const char *key;
  } fr[] = {{y->mass, "mass"},
            {y->density, "density"},
            {y->inertia, "inertia"},
            {y->lock, "lock"},
            {y->velocity, "velocity"},
            {y->omega, "omega"},
            {y->added_mass, "added_mass"}};
  for (size_t k = 0; k < sizeof fr / sizeof fr[0] && m != RHOD_MOTION_FREE; k++)
    if (fr[k].given) {
      snprintf(path, sizeof path, "%s.%s", base, fr[k].key);
      return rhod_sl_fail(c, path, "only for motion: free (this body's motion is %s)",
                          motion_word(m));
    }
  return RHOD_OK;
}

static int positive(lctx *c, const char *base, const char *key, double v) {
  char path[96];
  snprintf(path, sizeof path, "%s.%s", base, key);
  return v > 0 ? RHOD_OK : rhod_sl_fail(c, path, "must be > 0, got %g", v);
}

/* mass, density, inertia, lock, velocity and omega of a free body. The default inertia is
 * the shape's polar second moment of area about the centre times mass/area (uniform
 * density; docs/choices.md "body inertia"). */
static int load_free(lctx *c, const char *base, const y_body *y, rhod_body *b) {
  char path[96];
  if (!y->mass && !y->density)
    return rhod_sl_fail_missing(c, base, "mass", "or density: a free body needs one");
  if (y->mass)
    TRY(positive(c, base, "mass", *y->mass));
  if (y->density)
    TRY(positive(c, base, "density", *y->density));
  const double area = rhod_sl_shape_area(&b->shape);
  if (y->density) {
    b->density = *y->density;
    b->mass = b->density * area;
    /* both: only as the scene as run writes them, mass = density x area */
    if (y->mass && !(fabs(*y->mass - b->mass) <= 1e-12 * b->mass)) {
      snprintf(path, sizeof path, "%s.mass", base);
      return rhod_sl_fail(c, path,
                          "give mass or density, not both (mass %g differs from density x area "
                          "= %g kg/m)",
                          *y->mass, b->mass);
    }
  } else {
    b->mass = *y->mass;
  }
  if (y->inertia) {
    TRY(positive(c, base, "inertia", *y->inertia));
    b->inertia = *y->inertia;
  } else if (b->shape.kind == RHOD_SHAPE_CIRCLE) {
    const double dx = b->shape.center[0] - b->center[0], dy = b->shape.center[1] - b->center[1];
    const double r = b->shape.radius;
    b->inertia = b->mass * (0.5 * r * r + dx * dx + dy * dy);
  } else {
    unsigned n;
    double(*p)[2] = rhod_sl_shape_vertices(&b->shape, &n);
    if (!p)
      return rhod_sl_fail_oom(c);
    b->inertia = polygon_polar_moment((const double(*)[2])p, n, b->center) * b->mass / area;
    free(p);
  }
  b->added_mass = -1; /* rho0 x area, resolved by the run */
  if (y->added_mass) {
    snprintf(path, sizeof path, "%s.added_mass", base);
    if (!(*y->added_mass >= 0))
      return rhod_sl_fail(c, path, "must be >= 0 (kg/m; 0: no relaxation), got %g", *y->added_mass);
    b->added_mass = *y->added_mass;
  }
  if (!(b->inertia > 0 && isfinite(b->inertia) && isfinite(b->mass))) {
    snprintf(path, sizeof path, "%s", base);
    return rhod_sl_fail(c, path, "mass %g kg/m and inertia %g kg m must be finite and > 0", b->mass,
                        b->inertia);
  }
  for (unsigned k = 0; k < y->n_lock; k++) {
    const int d = y->lock[k];
    if (b->lock[d]) {
      snprintf(path, sizeof path, "%s.lock.%u", base, k);
      return rhod_sl_fail(c, path, "'%s' is named twice", dof_keys[d]);
    }
    b->lock[d] = 1;
  }
  if (y->velocity)
    memcpy(b->velocity, y->velocity, sizeof b->velocity);
  b->omega = y->omega ? *y->omega : 0;
  return RHOD_OK;
}

static int load_body(lctx *c, const y_body *y, unsigned i, rhod_scene *s) {
  rhod_body *b = &s->bodies[i];
  char base[32], path[96];
  snprintf(base, sizeof base, "bodies.%u", i);
  TRY(rhod_sl_load_shape(c, base, y->rect, y->circle, y->polygon, y->n_polygon, &b->shape));
  /* name: an identifier, unique among the bodies (probes.csv columns NAME_Fx ...) */
  TRY(rhod_sl_list_name(c, base, y->name, "a body", "body", i, &b->name, path, sizeof path));
  for (unsigned j = 0; j < i; j++)
    if (strcmp(b->name, s->bodies[j].name) == 0)
      return rhod_sl_fail(c, path, "the name '%s' is also bodies.%u's (names must differ)", b->name,
                          j);
  b->slip = y->slip ? (rhod_slip)*y->slip : RHOD_SLIP_FREE;
  b->refine = opt_bool(y->refine, 1);
  b->motion = y->motion ? (rhod_motion_kind)*y->motion : RHOD_MOTION_FIXED;
  /* center: the shape's centroid by default (area-weighted for a polygon) */
  if (y->center) {
    memcpy(b->center, y->center, sizeof b->center);
  } else if (b->shape.kind == RHOD_SHAPE_CIRCLE) {
    memcpy(b->center, b->shape.center, sizeof b->center);
  } else if (b->shape.kind == RHOD_SHAPE_RECT) {
    b->center[0] = 0.5 * (b->shape.min[0] + b->shape.max[0]);
    b->center[1] = 0.5 * (b->shape.min[1] + b->shape.max[1]);
  } else {
    polygon_centroid((const double(*)[2])b->shape.points, b->shape.n_points, b->center);
  }
  TRY(check_only_for(c, base, y, b->motion));
  if (b->motion == RHOD_MOTION_IMPOSED && y->law) {
    const char *const text[RHOD_NDOF] = {y->law->x, y->law->y, y->law->theta};
    for (int k = 0; k < RHOD_NDOF; k++) {
      if (!text[k])
        continue;
      snprintf(path, sizeof path, "%s.law.%s", base, dof_keys[k]);
      TRY(rhod_bd_check_law(c, path, text[k], &b->pose0[k]));
      if (!(b->law[k] = strdup(text[k])))
        return rhod_sl_fail_oom(c);
    }
  }
  if (b->motion == RHOD_MOTION_FREE)
    TRY(load_free(c, base, y, b));
  return RHOD_OK;
}

int rhod_bd_load(lctx *c, const y_body *bodies, unsigned n, rhod_scene *s) {
  if (!n)
    return RHOD_OK;
  if (!(s->bodies = calloc(n, sizeof *s->bodies)))
    return rhod_sl_fail_oom(c);
  s->n_bodies = n;
  for (unsigned i = 0; i < n; i++) {
    TRY(load_body(c, &bodies[i], i, s));
    TRY(check_place(c, s, i));
  }
  return RHOD_OK;
}

/* ---- the scene as run --------------------------------------------------------------------- */

void rhod_bd_tree(rhod_sl_tb *t, ry_node *root, const rhod_scene *s) {
  if (!s->n_bodies) /* absent without bodies, so older checkpoints resume */
    return;
  ry_node *list = rhod_sl_coll(t, root, "bodies", RY_SEQ, 0);
  for (unsigned i = 0; i < s->n_bodies; i++) {
    const rhod_body *b = &s->bodies[i];
    ry_node *e = rhod_sl_coll(t, list, NULL, RY_MAP, 0);
    rhod_sl_word(t, e, "name", b->name);
    rhod_sl_shape(t, e, &b->shape);
    rhod_sl_word(t, e, "slip", rhod_sl_enum_name(slip_names, CYAML_ARRAY_LEN(slip_names), b->slip));
    rhod_sl_bool(t, e, "refine", b->refine);
    rhod_sl_word(t, e, "motion", motion_word(b->motion));
    rhod_sl_vec(t, e, "center", b->center);
    if (b->law[0] || b->law[1] || b->law[2]) { /* the texts as given */
      ry_node *law = rhod_sl_coll(t, e, "law", RY_MAP, 1);
      for (int k = 0; k < RHOD_NDOF; k++)
        if (b->law[k])
          rhod_sl_word(t, law, dof_keys[k], b->law[k]);
    }
    if (b->motion != RHOD_MOTION_FREE)
      continue;
    rhod_sl_num(t, e, "mass", b->mass);
    if (b->density > 0) /* with the mass it gives, so that it reads back the same */
      rhod_sl_num(t, e, "density", b->density);
    rhod_sl_num(t, e, "inertia", b->inertia);
    if (b->added_mass >= 0)
      rhod_sl_num(t, e, "added_mass", b->added_mass);
    ry_node *lock = rhod_sl_coll(t, e, "lock", RY_SEQ, 1);
    for (int k = 0; k < RHOD_NDOF; k++)
      if (b->lock[k])
        rhod_sl_word(t, lock, NULL, dof_keys[k]);
    rhod_sl_vec(t, e, "velocity", b->velocity);
    rhod_sl_num(t, e, "omega", b->omega);
  }
}

void rhod_bd_free(rhod_scene *s) {
  for (unsigned i = 0; i < s->n_bodies; i++) {
    free(s->bodies[i].name);
    free(s->bodies[i].shape.points);
    for (int k = 0; k < RHOD_NDOF; k++)
      free(s->bodies[i].law[k]);
  }
  free(s->bodies);
  s->bodies = NULL;
  s->n_bodies = 0;
}
