/* Wall geometry from a scene: segments with their fluid-side normals, the corners
 * that need a double mirror, circles, and the domain box. Host side. */
#include "rhod/boundary.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Edge k (pt[k] to pt[k + 1]) moves at vel when bit k of `moving` is set. */
static int push_polygon(real **seg, int *nseg, int32_t **corner, int *ncorner,
                        const double (*pt)[2], unsigned np, int fluid_inside, int noslip,
                        const double vel[2], unsigned moving, int body, int refine) {
  /* orientation: signed area > 0 for counter-clockwise */
  double area = 0;
  for (unsigned k = 0; k < np; k++) {
    const double *a = pt[k], *b = pt[(k + 1) % np];
    area += a[0] * b[1] - b[0] * a[1];
  }
  const double side = (area > 0 ? 1.0 : -1.0) * (fluid_inside ? 1.0 : -1.0);
  const int first = *nseg;
  real *s = realloc(*seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)(*nseg + (int)np));
  if (!s)
    return RHOD_ERR_MEMORY;
  *seg = s;
  for (unsigned k = 0; k < np; k++) {
    const double *a = pt[k], *b = pt[(k + 1) % np];
    const double tx = b[0] - a[0], ty = b[1] - a[1], len = hypot(tx, ty);
    if (!(len > 0))
      continue;
    real *S = s + RHOD_SEG_STRIDE * (*nseg);
    S[0] = (real)a[0];
    S[1] = (real)a[1];
    /* left normal (-ty, tx) points inside a counter-clockwise polygon */
    S[2] = (real)(-ty / len * side);
    S[3] = (real)(tx / len * side);
    S[4] = (real)(tx / len);
    S[5] = (real)(ty / len);
    S[6] = (real)len;
    S[7] = (real)noslip;
    const int moves = k < 32 && ((moving >> k) & 1u);
    S[8] = moves ? (real)vel[0] : 0;
    S[9] = moves ? (real)vel[1] : 0;
    S[10] = (real)body;
    S[13] = (real)refine;
    /* shares at convex vertices (ghosts.c face_share): bodies and obstacle walls, the
     * outlines with the fluid outside */
    S[14] = body >= 0 || !fluid_inside;
    (*nseg)++;
  }
  /* corners: edge k ends where edge k+1 starts; the fluid wedge there is narrower
   * than a half plane (needs a double mirror) when n_k . t_{k+1} > 0 */
  const int ne = *nseg - first;
  for (int k = 0; k < ne; k++) {
    s[RHOD_SEG_STRIDE * (first + k) + 11] = (real)first;
    s[RHOD_SEG_STRIDE * (first + k) + 12] = (real)ne;
  }
  for (int k = 0; k < ne; k++) {
    const int a = first + k, b = first + (k + 1) % ne;
    const real *A = s + RHOD_SEG_STRIDE * a, *B = s + RHOD_SEG_STRIDE * b;
    if (A[2] * B[4] + A[3] * B[5] > 1e-9) {
      int32_t *c = realloc(*corner, sizeof(int32_t) * 2 * (size_t)(*ncorner + 1));
      if (!c)
        return RHOD_ERR_MEMORY;
      *corner = c;
      c[2 * *ncorner] = a;
      c[2 * *ncorner + 1] = b;
      (*ncorner)++;
    }
  }
  return RHOD_OK;
}

/* Appends one shape's boundary: body -1 for a wall. */
static int push_shape(rhod_boundary *b, const rhod_shape *sh, int fluid_inside, int noslip,
                      const double vel[2], unsigned moving, int body, int refine) {
  if (sh->kind == RHOD_SHAPE_RECT) {
    const double *m = sh->min, *M = sh->max;
    const double pts[4][2] = {{m[0], m[1]}, {M[0], m[1]}, {M[0], M[1]}, {m[0], M[1]}};
    return push_polygon(&b->seg, &b->nseg, &b->corner, &b->ncorner, pts, 4, fluid_inside, noslip,
                        vel, moving, body, refine);
  }
  if (sh->kind == RHOD_SHAPE_POLYGON)
    return push_polygon(&b->seg, &b->nseg, &b->corner, &b->ncorner, (const double(*)[2])sh->points,
                        sh->n_points, fluid_inside, noslip, vel, moving, body, refine);
  real *c = realloc(b->circ, sizeof(real) * RHOD_CIRC_STRIDE * (size_t)(b->ncirc + 1));
  if (!c)
    return RHOD_ERR_MEMORY;
  b->circ = c;
  real *C = c + RHOD_CIRC_STRIDE * b->ncirc;
  C[0] = (real)sh->center[0];
  C[1] = (real)sh->center[1];
  C[2] = (real)sh->radius;
  C[3] = fluid_inside ? 1 : -1;
  C[4] = (real)noslip;
  C[5] = (real)body;
  C[6] = (real)refine;
  b->ncirc++;
  return RHOD_OK;
}

