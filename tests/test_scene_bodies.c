/* The scene's bodies (src/scene_bodies.c, issue 51): every key and its resolved default
 * (centre, mass, inertia by hand for a rect, a triangle and circles), the law's value at
 * t = 0, the scene as run and the parameters, `--set`, the default domain, the placement
 * checks a periodic axis relaxes, and the fill leaving a body's interior empty where it
 * stands at t = 0 (src/sim.c). The malformed bodies are tests/scenes/bad/body_*.yaml
 * (test_scene.c). */
#define _POSIX_C_SOURCE 200809L

#include "rhod/sim.h"
#include "test_run_util.h"
#include "test_scene_load.h"

#include <math.h>
#include <matheval.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* relative 1e-12 (the loader works in double in both builds) */
#define REL(a, b) CU_ASSERT_DOUBLE_EQUAL((a), (b), 1e-12 * fabs((double)(b)))

/* tests/scenes/good/bodies.yaml by hand:
 * box: rect 0.2 x 0.1, mass 2: G the rect's centre, I = M (w^2 + h^2)/12;
 * tri: right triangle with legs a = 0.3 (x), b = 0.4 (y) at (1, 0.2), density 500:
 *   A = a b/2 = 0.06, M = 30, G = (1 + a/3, 0.2 + b/3), I = M (a^2 + b^2)/18;
 * cyl: imposed, law y = 0.05 cos(2 pi t): displaced by 0.05 at t = 0;
 * body3: circle r = 0.1, mass 20, about G = centre + (0.05, 0): I = M r^2/2 + M 0.05^2;
 * body4: fixed L of a 0.3 x 0.1 and a 0.1 x 0.2 rect: G = area-weighted centroids =
 *   ((0.03 0.25 + 0.02 0.15)/0.05, (0.03 1.15 + 0.02 1.3)/0.05) = (0.21, 1.21). */
static void check_resolved(const rhod_scene *s) {
  CU_ASSERT_EQUAL_FATAL(s->n_bodies, 5);
  const rhod_body *b = s->bodies;
  CU_ASSERT_STRING_EQUAL(b[0].name, "box");
  CU_ASSERT_EQUAL(b[0].shape.kind, RHOD_SHAPE_RECT);
  CU_ASSERT_EQUAL(b[0].motion, RHOD_MOTION_FREE);
  CU_ASSERT_EQUAL(b[0].slip, RHOD_SLIP_FREE);
  CU_ASSERT_EQUAL(b[0].refine, 1);
  REL(b[0].center[0], 0.3);
  REL(b[0].center[1], 0.25);
  REL(b[0].mass, 2);
  CU_ASSERT_EQUAL(b[0].density, 0);
  REL(b[0].inertia, 2 * (0.2 * 0.2 + 0.1 * 0.1) / 12);
  CU_ASSERT_FALSE(b[0].lock[0] || b[0].lock[1] || b[0].lock[2]);

  CU_ASSERT_STRING_EQUAL(b[1].name, "tri");
  CU_ASSERT_EQUAL(b[1].shape.kind, RHOD_SHAPE_POLYGON);
  CU_ASSERT_EQUAL(b[1].slip, RHOD_SLIP_NO);
  CU_ASSERT_EQUAL(b[1].refine, 0);
  REL(b[1].center[0], 1 + 0.3 / 3);
  REL(b[1].center[1], 0.2 + 0.4 / 3);
  REL(b[1].density, 500);
  REL(b[1].mass, 30);
  REL(b[1].inertia, 30 * (0.3 * 0.3 + 0.4 * 0.4) / 18);
  CU_ASSERT_TRUE(b[1].lock[RHOD_DOF_X] && !b[1].lock[RHOD_DOF_Y] && b[1].lock[RHOD_DOF_THETA]);

  CU_ASSERT_STRING_EQUAL(b[2].name, "cyl");
  CU_ASSERT_EQUAL(b[2].motion, RHOD_MOTION_IMPOSED);
  CU_ASSERT_PTR_NULL(b[2].law[RHOD_DOF_X]);
  CU_ASSERT_STRING_EQUAL(b[2].law[RHOD_DOF_Y], "0.05*cos(2*pi*t)");
  CU_ASSERT_STRING_EQUAL(b[2].law[RHOD_DOF_THETA], "0.1*t");
  REL(b[2].pose0[RHOD_DOF_Y], 0.05);
  CU_ASSERT_EQUAL(b[2].pose0[RHOD_DOF_X], 0);
  CU_ASSERT_EQUAL(b[2].pose0[RHOD_DOF_THETA], 0);
  REL(b[2].center[0], 1.6);
  REL(b[2].center[1], 0.5);
  CU_ASSERT_EQUAL(b[2].mass, 0);

  CU_ASSERT_STRING_EQUAL(b[3].name, "body3"); /* the default name */
  REL(b[3].center[0], 0.55);
  REL(b[3].mass, 20);
  REL(b[3].inertia, 20 * (0.1 * 0.1 / 2 + 0.05 * 0.05));
  REL(b[3].velocity[0], 0.1);
  CU_ASSERT_EQUAL(b[3].velocity[1], 0);
  REL(b[3].omega, 1);
  REL(b[3].added_mass, 25);
  CU_ASSERT(b[0].added_mass < 0); /* not given: rho0 x area, resolved by the run */

  CU_ASSERT_STRING_EQUAL(b[4].name, "body4");
  CU_ASSERT_EQUAL(b[4].motion, RHOD_MOTION_FIXED);
  REL(b[4].center[0], 0.21);
  REL(b[4].center[1], 1.21);
  CU_ASSERT_EQUAL(b[4].mass, 0);
  CU_ASSERT_EQUAL(b[4].inertia, 0);
}

