/* Load-time checks and set-up warnings: the limits the loader puts on what a run would
 * write or hold (tests/scenes/checks, each with the line, key and reason its message must
 * name), output.picture as a switch, fluid.N.surface and the hydrostatic start it sets,
 * the particle estimate, the blocks' positions and the set-up warnings (rhod_sim_warnings). */
#define _POSIX_C_SOURCE 200809L

#include "cunit_main.h"
#include "rhod/io.h"
#include "rhod/rhodsph/scene.h"
#include "rhod/scene.h"
#include "rhod/sim.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CHECKS(name) RHOD_SOURCE_DIR "/tests/scenes/checks/" name

static const struct {
  const char *file;
  int line;
  const char *key;
  const char *reason;
} checks[] = {
    {"picture_height.yaml", 12, "output.picture.width", "24000 pixels high"},
    {"picture_height_panel.yaml", 10, "output.picture.width", "two panels"},
    {"end_steps.yaml", 3, "time.end", "at least 1e+15 steps"},
    {"output_every_tiny.yaml", 4, "time.output_every", "1e+07 snapshots"},
    {"probe_rows.yaml", 8, "probes.every", "at least 1e+09 rows"},
    {"probe_every_tiny.yaml", 8, "probes.every", "below 1e-9 time.end"},
    {"particle_count.yaml", 4, "particles.dx", "about 1e+12 particles"},
    {"surface_uniform.yaml", 8, "fluid.0.surface", "needs pressure: hydrostatic"},
    {"surface_no_gravity.yaml", 8, "fluid.0.surface", "without physics.gravity"},
    {"picture_word.yaml", 8, "output.picture", "expected a mapping, true or false"},
};
#define N_CHECKS (sizeof checks / sizeof checks[0])

static void test_checks(void) {
  for (size_t i = 0; i < N_CHECKS; i++) {
    char path[512], err[1024] = "", prefix[600], key[128];
    snprintf(path, sizeof path, "%s/tests/scenes/checks/%s", RHOD_SOURCE_DIR, checks[i].file);
    rhod_scene *s = (rhod_scene *)1;
    int rc = rhod_scene_load(path, NULL, 0, &s, err, sizeof err);
    snprintf(prefix, sizeof prefix, "%s:%d:", path, checks[i].line);
    snprintf(key, sizeof key, ": %s: ", checks[i].key);
    int ok = rc == RHOD_ERR_SCENE && s == NULL && strncmp(err, prefix, strlen(prefix)) == 0 &&
             strstr(err, key) && strstr(err, checks[i].reason) && !strchr(err, '\n');
    if (!ok)
      fprintf(stderr, "\n%s: rc %d, message '%s', expected line %d key %s\n", checks[i].file, rc,
              err, checks[i].line, checks[i].key);
    CU_ASSERT_TRUE(ok);
  }
}

/* Every file in tests/scenes/checks is in the table. */
static void test_checks_complete(void) {
  FILE *p = popen("ls " RHOD_SOURCE_DIR "/tests/scenes/checks/*.yaml | wc -l", "r");
  CU_ASSERT_PTR_NOT_NULL_FATAL(p);
  unsigned n = 0;
  CU_ASSERT_EQUAL(fscanf(p, "%u", &n), 1);
  pclose(p);
  CU_ASSERT_EQUAL(n, N_CHECKS);
}

/* A scene from text, written to a scratch file. */
static int load_text(const char *text, const char *const *ov, int n, rhod_scene **s, char *err,
                     size_t len) {
  const char *tmp = "test_scene_checks.yaml";
  FILE *f = fopen(tmp, "w");
  if (!f)
    return -1;
  fputs(text, f);
  fclose(f);
  int rc = rhod_scene_load(tmp, ov, n, s, err, len);
  remove(tmp);
  return rc;
}

static const char *TANK = "time: {end: 0.1, output_every: 0.05}\n"
                          "particles: {dx: 0.01}\n"
                          "physics: {c0: 20, gravity: [0, -9.81]}\n"
                          "fluid:\n"
                          "  - rect: {min: [0, 0], max: [0.2, 0.1]}\n"
                          "walls:\n"
                          "  - rect: {min: [0, 0], max: [0.4, 0.3]}\n";

