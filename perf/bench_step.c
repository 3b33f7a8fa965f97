/* Whole RK4 step of single-resolution RHOD-SPH on a perturbed lattice in a periodic
 * box (every term on, no walls): microseconds per particle-step and bytes per
 * particle. usage: bench_step [N=1e4] [steps=20] */
#include "rhod/sim.h"
#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv) {
  const double N = argc > 1 ? atof(argv[1]) : 1e4;
  const int steps = argc > 2 ? atoi(argv[2]) : 20;
  const int side = (int)ceil(sqrt(N));
  const double L = 1.0, dx = L / side;
  rhod_scene sc;
  memset(&sc, 0, sizeof sc);
  sc.t_end = 1, sc.output_every = 1, sc.cfl = 0.5, sc.cfl_visc = 0.025;
  sc.dx = dx, sc.radius_ratio = 4, sc.kernel = RHOD_KERNEL_WENDLAND_C2;
  sc.rho0 = 1000, sc.c0 = 10, sc.mu = 0;
  sc.riemann = sc.reconstruction = sc.shifting = sc.acoustic_damper = sc.free_surface = 1;
  sc.shift_a = 0.5, sc.shift_b = 0.05, sc.shift_eps = 5e-4, sc.alpha_ad = 1;
  sc.fs_lambda_low = 0.2, sc.fs_lambda_high = 0.75;
  sc.shepard_threshold = 0.85, sc.theta_threshold = 0.95;
  sc.has_domain = 1, sc.domain_max[0] = L, sc.domain_max[1] = L;
  sc.periodic[0] = sc.periodic[1] = 1;
  rhod_fluid_block fb;
  memset(&fb, 0, sizeof fb);
  fb.shape.kind = RHOD_SHAPE_RECT;
  fb.shape.max[0] = L, fb.shape.max[1] = L;
  sc.fluid = &fb, sc.n_fluid = 1;
  sc.path = "bench";
  rhod_sim s;
  char err[512];
  if (rhod_sim_init(&s, &sc, err, sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench_step: %s\n", err);
    return 1;
  }
  /* perturb: a Taylor-Green velocity field and 10 % dx jitter */
  rhod_particles *p = &s.p;
  rhod_to_host(p->x, p->n * sizeof(real));
  rhod_to_host(p->y, p->n * sizeof(real));
  unsigned long r = 12345;
  for (size_t i = 0; i < p->n; i++) {
    r = r * 6364136223846793005ul + 1442695040888963407ul;
    p->x[i] += (real)(0.1 * dx * ((double)(r >> 11) / 9007199254740992.0 - 0.5));
    r = r * 6364136223846793005ul + 1442695040888963407ul;
    p->y[i] += (real)(0.1 * dx * ((double)(r >> 11) / 9007199254740992.0 - 0.5));
    p->ux[i] = (real)(sin(2 * M_PI * p->x[i]) * cos(2 * M_PI * p->y[i]));
    p->uy[i] = (real)(-cos(2 * M_PI * p->x[i]) * sin(2 * M_PI * p->y[i]));
  }
  rhod_to_device(p->x, p->n * sizeof(real));
  rhod_to_device(p->y, p->n * sizeof(real));
  rhod_to_device(p->ux, p->n * sizeof(real));
  rhod_to_device(p->uy, p->n * sizeof(real));
  rhod_sim_prepare(&s, 1);
  /* one warm-up step */
  if (rhod_sim_step(&s, s.dt, err, sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench_step: %s\n", err);
    return 1;
  }
  double t0 = now();
  for (int k = 0; k < steps; k++) {
    rhod_sim_prepare(&s, 1);
    if (rhod_sim_step(&s, s.dt, err, sizeof err) != RHOD_OK) {
      fprintf(stderr, "bench_step: %s\n", err);
      return 1;
    }
  }
  const double wall = now() - t0;
  size_t bytes = 0;
  for (int f = 0; f < p->nfields; f++)
    bytes += p->fields[f].elem;
  char where[256];
  rhod_where(where, sizeof where);
  printf("N = %zu (ghosts %zu), %d steps, %s precision, %s\n", p->n, p->ng, steps, RHOD_REAL_NAME,
         where);
  printf("us per particle-step: %.3f   particle-steps per second: %.4g   bytes per particle: "
         "%zu\n",
         1e6 * wall / ((double)p->n * steps), (double)p->n * steps / wall, bytes);
  rhod_sim_free(&s);
  return 0;
}