static void test_resolved(void) {
  rhod_scene *s = load_ok(GOOD("bodies.yaml"), NULL, 0);
  if (s)
    check_resolved(s);
  rhod_scene_free(s);
  /* the triangle given clockwise: stored counter-clockwise, the same values */
  const char *cw[] = {"bodies.1.polygon=[[1, 0.2], [1, 0.6], [1.3, 0.2]]"};
  s = load_ok(GOOD("bodies.yaml"), cw, 1);
  if (s) {
    REL(s->bodies[1].center[0], 1.1);
    REL(s->bodies[1].inertia, 30 * 0.25 / 18);
  }
  rhod_scene_free(s);
  /* a rect about a given centre (its corner): I = M (w^2 + h^2)/3 */
  const char *corner[] = {"bodies.0.center=[0.2, 0.2]"};
  s = load_ok(GOOD("bodies.yaml"), corner, 1);
  if (s)
    REL(s->bodies[0].inertia, 2 * (0.2 * 0.2 + 0.1 * 0.1) / 3);
  rhod_scene_free(s);
  /* an inertia given is kept; mass and density together when they agree (scene as run) */
  const char *given[] = {"bodies.0.inertia=0.5", "bodies.1.mass=30.000000000000014"};
  s = load_ok(GOOD("bodies.yaml"), given, 2);
  if (s) {
    REL(s->bodies[0].inertia, 0.5);
    REL(s->bodies[1].mass, 30);
  }
  rhod_scene_free(s);
}

