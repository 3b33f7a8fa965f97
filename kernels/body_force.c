/* The fluid's force and moment on rigid bodies (body.h): a gather over the bodies' ghosts,
 * then a reduction per body. */
#include "rhod/body.h"
#include "rhod/kernel.h"
#include <math.h>
#include <stdlib.h>

int rhod_bodies_forces(rhod_bodies *bb, const rhod_particles *p, const rhod_cells *c, int kern,
                       real ratio, const real *P, const real *V, real mu) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  for (int k = 0; k < bb->n; k++)
    bb->b[k].F[0] = bb->b[k].F[1] = bb->b[k].F[2] = 0;
  if (bb->n == 0 || nt == n || !p->gbody)
    return RHOD_OK;
  const size_t need = (size_t)(nt - n);
  if (need > bb->fghost_cap) {
    rhod_dev_free(bb->fghost, sizeof(real) * 2 * bb->fghost_cap);
    bb->fghost_cap = need + need / 4 + 64;
    bb->fghost = rhod_dev_calloc(2 * bb->fghost_cap, sizeof(real));
    if (!bb->fghost) {
      bb->fghost_cap = 0;
      return RHOD_ERR_MEMORY;
    }
  }
  /* the scan radius: a fluid particle's own R_i (it gathers with it), the largest */
  const real *dx = p->dx;
  real dmax = 0;
  RHOD_KERNEL_LOOP_REDUCE(max, dmax)
  for (long i = 0; i < n; i++)
    dmax = dx[i] > dmax ? dx[i] : dmax;
  const real Rmax = ratio * dmax;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx, *gbody = p->gbody;
  const real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy;
  real *f = bb->fghost;
  RHOD_GATHER_LOOP
  for (long g = n; g < nt; g++) {
    real fx = 0, fy = 0;
    if (gbody[g] >= 0) {
      const real xj = x[g], yj = y[g], Pj = P[g], Vj = V[g], uxj = ux[g], uyj = uy[g];
      RHOD_FOR_NEIGHBOURS(G, CS, CI, xj, yj, Rmax, i) {
        /* the fluid and its periodic images (gbody -2): each pair once, from the body's
         * own ghosts (their periodic images carry -1) */
        if (i < n || gbody[i] == -2) {
          const real rx = x[i] - xj, ry = y[i] - yj, r2 = rx * rx + ry * ry;
          const real Ri = ratio * dx[i];
          if (r2 < Ri * Ri && r2 > 0) {
            const real r = sqrt(r2);
            /* grad_i W_ij = dW/dr (x_i - x_j)/r, with i's radius */
            const real dWr = rhod_dW(kern, r, Ri) / r;
            /* Bouscasse et al. 2013 (paper 002 Ref. 8) pair form, d = 2:
             * [(P_i + P_j) - 2 (d + 2) mu pi_ij] grad_i W_ij V_i V_j */
            const real pij = ((ux[i] - uxj) * rx + (uy[i] - uyj) * ry) / r2;
            const real a = ((P[i] + Pj) - 8 * mu * pij) * dWr * V[i] * Vj;
            fx += a * rx;
            fy += a * ry;
          }
        }
      }
      RHOD_END_NEIGHBOURS
    }
    f[2 * (g - n)] = fx;
    f[2 * (g - n) + 1] = fy;
  }
  for (int k = 0; k < bb->n; k++) {
    rhod_body_state *B = &bb->b[k];
    const real Gx = (real)(B->G0[0] + B->q[0]), Gy = (real)(B->G0[1] + B->q[1]);
    real Fx = 0, Fy = 0, Mz = 0;
    RHOD_KERNEL_LOOP_REDUCE2(+, Fx, Fy)
    for (long g = n; g < nt; g++)
      if (gbody[g] == k)
        Fx += f[2 * (g - n)], Fy += f[2 * (g - n) + 1];
    RHOD_KERNEL_LOOP_REDUCE(+, Mz)
    for (long g = n; g < nt; g++)
      if (gbody[g] == k)
        Mz += (x[g] - Gx) * f[2 * (g - n) + 1] - (y[g] - Gy) * f[2 * (g - n)];
    B->F[0] = Fx, B->F[1] = Fy, B->F[2] = Mz;
  }
  return RHOD_OK;
}
