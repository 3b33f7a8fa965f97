/* The multiphase scheme's passes (paper 000 Sec. 2, regular particles; paper 001 Sec. 2.1
 * for the terms paper 000 cites; order of ../shared/design/multiphase.md section A).
 * Every pass is a gather over the fluid [0, n): it writes only particle i's entries.
 * Conventions: r_ij = r_i - r_j, grad W_ij = W'(r; R_i) r_ij / r (points from i towards
 * j), W taken with the radius R_i = ratio dx_i of the gathering particle, V = m / rho. */
#include "rhod/multiphase/mp.h"
#include "multiphase/mp_pair.h"
#include "rhod/boundary.h"
#include "rhod/kernel.h"
#include <math.h>
#include <string.h>

#define MAXP RHOD_MP_MAX_PHASES

/* A gather's per-particle body: inlined into each specialised copy on the host (one copy
 * on the device, where it stays a call to keep the device code small). */
#ifdef RHOD_OFFLOAD
#define PARTICLE_BODY static inline
#else
#define PARTICLE_BODY static inline __attribute__((always_inline))
#endif
#define BIG ((real)1e30)

/* h / R of a kernel (paper 000 Appendix A): Wendland h = R/2 (h/dx = 2 at R = 4 dx),
 * quintic spline h = R/3 (h/dx = 1 at R = 3 dx). */
static real h_over_R(int kernel) { return kernel == RHOD_KERNEL_QUINTIC ? (real)(1.0 / 3) : 0.5; }

/* h_s / R with h_s = 2 sigma (paper 001 after Eq. 3 and Eqs. 14-17), sigma the kernel's
 * standard deviation along one axis: sigma^2 = (1/2) int r^2 W dA over the unit support,
 * by the midpoint rule (0.52705 Wendland C2, 0.46057 Wendland C4, 0.46336 quintic;
 * docs/choices.md). */
static real hs_over_R(int kernel) {
  const int N = 20000;
  double s = 0;
  for (int k = 0; k < N; k++) {
    const double q = (k + 0.5) / N;
    s += 0.5 * q * q * (double)rhod_Wq(kernel, (real)q) * 2 * RHOD_PI * q / N;
  }
  return (real)(2 * sqrt(s));
}

