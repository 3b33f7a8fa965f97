/* A simulation: the engine (particles, ghosts, cells, integrator) driving one scheme
 * (include/rhod/scheme.h) for one scene. Library code: returns rhod_status codes with a
 * message. */
#ifndef RHOD_SIM_H
#define RHOD_SIM_H

#include "rhod/body.h"
#include "rhod/boundary.h"
#include "rhod/cells.h"
#include "rhod/integrator.h"
#include "rhod/io.h"
#include "rhod/open.h"
#include "rhod/particles.h"
#include "rhod/scene.h"
#include "rhod/scheme.h"

/* What the initial fill did with one fluid block's lattice points: those inside its shape
 * that became particles, and those left out, by cause (the first wall named). Points
 * claimed by an earlier block are in neither. */
typedef struct {
  size_t kept;
  size_t out_domain;       /* outside the domain box */
  size_t in_obstacle;      /* inside an obstacle (walls.N with fluid_inside: false) */
  size_t out_container;    /* outside a container (walls.N with fluid_inside: true) */
  size_t in_body;          /* inside a body (bodies.N) where it stands at t = 0 */
  size_t on_wall;          /* on or just behind a wall otherwise */
  int obstacle, container; /* the first such wall's index, -1 if none */
  int body;                /* the first such body's index, -1 if none */
  int bodies_more;         /* points inside other bodies than that too */
} rhod_fill_stats;

/* phases a scheme gives a reference density for (rhod_sim.rho0) */
#define RHOD_SIM_PHASES 8

typedef struct rhod_sim {
  const rhod_scene *sc;
  const rhod_scheme_ops *ops; /* the scheme (rhod_scheme_for) */
  void *sch;                  /* its state, made by ops->init */
  rhod_fill_stats *fill;      /* per fluid block, from rhod_sim_init */
  rhod_particles p;
  rhod_boundary bnd;
  rhod_bodies bodies;           /* the scene's bodies (body.h) */
  rhod_open open;               /* the scene's open boundaries (open.h) */
  double rho0[RHOD_SIM_PHASES]; /* the reference density of each phase (the scheme's; a
                                   one-fluid scheme's at 0): open boundaries' nominal mass */
  double c0[RHOD_SIM_PHASES];   /* and its speed of sound: the outflows' pressure relaxation */
  double body_mu; /* the dynamic viscosity of the bodies' force (the scheme's; 0 inviscid) */
  real **body_nu; /* or a per-particle kinematic viscosity over fluid and ghosts (the address
                     of the scheme's pointer, as P and V; NULL where body_mu serves) */
  unsigned *outline_start; /* the bodies' outlines of the last rhod_sim_fetch */
  double *outline_xy;
  real *vort; /* the vorticity of the last rhod_sim_fetch (a store field, "vort"), where the
                 picture or output.fields asks for it; else NULL */
  rhod_cells cells;
  rhod_rk rk;          /* made with the scene's time.integrator; the scheme adds its variables */
  real **P, **V;       /* the scheme's pressure and volume over fluid and ghosts after
                          ops->ghost_state (addresses of its pointers: the store moves them) */
  double lo[2], hi[2]; /* domain box */
  double margin;       /* ghost layer width: largest kernel radius */
  double dx_min;       /* finest particle size the scene allows */
  double mirror_ratio; /* wall mirrors within mirror_ratio * dx_i of a wall */
  double t, dt;
  long step;
  double particle_steps; /* sum over the steps run by this process of the particle count */
  long reflected;        /* particles put back by the wall-crossing guard, whole run */
  int neighbours_fresh;  /* ghosts and cells match the current state */
} rhod_sim;

/* Fills the fluid from the scene (square lattice of spacing dx, each particle's initial
 * state from the scheme the scene names) and sets everything up on the device. */
int rhod_sim_init(rhod_sim *s, const rhod_scene *sc, char *err, size_t errlen);
void rhod_sim_free(rhod_sim *s);

/* For schemes. The fluid block that owns (x, y): the first whose shape holds it, if it is
 * fluid (inside the domain, not behind a wall, not in a body where it stands at t = 0); -1
 * otherwise. */
