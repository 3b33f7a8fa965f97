/* Open boundaries in the engine (include/rhod/open.h, src/open.c, kernels/open.c): the mass
 * exchange conserves mass exactly (the fluid's change is what the markers let in minus what
 * left, to round-off), a uniform stream stays exactly uniform through insertion and
 * deletion, a coupling callback drives an inflow, a negative imbalance at an inflow is
 * carried and taken from the next particles, the ghosts carry the inflow's velocity, and an
 * outflow's pressure relaxation brings a compressed channel back to rho0. */
#define _POSIX_C_SOURCE 200809L

#include "cunit_main.h"
#include "rhod/open.h"
#include "test_run_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifdef RHOD_SINGLE
#define REL 1e-5
#else
#define REL 1e-11
#endif

/* A channel [0, L] x [0, 0.2] between obstacle walls, an inflow at x = 0 and an outflow at
 * x = L; `extra` goes into the fluid block, `law` is the inflow's velocity, `phys` into
 * physics and `out` into the outflow's entry. */
static int channel(run *r, const char *tag, double L, const char *extra, const char *law,
                   const char *phys, const char *out) {
  char yaml[2048];
  snprintf(yaml, sizeof yaml,
           "time: {end: 1, output_every: 0.1}\n"
           "particles: {dx: 0.02}\n"
           "physics: {rho0: 1000, c0: 20%s}\n"
           "domain: {min: [0, 0], max: [%g, 0.2]}\n"
           "fluid:\n  - rect: {min: [0, 0], max: [%g, 0.2]}\n%s"
           "walls:\n"
           "  - rect: {min: [-0.1, -0.1], max: [%g, 0]}\n    fluid_inside: false\n"
           "  - rect: {min: [-0.1, 0.2], max: [%g, 0.3]}\n    fluid_inside: false\n"
           "open_boundaries:\n"
           "  - {kind: inflow, from: [0, 0], to: [0, 0.2], velocity: \"%s\"}\n"
           "  - {kind: outflow, from: [%g, 0], to: [%g, 0.2]%s}\n"
           "output: {picture: false}\n",
           phys, L, L, extra, L + 0.1, L + 0.1, law, L, L, out);
  return run_open_in(r, "test_open", tag, yaml);
}

static int steps(rhod_sim *s, int n) {
  char err[512] = "";
  for (int k = 0; k < n; k++) {
    if (rhod_sim_dt(s) != RHOD_OK || rhod_sim_step(s, s->dt, err, sizeof err) != RHOD_OK) {
      fprintf(stderr, "\nstep %d: %s\n", k, err);
      return 0;
    }
  }
  return 1;
}

static double pending(const rhod_open *o) {
  double sum = 0;
  for (int q = 0; q < o->nmark; q++)
    sum += o->pending[q];
  return sum;
}

/* A channel started from rest by a ramped inflow: particles are made and removed, and the
 * fluid's mass changes by exactly what came in minus what went out; the inflow takes what
 * its markers prescribe (paper 001 Eq. 20) less what it still carries. */
static void test_mass_exact(void) {
  run r;
  CU_ASSERT_FATAL(channel(&r, "mass", 0.6, "", "2*(1 - exp(-t/0.05))", "", ""));
  rhod_sim *s = r.sim;
  const rhod_open *o = &s->open;
  CU_ASSERT_EQUAL(o->n, 2);
  CU_ASSERT_EQUAL(o->nmark, 20);
  const double m0 = rhod_open_mass(&s->p);
  CU_ASSERT_DOUBLE_EQUAL(o->mass0, m0, 1e-12 * m0);
  CU_ASSERT_FATAL(steps(s, 200));
  const double m1 = rhod_open_mass(&s->p);
  CU_ASSERT(o->created > 20);
  CU_ASSERT(o->deleted > 20);
  CU_ASSERT(o->taken_in > 0.1 * m0);
  CU_ASSERT_DOUBLE_EQUAL(m1 - m0, o->taken_in - o->taken_out, REL * m0);
  CU_ASSERT_DOUBLE_EQUAL(o->taken_in, o->prescribed_in - pending(o), REL * m0);
  /* what the outflow took is what crossed it, by the particles' own motion */
  CU_ASSERT_DOUBLE_EQUAL(o->taken_out, o->prescribed_out, REL * m0);
  /* nobody beyond the open boundaries, every mass in (0, m0] */
  long bad = 0;
  for (size_t i = 0; i < s->p.n; i++)
    bad += s->p.x[i] < -REL || s->p.x[i] > 0.6 + REL || !(s->p.m[i] > 0) ||
           s->p.m[i] > 0.4 * (1 + REL);
  CU_ASSERT_EQUAL(bad, 0);
  run_close(&r);
}

