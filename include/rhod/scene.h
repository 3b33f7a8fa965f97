/* A scene: everything a user chooses for one run, loaded from YAML by libcyaml.
 * Every key, its unit, default and paper reference is documented in docs/scene.md. */
#ifndef RHOD_SCENE_H
#define RHOD_SCENE_H

#include "rhod/integrator_kind.h"
#include "rhod/kernel_kind.h"
#include "rhod/status.h"
#include <stddef.h>

/* scheme.name: which scheme runs the scene. rhodsph: paper 002 (RHOD-SPH, the default;
 * its keys in rhod_scene.rs); multiphase: paper 000's multiphase scheme (its keys in
 * rhod_scene.mp). */
typedef enum { RHOD_SCHEME_RHODSPH = 0, RHOD_SCHEME_MULTIPHASE } rhod_scheme_kind;

struct rhod_mp_scene; /* include/rhod/multiphase/scene.h */
struct rhod_rs_scene; /* include/rhod/rhodsph/scene.h */

typedef enum { RHOD_SHAPE_RECT = 0, RHOD_SHAPE_POLYGON, RHOD_SHAPE_CIRCLE } rhod_shape_kind;

typedef struct {
  rhod_shape_kind kind;
  double min[2], max[2];    /* RECT: lower-left and upper-right corners [m] */
  double center[2], radius; /* CIRCLE [m] */
  double (*points)[2];      /* POLYGON: vertices [m], closed implicitly */
  unsigned n_points;        /* POLYGON: at least 3 */
} rhod_shape;

typedef enum { RHOD_INIT_UNIFORM = 0, RHOD_INIT_HYDROSTATIC } rhod_init_kind;

/* An analytic initial flow added to a block's uniform velocity and pressure. */
typedef enum {
  RHOD_FLOW_NONE = 0,
  RHOD_FLOW_TAYLOR_GREEN, /* u = U sin(kx) cos(ky), v = -U cos(kx) sin(ky), k = 2 pi / L,
                             P = rho0 U^2/4 (cos 2kx + cos 2ky) */
  RHOD_FLOW_ROTATION,     /* rigid rotation u = omega x (x - center) with the pressure
                             series of paper 002 Eq. 30 (rect blocks) */
  RHOD_FLOW_SHEAR_LAYER,  /* Kelvin-Helmholtz double shear layer, paper 000 Eq. 27:
                             u = U [tanh((y - y1)/w) - tanh((y - y2)/w) - 1],
                             v = UI sin(2 pi x/L) [exp(-(y - y1)^2/s^2) + exp(-(y - y2)^2/s^2)] */
  RHOD_FLOW_DROPLET       /* mode-2 droplet oscillation, paper 000 Eqs. 28-29, about center:
                             u = U x/R (1 - y^2/(R r)) exp(-r/R),
                             v = -U y/R (1 - x^2/(R r)) exp(-r/R) */
} rhod_flow_kind;

/* A block of fluid filled with a square lattice of spacing particles.dx. */
typedef struct {
  rhod_shape shape;
  rhod_flow_kind flow;     /* initial.taylor_green / rotation / shear_layer /
                              droplet_oscillation */
  double flow_U, flow_L;   /* taylor_green: amplitude [m/s], period [m] */
  double flow_omega;       /* rotation: angular velocity [1/s], > 0 counter-clockwise */
  double flow_center[2];   /* rotation, droplet_oscillation: centre [m], default the block's
                              centre */
  double flow_UI;          /* shear_layer: perturbation amplitude [m/s]; U is flow_U, L flow_L */
  double flow_y[2];        /* shear_layer: the interfaces y1, y2 [m] */
  double flow_width;       /* shear_layer: tanh width w [m] */
  double flow_spread;      /* shear_layer: Gaussian width s of the perturbation [m] */
  double flow_R;           /* droplet_oscillation: radius R of Eqs. 28-29 [m]; U is flow_U */
  double velocity[2];      /* initial velocity [m/s], default 0 */
  rhod_init_kind pressure; /* uniform (P = 0) or hydrostatic (paper 002 Sec. VI A,
                              free surface at `surface`) */
  int surface_set;         /* fluid.N.surface given */
  double surface;          /* hydrostatic: the free surface's level along -g [m], i.e. x.e
                              with e = -g/|g| (for g along -y, its y); default the block's
                              highest point along -g */
  double ambient_pressure; /* fluid.N.ambient_pressure: a uniform pressure added to the
                              initial one [Pa], default 0 (a confined flow's reference level,
                              as an outflow's open_boundaries.N.pressure) */
  int phase;               /* fluid.N.phase: index into mp->phases; -1 for rhodsph */
  unsigned line, col;      /* where the block starts in the scene file (for messages);
                              0, 0 when an override (--set) supplied it */
} rhod_fluid_block;

