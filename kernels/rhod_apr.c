/* Adaptive particle refinement, paper 002 Sec. V: criteria (V B) and the 1 -> 4
 * split (V A). Both are per-particle loops that write only particle i's own entries
 * (the children of i go to slots reserved for i by a scan), so they run on the
 * device like every other kernel. */
#include "kernel.h"
#include "rhod/apr.h"
#include "rhod/device.h"
#include <math.h>
#include <string.h>

/* Relative tolerance when comparing sizes: sizes are dx / 2^l, equal up to rounding. */
#define SIZE_TOL ((real)1e-3)

int rhod_apr_init(rhod_apr *a, const rhod_scene *sc, double dx_min) {
  memset(a, 0, sizeof *a);
  a->active = sc->refine_dynamic;
  a->dx_min = (real)dx_min;
  a->free_surface = sc->refine_free_surface;
  a->walls = sc->refine_walls;
  a->field = sc->refine_field;
  a->qty = sc->field_quantity;
  a->above = (real)fmin(sc->field_above, 1e30);
  a->below = (real)fmax(sc->field_below, -1e30);
  a->from = (real)sc->field_from;
  return RHOD_OK;
}

void rhod_apr_free(rhod_apr *a) {
  rhod_dev_free(a->mark, a->cap);
  rhod_dev_free(a->near, a->cap);
  rhod_dev_free(a->cnt, (a->cap + 1) * sizeof(int32_t));
  rhod_dev_free(a->sd, 4 * a->cap * sizeof(real));
  a->mark = a->near = NULL;
  a->cnt = NULL;
  a->sd = NULL;
  a->cap = 0;
}

static int ensure(rhod_apr *a, size_t n) {
  if (n <= a->cap && a->mark)
    return RHOD_OK;
  rhod_apr_free(a);
  a->cap = n + n / 4 + 64;
  a->mark = rhod_dev_calloc(a->cap, 1);
  a->near = rhod_dev_calloc(a->cap, 1);
  a->cnt = rhod_dev_calloc(a->cap + 1, sizeof(int32_t));
  a->sd = rhod_dev_calloc(4 * a->cap, sizeof(real));
  return a->mark && a->near && a->cnt && a->sd ? RHOD_OK : RHOD_ERR_MEMORY;
}

