/* Pair physics of RHOD-SPH (paper 002), static inline for the gather kernels. */
#ifndef RHOD_SPH_PAIR_H
#define RHOD_SPH_PAIR_H

#include "rhod/config.h"
#include <math.h>

/* Slope limiter of Eq. 15: harmonic mean of same-sign slopes, else 0. */
static inline real rhod_limit(real s1, real s2) {
  return (s1 * s2 > 0) ? 2 * s1 * s2 / (s1 + s2) : 0;
}

/* Primitive-variable Riemann solver (PVRS), Eqs. 17 and 19, with c_L = c_R = c0: the
 * normal velocity u_E and the pressure P_E at the interface. (One function per output,
 * no pointer outputs: the pair loops vectorise, and GCC's nvptx keeps them in
 * registers; the shared 1/(rho_L + rho_R) is computed once after inlining.) */
static inline real rhod_pvrs_u(real rhoL, real rhoR, real uL, real uR, real PL, real PR, real c0) {
  const real irs = 1 / (rhoL + rhoR);
  return (rhoR * uR + rhoL * uL) * irs + (PL - PR) * irs / c0;
}
static inline real rhod_pvrs_P(real rhoL, real rhoR, real uL, real uR, real PL, real PR, real c0) {
  const real irs = 1 / (rhoL + rhoR);
  return (rhoR * PL + rhoL * PR) * irs + rhoR * rhoL * c0 * (uL - uR) * irs;
}

/* A state of Eq. 16 along n_ij for a field phi: the left one (particle i) is
 * rhod_state(phi_i, s, grad phi_i . n_ij, w_i r), the right one (particle j)
 * rhod_state(phi_j, s, grad phi_j . n_ij, -w_j r), with s = (phi_j - phi_i)/r, r the
 * pair distance and w the weights of Eq. 12 (the right state's slopes are taken along
 * n_ji = -n_ij, i.e. -s and -g, and the limiter is odd). wr = 0: first order. */
static inline real rhod_state(real phi, real s, real g, real wr) {
  return phi + wr * rhod_limit(s, g);
}

/* Smallest eigenvalue of the symmetric part of a 2x2 matrix (row-major). */
static inline real rhod_min_eig_sym(const real *B) {
  const real a = B[0], d = B[3], b = (real)0.5 * (B[1] + B[2]);
  const real m = (real)0.5 * (a + d), q = (real)0.5 * (a - d);
  return m - sqrt(q * q + b * b);
}

#endif