/* The limits hold just inside them: a scene at the edge loads. */
static void test_limits_edges(void) {
  char err[1024];
  rhod_scene *s = NULL;
  /* the loader's picture limit is the writer's: around the edge (16384 pixels a side,
   * margins for the axes and the colour bar included), a scene loads exactly when
   * rhod_picture_layout can lay its picture out */
  int seen_fit = 0, seen_unfit = 0;
  for (int k = 0; k < 40; k++) {
    char wall[64];
    snprintf(wall, sizeof wall, "walls.0.rect.max=[0.4, %.2f]", 7.9 + 0.01 * k);
    const char *off[] = {wall, "output.picture=false"};
    CU_ASSERT_EQUAL_FATAL(load_text(TANK, off, 2, &s, err, sizeof err), RHOD_OK);
    rhod_picture_geometry g;
    const int fits = rhod_picture_layout(800, 1, s->domain_min, s->domain_max, &g) == 0;
    rhod_scene_free(s);
    s = NULL;
    const char *on[] = {wall, "output.picture.width=800"};
    const int rc = load_text(TANK, on, 2, &s, err, sizeof err);
    CU_ASSERT_EQUAL(rc, fits ? RHOD_OK : RHOD_ERR_SCENE);
    if (!fits)
      CU_ASSERT_PTR_NOT_NULL(strstr(err, "--set output.picture.width=800: output.picture.width: "));
    rhod_scene_free(s);
    s = NULL;
    seen_fit |= fits, seen_unfit |= !fits;
  }
  CU_ASSERT(seen_fit && seen_unfit);
  /* pictures off: no limit on their size */
  const char *ov3[] = {"walls.0.rect.max=[0.4, 8.3]", "output.picture=false"};
  CU_ASSERT_EQUAL(load_text(TANK, ov3, 2, &s, err, sizeof err), RHOD_OK);
  rhod_scene_free(s);
  /* 1e6 snapshots are allowed, not more */
  const char *ov4[] = {"time.end=1", "time.output_every=1e-6"};
  CU_ASSERT_EQUAL(load_text(TANK, ov4, 2, &s, err, sizeof err), RHOD_OK);
  rhod_scene_free(s);
  const char *ov5[] = {"time.end=1", "time.output_every=0.9e-6"};
  CU_ASSERT_EQUAL(load_text(TANK, ov5, 2, &s, err, sizeof err), RHOD_ERR_SCENE);
}

