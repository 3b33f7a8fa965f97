/* Open boundaries, device side (open.h): the boundary particles of a step, gathered into a
 * short list, and their new mass and place written back. */
#include "rhod/open.h"
#include <math.h>
#include <stdlib.h>

/* the relative shortfall below which a particle holds its nominal mass (released) */
#define FULL_TOL ((real)1e-5)

static int ensure(rhod_open *o, size_t n) {
  if (n + 1 > o->cnt_cap || !o->cnt) {
    rhod_dev_free(o->cnt, o->cnt_cap * sizeof(int32_t));
    o->cnt_cap = n + n / 4 + 64;
    o->cnt = rhod_dev_calloc(o->cnt_cap, sizeof(int32_t));
    if (!o->cnt)
      return RHOD_ERR_MEMORY;
  }
  return RHOD_OK;
}

static int ensure_list(rhod_open *o, size_t nb) {
  if (nb <= o->bcap && o->bi)
    return RHOD_OK;
  rhod_dev_free(o->bi, o->bcap * sizeof(int32_t));
  rhod_dev_free(o->bf, o->bcap * RHOD_OPEN_BF * sizeof(real));
  o->bcap = nb + nb / 2 + 64;
  o->bi = rhod_dev_calloc(o->bcap, sizeof(int32_t));
  o->bf = rhod_dev_calloc(o->bcap * RHOD_OPEN_BF, sizeof(real));
  return o->bi && o->bf ? RHOD_OK : RHOD_ERR_MEMORY;
}

/* The open segment of b that particle (x, y) of size dx is a boundary particle of, or -1:
 * its cuboid (paper 001 Sec. 3.1: cross-section A = dx (rho0/rho)^{1/2} in 2D along the
 * boundary, extent l = m/(rho A) across it) overlaps the segment tangentially and touches
 * or crosses the boundary (l/2 - d >= 0, d the depth of its centre), or it still lacks mass
 * (m < m0 = rho0 dx^2) within one size of the boundary. Of several, the one under its
 * centre, then the nearest. */
static inline int open_seg_of(const real *seg, int s0, int s1, real x, real y, real A, real l,
                              real dx, int partial) {
  int best = -1, bover = 0;
  real bd = 0;
  for (int s = s0; s < s1; s++) {
    const real *S = seg + RHOD_SEG_STRIDE * s;
    const real rx = x - S[0], ry = y - S[1];
    const real d = S[2] * rx + S[3] * ry, t = S[4] * rx + S[5] * ry;
    if (!(t > -A / 2 && t < S[6] + A / 2))
      continue;
    const int touch = l / 2 - d >= -(real)1e-6 * dx;
    if (!(touch || (partial && d < dx)))
      continue;
    /* a segment under the particle's centre before one it only overlaps (two collinear
     * segments meeting: cases/open_channel_fs, where the first one kept the particles that
     * had drifted over the second, which then made new ones on top of them), then the
     * nearer */
    const int over = t >= 0 && t <= S[6];
    if (best < 0 || over > bover || (over == bover && fabs(d) < fabs(bd)))
      best = s, bd = d, bover = over;
  }
  return best;
}

