/* The multiphase scheme's scene keys (src/multiphase/scene_mp.c, paper 000) and the
 * moving walls (walls.N.velocity, walls.N.edges): every key read, the scheme-dependent
 * defaults, `--set` errors naming the override, and the scene as run loading back to the
 * same scene (load, write, load, compare). The malformed files are in test_scene's table. */
#define _POSIX_C_SOURCE 200809L

#include "rhod/multiphase/scene.h"
#include "rhod/rhodsph/scene.h"
#include "rhod/scene.h"
#include "test_scene_load.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void test_full(void) {
  rhod_scene *s = load_ok(GOOD("multiphase.yaml"), NULL, 0);
  if (!s)
    return;
  CU_ASSERT_EQUAL(s->scheme, RHOD_SCHEME_MULTIPHASE);
  CU_ASSERT_EQUAL(s->integrator, RHOD_INTEGRATOR_RK2); /* given */
  CU_ASSERT_EQUAL(s->kernel, RHOD_KERNEL_QUINTIC);
  CLOSE(s->radius_ratio, 3);
  CLOSE(s->gravity[1], -9.81);
  const rhod_mp_scene *mp = s->mp;
  CU_ASSERT_PTR_NOT_NULL_FATAL(mp);
  CU_ASSERT_EQUAL_FATAL(mp->n_phases, 3);
  CU_ASSERT_STRING_EQUAL(mp->phases[0].name, "water");
  CLOSE(mp->phases[0].rho0, 1000);
  CLOSE(mp->phases[0].c, 20);
  CLOSE(mp->phases[0].gamma, 7);
  CLOSE(mp->phases[0].mu, 0.001);
  CLOSE(mp->phases[0].colour, 1); /* default for the first */
  CU_ASSERT_STRING_EQUAL(mp->phases[1].name, "air");
  CLOSE(mp->phases[1].rho0, 1.2);
  CLOSE(mp->phases[1].c, 30);
  CLOSE(mp->phases[1].gamma, 1);
  CLOSE(mp->phases[1].mu, 1.8e-5);
  CLOSE(mp->phases[1].colour, 0); /* default for the others */
  CLOSE(mp->phases[2].gamma, 7);  /* default */
  CLOSE(mp->phases[2].colour, 1); /* given */
  CU_ASSERT_EQUAL(rhod_mp_phase_index(mp, "oil"), 2);
  CU_ASSERT_EQUAL(rhod_mp_phase_index(mp, "gas"), -1);
  /* sigma: 0.07 for every pair, two pairs overridden (symmetric, 0 on the diagonal) */
  const double want[3][3] = {{0, 0.07, 0.03}, {0.07, 0, 0.02}, {0.03, 0.02, 0}};
  for (unsigned a = 0; a < 3; a++)
    for (unsigned b = 0; b < 3; b++)
      CLOSE(rhod_mp_sigma(mp, a, b), want[a][b]);
  CLOSE(mp->delta, 0.2);
  CLOSE(mp->xi_shift, 0.4);
  CLOSE(mp->xi_rep, 0);
  CLOSE(mp->rep_n, 3);
  CLOSE(mp->xi_rif, 0.05);
  CLOSE(mp->eta2, 0.02);
  CU_ASSERT_FALSE(mp->tensile_control);
  CLOSE(mp->cfl, 0.2);
  CLOSE(mp->cfl_visc, 0.1);
  CLOSE(mp->cfl_force, 0.3);
  CLOSE(mp->cfl_surface, 0.15);
  CU_ASSERT_EQUAL_FATAL(s->n_fluid, 3);
  CU_ASSERT_EQUAL(s->fluid[0].phase, 0);
  CU_ASSERT_EQUAL(s->fluid[1].phase, 1);
  CU_ASSERT_EQUAL(s->fluid[2].phase, 2);
  /* the lid: the rect's top edge (2) */
  CU_ASSERT_EQUAL_FATAL(s->n_walls, 2);
  CLOSE(s->walls[0].velocity[0], 1);
  CLOSE(s->walls[0].velocity[1], 0);
  CU_ASSERT_EQUAL(s->walls[0].moving_edges, 1u << 2);
  /* the clockwise polygon is stored reversed: its edge 1 ([2, 1] to [3, 0]) is stored
   * edge 0 (points[0] = [3, 0] to points[1] = [2, 1]) */
  CU_ASSERT_EQUAL(s->walls[1].moving_edges, 1u << 0);
  CLOSE(s->walls[1].shape.points[0][0], 3);
  CLOSE(s->walls[1].shape.points[1][1], 1);
  CU_ASSERT_TRUE(rhod_scene_walls_move(s));
  rhod_scene_free(s);
}