/* Whether a fluid wedge between segment A, leaving P along dA, and segment B through P
 * needs a double mirror: A goes into B's fluid side and B continues from P into A's. */
static int open_corner(const real *A, double px, double py, double dax, double day, const real *B) {
  const double len = B[6], tol = 1e-9 * (1 + len);
  const double rx = px - B[0], ry = py - B[1];
  const double tb = rx * B[4] + ry * B[5], db = rx * B[2] + ry * B[3];
  if (fabs(db) > tol || tb < -tol || tb > len + tol)
    return 0; /* P is not on B */
  if (B[2] * dax + B[3] * day <= 1e-9)
    return 0;                                     /* A does not go into B's fluid */
  const double along = A[2] * B[4] + A[3] * B[5]; /* n_A . t_B */
  return (along > 1e-9 && tb < len - tol) || (along < -1e-9 && tb > tol);
}

/* The open boundaries' segments (open.h) after the walls': normal into the fluid, kind
 * inflow or outflow, their markers (of the size of the particles each inserts) in [11] and
 * [12], no refinement; and the corners where one meets a wall or another open boundary. */
static int push_open(rhod_boundary *b, const rhod_scene *sc) {
  real *s = realloc(b->seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)(b->nseg + (int)sc->n_open));
  if (!s)
    return RHOD_ERR_MEMORY;
  b->seg = s;
  const int first = b->nseg;
  int nmark = 0;
  for (unsigned k = 0; k < sc->n_open; k++) {
    const rhod_open_boundary *O = &sc->open[k];
    const double tx = O->to[0] - O->from[0], ty = O->to[1] - O->from[1], len = hypot(tx, ty);
    real *S = s + RHOD_SEG_STRIDE * (first + (int)k);
    const int count = (int)fmax(1, floor(len / O->dx + 0.5));
    S[0] = (real)O->from[0], S[1] = (real)O->from[1];
    S[2] = (real)O->normal[0], S[3] = (real)O->normal[1];
    S[4] = (real)(tx / len), S[5] = (real)(ty / len);
    S[6] = (real)len;
    S[7] = O->kind == RHOD_OPEN_INFLOW ? RHOD_SEG_INFLOW : RHOD_SEG_OUTFLOW;
    S[8] = 0, S[9] = 0, S[10] = -1;
    S[11] = (real)nmark, S[12] = (real)count;
    S[13] = 0, S[14] = 0;
    nmark += count;
  }
  b->nseg += (int)sc->n_open;
  b->nmark = nmark;
  for (int a = first; a < b->nseg; a++) {
    const real *A = b->seg + RHOD_SEG_STRIDE * a;
    for (int end = 0; end < 2; end++) {
      const double px = A[0] + (end ? A[6] * A[4] : 0), py = A[1] + (end ? A[6] * A[5] : 0);
      const double dax = end ? -A[4] : A[4], day = end ? -A[5] : A[5];
      for (int w = 0; w < b->nseg; w++) {
        if (w == a || (w >= first && w < a)) /* a pair of open boundaries once */
          continue;
        if (!open_corner(A, px, py, dax, day, b->seg + RHOD_SEG_STRIDE * w))
          continue;
        int32_t *c = realloc(b->corner, sizeof(int32_t) * 2 * (size_t)(b->ncorner + 1));
        if (!c)
          return RHOD_ERR_MEMORY;
        b->corner = c;
        c[2 * b->ncorner] = w;
        c[2 * b->ncorner + 1] = a;
        b->ncorner++;
      }
    }
  }
  b->openu = calloc((size_t)(2 * nmark + 2), sizeof(real));
  if (!b->openu)
    return RHOD_ERR_MEMORY;
  rhod_dev_map(b->openu, sizeof(real) * (size_t)(2 * nmark + 2));
  return RHOD_OK;
}

