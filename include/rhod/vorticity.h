/* The vorticity of the particle velocity field, for output (snapshots and pictures): the
 * engine side, any scheme. */
#ifndef RHOD_VORTICITY_H
#define RHOD_VORTICITY_H

#include "rhod/cells.h"
#include "rhod/particles.h"

/* w[i] = du_y/dx - du_x/dy of fluid particle i (i < p->n) from the renormalised gradient
 * of paper 002 Eq. 14 (exact for a linear velocity field): L_i^T sum_j (u_j - u_i) (x)
 * grad_i W_ij V_j, L_i = B_i^-1 of Eq. 8, over the last build of c (fluid and ghosts) with
 * i's radius ratio dx_i (a gather); where det B_i <= 1e-2 (a support too empty to invert,
 * as the scheme's L_i), the sum without L_i. A ghost's velocity is its no-slip one where
 * its wall or body is no-slip (p->gTv, p->gUv: the viscous terms' map), else the one it
 * carries. Every array on the device; w holds p->n values. */
void rhod_vorticity(const rhod_cells *c, const rhod_particles *p, int kern, real ratio,
                    const real *V, real *w);

#endif
