/* Open boundaries, host side (open.h): markers, their state, the distribution of each
 * marker's imbalance among its boundary particles (paper 001 Eqs. 25-26), new particles,
 * deletions and the mass bookkeeping. Choices the papers leave open: docs/choices.md
 * "open boundaries". */
#include "rhod/open.h"
#include "rhod/shepard.h"
#include <math.h>
#include <matheval.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the mass below which a boundary particle counts as emptied, relative to its m0 */
#define EMPTY_TOL 1e-9

static double law_at(void *ev, double t) {
  char *names[1] = {"t"};
  double vals[1] = {t};
  return ev ? evaluator_evaluate(ev, 1, names, vals) : 0;
}

int rhod_open_init(rhod_open *o, const rhod_scene *sc, const rhod_boundary *b, const double *rho0,
                   const double *c0, char *err, size_t errlen) {
  memset(o, 0, sizeof *o);
  o->n = (int)sc->n_open;
  if (o->n == 0)
    return RHOD_OK;
  o->desc = sc->open;
  o->nmark = b->nmark;
  if (o->nmark > RHOD_OPEN_MAX_MARKERS) {
    snprintf(err, errlen,
             "%s: open_boundaries: %d markers (open boundary length / dx), at most %d: a "
             "coarser dx or shorter boundaries",
             sc->path, o->nmark, RHOD_OPEN_MAX_MARKERS);
    return RHOD_ERR_SCENE;
  }
  const size_t nb = (size_t)o->n, nm = (size_t)o->nmark;
  o->law = calloc(nb, sizeof *o->law);
  o->fn = calloc(nb, sizeof *o->fn);
  o->ctx = calloc(nb, sizeof *o->ctx);
  o->first = calloc(nb, sizeof *o->first);
  o->count = calloc(nb, sizeof *o->count);
  o->rho0 = calloc(nb, sizeof *o->rho0);
  o->c0 = calloc(nb, sizeof *o->c0);
  o->pinf = calloc(nm, sizeof *o->pinf);
  o->ukap = calloc(2 * nm, sizeof *o->ukap);
  o->fp = rhod_dev_calloc(nm, sizeof(real));
  o->mb = calloc(nm, sizeof *o->mb);
  o->mx = calloc(nm, sizeof *o->mx);
  o->my = calloc(nm, sizeof *o->my);
  o->us = calloc(nm, sizeof *o->us);
  o->vs = calloc(nm, sizeof *o->vs);
  o->rhos = calloc(nm, sizeof *o->rhos);
  o->wet = calloc(nm, sizeof *o->wet);
  o->pending = calloc(nm, sizeof *o->pending);
  o->px = rhod_dev_calloc(nm, sizeof(real));
  o->py = rhod_dev_calloc(nm, sizeof(real));
  o->fu = rhod_dev_calloc(nm, sizeof(real));
  o->fv = rhod_dev_calloc(nm, sizeof(real));
  o->frho = rhod_dev_calloc(nm, sizeof(real));
  o->gam = rhod_dev_calloc(nm, sizeof(real));
  if (!o->law || !o->fn || !o->ctx || !o->first || !o->count || !o->rho0 || !o->c0 || !o->pinf ||
      !o->ukap || !o->fp || !o->mb || !o->mx || !o->my || !o->us || !o->vs || !o->rhos || !o->wet ||
      !o->pending || !o->px || !o->py || !o->fu || !o->fv || !o->frho || !o->gam)
    return RHOD_ERR_MEMORY;
  for (int k = 0; k < o->n; k++) {
    const rhod_open_boundary *D = &sc->open[k];
    const real *S = b->seg + RHOD_SEG_STRIDE * (b->open0 + k);
    o->first[k] = (int)S[11];
    o->count[k] = (int)S[12];
    o->rho0[k] = rho0[D->phase > 0 ? D->phase : 0];
    o->c0[k] = c0[D->phase > 0 ? D->phase : 0];
    for (int j = 0; j < o->count[k]; j++) {
      const int q = o->first[k] + j;
      const double s = (j + 0.5) * (double)S[6] / o->count[k];
      o->mb[q] = k;
      o->mx[q] = D->from[0] + s * (double)S[4];
      o->my[q] = D->from[1] + s * (double)S[5];
      o->px[q] = (real)o->mx[q];
      o->py[q] = (real)o->my[q];
      /* an inflow marker is wet where its centre lies below the inflow's surface (its
       * level along -g, as fluid.N.surface), or everywhere without one */
      const double g = hypot(sc->gravity[0], sc->gravity[1]);
      const double level =
          g > 0 ? -(o->mx[q] * sc->gravity[0] + o->my[q] * sc->gravity[1]) / g : o->my[q];
      o->wet[q] = D->kind == RHOD_OPEN_INFLOW && (!D->surface_set || level < D->surface);
      /* an outflow's ambient pressure: open_boundaries.N.pressure (default 0) without
       * gravity; under gravity that pressure at its surface plus the hydrostatic part below
       * it (paper 002 Sec. VI A's profile, linearised); none under gravity without a
       * surface (the loader allows no pressure then) */
      o->pinf[q] =
          g == 0 ? D->pressure
          : D->surface_set
              ? D->pressure + (level < D->surface ? o->rho0[k] * g * (D->surface - level) : 0)
              : NAN;
    }
    o->nout += D->kind == RHOD_OPEN_OUTFLOW;
    if (D->kind == RHOD_OPEN_INFLOW) {
      o->law[k] = evaluator_create(D->velocity ? D->velocity : "0");
      if (!o->law[k]) {
        snprintf(err, errlen, "%s: open_boundaries.%d.velocity: cannot read \"%s\"", sc->path, k,
                 D->velocity ? D->velocity : "0");
        return RHOD_ERR_SCENE;
      }
    }
  }
  rhod_to_device(o->px, nm * sizeof(real));
  rhod_to_device(o->py, nm * sizeof(real));
  return RHOD_OK;
}

