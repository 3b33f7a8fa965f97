/* Ghost particles: wall mirrors and periodic images, rebuilt every RK stage on the
 * device: count per particle, scan, fill. */
#include "rhod/boundary.h"
#include "rhod/cells.h"
#include "rhod/kernel.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Whether (x, y) is mirrored in segment S: in front of it by less than R, its foot on it. */
static inline int seg_near(const real *S, real x, real y, real R) {
  const real rx = x - S[0], ry = y - S[1];
  const real d = S[2] * rx + S[3] * ry;
  const real t = S[4] * rx + S[5] * ry;
  return d > 0 && d < R && t >= 0 && t <= S[6];
}

/* Squared distance from (x, y) to segment S (its end points included). */
static inline real seg_dist2(const real *S, real x, real y) {
  const real rx = x - S[0], ry = y - S[1];
  real t = S[4] * rx + S[5] * ry;
  t = t < 0 ? 0 : (t > S[6] ? S[6] : t);
  const real ex = rx - t * S[4], ey = ry - t * S[5];
  return ex * ex + ey * ey;
}

/* The share of face k of a body's closed outline (S[14]; the fluid outside) in its mirror
 * image at (qx, qy) (docs/choices.md "bodies: ghosts
 * near convex vertices"). Within R of a vertex a point inside the outline is the image of
 * fluid in each face f whose mirror reaches it: q behind f's line by e_f < R, its foot on f
 * (0 <= t_f <= L_f). Each such face takes the share m_f / sum m, m_f = min(R - e_f, t_f,
 * L_f - t_f, the distance from q to the outline's other faces), the margin by which q stays
 * inside the region f's mirror reaches: the shares sum to 1 at every point (the inside
 * within R of the boundary is tiled once, as with the nearest face alone until 2026-12-07)
 * and each goes to 0 continuously where its mirror ends, so that a ghost fades in and out
 * as its source passes a vertex's bisector instead of appearing whole. A point outside the
 * outline (the image of fluid across a thin body or an acute keel) gets 0. Where only face
 * k reaches q the share is m/m = 1 exactly: a face away from vertices keeps the source's
 * mass bit for bit. A face f whose preimage of q (q + 2 e_f n_f) lies where no fluid can
 * stand, outside the domain box [xlo, xhi] x [ylo, yhi] (a periodic axis: unbounded) or
 * behind the line of an open boundary (segments [o0, o1)), takes no share (face k itself
 * always does: its preimage is the source, which may have crossed an outflow's line before
 * its deletion): no image of f reaches q (an obstacle wall thinner than 2 R at the domain's edge,
 * or one that runs past an outflow: its far face, its end face). */
static inline real face_share(const real *seg, int k, int first, int count, int o0, int o1,
                              real xlo, real xhi, real ylo, real yhi, real qx, real qy, real R) {
  /* the two nearest faces' squared distances (a face R or more away caps no margin) */
  real d1 = R * R, d2 = R * R;
  int i1 = -1, inside = 0;
  for (int s = first; s < first + count; s++) {
    const real *S = seg + RHOD_SEG_STRIDE * s;
    const real e2 = seg_dist2(S, qx, qy);
    if (e2 < d1)
      d2 = d1, d1 = e2, i1 = s;
    else if (e2 < d2)
      d2 = e2;
    /* crossing number of the ray from q along +x (the faces close the outline) */
    const real ax = S[0], ay = S[1], bx = S[0] + S[6] * S[4], by = S[1] + S[6] * S[5];
    if (RHOD_RAY_CROSSES(ax, ay, bx, by, qx, qy))
      inside = !inside;
  }
  if (!inside)
    return 0;
  /* with face k alone within R (away from the vertices: most mirrors) no other face can
   * reach q, and the loop below needs only k: mk / sum = 1 (0 at k's very ends) */
  const int lone = !(d2 < R * R);
  const int s0 = lone ? k : first, s1 = lone ? k + 1 : first + count;
  real mk = 0, sum = 0;
  for (int s = s0; s < s1; s++) {
    const real *S = seg + RHOD_SEG_STRIDE * s;
    const real rx = qx - S[0], ry = qy - S[1];
    const real e = -(S[2] * rx + S[3] * ry), t = S[4] * rx + S[5] * ry;
    if (!(e > 0 && e < R && t >= 0 && t <= S[6]))
      continue;
    const real px = qx + 2 * e * S[2], py = qy + 2 * e * S[3]; /* the preimage */
    int beyond = px < xlo || px > xhi || py < ylo || py > yhi;
    for (int o = o0; o < o1; o++) {
      const real *O = seg + RHOD_SEG_STRIDE * o;
      beyond |= O[2] * (px - O[0]) + O[3] * (py - O[1]) < 0;
    }
    if (beyond && s != k) /* k's preimage is the source itself, wherever it stands */
      continue;
    real m = R - e;
    m = t < m ? t : m;
    m = S[6] - t < m ? S[6] - t : m;
    const real o = sqrt(s == i1 ? d2 : d1);
    m = o < m ? o : m;
    sum += m;
    if (s == k)
      mk = m;
  }
  return mk > 0 ? mk / sum : 0;
}

/* A body's boundary velocity at (fx, fy) from its kinematics K (RHOD_KIN_STRIDE):
 * u_w = U + Omega x r, r = f - G (scalars, not a local array: offload_frames). */
