/* RHOD-SPH passes (paper 002, Secs. III-IV; order of ../shared/design/scheme.md).
 * Every pass is a gather: it writes only particle i's own entries. Conventions:
 * n_ij = (x_j - x_i)/r, grad_i W_ij = -W'(r; R_i) n_ij = F n_ij with F >= 0, and
 * W taken with the radius of the gathering particle i. */
#include "rhod/kernel.h"
#include "rhod/rhodsph/sph.h"
#include "rhodsph/sph_pair.h"
#include <float.h>
#include <math.h>
#include <string.h>

/* The gathers of passes A and C are written per particle (pass_a_particle,
 * pass_c_particle). The host build inlines them into specialised copies (below);
 * GCC 12's nvptx compiler fails (internal error) on a forced inline inside a target
 * region, and the device build has one copy anyway. */
#ifdef RHOD_OFFLOAD
#define PARTICLE_BODY static inline
#else
#define PARTICLE_BODY static inline __attribute__((always_inline))
#endif

/* The pair of i with the packed candidate k (RHOD_FOR_ROWS loops, xi, yi, R2 and the
 * rows kx, ky in scope): declares rx, ry, r2, r, ir and n_ij = (nx, ny), or skips (continue)
 * a candidate outside the support and one at r = 0: i itself, or a particle on top of i,
 * which has no n_ij (docs/choices.md). */
#define PAIR_OR_SKIP(k)                                                                            \
  const real rx = kx[k] - xi, ry = ky[k] - yi, r2 = rx * rx + ry * ry;                             \
  if (!(r2 < R2 && r2 > 0))                                                                        \
    continue;                                                                                      \
  const real r = sqrt(r2), ir = 1 / r;                                                             \
  const real nx = rx * ir, ny = ry * ir

/* a balanced scheme.shifting_switch: the Eq. 4 momentum term of pass C with du' at the
 * size jumps (rhod_sph_pass_jumps) */
static inline int rhod_sph_balanced(const rhod_sph *s) {
  return s->shsw == RHOD_SHSW_BALANCED || s->shsw == RHOD_SHSW_BALANCED_MOMENTUM;
}

int rhod_sph_init(rhod_sph *s, const rhod_scene *sc, rhod_particles *p) {
  memset(s, 0, sizeof *s);
  s->kernel = sc->kernel;
  s->ratio = (real)sc->radius_ratio;
  s->rho0 = (real)sc->rs->rho0;
  s->c0 = (real)sc->rs->c0;
  s->mu = (real)sc->rs->mu;
  s->gx = (real)sc->gravity[0];
  s->gy = (real)sc->gravity[1];
  s->cfl = (real)sc->rs->cfl;
  s->cfl_visc = (real)sc->rs->cfl_visc;
  s->riemann = sc->rs->riemann;
  s->recon = sc->rs->reconstruction;
  s->shifting = sc->rs->shifting;
  s->damper = sc->rs->acoustic_damper;
  s->fsdetect = sc->rs->free_surface;
  s->tic = sc->rs->tensile_control;
  s->shsw = sc->rs->shifting_switch;
  s->adlim = sc->rs->acoustic_damper && sc->rs->damper_step_limit;
  s->stlim = sc->rs->stiffness_limit && sc->integrator == RHOD_INTEGRATOR_RK4;
  s->alpha_ad = (real)sc->rs->alpha_ad;
  s->sa = (real)sc->rs->shift_a;
  s->sb = (real)sc->rs->shift_b;
  s->seps = (real)sc->rs->shift_eps;
  s->lam_lo = (real)sc->rs->fs_lambda_low;
  s->lam_hi = (real)sc->rs->fs_lambda_high;
  s->gamma_th = (real)sc->rs->shepard_threshold;
  s->theta_th = (real)sc->rs->theta_threshold;
  s->visc_cons = sc->rs->viscosity == RHOD_VISCOSITY_CONSISTENT && sc->rs->mu > 0;
  s->walls_move = rhod_scene_walls_move(sc);
  int st = RHOD_OK;
#define F(var, k)                                                                                  \
  if (st == RHOD_OK)                                                                               \
  st = rhod_particles_add_field(p, #var, (void **)&s->var, (k) * sizeof(*s->var), 0)
  F(P, 1);
  F(V, 1);
  F(gam, 1);
  F(ggam, 2);
  F(L, 4);
  F(gP, 2);
  F(gu, 4);
  F(D, 1);
  F(gC, 2);
  F(uch, 1);
  F(lam, 1);
  F(nrm, 2);
  F(nt, 2);
  F(sig, 1);
  F(du, 2);
  F(drho, 1);
  F(acc, 2);
  F(vel, 2);
  F(fs, 1);
  F(reg, 1);
  if (s->visc_cons) /* a scene without it does not carry it */
    F(lapB, 3);
  const int bal = rhod_sph_balanced(s);
  if (bal) {
    F(jmp, 1);
    F(jM, 3);
    F(dup, 2);
  }
  /* no slip in the viscous terms alone: their velocity and its two pack rows */
  s->vrow = sc->rs->mu > 0 && p->gTv ? RHOD_PK_UV_ROW(bal) : 0;
  if (s->vrow)
    F(uv, 2);
  F(pk, RHOD_PK_UV_ROW(bal) + (s->vrow ? 2 : 0));
  if (s->adlim) {
    st = st == RHOD_OK ? rhod_particles_add_field(p, "adv", (void **)&s->adv, 2 * sizeof *s->adv, 1)
                       : st;
    F(adD, 1);
    F(adG, 4);
  }
#undef F
  return st;
}

void rhod_sph_free(rhod_sph *s) {
  rhod_cells_free(&s->fsc);
  rhod_cells_free(&s->jsc);
}

void rhod_sph_fill_state(rhod_sph *s, rhod_particles *p) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  real *ux = p->ux, *uy = p->uy, *rho = p->rho, *P = s->P, *V = s->V;
  const real *m = p->m, *gT = p->gT, *gU = p->gU, *ge = p->ge, *gA = p->gA;
  const int32_t *gsrc = p->gsrc;
  const real c0 = s->c0, c2 = s->c0 * s->c0, rho0 = s->rho0, gx = s->gx, gy = s->gy;
  const int walls_move = s->walls_move;
  (void)c0;
  real *uv = s->uv;
  const real *gTv = p->gTv, *gUv = p->gUv;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    P[i] = c2 * (rho[i] - rho0); /* Eq. 2 */
    V[i] = m[i] / rho[i];
    if (uv)
      uv[2 * i] = ux[i], uv[2 * i + 1] = uy[i];
  }
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const int k = gsrc[g];
    const real *T = gT + 4 * g;
    /* u' = T u + gU (boundary.h): gU is a moving wall's part, added only when a wall
     * moves, so that a scene at rest computes exactly what it did before */
    real ugx = T[0] * ux[k] + T[1] * uy[k], ugy = T[2] * ux[k] + T[3] * uy[k];
    if (walls_move)
      ugx += gU[2 * g], ugy += gU[2 * g + 1];
    ux[g] = ugx;
    uy[g] = ugy;
    if (uv) { /* the viscous terms' map (docs/choices.md "no slip in the viscous term only") */
      const real *Tv = gTv + 4 * g;
      real vgx = Tv[0] * ux[k] + Tv[1] * uy[k], vgy = Tv[2] * ux[k] + Tv[3] * uy[k];
      if (walls_move)
        vgx += gUv[2 * g], vgy += gUv[2 * g + 1];
      uv[2 * g] = vgx;
      uv[2 * g + 1] = vgy;
    }
    /* Hydrostatic correction of the mirrored pressure (scheme.md, Walls). Our choice:
     * the exact weakly compressible profile of the state law (Eq. 2), along which
     * c0^2 d rho = rho g . dx, so rho_g = rho_k exp(a) with a = g . (x_g - x_k) / c0^2,
     * and P_g = P_k + rho_k c0^2 expm1(a). The linear form P_k + rho_k g . (x_g - x_k)
     * is off by rho g^2 d^2 / (2 c0^2) (about 1 Pa two radii below a 1 m column at
     * c0 = 10 sqrt(gH)): enough for the Riemann flux of Eq. 22 between the first rows
     * and their ghosts to pump mass upward through a tank at rest
     * (cases/hydrostatic/RESULTS.md). */
    const real Pk = c2 * (rho[k] - rho0);
    /* a moving body's ghost: g - a_w, the acceleration its boundary has at the mirror's
     * foot (docs/choices.md "bodies"); gA is 0 for walls, absent without bodies */
    const real a = rhod_ghost_head(ge, gA, gx, gy, g) / c2;
    const real Pg = Pk + rho[k] * c2 * expm1(a);
    P[g] = Pg;
    rho[g] = rho0 + Pg / c2;
    V[g] = m[g] / rho[g];
  }
}

static void pack_a(rhod_sph *s, const rhod_particles *p, const rhod_cells *c) {
  const long nt = (long)(p->n + p->ng), st = (long)p->cap;
  real *pk = s->pk;
  rhod_cells_pack(c, nt, pk + RHOD_PK_X * st, p->x, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_Y * st, p->y, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_V * st, s->V, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_P * st, s->P, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_UX * st, p->ux, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_UY * st, p->uy, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_DX * st, p->dx, 1, 0);
}

static void pack_c(rhod_sph *s, const rhod_particles *p, const rhod_cells *c) {
  const long nt = (long)(p->n + p->ng), st = (long)p->cap;
  real *pk = s->pk;
  rhod_cells_pack(c, nt, pk + RHOD_PK_D * st, s->D, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_GPX * st, s->gP, 2, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_GPY * st, s->gP, 2, 1);
  for (int a = 0; a < 4; a++)
    rhod_cells_pack(c, nt, pk + (RHOD_PK_GU0 + a) * st, s->gu, 4, a);
  rhod_cells_pack(c, nt, pk + RHOD_PK_DUX * st, s->du, 2, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_DUY * st, s->du, 2, 1);
  rhod_cells_pack(c, nt, pk + RHOD_PK_RHO * st, p->rho, 1, 0);
  if (s->dup) { /* a balanced shifting switch only */
    rhod_cells_pack(c, nt, pk + RHOD_PK_DPX * st, s->dup, 2, 0);
    rhod_cells_pack(c, nt, pk + RHOD_PK_DPY * st, s->dup, 2, 1);
  }
  if (s->vrow) { /* no slip in the viscous terms alone */
    rhod_cells_pack(c, nt, pk + s->vrow * st, s->uv, 2, 0);
    rhod_cells_pack(c, nt, pk + (s->vrow + 1) * st, s->uv, 2, 1);
  }
}

/* The particle loop of a gather whose body is FN(i, args..., kernel): the host build
 * calls a copy in which the default kernel is a constant (unless s->generic), the device
 * build its one copy. */
#ifdef RHOD_OFFLOAD
#define GATHER_BY_KERNEL(n, kern, generic, FN, ...)                                                \
  RHOD_GATHER_LOOP                                                                                 \
  for (long i = 0; i < (n); i++)                                                                   \
  FN(i, __VA_ARGS__, kern)
