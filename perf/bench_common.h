/* Shared set-up of the benchmarks: a perturbed lattice of about N particles with a
 * Taylor-Green velocity field, either in a doubly periodic unit box ("box", no free
 * surface) or as a free square patch in empty space ("patch", a free surface all
 * round). Every RHOD-SPH term on. */
#ifndef RHOD_BENCH_COMMON_H
#define RHOD_BENCH_COMMON_H

#include "rhod/rhodsph/scheme.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static inline double bench_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

typedef struct {
  rhod_scene sc;
  rhod_rs_scene rs; /* sc.rs */
  rhod_fluid_block fb;
} bench_scene;

/* Scheme switches from the command line: any of noshift, nodamper, nolimit (the damper
 * without its step limit), nostiff (no stiffness limit), nofs, noriemann, norecon, visc (mu such
 * that Re = 100 for the unit box), visc_consistent (the same with scheme.viscosity: consistent). An
 * unknown word is an error. */
static inline int bench_switches(rhod_scene *sc, int argc, char **argv, int first) {
  for (int k = first; k < argc; k++) {
    if (!strcmp(argv[k], "noshift"))
      sc->rs->shifting = 0;
    else if (!strcmp(argv[k], "nodamper"))
      sc->rs->acoustic_damper = 0;
    else if (!strcmp(argv[k], "nolimit"))
      sc->rs->damper_step_limit = 0;
    else if (!strcmp(argv[k], "nostiff"))
      sc->rs->stiffness_limit = 0;
    else if (!strcmp(argv[k], "nofs"))
      sc->rs->free_surface = 0;
    else if (!strcmp(argv[k], "noriemann"))
      sc->rs->riemann = 0;
    else if (!strcmp(argv[k], "norecon"))
      sc->rs->reconstruction = 0;
    else if (!strcmp(argv[k], "visc"))
      sc->rs->mu = 10;
    else if (!strcmp(argv[k], "visc_consistent"))
      sc->rs->mu = 10, sc->rs->viscosity = RHOD_VISCOSITY_CONSISTENT;
    else
      return -1;
  }
  return 0;
}

static inline int bench_setup(bench_scene *b, rhod_sim *s, double N, int patch, int argc,
                              char **argv, int first) {
  const int side = (int)ceil(sqrt(N));
  const double L = 1.0, dx = L / side;
  rhod_scene *sc = &b->sc;
  memset(b, 0, sizeof *b);
  sc->rs = &b->rs;
  sc->t_end = 1, sc->output_every = 1, sc->rs->cfl = 0.5, sc->rs->cfl_visc = 0.025;
  sc->dx = dx, sc->radius_ratio = 4, sc->kernel = RHOD_KERNEL_WENDLAND_C2;
  sc->rs->levels = 1; /* single resolution (0 made dx_min = 2 dx and cells twice too big) */
  sc->rs->rho0 = 1000, sc->rs->c0 = 10, sc->rs->mu = 0;
  sc->rs->riemann = sc->rs->reconstruction = sc->rs->shifting = sc->rs->acoustic_damper = 1;
  sc->rs->free_surface = 1;
  sc->rs->shift_a = 0.5, sc->rs->shift_b = 0.05, sc->rs->shift_eps = 5e-4, sc->rs->alpha_ad = 1;
  sc->rs->damper_step_limit = 1, sc->rs->stiffness_limit = 1;
  sc->rs->fs_lambda_low = 0.2, sc->rs->fs_lambda_high = 0.75;
  sc->rs->shepard_threshold = 0.85, sc->rs->theta_threshold = 0.95;
  sc->has_domain = 1;
  sc->domain_min[0] = sc->domain_min[1] = patch ? -0.5 : 0;
  sc->domain_max[0] = sc->domain_max[1] = patch ? 1.5 : L;
  sc->periodic[0] = sc->periodic[1] = !patch;
  b->fb.shape.kind = RHOD_SHAPE_RECT;
  b->fb.shape.max[0] = L, b->fb.shape.max[1] = L;
  sc->fluid = &b->fb, sc->n_fluid = 1;
  sc->path = "bench";
  if (bench_switches(sc, argc, argv, first) != 0) {
    fprintf(stderr, "bench: unknown switch (noshift nodamper nolimit nofs noriemann norecon "
                    "visc visc_consistent)\n");
    return RHOD_ERR_USAGE;
  }
  char err[512];
  if (rhod_sim_init(s, sc, err, sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench: %s\n", err);
    return 1;
  }
  rhod_particles *p = &s->p;
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
  return rhod_sim_prepare(s, 1);
}

/* Candidates the gather loop visits and real pairs (j != i, r < R_i) over all
 * particles, with the solver's own neighbour loop. */
static inline void bench_count_pairs(const rhod_sim *s, double *visited, double *pairs) {
  const rhod_particles *p = &s->p;
  const rhod_cells *c = &s->cells;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx;
  const real *x = p->x, *y = p->y, *dx = p->dx;
  const real ratio = (real)s->sc->radius_ratio;
  const long n = (long)p->n;
  long seen = 0, real_pairs = 0;
  RHOD_KERNEL_LOOP_REDUCE2(+, seen, real_pairs)
  for (long i = 0; i < n; i++) {
    const real xi = x[i], yi = y[i], Ri = ratio * dx[i], R2 = Ri * Ri;
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, Ri, j) {
      const real rx = x[j] - xi, ry = y[j] - yi;
      seen++;
      if (j != i && rx * rx + ry * ry < R2)
        real_pairs++;
    }
    RHOD_END_NEIGHBOURS
  }
  *visited = (double)seen, *pairs = (double)real_pairs;
}

static inline size_t bench_bytes(const rhod_particles *p) {
  size_t bytes = 0;
  for (int f = 0; f < p->nfields; f++)
    bytes += p->fields[f].elem;
  return bytes;
}

#endif
