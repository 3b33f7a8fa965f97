/* The multiphase scheme of paper 000 (Bürkle et al. 2025), Sec. 2: regular particles of
 * one resolution level, as passes over the engine's particles. Paper 001 (Wicker et al.)
 * writes out what paper 000 only cites (viscosity, surface tension, time step).
 * ../shared/design/multiphase.md section A gives the order, the misprints and our
 * choices (docs/choices.md). Uses engine headers only. */
#ifndef RHOD_MP_H
#define RHOD_MP_H

#include "rhod/cells.h"
#include "rhod/kernel_kind.h"
#include "rhod/multiphase/scene.h" /* RHOD_MP_MAX_PHASES */
#include "rhod/particles.h"
#include "rhod/status.h"

/* One fluid: Tait EOS (paper 000 Eq. 3) and dynamic viscosity; colour 1 liquid, 0 gas. */
typedef struct {
  real rho0, c, gamma, mu, colour;
} rhod_mp_phase;

typedef struct {
  int nphase;
  rhod_mp_phase ph[RHOD_MP_MAX_PHASES];
  real sigma[RHOD_MP_MAX_PHASES * RHOD_MP_MAX_PHASES]; /* surface tension per pair [a*MAX+b],
                                                          symmetric */
  int kernel;  /* rhod_kernel_kind: RHOD_KERNEL_WENDLAND_C4 or RHOD_KERNEL_QUINTIC (C2 too) */
  real ratio;  /* R/dx (4 for Wendland C4 h/dx = 2; 3 for quintic h/dx = 1) */
  real gx, gy; /* body force */
  real delta;  /* density diffusion coefficient, 0.1 (Eq. 1) */
  real xi_shift, xi_rep, rep_n, xi_rif; /* 0.5, 0.1, 2, 0.01 (Eqs. 4-7) */
  real eta2;                            /* Szewc regulariser: eta^2 = eta2 * h^2, eta2 = 0.01 */
  int tensile;                          /* tensile-instability switch (paper 001 Eq. 5), 1 = on */
  real cfl, cfl_visc, cfl_force, cfl_surface; /* paper 001 Eqs. 14-17: 0.25, 0.125, 0.25, 0.25 */
} rhod_mp_params;

/* rhod_mp_dt's binding limit: paper 001 Eq. 14 (viscous), 15 (force), 16 (sound), 17
 * (surface tension) */
enum { RHOD_MP_DT_VISC, RHOD_MP_DT_FORCE, RHOD_MP_DT_SOUND, RHOD_MP_DT_SURFACE };

/* Rows of the phase table (rhod_mp.tab, on the device): per phase k, tab[row * MAX + k];
 * then sigma[a * MAX + b] at tab[RHOD_MP_TAB_SIGMA * MAX + a * MAX + b]. */
enum {
  RHOD_MP_TAB_RHO0,
  RHOD_MP_TAB_C,
  RHOD_MP_TAB_GAMMA,
  RHOD_MP_TAB_MU,
  RHOD_MP_TAB_COLOUR,
  RHOD_MP_TAB_SIGMA_MAX, /* the largest sigma of a pair with phase k (Eq. 17) */
  RHOD_MP_TAB_SIGMA
};
#define RHOD_MP_TAB_SIZE                                                                           \
  (RHOD_MP_TAB_SIGMA * RHOD_MP_MAX_PHASES + RHOD_MP_MAX_PHASES * RHOD_MP_MAX_PHASES)

/* Reliable normals (multiphase.md, SILENT -> choice; docs/choices.md): a particle's
 * colour gradient counts as an interface normal where a particle of another colour lies in
 * its support and |grad C| > RHOD_MP_NORMAL_EPS * 2 w / h, w the kernel-weighted mean of
 * the density weight rho_i / (rho_i + rho_k) over those neighbours k (Morris 2000's 0.01/h
 * for equal densities). */
#define RHOD_MP_NORMAL_EPS ((real)0.01)

/* Rows of rhod_mp.pk: the neighbour-side fields of the gathers copied into the cells'
 * order (rhod_cells_pack; row r of the particle at sorted place k at pk[r * cap + k]), so
 * that the inner loops read them contiguously and vectorise (RHOD_FOR_LANES). The colour
 * pass reads the rows up to COL; the normals are packed after it, for the main pass. */
enum {
  RHOD_MP_PK_X,
  RHOD_MP_PK_Y,
  RHOD_MP_PK_V,
  RHOD_MP_PK_P,
  RHOD_MP_PK_UX,
  RHOD_MP_PK_UY,
  RHOD_MP_PK_RHO,
  RHOD_MP_PK_M,
  RHOD_MP_PK_NU,  /* kinematic viscosity mu / rho */
  RHOD_MP_PK_PH,  /* the phase index, as a real */
  RHOD_MP_PK_COL, /* the phase's colour */
  RHOD_MP_PK_ROWS_PLAIN,
  RHOD_MP_PK_NX = RHOD_MP_PK_ROWS_PLAIN, /* with surface tension: the normals */
  RHOD_MP_PK_NY,
  RHOD_MP_PK_ROWS
};

