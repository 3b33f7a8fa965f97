/* Moving walls in the ghosts (kernels/ghosts.c, src/boundary.c): each wall segment
 * carries its edge's velocity, and a ghost's velocity is u' = T u_src + gU, gU = 2 u_wall
 * for a no-slip mirror, 0 for a free-slip one, the mean of the no-slip walls' 2 u_wall at
 * a corner's double mirror (docs/choices.md "moving walls at corners"), copied by
 * periodic images; 0 everywhere when no wall moves. RHOD-SPH's ghost state
 * (rhod_sph_fill_state) adds it. */
#define _POSIX_C_SOURCE 200809L

#include "cunit_main.h"
#include "rhod/boundary.h"
#include "rhod/rhodsph/sph.h"
#include "test_scene_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define DX 0.01
/* positions and velocities compared to within (single precision: float's digits) */
#ifdef RHOD_SINGLE
#define EPS 1e-5
#else
#define EPS 1e-12
#endif

typedef struct {
  rhod_scene *sc;
  rhod_wall w;
  rhod_particles p;
  rhod_boundary b;
} setup;

/* A rect wall [lo, hi] with the given slip, moving edges and velocity, and fluid
 * particles at pts (velocity vel each), ghosts built; everything on the host after. */
static void make(setup *t, const double lo[2], const double hi[2], int noslip, unsigned edges,
                 double ux, double uy, const double (*pts)[2], int np, const double *vel,
                 const double dlo[2], const double dhi[2], int periodic_x) {
  memset(t, 0, sizeof *t);
  t->sc = unit_scene(DX);
  t->w.shape.kind = RHOD_SHAPE_RECT;
  memcpy(t->w.shape.min, lo, sizeof t->w.shape.min);
  memcpy(t->w.shape.max, hi, sizeof t->w.shape.max);
  t->w.slip = noslip ? RHOD_SLIP_NO : RHOD_SLIP_FREE;
  t->w.fluid_inside = 1;
  t->w.velocity[0] = ux, t->w.velocity[1] = uy;
  t->w.moving_edges = edges;
  t->sc->walls = &t->w, t->sc->n_walls = 1;
  t->sc->periodic[0] = periodic_x;
  /* room for every ghost: the store does not grow (which would zero gU) */
  CU_ASSERT_EQUAL_FATAL(rhod_particles_init(&t->p, 64), RHOD_OK);
  rhod_particles *p = &t->p;
  /* garbage where gU will be written: it must be overwritten, zeros included */
  for (size_t k = 0; k < p->cap; k++)
    p->gU[2 * k] = p->gU[2 * k + 1] = (real)7;
  for (int i = 0; i < np; i++) {
    p->x[i] = (real)pts[i][0], p->y[i] = (real)pts[i][1];
    p->ux[i] = (real)vel[2 * i], p->uy[i] = (real)vel[2 * i + 1];
    p->rho[i] = 1000, p->m[i] = (real)(1000 * DX * DX), p->dx[i] = (real)DX, p->id[i] = (uint64_t)i;
  }
  p->n = (size_t)np;
  CU_ASSERT_EQUAL_FATAL(rhod_boundary_init(&t->b, t->sc, dlo, dhi), RHOD_OK);
  rhod_particles_to_device(p);
  CU_ASSERT_EQUAL_FATAL(rhod_ghosts_build(&t->b, p, 4, (real)(4 * DX)), RHOD_OK);
  const size_t nt = p->n + p->ng;
  rhod_to_host(p->x, nt * sizeof(real));
  rhod_to_host(p->y, nt * sizeof(real));
  rhod_to_host(p->gsrc, nt * sizeof(int32_t));
  rhod_to_host(p->gT, 4 * nt * sizeof(real));
  rhod_to_host(p->gU, 2 * nt * sizeof(real));
}

static void unmake(setup *t) {
  rhod_boundary_free(&t->b);
  rhod_particles_free(&t->p);
  free(t->sc);
}

/* The ghost of source i nearest to (x, y), or -1. */
static long ghost_at(const rhod_particles *p, size_t i, double x, double y) {
  for (size_t g = p->n; g < p->n + p->ng; g++)
    if ((size_t)p->gsrc[g] == i && fabs(p->x[g] - x) < 1e3 * EPS && fabs(p->y[g] - y) < 1e3 * EPS)
      return (long)g;
  return -1;
}

static int gu_is(const rhod_particles *p, long g, double ux, double uy) {
  return g >= 0 && fabs(p->gU[2 * g] - ux) < EPS && fabs(p->gU[2 * g + 1] - uy) < EPS;
}