#else
#define GATHER_BY_KERNEL(n, kern, generic, FN, ...)                                                \
  RHOD_GATHER_LOOP                                                                                 \
  for (long i = 0; i < (n); i++) {                                                                 \
    if ((kern) == RHOD_KERNEL_WENDLAND_C2 && !(generic))                                           \
      FN(i, __VA_ARGS__, RHOD_KERNEL_WENDLAND_C2);                                                 \
    else                                                                                           \
      FN(i, __VA_ARGS__, kern);                                                                    \
  }
#endif

/* Pass A: Gamma, grad Gamma, B = L^-1, raw gradients of P and u, div u, grad C,
 * U_char; then L, the renormalised gradients (Eq. 14) and lambda, per particle. As in
 * pass C (below), the gather of one particle is an inlined function: the host build
 * compiles a copy for the default kernel in which it is a constant. */
#define PA_PARAMS                                                                                  \
  rhod_grid G, const int32_t *CS, const real *x, const real *y, const real *ux, const real *uy,    \
      const real *dx, const real *P, const real *V, const real *pk, long st, real *gam,            \
      real *ggam, real *L, real *gP, real *gu, real *D, real *gC, real *uch, real *lam,            \
      real *lapB, uint8_t *jmp, real *jB, const real ratio, const int vcons
#define PA_ARGS                                                                                    \
  G, CS, x, y, ux, uy, dx, P, V, pk, st, gam, ggam, L, gP, gu, D, gC, uch, lam, lapB, jmp, jB,     \
      ratio, vcons

PARTICLE_BODY void pass_a_particle(long i, PA_PARAMS, const int kern) {
  const real *kx = pk + RHOD_PK_X * st, *ky = pk + RHOD_PK_Y * st, *kV = pk + RHOD_PK_V * st,
             *kP = pk + RHOD_PK_P * st, *kux = pk + RHOD_PK_UX * st, *kuy = pk + RHOD_PK_UY * st,
             *kdx = pk + RHOD_PK_DX * st;
  const real xi = x[i], yi = y[i], Ri = ratio * dx[i], R2 = Ri * Ri;
  const real uxi = ux[i], uyi = uy[i], Pi = P[i], dxi = dx[i];
  const real iR = 1 / Ri, iR2 = iR * iR, iR3 = iR2 * iR;
  const real iWdx = 1 / rhod_Wq(kern, dxi * iR); /* R^-2/W(dx_ij) of Eq. 29, dx_j = dx_i */
  real RHOD_LANES(sg), RHOD_LANES(sggx), RHOD_LANES(sggy), RHOD_LANES(sB0), RHOD_LANES(sB1),
      RHOD_LANES(sB2), RHOD_LANES(sB3), RHOD_LANES(sGPx), RHOD_LANES(sGPy), RHOD_LANES(sGu0),
      RHOD_LANES(sGu1), RHOD_LANES(sGu2), RHOD_LANES(sGu3), RHOD_LANES(scx), RHOD_LANES(scy),
      RHOD_LANES(such), RHOD_LANES(sjmp);
  const real tol = RHOD_SIZE_TOL * dxi;
  RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
    RHOD_FOR_LANES(k0, kv, k) {
      PAIR_OR_SKIP(k);
      const real Vj = kV[k];
      const real q = r * iR;
      const real F = -rhod_dWq(kern, q) * iR3 * Vj; /* |grad_i W_ij| V_j */
      const real Wq = rhod_Wq(kern, q), Wv = Wq * iR2 * Vj;
      const real gwx = F * nx, gwy = F * ny;
      RHOD_LANE(sg) += Wv;                                    /* Eq. 7 */
      RHOD_LANE(sggx) += gwx, RHOD_LANE(sggy) += gwy;         /* Eq. 27 */
      RHOD_LANE(sB0) += rx * gwx, RHOD_LANE(sB1) += rx * gwy; /* Eq. 8: B_ab = sum r_a g_b V */
      RHOD_LANE(sB2) += ry * gwx, RHOD_LANE(sB3) += ry * gwy;
      const real dP = kP[k] - Pi, dux = kux[k] - uxi, duy = kuy[k] - uyi;
      RHOD_LANE(sGPx) += dP * gwx, RHOD_LANE(sGPy) += dP * gwy; /* Eq. 14, raw */
      RHOD_LANE(sGu0) += dux * gwx, RHOD_LANE(sGu1) += dux * gwy;
      RHOD_LANE(sGu2) += duy * gwx, RHOD_LANE(sGu3) += duy * gwy;
      /* Eq. 29: [1 + 0.2 (W_ij / W(dx_ij))^4] grad_i W_ij V_j, W(dx_ij) with R_i */
      const real dxj = kdx[k];
      const real wr = dxj == dxi ? Wq * iWdx : Wq / rhod_Wq(kern, (real)0.5 * (dxi + dxj) * iR);
      const real f = 1 + (real)0.2 * wr * wr * wr * wr;
      RHOD_LANE(scx) += f * gwx, RHOD_LANE(scy) += f * gwy;
      const real un = fabs(dux * nx + duy * ny); /* U_char, after Eq. 27 */
      RHOD_LANE(such) = un > RHOD_LANE(such) ? un : RHOD_LANE(such);
      RHOD_LANE(sjmp) = fabs(dxj - dxi) > tol ? 1 : RHOD_LANE(sjmp); /* another size */
    }
    RHOD_END_LANES
  }
  RHOD_END_ROWS
  const real g = rhod_Wq(kern, 0) * iR2 * V[i] + RHOD_LANES_SUM(sg); /* Eq. 7, self term too */
  const real ggx = RHOD_LANES_SUM(sggx), ggy = RHOD_LANES_SUM(sggy);
  const real B0 = RHOD_LANES_SUM(sB0), B1 = RHOD_LANES_SUM(sB1), B2 = RHOD_LANES_SUM(sB2),
             B3 = RHOD_LANES_SUM(sB3);
  const real GPx = RHOD_LANES_SUM(sGPx), GPy = RHOD_LANES_SUM(sGPy);
  const real Gu0 = RHOD_LANES_SUM(sGu0), Gu1 = RHOD_LANES_SUM(sGu1), Gu2 = RHOD_LANES_SUM(sGu2),
             Gu3 = RHOD_LANES_SUM(sGu3);
  const real cx = RHOD_LANES_SUM(scx), cy = RHOD_LANES_SUM(scy), um = RHOD_LANES_MAX(such);
  const real div = Gu0 + Gu3; /* Eq. 5: sum (u_j - u_i) . grad_i W_ij V_j, the trace */
  gam[i] = g;
  ggam[2 * i] = ggx, ggam[2 * i + 1] = ggy;
  D[i] = div;
  gC[2 * i] = cx, gC[2 * i + 1] = cy;
  uch[i] = um;
  if (jmp) {
    /* a balanced shifting switch (rhod_sph_pass_jumps): another size within R_i, and B,
     * which is the scatter moment M within R_i where every neighbour there has i's size */
    jmp[i] = RHOD_LANES_MAX(sjmp) > 0;
    jB[3 * i] = B0, jB[3 * i + 1] = (real)0.5 * (B1 + B2), jB[3 * i + 2] = B3;
  }
  const real Bm[4] = {B0, B1, B2, B3};
  lam[i] = rhod_min_eig_sym(Bm);
  /* L = B^-1 (Eq. 8), the identity where B is too near singular (kernel.h) */
  RHOD_RENORM_L(B0, B1, B2, B3, L0, L1, L2, L3);
  L[4 * i] = L0, L[4 * i + 1] = L1, L[4 * i + 2] = L2, L[4 * i + 3] = L3;
  /* exact for linear fields: sum (a.r) g V = B^T a, so grad = L^T G (scheme.md) */
  gP[2 * i] = L0 * GPx + L2 * GPy;
  gP[2 * i + 1] = L1 * GPx + L3 * GPy;
  gu[4 * i] = L0 * Gu0 + L2 * Gu1;
  gu[4 * i + 1] = L1 * Gu0 + L3 * Gu1;
  gu[4 * i + 2] = L0 * Gu2 + L2 * Gu3;
  gu[4 * i + 3] = L1 * Gu2 + L3 * Gu3;
  if (vcons) {
    /* moments of the consistent Laplacian: T = sum F r n n n n, Q = sum F n n n, P3 =
     * sum F r^2 n n n (fully symmetric; digits count the x and y indices), in a loop of
     * their own so that a scene without it pays nothing */
    real RHOD_LANES(s40), RHOD_LANES(s31), RHOD_LANES(s22), RHOD_LANES(s13), RHOD_LANES(s04);
    real RHOD_LANES(q30), RHOD_LANES(q21), RHOD_LANES(q12), RHOD_LANES(q03);
    real RHOD_LANES(p30), RHOD_LANES(p21), RHOD_LANES(p12), RHOD_LANES(p03);
    RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
      RHOD_FOR_LANES(k0, kv, k) {
        PAIR_OR_SKIP(k);
        const real F = -rhod_dWq(kern, r * iR) * iR3 * kV[k];
        const real exx = nx * nx, exy = nx * ny, eyy = ny * ny, a = F * r, b = F * r2;
        RHOD_LANE(s40) += a * exx * exx, RHOD_LANE(s31) += a * exx * exy;
        RHOD_LANE(s22) += a * exx * eyy, RHOD_LANE(s13) += a * exy * eyy;
        RHOD_LANE(s04) += a * eyy * eyy;
        RHOD_LANE(q30) += F * exx * nx, RHOD_LANE(q21) += F * exx * ny;
        RHOD_LANE(q12) += F * eyy * nx, RHOD_LANE(q03) += F * eyy * ny;
        RHOD_LANE(p30) += b * exx * nx, RHOD_LANE(p21) += b * exx * ny;
        RHOD_LANE(p12) += b * eyy * nx, RHOD_LANE(p03) += b * eyy * ny;
      }
      RHOD_END_LANES
    }
    RHOD_END_ROWS
    const real T40 = RHOD_LANES_SUM(s40), T31 = RHOD_LANES_SUM(s31), T22 = RHOD_LANES_SUM(s22),
               T13 = RHOD_LANES_SUM(s13), T04 = RHOD_LANES_SUM(s04);
    const real Q30 = RHOD_LANES_SUM(q30), Q21 = RHOD_LANES_SUM(q21), Q12 = RHOD_LANES_SUM(q12),
               Q03 = RHOD_LANES_SUM(q03);
    const real P30 = RHOD_LANES_SUM(p30), P21 = RHOD_LANES_SUM(p21), P12 = RHOD_LANES_SUM(p12),
               P03 = RHOD_LANES_SUM(p03);
    /* The consistent Laplacian (our choice for scheme.viscosity: consistent, in the
     * manner of Fatehi & Manzari 2011; paper 002 names such higher-order operators
     * after Eq. 10 without giving one): lap f_i = B^ : sum_j 2 F n n ((f_j - f_i)/r -
     * n . grad f_i), grad f the renormalised gradient above. A Taylor expansion gives
     * sum = T' : H with T'_abcd = T_abcd - Q_abm M_mcd, M = L^T P3 (the gradient's
     * own error on a quadratic field), so B^ solves B^_ab T'_abcd = delta_cd and the
     * operator is exact for quadratic fields on any cloud (tests/test_kernels.c). On
     * a lattice T' = (delta delta + 2 sym) / 4 and B^ = I. */
    const real Mx0 = L0 * P30 + L2 * P21, Mx1 = L0 * P21 + L2 * P12, Mx2 = L0 * P12 + L2 * P03;
    const real My0 = L1 * P30 + L3 * P21, My1 = L1 * P21 + L3 * P12, My2 = L1 * P12 + L3 * P03;
    /* T'_(ab)(cd), ab and cd in xx (0), xy (1), yy (2) */
    const real t00 = T40 - (Q30 * Mx0 + Q21 * My0), t01 = T31 - (Q30 * Mx1 + Q21 * My1),
               t02 = T22 - (Q30 * Mx2 + Q21 * My2);
    const real t10 = T31 - (Q21 * Mx0 + Q12 * My0), t11 = T22 - (Q21 * Mx1 + Q12 * My1),
               t12 = T13 - (Q21 * Mx2 + Q12 * My2);
    const real t20 = T22 - (Q12 * Mx0 + Q03 * My0), t21 = T13 - (Q12 * Mx1 + Q03 * My1),
               t22 = T04 - (Q12 * Mx2 + Q03 * My2);
    /* rows cd = xx, yy, xy; unknowns (B^xx, B^xy, B^yy); right side (1, 1, 0) */
    const real a00 = t00, a01 = 2 * t10, a02 = t20;
    const real a10 = t02, a11 = 2 * t12, a12 = t22;
    const real a20 = t01, a21 = 2 * t11, a22 = t21;
    const real det = a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20) +
                     a02 * (a10 * a21 - a11 * a20);
    real bxx = 0, bxy = 0, byy = 0;
    /* our choice: |det| below a tenth of the full support's 1/4 leaves B^ = 0, and
     * pass C uses Eq. 10 for that particle */
    if (fabs(det) > (real)0.025) {
      const real id = 1 / det;
      bxx = ((a11 * a22 - a12 * a21) - (a01 * a22 - a02 * a21)) * id;
      bxy = ((a00 * a22 - a02 * a20) - (a10 * a22 - a12 * a20)) * id;
      byy = ((a10 * a21 - a11 * a20) - (a00 * a21 - a01 * a20)) * id;
    }
    lapB[3 * i] = bxx, lapB[3 * i + 1] = bxy, lapB[3 * i + 2] = byy;
  }
}

