/* The scene's open boundaries (src/scene_open.c, issue 52): every key's resolved default
 * (name, normal toward the domain's centre, velocity "0", profile, dx, phase), an explicit
 * normal on the other side, the default domain, the scene as run and `--set`, and one
 * message per check (key path and reason). The malformed files are
 * tests/scenes/bad/open_*.yaml (test_scene.c, cli_bad_scenes). */
#define _POSIX_C_SOURCE 200809L

#include "test_scene_load.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CHANNEL GOOD("open_channel.yaml")

/* the channel: an inflow at x = 0 and an outflow at x = 1, every default */
static void test_defaults(void) {
  rhod_scene *s = load_ok(CHANNEL, NULL, 0);
  if (!s)
    return;
  CU_ASSERT_EQUAL_FATAL(s->n_open, 2);
  const rhod_open_boundary *a = &s->open[0], *b = &s->open[1];
  CU_ASSERT_STRING_EQUAL(a->name, "open0");
  CU_ASSERT_STRING_EQUAL(b->name, "open1");
  CU_ASSERT_EQUAL(a->kind, RHOD_OPEN_INFLOW);
  CU_ASSERT_EQUAL(b->kind, RHOD_OPEN_OUTFLOW);
  /* toward the domain's centre (0.5, 0.1) */
  CU_ASSERT_EQUAL(a->normal[0], 1);
  CU_ASSERT_EQUAL(a->normal[1], 0);
  CU_ASSERT_EQUAL(b->normal[0], -1);
  CU_ASSERT_EQUAL(b->normal[1], 0);
  CU_ASSERT_FALSE(signbit(a->normal[1])); /* no -0 in the scene as run */
  CU_ASSERT_STRING_EQUAL(a->velocity, "0");
  CU_ASSERT_PTR_NULL(b->velocity);
  CU_ASSERT_EQUAL(a->profile, RHOD_PROFILE_UNIFORM);
  CU_ASSERT_EQUAL(a->dx, 0.02);
  CU_ASSERT_EQUAL(b->dx, 0.02);
  CU_ASSERT_EQUAL(a->phase, -1);
  CU_ASSERT_EQUAL(a->surface_set, 0);
  CU_ASSERT_EQUAL(a->line, 21);
  CU_ASSERT_EQUAL(b->line, 24);
  CU_ASSERT_EQUAL(a->from[1], 0);
  CU_ASSERT_EQUAL(a->to[1], 0.2);
  CU_ASSERT_TRUE(rhod_scene_walls_move(s)); /* an inflow: the ghosts carry velocity */
  rhod_scene_free(s);
}

/* normal given on the side away from the domain's centre, neither unit nor perpendicular:
 * resolved to the unit perpendicular on its side; a slanted segment's default */
static void test_normal(void) {
  const char *ov[] = {"domain.max=[2, 0.2]", "open_boundaries.1.from=[1.5, 0]",
                      "open_boundaries.1.to=[1.5, 0.2]", "open_boundaries.1.normal=[3, 1]",
                      "open_boundaries.2={kind: outflow, from: [1.6, 0], to: [1.8, 0.2]}"};
  rhod_scene *s = load_ok(CHANNEL, ov, 5);
  if (!s)
    return;
  CU_ASSERT_EQUAL_FATAL(s->n_open, 3);
  CU_ASSERT_EQUAL(s->open[1].normal[0], 1); /* the centre (1, 0.1) lies at -x */
  CU_ASSERT_EQUAL(s->open[1].normal[1], 0);
  /* from (1.6, 0) to (1.8, 0.2): t = (1, 1)/sqrt 2, the centre on the side (-1, 1)/sqrt 2 */
  CU_ASSERT_DOUBLE_EQUAL(s->open[2].normal[0], -sqrt(0.5), 1e-15);
  CU_ASSERT_DOUBLE_EQUAL(s->open[2].normal[1], sqrt(0.5), 1e-15);
  rhod_scene_free(s);
  /* the same segment, the normal given the other way round */
  const char *ov2[] = {"domain.max=[2, 0.2]", "open_boundaries.1.from=[1.5, 0]",
                       "open_boundaries.1.to=[1.5, 0.2]",
                       "open_boundaries.2={kind: outflow, from: [1.6, 0], to: [1.8, 0.2], normal: "
                       "[1, -0.2]}"};
  s = load_ok(CHANNEL, ov2, 4);
  if (!s)
    return;
  CU_ASSERT_DOUBLE_EQUAL(s->open[2].normal[0], sqrt(0.5), 1e-15);
  CU_ASSERT_DOUBLE_EQUAL(s->open[2].normal[1], -sqrt(0.5), 1e-15);
  rhod_scene_free(s);
}

