/* A step of either scheme on the same flow, through the scene loader and the driver as a
 * run takes it: a Taylor-Green vortex (U = 1, Re = 100) in a doubly periodic unit box of
 * about N particles, rho = 1, c = 10, the lattice jittered by 10 % of dx.
 *   multiphase: paper 000's scheme (midpoint, two right-hand sides a step), one phase;
 *   drop:       the same with a liquid disc (R = 0.25) in a gas of half its density,
 *               sigma = 1 (the colour pass and the surface force on);
 *   rhodsph:    RHOD-SPH (RK4, four right-hand sides; free surface off, consistent
 *               viscosity, as cases/taylor_green).
 * Prints microseconds per particle-step, particle-steps per second, neighbour pairs (j != i
 * within R_i) times right-hand sides per second,
 * bytes per particle, the step dt and the wall time per simulated second per particle.
 * usage: bench_mp [multiphase|drop|rhodsph] [N=1e4] [steps=20] */
#define _DEFAULT_SOURCE /* mkstemp */
#include "bench_common.h"
#include <unistd.h>

static const char *scene_text(const char *kind, double dx, char *buf, size_t len) {
  const char *common = "time: {end: 10, output_every: 1}\n"
                       "domain: {min: [0, 0], max: [1, 1], periodic: [true, true]}\n"
                       "output: {picture: false}\n";
  if (!strcmp(kind, "rhodsph")) {
    snprintf(buf, len,
             "name: bench\n%sparticles: {dx: %.17g, jitter: 0.1}\n"
             "physics: {rho0: 1, c0: 10, mu: 0.01}\n"
             "scheme: {free_surface: false, viscosity: consistent}\n"
             "fluid:\n  - rect: {min: [0, 0], max: [1, 1]}\n"
             "    initial: {taylor_green: {U: 1, L: 1}}\n",
             common, dx);
  } else {
    const int drop = !strcmp(kind, "drop");
    snprintf(buf, len,
             "name: bench\n%sparticles: {dx: %.17g, jitter: 0.1}\n"
             "scheme: {name: multiphase}\n"
             "phases:\n  - {name: liquid, rho0: 1, c: 10, mu: 0.01}\n%s"
             "%s"
             "fluid:\n%s"
             "  - rect: {min: [0, 0], max: [1, 1]}\n    phase: %s\n"
             "    initial: {taylor_green: {U: 1, L: 1}}\n",
             common, dx, drop ? "  - {name: gas, rho0: 0.5, c: 10, mu: 0.01, gamma: 1}\n" : "",
             drop ? "multiphase: {sigma: 1}\n" : "",
             drop ? "  - circle: {center: [0.5, 0.5], radius: 0.25}\n    phase: liquid\n"
                    "    initial: {taylor_green: {U: 1, L: 1}}\n"
                  : "",
             drop ? "gas" : "liquid");
  }
  return buf;
}

int main(int argc, char **argv) {
  const char *kind = argc > 1 ? argv[1] : "multiphase";
  const double N = argc > 2 ? atof(argv[2]) : 1e4;
  const int steps = argc > 3 ? atoi(argv[3]) : 20;
  if (strcmp(kind, "multiphase") && strcmp(kind, "drop") && strcmp(kind, "rhodsph")) {
    fprintf(stderr, "bench_mp: unknown kind %s (multiphase, drop or rhodsph)\n", kind);
    return 2;
  }
  char text[2048], path[] = "/tmp/bench_mp_XXXXXX", err[1024];
  const int fd = mkstemp(path);
  if (fd < 0) {
    perror("bench_mp");
    return 1;
  }
  scene_text(kind, 1 / sqrt(N), text, sizeof text);
  const ssize_t w = write(fd, text, strlen(text));
  close(fd);
  rhod_scene *sc = NULL;
  int st = w == (ssize_t)strlen(text) ? rhod_scene_load(path, NULL, 0, &sc, err, sizeof err)
                                      : RHOD_ERR_IO;
  unlink(path);
  if (st != RHOD_OK) {
    fprintf(stderr, "bench_mp: %s\n", err);
    return 1;
  }
  rhod_sim s;
  if (rhod_sim_init(&s, sc, err, sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench_mp: %s\n", err);
    return 1;
  }
  /* one warm-up step */
  if (rhod_sim_dt(&s) != RHOD_OK || rhod_sim_step(&s, s.dt, err, sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench_mp: %s\n", err);
    return 1;
  }
  double dt_sum = 0;
  const double t0 = bench_now();
  for (int k = 0; k < steps; k++) {
    rhod_sim_prepare(&s, 1);
    if (rhod_sim_dt(&s) != RHOD_OK || rhod_sim_step(&s, s.dt, err, sizeof err) != RHOD_OK) {
      fprintf(stderr, "bench_mp: %s\n", err);
      return 1;
    }
    dt_sum += s.dt;
  }
  const double wall = bench_now() - t0;
  rhod_sim_prepare(&s, 1);
  double visited, pairs;
  bench_count_pairs(&s, &visited, &pairs);
  const rhod_particles *p = &s.p;
  char where[256];
  rhod_where(where, sizeof where);
  const double ups = 1e6 * wall / ((double)p->n * steps);
  printf("%s: N = %zu (ghosts %zu), %d steps of %d right-hand sides, %s precision, %s\n", kind,
         p->n, p->ng, steps, s.rk.stages, RHOD_REAL_NAME, where);
  printf("us per particle-step: %.3f   particle-steps per second: %.4g   pairs per second: "
         "%.4g (%.1f per particle)   bytes per particle: %zu\n",
         ups, (double)p->n * steps / wall, pairs * steps * s.rk.stages / wall, pairs / p->n,
         bench_bytes(p));
  printf("dt: %.4g s   wall seconds per simulated second per particle: %.4g\n", dt_sum / steps,
         wall / (dt_sum * p->n));
  rhod_sim_free(&s);
  rhod_scene_free(sc);
  return 0;
}