/* Every particle of a uniform 1 m/s stream at rho0 = 1000, to round-off. */
static void assert_stream(const rhod_particles *p) {
  double du = 0, drho = 0;
  for (size_t i = 0; i < p->n; i++) {
    du = fmax(du, fabs(p->ux[i] - 1) + fabs(p->uy[i]));
    drho = fmax(drho, fabs(p->rho[i] - 1000));
  }
  CU_ASSERT(du < 1e3 * REL);
  CU_ASSERT(drho < 1e3 * REL * 1000);
}

/* A uniform stream at the inflow's speed is an exact solution: every particle keeps the
 * stream's velocity and density through 300 steps of insertion and deletion, the mass comes
 * back to its start at every full cycle of the markers, and the boundary particles tile the
 * channel (their masses and the gaps between the rows agree). */
static void test_uniform_stream(void) {
  run r;
  CU_ASSERT_FATAL(channel(&r, "uniform", 0.6, "    velocity: [1, 0]\n", "1", "", ""));
  rhod_sim *s = r.sim;
  const double m0 = rhod_open_mass(&s->p);
  CU_ASSERT_FATAL(steps(s, 300));
  const rhod_particles *p = &s->p;
  assert_stream(p);
  /* per row: the mass between the boundaries is rho0 dx (L) exactly */
  CU_ASSERT_DOUBLE_EQUAL(rhod_open_mass(p), m0, 1e3 * REL * m0);
  CU_ASSERT(s->open.created >= 10 * 14);
  run_close(&r);
}

/* Obstacle walls whose faces share their inside near convex vertices (ghosts.c face_share)
 * and run just past both open boundaries, in a domain box wider than the channel: their end
 * faces reach the last particles' mirrors, but the end faces' preimages lie beyond the open
 * boundaries, where no fluid stands, and take no share: every ghost carries its source's mass
 * (with the end faces sharing, 48 of them lose part of it), and the uniform stream
 * stays exact. */
static void test_walls_past_open_ends(void) {
  run r;
  const char *yaml = "time: {end: 1, output_every: 0.1}\n"
                     "particles: {dx: 0.02}\n"
                     "physics: {rho0: 1000, c0: 20}\n"
                     "domain: {min: [-0.4, -0.4], max: [1.0, 0.6]}\n"
                     "fluid:\n  - rect: {min: [0, 0], max: [0.6, 0.2]}\n"
                     "    velocity: [1, 0]\n"
                     "walls:\n"
                     "  - rect: {min: [-0.02, -0.3], max: [0.62, 0]}\n    fluid_inside: false\n"
                     "  - rect: {min: [-0.02, 0.2], max: [0.62, 0.5]}\n    fluid_inside: false\n"
                     "open_boundaries:\n"
                     "  - {kind: inflow, from: [0, 0], to: [0, 0.2], velocity: \"1\"}\n"
                     "  - {kind: outflow, from: [0.6, 0], to: [0.6, 0.2]}\n"
                     "output: {picture: false}\n";
  CU_ASSERT_FATAL(run_open_in(&r, "test_open", "past_ends", yaml));
  rhod_sim *s = r.sim;
  long lighter = 0;
  for (size_t g = s->p.n; g < s->p.n + s->p.ng; g++)
    lighter += s->p.m[g] != s->p.m[s->p.gsrc[g]];
  CU_ASSERT_EQUAL(lighter, 0);
  const double m0 = rhod_open_mass(&s->p);
  CU_ASSERT_FATAL(steps(s, 100));
  const rhod_particles *p = &s->p;
  assert_stream(p);
  CU_ASSERT_DOUBLE_EQUAL(rhod_open_mass(p), m0, 1e3 * REL * m0);
  run_close(&r);
}

/* A coupling surface (paper 001 Sec. 3.2): the inflow's velocity from a callback, here an
 * analytic field (a uniform 1.5 m/s stream); the run equals the one whose law says "1.5". */
static int stream(void *ctx, int b, int k, double t, double x, double y, double *u, double *v,
                  double *rho) {
  (void)b, (void)k, (void)t, (void)x, (void)y, (void)rho;
  *u = *(const double *)ctx;
  *v = 0;
  return 0;
}

