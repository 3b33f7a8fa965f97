/* Simulation set-up, stepping, checks and probes. */
#define _DEFAULT_SOURCE /* sysconf(_SC_PHYS_PAGES) */
#include "rhod/sim.h"
#include "rhod/kernel.h"
#include "rhod/shepard.h"
#include "rhod/vorticity.h"
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int in_shape(const rhod_shape *sh, double x, double y) {
  if (sh->kind == RHOD_SHAPE_RECT)
    return x >= sh->min[0] && x <= sh->max[0] && y >= sh->min[1] && y <= sh->max[1];
  if (sh->kind == RHOD_SHAPE_CIRCLE)
    return hypot(x - sh->center[0], y - sh->center[1]) <= sh->radius;
  int inside = 0; /* even-odd rule */
  for (unsigned a = 0, b = sh->n_points - 1; a < sh->n_points; b = a++) {
    const double *P = sh->points[a], *Q = sh->points[b];
    if (RHOD_RAY_CROSSES(P[0], P[1], Q[0], Q[1], x, y))
      inside = !inside;
  }
  return inside;
}

int rhod_shape_contains(const rhod_shape *sh, double x, double y) { return in_shape(sh, x, y); }

/* Whether (x, y) lies in body B (or on its outline) where it stands at t = 0: the point
 * taken back to the body at zero displacement, x0 = G + R(-theta0) (x - G - d0), with d0 and
 * theta0 the law's values at t = 0 (rhod_body.pose0; 0 unless imposed). */
static int in_body0(const rhod_body *B, double x, double y) {
  const double *d = B->pose0, *G = B->center;
  if (d[0] == 0 && d[1] == 0 && d[2] == 0)
    return in_shape(&B->shape, x, y);
  const double rx = x - G[0] - d[0], ry = y - G[1] - d[1], c = cos(d[2]), sn = sin(d[2]);
  return in_shape(&B->shape, G[0] + c * rx + sn * ry, G[1] - sn * rx + c * ry);
}

static void shape_box(const rhod_shape *sh, double lo[2], double hi[2]) {
  if (sh->kind == RHOD_SHAPE_RECT) {
    for (int a = 0; a < 2; a++)
      lo[a] = sh->min[a], hi[a] = sh->max[a];
  } else if (sh->kind == RHOD_SHAPE_CIRCLE) {
    for (int a = 0; a < 2; a++)
      lo[a] = sh->center[a] - sh->radius, hi[a] = sh->center[a] + sh->radius;
  } else {
    lo[0] = lo[1] = HUGE_VAL;
    hi[0] = hi[1] = -HUGE_VAL;
    for (unsigned k = 0; k < sh->n_points; k++)
      for (int a = 0; a < 2; a++) {
        lo[a] = fmin(lo[a], sh->points[k][a]);
        hi[a] = fmax(hi[a], sh->points[k][a]);
      }
  }
}

/* Highest point of a shape along -g (for the hydrostatic start). */
static double shape_top(const rhod_shape *sh, double ex, double ey) {
  if (sh->kind == RHOD_SHAPE_CIRCLE)
    return sh->center[0] * ex + sh->center[1] * ey + sh->radius;
  double lo[2], hi[2], best = -HUGE_VAL;
  if (sh->kind == RHOD_SHAPE_POLYGON) {
    for (unsigned k = 0; k < sh->n_points; k++)
      best = fmax(best, sh->points[k][0] * ex + sh->points[k][1] * ey);
    return best;
  }
  shape_box(sh, lo, hi);
  const double cx[2] = {lo[0], hi[0]}, cy[2] = {lo[1], hi[1]};
  for (int a = 0; a < 2; a++)
    for (int b = 0; b < 2; b++)
      best = fmax(best, cx[a] * ex + cy[b] * ey);
  return best;
}

/* Pressure of a rigid rotation in a rectangle a x b with P = 0 on its sides: the
 * solution of lap P = 2 rho0 omega^2 as the double sine series of paper 002 Eq. 30
 * (x, y from the lower-left corner; only odd m, n contribute: the even terms of the
 * series of a constant vanish). Our choice: terms up to m, n = 199 (the truncation
 * error is below 1e-5 rho0 omega^2 a b). */
static double rotation_pressure(double rho0, double omega, double a, double b, double x, double y) {
  enum { M = 100 };
  double sx[M], sy[M];
  for (int k = 0; k < M; k++) {
    const int m = 2 * k + 1;
    sx[k] = sin(m * M_PI * x / a);
    sy[k] = sin(m * M_PI * y / b);
  }
  double p = 0;
  for (int k = 0; k < M; k++) {
    const double m = 2 * k + 1, km = m * M_PI / a;
    for (int l = 0; l < M; l++) {
      const double n = 2 * l + 1, kn = n * M_PI / b;
      p += -32 * omega * omega / (m * n * M_PI * M_PI * (km * km + kn * kn)) * sx[k] * sy[l];
    }
  }
  return rho0 * p;
}

/* Deterministic uniform numbers in [-0.5, 0.5) for the lattice jitter. */
static double jitter_rand(uint64_t *st) {
  *st = *st * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(*st >> 11) / 9007199254740992.0 - 0.5;
}

/* The jitter given to the lattice as it is filled: particles.jitter, or none where the
 * scheme jitters the lattice itself (its fill_unjittered hook). */
static double lattice_jitter(const rhod_sim *s) {
  return s->ops->fill_unjittered && s->ops->fill_unjittered(s->sc) ? 0 : s->sc->jitter;
}

/* Finest initial level the scheme asks for at (x, y) (its fill_level hook); 0: dx. */
static int region_level(const rhod_sim *s, double x, double y) {
  return s->ops->fill_level ? s->ops->fill_level(s->sc, x, y) : 0;
}

int rhod_sim_block_at(const rhod_sim *s, double x, double y) {
  const rhod_scene *sc = s->sc;
  if (x < s->lo[0] || x > s->hi[0] || y < s->lo[1] || y > s->hi[1])
    return -1;
  if (s->bnd.nseg + s->bnd.ncirc > 0 && rhod_wall_distance(&s->bnd, x, y) <= 0)
    return -1;
  for (unsigned k = 0; k < sc->n_bodies; k++) /* a body's interior at t = 0 stays empty */
    if (in_body0(&sc->bodies[k], x, y))
      return -1;
  for (unsigned b = 0; b < sc->n_fluid; b++) /* a point of an earlier block is not filled twice */
    if (in_shape(&sc->fluid[b].shape, x, y))
      return (int)b;
  return -1;
}

double rhod_sim_block_depth(const rhod_sim *s, unsigned b, double x, double y, double *g_out) {
  const rhod_scene *sc = s->sc;
  const rhod_fluid_block *B = &sc->fluid[b];
  const double g = hypot(sc->gravity[0], sc->gravity[1]);
  const double ex = g > 0 ? -sc->gravity[0] / g : 0, ey = g > 0 ? -sc->gravity[1] / g : 1;
  const double top = B->surface_set ? B->surface : shape_top(&B->shape, ex, ey);
  *g_out = g;
  return top - (x * ex + y * ey);
}

