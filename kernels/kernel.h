/* Smoothing kernels, 2D, compact support of radius R (q = r/R). Static inline so
 * they run inside device regions. Every kernel is normalised to 1 over its support
 * (checked by tests/test_kernels.c). */
#ifndef RHOD_KERNEL_H
#define RHOD_KERNEL_H

#include "rhod/config.h"
#include "rhod/scene.h"
#include <math.h>

#define RHOD_PI 3.14159265358979323846

/* W(r; R). */
static inline real rhod_W(int kind, real r, real R) {
  const real q = r / R;
  if (q >= 1)
    return 0;
  const real iR2 = 1 / (R * R);
  if (kind == RHOD_KERNEL_WENDLAND_C2) {
    /* Wendland C2 (paper 002 Sec. IV A, Ref. 92): 7/(pi R^2) (1-q)^4 (1+4q) */
    const real a = 1 - q, a2 = a * a;
    return (real)(7 / RHOD_PI) * iR2 * a2 * a2 * (1 + 4 * q);
  }
  if (kind == RHOD_KERNEL_WENDLAND_C4) {
    /* Wendland C4, 2D: 9/(pi R^2) (1-q)^6 (1 + 6q + 35/3 q^2) */
    const real a = 1 - q, a3 = a * a * a;
    return (real)(9 / RHOD_PI) * iR2 * a3 * a3 * (1 + 6 * q + (real)(35.0 / 3) * q * q);
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
  return (real)(7 / (478 * RHOD_PI)) * 9 * iR2 * w;
}

/* dW/dr (<= 0). */
static inline real rhod_dW(int kind, real r, real R) {
  const real q = r / R;
  if (q >= 1)
    return 0;
  const real iR3 = 1 / (R * R * R);
  if (kind == RHOD_KERNEL_WENDLAND_C2) {
    const real a = 1 - q;
    return -(real)(140 / RHOD_PI) * iR3 * q * a * a * a;
  }
  if (kind == RHOD_KERNEL_WENDLAND_C4) {
    const real a = 1 - q, a5 = a * a * a * a * a;
    return -(real)(9 * 56 / (3 * RHOD_PI)) * iR3 * q * a5 * (1 + 5 * q);
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
  return (real)(7 / (478 * RHOD_PI)) * 27 * iR3 * w;
}

#endif
