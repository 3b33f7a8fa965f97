/* Each pass of one RK stage timed alone, repeated: microseconds per particle per call
 * and real neighbour pairs per second for the gathers.
 * usage: bench_passes [N=1e5] [repeats=10] [box|patch] [switches as bench_step] */
#include "bench_common.h"
#include "rhod/kernel.h"

int main(int argc, char **argv) {
  const double N = argc > 1 ? atof(argv[1]) : 1e5;
  const int reps = argc > 2 ? atoi(argv[2]) : 10;
  const int patch = argc > 3 && !strcmp(argv[3], "patch");
  bench_scene b;
  rhod_sim s;
  if (bench_setup(&b, &s, N, patch, argc, argv, 4) != RHOD_OK)
    return 1;
  rhod_particles *p = &s.p;
  rhod_sph *h = &rhod_rs(&s)->sph;
  const real dt = (real)s.dt;
  rhod_sph_rhs(h, p, &s.cells, dt); /* warm-up, and every field valid */
  double visited, pairs;
  bench_count_pairs(&s, &visited, &pairs);
  const double n = (double)p->n;
  char where[256];
  rhod_where(where, sizeof where);
  printf("N = %zu (ghosts %zu), %s, %s precision, %s; %.1f neighbours per particle (%.1f "
         "candidates visited)\n",
         p->n, p->ng, patch ? "free patch" : "periodic box", RHOD_REAL_NAME, where, pairs / n,
         visited / n);
  printf("%-22s %12s %16s\n", "pass", "us/particle", "pairs/s");
  double total = 0;
  for (int k = 0; k < 11; k++) {
    if (k == 10)
      rhod_rk_begin(&s.rk, p); /* y0 = y, so the dt = 0 stages below leave y alone */
    const double t0 = bench_now();
    for (int r = 0; r < reps; r++) {
      switch (k) {
      case 0:
        rhod_sim_prepare(&s, 1);
        break; /* sort + ghosts + cells */
      case 1:
        rhod_ghosts_build(&s.bnd, p, (real)s.mirror_ratio, (real)s.margin);
        break;
      case 2:
        rhod_cells_build(&s.cells, p->x, p->y, p->n + p->ng);
        break;
      case 3:
        rhod_sph_fill_state(h, p);
        break;
      case 4:
        rhod_sph_pass_a(h, p, &s.cells);
        break;
      case 5:
        rhod_sph_mirror_gradients(h, p);
        break;
      case 6:
        rhod_sph_pass_free_surface(h, p, &s.cells);
        break;
      case 7:
        rhod_sph_pass_region(h, p, &s.cells);
        break;
      case 8:
        rhod_sph_pass_shift(h, p, dt);
        break;
      case 9:
        rhod_sph_pass_c(h, p, &s.cells);
        break;
      case 10:
        rhod_rk_stage(&s.rk, p, 0, 0);
        break; /* dt = 0: state unchanged */
      }
    }
    const double us = 1e6 * (bench_now() - t0) / (reps * n);
    static const char *names[] = {"sort+ghosts+cells",
                                  "  ghosts",
                                  "  cells",
                                  "fill state (EOS)",
                                  "pass A",
                                  "mirror gradients",
                                  "free-surface scan",
                                  "free-surface region",
                                  "shifting",
                                  "pass C",
                                  "RK4 update"};
    const int gather = k == 4 || k == 6 || k == 7 || k == 9;
    if (gather)
      printf("%-22s %12.4f %16.4g\n", names[k], us, pairs / (us * 1e-6 * n));
    else
      printf("%-22s %12.4f %16s\n", names[k], us, "");
    if (k == 0 || k >= 3)
      total += us;
  }
  printf("one stage (sort counted once per stage): %.3f us/particle; a step is 4 stages\n", total);
  rhod_sim_free(&s);
  return 0;
}
