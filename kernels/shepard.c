/* Shepard interpolation at points over a cell build (shepard.h). */
#include "rhod/shepard.h"
#include "rhod/kernel.h"
#include <math.h>

void rhod_shepard(const rhod_cells *c, int kern, real ratio, const real *x, const real *y,
                  const real *dx, const real *V, const real *f, long np, const real *px,
                  const real *py, real *fp, real *gamma) {
  const long nb = c->nbuilt;
  /* the largest radius: a point has no size of its own, so its scan must reach every
   * particle whose support holds it, R_j <= ratio max dx (the cells' reach covers it,
   * rhod_cell_reach) */
  const real Rmax = ratio * rhod_max_real(dx, nb);
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx;
  const int any = nb > 0;
  RHOD_GATHER_LOOP
  for (long k = 0; k < np; k++) {
    const real xk = px[k], yk = py[k];
    real num = 0, den = 0;
    if (any) {
      RHOD_FOR_NEIGHBOURS(G, CS, CI, xk, yk, Rmax, j) {
        /* paper 000 Eq. 8: W(|p - x_j|, R_j) V_j, each particle with its own radius
         * (W = 0 outside it) */
        const real rx = x[j] - xk, ry = y[j] - yk;
        const real w = rhod_W(kern, sqrt(rx * rx + ry * ry), ratio * dx[j]) * V[j];
        num += w * f[j];
        den += w;
      }
      RHOD_END_NEIGHBOURS
    }
    /* paper 000 Eq. 8: the sum normalised by Gamma = sum_j V_j W */
    fp[k] = den > 0 ? num / den : 0;
    gamma[k] = den;
  }
}
