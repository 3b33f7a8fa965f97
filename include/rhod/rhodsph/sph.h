/* The RHOD-SPH scheme of paper 002 (Michel et al. 2025), Secs. III-IV, as a set of
 * passes over the engine's particles. ../shared/design/scheme.md gives the order. */
#ifndef RHOD_SPH_H
#define RHOD_SPH_H

#include "rhod/boundary.h"
#include "rhod/cells.h"
#include "rhod/particles.h"
#include "rhod/rhodsph/scene.h"

/* rhod_sph_dt's binding limit */
enum { RHOD_DT_BY_EQ11, RHOD_DT_BY_DAMPER, RHOD_DT_BY_STIFFNESS };

/* Rows of rhod_sph.pk: the neighbour-side fields of the gathers, copied into the order
 * of the sorted cells (row r of particle CI[k] at pk[r * cap + k]), so that the inner
 * loops over a row of cells read them contiguously and vectorise (RHOD_FOR_ROWS).
 * Pass A packs the first rows (the state), pass C the rest (pass A's gradients, the
 * shifting velocity and rho). The cells must have been built over the fluid and the
 * ghosts. After a right-hand side (rhod_sph_rhs) both sets hold that stage's values,
 * which the refinement criteria read (rhod_apr_mark), and the scheme's subset cells fsc
 * hold that stage's free-surface particles (the region pass). */
enum {
  RHOD_PK_X,
  RHOD_PK_Y,
  RHOD_PK_V,
  RHOD_PK_P,
  RHOD_PK_UX,
  RHOD_PK_UY,
  RHOD_PK_DX, /* the rows above: pass A's */
  RHOD_PK_D,
  RHOD_PK_GPX,
  RHOD_PK_GPY,
  RHOD_PK_GU0,
  RHOD_PK_GU1,
  RHOD_PK_GU2,
  RHOD_PK_GU3,
  RHOD_PK_DUX,
  RHOD_PK_DUY,
  RHOD_PK_RHO, /* from RHOD_PK_D: pass C's */
  RHOD_PK_ROWS,
  /* the region pass's rows, in pass C's (packed again by pass C after it): the
   * positions and normals of the free-surface particles, in the order of the subset
   * cells fsc (rhod_cells_build_subset) */
  RHOD_PK_FX = RHOD_PK_D,
  RHOD_PK_FY = RHOD_PK_GPX,
  RHOD_PK_FNX = RHOD_PK_GPY,
  RHOD_PK_FNY = RHOD_PK_GU0,
  /* rhod_sph_pass_jumps' rows, in pass C's too: the positions, volumes and sizes of the
   * particles it flagged, in the order of the subset cells jsc */
  RHOD_PK_JX = RHOD_PK_D,
  RHOD_PK_JY = RHOD_PK_GPX,
  RHOD_PK_JV = RHOD_PK_GPY,
  RHOD_PK_JDX = RHOD_PK_GU0,
  /* with a balanced scheme.shifting_switch: du' of rhod_sph_pass_jumps (packed by pass C) */
  RHOD_PK_DPX = RHOD_PK_ROWS,
  RHOD_PK_DPY,
  RHOD_PK_ROWS_BALANCED
};
/* with no slip in the viscous terms alone (rhod_sph.vrow): the row of the viscous velocity's
 * x, its y the next, after the rows above (bal: a balanced shifting switch) */
#define RHOD_PK_UV_ROW(bal) ((bal) ? RHOD_PK_ROWS_BALANCED : RHOD_PK_ROWS)

