/* The analytic initial flows of the validation cases (src/sim.c rhod_sim_initial_flow):
 * `initial.shear_layer` (paper 000 Eq. 27, cases/kelvin_helmholtz) and
 * `initial.droplet_oscillation` (paper 000 Eqs. 28-29, cases/oscillating_droplet). Each
 * is checked on the particles a scene builds, against properties the formulas must have
 * (far-field velocities, the perturbation's wavelength and decay, divergence-free,
 * symmetric, the mode-2 sense), and through the scene as run loading back the same. */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE

#include "cunit_main.h"
#include "rhod/io.h"
#include "rhod/scene.h"
#include "rhod/sim.h"
#include "test_run_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef RHOD_SINGLE
#define VTOL 1e-6
#else
#define VTOL 1e-12
#endif

static int run_open(run *r, const char *tag, const char *yaml) {
  return run_open_in(r, "test_initial_flows", tag, yaml);
}

/* The scene as run (sc->yaml) loads back to the same flow parameters and the same text. */
static void as_run_same(const rhod_scene *a) {
  const char *tmp = "test_initial_flows_as_run.yaml";
  FILE *f = fopen(tmp, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fputs(a->yaml, f);
  fclose(f);
  char err[1024] = "";
  rhod_scene *b = NULL;
  const int st = rhod_scene_load(tmp, NULL, 0, &b, err, sizeof err);
  remove(tmp);
  CU_ASSERT_EQUAL_FATAL(st, RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(a->n_fluid, b->n_fluid);
  for (unsigned i = 0; i < a->n_fluid; i++) {
    const rhod_fluid_block *p = &a->fluid[i], *q = &b->fluid[i];
    CU_ASSERT_EQUAL(p->flow, q->flow);
    CU_ASSERT(p->flow_U == q->flow_U && p->flow_L == q->flow_L && p->flow_UI == q->flow_UI);
    CU_ASSERT(p->flow_y[0] == q->flow_y[0] && p->flow_y[1] == q->flow_y[1]);
    CU_ASSERT(p->flow_width == q->flow_width && p->flow_spread == q->flow_spread);
    CU_ASSERT(p->flow_R == q->flow_R);
    CU_ASSERT(p->flow_center[0] == q->flow_center[0] && p->flow_center[1] == q->flow_center[1]);
  }
  CU_ASSERT_STRING_EQUAL(a->yaml, b->yaml);
  rhod_scene_free(b);
}

#define KH_SCENE                                                                                   \
  "time: {end: 1, output_every: 1}\n"                                                              \
  "particles: {dx: 0.0625, kernel: wendland_c4, radius_ratio: 4.8}\n"                              \
  "scheme: {name: multiphase}\n"                                                                   \
  "phases:\n"                                                                                      \
  "  - {name: outer, rho0: 1, c: 20, mu: 2.0e-5}\n"                                                \
  "  - {name: inner, rho0: 1, c: 20, mu: 2.0e-5}\n"                                                \
  "domain: {min: [0, 0], max: [1, 2], periodic: [true, true]}\n"                                   \
  "fluid:\n"                                                                                       \
  "  - rect: {min: [0, 0.5], max: [1, 1.5]}\n"                                                     \
  "    phase: inner\n"                                                                             \
  "    initial: {shear_layer: {U: 1, UI: 0.01, y: [0.5, 1.5], width: 0.05, spread: 0.2, L: 1}}\n"  \
  "  - rect: {min: [0, 0], max: [1, 2]}\n"                                                         \
  "    phase: outer\n"                                                                             \
  "    initial: {shear_layer: {U: 1, UI: 0.01, y: [0.5, 1.5], width: 0.05, spread: 0.2, L: 1}}\n"

/* Paper 000 Eq. 27 on the particles: u = -1 below y1 and above y2 (far from them), +1
 * between, 0 on each interface; v = U_I sin(2 pi x) at the interfaces, falling as
 * exp(-(y - y_i)^2/0.04); the particles' own values against the formula. */
static void test_shear_layer(void) {
  run r;
  CU_ASSERT_FATAL(run_open(&r, "kh", KH_SCENE));
  rhod_snapshot_view w;
  rhod_sim_fetch(r.sim, &w);
  CU_ASSERT_EQUAL_FATAL(w.n, 16 * 32);
  double far = 0, mid = 0, worst = 0;
  int nfar = 0, nmid = 0, inner = 0;
  for (size_t i = 0; i < w.n; i++) {
    const double x = w.x[i], y = w.y[i];
    const double u = 1 * (tanh((y - 0.5) / 0.05) - tanh((y - 1.5) / 0.05) - 1);
    const double v = 0.01 * sin(2 * M_PI * x) *
                     (exp(-(y - 0.5) * (y - 0.5) / 0.04) + exp(-(y - 1.5) * (y - 1.5) / 0.04));
    worst = fmax(worst, fmax(fabs(w.ux[i] - u), fabs(w.uy[i] - v)));
    if (y < 0.25 || y > 1.75)
      far += w.ux[i], nfar++;
    if (y > 0.75 && y < 1.25)
      mid += w.ux[i], nmid++;
    inner += (y > 0.5 && y < 1.5) == (w.phase[i] == 1);
  }
  CU_ASSERT(worst < VTOL);
  CU_ASSERT(nfar > 0 && nmid > 0);
  CU_ASSERT_DOUBLE_EQUAL(far / nfar, -1, 2e-4); /* du = 2 U0 (Sec. 4.3) */
  CU_ASSERT_DOUBLE_EQUAL(mid / nmid, 1, 2e-4);
  CU_ASSERT_EQUAL(inner, (int)w.n); /* the phases split at y1, y2 */
  /* the formula itself, at points: on the interface u = 0 and v = U_I sin(2 pi x) (plus the
   * other Gaussian's e^-25); one spread away v falls by e^-1; wavelength L = 1 */
  double u, v, P;
  rhod_sim_initial_flow(r.sim, 1, 0.25, 0.5, 1, &u, &v, &P);
  CU_ASSERT_DOUBLE_EQUAL(u, 0, 1e-12);
  CU_ASSERT_DOUBLE_EQUAL(v, 0.01 * (1 + exp(-25)), 1e-15);
  CU_ASSERT_DOUBLE_EQUAL(P, 0, 0);
  rhod_sim_initial_flow(r.sim, 1, 0.75, 1.5 + 0.2, 1, &u, &v, &P);
  CU_ASSERT_DOUBLE_EQUAL(v, -0.01 * exp(-1), 1e-9);
  rhod_sim_initial_flow(r.sim, 1, 1.25, 0.5, 1, &u, &v, &P);
  CU_ASSERT_DOUBLE_EQUAL(v, 0.01 * (1 + exp(-25)), 1e-15);
  as_run_same(r.sc);
  run_close(&r);
}

#define DROP_SCENE                                                                                 \
  "time: {end: 1, output_every: 1}\n"                                                              \
  "particles: {dx: 1.0e-5, kernel: quintic, radius_ratio: 3}\n"                                    \
  "scheme: {name: multiphase}\n"                                                                   \
  "phases:\n"                                                                                      \
  "  - {name: liquid, rho0: 1000, c: 15, mu: 2.93e-3}\n"                                           \
  "  - {name: gas, rho0: 9.95, c: 150, gamma: 1, mu: 3.4e-5}\n"                                    \
  "multiphase: {sigma: 0.07}\n"                                                                    \
  "domain: {min: [0, 0], max: [3.0e-4, 3.0e-4], periodic: [true, true]}\n"                         \
  "fluid:\n"                                                                                       \
  "  - circle: {center: [1.5e-4, 1.5e-4], radius: 7.0e-5}\n"                                       \
  "    phase: liquid\n"                                                                            \
  "    initial: {droplet_oscillation: {U: 2.5, R: 7.0e-5}}\n"                                      \
  "  - rect: {min: [0, 0], max: [3.0e-4, 3.0e-4]}\n"                                               \
  "    phase: gas\n"

/* Paper 000 Eqs. 28-29: the gas at rest, the droplet's particles on the formula; the field
 * divergence free (central differences of the formula, against its gradient's size),
 * v(x, y) = -u(y, x), 0 at the centre, stretching along x (mode 2) and squeezing along y. */
static void test_droplet_oscillation(void) {
  run r;
  CU_ASSERT_FATAL(run_open(&r, "drop", DROP_SCENE));
  const double U = 2.5, R = 7.0e-5, c = 1.5e-4;
  rhod_snapshot_view w;
  rhod_sim_fetch(r.sim, &w);
  double worst = 0, gas = 0;
  int nliq = 0;
  for (size_t i = 0; i < w.n; i++) {
    const double X = w.x[i] - c, Y = w.y[i] - c, rr = hypot(X, Y);
    if (w.phase[i] == 1) {
      gas = fmax(gas, hypot(w.ux[i], w.uy[i]));
      continue;
    }
    nliq++;
    CU_ASSERT(rr <= R);
    const double e = exp(-rr / R);
    const double u = U * X / R * (1 - Y * Y / (R * rr)) * e;
    const double v = -U * Y / R * (1 - X * X / (R * rr)) * e;
    worst = fmax(worst, fmax(fabs(w.ux[i] - u), fabs(w.uy[i] - v)) / U);
  }
  CU_ASSERT(nliq > 100);
  CU_ASSERT(worst < VTOL);
  CU_ASSERT_EQUAL(gas, 0); /* 001 Sec. 4.4: the field on the droplet only */
  double u, v, P, u2, v2;
  rhod_sim_initial_flow(r.sim, 0, c, c, 1000, &u, &v, &P);
  CU_ASSERT(u == 0 && v == 0 && P == 0);
  rhod_sim_initial_flow(r.sim, 0, c + 0.5 * R, c, 1000, &u, &v, &P);
  CU_ASSERT(u > 0.1 * U && fabs(v) < 1e-12); /* outward along x */
  rhod_sim_initial_flow(r.sim, 0, c, c + 0.5 * R, 1000, &u, &v, &P);
  CU_ASSERT(v < -0.1 * U && fabs(u) < 1e-12); /* inward along y */
  /* divergence and symmetry at points off the axes, inside and outside r = R */
  const double pts[4][2] = {{0.3, 0.2}, {-0.6, 0.5}, {-0.9, -0.4}, {1.3, 0.9}};
  const double hh = 1e-4 * R;
  for (int k = 0; k < 4; k++) {
    const double X = pts[k][0] * R, Y = pts[k][1] * R;
    double uxp, uxm, vyp, vym, t0, t1;
    rhod_sim_initial_flow(r.sim, 0, c + X + hh, c + Y, 1000, &uxp, &t0, &P);
    rhod_sim_initial_flow(r.sim, 0, c + X - hh, c + Y, 1000, &uxm, &t1, &P);
    rhod_sim_initial_flow(r.sim, 0, c + X, c + Y + hh, 1000, &t0, &vyp, &P);
    rhod_sim_initial_flow(r.sim, 0, c + X, c + Y - hh, 1000, &t1, &vym, &P);
    const double dudx = (uxp - uxm) / (2 * hh), dvdy = (vyp - vym) / (2 * hh);
    CU_ASSERT(fabs(dudx) > 0.05 * U / R);
    CU_ASSERT(fabs(dudx + dvdy) < 1e-6 * U / R);
    rhod_sim_initial_flow(r.sim, 0, c + X, c + Y, 1000, &u, &v, &P);
    rhod_sim_initial_flow(r.sim, 0, c + Y, c + X, 1000, &u2, &v2, &P);
    CU_ASSERT_DOUBLE_EQUAL(v, -u2, 1e-12 * U);
  }
  as_run_same(r.sc);
  run_close(&r);
}

/* Bad parameters name the key. */
static void test_refused(void) {
  const char *bad[][2] = {
      {"initial: {shear_layer: {U: 1, UI: 0.01, y: [0.5, 1.5], width: 0, spread: 0.2, L: 1}}",
       "fluid.0.initial.shear_layer.width: must be > 0"},
      {"initial: {shear_layer: {U: 1, UI: 0.01, y: [0.5, 1.5], width: 0.05, spread: 0.2, L: -1}}",
       "fluid.0.initial.shear_layer.L: must be > 0"},
      {"initial: {droplet_oscillation: {U: 1, R: 0}}",
       "fluid.0.initial.droplet_oscillation.R: must be > 0"},
      {"initial: {droplet_oscillation: {U: 1, R: 1}, taylor_green: {U: 1, L: 1}}",
       "needs exactly one of taylor_green, rotation, shear_layer, droplet_oscillation"},
  };
  for (unsigned k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    char yaml[1024], err[1024] = "";
    snprintf(yaml, sizeof yaml,
             "time: {end: 1, output_every: 1}\n"
             "particles: {dx: 0.1}\n"
             "physics: {c0: 10}\n"
             "fluid:\n"
             "  - rect: {min: [0, 0], max: [1, 1]}\n"
             "    %s\n",
             bad[k][0]);
    const char *path = "test_initial_flows_bad.yaml";
    FILE *f = fopen(path, "w");
    CU_ASSERT_PTR_NOT_NULL_FATAL(f);
    fputs(yaml, f);
    fclose(f);
    rhod_scene *s = NULL;
    const int st = rhod_scene_load(path, NULL, 0, &s, err, sizeof err);
    remove(path);
    CU_ASSERT_NOT_EQUAL(st, RHOD_OK);
    CU_ASSERT_PTR_NOT_NULL(strstr(err, bad[k][1]));
    if (!strstr(err, bad[k][1]))
      fprintf(stderr, "\nexpected '%s' in '%s'\n", bad[k][1], err);
    if (s)
      rhod_scene_free(s);
  }
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"shear_layer (paper 000 Eq. 27)", test_shear_layer},
      {"droplet_oscillation (paper 000 Eqs. 28-29)", test_droplet_oscillation},
      {"bad parameters refused", test_refused},
  };
  return RHOD_RUN_TESTS("initial_flows", cases);
}