void rhod_open_free(rhod_open *o) {
  for (int k = 0; o->law && k < o->n; k++)
    if (o->law[k])
      evaluator_destroy(o->law[k]);
  const size_t nm = (size_t)o->nmark;
  free(o->law), free(o->fn), free(o->ctx), free(o->first), free(o->count), free(o->rho0);
  free(o->c0), free(o->pinf), free(o->ukap);
  rhod_dev_free(o->fp, nm * sizeof(real));
  free(o->mb), free(o->mx), free(o->my), free(o->us), free(o->vs), free(o->rhos), free(o->wet);
  free(o->pending);
  rhod_dev_free(o->px, nm * sizeof(real));
  rhod_dev_free(o->py, nm * sizeof(real));
  rhod_dev_free(o->fu, nm * sizeof(real));
  rhod_dev_free(o->fv, nm * sizeof(real));
  rhod_dev_free(o->frho, nm * sizeof(real));
  rhod_dev_free(o->gam, nm * sizeof(real));
  rhod_dev_free(o->cnt, o->cnt_cap * sizeof(int32_t));
  rhod_dev_free(o->bi, o->bcap * sizeof(int32_t));
  rhod_dev_free(o->bf, o->bcap * RHOD_OPEN_BF * sizeof(real));
  memset(o, 0, sizeof *o);
}

void rhod_open_couple(rhod_open *o, int k, rhod_open_state_fn fn, void *ctx) {
  if (k >= 0 && k < o->n) {
    o->nout -= o->desc[k].kind == RHOD_OPEN_OUTFLOW && !o->fn[k] && fn;
    o->fn[k] = fn, o->ctx[k] = ctx;
  }
}

/* Marker q's profile factor: 1, or 6 s (1 - s) at its centre: over n markers the rate is
 * 1 - 1/(2 n^2) of the mean speed times the length (0.5 % low at n = 10). The marker's exact
 * mean made cases/poiseuille's mass excess (+1.46 % -> +2.17 % at H/dx = 20, t = 10 s) and
 * profile worse, so it waits until the crowding at the inflow's corners is understood. */
static double profile(const rhod_open *o, int q) {
  const int k = o->mb[q];
  if (o->desc[k].profile != RHOD_PROFILE_PARABOLIC)
    return 1;
  const double s = (q - o->first[k] + 0.5) / o->count[k];
  return 6 * s * (1 - s);
}

