/* Smoothing kernels, 2D, compact support of radius R (q = r/R). Static inline so
 * they run inside device regions. Every kernel is normalised to 1 over its support
 * (checked by tests/test_kernels.c).
 *
 * The hot loops use the dimensionless forms: W(r; R) = rhod_Wq(kind, q) / R^2 and
 * dW/dr = rhod_dWq(kind, q) / R^3, with 1/R computed once per gathering particle. */
#ifndef RHOD_KERNEL_H
#define RHOD_KERNEL_H

#include "rhod/config.h"
#include "rhod/kernel_kind.h"
#include <math.h>

#define RHOD_PI 3.14159265358979323846

/* Where a yes-or-no question asks whether a particle lies in another's support of
 * radius R (the free-surface region V, the APR criteria 1 and 3), "in" means r <= R up
 * to rounding: r^2 < R^2 (1 + 2 RHOD_SUPPORT_TIE) (rhod_closed_support2); the same
 * tolerance settles ties between nearest neighbours and split patterns (rhod_apr_mark).
 * Our choice (the paper is silent): on a lattice many pairs stand exactly R apart, and
 * there the rounding of r^2, which differs between mirror images of one pair, decided,
 * breaking a symmetric scene's symmetry (cases/rotating_square/RESULTS.md, "Symmetry").
 * The open support r < R (1 - tie) is symmetric too, but it leaves a lattice's row at
 * exactly R out of V, and so out of criterion 3's initial band: the three-level dam
 * break's P1 went from 0.95 % to 8.8 % of its SR 100 reference with it. Sums over W need
 * no rule: W(R) = 0. The cells' scan holds every particle at r <= R. */
#ifdef RHOD_SINGLE
#define RHOD_SUPPORT_TIE ((real)1e-4)
#else
#define RHOD_SUPPORT_TIE ((real)1e-9)
#endif

/* Relative tolerance when comparing particle sizes (APR criteria, coalescing, the
 * relaxation at size jumps): sizes are dx / e^l, equal up to rounding. */
#define RHOD_SIZE_TOL ((real)1e-3)

/* The bound on r^2 of the closed support of radius R: j is in when r^2 < this. */
static inline real rhod_closed_support2(real R) { return R * R * (1 + 2 * RHOD_SUPPORT_TIE); }

/* R^2 W as a function of q = r/R (0 for q >= 1). */
static inline real rhod_Wq(int kind, real q) {
  if (q >= 1)
    return 0;
  if (kind == RHOD_KERNEL_WENDLAND_C2) {
    /* Wendland C2 (paper 002 Sec. IV A, Ref. 92): 7/(pi R^2) (1-q)^4 (1+4q) */
    const real a = 1 - q, a2 = a * a;
    return (real)(7 / RHOD_PI) * a2 * a2 * (1 + 4 * q);
  }
  if (kind == RHOD_KERNEL_WENDLAND_C4) {
    /* Wendland C4, 2D: 9/(pi R^2) (1-q)^6 (1 + 6q + 35/3 q^2) */
    const real a = 1 - q, a3 = a * a * a;
    return (real)(9 / RHOD_PI) * a3 * a3 * (1 + 6 * q + (real)(35.0 / 3) * q * q);
  }
  /* quintic spline (Morris et al. 1997), h = R/3, s = r/h:
   * 7/(478 pi h^2) [(3-s)^5 - 6 (2-s)^5 + 15 (1-s)^5]_+ */
  const real s = 3 * q;
  real w = 0, t;
  t = 3 - s;
  w += t * t * t * t * t;
  if (s < 2) {
    t = 2 - s;
    w -= 6 * t * t * t * t * t;
  }
  if (s < 1) {
    t = 1 - s;
    w += 15 * t * t * t * t * t;
  }
  return (real)(7 / (478 * RHOD_PI)) * 9 * w;
}

/* R^3 dW/dr as a function of q (<= 0). */
static inline real rhod_dWq(int kind, real q) {
  if (q >= 1)
    return 0;
  if (kind == RHOD_KERNEL_WENDLAND_C2) {
    const real a = 1 - q;
    return -(real)(140 / RHOD_PI) * q * a * a * a;
  }
  if (kind == RHOD_KERNEL_WENDLAND_C4) {
    const real a = 1 - q, a5 = a * a * a * a * a;
    return -(real)(9 * 56 / (3 * RHOD_PI)) * q * a5 * (1 + 5 * q);
  }
  const real s = 3 * q;
  real w = 0, t;
  t = 3 - s;
  w -= 5 * t * t * t * t;
  if (s < 2) {
    t = 2 - s;
    w += 30 * t * t * t * t;
  }
  if (s < 1) {
    t = 1 - s;
    w -= 75 * t * t * t * t;
  }
  return (real)(7 / (478 * RHOD_PI)) * 27 * w;
}

/* W(r; R). */
static inline real rhod_W(int kind, real r, real R) {
  const real iR = 1 / R;
  return rhod_Wq(kind, r * iR) * iR * iR;
}

/* dW/dr (<= 0). */
static inline real rhod_dW(int kind, real r, real R) {
  const real iR = 1 / R;
  return rhod_dWq(kind, r * iR) * iR * iR * iR;
}

/* The renormalisation matrix L = B^-1 of paper 002 Eq. 8, B = [B0 B1; B2 B3] = sum (x_j -
 * x_i) (x) grad_i W_ij V_j, declared as the reals L0 .. L3 (row-major). Our choice
 * (docs/choices.md): where det B <= 1e-2, a support too empty to invert (isolated particles,
 * thin jets), L is the identity and the gradients fall back to the plain SPH sums. The
 * gradient of a field is then L^T sum (phi_j - phi_i) grad_i W_ij V_j (Eq. 14). A macro:
 * four outputs, which GCC 12 nvptx would put in a lane-shared frame as pointer outputs. */
#define RHOD_RENORM_L(B0, B1, B2, B3, L0, L1, L2, L3)                                              \
  real L0 = 1, L1 = 0, L2 = 0, L3 = 1;                                                             \
  do {                                                                                             \
    const real det_ = (B0) * (B3) - (B1) * (B2);                                                   \
    if (det_ > (real)1e-2) {                                                                       \
      const real id_ = 1 / det_;                                                                   \
      L0 = (B3)*id_, L1 = -(B1)*id_, L2 = -(B2)*id_, L3 = (B0)*id_;                                \
    }                                                                                              \
  } while (0)

#endif