void rhod_sph_pass_a(rhod_sph *s, rhod_particles *p, const rhod_cells *c) {
  pack_a(s, p, c);
  const long n = (long)p->n, st = (long)p->cap;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start;
  const real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy, *dx = p->dx;
  const real *P = s->P, *V = s->V, *pk = s->pk;
  real *gam = s->gam, *ggam = s->ggam, *L = s->L, *gP = s->gP, *gu = s->gu, *D = s->D, *gC = s->gC,
       *uch = s->uch, *lam = s->lam, *lapB = s->lapB;
  uint8_t *jmp = s->shifting ? s->jmp : NULL;
  real *jB = s->jM;
  const int kern = s->kernel, vcons = s->visc_cons, generic = s->generic;
  const real ratio = s->ratio;
  (void)generic;
  GATHER_BY_KERNEL(n, kern, generic, pass_a_particle, PA_ARGS);
}

/* div u of a ghost (shared by rhod_sph_mirror_gradients and the damper probe). Where the map
 * is a free-slip mirror, one that reverses the normal velocity and keeps the tangential one's
 * sign, the source's own raw (Eq. 5) value Dk: D enters Eq. 9 as P does Eq. 6, so its ghost
 * mirrors it as the pressure is mirrored. That is T = J (the plane mirror, a corner's double
 * mirror, the periodic images) and a circle's single curved mirror T = k (I - e e^T) - e e^T,
 * k = r_g/r_s > 0 (kernels/ghosts.c), J = I - 2 e e^T: det J < 0, T e = -e, tr T = k - 1 > -1,
 * tested as T (I - J) = -(I - J) with e e^T = (I - J)/2. Elsewhere (no slip T = -I, the open
 * boundaries' maps) the trace of the mapped gradient (T U) J^T, U the source's renormalised
 * gradient (row-major). The curved mirror's trace, k U_tt + U_nn, would add (k - 1) U_tt =
 * O(dx/a) |u - u_w|/a, a damper pressure of order alpha rho0 c0 R |u - u_w| dx/a^2 that pushed a
 * cylinder moving through still water along its velocity (docs/choices.md "ghost values"). */
static inline real ghost_div(const real *J, const real *T, const real *U, real Dk) {
  if (T[0] == J[0] && T[1] == J[1] && T[2] == J[2] && T[3] == J[3])
    return Dk;
  const real N0 = (1 - J[0]) * (real)0.5, N1 = -J[1] * (real)0.5, N2 = -J[2] * (real)0.5,
             N3 = (1 - J[3]) * (real)0.5;
  const real e0 = T[0] * N0 + T[1] * N2 + N0, e1 = T[0] * N1 + T[1] * N3 + N1;
  const real e2 = T[2] * N0 + T[3] * N2 + N2, e3 = T[2] * N1 + T[3] * N3 + N3;
  const real tol = (real)1e-5;
  if (J[0] * J[3] - J[1] * J[2] < 0 && T[0] + T[3] > -1 && fabs(e0) < tol && fabs(e1) < tol &&
      fabs(e2) < tol && fabs(e3) < tol)
    return Dk;
  const real M0 = T[0] * U[0] + T[1] * U[2], M1 = T[0] * U[1] + T[1] * U[3];
  const real M2 = T[2] * U[0] + T[3] * U[2], M3 = T[2] * U[1] + T[3] * U[3];
  return (M0 * J[0] + M1 * J[1]) + (M2 * J[2] + M3 * J[3]);
}

/* Ghost copies of the pass A gradients: grad P' = e^a J grad P + rho' (I - J) g, the
 * gradient at the ghost of the hydrostatic-corrected ghost pressure of
 * rhod_sph_fill_state (P' = c0^2 (rho e^a - rho0), a = g . (x' - x) / c0^2, x' = J x + b,
 * J^-1 = J; e^a = rho'/rho), grad u' = T (grad u) J^T, div u' = tr grad u'. */
void rhod_sph_mirror_gradients(rhod_sph *s, rhod_particles *p) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  const int32_t *gsrc = p->gsrc;
  const real *gJ = p->gJ, *gT = p->gT, *rho = p->rho, *gA = p->gA;
  real *gP = s->gP, *gu = s->gu, *D = s->D;
  const real gx0 = s->gx, gy0 = s->gy;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const int k = gsrc[g];
    const real *J = gJ + 4 * g, *T = gT + 4 * g;
    const real px = gP[2 * k], py = gP[2 * k + 1];
    /* a moving body's ghost: g - a_w, as its pressure (rhod_sph_fill_state) */
    real gx = gx0, gy = gy0;
    if (gA)
      gx -= gA[2 * g], gy -= gA[2 * g + 1];
    const real Jgx = J[0] * gx + J[1] * gy, Jgy = J[2] * gx + J[3] * gy;
    const real ea = rho[g] / rho[k];
    gP[2 * g] = ea * (J[0] * px + J[1] * py) + rho[g] * (gx - Jgx);
    gP[2 * g + 1] = ea * (J[2] * px + J[3] * py) + rho[g] * (gy - Jgy);
    const real *U = gu + 4 * k;
    /* M = T U */
    const real M0 = T[0] * U[0] + T[1] * U[2], M1 = T[0] * U[1] + T[1] * U[3];
    const real M2 = T[2] * U[0] + T[3] * U[2], M3 = T[2] * U[1] + T[3] * U[3];
    /* M J^T */
    real *O = gu + 4 * g;
    O[0] = M0 * J[0] + M1 * J[1];
    O[1] = M0 * J[2] + M1 * J[3];
    O[2] = M2 * J[0] + M3 * J[1];
    O[3] = M2 * J[2] + M3 * J[3];
    D[g] = ghost_div(J, T, U, D[k]);
  }
}

/* The size jumps of a balanced scheme.shifting_switch (our choice, docs/choices.md
 * "balanced shifting switch"; paper 002 Eq. 4 writes the momentum term in the sum form). The Eq. 4
 * momentum term's torque plus that of moving the particles at u + du (Eq. 3's dx/dt) is, summed
 * over the fluid, sum m (x x u) ((c s - sigma) . du') - sum m ((M du' - du) x u), with s = sum
 * grad_i W(r_ij, R_i) V_j the gather gradient of Gamma (Eq. 27), sigma = sum grad_i W(r_ij, R_j)
 * V_j the scatter one, M = sum V_j r |dW/dr(r_ij, R_j)| n_ij n_ij the scatter moment, c = +1 in the
 * sum form of Eq. 4 and -1 in the difference form, and du' the shifting velocity that the momentum
 * term carries (cases/rotating_square/RESULTS.md "The shifting at a size jump"). Where every
 * particle within reach has i's size, sigma = s and M = B of Eq. 8, so the paper's sum form leaves
 * only the (B - I) du part, as in single resolution. At a size jump sigma != s and M != B: there
 * the momentum term takes the difference form with du' = M^-1 du, which removes the second sum. A
 * jump particle has one of another size within max(R_i, R_j). Pass A flags those with one within
 * R_i; a coarser j with R_i <= r < R_j is itself flagged (i lies within its R_j), and so are the
 * ghosts. So a particle that pass A did not flag looks for such a j among the flagged ones alone
 * (the subset cells jsc, with their x, y, V and dx packed in its order), and skips even that when
 * none lies within the largest radius (two reads per row of the subset). Within R_i such a particle
 * has only neighbours of its own size, where M's sum is pass A's B (left in jM), so only the
 * particles pass A flagged gather M within R_i again. Writes jmp (1 at a jump) and jM (M there, 0
 * elsewhere) of the fluid. */