static void test_defaults(void) {
  rhod_scene *s = load_ok(GOOD("multiphase_minimal.yaml"), NULL, 0);
  if (!s)
    return;
  CU_ASSERT_EQUAL(s->scheme, RHOD_SCHEME_MULTIPHASE);
  /* scheme-dependent defaults */
  CU_ASSERT_EQUAL(s->integrator, RHOD_INTEGRATOR_MIDPOINT);
  CU_ASSERT_EQUAL(s->kernel, RHOD_KERNEL_WENDLAND_C4);
  CLOSE(s->radius_ratio, 4);
  /* none of rhodsph's keys: no stiffness limit, one level (no refinement) */
  CU_ASSERT_PTR_NULL(s->rs);
  CLOSE(s->gravity[0], 0);
  CLOSE(s->gravity[1], 0);
  const rhod_mp_scene *mp = s->mp;
  CU_ASSERT_PTR_NOT_NULL_FATAL(mp);
  CU_ASSERT_EQUAL_FATAL(mp->n_phases, 1);
  CLOSE(mp->phases[0].gamma, 7);
  CLOSE(mp->phases[0].mu, 0);
  CLOSE(mp->phases[0].colour, 1);
  CLOSE(rhod_mp_sigma(mp, 0, 0), 0);
  CLOSE(mp->delta, 0.1);
  CLOSE(mp->xi_shift, 0.5);
  CLOSE(mp->xi_rep, 0.1);
  CLOSE(mp->rep_n, 2);
  CLOSE(mp->xi_rif, 0.01);
  CLOSE(mp->eta2, 0.01);
  CU_ASSERT_TRUE(mp->tensile_control);
  CLOSE(mp->cfl, 0.25);
  CLOSE(mp->cfl_visc, 0.125);
  CLOSE(mp->cfl_force, 0.25);
  CLOSE(mp->cfl_surface, 0.25);
  CU_ASSERT_EQUAL(s->fluid[0].phase, 0);
  CU_ASSERT_FALSE(rhod_scene_walls_move(s));
  /* two phases: the second's colour is 0 by default, sigma 0 unless given */
  const char *ov[] = {"phases.1={name: air, rho0: 1, c: 10}", "multiphase.sigma=0.5"};
  rhod_scene *t = load_ok(GOOD("multiphase_minimal.yaml"), ov, 2);
  if (t) {
    CU_ASSERT_EQUAL_FATAL(t->mp->n_phases, 2);
    CLOSE(t->mp->phases[1].colour, 0);
    CLOSE(rhod_mp_sigma(t->mp, 0, 1), 0.5);
    CLOSE(rhod_mp_sigma(t->mp, 1, 0), 0.5);
    CLOSE(rhod_mp_sigma(t->mp, 1, 1), 0);
  }
  rhod_scene_free(t);
  rhod_scene_free(s);
  /* rhodsph keeps its own defaults and has no multiphase part */
  s = load_ok(GOOD("minimal.yaml"), NULL, 0);
  if (s) {
    CU_ASSERT_EQUAL(s->scheme, RHOD_SCHEME_RHODSPH);
    CU_ASSERT_PTR_NULL(s->mp);
    CU_ASSERT_EQUAL(s->integrator, RHOD_INTEGRATOR_RK4);
    CU_ASSERT_EQUAL(s->kernel, RHOD_KERNEL_WENDLAND_C2);
    CU_ASSERT_EQUAL(s->fluid[0].phase, -1);
    /* and its scene as run has none of the new keys */
    CU_ASSERT_PTR_NULL(strstr(s->yaml, "name: rhodsph"));
    CU_ASSERT_PTR_NULL(strstr(s->yaml, "phase"));
    CU_ASSERT_PTR_NULL(strstr(s->yaml, "multiphase"));
  }
  rhod_scene_free(s);
  /* the midpoint integrator is rhodsph's too */
  const char *mid[] = {"time.integrator=midpoint"};
  s = load_ok(GOOD("minimal.yaml"), mid, 1);
  if (s)
    CU_ASSERT_EQUAL(s->integrator, RHOD_INTEGRATOR_MIDPOINT);
  rhod_scene_free(s);
}