static inline real body_uwx(const real *K, real fx, real fy) {
  (void)fx;
  return K[2] - K[4] * (fy - K[1]);
}
static inline real body_uwy(const real *K, real fx, real fy) {
  (void)fy;
  return K[3] + K[4] * (fx - K[0]);
}

/* A body ghost's wall parts (docs/choices.md "bodies"): u_g = u_w + T (u_s - u_w), so
 * U = (I - T) u_w; A = a_w = A_G + dOmega/dt x r - Omega^2 r, r = f - G. */
static inline void body_ghost(const real *K, real fx, real fy, const real *Tn, real *Un, real *An) {
  const real uwx = body_uwx(K, fx, fy), uwy = body_uwy(K, fx, fy);
  Un[0] = uwx - (Tn[0] * uwx + Tn[1] * uwy);
  Un[1] = uwy - (Tn[2] * uwx + Tn[3] * uwy);
  if (An) {
    const real rx = fx - K[0], ry = fy - K[1], W = K[4], Wd = K[7];
    An[0] = K[5] - Wd * ry - W * W * rx;
    An[1] = K[6] + Wd * rx - W * W * ry;
  }
}

/* An open boundary's velocity transform (open.h): an inflow's mirror carries the velocity
 * its marker at tangential coordinate t imposes (T = 0, U = openu of the marker), an
 * outflow's the fluid's as it is (T = I, U = 0: zero gradient across the boundary). */
static inline void open_ghost(const real *S, const real *openu, real t, real *Tn, real *Un) {
  if (S[7] == RHOD_SEG_INFLOW) {
    const int count = (int)S[12];
    int k = (int)floor(t / S[6] * (real)count);
    k = k < 0 ? 0 : (k >= count ? count - 1 : k);
    k += (int)S[11];
    Tn[0] = 0, Tn[1] = 0, Tn[2] = 0, Tn[3] = 0;
    Un[0] = openu[2 * k], Un[1] = openu[2 * k + 1];
  } else {
    const int count = (int)S[12];
    int k = (int)floor(t / S[6] * (real)count);
    k = k < 0 ? 0 : (k >= count ? count - 1 : k);
    k += (int)S[11];
    Tn[0] = 1, Tn[1] = 0, Tn[2] = 0, Tn[3] = 1;
    Un[0] = openu[2 * k], Un[1] = openu[2 * k + 1];
  }
}

/* One segment's velocity map at a corner (wall_mirrors): an open boundary's (open_ghost) at
 * the source's foot, a no-slip wall's -I and 2 u_wall where `wall` asks for the walls'
 * own conditions, else the free-slip mirror J (a0, a1; a1, a3), U = 0. */
static inline void corner_seg_map(const real *S, const real *openu, real x, real y, int wall,
                                  real a0, real a1, real a3, real *Tn, real *Un) {
  if (S[7] >= RHOD_SEG_INFLOW) {
    open_ghost(S, openu, S[4] * (x - S[0]) + S[5] * (y - S[1]), Tn, Un);
  } else if (wall && S[7] != 0) {
    Tn[0] = -1, Tn[1] = 0, Tn[2] = 0, Tn[3] = -1;
    Un[0] = 2 * S[8], Un[1] = 2 * S[9];
  } else {
    Tn[0] = a0, Tn[1] = a1, Tn[2] = a1, Tn[3] = a3;
    Un[0] = 0, Un[1] = 0;
  }
}

/* The velocity map of the double mirror of (x, y) in segments a then b (position Jacobian
 * Jn): the walls' own conditions where `wall` is set, else their free-slip mirrors (open
 * boundaries keep theirs). */
static inline void corner_map(const real *A_, const real *B_, const real *openu, real x, real y,
                              const real *Jn, int wall, real *Tn, real *Un) {
  const real a0 = 1 - 2 * A_[2] * A_[2], a1 = -2 * A_[2] * A_[3], a3 = 1 - 2 * A_[3] * A_[3];
  const real b0 = 1 - 2 * B_[2] * B_[2], b1 = -2 * B_[2] * B_[3], b3 = 1 - 2 * B_[3] * B_[3];
  if (A_[7] >= RHOD_SEG_INFLOW || B_[7] >= RHOD_SEG_INFLOW) {
    /* a corner with an open boundary (open.h): the two mirrors composed, u' = T_b (T_a u +
     * U_a) + U_b, each segment's own transform at the source's foot on it */
    corner_seg_map(A_, openu, x, y, wall, a0, a1, a3, Tn, Un);
    const real Ta0 = Tn[0], Ta1 = Tn[1], Ta2 = Tn[2], Ta3 = Tn[3], Ua0 = Un[0], Ua1 = Un[1];
    corner_seg_map(B_, openu, x, y, wall, b0, b1, b3, Tn, Un);
    const real Tb0 = Tn[0], Tb1 = Tn[1], Tb2 = Tn[2], Tb3 = Tn[3], Ub0 = Un[0], Ub1 = Un[1];
    Tn[0] = Tb0 * Ta0 + Tb1 * Ta2, Tn[1] = Tb0 * Ta1 + Tb1 * Ta3;
    Tn[2] = Tb2 * Ta0 + Tb3 * Ta2, Tn[3] = Tb2 * Ta1 + Tb3 * Ta3;
    Un[0] = Tb0 * Ua0 + Tb1 * Ua1 + Ub0, Un[1] = Tb2 * Ua0 + Tb3 * Ua1 + Ub1;
  } else if (wall && (A_[7] != 0 || B_[7] != 0)) {
    Tn[0] = -1, Tn[1] = 0, Tn[2] = 0, Tn[3] = -1;
    /* our choice (docs/choices.md "moving walls at corners"): with T = -I the corner
     * ghost is a no-slip mirror of the corner, whose velocity is the mean of the
     * no-slip walls meeting there (a free-slip wall imposes none): U = 2 u_corner.
     * Composing the two mirrors, T_b (T_a u + U_a) + U_b, would give -U_a + U_b for
     * two no-slip walls: the lid's velocity reversed at one of a cavity's corners */
    const real na = A_[7] != 0 ? 1 : 0, nb = B_[7] != 0 ? 1 : 0;
    Un[0] = 2 * (na * A_[8] + nb * B_[8]) / (na + nb);
    Un[1] = 2 * (na * A_[9] + nb * B_[9]) / (na + nb);
  } else {
    for (int k = 0; k < 4; k++)
      Tn[k] = Jn[k];
    Un[0] = 0, Un[1] = 0; /* T_b (T_a u + 0) + 0: free slip on both */
  }
}