PARTICLE_BODY void jumps_particle(long i, const rhod_grid G, const int32_t *CS, const rhod_grid GS,
                                  const int32_t *SS, const real *x, const real *y, const real *dx,
                                  const real *pk, long st, uint8_t *jmp, real *jM, const real ratio,
                                  const real dmax, const int kern) {
  const real xi = x[i], yi = y[i], dxi = dx[i], Ri = ratio * dxi, R2 = Ri * Ri;
  const real tol = RHOD_SIZE_TOL * dxi, Rmax = ratio * dmax;
  const int own = jmp[i];
  const int far = dxi < dmax - tol && rhod_cells_near_any(GS, SS, xi, yi, Rmax);
  real mxx = 0, mxy = 0, myy = 0, cross = own;
  if (own || far) {
    real RHOD_LANES(sxx), RHOD_LANES(sxy), RHOD_LANES(syy), RHOD_LANES(sfar);
    /* within R_i: pass A's B where every neighbour there has i's size; else every
     * neighbour, with W at its own radius R_j (0 beyond it) */
    const real bxx = own ? 0 : jM[3 * i], bxy = own ? 0 : jM[3 * i + 1];
    const real byy = own ? 0 : jM[3 * i + 2];
    if (own) {
      const real *kx = pk + RHOD_PK_X * st, *ky = pk + RHOD_PK_Y * st, *kV = pk + RHOD_PK_V * st,
                 *kdx = pk + RHOD_PK_DX * st;
      RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
        RHOD_FOR_LANES(k0, kv, k) {
          PAIR_OR_SKIP(k);
          const real Rj = ratio * kdx[k], iRj = 1 / Rj;
          const real a = r < Rj ? -rhod_dWq(kern, r * iRj) * iRj * iRj * iRj * kV[k] * r : 0;
          RHOD_LANE(sxx) += a * nx * nx, RHOD_LANE(sxy) += a * nx * ny;
          RHOD_LANE(syy) += a * ny * ny;
        }
        RHOD_END_LANES
      }
      RHOD_END_ROWS
    }
    /* beyond R_i: the coarser flagged ones whose R_j reaches i */
    if (far) {
      const real *fx = pk + RHOD_PK_JX * st, *fy = pk + RHOD_PK_JY * st, *fV = pk + RHOD_PK_JV * st,
                 *fdx = pk + RHOD_PK_JDX * st;
      RHOD_FOR_ROWS(GS, SS, xi, yi, Rmax, k0, k1, kv) {
        RHOD_FOR_LANES(k0, kv, k) {
          const real rx = fx[k] - xi, ry = fy[k] - yi, r2 = rx * rx + ry * ry;
          const real Rj = ratio * fdx[k];
          if (!(r2 >= R2 && r2 < Rj * Rj))
            continue;
          const real r = sqrt(r2), nx = rx / r, ny = ry / r, iRj = 1 / Rj;
          const real a = -rhod_dWq(kern, r * iRj) * iRj * iRj * iRj * fV[k] * r;
          RHOD_LANE(sxx) += a * nx * nx, RHOD_LANE(sxy) += a * nx * ny;
          RHOD_LANE(syy) += a * ny * ny;
          RHOD_LANE(sfar) = 1;
        }
        RHOD_END_LANES
      }
      RHOD_END_ROWS
      cross = RHOD_LANES_MAX(sfar) > 0 ? 1 : cross;
    }
    if (cross > 0)
      mxx = bxx + RHOD_LANES_SUM(sxx), mxy = bxy + RHOD_LANES_SUM(sxy),
      myy = byy + RHOD_LANES_SUM(syy);
  }
  jmp[i] = cross > 0;
  jM[3 * i] = mxx, jM[3 * i + 1] = mxy, jM[3 * i + 2] = myy;
}

int rhod_sph_pass_jumps(rhod_sph *s, rhod_particles *p, const rhod_cells *c) {
  if (!rhod_sph_balanced(s) || !s->shifting)
    return RHOD_OK;
  const long n = (long)p->n, nt = (long)(p->n + p->ng), st = (long)p->cap;
  uint8_t *jmp = s->jmp;
  real *jM = s->jM, *pk = s->pk;
  const real *x = p->x, *y = p->y, *dx = p->dx, *V = s->V;
  const real dmax = rhod_max_real(dx, nt);
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++)
    jmp[g] = 1;
  rhod_cells *u = &s->jsc;
  const long nf = rhod_cells_build_subset(u, c, jmp);
  if (nf < 0)
    return RHOD_ERR_MEMORY;
  rhod_cells_pack(u, nf, pk + RHOD_PK_JX * st, x, 1, 0);
  rhod_cells_pack(u, nf, pk + RHOD_PK_JY * st, y, 1, 0);
  rhod_cells_pack(u, nf, pk + RHOD_PK_JV * st, V, 1, 0);
  rhod_cells_pack(u, nf, pk + RHOD_PK_JDX * st, dx, 1, 0);
  const rhod_grid G = c->g, GS = u->g;
  const int32_t *CS = c->start, *SS = u->start;
  const real ratio = s->ratio;
  const int kern = s->kernel, generic = s->generic;
  (void)generic;
  GATHER_BY_KERNEL(n, kern, generic, jumps_particle, G, CS, GS, SS, x, y, dx, pk, st, jmp, jM,
                   ratio, dmax);
  return RHOD_OK;
}

/* Free-surface detection of Marrone et al. 2010 (paper 002 Ref. 51; scheme.md step 3):
 * lambda <= lam_lo: surface; > lam_hi: not; between: the scan-region test. */
void rhod_sph_pass_free_surface(rhod_sph *s, rhod_particles *p, const rhod_cells *c) {
  const long n = (long)p->n;
  uint8_t *fs = s->fs;
  real *nrm = s->nrm;
  const real *lam = s->lam, *L = s->L, *ggam = s->ggam, *x = p->x, *y = p->y, *dx = p->dx;
  if (!s->fsdetect) {
    RHOD_KERNEL_LOOP
    for (long i = 0; i < n; i++) {
      fs[i] = 0;
      nrm[2 * i] = 0, nrm[2 * i + 1] = 0;
    }
    return;
  }
  const rhod_grid G = c->g;
  const int32_t *CS = c->start;
  const real *pk = s->pk;
  const long st = (long)p->cap;
  const real lo = s->lam_lo, hi = s->lam_hi, ratio = s->ratio;
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    /* normal n = -L^T grad Gamma / |.| (outward) */
    const real *Li = L + 4 * i;
    const real gx = ggam[2 * i], gy = ggam[2 * i + 1];
    real nx = -(Li[0] * gx + Li[2] * gy), ny = -(Li[1] * gx + Li[3] * gy);
    const real nn = sqrt(nx * nx + ny * ny);
    if (nn > 0) {
      nx /= nn, ny /= nn;
    } else {
      nx = 0, ny = 0;
    }
    nrm[2 * i] = nx, nrm[2 * i + 1] = ny;
    const real l = lam[i];
    if (l <= lo) {
      fs[i] = 1;
      continue;
    }
    if (l > hi || nn == 0) {
      fs[i] = 0;
      continue;
    }
    /* the scan region: is any neighbour j in the umbrella-shaped region around T = x_i
     * + h n (Marrone et al. 2010)? Over pass A's packed positions (vectorised lanes);
     * j = i is left out by r > 0 (a neighbour exactly on top of i would be too, and
     * would not count anyway: it lies at |n.q| + |t.q| = h, not inside) */
    const real *kx = pk + RHOD_PK_X * st, *ky = pk + RHOD_PK_Y * st;
    const real xi = x[i], yi = y[i], Ri = ratio * dx[i], h = (real)0.5 * Ri;
    const real Tx = xi + h * nx, Ty = yi + h * ny;
    const real tx = -ny, ty = nx;
    const real h2 = h * h, s2h2 = 2 * h2, R2 = Ri * Ri;
    real RHOD_LANES(socc);
    RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
      RHOD_FOR_LANES(k0, kv, k) {
        const real rx = kx[k] - xi, ry = ky[k] - yi, r2 = rx * rx + ry * ry;
        const real qx = kx[k] - Tx, qy = ky[k] - Ty;
        /* q inside the circle of radius h about T beyond sqrt 2 h from i, inside the
         * square of half-diagonal h nearer: a negative value (reals, not ints, so that
         * the loop takes the lanes of the reals) */
        const real in = r2 >= s2h2 ? qx * qx + qy * qy - h2
                                   : fabs(nx * qx + ny * qy) + fabs(tx * qx + ty * qy) - h;
        RHOD_LANE(socc) = r2 < R2 && r2 > 0 && in < 0 ? 1 : RHOD_LANE(socc);
      }
      RHOD_END_LANES
    }
    RHOD_END_ROWS
    fs[i] = RHOD_LANES_MAX(socc) > 0 ? 0 : 1;
  }
}

/* Ghosts take the flags and normals of their sources (normal mirrored with J). */
void rhod_sph_mirror_surface(rhod_sph *s, rhod_particles *p) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng);
  const int32_t *gsrc = p->gsrc;
  const real *gJ = p->gJ;
  uint8_t *fs = s->fs;
  real *nrm = s->nrm;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const int k = gsrc[g];
    const real *J = gJ + 4 * g;
    fs[g] = fs[k];
    const real nx = nrm[2 * k], ny = nrm[2 * k + 1];
    nrm[2 * g] = J[0] * nx + J[1] * ny;
    nrm[2 * g + 1] = J[2] * nx + J[3] * ny;
  }
}

/* Free-surface region (F u V) and the projection of Eq. 26. Our choice for the
 * quantities paper 002 takes from its Ref. 55: n~_i = the W-weighted mean of the
 * normals of the free-surface particles in the support (i itself included when in F),
 * normalised; sigma_i = 1 on F and 1 - d_i/R_i on V, d_i the distance to the nearest
 * free-surface particle, so the projection fades out continuously across V.
 * refinement.surface_band (rhod_apr_mark) reads d_i / R_i back as 1 - sigma_i: a change
 * of sigma's definition must change it too (test_apr's direct sum fails otherwise). */
#define RG_PARAMS                                                                                  \
  rhod_grid G, const int32_t *CS, const real *x, const real *y, const real *dx, const uint8_t *fs, \
      const real *pk, long st, uint8_t *reg, real *nt, real *sig, const real ratio
#define RG_ARGS G, CS, x, y, dx, fs, pk, st, reg, nt, sig, ratio

/* One particle's gather of the region pass (an inlined function, specialised for the
 * default kernel on the host as pass A's) over the free-surface particles alone (the
 * subset cells fsc, G and CS, with their positions and normals packed in its order): the
 * sum of W n_j over those in the support (i itself included) and the nearest of them
 * other than i (r > 0, as PAIR_OR_SKIP). */
