/* Shepard interpolation of a particle field at arbitrary points (paper 000 Sec. 3.2, Eq. 8:
 * <phi>(p) = sum_j V_j phi_j W(|p - x_j|, R_j) / sum_k V_k W(|p - x_k|, R_k)), the gather
 * paper 000 fills guard particles, constraint particles and markers of one level with from
 * the other level's particles, and the engine's pressure probe (src/sim.c). Engine side:
 * any field, any particles that a cell build sorted. */
#ifndef RHOD_SHEPARD_H
#define RHOD_SHEPARD_H

#include "rhod/cells.h"
#include "rhod/config.h"

/* For the np points (px[k], py[k]): fp[k] = the Shepard interpolation of the field f over
 * the particles of the last build of c (fluid and ghosts, c->nbuilt of them), each particle
 * j with its own radius R_j = ratio dx[j] and volume V[j], kernel `kern` (rhod_kernel_kind);
 * gamma[k] = its denominator sum_j V_j W (Shepard's Gamma, 1 in a full support); fp[k] = 0
 * where Gamma is 0 (no particle within reach). Every array on the device; px, py, fp and
 * gamma hold np values. The sums run over the cells in their order (row by row, by index
 * in a cell), the same on every run and thread count. */
void rhod_shepard(const rhod_cells *c, int kern, real ratio, const real *x, const real *y,
                  const real *dx, const real *V, const real *f, long np, const real *px,
                  const real *py, real *fp, real *gamma);

#endif
