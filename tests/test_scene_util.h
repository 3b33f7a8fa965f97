/* Shared by the unit tests: a scene filled in by hand with the papers' defaults. */
#ifndef RHOD_TEST_SCENE_UTIL_H
#define RHOD_TEST_SCENE_UTIL_H

#include "rhod/scene.h"
#include <stdlib.h>

/* A minimal scene for the scheme's parameters (no refinement criterion on); free()
 * it (path is a literal). */
static inline rhod_scene *unit_scene(double dx) {
  rhod_scene *sc = calloc(1, sizeof *sc);
  sc->t_end = 1, sc->output_every = 1, sc->cfl = 0.5, sc->cfl_visc = 0.025;
  sc->dx = dx, sc->radius_ratio = 4, sc->kernel = RHOD_KERNEL_WENDLAND_C2;
  sc->levels = 1;
  sc->rho0 = 1000, sc->c0 = 20, sc->mu = 0;
  sc->riemann = sc->reconstruction = sc->shifting = sc->acoustic_damper = sc->free_surface = 1;
  sc->shift_a = 0.5, sc->shift_b = 0.05, sc->shift_eps = 5e-4, sc->alpha_ad = 1;
  sc->damper_step_limit = 1, sc->stiffness_limit = 1;
  sc->fs_lambda_low = 0.2, sc->fs_lambda_high = 0.75;
  sc->shepard_threshold = 0.85, sc->theta_threshold = 0.95;
  sc->path = "unit";
  return sc;
}

#endif