PARTICLE_BODY void region_particle(long i, RG_PARAMS, const int kern) {
  const real xi = x[i], yi = y[i], Ri = ratio * dx[i], R2 = Ri * Ri;
  if (!rhod_cells_near_any(G, CS, xi, yi, Ri)) {
    reg[i] = 0, sig[i] = 0;
    nt[2 * i] = 0, nt[2 * i + 1] = 0;
    return;
  }
  const real *kx = pk + RHOD_PK_FX * st, *ky = pk + RHOD_PK_FY * st, *knx = pk + RHOD_PK_FNX * st,
             *kny = pk + RHOD_PK_FNY * st;
  const real iR = 1 / Ri, R2in = rhod_closed_support2(Ri); /* kernel.h */
  real RHOD_LANES(ssx), RHOD_LANES(ssy), RHOD_LANES(sd2), RHOD_LANES(sany);
  RHOD_LANES_SET(sd2, R2);
  RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
    RHOD_FOR_LANES(k0, kv, k) {
      const real rx = kx[k] - xi, ry = ky[k] - yi, r2 = rx * rx + ry * ry;
      if (!(r2 < R2in))
        continue;
      const real w = rhod_Wq(kern, sqrt(r2) * iR); /* W R^2: nt is normalised below */
      RHOD_LANE(ssx) += w * knx[k], RHOD_LANE(ssy) += w * kny[k];
      const real d2 = r2 > 0 ? r2 : R2;
      RHOD_LANE(sd2) = d2 < RHOD_LANE(sd2) ? d2 : RHOD_LANE(sd2);
      RHOD_LANE(sany) = 1;
    }
    RHOD_END_LANES
  }
  RHOD_END_ROWS
  const real sx = RHOD_LANES_SUM(ssx), sy = RHOD_LANES_SUM(ssy);
  const real dmin2 = RHOD_LANES_MIN(sd2), any = RHOD_LANES_MAX(sany);
  const real sn = sqrt(sx * sx + sy * sy);
  if (fs[i]) {
    reg[i] = 2, sig[i] = 1;
  } else if (any > 0) {
    reg[i] = 1, sig[i] = 1 - sqrt(dmin2) / Ri;
  } else {
    reg[i] = 0, sig[i] = 0;
  }
  nt[2 * i] = sn > 0 ? sx / sn : 0;
  nt[2 * i + 1] = sn > 0 ? sy / sn : 0;
}

int rhod_sph_pass_region(rhod_sph *s, rhod_particles *p, const rhod_cells *c) {
  const long n = (long)p->n;
  uint8_t *reg = s->reg;
  real *nt = s->nt, *sig = s->sig;
  const uint8_t *fs = s->fs;
  const real *nrm = s->nrm, *x = p->x, *y = p->y, *dx = p->dx;
  if (!s->fsdetect) {
    RHOD_KERNEL_LOOP
    for (long i = 0; i < n; i++) {
      reg[i] = 0, sig[i] = 0;
      nt[2 * i] = 0, nt[2 * i + 1] = 0;
    }
    return RHOD_OK;
  }
  /* the free-surface particles (fluid and ghosts) sorted into the cells alone (the
   * subset fsc), so that the gather visits only them, and a particle with none in reach
   * skips it; their positions and normals packed in that order */
  rhod_cells *u = &s->fsc;
  const long nf = rhod_cells_build_subset(u, c, fs), st = (long)p->cap;
  if (nf < 0)
    return RHOD_ERR_MEMORY;
  const rhod_grid G = u->g;
  const int32_t *CS = u->start;
  real *pk = s->pk;
  rhod_cells_pack(u, nf, pk + RHOD_PK_FX * st, x, 1, 0);
  rhod_cells_pack(u, nf, pk + RHOD_PK_FY * st, y, 1, 0);
  rhod_cells_pack(u, nf, pk + RHOD_PK_FNX * st, nrm, 2, 0);
  rhod_cells_pack(u, nf, pk + RHOD_PK_FNY * st, nrm, 2, 1);
  const int kern = s->kernel, generic = s->generic;
  const real ratio = s->ratio;
  (void)generic;
  GATHER_BY_KERNEL(n, kern, generic, region_particle, RG_ARGS);
  return RHOD_OK;
}

/* J_i = -R_i grad C_i (Eq. 25) projected in the free-surface region (Eq. 26), into the
 * locals Jx, Jy; reads ratio, dx, gC, nt and sig. A macro, not a function with pointer
 * outputs (addressable locals on nvptx, offload.md). */
#define SHIFT_J(i, Jx, Jy)                                                                         \
  real Jx = -ratio * dx[i] * gC[2 * (i)], Jy = -ratio * dx[i] * gC[2 * (i) + 1];                   \
  do {                                                                                             \
    const real nx_ = nt[2 * (i)], ny_ = nt[2 * (i) + 1];                                           \
    const real jn_ = sig[i] * (Jx * nx_ + Jy * ny_);                                               \
    Jx -= jn_ * nx_, Jy -= jn_ * ny_;                                                              \
  } while (0)

/* Shifting velocity, Eqs. 25-27 (no gather: grad C and U_char come from pass A). */
void rhod_sph_pass_shift(rhod_sph *s, rhod_particles *p, real dt) {
  const long n = (long)p->n, nt_ = (long)(p->n + p->ng);
  real *du = s->du, *dup = s->dup;
  if (!s->shifting) {
    RHOD_KERNEL_LOOP
    for (long i = 0; i < nt_; i++) {
      du[2 * i] = 0, du[2 * i + 1] = 0;
      if (dup)
        dup[2 * i] = 0, dup[2 * i + 1] = 0;
    }
    return;
  }
  const real *gC = s->gC, *nt = s->nt, *sig = s->sig, *uch = s->uch, *ggam = s->ggam, *dx = p->dx;
  const real *jM = s->jM;
  const uint8_t *jmp = s->jmp;
  const real ratio = s->ratio, a = s->sa, b = s->sb, eps = s->seps;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    SHIFT_J(i, Jx, Jy);
    const real jm = sqrt(Jx * Jx + Jy * Jy);
    real f = a * uch[i]; /* Eq. 27 */
    if (jm > 0) {
      const real f2 = b * ratio * uch[i] / jm;
      f = f2 < f ? f2 : f;
      const real jg = fabs(Jx * ggam[2 * i] + Jy * ggam[2 * i + 1]);
      if (jg > 0) {
        const real f3 = eps / (2 * dt * jg);
        f = f3 < f ? f3 : f;
      }
    }
    const real ux_ = f * Jx, uy_ = f * Jy;
    du[2 * i] = ux_, du[2 * i + 1] = uy_;
    if (dup) {
      /* a balanced shifting switch (rhod_sph_pass_jumps): du' = M^-1 du at a size jump.
       * Our choice: where det M <= 0.1 (a support too empty to invert; M = I on a full
       * one) du' = du */
      real px = ux_, py = uy_;
      const real mxx = jM[3 * i], mxy = jM[3 * i + 1], myy = jM[3 * i + 2];
      const real det = mxx * myy - mxy * mxy;
      if (jmp[i] && det > (real)0.1) {
        const real id = 1 / det;
        px = id * (myy * ux_ - mxy * uy_), py = id * (mxx * uy_ - mxy * ux_);
      }
      dup[2 * i] = px, dup[2 * i + 1] = py;
    }
  }
  const int32_t *gsrc = p->gsrc;
  const real *gJ = p->gJ;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt_; g++) {
    const int k = gsrc[g];
    const real *J = gJ + 4 * g;
    const real vx = du[2 * k], vy = du[2 * k + 1];
    du[2 * g] = J[0] * vx + J[1] * vy;
    du[2 * g + 1] = J[2] * vx + J[3] * vy;
    if (dup) /* our choice: a ghost carries du' = du (its mirror's du) */
      dup[2 * g] = du[2 * g], dup[2 * g + 1] = du[2 * g + 1];
  }
}

/* Pass A, the free-surface detection and the region pass, with the ghosts' mirrors: what
 * the shifting direction (Eqs. 25-26) needs; the start of every right-hand side and of
 * every relaxation iteration. With jumps, the size jumps of pass C's momentum term too
 * (the relaxation does not need them). */