int rhod_mp_init(rhod_mp *m, const rhod_mp_params *prm, rhod_particles *p) {
  memset(m, 0, sizeof *m);
  if (prm->nphase < 1 || prm->nphase > MAXP)
    return RHOD_ERR_SCENE;
  if (prm->kernel != RHOD_KERNEL_WENDLAND_C2 && prm->kernel != RHOD_KERNEL_WENDLAND_C4 &&
      prm->kernel != RHOD_KERNEL_QUINTIC)
    return RHOD_ERR_SCENE;
  m->prm = *prm;
  m->hfac = h_over_R(prm->kernel);
  m->hs_fac = hs_over_R(prm->kernel);
  m->tab = rhod_dev_calloc(RHOD_MP_TAB_SIZE, sizeof(real));
  if (!m->tab)
    return RHOD_ERR_MEMORY;
  real *T = m->tab;
  for (int k = 0; k < prm->nphase; k++) {
    T[RHOD_MP_TAB_RHO0 * MAXP + k] = prm->ph[k].rho0;
    T[RHOD_MP_TAB_C * MAXP + k] = prm->ph[k].c;
    T[RHOD_MP_TAB_GAMMA * MAXP + k] = prm->ph[k].gamma;
    T[RHOD_MP_TAB_MU * MAXP + k] = prm->ph[k].mu;
    T[RHOD_MP_TAB_COLOUR * MAXP + k] = prm->ph[k].colour;
    real smax = 0;
    for (int b = 0; b < prm->nphase; b++) {
      const real s = prm->sigma[k * MAXP + b];
      T[RHOD_MP_TAB_SIGMA * MAXP + k * MAXP + b] = s;
      smax = s > smax ? s : smax;
      if (s > 0)
        m->surface = 1;
    }
    T[RHOD_MP_TAB_SIGMA_MAX * MAXP + k] = smax;
  }
  rhod_to_device(m->tab, RHOD_MP_TAB_SIZE * sizeof(real));
  int st = rhod_particles_add_tags(p);
#define F(var, k)                                                                                  \
  if (st == RHOD_OK)                                                                               \
  st = rhod_particles_add_field(p, "mp_" #var, (void **)&m->var, (k) * sizeof(*m->var), 0)
  F(P, 1);
  F(V, 1);
  F(nu, 1);
  F(col, 1);
  /* a scene with a no-slip wall or body splits the ghosts' velocity: the free-slip map in
   * every term but the viscous one, which reads two more rows (uvr) */
  const long base = m->surface ? RHOD_MP_PK_ROWS : RHOD_MP_PK_ROWS_PLAIN;
  m->uvr = p->gTv ? base : RHOD_MP_PK_UX;
  F(pk, p->gTv ? base + 2 : base);
  if (p->gTv) {
    F(uvx, 1);
    F(uvy, 1);
  }
  F(us, 2);
  F(drho, 1);
  F(acc, 2);
  F(vel, 2);
  if (m->surface) { /* a scene without surface tension does not carry them */
    F(gC, 2);
    F(nrm, 2);
    F(sig, 1);
    F(kap, 1);
  }
#undef F
  return st;
}

void rhod_mp_free(rhod_mp *m) {
  rhod_dev_free(m->tab, RHOD_MP_TAB_SIZE * sizeof(real));
  m->tab = NULL;
}

real rhod_mp_pressure(const rhod_mp_params *prm, int phase, real rho) {
  const rhod_mp_phase *f = &prm->ph[phase];
  return rhod_mp_eos(f->rho0, f->c, f->gamma, rho); /* paper 000 Eq. 3 */
}

real rhod_mp_density(const rhod_mp_params *prm, int phase, real P) {
  const rhod_mp_phase *f = &prm->ph[phase];
  return rhod_mp_eos_inv(f->rho0, f->c, f->gamma, P); /* inverse of paper 000 Eq. 3 */
}

void rhod_mp_fill_state(rhod_mp *m, rhod_particles *p) {
  const long n = (long)p->n;
  const real *rho = p->rho, *mass = p->m, *T = m->tab;
  const uint8_t *ph = p->phase;
  real *P = m->P, *V = m->V, *nu = m->nu, *col = m->col;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    const int k = ph[i];
    P[i] = rhod_mp_eos(T[RHOD_MP_TAB_RHO0 * MAXP + k], T[RHOD_MP_TAB_C * MAXP + k],
                       T[RHOD_MP_TAB_GAMMA * MAXP + k], rho[i]); /* paper 000 Eq. 3 */
    V[i] = mass[i] / rho[i];
    nu[i] = T[RHOD_MP_TAB_MU * MAXP + k] / rho[i];
    col[i] = T[RHOD_MP_TAB_COLOUR * MAXP + k];
  }
  /* ghosts: copies of the source's state. The velocity: the free-slip map (gT) in every
   * term, and where a wall or body is no slip, that condition's map (gTv) in the viscous
   * term alone (docs/choices.md "no slip in the viscous term only"). Until 2026-12-07 the
   * no-slip map entered every term here, the mirrors' reversed tangential velocity a
   * spurious divergence in Eq. 1 along every no-slip wall (the lid-driven cavity at
   * L/dx = 50: rms error of u against Ghia 1.11 % of U then, 0.21 % now). */
  if (m->uvx) {
    real *ux = p->ux, *uy = p->uy, *vx = m->uvx, *vy = m->uvy;
    RHOD_KERNEL_LOOP
    for (long i = 0; i < n; i++)
      vx[i] = ux[i], vy[i] = uy[i];
    rhod_ghosts_map_velocity_viscous(p, vx, vy);
  }
  rhod_ghosts_map_velocity(p, p->ux, p->uy);
  rhod_ghosts_map_scalar(p, p->rho);
  rhod_ghosts_map_scalar(p, m->P);
  /* a ghost's volume is its own mass over the source's density: a circle's mirror carries
   * m_s r_g/r_s, the area ratio of the radial mirror (docs/choices.md "bodies"); elsewhere
   * m_g = m_s and this is the source's V bit for bit. Until 2026-12-07 V was the source's
   * there too, over-weighting the ghosts inside a circle by r_s/r_g (up to 9 at a/R = 5/4),
   * and the transport velocity (Eq. 7) next to it went unstable within 150 steps. */
  const long ntot = n + (long)p->ng;
  RHOD_KERNEL_LOOP
  for (long g = n; g < ntot; g++)
    V[g] = mass[g] / rho[g];
  rhod_ghosts_map_scalar(p, m->nu);
  rhod_ghosts_map_scalar(p, m->col);
  rhod_ghosts_map_u8(p, p->phase);
  /* The density and pressure of a mirror continue the source's hydrostatic profile under
   * the body force less the acceleration of the wall at the mirror's foot (a moving body's
   * gA), as RHOD-SPH's ghosts do (docs/choices.md "ghost values", "bodies"): along it
   * dP = rho a . dx, which the Tait law (paper 000 Eq. 3) integrates exactly to
   * (rho_g/rho0)^(gamma - 1) = (rho_k/rho0)^(gamma - 1) + (gamma - 1) a . (x_g - x_k) / c^2,
   * rho_g = rho_k exp(a . (x_g - x_k) / c^2) for gamma = 1. Our choice: paper 000 states
   * none (its cases have no body force). Skipped where there is neither, so that such a
   * scene computes exactly what it did; a periodic image has x_g - x_k = 0 (ge). The volume
   * stays the source's (a mirror keeps areas; m_g/rho_g would make the ghosts of a denser
   * bottom row smaller than the lattice's cells, and the floor's rows fell at 2.8 % of g). */
  const real gx = m->prm.gx, gy = m->prm.gy, *gA = p->gA, *ge = p->ge;
  if (gx == 0 && gy == 0 && !gA)
    return;
  const long nt = n + (long)p->ng;
  real *R = p->rho;
  RHOD_KERNEL_LOOP
  for (long g = n; g < nt; g++) {
    const real a = rhod_ghost_head(ge, gA, gx, gy, g);
    const int k = ph[g];
    const real r0 = T[RHOD_MP_TAB_RHO0 * MAXP + k], c = T[RHOD_MP_TAB_C * MAXP + k],
               gam = T[RHOD_MP_TAB_GAMMA * MAXP + k], rk = R[g];
    real rg;
    if (gam == 1) {
      rg = rk * exp(a / (c * c));
    } else {
      const real base = pow(rk / r0, gam - 1) + (gam - 1) * a / (c * c);
      rg = base > 0 ? r0 * pow(base, 1 / (gam - 1)) : rk;
    }
    R[g] = rg;
    P[g] = rhod_mp_eos(r0, c, gam, rg); /* paper 000 Eq. 3 */
    nu[g] *= rk / rg;                   /* mu / rho; V keeps the source's: a mirror's area */
  }
}