static void test_coupling_callback(void) {
  run a, b;
  CU_ASSERT_FATAL(channel(&a, "law", 0.6, "", "1.5", "", ""));
  CU_ASSERT_FATAL(channel(&b, "callback", 0.6, "", "0", "", ""));
  double U = 1.5;
  rhod_open_couple(&b.sim->open, 0, stream, &U);
  CU_ASSERT_FATAL(steps(a.sim, 60));
  CU_ASSERT_FATAL(steps(b.sim, 60));
  CU_ASSERT_EQUAL(a.sim->p.n, b.sim->p.n);
  CU_ASSERT_DOUBLE_EQUAL(a.sim->open.taken_in, b.sim->open.taken_in, 1e-12);
  CU_ASSERT(a.sim->open.taken_in > 10);
  double dmax = 0;
  for (size_t i = 0; i < a.sim->p.n && a.sim->p.n == b.sim->p.n; i++)
    dmax = fmax(dmax, fabs(a.sim->p.x[i] - b.sim->p.x[i]) + fabs(a.sim->p.ux[i] - b.sim->p.ux[i]));
  CU_ASSERT(dmax < 1e-12);
  run_close(&a);
  run_close(&b);
}

/* An inflow whose law reverses (fluid drawn out through it): the negative imbalance drains
 * the boundary particles, the closest first; what they cannot give is carried to the next
 * steps (Eq. 26), and mass stays exact. */
static void test_negative_imbalance(void) {
  run r;
  CU_ASSERT_FATAL(channel(&r, "reverse", 0.6, "    velocity: [-0.5, 0]\n", "-0.5", "", ""));
  rhod_sim *s = r.sim;
  const double m0 = rhod_open_mass(&s->p);
  CU_ASSERT_FATAL(steps(s, 150));
  const rhod_open *o = &s->open;
  CU_ASSERT(o->prescribed_in < -0.01 * m0); /* mass left through the inflow */
  CU_ASSERT(o->deleted > 5);
  CU_ASSERT_DOUBLE_EQUAL(rhod_open_mass(&s->p) - m0, o->taken_in - o->taken_out, REL * m0);
  CU_ASSERT_DOUBLE_EQUAL(o->taken_in, o->prescribed_in - pending(o), REL * m0);
  run_close(&r);
}

/* The ghosts of an inflow carry its markers' velocity (T = 0), those of an outflow their
 * source's (T = I), and a particle near the corner of an inflow and a wall has a double
 * mirror whose velocity is the inflow's too. */
static void test_ghosts(void) {
  run r;
  CU_ASSERT_FATAL(channel(&r, "ghosts", 0.6, "    velocity: [0.3, 0.1]\n", "2", "", ""));
  rhod_sim *s = r.sim;
  const rhod_particles *p = &s->p;
  long nin = 0, nout = 0, ncorner = 0, bad = 0;
  for (size_t g = p->n; g < p->n + p->ng; g++) {
    const int k = p->gsrc[g];
    if (p->x[g] < 0) {
      nin++;
      ncorner += p->y[g] < 0 || p->y[g] > 0.2;
      bad += fabs(p->ux[g] - 2) > 1e-12 || fabs(p->uy[g]) > 1e-12;
    } else if (p->x[g] > 0.6) {
      nout++;
      bad += p->y[g] > 0 && p->y[g] < 0.2 &&
             (fabs(p->ux[g] - p->ux[k]) > 1e-12 || fabs(p->uy[g] - p->uy[k]) > 1e-12);
    }
  }
  CU_ASSERT_EQUAL(bad, 0);
  /* the corners' double mirrors: the particles within R of a corner (ghosts.c) */
  long near = 0;
  for (size_t i = 0; i < p->n; i++)
    for (int c = 0; c < 2; c++)
      near += hypot(p->x[i], p->y[i] - 0.2 * c) < 0.08;
  CU_ASSERT_EQUAL(near, 2 * 13);
  CU_ASSERT_EQUAL(nin, 10 * 4 + near);
  /* four columns, and the corners */ /* four columns, and the two corners' squares */
  CU_ASSERT_EQUAL(nout, 10 * 4 + near);
  CU_ASSERT_EQUAL(ncorner, near);
  run_close(&r);
}

/* An outflow's pressure relaxation (RHOD_OPEN_KAPPA): a channel at rest compressed by 1 %
 * with no inflow lets fluid out until its pressure is the ambient one. */