void rhod_sim_initial_flow(const rhod_sim *s, unsigned b, double x, double y, double rho0,
                           double *u_out, double *v_out, double *P_out) {
  const rhod_fluid_block *B = &s->sc->fluid[b];
  double u = B->velocity[0], v = B->velocity[1], P = 0;
  if (B->flow == RHOD_FLOW_TAYLOR_GREEN) {
    const double kw = 2 * M_PI / B->flow_L, U = B->flow_U;
    u += U * sin(kw * x) * cos(kw * y);
    v -= U * cos(kw * x) * sin(kw * y);
    P = rho0 * U * U / 4 * (cos(2 * kw * x) + cos(2 * kw * y));
  } else if (B->flow == RHOD_FLOW_ROTATION) {
    const double w = B->flow_omega;
    u -= w * (y - B->flow_center[1]);
    v += w * (x - B->flow_center[0]);
    P = rotation_pressure(rho0, w, B->shape.max[0] - B->shape.min[0],
                          B->shape.max[1] - B->shape.min[1], x - B->shape.min[0],
                          y - B->shape.min[1]);
  } else if (B->flow == RHOD_FLOW_SHEAR_LAYER) {
    /* paper 000 Eq. 27 (after Lecoanet et al. 2016): two tanh shear layers at y1, y2 and
     * a vertical perturbation of wavelength L localised at both; P unchanged */
    const double y1 = B->flow_y[0], y2 = B->flow_y[1], w = B->flow_width, s2 = B->flow_spread;
    u += B->flow_U * (tanh((y - y1) / w) - tanh((y - y2) / w) - 1);
    v += B->flow_UI * sin(2 * M_PI * x / B->flow_L) *
         (exp(-(y - y1) * (y - y1) / (s2 * s2)) + exp(-(y - y2) * (y - y2) / (s2 * s2)));
  } else if (B->flow == RHOD_FLOW_DROPLET) {
    /* paper 000 Eqs. 28-29 (after Adami et al. 2010), x and y from the centre; divergence
     * free; 0 at the centre (the r -> 0 limit of x y^2/r and y x^2/r) */
    const double X = x - B->flow_center[0], Y = y - B->flow_center[1], R = B->flow_R;
    const double r = hypot(X, Y), e = exp(-r / R);
    if (r > 0) {
      u += B->flow_U * X / R * (1 - Y * Y / (R * r)) * e;
      v -= B->flow_U * Y / R * (1 - X * X / (R * r)) * e;
    }
  }
  *u_out = u, *v_out = v, *P_out = P;
}

/* Why a lattice point of block b that fluid_block_at refused is left out (s->fill). */
static void count_dropped(rhod_sim *s, unsigned b, double x, double y) {
  const rhod_scene *sc = s->sc;
  rhod_fill_stats *f = &s->fill[b];
  if (x < s->lo[0] || x > s->hi[0] || y < s->lo[1] || y > s->hi[1]) {
    f->out_domain++;
    return;
  }
  for (unsigned w = 0; w < sc->n_walls; w++)
    if (!sc->walls[w].fluid_inside && in_shape(&sc->walls[w].shape, x, y)) {
      f->in_obstacle++;
      f->obstacle = f->obstacle < 0 ? (int)w : f->obstacle;
      return;
    }
  for (unsigned w = 0; w < sc->n_walls; w++)
    if (sc->walls[w].fluid_inside && !in_shape(&sc->walls[w].shape, x, y)) {
      f->out_container++;
      f->container = f->container < 0 ? (int)w : f->container;
      return;
    }
  for (unsigned k = 0; k < sc->n_bodies; k++)
    if (in_body0(&sc->bodies[k], x, y)) {
      f->in_body++;
      f->body = f->body < 0 ? (int)k : f->body;
      f->bodies_more |= f->body != (int)k;
      return;
    }
  f->on_wall++;
}

/* One fluid particle of size dx at (x, y) of block b, if the point belongs to block b
 * (fluid_block_at). Counts it; writes it when `write`, else keeps the fill's tally. */
static void emit(rhod_sim *s, unsigned b, double x, double y, double dx, size_t *n, int write) {
  const int owner = rhod_sim_block_at(s, x, y);
  if (owner != (int)b) {
    if (!write && owner < 0 && in_shape(&s->sc->fluid[b].shape, x, y))
      count_dropped(s, b, x, y);
    return;
  }
  /* not within half a size of a body: a particle nearer than that would nearly coincide
   * with its own mirror (docs/choices.md "bodies: fill"; one exactly dx/2 off, as a lattice
   * beside a face half-way between rows, stays); the walls' lattices stand dx/2
   * off them by construction */
  if (s->bnd.nbody > 0 &&
      rhod_body_distance(&s->bnd, x, y) < 0.5 * dx * (1 - 2 * (double)RHOD_SUPPORT_TIE)) {
    if (!write)
      s->fill[b].on_wall++;
    return;
  }
  if (write) {
    s->ops->initial_state(s, b, *n, x, y, dx);
    s->p.id[*n] = *n;
  } else
    s->fill[b].kept++;
  (*n)++;
}

/* "FILE:LINE:COL: fluid.N" (or the override's note) for a message about block b. */
static void block_where(const rhod_scene *sc, unsigned b, char *buf, size_t len) {
  const rhod_fluid_block *B = &sc->fluid[b];
  if (B->line)
    snprintf(buf, len, "%s:%u:%u: fluid.%u", sc->path, B->line, B->col, b);
  else
    snprintf(buf, len, "%s: fluid.%u (given by --set)", sc->path, b);
}

/* The causes of a block's left-out points: "N lie outside its container walls.K, M ...". */
static void block_dropped(const rhod_fill_stats *f, char *buf, size_t len) {
  size_t used = 0;
  buf[0] = '\0';
#define DROP_PUT(...)                                                                              \
  do {                                                                                             \
    if (used < len)                                                                                \
      used += (size_t)snprintf(buf + used, len - used, __VA_ARGS__);                               \
  } while (0)
  if (f->out_container)
    DROP_PUT("%s%zu outside its container walls.%d", used ? ", " : "", f->out_container,
             f->container);
  if (f->in_obstacle)
    DROP_PUT("%s%zu inside the obstacle walls.%d", used ? ", " : "", f->in_obstacle, f->obstacle);
  if (f->in_body)
    DROP_PUT("%s%zu inside the body bodies.%d%s", used ? ", " : "", f->in_body, f->body,
             f->bodies_more ? " and others" : "");
  if (f->out_domain)
    DROP_PUT("%s%zu outside the domain", used ? ", " : "", f->out_domain);
  if (f->on_wall)
    DROP_PUT("%s%zu on a wall", used ? ", " : "", f->on_wall);
#undef DROP_PUT
}