/* The rows every gather reads, in the order of the cells' last build (fluid and ghosts). */
void rhod_mp_pack(rhod_mp *m, const rhod_particles *p, const rhod_cells *c) {
  const long nt = (long)(p->n + p->ng), st = (long)p->cap;
  real *pk = m->pk;
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_X * st, p->x, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_Y * st, p->y, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_V * st, m->V, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_P * st, m->P, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_UX * st, p->ux, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_UY * st, p->uy, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_RHO * st, p->rho, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_M * st, p->m, 1, 0);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_NU * st, m->nu, 1, 0);
  rhod_cells_pack_u8(c, nt, pk + RHOD_MP_PK_PH * st, p->phase);
  rhod_cells_pack(c, nt, pk + RHOD_MP_PK_COL * st, m->col, 1, 0);
  if (m->uvx) {
    rhod_cells_pack(c, nt, pk + m->uvr * st, m->uvx, 1, 0);
    rhod_cells_pack(c, nt, pk + (m->uvr + 1) * st, m->uvy, 1, 0);
  }
}

/* Pass 1 (only with surface tension): the colour gradient of Adami et al. with the
 * density-weighted colour (paper 001 Eq. 8 with f_ij of Eq. 39 and c~_ij of multiphase.md),
 * the interface normal (Eq. 9) where it is reliable (RHOD_MP_NORMAL_EPS, docs/choices.md),
 * and the surface tension of i's interface: the W-weighted mean of sigma(phase_i,
 * phase_j) over the neighbours j of another colour (our choice for more than two phases;
 * exactly the pair's sigma for two). */