/* Mirrors of (x, y) in the walls and bodies within R: positions, Jacobians J, velocity
 * transforms T (row-major 2x2), the moving walls' part U of the ghost velocity u' = T u + U,
 * and with bodies (A, B not NULL) the boundary's acceleration A and the body index B; M
 * the ghost's mass from the source's ms. Free slip: T = J (normal velocity reversed), U = 0
 * for a wall (a wall's motion along itself does not act on a free-slip fluid); no slip:
 * T = -I (both components reversed), U = 2 u_wall, so that the mean of u and u' is the
 * wall's velocity. With Tv not NULL (a scene with a no-slip wall or body), (T, U) is the
 * free-slip map of every wall and (Tv, Uv) the map the wall's condition asks for, which
 * only the viscous terms read (docs/choices.md "no slip in the viscous term only").
 * Returns the count; with gx NULL it only counts. The outputs are written
 * straight into the ghost arrays (gx[k], J[4k]): a local array here would sit in GCC 12's
 * per-warp nvptx frame, shared by the 32 lanes of a simd loop, and the lanes would
 * overwrite each other's mirrors (tools/check_offload_frames.sh guards against any such
 * array in a kernel). */
static inline int wall_mirrors(const real *seg, int nseg, int o0, int o1, real xlo, real xhi,
                               real ylo, real yhi, const int32_t *corner, int ncorner,
                               const real *circ, int ncirc, const real *kin, const real *openu,
                               real x, real y, real R, real ms, real *gx, real *gy, real *J,
                               real *T, real *U, real *Tv, real *Uv, real *A, int32_t *B, real *M) {
  int n = 0;
  for (int s = 0; s < nseg; s++) {
    const real *S = seg + RHOD_SEG_STRIDE * s;
    const real rx = x - S[0], ry = y - S[1];
    const real d = S[2] * rx + S[3] * ry;
    const real t = S[4] * rx + S[5] * ry;
    if (!(d > 0 && d < R && t >= 0 && t <= S[6]))
      continue;
    const real qx = x - 2 * d * S[2], qy = y - 2 * d * S[3];
    const int body = (int)S[10];
    /* our choice (docs/choices.md "bodies: ghosts near convex vertices"): the faces of a
     * body or an obstacle wall share its inside near a convex vertex, so that their images
     * neither overlap nor appear whole when a source crosses the vertex's bisector */
    const real share = S[14] != 0 ? face_share(seg, s, (int)S[11], (int)S[12], o0, o1, xlo, xhi,
                                               ylo, yhi, qx, qy, R)
                                  : (real)1;
    if (!(share > 0))
      continue;
    if (gx) {
      gx[n] = qx;
      gy[n] = qy;
      M[n] = ms * share;
      real *Jn = J + 4 * n, *Tn = T + 4 * n, *Un = U + 2 * n;
      Jn[0] = 1 - 2 * S[2] * S[2];
      Jn[1] = -2 * S[2] * S[3];
      Jn[2] = Jn[1];
      Jn[3] = 1 - 2 * S[3] * S[3];
      if (S[7] >= RHOD_SEG_INFLOW) {
        open_ghost(S, openu, t, Tn, Un);
      } else if (S[7] != 0 && !Tv) {
        Tn[0] = -1, Tn[1] = 0, Tn[2] = 0, Tn[3] = -1;
        Un[0] = 2 * S[8], Un[1] = 2 * S[9];
      } else {
        for (int k = 0; k < 4; k++)
          Tn[k] = Jn[k];
        Un[0] = 0, Un[1] = 0;
      }
      if (Tv) { /* the viscous map: the wall's own condition */
        real *Tw = Tv + 4 * n, *Uw = Uv + 2 * n;
        if (S[7] == 1) {
          Tw[0] = -1, Tw[1] = 0, Tw[2] = 0, Tw[3] = -1;
          Uw[0] = 2 * S[8], Uw[1] = 2 * S[9];
        } else {
          for (int k = 0; k < 4; k++)
            Tw[k] = Tn[k];
          Uw[0] = Un[0], Uw[1] = Un[1];
        }
        if (body >= 0)
          body_ghost(kin + RHOD_KIN_STRIDE * body, x - d * S[2], y - d * S[3], Tw, Uw, NULL);
      }
      if (body >= 0)
        body_ghost(kin + RHOD_KIN_STRIDE * body, x - d * S[2], y - d * S[3], Tn, Un,
                   A ? A + 2 * n : NULL);
      else if (A)
        A[2 * n] = 0, A[2 * n + 1] = 0;
      if (B)
        B[n] = body;
    }
    n++;
  }
  for (int c = 0; c < ncorner; c++) {
    const int a = corner[2 * c], b = corner[2 * c + 1];
    const real *A_ = seg + RHOD_SEG_STRIDE * a, *B_ = seg + RHOD_SEG_STRIDE * b;
    if (!seg_near(A_, x, y, R) || !seg_near(B_, x, y, R))
      continue;
    /* reflect in a, then in b */
    const real da = A_[2] * (x - A_[0]) + A_[3] * (y - A_[1]);
    const real x1 = x - 2 * da * A_[2], y1 = y - 2 * da * A_[3];
    const real db = B_[2] * (x1 - B_[0]) + B_[3] * (y1 - B_[1]);
    const real x2 = x1 - 2 * db * B_[2], y2 = y1 - 2 * db * B_[3];
    /* the corner ghost lies 2 rho from its source (rho the distance to the corner)
     * and at least rho from any particle on the fluid side: it is needed when
     * rho < R, i.e. closer than 2R to its source (it was R until 2026-11-22, which
     * left out the corner ghosts of particles between R/2 and R from the corner:
     * Gamma = 0.995 at a corner particle instead of 1.001; found by test_apr) */
    if ((x2 - x) * (x2 - x) + (y2 - y) * (y2 - y) >= 4 * R * R)
      continue;
    if (gx) {
      gx[n] = x2;
      gy[n] = y2;
      M[n] = ms;
      /* J = Jb Ja, each a reflection I - 2 e e^T (symmetric) */
      const real a0 = 1 - 2 * A_[2] * A_[2], a1 = -2 * A_[2] * A_[3], a3 = 1 - 2 * A_[3] * A_[3];
      const real b0 = 1 - 2 * B_[2] * B_[2], b1 = -2 * B_[2] * B_[3], b3 = 1 - 2 * B_[3] * B_[3];
      real *Jn = J + 4 * n, *Tn = T + 4 * n, *Un = U + 2 * n;
      Jn[0] = b0 * a0 + b1 * a1;
      Jn[1] = b0 * a1 + b1 * a3;
      Jn[2] = b1 * a0 + b3 * a1;
      Jn[3] = b1 * a1 + b3 * a3;
      corner_map(A_, B_, openu, x, y, Jn, !Tv, Tn, Un);
      if (Tv)
        corner_map(A_, B_, openu, x, y, Jn, 1, Tv + 4 * n, Uv + 2 * n);
      const int body = (int)A_[10];
      if (body >= 0) { /* a body's concave vertex: the kinematics at the vertex, b's start */
        body_ghost(kin + RHOD_KIN_STRIDE * body, B_[0], B_[1], Tn, Un, A ? A + 2 * n : NULL);
        if (Tv)
          body_ghost(kin + RHOD_KIN_STRIDE * body, B_[0], B_[1], Tv + 4 * n, Uv + 2 * n, NULL);
      } else if (A)
        A[2 * n] = 0, A[2 * n + 1] = 0;
      if (B)
        B[n] = body;
    }
    n++;
  }
  for (int c = 0; c < ncirc; c++) {
    const real *C = circ + RHOD_CIRC_STRIDE * c;
    const real rx = x - C[0], ry = y - C[1];
    const real dist = sqrt(rx * rx + ry * ry);
    if (!(dist > 0))
      continue;
    const real d = C[3] > 0 ? C[2] - dist : dist - C[2]; /* distance into the fluid */
    if (!(d > 0 && d < R))
      continue;
    const real rg = C[3] > 0 ? C[2] + d : C[2] - d; /* mirror radius */
    if (!(rg > 0))
      continue;
    if (gx) {
      const real ex = rx / dist, ey = ry / dist;
      gx[n] = C[0] + rg * ex;
      gy[n] = C[1] + rg * ey;
      /* the radial mirror r -> 2a - r maps r dr dphi onto r_g dr dphi: the image of the
       * source's area is r_g / r_s of it (docs/choices.md "bodies": a constant mass
       * over-weighted the ghosts of a convex obstacle by up to 7.5 %) */
      M[n] = ms * (rg / dist);
      /* local mirror in the tangent line */
      real *Jn = J + 4 * n, *Tn = T + 4 * n, *Un = U + 2 * n;
      Un[0] = 0, Un[1] = 0; /* a wall's circle does not move */
      Jn[0] = 1 - 2 * ex * ex;
      Jn[1] = -2 * ex * ey;
      Jn[2] = Jn[1];
      Jn[3] = 1 - 2 * ey * ey;
      if (C[4] != 0 && !Tv) {
        Tn[0] = -1, Tn[1] = 0, Tn[2] = 0, Tn[3] = -1;
      } else {
        /* free slip on a curved wall: no shear stress is d(u_t/r)/dr = 0, so the mirror
         * keeps u_t/r, u_t' = (r_g/r_s) u_t, and reverses u_n: T = k (I - e e^T) - e e^T,
         * k = r_g/r_s (docs/choices.md "bodies"; the plain mirror J, k = 1, let the first
         * rows around a circle at rest start a growing oscillation) */
        const real k = rg / dist;
        Tn[0] = k - (1 + k) * ex * ex;
        Tn[1] = -(1 + k) * ex * ey;
        Tn[2] = Tn[1];
        Tn[3] = k - (1 + k) * ey * ey;
      }
      const int body = (int)C[5];
      if (Tv) { /* the viscous map: the circle's own condition */
        real *Tw = Tv + 4 * n, *Uw = Uv + 2 * n;
        for (int q = 0; q < 4; q++)
          Tw[q] = C[4] != 0 ? (q == 0 || q == 3 ? -1 : 0) : Tn[q];
        Uw[0] = 0, Uw[1] = 0;
        if (body >= 0)
          body_ghost(kin + RHOD_KIN_STRIDE * body, C[0] + C[2] * ex, C[1] + C[2] * ey, Tw, Uw,
                     NULL);
      }
      if (body >= 0)
        body_ghost(kin + RHOD_KIN_STRIDE * body, C[0] + C[2] * ex, C[1] + C[2] * ey, Tn, Un,
                   A ? A + 2 * n : NULL);
      else if (A)
        A[2 * n] = 0, A[2 * n + 1] = 0;
      if (B)
        B[n] = body;
    }
    n++;
  }
  return n;
}

