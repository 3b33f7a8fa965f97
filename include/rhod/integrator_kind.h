/* The explicit time integrators the engine has (include/rhod/integrator.h). */
#ifndef RHOD_INTEGRATOR_KIND_H
#define RHOD_INTEGRATOR_KIND_H

/* time.integrator: the explicit Runge-Kutta method of the step (integrator.h) */
typedef enum {
  RHOD_INTEGRATOR_RK4 = 0, /* classical, 4 right-hand sides per step (paper 002 Sec. IV A) */
  RHOD_INTEGRATOR_RK2,     /* Heun (SSP-RK2), 2 right-hand sides per step: our option */
  RHOD_INTEGRATOR_MIDPOINT /* explicit midpoint, 2 right-hand sides (paper 000 Eqs. 9-10) */
} rhod_integrator_kind;

#endif