/* Why block b holds no particle, for the "no particle fits" error. */
static void block_empty_why(const rhod_sim *s, unsigned b, char *buf, size_t len) {
  const rhod_fill_stats *f = &s->fill[b];
  const size_t dropped =
      f->out_container + f->in_obstacle + f->in_body + f->out_domain + f->on_wall;
  if (dropped) {
    char causes[512];
    block_dropped(f, causes, sizeof causes);
    snprintf(buf, len, "all %zu of its lattice points are left out: %s", dropped, causes);
  } else {
    snprintf(buf, len,
             "no lattice point of spacing dx falls inside it (it is thinner than dx there) or "
             "an earlier block holds them");
  }
}

/* The lattice cell of size f dx0 (f = 2^-l at level l) centred at lo + (ci, cj) dx0:
 * one particle (jittered by (jx, jy) of its size), or, where a refinement region asks
 * for a finer level at its centre, its four quarter cells, each refined again where
 * asked. This nests the levels as a quadtree: the recipe of paper 002 Sec. VI C
 * (Fig. 14) once the regions are at least 8 dx of their level apart. */
static void fill_cell(rhod_sim *s, unsigned b, const double lo[2], double dx0, double ci, double cj,
                      double f, int l, double jx, double jy, uint64_t *rs, size_t *n, int write) {
  if (region_level(s, lo[0] + ci * dx0, lo[1] + cj * dx0) <= l) {
    emit(s, b, lo[0] + (ci + jx * f) * dx0, lo[1] + (cj + jy * f) * dx0, f * dx0, n, write);
    return;
  }
  for (int q = 0; q < 4; q++) {
    const double jit = lattice_jitter(s);
    const double j2x = jit * jitter_rand(rs), j2y = jit * jitter_rand(rs);
    fill_cell(s, b, lo, dx0, ci + ((q & 1) ? 0.25 : -0.25) * f, cj + ((q & 2) ? 0.25 : -0.25) * f,
              0.5 * f, l + 1, j2x, j2y, rs, n, write);
  }
}

static int fill_fluid(rhod_sim *s, char *err, size_t errlen) {
  const rhod_scene *sc = s->sc;
  const double dx = sc->dx;
  /* count first, then fill */
  for (int pass = 0; pass < 2; pass++) {
    size_t n = 0;
    /* the same sequence in both passes: a lattice point keeps its place */
    uint64_t rs = 0x5eed;
    for (unsigned b = 0; b < sc->n_fluid; b++) {
      const rhod_fluid_block *B = &sc->fluid[b];
      double lo[2], hi[2];
      shape_box(&B->shape, lo, hi);
      const long nx = (long)floor((hi[0] - lo[0]) / dx + 1e-9);
      const long ny = (long)floor((hi[1] - lo[1]) / dx + 1e-9);
      for (long j = 0; j < ny; j++)
        for (long i = 0; i < nx; i++) {
          /* particles.jitter breaks the symmetry of the lattice, which otherwise
           * deforms affinely under a strain field, where Fickian shifting (uniform
           * concentration) cannot act, until it collapses (seen on the Taylor-Green
           * vortex) */
          const double jit = lattice_jitter(s);
          const double jx = jit * jitter_rand(&rs), jy = jit * jitter_rand(&rs);
          fill_cell(s, b, lo, dx, i + 0.5, j + 0.5, 1.0, 0, jx, jy, &rs, &n, pass);
        }
    }
    if (pass == 0) {
      if (n == 0) {
        char where[512], why[768];
        block_where(sc, 0, where, sizeof where);
        block_empty_why(s, 0, why, sizeof why);
        snprintf(err, errlen, "%s: no particle fits at dx = %g m: %s%s", where, dx, why,
                 sc->n_fluid > 1 ? "; no other block holds one either" : "");
        return RHOD_ERR_SCENE;
      }
      if (n > 2000000000u) {
        snprintf(err, errlen, "%s: particles.dx: %zu particles is more than supported", sc->path,
                 n);
        return RHOD_ERR_SCENE;
      }
      int st = rhod_particles_reserve(&s->p, n + n / 2 + 256);
      if (st != RHOD_OK) {
        snprintf(err, errlen, "out of memory for %zu particles", n);
        return st;
      }
    } else {
      s->p.n = n;
      s->p.next_id = n;
    }
  }
  return RHOD_OK;
}

int rhod_sim_restate(rhod_sim *s, double jit, const int *blk) {
  rhod_particles *p = &s->p;
  rhod_particles_to_host(p);
  uint64_t rs = 0x5eed;
  for (size_t k = 0; k < p->n; k++) {
    const double x = p->x[k], y = p->y[k], dx = p->dx[k];
    const double xj = x + jit * dx * jitter_rand(&rs), yj = y + jit * dx * jitter_rand(&rs);
    const uint64_t id = p->id[k];
    const int b = blk ? blk[id] : rhod_sim_block_at(s, x, y);
    if (b < 0)
      continue;
    const int moved = rhod_sim_block_at(s, xj, yj) == b;
    s->ops->initial_state(s, (unsigned)b, k, moved ? xj : x, moved ? yj : y, dx);
    p->id[k] = id;
  }
  rhod_particles_to_device(p);
  return rhod_sim_prepare(s, 1);
}

/* The probe kinds rhod_probe_values reads itself; the others are the scheme's. */
static int engine_probe(rhod_probe_kind kind) {
  return kind != RHOD_PROBE_ELASTIC_ENERGY && kind != RHOD_PROBE_TORQUE_BUDGET;
}

/* ---- output.fields ------------------------------------------------------------------------ */

/* The engine's own fields output.fields may name: the persistent tags (where a scheme has
 * them; the phase is written as Phase already). */
static const rhod_output_field engine_outputs[] = {
    {"level", "Level", "1"},
    {"kind", "Kind", "1"},
    {"vort", "Vorticities", "1/s"}, /* computed at output (vorticity.h) */
    {NULL, NULL, NULL},
};

/* The store's entry for a field output.fields may name: in the engine's or the scheme's
 * list, registered in this run, and of a type a snapshot holds (uint8, 1 or 2 reals);
 * *d its description, *scheme 1 when it is the scheme's. NULL when there is none. */
static const rhod_field_desc *output_field(const rhod_sim *s, const char *name,
                                           const rhod_output_field **d, int *scheme) {
  const rhod_output_field *lists[2] = {engine_outputs, s->ops->outputs};
  for (int l = 0; l < 2; l++)
    for (const rhod_output_field *o = lists[l]; o && o->field; o++) {
      if (strcmp(o->field, name) != 0)
        continue;
      for (int k = 0; k < s->p.nfields; k++) {
        const rhod_field_desc *f = &s->p.fields[k];
        const size_t e = f->elem;
        if (strcmp(f->name, name) == 0 && (e == 1 || e == sizeof(real) || e == 2 * sizeof(real))) {
          *d = o;
          *scheme = l;
          return f;
        }
      }
    }
  return NULL;
}

