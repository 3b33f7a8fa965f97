/* Adaptive particle refinement, paper 002 Sec. V: criteria (V B), the 1 -> 4 split
 * (V A) or the 1 -> 3 of the Appendix, and its inverse, coalescing (ours, after paper 004
 * Sec. 2.3). All are per-particle loops that write only particle i's own entries (the children of i
 * go to slots reserved for i by a scan; a merged group is written by its leader), so they run on
 * the device like every other kernel. */
#include "rhod/device.h"
#include "rhod/kernel.h"
#include "rhod/rhodsph/apr.h"
#include <math.h>
#include <string.h>

/* Coalescing (our choices, docs/choices.md "APR coalescing"). A particle of size dx_i
 * is a candidate when the particle of size e dx_i that its group would become would
 * not be refined again: criteria 1, 2 and 5 evaluated for the support of radius
 * e R_i, criteria 3 and 4 for a support HYST times wider, criterion 2 and the
 * thresholds of 5 with the same margin (the hysteresis that keeps a particle from
 * splitting and merging in turn). Criterion 2 counts the other candidates as the
 * merged particles they will mostly become (coalesce_c2). */
#define HYST ((real)1.25)
/* A group: the candidate and the three (triangle: two) same-size candidates nearest to
 * the group's running centroid, all within 2 dx_i of it; kept when none lies farther
 * than dx_i from the centre of mass (a 2 x 2 block of a lattice: 0.71 dx_i) and no
 * other particle j comes nearer to that centre than Q_MIN (e dx_i + dx_j)/2, the spacing
 * of the merged particle and j on a regular layout (0.5 of it, which is where the
 * children of a split stand on a regular lattice too); a j finer than the merged
 * particle no nearer than refinement.crowding of it either, when that is more, or the
 * merged particle would split again at once. */
#define Q_MIN ((real)0.5)
#define NONE ((real)1e30)

/* (sa, sb): child k's offset along the pattern's direction e and across it (Sec. V A,
 * Fig. 5; Appendix for the triangle): the corners of the rectangle of half-sides ha
 * along e and hb across, or (tri) of the equilateral triangle of circumradius rt with
 * corner 0 along e. A macro, not a function: two outputs would be pointer outputs,
 * which GCC 12 nvptx puts in the warp-shared frame (tests/offload_frames.sh). */
#define CHILD_OFFSET(tri, k, ha, hb, rt, sa, sb)                                                   \
  const real sa = (tri) ? ((k) == 0 ? (rt) : -(real)0.5 * (rt)) : (((k)&1) ? (ha) : -(ha));        \
  const real sb = (tri) ? ((k) == 0 ? 0 : ((k) == 1 ? S32 : -S32) * (rt)) : (((k)&2) ? (hb) : -(hb))
#define S32 ((real)0.86602540378443865) /* sqrt(3)/2 */

/* Our choice (the paper is silent): where a child would land behind a wall, or nearer
 * to it than keep (a quarter of its size), the whole pattern moves along the wall
 * normal until every child stands at least keep in front; (shx, shy), zero on entry,
 * gets that move. A child behind a wall has no ghosts and was seen to blow up the dam
 * break within steps. Moving the children one by one put two of them on one point, with
 * one velocity, where a parent stood within a quarter of a child's size of a wall (two
 * such pairs in the four-level dam break; cases/dam_break_lobovsky/RESULTS.md "Twin
 * children at a wall"); moved together they keep the pattern's spacing. Each child's
 * move carries to the next; a second round settles a corner whose walls are not at
 * right angles. Walls farther behind a child than back are not its walls (the far side
 * of a thin body). Over the locals seg, nseg, circ, ncirc (the walls of rhod_boundary) and
 * o0_, o1_ (its open boundaries' segments [o0_, o1_), which keep nothing off). */
#define PATTERN_SHIFT(tri, xi, yi, ex, ey, ha, hb, rt, keep, back, shx, shy)                       \
  for (int r_ = 0; r_ < 2; r_++)                                                                   \
    for (int k_ = 0; k_ < ((tri) ? 3 : 4); k_++) {                                                 \
      CHILD_OFFSET(tri, k_, ha, hb, rt, sa_, sb_);                                                 \
      const real ex_ = (ex), ey_ = (ey);                                                           \
      const real cx_ = (xi) + sa_ * ex_ - sb_ * ey_ + (shx);                                       \
      const real cy_ = (yi) + sa_ * ey_ + sb_ * ex_ + (shy);                                       \
      const rhod_point p_ = rhod_walls_keep_off(seg, o0_, circ, 0, cx_, cy_, keep, back);          \
      const rhod_point q_ = rhod_walls_keep_off(seg + RHOD_SEG_STRIDE * o1_, nseg - o1_, circ,     \
                                                ncirc, p_.x, p_.y, keep, back);                    \
      (shx) += q_.x - cx_, (shy) += q_.y - cy_;                                                    \
    }

/* The size a held region asks for at (x, y): the finest among those whose signed
 * distance from (x, y) is below margin (0: the centre inside; > 0: within margin of the
 * shape), NONE where there is none. Signed distances: a rect's as a box's, a circle's
 * from its centre minus the radius, a polygon's to the nearest edge, negative inside
 * (crossing number). */
static inline real held_dx(int nh, const real *hr, const real *hp, real x, real y, real margin) {
  real want = NONE;
  for (int k = 0; k < nh; k++) {
    const real *r = hr + RHOD_HOLD_STRIDE * k;
    real d;
    if ((int)r[0] == RHOD_SHAPE_RECT) {
      const real qx = fmax(r[2] - x, x - r[4]), qy = fmax(r[3] - y, y - r[5]);
      d = qx < 0 && qy < 0 ? fmax(qx, qy) : hypot(fmax(qx, 0), fmax(qy, 0));
    } else if ((int)r[0] == RHOD_SHAPE_CIRCLE) {
      d = hypot(x - r[2], y - r[3]) - r[4];
    } else {
      const long v0 = (long)r[2], nv = (long)r[3];
      real d2 = NONE;
      int in = 0;
      for (long v = 0; v < nv; v++) {
        const real *A = hp + 2 * (v0 + v), *B = hp + 2 * (v0 + (v + 1) % nv);
        const real ex = B[0] - A[0], ey = B[1] - A[1], wx = x - A[0], wy = y - A[1];
        const real l2 = ex * ex + ey * ey;
        const real u = l2 > 0 ? fmin(fmax((wx * ex + wy * ey) / l2, 0), 1) : 0;
        const real dx_ = wx - u * ex, dy_ = wy - u * ey;
        d2 = fmin(d2, dx_ * dx_ + dy_ * dy_);
        if (RHOD_RAY_CROSSES(A[0], A[1], B[0], B[1], x, y))
          in = !in;
      }
      d = in ? -sqrt(d2) : sqrt(d2);
    }
    if (d < margin)
      want = fmin(want, r[1]);
  }
  return want;
}