/* The lid-driven cavity: the unit box, no slip, the top edge (2) moving at [1, 0]. */
static void test_lid(void) {
  const double lo[2] = {0, 0}, hi[2] = {1, 1};
  const double pts[][2] = {{0.5, 0.98}, {0.5, 0.02}, {0.02, 0.97}, {0.97, 0.98}};
  const double vel[8] = {0.3, -0.1, 0.2, 0.05, 0.1, 0.1, 0.4, -0.2};
  setup t;
  make(&t, lo, hi, 1, 1u << 2, 1, 0, pts, 4, vel, lo, hi, 0);
  rhod_particles *p = &t.p;
  CU_ASSERT_TRUE(t.b.moving);
  /* the segments carry their edge's velocity */
  CU_ASSERT(t.b.seg[RHOD_SEG_STRIDE * 2 + 8] == 1 && t.b.seg[RHOD_SEG_STRIDE * 2 + 9] == 0);
  for (int s = 0; s < 4; s++)
    if (s != 2)
      CU_ASSERT(t.b.seg[RHOD_SEG_STRIDE * s + 8] == 0 && t.b.seg[RHOD_SEG_STRIDE * s + 9] == 0);
  /* under the lid: gU = 2 u_lid, so (u + u')/2 = u_lid */
  const long top = ghost_at(p, 0, 0.5, 1.02);
  CU_ASSERT(gu_is(p, top, 2, 0));
  if (top >= 0) {
    const real *T = p->gT + 4 * top;
    const double ugx = T[0] * p->ux[0] + T[1] * p->uy[0] + p->gU[2 * top];
    const double ugy = T[2] * p->ux[0] + T[3] * p->uy[0] + p->gU[2 * top + 1];
    CU_ASSERT_DOUBLE_EQUAL(0.5 * (p->ux[0] + ugx), 1, EPS);
    CU_ASSERT_DOUBLE_EQUAL(0.5 * (p->uy[0] + ugy), 0, EPS);
  }
  /* the floor does not move */
  CU_ASSERT(gu_is(p, ghost_at(p, 1, 0.5, -0.02), 0, 0));
  /* top-left corner: the lid's mirror, the left wall's at rest, and the double mirror
   * (T = -I) with the mean of the two no-slip walls, 2 (u_lid + 0)/2 */
  CU_ASSERT(gu_is(p, ghost_at(p, 2, 0.02, 1.03), 2, 0));
  CU_ASSERT(gu_is(p, ghost_at(p, 2, -0.02, 0.97), 0, 0));
  const long cl = ghost_at(p, 2, -0.02, 1.03);
  CU_ASSERT(gu_is(p, cl, 1, 0));
  if (cl >= 0)
    CU_ASSERT(p->gT[4 * cl] == -1 && p->gT[4 * cl + 3] == -1);
  /* top-right corner: the same (both corners of the lid alike) */
  const long cr = ghost_at(p, 3, 1.03, 1.02);
  CU_ASSERT(gu_is(p, cr, 1, 0));
  CU_ASSERT_EQUAL(p->ng, 1 + 1 + 3 + 3);
  unmake(&t);
}

/* Two moving edges of a no-slip box meeting at a corner, and free slip. */
static void test_corner_and_free_slip(void) {
  const double lo[2] = {0, 0}, hi[2] = {1, 1};
  const double pts[][2] = {{0.98, 0.97}};
  const double vel[2] = {0, 0};
  setup t;
  /* right edge (1) and top edge (2) both move; a rect moves all its moving edges at one
   * velocity, so set the segments' velocities by hand: right along y, top along x */
  make(&t, lo, hi, 1, 0, 0, 0, pts, 1, vel, lo, hi, 0);
  real *S1 = t.b.seg + RHOD_SEG_STRIDE * 1, *S2 = t.b.seg + RHOD_SEG_STRIDE * 2;
  S1[8] = 0, S1[9] = (real)0.5, S2[8] = (real)-1, S2[9] = 0;
  rhod_to_device(t.b.seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)t.b.nseg);
  rhod_particles_to_device(&t.p);
  CU_ASSERT_EQUAL_FATAL(rhod_ghosts_build(&t.b, &t.p, 4, (real)(4 * DX)), RHOD_OK);
  rhod_particles *p = &t.p;
  const size_t nt = p->n + p->ng;
  rhod_to_host(p->x, nt * sizeof(real));
  rhod_to_host(p->y, nt * sizeof(real));
  rhod_to_host(p->gsrc, nt * sizeof(int32_t));
  rhod_to_host(p->gU, 2 * nt * sizeof(real));
  CU_ASSERT(gu_is(p, ghost_at(p, 0, 1.02, 0.97), 0, 1));    /* right: 2 (0, 0.5) */
  CU_ASSERT(gu_is(p, ghost_at(p, 0, 0.98, 1.03), -2, 0));   /* top: 2 (-1, 0) */
  CU_ASSERT(gu_is(p, ghost_at(p, 0, 1.02, 1.03), -1, 0.5)); /* corner: (U_a + U_b)/2 */
  unmake(&t);
  /* free slip: the lid's motion does not act, gU = 0 (T = J) */
  const double pts2[][2] = {{0.5, 0.98}, {0.02, 0.97}};
  const double vel2[4] = {0.3, 0.1, 0, 0};
  make(&t, lo, hi, 0, 1u << 2, 1, 0, pts2, 2, vel2, lo, hi, 0);
  p = &t.p;
  CU_ASSERT_EQUAL(p->ng, 1 + 3);
  for (size_t g = p->n; g < p->n + p->ng; g++)
    CU_ASSERT(gu_is(p, (long)g, 0, 0));
  unmake(&t);
}

