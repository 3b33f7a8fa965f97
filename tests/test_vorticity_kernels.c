/* The vorticity output (kernels/vorticity.c, the renormalised gradient of paper 002
 * Eq. 14): exact for a linear velocity field on a jittered cloud with a jump of particle
 * size, wherever the support is full; exact next to a no-slip wall for the Couette profile
 * (the no-slip ghosts continue it; the free-slip ones do not); second order for the
 * Taylor-Green field. Runs set up from scene text; the velocities set by hand. */
#include "cunit_main.h"
#include "rhod/device.h"
#include "test_run_util.h"

#include <math.h>
#include <string.h>

#ifdef RHOD_SINGLE
#define TOL 2e-4
#else
#define TOL 1e-9
#endif

/* A 0.3 m box of jittered lattice (dx 0.01, and 0.005 in its middle third), walls of the
 * given slip all round, vorticity among the output fields. */
static int box(run *r, const char *tag, const char *slip) {
  char yaml[1024];
  snprintf(yaml, sizeof yaml,
           "time: {end: 1, output_every: 1}\n"
           "particles: {dx: 0.01, jitter: 0.3}\n"
           "physics: {c0: 10}\n"
           "fluid:\n"
           "  - rect: {min: [0, 0], max: [0.3, 0.3]}\n"
           "walls:\n"
           "  - rect: {min: [0, 0], max: [0.3, 0.3]}\n"
           "    slip: \"%s\"\n"
           "refinement:\n"
           "  levels: 2\n"
           "  dynamic: false\n"
           "  regions: [{rect: {min: [0.1, 0.1], max: [0.2, 0.2]}, level: 1}]\n"
           "output: {fields: [vort]}\n",
           slip);
  return run_open_in(r, "test_vorticity", tag, yaml);
}

/* u = (a x + b y + c, d x + e y + f) on every fluid particle; the output's vorticity. */
static void set_linear(run *r, const double k[6], rhod_snapshot_view *v) {
  rhod_particles *p = &r->sim->p;
  rhod_to_host(p->x, p->n * sizeof(real));
  rhod_to_host(p->y, p->n * sizeof(real));
  for (size_t i = 0; i < p->n; i++) {
    p->ux[i] = (real)(k[0] * p->x[i] + k[1] * p->y[i] + k[2]);
    p->uy[i] = (real)(k[3] * p->x[i] + k[4] * p->y[i] + k[5]);
  }
  rhod_to_device(p->ux, p->n * sizeof(real));
  rhod_to_device(p->uy, p->n * sizeof(real));
  r->sim->neighbours_fresh = 0; /* the ghosts take the new velocities */
  CU_ASSERT_EQUAL_FATAL(rhod_sim_fetch(r->sim, v), RHOD_OK);
  CU_ASSERT_PTR_NOT_NULL_FATAL(v->vort);
}

/* A linear field: d - b for every particle whose support (R = 4 dx <= 0.04 m) stays
 * 0.05 m clear of the walls, across the size jump; the snapshot's extra dataset is it. */
static void test_linear(void) {
  run r;
  CU_ASSERT_FATAL(box(&r, "linear", "free"));
  const double k[6] = {0.3, -1.7, 0.2, 2.9, -0.3, -0.4};
  rhod_snapshot_view v;
  set_linear(&r, k, &v);
  double worst = 0;
  long checked = 0, fine = 0;
  for (size_t i = 0; i < v.n; i++) {
    const double x = v.x[i], y = v.y[i];
    if (fmin(fmin(x, 0.3 - x), fmin(y, 0.3 - y)) < 0.05)
      continue;
    worst = fmax(worst, fabs(v.vort[i] - (k[3] - k[1])));
    checked++, fine += v.size[i] < (real)0.0075;
  }
  int extra = 0;
  for (unsigned e = 0; e < v.nextra; e++)
    extra |= strcmp(v.extra[e].name, "Vorticities") == 0 && v.extra[e].data == (void *)v.vort;
  printf("\n  %ld particles (%ld fine): largest |w - (d - b)| %.3e of %g ", checked, fine, worst,
         k[3] - k[1]);
  CU_ASSERT(checked > 300 && fine > 300);
  CU_ASSERT(worst < TOL * 10);
  CU_ASSERT(extra);
  run_close(&r);
}