int rhod_apr_init(rhod_apr *a, const rhod_scene *sc, double dx_min) {
  memset(a, 0, sizeof *a);
  a->active = sc->rs->refine_dynamic;
  a->dx_min = (real)dx_min;
  a->free_surface = sc->rs->refine_free_surface;
  a->band = (real)sc->rs->refine_band;
  a->crowd = (real)sc->rs->refine_crowding;
  a->walls = sc->rs->refine_walls;
  a->field = sc->rs->refine_field;
  const rhod_quantity q = sc->rs->field_quantity;
  const double *g = sc->gravity, *x0 = sc->rs->field_x0, rho0 = sc->rs->rho0;
  const int hyd = q == RHOD_QTY_HYDRODYNAMIC_PRESSURE;
  a->fc[0] = q != RHOD_QTY_DYNAMIC_PRESSURE, a->fc[1] = q == RHOD_QTY_DYNAMIC_PRESSURE;
  a->fc[2] = hyd ? (real)(-rho0 * g[0]) : 0, a->fc[3] = hyd ? (real)(-rho0 * g[1]) : 0;
  a->fc[4] = hyd ? (real)(rho0 * (g[0] * x0[0] + g[1] * x0[1])) : 0;
  a->above = (real)fmin(sc->rs->field_above, 1e30);
  a->below = (real)fmax(sc->rs->field_below, -1e30);
  a->from = (real)sc->rs->field_from;
  a->nsplit = rhod_pattern_children(sc->rs->pattern);
  a->eps = (real)rhod_pattern_ratio(sc->rs->pattern);
  a->ieps = (real)(1 / rhod_pattern_ratio(sc->rs->pattern));
  a->coalesce = sc->rs->refine_coalesce;
  a->absorb = sc->rs->refine_absorb;
  a->dx_max = (real)sc->dx;
  /* the held regions, as flat records on the device (apr.h) */
  const rhod_rs_scene *rs = sc->rs;
  for (unsigned k = 0; k < rs->n_regions; k++)
    if (rs->regions[k].hold) {
      a->nhold++;
      if (rs->regions[k].shape.kind == RHOD_SHAPE_POLYGON)
        a->nhp += rs->regions[k].shape.n_points;
    }
  if (a->nhold == 0 || !a->active)
    return RHOD_OK;
  a->hr = rhod_dev_calloc(RHOD_HOLD_STRIDE * (size_t)a->nhold, sizeof(real));
  a->hp = rhod_dev_calloc(2 * (size_t)a->nhp + 2, sizeof(real));
  if (!a->hr || !a->hp)
    return RHOD_ERR_MEMORY;
  int h = 0;
  long v = 0;
  for (unsigned k = 0; k < rs->n_regions; k++) {
    const rhod_region *g = &rs->regions[k];
    if (!g->hold)
      continue;
    real *r = a->hr + RHOD_HOLD_STRIDE * h++;
    r[0] = (real)g->shape.kind;
    r[1] = (real)(sc->dx / pow(rhod_pattern_ratio(rs->pattern), g->level));
    if (g->shape.kind == RHOD_SHAPE_RECT) {
      r[2] = (real)g->shape.min[0], r[3] = (real)g->shape.min[1];
      r[4] = (real)g->shape.max[0], r[5] = (real)g->shape.max[1];
    } else if (g->shape.kind == RHOD_SHAPE_CIRCLE) {
      r[2] = (real)g->shape.center[0], r[3] = (real)g->shape.center[1];
      r[4] = (real)g->shape.radius;
    } else {
      r[2] = (real)v, r[3] = (real)g->shape.n_points;
      for (unsigned q = 0; q < g->shape.n_points; q++, v++)
        a->hp[2 * v] = (real)g->shape.points[q][0], a->hp[2 * v + 1] = (real)g->shape.points[q][1];
    }
  }
  rhod_to_device(a->hr, sizeof(real) * RHOD_HOLD_STRIDE * (size_t)a->nhold);
  rhod_to_device(a->hp, sizeof(real) * (2 * (size_t)a->nhp + 2));
  return RHOD_OK;
}

/* the per-particle buffers (ensure reallocates them) */
static void free_buffers(rhod_apr *a) {
  rhod_dev_free(a->mark, a->cap);
  rhod_dev_free(a->near, a->cap);
  rhod_dev_free(a->cnt, (a->cap + 1) * sizeof(int32_t));
  rhod_dev_free(a->sd, 4 * a->cap * sizeof(real));
  rhod_dev_free(a->near2, a->cap);
  rhod_dev_free(a->grp, 4 * a->cap * sizeof(int32_t));
  rhod_dev_free(a->claim, a->cap * sizeof(int32_t));
  rhod_dev_free(a->acc, a->cap);
  rhod_dev_free(a->sp, a->cap * sizeof(real));
  a->mark = a->near = a->near2 = a->acc = NULL;
  a->cnt = a->grp = a->claim = NULL;
  a->sd = a->sp = NULL;
  a->cap = 0;
}

void rhod_apr_free(rhod_apr *a) {
  free_buffers(a);
  rhod_dev_free(a->hr, sizeof(real) * RHOD_HOLD_STRIDE * (size_t)a->nhold);
  rhod_dev_free(a->hp, sizeof(real) * (2 * (size_t)a->nhp + 2));
  a->hr = a->hp = NULL;
}

static int ensure(rhod_apr *a, size_t n) {
  if (n <= a->cap && a->mark)
    return RHOD_OK;
  free_buffers(a);
  a->cap = n + n / 4 + 64;
  a->mark = rhod_dev_calloc(a->cap, 1);
  a->near = rhod_dev_calloc(a->cap, 1);
  a->cnt = rhod_dev_calloc(a->cap + 1, sizeof(int32_t));
  a->sd = rhod_dev_calloc(4 * a->cap, sizeof(real));
  a->near2 = rhod_dev_calloc(a->cap, 1);
  a->grp = rhod_dev_calloc(4 * a->cap, sizeof(int32_t));
  a->claim = rhod_dev_calloc(a->cap, sizeof(int32_t));
  a->acc = rhod_dev_calloc(a->cap, 1);
  a->sp = rhod_dev_calloc(a->cap, sizeof(real));
  return a->mark && a->near && a->cnt && a->sd && a->near2 && a->grp && a->claim && a->acc && a->sp
             ? RHOD_OK
             : RHOD_ERR_MEMORY;
}

/* The field of criterion 5 of a particle at (x, y): fc[0] P + fc[1] rho |u|^2 / 2 + fc[2] x +
 * fc[3] y + fc[4], one branch-free form for P (fc = 1, 0, 0, 0, 0), the dynamic pressure
 * rho |u|^2 / 2 (0, 1, 0, 0, 0) and paper 002 Sec. VI F's P - rho0 g.(x - x0)
 * (1, 0, -rho0 g_x, -rho0 g_y, rho0 g.x0); rhod_apr_init sets fc. Scalars, not the array,
 * in the kernels (FIELD_OF), which copy them in as firstprivate. */
#define FIELD_OF(rho, ux, uy, P, x, y)                                                             \
  (fcP * (P) + fcK * (real)0.5 * (rho) * ((ux) * (ux) + (uy) * (uy)) + fcX * (x) + fcY * (y) + fc1)