/* The inflow markers' velocity at t (law and profile along the normal, or the callback). */
static int inflow_velocity(rhod_open *o, double t, char *err, size_t errlen) {
  for (int q = 0; q < o->nmark; q++) {
    const int k = o->mb[q];
    const rhod_open_boundary *D = &o->desc[k];
    if (D->kind != RHOD_OPEN_INFLOW && !o->fn[k])
      continue;
    if (o->fn[k]) {
      double u = o->us[q], v = o->vs[q], r = o->rhos[q];
      if (o->fn[k](o->ctx[k], k, q - o->first[k], t, o->mx[q], o->my[q], &u, &v, &r) != 0) {
        snprintf(err, errlen, "open_boundaries.%d (%s): its coupling state failed at t = %g s", k,
                 D->name, t);
        return RHOD_ERR_UNSTABLE;
      }
      o->us[q] = u, o->vs[q] = v, o->rhos[q] = r;
    } else {
      const double speed = law_at(o->law[k], t) * profile(o, q);
      o->us[q] = speed * D->normal[0];
      o->vs[q] = speed * D->normal[1];
    }
    if (!isfinite(o->us[q]) || !isfinite(o->vs[q])) {
      snprintf(err, errlen, "open_boundaries.%d (%s): its velocity is not finite at t = %g s", k,
               D->name, t);
      return RHOD_ERR_UNSTABLE;
    }
  }
  return RHOD_OK;
}

int rhod_open_ghost_velocity(rhod_open *o, rhod_boundary *b, double t, char *err, size_t errlen) {
  if (o->n == 0)
    return RHOD_OK;
  const int st = inflow_velocity(o, t, err, errlen);
  if (st != RHOD_OK)
    return st;
  for (int q = 0; q < o->nmark; q++) {
    /* an inflow's ghosts carry its velocity; an outflow's their source's plus the pressure
     * relaxation (T = I, boundary.h) */
    const int out = o->desc[o->mb[q]].kind != RHOD_OPEN_INFLOW && !o->fn[o->mb[q]];
    b->openu[2 * q] = (real)(out ? o->ukap[2 * q] : o->us[q]);
    b->openu[2 * q + 1] = (real)(out ? o->ukap[2 * q + 1] : o->vs[q]);
  }
  rhod_to_device(b->openu, sizeof(real) * (size_t)(2 * o->nmark));
  return RHOD_OK;
}

int rhod_open_state(rhod_open *o, rhod_boundary *b, const rhod_particles *p, const rhod_cells *c,
                    int kern, real ratio, const real *V, const real *P, double t, char *err,
                    size_t errlen) {
  if (o->n == 0)
    return RHOD_OK;
  const long nm = o->nmark;
  /* paper 001 Eq. 29: Shepard interpolation over fluid and ghosts at the markers */
  rhod_shepard(c, kern, ratio, p->x, p->y, p->dx, V, p->ux, nm, o->px, o->py, o->fu, o->gam);
  rhod_shepard(c, kern, ratio, p->x, p->y, p->dx, V, p->uy, nm, o->px, o->py, o->fv, o->gam);
  rhod_shepard(c, kern, ratio, p->x, p->y, p->dx, V, P, nm, o->px, o->py, o->fp, o->gam);
  rhod_shepard(c, kern, ratio, p->x, p->y, p->dx, V, p->rho, nm, o->px, o->py, o->frho, o->gam);
  const size_t bytes = sizeof(real) * (size_t)nm;
  rhod_to_host(o->fu, bytes);
  rhod_to_host(o->fv, bytes);
  rhod_to_host(o->frho, bytes);
  rhod_to_host(o->fp, bytes);
  rhod_to_host(o->gam, bytes);
  for (int q = 0; q < nm; q++) {
    const int k = o->mb[q];
    const rhod_open_boundary *D = &o->desc[k];
    /* a marker with half a support of fluid or more is wet (our choice: an outflow marker
     * above a free surface takes no mass); an inflow's below its surface always */
    const int fluid = o->gam[q] >= (real)0.5;
    o->rhos[q] = fluid ? (double)o->frho[q] : o->rho0[k];
    if (D->kind != RHOD_OPEN_INFLOW) {
      /* the pressure relaxation RHOD_OPEN_KAPPA (open.h) */
      const double dp = isnan(o->pinf[q]) ? 0 : (double)o->fp[q] - o->pinf[q];
      const double un = -RHOD_OPEN_KAPPA * dp / (o->rho0[k] * o->c0[k]);
      o->us[q] = fluid ? (double)o->fu[q] + un * D->normal[0] : 0;
      o->vs[q] = fluid ? (double)o->fv[q] + un * D->normal[1] : 0;
      o->ukap[2 * q] = fluid ? un * D->normal[0] : 0;
      o->ukap[2 * q + 1] = fluid ? un * D->normal[1] : 0;
      o->wet[q] = fluid;
    }
  }
  return rhod_open_ghost_velocity(o, b, t, err, errlen);
}