/* Every name of output.fields must be a field this run can write: else the message names
 * the key, the name and those it has. */
static int check_output_fields(const rhod_sim *s, char *err, size_t errlen) {
  const rhod_scene *sc = s->sc;
  for (unsigned i = 0; i < sc->n_output_fields; i++) {
    const rhod_output_field *d;
    int scheme;
    if (output_field(s, sc->output_fields[i], &d, &scheme))
      continue;
    char have[512] = "";
    size_t at = 0;
    const rhod_output_field *lists[2] = {engine_outputs, s->ops->outputs};
    for (int l = 0; l < 2; l++)
      for (const rhod_output_field *o = lists[l]; o && o->field; o++)
        if (output_field(s, o->field, &d, &scheme) && at < sizeof have)
          at += (size_t)snprintf(have + at, sizeof have - at, "%s%s", at ? ", " : "", o->field);
    snprintf(err, errlen,
             "%s: output.fields.%u: no field '%s' to write with scheme %s; available: %s", sc->path,
             i, sc->output_fields[i], s->ops->name, at ? have : "none");
    return RHOD_ERR_SCENE;
  }
  return RHOD_OK;
}

int rhod_sim_init(rhod_sim *s, const rhod_scene *sc, char *err, size_t errlen) {
  memset(s, 0, sizeof *s);
  s->sc = sc;
  /* the lattice is not walked for a count the machine cannot hold (docs/choices.md
   * "load-time limits"): the loader refuses more than RHOD_MAX_PARTICLES, this the memory */
  const double est = rhod_scene_particle_estimate(sc);
  const double mem = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
  if (!(est <= RHOD_MAX_PARTICLES)) {
    snprintf(err, errlen, "%s: particles.dx: %g m makes about %.3g particles, more than %.0e",
             sc->path, sc->dx, est, RHOD_MAX_PARTICLES);
    return RHOD_ERR_SCENE;
  }
  if (mem > 0 && est * (double)RHOD_BYTES_PER_PARTICLE > mem) {
    snprintf(err, errlen,
             "%s: particles.dx: %g m makes about %.3g particles, at least %.3g GB at %zu bytes "
             "each, more than this machine's %.3g GB of memory",
             sc->path, sc->dx, est, est * (double)RHOD_BYTES_PER_PARTICLE / 1e9,
             (size_t)RHOD_BYTES_PER_PARTICLE, mem / 1e9);
    return RHOD_ERR_MEMORY;
  }
  s->fill = calloc(sc->n_fluid ? sc->n_fluid : 1, sizeof *s->fill);
  if (!s->fill) {
    snprintf(err, errlen, "out of memory setting up the particles");
    return RHOD_ERR_MEMORY;
  }
  for (unsigned b = 0; b < sc->n_fluid; b++)
    s->fill[b].obstacle = s->fill[b].container = s->fill[b].body = -1;
  if (sc->has_domain) {
    for (int a = 0; a < 2; a++)
      s->lo[a] = sc->domain_min[a], s->hi[a] = sc->domain_max[a];
  } else {
    s->lo[0] = s->lo[1] = HUGE_VAL;
    s->hi[0] = s->hi[1] = -HUGE_VAL;
    double lo[2], hi[2];
    for (unsigned k = 0; k < sc->n_fluid + sc->n_walls; k++) {
      const rhod_shape *sh =
          k < sc->n_fluid ? &sc->fluid[k].shape : &sc->walls[k - sc->n_fluid].shape;
      shape_box(sh, lo, hi);
      for (int a = 0; a < 2; a++)
        s->lo[a] = fmin(s->lo[a], lo[a]), s->hi[a] = fmax(s->hi[a], hi[a]);
    }
  }
  s->ops = rhod_scheme_for(sc);
  if (!s->ops) {
    snprintf(err, errlen, "%s: scheme.name: this build has no such scheme", sc->path);
    return RHOD_ERR_SCENE;
  }
  s->margin = sc->radius_ratio * sc->dx; /* particles.dx is the coarsest size (level 0) */
  int st = s->ops->geometry(sc, &s->dx_min, &s->mirror_ratio, err, errlen);
  if (st != RHOD_OK)
    return st;
  s->mirror_ratio *= sc->radius_ratio;
  st = rhod_particles_init(&s->p, 1024);
  if (st == RHOD_OK)
    st = rhod_boundary_init(&s->bnd, sc, s->lo, s->hi);
  if (st == RHOD_OK && sc->n_bodies > 0)
    st = rhod_particles_add_body_fields(&s->p);
  if (st == RHOD_OK && s->bnd.noslip)
    st = rhod_particles_add_noslip_fields(&s->p);
  if (st != RHOD_OK) {
    snprintf(err, errlen, "out of memory setting up the particles");
    return st;
  }
  if (sc->n_bodies > RHOD_MAX_BODIES) {
    snprintf(err, errlen, "%s: bodies: %u bodies, at most %d", sc->path, sc->n_bodies,
             RHOD_MAX_BODIES);
    return RHOD_ERR_SCENE;
  }
  /* the bodies where they stand at t = 0 (the fill leaves their insides empty) */
  st = rhod_bodies_init(&s->bodies, sc, &s->bnd, 0.0, 0.5 * s->dx_min, err, errlen);
  if (st != RHOD_OK) {
    if (st == RHOD_ERR_MEMORY)
      snprintf(err, errlen, "out of memory setting up the bodies");
    return st;
  }
  rhod_particles *p = &s->p;
  /* the integrator, then the scheme's fields and variables: their arrays grow with the
   * fill's reservation */
  st = rhod_rk_init(&s->rk, p, sc->integrator);
  if (st != RHOD_OK) {
    snprintf(err, errlen, "%s: time.integrator: unknown method", sc->path);
    return st;
  }
  st = s->ops->init(s, err, errlen);
  if (st != RHOD_OK)
    return st;
  /* the free bodies' added-mass estimates, with the scheme's densest fluid */
  double rho_max = 0;
  for (int k = 0; k < RHOD_SIM_PHASES; k++)
    rho_max = fmax(rho_max, s->rho0[k]);
  rhod_bodies_relaxation(&s->bodies, rho_max);
  /* the open boundaries' markers (their segments are in the boundary already) */
  st = rhod_open_init(&s->open, sc, &s->bnd, s->rho0, s->c0, err, errlen);
  if (st != RHOD_OK) {
    if (st == RHOD_ERR_MEMORY)
      snprintf(err, errlen, "out of memory setting up the open boundaries");
    return st;
  }
  /* the probes the engine does not read must be the scheme's */
  for (unsigned i = 0; i < sc->n_probes; i++)
    if (!engine_probe(sc->probes[i].kind) && s->ops->probe(s, &sc->probes[i], NULL) != RHOD_OK) {
      snprintf(err, errlen, "%s: probes.list.%u: the %s probe is not available with scheme %s",
               sc->path, i, sc->probes[i].name, s->ops->name);
      return RHOD_ERR_SCENE;
    }
  /* the vorticity, where the picture or output.fields asks for it: a store field the
   * output fills (rhod_sim_fetch) */
  int vort = sc->picture_enabled && sc->picture_field == RHOD_FIELD_VORTICITY;
  for (unsigned i = 0; i < sc->n_output_fields; i++)
    vort |= strcmp(sc->output_fields[i], "vort") == 0;
  if (vort && rhod_particles_add_field(p, "vort", (void **)&s->vort, sizeof(real), 0) != RHOD_OK) {
    snprintf(err, errlen, "out of memory for the vorticity");
    return RHOD_ERR_MEMORY;
  }
  /* the fields output.fields names must be the run's */
  st = check_output_fields(s, err, errlen);
  if (st != RHOD_OK)
    return st;
  /* host-side fill happens before anything is sent to the device */
  st = fill_fluid(s, err, errlen);
  if (st != RHOD_OK)
    return st;
  rhod_particles_to_device(p); /* the persistent state goes to the device */
  if (s->open.n > 0)
    s->open.mass0 = rhod_open_mass(p);
  const double glo[2] = {s->lo[0] - 2 * s->margin, s->lo[1] - 2 * s->margin};
  const double ghi[2] = {s->hi[0] + 2 * s->margin, s->hi[1] + 2 * s->margin};
  /* one grid made for the finest radius; coarser particles scan more cells (cells.h) */
  st = rhod_cells_init(&s->cells, glo, ghi, sc->radius_ratio * s->dx_min, RHOD_CELL_REACH, p->cap);
  if (st != RHOD_OK) {
    snprintf(err, errlen, "%s: domain: too many cells for a finest size of %g m", sc->path,
             s->dx_min);
    return st;
  }
  st = rhod_sim_prepare(s, 1);
  if (st == RHOD_OK && s->ops->start)
    st = s->ops->start(s, err, errlen);
  return st;
}