/* The scene as run holds every resolved value and loads back to the same scene. */
static void test_round_trip(void) {
  rhod_scene *a = load_ok(GOOD("bodies.yaml"), NULL, 0);
  if (!a)
    return;
  CU_ASSERT_PTR_NOT_NULL(strstr(a->yaml, "\nbodies:\n- name: box\n"));
  CU_ASSERT_PTR_NOT_NULL(strstr(a->yaml, "law: {y: 0.05*cos(2*pi*t), theta: 0.1*t}"));
  CU_ASSERT_PTR_NOT_NULL(strstr(a->yaml, "inertia: 0.4166666666666667\n"));
  CU_ASSERT_PTR_NOT_NULL(strstr(a->yaml, "center: [0.21000000000000002, 1.21]\n"));
  const char *tmp = "test_scene_bodies_as_run.yaml";
  FILE *f = fopen(tmp, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fputs(a->yaml, f);
  fclose(f);
  rhod_scene *b = load_ok(tmp, NULL, 0);
  remove(tmp);
  if (b) {
    CU_ASSERT_STRING_EQUAL(a->yaml, b->yaml);
    check_resolved(b);
    for (unsigned i = 0; i < a->n_bodies && i < b->n_bodies; i++) {
      const rhod_body *x = &a->bodies[i], *y = &b->bodies[i];
      CU_ASSERT_EQUAL(x->mass, y->mass);
      CU_ASSERT_EQUAL(x->density, y->density);
      CU_ASSERT_EQUAL(x->inertia, y->inertia);
      CU_ASSERT_EQUAL(x->added_mass, y->added_mass);
      CU_ASSERT_EQUAL(x->center[0], y->center[0]);
      CU_ASSERT_EQUAL(x->center[1], y->center[1]);
      for (int k = 0; k < RHOD_NDOF; k++) {
        CU_ASSERT_EQUAL(x->pose0[k], y->pose0[k]);
        CU_ASSERT_EQUAL(x->lock[k], y->lock[k]);
        CU_ASSERT_TRUE((!x->law[k] && !y->law[k]) ||
                       (x->law[k] && y->law[k] && !strcmp(x->law[k], y->law[k])));
      }
    }
  }
  rhod_scene_free(a);
  rhod_scene_free(b);
  /* no bodies: no key (the scenes as run of older runs stay as they were) */
  a = load_ok(GOOD("minimal.yaml"), NULL, 0);
  if (a) {
    CU_ASSERT_PTR_NULL(strstr(a->yaml, "bodies"));
    CU_ASSERT_EQUAL(a->n_bodies, 0);
    CU_ASSERT_PTR_NULL(a->bodies);
  }
  rhod_scene_free(a);
}

static void test_params(void) {
  rhod_scene *s = load_ok(GOOD("bodies.yaml"), NULL, 0);
  if (!s)
    return;
  rhod_param_list p;
  CU_ASSERT_EQUAL_FATAL(rhod_scene_params(s, &p), RHOD_OK);
  const struct {
    const char *key, *value;
  } want[] = {
      {"bodies.0.name", "box"},
      {"bodies.0.motion", "free"},
      {"bodies.0.center", "[0.30000000000000004, 0.25]"},
      {"bodies.0.inertia", "0.008333333333333331"},
      {"bodies.1.slip", "no"},
      {"bodies.1.refine", "false"},
      {"bodies.1.density", "500"},
      {"bodies.1.mass", "30.000000000000014"},
      {"bodies.1.lock", "[x, theta]"},
      {"bodies.2.law.y", "0.05*cos(2*pi*t)"},
      {"bodies.2.law.theta", "0.1*t"},
      {"bodies.3.name", "body3"},
      {"bodies.3.velocity", "[0.1, 0]"},
      {"bodies.3.omega", "1"},
      {"bodies.4.motion", "fixed"},
      {"bodies.4.center", "[0.21000000000000002, 1.21]"},
  };
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
    const char *v = param(&p, want[i].key);
    if (!v || strcmp(v, want[i].value) != 0)
      fprintf(stderr, "\n%s: '%s', expected '%s'\n", want[i].key, v ? v : "(none)", want[i].value);
    CU_ASSERT_TRUE(v && strcmp(v, want[i].value) == 0);
  }
  CU_ASSERT_PTR_NULL(param(&p, "bodies.4.mass"));  /* only for free bodies */
  CU_ASSERT_PTR_NULL(param(&p, "bodies.2.law.x")); /* the texts as given */
  rhod_param_list_free(&p);
  rhod_scene_free(s);
}