/* Couette u = g y over the no-slip bottom wall (y = 0): w = -g exactly down to the wall,
 * with the no-slip ghosts; the free-slip ones mirror u = g |y| and miss it there. */
static void test_couette_wall(void) {
  double worst[2] = {0, 0};
  long checked = 0;
  for (int noslip = 1; noslip >= 0; noslip--) {
    run r;
    CU_ASSERT_FATAL(box(&r, noslip ? "couette_no" : "couette_free", noslip ? "no" : "free"));
    const double g = 2.5, k[6] = {0, g, 0, 0, 0, 0};
    rhod_snapshot_view v;
    set_linear(&r, k, &v);
    for (size_t i = 0; i < v.n; i++) {
      const double x = v.x[i], y = v.y[i];
      if (y > 0.05 || x < 0.05 || x > 0.25)
        continue;
      worst[noslip] = fmax(worst[noslip], fabs(v.vort[i] + g));
      checked += noslip;
    }
    run_close(&r);
  }
  printf("\n  %ld particles within 0.05 m of the wall: largest |w + g| %.3e no-slip, %.3e "
         "free-slip ",
         checked, worst[1], worst[0]);
  CU_ASSERT(checked >= 100);
  CU_ASSERT(worst[1] < TOL * 10);
  CU_ASSERT(worst[0] > 0.5);
}

/* Taylor-Green, u = U sin kx cos ky, v = -U cos kx sin ky: w = 2 U k sin kx sin ky, in a
 * periodic box (the scene's initial flow), at L/dx = 25 and 50: the largest error falls
 * by about 4 (second order on a lattice; the kernel's smoothing, R = 4 dx). */
static void test_taylor_green(void) {
  double err[2];
  for (int l = 0; l < 2; l++) {
    char yaml[1024];
    snprintf(yaml, sizeof yaml,
             "time: {end: 1, output_every: 1}\n"
             "particles: {dx: %g}\n"
             "physics: {c0: 10}\n"
             "domain: {min: [0, 0], max: [1, 1], periodic: [true, true]}\n"
             "fluid:\n"
             "  - rect: {min: [0, 0], max: [1, 1]}\n"
             "    pressure: uniform\n"
             "    initial: {taylor_green: {U: 1, L: 1}}\n"
             "output: {fields: [vort]}\n",
             l ? 0.02 : 0.04);
    run r;
    CU_ASSERT_FATAL(run_open_in(&r, "test_vorticity", "tg", yaml));
    rhod_snapshot_view v;
    CU_ASSERT_EQUAL_FATAL(rhod_sim_fetch(r.sim, &v), RHOD_OK);
    CU_ASSERT_PTR_NOT_NULL_FATAL(v.vort);
    const double k = 2 * 3.14159265358979323846, wmax = 2 * k;
    err[l] = 0;
    for (size_t i = 0; i < v.n; i++)
      err[l] = fmax(err[l], fabs(v.vort[i] - wmax * sin(k * v.x[i]) * sin(k * v.y[i])));
    err[l] /= wmax;
    run_close(&r);
  }
  printf("\n  largest error over 2 U k: %.3e at L/dx = 25, %.3e at 50 ", err[0], err[1]);
  CU_ASSERT(err[0] < 0.1);
  CU_ASSERT(err[1] < err[0] / 3);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"a linear field: exact across a size jump", test_linear},
      {"Couette over a no-slip wall: exact down to the wall", test_couette_wall},
      {"Taylor-Green: second order", test_taylor_green},
  };
  return RHOD_RUN_TESTS("vorticity", cases);
}
