/* Rigid bodies (the scene's bodies: list): obstacles that rest, move by a law of time or
 * move freely under the fluid's force, with the force and moment the fluid exerts on each.
 * Engine side: both schemes use them. Paper 002 Sec. IV A states only "mirrored ghost
 * particles" and forces "following Ref. 8"; the choices are in docs/choices.md ("bodies").
 *
 * A body's pose is the displacement d of its reference point G from G0 (bodies.N.center)
 * and the rotation theta about G: a point X0 of the body as the scene gives it stands at
 * G0 + d + R(theta) (X0 - G0). Its boundary is a set of segments or a circle in the ghost
 * machinery (boundary.h), moved to the pose before each ghost build. */
#ifndef RHOD_BODY_H
#define RHOD_BODY_H

#include "rhod/boundary.h"
#include "rhod/cells.h"
#include "rhod/checkpoint.h"
#include "rhod/integrator.h"
#include "rhod/particles.h"
#include "rhod/scene.h"

/* probes.csv columns a body adds, in this order after the scene's probes: NAME_Fx, NAME_Fy
 * [N/m], NAME_Mz [N] (about G), NAME_x, NAME_y [m] (G), NAME_theta [rad], NAME_u, NAME_v
 * [m/s] (G's velocity), NAME_omega [1/s] */
#define RHOD_BODY_COLUMNS 9
_Static_assert(RHOD_RUN_COLUMNS_MAX ==
                   RHOD_PROBE_COLUMNS_TOTAL + RHOD_BODY_COLUMNS * RHOD_MAX_BODIES,
               "scene.h counts 9 columns a body");
extern const char *const rhod_body_column_suffix[RHOD_BODY_COLUMNS];

typedef struct {
  const rhod_body *desc;   /* the scene's */
  void *law[RHOD_NDOF][3]; /* imposed: libmatheval evaluators of the law, its first and second
                              derivatives (NULL where the law is 0) */
  double G0[2];            /* G at zero displacement */
  /* state: q = (d_x, d_y, theta), qd its rate; qdd the acceleration the ghost pressure uses */
  double q[RHOD_NDOF], qd[RHOD_NDOF], qdd[RHOD_NDOF];
  double q0[RHOD_NDOF], qd0[RHOD_NDOF], kq[RHOD_NDOF], kqd[RHOD_NDOF]; /* RK bookkeeping */
  double F[3];          /* the fluid's force (Fx, Fy) and moment about G, last measured */
  double area;          /* the shape's */
  double ma[RHOD_NDOF]; /* free: the added-mass estimate of the relaxation (x, y [kg/m];
                           theta [kg m]), rhod_bodies_relaxation */
} rhod_body_state;

typedef struct {
  int n;
  rhod_body_state *b;
  int moving;   /* some body is not fixed */
  real *fghost; /* scratch: per ghost (fx, fy) of the viscous pass, 2 reals, device */
  size_t fghost_cap;
  /* the pressure's quadrature points on the bodies' boundaries (spacing at most half the
   * finest particle size): at zero displacement (x0, y0, outward normal n0, length ds,
   * body), and where they stand now with the pressure there (device: px, py, fp, gam) */
  int ns;
  double *x0, *y0, *nx0, *ny0, *ds;
  int *sb;
  real *px, *py, *fp, *gam;
} rhod_bodies;

/* Compiles the laws, sets the initial pose (imposed: the law at t; free: at rest at zero
 * displacement with the given velocities) and appends every body's boundary to b (after
 * the walls, rhod_boundary_init) at that pose; ds: the largest spacing of the pressure's
 * quadrature points along the boundaries. Errors: RHOD_ERR_SCENE with a one-line
 * message (a law libmatheval refuses), RHOD_ERR_MEMORY. */
int rhod_bodies_init(rhod_bodies *bb, const rhod_scene *sc, rhod_boundary *b, double t, double ds,
                     char *err, size_t errlen);
void rhod_bodies_free(rhod_bodies *bb);

/* Moves every body's boundary in b to its state (q, qd, qdd) and copies it to the device. */
void rhod_bodies_place(const rhod_bodies *bb, rhod_boundary *b);