static void test_overrides(void) {
  const char *ov[] = {"bodies.0.slip=no", "bodies.2.law.x=0.2*t", "bodies.4.refine=false",
                      "bodies.5={circle: {center: [1.8, 1.3], radius: 0.05}}",
                      "bodies.3.lock=[theta]"};
  rhod_scene *s = load_ok(GOOD("bodies.yaml"), ov, 5);
  if (!s)
    return;
  CU_ASSERT_EQUAL_FATAL(s->n_bodies, 6);
  CU_ASSERT_EQUAL(s->bodies[0].slip, RHOD_SLIP_NO);
  CU_ASSERT_STRING_EQUAL(s->bodies[2].law[RHOD_DOF_X], "0.2*t");
  CU_ASSERT_EQUAL(s->bodies[4].refine, 0);
  CU_ASSERT_STRING_EQUAL(s->bodies[5].name, "body5");
  CU_ASSERT_EQUAL(s->bodies[5].motion, RHOD_MOTION_FIXED);
  CU_ASSERT_TRUE(s->bodies[3].lock[RHOD_DOF_THETA] && !s->bodies[3].lock[RHOD_DOF_X]);
  rhod_scene_free(s);

  static const struct {
    const char *set, *key, *reason;
  } bad[] = {
      {"bodies.1.mass=-1", "bodies.1.mass", "must be > 0, got -1"},
      {"bodies.4.mass=1", "bodies.4.mass", "only for motion: free (this body's motion is fixed)"},
      {"bodies.4.omega=1", "bodies.4.omega", "only for motion: free"},
      {"bodies.2.velocity=[1, 0]", "bodies.2.velocity", "only for motion: free"},
      {"bodies.0.law={x: t}", "bodies.0.law", "only for motion: imposed"},
      {"bodies.2.law.x=t+", "bodies.2.law.x", "'t+' is not an expression"},
      {"bodies.2.law.theta=log(t)", "bodies.2.law.theta", "its value at t = 0 is -inf"},
      {"bodies.2.law.y=abs(t)", "bodies.2.law.y", "its second derivative at t = 0"},
      {"bodies.2.law.y=T", "bodies.2.law.y", "unknown variable 'T'"},
      {"bodies.3.name=box", "bodies.3.name", "the name 'box' is also bodies.0's"},
      {"bodies.3.slip=sticky", "bodies.3.slip", "invalid value 'sticky'"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char err[1024] = "", want[512];
    rhod_scene *t = (rhod_scene *)1;
    const char *o[] = {bad[i].set};
    int rc = rhod_scene_load(GOOD("bodies.yaml"), o, 1, &t, err, sizeof err);
    snprintf(want, sizeof want, "--set %s: %s: ", bad[i].set, bad[i].key);
    int ok = rc == RHOD_ERR_SCENE && t == NULL && strncmp(err, want, strlen(want)) == 0 &&
             strstr(err, bad[i].reason) && !strchr(err, '\n');
    if (!ok)
      fprintf(stderr, "\n--set %s: rc %d, message '%s'\n", bad[i].set, rc, err);
    CU_ASSERT_TRUE(ok);
  }
  /* a placement error points at the body (here in the file) */
  char err[1024] = "";
  rhod_scene *t = (rhod_scene *)1;
  const char *up[] = {"bodies.2.circle.center=[1.6, 1.45]"};
  CU_ASSERT_EQUAL(rhod_scene_load(GOOD("bodies.yaml"), up, 1, &t, err, sizeof err), RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(
      strstr(err, "bodies.yaml:23:5: bodies.2: crosses the boundary of walls.0"));
}

/* The laws' own parser (libmatheval leaks on a syntax error and echoes unknown characters,
 * so it sees only laws that parse) agrees with libmatheval: every law here that libmatheval
 * reads loads, every one it refuses is refused before it reaches it. */
static void test_law_syntax(void) {
  static const char *const good[] = {
      "--t",     "-t^2",     "2^-t",         "1.e3*t",        ".5*t",         "e^t",
      "log2e*t", "1_pi*t",   "2_sqrtpi + t", "erf(t)",        "  sin ( t ) ", "t^2^3",
      "-(-(t))", "1.5E+2*t", "1e-3*t",       "sqrt2*sinh(t)", "t-1e2",        "pi_2*cos(2_pi*t)"};
  for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
    char set[128];
    snprintf(set, sizeof set, "bodies.2.law.theta=%s", good[i]);
    const char *ov[] = {set};
    char err[1024] = "";
    rhod_scene *s = NULL;
    const int rc = rhod_scene_load(GOOD("bodies.yaml"), ov, 1, &s, err, sizeof err);
    if (rc != RHOD_OK)
      fprintf(stderr, "\n%s: %s\n", good[i], err);
    CU_ASSERT_EQUAL(rc, RHOD_OK);
    rhod_scene_free(s);
    char *copy = strdup(good[i]);
    void *ev = evaluator_create(copy);
    CU_ASSERT_PTR_NOT_NULL(ev);
    if (ev)
      evaluator_destroy(ev);
    free(copy);
  }
  static const char *const bad[] = {"2t",       "t t",   "sin t", "+t",   "()",   "sin(t)(t)",
                                    "max(t,1)", "t @ 2", "a.b",   "1e",   "t,",   "sin",
                                    "t^",       "((t)",  "t)",    "1ee3", "t*/t", "."};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char set[128];
    snprintf(set, sizeof set, "bodies.2.law.theta=%s", bad[i]);
    const char *ov[] = {set};
    char err[1024] = "";
    rhod_scene *s = (rhod_scene *)1;
    const int rc = rhod_scene_load(GOOD("bodies.yaml"), ov, 1, &s, err, sizeof err);
    const int ok = rc == RHOD_ERR_SCENE && !s && strstr(err, "is not an expression of t");
    if (!ok)
      fprintf(stderr, "\n%s: rc %d: %s\n", bad[i], rc, err);
    CU_ASSERT_TRUE(ok);
  }
  /* nesting and length are bounded (libmatheval's evaluation recurses) */
  char deep[256] = "", set[300];
  for (int k = 0; k < 70; k++)
    strcat(deep, "(");
  strcat(deep, "t");
  for (int k = 0; k < 70; k++)
    strcat(deep, ")");
  snprintf(set, sizeof set, "bodies.2.law.theta=%s", deep);
  const char *ov[] = {set};
  char err[1024];
  rhod_scene *s = NULL;
  CU_ASSERT_EQUAL(rhod_scene_load(GOOD("bodies.yaml"), ov, 1, &s, err, sizeof err), RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "at character 65"));
}

