/* RK4 over registered state arrays: y_{n+1} = y_n + dt/6 (k1 + 2 k2 + 2 k3 + k4). */
#include "rhod/integrator.h"
#include "rhod/scene.h"
#include <string.h>

int rhod_rk4_init(rhod_rk4 *rk, rhod_particles *p) {
  (void)p;
  memset(rk, 0, sizeof *rk);
  return RHOD_OK;
}

int rhod_rk4_add(rhod_rk4 *rk, rhod_particles *p, real **state, real **deriv, int stride,
                 int offset) {
  if (rk->nvars >= RHOD_RK_MAX_VARS)
    return RHOD_ERR_MEMORY;
  const int k = rk->nvars;
  rk->state[k] = state;
  rk->deriv[k] = deriv;
  rk->stride[k] = stride;
  rk->offset[k] = offset;
  /* persistent: they must survive a growth of the store in the middle of a step */
  int st = rhod_particles_add_field(p, "rk_y0", (void **)&rk->y0[k], sizeof(real), 1);
  if (st == RHOD_OK)
    st = rhod_particles_add_field(p, "rk_sum", (void **)&rk->sum[k], sizeof(real), 1);
  if (st == RHOD_OK)
    rk->nvars++;
  return st;
}

void rhod_rk4_begin(rhod_rk4 *rk, const rhod_particles *p) {
  const long n = (long)p->n;
  for (int v = 0; v < rk->nvars; v++) {
    const real *y = *rk->state[v];
    real *y0 = rk->y0[v], *sum = rk->sum[v];
    RHOD_KERNEL_LOOP
    for (long i = 0; i < n; i++) {
      y0[i] = y[i];
      sum[i] = 0;
    }
  }
}

void rhod_rk4_stage(rhod_rk4 *rk, const rhod_particles *p, int s, real dt) {
  static const real w[4] = {1, 2, 2, 1};     /* weights x 6 */
  static const real c[4] = {0.5, 0.5, 1, 0}; /* next stage's fraction of dt */
  const long n = (long)p->n;
  const real ws = w[s], cs = c[s] * dt, d6 = dt / 6;
  const int last = s == 3;
  for (int v = 0; v < rk->nvars; v++) {
    real *y = *rk->state[v];
    const real *d = *rk->deriv[v];
    real *y0 = rk->y0[v], *sum = rk->sum[v];
    const int st = rk->stride[v], of = rk->offset[v];
    RHOD_KERNEL_LOOP
    for (long i = 0; i < n; i++) {
      const real k = d[st * i + of];
      const real acc = sum[i] + ws * k;
      sum[i] = acc;
      y[i] = last ? y0[i] + d6 * acc : y0[i] + cs * k;
    }
  }
}