/* ---- the exchange ---------------------------------------------------------------------- */

/* The share of a boundary particle's cross-section [t - A/2, t + A/2] along the segment that
 * lies over [a, b] (paper 001's omega_is = |A_i cap A_s| / A_s, over A_i instead: our choice,
 * docs/choices.md "open boundaries: overlap", so that a particle's predicted change is
 * shared out whole among the markers it covers, sum_s omega_is = 1, even when compression
 * makes A_i differ from A_s). */
static double overlap(double t, double A, double a, double b) {
  const double lo = fmax(t - A / 2, a), hi = fmin(t + A / 2, b);
  return hi > lo ? (hi - lo) / A : 0;
}

typedef struct {
  int k;     /* entry in the boundary list */
  double om; /* its overlap with the marker */
  double d;  /* its depth */
} cand;

static int by_depth_up(const void *a, const void *b) {
  const cand *x = a, *y = b;
  return x->d < y->d ? -1 : (x->d > y->d ? 1 : (x->k < y->k ? -1 : x->k > y->k));
}

/* new particles of a step: marker, mass */
typedef struct {
  int q;
  double m;
} birth;

int rhod_open_exchange(rhod_open *o, const rhod_boundary *b, rhod_particles *p, double dt,
                       const double *rho0_phase, char *err, size_t errlen) {
  if (o->n == 0)
    return RHOD_OK;
  /* a marker that could not keep up in the last step: more than a particle's mass waits at it (an
   * inflow of more than one particle a step, an outflow drawn on with nothing left to give) */
  for (int q = 0; q < o->nmark; q++) {
    const int kb = o->mb[q];
    const rhod_open_boundary *D = &o->desc[kb];
    const double m0 = o->rho0[kb] * D->dx * D->dx;
    if (fabs(o->pending[q]) > m0) {
      snprintf(err, errlen,
               "open boundary %s (open_boundaries.%d) is overwhelmed at (%g, %g): %.3g of a "
               "particle's mass waits at one marker (%s); a smaller time step or a larger dx "
               "there",
               D->name, kb, o->mx[q], o->my[q], fabs(o->pending[q]) / m0,
               o->pending[q] > 0 ? "more fluid comes in than a particle a step can take"
                                 : "fluid is drawn out faster than it reaches the boundary");
      return RHOD_ERR_UNSTABLE;
    }
  }
  const long nb = rhod_open_gather(o, b, p, rho0_phase);
  if (nb < 0)
    return RHOD_ERR_MEMORY;
  const long n0 = (long)p->n;
  real *bf = o->bf;
  /* dm* (Eq. 23, limited by Eq. 24, kernels/open.c) and the new mass so far, per entry */
  double *mnew = malloc(sizeof(double) * (size_t)(nb + 1));
  double *m_old = malloc(sizeof(double) * (size_t)(nb + 1));
  double *beyond = calloc((size_t)(nb + 1), sizeof(double));
  cand *cl = malloc(sizeof(cand) * (size_t)(nb + 1));
  birth *born = NULL;
  int nborn = 0, cap_born = 0;
  if (!mnew || !m_old || !cl || !beyond) {
    free(mnew), free(m_old), free(cl), free(beyond);
    return RHOD_ERR_MEMORY;
  }
  for (long k = 0; k < nb; k++) {
    const real *F = bf + RHOD_OPEN_BF * k;
    m_old[k] = F[4];
    /* Eq. 23's change over the open boundary: the part of the cross-section beyond the
     * segment's ends (over a wall) takes none (our choice, with the overlap above) */
    const real *S = b->seg + RHOD_SEG_STRIDE * (int)F[0];
    mnew[k] = (double)F[4] + overlap(F[1], F[3], 0, S[6]) * (double)F[7];
  }
  int st = RHOD_OK;
  for (int q = 0; q < o->nmark && st == RHOD_OK; q++) {
    const int kb = o->mb[q];
    const rhod_open_boundary *D = &o->desc[kb];
    const int seg = b->open0 + kb, j = q - o->first[kb];
    const double w = (double)b->seg[RHOD_SEG_STRIDE * seg + 6] / o->count[kb];
    /* the boundary particles over the marker and what they took by themselves (Eq. 23) */
    int nc = 0;
    double own = 0;
    for (long k = 0; k < nb; k++) {
      const real *F = bf + RHOD_OPEN_BF * k;
      if ((int)F[0] != seg)
        continue;
      const double om = overlap(F[1], F[3], j * w, (j + 1) * w);
      if (om <= 0)
        continue;
      own += om * (double)F[7];
      cl[nc].k = (int)k, cl[nc].om = om, cl[nc].d = F[2];
      nc++;
    }
    /* paper 001 Eq. 20: the mass the marker lets in this step, dm_s = -rho_s A_s (u_s . n_s)
     * dt with n_s pointing out of the fluid (our normal points in) */
    const double un = o->us[q] * D->normal[0] + o->vs[q] * D->normal[1];
    double M;
    if (D->kind == RHOD_OPEN_INFLOW || o->fn[kb]) {
      const double dms = o->wet[q] ? o->rhos[q] * w * un * dt : 0;
      if (D->kind == RHOD_OPEN_INFLOW)
        o->prescribed_in += dms;
      else
        o->prescribed_out -= dms;
      /* Eq. 25: the imbalance after the boundary particles' own changes */
      M = dms - own;
    } else {
      /* an outflow (our choice, docs/choices.md "open boundaries: outflow"): what crosses
       * leaves as it comes (Eq. 23) and the marker imposes nothing of its own (the pressure
       * relaxation RHOD_OPEN_KAPPA acts through its ghosts). Imposing the whole of Eq. 20
       * there kept any gap the fluid brought to the boundary in the domain (the carried rest
       * drains the next particle by the gap's mass): a channel started from rest stayed
       * 0.4 % light. Where the fluid flows back in, Eq. 20 with the fluid's own velocity
       * fills the boundary as an inflow would. */
      const double back = un - (o->ukap[2 * q] * D->normal[0] + o->ukap[2 * q + 1] * D->normal[1]);
      if (back > 0 && o->wet[q]) {
        const double dms = o->rhos[q] * w * back * dt;
        o->prescribed_out -= dms;
        M = dms - own;
      } else {
        o->prescribed_out -= own;
        M = 0;
      }
    }
    /* with what an earlier step could not take */
    M += o->pending[q];
    o->pending[q] = 0;
    if (M == 0)
      continue;
    qsort(cl, (size_t)nc, sizeof *cl, by_depth_up);
    if (M > 0) {
      /* Eq. 26, positive: the furthest particle with omega > 0.5 first, then the closest
       * others, each up to its nominal mass (paper 001 Sec. 3.1) */
      for (int pass = 0; pass < 2 && M > 0; pass++)
        for (int c = 0; c < nc && M > 0; c++) {
          const cand *C = pass == 0 ? &cl[nc - 1 - c] : &cl[c];
          if ((pass == 0) != (C->om > 0.5))
            continue;
          const double room = (double)bf[RHOD_OPEN_BF * C->k + 6] - mnew[C->k];
          const double give = room < M ? room : M;
          if (give > 0)
            mnew[C->k] += give, M -= give;
        }
      if (M > 0) {
        /* the rest: a new particle at the marker (Eq. 15) */
        if (nborn == cap_born) {
          cap_born = 2 * cap_born + 16;
          birth *nbn = realloc(born, sizeof *born * (size_t)cap_born);
          if (!nbn) {
            st = RHOD_ERR_MEMORY;
            break;
          }
          born = nbn;
        }
        born[nborn].q = q, born[nborn].m = M;
        nborn++;
        /* the particles this step filled stand beyond the newborn's cuboid, not in contact
         * with the boundary: they would have moved on by its extent had they filled at the
         * moment they did (our choice; a released particle put in contact overlapped the
         * next one by up to u dt, and a uniform stream's mass varied by 0.2 %) */
        const double rho = o->rhos[q], A = D->dx * sqrt(o->rho0[kb] / rho);
        const double lb =
            (M < o->rho0[kb] * D->dx * D->dx ? M : o->rho0[kb] * D->dx * D->dx) / (rho * A);
        for (int c = 0; c < nc; c++) {
          const int k = cl[c].k;
          if (mnew[k] >= (double)bf[RHOD_OPEN_BF * k + 6] * (1 - 1e-12))
            beyond[k] = fmax(beyond[k], lb);
        }
      }
    } else {
      /* negative: the closest first, down to zero mass; the rest waits for the next step */
      for (int c = 0; c < nc && M < 0; c++) {
        const double take = mnew[cl[c].k] < -M ? mnew[cl[c].k] : -M;
        if (take > 0)
          mnew[cl[c].k] -= take, M += take;
      }
      o->pending[q] = M;
    }
  }
  /* Eq. 27, and the cuboid's barycentre in contact with the boundary (Eq. 28; multiphase.md
   * B (g)): depth l/2 = m/(2 rho A) along the normal. Emptied particles go. */
  long ndel = 0;
  for (long k = 0; k < nb && st == RHOD_OK; k++) {
    real *F = bf + RHOD_OPEN_BF * k;
    const int seg = (int)F[0];
    const real *S = b->seg + RHOD_SEG_STRIDE * seg;
    const double m0 = F[6];
    double m = mnew[k];
    if (m <= EMPTY_TOL * m0)
      m = 0, ndel++;
    else if (m > m0 * (1 - 1e-12) && m_old[k] <= m0)
      m = m0; /* filled (one heavier than m0 from the start keeps its mass) */
    const double dm = m - m_old[k];
    if (S[7] == RHOD_SEG_INFLOW)
      o->taken_in += dm;
    else
      o->taken_out -= dm;
    F[4] = (real)m;
    if (m > 0) {
      const double shift = m / (2 * (double)F[5] * (double)F[3]) + beyond[k] - (double)F[2];
      F[8] = (real)((double)F[8] + shift * (double)S[2]);
      F[9] = (real)((double)F[9] + shift * (double)S[3]);
    }
  }
  free(mnew), free(m_old), free(cl), free(beyond);
  if (st != RHOD_OK) {
    free(born);
    return st;
  }
  int32_t *keep = o->cnt; /* n0 + 1 entries (gather sized it) */
  rhod_open_scatter(o, p, nb, keep);
  o->deleted += (double)ndel;
  if (nborn > 0) {
    if (p->n == 0) {
      /* nothing to copy the scheme's fields from: the mass waits at its markers */
      for (int c = 0; c < nborn; c++)
        o->pending[born[c].q] += born[c].m;
    } else {
      st = rhod_particles_reserve(p, p->n + (size_t)nborn + 1);
      int32_t *src = malloc(sizeof(int32_t) * (size_t)nborn);
      real *nf = malloc(sizeof(real) * 7 * (size_t)nborn);
      uint8_t *ph = malloc((size_t)nborn);
      if (st != RHOD_OK || !src || !nf || !ph) {
        free(src), free(nf), free(ph), free(born);
        return RHOD_ERR_MEMORY;
      }
      for (int c = 0; c < nborn; c++) {
        const int q = born[c].q, kb = o->mb[q];
        const rhod_open_boundary *D = &o->desc[kb];
        const double rho = o->rhos[q], A = D->dx * sqrt(o->rho0[kb] / rho);
        const double m0 = o->rho0[kb] * D->dx * D->dx;
        const double m = born[c].m < m0 ? born[c].m : m0;
        if (born[c].m > m0) /* more than a particle's worth in one step: the rest waits */
          o->pending[q] += born[c].m - m0;
        /* the scheme's own fields come from the nearest boundary particle of this boundary
         * (of this size where there is one), else from particle 0 */
        long bestk = -1;
        double bd = HUGE_VAL;
        for (long k = 0; k < nb; k++) {
          const real *F = bf + RHOD_OPEN_BF * k;
          if ((int)F[0] != b->open0 + kb || F[4] <= 0)
            continue;
          const double dd = hypot((double)F[8] - o->mx[q], (double)F[9] - o->my[q]) +
                            (fabs((double)F[10] - D->dx) > 1e-9 * D->dx ? 1e30 : 0);
          if (dd < bd)
            bd = dd, bestk = k;
        }
        src[c] = bestk >= 0 ? o->bi[bestk] : 0;
        const double l = m / (rho * A);
        real *N = nf + 7 * c;
        N[0] = (real)(o->mx[q] + 0.5 * l * D->normal[0]);
        N[1] = (real)(o->my[q] + 0.5 * l * D->normal[1]);
        N[2] = (real)o->us[q], N[3] = (real)o->vs[q], N[4] = (real)rho, N[5] = (real)m;
        N[6] = (real)D->dx;
        ph[c] = (uint8_t)(D->phase > 0 ? D->phase : 0);
        if (D->kind == RHOD_OPEN_INFLOW)
          o->taken_in += m;
        else
          o->taken_out -= m;
      }
      rhod_open_born(p, src, nf, ph, nborn);
      o->created += nborn;
      free(src), free(nf), free(ph);
    }
  }
  free(born);
  if (st != RHOD_OK)
    return st;
  if (ndel > 0 && rhod_particles_compact(p, keep, (size_t)n0) < 0)
    return RHOD_ERR_MEMORY;
  return RHOD_OK;
}