static int ensure_count(rhod_boundary *b, size_t need) {
  if (need <= b->count_cap && b->count)
    return RHOD_OK;
  rhod_dev_free(b->count, b->count_cap * sizeof(int32_t));
  b->count_cap = need + need / 4 + 64;
  b->count = rhod_dev_calloc(b->count_cap, sizeof(int32_t));
  return b->count ? RHOD_OK : RHOD_ERR_MEMORY;
}

/* Whether a support of radius R at (x, y) reaches a wall or body whose refine flag
 * (S[13], C[6]) is set (paper 002 Sec. V B, criterion 4, switchable per body and per
 * wall: "disabled at the bottom part of the tank" in its case F). A body by the distance
 * to its segments (vertices included, so that convex corners are seen) or circle; a wall
 * where (x, y) has a mirror in it (in front of a segment by less than R with its foot on
 * it, or inside a circle's reach with a mirror radius > 0): the test rhod_walls_near has
 * made for walls since criterion 4 came in, kept so that the refined layouts of the APR
 * scenes stay as they were (a concave corner's double mirror needs both segments' mirrors,
 * so it adds nothing). */
static inline int support_reaches(const real *seg, int nseg, const real *circ, int ncirc, real x,
                                  real y, real R) {
  for (int s = 0; s < nseg; s++) {
    const real *S = seg + RHOD_SEG_STRIDE * s;
    if (S[13] == 0)
      continue;
    if (S[10] >= 0 ? seg_dist2(S, x, y) < R * R : seg_near(S, x, y, R))
      return 1;
  }
  for (int c = 0; c < ncirc; c++) {
    const real *C = circ + RHOD_CIRC_STRIDE * c;
    if (C[6] == 0)
      continue;
    const real rx = x - C[0], ry = y - C[1], dist = sqrt(rx * rx + ry * ry);
    if (C[5] >= 0) {
      const real d = dist - C[2];
      if (d < R && d > -R)
        return 1;
    } else if (dist > 0) {
      const real d = C[3] > 0 ? C[2] - dist : dist - C[2]; /* distance into the fluid */
      const real rg = C[3] > 0 ? C[2] + d : C[2] - d;      /* mirror radius */
      if (d > 0 && d < R && rg > 0)
        return 1;
    }
  }
  return 0;
}

