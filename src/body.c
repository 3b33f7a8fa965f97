/* Rigid bodies, host side: laws of motion (libmatheval), poses, the lockstep integration
 * of free bodies, probe columns, outlines and checkpoint extras (body.h). */
#include "rhod/body.h"
#include "rhod/io.h"
#include "rhod/kernel.h"
#include <math.h>
#include <matheval.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const rhod_body_column_suffix[RHOD_BODY_COLUMNS] = {
    "_Fx", "_Fy", "_Mz", "_x", "_y", "_theta", "_u", "_v", "_omega"};

static double shape_area(const rhod_shape *sh) {
  if (sh->kind == RHOD_SHAPE_RECT)
    return (sh->max[0] - sh->min[0]) * (sh->max[1] - sh->min[1]);
  if (sh->kind == RHOD_SHAPE_CIRCLE)
    return RHOD_PI * sh->radius * sh->radius;
  double a = 0;
  for (unsigned k = 0; k < sh->n_points; k++) {
    const double *p = sh->points[k], *q = sh->points[(k + 1) % sh->n_points];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return fabs(a) / 2;
}

static double law_at(void *ev, double t) {
  if (!ev)
    return 0;
  char *names[1] = {"t"};
  double vals[1] = {t};
  return evaluator_evaluate(ev, 1, names, vals);
}

void rhod_bodies_impose(rhod_bodies *bb, double t) {
  for (int k = 0; k < bb->n; k++) {
    rhod_body_state *B = &bb->b[k];
    if (B->desc->motion != RHOD_MOTION_IMPOSED)
      continue;
    for (int d = 0; d < RHOD_NDOF; d++) {
      B->q[d] = law_at(B->law[d][0], t);
      B->qd[d] = law_at(B->law[d][1], t);
      B->qdd[d] = law_at(B->law[d][2], t);
    }
  }
}

/* The quadrature points of the boundary of shape sh (at zero displacement), at most ds
 * apart, into bb from index *q (count only when bb->x0 is NULL). RHOD_ERR_MEMORY or RHOD_OK. */
static int shape_samples(rhod_bodies *bb, int body, const rhod_shape *sh, double ds, int *q) {
  if (sh->kind == RHOD_SHAPE_CIRCLE) {
    const int m = (int)fmax(16, ceil(2 * RHOD_PI * sh->radius / ds));
    for (int k = 0; k < m; k++, (*q)++)
      if (bb->x0) {
        const double phi = 2 * RHOD_PI * (k + 0.5) / m;
        bb->nx0[*q] = cos(phi), bb->ny0[*q] = sin(phi);
        bb->x0[*q] = sh->center[0] + sh->radius * cos(phi);
        bb->y0[*q] = sh->center[1] + sh->radius * sin(phi);
        bb->ds[*q] = 2 * RHOD_PI * sh->radius / m;
        bb->sb[*q] = body;
      }
    return RHOD_OK;
  }
  double(*pt)[2] = malloc(sizeof(double[2]) * (sh->kind == RHOD_SHAPE_RECT ? 4 : sh->n_points));
  if (!pt)
    return RHOD_ERR_MEMORY;
  const unsigned np = rhod_shape_outline(sh, 0, pt);
  for (unsigned e = 0; e < np; e++) {
    const double *a = pt[e], *c = pt[(e + 1) % np];
    const double tx = c[0] - a[0], ty = c[1] - a[1], len = hypot(tx, ty);
    const int m = (int)fmax(1, ceil(len / ds));
    for (int k = 0; k < m; k++, (*q)++)
      if (bb->x0) {
        const double f = (k + 0.5) / m;
        /* counter-clockwise (the loader stores polygons so): the outward normal is the
         * edge's right-hand one */
        bb->nx0[*q] = ty / len, bb->ny0[*q] = -tx / len;
        bb->x0[*q] = a[0] + f * tx, bb->y0[*q] = a[1] + f * ty;
        bb->ds[*q] = len / m;
        bb->sb[*q] = body;
      }
  }
  free(pt);
  return RHOD_OK;
}

int rhod_bodies_init(rhod_bodies *bb, const rhod_scene *sc, rhod_boundary *b, double t, double ds,
                     char *err, size_t errlen) {
  memset(bb, 0, sizeof *bb);
  if (sc->n_bodies == 0)
    return RHOD_OK;
  bb->b = calloc(sc->n_bodies, sizeof *bb->b);
  if (!bb->b)
    return RHOD_ERR_MEMORY;
  bb->n = (int)sc->n_bodies;
  static const char *const dof[RHOD_NDOF] = {"x", "y", "theta"};
  for (int k = 0; k < bb->n; k++) {
    rhod_body_state *B = &bb->b[k];
    const rhod_body *D = &sc->bodies[k];
    B->desc = D;
    B->G0[0] = D->center[0], B->G0[1] = D->center[1];
    B->area = shape_area(&D->shape);
    bb->moving |= D->motion != RHOD_MOTION_FIXED;
    if (D->motion == RHOD_MOTION_IMPOSED) {
      for (int d = 0; d < RHOD_NDOF; d++) {
        if (!D->law[d])
          continue;
        void *ev = evaluator_create(D->law[d]);
        if (!ev) {
          snprintf(err, errlen, "%s: bodies.%d.law.%s: cannot read \"%s\"", sc->path, k, dof[d],
                   D->law[d]);
          return RHOD_ERR_SCENE;
        }
        B->law[d][0] = ev;
        B->law[d][1] = evaluator_derivative(ev, "t");
        B->law[d][2] = B->law[d][1] ? evaluator_derivative(B->law[d][1], "t") : NULL;
        if (!B->law[d][1] || !B->law[d][2])
          return RHOD_ERR_MEMORY;
      }
    } else if (D->motion == RHOD_MOTION_FREE) {
      B->qd[0] = D->lock[0] ? 0 : D->velocity[0];
      B->qd[1] = D->lock[1] ? 0 : D->velocity[1];
      B->qd[2] = D->lock[2] ? 0 : D->omega;
    }
  }
  /* the pressure's quadrature points */
  int q = 0;
  for (int k = 0; k < bb->n; k++)
    if (shape_samples(bb, k, &sc->bodies[k].shape, ds, &q) != RHOD_OK)
      return RHOD_ERR_MEMORY;
  bb->ns = q;
  const size_t nq = (size_t)q;
  bb->x0 = malloc(sizeof(double) * nq), bb->y0 = malloc(sizeof(double) * nq);
  bb->nx0 = malloc(sizeof(double) * nq), bb->ny0 = malloc(sizeof(double) * nq);
  bb->ds = malloc(sizeof(double) * nq), bb->sb = malloc(sizeof(int) * nq);
  bb->px = malloc(sizeof(real) * nq), bb->py = malloc(sizeof(real) * nq);
  bb->fp = malloc(sizeof(real) * nq), bb->gam = malloc(sizeof(real) * nq);
  if (!bb->x0 || !bb->y0 || !bb->nx0 || !bb->ny0 || !bb->ds || !bb->sb || !bb->px || !bb->py ||
      !bb->fp || !bb->gam)
    return RHOD_ERR_MEMORY;
  q = 0;
  for (int k = 0; k < bb->n; k++)
    if (shape_samples(bb, k, &sc->bodies[k].shape, ds, &q) != RHOD_OK)
      return RHOD_ERR_MEMORY;
  rhod_dev_map(bb->px, sizeof(real) * nq);
  rhod_dev_map(bb->py, sizeof(real) * nq);
  rhod_dev_map(bb->fp, sizeof(real) * nq);
  rhod_dev_map(bb->gam, sizeof(real) * nq);
  rhod_bodies_impose(bb, t);
  rhod_bodies_place(bb, b);
  return RHOD_OK;
}

void rhod_bodies_free(rhod_bodies *bb) {
  for (int k = 0; k < bb->n; k++)
    for (int d = 0; d < RHOD_NDOF; d++)
      for (int o = 0; o < 3; o++)
        if (bb->b[k].law[d][o])
          evaluator_destroy(bb->b[k].law[d][o]);
  free(bb->b);
  rhod_dev_free(bb->fghost, sizeof(real) * 2 * bb->fghost_cap);
  if (bb->px) {
    const size_t nq = (size_t)bb->ns;
    rhod_dev_unmap(bb->px, sizeof(real) * nq);
    rhod_dev_unmap(bb->py, sizeof(real) * nq);
    rhod_dev_unmap(bb->fp, sizeof(real) * nq);
    rhod_dev_unmap(bb->gam, sizeof(real) * nq);
  }
  free(bb->x0), free(bb->y0), free(bb->nx0), free(bb->ny0), free(bb->ds), free(bb->sb);
  free(bb->px), free(bb->py), free(bb->fp), free(bb->gam);
  memset(bb, 0, sizeof *bb);
}

/* A point X0 of body B at zero displacement where the body stands now. */
static void to_world(const rhod_body_state *B, double c, double s, double x0, double y0, double *x,
                     double *y) {
  const double rx = x0 - B->G0[0], ry = y0 - B->G0[1];
  *x = B->G0[0] + B->q[0] + c * rx - s * ry;
  *y = B->G0[1] + B->q[1] + s * rx + c * ry;
}

void rhod_bodies_place(const rhod_bodies *bb, rhod_boundary *b) {
  if (bb->n == 0)
    return;
  for (int s = b->nwallseg; s < b->nseg; s++) {
    const real *S0 = b->seg0 + RHOD_SEG_STRIDE * s;
    real *S = b->seg + RHOD_SEG_STRIDE * s;
    const rhod_body_state *B = &bb->b[(int)S0[10]];
    const double c = cos(B->q[2]), sn = sin(B->q[2]);
    double ax, ay;
    to_world(B, c, sn, S0[0], S0[1], &ax, &ay);
    S[0] = (real)ax, S[1] = (real)ay;
    S[2] = (real)(c * S0[2] - sn * S0[3]), S[3] = (real)(sn * S0[2] + c * S0[3]);
    S[4] = (real)(c * S0[4] - sn * S0[5]), S[5] = (real)(sn * S0[4] + c * S0[5]);
  }
  for (int k = b->nwallcirc; k < b->ncirc; k++) {
    const real *C0 = b->circ0 + RHOD_CIRC_STRIDE * k;
    real *C = b->circ + RHOD_CIRC_STRIDE * k;
    const rhod_body_state *B = &bb->b[(int)C0[5]];
    double cx, cy;
    to_world(B, cos(B->q[2]), sin(B->q[2]), C0[0], C0[1], &cx, &cy);
    C[0] = (real)cx, C[1] = (real)cy;
  }
  for (int k = 0; k < bb->n; k++) {
    const rhod_body_state *B = &bb->b[k];
    real *K = b->kin + RHOD_KIN_STRIDE * k;
    K[0] = (real)(B->G0[0] + B->q[0]), K[1] = (real)(B->G0[1] + B->q[1]);
    K[2] = (real)B->qd[0], K[3] = (real)B->qd[1], K[4] = (real)B->qd[2];
    K[5] = (real)B->qdd[0], K[6] = (real)B->qdd[1], K[7] = (real)B->qdd[2];
  }
  rhod_to_device(b->seg, sizeof(real) * RHOD_SEG_STRIDE * (size_t)b->nseg);
  rhod_to_device(b->circ, sizeof(real) * RHOD_CIRC_STRIDE * (size_t)b->ncirc);
  rhod_to_device(b->kin, sizeof(real) * RHOD_KIN_STRIDE * (size_t)b->nbody);
}

void rhod_bodies_begin(rhod_bodies *bb) {
  for (int k = 0; k < bb->n; k++) {
    rhod_body_state *B = &bb->b[k];
    for (int d = 0; d < RHOD_NDOF; d++) {
      B->q0[d] = B->q[d], B->qd0[d] = B->qd[d];
      B->kq[d] = 0, B->kqd[d] = 0;
    }
  }
}

void rhod_bodies_relaxation(rhod_bodies *bb, double rho0) {
  for (int k = 0; k < bb->n; k++) {
    rhod_body_state *B = &bb->b[k];
    const rhod_body *D = B->desc;
    if (D->motion != RHOD_MOTION_FREE)
      continue;
    const double ma = D->added_mass >= 0 ? D->added_mass : rho0 * B->area;
    B->ma[0] = B->ma[1] = ma;
    B->ma[2] = ma * D->inertia / D->mass;
  }
}

void rhod_bodies_stage(rhod_bodies *bb, const rhod_rk_table *tab, int s, double t, double dt,
                       const double gravity[2]) {
  const int last = s == tab->stages - 1;
  const double ts = last ? t + dt : t + tab->c[s] * dt; /* the next stage's time */
  for (int k = 0; k < bb->n; k++) {
    rhod_body_state *B = &bb->b[k];
    const rhod_body *D = B->desc;
    if (D->motion != RHOD_MOTION_FREE)
      continue;
    /* 2D rigid-body dynamics: M dU/dt = F + M g, I dOmega/dt = M_z (about the centre of
     * mass G); dq/dt = (U, Omega) */
    const double M[RHOD_NDOF] = {D->mass, D->mass, D->inertia};
    const double f[RHOD_NDOF] = {B->F[0] + D->mass * gravity[0], B->F[1] + D->mass * gravity[1],
                                 B->F[2]};
    double a[RHOD_NDOF];
    for (int d = 0; d < RHOD_NDOF; d++) /* the relaxation (body.h) */
      a[d] = (f[d] + B->ma[d] * B->qdd[d]) / (M[d] + B->ma[d]);
    for (int d = 0; d < RHOD_NDOF; d++) {
      if (D->lock[d]) {
        a[d] = 0;
        continue; /* held exactly: q and its rate stay as they are */
      }
      const double kq = B->qd[d], kqd = a[d]; /* this stage's derivatives */
      B->kq[d] += tab->w[s] * kq;
      B->kqd[d] += tab->w[s] * kqd;
      if (last) {
        B->q[d] = B->q0[d] + dt / tab->div * B->kq[d];
        B->qd[d] = B->qd0[d] + dt / tab->div * B->kqd[d];
      } else {
        B->q[d] = B->q0[d] + tab->c[s] * dt * kq;
        B->qd[d] = B->qd0[d] + tab->c[s] * dt * kqd;
      }
    }
    /* the next stage's ghost pressure uses this stage's acceleration (body.h) */
    for (int d = 0; d < RHOD_NDOF; d++)
      B->qdd[d] = a[d];
  }
  rhod_bodies_impose(bb, ts);
}

void rhod_bodies_values(const rhod_bodies *bb, double *out) {
  for (int k = 0; k < bb->n; k++) {
    const rhod_body_state *B = &bb->b[k];
    double *o = out + RHOD_BODY_COLUMNS * k;
    o[0] = B->F[0], o[1] = B->F[1], o[2] = B->F[2];
    o[3] = B->G0[0] + B->q[0], o[4] = B->G0[1] + B->q[1], o[5] = B->q[2];
    o[6] = B->qd[0], o[7] = B->qd[1], o[8] = B->qd[2];
  }
}

/* The circle segments of an outline: at most seg_len long, at least 16. */
static unsigned circle_segments(const rhod_shape *sh, double seg_len) {
  const double m = ceil(2 * RHOD_PI * sh->radius / seg_len);
  return m < 16 ? 16 : (m > 1e6 ? 1000000 : (unsigned)m);
}

int rhod_bodies_outline(const rhod_bodies *bb, double seg_len, unsigned **start, double **xy) {
  *start = calloc((size_t)bb->n + 1, sizeof **start);
  if (!*start)
    return RHOD_ERR_MEMORY;
  unsigned total = 0;
  for (int k = 0; k < bb->n; k++) {
    const rhod_shape *sh = &bb->b[k].desc->shape;
    (*start)[k] = total;
    total += rhod_shape_outline(sh, circle_segments(sh, seg_len), NULL);
  }
  (*start)[bb->n] = total;
  *xy = malloc(sizeof **xy * 2 * (total ? total : 1));
  if (!*xy) {
    free(*start);
    *start = NULL;
    return RHOD_ERR_MEMORY;
  }
  double(*pt)[2] = (double(*)[2]) * xy;
  for (int k = 0; k < bb->n; k++) {
    const rhod_body_state *B = &bb->b[k];
    const rhod_shape *sh = &B->desc->shape;
    const unsigned a = (*start)[k];
    /* the outline at zero displacement, then each point where the body stands */
    const unsigned np = rhod_shape_outline(sh, circle_segments(sh, seg_len), pt + a);
    const double c = cos(B->q[2]), s = sin(B->q[2]);
    for (unsigned j = a; j < a + np; j++)
      to_world(B, c, s, pt[j][0], pt[j][1], &pt[j][0], &pt[j][1]);
  }
  return RHOD_OK;
}

static void extra_name(int k, int e, char *buf, size_t len) {
  static const char *const part[3] = {"q", "qd", "qdd"};
  snprintf(buf, len, "body.%d.%s%d", k, part[e / RHOD_NDOF], e % RHOD_NDOF);
}

void rhod_bodies_save(const rhod_bodies *bb, rhod_checkpoint *ck) {
  for (int k = 0; k < bb->n; k++) {
    const rhod_body_state *B = &bb->b[k];
    for (int e = 0; e < RHOD_BODY_EXTRAS && ck->nextra < RHOD_CK_MAX_EXTRAS; e++) {
      const double *v = e < RHOD_NDOF ? B->q : (e < 2 * RHOD_NDOF ? B->qd : B->qdd);
      extra_name(k, e, ck->extra_name[ck->nextra], sizeof ck->extra_name[0]);
      ck->extra[ck->nextra++] = v[e % RHOD_NDOF];
    }
  }
}

int rhod_bodies_load(rhod_bodies *bb, rhod_boundary *b, const rhod_checkpoint *ck, char *err,
                     size_t errlen) {
  for (int k = 0; k < bb->n; k++) {
    rhod_body_state *B = &bb->b[k];
    for (int e = 0; e < RHOD_BODY_EXTRAS; e++) {
      char name[32];
      extra_name(k, e, name, sizeof name);
      int i = 0;
      while (i < ck->nextra && strcmp(ck->extra_name[i], name) != 0)
        i++;
      if (i == ck->nextra) {
        snprintf(err, errlen, "the checkpoint has no %s (body %s)", name, B->desc->name);
        return RHOD_ERR_CHECKPOINT;
      }
      double *v = e < RHOD_NDOF ? B->q : (e < 2 * RHOD_NDOF ? B->qd : B->qdd);
      v[e % RHOD_NDOF] = ck->extra[i];
    }
  }
  rhod_bodies_place(bb, b);
  return RHOD_OK;
}