void rhod_open_report(const rhod_open *o, const rhod_particles *p, rhod_warn_buf *w) {
  if (o->n == 0)
    return;
  double pending = 0;
  for (int q = 0; q < o->nmark; q++)
    pending += o->pending[q];
  const double mass = rhod_open_mass(p), change = mass - o->mass0;
  rhod_warn(w,
            "open boundaries: mass in %.9g kg/m (prescribed %.9g), out %.9g kg/m (prescribed "
            "%.9g), imbalance carried %.3g kg/m",
            o->taken_in, o->prescribed_in, o->taken_out, o->prescribed_out, pending);
  rhod_warn(w,
            "open boundaries: fluid mass %.12g kg/m, change %.9g = in - out %+.3g (round-off); "
            "%.0f particles made, %.0f removed",
            mass, change, change - (o->taken_in - o->taken_out), o->created, o->deleted);
}

static const char *const total_name[RHOD_OPEN_TOTALS] = {
    "open.prescribed_in", "open.prescribed_out", "open.taken_in", "open.taken_out",
    "open.created",       "open.deleted",        "open.mass0"};

static double *total(rhod_open *o, int k) {
  double *const v[RHOD_OPEN_TOTALS] = {&o->prescribed_in, &o->prescribed_out, &o->taken_in,
                                       &o->taken_out,     &o->created,        &o->deleted,
                                       &o->mass0};
  return v[k];
}