/* Sums of the criteria over the neighbours j within R of particle i (r_ij > 0, which
 * leaves i out), added to the variables named (which hold the self terms): Gamma_ij =
 * W(r_ij; R) V_j over sizes >= big into same (criterion 2), any size <= small into
 * anysmall (criterion 1), any size below own nearer than ck (own + dx_j)/2 into crowded
 * (refinement.crowding, ck = 0: never), and the Shepard sums of the criterion-5 field
 * into num, den (computed always, used only with c5: a branch would keep the loop from
 * vectorising).
 * One text for a particle's own support and for the support e R_i of the particle its
 * coalescing group would make. Reads the rows the last right-hand side packed in cell
 * order (RHOD_PK_*) in vector lanes (cells.h RHOD_FOR_LANES), as the scheme's gathers do.
 * A macro over the marking loop's locals (G, CS, x, y, kx, ky, kV, kdx, kP, kux, kuy,
 * krho, kern, fcP, fcK, fcX, fcY, fc1), not a function: GCC 12 nvptx puts a returned struct, like
 * pointer outputs, in the warp-shared frame (tests/offload_frames.sh). */
#define CRITERIA_SUMS(i, R, small, big, own, ck, same, num, den, anysmall, crowded)                \
  {                                                                                                \
    const real xs_ = x[i], ys_ = y[i], iR_ = 1 / (R), iR2_ = iR_ * iR_;                            \
    const real R2_ = rhod_closed_support2(R); /* kernel.h */                                       \
    real RHOD_LANES(ssame_), RHOD_LANES(snum_), RHOD_LANES(sden_), RHOD_LANES(ssmall_);            \
    real RHOD_LANES(scrowd_);                                                                      \
    RHOD_FOR_ROWS(G, CS, xs_, ys_, (R), k0_, k1_, kv_) {                                           \
      RHOD_FOR_LANES(k0_, kv_, k_) {                                                               \
        const real rx_ = kx[k_] - xs_, ry_ = ky[k_] - ys_, r2_ = rx_ * rx_ + ry_ * ry_;            \
        if (!(r2_ < R2_ && r2_ > 0))                                                               \
          continue;                                                                                \
        const real dxj_ = kdx[k_];                                                                 \
        RHOD_LANE(ssmall_) = dxj_ <= (small) ? 1 : RHOD_LANE(ssmall_);                             \
        const real dc_ = (ck) * (real)0.5 * ((own) + dxj_);                                        \
        const int cr_ = dxj_ < (own) * (1 - RHOD_SIZE_TOL) && r2_ < dc_ * dc_;                     \
        RHOD_LANE(scrowd_) = cr_ ? 1 : RHOD_LANE(scrowd_);                                         \
        const real w_ = rhod_Wq(kern, sqrt(r2_) * iR_) * iR2_ * kV[k_];                            \
        RHOD_LANE(ssame_) += dxj_ >= (big) ? w_ : 0;                                               \
        const real phij_ = FIELD_OF(krho[k_], kux[k_], kuy[k_], kP[k_], kx[k_], ky[k_]);           \
        RHOD_LANE(snum_) += w_ * phij_, RHOD_LANE(sden_) += w_;                                    \
      }                                                                                            \
      RHOD_END_LANES                                                                               \
    }                                                                                              \
    RHOD_END_ROWS                                                                                  \
    const real same_ = RHOD_LANES_SUM(ssame_), num_ = RHOD_LANES_SUM(snum_);                       \
    const real den_ = RHOD_LANES_SUM(sden_), small_ = RHOD_LANES_MAX(ssmall_);                     \
    const real crowd_ = RHOD_LANES_MAX(scrowd_);                                                   \
    (same) += same_, (num) += num_, (den) += den_;                                                 \
    (anysmall) |= small_ > 0;                                                                      \
    (crowded) |= crowd_ > 0;                                                                       \
  }

/* Candidates not grouped go back to no mark. */
static void drop_candidates(uint8_t *mark, long n) {
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++)
    mark[i] = mark[i] == 2 ? 0 : mark[i];
}

static long group(rhod_apr *a, const rhod_particles *p, const rhod_cells *c);
static long absorb(rhod_apr *a, const rhod_sph *s, const rhod_particles *p, const rhod_cells *c);
static long coalesce_c2(rhod_apr *a, const rhod_sph *s, const rhod_particles *p,
                        const rhod_cells *c);