static void test_picture_switch(void) {
  char err[1024];
  rhod_scene *s = NULL;
  const char *off[] = {"output.picture=false"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, off, 1, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(s->picture_enabled, 0);
  CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "picture: false"));
  rhod_param_list pl;
  CU_ASSERT_EQUAL(rhod_scene_params(s, &pl), RHOD_OK);
  int found = 0;
  for (unsigned i = 0; i < pl.n; i++) {
    if (!strcmp(pl.keys[i], "output.picture"))
      found = !strcmp(pl.values[i], "false");
    CU_ASSERT_PTR_NULL(strstr(pl.keys[i], "output.picture.")); /* no picture settings */
  }
  CU_ASSERT_TRUE(found);
  rhod_param_list_free(&pl);
  /* the scene as run loads back to pictures off, with the same text */
  rhod_scene *b = NULL;
  CU_ASSERT_EQUAL(load_text(s->yaml, NULL, 0, &b, err, sizeof err), RHOD_OK);
  if (b) {
    CU_ASSERT_EQUAL(b->picture_enabled, 0);
    CU_ASSERT_STRING_EQUAL(b->yaml, s->yaml);
    rhod_scene_free(b);
  }
  rhod_scene_free(s);
  /* true: the defaults, as without the key */
  const char *on[] = {"output.picture=yes"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, on, 1, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(s->picture_enabled, 1);
  CU_ASSERT_EQUAL(s->picture_width, 800);
  rhod_scene *d = NULL;
  CU_ASSERT_EQUAL(load_text(TANK, NULL, 0, &d, err, sizeof err), RHOD_OK);
  if (d) {
    CU_ASSERT_EQUAL(d->picture_enabled, 1);
    CU_ASSERT_STRING_EQUAL(d->yaml, s->yaml);
    rhod_scene_free(d);
  }
  rhod_scene_free(s);
  /* a mapping, as before */
  const char *map[] = {"output.picture={width: 640}"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, map, 1, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(s->picture_enabled, 1);
  CU_ASSERT_EQUAL(s->picture_width, 640);
  rhod_scene_free(s);
}

/* Where each block starts, for the set-up's messages; 0 for a block from --set. */
static void test_block_positions(void) {
  char err[1024];
  rhod_scene *s = NULL;
  const char *ov[] = {"fluid.1={rect: {min: [0.3, 0], max: [0.35, 0.05]}}"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, ov, 1, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(s->fluid[0].line, 5);
  CU_ASSERT_EQUAL(s->fluid[0].col, 5);
  CU_ASSERT_EQUAL(s->fluid[1].line, 0);
  rhod_scene_free(s);
}

static void test_particle_estimate(void) {
  char err[1024];
  rhod_scene *s = NULL;
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, NULL, 0, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_DOUBLE_EQUAL(rhod_scene_particle_estimate(s), 200, 1e-6);
  rhod_scene_free(s);
  /* a level-2 region over half the block: 16 particles a coarse cell there */
  const char *ov[] = {"refinement.levels=3",
                      "refinement.regions=[{rect: {min: [0, 0], max: [0.1, 0.1]}, level: 2}]"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, ov, 2, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_DOUBLE_EQUAL(rhod_scene_particle_estimate(s), 100 + 100 * 16, 1e-6);
  rhod_scene_free(s);
}

/* fluid.N.surface: the hydrostatic start's free surface, P = rho0 c0^2 (exp(g (surface -
 * y)/c0^2) - 1) and rho = rho0 + P/c0^2 (Eq. 2), at every particle; default the top. */
static void check_hydrostatic(const char *const *ov, int n, double surface) {
  char err[1024];
  rhod_scene *s = NULL;
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, ov, n, &s, err, sizeof err), RHOD_OK);
  rhod_sim sim;
  CU_ASSERT_EQUAL_FATAL(rhod_sim_init(&sim, s, err, sizeof err), RHOD_OK);
  rhod_particles_to_host(&sim.p);
  const double c2 = 400, rho0 = 1000, g = 9.81;
  double worst = 0;
  for (size_t k = 0; k < sim.p.n; k++) {
    const double P = rho0 * c2 * (exp(g * (surface - sim.p.y[k]) / c2) - 1);
    const double P_got = c2 * (sim.p.rho[k] - rho0);
    worst = fmax(worst, fabs(P_got - P));
  }
  /* a millionth of the column's pressure; in single precision rho holds ~7 digits, so
   * c0^2 rho0 a few float epsilons (0.1 Pa; a surface 1 cm off is 98 Pa off) */
  const double eps = sizeof(real) == 4 ? FLT_EPSILON : DBL_EPSILON;
  const double tol = fmax(1e-6 * rho0 * g * 0.3, 4 * c2 * rho0 * eps);
  CU_ASSERT_TRUE(sim.p.n == 200);
  CU_ASSERT_TRUE(worst < tol);
  if (!(worst < tol))
    fprintf(stderr, "\nsurface %g: worst pressure error %g Pa\n", surface, worst);
  rhod_sim_free(&sim);
  rhod_scene_free(s);
}

static void test_surface(void) {
  check_hydrostatic(NULL, 0, 0.1);
  const char *ov[] = {"fluid.0.surface=0.25"};
  check_hydrostatic(ov, 1, 0.25);
  /* the level is kept in the scene as run, only when given */
  char err[1024];
  rhod_scene *s = NULL;
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, ov, 1, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "surface: 0.25"));
  rhod_scene_free(s);
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, NULL, 0, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_PTR_NULL(strstr(s->yaml, " surface:"));
  rhod_scene_free(s);
  /* below the block's top: a warning (the particles above it start in tension) */
  const char *low[] = {"fluid.0.surface=0.05"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, low, 1, &s, err, sizeof err), RHOD_OK);
  char w[2048];
  CU_ASSERT_TRUE(rhod_scene_warnings(s, w, sizeof w) >= 1);
  CU_ASSERT_PTR_NOT_NULL(strstr(w, "fluid.0.surface: 0.05 m is below the block's top (0.1 m"));
  rhod_scene_free(s);
}