typedef struct {
  /* parameters (from the scene) */
  int kernel;
  real ratio; /* R/dx */
  real rho0, c0, mu, gx, gy;
  real cfl, cfl_visc;
  int riemann, recon, shifting, damper, fsdetect;
  int tic;        /* scheme.tensile_control */
  int shsw;       /* scheme.shifting_switch (rhod_shifting_switch) */
  int adlim;      /* scheme.damper_step_limit (and the damper on) */
  int visc_cons;  /* scheme.viscosity: consistent (and mu > 0) */
  int walls_move; /* some wall edge moves: ghost velocities add gU (rhod_sph_fill_state) */
  int vrow;       /* with viscosity and a no-slip wall or body (the store has gTv): the pack
                     row of uv's x (its y the next), after the others; 0 otherwise */
  int generic;    /* 1: the general copies of the gathers, never the specialised ones
                     (tests/test_kernels.c compares them) */
  real alpha_ad, sa, sb, seps, lam_lo, lam_hi, gamma_th, theta_th;
  real ad_lambda; /* largest |eigenvalue| of Eq. 9 as last measured (rhod_sph_damper_probe);
                     0: none */
  int stlim;      /* time.stiffness_limit (and RK4) */
  int dt_by;      /* which limit set the last rhod_sph_dt: RHOD_DT_BY_* */
  real st_lambda; /* stiffness of the last step's RK4 stages, -q of rhod_rk_stiffness over
                     the inner particles (1/s); 0: none */
  /* per-particle fields (scratch, rebuilt each stage) */
  real *P, *V;
  real *gam, *ggam;       /* Shepard Gamma (Eq. 7) and its gradient (Eq. 27), 2 */
  real *L;                /* renormalisation matrix (Eq. 8), 4, row-major */
  real *gP, *gu;          /* renormalised gradients (Eq. 14) of P (2) and u (4: dux/dx,
                             dux/dy, duy/dx, duy/dy) */
  real *D;                /* velocity divergence (Eq. 5) */
  real *lapB;             /* consistent Laplacian's correction B^ (xx, xy, yy), 3; only
                             with visc_cons; B^ = 0 where it cannot be solved */
  real *gC;               /* concentration gradient (Eq. 29), 2 */
  real *uch;              /* U_char (after Eq. 27) */
  real *lam;              /* smallest eigenvalue of sym(L^-1) */
  real *nrm;              /* free-surface normal, 2 */
  real *nt, *sig;         /* shifting projection normal and weight (Eq. 26), 2 and 1 */
  real *du;               /* shifting velocity (Eq. 27), 2 */
  uint8_t *jmp;           /* with a balanced shifting switch: 1 where a particle of another
                             size lies within max(R_i, R_j) (a size jump), from
                             rhod_sph_pass_jumps (pass A: within R_i; ghosts: 1) */
  real *jM;               /* there: the scatter moment M_i (xx, xy, yy), 3; 0 elsewhere */
  real *dup;              /* there: du' = M^-1 du (du elsewhere), 2 */
  real *uv;               /* with vrow: the velocity the viscous terms see, 2 (the fluid's
                             own; a ghost's through gTv, gUv: docs/choices.md "no slip in
                             the viscous term only") */
  real *drho, *acc, *vel; /* time derivatives: d rho/dt, du/dt (2), dx/dt (2) */
  uint8_t *fs;            /* 1: free-surface particle (set F) */
  uint8_t *reg;           /* 0 inner (I), 1 vicinity (V), 2 free surface (F) */
  real *pk;               /* neighbour-side fields packed in cell order (RHOD_PK_*) */
  real *adv;              /* with adlim: the damper probe's iterate (2, carried across
                             steps and checkpointed), its divergence (adD, 1) and gradient
                             (adG, 4) */
  real *adD, *adG;
  /* neighbour structures of particle sets, subsets of the caller's cells (owned here,
   * sized on first use by rhod_cells_build_subset, freed by rhod_sph_free): */
  rhod_cells fsc; /* the free-surface particles (fluid and ghosts) of the last region
                     pass, which rhod_apr_mark reads too */
  rhod_cells jsc; /* the particles rhod_sph_pass_jumps flagged */
} rhod_sph;

int rhod_sph_init(rhod_sph *s, const rhod_scene *sc, rhod_particles *p);
/* Frees what the state owns besides the store's fields (its subset cells). */
void rhod_sph_free(rhod_sph *s);

/* One right-hand-side evaluation at the current positions: the neighbour structure
 * must be built (ghosts generated, cells sorted). Fills drho, acc, vel for the fluid.
 * RHOD_ERR_MEMORY when a subset's cells cannot be allocated (the passes below return
 * the same). */
int rhod_sph_rhs(rhod_sph *s, rhod_particles *p, rhod_cells *c, real dt);

/* Values of the ghosts from their sources (state part: u, P, rho, V), and the fluid
 * EOS. Called after the ghosts are built and before any gather. */
void rhod_sph_fill_state(rhod_sph *s, rhod_particles *p);

/* The passes of one right-hand side, in the order rhod_sph_rhs runs them (public for
 * the per-pass benchmarks). The free-surface detection reads the positions that pass A
 * packed in cell order, so it follows pass A over the same cells: */