typedef enum { RHOD_SLIP_FREE = 0, RHOD_SLIP_NO } rhod_slip;

/* A solid wall: the boundary of a shape, modelled by mirrored ghost particles. */
typedef struct {
  rhod_shape shape;
  rhod_slip slip;        /* free (default) or no-slip */
  int fluid_inside;      /* 1 (default): the shape is a container; 0: an obstacle */
  double velocity[2];    /* walls.N.velocity [m/s] of its moving edges, default [0, 0] */
  unsigned moving_edges; /* bit k: edge k moves (rect: 0 bottom, 1 right, 2 top, 3 left;
                            polygon: from points[k] to points[k+1], in the stored
                            counter-clockwise order); 0 when the velocity is zero */
  int refine;            /* walls.N.refine: refinement criterion 4 near this wall (paper 002
                            Sec. V B; case F switches it off at the bottom), default 1 */
} rhod_wall;

/* bodies.N.motion: how a body moves (include/rhod/body.h). */
typedef enum {
  RHOD_MOTION_FIXED = 0, /* at rest (the default) */
  RHOD_MOTION_IMPOSED,   /* a law of time in the scene */
  RHOD_MOTION_FREE       /* 2D rigid-body dynamics under the fluid's force and gravity */
} rhod_motion_kind;

/* bodies.N.lock: the degrees of freedom a free body keeps fixed */
enum { RHOD_DOF_X = 0, RHOD_DOF_Y, RHOD_DOF_THETA, RHOD_NDOF };

/* A rigid body: an obstacle (fluid outside) whose boundary is modelled by ghost particles,
 * that may move, and on which the fluid's force and moment are measured every step. The
 * loader resolves every default: after it, center, mass and inertia are the values a run
 * uses. */
typedef struct {
  char *name;              /* bodies.N.name: probes.csv columns NAME_Fx ...; default "bodyN" */
  rhod_shape shape;        /* rect, polygon or circle, where the body stands at zero
                              displacement (the law's x = y = theta = 0) */
  rhod_slip slip;          /* free (default) or no */
  int refine;              /* bodies.N.refine: refinement criterion 4 near this body (paper 002
                              Sec. V B); default 1 */
  rhod_motion_kind motion; /* bodies.N.motion, default fixed */
  double center[2];        /* bodies.N.center: the reference point G at zero displacement
                              (rotation centre; a free body's centre of mass) [m]; default
                              the shape's centroid */
  char *law[RHOD_NDOF];    /* imposed: bodies.N.law.{x, y, theta}: G's displacement [m] and
                              the rotation about G [rad, counter-clockwise] as expressions of
                              t [s] (libmatheval syntax); NULL where not given (0) */
  double pose0[RHOD_NDOF]; /* where the body stands at t = 0: the law's x, y [m] and theta
                              [rad] at t = 0 (imposed; 0 otherwise), resolved by the loader */
  double mass;             /* free: per unit depth [kg/m] (bodies.N.mass, or density x area) */
  double density;          /* free: bodies.N.density [kg/m^3] as given, 0 when mass was */
  double inertia;          /* free: moment of inertia about G per unit depth [kg m]
                              (bodies.N.inertia; default: the shape's, uniform density) */
  double added_mass;       /* free: bodies.N.added_mass [kg/m], the estimate that stabilises
                              the coupling (body.h); < 0 when not given: rho0 x area, resolved
                              by the run (rhod_bodies_relaxation) */
  int lock[RHOD_NDOF];     /* free: bodies.N.lock, 1 where that DOF is held */
  double velocity[2];      /* free: initial velocity of G [m/s], default [0, 0] */
  double omega;            /* free: initial angular velocity [1/s], default 0 */
} rhod_body;

/* open_boundaries.N.kind: how fluid crosses an open boundary (include/rhod/open.h) */
typedef enum {
  RHOD_OPEN_INFLOW = 0, /* the velocity is imposed (a law of time and a profile) */
  RHOD_OPEN_OUTFLOW     /* the fluid leaves with the velocity it has there */
} rhod_open_kind;

/* open_boundaries.N.profile: the inflow velocity's shape along the segment */
typedef enum {
  RHOD_PROFILE_UNIFORM = 0, /* the same speed everywhere */
  RHOD_PROFILE_PARABOLIC    /* 6 s (1 - s) times the speed, s in [0, 1] along the segment:
                               0 at both ends, the given speed as its mean */
} rhod_profile_kind;

/* An open boundary: a straight segment through which fluid enters or leaves by continuous
 * mass insertion and deletion (paper 000 Sec. 3.3, Eqs. 11-17; paper 001 Sec. 3.1,
 * Eqs. 20-28). The loader resolves every default. */