/* Moving walls: default edges (all), zero velocity (nothing moves), tangential slanted
 * polygon edges, in either scheme. */
static void test_wall_motion(void) {
  const char *all[] = {"walls.0={rect: {min: [0, 0], max: [1, 1]}, velocity: [0, 0]}",
                       "walls.1={polygon: [[2, 0], [3, 0], [3, 1]], velocity: [0, 0], edges: [0]}",
                       "walls.2={polygon: [[0, 2], [1, 3], [1, 2]], velocity: [2, 2], edges: [0]}"};
  rhod_scene *s = load_ok(GOOD("minimal.yaml"), all, 3);
  if (s) {
    CU_ASSERT_EQUAL_FATAL(s->n_walls, 3);
    CU_ASSERT_EQUAL(s->walls[0].moving_edges, 0u); /* at rest: nothing moves */
    CU_ASSERT_EQUAL(s->walls[1].moving_edges, 0u);
    /* clockwise: edge 0 ([0, 2] to [1, 3]) is stored edge 1 */
    CU_ASSERT_EQUAL(s->walls[2].moving_edges, 1u << 1);
    CU_ASSERT_TRUE(rhod_scene_walls_move(s));
    CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "velocity: [2, 2]\n"));
    CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "edges: [1]\n"));
  }
  rhod_scene_free(s);
  /* a rect moving along x needs its vertical edges left out; periodic along x is fine
   * for the horizontal ones (their normals lie along y) */
  const char *couette[] = {"domain.min=[0, 0]", "domain.max=[1, 1]",
                           "domain.periodic=[true, false]",
                           "walls.0={rect: {min: [-1, 0], max: [2, 1]}, slip: 'no', velocity: [1, "
                           "0], edges: [0, 2]}"};
  s = load_ok(GOOD("minimal.yaml"), couette, 4);
  if (s)
    CU_ASSERT_EQUAL(s->walls[0].moving_edges, (1u << 0) | (1u << 2));
  rhod_scene_free(s);
  /* a triangle whose every edge is along [1, 0]: no, but the default "all" edges of a
   * rect moving along x are refused at edge 1, the first vertical one */
  char err[1024];
  const char *rect_all[] = {"walls.0={rect: {min: [0, 0], max: [1, 1]}, velocity: [1, 0]}"};
  rhod_scene *bad = (rhod_scene *)1;
  CU_ASSERT_EQUAL(rhod_scene_load(GOOD("minimal.yaml"), rect_all, 1, &bad, err, sizeof err),
                  RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "walls.0.velocity: [1, 0] is not along edge 1"));
}