/* Loads scene text written to a file; NULL (message in err) when it fails. */
static rhod_scene *load_text(const char *tag, const char *yaml, char *err, size_t len) {
  char path[128];
  snprintf(path, sizeof path, "test_scene_bodies_%s.yaml", tag);
  FILE *f = fopen(path, "w");
  if (!f)
    return NULL;
  fputs(yaml, f);
  fclose(f);
  rhod_scene *s = NULL;
  err[0] = '\0';
  rhod_scene_load(path, NULL, 0, &s, err, len);
  remove(path);
  return s;
}

#define HEAD "time: {end: 0.01, output_every: 0.01}\nparticles: {dx: 0.01}\nphysics: {c0: 20}\n"

/* The default domain covers the bodies where they stand at t = 0; a body may cross a
 * periodic boundary, not a closed one; the multiphase scheme takes bodies too. */
static void test_domain(void) {
  char err[1024];
  rhod_scene *s = load_text("box",
                            HEAD "fluid:\n  - rect: {min: [0, 0], max: [1, 0.5]}\n"
                                 "bodies:\n  - circle: {center: [0.5, 0.9], radius: 0.2}\n"
                                 "    motion: imposed\n    law: {y: 0.1 + t, x: -0.6*cos(t)}\n",
                            err, sizeof err);
  CU_ASSERT_PTR_NOT_NULL(s);
  if (s) {
    REL(s->domain_max[1], 1.2);
    REL(s->domain_min[0], -0.3);
    REL(s->domain_max[0], 1);
    CU_ASSERT_EQUAL(s->domain_min[1], 0);
  }
  rhod_scene_free(s);
  const char *periodic = HEAD "domain: {min: [0, 0], max: [1, 1], periodic: [true, false]}\n"
                              "fluid:\n  - rect: {min: [0, 0], max: [1, 0.5]}\n"
                              "bodies:\n  - circle: {center: [0, 0.7], radius: 0.1}\n";
  s = load_text("periodic", periodic, err, sizeof err);
  CU_ASSERT_PTR_NOT_NULL(s);
  rhod_scene_free(s);
  const char *closed = HEAD "domain: {min: [0, 0], max: [1, 1], periodic: [false, true]}\n"
                            "fluid:\n  - rect: {min: [0, 0], max: [1, 0.5]}\n"
                            "bodies:\n  - circle: {center: [0, 0.7], radius: 0.1}\n";
  s = load_text("closed", closed, err, sizeof err);
  CU_ASSERT_PTR_NULL(s);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, ": bodies.0: lies outside the domain"));
  rhod_scene_free(s);
  const char *ov[] = {"bodies.0={circle: {center: [0.5, 0.8], radius: 0.1}, motion: free, "
                      "density: 2000}"};
  s = load_ok(GOOD("multiphase_minimal.yaml"), ov, 1);
  if (s) {
    CU_ASSERT_EQUAL(s->n_bodies, 1);
    REL(s->bodies[0].mass, 2000 * M_PI * 0.01);
  }
  rhod_scene_free(s);
}

