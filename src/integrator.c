/* Explicit Runge-Kutta over registered state arrays (integrator.h), each method a stage
 * table (rhod_rk_table):
 * RK4 y_{n+1} = y_n + dt/6 (k1 + 2 k2 + 2 k3 + k4), stages at y_n + (dt/2, dt/2, dt) k;
 * RK2 (Heun) y_{n+1} = y_n + dt/2 (k1 + k2), k2 at y_n + dt k1;
 * midpoint y_{n+1} = y_n + dt k2, k2 at y_n + dt/2 k1 (paper 000 Eqs. 9-10, paper 001
 * Eq. 13: the explicit form of the "modified velocity Verlet" paper 000 uses). */
#include "rhod/integrator.h"
#include <math.h>
#include <string.h>

/* The stage tables: Butcher weights (times their divisor) and the next stage's fraction
 * of dt, by rhod_integrator_kind. */
static const rhod_rk_table tables[] = {
    [RHOD_INTEGRATOR_RK4] = {4, 6, {1, 2, 2, 1}, {0.5, 0.5, 1, 0}},
    [RHOD_INTEGRATOR_RK2] = {2, 2, {1, 1}, {1, 0}},
    [RHOD_INTEGRATOR_MIDPOINT] = {2, 1, {0, 1}, {0.5, 0}},
};

const rhod_rk_table *rhod_rk_table_of(rhod_integrator_kind method) {
  if ((unsigned)method >= sizeof tables / sizeof tables[0])
    return NULL;
  return &tables[method];
}

int rhod_rk_init(rhod_rk *rk, rhod_particles *p, rhod_integrator_kind method) {
  (void)p;
  memset(rk, 0, sizeof *rk);
  const rhod_rk_table *t = rhod_rk_table_of(method);
  if (!t)
    return RHOD_ERR_SCENE;
  rk->method = method;
  rk->table = *t;
  rk->stages = t->stages;
  return RHOD_OK;
}

int rhod_rk_add(rhod_rk *rk, rhod_particles *p, real **state, real **deriv, int stride,
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

int rhod_rk_watch(rhod_rk *rk, rhod_particles *p, real **state, real w) {
  int v = 0;
  while (v < rk->nvars && rk->state[v] != state)
    v++;
  if (v == rk->nvars || !(w > 0 && isfinite(w)))
    return RHOD_ERR_SCENE; /* the weights come from the scene (c0, rho0) */
  if (rk->method != RHOD_INTEGRATOR_RK4)
    return RHOD_OK; /* nothing to measure: no third stage */
  if (!rk->d21[v]) {
    /* the store keeps the name's pointer */
    static const char *names[RHOD_RK_MAX_VARS] = {"rk_d21_0", "rk_d21_1", "rk_d21_2", "rk_d21_3",
                                                  "rk_d21_4", "rk_d21_5", "rk_d21_6", "rk_d21_7"};
    const int st =
        rhod_particles_add_field(p, names[v], (void **)&rk->d21[v], sizeof(real), RHOD_FIELD_STEP);
    if (st != RHOD_OK)
      return st;
  }
  rk->watch[v] = w;
  return RHOD_OK;
}

real rhod_rk_stiffness(const rhod_rk *rk, const rhod_particles *p, real dt, const uint8_t *skip) {
  const long n = (long)p->n;
  const real h = dt / 2;
  double num = 0, den = 0;
  for (int v = 0; v < rk->nvars; v++) {
    if (!(rk->watch[v] > 0))
      continue;
    const real *d = *rk->deriv[v], *d21 = rk->d21[v], *sum = rk->sum[v];
    const int st = rk->stride[v], of = rk->offset[v];
    real a = 0, b = 0;
    /* here sum = k1 + 2 k2 and d21 = k2 - k1, so k2 = (sum + d21) / 3 */
    RHOD_KERNEL_LOOP_REDUCE2(+, a, b)
    for (long i = 0; i < n; i++) {
      const real dy = skip && skip[i] ? 0 : h * d21[i];
      const real dk = d[st * i + of] - (sum[i] + d21[i]) / 3;
      a += dy * dk, b += dy * dy;
    }
    const double w2 = (double)rk->watch[v] * rk->watch[v];
    num += w2 * a, den += w2 * b;
  }
  return den > 0 ? (real)(num / den) : 0;
}

void rhod_rk_begin(rhod_rk *rk, const rhod_particles *p) {
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

void rhod_rk_stage(rhod_rk *rk, const rhod_particles *p, int s, real dt) {
  const rhod_rk_table *t = &rk->table;
  const long n = (long)p->n;
  const real ws = t->w[s], cs = t->c[s] * dt, d6 = dt / t->div;
  const int last = s == rk->stages - 1;
  for (int v = 0; v < rk->nvars; v++) {
    real *y = *rk->state[v];
    const real *d = *rk->deriv[v];
    real *y0 = rk->y0[v], *sum = rk->sum[v];
    const int st = rk->stride[v], of = rk->offset[v];
    /* the stiffness measure keeps k2 - k1; at stage 1 the sum holds k1 */
    real *d21 = s == 1 && rk->method == RHOD_INTEGRATOR_RK4 && rk->watch[v] > 0 ? rk->d21[v] : NULL;
    RHOD_KERNEL_LOOP
    for (long i = 0; i < n; i++) {
      const real k = d[st * i + of];
      if (d21)
        d21[i] = k - sum[i];
      const real acc = sum[i] + ws * k;
      sum[i] = acc;
      y[i] = last ? y0[i] + d6 * acc : y0[i] + cs * k;
    }
  }
}