int rhod_apr_mark(rhod_apr *a, const rhod_sph *s, const rhod_particles *p, const rhod_cells *c,
                  const rhod_boundary *b, double t) {
  const long n = (long)p->n;
  if (ensure(a, p->n) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  if (a->walls)
    rhod_walls_near(b, p, s->ratio, a->near);
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx;
  const real *x = p->x, *y = p->y, *dx = p->dx, *ux = p->ux, *uy = p->uy, *rho = p->rho;
  const real *V = s->V, *P = s->P, *gP = s->gP;
  const uint8_t *reg = s->reg, *near = a->near;
  uint8_t *mark = a->mark;
  real *sd = a->sd;
  const int kern = s->kernel;
  const real ratio = s->ratio, dmin = a->dx_min * (1 - SIZE_TOL);
  const int c3 = a->free_surface && s->fsdetect, c4 = a->walls;
  const int c5 = a->field && (real)t >= a->from, dyn = a->qty == RHOD_QTY_DYNAMIC_PRESSURE;
  const real above = a->above, below = a->below;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    const real xi = x[i], yi = y[i], dxi = dx[i], Ri = ratio * dxi, R2 = Ri * Ri;
    sd[4 * i] = gP[2 * i], sd[4 * i + 1] = gP[2 * i + 1];
    sd[4 * i + 2] = 1, sd[4 * i + 3] = 0;
    if ((real)0.5 * dxi < dmin) { /* dx_min is never crossed (Sec. V B) */
      mark[i] = 0;
      continue;
    }
    const real iR = 1 / Ri, iR2 = iR * iR;
    const real self = rhod_Wq(kern, 0) * iR2 * V[i]; /* Gamma_ii, Eq. 7 */
    const real phii = dyn ? (real)0.5 * rho[i] * (ux[i] * ux[i] + uy[i] * uy[i]) : P[i];
    real best = R2, ex = 1, ey = 0;
    real same = self; /* criterion 2: sum of Gamma_ij over dx_j >= dx_i, i included */
    real num = self * phii, den = self; /* criterion 5: Shepard average, i included */
    int grand = 0;                      /* criterion 1 */
    const real quarter = (real)0.25 * dxi * (1 + SIZE_TOL), lower = dxi * (1 - SIZE_TOL);
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, Ri, j) {
      const real rx = x[j] - xi, ry = y[j] - yi, r2 = rx * rx + ry * ry;
      if (r2 < R2 && j != i) {
        if (r2 < best)
          best = r2, ex = rx, ey = ry;
        const real dxj = dx[j];
        grand |= dxj <= quarter;
        const real w = rhod_Wq(kern, sqrt(r2) * iR) * iR2 * V[j];
        same += dxj >= lower ? w : 0;
        if (c5) {
          const real phij = dyn ? (real)0.5 * rho[j] * (ux[j] * ux[j] + uy[j] * uy[j]) : P[j];
          num += w * phij, den += w;
        }
      }
    }
    RHOD_END_NEIGHBOURS
    const real phi = num / den;
    const int m = grand || same < 2 * self || (c3 && reg[i] != 0) || (c4 && near[i]) ||
                  (c5 && (phi > above || phi < below));
    mark[i] = (uint8_t)m;
    if (!m || !(best < R2))
      continue;
    /* Pattern of the children (Sec. V A, Fig. 5). The paper turns the square of side
     * dx_i/2 towards the nearest neighbour "to maximize the minimum inter-particle
     * distance once the refinement is completed". Our generalisation (docs/choices.md):
     * a rectangle of the same area, sides a dx_i/2 along e and dx_i/(2a) across, e the
     * nearest-neighbour direction turned by 0, 15, ... 75 degrees and a in 1.25^-4 ..
     * 1.25^4 (a and 1/a cover the other half turn). A pattern scores the smaller of
     * its sibling spacing, min(a, 1/a) dx_i/2, and, for every neighbour j within
     * 2 dx_i (ghosts too, so a wall counts), twice the distance by which each child
     * stays on i's side of the i-j interface point x_i + w_i (x_j - x_i) of Eq. 12:
     * the distance to j's children if j splits alike. The best score wins; ties keep
     * the square aligned with the nearest neighbour (the paper's pattern), which is
     * what a regular lattice gets. On a strained lattice (rows squeezed to 0.4 dx by
     * a dam break's stretching) the square would put a child nearly on top of a
     * neighbour's child; the rectangle follows the strain and the children form the
     * same strained lattice at half the spacing.
     * One neighbour pass per pattern, each with a scalar minimum, the turns made by a
     * constant 15-degree rotation: an array of minima, or cos/sin of a variable angle
     * (fused into sincos() with pointer outputs), would be an addressable local, which
     * GCC 12 nvptx puts in the warp-shared frame (offload.md, tests/offload_frames.sh).
     * Only marked particles pay for the passes. */
    const real e0 = sqrt(best), h = (real)0.25 * dxi, reach = 2 * dxi, reach2 = reach * reach;
    const real c15 = (real)0.96592582628906829, s15 = (real)0.25881904510252076;
    real sbest = (real)-1e30, fx = ex / e0, fy = ey / e0, bx = fx, by = fy;
    for (int k = 0; k < 6; k++) {
      real up = 1;
      for (int q = 0; q < 9; q++) {
        /* q = 0: a = 1; then 1.25, 0.8, 1.25^2, 1.25^-2, ... */
        up = (q & 1) ? up * (real)1.25 : up;
        const real a = (q & 1) || q == 0 ? up : 1 / up, ha = h * a, hb = h / a;
        real score = 2 * (a < 1 ? ha : hb);
        RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, reach, j) {
          const real rx = x[j] - xi, ry = y[j] - yi, r2 = rx * rx + ry * ry;
          if (j != i && r2 < reach2) {
            /* w_i r of Eq. 12 (exactly r/2 at equal sizes: x / (x + x) = 0.5) */
            const real r = sqrt(r2), wr = dxi / (dxi + dx[j]) * r;
            /* the child farthest along n_ij: |o.n| is largest at the corner whose
             * signs match those of (e.n, e_perp.n) */
            const real en = (fx * rx + fy * ry) / r, pn = (fx * ry - fy * rx) / r;
            const real on = ha * fabs(en) + hb * fabs(pn);
            const real sj = 2 * (wr - on);
            score = sj < score ? sj : score;
          }
        }
        RHOD_END_NEIGHBOURS
        if (score > sbest) /* strict: ties keep the earlier pattern */
          sbest = score, bx = a * fx, by = a * fy;
      }
      const real gx = c15 * fx - s15 * fy; /* e turned by a further 15 degrees */
      fy = s15 * fx + c15 * fy, fx = gx;
    }
    sd[4 * i + 2] = bx, sd[4 * i + 3] = by; /* e scaled by the aspect a */
  }
  return RHOD_OK;
}

