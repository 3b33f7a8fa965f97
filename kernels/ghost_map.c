/* Ghost fields mapped from their source fluid particles (declared in boundary.h). Each
 * ghost g in [n, n + ng) reads its source gsrc[g] < n, so the loops write only ghost
 * entries and read only fluid ones: no order dependence. */
#include "rhod/boundary.h"

void rhod_ghosts_map_scalar(const rhod_particles *p, real *f) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  const int32_t *gsrc = p->gsrc;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++)
    f[g] = f[gsrc[g]];
}

void rhod_ghosts_map_u8(const rhod_particles *p, uint8_t *f) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  const int32_t *gsrc = p->gsrc;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++)
    f[g] = f[gsrc[g]];
}

void rhod_ghosts_map_vector(const rhod_particles *p, real *v) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  const int32_t *gsrc = p->gsrc;
  const real *gJ = p->gJ;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const long k = gsrc[g];
    const real *J = gJ + 4 * g, a = v[2 * k], b = v[2 * k + 1];
    v[2 * g] = J[0] * a + J[1] * b;
    v[2 * g + 1] = J[2] * a + J[3] * b;
  }
}

static void map_velocity(const rhod_particles *p, const real *gT, const real *gU, real *vx,
                         real *vy) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  const int32_t *gsrc = p->gsrc;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const long k = gsrc[g];
    const real *T = gT + 4 * g, a = vx[k], b = vy[k];
    /* u_g = T u_src + gU, gU the moving wall's part (0 where no wall moves) */
    vx[g] = T[0] * a + T[1] * b + gU[2 * g];
    vy[g] = T[2] * a + T[3] * b + gU[2 * g + 1];
  }
}

void rhod_ghosts_map_velocity(const rhod_particles *p, real *vx, real *vy) {
  map_velocity(p, p->gT, p->gU, vx, vy);
}

void rhod_ghosts_map_velocity_viscous(const rhod_particles *p, real *vx, real *vy) {
  if (p->gTv)
    map_velocity(p, p->gTv, p->gUv, vx, vy);
  else
    map_velocity(p, p->gT, p->gU, vx, vy);
}