/* The free bodies' added-mass estimates m_a (bodies.N.added_mass, else rho0 x the shape's
 * area; rho0 the fluid's, the densest phase's) for x and y, and m_a I/M (the body's radius
 * of gyration) for theta: rhod_bodies_stage's relaxation. */
void rhod_bodies_relaxation(rhod_bodies *bb, double rho0);

/* Imposed bodies: q, qd, qdd from the law at time t (others unchanged). */
void rhod_bodies_impose(rhod_bodies *bb, double t);

/* The lockstep integration of free bodies with the fluid's Runge-Kutta method (the same
 * stage table, integrator.h): begin before stage 0; after the forces of stage s are known
 * (rhod_bodies_forces), stage sets the state for stage s + 1 at time t + c[s] dt, or the
 * final one. Imposed bodies follow their law at the stage's time. Locked degrees of
 * freedom keep their value and rate exactly. gravity: the scene's. The stage's
 * acceleration is relaxed with the added-mass estimate m_a (ours, docs/choices.md "bodies:
 * added-mass relaxation"): a = (F + M g + m_a a') / (M + m_a), a' the acceleration the
 * ghosts' pressure took (the stage before's). The fluid answers a' with about -m_A a'
 * (m_A the true added mass), so a repeats a' when a = (F_0 + M g)/(M + m_A), the coupled
 * solution, and an error in a' comes back times (m_a - m_A)/(M + m_a) instead of the
 * explicit coupling's -m_A/M, which grows for bodies lighter than m_A. */
void rhod_bodies_begin(rhod_bodies *bb);
void rhod_bodies_stage(rhod_bodies *bb, const rhod_rk_table *tab, int s, double t, double dt,
                       const double gravity[2]);

/* The fluid's force and moment on every body (into bb->b[k].F) from the prepared state:
 * ghosts built (p->gbody set), cells over fluid and ghosts, P and V over both.
 * Pressure: the surface integral F = -oint P n dS, M = -oint (x - x_G) x P n dS over the
 * quadrature points, P there the Shepard interpolation over fluid and ghosts (paper 000
 * Eq. 8; 0 where Gamma < 0.1, a dry point of a body piercing the surface).
 * Viscosity (mu > 0, or nu given): the viscous part of the pair form of Bouscasse et al.
 * 2013 (paper 002 Ref. 8), central pair forces, F = sum_{j ghost of B} sum_{i fluid}
 * -2 (d + 2) mu_ij pi_ij grad_i W_ij V_i V_j, M = sum (x_j - x_G) x [the same],
 * pi_ij = (u_i - u_j).(x_i - x_j) / |x_i - x_j|^2, W with fluid particle i's radius (ratio
 * dx_i). mu_ij = mu, or with a per-particle kinematic viscosity nu (fluid and ghosts; a
 * multiphase scheme's) rho_i rho_j (nu_i + nu_j) / (rho_i + rho_j), the coefficient of
 * paper 001 Eq. 6 (Szewc et al.), which is mu for one fluid. Our choices: docs/choices.md
 * "bodies: force". RHOD_ERR_MEMORY when the scratch cannot grow. */
int rhod_bodies_forces(rhod_bodies *bb, const rhod_particles *p, const rhod_cells *c, int kern,
                       real ratio, const real *P, const real *V, real mu, const real *nu);

/* The columns for probes.csv (RHOD_BODY_COLUMNS per body) at the current state. */
void rhod_bodies_values(const rhod_bodies *bb, double *out);

/* The outline of every body at its pose (circles with segments of at most seg_len):
 * start (n + 1 entries) and xy (x, y interleaved) malloc'd into *start and *xy. */
int rhod_bodies_outline(const rhod_bodies *bb, double seg_len, unsigned **start, double **xy);

/* Checkpoint extras: per body its 9 numbers q, qd, qdd, named "body.K.q0" ... "body.K.qdd2".
 * save appends them to ck's extras; load takes them back (every body's must be there:
 * RHOD_ERR_CHECKPOINT naming the first missing one otherwise) and places the bodies. */
#define RHOD_BODY_EXTRAS 9
void rhod_bodies_save(const rhod_bodies *bb, rhod_checkpoint *ck);
int rhod_bodies_load(rhod_bodies *bb, rhod_boundary *b, const rhod_checkpoint *ck, char *err,
                     size_t errlen);

#endif