void rhod_sim_free(rhod_sim *s) {
  free(s->fill);
  s->fill = NULL;
  if (s->ops && s->ops->free)
    s->ops->free(s);
  rhod_cells_free(&s->cells);
  rhod_bodies_free(&s->bodies);
  rhod_open_free(&s->open);
  free(s->outline_start);
  free(s->outline_xy);
  s->outline_start = NULL, s->outline_xy = NULL;
  rhod_boundary_free(&s->bnd);
  /* the store frees the scheme's fields through pointers that live in its state: the
   * state goes last */
  rhod_particles_free(&s->p);
  free(s->sch);
  s->sch = NULL;
}

/* Periodic wrap of the fluid into the box (once per step, before sorting). */
static void wrap_periodic(rhod_sim *s) {
  rhod_particles *p = &s->p;
  const long n = (long)p->n;
  real *x = p->x, *y = p->y;
  const int px = s->bnd.periodic[0], py = s->bnd.periodic[1];
  if (!px && !py)
    return;
  const real lox = (real)s->lo[0], loy = (real)s->lo[1];
  const real Lx = (real)(s->hi[0] - s->lo[0]), Ly = (real)(s->hi[1] - s->lo[1]);
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    if (px) {
      if (x[i] < lox)
        x[i] += Lx;
      else if (x[i] >= lox + Lx)
        x[i] -= Lx;
    }
    if (py) {
      if (y[i] < loy)
        y[i] += Ly;
      else if (y[i] >= loy + Ly)
        y[i] -= Ly;
    }
  }
}

/* rhod_sim_prepare for the state at time t (a stage's): the inflows' ghosts carry their
 * velocity at t. */
