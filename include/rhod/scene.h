/* A scene: everything a user chooses for one run, loaded from YAML by libcyaml.
 * Every key, its unit, default and paper reference is documented in docs/scene.md. */
#ifndef RHOD_SCENE_H
#define RHOD_SCENE_H

#include "rhod/integrator_kind.h"
#include "rhod/kernel_kind.h"
#include "rhod/status.h"
#include <stddef.h>

/* scheme.name: which scheme runs the scene. rhodsph: paper 002 (RHOD-SPH, the default);
 * multiphase: paper 000's multiphase scheme (its keys in rhod_scene.mp). */
typedef enum { RHOD_SCHEME_RHODSPH = 0, RHOD_SCHEME_MULTIPHASE } rhod_scheme_kind;

struct rhod_mp_scene; /* include/rhod/multiphase/scene.h */

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
} rhod_wall;

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
  RHOD_FIELD_PHASE /* the phase index (multiphase scheme) */
} rhod_field;

/* Most particle sizes a scene may use: dx, dx/e, ..., dx/e^(RHOD_MAX_LEVELS-1). */
#define RHOD_MAX_LEVELS 8
/* refinement.crowding's default: split a particle when a finer one stands nearer than
 * this times the mean of their sizes (about 1 where the sizes tile the plane).
 * docs/choices.md "crowding at size jumps" */
#define RHOD_CROWDING_DEFAULT 0.75
/* Most iterations of the initial relaxation (particles.relax). */
#define RHOD_RELAX_MAX 100000

/* scheme.viscosity: how F^mu approximates mu lap u. Monaghan: paper 002 Eq. 10 (the
 * default). Consistent: exact for quadratic velocity fields on any particle cloud, in
 * the bulk (our choice, the higher-order operator paper 002 points to after Eq. 10;
 * docs/choices.md "Consistent viscous operator"). */
typedef enum { RHOD_VISCOSITY_MONAGHAN = 0, RHOD_VISCOSITY_CONSISTENT } rhod_viscosity;

/* particles.relax_where: which particles the initial relaxation moves: all of them, or
 * only those within reach of a particle of another size (r <= R of the larger of the
 * two), so that a lattice start keeps its lattice away from the size jumps. */
typedef enum { RHOD_RELAX_ALL = 0, RHOD_RELAX_JUMPS } rhod_relax_where;

/* scheme.shifting_switch: where Eq. 6 is renormalised, which of the Eq. 4 divergences
 * take the difference form instead of the paper's sum form (docs/choices.md "Shifting
 * terms at size jumps"): none (false), the momentum term alone (momentum), or the
 * momentum and continuity terms (true). The balanced forms keep the momentum term's sum
 * form except at the particles of a size jump, where it takes the difference form with
 * du' = M^-1 du (rhod_sph_pass_jumps): with the continuity terms switched as in `true`
 * (balanced) or not (balanced_momentum). */
typedef enum {
  RHOD_SHSW_NONE = 0,
  RHOD_SHSW_MOMENTUM,
  RHOD_SHSW_ALL,
  RHOD_SHSW_BALANCED,
  RHOD_SHSW_BALANCED_MOMENTUM
} rhod_shifting_switch;

/* refinement.pattern: how a particle splits (paper 002 Sec. V A and Appendix, Fig. 32).
 * Square: 1 -> 4, level size ratio e = dx_l / dx_(l+1) = 2 (the paper's pattern);
 * triangle: 1 -> 3, e = sqrt 3 (the Appendix's choice for R/dx = 3). The children have
 * the parent's area between them: e = sqrt(N_split). */
typedef enum { RHOD_PATTERN_SQUARE = 0, RHOD_PATTERN_TRIANGLE } rhod_pattern;

/* Children per split, and the size ratio of two adjacent levels. */
static inline int rhod_pattern_children(rhod_pattern p) {
  return p == RHOD_PATTERN_TRIANGLE ? 3 : 4;
}
static inline double rhod_pattern_ratio(rhod_pattern p) {
  return p == RHOD_PATTERN_TRIANGLE ? 1.7320508075688772 : 2.0;
}

/* An initial refinement region (square pattern): the lattice inside it starts at
 * `level` (size particles.dx / 2^level), the finest region containing a point winning. */
typedef struct {
  rhod_shape shape;
  int level;
} rhod_region;

/* The field of refinement criterion 5 (paper 002 Sec. V B), Shepard-averaged. */
typedef enum { RHOD_QTY_PRESSURE = 0, RHOD_QTY_DYNAMIC_PRESSURE } rhod_quantity;