int rhod_apr_mark(rhod_apr *a, const rhod_sph *s, const rhod_particles *p, const rhod_cells *c,
                  const rhod_boundary *b, double t, int coalesce) {
  const long n = (long)p->n;
  if (ensure(a, p->n) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  a->n_marked = n;
  const int co = coalesce && a->coalesce;
  if (a->walls)
    rhod_walls_near(b, p, s->ratio, a->near);
  if (a->walls && co)
    rhod_walls_near(b, p, a->eps * HYST * s->ratio, a->near2);
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx;
  const real *x = p->x, *y = p->y, *dx = p->dx, *ux = p->ux, *uy = p->uy, *rho = p->rho;
  const real *V = s->V, *P = s->P, *gP = s->gP;
  /* the neighbour side of the criteria's sums: the rows packed by the last right-hand side */
  const long st = (long)p->cap;
  const real *kx = s->pk + RHOD_PK_X * st, *ky = s->pk + RHOD_PK_Y * st;
  const real *kV = s->pk + RHOD_PK_V * st, *kdx = s->pk + RHOD_PK_DX * st;
  const real *kP = s->pk + RHOD_PK_P * st, *kux = s->pk + RHOD_PK_UX * st;
  const real *kuy = s->pk + RHOD_PK_UY * st, *krho = s->pk + RHOD_PK_RHO * st;
  const real *seg = b->seg, *circ = b->circ;
  const int nseg = b->nseg, ncirc = b->ncirc, o0_ = b->open0, o1_ = b->nwallseg;
  const uint8_t *reg = s->reg, *near = a->near, *near2 = a->near2;
  /* the free-surface particles alone (the region pass's subset cells, s->fsc) */
  const rhod_grid Gf = s->fsc.g;
  const int32_t *CSf = s->fsc.start, *CIf = s->fsc.idx;
  const real *sig = s->sig;
  uint8_t *mark = a->mark;
  real *sd = a->sd, *sp = a->sp;
  const int kern = s->kernel;
  const real ratio = s->ratio, dmin = a->dx_min * (1 - RHOD_SIZE_TOL);
  const real eps = a->eps, ieps = a->ieps, nsplit = (real)a->nsplit;
  const int tri = a->nsplit == 3;
  const int c3 = a->free_surface && s->fsdetect, c4 = a->walls;
  /* criterion 3 (Sec. V B): a free-surface particle in the support, i.e. i in F u V
   * (the region pass). With refinement.surface_band f < 1 (our option, a departure
   * from the paper; docs/choices.md "criterion 3's reach"): i in F, or a free-surface
   * particle nearer than f R_i, read from sigma_i = 1 - d_i/R_i on V (region pass) */
  const real band = a->band, sband = 1 - a->band;
  /* ours (refinement.crowding, docs/choices.md "crowding at size jumps"): split i when a
   * finer particle j stands nearer than crowd (dx_i + dx_j)/2, i.e. inside i's share of
   * the plane (about 1 where the sizes tile it). Such a pair is where APR case B's
   * pressure bursts start: a child of a split in a squeezed lattice next to an unsplit
   * coarse neighbour (cases/rotating_square/RESULTS.md, "Bursts at the size jumps");
   * splitting the coarse one leaves pairs of one size, which single resolution bears. */
  const real crowd = a->crowd;
  const int c5 = a->field && (real)t >= a->from;
  const real fcP = a->fc[0], fcK = a->fc[1], fcX = a->fc[2], fcY = a->fc[3], fc1 = a->fc[4];
  const real above = a->above, below = a->below;
  const int nh = a->nhold;
  const real *hr = a->hr, *hp = a->hp;
  /* coalescing: the largest size that may merge, the thresholds of criterion 5 with
   * the margin (HYST - 1) |threshold| (1e30 stands for none and stays far away) */
  const real dgrow = ieps * a->dx_max * (1 + RHOD_SIZE_TOL);
  const real above2 = above - (HYST - 1) * fabs(above), below2 = below + (HYST - 1) * fabs(below);
  /* a gather loop (its work per particle varies: the candidates and marked particles
   * gather, the rest stop early); the candidates are counted after it, so that the count
   * needs no reduction here */
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    const real xi = x[i], yi = y[i], dxi = dx[i], Ri = ratio * dxi, R2 = Ri * Ri;
    sd[4 * i] = gP[2 * i], sd[4 * i + 1] = gP[2 * i + 1];
    sd[4 * i + 2] = 1, sd[4 * i + 3] = 0;
    const int can_split = dxi * ieps >= dmin; /* dx_min is never crossed (Sec. V B) */
    if (!can_split && !(co && dxi <= dgrow)) {
      mark[i] = 0;
      continue;
    }
    const real iR = 1 / Ri, iR2 = iR * iR;
    const real self = rhod_Wq(kern, 0) * iR2 * V[i]; /* Gamma_ii, Eq. 7 */
    const real phii = FIELD_OF(rho[i], ux[i], uy[i], P[i], xi, yi);
    /* criterion 1: a neighbour two levels finer, dx_i / e^2 (dx_i / 4 at e = 2) */
    const real quarter = dxi * ieps * ieps * (1 + RHOD_SIZE_TOL), lower = dxi * (1 - RHOD_SIZE_TOL);
    real same = self; /* criterion 2: sum of Gamma_ij over dx_j >= dx_i, i included */
    real num = self * phii, den = self; /* criterion 5: Shepard average, i included */
    int grand = 0;                      /* criterion 1 */
    int crowded = 0;                    /* refinement.crowding */
    if (can_split) /* a particle at dx_min is here only as a coalescing candidate */
      CRITERIA_SUMS(i, Ri, quarter, lower, dxi, crowd, same, num, den, grand, crowded);
    const real phi = num / den;
    const int in3 = c3 && (reg[i] == 2 || (reg[i] == 1 && (band >= 1 || sig[i] > sband)));
    /* last, a held region (ours, refinement.regions.N.hold) asking for a finer size here */
    const int m = can_split && (grand || crowded || same < 2 * self || in3 || (c4 && near[i]) ||
                                (c5 && (phi > above || phi < below)) ||
                                (nh && held_dx(nh, hr, hp, xi, yi, 0) < dxi * (1 - RHOD_SIZE_TOL)));
    mark[i] = (uint8_t)m;
    /* nor may a group merge within one merged size e dx_i of a region that asks for
     * less than that size: the merged particle, at most dx_i from each member, would
     * stand in the region or split again as soon as it drifted in */
    if (!m && co && dxi <= dgrow && !in3 && !(c4 && near2[i]) &&
        !(nh && held_dx(nh, hr, hp, xi, yi, eps * dxi) < eps * dxi * (1 - RHOD_SIZE_TOL))) {
      /* Coalescing candidate: the criteria for the particle of size D = e dx_i at x_i
       * (HYST above). Criterion 3 first: no free-surface particle within HYST f e R_i,
       * looked for among the free-surface particles alone (the subset cells fsc that the
       * region pass sorted), then one pass over the support e R_i:
       * no particle of size dx_i/e or less (criterion 1: it would be D/e^2) and the
       * Shepard field inside the thresholds with margin (criterion 5). Criterion 2
       * needs the other candidates too (coalesce_c2): the sum of Gamma over sizes >= D
       * is kept in sp. */
      const real RD = eps * Ri, iRD = 1 / RD, iRD2 = iRD * iRD;
      const real RH = HYST * band * RD, RH2 = rhod_closed_support2(RH);
      int ok = 1;
      if (c3) {
        RHOD_FOR_NEIGHBOURS(Gf, CSf, CIf, xi, yi, RH, j) {
          const real rx = x[j] - xi, ry = y[j] - yi;
          ok &= !(rx * rx + ry * ry < RH2);
        }
        RHOD_END_NEIGHBOURS
      }
      if (ok) {
        const real self2 = rhod_Wq(kern, 0) * iRD2 * nsplit * V[i];
        const real half = ieps * dxi * (1 + RHOD_SIZE_TOL), big = eps * dxi * (1 - RHOD_SIZE_TOL);
        real same2 = 0, num2 = self2 * phii, den2 = self2;
        int fine = 0;
        /* crowding: the group's room test (group_round), which knows its members */
        CRITERIA_SUMS(i, RD, half, big, dxi, 0, same2, num2, den2, fine, fine);
        const real phi2 = num2 / den2;
        ok = !fine && !(c5 && (phi2 > above2 || phi2 < below2));
        sp[i] = same2;
      }
      mark[i] = ok ? 2 : 0;
    }
    if (!m)
      continue;
    /* the nearest neighbour, for the marked particles only. Our choice where several are
     * nearest (within RHOD_SUPPORT_TIE, kernel.h; a lattice has many such ties, where
     * rounding picked the first in the cells' order, which a quarter-turned copy of the
     * scene does not share): the one whose direction, turned by a multiple of 90 degrees
     * into [0, 90), makes the smallest angle with +x (key = tan of that angle over 1 +
     * tan, read 0 within rounding of 90), so that a scene symmetric under a quarter turn
     * refines symmetrically; the first where the keys tie too (directions a quarter
     * turn apart, whose squares are the same). The sum of the tied unit vectors
     * instead (also symmetric) took the four-level dam break's P1 from 3.1 % to 6.5 % of
     * the stored SR 200 run, this rule 3.8 % (cases/rotating_square/RESULTS.md, "Symmetry"). */
    real best = R2, ex = 1, ey = 0, bkey = 2;
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, Ri, j) {
      const real rx = x[j] - xi, ry = y[j] - yi, r2 = rx * rx + ry * ry;
      if (j != i && r2 < best * (1 + 2 * RHOD_SUPPORT_TIE)) {
        const int q1 = rx > 0 && ry >= 0, q2 = rx <= 0 && ry > 0, q3 = rx < 0 && ry <= 0;
        const real qx = q1 ? rx : (q2 ? ry : (q3 ? -rx : -ry));
        const real qy = q1 ? ry : (q2 ? -rx : (q3 ? -ry : rx));
        real key = qy / (qx + qy);
        key = key > 1 - 4 * RHOD_SUPPORT_TIE ? 0 : key;
        if (r2 < best * (1 - 2 * RHOD_SUPPORT_TIE) || key < bkey - 4 * RHOD_SUPPORT_TIE)
          best = r2 < best ? r2 : best, ex = rx, ey = ry, bkey = key;
      }
    }
    RHOD_END_NEIGHBOURS
    if (!(best < R2))
      continue;
    /* Pattern of the children (Sec. V A, Fig. 5). The paper turns the square of side
     * dx_i/2 towards the nearest neighbour "to maximize the minimum inter-particle
     * distance once the refinement is completed". Our generalisation (docs/choices.md):
     * a rectangle of the same area, sides a dx_i/2 along e and dx_i/(2a) across, e the
     * nearest-neighbour direction turned by 0, 15, ... 75 degrees and a in 1.25^-4 ..
     * 1.25^4 (a and 1/a cover the other half turn). A pattern scores the smaller of
     * its sibling spacing, min(a, 1/a) dx_i/2, and, for every neighbour j within
     * 2 dx_i (ghosts too, so a wall counts), twice the distance by which each child,
     * moved off the walls as the split will move it (PATTERN_SHIFT), stays on i's side
     * of the i-j interface point x_i + w_i (x_j - x_i) of Eq. 12:
     * the distance to j's children if j splits alike. The best score wins; ties keep
     * the square aligned with the nearest neighbour (the paper's pattern), which is
     * what a regular lattice gets. On a strained lattice (rows squeezed to 0.4 dx by
     * a dam break's stretching) the square would put a child nearly on top of a
     * neighbour's child; the rectangle follows the strain and the children form the
     * same strained lattice at half the spacing.
     * Triangle (1 -> 3, Appendix, Fig. 32; the paper gives no placement): the children
     * at the corners of the equilateral triangle of side dx_i/sqrt 3 (their own size)
     * centred on x_i, circumradius dx_i/3, one corner along e; the same score over
     * the turns 0, 15, ... 105 degrees (the triangle repeats every 120), no aspect.
     * One neighbour pass per pattern, each with a scalar minimum, the turns made by a
     * constant 15-degree rotation: an array of minima, or cos/sin of a variable angle
     * (fused into sincos() with pointer outputs), would be an addressable local, which
     * GCC 12 nvptx puts in the warp-shared frame (offload.md, tests/offload_frames.sh).
     * Only marked particles pay for the passes. */
    const real e0 = sqrt(best), h = (real)0.25 * dxi, reach = 2 * dxi, reach2 = reach * reach;
    const real c15 = (real)0.96592582628906829, s15 = (real)0.25881904510252076;
    const real s32 = S32, rt = dxi / 3, keep = (real)0.25 * (dxi * ieps), back = (real)0.5 * dxi;
    const int turns = tri ? 8 : 6, aspects = tri ? 1 : 9;
    real sbest = (real)-1e30, fx = ex / e0, fy = ey / e0, bx = fx, by = fy;
    for (int k = 0; k < turns; k++) {
      real up = 1;
      for (int q = 0; q < aspects; q++) {
        /* q = 0: a = 1; then 1.25, 0.8, 1.25^2, 1.25^-2, ... */
        up = (q & 1) ? up * (real)1.25 : up;
        const real a = (q & 1) || q == 0 ? up : 1 / up, ha = h * a, hb = h / a;
        real score = tri ? s32 * 2 * rt : 2 * (a < 1 ? ha : hb);
        /* the pattern where the split will put it: moved off the walls */
        real shx = 0, shy = 0;
        PATTERN_SHIFT(tri, xi, yi, fx, fy, ha, hb, rt, keep, back, shx, shy);
        RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, reach, j) {
          const real rx = x[j] - xi, ry = y[j] - yi, r2 = rx * rx + ry * ry;
          if (j != i && r2 < reach2) {
            /* w_i r of Eq. 12 (exactly r/2 at equal sizes: x / (x + x) = 0.5) */
            const real r = sqrt(r2), wr = dxi / (dxi + dx[j]) * r;
            /* the child farthest along n_ij. Rectangle: |o.n| is largest at the
             * corner whose signs match those of (e.n, e_perp.n). Triangle: the
             * largest of rt (c_k e.n + s_k e_perp.n) over the corners (c, s) = (1, 0),
             * (-1/2, +-sqrt(3)/2) */
            const real en = (fx * rx + fy * ry) / r, pn = (fx * ry - fy * rx) / r;
            const real tn = -(real)0.5 * en + s32 * fabs(pn);
            const real on = (tri ? rt * (en > tn ? en : tn) : ha * fabs(en) + hb * fabs(pn)) +
                            (shx * rx + shy * ry) / r;
            const real sj = 2 * (wr - on);
            score = sj < score ? sj : score;
          }
        }
        RHOD_END_NEIGHBOURS
        /* strict, beyond rounding: ties keep the earlier pattern */
        if (score > sbest + RHOD_SUPPORT_TIE * dxi)
          sbest = score, bx = a * fx, by = a * fy;
      }
      const real gx = c15 * fx - s15 * fy; /* e turned by a further 15 degrees */
      fy = s15 * fx + c15 * fy, fx = gx;
    }
    sd[4 * i + 2] = bx, sd[4 * i + 3] = by; /* e scaled by the aspect a */
  }
  long ncand = 0;
  if (co) {
    RHOD_KERNEL_LOOP_REDUCE(+, ncand)
    for (long i = 0; i < n; i++)
      ncand += mark[i] == 2;
  }
  const long kept = ncand > 0 ? coalesce_c2(a, s, p, c) : 0;
  a->groups = kept >= a->nsplit ? group(a, p, c) : 0;
  a->absorbed = a->absorb && kept > a->groups * a->nsplit ? absorb(a, s, p, c) : 0;
  if (ncand > 0)
    drop_candidates(mark, n); /* the candidates left over */
  return RHOD_OK;
}

