/* Whole RK4 step of single-resolution RHOD-SPH, with the step size as a run takes it
 * (rhod_sim_dt: the damper probe included): microseconds per particle-step and bytes
 * per particle. usage: bench_step [N=1e4] [steps=20] [box|patch] [switch ...] (bench_common.h) */
#include "bench_common.h"

int main(int argc, char **argv) {
  const double N = argc > 1 ? atof(argv[1]) : 1e4;
  const int steps = argc > 2 ? atoi(argv[2]) : 20;
  const int patch = argc > 3 && !strcmp(argv[3], "patch");
  bench_scene b;
  rhod_sim s;
  char err[512];
  if (bench_setup(&b, &s, N, patch, argc, argv, 4) != RHOD_OK)
    return 1;
  /* one warm-up step */
  if (rhod_sim_step(&s, s.dt, err, sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench_step: %s\n", err);
    return 1;
  }
  const double t0 = bench_now();
  for (int k = 0; k < steps; k++) {
    rhod_sim_prepare(&s, 1);
    if (rhod_sim_dt(&s) != RHOD_OK) {
      fprintf(stderr, "bench_step: out of memory for ghost particles\n");
      return 1;
    }
    if (rhod_sim_step(&s, s.dt, err, sizeof err) != RHOD_OK) {
      fprintf(stderr, "bench_step: %s\n", err);
      return 1;
    }
  }
  const double wall = bench_now() - t0;
  const rhod_particles *p = &s.p;
  char where[256];
  rhod_where(where, sizeof where);
  printf("N = %zu (ghosts %zu), %s, %d steps, %s precision, %s\n", p->n, p->ng,
         patch ? "free patch" : "periodic box", steps, RHOD_REAL_NAME, where);
  printf("us per particle-step: %.3f   particle-steps per second: %.4g   bytes per particle: "
         "%zu\n",
         1e6 * wall / ((double)p->n * steps), (double)p->n * steps / wall, bench_bytes(p));
  rhod_sim_free(&s);
  return 0;
}
