/* Pair physics of the multiphase scheme (paper 000 Sec. 2, paper 001 Sec. 2.1), static
 * inline for the gathers of kernels/multiphase/mp.c. Conventions (multiphase.md):
 * r_ij = r_i - r_j, grad W_ij = W'(r) r_ij / r is the gradient at i (W' <= 0, so it
 * points from i towards j), V = m / rho. Each function returns the scalar that multiplies
 * grad W_ij (or the pair's term itself), one output each so the loops keep registers. */
#ifndef RHOD_MP_PAIR_H
#define RHOD_MP_PAIR_H

#include "rhod/config.h"
#include <math.h>

/* Tait EOS, paper 000 Eq. 3 (= paper 001 Eq. 1): p = rho0 c^2 / gamma [(rho/rho0)^gamma - 1];
 * gamma = 1 is the linear law c^2 (rho - rho0). No background pressure. */
static inline real rhod_mp_eos(real rho0, real c, real gamma, real rho) {
  if (gamma == 1)
    return c * c * (rho - rho0);
  return rho0 * c * c / gamma * (pow(rho / rho0, gamma) - 1);
}

/* Its inverse: rho = rho0 (1 + gamma p / (rho0 c^2))^(1/gamma). */
static inline real rhod_mp_eos_inv(real rho0, real c, real gamma, real p) {
  if (gamma == 1)
    return rho0 + p / (c * c);
  return rho0 * pow(1 + gamma * p / (rho0 * c * c), 1 / gamma);
}

/* Continuity, paper 000 Eq. 1, first sum: rho_i (u_i - u_j) . grad W_ij V_j, with
 * uw = (u_i - u_j) . grad W_ij. */
static inline real rhod_mp_div_term(real rhoi, real uw, real Vj) { return rhoi * uw * Vj; }

/* Continuity, paper 000 Eq. 1, the delta-SPH diffusion (between particles of the same
 * phase only; the sum is printed over i, a TYPO, it runs over j):
 * delta c_i (rho_i - rho_j) (r_ij/|r_ij| . grad W_ij) V_j, and r_ij/|r_ij| . grad W_ij = W'
 * (dW = W'(r) <= 0): rho_i rises where its neighbours are denser (diffusive). */
static inline real rhod_mp_diffusion(real delta, real ci, real rhoi, real rhoj, real dW, real Vj) {
  return delta * ci * (rhoi - rhoj) * dW * Vj;
}

/* Momentum, paper 000 Eq. 2 with the tensile-instability switch of paper 001 Eq. 5: the
 * factor of grad W_ij in -(p_j +- p_i) / (rho_i rho_j) m_j grad W_ij = -(p_j +- p_i) V_j /
 * rho_i grad W_ij; plus = 1: p_j + p_i (p_i >= 0, momentum-conserving), 0: p_j - p_i. */
static inline real rhod_mp_press_coef(real pi, real pj, real Vj, real rhoi, int plus) {
  return -(plus ? pj + pi : pj - pi) * Vj / rhoi;
}

/* Viscosity after Szewc et al., paper 001 Eq. 6: the factor of grad W_ij in
 * 2 m_j (d + 2) (nu_i + nu_j) / (rho_i + rho_j) (u_ij . r_ij) / (r_ij^2 + eta^2) grad W_ij,
 * d = 2, with ur = u_ij . r_ij and eta2 = eta^2 = 0.01 h^2 (the TYPO "eta = 0.01/h"). */
static inline real rhod_mp_visc_coef(real mj, real nui, real nuj, real rhoi, real rhoj, real ur,
                                     real r2, real eta2) {
  return 2 * mj * (RHOD_DIM + 2) * (nui + nuj) / (rhoi + rhoj) * ur / (r2 + eta2);
}

/* Adami's density-weighted colour of a pair (paper 001 Eqs. 8 and 39, multiphase.md):
 * c~_ij = rho_j/(rho_i + rho_j) c_i + rho_i/(rho_i + rho_j) c_j; its pair factor
 * f_ij = (V_i^2 + V_j^2) c~_ij multiplies grad W_ij in grad C_i = (1/V_i) sum_j f_ij grad W_ij. */
static inline real rhod_mp_colour_f(real Vi, real Vj, real rhoi, real rhoj, real ci, real cj) {
  return (Vi * Vi + Vj * Vj) * (rhoj * ci + rhoi * cj) / (rhoi + rhoj);
}

/* Repulsive term of the shifting, paper 000 Eq. 6: f_ij = xi_Rep (W_ij / W(dx))^n. */
static inline real rhod_mp_rep(real xi_rep, real W, real Wdx, real n) {
  if (xi_rep == 0)
    return 0;
  const real q = W / Wdx;
  return xi_rep * (n == 2 ? q * q : pow(q, n));
}

/* Shifting velocity, paper 000 Eq. 7 (Eq. 5 with the RIF; Eq. 5's sum is printed over i,
 * a TYPO): u_s = -xi_Shift (h/dt)^2 [S + xi_RIF alpha S_RIF] dt = -xi_Shift h^2 / dt [...],
 * with s = S + xi_RIF alpha S_RIF one component of the bracket. */
static inline real rhod_mp_shift(real xi_shift, real h, real dt, real s) {
  return dt > 0 ? -xi_shift * h * h / dt * s : 0;
}

#endif
