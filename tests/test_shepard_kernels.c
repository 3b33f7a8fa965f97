/* The Shepard gather at points (kernels/shepard.c, paper 000 Eq. 8) over a cell build:
 * a linear field on a lattice comes back to rounding in the bulk at the lattice's points
 * of symmetry (nodes, cell centres, edge midpoints: the first moment of the weights
 * vanishes there), and at random points, near and beyond a block's edge and across a jump
 * of particle size (each particle with its own radius), the gather equals the brute-force
 * sum over every particle. */
#include "cunit_main.h"
#include "rhod/device.h"
#include "rhod/kernel.h"
#include "rhod/shepard.h"
#include "rhod/status.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifdef RHOD_SINGLE
#define TOL 2e-5
#else
#define TOL 1e-12
#endif

#define DXF 0.01  /* the fine block's spacing */
#define RATIO 2.0 /* R = 2 dx */
#define NMAX 4000
#define NPT 400

typedef struct {
  long n;
  real *x, *y, *dx, *V, *f;
  rhod_cells c;
} cloud;

/* The field: linear, with an offset that keeps it away from 0. */
static double field(double x, double y) { return 3.0 + 2.0 * x - 5.0 * y; }

static void add(cloud *s, double x, double y, double d) {
  CU_ASSERT_FATAL(s->n < NMAX);
  const long k = s->n++;
  s->x[k] = (real)x, s->y[k] = (real)y, s->dx[k] = (real)d;
  s->V[k] = (real)(d * d);
  s->f[k] = (real)field(x, y);
}

/* A fine lattice (DXF) on [0, 0.3] x [0, 0.3]; with `coarse`, a lattice of 2 DXF on
 * [0.3, 0.5] x [0, 0.3] beside it. Cells made for the fine radius and built. */
static void make(cloud *s, int coarse) {
  memset(s, 0, sizeof *s);
  s->x = rhod_dev_calloc(NMAX, sizeof(real));
  s->y = rhod_dev_calloc(NMAX, sizeof(real));
  s->dx = rhod_dev_calloc(NMAX, sizeof(real));
  s->V = rhod_dev_calloc(NMAX, sizeof(real));
  s->f = rhod_dev_calloc(NMAX, sizeof(real));
  for (int j = 0; j < 30; j++)
    for (int i = 0; i < 30; i++)
      add(s, (i + 0.5) * DXF, (j + 0.5) * DXF, DXF);
  for (int j = 0; coarse && j < 15; j++)
    for (int i = 0; i < 10; i++)
      add(s, 0.3 + (i + 0.5) * 2 * DXF, (j + 0.5) * 2 * DXF, 2 * DXF);
  const size_t b = NMAX * sizeof(real);
  rhod_to_device(s->x, b), rhod_to_device(s->y, b), rhod_to_device(s->dx, b);
  rhod_to_device(s->V, b), rhod_to_device(s->f, b);
  const double lo[2] = {-0.1, -0.1}, hi[2] = {0.6, 0.4};
  CU_ASSERT_EQUAL_FATAL(rhod_cells_init(&s->c, lo, hi, RATIO * DXF, RHOD_CELL_REACH, NMAX),
                        RHOD_OK);
  rhod_cells_build(&s->c, s->x, s->y, (size_t)s->n);
}

static void unmake(cloud *s) {
  rhod_cells_free(&s->c);
  const size_t b = NMAX * sizeof(real);
  rhod_dev_free(s->x, b), rhod_dev_free(s->y, b), rhod_dev_free(s->dx, b);
  rhod_dev_free(s->V, b), rhod_dev_free(s->f, b);
}

/* The gather at np points (host arrays), results on the host. */
static void gather(cloud *s, int kern, int np, real *px, real *py, real *fp, real *gm) {
  const size_t b = (size_t)np * sizeof(real);
  rhod_dev_map(px, b), rhod_dev_map(py, b), rhod_dev_map(fp, b), rhod_dev_map(gm, b);
  rhod_shepard(&s->c, kern, (real)RATIO, s->x, s->y, s->dx, s->V, s->f, np, px, py, fp, gm);
  rhod_to_host(fp, b), rhod_to_host(gm, b);
  rhod_dev_unmap(px, b), rhod_dev_unmap(py, b), rhod_dev_unmap(fp, b), rhod_dev_unmap(gm, b);
}

/* Brute force over every particle, in index order, in long double. */
static void brute(const cloud *s, int kern, double px, double py, long double *f, long double *g) {
  long double num = 0, den = 0;
  for (long j = 0; j < s->n; j++) {
    const double rx = s->x[j] - px, ry = s->y[j] - py;
    const long double w =
        (long double)rhod_W(kern, (real)sqrt(rx * rx + ry * ry), (real)(RATIO * s->dx[j])) *
        s->V[j];
    num += w * s->f[j], den += w;
  }
  *f = den > 0 ? num / den : 0, *g = den;
}