void rhod_walls_near(const rhod_boundary *b, const rhod_particles *p, real ratio, uint8_t *near) {
  const int nseg = b->nseg, ncirc = b->ncirc;
  const real *seg = b->seg, *circ = b->circ, *x = p->x, *y = p->y, *dx = p->dx;
  const long n = (long)p->n;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++)
    near[i] = (uint8_t)support_reaches(seg, nseg, circ, ncirc, x[i], y[i], ratio * dx[i]);
}

/* Phase 1: wall mirrors of the fluid. Returns the number of ghosts written or < 0. */
static long build_wall_ghosts(rhod_boundary *b, rhod_particles *p, real ratio) {
  const int nseg = b->nseg, ncorner = b->ncorner, ncirc = b->ncirc, o0 = b->open0;
  const int o1 = b->nwallseg;
  if (nseg + ncirc == 0)
    return 0;
  /* where fluid can stand (face_share): the domain box, unbounded along a periodic axis */
  const real xlo = b->periodic[0] ? (real)-1e30 : (real)b->lo[0];
  const real xhi = b->periodic[0] ? (real)1e30 : (real)b->hi[0];
  const real ylo = b->periodic[1] ? (real)-1e30 : (real)b->lo[1];
  const real yhi = b->periodic[1] ? (real)1e30 : (real)b->hi[1];
  const long n = (long)p->n;
  if (ensure_count(b, p->n + 1) != RHOD_OK)
    return -1;
  for (;;) {
    const real *seg = b->seg, *circ = b->circ, *kin = b->kin, *openu = b->openu;
    const int32_t *corner = b->corner;
    int32_t *cnt = b->count;
    const real *x = p->x, *y = p->y, *dx = p->dx;
    RHOD_KERNEL_LOOP
    for (long i = 0; i <= n; i++) {
      if (i == n) {
        cnt[i] = 0;
        continue;
      }
      cnt[i] = wall_mirrors(seg, nseg, o0, o1, xlo, xhi, ylo, yhi, corner, ncorner, circ, ncirc,
                            kin, openu, x[i], y[i], ratio * dx[i], 0, NULL, NULL, NULL, NULL, NULL,
                            NULL, NULL, NULL, NULL, NULL);
    }
    const long total = rhod_scan_exclusive(cnt, (size_t)n + 1);
    if (total < 0)
      return -1;
    if (p->n + (size_t)total + 1 > p->cap) {
      if (rhod_particles_reserve(p, p->n + (size_t)total + 1) != RHOD_OK)
        return -1;
      continue; /* the arrays moved: count again */
    }
    real *gxo = p->x, *gyo = p->y, *m = p->m, *gdx = p->dx, *gJ = p->gJ, *gT = p->gT, *ge = p->ge;
    real *gU = p->gU, *gA = p->gA, *gTv = p->gTv, *gUv = p->gUv;
    int32_t *gsrc = p->gsrc, *gbody = p->gbody;
    RHOD_KERNEL_LOOP
    for (long i = 0; i < n; i++) {
      const int c = cnt[i + 1] - cnt[i];
      if (c == 0)
        continue;
      const long base = n + cnt[i];
      wall_mirrors(seg, nseg, o0, o1, xlo, xhi, ylo, yhi, corner, ncorner, circ, ncirc, kin, openu,
                   gxo[i], gyo[i], ratio * gdx[i], m[i], gxo + base, gyo + base, gJ + 4 * base,
                   gT + 4 * base, gU + 2 * base, gTv ? gTv + 4 * base : NULL,
                   gTv ? gUv + 2 * base : NULL, gA ? gA + 2 * base : NULL,
                   gbody ? gbody + base : NULL, m + base);
      for (long g = base; g < base + c; g++) {
        gdx[g] = gdx[i];
        gsrc[g] = (int32_t)i;
        ge[2 * g] = gxo[g] - gxo[i];
        ge[2 * g + 1] = gyo[g] - gyo[i];
      }
    }
    return total;
  }
}