/* --set errors of the new keys name the override and the key. */
static const struct {
  const char *set, *key, *reason;
} bad_overrides[] = {
    {"phases.0.gamma=0", "phases.0.gamma", "must be > 0"},
    {"phases.0.rho0=-1", "phases.0.rho0", "must be > 0"},
    {"phases.0.c=0", "phases.0.c", "must be > 0"},
    {"phases.0.mu=-1", "phases.0.mu", "must be >= 0"},
    {"phases.0.name=a b", "phases.0.name", "not an identifier"},
    {"phases.1={name: water, rho0: 1, c: 1}", "phases.1.name", "duplicate phase name"},
    {"phases.0.foo=1", "phases.0.foo", "unknown key"},
    {"fluid.0.phase=oil", "fluid.0.phase", "unknown phase 'oil' (phases: water)"},
    {"multiphase.sigma=-1", "multiphase.sigma", "must be >= 0"},
    {"multiphase.sigma=0.07", "multiphase.sigma", "needs at least two phases"},
    {"multiphase.sigma_pairs.0={phases: [water, water], sigma: 1}", "multiphase.sigma_pairs",
     "needs at least two phases"},
    {"multiphase.delta=-0.1", "multiphase.delta", "must be >= 0"},
    {"multiphase.shifting=-1", "multiphase.shifting", "must be >= 0"},
    {"multiphase.repulsion=-1", "multiphase.repulsion", "must be >= 0"},
    {"multiphase.repulsion_power=0", "multiphase.repulsion_power", "must be > 0"},
    {"multiphase.interface_force=-1", "multiphase.interface_force", "must be >= 0"},
    {"multiphase.viscosity_eta=0", "multiphase.viscosity_eta", "must be > 0"},
    {"multiphase.cfl=2", "multiphase.cfl", "must be in (0, 1]"},
    {"multiphase.cfl_visc=0", "multiphase.cfl_visc", "must be > 0"},
    {"multiphase.cfl_force=0", "multiphase.cfl_force", "must be > 0"},
    {"multiphase.cfl_surface=0", "multiphase.cfl_surface", "must be > 0"},
    {"multiphase.tensile_control=maybe", "multiphase.tensile_control", "invalid boolean"},
    {"physics.c0=20", "physics.c0", "belongs to the rhodsph scheme"},
    {"physics.mu=1", "physics.mu", "belongs to the rhodsph scheme"},
    {"physics.rho0=1", "physics.rho0", "belongs to the rhodsph scheme"},
    {"particles.relax=3", "particles.relax", "belongs to the rhodsph scheme"},
    {"time.cfl=0.3", "time.cfl", "belongs to the rhodsph scheme"},
    {"scheme.shifting=false", "scheme.shifting", "belongs to the rhodsph scheme"},
    {"refinement.levels=2", "refinement.levels", "belongs to the rhodsph scheme"},
    {"refinement={}", "refinement", "belongs to the rhodsph scheme"},
    {"scheme.name=sph", "scheme.name", "invalid value 'sph'"},
    {"walls.0={circle: {center: [0, 0], radius: 2}, velocity: [1, 0]}", "walls.0.velocity",
     "a circle wall cannot move"},
    {"walls.0={rect: {min: [0, 0], max: [1, 1]}, velocity: [0, 1], edges: [0]}", "walls.0.velocity",
     "is not along edge 0"},
    {"walls.0={rect: {min: [0, 0], max: [1, 1]}, velocity: [0, 1], edges: [4]}", "walls.0.edges.0",
     "out of range"},
};