int rhod_boundary_init(rhod_boundary *b, const rhod_scene *sc, const double lo[2],
                       const double hi[2]) {
  memset(b, 0, sizeof *b);
  for (int a = 0; a < 2; a++) {
    b->lo[a] = lo[a];
    b->hi[a] = hi[a];
    b->periodic[a] = sc->periodic[a];
  }
  for (unsigned w = 0; w < sc->n_walls; w++) {
    const rhod_wall *W = &sc->walls[w];
    const int st = push_shape(b, &W->shape, W->fluid_inside, W->slip == RHOD_SLIP_NO, W->velocity,
                              W->moving_edges, -1, W->refine);
    if (st != RHOD_OK)
      return st;
  }
  b->open0 = b->nseg;
  if (sc->n_open > 0) {
    const int st = push_open(b, sc);
    if (st != RHOD_OK)
      return st;
  }
  b->nwallseg = b->nseg;
  b->nwallcirc = b->ncirc;
  /* bodies: obstacles (fluid outside), at zero displacement (body.h moves them) */
  static const double still[2] = {0, 0};
  for (unsigned k = 0; k < sc->n_bodies; k++) {
    const rhod_body *B = &sc->bodies[k];
    const int st =
        push_shape(b, &B->shape, 0, B->slip == RHOD_SLIP_NO, still, 0, (int)k, B->refine);
    if (st != RHOD_OK)
      return st;
    b->moving |= B->motion != RHOD_MOTION_FIXED;
  }
  b->nbody = (int)sc->n_bodies;
  for (int k = 0; k < b->nseg; k++) {
    b->moving |= b->seg[RHOD_SEG_STRIDE * k + 8] != 0 || b->seg[RHOD_SEG_STRIDE * k + 9] != 0;
    b->noslip |= b->seg[RHOD_SEG_STRIDE * k + 7] == 1;
  }
  for (int k = 0; k < b->ncirc; k++)
    b->noslip |= b->circ[RHOD_CIRC_STRIDE * k + 4] != 0;
  if (b->nbody > 0) {
    const size_t ss = sizeof(real) * RHOD_SEG_STRIDE * (size_t)b->nseg;
    const size_t cs = sizeof(real) * RHOD_CIRC_STRIDE * (size_t)b->ncirc;
    b->seg0 = malloc(ss ? ss : 1);
    b->circ0 = malloc(cs ? cs : 1);
    b->kin = calloc((size_t)b->nbody * RHOD_KIN_STRIDE, sizeof(real));
    if (!b->seg0 || !b->circ0 || !b->kin)
      return RHOD_ERR_MEMORY;
    if (ss)
      memcpy(b->seg0, b->seg, ss);
    if (cs)
      memcpy(b->circ0, b->circ, cs);
    rhod_dev_map(b->kin, sizeof(real) * RHOD_KIN_STRIDE * (size_t)b->nbody);
  }
  rhod_dev_map(b->seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)b->nseg);
  rhod_dev_map(b->corner, sizeof(int32_t) * 2 * (size_t)b->ncorner);
  rhod_dev_map(b->circ, sizeof(real) * RHOD_CIRC_STRIDE * (size_t)b->ncirc);
  return RHOD_OK;
}

void rhod_boundary_free(rhod_boundary *b) {
  rhod_dev_unmap(b->seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)b->nseg);
  rhod_dev_unmap(b->corner, sizeof(int32_t) * 2 * (size_t)b->ncorner);
  rhod_dev_unmap(b->circ, sizeof(real) * RHOD_CIRC_STRIDE * (size_t)b->ncirc);
  if (b->kin)
    rhod_dev_unmap(b->kin, sizeof(real) * RHOD_KIN_STRIDE * (size_t)b->nbody);
  if (b->openu)
    rhod_dev_unmap(b->openu, sizeof(real) * (size_t)(2 * b->nmark + 2));
  free(b->openu);
  free(b->seg);
  free(b->corner);
  free(b->circ);
  free(b->seg0);
  free(b->circ0);
  free(b->kin);
  rhod_dev_free(b->count, sizeof(int32_t) * b->count_cap);
  memset(b, 0, sizeof *b);
}

double rhod_wall_distance(const rhod_boundary *b, double x, double y) {
  double best = HUGE_VAL;
  for (int s = 0; s < b->nseg; s++) {
    const real *S = b->seg + RHOD_SEG_STRIDE * s;
    const double rx = x - S[0], ry = y - S[1];
    double t = rx * S[4] + ry * S[5];
    t = t < 0 ? 0 : (t > S[6] ? S[6] : t);
    const double px = S[0] + t * S[4], py = S[1] + t * S[5];
    const double dist = hypot(x - px, y - py);
    const double sgn = (rx * S[2] + ry * S[3]) >= 0 ? 1.0 : -1.0;
    if (dist < fabs(best))
      best = sgn * dist;
  }
  for (int c = 0; c < b->ncirc; c++) {
    const real *C = b->circ + RHOD_CIRC_STRIDE * c;
    const double d = C[3] * (C[2] - hypot(x - C[0], y - C[1]));
    if (fabs(d) < fabs(best))
      best = d;
  }
  return best;
}

double rhod_body_distance(const rhod_boundary *b, double x, double y) {
  double best = HUGE_VAL;
  for (int s = b->nwallseg; s < b->nseg; s++) {
    const real *S = b->seg + RHOD_SEG_STRIDE * s;
    const double rx = x - S[0], ry = y - S[1];
    double t = rx * S[4] + ry * S[5];
    t = t < 0 ? 0 : (t > S[6] ? S[6] : t);
    best = fmin(best, hypot(rx - t * S[4], ry - t * S[5]));
  }
  for (int c = b->nwallcirc; c < b->ncirc; c++) {
    const real *C = b->circ + RHOD_CIRC_STRIDE * c;
    best = fmin(best, fabs(hypot(x - C[0], y - C[1]) - C[2]));
  }
  return best;
}