int rhod_sim_block_at(const rhod_sim *s, double x, double y);
/* Whether (x, y) lies in the shape (its boundary included; a polygon by the even-odd
 * rule), as the fill tests it. */
int rhod_shape_contains(const rhod_shape *sh, double x, double y);
/* The initial flow of block b at (x, y) for a fluid of density rho0: the block's velocity
 * plus its analytic flow (fluid.N.initial), and that flow's pressure (0 without one). */
void rhod_sim_initial_flow(const rhod_sim *s, unsigned b, double x, double y, double rho0,
                           double *u, double *v, double *P);
/* The depth of (x, y) below block b's free surface along gravity (the surface at
 * fluid.N.surface, or the block's highest point along -g), and |g| into *g. */
double rhod_sim_block_depth(const rhod_sim *s, unsigned b, double x, double y, double *g);
/* Each particle gets the initial state of its block where it stands (ops->initial_state),
 * sizes and ids kept: its block is blk[id] when a table is given, else the block at its
 * place; a particle of no block keeps its fields. With jit > 0 it is first jittered by
 * jit times its own size, unless that takes it out of its block. Then prepares (sorted). */
int rhod_sim_restate(rhod_sim *s, double jit, const int *blk);

/* Warnings about the particles as set up (after rhod_sim_init), one line each into buf,
 * separated by '\n': fluid left out of a block by walls or the domain, pressure probes
 * the fluid can never reach, fluid with nothing below it along gravity. Returns how many. */
int rhod_sim_warnings(rhod_sim *s, char *buf, size_t len);

/* Bytes per fluid particle the memory check of rhod_sim_init assumes: a lower bound of
 * what a run holds (the store with its spare room, ghosts, cells; measured about 900 in
 * double precision on the dam break), so that a refused scene would not have fitted. */
#define RHOD_BYTES_PER_PARTICLE (64 * sizeof(real))

/* Makes ghosts and cells match the current state (sorting the fluid by cell first when
 * sort != 0). After it, probes and outputs see consistent ghost values. */
int rhod_sim_prepare(rhod_sim *s, int sort);

/* Sets s->dt for the next step (the scheme's ops->dt; RHOD-SPH measures the damper's
 * stiffness there, so call it once per step). Returns RHOD_OK or RHOD_ERR_MEMORY. */
int rhod_sim_dt(rhod_sim *s);

/* One step of size dt (s->dt clipped by the caller) with the scene's integrator, then the
 * scheme's end-of-step work, then the open boundaries' mass exchange (open.h). Checks the
 * new state first: RHOD_ERR_UNSTABLE with the particle and the cause in err when it is not
 * finite or a particle left the domain (other than behind an open boundary), or when an
 * open boundary is overwhelmed; the state is then left as computed (not written out). */
int rhod_sim_step(rhod_sim *s, double dt, char *err, size_t errlen);

/* Probe columns: names (momentum probes give two, NAME_x and NAME_y, written into the
 * caller's buf) and values at the current (prepared) state. */
#define RHOD_PROBE_NAME_MAX 80
unsigned rhod_probe_columns(const rhod_scene *sc, char (*buf)[RHOD_PROBE_NAME_MAX],
                            const char **names, unsigned max);
void rhod_probe_values(rhod_sim *s, double *values);

/* Brings the fluid's output fields to the host and points a snapshot view at them
 * (valid until the next step), the scene's output.fields among the view's extras and the
 * bodies' outlines where they stand. Returns RHOD_OK, or RHOD_ERR_MEMORY when the ghosts
 * those fields need or the outlines cannot be made. */
int rhod_sim_fetch(rhod_sim *s, rhod_snapshot_view *v);

/* The scheme's statistics and end-of-run lines (ops->stats, ops->report); none when the
 * scheme has no such hook. */
int rhod_sim_stats(const rhod_sim *s, rhod_stat *out, int max);
void rhod_sim_report(const rhod_sim *s, long steps, rhod_warn_buf *w);

#endif
