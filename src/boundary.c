/* Wall geometry from a scene: segments with their fluid-side normals, the corners
 * that need a double mirror, circles, and the domain box. Host side. */
#include "rhod/boundary.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Edge k (pt[k] to pt[k + 1]) moves at vel when bit k of `moving` is set. */
static int push_polygon(real **seg, int *nseg, int32_t **corner, int *ncorner,
                        const double (*pt)[2], unsigned np, int fluid_inside, int noslip,
                        const double vel[2], unsigned moving) {
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
    (*nseg)++;
  }
  /* corners: edge k ends where edge k+1 starts; the fluid wedge there is narrower
   * than a half plane (needs a double mirror) when n_k . t_{k+1} > 0 */
  const int ne = *nseg - first;
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
    const int noslip = W->slip == RHOD_SLIP_NO;
    int st = RHOD_OK;
    if (W->shape.kind == RHOD_SHAPE_RECT) {
      const double *m = W->shape.min, *M = W->shape.max;
      const double pts[4][2] = {{m[0], m[1]}, {M[0], m[1]}, {M[0], M[1]}, {m[0], M[1]}};
      st = push_polygon(&b->seg, &b->nseg, &b->corner, &b->ncorner, pts, 4, W->fluid_inside, noslip,
                        W->velocity, W->moving_edges);
    } else if (W->shape.kind == RHOD_SHAPE_POLYGON) {
      st = push_polygon(&b->seg, &b->nseg, &b->corner, &b->ncorner,
                        (const double(*)[2])W->shape.points, W->shape.n_points, W->fluid_inside,
                        noslip, W->velocity, W->moving_edges);
    } else {
      real *c = realloc(b->circ, sizeof(real) * RHOD_CIRC_STRIDE * (size_t)(b->ncirc + 1));
      if (!c)
        return RHOD_ERR_MEMORY;
      b->circ = c;
      real *C = c + RHOD_CIRC_STRIDE * b->ncirc;
      C[0] = (real)W->shape.center[0];
      C[1] = (real)W->shape.center[1];
      C[2] = (real)W->shape.radius;
      C[3] = W->fluid_inside ? 1 : -1;
      C[4] = (real)noslip;
      b->ncirc++;
    }
    if (st != RHOD_OK)
      return st;
  }
  for (int k = 0; k < b->nseg; k++)
    b->moving |= b->seg[RHOD_SEG_STRIDE * k + 8] != 0 || b->seg[RHOD_SEG_STRIDE * k + 9] != 0;
  rhod_dev_map(b->seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)b->nseg);
  rhod_dev_map(b->corner, sizeof(int32_t) * 2 * (size_t)b->ncorner);
  rhod_dev_map(b->circ, sizeof(real) * RHOD_CIRC_STRIDE * (size_t)b->ncirc);
  return RHOD_OK;
}

void rhod_boundary_free(rhod_boundary *b) {
  rhod_dev_unmap(b->seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)b->nseg);
  rhod_dev_unmap(b->corner, sizeof(int32_t) * 2 * (size_t)b->ncorner);
  rhod_dev_unmap(b->circ, sizeof(real) * RHOD_CIRC_STRIDE * (size_t)b->ncirc);
  free(b->seg);
  free(b->corner);
  free(b->circ);
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