typedef struct {
  rhod_mp_params prm;
  real hfac;     /* h / R: 1/2 Wendland, 1/3 quintic */
  real hs_fac;   /* h_s / R, h_s = 2 x the kernel's per-axis standard deviation (computed
                    at init by quadrature: 0.5270 C2, 0.4606 C4, 0.4634 quintic) */
  int surface;   /* 1 when some sigma > 0: the colour-gradient pass runs */
  real *tab;     /* phase table (RHOD_MP_TAB_*), RHOD_MP_TAB_SIZE reals, on the device */
  int dt_by;     /* which limit set the last rhod_mp_dt: RHOD_MP_DT_* */
  real force_dt; /* > 0: Eq. 15's limit rhod_mp_dt takes instead of computing it from acc:
                    the caller sets it (rhod_mp_force_dt) after a step's last right-hand side,
                    before the particles are sorted again, and a resume carries it */
  real us_max;   /* max |u_s| dt / dx of the fluid after the last rhs (multiphase.md: logged,
                    no cap) */
  /* per-particle fields (scratch, rebuilt each stage) */
  real *P, *V;
  real *gC;               /* colour gradient grad C (001 Eq. 8, Adami's colour), 2 */
  real *nrm;              /* interface normal (001 Eq. 9) where reliable, else 0, 2 */
  real *sig;              /* surface tension of i's interface (0: none in reach) */
  real *kap;              /* curvature (001 Eq. 10), 0 where the normal is unreliable */
  real *us;               /* shifting velocity u_s (paper 000 Eq. 7), 2 */
  real *nu, *col;         /* kinematic viscosity and colour (fluid and ghosts) */
  real *uvx, *uvy;        /* with a no-slip wall or body (p->gTv): the velocity the viscous
                             term reads, the ghosts' through the walls' own conditions
                             (docs/choices.md "no slip in the viscous term only") */
  long uvr;               /* the pk row of uvx (uvy the next), RHOD_MP_PK_UX without them */
  real *pk;               /* neighbour-side rows in cell order (RHOD_MP_PK_*) */
  real *drho, *acc, *vel; /* d rho/dt (1), du/dt (2), dx/dt = u + u_s (2) */
} rhod_mp;

/* Registers its fields in p and the tags (rhod_particles_add_tags: p->phase holds each
 * particle's phase index, set by the caller's fill). RHOD_ERR_SCENE for a bad parameter
 * set (nphase out of 1..RHOD_MP_MAX_PHASES, unknown kernel), RHOD_ERR_MEMORY. */
int rhod_mp_init(rhod_mp *m, const rhod_mp_params *prm, rhod_particles *p);
void rhod_mp_free(rhod_mp *m);
/* Tait EOS (Eq. 3) and its inverse, for the initial state */
real rhod_mp_pressure(const rhod_mp_params *prm, int phase, real rho);
real rhod_mp_density(const rhod_mp_params *prm, int phase, real P);
/* After the engine built the ghosts (rhod_ghosts_build) and before any gather: pressure by
 * the EOS for the fluid [0, n), and the ghosts' state [n, n+ng) from their source gsrc:
 * u = T u_src (gT), rho, P, V, phase (wall mirrors and periodic images alike) */
void rhod_mp_fill_state(rhod_mp *m, rhod_particles *p);
/* One right-hand side at the current positions (ghosts and cells built over n + ng):
 * fills drho (1), acc (2: du/dt) and vel (2: dx/dt = u + u_s) for the fluid [0, n).
 * dt is the step of the shifting velocity (Eq. 7); dt <= 0 gives u_s = 0. */
void rhod_mp_rhs(rhod_mp *m, rhod_particles *p, const rhod_cells *c, real dt);
/* The passes of rhod_mp_rhs, in its order (public for tests and benchmarks): the rows in
 * cell order (rhod_mp_pack), the colour gradient, normal and sigma (only when m->surface),
 * the ghosts' copies of them, the normals' rows, then the rest. */
void rhod_mp_pack(rhod_mp *m, const rhod_particles *p, const rhod_cells *c);
void rhod_mp_pass_colour(rhod_mp *m, rhod_particles *p, const rhod_cells *c);
void rhod_mp_pass_main(rhod_mp *m, rhod_particles *p, const rhod_cells *c, real dt);
/* The time step of paper 001 Eqs. 14-17 (the four limits; |a_i| from the last rhs' acc);
 * dt_by says which one set it. */
real rhod_mp_dt(rhod_mp *m, const rhod_particles *p);
/* Eq. 15 alone, from the last right-hand side's accelerations. */
real rhod_mp_force_dt(const rhod_mp *m, const rhod_particles *p);

#endif
