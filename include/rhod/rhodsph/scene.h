/* The RHOD-SPH scheme's part of a scene (paper 002, Michel et al. 2025): the scheme's
 * switches (scheme.* but scheme.name), adaptive particle refinement (refinement.*), its
 * single fluid's physics (physics.rho0, c0, mu), the initial relaxation
 * (particles.relax*) and its time step (time.cfl, cfl_visc, stiffness_limit). Loaded by
 * src/scene.c through src/rhodsph/scene_rs.c; every key, unit, default and paper
 * reference is documented in docs/scene.md. rhod_scene.rs points here (NULL for the
 * multiphase scheme). */
#ifndef RHOD_RHODSPH_SCENE_H
#define RHOD_RHODSPH_SCENE_H

#include "rhod/scene.h"

/* Most particle sizes a scene may use: dx, dx/e, ..., dx/e^(RHOD_MAX_LEVELS-1). */
#define RHOD_MAX_LEVELS 8
/* refinement.crowding's default: split a particle when a finer one stands nearer than
 * this times the mean of their sizes (about 1 where the sizes tile the plane).
 * docs/choices.md "crowding at size jumps" */
#define RHOD_CROWDING_DEFAULT 0.75
/* Most iterations of the initial relaxation (particles.relax). */
#define RHOD_RELAX_MAX 100000

/* scheme.viscosity: how F^mu approximates mu lap u. Monaghan: paper 002 Eq. 10 (the
 * default). Consistent: exact for quadratic velocity fields on any particle cloud, in
 * the bulk (our choice, the higher-order operator paper 002 points to after Eq. 10;
 * docs/choices.md "Consistent viscous operator"). */
typedef enum { RHOD_VISCOSITY_MONAGHAN = 0, RHOD_VISCOSITY_CONSISTENT } rhod_viscosity;

/* particles.relax_where: which particles the initial relaxation moves: all of them, or
 * only those within reach of a particle of another size (r <= R of the larger of the
 * two), so that a lattice start keeps its lattice away from the size jumps. */
typedef enum { RHOD_RELAX_ALL = 0, RHOD_RELAX_JUMPS } rhod_relax_where;

/* scheme.shifting_switch: where Eq. 6 is renormalised, which of the Eq. 4 divergences
 * take the difference form instead of the paper's sum form (docs/choices.md "Shifting
 * terms at size jumps"): none (false), the momentum term alone (momentum), or the
 * momentum and continuity terms (true). The balanced forms keep the momentum term's sum
 * form except at the particles of a size jump, where it takes the difference form with
 * du' = M^-1 du (rhod_sph_pass_jumps): with the continuity terms switched as in `true`
 * (balanced) or not (balanced_momentum). */
typedef enum {
  RHOD_SHSW_NONE = 0,
  RHOD_SHSW_MOMENTUM,
  RHOD_SHSW_ALL,
  RHOD_SHSW_BALANCED,
  RHOD_SHSW_BALANCED_MOMENTUM
} rhod_shifting_switch;

/* refinement.pattern: how a particle splits (paper 002 Sec. V A and Appendix, Fig. 32).
 * Square: 1 -> 4, level size ratio e = dx_l / dx_(l+1) = 2 (the paper's pattern);
 * triangle: 1 -> 3, e = sqrt 3 (the Appendix's choice for R/dx = 3). The children have
 * the parent's area between them: e = sqrt(N_split). */
typedef enum { RHOD_PATTERN_SQUARE = 0, RHOD_PATTERN_TRIANGLE } rhod_pattern;

/* Children per split, and the size ratio of two adjacent levels. */
static inline int rhod_pattern_children(rhod_pattern p) {
  return p == RHOD_PATTERN_TRIANGLE ? 3 : 4;
}
static inline double rhod_pattern_ratio(rhod_pattern p) {
  return p == RHOD_PATTERN_TRIANGLE ? 1.7320508075688772 : 2.0;
}

/* An initial refinement region (square pattern): the lattice inside it starts at
 * `level` (size particles.dx / 2^level), the finest region containing a point winning;
 * with hold, dynamic refinement keeps it there (paper 002 Sec. VI E, strategy a). */
typedef struct {
  rhod_shape shape;
  int level;
  int hold; /* refinement.regions.N.hold: kept at its level during the run (ours) */
} rhod_region;

/* The field of refinement criterion 5 (paper 002 Sec. V B), Shepard-averaged: P;
 * rho |u|^2 / 2; or P - rho0 g.(x - x0), the pressure less the hydrostatic one below the
 * free surface's reference point x0 (Sec. VI F, which calls it the dynamic pressure
 * component). */