/* Criterion 2 for the particle a candidate's group would make (size D, support RD =
 * e R_i, volume N V_i, N the children of a split): sum of Gamma over the neighbours of size >= D
 * (sp, from the marking pass) plus over the candidates of i's size, i included, which will mostly
 * be merged too (their volume is what the merged particles will have), at least
 * 2 HYST Gamma_DD. Counting the candidates lets a fine region with no coarser
 * particle left merge as a whole instead of only from a coarse edge inward. Returns
 * the candidates kept. */
static long coalesce_c2(rhod_apr *a, const rhod_sph *s, const rhod_particles *p,
                        const rhod_cells *c) {
  const long n = (long)p->n;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx;
  const real *x = p->x, *y = p->y, *dx = p->dx, *V = s->V, *sp = a->sp;
  uint8_t *mark = a->mark, *acc = a->acc;
  const int kern = s->kernel;
  const real ratio = s->ratio, eps = a->eps, nsplit = (real)a->nsplit;
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    acc[i] = 0;
    if (mark[i] != 2)
      continue;
    const real xi = x[i], yi = y[i], dxi = dx[i], RD = eps * ratio * dxi, RD2 = RD * RD;
    const real iRD = 1 / RD, iRD2 = iRD * iRD, self2 = rhod_Wq(kern, 0) * iRD2 * nsplit * V[i];
    const real lo = dxi * (1 - RHOD_SIZE_TOL), hi = dxi * (1 + RHOD_SIZE_TOL);
    real sum = sp[i];
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, RD, j) {
      const real rx = x[j] - xi, ry = y[j] - yi, r2 = rx * rx + ry * ry;
      if (j < n && r2 < RD2 && mark[j] == 2 && dx[j] > lo && dx[j] < hi)
        sum += rhod_Wq(kern, sqrt(r2) * iRD) * iRD2 * V[j];
    }
    RHOD_END_NEIGHBOURS
    acc[i] = sum >= 2 * HYST * self2;
  }
  long kept = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, kept)
  for (long i = 0; i < n; i++)
    if (mark[i] == 2) {
      mark[i] = acc[i] ? 2 : 0;
      kept += acc[i];
    }
  return kept;
}