static void test_outflow_relaxation(void) {
  run r;
  CU_ASSERT_FATAL(channel(&r, "relax", 0.4, "", "0", "", ""));
  rhod_sim *s = r.sim;
  for (size_t i = 0; i < s->p.n; i++)
    s->p.rho[i] = 1010;
  rhod_particles_to_device(&s->p);
  s->neighbours_fresh = 0;
  CU_ASSERT_FATAL(steps(s, 1500)); /* 3 s, about 150 acoustic crossings */
  rhod_particles_to_host(&s->p);
  double rmax = 0;
  for (size_t i = 0; i < s->p.n; i++)
    rmax = fmax(rmax, fabs(s->p.rho[i] - 1000));
  CU_ASSERT(rmax < 0.5); /* from 10 */
  CU_ASSERT(s->open.taken_out > 0.005 * s->open.mass0);
  run_close(&r);
}

/* An ambient pressure (fluid.N.ambient_pressure, open_boundaries.N.pressure): a channel at
 * rest started at its outflow's pressure (2000 Pa, rho = 1000 + 2000/c0^2 = 1005) stays
 * there, nothing moves and the outflow takes only, in the first step, what of its boundary
 * row's cuboids (l = dx sqrt(rho/rho0), Eq. 23) lies beyond the segment; started at
 * 4000 Pa it lets fluid out until it is back at 2000 Pa, not at 0. */
static void test_ambient_pressure(void) {
  static const double start[2] = {2000, 4000};
  for (int k = 0; k < 2; k++) {
    run r;
    char extra[64];
    snprintf(extra, sizeof extra, "    ambient_pressure: %g\n", start[k]);
    CU_ASSERT_FATAL(
        channel(&r, k ? "ambient_high" : "ambient", 0.4, extra, "0", "", ", pressure: 2000"));
    rhod_sim *s = r.sim;
    double r0 = 0;
    for (size_t i = 0; i < s->p.n; i++) /* Eq. 2: rho = rho0 + P/c0^2 */
      r0 = fmax(r0, fabs(s->p.rho[i] - (1000 + start[k] / 400)));
    CU_ASSERT(r0 < 1e3 * REL * 1000);
    CU_ASSERT_FATAL(steps(s, 1));
    const double first = s->open.taken_out;
    CU_ASSERT_FATAL(steps(s, k ? 1500 : 300));
    rhod_particles_to_host(&s->p);
    double rmax = 0, umax = 0;
    for (size_t i = 0; i < s->p.n; i++) {
      rmax = fmax(rmax, fabs(s->p.rho[i] - 1005));
      umax = fmax(umax, hypot(s->p.ux[i], s->p.uy[i]));
    }
    if (k == 0) {
      CU_ASSERT(rmax < 1e3 * REL * 1000);
      CU_ASSERT(umax < 1e3 * REL);
      CU_ASSERT(first < 1e-4 * s->open.mass0);
      CU_ASSERT_DOUBLE_EQUAL(s->open.taken_out, first, REL * s->open.mass0);
    } else {
      CU_ASSERT(rmax < 0.5); /* from 5 */
      CU_ASSERT(s->open.taken_out > 0.003 * s->open.mass0);
    }
    run_close(&r);
  }
}

/* An inflow faster than one particle a step (15 m/s against dx/dt = 10 m/s): the mass waiting
 * at its markers grows until the run stops, naming the boundary; nothing is changed then. */
static void test_overwhelmed(void) {
  run r;
  CU_ASSERT_FATAL(channel(&r, "overwhelmed", 0.6, "", "15", "", ""));
  rhod_sim *s = r.sim;
  char err[512] = "";
  int st = RHOD_OK, k = 0;
  for (; k < 20 && st == RHOD_OK; k++) {
    CU_ASSERT_EQUAL_FATAL(rhod_sim_dt(s), RHOD_OK);
    st = rhod_sim_step(s, s->dt, err, sizeof err);
  }
  CU_ASSERT_EQUAL(st, RHOD_ERR_UNSTABLE);
  CU_ASSERT(k < 10);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "open boundary open0 (open_boundaries.0) is overwhelmed"));
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "more fluid comes in"));
  run_close(&r);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"mass in = mass out + change inside, to round-off", test_mass_exact},
      {"a uniform stream stays exactly uniform", test_uniform_stream},
      {"obstacle walls past the open ends share no mirror there", test_walls_past_open_ends},
      {"a coupling callback drives the inflow", test_coupling_callback},
      {"a negative imbalance is carried and taken", test_negative_imbalance},
      {"ghosts: inflow velocity, outflow copies, corners", test_ghosts},
      {"an outflow relaxes the pressure to the ambient", test_outflow_relaxation},
      {"an ambient pressure holds at the outflow's", test_ambient_pressure},
      {"an overwhelmed inflow stops the run, named", test_overwhelmed},
  };
  return RHOD_RUN_TESTS("open", cases);
}