typedef struct {
  rhod_scheme_kind scheme;  /* scheme.name, default rhodsph */
  struct rhod_mp_scene *mp; /* phases and the multiphase section; NULL for rhodsph */
  /* time: */
  double t_end;                    /* time.end [s] (required) */
  double output_every;             /* time.output_every [s] (required) */
  double cfl;                      /* time.cfl, CFL_h of Eq. 11, default 0.5 */
  double cfl_visc;                 /* time.cfl_visc, CFL_mu of Eq. 11, default 0.025 */
  rhod_integrator_kind integrator; /* time.integrator, default rk4 */
  int stiffness_limit;             /* time.stiffness_limit: dt also kept below the stiffness
                                      the RK4 stages measure (integrator.h); default on */
  /* particles: */
  double dx;               /* particles.dx [m] (required) */
  double radius_ratio;     /* particles.radius_ratio = R/dx, default 4 (paper 002 Sec. IV D) */
  rhod_kernel_kind kernel; /* particles.kernel, default wendland_c2 */
  double jitter;           /* particles.jitter: random shift of the initial lattice points,
                              a fraction of dx in [0, 0.5], default 0 */
  int relax;               /* particles.relax: iterations of the initial relaxation by the
                              shifting operator (before t = 0), default 0 */
  /* particles.relax_where, default all */
  rhod_relax_where relax_where;
  /* physics: */
  double rho0;       /* physics.rho0 [kg/m^3], default 1000 */
  double c0;         /* physics.c0 [m/s] (required), Eq. 2 */
  double mu;         /* physics.mu [Pa s], default 0 (inviscid) */
  double gravity[2]; /* physics.gravity [m/s^2], default [0, 0] */
  /* scheme (paper 002 Sec. IV A; each switch defaults to on): */
  int riemann;                          /* scheme.riemann: Theta^rho and Theta^u, Eqs. 23-24 */
  int reconstruction;                   /* scheme.reconstruction: limited linear states Eqs. 13-16
                                           (off: first order, phi_L = phi_i) */
  int shifting;                         /* scheme.shifting: Eqs. 25-29 and the Eq. 4 terms */
  double shift_a, shift_b, shift_eps;   /* scheme.shifting_a/b/eps: 0.5, 0.05, 5e-4 (Eq. 27) */
  int acoustic_damper;                  /* scheme.acoustic_damper: Eq. 9 */
  double alpha_ad;                      /* scheme.alpha_ad: 1 */
  int damper_step_limit;                /* scheme.damper_step_limit: dt also kept below the
                                           damper's measured stiffness (rhod_sph.c); default on */
  int tensile_control;                  /* scheme.tensile_control: P_j - P_i in the conservative
                                          Eq. 6 where P_i < 0, off the free surface (paper 001
                                          Eq. 5); default off */
  rhod_shifting_switch shifting_switch; /* scheme.shifting_switch: which Eq. 4 divergences
                                           take the difference form where Eq. 6 is
                                           renormalised; default none (the paper's sum form
                                           everywhere) */
  int free_surface; /* scheme.free_surface: detection of Ref. 51 and the Eq. 6 switch;
                       off: every particle is inner */
  double fs_lambda_low, fs_lambda_high; /* scheme.free_surface_lambda: [0.2, 0.75] */
  double shepard_threshold;             /* scheme.shepard_threshold: Gamma_th = 0.85 (Eq. 6) */
  double theta_threshold;               /* scheme.theta_threshold: 0.95 (Eq. 24) */
  rhod_viscosity viscosity;             /* scheme.viscosity: the Laplacian of F^mu */
  /* domain (default: the bounding box of walls and fluid): */
  int has_domain;
  double domain_min[2], domain_max[2];
  int periodic[2]; /* domain.periodic: [false, false] */
  /* geometry: */
  rhod_fluid_block *fluid;
  unsigned n_fluid;
  rhod_wall *walls;
  unsigned n_walls;
  rhod_probe *probes;
  unsigned n_probes;
  double probe_every; /* probes.every [s]: sampling interval, default output_every/10 */
  /* refinement (adaptive particle refinement, paper 002 Secs. IV D and V): */
  int levels;           /* refinement.levels: sizes dx ... dx/e^(levels-1), default 1 */
  rhod_pattern pattern; /* refinement.pattern, default square (e = 2) */
  rhod_region *regions; /* refinement.regions: initial nested levels */
  unsigned n_regions;
  int refine_dynamic;      /* refinement.dynamic: split by the criteria during the run
                              (criteria 1 and 2 always), default true when levels > 1 */
  int refine_free_surface; /* refinement.free_surface: criterion 3, default false */
  double refine_band;      /* refinement.surface_band: criterion 3's reach over R_i, default 1 */
  double refine_crowding;  /* refinement.crowding: split where a finer particle is nearer than
                              this times the mean of the two sizes (ours), 0 = off */
  int refine_walls;        /* refinement.walls: criterion 4, default false */
  int refine_field;        /* refinement.field given: criterion 5 */
  int refine_coalesce;     /* refinement.coalesce: merge back where no criterion
                              holds any more, default false */
  rhod_quantity field_quantity;    /* refinement.field.quantity */
  double field_above, field_below; /* thresholds (+-HUGE_VAL when absent) */
  double field_from;               /* refinement.field.from [s], default 0 */
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

/* Whether some wall edge moves (a non-zero walls.N.velocity): the ghosts then carry
 * their wall's velocity (rhod_particles.gU). */
int rhod_scene_walls_move(const rhod_scene *s);

#endif
