/* Pair physics of RHOD-SPH (paper 002), static inline for the gather kernels. */
#ifndef RHOD_SPH_PAIR_H
#define RHOD_SPH_PAIR_H

#include "rhod/config.h"
#include <math.h>

/* Slope limiter of Eq. 15: harmonic mean of same-sign slopes, else 0. */
static inline real rhod_limit(real s1, real s2) {
  return (s1 * s2 > 0) ? 2 * s1 * s2 / (s1 + s2) : 0;
}

/* Primitive-variable Riemann solver (PVRS), Eqs. 17 and 19, with c_L = c_R = c0:
 * normal velocity u_E and pressure P_E at the interface. */
static inline void rhod_pvrs(real rhoL, real rhoR, real uL, real uR, real PL, real PR, real c0,
                             real *uE, real *PE) {
  const real irs = 1 / (rhoL + rhoR);
  *uE = (rhoR * uR + rhoL * uL) * irs + (PL - PR) * irs / c0;
  *PE = (rhoR * PL + rhoL * PR) * irs + rhoR * rhoL * c0 * (uL - uR) * irs;
}

/* Left and right states of Eq. 16 along n_ij for a field phi with values phi_i, phi_j,
 * directional derivatives gi = grad phi_i . n_ij and gj = grad phi_j . n_ij, the pair
 * distance r and the weights w_i, w_j of Eq. 12. */
static inline void rhod_states(real phii, real phij, real gi, real gj, real r, real wi, real wj,
                               int recon, real *L, real *R) {
  if (!recon) {
    *L = phii;
    *R = phij;
    return;
  }
  const real s1 = (phij - phii) / r;
  /* right state: slopes along n_ji = -n_ij, i.e. -(s1) and -(gj); the limiter is odd */
  *L = phii + wi * r * rhod_limit(s1, gi);
  *R = phij - wj * r * rhod_limit(s1, gj);
}

/* Smallest eigenvalue of the symmetric part of a 2x2 matrix (row-major). */
static inline real rhod_min_eig_sym(const real *B) {
  const real a = B[0], d = B[3], b = (real)0.5 * (B[1] + B[2]);
  const real m = (real)0.5 * (a + d), q = (real)0.5 * (a - d);
  return m - sqrt(q * q + b * b);
}

#endif
