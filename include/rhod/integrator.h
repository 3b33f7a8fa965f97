/* Classical fourth-order Runge-Kutta (paper 002 Sec. IV A) over any set of per-particle
 * state arrays. Knows no physics: a state array, its derivative array (with stride and
 * offset, so interleaved vectors work) and nothing else. */
#ifndef RHOD_INTEGRATOR_H
#define RHOD_INTEGRATOR_H

#include "rhod/particles.h"

#define RHOD_RK_MAX_VARS 8

typedef struct {
  int nvars;
  real **state[RHOD_RK_MAX_VARS]; /* addresses of the store's pointers (they move on growth) */
  real **deriv[RHOD_RK_MAX_VARS];
  int stride[RHOD_RK_MAX_VARS], offset[RHOD_RK_MAX_VARS];
  real *y0[RHOD_RK_MAX_VARS], *sum[RHOD_RK_MAX_VARS]; /* registered persistent fields */
} rhod_rk4;

int rhod_rk4_init(rhod_rk4 *rk, rhod_particles *p);
int rhod_rk4_add(rhod_rk4 *rk, rhod_particles *p, real **state, real **deriv, int stride,
                 int offset);
/* Before stage 0: saves y0 and clears the sum. */
void rhod_rk4_begin(rhod_rk4 *rk, const rhod_particles *p);
/* After the derivative of stage s (0..3) is known: accumulates it and sets the state
 * for the next stage (or the final state after stage 3). */
void rhod_rk4_stage(rhod_rk4 *rk, const rhod_particles *p, int s, real dt);

#endif