static void test_linear_in_bulk(void) {
  cloud s;
  make(&s, 0);
  /* nodes of the lattice, centres of its cells, midpoints of its edges, all at least R
   * from the block's edges */
  static real px[NPT], py[NPT], fp[NPT], gm[NPT];
  int np = 0;
  for (int j = 4; j < 26; j += 3)
    for (int i = 4; i < 26; i += 3)
      for (int t = 0; t < 4; t++) {
        const double ox = t & 1 ? 0.5 : 0, oy = t & 2 ? 0.5 : 0;
        px[np] = (real)((i + 0.5 + ox) * DXF), py[np] = (real)((j + 0.5 + oy) * DXF);
        np++;
      }
  const int kerns[3] = {RHOD_KERNEL_WENDLAND_C2, RHOD_KERNEL_WENDLAND_C4, RHOD_KERNEL_QUINTIC};
  for (int q = 0; q < 3; q++) {
    gather(&s, kerns[q], np, px, py, fp, gm);
    double worst = 0, gmin = 1e30, gmax = 0;
    for (int k = 0; k < np; k++) {
      const double want = field(px[k], py[k]);
      worst = fmax(worst, fabs(fp[k] - want) / fabs(want));
      gmin = fmin(gmin, gm[k]), gmax = fmax(gmax, gm[k]);
    }
    printf("\n  kernel %d: %d points, largest relative error %.2e, Gamma in [%.6f, %.6f]", kerns[q],
           np, worst, gmin, gmax);
    CU_ASSERT(worst < 10 * TOL);
    /* a full support: Gamma near 1 (the lattice sum of W dx^2) */
    CU_ASSERT(gmin > 0.95 && gmax < 1.05);
  }
  unmake(&s);
}

static uint64_t rs = 0x5eed;
static double urand(void) {
  rs = rs * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(rs >> 11) / 9007199254740992.0;
}

static void test_against_brute_force(void) {
  cloud s;
  make(&s, 1);
  static real px[NPT], py[NPT], fp[NPT], gm[NPT];
  int np = 0;
  /* anywhere around the blocks, out to 2 R_max beyond them */
  for (; np < 200; np++)
    px[np] = (real)(-0.08 + 0.66 * urand()), py[np] = (real)(-0.08 + 0.46 * urand());
  /* within a radius of the edges: the fine block's left and top, the coarse block's right,
   * the size jump at x = 0.3 */
  for (; np < 260; np++)
    px[np] = (real)(-0.02 + 0.04 * urand()), py[np] = (real)(0.3 * urand());
  for (; np < 320; np++)
    px[np] = (real)(0.3 * urand()), py[np] = (real)(0.28 + 0.04 * urand());
  for (; np < 360; np++)
    px[np] = (real)(0.28 + 0.04 * urand()), py[np] = (real)(0.3 * urand());
  for (; np < 390; np++)
    px[np] = (real)(0.46 + 0.08 * urand()), py[np] = (real)(0.3 * urand());
  /* far from every particle */
  px[np] = (real)5, py[np] = (real)-3, np++;
  px[np] = (real)0.55, py[np] = (real)0.35, np++;
  const int kerns[2] = {RHOD_KERNEL_WENDLAND_C2, RHOD_KERNEL_QUINTIC};
  for (int q = 0; q < 2; q++) {
    gather(&s, kerns[q], np, px, py, fp, gm);
    double worst = 0, worstg = 0;
    int partial = 0, dry = 0;
    for (int k = 0; k < np; k++) {
      long double f, g;
      brute(&s, kerns[q], px[k], py[k], &f, &g);
      partial += g > 0.05 && g < 0.9;
      dry += g == 0;
      if (g == 0) {
        CU_ASSERT_EQUAL(gm[k], 0);
        CU_ASSERT_EQUAL(fp[k], 0);
        continue;
      }
      worstg = fmax(worstg, (double)(fabsl(gm[k] - g) / g));
      /* against the scale of the field (it is not near 0 here) */
      worst = fmax(worst, (double)(fabsl(fp[k] - f) / fabsl(f)));
    }
    printf("\n  kernel %d: %d points (%d with a partial support, %d dry), largest relative "
           "difference %.2e (Gamma %.2e)",
           kerns[q], np, partial, dry, worst, worstg);
    CU_ASSERT(worst < TOL);
    CU_ASSERT(worstg < TOL);
    CU_ASSERT(partial > 50);
    CU_ASSERT(dry >= 2);
  }
  unmake(&s);
}

/* No particle built: every point dry. */
static void test_empty(void) {
  cloud s;
  make(&s, 0);
  rhod_cells_build(&s.c, s.x, s.y, 0);
  real px[2] = {0.1, 0.2}, py[2] = {0.1, 0.2}, fp[2] = {7, 7}, gm[2] = {7, 7};
  gather(&s, RHOD_KERNEL_WENDLAND_C2, 2, px, py, fp, gm);
  CU_ASSERT(fp[0] == 0 && fp[1] == 0 && gm[0] == 0 && gm[1] == 0);
  unmake(&s);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"a linear field in the bulk, to rounding", test_linear_in_bulk},
      {"random points, edges, a size jump: the brute-force sum", test_against_brute_force},
      {"no particles: every point dry", test_empty},
  };
  return RHOD_RUN_TESTS("Shepard gather", cases);
}