/* Groups of four (triangle: three) candidates (mark 2), formed at the marking
 * positions in rounds: each candidate left proposes one (Q_MIN above), each candidate
 * takes the proposal containing it with the smallest spread (ties: the lower index),
 * and a proposal whose members all took it is accepted: leader mark 3, members 4. On a lattice
 * every spread ties and overlapping proposals block each other, so one round accepts few;
 * GROUP_ROUNDS rounds (or until one accepts none); the candidates left over may
 * group at a later marking. Returns the groups accepted. Every pass writes only its
 * own particle's entries. */
#define GROUP_ROUNDS 6
static long group_round(rhod_apr *a, const rhod_particles *p, const rhod_cells *c);

static long group(rhod_apr *a, const rhod_particles *p, const rhod_cells *c) {
  long total = 0, got = 1;
  for (int r = 0; r < GROUP_ROUNDS && got > 0; r++)
    total += got = group_round(a, p, c);
  return total;
}

static long group_round(rhod_apr *a, const rhod_particles *p, const rhod_cells *c) {
  const long n = (long)p->n;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx;
  const real *x = p->x, *y = p->y, *dx = p->dx, *m = p->m;
  uint8_t *mark = a->mark, *acc = a->acc;
  int32_t *grp = a->grp, *claim = a->claim;
  real *sp = a->sp;
  const real eps = a->eps;
  const real qcrowd = a->crowd > Q_MIN ? a->crowd : Q_MIN;
  const int others = a->nsplit - 1; /* members besides the candidate: 3 or 2 */
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    sp[i] = NONE;
    if (mark[i] != 2)
      continue;
    const real xi = x[i], yi = y[i], dxi = dx[i], reach = 2 * dxi, reach2 = reach * reach;
    const real lo = dxi * (1 - RHOD_SIZE_TOL), hi = dxi * (1 + RHOD_SIZE_TOL);
    int32_t g1 = -1, g2 = -1, g3 = -1;
    real cx = xi, cy = yi;
    for (int r = 0; r < others; r++) {
      real bd = reach2;
      int32_t bj = -1;
      RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, reach, j) {
        if (j < n && j != i && j != g1 && j != g2 && mark[j] == 2 && dx[j] > lo && dx[j] < hi) {
          const real rx = x[j] - cx, ry = y[j] - cy, d2 = rx * rx + ry * ry;
          if (d2 < bd || (d2 == bd && j < bj))
            bd = d2, bj = j;
        }
      }
      RHOD_END_NEIGHBOURS
      if (bj < 0)
        break;
      g1 = r == 0 ? bj : g1, g2 = r == 1 ? bj : g2, g3 = r == 2 ? bj : g3;
      cx += (x[bj] - cx) / (r + 2), cy += (y[bj] - cy) / (r + 2);
    }
    if (others == 3 ? g3 < 0 : g2 < 0)
      continue;
    /* centre of mass and spread (a group of three has no g3: its terms are zero) */
    const real m3 = others == 3 ? m[g3] : 0, x3 = others == 3 ? x[g3] : 0;
    const real y3 = others == 3 ? y[g3] : 0;
    const real M = m[i] + m[g1] + m[g2] + m3;
    const real X = (m[i] * xi + m[g1] * x[g1] + m[g2] * x[g2] + m3 * x3) / M;
    const real Y = (m[i] * yi + m[g1] * y[g1] + m[g2] * y[g2] + m3 * y3) / M;
    real s2 = (xi - X) * (xi - X) + (yi - Y) * (yi - Y);
    real d = (x[g1] - X) * (x[g1] - X) + (y[g1] - Y) * (y[g1] - Y);
    s2 = d > s2 ? d : s2;
    d = (x[g2] - X) * (x[g2] - X) + (y[g2] - Y) * (y[g2] - Y);
    s2 = d > s2 ? d : s2;
    d = others == 3 ? (x3 - X) * (x3 - X) + (y3 - Y) * (y3 - Y) : 0;
    s2 = d > s2 ? d : s2;
    if (s2 > dxi * dxi)
      continue;
    /* room around the merged particle (ghosts included, so walls count) */
    int room = 1;
    const real look = 3 * dxi, D = eps * dxi * (1 - RHOD_SIZE_TOL);
    RHOD_FOR_NEIGHBOURS(G, CS, CI, X, Y, look, j) {
      if (j != i && j != g1 && j != g2 && j != g3) {
        /* a finer j nearer than refinement.crowding allows would split the merged
         * particle again at once */
        const real qj = dx[j] < D ? qcrowd : Q_MIN;
        const real rx = x[j] - X, ry = y[j] - Y, q = qj * ((real)0.5 * (eps * dxi + dx[j]));
        room &= rx * rx + ry * ry >= q * q;
      }
    }
    RHOD_END_NEIGHBOURS
    if (!room)
      continue;
    grp[4 * i] = (int32_t)i, grp[4 * i + 1] = g1, grp[4 * i + 2] = g2;
    grp[4 * i + 3] = others == 3 ? g3 : -1;
    sp[i] = s2;
  }
  RHOD_GATHER_LOOP
  for (long j = 0; j < n; j++) {
    claim[j] = -1;
    if (mark[j] != 2)
      continue;
    const real reach = 2 * dx[j] * (1 + RHOD_SIZE_TOL);
    real bs = NONE;
    int32_t bi = -1;
    RHOD_FOR_NEIGHBOURS(G, CS, CI, x[j], y[j], reach, i) {
      if (i < n && sp[i] < NONE &&
          (grp[4 * i] == j || grp[4 * i + 1] == j || grp[4 * i + 2] == j || grp[4 * i + 3] == j) &&
          (sp[i] < bs || (sp[i] == bs && i < bi)))
        bs = sp[i], bi = i;
    }
    RHOD_END_NEIGHBOURS
    claim[j] = bi;
  }
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++)
    acc[i] = sp[i] < NONE && claim[grp[4 * i]] == i && claim[grp[4 * i + 1]] == i &&
             claim[grp[4 * i + 2]] == i && (grp[4 * i + 3] < 0 || claim[grp[4 * i + 3]] == i);
  long accepted = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, accepted)
  for (long j = 0; j < n; j++)
    if (mark[j] == 2) {
      const int32_t k = claim[j];
      mark[j] = k >= 0 && acc[k] ? (k == j ? 3 : 4) : 2;
      accepted += k == j && acc[k];
    }
  return accepted;
}

/* Absorption of stragglers (ours, docs/choices.md "APR coalescing"): a candidate left
 * ungrouped with fewer than N - 1 other particles of its size within 2 dx_i (N = 4, or
 * 3 for the triangle) can be in no group (a group's members lie within dx_i of their
 * centre of mass, so within 2 dx_i of each other) and, with no particle of its size
 * coming near, never will: a fine particle left behind among coarser ones when a
 * refined region merged back. It keeps the coarser particles around it from merging
 * in turn (criterion 1 for them). Such a donor i is shared out among the particles
 * one size coarser (e dx_i, the size its group would have made) within R_a = (1 + e)
 * dx_i (the first two rings of them on a regular layout: a particle of size dx_i and
 * one of e dx_i stand (1 + e) dx_i / 2 apart), in the proportions f_ij = W(r_ij; R_a)
 * / sum_k W(r_ik; R_a): receiver j gains f_ij m_i, f_ij m_i u_i, f_ij V_i and moves to
 * the centre of mass of itself and its share, so mass, momentum, volume and the centre
 * of mass are conserved, as in a merge, and the sizes stay the level sizes. A
 * receiver is not splitting, grouped, or a donor itself, has a volume m_j / rho_j
 * below ABSORB_VMAX dx_j^2 (so that repeated absorptions cannot inflate one particle
 * beyond its size: its support stays R_j), and takes at most the four nearest donors
 * (ties: lower index); a donor no receiver takes stays a candidate. Marks: donor 5,
 * receiver 6; a receiver keeps its donors in grp and their shares f_ij in sd, which
 * are free for it (sd is read only for the particles that split). Returns the donors. */