/* time.output_every > time.end: the warning says what is written (two snapshots). */
static void test_output_every_warning(void) {
  char err[1024], w[2048];
  rhod_scene *s = NULL;
  const char *ov[] = {"time.output_every=0.5"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, ov, 1, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_TRUE(rhod_scene_warnings(s, w, sizeof w) >= 1);
  CU_ASSERT_PTR_NOT_NULL(strstr(w, "time.output_every: 0.5 s exceeds time.end = 0.1 s: two "
                                   "snapshots are written, at t = 0 and at the end"));
  rhod_scene_free(s);
}

/* rhod_sim_warnings: left-out fluid, an unreachable probe, a fall with no wall below. */
static void test_sim_warnings(void) {
  char err[1024], w[4096];
  rhod_scene *s = NULL;
  rhod_sim sim;
  /* the tank as is: nothing to say */
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, NULL, 0, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_sim_init(&sim, s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_sim_warnings(&sim, w, sizeof w), 0);
  rhod_sim_free(&sim);
  rhod_scene_free(s);
  /* half the block beside the tank, a probe in an obstacle, one above the water */
  const char *ov[] = {"fluid.0.rect.min=[-0.2, 0]",
                      "walls.1={circle: {center: [0.3, 0.15], radius: 0.05}, fluid_inside: false}",
                      "probes.list=[{pressure: {name: stone, at: [0.3, 0.15]}},"
                      " {pressure: {name: air, at: [0.35, 0.28]}}]"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, ov, 3, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_sim_init(&sim, s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_sim_warnings(&sim, w, sizeof w), 2);
  CU_ASSERT_PTR_NOT_NULL(strstr(w, ":5:5: fluid.0: 200 of the 400 particles of its lattice are "
                                   "left out: 200 outside its container walls.0"));
  CU_ASSERT_PTR_NOT_NULL(strstr(w, "probes.list.0.pressure.at: [0.3, 0.15] lies behind a wall"));
  CU_ASSERT_PTR_NULL(strstr(w, "probes.list.1"));
  rhod_sim_free(&sim);
  rhod_scene_free(s);
  /* no walls, a domain below: the fluid falls out */
  const char *fall[] = {"walls=[]", "domain={min: [0, -1], max: [0.2, 0.1]}"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, fall, 2, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_sim_init(&sim, s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_sim_warnings(&sim, w, sizeof w), 1);
  CU_ASSERT_PTR_NOT_NULL(strstr(w, "physics.gravity: 200 of the 200 fluid particles have no wall "
                                   "below them"));
  CU_ASSERT_PTR_NOT_NULL(strstr(w, "will leave the domain"));
  rhod_sim_free(&sim);
  rhod_scene_free(s);
  /* ... unless y is periodic */
  const char *wrap[] = {"walls=[]",
                        "domain={min: [0, -1], max: [0.2, 0.1], periodic: [false, true]}"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, wrap, 2, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_sim_init(&sim, s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_sim_warnings(&sim, w, sizeof w), 0);
  rhod_sim_free(&sim);
  rhod_scene_free(s);
}

/* No particle fits: the block, where it is, and why. */
static void test_no_fit(void) {
  char err[1024];
  rhod_scene *s = NULL;
  rhod_sim sim;
  const char *ov[] = {"fluid.0.rect={min: [0.5, 0], max: [0.6, 0.1]}",
                      "domain={min: [0, 0], max: [0.7, 0.3]}"};
  CU_ASSERT_EQUAL_FATAL(load_text(TANK, ov, 2, &s, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_sim_init(&sim, s, err, sizeof err), RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "test_scene_checks.yaml:5:5: fluid.0: no particle fits at "
                                     "dx = 0.01 m: all 100 of its lattice points are left out: "
                                     "100 outside its container walls.0"));
  CU_ASSERT_PTR_NULL(strchr(err, '\n'));
  rhod_sim_free(&sim);
  rhod_scene_free(s);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"load-time limits: line, key and reason", test_checks},
      {"every checks scene is in the table", test_checks_complete},
      {"limits at their edges", test_limits_edges},
      {"output.picture: false, true or a mapping", test_picture_switch},
      {"fluid blocks' positions", test_block_positions},
      {"particle estimate", test_particle_estimate},
      {"fluid.N.surface: hydrostatic start", test_surface},
      {"output_every > end warning", test_output_every_warning},
      {"set-up warnings", test_sim_warnings},
      {"no particle fits: block and cause", test_no_fit},
  };
  return RHOD_RUN_TESTS("scene_checks", cases);
}
