/* Open boundaries (the scene's open_boundaries: list): inflows and outflows by continuous
 * mass insertion and deletion (paper 001 Sec. 3.1, Eqs. 20-28; paper 000 Sec. 3.3,
 * Eqs. 11-17; docs/choices.md "open boundaries"). Engine side: both schemes use it, and the
 * same machinery is meant for the internal boundaries between levels (paper 000) and a
 * coupling surface to another solver (paper 001).
 *
 * An open boundary is a straight segment cut into markers (paper 001's segments s) of
 * length A_s = dx, the size of the particles it inserts. Beyond it, mirror ghosts keep the
 * supports of the particles near it full (boundary.h: an inflow's ghosts carry the imposed
 * velocity, T = 0; an outflow's the fluid's, T = I). Once per step, after the integrator:
 *   - every marker's state (u_s, rho_s) is the one of the step's start: the inflow's law,
 *     or a coupling callback, or the Shepard interpolation of the fluid there (paper 001
 *     Eq. 29);
 *   - the particles whose cuboid (cross-section A_i = A_s (rho_0/rho_i)^{(d-1)/d}, extent
 *     l_i = V_i / A_i) touches the boundary, or that still have less than the nominal mass,
 *     are the boundary particles B; what crossed the boundary in the step is their
 *     predicted change dm*_i (Eq. 23), limited by 0 <= m <= m_0 (Eq. 24);
 *   - each marker's imbalance M_s = dm_s - sum_i omega_is dm*_i (Eqs. 20, 25) is given to its
 *     boundary particles (Eq. 26: a positive one to the furthest particle with omega > 0.5,
 *     then the closest ones, the rest to a new particle at the marker; a negative one from
 *     the closest first, the rest carried to the next step);
 *   - masses change (Eq. 27), a particle at zero mass is deleted, the others move to the
 *     barycentre of their cuboid, in contact with the boundary (Eq. 28; multiphase.md B (g));
 *     a particle at m_0 is released. */
#ifndef RHOD_OPEN_H
#define RHOD_OPEN_H

#include "rhod/boundary.h"
#include "rhod/cells.h"
#include "rhod/checkpoint.h"
#include "rhod/particles.h"
#include "rhod/scene.h"

/* An outflow's pressure relaxation (our choice, docs/choices.md "open boundaries: outflow
 * pressure"): its markers let the fluid out at u_s = u - kappa (p - p_inf)/(rho0 c0) n, u and p
 * the fluid's there, n the normal into the fluid, so that the pressure level cannot drift
 * (without it both ends of a channel leave it free); relaxes over about L/(kappa c0), and
 * turns about kappa/2 of an outgoing pressure wave back. */
#define RHOD_OPEN_KAPPA 0.2
/* markers of all open boundaries together, at most (a run refuses more) */
#define RHOD_OPEN_MAX_MARKERS 4096
/* checkpoint extras: a marker's carried imbalance, and the totals (RHOD_OPEN_TOTALS) */
#define RHOD_OPEN_TOTALS 7

/* A coupling surface's state (paper 001 Sec. 3.2): at marker k of open boundary b, centre
 * (x, y), time t, the velocity (*u, *v) and density *rho (leave *rho as it comes to keep the
 * fluid's). Returns 0, or non-zero to stop the run (the message is the caller's). */
typedef int (*rhod_open_state_fn)(void *ctx, int b, int k, double t, double x, double y, double *u,
                                  double *v, double *rho);

typedef struct {
  int n;                          /* open boundaries */
  int nout;                       /* outflows among them (without a coupling callback) */
  const rhod_open_boundary *desc; /* the scene's */
  void **law;                     /* per boundary: the inflow speed's evaluator (NULL: outflow) */
  rhod_open_state_fn *fn;         /* per boundary: a coupling callback, NULL where none */
  void **ctx;
  int *first, *count; /* per boundary: its markers */
  double *rho0, *c0;  /* per boundary: the reference density and sound speed of its
                         phase */
  /* markers (host), nmark of them */
  int nmark;
  int *mb;                /* its boundary */
  double *mx, *my;        /* its centre */
  double *us, *vs, *rhos; /* its state for the step (u_s, rho_s of Eq. 20) */
  int *wet;               /* 0: dry (above the inflow's surface, or no fluid near) */
  double *pending;        /* the imbalance carried to the next step (Eq. 26's rest) */
  double *pinf;           /* an outflow marker's ambient pressure (NAN: none, no anchor) */
  double *ukap;           /* an outflow marker's pressure relaxation, a velocity its ghosts
                             add to their source's (2 per marker) */
  /* device: marker points and Shepard values */
  real *px, *py, *fu, *fv, *frho, *fp, *gam;
  /* totals since t = 0 [kg per unit depth]: mass the markers prescribed (Eq. 20) into
   * inflows and out of outflows, and the mass the particles took through each kind */
  double prescribed_in, prescribed_out, taken_in, taken_out;
  double created, deleted; /* particles made and removed */
  double mass0;            /* the fluid's mass at t = 0 */
  /* scratch for the boundary particles (device and host) */
  int32_t *cnt;
  size_t cnt_cap;
  int32_t *bi; /* particle index */
  real *bf;    /* RHOD_OPEN_BF reals per boundary particle */
  size_t bcap;
} rhod_open;