typedef enum {
  RHOD_QTY_PRESSURE = 0,
  RHOD_QTY_DYNAMIC_PRESSURE,
  RHOD_QTY_HYDRODYNAMIC_PRESSURE
} rhod_quantity;

typedef struct rhod_rs_scene {
  /* time: */
  double cfl;          /* time.cfl, CFL_h of Eq. 11, default 0.5 */
  double cfl_visc;     /* time.cfl_visc, CFL_mu of Eq. 11, default 0.025 */
  int stiffness_limit; /* time.stiffness_limit: dt also kept below the stiffness
                          the RK4 stages measure (integrator.h); default on */
  /* particles: */
  int relax; /* particles.relax: iterations of the initial relaxation by the
                shifting operator (before t = 0), default 0 */
  /* particles.relax_where, default all */
  rhod_relax_where relax_where;
  /* physics: */
  double rho0; /* physics.rho0 [kg/m^3], default 1000 */
  double c0;   /* physics.c0 [m/s] (required), Eq. 2 */
  double mu;   /* physics.mu [Pa s], default 0 (inviscid) */
  /* scheme (paper 002 Sec. IV A; each switch defaults to on): */
  int riemann;                          /* scheme.riemann: Theta^rho and Theta^u, Eqs. 23-24 */
  int reconstruction;                   /* scheme.reconstruction: limited linear states Eqs. 13-16
                                           (off: first order, phi_L = phi_i) */
  int shifting;                         /* scheme.shifting: Eqs. 25-29 and the Eq. 4 terms */
  double shift_a, shift_b, shift_eps;   /* scheme.shifting_a/b/eps: 0.5, 0.05, 5e-4 (Eq. 27) */
  int acoustic_damper;                  /* scheme.acoustic_damper: Eq. 9 */
  double alpha_ad;                      /* scheme.alpha_ad: 1 */
  int damper_step_limit;                /* scheme.damper_step_limit: dt also kept below the
                                           damper's measured stiffness (rhod_sph.c); default on */
  int tensile_control;                  /* scheme.tensile_control: P_j - P_i in the conservative
                                          Eq. 6 where P_i < 0, off the free surface (paper 001
                                          Eq. 5); default off */
  rhod_shifting_switch shifting_switch; /* scheme.shifting_switch: which Eq. 4 divergences
                                           take the difference form where Eq. 6 is
                                           renormalised; default none (the paper's sum form
                                           everywhere) */
  int free_surface; /* scheme.free_surface: detection of Ref. 51 and the Eq. 6 switch;
                       off: every particle is inner */
  double fs_lambda_low, fs_lambda_high; /* scheme.free_surface_lambda: [0.2, 0.75] */
  double shepard_threshold;             /* scheme.shepard_threshold: Gamma_th = 0.85 (Eq. 6) */
  double theta_threshold;               /* scheme.theta_threshold: 0.95 (Eq. 24) */
  rhod_viscosity viscosity;             /* scheme.viscosity: the Laplacian of F^mu */
  /* refinement (adaptive particle refinement, paper 002 Secs. IV D and V): */
  int levels;           /* refinement.levels: sizes dx ... dx/e^(levels-1), default 1 */
  rhod_pattern pattern; /* refinement.pattern, default square (e = 2) */
  rhod_region *regions; /* refinement.regions: initial nested levels */
  unsigned n_regions;
  int refine_dynamic;      /* refinement.dynamic: split by the criteria during the run
                              (criteria 1 and 2 always), default true when levels > 1 */
  int refine_free_surface; /* refinement.free_surface: criterion 3, default false */
  double refine_band;      /* refinement.surface_band: criterion 3's reach over R_i, default 1 */
  double refine_crowding;  /* refinement.crowding: split where a finer particle is nearer than
                              this times the mean of the two sizes (ours), 0 = off */
  int refine_walls;        /* refinement.walls: criterion 4, default false */
  int refine_field;        /* refinement.field given: criterion 5 */
  int refine_coalesce;     /* refinement.coalesce: merge back where no criterion
                              holds any more, default false */
  int refine_absorb;       /* refinement.absorb: coalescing shares stragglers out among
                              their coarser neighbours, default true (with coalesce) */
  rhod_quantity field_quantity;    /* refinement.field.quantity */
  double field_above, field_below; /* thresholds (+-HUGE_VAL when absent) */
  double field_from;               /* refinement.field.from [s], default 0 */
  double field_x0[2]; /* refinement.field.x0 [m]: hydrodynamic_pressure's reference point */
} rhod_rs_scene;

void rhod_rs_scene_free(rhod_rs_scene *rs);

#endif
