/* The fluid's force and moment on rigid bodies (body.h): the pressure integrated over the
 * boundary, and the viscous pair term gathered over the bodies' ghosts, reduced per body. */
#include "rhod/body.h"
#include "rhod/kernel.h"
#include "rhod/shepard.h"
#include <math.h>
#include <stdlib.h>

/* The viscous part (body.h): per ghost of a body, its pair sum over the fluid. */
static int viscous(rhod_bodies *bb, const rhod_particles *p, const rhod_cells *c, int kern,
                   real ratio, const real *V, real mu, const real *nu) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
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
  const real Rmax = ratio * rhod_max_real(dx, n);
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx, *gbody = p->gbody;
  const real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy, *gTv = p->gTv, *gUv = p->gUv;
  const real *rho = p->rho;
  const int32_t *gsrc = p->gsrc;
  real *f = bb->fghost;
  RHOD_GATHER_LOOP
  for (long g = n; g < nt; g++) {
    real fx = 0, fy = 0;
    if (gbody[g] >= 0) {
      /* the ghost's velocity in the viscous terms: through gTv, gUv where a wall or body is
       * no-slip (boundary.h), else the one it carries */
      real uxj = ux[g], uyj = uy[g];
      if (gTv) {
        const real *Tv = gTv + 4 * g;
        const long k = gsrc[g];
        uxj = Tv[0] * ux[k] + Tv[1] * uy[k] + gUv[2 * g];
        uyj = Tv[2] * ux[k] + Tv[3] * uy[k] + gUv[2 * g + 1];
      }
      const real xj = x[g], yj = y[g], Vj = V[g];
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
            /* Bouscasse et al. 2013 (paper 002 Ref. 8), d = 2: -2 (d + 2) mu_ij pi_ij
             * grad_i W_ij V_i V_j, the reaction of paper 002 Eq. 10's force on i; with nu,
             * mu_ij = rho_i rho_j (nu_i + nu_j) / (rho_i + rho_j) (paper 001 Eq. 6) */
            const real muij = nu ? rho[i] * rho[g] * (nu[i] + nu[g]) / (rho[i] + rho[g]) : mu;
            const real pij = ((ux[i] - uxj) * rx + (uy[i] - uyj) * ry) / r2;
            const real a = -8 * muij * pij * dWr * V[i] * Vj;
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
    B->F[0] += Fx, B->F[1] += Fy, B->F[2] += Mz;
  }
  return RHOD_OK;
}

int rhod_bodies_forces(rhod_bodies *bb, const rhod_particles *p, const rhod_cells *c, int kern,
                       real ratio, const real *P, const real *V, real mu, const real *nu) {
  for (int k = 0; k < bb->n; k++)
    bb->b[k].F[0] = bb->b[k].F[1] = bb->b[k].F[2] = 0;
  if (bb->n == 0)
    return RHOD_OK;
  /* the quadrature points where the bodies stand, and the pressure there */
  const int ns = bb->ns;
  for (int q = 0; q < ns; q++) {
    const rhod_body_state *B = &bb->b[bb->sb[q]];
    const double cs = cos(B->q[2]), sn = sin(B->q[2]);
    const double rx = bb->x0[q] - B->G0[0], ry = bb->y0[q] - B->G0[1];
    bb->px[q] = (real)(B->G0[0] + B->q[0] + cs * rx - sn * ry);
    bb->py[q] = (real)(B->G0[1] + B->q[1] + sn * rx + cs * ry);
  }
  rhod_to_device(bb->px, sizeof(real) * (size_t)ns);
  rhod_to_device(bb->py, sizeof(real) * (size_t)ns);
  rhod_shepard(c, kern, ratio, p->x, p->y, p->dx, V, P, ns, bb->px, bb->py, bb->fp, bb->gam);
  rhod_to_host(bb->fp, sizeof(real) * (size_t)ns);
  rhod_to_host(bb->gam, sizeof(real) * (size_t)ns);
  for (int q = 0; q < ns; q++) {
    rhod_body_state *B = &bb->b[bb->sb[q]];
    const double cs = cos(B->q[2]), sn = sin(B->q[2]);
    const double nx = cs * bb->nx0[q] - sn * bb->ny0[q], ny = sn * bb->nx0[q] + cs * bb->ny0[q];
    /* -P n dS, n out of the body; a dry point (Gamma < 0.1, as the pressure probes) adds 0 */
    const double Pq = bb->gam[q] > (real)0.1 ? (double)bb->fp[q] : 0.0;
    const double fx = -Pq * nx * bb->ds[q], fy = -Pq * ny * bb->ds[q];
    const double rx = bb->px[q] - (B->G0[0] + B->q[0]), ry = bb->py[q] - (B->G0[1] + B->q[1]);
    B->F[0] += fx, B->F[1] += fy, B->F[2] += rx * fy - ry * fx;
  }
  if ((mu > 0 || nu) && p->gbody && p->ng > 0)
    return viscous(bb, p, c, kern, ratio, V, mu, nu);
  return RHOD_OK;
}