static void test_override_errors(void) {
  for (size_t i = 0; i < sizeof bad_overrides / sizeof bad_overrides[0]; i++) {
    char err[1024] = "", want[512];
    rhod_scene *s = (rhod_scene *)1;
    const char *ov[] = {"time.end=2", bad_overrides[i].set};
    int rc = rhod_scene_load(GOOD("multiphase_minimal.yaml"), ov, 2, &s, err, sizeof err);
    snprintf(want, sizeof want, "--set %s: %s: ", bad_overrides[i].set, bad_overrides[i].key);
    int ok = rc == RHOD_ERR_SCENE && s == NULL && strncmp(err, want, strlen(want)) == 0 &&
             strstr(err, bad_overrides[i].reason) && !strchr(err, '\n');
    if (!ok)
      fprintf(stderr, "\n--set %s: rc %d, message '%s'\n", bad_overrides[i].set, rc, err);
    CU_ASSERT_TRUE(ok);
  }
  /* on the three-phase scene */
  const char *full[][3] = {
      {"multiphase.sigma_pairs.0.sigma=-1", "multiphase.sigma_pairs.0.sigma", "must be >= 0"},
      {"multiphase.sigma_pairs.1.phases=[water, gas]", "multiphase.sigma_pairs.1.phases.1",
       "unknown phase 'gas' (phases: water, air, oil)"},
      {"phases=[]", "phases", "expected at least 1 entry, got 0"},
      {"walls.1.edges=[3]", "walls.1.edges.0", "the polygon has 3 edges"},
  };
  for (size_t i = 0; i < sizeof full / sizeof full[0]; i++) {
    char err[1024] = "", want[512];
    rhod_scene *s = (rhod_scene *)1;
    const char *ov[] = {full[i][0]};
    int rc = rhod_scene_load(GOOD("multiphase.yaml"), ov, 1, &s, err, sizeof err);
    snprintf(want, sizeof want, "--set %s: %s: ", full[i][0], full[i][1]);
    int ok =
        rc == RHOD_ERR_SCENE && strncmp(err, want, strlen(want)) == 0 && strstr(err, full[i][2]);
    if (!ok)
      fprintf(stderr, "\n--set %s: rc %d, message '%s'\n", full[i][0], rc, err);
    CU_ASSERT_TRUE(ok);
  }
  /* the rhodsph scheme refuses the multiphase keys, from an override too */
  const char *rh[][2] = {
      {"phases.0={name: water, rho0: 1, c: 1}", "phases"},
      {"multiphase.sigma=1", "multiphase"},
      {"fluid.0.phase=water", "fluid.0.phase"},
  };
  for (size_t i = 0; i < sizeof rh / sizeof rh[0]; i++) {
    char err[1024] = "", want[512];
    rhod_scene *s = (rhod_scene *)1;
    const char *ov[] = {rh[i][0]};
    int rc = rhod_scene_load(GOOD("minimal.yaml"), ov, 1, &s, err, sizeof err);
    snprintf(want, sizeof want, "--set %s: %s: belongs to the multiphase scheme", rh[i][0],
             rh[i][1]);
    if (rc != RHOD_ERR_SCENE || strncmp(err, want, strlen(want)) != 0)
      fprintf(stderr, "\n--set %s: rc %d, message '%s'\n", rh[i][0], rc, err);
    CU_ASSERT_EQUAL(rc, RHOD_ERR_SCENE);
    CU_ASSERT_EQUAL(strncmp(err, want, strlen(want)), 0);
  }
}

/* ---- the scene as run: load, write, load, compare ----------------------------------- */

static int same_shape(const rhod_shape *a, const rhod_shape *b) {
  if (a->kind != b->kind || a->n_points != b->n_points || a->radius != b->radius)
    return 0;
  for (int d = 0; d < 2; d++)
    if (a->min[d] != b->min[d] || a->max[d] != b->max[d] || a->center[d] != b->center[d])
      return 0;
  for (unsigned k = 0; k < a->n_points; k++)
    if (a->points[k][0] != b->points[k][0] || a->points[k][1] != b->points[k][1])
      return 0;
  return 1;
}

/* every field of the two scenes that the multiphase keys and moving walls touch, and
 * the shared ones */