#define COLOUR_PARAMS                                                                              \
  rhod_grid G, const int32_t *CS, long st, const real *x, const real *y, const real *dx,           \
      const real *rho, const real *V, const real *T, const real *pk, const real *col,              \
      const uint8_t *ph, real *gC, real *nrm, real *sig, real ratio, real hfac
#define COLOUR_ARGS G, CS, st, x, y, dx, rho, V, T, pk, col, ph, gC, nrm, sig, ratio, hfac

/* The colour pass's gather of particle i (kern a constant in the host's copies). */
PARTICLE_BODY void colour_particle(long i, COLOUR_PARAMS, const int kern) {
  const real *kx = pk + RHOD_MP_PK_X * st, *ky = pk + RHOD_MP_PK_Y * st,
             *kV = pk + RHOD_MP_PK_V * st, *krho = pk + RHOD_MP_PK_RHO * st,
             *kph = pk + RHOD_MP_PK_PH * st, *kcol = pk + RHOD_MP_PK_COL * st;
  const real xi = x[i], yi = y[i], Ri = ratio * dx[i], iR = 1 / Ri, R2 = Ri * Ri;
  const real iR2 = iR * iR, iR3 = iR2 * iR;
  const real rhoi = rho[i], Vi = V[i], ci = col[i];
  const int pi = ph[i];
  const real *sigrow = T + RHOD_MP_TAB_SIGMA * MAXP + pi * MAXP;
  real RHOD_LANES(sgx), RHOD_LANES(sgy), RHOD_LANES(sww), RHOD_LANES(ssw), RHOD_LANES(srw);
  RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
    RHOD_FOR_LANES(k0, kv, k) {
      const real rx = xi - kx[k], ry = yi - ky[k], r2 = rx * rx + ry * ry;
      if (!(r2 < R2 && r2 > 0))
        continue;
      const real r = sqrt(r2), q = r * iR;
      const real dWr = rhod_dWq(kern, q) * iR3 / r; /* grad W_ij = dWr r_ij */
      const real cj = kcol[k], rhoj = krho[k];
      /* paper 001 Eq. 8: (1/V_i) sum_j f_ij grad W_ij, f_ij = (V_i^2 + V_j^2) c~_ij */
      const real f = rhod_mp_colour_f(Vi, kV[k], rhoi, rhoj, ci, cj);
      RHOD_LANE(sgx) += f * dWr * rx;
      RHOD_LANE(sgy) += f * dWr * ry;
      /* the neighbours of another colour: the interface's sigma and density weight */
      const real w = cj != ci ? rhod_Wq(kern, q) * iR2 : 0;
      RHOD_LANE(sww) += w;
      RHOD_LANE(ssw) += sigrow[(int)kph[k]] * w;
      RHOD_LANE(srw) += rhoi / (rhoi + rhoj) * w;
    }
    RHOD_END_LANES
  }
  RHOD_END_ROWS
  const real gx = RHOD_LANES_SUM(sgx) / Vi, gy = RHOD_LANES_SUM(sgy) / Vi;
  const real ww = RHOD_LANES_SUM(sww), sw = RHOD_LANES_SUM(ssw), rw = RHOD_LANES_SUM(srw);
  gC[2 * i] = gx, gC[2 * i + 1] = gy;
  sig[i] = ww > 0 ? sw / ww : 0;
  const real g = sqrt(gx * gx + gy * gy), h = hfac * Ri;
  /* paper 001 Eq. 9, where reliable: Morris' |grad C| > 0.01/h, scaled by the density
   * weight (2 rw/ww = 1 for equal densities) that Adami's colour gives i's side */
  const int ok = ww > 0 && g > RHOD_MP_NORMAL_EPS * 2 * (rw / ww) / h;
  nrm[2 * i] = ok ? gx / g : 0;
  nrm[2 * i + 1] = ok ? gy / g : 0;
}