_Static_assert(RHOD_CK_MAX_EXTRAS >=
                   16 + 9 * RHOD_MAX_BODIES + RHOD_OPEN_MAX_MARKERS + RHOD_OPEN_TOTALS,
               "the checkpoint holds every marker's imbalance");

void rhod_open_save(const rhod_open *o, rhod_checkpoint *ck) {
  for (int k = 0; k < RHOD_OPEN_TOTALS && o->n > 0 && ck->nextra < RHOD_CK_MAX_EXTRAS; k++) {
    snprintf(ck->extra_name[ck->nextra], sizeof ck->extra_name[0], "%s", total_name[k]);
    ck->extra[ck->nextra++] = *total((rhod_open *)o, k);
  }
  for (int q = 0; q < o->nmark && ck->nextra < RHOD_CK_MAX_EXTRAS; q++) {
    snprintf(ck->extra_name[ck->nextra], sizeof ck->extra_name[0], "open.m.%d", q);
    ck->extra[ck->nextra++] = o->pending[q];
  }
}

int rhod_open_load(rhod_open *o, const rhod_checkpoint *ck, char *err, size_t errlen) {
  if (o->n == 0)
    return RHOD_OK;
  /* the extras in the order save wrote them: look from where the last one was found */
  int from = 0;
  for (int k = 0; k < RHOD_OPEN_TOTALS + o->nmark; k++) {
    char name[32];
    if (k < RHOD_OPEN_TOTALS)
      snprintf(name, sizeof name, "%s", total_name[k]);
    else
      snprintf(name, sizeof name, "open.m.%d", k - RHOD_OPEN_TOTALS);
    int i = -1;
    for (int c = 0; c < ck->nextra && i < 0; c++) {
      const int e = (from + c) % ck->nextra;
      if (strcmp(ck->extra_name[e], name) == 0)
        i = e;
    }
    if (i < 0) {
      snprintf(err, errlen, "the checkpoint has no %s (open boundaries)", name);
      return RHOD_ERR_CHECKPOINT;
    }
    from = i + 1;
    if (k < RHOD_OPEN_TOTALS)
      *total(o, k) = ck->extra[i];
    else
      o->pending[k - RHOD_OPEN_TOTALS] = ck->extra[i];
  }
  return RHOD_OK;
}