#define ABSORB_VMAX ((real)1.25)
/* keeps (d0, j0) .. (d3, j3) the four smallest (d, j), lexicographically */
#define KEEP4(d, j)                                                                                \
  if ((d) < d3 || ((d) == d3 && (j) < j3)) {                                                       \
    d3 = (d), j3 = (j);                                                                            \
    if (d3 < d2 || (d3 == d2 && j3 < j2)) {                                                        \
      const real td_ = d2;                                                                         \
      const int32_t tj_ = j2;                                                                      \
      d2 = d3, j2 = j3, d3 = td_, j3 = tj_;                                                        \
      if (d2 < d1 || (d2 == d1 && j2 < j1)) {                                                      \
        const real ud_ = d1;                                                                       \
        const int32_t uj_ = j1;                                                                    \
        d1 = d2, j1 = j2, d2 = ud_, j2 = uj_;                                                      \
        if (d1 < d0 || (d1 == d0 && j1 < j0)) {                                                    \
          const real vd_ = d0;                                                                     \
          const int32_t vj_ = j0;                                                                  \
          d0 = d1, j0 = j1, d1 = vd_, j1 = vj_;                                                    \
        }                                                                                          \
      }                                                                                            \
    }                                                                                              \
  }

static long absorb(rhod_apr *a, const rhod_sph *s, const rhod_particles *p, const rhod_cells *c) {
  const long n = (long)p->n;
  const rhod_grid G = c->g;
  const int32_t *CS = c->start, *CI = c->idx;
  const real *x = p->x, *y = p->y, *dx = p->dx, *m = p->m, *rho = p->rho;
  uint8_t *mark = a->mark, *acc = a->acc;
  int32_t *grp = a->grp, *claim = a->claim;
  real *sd = a->sd, *sp = a->sp;
  const int kern = s->kernel, others = a->nsplit - 1;
  const real eps = a->eps, ieps = a->ieps;
  /* the donors: candidates with fewer than N - 1 particles of their size within 2 dx_i */
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    acc[i] = 0;
    if (mark[i] != 2)
      continue;
    const real xi = x[i], yi = y[i], dxi = dx[i], reach = 2 * dxi, reach2 = reach * reach;
    const real lo = dxi * (1 - RHOD_SIZE_TOL), hi = dxi * (1 + RHOD_SIZE_TOL);
    int same = 0;
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, reach, j) {
      const real rx = x[j] - xi, ry = y[j] - yi;
      same += j < n && j != i && dx[j] > lo && dx[j] < hi && rx * rx + ry * ry < reach2;
    }
    RHOD_END_NEIGHBOURS
    acc[i] = same < others;
  }
  /* the receivers: each lists its four nearest donors i (of size dx_j / e, within R_a of
   * them) with the weights W(r_ij; R_a) */
  RHOD_GATHER_LOOP
  for (long j = 0; j < n; j++) {
    claim[j] = 0;
    const real dxj = dx[j];
    if (!(mark[j] == 0 || mark[j] == 2) || acc[j] || m[j] >= ABSORB_VMAX * rho[j] * dxj * dxj)
      continue;
    const real xj = x[j], yj = y[j], dd = dxj * ieps; /* the donors' size */
    const real lo = dd * (1 - RHOD_SIZE_TOL), hi = dd * (1 + RHOD_SIZE_TOL), Ra = (1 + eps) * dd;
    const real Ra2 = Ra * Ra;
    real d0 = NONE, d1 = NONE, d2 = NONE, d3 = NONE;
    int32_t j0 = -1, j1 = -1, j2 = -1, j3 = -1;
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xj, yj, Ra, i) {
      const real rx = x[i] - xj, ry = y[i] - yj, r2 = rx * rx + ry * ry;
      if (i < n && acc[i] && dx[i] > lo && dx[i] < hi && r2 < Ra2)
        KEEP4(r2, (int32_t)i);
    }
    RHOD_END_NEIGHBOURS
    grp[4 * j] = j0, grp[4 * j + 1] = j1, grp[4 * j + 2] = j2, grp[4 * j + 3] = j3;
    const real iRa = 1 / Ra;
    sd[4 * j] = j0 >= 0 ? rhod_Wq(kern, sqrt(d0) * iRa) : 0;
    sd[4 * j + 1] = j1 >= 0 ? rhod_Wq(kern, sqrt(d1) * iRa) : 0;
    sd[4 * j + 2] = j2 >= 0 ? rhod_Wq(kern, sqrt(d2) * iRa) : 0;
    sd[4 * j + 3] = j3 >= 0 ? rhod_Wq(kern, sqrt(d3) * iRa) : 0;
    claim[j] = (j0 >= 0) + (j1 >= 0) + (j2 >= 0) + (j3 >= 0);
  }
  /* the donors' normalisation: the weights of the receivers that listed them */
  RHOD_GATHER_LOOP
  for (long i = 0; i < n; i++) {
    sp[i] = 0;
    if (!acc[i])
      continue;
    const real xi = x[i], yi = y[i], Ra = (1 + eps) * dx[i];
    real S = 0;
    RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, Ra, j) {
      if (j < n && claim[j] > 0)
        for (int k = 0; k < 4; k++)
          S += grp[4 * j + k] == (int32_t)i ? sd[4 * j + k] : 0;
    }
    RHOD_END_NEIGHBOURS
    sp[i] = S;
  }
  /* the shares f_ij, and the marks */
  long donors = 0;
  RHOD_KERNEL_LOOP_REDUCE(+, donors)
  for (long q = 0; q < n; q++) {
    if (claim[q] > 0) {
      for (int k = 0; k < 4; k++) {
        const int32_t i = grp[4 * q + k];
        sd[4 * q + k] = i >= 0 && sp[i] > 0 ? sd[4 * q + k] / sp[i] : 0;
      }
      mark[q] = 6;
    } else if (acc[q] && sp[q] > 0) {
      mark[q] = 5;
      donors++;
    }
  }
  return donors;
}