static int gradients_and_surface(rhod_sph *s, rhod_particles *p, rhod_cells *c, int jumps) {
  rhod_sph_pass_a(s, p, c);
  rhod_sph_mirror_gradients(s, p);
  if (jumps && rhod_sph_pass_jumps(s, p, c) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  rhod_sph_pass_free_surface(s, p, c);
  rhod_sph_mirror_surface(s, p);
  return rhod_sph_pass_region(s, p, c);
}

/* One iteration of the initial relaxation (particles.relax; our choice, docs/choices.md
 * "initial relaxation"). Paper 002 packs its initial particles with the algorithm of its
 * Ref. 16, which it does not restate; we move them instead along the scheme's own
 * shifting direction: delta x_i = f_i J_i with J_i of Eqs. 25-26 (so the free surface
 * keeps its place: only the tangential part moves F particles) and
 * f_i = min(RHOD_RELAX_BETA dx_i, RHOD_RELAX_STEP dx_i / |J_i|, eps / (2 |J_i . grad Gamma_i|)),
 * Eq. 27 with U_char dt replaced by a fixed fraction of the particle's size: J = -R grad C
 * makes it a diffusion of the concentration with coefficient RHOD_RELAX_BETA R dx, the
 * step is at most RHOD_RELAX_STEP dx, and the last bound is Eq. 27's own limit on the
 * change of Gamma. With jumps_dx > 0 (particles.relax_where: jumps, our option) only a
 * particle within reach of one of another size moves: r_ij <= R of the larger of the two
 * (the closed support of the yes-or-no tests, kernel.h), sizes apart by more than
 * RHOD_SIZE_TOL dx_i; jumps_dx is the largest size present, which bounds the gather. It reads the
 * positions from pass A's packed rows, so moving x_i in the same loop races with no
 * other particle's test. Needs the cells and ghosts of the current positions
 * (rhod_sim_prepare); moves the fluid particles only and leaves every other field as it
 * was. */
int rhod_sph_relax(rhod_sph *s, rhod_particles *p, rhod_cells *c, real jumps_dx) {
  if (gradients_and_surface(s, p, c, 0) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  const long n = (long)p->n, st = (long)p->cap;
  real *x = p->x, *y = p->y;
  const real *gC = s->gC, *nt = s->nt, *sig = s->sig, *ggam = s->ggam, *dx = p->dx;
  const real *kx = s->pk + RHOD_PK_X * st, *ky = s->pk + RHOD_PK_Y * st;
  const real *kdx = s->pk + RHOD_PK_DX * st;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start;
  const real ratio = s->ratio, eps = s->seps, Rg = ratio * jumps_dx;
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    if (jumps_dx > 0) {
      const real xi = x[i], yi = y[i], dxi = dx[i], tol = RHOD_SIZE_TOL * dxi;
      real RHOD_LANES(sjump);
      RHOD_FOR_ROWS(G, CS, xi, yi, Rg, k0, k1, kv) {
        RHOD_FOR_LANES(k0, kv, k) {
          const real rx = kx[k] - xi, ry = ky[k] - yi, dxj = kdx[k];
          const real Rm = ratio * (dxj > dxi ? dxj : dxi);
          const int other = fabs(dxj - dxi) > tol && rx * rx + ry * ry < rhod_closed_support2(Rm);
          RHOD_LANE(sjump) = other ? 1 : RHOD_LANE(sjump);
        }
        RHOD_END_LANES
      }
      RHOD_END_ROWS
      if (!(RHOD_LANES_MAX(sjump) > 0))
        continue;
    }
    SHIFT_J(i, Jx, Jy);
    const real jm = sqrt(Jx * Jx + Jy * Jy);
    if (!(jm > 0))
      continue;
    real f = (real)RHOD_RELAX_BETA * dx[i];
    const real f2 = (real)RHOD_RELAX_STEP * dx[i] / jm;
    f = f2 < f ? f2 : f;
    const real jg = fabs(Jx * ggam[2 * i] + Jy * ggam[2 * i + 1]);
    if (jg > 0) {
      const real f3 = eps / (2 * jg);
      f = f3 < f ? f3 : f;
    }
    x[i] += f * Jx, y[i] += f * Jy;
  }
  return RHOD_OK;
}

/* Pass C: the right-hand side of Eq. 3. The gather of one particle is an inlined
 * function, so that the host build can compile specialised copies of it in which the
 * scene's switches (kernel, Riemann terms, reconstruction, shifting, viscosity) are
 * constants: a switched-off term then costs nothing, and the neighbour loop has no
 * branch and vectorises (RHOD_FOR_LANES). The device build keeps one copy (its lanes are
 * particles, and a branch on a switch is uniform across them). */
typedef struct {
  real ratio, c0, rho0, ic2, gx, gy, alpha_ad, gth, tth, visc_k, mu;
  int flags; /* PC_VCONS | PC_TIC | PC_SHSW | PC_SHSWC | PC_SHBAL: one int, since with two GCC 12
                nvptx put the struct in a lane-shared frame (tests/offload_frames.sh) */
} pass_c_consts;
/* the consistent Laplacian; scheme.tensile_control; scheme.shifting_switch: the momentum
 * term's difference form, the continuity terms', the balanced momentum term; the viscous
 * terms' own velocity rows (rhod_sph.vrow) */
enum { PC_VCONS = 1, PC_TIC = 2, PC_SHSW = 4, PC_SHSWC = 8, PC_SHBAL = 16, PC_UV = 32 };

#define PC_PARAMS                                                                                  \
  rhod_grid G, const int32_t *CS, const real *x, const real *y, const real *ux, const real *uy,    \
      const real *rho, const real *dx, const real *P, const real *L, const real *gP,               \
      const real *gu, const real *D, const real *du, const real *dup, const uint8_t *jmp,          \
      const real *gam, const uint8_t *reg, const real *lapB, const real *pk, long st, real *drho,  \
      real *acc, real *vel, const pass_c_consts K
#define PC_ARGS                                                                                    \
  G, CS, x, y, ux, uy, rho, dx, P, L, gP, gu, D, du, dup, jmp, gam, reg, lapB, pk, st, drho, acc,  \
      vel, K

PARTICLE_BODY void pass_c_particle(long i, PC_PARAMS, const int kern, const int riemann,
                                   const int recon, const int shifting, const int visc) {
  const real *kx = pk + RHOD_PK_X * st, *ky = pk + RHOD_PK_Y * st, *kV = pk + RHOD_PK_V * st,
             *kP = pk + RHOD_PK_P * st, *kux = pk + RHOD_PK_UX * st, *kuy = pk + RHOD_PK_UY * st,
             *kdx = pk + RHOD_PK_DX * st, *kD = pk + RHOD_PK_D * st, *kgPx = pk + RHOD_PK_GPX * st,
             *kgPy = pk + RHOD_PK_GPY * st, *kg0 = pk + RHOD_PK_GU0 * st,
             *kg1 = pk + RHOD_PK_GU1 * st, *kg2 = pk + RHOD_PK_GU2 * st,
             *kg3 = pk + RHOD_PK_GU3 * st, *kdux = pk + RHOD_PK_DUX * st,
             *kduy = pk + RHOD_PK_DUY * st, *krho = pk + RHOD_PK_RHO * st;
  const real c0 = K.c0, rho0 = K.rho0, ic2 = K.ic2;
  const real xi = x[i], yi = y[i], dxi = dx[i], Ri = K.ratio * dxi, R2 = Ri * Ri;
  const real iR = 1 / Ri, iR3 = iR * iR * iR;
  const real uxi = ux[i], uyi = uy[i], rhoi = rho[i], Pi = P[i], Di = D[i];
  const real dui = du[2 * i], dvi = du[2 * i + 1];
  /* the du' of the momentum term: du, or with a balanced switch rhod_sph_pass_jumps' */
  const int bal = (K.flags & PC_SHBAL) != 0;
  const real dpi = bal ? dup[2 * i] : dui, dqi = bal ? dup[2 * i + 1] : dvi;
  const real *kdpx = bal ? pk + RHOD_PK_DPX * st : kdux, *kdpy = bal ? pk + RHOD_PK_DPY * st : kduy;
  /* the neighbours' velocity in the viscous terms: a no-slip ghost's own (rhod_sph.vrow, the
   * rows after the others) */
  const long vrow = RHOD_PK_UV_ROW(bal);
  const int hasv = (K.flags & PC_UV) != 0;
  const real *kvx = hasv ? pk + vrow * st : kux, *kvy = hasv ? pk + (vrow + 1) * st : kuy;
  const real gPix = gP[2 * i], gPiy = gP[2 * i + 1];
  const real Gi0 = gu[4 * i], Gi1 = gu[4 * i + 1], Gi2 = gu[4 * i + 2], Gi3 = gu[4 * i + 3];
  /* Which sums are renormalised is known before the loop (Eq. 6: i in I and
   * Gamma_i >= 0.85; Eq. 24: i in I and Gamma_i > 0.95), so the pressure, Theta^u
   * and damper sums share two vector accumulators: vR (multiplied by L^T after the
   * loop) and vC (used as is); sf = sum grad_i W_ij V_j carries the P_i and D_i
   * parts. */
  const int inner = reg[i] == 0;
  const real renP = (inner && gam[i] >= K.gth) ? 1 : 0;
  const real renT = (inner && gam[i] > K.tth) ? 1 : 0;
  /* Theta^u only without viscosity: the alpha_mu exclusion of Eq. 3 */
  const real tR = (riemann && !visc) ? renT : 0, tC = (riemann && !visc) ? 1 - renT : 0;
  /* the consistent Laplacian where the pressure gradient is renormalised and B^ was
   * solved (pass A), with mu folded in; elsewhere Eq. 10 (weight e10) */
  real bxx = 0, bxy = 0, byy = 0;
  if (visc && (K.flags & PC_VCONS) && renP != 0)
    bxx = K.mu * lapB[3 * i], bxy = K.mu * lapB[3 * i + 1], byy = K.mu * lapB[3 * i + 2];
  const real e10 = (bxx + byy != 0) ? 0 : K.visc_k;
  const real kAD = K.alpha_ad * rho0 * c0 * (real)0.5 * Ri; /* Eq. 9, h_i = R_i/2 */
  real RHOD_LANES(svRx), RHOD_LANES(svRy), RHOD_LANES(svCx), RHOD_LANES(svCy);
  real RHOD_LANES(ssfx), RHOD_LANES(ssfy);
  real RHOD_LANES(scont);                  /* continuity, Eq. 22 */
  real RHOD_LANES(svsx), RHOD_LANES(svsy); /* F^mu */
  real RHOD_LANES(sddu), RHOD_LANES(sdrdu), RHOD_LANES(sruux), RHOD_LANES(sruuy); /* Eq. 4 */
  RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
    RHOD_FOR_LANES(k0, kv, k) {
      PAIR_OR_SKIP(k);
      const real F = -rhod_dWq(kern, r * iR) * iR3 * kV[k]; /* |grad_i W_ij| V_j */
      const real fx = F * nx, fy = F * ny;
      const real Pj = kP[k], uxj = kux[k], uyj = kuy[k];
      real aR = renP * Pj, aC = (1 - renP) * Pj - kAD * kD[k];
      RHOD_LANE(ssfx) += fx, RHOD_LANE(ssfy) += fy;
      const real uni = uxi * nx + uyi * ny, unj = uxj * nx + uyj * ny;
      if (riemann) {
        /* weights of Eq. 12: w_i = dx_i / (dx_i + dx_j) (1/2 at equal sizes) */
        const real dxj = kdx[k];
        const real wi = dxj == dxi ? (real)0.5 : dxi / (dxi + dxj), wj = 1 - wi;
        /* states of Eqs. 13-16 for P and the normal velocity u.n_ij */
        real PL = Pi, PR = Pj, uL = uni, uR = unj;
        if (recon) {
          const real gPi_n = gPix * nx + gPiy * ny;
          const real gPj_n = kgPx[k] * nx + kgPy[k] * ny;
          const real gui_n = nx * (Gi0 * nx + Gi1 * ny) + ny * (Gi2 * nx + Gi3 * ny);
          const real guj_n = nx * (kg0[k] * nx + kg1[k] * ny) + ny * (kg2[k] * nx + kg3[k] * ny);
          const real sP = (Pj - Pi) * ir, su = (unj - uni) * ir;
          PL = rhod_state(Pi, sP, gPi_n, wi * r), PR = rhod_state(Pj, sP, gPj_n, -wj * r);
          uL = rhod_state(uni, su, gui_n, wi * r), uR = rhod_state(unj, su, guj_n, -wj * r);
        }
        const real rhoL = rho0 + PL * ic2, rhoR = rho0 + PR * ic2;
        const real uE = rhod_pvrs_u(rhoL, rhoR, uL, uR, PL, PR, c0);
        /* Eq. 22: -rho_i <div u> + Theta^rho = -2 rho_i sum (u_E + R_ij).n F V,
         * R_ij = -(3/2 - w_i) u_i - (1/2 - w_j) u_j */
        RHOD_LANE(scont) += (uE - ((real)1.5 - wi) * uni - ((real)0.5 - wj) * unj) * F;
        if (!visc) {
          /* Eq. 24: theta_ij = 2 (P_E - [(1 - w_i) P_i + (1 - w_j) P_j]) */
          const real PE = rhod_pvrs_P(rhoL, rhoR, uL, uR, PL, PR, c0);
          const real th = 2 * (PE - ((1 - wi) * Pi + (1 - wj) * Pj));
          aR += tR * th;
          aC += tC * th;
        }
      } else {
        RHOD_LANE(scont) += (unj - uni) * F; /* Eq. 5 */
      }
      RHOD_LANE(svRx) += aR * fx, RHOD_LANE(svRy) += aR * fy;
      RHOD_LANE(svCx) += aC * fx, RHOD_LANE(svCy) += aC * fy;
      if (visc) {
        /* consistent: mu 2 F (n.B^.n) ((u_j - u_i)/r - n.grad u_i), see pass A; Eq. 10:
         * 2 (d + 2) mu pi_ij grad_i W_ij V_j */
        const real vxj = kvx[k], vyj = kvy[k];
        const real fc = 2 * F * (bxx * nx * nx + 2 * bxy * nx * ny + byy * ny * ny);
        const real pij = e10 * ((vxj - uxi) * rx + (vyj - uyi) * ry) * ir * ir;
        RHOD_LANE(svsx) += fc * ((vxj - uxi) * ir - (Gi0 * nx + Gi1 * ny)) + pij * fx;
        RHOD_LANE(svsy) += fc * ((vyj - uyi) * ir - (Gi2 * nx + Gi3 * ny)) + pij * fy;
      }
      if (shifting) {
        const real duj = kdux[k], dvj = kduy[k], rhoj = krho[k];
        const real dun_i = dui * nx + dvi * ny, dun_j = duj * nx + dvj * ny;
        const real dpn_i = dpi * nx + dqi * ny, dpn_j = kdpx[k] * nx + kdpy[k] * ny;
        RHOD_LANE(sddu) += (dun_j - dun_i) * F;
        RHOD_LANE(sdrdu) += (rhoi * dun_i + rhoj * dun_j) * F;
        RHOD_LANE(sruux) += (rhoi * uxi * dpn_i + rhoj * uxj * dpn_j) * F;
        RHOD_LANE(sruuy) += (rhoi * uyi * dpn_i + rhoj * uyj * dpn_j) * F;
      }
    }
    RHOD_END_LANES
  }
  RHOD_END_ROWS
  const real vRx = RHOD_LANES_SUM(svRx), vRy = RHOD_LANES_SUM(svRy);
  const real vCx = RHOD_LANES_SUM(svCx), vCy = RHOD_LANES_SUM(svCy);
  const real sfx = RHOD_LANES_SUM(ssfx), sfy = RHOD_LANES_SUM(ssfy);
  const real cont = RHOD_LANES_SUM(scont), vsx = RHOD_LANES_SUM(svsx), vsy = RHOD_LANES_SUM(svsy);
  const real ddu = RHOD_LANES_SUM(sddu), drdu = RHOD_LANES_SUM(sdrdu);
  const real ruux = RHOD_LANES_SUM(sruux), ruuy = RHOD_LANES_SUM(sruuy);
  const real *Li = L + 4 * i;
  /* renormalised part: L^T (vR - renP P_i sf) */
  const real wx = vRx - renP * Pi * sfx, wy = vRy - renP * Pi * sfy;
  /* plain part: vC + ((1 - renP) P_i - kAD D_i) sf, i.e. sum (P_j + P_i) gW V for a
   * conservative Eq. 6, and -F^AD of Eq. 9. With scheme.tensile_control, where
   * P_i < 0 the conservative sum is sum (P_j - P_i) gW V instead: the tensile-
   * instability switch of Sun et al. 2018 as paper 001 writes it (Eq. 5; paper 000
   * Eq. 2, p_j +- p_i). Our choice (docs/choices.md): only where Eq. 6 is conservative
   * (the renormalised bulk form avoids the tensile instability, paper 002 Sec. IV,
   * item iv) and i is not itself a free-surface particle: with a truncated support the
   * minus form loses the dynamic free-surface condition (paper 000 Sec. 2.1 asks for a
   * free-surface detection to exclude it; applied on F too, the dam break at H/dx = 50
   * blew up within 93 steps). */
  const real Pc = ((K.flags & PC_TIC) && Pi < 0 && reg[i] != 2) ? -Pi : Pi;
  const real ki = (1 - renP) * Pc - kAD * Di;
  real fx = -(Li[0] * wx + Li[2] * wy) - (vCx + ki * sfx) + rhoi * K.gx + vsx;
  real fy = -(Li[1] * wx + Li[3] * wy) - (vCy + ki * sfy) + rhoi * K.gy + vsy;
  /* continuity: Eq. 22 with Riemann, else -rho_i <div u> (Eq. 5) */
  real dr = riemann ? -2 * rhoi * cont : -rhoi * cont;
  if (shifting) {
    /* Eq. 4: -rho_i <div du> + <div(rho du)> and <div(rho u (x) du)>, sum forms
     * sum (phi_i + phi_j) grad_i W_ij V_j. The sum form carries 2 phi_i sum grad_i W_ij
     * V_j = 2 phi_i grad Gamma_i, a zeroth-order error wherever grad Gamma_i != 0 inside
     * the fluid, as at the size jumps of APR; in the momentum term it is the force
     * 2 rho_i u_i (du_i . grad Gamma_i), along u_i. With scheme.shifting_switch, where
     * Eq. 6 is renormalised (the support is full), the momentum term (PC_SHSW:
     * `momentum` or `true`) and the continuity terms (PC_SHSWC: `true`) take the
     * difference form sum (phi_j - phi_i) grad_i W_ij V_j instead (our choice,
     * docs/choices.md "Shifting terms at size jumps": the rotating square needs both for
     * its angular momentum; with both the four-level dam break gained energy and stopped
     * at t = 1.52 s, with the momentum term alone it runs to t sqrt(g/H) = 10). The
     * free-surface region keeps the sum form, as Eq. 6 keeps its conservative form there.
     * sf = sum grad_i W_ij V_j, so the switch costs nothing in the loop. The balanced
     * forms (PC_SHBAL) keep the sum form except at a size jump, where the difference form
     * carries du' (rhod_sph_pass_jumps). */
    const real g2 = renP * 2 * (dui * sfx + dvi * sfy);
    const real dsm =
        bal ? (jmp[i] ? renP * 2 * (dpi * sfx + dqi * sfy) : 0) : ((K.flags & PC_SHSW) ? g2 : 0);
    const real dsc = (K.flags & PC_SHSWC) ? g2 : 0;
    dr += -rhoi * ddu + drdu - rhoi * dsc;
    fx += ruux - rhoi * uxi * dsm, fy += ruuy - rhoi * uyi * dsm;
  }
  drho[i] = dr;
  acc[2 * i] = fx / rhoi, acc[2 * i + 1] = fy / rhoi;
  vel[2 * i] = uxi + dui, vel[2 * i + 1] = uyi + dvi;
}

