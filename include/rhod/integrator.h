/* Explicit Runge-Kutta over any set of per-particle state arrays. Knows no physics: a
 * state array, its derivative array (with stride and offset, so interleaved vectors
 * work) and nothing else. Methods of the same low-storage form, where each stage is
 * evaluated at y0 + c dt k_prev (a stage table each, src/integrator.c):
 *   RK4: classical fourth order (paper 002 Sec. IV A), 4 derivative evaluations;
 *   RK2: Heun's method (SSP-RK2, second order), 2 evaluations. Our cheaper option:
 *        strong-stability preserving, so it keeps the limited reconstruction's
 *        monotonicity, and half the cost per step at the same dt (perf/RESULTS.md);
 *   midpoint: the explicit midpoint rule, second order, 2 evaluations (paper 000 Eqs.
 *        9-10 and paper 001 Eq. 13; the multiphase scheme's integrator). */
#ifndef RHOD_INTEGRATOR_H
#define RHOD_INTEGRATOR_H

#include "rhod/integrator_kind.h"
#include "rhod/particles.h"
#include "rhod/status.h"

#define RHOD_RK_MAX_VARS 8
#define RHOD_RK_MAX_STAGES 4

/* A method's stage table: y_{n+1} = y_n + dt/div sum_s w[s] k_s, and stage s + 1
 * evaluated at y_n + c[s] dt k_s. */
typedef struct {
  int stages;
  real div;
  real w[RHOD_RK_MAX_STAGES], c[RHOD_RK_MAX_STAGES];
} rhod_rk_table;
/* The table of a method; NULL for an unknown one. */
const rhod_rk_table *rhod_rk_table_of(rhod_integrator_kind method);

typedef struct {
  rhod_integrator_kind method;
  rhod_rk_table table;
  int stages;
  int nvars;
  real **state[RHOD_RK_MAX_VARS]; /* addresses of the store's pointers (they move on growth) */
  real **deriv[RHOD_RK_MAX_VARS];
  int stride[RHOD_RK_MAX_VARS], offset[RHOD_RK_MAX_VARS];
  real *y0[RHOD_RK_MAX_VARS], *sum[RHOD_RK_MAX_VARS]; /* registered persistent fields */
  /* the stiffness measure (rhod_rk_stiffness): a variable's weight, 0 where it is not
   * measured, and its k2 - k1 (a registered RHOD_FIELD_STEP field, RK4 only) */
  real watch[RHOD_RK_MAX_VARS];
  real *d21[RHOD_RK_MAX_VARS];
} rhod_rk;

/* RHOD_ERR_SCENE for an unknown method. */
int rhod_rk_init(rhod_rk *rk, rhod_particles *p, rhod_integrator_kind method);
int rhod_rk_add(rhod_rk *rk, rhod_particles *p, real **state, real **deriv, int stride, int offset);
/* Before stage 0: saves y0 and clears the sum. */
void rhod_rk_begin(rhod_rk *rk, const rhod_particles *p);
/* After the derivative of stage s (0 .. stages - 1) is known: accumulates it and sets
 * the state for the next stage (or the final state after the last stage). */
void rhod_rk_stage(rhod_rk *rk, const rhod_particles *p, int s, real dt);

/* The stiffness the RK4 stages see (docs/choices.md "stiffness step limit"). Stages 2 and 3
 * are evaluated at Y2 = y0 + dt/2 k1 and Y3 = y0 + dt/2 k2, so k3 - k2 = J (Y3 - Y2) to
 * first order, J the Jacobian of the right-hand side: each stage difference is a power
 * iteration on the last, which brings out the stiffest modes the flow has excited. The
 * weighted Rayleigh quotient
 *   q = sum_v w_v^2 sum_i dY_i dK_i / sum_v w_v^2 sum_i dY_i^2,  dY = Y3 - Y2, dK = k3 - k2,
 * is exactly lambda for y' = lambda y, and estimates the real part of the excited modes
 * (an oscillating mode adds nothing to it); q dt below -2.785 is RK4 past its bound on
 * the real axis.
 * rhod_rk_watch puts the variable of `state` (as given to rhod_rk_add) into the measure
 * with weight w (the scale that makes the variables comparable); RHOD_ERR_SCENE for a
 * state not added or a w that is not finite and positive, RHOD_ERR_MEMORY, and nothing
 * done with RK2 (no third stage).
 * rhod_rk_stiffness returns q (1/s): call it after the derivative of stage 2 is known and
 * before rhod_rk_stage(rk, p, 2, dt). Particles i with skip[i] != 0 are left out (skip may
 * be NULL); 0 where nothing is watched or dY vanishes. */
int rhod_rk_watch(rhod_rk *rk, rhod_particles *p, real **state, real w);
real rhod_rk_stiffness(const rhod_rk *rk, const rhod_particles *p, real dt, const uint8_t *skip);

#endif