/* Phase 2: periodic images of fluid and wall ghosts [0, n + nw). */
static long build_periodic(rhod_boundary *b, rhod_particles *p, long nw, real margin) {
  if (!b->periodic[0] && !b->periodic[1])
    return 0;
  const long n = (long)p->n, nsrc = n + nw;
  if (ensure_count(b, (size_t)nsrc + 1) != RHOD_OK)
    return -1;
  const int px = b->periodic[0], py = b->periodic[1];
  const real lox = (real)b->lo[0], hix = (real)b->hi[0], loy = (real)b->lo[1], hiy = (real)b->hi[1];
  const real Lx = hix - lox, Ly = hiy - loy;
  for (;;) {
    int32_t *cnt = b->count;
    const real *x = p->x, *y = p->y;
    RHOD_KERNEL_LOOP
    for (long k = 0; k <= nsrc; k++) {
      if (k == nsrc) {
        cnt[k] = 0;
        continue;
      }
      int c = 0;
      for (int sy = -py; sy <= py; sy++)
        for (int sx = -px; sx <= px; sx++) {
          if (sx == 0 && sy == 0)
            continue;
          const real X = x[k] + sx * Lx, Y = y[k] + sy * Ly;
          if (sx != 0 && (X < lox - margin || X > hix + margin))
            continue;
          if (sy != 0 && (Y < loy - margin || Y > hiy + margin))
            continue;
          c++;
        }
      cnt[k] = c;
    }
    const long total = rhod_scan_exclusive(cnt, (size_t)nsrc + 1);
    if (total < 0)
      return -1;
    if ((size_t)(nsrc + total) + 1 > p->cap) {
      /* growing keeps only the fluid: the wall ghosts must be built again */
      if (rhod_particles_reserve(p, (size_t)(nsrc + total) + 1) != RHOD_OK)
        return -1;
      return -2;
    }
    real *X = p->x, *Y = p->y, *m = p->m, *gdx = p->dx, *gJ = p->gJ, *gT = p->gT, *ge = p->ge;
    real *gU = p->gU, *gA = p->gA, *gTv = p->gTv, *gUv = p->gUv;
    int32_t *gsrc = p->gsrc, *gbody = p->gbody;
    RHOD_KERNEL_LOOP
    for (long k = 0; k < nsrc; k++) {
      long g = nsrc + cnt[k];
      if (cnt[k + 1] == cnt[k])
        continue;
      for (int sy = -py; sy <= py; sy++)
        for (int sx = -px; sx <= px; sx++) {
          if (sx == 0 && sy == 0)
            continue;
          const real xs = X[k] + sx * Lx, ys = Y[k] + sy * Ly;
          if (sx != 0 && (xs < lox - margin || xs > hix + margin))
            continue;
          if (sy != 0 && (ys < loy - margin || ys > hiy + margin))
            continue;
          X[g] = xs;
          Y[g] = ys;
          m[g] = m[k];
          gdx[g] = gdx[k];
          if (k < n) {
            gsrc[g] = (int32_t)k;
            gJ[4 * g] = 1, gJ[4 * g + 1] = 0, gJ[4 * g + 2] = 0, gJ[4 * g + 3] = 1;
            gT[4 * g] = 1, gT[4 * g + 1] = 0, gT[4 * g + 2] = 0, gT[4 * g + 3] = 1;
            ge[2 * g] = 0, ge[2 * g + 1] = 0;
            gU[2 * g] = 0, gU[2 * g + 1] = 0;
            if (gTv) {
              gTv[4 * g] = 1, gTv[4 * g + 1] = 0, gTv[4 * g + 2] = 0, gTv[4 * g + 3] = 1;
              gUv[2 * g] = 0, gUv[2 * g + 1] = 0;
            }
            if (gA)
              gA[2 * g] = 0, gA[2 * g + 1] = 0;
            if (gbody)
              gbody[g] = -2; /* an image of the fluid (the force pass counts it as fluid) */
          } else {
            gsrc[g] = gsrc[k];
            for (int q = 0; q < 4; q++) {
              gJ[4 * g + q] = gJ[4 * k + q];
              gT[4 * g + q] = gT[4 * k + q];
            }
            ge[2 * g] = ge[2 * k], ge[2 * g + 1] = ge[2 * k + 1];
            gU[2 * g] = gU[2 * k], gU[2 * g + 1] = gU[2 * k + 1];
            if (gTv) {
              for (int q = 0; q < 4; q++)
                gTv[4 * g + q] = gTv[4 * k + q];
              gUv[2 * g] = gUv[2 * k], gUv[2 * g + 1] = gUv[2 * k + 1];
            }
            if (gA)
              gA[2 * g] = gA[2 * k], gA[2 * g + 1] = gA[2 * k + 1];
            if (gbody) /* an image of a mirror: the force pass counts its original only */
              gbody[g] = -1;
          }
          g++;
        }
    }
    return total;
  }
}