/* the specialised copies: Wendland C2 (the default kernel) with every combination of
 * the switches; other kernels take the general copy */
#define PC_CALL(KERN, RI, RE, SH, VI) pass_c_particle(i, PC_ARGS, KERN, RI, RE, SH, VI)
#define PC_CASES(B, RI, RE)                                                                        \
  case B:                                                                                          \
    PC_CALL(RHOD_KERNEL_WENDLAND_C2, RI, RE, 0, 0);                                                \
    break;                                                                                         \
  case B + 1:                                                                                      \
    PC_CALL(RHOD_KERNEL_WENDLAND_C2, RI, RE, 0, 1);                                                \
    break;                                                                                         \
  case B + 2:                                                                                      \
    PC_CALL(RHOD_KERNEL_WENDLAND_C2, RI, RE, 1, 0);                                                \
    break;                                                                                         \
  case B + 3:                                                                                      \
    PC_CALL(RHOD_KERNEL_WENDLAND_C2, RI, RE, 1, 1);                                                \
    break;

void rhod_sph_pass_c(rhod_sph *s, rhod_particles *p, const rhod_cells *c) {
  pack_c(s, p, c);
  const long n = (long)p->n, st = (long)p->cap;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start;
  const real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy, *rho = p->rho, *dx = p->dx;
  const real *P = s->P, *L = s->L, *gP = s->gP, *gu = s->gu, *D = s->D, *du = s->du, *gam = s->gam,
             *lapB = s->lapB, *pk = s->pk, *dup = s->dup;
  const uint8_t *reg = s->reg, *jmp = s->jmp;
  real *drho = s->drho, *acc = s->acc, *vel = s->vel;
  const pass_c_consts K = {
      .ratio = s->ratio,
      .c0 = s->c0,
      .rho0 = s->rho0,
      .ic2 = 1 / (s->c0 * s->c0),
      .gx = s->gx,
      .gy = s->gy,
      .alpha_ad = s->damper ? s->alpha_ad : 0,
      .gth = s->gamma_th,
      .tth = s->theta_th,
      .visc_k = 2 * (RHOD_DIM + 2) * s->mu, /* Eq. 10 */
      .mu = s->mu,
      .flags = (s->visc_cons ? PC_VCONS : 0) | (s->tic ? PC_TIC : 0) |
               (s->shsw == RHOD_SHSW_MOMENTUM || s->shsw == RHOD_SHSW_ALL ? PC_SHSW : 0) |
               (s->shsw == RHOD_SHSW_ALL || s->shsw == RHOD_SHSW_BALANCED ? PC_SHSWC : 0) |
               (rhod_sph_balanced(s) ? PC_SHBAL : 0) | (s->vrow ? PC_UV : 0),
  };
  const int kern = s->kernel, riemann = s->riemann, recon = riemann && s->recon,
            shifting = s->shifting, visc = s->mu != 0;
  const int sel = (kern != RHOD_KERNEL_WENDLAND_C2 || s->generic)
                      ? -1
                      : 4 * (riemann + recon) + 2 * shifting + visc;
  (void)sel;
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
#ifdef RHOD_OFFLOAD
    pass_c_particle(i, PC_ARGS, kern, riemann, recon, shifting, visc);
#else
    switch (sel) {
      PC_CASES(0, 0, 0)
      PC_CASES(4, 1, 0)
      PC_CASES(8, 1, 1)
    default:
      pass_c_particle(i, PC_ARGS, kern, riemann, recon, shifting, visc);
    }
#endif
  }
}

int rhod_sph_rhs(rhod_sph *s, rhod_particles *p, rhod_cells *c, real dt) {
  if (gradients_and_surface(s, p, c, 1) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  rhod_sph_pass_shift(s, p, dt);
  rhod_sph_pass_c(s, p, c);
  return RHOD_OK;
}

/* sum m (x - a) x acc over the fluid */
static real torque_of_acc(const rhod_sph *s, const rhod_particles *p, real ax, real ay) {
  const long n = (long)p->n;
  const real *x = p->x, *y = p->y, *m = p->m, *acc = s->acc;
  real t = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, t)
  for (long i = 0; i < n; i++)
    t += m[i] * ((x[i] - ax) * acc[2 * i + 1] - (y[i] - ay) * acc[2 * i]);
  return t;
}