void rhod_mp_pass_colour(rhod_mp *m, rhod_particles *p, const rhod_cells *c) {
  const long n = (long)p->n, st = (long)p->cap;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start;
  const real *x = p->x, *y = p->y, *dx = p->dx, *rho = p->rho, *V = m->V, *T = m->tab;
  const real *pk = m->pk, *col = m->col;
  const uint8_t *ph = p->phase;
  real *gC = m->gC, *nrm = m->nrm, *sig = m->sig;
  const int kern = m->prm.kernel;
  const real ratio = m->prm.ratio, hfac = m->hfac;
#ifdef RHOD_OFFLOAD
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++)
    colour_particle(i, COLOUR_ARGS, kern);
#else
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    if (kern == RHOD_KERNEL_WENDLAND_C4)
      colour_particle(i, COLOUR_ARGS, RHOD_KERNEL_WENDLAND_C4);
    else if (kern == RHOD_KERNEL_QUINTIC)
      colour_particle(i, COLOUR_ARGS, RHOD_KERNEL_QUINTIC);
    else
      colour_particle(i, COLOUR_ARGS, kern);
  }
#endif
  /* the ghosts' gradients and normals from their sources: vectors map with J */
  rhod_ghosts_map_vector(p, m->gC);
  rhod_ghosts_map_vector(p, m->nrm);
}

/* Pass 2: continuity (paper 000 Eq. 1), momentum (Eq. 2 with paper 001 Eq. 5's switch),
 * viscosity (paper 001 Eq. 6), the CSF curvature and force (paper 001 Eqs. 7 and 10) and
 * the shifting velocity (paper 000 Eqs. 4-7). */
#define MAIN_PARAMS                                                                                \
  rhod_grid G, const int32_t *CS, long st, const real *x, const real *y, const real *dx,           \
      const real *rho, const real *ux, const real *uy, const real *P, const real *nu,              \
      const real *T, const real *pk, const uint8_t *ph, const real *gC, const real *nrm,           \
      const real *sig, real *kap, real *drho, real *acc, real *vel, real *us, int tensile,         \
      int surface, real ratio, real hfac, real delta, real eta2, real xi_shift, real xi_rep,       \
      real rep_n, real xi_rif, real gxb, real gyb, real alpha, real visc, long nxr, long nyr,      \
      long uvr
#define MAIN_ARGS                                                                                  \
  G, CS, st, x, y, dx, rho, ux, uy, P, nu, T, pk, ph, gC, nrm, sig, kap, drho, acc, vel, us,       \
      tensile, surface, ratio, hfac, delta, eta2, xi_shift, xi_rep, rep_n, xi_rif, gxb, gyb,       \
      alpha, visc, nxr, nyr, uvr

/* The main pass's gather of particle i; kern and rep2 (the repulsive term's n = 2) are
 * constants in the host build's specialised copies, so that the lanes vectorise. */
