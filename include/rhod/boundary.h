/* Solid walls and periodic boundaries as ghost particles (paper 002 Sec. IV A:
 * "mirrored ghost particles", Refs. 17 and 42). Engine side only: where the ghosts
 * are and how vectors map into them. Which values they carry (pressure with the
 * hydrostatic correction, mirrored gradients) is the scheme's business.
 *
 * A ghost g of fluid particle s: x_g = J x_s + c, velocity u_g = T u_s + U_g (U_g the
 * moving wall's part, 0 where no wall moves), and the displacement e_g = x_g - x_s of
 * its wall mirror (zero for pure periodic images). */
#ifndef RHOD_BOUNDARY_H
#define RHOD_BOUNDARY_H

#include "rhod/config.h"
#include "rhod/particles.h"
#include "rhod/scene.h"
#include <math.h>

#define RHOD_SEG_STRIDE                                                                            \
  15 /* ax, ay, nx, ny, tx, ty, length, kind (RHOD_SEG_*), ux, uy (a wall edge's velocity along    \
        itself, walls.N.velocity; 0 at rest), body (its index, -1 for a wall or an open            \
        boundary), first, count (the outline's segments; an open boundary's markers), refine (1:   \
        refinement criterion 4 near it), share (1: a body's or an obstacle wall's face, whose      \
        mirrors share its inside near a convex vertex: ghosts.c face_share) */
/* S[7], what a segment is: a wall or body with free or no slip, or an open boundary
 * (open.h) whose mirrors carry the inflow's velocity (T = 0, U = the marker's) or the
 * fluid's (an outflow: T = I, U = 0) */
#define RHOD_SEG_FREE 0
#define RHOD_SEG_NOSLIP 1
#define RHOD_SEG_INFLOW 2
#define RHOD_SEG_OUTFLOW 3
#define RHOD_CIRC_STRIDE                                                                           \
  7 /* cx, cy, radius, side (+1 fluid inside, -1 outside), noslip, body (-1: a wall), refine */
/* per body: G (x, y), its velocity (u, v), angular velocity Omega, G's acceleration (x, y),
 * angular acceleration: the kinematics of a body's boundary (u_w = U + Omega x (x_w - G),
 * a_w = A + dOmega/dt x r - Omega^2 r, r = x_w - G) */
#define RHOD_KIN_STRIDE 8

typedef struct {
  int nseg, ncorner, ncirc;
  real *seg;       /* nseg * RHOD_SEG_STRIDE; n is the normal pointing into the fluid */
  int32_t *corner; /* ncorner * 2: segments meeting at a corner that needs a double mirror */
  real *circ;      /* ncirc * RHOD_CIRC_STRIDE */
  int moving;      /* some segment has a non-zero velocity, or some body moves */
  int noslip;      /* some wall or body is no-slip (the ghosts then carry two velocity maps) */
  int periodic[2];
  double lo[2], hi[2]; /* domain box */
  int32_t *count;      /* per-particle ghost counts (scan buffer), cap + 1 */
  size_t count_cap;
  /* bodies (body.h): their segments and circles follow the walls' ones; seg0 and circ0
   * (host) hold them at zero displacement, kin their kinematics (device) */
  int nbody, nwallseg, nwallcirc;
  real *seg0, *circ0, *kin;
  /* open boundaries (open.h): their segments are [open0, nwallseg), after the walls' and
   * before the bodies'; openu (device) holds the velocity each of their nmark markers gives
   * an inflow's ghosts, 2 per marker */
  int open0, nmark;
  real *openu;
} rhod_boundary;

/* Builds the wall segments, corners and circles of a scene, and the domain box. */
int rhod_boundary_init(rhod_boundary *b, const rhod_scene *s, const double lo[2],
                       const double hi[2]);
void rhod_boundary_free(rhod_boundary *b);

/* Regenerates every ghost for the fluid at [0, p->n): wall mirrors of fluid particles
 * within `radius_ratio * dx_i` of a wall, then periodic images of fluid and wall
 * ghosts that fall within `margin` of the box. Grows the store if needed.
 * Copies x, y, m, dx into the ghosts and sets gsrc, gJ, gT, gU, ge. The wall part of a
 * ghost's velocity, gU (u_g = T u_s + gU): 2 u_wall for a no-slip mirror (T = -I), 0 for
 * a free-slip one (T = J: the wall's tangential motion does not act); at a double mirror
 * in a corner (T = -I where either wall is no-slip, else J_b J_a) the mean of the
 * no-slip walls' 2 u_wall (docs/choices.md "moving walls at corners"); a periodic image
 * copies its source's.
 * With gTv (rhod_particles_add_noslip_fields: a scene with a no-slip wall or body), that
 * map goes to gTv, gUv, which the viscous terms read, and gT, gU take every wall's and
 * body's free-slip map (T = J, or the curved mirror of a circle; a body's gU = (I - T) u_w),
 * which the other terms read (docs/choices.md "no slip in the viscous term only").
 * A body's ghosts (docs/choices.md "bodies"): u_g = u_w + T (u_s - u_w), i.e. gU = (I - T) u_w
 * with u_w the boundary's velocity at the mirror's foot (a vertex for a double mirror);
 * when the store has them (rhod_particles_add_body_fields), gA = a_w there (0 for walls)
 * and gbody = the body's index (-1 for walls, -2 for periodic images of the fluid, -1 for
 * periodic images of mirrors: particles.h). A mirror in a body's
 * segment is kept only where no other segment of that body lies nearer to the ghost than
 * the mirrored one: the images of the two faces at a convex vertex would overlap. A
 * circle's mirror carries m_s r_g / r_s, the area ratio of the radial mirror.
 * No cap on the ghosts of a particle. */