typedef struct {
  char *name;                /* open_boundaries.N.name: default "openN" */
  rhod_open_kind kind;       /* open_boundaries.N.kind (required) */
  double from[2], to[2];     /* the segment's ends [m] (required) */
  double normal[2];          /* unit normal pointing into the fluid: open_boundaries.N.normal's
                                side, default the side of the domain's centre */
  char *velocity;            /* inflow: the normal speed into the fluid [m/s] as an expression
                                of t (libmatheval), the profile's mean; "0" by default; NULL
                                for an outflow */
  rhod_profile_kind profile; /* inflow: default uniform */
  int surface_set;           /* open_boundaries.N.surface given */
  double surface;            /* the free surface's level along -g (as fluid.N.surface): only
                                the part of the segment below it is wet */
  double pressure;           /* outflow: the ambient pressure at the free surface's level, or
                                everywhere without gravity [Pa], default 0; the hydrostatic
                                part below the surface is added (src/open.c) */
  double dx;                 /* the size of the particles it inserts [m], default particles.dx */
  int phase;                 /* multiphase: the phase it inserts (index), default 0; -1 for
                                rhodsph */
  unsigned line, col;        /* where the entry starts in the scene file (for messages) */
} rhod_open_boundary;

typedef enum {
  RHOD_PROBE_PRESSURE = 0,     /* Shepard-interpolated pressure at a point [Pa] */
  RHOD_PROBE_KINETIC_ENERGY,   /* sum 1/2 m |u|^2 [J/m] */
  RHOD_PROBE_POTENTIAL_ENERGY, /* sum -m g.x [J/m] */
  RHOD_PROBE_FRONT,            /* max over fluid of x.direction [m] */
  RHOD_PROBE_MASS,             /* sum m [kg/m] */
  RHOD_PROBE_MOMENTUM,         /* sum m u, two columns name_x, name_y [kg/s] */
  RHOD_PROBE_ANGULAR_MOMENTUM, /* sum m (x - at) x u [kg m/s] */
  RHOD_PROBE_ELASTIC_ENERGY,   /* sum m e(rho), e the compression energy of Eq. 2 [J/m] */
  RHOD_PROBE_TORQUE_BUDGET     /* d/dt sum m (x - at) x u term by term, seven columns
                                  (rhod_sph_torque_budget) [kg m/s^2] */
} rhod_probe_kind;
/* CSV columns of a probe kind: name + suffix for each (one column: the suffix ""). */
#define RHOD_PROBE_MAX_COLUMNS 7
/* columns of all the probes of a scene together, at most (the loader refuses more) */
#define RHOD_PROBE_COLUMNS_TOTAL 64
/* bodies at most (a run refuses more), and the probes.csv columns of a run at most: the
 * probes' and RHOD_BODY_COLUMNS (body.h) per body */
#define RHOD_MAX_BODIES 64
#define RHOD_RUN_COLUMNS_MAX (RHOD_PROBE_COLUMNS_TOTAL + 9 * RHOD_MAX_BODIES)
unsigned rhod_probe_ncolumns(rhod_probe_kind kind);
const char *rhod_probe_suffix(rhod_probe_kind kind, unsigned column);

typedef struct {
  rhod_probe_kind kind;
  char *name;          /* CSV column name; default: the kind's name */
  double at[2];        /* PRESSURE: the point; ANGULAR_MOMENTUM, TORQUE_BUDGET: the origin */
  double direction[2]; /* FRONT: unit direction, default [1, 0] */
} rhod_probe;

typedef enum {
  RHOD_FIELD_PRESSURE = 0,
  RHOD_FIELD_VELOCITY, /* magnitude */
  RHOD_FIELD_DENSITY,
  RHOD_FIELD_SIZE,
  RHOD_FIELD_FREE_SURFACE,
  RHOD_FIELD_PHASE,    /* the phase index (multiphase scheme) */
  RHOD_FIELD_VORTICITY /* du_y/dx - du_x/dy (vorticity.h) */
} rhod_field;

