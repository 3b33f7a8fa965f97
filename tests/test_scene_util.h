/* Shared by the unit tests: a scene filled in by hand with the papers' defaults. */
#ifndef RHOD_TEST_SCENE_UTIL_H
#define RHOD_TEST_SCENE_UTIL_H

#include "rhod/rhodsph/scene.h"
#include <stdlib.h>

/* The scene and its rhodsph keys in one allocation: free(sc) frees both. */
typedef struct {
  rhod_scene sc;
  rhod_rs_scene rs;
} unit_scene_mem;

/* A minimal rhodsph scene for the scheme's parameters (no refinement criterion on);
 * free() it (path is a literal). */
static inline rhod_scene *unit_scene(double dx) {
  unit_scene_mem *u = calloc(1, sizeof *u);
  rhod_scene *sc = &u->sc;
  sc->rs = &u->rs;
  sc->t_end = 1, sc->output_every = 1, sc->rs->cfl = 0.5, sc->rs->cfl_visc = 0.025;
  sc->dx = dx, sc->radius_ratio = 4, sc->kernel = RHOD_KERNEL_WENDLAND_C2;
  sc->rs->levels = 1;
  sc->rs->rho0 = 1000, sc->rs->c0 = 20, sc->rs->mu = 0;
  sc->rs->riemann = sc->rs->reconstruction = sc->rs->shifting = sc->rs->acoustic_damper =
      sc->rs->free_surface = 1;
  sc->rs->shift_a = 0.5, sc->rs->shift_b = 0.05, sc->rs->shift_eps = 5e-4, sc->rs->alpha_ad = 1;
  sc->rs->damper_step_limit = 1, sc->rs->stiffness_limit = 1;
  sc->rs->fs_lambda_low = 0.2, sc->rs->fs_lambda_high = 0.75;
  sc->rs->shepard_threshold = 0.85, sc->rs->theta_threshold = 0.95;
  sc->path = "unit";
  return sc;
}

#endif