/* Reals per boundary particle in rhod_open.bf: segment, t (along it), depth d (into the
 * fluid), A_i, m, rho, m_0, dm*, x, y, dx */
#define RHOD_OPEN_BF 11

/* Sets up the markers of the scene's open boundaries (their segments are in b already,
 * rhod_boundary_init) and compiles the inflow laws. rho0: per phase, the reference density
 * (a one-fluid scheme's at index 0). Errors: RHOD_ERR_SCENE with a one-line message (too
 * many markers, a law libmatheval refuses), RHOD_ERR_MEMORY. */
int rhod_open_init(rhod_open *o, const rhod_scene *sc, const rhod_boundary *b, const double *rho0,
                   const double *c0, char *err, size_t errlen);
void rhod_open_free(rhod_open *o);

/* Drives open boundary k's state from fn (a coupling surface) instead of its law. */
void rhod_open_couple(rhod_open *o, int k, rhod_open_state_fn fn, void *ctx);

/* The markers' state at time t from the prepared state (cells over fluid and ghosts, V and
 * the pressure P over both): each inflow's law (or callback) for the velocity, the Shepard
 * interpolation of the fluid for the rest (an outflow's velocity with the pressure
 * relaxation RHOD_OPEN_KAPPA); and the inflows' velocity into b's ghost table (b->openu).
 * Returns RHOD_OK, RHOD_ERR_MEMORY, or RHOD_ERR_UNSTABLE with a message when a callback
 * fails or a law is not finite. */
int rhod_open_state(rhod_open *o, rhod_boundary *b, const rhod_particles *p, const rhod_cells *c,
                    int kern, real ratio, const real *V, const real *P, double t, char *err,
                    size_t errlen);

/* Inflow velocities at time t into b->openu (the ghosts' velocity), before a stage. */
int rhod_open_ghost_velocity(rhod_open *o, rhod_boundary *b, double t, char *err, size_t errlen);

/* The mass exchange of a step of size dt (after the integrator; the particles moved). Adds,
 * removes and moves particles (ghosts are dropped). Returns RHOD_OK, RHOD_ERR_MEMORY, or
 * RHOD_ERR_UNSTABLE with a message when a boundary is overwhelmed (more than a particle's
 * mass waits at one of its markers); the particles are then left as they were. */
int rhod_open_exchange(rhod_open *o, const rhod_boundary *b, rhod_particles *p, double dt,
                       const double *rho0_phase, char *err, size_t errlen);

/* The fluid's mass, sum of m over [0, n) (a device reduction). */
double rhod_open_mass(const rhod_particles *p);
/* The end-of-run lines: mass in and out, the fluid's change against them, the imbalance
 * still carried, particles made and removed (nothing without open boundaries). */
void rhod_open_report(const rhod_open *o, const rhod_particles *p, rhod_warn_buf *w);

/* Checkpoint extras: every marker's carried imbalance ("open.m.K") and the totals. */
void rhod_open_save(const rhod_open *o, rhod_checkpoint *ck);
int rhod_open_load(rhod_open *o, const rhod_checkpoint *ck, char *err, size_t errlen);

/* Device side (kernels/open.c). The boundary particles of the step: those within reach of
 * an open segment of b whose cuboid touches it (or that still lack mass): their indices and
 * RHOD_OPEN_BF reals (host copies in o->bi, o->bf). rho0 per phase (phase NULL: index 0).
 * Returns their count, or -1 when out of memory. */
long rhod_open_gather(rhod_open *o, const rhod_boundary *b, const rhod_particles *p,
                      const double *rho0_phase);
/* Writes back mass and position of the nb boundary particles (o->bi, o->bf on the host:
 * m at [4], x, y at [8], [9]) and flags in keep[i] (0: delete) the ones with no mass left. */
void rhod_open_scatter(rhod_open *o, rhod_particles *p, long nb, int32_t *keep);
/* Appends count particles, copies of src[c] (host array) in every persistent field, then
 * sets x, y, ux, uy, rho, m, dx from nf[7 c ...] and, where the store has phases, the phase
 * ph[c] (host arrays). The caller has reserved room. */
void rhod_open_born(rhod_particles *p, int32_t *src, real *nf, uint8_t *ph, int count);

#endif