int rhod_ghosts_build(rhod_boundary *b, rhod_particles *p, real radius_ratio, real margin);

/* near[i] = 1 when the support of fluid particle i (radius radius_ratio * dx_i)
 * reaches a wall or a body whose refine flag is set (walls.N.refine, bodies.N.refine:
 * S[13], C[6]), else 0 (refinement criterion 4 of paper 002 Sec. V B): for a wall, where
 * i has a mirror in it; for a body, by the distance to its segments (vertices included)
 * or circle. */
void rhod_walls_near(const rhod_boundary *b, const rhod_particles *p, real radius_ratio,
                     uint8_t *near);

/* Reflects fluid particles that ended a step just behind a wall (see ghosts.c);
 * returns how many. */
long rhod_walls_guard(const rhod_boundary *b, rhod_particles *p);

/* The first fluid particle that lies more than half its size inside a body (past what the
 * wall guard puts back), or -1; *body its body's index. Host-side result of a device loop. */
long rhod_bodies_entered(const rhod_boundary *b, const rhod_particles *p, int *body);

/* Whether the ray from (x, y) along +x crosses the edge from (ax, ay) to (bx, by): the
 * step of the crossing-number (even-odd) test that every inside-a-polygon question here
 * uses (scene shapes, held regions, bodies' outlines). A macro, so that it serves the host's
 * doubles and the device's reals alike; each argument is read once or twice, so pass plain
 * values. */
#define RHOD_RAY_CROSSES(ax, ay, bx, by, x, y)                                                     \
  (((ay) > (y)) != ((by) > (y)) && (x) < (ax) + ((y) - (ay)) * ((bx) - (ax)) / ((by) - (ay)))

/* A point moved off the walls (pass walls and bodies, not the open boundaries' segments: a
 * test of a segment's kind here made GCC 12's nvptx compiler fail, tree-nrv.cc:179): where
 * (x, y) lies less than `keep` in front of a wall (or behind it, by less than `back`), with its
 * foot on the wall, it moves along the wall normal to stand `keep` in front; walls in order,
 * segments then circles. For points placed near walls by a kernel (the APR split's children);
 * inline, so that device loops can call it. */
typedef struct {
  real x, y;
} rhod_point;

static inline rhod_point rhod_walls_keep_off(const real *seg, int nseg, const real *circ, int ncirc,
                                             real x, real y, real keep, real back) {
  for (int s = 0; s < nseg; s++) {
    const real *S = seg + RHOD_SEG_STRIDE * s;
    const real rx = x - S[0], ry = y - S[1];
    const real d = S[2] * rx + S[3] * ry, t = S[4] * rx + S[5] * ry;
    if (d < keep && d > -back && t >= 0 && t <= S[6])
      x += (keep - d) * S[2], y += (keep - d) * S[3];
  }
  for (int c = 0; c < ncirc; c++) {
    const real *C = circ + RHOD_CIRC_STRIDE * c;
    const real rx = x - C[0], ry = y - C[1], dist = sqrt(rx * rx + ry * ry);
    const real d = C[3] > 0 ? C[2] - dist : dist - C[2];
    if (d < keep && d > -back && dist > 0) {
      const real ex = C[3] * (-rx / dist), ey = C[3] * (-ry / dist); /* into the fluid */
      x += (keep - d) * ex, y += (keep - d) * ey;
    }
  }
  const rhod_point q = {x, y};
  return q;
}

/* Distance from a point to the nearest body's boundary (either side); +HUGE_VAL without
 * bodies. Host side, for setup. */
double rhod_body_distance(const rhod_boundary *b, double x, double y);

/* Signed distance from a point to the nearest wall (positive on the fluid side);
 * +HUGE_VAL when there are no walls. Host side, for setup. */
double rhod_wall_distance(const rhod_boundary *b, double x, double y);

/* Ghost fields from their sources (kernels/ghost_map.c), for the ghosts [n, n + ng) that
 * rhod_ghosts_build made (gsrc, gJ, gT set); device loops over the ghosts only. */
/* f[g] = f[gsrc[g]]: a scalar (density, pressure, a tag) */
void rhod_ghosts_map_scalar(const rhod_particles *p, real *f);
void rhod_ghosts_map_u8(const rhod_particles *p, uint8_t *f);
/* v_g = J v_src for a vector stored 2 per particle (a normal, a gradient of a scalar) */
void rhod_ghosts_map_vector(const rhod_particles *p, real *v);
/* (vx, vy)_g = T (vx, vy)_src + gU: a velocity (T is J for free slip and periodic images,
 * -I for no slip unless the store has gTv, which then holds it; gU a moving wall's part,
 * 0 where no wall moves) */
void rhod_ghosts_map_velocity(const rhod_particles *p, real *vx, real *vy);
/* The same with the viscous terms' map (gTv, gUv) where the store has it, else gT, gU */
void rhod_ghosts_map_velocity_viscous(const rhod_particles *p, real *vx, real *vy);

#endif