typedef struct {
  rhod_scheme_kind scheme;  /* scheme.name, default rhodsph */
  struct rhod_mp_scene *mp; /* phases and the multiphase section; NULL for rhodsph */
  struct rhod_rs_scene *rs; /* rhodsph's keys (scheme switches, refinement, its physics,
                               relaxation, time step); NULL for multiphase */
  /* time: */
  double t_end;                    /* time.end [s] (required) */
  double output_every;             /* time.output_every [s] (required) */
  rhod_integrator_kind integrator; /* time.integrator, default rk4 */
  /* particles: */
  double dx;               /* particles.dx [m] (required) */
  double radius_ratio;     /* particles.radius_ratio = R/dx, default 4 (paper 002 Sec. IV D) */
  rhod_kernel_kind kernel; /* particles.kernel, default wendland_c2 */
  double jitter;           /* particles.jitter: random shift of the initial lattice points,
                              a fraction of dx in [0, 0.5], default 0 */
  /* physics: */
  double gravity[2]; /* physics.gravity [m/s^2], default [0, 0] */
  /* domain (default: the bounding box of walls, fluid and bodies at t = 0): */
  int has_domain;
  double domain_min[2], domain_max[2];
  int periodic[2]; /* domain.periodic: [false, false] */
  /* geometry: */
  rhod_fluid_block *fluid;
  unsigned n_fluid;
  rhod_wall *walls;
  unsigned n_walls;
  rhod_body *bodies; /* bodies: rigid bodies (obstacles), in order */
  unsigned n_bodies;
  rhod_open_boundary *open; /* open_boundaries: inflows and outflows, in order */
  unsigned n_open;
  rhod_probe *probes;
  unsigned n_probes;
  double probe_every; /* probes.every [s]: sampling interval, default output_every/10 */
  /* output: */
  int picture_enabled;      /* output.picture: false switches pictures off; default 1 */
  rhod_field picture_field; /* output.picture.field, default pressure */
  unsigned picture_width;   /* output.picture.width [pixels], default 800 */
  int picture_size_panel;   /* output.picture.size_panel: a second panel coloured by size,
                               default true when refinement.levels > 1 (false for the
                               size field itself) */
  int picture_range_set;
  double picture_range[2]; /* output.picture.range: colour scale limits (default: auto) */
  int picture_box_set;
  double picture_box_min[2], picture_box_max[2]; /* output.picture.box (default: domain) */
  char **output_fields; /* output.fields: names of particle-store fields to write as well
                           (rhod_scheme_ops.outputs); n_output_fields of them (at most
                           RHOD_MAX_OUTPUT_FIELDS), default none */
  unsigned n_output_fields;
  /* bookkeeping */
  char *name; /* name: default the file's base name without extension (the
                 folder's name for a file called scene.yaml) */
  char *path; /* the file it was loaded from */
  char *yaml; /* the scene as run (all keys, defaults filled), YAML text */
} rhod_scene;

/* Loads a scene from `path`, applying `--set key=value` overrides (dotted keys) in order.
 * On failure returns an rhod_status and writes a one-line message
 * "file:line:col: key: reason" (or "--set key=value: reason") into err. */
int rhod_scene_load(const char *path, const char *const *overrides, int n_overrides,
                    rhod_scene **out, char *err, size_t errlen);
void rhod_scene_free(rhod_scene *s);

/* Flattened "dotted.key" -> value strings of the scene as run (for /Parameters). */
typedef struct {
  char **keys, **values;
  unsigned n;
} rhod_param_list;
int rhod_scene_params(const rhod_scene *s, rhod_param_list *out);
void rhod_param_list_free(rhod_param_list *p);

/* Physical plausibility warnings that do not stop a run (e.g. c0 below the Eq. 2 bound),
 * one line each, written to buf separated by '\n'. Returns how many. */
int rhod_scene_warnings(const rhod_scene *s, char *buf, size_t len);

/* Warning lines gathered into a caller's buffer (rhod_scene_warnings, rhod_sim_warnings):
 * each call appends one line (newline-separated, cut at the buffer's end) and counts it. */
typedef struct {
  char *buf;
  size_t len, used;
  int count;
} rhod_warn_buf;
void rhod_warn(rhod_warn_buf *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* output.fields names at most (the extra datasets of a snapshot, io.h) */
#define RHOD_MAX_OUTPUT_FIELDS 16

/* Limits the loader enforces on what a run would write or hold (docs/choices.md "load-time
 * limits"): the picture's sides, the snapshots and probe rows a run writes, the steps
 * that t_end needs at the largest dt Eq. 11 allows, and the initial particle count. */
#define RHOD_PICTURE_MAX_SIDE 16384u /* pixels, each side (src/picture.c) */
#define RHOD_MAX_SNAPSHOTS 1e6
#define RHOD_MAX_PROBE_ROWS 1e8
#define RHOD_MAX_STEPS 1e12
#define RHOD_MAX_PARTICLES 2e9 /* int32 particle indices (cells, permutations) */

/* The initial fluid particle count a scene asks for, estimated from the blocks' areas
 * over dx^2 and, with refinement regions, the finer lattices of their overlap with the
 * blocks' bounding boxes (an upper estimate there). Before walls and domain cut it. */
double rhod_scene_particle_estimate(const rhod_scene *s);

/* Whether some wall edge moves (a non-zero walls.N.velocity), some body is not fixed or
 * there is an inflow: the ghosts then carry their wall's velocity (rhod_particles.gU). */
int rhod_scene_walls_move(const rhod_scene *s);

#endif