PARTICLE_BODY void main_particle(long i, MAIN_PARAMS, real dt, const int kern, const int rep2) {
  const real *kx = pk + RHOD_MP_PK_X * st, *ky = pk + RHOD_MP_PK_Y * st,
             *kV = pk + RHOD_MP_PK_V * st, *kP = pk + RHOD_MP_PK_P * st,
             *kux = pk + RHOD_MP_PK_UX * st, *kuy = pk + RHOD_MP_PK_UY * st,
             *krho = pk + RHOD_MP_PK_RHO * st, *km = pk + RHOD_MP_PK_M * st,
             *knu = pk + RHOD_MP_PK_NU * st, *kph = pk + RHOD_MP_PK_PH * st, *knx = pk + nxr * st,
             *kny = pk + nyr * st, *kvx = pk + uvr * st, *kvy = pk + (uvr + 1) * st;
  const real xi = x[i], yi = y[i], Ri = ratio * dx[i], iR = 1 / Ri, R2 = Ri * Ri;
  const real iR2 = iR * iR, iR3 = iR2 * iR;
  const real h = hfac * Ri, eta2h = eta2 * h * h;
  const real rhoi = rho[i], Pi = P[i], uxi = ux[i], uyi = uy[i], nui = nu[i];
  const int pi = ph[i];
  const real phi = (real)pi, ci = T[RHOD_MP_TAB_C * MAXP + pi];
  /* paper 001 Eq. 5: the + form where p_i >= 0, the - form where p_i < 0 (tensile on) */
  const real sgn = !tensile || Pi >= 0 ? 1 : -1;
  const real Wdx = rhod_Wq(kern, dx[i] * iR) * iR2; /* W(dx), paper 000 Eq. 6 */
  const real nxi = surface ? nrm[2 * i] : 0, nyi = surface ? nrm[2 * i + 1] : 0;
  const real reli = nxi != 0 || nyi != 0 ? 1 : 0;
  real RHOD_LANES(s_div), RHOD_LANES(s_dif), RHOD_LANES(s_apx), RHOD_LANES(s_apy),
      RHOD_LANES(s_avx), RHOD_LANES(s_avy), RHOD_LANES(s_kn), RHOD_LANES(s_kd), RHOD_LANES(s_sx),
      RHOD_LANES(s_sy), RHOD_LANES(s_fx), RHOD_LANES(s_fy);
  RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
    RHOD_FOR_LANES(k0, kv, k) {
      const real rx = xi - kx[k], ry = yi - ky[k], r2 = rx * rx + ry * ry;
      if (!(r2 < R2 && r2 > 0))
        continue;
      const real r = sqrt(r2), q = r * iR;
      const real dW = rhod_dWq(kern, q) * iR3, dWr = dW / r;
      const real gwx = dWr * rx, gwy = dWr * ry; /* grad W_ij */
      const real Vj = kV[k], rhoj = krho[k];
      const real same = kph[k] == phi ? 1 : 0;
      const real uijx = uxi - kux[k], uijy = uyi - kuy[k];
      /* paper 000 Eq. 1, first sum: rho_i (u_i - u_j) . grad W_ij V_j (all phases) */
      RHOD_LANE(s_div) += rhod_mp_div_term(rhoi, uijx * gwx + uijy * gwy, Vj);
      /* paper 000 Eq. 1, delta-SPH diffusion: the same phase only */
      RHOD_LANE(s_dif) += same * rhod_mp_diffusion(delta, ci, rhoi, rhoj, dW, Vj);
      /* paper 000 Eq. 2 (paper 001 Eq. 5): -(p_j +- p_i) V_j / rho_i grad W_ij */
      const real pc = -(kP[k] + sgn * Pi) * Vj / rhoi;
      RHOD_LANE(s_apx) += pc * gwx;
      RHOD_LANE(s_apy) += pc * gwy;
      /* paper 001 Eq. 6, all phases */
      const real vc =
          visc * rhod_mp_visc_coef(km[k], nui, knu[k], rhoi, rhoj,
                                   (uxi - kvx[k]) * rx + (uyi - kvy[k]) * ry, r2, eta2h);
      RHOD_LANE(s_avx) += vc * gwx;
      RHOD_LANE(s_avy) += vc * gwy;
      /* paper 001 Eq. 10 over the neighbours with a reliable normal */
      const real nxj = knx[k], nyj = kny[k];
      const real relj = reli * (nxj != 0 || nyj != 0 ? 1 : 0);
      RHOD_LANE(s_kn) += relj * Vj * ((nxi - nxj) * gwx + (nyi - nyj) * gwy);
      /* D_i: the scalar (001 Eq. 10's TYPO prints a vector) */
      RHOD_LANE(s_kd) += relj * Vj * r * fabs(dW);
      /* paper 000 Eq. 7: sum_j V_j (1 + f_ij) grad W_ij, f_ij of Eq. 6 ... */
      const real wq = rhod_Wq(kern, q) * iR2 / Wdx;
      const real f = rep2 ? xi_rep * wq * wq : rhod_mp_rep(xi_rep, wq, 1, rep_n);
      RHOD_LANE(s_sx) += Vj * (1 + f) * gwx;
      RHOD_LANE(s_sy) += Vj * (1 + f) * gwy;
      /* ... and the RIF's sum over j not in chi_i */
      RHOD_LANE(s_fx) += (1 - same) * Vj * gwx;
      RHOD_LANE(s_fy) += (1 - same) * Vj * gwy;
    }
    RHOD_END_LANES
  }
  RHOD_END_ROWS
  drho[i] = RHOD_LANES_SUM(s_div) + RHOD_LANES_SUM(s_dif);
  real ax = RHOD_LANES_SUM(s_apx) + RHOD_LANES_SUM(s_avx) + gxb;
  real ay = RHOD_LANES_SUM(s_apy) + RHOD_LANES_SUM(s_avy) + gyb;
  if (surface) {
    const real kn = RHOD_LANES_SUM(s_kn), kd = RHOD_LANES_SUM(s_kd);
    real kap_i = 0;
    if (reli != 0 && kd > 0) {
      kap_i = -RHOD_DIM * kn / kd; /* paper 001 Eq. 10 */
      /* paper 001 Eq. 7 with n |grad C| = grad C: a = -(1/rho_i) sigma kappa grad C */
      const real s = -sig[i] * kap_i / rhoi;
      ax += s * gC[2 * i];
      ay += s * gC[2 * i + 1];
    }
    kap[i] = kap_i;
  }
  acc[2 * i] = ax;
  acc[2 * i + 1] = ay;
  /* paper 000 Eqs. 4 and 7: x moves with u + u_s */
  const real sx = RHOD_LANES_SUM(s_sx), sy = RHOD_LANES_SUM(s_sy);
  const real fx = RHOD_LANES_SUM(s_fx), fy = RHOD_LANES_SUM(s_fy);
  const real usx = rhod_mp_shift(xi_shift, h, dt, sx + xi_rif * alpha * fx);
  const real usy = rhod_mp_shift(xi_shift, h, dt, sy + xi_rif * alpha * fy);
  us[2 * i] = usx;
  us[2 * i + 1] = usy;
  vel[2 * i] = uxi + usx;
  vel[2 * i + 1] = uyi + usy;
}