int rhod_ghosts_build(rhod_boundary *b, rhod_particles *p, real radius_ratio, real margin) {
  for (;;) {
    p->ng = 0;
    const long nw = build_wall_ghosts(b, p, radius_ratio);
    if (nw < 0)
      return RHOD_ERR_MEMORY;
    p->ng = (size_t)nw;
    const long np = build_periodic(b, p, nw, margin);
    if (np == -2)
      continue;
    if (np < 0)
      return RHOD_ERR_MEMORY;
    p->ng += (size_t)np;
    return RHOD_OK;
  }
}

/* Wall-crossing guard (our choice; paper 002 does not discuss it). Mirrored ghosts
 * repel a particle less and less as it nears the wall (W'(r) -> 0 as r -> 0), so a
 * thin sheet sliding along a wall under gravity can end a step a hair on the wrong
 * side, where it would have no ghosts and fall through. Such a particle is reflected
 * back elastically (position and normal velocity) across the wall it crossed, if it is
 * less than half its size behind it; further than that it is a real failure and is
 * left for the domain check to report. A particle behind both walls of a concave
 * corner, beyond the ends of both segments (seen in single precision at the dam
 * break's far corner), is reflected in both. Returns how many were reflected. */
long rhod_walls_guard(const rhod_boundary *b, rhod_particles *p) {
  const int nseg = b->nseg, ncirc = b->ncirc;
  if (nseg + ncirc == 0)
    return 0;
  const long n = (long)p->n;
  const real *seg = b->seg, *circ = b->circ, *kin = b->kin;
  const int32_t *corner = b->corner;
  const int ncorner = b->ncorner;
  real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy;
  const real *dx = p->dx;
  long count = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, count)
  for (long i = 0; i < n; i++) {
    const real lim = (real)0.5 * dx[i];
    for (int s = 0; s < nseg; s++) {
      const real *S = seg + RHOD_SEG_STRIDE * s;
      const real rx = x[i] - S[0], ry = y[i] - S[1];
      const real d = S[2] * rx + S[3] * ry, t = S[4] * rx + S[5] * ry;
      /* an open boundary lets particles through (open.h takes them out) */
      if (S[7] < RHOD_SEG_INFLOW && d <= 0 && d > -lim && t >= 0 && t <= S[6]) {
        /* a body's boundary moves: the normal velocity relative to it is reflected */
        real wx = 0, wy = 0;
        if (S[10] >= 0) {
          const real *K = kin + RHOD_KIN_STRIDE * (int)S[10];
          wx = body_uwx(K, x[i] - d * S[2], y[i] - d * S[3]);
          wy = body_uwy(K, x[i] - d * S[2], y[i] - d * S[3]);
        }
        x[i] -= 2 * d * S[2], y[i] -= 2 * d * S[3];
        const real un = (ux[i] - wx) * S[2] + (uy[i] - wy) * S[3];
        if (un < 0)
          ux[i] -= 2 * un * S[2], uy[i] -= 2 * un * S[3];
        count++;
      }
    }
    for (int c = 0; c < ncorner; c++) {
      const real *A = seg + RHOD_SEG_STRIDE * corner[2 * c];
      const real *B = seg + RHOD_SEG_STRIDE * corner[2 * c + 1];
      const real da = A[2] * (x[i] - A[0]) + A[3] * (y[i] - A[1]);
      const real db = B[2] * (x[i] - B[0]) + B[3] * (y[i] - B[1]);
      if (A[7] < RHOD_SEG_INFLOW && B[7] < RHOD_SEG_INFLOW && da <= 0 && da > -lim && db <= 0 &&
          db > -lim) {
        x[i] -= 2 * da * A[2], y[i] -= 2 * da * A[3];
        const real db2 = B[2] * (x[i] - B[0]) + B[3] * (y[i] - B[1]); /* after the first */
        if (db2 < 0)
          x[i] -= 2 * db2 * B[2], y[i] -= 2 * db2 * B[3];
        const real ua = ux[i] * A[2] + uy[i] * A[3];
        if (ua < 0)
          ux[i] -= 2 * ua * A[2], uy[i] -= 2 * ua * A[3];
        const real ub = ux[i] * B[2] + uy[i] * B[3];
        if (ub < 0)
          ux[i] -= 2 * ub * B[2], uy[i] -= 2 * ub * B[3];
        count++;
      }
    }
    for (int c = 0; c < ncirc; c++) {
      const real *C = circ + RHOD_CIRC_STRIDE * c;
      const real rx = x[i] - C[0], ry = y[i] - C[1], dist = sqrt(rx * rx + ry * ry);
      const real d = C[3] > 0 ? C[2] - dist : dist - C[2];
      if (d <= 0 && d > -lim && dist > 0) {
        const real ex = C[3] * (-rx / dist), ey = C[3] * (-ry / dist); /* into the fluid */
        real wx = 0, wy = 0;
        if (C[5] >= 0) {
          const real *K = kin + RHOD_KIN_STRIDE * (int)C[5];
          wx = body_uwx(K, C[0] + C[2] * rx / dist, C[1] + C[2] * ry / dist);
          wy = body_uwy(K, C[0] + C[2] * rx / dist, C[1] + C[2] * ry / dist);
        }
        x[i] -= 2 * d * ex, y[i] -= 2 * d * ey;
        const real un = (ux[i] - wx) * ex + (uy[i] - wy) * ey;
        if (un < 0)
          ux[i] -= 2 * un * ex, uy[i] -= 2 * un * ey;
        count++;
      }
    }
  }
  return count;
}