long rhod_open_gather(rhod_open *o, const rhod_boundary *b, const rhod_particles *p,
                      const double *rho0_phase) {
  const long n = (long)p->n;
  const int s0 = b->open0, s1 = b->nwallseg;
  if (s1 <= s0)
    return 0;
  if (ensure(o, p->n) != RHOD_OK)
    return -1;
  const real *seg = b->seg, *x = p->x, *y = p->y, *m = p->m, *rho = p->rho, *dx = p->dx;
  const uint8_t *phase = p->phase;
  const real r00 = (real)rho0_phase[0], r01 = (real)rho0_phase[1], r02 = (real)rho0_phase[2],
             r03 = (real)rho0_phase[3], r04 = (real)rho0_phase[4], r05 = (real)rho0_phase[5],
             r06 = (real)rho0_phase[6], r07 = (real)rho0_phase[7];
  int32_t *cnt = o->cnt;
#define RHO0_OF(i)                                                                                 \
  (!phase ? r00                                                                                    \
          : (phase[i] == 0   ? r00                                                                 \
             : phase[i] == 1 ? r01                                                                 \
             : phase[i] == 2 ? r02                                                                 \
             : phase[i] == 3 ? r03                                                                 \
             : phase[i] == 4 ? r04                                                                 \
             : phase[i] == 5 ? r05                                                                 \
             : phase[i] == 6 ? r06                                                                 \
                             : r07))
  RHOD_KERNEL_LOOP
  for (long i = 0; i <= n; i++) {
    if (i == n) {
      cnt[i] = 0;
      continue;
    }
    const real r0 = RHO0_OF(i);
    const real A = dx[i] * sqrt(r0 / rho[i]), l = m[i] / (rho[i] * A);
    const int partial = m[i] < r0 * dx[i] * dx[i] * (1 - FULL_TOL);
    cnt[i] = open_seg_of(seg, s0, s1, x[i], y[i], A, l, dx[i], partial) >= 0;
  }
  const long nb = rhod_scan_exclusive(cnt, (size_t)n + 1);
  if (nb < 0 || ensure_list(o, (size_t)nb) != RHOD_OK)
    return -1;
  int32_t *bi = o->bi;
  real *bf = o->bf;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    if (cnt[i + 1] == cnt[i])
      continue;
    const long k = cnt[i];
    const real r0 = RHO0_OF(i);
    const real A = dx[i] * sqrt(r0 / rho[i]), l = m[i] / (rho[i] * A);
    const real m0 = r0 * dx[i] * dx[i];
    const int partial = m[i] < m0 * (1 - FULL_TOL);
    const int s = open_seg_of(seg, s0, s1, x[i], y[i], A, l, dx[i], partial);
    const real *S = seg + RHOD_SEG_STRIDE * s;
    const real d = S[2] * (x[i] - S[0]) + S[3] * (y[i] - S[1]);
    const real t = S[4] * (x[i] - S[0]) + S[5] * (y[i] - S[1]);
    /* paper 001 Eq. 23 after the move: what of the cuboid now lies beyond the boundary,
     * l/2 - d (negative: the gap a particle in contact left behind, which it fills),
     * limited by 0 <= m + dm* <= m0 (Eq. 24) */
    real dm = -rho[i] * A * (l / 2 - d);
    /* the upper limit holds growth only: a particle made heavier than m0 (a hydrostatic
     * fill's m = rho dx^2) keeps its mass until it crosses (cases/open_channel_fs) */
    const real room = m0 - m[i] > 0 ? m0 - m[i] : 0;
    dm = dm < -m[i] ? -m[i] : (dm > room ? room : dm);
    real *F = bf + RHOD_OPEN_BF * k;
    bi[k] = (int32_t)i;
    F[0] = (real)s, F[1] = t, F[2] = d, F[3] = A, F[4] = m[i], F[5] = rho[i], F[6] = m0;
    F[7] = dm, F[8] = x[i], F[9] = y[i], F[10] = dx[i];
  }
#undef RHO0_OF
  rhod_to_host(bi, sizeof(int32_t) * (size_t)nb);
  rhod_to_host(bf, sizeof(real) * RHOD_OPEN_BF * (size_t)nb);
  return nb;
}

void rhod_open_scatter(rhod_open *o, rhod_particles *p, long nb, int32_t *keep) {
  const long n = (long)p->n;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++)
    keep[i] = 1;
  if (nb == 0)
    return;
  rhod_to_device(o->bf, sizeof(real) * RHOD_OPEN_BF * (size_t)nb);
  const int32_t *bi = o->bi;
  const real *bf = o->bf;
  real *x = p->x, *y = p->y, *m = p->m;
  RHOD_KERNEL_LOOP
  for (long k = 0; k < nb; k++) {
    const long i = bi[k];
    const real *F = bf + RHOD_OPEN_BF * k;
    m[i] = F[4];
    x[i] = F[8];
    y[i] = F[9];
    keep[i] = F[4] > 0;
  }
}

void rhod_open_born(rhod_particles *p, int32_t *src, real *nf, uint8_t *ph, int count) {
  const size_t sb = sizeof(int32_t) * (size_t)count, fb = sizeof(real) * 7 * (size_t)count;
  rhod_dev_map(src, sb);
  rhod_dev_map(nf, fb);
  rhod_dev_map(ph, (size_t)count);
  const long n0 = (long)p->n;
  rhod_particles_append(p, src, (size_t)count);
  real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy, *rho = p->rho, *m = p->m, *dx = p->dx;
  uint8_t *phase = p->phase;
  RHOD_KERNEL_LOOP
  for (long c = 0; c < count; c++) {
    const real *N = nf + 7 * c;
    const long i = n0 + c;
    x[i] = N[0], y[i] = N[1], ux[i] = N[2], uy[i] = N[3], rho[i] = N[4], m[i] = N[5];
    dx[i] = N[6];
    if (phase)
      phase[i] = ph[c];
  }
  rhod_dev_unmap(src, sb);
  rhod_dev_unmap(nf, fb);
  rhod_dev_unmap(ph, (size_t)count);
}

double rhod_open_mass(const rhod_particles *p) {
  const long n = (long)p->n;
  const real *m = p->m;
  double sum = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, sum)
  for (long i = 0; i < n; i++)
    sum += (double)m[i];
  return sum;
}