void rhod_mp_pass_main(rhod_mp *m, rhod_particles *p, const rhod_cells *c, real dt) {
  const long n = (long)p->n, st = (long)p->cap;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start;
  const real *x = p->x, *y = p->y, *dx = p->dx, *rho = p->rho, *ux = p->ux, *uy = p->uy, *P = m->P,
             *nu = m->nu, *T = m->tab, *pk = m->pk;
  const uint8_t *ph = p->phase;
  const real *gC = m->gC, *nrm = m->nrm, *sig = m->sig;
  real *kap = m->kap, *drho = m->drho, *acc = m->acc, *vel = m->vel, *us = m->us;
  const rhod_mp_params *q_ = &m->prm;
  const int kern = q_->kernel, tensile = q_->tensile, surface = m->surface;
  const real ratio = q_->ratio, hfac = m->hfac, delta = q_->delta, eta2 = q_->eta2;
  const real xi_shift = q_->xi_shift, xi_rep = q_->xi_rep, rep_n = q_->rep_n, xi_rif = q_->xi_rif,
             gxb = q_->gx, gyb = q_->gy;
  const real alpha = 1; /* regular particles (paper 000 Eq. 7, Fig. 11) */
  int visc_on = 0;
  for (int k = 0; k < q_->nphase; k++)
    visc_on |= q_->ph[k].mu > 0;
  const real visc = visc_on ? 1 : 0;
  /* the normals' rows exist with surface tension only: elsewhere read the x row (any
   * row will do: every use is multiplied by reli = 0) */
  const long nxr = surface ? RHOD_MP_PK_NX : RHOD_MP_PK_X,
             nyr = surface ? RHOD_MP_PK_NY : RHOD_MP_PK_X;
  const long uvr = m->uvr; /* RHOD_MP_PK_UX (the same velocity) without no slip */
  const int rep2 = rep_n == 2;
  (void)rep2;
#ifdef RHOD_OFFLOAD
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++)
    main_particle(i, MAIN_ARGS, dt, kern, 0);
#else
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    if (kern == RHOD_KERNEL_WENDLAND_C4 && rep2)
      main_particle(i, MAIN_ARGS, dt, RHOD_KERNEL_WENDLAND_C4, 1);
    else if (kern == RHOD_KERNEL_QUINTIC && rep2)
      main_particle(i, MAIN_ARGS, dt, RHOD_KERNEL_QUINTIC, 1);
    else
      main_particle(i, MAIN_ARGS, dt, kern, 0);
  }
#endif
}