long rhod_apr_split(rhod_apr *a, const rhod_sph *s, rhod_particles *p, const rhod_boundary *b) {
  const long n = (long)p->n;
  a->split_last = 0;
  if (!a->mark || a->cap < p->n)
    return 0;
  uint8_t *mark = a->mark;
  int32_t *cnt = a->cnt;
  const int nsplit = a->nsplit, extra = nsplit - 1; /* the parent's slot keeps a child */
  RHOD_KERNEL_LOOP
  for (long i = 0; i <= n; i++)
    cnt[i] = i < n && mark[i] == 1 ? extra : 0;
  const long added = rhod_scan_exclusive(cnt, (size_t)n + 1);
  if (added <= 0)
    return added;
  if (rhod_particles_reserve(p, (size_t)(n + added) + 1) != RHOD_OK)
    return -1;
  int32_t *src = p->perm;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++)
    if (mark[i] == 1)
      for (int k = 0; k < extra; k++)
        src[cnt[i] + k] = (int32_t)i;
  /* velocity (u_child = u_i, Sec. V A) and every other persistent array come along; the
   * store gives the children at n + cnt[i] + k - 1 their new ids */
  rhod_particles_append(p, src, (size_t)added);
  real *x = p->x, *y = p->y, *rho = p->rho, *m = p->m, *dx = p->dx;
  const real *sd = a->sd;
  const real c2 = s->c0 * s->c0, ic2 = 1 / c2, rho0 = s->rho0;
  const real ieps = a->ieps, inn = 1 / (real)nsplit;
  const int tri = nsplit == 3;
  const real *seg = b->seg, *circ = b->circ;
  const int nseg = b->nseg, ncirc = b->ncirc, o0_ = b->open0, o1_ = b->nwallseg;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    if (mark[i] != 1)
      continue;
    const real xi = x[i], yi = y[i], dxi = dx[i], mi = m[i];
    const real Pi = c2 * (rho[i] - rho0); /* Eq. 2 */
    const real gx = sd[4 * i], gy = sd[4 * i + 1];
    /* Fig. 5: children at the corners of a square of side dx_i/2 centred on x_i (on
     * the circle of radius dx_i/(2 sqrt 2)), sides along and across the direction e
     * to the nearest neighbour; in general the rectangle of the same area and aspect
     * a chosen by rhod_apr_mark, which stores a e. Triangle (Appendix): the corners
     * of the equilateral triangle of circumradius dx_i/3 with one corner along e. */
    const real a = sqrt(sd[4 * i + 2] * sd[4 * i + 2] + sd[4 * i + 3] * sd[4 * i + 3]);
    const real ex = sd[4 * i + 2] / a, ey = sd[4 * i + 3] / a;
    const real ha = (real)0.25 * dxi * a, hb = (real)0.25 * dxi / a, rt = dxi / 3;
    const real dc = dxi * ieps; /* the children's size */
    /* the children stay a quarter of their size in front of the walls (PATTERN_SHIFT) */
    real shx = 0, shy = 0;
    PATTERN_SHIFT(tri, xi, yi, ex, ey, ha, hb, rt, (real)0.25 * dc, (real)0.5 * dxi, shx, shy);
    for (int k = 0; k < nsplit; k++) {
      CHILD_OFFSET(tri, k, ha, hb, rt, sa, sb);
      const real cx = xi + sa * ex - sb * ey + shx, cy = yi + sa * ey + sb * ex + shy;
      const real ox = cx - xi, oy = cy - yi;
      const long c = k == 0 ? i : n + cnt[i] + k - 1;
      /* Sec. V A: P_c = P_i + <grad P>^L_i . (x_c - x_i), rho_c from Eq. 2,
       * m_c = m_i/N so that V_c = (V_i rho_i / N) / rho_c (N = 4; 3 for the triangle,
       * the Appendix's "modified consistently") */
      const real Pc = Pi + gx * ox + gy * oy;
      x[c] = cx, y[c] = cy;
      rho[c] = rho0 + Pc * ic2;
      m[c] = inn * mi;
      dx[c] = dc;
    }
  }
  a->split_last = added / extra;
  a->split_total += added / extra;
  return added / extra;
}

long rhod_apr_coalesce(rhod_apr *a, rhod_particles *p) {
  const long n = (long)p->n, nm = a->n_marked;
  a->merged_last = 0;
  a->absorbed_last = 0;
  const long groups = a->groups, absorbed = a->absorbed;
  a->groups = a->absorbed = 0;
  if ((groups == 0 && absorbed == 0) || nm > n)
    return 0;
  const uint8_t *mark = a->mark;
  const int32_t *grp = a->grp;
  int32_t *cnt = a->cnt;
  real *x = p->x, *y = p->y, *ux = p->ux, *uy = p->uy, *rho = p->rho, *m = p->m, *dx = p->dx;
  const real dx_max = a->dx_max, ieps = a->ieps;
  /* kept: all but the merged members (4) and the spent donors (5) */
  RHOD_KERNEL_LOOP
  for (long i = 0; i < nm; i++)
    cnt[i] = mark[i] != 4 && mark[i] != 5;
  /* The merged particle, in the leader's slot (our choice, docs/choices.md): mass
   * m = sum m_k; position and velocity the mass-weighted means (centre of mass and
   * momentum conserved, as in paper 004 Sec. 2.3); volume V = sum m_k / rho_k
   * conserved, so rho = m / V (the inverse of the split's V_c = (V_i rho_i / 4) /
   * rho_c); the next coarser size; the leader's id. The kinetic energy of the members' motion
   * about their mean, sum m_k |u_k|^2 / 2 - M |U|^2 / 2, is lost (a dissipation the
   * energy probes see, summed into a->ke_merged; a receiver's into a->ke_absorbed). */
  const real *sd = a->sd;
  real kem = 0, kea = 0;
  RHOD_KERNEL_LOOP_REDUCE2(+, kem, kea)
  for (long i = 0; i < nm; i++) {
    const int lead = mark[i] == 3, recv = mark[i] == 6;
    if (!lead && !recv)
      continue;
    /* a leader's members (itself first, grp[4 i]), each whole; a receiver (absorb
     * above) itself and its donors' shares f_k */
    const real mi = recv ? m[i] : 0;
    real M = mi, X = mi * x[i], Y = mi * y[i], U = mi * ux[i], W = mi * uy[i];
    real V = recv ? m[i] / rho[i] : 0, K = mi * (ux[i] * ux[i] + uy[i] * uy[i]);
    for (int k = 0; k < 4; k++) {
      const int32_t j = grp[4 * i + k];
      const int32_t jj = j >= 0 ? j : (int32_t)i;
      const real mj = j < 0 ? 0 : (recv ? sd[4 * i + k] : 1) * m[jj];
      M += mj, X += mj * x[jj], Y += mj * y[jj], U += mj * ux[jj], W += mj * uy[jj];
      V += mj / rho[jj], K += mj * (ux[jj] * ux[jj] + uy[jj] * uy[jj]);
    }
    const real ke = (real)0.5 * (K - (U * U + W * W) / M);
    kem += lead ? ke : 0, kea += recv ? ke : 0;
    x[i] = X / M, y[i] = Y / M, ux[i] = U / M, uy[i] = W / M;
    m[i] = M, rho[i] = M / V;
    /* a leader takes the size one level up, made by the multiplications the splits make
     * from particles.dx, so that it equals the sizes of that level exactly (2 dx at e = 2) */
    real D = dx_max;
    while (lead && D * ieps > dx[i] * (1 + RHOD_SIZE_TOL))
      D *= ieps;
    dx[i] = lead ? D : dx[i];
  }
  /* the children of this step's split, after nm, stay behind in order */
  if (rhod_particles_compact(p, cnt, (size_t)nm) < 0)
    return -1;
  a->merged_last = groups;
  a->merged_total += groups;
  a->absorbed_last = absorbed;
  a->absorbed_total += absorbed;
  a->ke_merged += kem, a->ke_absorbed += kea;
  return groups;
}