long rhod_bodies_entered(const rhod_boundary *b, const rhod_particles *p, int *body) {
  *body = -1;
  if (b->nbody == 0)
    return -1;
  const int s0 = b->nwallseg, s1 = b->nseg, c0 = b->nwallcirc, c1 = b->ncirc;
  const real *seg = b->seg, *circ = b->circ, *x = p->x, *y = p->y, *dx = p->dx;
  const long n = (long)p->n;
  long bad = n;
  RHOD_KERNEL_LOOP_REDUCE(min, bad)
  for (long i = 0; i < n; i++) {
    const real lim = (real)0.5 * dx[i], xi = x[i], yi = y[i];
    /* deeper than lim into the body of the nearest segment: inside its polygon by the
     * crossings of a ray along +x (each segment from its start to the next one's, the
     * polygon's own vertices). The sign of the nearest segment's normal distance, used
     * until 2026-12-06, is undecided where a vertex is nearest to both of its faces:
     * cases/body_refine stopped on a particle just below the level of its wedge's top
     * (then at 0.35 m), 0.19 m beside it, that rounding had given to the top face */
    real best = -1;
    int nearest = -1;
    for (int s = s0; s < s1; s++) {
      const real e2 = seg_dist2(seg + RHOD_SEG_STRIDE * s, xi, yi);
      if (best < 0 || e2 < best)
        best = e2, nearest = s;
    }
    int in = 0;
    if (nearest >= 0 && best > lim * lim) {
      const real *N = seg + RHOD_SEG_STRIDE * nearest;
      const int first = (int)N[11], count = (int)N[12];
      for (int k = 0; k < count; k++) {
        const real *A = seg + RHOD_SEG_STRIDE * (first + k);
        const real *B = seg + RHOD_SEG_STRIDE * (first + (k + 1) % count);
        if (RHOD_RAY_CROSSES(A[0], A[1], B[0], B[1], xi, yi))
          in = !in;
      }
    }
    for (int c = c0; c < c1; c++) {
      const real *C = circ + RHOD_CIRC_STRIDE * c;
      const real rx = xi - C[0], ry = yi - C[1];
      in |= sqrt(rx * rx + ry * ry) < C[2] - lim;
    }
    if (in && i < bad)
      bad = i;
  }
  if (bad == n)
    return -1;
  /* which body (host side, one particle) */
  real xb = 0, yb = 0;
  rhod_to_host(p->x + bad, sizeof(real));
  rhod_to_host(p->y + bad, sizeof(real));
  xb = p->x[bad], yb = p->y[bad];
  double best = HUGE_VAL;
  for (int s = s0; s < s1; s++) {
    const double e2 = seg_dist2(b->seg + RHOD_SEG_STRIDE * s, xb, yb);
    if (e2 < best)
      best = e2, *body = (int)b->seg[RHOD_SEG_STRIDE * s + 10];
  }
  for (int c = c0; c < c1; c++) {
    const real *C = b->circ + RHOD_CIRC_STRIDE * c;
    if (hypot(xb - C[0], yb - C[1]) < C[2])
      *body = (int)C[5];
  }
  return bad;
}