static void compare(const rhod_scene *a, const rhod_scene *b) {
  CU_ASSERT_EQUAL(a->scheme, b->scheme);
  CU_ASSERT(a->t_end == b->t_end && a->output_every == b->output_every);
  CU_ASSERT_EQUAL(a->integrator, b->integrator);
  CU_ASSERT(a->dx == b->dx && a->radius_ratio == b->radius_ratio && a->jitter == b->jitter);
  CU_ASSERT_EQUAL(a->kernel, b->kernel);
  CU_ASSERT(a->gravity[0] == b->gravity[0] && a->gravity[1] == b->gravity[1]);
  /* rhodsph's keys: a multiphase scene has none (rs NULL) */
  CU_ASSERT_EQUAL(!a->rs, !b->rs);
  if (a->rs && b->rs) {
    CU_ASSERT(a->rs->cfl == b->rs->cfl && a->rs->cfl_visc == b->rs->cfl_visc);
    CU_ASSERT_EQUAL(a->rs->stiffness_limit, b->rs->stiffness_limit);
    CU_ASSERT(a->rs->rho0 == b->rs->rho0 && a->rs->c0 == b->rs->c0 && a->rs->mu == b->rs->mu);
    CU_ASSERT_EQUAL(a->rs->levels, b->rs->levels);
  }
  CU_ASSERT_EQUAL_FATAL(a->n_fluid, b->n_fluid);
  for (unsigned i = 0; i < a->n_fluid; i++) {
    CU_ASSERT(same_shape(&a->fluid[i].shape, &b->fluid[i].shape));
    CU_ASSERT_EQUAL(a->fluid[i].phase, b->fluid[i].phase);
    CU_ASSERT_EQUAL(a->fluid[i].pressure, b->fluid[i].pressure);
  }
  CU_ASSERT_EQUAL_FATAL(a->n_walls, b->n_walls);
  for (unsigned i = 0; i < a->n_walls; i++) {
    CU_ASSERT(same_shape(&a->walls[i].shape, &b->walls[i].shape));
    CU_ASSERT_EQUAL(a->walls[i].slip, b->walls[i].slip);
    CU_ASSERT_EQUAL(a->walls[i].moving_edges, b->walls[i].moving_edges);
    CU_ASSERT(a->walls[i].velocity[0] == b->walls[i].velocity[0] &&
              a->walls[i].velocity[1] == b->walls[i].velocity[1]);
  }
  CU_ASSERT_EQUAL(!a->mp, !b->mp);
  if (!a->mp || !b->mp)
    return;
  const rhod_mp_scene *p = a->mp, *q = b->mp;
  CU_ASSERT_EQUAL_FATAL(p->n_phases, q->n_phases);
  for (unsigned k = 0; k < p->n_phases; k++) {
    const rhod_mp_phase_desc *x = &p->phases[k], *y = &q->phases[k];
    CU_ASSERT_STRING_EQUAL(x->name, y->name);
    CU_ASSERT(x->rho0 == y->rho0 && x->c == y->c && x->gamma == y->gamma && x->mu == y->mu &&
              x->colour == y->colour);
  }
  for (unsigned k = 0; k < p->n_phases * p->n_phases; k++)
    CU_ASSERT(p->sigma[k] == q->sigma[k]);
  CU_ASSERT(p->delta == q->delta && p->xi_shift == q->xi_shift && p->xi_rep == q->xi_rep &&
            p->rep_n == q->rep_n && p->xi_rif == q->xi_rif && p->eta2 == q->eta2);
  CU_ASSERT_EQUAL(p->tensile_control, q->tensile_control);
  CU_ASSERT(p->cfl == q->cfl && p->cfl_visc == q->cfl_visc && p->cfl_force == q->cfl_force &&
            p->cfl_surface == q->cfl_surface);
}