int rhod_sph_torque_budget(rhod_sph *s, rhod_particles *p, rhod_cells *c, real dt, real ax, real ay,
                           double out[RHOD_TQ_TERMS]) {
  if (rhod_sph_rhs(s, p, c, dt) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  const real tf = torque_of_acc(s, p, ax, ay); /* the full right-hand side */
  const long n = (long)p->n;
  const real *x = p->x, *y = p->y, *m = p->m, *ux = p->ux, *uy = p->uy, *du = s->du;
  const real gx = s->gx, gy = s->gy;
  real mo = 0, bo = 0;
  RHOD_KERNEL_LOOP_REDUCE2(+, mo, bo)
  for (long i = 0; i < n; i++) {
    mo += m[i] * (du[2 * i] * uy[i] - du[2 * i + 1] * ux[i]);
    bo += m[i] * ((x[i] - ax) * gy - (y[i] - ay) * gx);
  }
  /* pass C with the terms switched on one after the other; viscosity before Theta^u,
   * which Eq. 3 leaves out where there is viscosity (alpha_mu) */
  const rhod_sph keep = *s;
  s->riemann = 0, s->mu = 0, s->visc_cons = 0, s->damper = 0, s->shifting = 0;
  rhod_sph_pass_c(s, p, c);
  const real t0 = torque_of_acc(s, p, ax, ay); /* pressure and body force */
  s->mu = keep.mu, s->visc_cons = keep.visc_cons;
  rhod_sph_pass_c(s, p, c);
  const real t1 = torque_of_acc(s, p, ax, ay);
  s->riemann = keep.riemann;
  rhod_sph_pass_c(s, p, c);
  const real t2 = torque_of_acc(s, p, ax, ay);
  s->damper = keep.damper;
  rhod_sph_pass_c(s, p, c);
  const real t3 = torque_of_acc(s, p, ax, ay);
  *s = keep;
  out[RHOD_TQ_PRESSURE] = t0 - bo;
  out[RHOD_TQ_VISCOUS] = t1 - t0;
  out[RHOD_TQ_RIEMANN] = t2 - t1;
  out[RHOD_TQ_DAMPER] = t3 - t2;
  out[RHOD_TQ_SHIFTING] = tf - t3;
  out[RHOD_TQ_BODY] = bo;
  out[RHOD_TQ_MOTION] = mo;
  return RHOD_OK;
}

/* The damper step limit (our choice; paper 002 does not discuss it; docs/choices.md
 * "Damper step limit"). Eq. 9 with D from Eq. 5 is linear in u: F^AD / rho = A u, a bulk
 * viscosity alpha c0 h integrated explicitly, whose eigenvalues are real and negative.
 * Eq. 11 keeps dt |lambda| below RK4's bound of 2.785 on a regular support (a lattice at
 * cfl 0.5: 1.43), but not in a film one particle thick on a wall, where the four-level
 * dam break reached 4.46 and stopped (cases/dam_break_lobovsky/RESULTS.md). So the
 * largest |lambda| is measured: one power iteration per step on an iterate carried with
 * the particles (and checkpointed, so that a resumed run takes the same steps), plus a
 * small reproducible perturbation that lets a new stiff mode grow into it, and
 * rhod_sph_dt keeps dt |lambda| <= RHOD_DT_TARGET. A measures what the run integrates:
 * the ghosts carry the iterate mapped as the velocity (T v) and the divergence as pass A's
 * mirror (the source's, or the trace of the mapped renormalised gradient). */

/* a reproducible number in [-1, 1) per particle id and component (splitmix64) */
static inline real id_noise(uint64_t id, uint64_t comp) {
  uint64_t z = id * 2 + comp + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return (real)((double)(z >> 11) * (2.0 / 9007199254740992.0) - 1.0);
}

real rhod_sph_damper_probe(rhod_sph *s, rhod_particles *p, const rhod_cells *c) {
  const long n = (long)p->n, nt = (long)(p->n + p->ng), st = (long)p->cap;
  if (n == 0)
    return 0;
  real *v = s->adv, *aD = s->adD, *aG = s->adG, *pk = s->pk;
  const real *x = p->x, *y = p->y, *dx = p->dx, *rho = p->rho, *V = s->V;
  const real *gJ = p->gJ, *gT = p->gT;
  const uint64_t *id = p->id;
  const int32_t *gsrc = p->gsrc, *CS = c->start;
  const rhod_grid G = c->g;
  const int kern = s->kernel;
  const real ratio = s->ratio, kad = s->alpha_ad * s->rho0 * s->c0 * (real)0.5; /* Eq. 9 */
  /* normalise the iterate and add the perturbation: components in [-1, 1) have a mean
   * square of 1/3, so sqrt(1.5 / n) gives the perturbation a norm near 1, weighted 0.05
   * (all of it for the first iterate) */
  real nv = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, nv)
  for (long i = 0; i < n; i++)
    nv += v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1];
  const real a = nv > 0 ? 1 / sqrt(nv) : 0;
  const real b = (nv > 0 ? (real)0.05 : 1) * sqrt((real)1.5 / (real)n);
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    v[2 * i] = a * v[2 * i] + b * id_noise(id[i], 0);
    v[2 * i + 1] = a * v[2 * i + 1] + b * id_noise(id[i], 1);
  }
  /* the ghosts' iterate, as their velocity (rhod_sph_fill_state), and the rows of the
   * first gather */
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const int k = gsrc[g];
    const real *T = gT + 4 * g;
    v[2 * g] = T[0] * v[2 * k] + T[1] * v[2 * k + 1];
    v[2 * g + 1] = T[2] * v[2 * k] + T[3] * v[2 * k + 1];
  }
  rhod_cells_pack(c, nt, pk + RHOD_PK_X * st, x, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_Y * st, y, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_V * st, V, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_UX * st, v, 2, 0);
  rhod_cells_pack(c, nt, pk + RHOD_PK_UY * st, v, 2, 1);
  /* D of the iterate (Eq. 5) and its renormalised gradient (Eqs. 8 and 14, as pass A) */
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    const real *kx = pk + RHOD_PK_X * st, *ky = pk + RHOD_PK_Y * st, *kV = pk + RHOD_PK_V * st,
               *kvx = pk + RHOD_PK_UX * st, *kvy = pk + RHOD_PK_UY * st;
    const real xi = x[i], yi = y[i], Ri = ratio * dx[i], R2 = Ri * Ri;
    const real iR = 1 / Ri, iR3 = iR * iR * iR, vxi = v[2 * i], vyi = v[2 * i + 1];
    real RHOD_LANES(sB0), RHOD_LANES(sB1), RHOD_LANES(sB2), RHOD_LANES(sB3);
    real RHOD_LANES(sG0), RHOD_LANES(sG1), RHOD_LANES(sG2), RHOD_LANES(sG3);
    RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
      RHOD_FOR_LANES(k0, kv, k) {
        PAIR_OR_SKIP(k);
        const real F = -rhod_dWq(kern, r * iR) * iR3 * kV[k];
        const real gwx = F * nx, gwy = F * ny, dvx = kvx[k] - vxi, dvy = kvy[k] - vyi;
        RHOD_LANE(sB0) += rx * gwx, RHOD_LANE(sB1) += rx * gwy;
        RHOD_LANE(sB2) += ry * gwx, RHOD_LANE(sB3) += ry * gwy;
        RHOD_LANE(sG0) += dvx * gwx, RHOD_LANE(sG1) += dvx * gwy;
        RHOD_LANE(sG2) += dvy * gwx, RHOD_LANE(sG3) += dvy * gwy;
      }
      RHOD_END_LANES
    }
    RHOD_END_ROWS
    const real B0 = RHOD_LANES_SUM(sB0), B1 = RHOD_LANES_SUM(sB1), B2 = RHOD_LANES_SUM(sB2),
               B3 = RHOD_LANES_SUM(sB3);
    const real G0 = RHOD_LANES_SUM(sG0), G1 = RHOD_LANES_SUM(sG1), G2 = RHOD_LANES_SUM(sG2),
               G3 = RHOD_LANES_SUM(sG3);
    aD[i] = G0 + G3;
    RHOD_RENORM_L(B0, B1, B2, B3, L0, L1, L2, L3);
    aG[4 * i] = L0 * G0 + L2 * G1, aG[4 * i + 1] = L1 * G0 + L3 * G1;
    aG[4 * i + 2] = L0 * G2 + L2 * G3, aG[4 * i + 3] = L1 * G2 + L3 * G3;
  }
  /* the ghosts' D (ghost_div, as rhod_sph_mirror_gradients), and the second gather's row */
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const int k = gsrc[g];
    aD[g] = ghost_div(gJ + 4 * g, gT + 4 * g, aG + 4 * k, aD[k]);
  }
  rhod_cells_pack(c, nt, pk + RHOD_PK_D * st, aD, 1, 0);
  /* F^AD / rho of the iterate (Eq. 9, h_i = R_i / 2 as in pass C), which becomes the next
   * iterate; |A v| / |v| estimates the largest |lambda|. The norms are summed in loops
   * of their own, so that the gather needs no reduction (RHOD_GATHER_LOOP) */
  real nw = 0, n0 = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, n0)
  for (long i = 0; i < n; i++)
    n0 += v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1];
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    const real *kx = pk + RHOD_PK_X * st, *ky = pk + RHOD_PK_Y * st, *kV = pk + RHOD_PK_V * st,
               *kD = pk + RHOD_PK_D * st;
    const real xi = x[i], yi = y[i], Ri = ratio * dx[i], R2 = Ri * Ri, Di = aD[i];
    const real iR = 1 / Ri, iR3 = iR * iR * iR;
    real RHOD_LANES(sfx), RHOD_LANES(sfy);
    RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
      RHOD_FOR_LANES(k0, kv, k) {
        PAIR_OR_SKIP(k);
        const real F = -rhod_dWq(kern, r * iR) * iR3 * kV[k] * (kD[k] + Di);
        RHOD_LANE(sfx) += F * nx, RHOD_LANE(sfy) += F * ny;
      }
      RHOD_END_LANES
    }
    RHOD_END_ROWS
    const real fx = RHOD_LANES_SUM(sfx), fy = RHOD_LANES_SUM(sfy);
    const real ki = kad * Ri / rho[i];
    v[2 * i] = ki * fx, v[2 * i + 1] = ki * fy;
  }
  RHOD_KERNEL_LOOP_REDUCE(+, nw)
  for (long i = 0; i < n; i++)
    nw += v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1];
  return n0 > 0 ? sqrt(nw / n0) : 0;
}

real rhod_sph_dt(rhod_sph *s, const rhod_particles *p) {
  const long n = (long)p->n;
  const real *dx = p->dx;
  real dmin = (real)FLT_MAX;
  RHOD_KERNEL_LOOP_REDUCE(min, dmin)
  for (long i = 0; i < n; i++)
    dmin = dx[i] < dmin ? dx[i] : dmin;
  const real R = s->ratio * dmin;
  /* Eq. 11 */
  real dt = s->cfl * R / s->c0;
  if (s->damper && s->alpha_ad > 0) {
    const real d2 = s->cfl * R / (s->alpha_ad * s->c0);
    dt = d2 < dt ? d2 : dt;
  }
  if (s->mu > 0) {
    const real d3 = s->cfl_visc * s->rho0 * R * R / s->mu;
    dt = d3 < dt ? d3 : dt;
  }
  s->dt_by = RHOD_DT_BY_EQ11;
  /* the damper step limit (rhod_sph_damper_probe) */
  if (s->adlim && s->ad_lambda > 0) {
    const real d4 = (real)RHOD_DT_TARGET / s->ad_lambda;
    if (d4 < dt)
      dt = d4, s->dt_by = RHOD_DT_BY_DAMPER;
  }
  /* the stiffness limit (rhod_sim_step, rhod_rk_stiffness), never below RHOD_ST_FLOOR of
   * the others: a stiffness that does not scale with dt (a switch between stages that
   * the inner particles' mask misses) must not drive dt down step after step */
  if (s->stlim && s->st_lambda > 0) {
    real d5 = (real)RHOD_DT_TARGET / s->st_lambda;
    d5 = d5 > (real)RHOD_ST_FLOOR * dt ? d5 : (real)RHOD_ST_FLOOR * dt;
    if (d5 < dt)
      dt = d5, s->dt_by = RHOD_DT_BY_STIFFNESS;
  }
  return dt;
}