/* The fill leaves the body's interior empty where the law puts it at t = 0: the rect
 * [0.4, 0.6] x [0.45, 0.55] about G = (0.4, 0.5) (its left edge's middle), moved by
 * (0.1, -0.05) and turned by pi/2 counter-clockwise, covers [0.45, 0.55] x [0.45, 0.65]
 * (turned clockwise it would cover y in [0.25, 0.45]): 10 x 20 lattice points of dx = 0.01.
 * Of its rest position, the strips x in [0.4, 0.45] and [0.55, 0.6] hold fluid. */
static void test_fill(void) {
  run r;
  const char *yaml = HEAD "fluid:\n  - rect: {min: [0, 0], max: [1, 1]}\n"
                          "bodies:\n  - rect: {min: [0.4, 0.45], max: [0.6, 0.55]}\n"
                          "    center: [0.4, 0.5]\n    motion: imposed\n"
                          "    law: {x: 0.1 + 0.05*t, y: -0.05*cos(t), theta: pi/2 + t}\n";
  if (!run_open_in(&r, "test_scene_bodies", "fill", yaml)) {
    CU_FAIL("set-up");
    run_close(&r);
    return;
  }
  const rhod_particles *p = &r.sim->p;
  CU_ASSERT_EQUAL(p->n, 100 * 100 - 200);
  CU_ASSERT_EQUAL(r.sim->fill[0].in_body, 200);
  CU_ASSERT_EQUAL(r.sim->fill[0].body, 0);
  size_t inside = 0, at_rest = 0;
  for (size_t k = 0; k < p->n; k++) {
    const double x = p->x[k], y = p->y[k];
    inside += x > 0.45 && x < 0.55 && y > 0.45 && y < 0.65;
    at_rest += ((x > 0.4 && x < 0.45) || (x > 0.55 && x < 0.6)) && y > 0.45 && y < 0.55;
  }
  CU_ASSERT_EQUAL(inside, 0);
  CU_ASSERT_EQUAL(at_rest, 2 * 5 * 10);
  char w[2048];
  CU_ASSERT_EQUAL(rhod_sim_warnings(r.sim, w, sizeof w), 1);
  CU_ASSERT_PTR_NOT_NULL(strstr(w, "200 of the 10000 particles of its lattice are left out: 200 "
                                   "inside the body bodies.0"));
  run_close(&r);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"resolved centre, mass and inertia (rect, triangle, circle, L)", test_resolved},
      {"scene as run: every value, loads back identically", test_round_trip},
      {"flattened parameters", test_params},
      {"--set on bodies and its errors", test_overrides},
      {"the laws' syntax agrees with libmatheval's", test_law_syntax},
      {"default domain, periodic axes, multiphase", test_domain},
      {"the fill leaves the body empty at its t = 0 pose", test_fill},
  };
  return RHOD_RUN_TESTS("scene bodies", cases);
}