static void round_trip(const char *path, const char *const *ov, int n) {
  rhod_scene *a = load_ok(path, ov, n);
  if (!a)
    return;
  const char *tmp = "test_scene_mp_as_run.yaml";
  FILE *f = fopen(tmp, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fputs(a->yaml, f);
  fclose(f);
  rhod_scene *b = load_ok(tmp, NULL, 0);
  remove(tmp);
  if (b) {
    compare(a, b);
    CU_ASSERT_STRING_EQUAL(a->yaml, b->yaml);
    if (strcmp(a->yaml, b->yaml) != 0)
      fprintf(stderr, "\n--- first\n%s--- second\n%s", a->yaml, b->yaml);
  }
  rhod_scene_free(a);
  rhod_scene_free(b);
}

static void test_as_run(void) {
  round_trip(GOOD("multiphase.yaml"), NULL, 0);
  round_trip(GOOD("multiphase_minimal.yaml"), NULL, 0);
  /* sigma pairs all unlike the global value, and a sigma of a single overridden pair */
  const char *ov[] = {"multiphase.sigma=0.01",
                      "multiphase.sigma_pairs.2={phases: [water, air], sigma: 0.04}"};
  round_trip(GOOD("multiphase.yaml"), ov, 2);
  const char *two[] = {"phases.1={name: gas, rho0: 1, c: 10, colour: 1}",
                       "multiphase.sigma_pairs.0={phases: [gas, water], sigma: 0.3}"};
  round_trip(GOOD("multiphase_minimal.yaml"), two, 2);
  /* rhodsph with a moving wall */
  const char *lid[] = {
      "walls.0={rect: {min: [0, 0], max: [1, 1]}, slip: 'no', velocity: [1, 0], "
      "edges: [2]}",
      "walls.1={polygon: [[2, 0], [2, 1], [3, 0]], velocity: [0, -1], edges: [0]}"};
  round_trip(GOOD("minimal.yaml"), lid, 2);
}

static void test_params(void) {
  rhod_scene *s = load_ok(GOOD("multiphase.yaml"), NULL, 0);
  if (!s)
    return;
  rhod_param_list p;
  CU_ASSERT_EQUAL_FATAL(rhod_scene_params(s, &p), RHOD_OK);
  const struct {
    const char *key, *value;
  } want[] = {
      {"scheme.name", "multiphase"},
      {"time.integrator", "rk2"},
      {"phases.0.name", "water"},
      {"phases.1.rho0", "1.2"},
      {"phases.1.colour", "0"},
      {"phases.2.mu", "0.05"},
      {"multiphase.sigma", "0.07"},
      {"multiphase.sigma_pairs.0.phases", "[water, oil]"},
      {"multiphase.sigma_pairs.1.sigma", "0.02"},
      {"multiphase.delta", "0.2"},
      {"multiphase.repulsion_power", "3"},
      {"multiphase.viscosity_eta", "0.02"},
      {"multiphase.tensile_control", "false"},
      {"multiphase.cfl_surface", "0.15"},
      {"fluid.2.phase", "oil"},
      {"walls.0.velocity", "[1, 0]"},
      {"walls.0.edges", "[2]"},
      {"walls.1.edges", "[0]"},
  };
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
    const char *v = param(&p, want[i].key);
    if (!v || strcmp(v, want[i].value) != 0)
      fprintf(stderr, "\n%s: '%s', expected '%s'\n", want[i].key, v ? v : "(none)", want[i].value);
    CU_ASSERT_TRUE(v && strcmp(v, want[i].value) == 0);
  }
  /* none of rhodsph's keys */
  const char *absent[] = {"physics.c0",     "physics.rho0",      "physics.mu",     "time.cfl",
                          "scheme.riemann", "refinement.levels", "particles.relax"};
  for (size_t i = 0; i < sizeof absent / sizeof absent[0]; i++)
    CU_ASSERT_PTR_NULL(param(&p, absent[i]));
  rhod_param_list_free(&p);
  rhod_scene_free(s);
}

/* A multiphase scene has no physics.c0: the load-time limits use the fastest phase. */
static void test_limits(void) {
  char err[1024];
  rhod_scene *s = (rhod_scene *)1;
  const char *ov[] = {"time.end=1e9", "particles.dx=1e-4"};
  CU_ASSERT_EQUAL(rhod_scene_load(GOOD("multiphase_minimal.yaml"), ov, 2, &s, err, sizeof err),
                  RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "time.end: "));
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "paper 001 Eq. 16"));
  /* no Eq. 2 warning on c0 for the multiphase scheme */
  s = load_ok(GOOD("multiphase.yaml"), NULL, 0);
  if (s) {
    char buf[2048];
    rhod_scene_warnings(s, buf, sizeof buf);
    CU_ASSERT_PTR_NULL(strstr(buf, "physics.c0"));
  }
  rhod_scene_free(s);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"multiphase scene: every key read", test_full},
      {"scheme-dependent defaults", test_defaults},
      {"moving walls: edges, tangential velocity", test_wall_motion},
      {"--set errors of the new keys", test_override_errors},
      {"scene as run: load, write, load, compare", test_as_run},
      {"flattened parameters list the new keys", test_params},
      {"load-time limits without c0", test_limits},
  };
  return RHOD_RUN_TESTS("scene_mp", cases);
}