/* every key given, the scene as run, loaded back */
static void test_round_trip(void) {
  const char *ov[] = {"open_boundaries.0.velocity=2",   "open_boundaries.0.profile=parabolic",
                      "open_boundaries.0.name=inlet",   "physics.gravity=[0, -9.81]",
                      "open_boundaries.0.surface=0.15", "refinement.levels=3",
                      "open_boundaries.1.dx=0.005"};
  rhod_scene *a = load_ok(CHANNEL, ov, 7);
  if (!a)
    return;
  CU_ASSERT_STRING_EQUAL(a->open[0].name, "inlet");
  CU_ASSERT_STRING_EQUAL(a->open[0].velocity, "2");
  CU_ASSERT_EQUAL(a->open[0].profile, RHOD_PROFILE_PARABOLIC);
  CU_ASSERT_EQUAL(a->open[0].surface_set, 1);
  CU_ASSERT_EQUAL(a->open[0].surface, 0.15);
  CU_ASSERT_EQUAL(a->open[1].dx, 0.005);
  CU_ASSERT_EQUAL(a->open[0].line, 21); /* the entry is the file's */
  const char *want = "\nopen_boundaries:\n- name: inlet\n  kind: inflow\n  from: [0, 0]\n  to: "
                     "[0, 0.2]\n  normal: [1, 0]\n  velocity: \"2\"\n  profile: parabolic\n  "
                     "surface: 0.15\n  dx: 0.02\n- name: open1\n  kind: outflow\n  from: [1, "
                     "0]\n  to: [1, 0.2]\n  normal: [-1, 0]\n  dx: 0.005\n";
  if (!strstr(a->yaml, want))
    fprintf(stderr, "\nscene as run:\n%s\n", a->yaml);
  CU_ASSERT_PTR_NOT_NULL(strstr(a->yaml, want));
  const char *tmp = "test_scene_open_as_run.yaml";
  FILE *f = fopen(tmp, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fputs(a->yaml, f);
  fclose(f);
  rhod_scene *b = load_ok(tmp, NULL, 0);
  remove(tmp);
  if (b) {
    CU_ASSERT_STRING_EQUAL(a->yaml, b->yaml);
    CU_ASSERT_EQUAL_FATAL(b->n_open, 2);
    CU_ASSERT_STRING_EQUAL(b->open[0].velocity, "2");
    CU_ASSERT_EQUAL(b->open[1].dx, 0.005);
  }
  rhod_param_list p;
  CU_ASSERT_EQUAL_FATAL(rhod_scene_params(a, &p), RHOD_OK);
  const char *v = param(&p, "open_boundaries.0.velocity");
  CU_ASSERT_TRUE(v && strcmp(v, "2") == 0);
  CU_ASSERT_PTR_NULL(param(&p, "open_boundaries.1.velocity")); /* an outflow's */
  CU_ASSERT_PTR_NULL(param(&p, "open_boundaries.1.surface"));  /* only when set */
  rhod_param_list_free(&p);
  rhod_scene_free(a);
  rhod_scene_free(b);
  /* an outflow's pressure and the fluid's ambient pressure (absent at 0, above) */
  CU_ASSERT_PTR_NULL(strstr(want, "pressure"));
  const char *amb[] = {"open_boundaries.1.pressure=1000", "fluid.0.ambient_pressure=-250.5"};
  a = load_ok(CHANNEL, amb, 2);
  if (a) {
    CU_ASSERT_EQUAL(a->open[1].pressure, 1000);
    CU_ASSERT_EQUAL(a->open[0].pressure, 0);
    CU_ASSERT_EQUAL(a->fluid[0].ambient_pressure, -250.5);
    CU_ASSERT_PTR_NOT_NULL(strstr(a->yaml, "  normal: [-1, 0]\n  pressure: 1000\n  dx: 0.02\n"));
    CU_ASSERT_PTR_NOT_NULL(strstr(a->yaml, "  ambient_pressure: -250.5\n"));
    FILE *g = fopen(tmp, "w");
    CU_ASSERT_PTR_NOT_NULL_FATAL(g);
    fputs(a->yaml, g);
    fclose(g);
    b = load_ok(tmp, NULL, 0);
    remove(tmp);
    if (b)
      CU_ASSERT_STRING_EQUAL(a->yaml, b->yaml);
    rhod_scene_free(b);
  }
  rhod_scene_free(a);
  /* none: no key */
  a = load_ok(GOOD("minimal.yaml"), NULL, 0);
  if (a) {
    CU_ASSERT_PTR_NULL(strstr(a->yaml, "open_boundaries"));
    CU_ASSERT_EQUAL(a->n_open, 0);
  }
  rhod_scene_free(a);
}

/* the default domain takes the segments' ends; a multiphase scene's phase */
static void test_domain_phase(void) {
  const char *ov[] = {"open_boundaries.0={kind: outflow, from: [1.5, 0], to: [1.5, 0.3]}"};
  rhod_scene *s = load_ok(GOOD("minimal.yaml"), ov, 1);
  if (s) {
    CU_ASSERT_EQUAL(s->domain_max[0], 1.5);
    CU_ASSERT_EQUAL(s->domain_max[1], 0.5);
    CU_ASSERT_EQUAL(s->open[0].normal[0], -1); /* the centre (0.75, 0.25) */
  }
  rhod_scene_free(s);
  const char *mp[] = {
      "phases.1={name: oil, rho0: 800, c: 20}",
      "open_boundaries.0={kind: inflow, from: [1.2, 0], to: [1.2, 0.5], phase: "
      "oil, velocity: -1}",
      "open_boundaries.1={kind: inflow, from: [1.3, 0], to: [1.3, 0.5], dx: "
      "0.0025}",
      "open_boundaries.2={kind: outflow, from: [1.4, 0], to: [1.4, 0.5], phase: 1}"};
  s = load_ok(GOOD("multiphase_minimal.yaml"), mp, 4);
  if (s) {
    CU_ASSERT_EQUAL_FATAL(s->n_open, 3);
    CU_ASSERT_EQUAL(s->open[0].phase, 1);
    CU_ASSERT_EQUAL(s->open[1].phase, 0); /* the default */
    CU_ASSERT_EQUAL(s->open[2].phase, 1);
    CU_ASSERT_EQUAL(s->open[1].dx, 0.0025); /* 2^-3: any k for the multiphase scheme */
    CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "  dx: 0.0025\n  phase: water\n"));
    CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "  phase: oil\n"));
  }
  rhod_scene_free(s);
}