static int prepare_at(rhod_sim *s, int sort, double t) {
  rhod_particles *p = &s->p;
  if (s->open.n > 0 && rhod_open_ghost_velocity(&s->open, &s->bnd, t, NULL, 0) != RHOD_OK)
    return RHOD_ERR_UNSTABLE;
  if (sort) {
    wrap_periodic(s);
    p->ng = 0;
    if (rhod_cells_reserve(&s->cells, p->cap) != RHOD_OK)
      return RHOD_ERR_MEMORY;
    rhod_cells_build(&s->cells, p->x, p->y, p->n);
    /* the fluid part of the cell order is the new particle order */
    int32_t *perm = p->perm;
    const int32_t *idx = s->cells.idx;
    const long n = (long)p->n;
    RHOD_KERNEL_LOOP
    for (long k = 0; k < n; k++)
      perm[k] = idx[k];
    rhod_particles_permute(p);
  }
  int st = rhod_ghosts_build(&s->bnd, p, (real)s->mirror_ratio, (real)s->margin);
  if (st != RHOD_OK)
    return st;
  if (rhod_cells_reserve(&s->cells, p->cap) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  s->ops->ghost_state(s);
  rhod_cells_build(&s->cells, p->x, p->y, p->n + p->ng);
  s->neighbours_fresh = 1;
  return RHOD_OK;
}

int rhod_sim_prepare(rhod_sim *s, int sort) { return prepare_at(s, sort, s->t); }

/* Finds the first fluid particle that is not finite or out of the domain. */
static int check_state(rhod_sim *s, char *err, size_t errlen) {
  rhod_particles *p = &s->p;
  const long n = (long)p->n;
  const real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy, *rho = p->rho;
  const real lox = (real)s->lo[0], hix = (real)s->hi[0], loy = (real)s->lo[1], hiy = (real)s->hi[1];
  const int px = s->bnd.periodic[0], py = s->bnd.periodic[1];
  /* periodic axes may sit up to one step outside before the wrap */
  const real mx = px ? (real)s->margin : 0, my = py ? (real)s->margin : 0;
  /* behind an open boundary is not outside: the exchange that follows takes it (open.h) */
  const real *seg = s->bnd.seg;
  const int o0 = s->bnd.open0, o1 = s->bnd.nwallseg;
  long bad = n;
  RHOD_KERNEL_LOOP_REDUCE(min, bad)
  for (long i = 0; i < n; i++) {
    const int finite = isfinite(x[i]) && isfinite(y[i]) && isfinite(ux[i]) && isfinite(uy[i]) &&
                       isfinite(rho[i]) && rho[i] > 0;
    int inside = x[i] >= lox - mx && x[i] <= hix + mx && y[i] >= loy - my && y[i] <= hiy + my;
    for (int k = o0; k < o1 && !inside; k++) {
      const real *S = seg + RHOD_SEG_STRIDE * k;
      const real rx = x[i] - S[0], ry = y[i] - S[1], t = S[4] * rx + S[5] * ry;
      inside = S[2] * rx + S[3] * ry < 0 && t >= 0 && t <= S[6];
    }
    if (!(finite && inside) && i < bad)
      bad = i;
  }
  if (bad == n) {
    /* a particle deep inside a body: the body overtook it or it went through (stops the
     * run: its ghosts would be wrong from now on) */
    int body;
    const long e = rhod_bodies_entered(&s->bnd, p, &body);
    if (e < 0)
      return RHOD_OK;
    rhod_to_host(p->id + e, sizeof(uint64_t));
    snprintf(err, errlen,
             "unstable at t = %.6g s (step %ld): particle id %llu entered body %s (more than "
             "half its size inside, at x = %g, y = %g)",
             s->t, s->step, (unsigned long long)p->id[e],
             body >= 0 ? s->sc->bodies[body].name : "?", (double)p->x[e], (double)p->y[e]);
    return RHOD_ERR_UNSTABLE;
  }
  real v[5];
  rhod_to_host(p->x + bad, sizeof(real));
  rhod_to_host(p->y + bad, sizeof(real));
  rhod_to_host(p->ux + bad, sizeof(real));
  rhod_to_host(p->uy + bad, sizeof(real));
  rhod_to_host(p->rho + bad, sizeof(real));
  rhod_to_host(p->id + bad, sizeof(uint64_t));
  v[0] = p->x[bad], v[1] = p->y[bad], v[2] = p->ux[bad], v[3] = p->uy[bad], v[4] = p->rho[bad];
  const unsigned long long id = (unsigned long long)p->id[bad];
  const char *what;
  if (!isfinite(v[4]) || !(v[4] > 0))
    what = "density is not finite and positive";
  else if (!isfinite(v[2]) || !isfinite(v[3]))
    what = "velocity is not finite";
  else if (!isfinite(v[0]) || !isfinite(v[1]))
    what = "position is not finite";
  else
    what = "left the domain";
  snprintf(err, errlen,
           "unstable at t = %.6g s (step %ld): particle id %llu %s (x = %g, y = %g, u = %g, "
           "v = %g, rho = %g)",
           s->t, s->step, id, what, (double)v[0], (double)v[1], (double)v[2], (double)v[3],
           (double)v[4]);
  return RHOD_ERR_UNSTABLE;
}

int rhod_sim_dt(rhod_sim *s) { return s->ops->dt(s); }

int rhod_sim_step(rhod_sim *s, double dt, char *err, size_t errlen) {
  rhod_particles *p = &s->p;
  int st;
  if (!s->neighbours_fresh) {
    st = rhod_sim_prepare(s, 1);
    if (st != RHOD_OK)
      goto mem;
  }
  /* the open boundaries' markers take the state of the step's start (open.h) */
  st = rhod_open_state(&s->open, &s->bnd, p, &s->cells, s->sc->kernel, (real)s->sc->radius_ratio,
                       *s->V, *s->P, s->t, err, errlen);
  if (st != RHOD_OK)
    return st;
  /* an outflow's ghosts carry the pressure relaxation just measured: built again, so that
   * the step depends on the state at its start only (a resumed run does the same) */
  if (s->open.nout > 0) {
    st = rhod_sim_prepare(s, 0);
    if (st != RHOD_OK)
      goto mem;
  }
  rhod_rk_begin(&s->rk, p);
  rhod_bodies_begin(&s->bodies);
  for (int stage = 0; stage < s->rk.stages; stage++) {
    if (stage > 0) {
      st = prepare_at(s, 0, s->t + (double)s->rk.table.c[stage - 1] * dt);
      if (st != RHOD_OK)
        goto mem;
    }
    st = s->ops->rhs(s, stage, s->t, (real)dt);
    if (st != RHOD_OK)
      goto mem;
    if (s->bodies.moving) {
      /* the bodies in lockstep (body.h): free ones take this stage's force, every moving
       * one stands where the next stage is evaluated */
      st = rhod_bodies_forces(&s->bodies, p, &s->cells, s->sc->kernel, (real)s->sc->radius_ratio,
                              *s->P, *s->V, (real)s->body_mu, s->body_nu ? *s->body_nu : NULL);
      if (st != RHOD_OK)
        goto mem;
      rhod_bodies_stage(&s->bodies, &s->rk.table, stage, s->t, dt, s->sc->gravity);
      rhod_bodies_place(&s->bodies, &s->bnd);
    }
    rhod_rk_stage(&s->rk, p, stage, (real)dt);
  }
  s->neighbours_fresh = 0;
  s->reflected += rhod_walls_guard(&s->bnd, p);
  s->t += dt;
  s->step++;
  s->particle_steps += (double)p->n;
  st = check_state(s, err, errlen);
  if (st != RHOD_OK)
    return st;
  if (s->ops->end_step) {
    st = s->ops->end_step(s);
    if (st != RHOD_OK)
      goto mem;
  }
  /* mass in and out through the open boundaries, after the scheme's end of step (RHOD-SPH's
   * refinement marks go by particle index, which the exchange renumbers: found by
   * cases/open_channel_fs, particles split below dx_min at the outflow) */
  st = rhod_open_exchange(&s->open, &s->bnd, p, dt, s->rho0, err, errlen);
  if (st == RHOD_ERR_UNSTABLE)
    return st;
  if (st != RHOD_OK)
    goto mem;
  return RHOD_OK;
mem:
  snprintf(err, errlen, "out of memory for %zu particles at t = %g s", p->n, s->t);
  return st;
}

int rhod_sim_stats(const rhod_sim *s, rhod_stat *out, int max) {
  return s->ops && s->ops->stats ? s->ops->stats(s, out, max) : 0;
}

void rhod_sim_report(const rhod_sim *s, long steps, rhod_warn_buf *w) {
  if (s->ops && s->ops->report)
    s->ops->report(s, steps, w);
  rhod_open_report(&s->open, &s->p, w);
}

unsigned rhod_probe_columns(const rhod_scene *sc, char (*buf)[RHOD_PROBE_NAME_MAX],
                            const char **names, unsigned max) {
  unsigned k = 0;
  for (unsigned i = 0; i < sc->n_probes && k < max; i++) {
    const rhod_probe *pr = &sc->probes[i];
    const unsigned nc = rhod_probe_ncolumns(pr->kind);
    for (unsigned a = 0; a < nc && k < max; a++, k++) {
      /* the loader names every probe */
      snprintf(buf[k], RHOD_PROBE_NAME_MAX, "%s%s", pr->name, rhod_probe_suffix(pr->kind, a));
      names[k] = buf[k];
    }
  }
  /* then each body's (body.h) */
  for (unsigned b = 0; b < sc->n_bodies; b++)
    for (unsigned a = 0; a < RHOD_BODY_COLUMNS && k < max; a++, k++) {
      snprintf(buf[k], RHOD_PROBE_NAME_MAX, "%s%s", sc->bodies[b].name, rhod_body_column_suffix[a]);
      names[k] = buf[k];
    }
  return k;
}

/* The pressure probes are read PROBE_CHUNK points at a time. */
#define PROBE_CHUNK 16

/* Pressure at the nq points (px, py): Shepard interpolation (rhod_shepard, paper 000 Eq. 8)
 * over fluid and ghosts from the cells of the prepared state; 0 where the support is dry
 * (Gamma < 0.1). A point has no size of its own: each particle contributes with its own
 * radius R_j (our choice; one size gives the usual sum). Into values[col[q]]. */
static void pressure_probes(rhod_sim *s, int nq, real *px, real *py, const unsigned *col,
                            double *values) {
  if (nq == 0)
    return;
  const rhod_particles *p = &s->p;
  real fp[PROBE_CHUNK], gm[PROBE_CHUNK];
  const size_t bytes = (size_t)nq * sizeof(real);
  rhod_dev_map(px, bytes);
  rhod_dev_map(py, bytes);
  rhod_dev_map(fp, bytes);
  rhod_dev_map(gm, bytes);
  rhod_shepard(&s->cells, s->sc->kernel, (real)s->sc->radius_ratio, p->x, p->y, p->dx, *s->V, *s->P,
               nq, px, py, fp, gm);
  rhod_to_host(fp, bytes);
  rhod_to_host(gm, bytes);
  rhod_dev_unmap(px, bytes);
  rhod_dev_unmap(py, bytes);
  rhod_dev_unmap(fp, bytes);
  rhod_dev_unmap(gm, bytes);
  for (int q = 0; q < nq; q++)
    values[col[q]] = gm[q] > (real)0.1 ? (double)fp[q] : 0.0;
}

void rhod_probe_values(rhod_sim *s, double *values) {
  const rhod_scene *sc = s->sc;
  rhod_particles *p = &s->p;
  const long n = (long)p->n;
  const real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy, *m = p->m;
  const real gx = (real)sc->gravity[0], gy = (real)sc->gravity[1];
  real px[PROBE_CHUNK], py[PROBE_CHUNK];
  unsigned col[PROBE_CHUNK];
  int nq = 0;
  unsigned k = 0;
  for (unsigned i = 0; i < sc->n_probes; i++) {
    const rhod_probe *pr = &sc->probes[i];
    const real ax = (real)pr->at[0], ay = (real)pr->at[1];
    const real dx_ = (real)pr->direction[0], dy_ = (real)pr->direction[1];
    switch (pr->kind) {
    case RHOD_PROBE_PRESSURE:
      px[nq] = ax, py[nq] = ay, col[nq] = k++;
      if (++nq == PROBE_CHUNK) {
        pressure_probes(s, nq, px, py, col, values);
        nq = 0;
      }
      break;
    case RHOD_PROBE_KINETIC_ENERGY: {
      real e = 0;
      RHOD_KERNEL_LOOP_REDUCE(+, e)
      for (long j = 0; j < n; j++)
        e += (real)0.5 * m[j] * (ux[j] * ux[j] + uy[j] * uy[j]);
      values[k++] = e;
      break;
    }
    case RHOD_PROBE_POTENTIAL_ENERGY: {
      real e = 0;
      RHOD_KERNEL_LOOP_REDUCE(+, e)
      for (long j = 0; j < n; j++)
        e -= m[j] * (gx * x[j] + gy * y[j]);
      values[k++] = e;
      break;
    }
    case RHOD_PROBE_FRONT: {
      real f = -(real)FLT_MAX;
      RHOD_KERNEL_LOOP_REDUCE(max, f)
      for (long j = 0; j < n; j++) {
        const real v = x[j] * dx_ + y[j] * dy_;
        f = v > f ? v : f;
      }
      values[k++] = f;
      break;
    }
    case RHOD_PROBE_MASS: {
      real e = 0;
      RHOD_KERNEL_LOOP_REDUCE(+, e)
      for (long j = 0; j < n; j++)
        e += m[j];
      values[k++] = e;
      break;
    }
    case RHOD_PROBE_MOMENTUM: {
      real a = 0, b = 0;
      RHOD_KERNEL_LOOP_REDUCE2(+, a, b)
      for (long j = 0; j < n; j++)
        a += m[j] * ux[j], b += m[j] * uy[j];
      values[k++] = a;
      values[k++] = b;
      break;
    }
    case RHOD_PROBE_ANGULAR_MOMENTUM: {
      real a = 0;
      RHOD_KERNEL_LOOP_REDUCE(+, a)
      for (long j = 0; j < n; j++)
        a += m[j] * ((x[j] - ax) * uy[j] - (y[j] - ay) * ux[j]);
      values[k++] = a;
      break;
    }
    default:
      /* the scheme's own probes (rhod_sim_init refused those it has not), after the
       * pressures before them (a scheme's probe may use the scheme's scratch) */
      pressure_probes(s, nq, px, py, col, values);
      nq = 0;
      s->ops->probe(s, pr, values + k);
      k += rhod_probe_ncolumns(pr->kind);
      break;
    }
  }
  pressure_probes(s, nq, px, py, col, values);
  if (s->bodies.n > 0) {
    /* the force on each body at this (prepared) state; without the scratch it needs, NaN
     * (the run's snapshot check does not see probes: the row says what is missing) */
    if (rhod_bodies_forces(&s->bodies, p, &s->cells, sc->kernel, (real)sc->radius_ratio, *s->P,
                           *s->V, (real)s->body_mu, s->body_nu ? *s->body_nu : NULL) != RHOD_OK)
      for (int b = 0; b < s->bodies.n; b++)
        s->bodies.b[b].F[0] = s->bodies.b[b].F[1] = s->bodies.b[b].F[2] = NAN;
    rhod_bodies_values(&s->bodies, values + k);
  }
}

int rhod_sim_fetch(rhod_sim *s, rhod_snapshot_view *v) {
  rhod_particles *p = &s->p;
  const rhod_scene *sc = s->sc;
  *v = (rhod_snapshot_view){0};
  /* a field of the scheme's among output.fields: the scheme computes it for this state,
   * which needs the ghosts and cells of the current positions. After a step they are
   * built again here, unsorted, and marked stale again, so that the next step sorts and
   * builds them as it would have: the run goes on bit for bit as without the fields. */
  int refresh = s->vort && !s->neighbours_fresh; /* the vorticity's gather too */
  for (unsigned i = 0; i < sc->n_output_fields && !s->neighbours_fresh; i++) {
    const rhod_output_field *d;
    int scheme = 0;
    output_field(s, sc->output_fields[i], &d, &scheme);
    refresh |= scheme;
  }
  if (refresh) {
    const int st = rhod_sim_prepare(s, 0);
    if (st != RHOD_OK)
      return st;
  }
  s->ops->output(s, v); /* the scheme's fields (pressure, free surface ...) */
  if (s->vort) {
    rhod_vorticity(&s->cells, p, sc->kernel, (real)sc->radius_ratio, *s->V, s->vort);
    rhod_to_host(s->vort, p->n * sizeof(real));
    v->vort = s->vort;
  }
  if (refresh)
    s->neighbours_fresh = 0;
  const size_t n = p->n;
  real *const f[7] = {p->x, p->y, p->ux, p->uy, p->rho, p->m, p->dx};
  for (int k = 0; k < 7; k++)
    rhod_to_host(f[k], n * sizeof(real));
  rhod_to_host(p->id, n * sizeof(uint64_t));
  v->time = s->t;
  v->n = n;
  v->x = p->x, v->y = p->y, v->ux = p->ux, v->uy = p->uy, v->rho = p->rho;
  v->m = p->m, v->size = p->dx, v->id = p->id;
  if (p->phase) { /* the phase tag, where a scheme has one */
    rhod_to_host(p->phase, n);
    v->phase = p->phase;
  }
  /* output.fields, in the scene's order (rhod_sim_init checked the names) */
  for (unsigned i = 0; i < sc->n_output_fields && v->nextra < RHOD_MAX_EXTRA_FIELDS; i++) {
    const rhod_output_field *d;
    int scheme;
    const rhod_field_desc *fd = output_field(s, sc->output_fields[i], &d, &scheme);
    if (!fd)
      continue;
    void *data = *fd->ptr;
    rhod_to_host(data, n * fd->elem);
    v->extra[v->nextra++] = (rhod_snapshot_extra){
        .name = d->dataset,
        .units = d->units,
        .data = data,
        .u8 = fd->elem == 1,
        .comps = fd->elem == 2 * sizeof(real) ? 2 : 1,
    };
  }
  if (s->bodies.n > 0) { /* where the bodies stand (circles with segments of dx/4) */
    free(s->outline_start);
    free(s->outline_xy);
    s->outline_start = NULL, s->outline_xy = NULL;
    const int st =
        rhod_bodies_outline(&s->bodies, 0.25 * s->dx_min, &s->outline_start, &s->outline_xy);
    if (st != RHOD_OK)
      return st;
    v->n_bodies = (unsigned)s->bodies.n;
    v->body_start = s->outline_start;
    v->body_xy = s->outline_xy;
  }
  return RHOD_OK;
}

/* ---- warnings about the particles as set up -------------------------------------------- */

/* Whether the ray from (x, y) along the unit vector d meets a wall. */
static int wall_along(const rhod_boundary *b, double x, double y, const double d[2]) {
  for (int k = 0; k < b->nseg; k++) {
    const real *S = b->seg + RHOD_SEG_STRIDE * k;
    if (S[7] >= RHOD_SEG_INFLOW) /* an open boundary holds nothing up */
      continue;
    const double tx = S[4], ty = S[5], ax = S[0] - x, ay = S[1] - y;
    const double den = d[0] * ty - d[1] * tx;
    if (fabs(den) < 1e-12)
      continue;
    const double t = (ax * ty - ay * tx) / den, u = (ax * d[1] - ay * d[0]) / den;
    if (t > 0 && u >= 0 && u <= S[6])
      return 1;
  }
  for (int k = 0; k < b->ncirc; k++) {
    const real *C = b->circ + RHOD_CIRC_STRIDE * k;
    const double px = x - C[0], py = y - C[1];
    const double hb = px * d[0] + py * d[1], c = px * px + py * py - (double)C[2] * C[2];
    const double disc = hb * hb - c;
    if (disc >= 0 && -hb + sqrt(disc) > 0)
      return 1;
  }
  return 0;
}

int rhod_sim_warnings(rhod_sim *s, char *buf, size_t len) {
  rhod_warn_buf w = {buf, len, 0, 0};
  if (buf && len)
    buf[0] = '\0';
  if (!s || !s->sc)
    return 0;
  const rhod_scene *sc = s->sc;
  rhod_particles *p = &s->p;
  rhod_particles_to_host(p);
  const size_t n = p->n;

  /* fluid left out of its block by walls or the domain */
  for (unsigned b = 0; s->fill && b < sc->n_fluid; b++) {
    const rhod_fill_stats *f = &s->fill[b];
    const size_t dropped =
        f->out_container + f->in_obstacle + f->in_body + f->out_domain + f->on_wall;
    if (!dropped)
      continue;
    char where[512], causes[512];
    block_where(sc, b, where, sizeof where);
    block_dropped(f, causes, sizeof causes);
    rhod_warn(&w, "%s: %zu of the %zu particles of its lattice are left out: %s", where, dropped,
              dropped + f->kept, causes);
  }

  /* pressure probes no fluid can reach: nothing within R at t = 0, and more than R
   * behind a wall (inside an obstacle or outside every container) or outside the domain */
  const double R = sc->radius_ratio * sc->dx;
  for (unsigned i = 0; i < sc->n_probes; i++) {
    const rhod_probe *pr = &sc->probes[i];
    if (pr->kind != RHOD_PROBE_PRESSURE)
      continue;
    const double ax = pr->at[0], ay = pr->at[1];
    int near = 0;
    for (size_t k = 0; k < n && !near; k++)
      near = hypot(p->x[k] - ax, p->y[k] - ay) <= sc->radius_ratio * p->dx[k];
    if (near)
      continue;
    const int outside =
        ax < s->lo[0] - R || ax > s->hi[0] + R || ay < s->lo[1] - R || ay > s->hi[1] + R;
    const int behind = s->bnd.nseg + s->bnd.ncirc > 0 && rhod_wall_distance(&s->bnd, ax, ay) < -R;
    if (outside || behind)
      rhod_warn(&w,
                "%s: probes.list.%u.pressure.at: [%g, %g] lies %s, where no fluid can come: "
                "probe %s will read 0",
                sc->path, i, ax, ay,
                outside ? "outside the domain"
                        : "behind a wall (inside an obstacle or outside "
                          "every container)",
                pr->name);
  }

  /* gravity with nothing below: the fall along the non-periodic axes (a periodic axis
   * wraps) from each particle meets no wall */
  double d[2] = {sc->periodic[0] ? 0 : sc->gravity[0], sc->periodic[1] ? 0 : sc->gravity[1]};
  const double g = hypot(d[0], d[1]);
  if (g > 0) {
    d[0] /= g, d[1] /= g;
    size_t falling = 0;
    for (size_t k = 0; k < n; k++)
      falling += !wall_along(&s->bnd, p->x[k], p->y[k], d);
    if (falling)
      rhod_warn(&w,
                "%s: physics.gravity: %zu of the %zu fluid particles have no wall below them "
                "(along gravity, outside the periodic axes): they will leave the domain, and the "
                "run then stops as unstable",
                sc->path, falling, n);
  }
  return w.count;
}