void rhod_mp_rhs(rhod_mp *m, rhod_particles *p, const rhod_cells *c, real dt) {
  rhod_mp_pack(m, p, c);
  if (m->surface) {
    rhod_mp_pass_colour(m, p, c);
    const long nt = (long)(p->n + p->ng), st = (long)p->cap;
    rhod_cells_pack(c, nt, m->pk + RHOD_MP_PK_NX * st, m->nrm, 2, 0);
    rhod_cells_pack(c, nt, m->pk + RHOD_MP_PK_NY * st, m->nrm, 2, 1);
  }
  rhod_mp_pass_main(m, p, c, dt);
  /* the largest shift per step in particle sizes (logged; multiphase.md: no cap) */
  const long n = (long)p->n;
  const real *us = m->us, *dx = p->dx;
  real umax = 0;
  RHOD_KERNEL_LOOP_REDUCE(max, umax)
  for (long i = 0; i < n; i++) {
    const real u = sqrt(us[2 * i] * us[2 * i] + us[2 * i + 1] * us[2 * i + 1]) / dx[i];
    umax = u > umax ? u : umax;
  }
  m->us_max = umax * (dt > 0 ? dt : 0);
}

/* Paper 001 Eqs. 14-17, per particle, with h_s = hs_fac R_i:
 * 14: C_tau h_s^2 rho_i / mu_i, 15: C_a sqrt(h_s / |a_i|), 16: C_c h_s / c_i,
 * 17: C_sigma sqrt(h_s^3 rho_i / (2 pi sigma)), sigma the largest of i's phase's pairs. */
real rhod_mp_force_dt(const rhod_mp *m, const rhod_particles *p) {
  const long n = (long)p->n;
  const real *dx = p->dx, *acc = m->acc;
  const real hsR = m->hs_fac * m->prm.ratio, ca = m->prm.cfl_force;
  real d15 = BIG;
  RHOD_KERNEL_LOOP_REDUCE(min, d15)
  for (long i = 0; i < n; i++) {
    const real hs = hsR * dx[i];
    const real am = sqrt(acc[2 * i] * acc[2 * i] + acc[2 * i + 1] * acc[2 * i + 1]);
    const real a = am > 0 ? ca * sqrt(hs / am) : BIG; /* Eq. 15 */
    d15 = a < d15 ? a : d15;
  }
  return d15;
}

real rhod_mp_dt(rhod_mp *m, const rhod_particles *p) {
  const long n = (long)p->n;
  const real *dx = p->dx, *rho = p->rho, *T = m->tab;
  const uint8_t *ph = p->phase;
  const real hsR = m->hs_fac * m->prm.ratio;
  const real cv = m->prm.cfl_visc, cc = m->prm.cfl, cs = m->prm.cfl_surface;
  real d14 = BIG, d17 = BIG, d16 = BIG;
  RHOD_KERNEL_LOOP_REDUCE2(min, d14, d17)
  for (long i = 0; i < n; i++) {
    const int k = ph[i];
    const real hs = hsR * dx[i], mu = T[RHOD_MP_TAB_MU * MAXP + k];
    const real sg = T[RHOD_MP_TAB_SIGMA_MAX * MAXP + k];
    const real a = mu > 0 ? cv * hs * hs * rho[i] / mu : BIG; /* Eq. 14 */
    const real b = sg > 0 ? cs * sqrt(hs * hs * hs * rho[i] / (2 * RHOD_PI * sg)) : BIG; /* 17 */
    d14 = a < d14 ? a : d14;
    d17 = b < d17 ? b : d17;
  }
  RHOD_KERNEL_LOOP_REDUCE(min, d16)
  for (long i = 0; i < n; i++) {
    const real hs = hsR * dx[i];
    const real b = cc * hs / T[RHOD_MP_TAB_C * MAXP + ph[i]]; /* Eq. 16 */
    d16 = b < d16 ? b : d16;
  }
  /* Eq. 15: as the caller kept it after the step's last right-hand side, or from acc */
  const real d15 = m->force_dt > 0 ? m->force_dt : rhod_mp_force_dt(m, p);
  real dt = d14;
  m->dt_by = RHOD_MP_DT_VISC;
  if (d15 < dt)
    dt = d15, m->dt_by = RHOD_MP_DT_FORCE;
  if (d16 < dt)
    dt = d16, m->dt_by = RHOD_MP_DT_SOUND;
  if (d17 < dt)
    dt = d17, m->dt_by = RHOD_MP_DT_SURFACE;
  return dt;
}
