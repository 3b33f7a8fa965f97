/* The vorticity of the particle velocity field (vorticity.h). */
#include "rhod/vorticity.h"
#include "rhod/kernel.h"
#include <math.h>

void rhod_vorticity(const rhod_cells *c, const rhod_particles *p, int kern, real ratio,
                    const real *V, real *w) {
  const long n = (long)p->n;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx, *gsrc = p->gsrc;
  const real *x = p->x, *y = p->y, *dx = p->dx, *ux = p->ux, *uy = p->uy;
  const real *gTv = p->gTv, *gUv = p->gUv;
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    const real xi = x[i], yi = y[i], uxi = ux[i], uyi = uy[i], Ri = ratio * dx[i];
    const real R2 = Ri * Ri;
    real b00 = 0, b01 = 0, b10 = 0, b11 = 0, sx0 = 0, sx1 = 0, sy0 = 0, sy1 = 0;
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, Ri, j) {
      const real rx = xi - x[j], ry = yi - y[j], r2 = rx * rx + ry * ry;
      if (r2 < R2 && r2 > 0) {
        const real r = sqrt(r2);
        /* grad_i W_ij V_j = dW/dr (x_i - x_j)/r V_j */
        const real f = rhod_dW(kern, r, Ri) / r * V[j], fx = f * rx, fy = f * ry;
        real uxj = ux[j], uyj = uy[j];
        if (gTv && j >= n) {
          const real *Tv = gTv + 4 * j;
          const long k = gsrc[j];
          uxj = Tv[0] * ux[k] + Tv[1] * uy[k] + gUv[2 * j];
          uyj = Tv[2] * ux[k] + Tv[3] * uy[k] + gUv[2 * j + 1];
        }
        /* paper 002 Eq. 8: B = sum (x_j - x_i) (x) grad_i W_ij V_j */
        b00 -= rx * fx, b01 -= rx * fy, b10 -= ry * fx, b11 -= ry * fy;
        sx0 += (uxj - uxi) * fx, sx1 += (uxj - uxi) * fy;
        sy0 += (uyj - uyi) * fx, sy1 += (uyj - uyi) * fy;
      }
    }
    RHOD_END_NEIGHBOURS
    /* Eq. 14: grad phi = L^T s; du_y/dx = (L^T s_y)_x, du_x/dy = (L^T s_x)_y */
    RHOD_RENORM_L(b00, b01, b10, b11, L0, L1, L2, L3);
    w[i] = (L0 * sy0 + L2 * sy1) - (L1 * sx0 + L3 * sx1);
  }
}
