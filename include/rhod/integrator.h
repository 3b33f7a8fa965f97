/* Explicit Runge-Kutta over any set of per-particle state arrays. Knows no physics: a
 * state array, its derivative array (with stride and offset, so interleaved vectors
 * work) and nothing else. Two methods of the same low-storage form, where each stage
 * is evaluated at y0 + c dt k_prev:
 *   RK4: classical fourth order (paper 002 Sec. IV A), 4 derivative evaluations;
 *   RK2: Heun's method (SSP-RK2, second order), 2 evaluations. Our cheaper option:
 *        strong-stability preserving, so it keeps the limited reconstruction's
 *        monotonicity, and half the cost per step at the same dt (perf/RESULTS.md). */
#ifndef RHOD_INTEGRATOR_H
#define RHOD_INTEGRATOR_H

#include "rhod/particles.h"
#include "rhod/scene.h"

#define RHOD_RK_MAX_VARS 8

typedef struct {
  rhod_integrator_kind method;
  int stages;
  int nvars;
  real **state[RHOD_RK_MAX_VARS]; /* addresses of the store's pointers (they move on growth) */
  real **deriv[RHOD_RK_MAX_VARS];
  int stride[RHOD_RK_MAX_VARS], offset[RHOD_RK_MAX_VARS];
  real *y0[RHOD_RK_MAX_VARS], *sum[RHOD_RK_MAX_VARS]; /* registered persistent fields */
} rhod_rk;

int rhod_rk_init(rhod_rk *rk, rhod_particles *p, rhod_integrator_kind method);
int rhod_rk_add(rhod_rk *rk, rhod_particles *p, real **state, real **deriv, int stride, int offset);
/* Before stage 0: saves y0 and clears the sum. */
void rhod_rk_begin(rhod_rk *rk, const rhod_particles *p);
/* After the derivative of stage s (0 .. stages - 1) is known: accumulates it and sets
 * the state for the next stage (or the final state after the last stage). */
void rhod_rk_stage(rhod_rk *rk, const rhod_particles *p, int s, real dt);

#endif