long rhod_apr_split(rhod_apr *a, const rhod_sph *s, rhod_particles *p, const rhod_boundary *b) {
  const long n = (long)p->n;
  a->split_last = 0;
  if (!a->mark || a->cap < p->n)
    return 0;
  uint8_t *mark = a->mark;
  int32_t *cnt = a->cnt;
  RHOD_KERNEL_LOOP
  for (long i = 0; i <= n; i++)
    cnt[i] = i < n && mark[i] ? 3 : 0;
  const long added = rhod_scan_exclusive(cnt, (size_t)n + 1);
  if (added <= 0)
    return added;
  if (rhod_particles_reserve(p, (size_t)(n + added) + 1) != RHOD_OK)
    return -1;
  int32_t *src = p->perm;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++)
    if (mark[i])
      for (int k = 0; k < 3; k++)
        src[cnt[i] + k] = (int32_t)i;
  /* velocity (u_child = u_i, Sec. V A) and every other persistent array come along */
  rhod_particles_append(p, src, (size_t)added);
  real *x = p->x, *y = p->y, *rho = p->rho, *m = p->m, *dx = p->dx;
  uint64_t *id = p->id;
  const real *sd = a->sd;
  const uint64_t id0 = p->next_id;
  const real c2 = s->c0 * s->c0, ic2 = 1 / c2, rho0 = s->rho0;
  const real *seg = b->seg, *circ = b->circ;
  const int nseg = b->nseg, ncirc = b->ncirc;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    if (!mark[i])
      continue;
    const real xi = x[i], yi = y[i], dxi = dx[i], mi = m[i];
    const real Pi = c2 * (rho[i] - rho0); /* Eq. 2 */
    const real gx = sd[4 * i], gy = sd[4 * i + 1];
    /* Fig. 5: children at the corners of a square of side dx_i/2 centred on x_i (on
     * the circle of radius dx_i/(2 sqrt 2)), sides along and across the direction e
     * to the nearest neighbour; in general the rectangle of the same area and aspect
     * a chosen by rhod_apr_mark, which stores a e */
    const real a = sqrt(sd[4 * i + 2] * sd[4 * i + 2] + sd[4 * i + 3] * sd[4 * i + 3]);
    const real ex = sd[4 * i + 2] / a, ey = sd[4 * i + 3] / a;
    const real ha = (real)0.25 * dxi * a, hb = (real)0.25 * dxi / a;
    for (int k = 0; k < 4; k++) {
      const real sa = (k & 1) ? ha : -ha, sb = (k & 2) ? hb : -hb;
      /* Our choice (the paper is silent): a child that would land behind a wall, or
       * nearer to it than a quarter of its size, is moved along the wall normal to a
       * quarter of its size in front (half would push both children of a parent
       * squeezed against the wall onto one line); a child behind a wall has no ghosts
       * and was seen to blow up in the dam break within steps. Its pressure is
       * projected at the moved place. */
      const rhod_point q =
          rhod_walls_keep_off(seg, nseg, circ, ncirc, xi + sa * ex - sb * ey,
                              yi + sa * ey + sb * ex, (real)0.125 * dxi, (real)0.5 * dxi);
      const real ox = q.x - xi, oy = q.y - yi;
      const long c = k == 0 ? i : n + cnt[i] + k - 1;
      /* Sec. V A: P_c = P_i + <grad P>^L_i . (x_c - x_i), rho_c from Eq. 2,
       * m_c = m_i/4 so that V_c = (V_i rho_i / 4) / rho_c */
      const real Pc = Pi + gx * ox + gy * oy;
      x[c] = q.x, y[c] = q.y;
      rho[c] = rho0 + Pc * ic2;
      m[c] = (real)0.25 * mi;
      dx[c] = (real)0.5 * dxi;
      if (k > 0)
        id[c] = id0 + (uint64_t)(cnt[i] + k - 1);
    }
  }
  p->next_id += (uint64_t)added;
  a->split_last = added / 3;
  a->split_total += added / 3;
  return added / 3;
}
