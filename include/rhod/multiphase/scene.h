/* The multiphase scheme's part of a scene (paper 000, Buerkle et al. 2025; paper 001,
 * Wicker et al., writes the same scheme out): the phases and the `multiphase` section.
 * Loaded by src/scene.c through src/multiphase/scene_mp.c; every key, unit, default and
 * paper reference is documented in docs/scene.md. rhod_scene.mp points here (NULL for
 * the rhodsph scheme). */
#ifndef RHOD_MULTIPHASE_SCENE_H
#define RHOD_MULTIPHASE_SCENE_H

/* Most phases a scene may hold (particle tag `phase` is a uint8). */
#define RHOD_MP_MAX_PHASES 8

/* One phase (paper 000 Sec. 2, Eq. 3 = paper 001 Eq. 1): p = rho0 c^2/gamma
 * [(rho/rho0)^gamma - 1]. */
typedef struct {
  char *name;    /* phases.N.name: an identifier, unique */
  double rho0;   /* reference density [kg/m^3] > 0 */
  double c;      /* artificial speed of sound [m/s] > 0 */
  double gamma;  /* polytropic exponent > 0, default 7 */
  double mu;     /* dynamic viscosity [Pa s] >= 0, default 0 */
  double colour; /* colour function value: 1 liquid, 0 gas (paper 001 Eq. 8) */
} rhod_mp_phase_desc;

typedef struct rhod_mp_scene {
  rhod_mp_phase_desc *phases;
  unsigned n_phases;
  double *sigma; /* surface tension [N/m] of each pair: n_phases * n_phases, symmetric, 0 on
                    the diagonal (multiphase.sigma, overridden by multiphase.sigma_pairs) */
  double delta;  /* density diffusion coefficient, paper 000 Eq. 1, default 0.1 */
  double xi_shift, xi_rep, rep_n, xi_rif; /* transport velocity, paper 000 Eqs. 4-7:
                                             0.5, 0.1, 2, 0.01 */
  double eta2;         /* viscosity regulariser: eta^2 = eta2 h^2 (paper 001 Eq. 6), 0.01 */
  int tensile_control; /* paper 001 Eq. 5, default on */
  double cfl, cfl_visc, cfl_force, cfl_surface; /* time step, paper 001 Eqs. 14-17:
                                                   0.25, 0.125, 0.25, 0.25 */
} rhod_mp_scene;

/* Index of the phase called `name`, or -1. */
int rhod_mp_phase_index(const rhod_mp_scene *mp, const char *name);

/* sigma of the pair (a, b) [N/m]. */
static inline double rhod_mp_sigma(const rhod_mp_scene *mp, unsigned a, unsigned b) {
  return mp->sigma[a * mp->n_phases + b];
}

void rhod_mp_scene_free(rhod_mp_scene *mp);

#endif