/* Couette: periodic in x, the floor moving along x; the images of the floor's ghosts
 * copy their gU, the images of fluid particles have none. */
static void test_periodic(void) {
  const double lo[2] = {-1, 0}, hi[2] = {2, 1}, dlo[2] = {0, 0}, dhi[2] = {1, 1};
  const double pts[][2] = {{0.01, 0.02}, {0.5, 0.5}};
  const double vel[4] = {0.1, 0, 0, 0};
  setup t;
  make(&t, lo, hi, 1, 1u << 0, 1, 0, pts, 2, vel, dlo, dhi, 1);
  rhod_particles *p = &t.p;
  const long mirror = ghost_at(p, 0, 0.01, -0.02), image = ghost_at(p, 0, 1.01, -0.02);
  const long fimage = ghost_at(p, 0, 1.01, 0.02);
  CU_ASSERT(gu_is(p, mirror, 2, 0));
  CU_ASSERT(gu_is(p, image, 2, 0));
  CU_ASSERT(gu_is(p, fimage, 0, 0));
  CU_ASSERT_EQUAL(p->ng, 3);
  unmake(&t);
}

/* No wall moves: gU = 0 on every ghost, and RHOD-SPH's ghost velocity is T u exactly;
 * a moving wall: T u + gU. */
static void test_fill_state(void) {
  const double lo[2] = {0, 0}, hi[2] = {1, 1};
  const double pts[][2] = {{0.5, 0.98}, {0.02, 0.97}, {0.97, 0.02}};
  /* at rest, free slip: particle 0's mirror in the lid holds uy' = -0 * ux - uy = -0,
   * which adding a zero gU would turn into +0 */
  const double vel[6] = {0.3, 0, 0.1, 0.2, -0.4, 0.25};
  for (int moving = 0; moving < 2; moving++) {
    setup t;
    make(&t, lo, hi, moving, moving ? 1u << 2 : 0, moving ? 1 : 0, 0, pts, 3, vel, lo, hi, 0);
    rhod_particles *p = &t.p;
    CU_ASSERT_EQUAL(t.b.moving, moving);
    rhod_sph s;
    CU_ASSERT_EQUAL_FATAL(rhod_sph_init(&s, t.sc, p), RHOD_OK);
    CU_ASSERT_EQUAL(s.walls_move, moving);
    const size_t nt = p->n + p->ng;
    int some = 0;
    for (size_t g = p->n; g < nt; g++)
      some += p->gU[2 * g] != 0;
    CU_ASSERT_EQUAL(some, moving ? 3 : 0); /* two mirrors in the lid, a corner ghost */
    if (moving) {                          /* both components of gU, whatever they are */
      for (size_t g = p->n; g < nt; g++)
        p->gU[2 * g] += (real)(0.01 * (double)g), p->gU[2 * g + 1] = (real)(-0.02 * (double)g);
      rhod_to_device(p->gU, 2 * nt * sizeof(real));
    }
    rhod_sph_fill_state(&s, p);
    rhod_to_host(p->ux, nt * sizeof(real));
    rhod_to_host(p->uy, nt * sizeof(real));
    int ok = 1, negzero = 0;
    for (size_t g = p->n; g < nt; g++) {
      const int k = p->gsrc[g];
      const real *T = p->gT + 4 * g;
      const real tx = T[0] * p->ux[k] + T[1] * p->uy[k], ty = T[2] * p->ux[k] + T[3] * p->uy[k];
      if (!moving)
        ok &= p->gU[2 * g] == 0 && p->gU[2 * g + 1] == 0 && !memcmp(&p->ux[g], &tx, sizeof tx) &&
              !memcmp(&p->uy[g], &ty, sizeof ty),
            negzero += ty == 0 && signbit(ty);
      else
        ok &= fabs(p->ux[g] - (tx + p->gU[2 * g])) < EPS &&
              fabs(p->uy[g] - (ty + p->gU[2 * g + 1])) < EPS;
    }
    CU_ASSERT(ok);
    CU_ASSERT(moving || negzero > 0);
    unmake(&t);
  }
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"lid-driven box: mirrors and corners carry the lid", test_lid},
      {"two moving edges at a corner; free slip", test_corner_and_free_slip},
      {"periodic images copy their source's gU", test_periodic},
      {"RHOD-SPH ghost velocity T u + gU, exactly T u at rest", test_fill_state},
  };
  return RHOD_RUN_TESTS("walls_moving", cases);
}