void rhod_sph_pass_a(rhod_sph *s, rhod_particles *p, const rhod_cells *c);
void rhod_sph_mirror_gradients(rhod_sph *s, rhod_particles *p);
/* With a balanced scheme.shifting_switch (and shifting on): the size-jump flags and scatter
 * moments (jmp, jM) after pass A and its mirrors, with the flagged particles in jsc. Does
 * nothing otherwise. */
int rhod_sph_pass_jumps(rhod_sph *s, rhod_particles *p, const rhod_cells *c);
void rhod_sph_pass_free_surface(rhod_sph *s, rhod_particles *p, const rhod_cells *c);
void rhod_sph_mirror_surface(rhod_sph *s, rhod_particles *p);
int rhod_sph_pass_region(rhod_sph *s, rhod_particles *p, const rhod_cells *c);
void rhod_sph_pass_shift(rhod_sph *s, rhod_particles *p, real dt);
void rhod_sph_pass_c(rhod_sph *s, rhod_particles *p, const rhod_cells *c);
/* One iteration of the initial relaxation (particles.relax): moves the fluid particles
 * along the shifting direction J of Eqs. 25-26; cells and ghosts must be current. With
 * jumps_dx > 0 (the largest size present; particles.relax_where: jumps) only those within
 * reach of a particle of another size move. */
int rhod_sph_relax(rhod_sph *s, rhod_particles *p, rhod_cells *c, real jumps_dx);

/* Target of the measured step limits: dt |lambda| of Eq. 9 (the damper step limit) and
 * dt times the stiffness of the RK4 stages (the stiffness limit) kept at or below this,
 * RK4 being stable down to dt lambda = -2.785 on the real axis (rhod_sph.c). */
#define RHOD_DT_TARGET 2.2
/* The stiffness limit takes dt down to this fraction of the other limits' at most. */
#define RHOD_ST_FLOOR 0.1
/* The initial relaxation's step (rhod_sph_relax): coefficient of delta x = beta dx J and
 * the largest step, both in units of the particle's size. */
#define RHOD_RELAX_BETA 0.25
#define RHOD_RELAX_STEP 0.1

/* One power iteration of the acoustic damper's operator (Eq. 9 with Eq. 5, linear in u)
 * on the carried iterate: returns the estimate of its largest |eigenvalue| (1/s). The
 * neighbour structure must be built (ghosts, cells, rhod_sph_fill_state); it overwrites
 * the packed rows of the gathers, which the next pass A and pass C pack again. */
real rhod_sph_damper_probe(rhod_sph *s, rhod_particles *p, const rhod_cells *c);

/* The angular-momentum budget of one right-hand side (the torque_budget probe): the
 * torque about (ax, ay) of each term of the momentum equation (Eq. 3), sum m (x - a) x
 * a_term, switched on one after the other in pass C (so each is its own difference):
 * RHOD_TQ_PRESSURE (Eq. 6), RHOD_TQ_VISCOUS (Eq. 10 or the consistent Laplacian),
 * RHOD_TQ_RIEMANN (Theta^u, Eq. 24; zero with viscosity), RHOD_TQ_DAMPER (Eq. 9),
 * RHOD_TQ_SHIFTING (the Eq. 4 momentum term), RHOD_TQ_BODY (the body force), and
 * RHOD_TQ_MOTION = sum m du x u, the change of sum m x x u that comes from moving the
 * particles at u + du (Eq. 3's dx/dt) instead of u. Their sum is dLz/dt of the fluid.
 * Runs a full right-hand side first (the neighbour structure must be built), then
 * pass C four times; drho, acc and vel are left as the last of these (scratch, which
 * the next right-hand side overwrites). */
enum {
  RHOD_TQ_PRESSURE,
  RHOD_TQ_VISCOUS,
  RHOD_TQ_RIEMANN,
  RHOD_TQ_DAMPER,
  RHOD_TQ_SHIFTING,
  RHOD_TQ_BODY,
  RHOD_TQ_MOTION,
  RHOD_TQ_TERMS
};
int rhod_sph_torque_budget(rhod_sph *s, rhod_particles *p, rhod_cells *c, real dt, real ax, real ay,
                           double out[RHOD_TQ_TERMS]);

/* Time step of Eq. 11 over the fluid, with adlim no more than RHOD_DT_TARGET / ad_lambda,
 * and with stlim no more than RHOD_DT_TARGET / st_lambda but at least RHOD_ST_FLOOR of the
 * rest; dt_by says which one set it. */
real rhod_sph_dt(rhod_sph *s, const rhod_particles *p);

#endif