/* one override per check: "--set ...: open_boundaries.N[.key]: reason" */
static void test_errors(void) {
  static const struct {
    const char *set, *key, *reason;
  } bad[] = {
      {"open_boundaries.0.kind=sink", "open_boundaries.0.kind", "invalid value 'sink'"},
      {"open_boundaries.2={from: [0.5, 0], to: [0.5, 0.2]}", "open_boundaries.2.kind",
       "missing required key"},
      {"open_boundaries.2={kind: outflow, to: [0.5, 0.2]}", "open_boundaries.2.from",
       "missing required key"},
      {"open_boundaries.0.to=[0, 0]", "open_boundaries.0.to", "the segment has no length"},
      {"open_boundaries.1.name=open0", "open_boundaries.1.name", "the name 'open0' is also"},
      {"open_boundaries.1.name=2out", "open_boundaries.1.name", "not an open boundary name"},
      {"open_boundaries.0.normal=[0, 0]", "open_boundaries.0.normal", "zero vector"},
      {"open_boundaries.0.normal=[0.1, 1]", "open_boundaries.0.normal", "lies along the segment"},
      {"open_boundaries.0.velocity=t+", "open_boundaries.0.velocity",
       "'t+' is not an expression of t"},
      {"open_boundaries.0.velocity=2*x", "open_boundaries.0.velocity", "unknown variable 'x'"},
      {"open_boundaries.1.velocity=1", "open_boundaries.1.velocity", "only for kind: inflow"},
      {"open_boundaries.1.profile=parabolic", "open_boundaries.1.profile", "only for kind: inflow"},
      {"open_boundaries.0.pressure=100", "open_boundaries.0.pressure", "only for kind: outflow"},
      {"open_boundaries.1.pressure=1e", "open_boundaries.1.pressure", "invalid number '1e'"},
      {"open_boundaries.0.surface=0.1", "open_boundaries.0.surface",
       "no effect without physics.gravity"},
      {"open_boundaries.0.dx=0", "open_boundaries.0.dx", "must be > 0"},
      {"open_boundaries.0.dx=0.015", "open_boundaries.0.dx", "not particles.dx (0.02 m) / 2^k"},
      {"open_boundaries.0.dx=0.04", "open_boundaries.0.dx", "not particles.dx"},
      {"open_boundaries.0.dx=0.01", "open_boundaries.0.dx", "finer than the finest level"},
      {"open_boundaries.0.phase=water", "open_boundaries.0.phase",
       "belongs to the multiphase scheme"},
      {"open_boundaries.0.to=[0, 0.3]", "open_boundaries.0", "to [0, 0.3] lies outside the domain"},
      {"open_boundaries.1.normal=[1, 0]", "open_boundaries.1",
       "the fluid (fluid.0) extends behind it"},
      {"open_boundaries.2={kind: outflow, from: [0.6, 0], to: [0.6, 0.2]}", "open_boundaries.2",
       "the fluid (fluid.0) extends behind it"},
      {"open_boundaries.2={kind: outflow, from: [0, 0.1], to: [0, 0.15]}", "open_boundaries.2",
       "overlaps open_boundaries.0"},
      {"open_boundaries.2={kind: outflow, from: [0.2, 0.2], to: [0.4, 0.2]}", "open_boundaries.2",
       "lies on walls.1: remove that wall edge"},
      {"bodies.0={rect: {min: [0.4, 0.05], max: [0.5, 0.1]}}", "open_boundaries.0",
       "lies on bodies.0"},
      {"domain.periodic=[true, false]", "open_boundaries.0",
       "a periodic axis across it: its normal [1, 0] has a component along x"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char err[1024] = "", want[512];
    rhod_scene *t = (rhod_scene *)1;
    const char *extra = NULL;
    /* the body case: an open boundary along the body's left edge */
    if (strncmp(bad[i].set, "bodies.0", 8) == 0)
      extra = "open_boundaries.0={kind: outflow, from: [0.4, 0.05], to: [0.4, 0.1]}";
    const char *o[] = {bad[i].set, extra};
    int rc = rhod_scene_load(CHANNEL, o, extra ? 2 : 1, &t, err, sizeof err);
    snprintf(want, sizeof want, ": %s: ", bad[i].key);
    int ok = rc == RHOD_ERR_SCENE && t == NULL && strstr(err, want) && strstr(err, bad[i].reason) &&
             !strchr(err, '\n');
    if (!ok)
      fprintf(stderr, "\n--set %s: rc %d, message '%s'\n", bad[i].set, rc, err);
    CU_ASSERT_TRUE(ok);
  }
}

/* the checks that need more than one override */
static void test_errors_more(void) {
  static const struct {
    const char *set[3];
    const char *key, *reason;
  } bad[] = {
      /* the domain's centre (0.5, 0.1) on the segment's line */
      {{"domain.max=[1, 0.4]",
        "open_boundaries.2={kind: outflow, from: [0.5, 0.25], to: [0.5, "
        "0.4]}",
        NULL},
       "open_boundaries.2",
       "give normal"},
      {{"physics.gravity=[0, -9.81]", "open_boundaries.0.surface=-0.01", NULL},
       "open_boundaries.0.surface",
       "negative depth"},
      {{"physics.gravity=[0, -9.81]", "open_boundaries.1.pressure=100", NULL},
       "open_boundaries.1.pressure",
       "needs surface under gravity"},
      /* crossing open_boundaries.0 away from the fluid */
      {{"domain.min=[-0.5, 0]",
        "open_boundaries.2={kind: outflow, from: [-0.1, 0.05], to: [0, "
        "0.15], normal: [-1, 1]}",
        NULL},
       "open_boundaries.2",
       "overlaps open_boundaries.0"},
      /* a T: its end on open_boundaries.0's middle */
      {{"domain.min=[-0.5, 0]",
        "open_boundaries.2={kind: outflow, from: [-0.1, 0.1], to: [0, "
        "0.1], normal: [0, 1]}",
        NULL},
       "open_boundaries.2",
       "overlaps open_boundaries.0"},
      {{"refinement.levels=2", "open_boundaries.0.dx=0.005", NULL},
       "open_boundaries.0.dx",
       "particles.dx / 2^2, finer than the finest level (refinement.levels: 2)"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char err[1024] = "", want[512];
    rhod_scene *t = (rhod_scene *)1;
    int n = bad[i].set[2] ? 3 : 2;
    int rc = rhod_scene_load(CHANNEL, bad[i].set, n, &t, err, sizeof err);
    snprintf(want, sizeof want, ": %s: ", bad[i].key);
    int ok = rc == RHOD_ERR_SCENE && t == NULL && strstr(err, want) && strstr(err, bad[i].reason) &&
             !strchr(err, '\n');
    if (!ok)
      fprintf(stderr, "\ncase %zu: rc %d, message '%s'\n", i, rc, err);
    CU_ASSERT_TRUE(ok);
  }
  /* sharing only an end is fine (open_boundaries.0's top end), as is the level above */
  const char *fine[] = {"domain.min=[-0.5, 0]", "domain.max=[1, 0.5]",
                        "open_boundaries.2={kind: outflow, from: [0, 0.2], to: [-0.2, 0.4]}"};
  rhod_scene *s = load_ok(CHANNEL, fine, 3);
  rhod_scene_free(s);
  const char *mp[] = {"open_boundaries.0={kind: outflow, from: [1.2, 0], to: [1.2, 0.5], phase: "
                      "oil}"};
  char err[1024] = "";
  s = (rhod_scene *)1;
  int rc = rhod_scene_load(GOOD("multiphase_minimal.yaml"), mp, 1, &s, err, sizeof err);
  CU_ASSERT_EQUAL(rc, RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, ": open_boundaries.0.phase: unknown phase 'oil'"));
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"defaults: name, normal toward the centre, velocity, profile, dx", test_defaults},
      {"an explicit normal on the other side, a slanted segment", test_normal},
      {"scene as run: every value, loads back identically", test_round_trip},
      {"default domain and the multiphase phase", test_domain_phase},
      {"one message per check", test_errors},
      {"the checks needing several overrides", test_errors_more},
  };
  return RHOD_RUN_TESTS("scene open boundaries", cases);
}
