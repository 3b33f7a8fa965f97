/* Mixed-size neighbour search (paper 002 Sec. IV D; issue: "measure whatever you choose
 * against a single grid"). Ours (include/rhod/cells.h): one grid with cells of side
 * R_min / reach, R_min the kernel radius of the finest size the scene allows; a particle
 * of radius R_i scans reach * ceil(R_i / R_min) cells on each side. Against it: the
 * plain single grid made for the coarsest radius (cells of side R_max / reach, every
 * particle scans reach cells on each side), which every particle can use as it is but
 * which makes a fine particle look through (R_max / R_i)^2 times the area it needs.
 * Both on the particles a scene has after its t = 0 refinement (the mixed layout a run
 * starts from), timed on the two gathers that dominate a stage (pass A and pass C),
 * with the candidates visited and the real pairs (r < R_i) counted by the same loop.
 *
 * usage: bench_mixed SCENE [repeats=20] [key=value ...]   (key=value as --set) */
#include "bench_common.h"
#include "rhod/kernel.h"
#include "rhod/rhodsph/sph.h"

/* Times pass A and pass C (reps calls each); returns us per particle per call. */
static void time_passes(rhod_sim *s, int reps, double *ua, double *uc) {
  rhod_particles *p = &s->p;
  const double n = (double)p->n;
  double t0 = bench_now();
  for (int r = 0; r < reps; r++)
    rhod_sph_pass_a(&rhod_rs(s)->sph, p, &s->cells);
  *ua = 1e6 * (bench_now() - t0) / (reps * n);
  t0 = bench_now();
  for (int r = 0; r < reps; r++)
    rhod_sph_pass_c(&rhod_rs(s)->sph, p, &s->cells);
  *uc = 1e6 * (bench_now() - t0) / (reps * n);
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_mixed SCENE [repeats=20] [key=value ...]\n");
    return 2;
  }
  const int reps = argc > 2 ? atoi(argv[2]) : 20;
  char err[1024] = "";
  rhod_scene *sc = NULL;
  if (rhod_scene_load(argv[1], (const char *const *)(argv + 3), argc > 3 ? argc - 3 : 0, &sc, err,
                      sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench_mixed: %s\n", err);
    return 1;
  }
  rhod_sim s;
  if (rhod_sim_init(&s, sc, err, sizeof err) != RHOD_OK) {
    fprintf(stderr, "bench_mixed: %s\n", err);
    return 1;
  }
  rhod_particles *p = &s.p;
  rhod_sph_rhs(&rhod_rs(&s)->sph, p, &s.cells, (real)s.dt); /* every field valid */
  /* the sizes present */
  rhod_particles_to_host(p);
  real dmin = p->dx[0], dmax = p->dx[0];
  long per_level[RHOD_MAX_LEVELS] = {0};
  for (size_t i = 0; i < p->n; i++) {
    dmin = p->dx[i] < dmin ? p->dx[i] : dmin;
    dmax = p->dx[i] > dmax ? p->dx[i] : dmax;
    const int l =
        (int)lround(log((double)sc->dx / p->dx[i]) / log(rhod_pattern_ratio(sc->rs->pattern)));
    if (l >= 0 && l < RHOD_MAX_LEVELS)
      per_level[l]++;
  }
  char where[256];
  rhod_where(where, sizeof where);
  printf("%s: %zu particles (ghosts %zu), sizes %g .. %g, %s precision, %s\n", argv[1], p->n, p->ng,
         (double)dmin, (double)dmax, RHOD_REAL_NAME, where);
  printf("particles per level:");
  for (int l = 0; l < sc->rs->levels; l++)
    printf(" %ld", per_level[l]);
  printf("\n%-34s %11s %11s %10s %10s %10s\n", "grid", "visited/p", "pairs/p", "pass A us",
         "pass C us", "A+C us");
  const double n = (double)p->n;
  /* the reference: pass A's Gamma with our grid, for the check below */
  real *gam0 = malloc(p->n * sizeof(real));
  rhod_to_host(rhod_rs(&s)->sph.gam, p->n * sizeof(real));
  memcpy(gam0, rhod_rs(&s)->sph.gam, p->n * sizeof(real));
  const double R_min = sc->radius_ratio * s.dx_min, R_max = sc->radius_ratio * sc->dx;
  for (int g = 0; g < 2; g++) {
    const double R0 = g == 0 ? R_min : R_max;
    rhod_cells_free(&s.cells);
    const double glo[2] = {s.lo[0] - 2 * s.margin, s.lo[1] - 2 * s.margin};
    const double ghi[2] = {s.hi[0] + 2 * s.margin, s.hi[1] + 2 * s.margin};
    if (rhod_cells_init(&s.cells, glo, ghi, R0, RHOD_CELL_REACH, p->cap) != RHOD_OK) {
      fprintf(stderr, "bench_mixed: out of memory\n");
      return 1;
    }
    rhod_cells_build(&s.cells, p->x, p->y, p->n + p->ng);
    double visited, pairs, ua, uc;
    bench_count_pairs(&s, &visited, &pairs);
    rhod_sph_pass_a(&rhod_rs(&s)->sph, p, &s.cells); /* warm-up */
    time_passes(&s, reps, &ua, &uc);
    /* the same neighbours, in another order: Gamma equal to round-off */
    rhod_sph_pass_a(&rhod_rs(&s)->sph, p, &s.cells);
    rhod_to_host(rhod_rs(&s)->sph.gam, p->n * sizeof(real));
    double dg = 0;
    for (size_t i = 0; i < p->n; i++)
      dg = fmax(dg, fabs((double)(rhod_rs(&s)->sph.gam[i] - gam0[i])));
    char name[64];
    snprintf(name, sizeof name, "%s (cell %.3g m)",
             g == 0 ? "ours: R_min grid" : "single R_max grid", R0 / RHOD_CELL_REACH);
    printf("%-34s %11.1f %11.1f %10.4f %10.4f %10.4f   max |dGamma| %.1e\n", name, visited / n,
           pairs / n, ua, uc, ua + uc, dg);
  }
  free(gam0);
  rhod_sim_free(&s);
  rhod_scene_free(sc);
  return 0;
}
