/* RHOD-SPH (paper 002) behind the engine's scheme hooks (include/rhod/scheme.h). */
#include "rhod/rhodsph/scheme.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Before the fill: the finest size (triangle: by the multiplications the splits make) and
 * the wall mirrors' reach. */
static int rs_geometry(const rhod_scene *sc, double *dx_min, double *mirror_reach, char *err,
                       size_t errlen) {
  if (!sc->rs) { /* the loader always makes it; a scene built by hand might lack it */
    snprintf(err, errlen, "%s: scheme.name: rhodsph, but the scene holds none of its keys",
             sc->path);
    return RHOD_ERR_SCENE;
  }
  if (sc->rs->levels < 1 || sc->rs->levels > RHOD_MAX_LEVELS) {
    /* the loader never lets this through; a scene built by hand might */
    snprintf(err, errlen, "%s: refinement.levels: %d is outside [1, %d]", sc->path, sc->rs->levels,
             RHOD_MAX_LEVELS);
    return RHOD_ERR_SCENE;
  }
  *dx_min = ldexp(sc->dx, -(sc->rs->levels - 1));
  if (sc->rs->pattern == RHOD_PATTERN_TRIANGLE) {
    real dmin = (real)sc->dx;
    for (int l = 1; l < sc->rs->levels; l++)
      dmin *= (real)(1 / rhod_pattern_ratio(sc->rs->pattern));
    *dx_min = dmin;
  }
  /* Wall mirrors: a fluid particle's ghost is needed by every particle whose support
   * crosses the wall. With one size that is within R_i of the wall; with mixed sizes
   * a neighbour may be up to twice as large (criterion 1 keeps sizes in a support
   * within a factor 2), so mirrors reach 2 R_i. */
  *mirror_reach = sc->rs->levels > 1 ? 2 : 1;
  return RHOD_OK;
}

/* The fill's initial levels: the finest refinement region containing the point
 * (refinement.regions, paper 002 Sec. VI C, Fig. 14: the nested lattices of its initial
 * setup); 0 outside all. */
static int rs_fill_level(const rhod_scene *sc, double x, double y) {
  const rhod_rs_scene *r = sc->rs;
  int l = 0;
  for (unsigned k = 0; k < r->n_regions; k++)
    if (r->regions[k].level > l && rhod_shape_contains(&r->regions[k].shape, x, y))
      l = r->regions[k].level;
  return l;
}

/* With dynamic refinement the lattice is filled unjittered, refined by the initial
 * criteria cascade (whose splits then fall on the finer lattices), and jittered
 * afterwards, each particle by its own size (refine_initial): jittered parents would give
 * children that crowd their neighbours' children. */
static int rs_fill_unjittered(const rhod_scene *sc) { return sc->rs->refine_dynamic; }

/* Particle k of size dx at (x, y) with the initial state of block b: the block's flow,
 * the hydrostatic pressure where asked, its ambient pressure, the density of Eq. 2 and
 * m = rho V. */
static void rs_initial_state(rhod_sim *s, unsigned b, size_t k, double x, double y, double dx) {
  const rhod_scene *sc = s->sc;
  const rhod_fluid_block *B = &sc->fluid[b];
  rhod_particles *p = &s->p;
  const double c2 = sc->rs->c0 * sc->rs->c0;
  double P = 0;
  if (B->pressure == RHOD_INIT_HYDROSTATIC) {
    /* paper 002 Sec. VI A: P = rho0 c0^2 (exp(g.(x - x_FS)/c0^2) - 1), the free surface
     * at fluid.N.surface (default the block's top along -g) */
    double g;
    const double depth = rhod_sim_block_depth(s, b, x, y, &g);
    P = sc->rs->rho0 * c2 * (exp(g * depth / c2) - 1);
  }
  double u, v, Pf;
  rhod_sim_initial_flow(s, b, x, y, sc->rs->rho0, &u, &v, &Pf);
  if (B->flow != RHOD_FLOW_NONE)
    P += Pf;
  P += B->ambient_pressure; /* fluid.N.ambient_pressure (docs/choices.md "ambient pressure") */
  const double rho = sc->rs->rho0 + P / c2; /* Eq. 2 */
  p->x[k] = (real)x;
  p->y[k] = (real)y;
  p->ux[k] = (real)u;
  p->uy[k] = (real)v;
  p->rho[k] = (real)rho;
  p->m[k] = (real)(rho * dx * dx); /* m_i = rho_i(0) V_i(0) */
  p->dx[k] = (real)dx;
}

static int rs_init(rhod_sim *s, char *err, size_t errlen) {
  const rhod_scene *sc = s->sc;
  rhod_rhodsph *rs = calloc(1, sizeof *rs);
  if (!rs) {
    snprintf(err, errlen, "out of memory setting up the scheme");
    return RHOD_ERR_MEMORY;
  }
  s->sch = rs;
  rhod_particles *p = &s->p;
  rhod_sph *h = &rs->sph;
  int st = rhod_sph_init(h, sc, p);
  s->body_mu = h->mu;                     /* the bodies' viscous force (body.h) */
  s->rho0[0] = sc->rs ? sc->rs->rho0 : 0; /* the open boundaries' nominal mass (open.h) */
  s->c0[0] = sc->rs ? sc->rs->c0 : 0;
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->x, &h->vel, 2, 0);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->y, &h->vel, 2, 1);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->ux, &h->acc, 2, 0);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->uy, &h->acc, 2, 1);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->rho, &h->drho, 1, 0);
  /* the stiffness limit measures u and rho in the acoustic energy's scales, u / c0 and
   * rho / rho0 (positions left out: dx/dt = u makes their stage differences those of u,
   * a ratio near dt c0 / dx whatever the stiffness) */
  if (st == RHOD_OK && h->stlim)
    st = rhod_rk_watch(&s->rk, p, &p->ux, 1 / h->c0);
  if (st == RHOD_OK && h->stlim)
    st = rhod_rk_watch(&s->rk, p, &p->uy, 1 / h->c0);
  if (st == RHOD_OK && h->stlim)
    st = rhod_rk_watch(&s->rk, p, &p->rho, 1 / h->rho0);
  if (st == RHOD_ERR_SCENE) {
    /* the stiffness limit's weights 1/c0 and 1/rho0 (rhod_rk_watch) */
    snprintf(err, errlen,
             "%s: physics.c0 = %g m/s, physics.rho0 = %g kg/m^3: 1/c0 or 1/rho0 is not a finite "
             "number in %s precision",
             sc->path, sc->rs->c0, sc->rs->rho0, RHOD_REAL_NAME);
    return st;
  }
  if (st != RHOD_OK) {
    snprintf(err, errlen, "out of memory setting up the scheme");
    return st;
  }
  s->P = &h->P;
  s->V = &h->V;
  return rhod_apr_init(&rs->apr, sc, s->dx_min);
}

/* The initial relaxation (particles.relax, rhod_sph_relax): the particles move along the
 * shifting direction for that many iterations, then each gets the exact initial fields of
 * the block it was made in, where it now stands (set_state: a particle that left its
 * block, e.g. a surface particle by a fraction of dx, takes the block's fields extended
 * there). Sizes, ids and the count are kept. */
static int relax_initial(rhod_sim *s) {
  rhod_rhodsph *rs = rhod_rs(s);
  rhod_particles *p = &s->p;
  rhod_particles_to_host(p);
  /* the block of each particle, by id (the sorts of the iterations reorder them) */
  const size_t nid = (size_t)p->next_id;
  int *blk = malloc((nid ? nid : 1) * sizeof *blk);
  if (!blk)
    return RHOD_ERR_MEMORY;
  for (size_t k = 0; k < p->n; k++)
    blk[p->id[k]] = rhod_sim_block_at(s, p->x[k], p->y[k]);
  /* particles.relax_where: jumps: the largest size present bounds the test's gather */
  real jumps_dx = 0;
  if (s->sc->rs->relax_where == RHOD_RELAX_JUMPS)
    for (size_t k = 0; k < p->n; k++)
      jumps_dx = p->dx[k] > jumps_dx ? p->dx[k] : jumps_dx;
  int st = RHOD_OK;
  for (int it = 0; it < s->sc->rs->relax && st == RHOD_OK; it++) {
    st = rhod_sph_relax(&rs->sph, p, &s->cells, jumps_dx);
    if (st != RHOD_OK)
      break;
    rhod_walls_guard(&s->bnd, p);
    st = rhod_sim_prepare(s, 1);
  }
  if (st == RHOD_OK)
    st = rhod_sim_restate(s, 0, blk);
  free(blk);
  return st;
}

/* The initial lattice refined by the criteria (rhod_sim_init). */
static int refine_initial(rhod_sim *s, char *err, size_t errlen) {
  const rhod_scene *sc = s->sc;
  rhod_rhodsph *rs = rhod_rs(s);
  rhod_particles *p = &s->p;
  int st;
  /* The initial lattice is refined by the criteria before the first step, until none
   * asks for more, so the run starts from a layout that satisfies them (paper 002
   * Sec. V B: "the initial particle setup is chosen to naturally ensure the criteria")
   * instead of splitting in cascade once it moves. A split near the surface can make
   * criterion 1 split its coarser neighbours in the next round, and so on inward, so
   * levels - 1 rounds are not always enough (the dam break still split 64, 139 and 507
   * particles in its first step at three, four and seven levels with that limit); the
   * cap of 4 levels rounds only bounds a cascade that would not settle. */
  for (int round = 1; round < 4 * sc->rs->levels; round++) {
    st = rhod_sph_rhs(&rs->sph, p, &s->cells, (real)s->dt);
    if (st == RHOD_OK)
      st = rhod_apr_mark(&rs->apr, &rs->sph, p, &s->cells, &s->bnd, 0, 0);
    const long split = st == RHOD_OK ? rhod_apr_split(&rs->apr, &rs->sph, p, &s->bnd) : -1;
    if (split < 0) {
      snprintf(err, errlen, "out of memory refining the initial particles");
      return RHOD_ERR_MEMORY;
    }
    if (split == 0)
      break;
    s->dt = rhod_sph_dt(&rs->sph, p);
    st = rhod_sim_prepare(s, 1);
    if (st != RHOD_OK)
      return st;
  }
  rs->apr.split_total = 0;
  return rhod_sim_restate(s, sc->jitter, NULL);
}

/* Before t = 0: the first dt, the initial refinement and the relaxation. */
static int rs_start(rhod_sim *s, char *err, size_t errlen) {
  rhod_rhodsph *rs = rhod_rs(s);
  s->dt = rhod_sph_dt(&rs->sph, &s->p);
  int st = RHOD_OK;
  if (rs->apr.active)
    st = refine_initial(s, err, errlen);
  if (st == RHOD_OK && s->sc->rs->relax > 0 && (st = relax_initial(s)) != RHOD_OK)
    snprintf(err, errlen, "out of memory relaxing the initial particles");
  return st;
}

static void rs_free(rhod_sim *s) {
  if (s->sch) {
    rhod_apr_free(&rhod_rs(s)->apr);
    rhod_sph_free(&rhod_rs(s)->sph);
  }
}

static void rs_ghost_state(rhod_sim *s) { rhod_sph_fill_state(&rhod_rs(s)->sph, &s->p); }

static int rs_rhs(rhod_sim *s, int stage, double t, real dt) {
  rhod_rhodsph *rs = rhod_rs(s);
  rhod_particles *p = &s->p;
  const int st = rhod_sph_rhs(&rs->sph, p, &s->cells, dt);
  if (st != RHOD_OK)
    return st;
  /* the stiffness limit (docs/choices.md): the RK4 stages' stiffness over the inner
   * particles, where the right-hand side is smooth (the free-surface region switches
   * operators and sets between stages, which the stage differences would read as a
   * stiffness of order 1/dt) */
  if (stage == 2 && rs->sph.stlim) {
    const real q = rhod_rk_stiffness(&s->rk, p, dt, rs->sph.reg);
    rs->sph.st_lambda = q < 0 ? -q : 0;
  }
  /* refinement criteria during the last stage (paper 002 Sec. V) */
  if (rs->apr.active && stage == s->rk.stages - 1) {
    /* coalescing is looked for every RHOD_COALESCE_EVERY steps: its candidate
     * test gathers over twice the support (docs/choices.md "APR coalescing") */
    const int co = s->step % RHOD_COALESCE_EVERY == 0;
    return rhod_apr_mark(&rs->apr, &rs->sph, p, &s->cells, &s->bnd, t + dt, co);
  }
  return RHOD_OK;
}

/* Eq. 11, and with the damper step limit a measurement of the damper's stiffness first
 * (rhod_sph_damper_probe; one per call). */
static int rs_dt(rhod_sim *s) {
  rhod_rhodsph *rs = rhod_rs(s);
  if (rs->sph.adlim) {
    if (!s->neighbours_fresh) {
      const int st = rhod_sim_prepare(s, 1);
      if (st != RHOD_OK)
        return st;
    }
    rs->sph.ad_lambda = rhod_sph_damper_probe(&rs->sph, &s->p, &s->cells);
  }
  s->dt = rhod_sph_dt(&rs->sph, &s->p);
  rs->damper_limited += rs->sph.dt_by == RHOD_DT_BY_DAMPER;
  rs->stiffness_limited += rs->sph.dt_by == RHOD_DT_BY_STIFFNESS;
  return RHOD_OK;
}

/* The marked particles split before the next step, which sorts them in; then coalescing. */
static int rs_end_step(rhod_sim *s) {
  rhod_rhodsph *rs = rhod_rs(s);
  rhod_particles *p = &s->p;
  if (!rs->apr.active)
    return RHOD_OK;
  if (rhod_apr_split(&rs->apr, &rs->sph, p, &s->bnd) < 0)
    return RHOD_ERR_MEMORY;
  if (rhod_apr_coalesce(&rs->apr, p) < 0)
    return RHOD_ERR_MEMORY;
  if (rs->apr.split_last > 0 || rs->apr.merged_last > 0 || rs->apr.absorbed_last > 0)
    s->dt = rhod_sph_dt(&rs->sph, p);
  return RHOD_OK;
}

/* The probes of this scheme: the elastic energy of Eq. 2's state law and the torque
 * budget of the momentum equation. out NULL: only whether the scheme has the kind. */
static int rs_probe(rhod_sim *s, const rhod_probe *pr, double *values) {
  if (pr->kind != RHOD_PROBE_ELASTIC_ENERGY && pr->kind != RHOD_PROBE_TORQUE_BUDGET)
    return RHOD_ERR_SCENE;
  if (!values)
    return RHOD_OK;
  rhod_rhodsph *rs = rhod_rs(s);
  rhod_particles *p = &s->p;
  rhod_sph *h = &rs->sph;
  const long n = (long)p->n;
  const real *m = p->m;
  const real ax = (real)pr->at[0], ay = (real)pr->at[1];
  unsigned k = 0;
  switch (pr->kind) {
  case RHOD_PROBE_ELASTIC_ENERGY: {
    /* The energy stored by compression: with the linear state law of paper 002
     * Eq. 2, P = c0^2 (rho - rho0), the work per unit mass
     * e = int_rho0^rho P / r^2 dr = c0^2 (ln(rho/rho0) + rho0/rho - 1), or with
     * q = 1 - rho0/rho, e = c0^2 (-ln(1 - q) - q) = c0^2 (q^2/2 + q^3/3 + ...). The
     * series (to q^5, relative error below q^4/3) where |q| < 0.01 avoids the
     * cancellation of the closed form in single precision. Conservative SPH without
     * the diffusive terms conserves E_k + E_e (tests). */
    const real c2 = h->c0 * h->c0, rho0 = h->rho0;
    const real *rho = p->rho;
    real e = 0;
    RHOD_KERNEL_LOOP_REDUCE(+, e)
    for (long j = 0; j < n; j++) {
      const real q = 1 - rho0 / rho[j];
      const real f =
          fabs(q) < (real)0.01
              ? q * q * ((real)0.5 + q * ((real)1 / 3 + q * ((real)0.25 + q * (real)0.2)))
              : -log1p(-q) - q;
      e += m[j] * c2 * f;
    }
    values[k++] = e;
    break;
  }
  case RHOD_PROBE_TORQUE_BUDGET: {
    /* one value per column the loader and rhod_probe_columns count for this kind */
    _Static_assert(RHOD_TQ_TERMS == RHOD_PROBE_MAX_COLUMNS, "torque_budget columns");
    double tq[RHOD_TQ_TERMS];
    if (rhod_sph_torque_budget(h, p, &s->cells, (real)s->dt, ax, ay, tq) != RHOD_OK)
      for (int a = 0; a < RHOD_TQ_TERMS; a++)
        tq[a] = NAN; /* out of memory: a column that is not finite stops the run */
    for (int a = 0; a < RHOD_TQ_TERMS; a++)
      values[k++] = tq[a];
    break;
  }
  default:
    break;
  }
  return RHOD_OK;
}

/* Pressure and free-surface flags for the prepared state: the flags of the last stage
 * belong to the particle order before the step's sort (and to the stage's positions), so
 * they are detected again here when the neighbours are fresh (pass A gives lambda, L and
 * grad Gamma). */
static void rs_output(rhod_sim *s, rhod_snapshot_view *v) {
  rhod_rhodsph *rs = rhod_rs(s);
  rhod_particles *p = &s->p;
  rhod_sph_fill_state(&rs->sph, p);
  if (s->neighbours_fresh) {
    rhod_sph_pass_a(&rs->sph, p, &s->cells);
    rhod_sph_pass_free_surface(&rs->sph, p, &s->cells);
  }
  rhod_to_host(rs->sph.P, p->n * sizeof(real));
  rhod_to_host(rs->sph.fs, p->n);
  v->p = rs->sph.P;
  v->fs = rs->sph.fs;
}

/* The fields output.fields may name: the volume (rhod_sph_fill_state above) and what
 * pass A (paper 002 Eqs. 7, 14, 5, 29, U_char after Eq. 27, lambda) and the free-surface
 * detection compute for the prepared state in rs_output (rhod_sim_fetch makes the
 * neighbours fresh for them). Not the shifting velocity nor the region pass's fields: those
 * need the region pass and dt, which the output does not run. */
static const rhod_output_field rs_outputs[] = {
    {"V", "Volumes", "m^2"},
    {"gam", "ShepardGamma", "1"},
    {"ggam", "ShepardGammaGradients", "1/m"},
    {"gP", "PressureGradients", "Pa/m"},
    {"D", "VelocityDivergences", "1/s"},
    {"gC", "ConcentrationGradients", "1/m"},
    {"uch", "CharacteristicVelocities", "m/s"},
    {"lam", "SmallestEigenvalues", "1"},
    {"nrm", "Normals", "1"},
    {NULL, NULL, NULL},
};

static int rs_stats(const rhod_sim *s, rhod_stat *out, int max) {
  const rhod_rhodsph *rs = rhod_rs(s);
  const rhod_stat st[] = {
      {"splits", (double)rs->apr.split_total, 1},
      {"merges", (double)rs->apr.merged_total, 1},
      {"absorbed", (double)rs->apr.absorbed_total, 1},
      {"merge_dissipation", rs->apr.ke_merged, 0},
      {"absorb_dissipation", rs->apr.ke_absorbed, 0},
      {"damper_limited_steps", (double)rs->damper_limited, 1},
      {"stiffness_limited_steps", (double)rs->stiffness_limited, 1},
  };
  int k = 0;
  for (; k < (int)(sizeof st / sizeof st[0]) && k < max; k++)
    out[k] = st[k];
  return k;
}

static void rs_report(const rhod_sim *s, long steps, rhod_warn_buf *w) {
  const rhod_rhodsph *rs = rhod_rs(s);
  const rhod_apr *a = &rs->apr;
  if (a->split_total || a->merged_total)
    rhod_warn(w,
              "%ld particles split by the refinement criteria and %ld groups of %d coalesced "
              "during the run (%zu particles now)",
              a->split_total, a->merged_total, a->nsplit, s->p.n);
  if (a->merged_total || a->absorbed_total)
    rhod_warn(w,
              "%ld stragglers absorbed by their coarser neighbours; the merges took %.4g J/m of "
              "kinetic energy out, the absorptions %.4g J/m",
              a->absorbed_total, a->ke_merged, a->ke_absorbed);
  if (rs->damper_limited)
    rhod_warn(w,
              "%ld of the %ld steps run here took a dt set by the acoustic damper's measured "
              "stiffness (scheme.damper_step_limit)",
              rs->damper_limited, steps);
  if (rs->stiffness_limited)
    rhod_warn(w,
              "%ld of the %ld steps run here took a dt set by the stiffness the RK4 stages "
              "measured (time.stiffness_limit)",
              rs->stiffness_limited, steps);
}

/* The scalars a resume needs, as the checkpoint's named extras: the APR totals the summary
 * reports and the stiffness limit's last measure (1/s), which sets the next dt. The names
 * are those the checkpoint reader gives the fixed fields of versions 2 to 6
 * (rhod_ck_legacy_extra), so an older checkpoint resumes as before. */
enum { RS_SPLITS, RS_MERGES, RS_STIFFNESS, RS_ABSORBED, RS_KE_MERGED, RS_KE_ABSORBED, RS_NEXTRA };
_Static_assert(RS_NEXTRA == RHOD_CK_LEGACY_EXTRAS, "RHOD-SPH's extras are the legacy fields");

static void rs_save(const rhod_sim *s, rhod_checkpoint *ck) {
  const rhod_rhodsph *rs = rhod_rs(s);
  const double v[RS_NEXTRA] = {
      [RS_SPLITS] = (double)rs->apr.split_total, [RS_MERGES] = (double)rs->apr.merged_total,
      [RS_STIFFNESS] = rs->sph.st_lambda,        [RS_ABSORBED] = (double)rs->apr.absorbed_total,
      [RS_KE_MERGED] = rs->apr.ke_merged,        [RS_KE_ABSORBED] = rs->apr.ke_absorbed};
  ck->nextra = RS_NEXTRA;
  for (int k = 0; k < RS_NEXTRA; k++) {
    snprintf(ck->extra_name[k], sizeof ck->extra_name[k], "%s", rhod_ck_legacy_extra[k]);
    ck->extra[k] = v[k];
  }
}

static int rs_load(rhod_sim *s, const rhod_checkpoint *ck, char *err, size_t errlen) {
  rhod_rhodsph *rs = rhod_rs(s);
  double v[RS_NEXTRA];
  for (int k = 0; k < RS_NEXTRA; k++) {
    const char *name = rhod_ck_legacy_extra[k];
    int i = 0;
    while (i < ck->nextra && strcmp(ck->extra_name[i], name))
      i++;
    if (i == ck->nextra) {
      snprintf(err, errlen, "the checkpoint has no %s (not an rhodsph run's?)", name);
      return RHOD_ERR_CHECKPOINT;
    }
    v[k] = ck->extra[i];
    /* counts: whole numbers >= 0 (below 2^53, exact in a double); the stiffness finite and
     * >= 0; the energies finite */
    const int count = k == RS_SPLITS || k == RS_MERGES || k == RS_ABSORBED;
    const int bad = count               ? !(v[k] >= 0 && v[k] < 0x1p53 && v[k] == floor(v[k]))
                    : k == RS_STIFFNESS ? !(v[k] >= 0 && v[k] < HUGE_VAL)
                                        : !isfinite(v[k]);
    if (bad) {
      snprintf(err, errlen, "the checkpoint's %s: %g, %s", name, v[k],
               count               ? "must be a whole number >= 0"
               : k == RS_STIFFNESS ? "must be finite and >= 0"
                                   : "not a finite number");
      return RHOD_ERR_CHECKPOINT;
    }
  }
  rs->apr.split_total = (long)v[RS_SPLITS];
  rs->apr.merged_total = (long)v[RS_MERGES];
  rs->apr.absorbed_total = (long)v[RS_ABSORBED];
  rs->apr.ke_merged = v[RS_KE_MERGED];
  rs->apr.ke_absorbed = v[RS_KE_ABSORBED];
  rs->sph.st_lambda = (real)v[RS_STIFFNESS];
  s->dt = rhod_sph_dt(&rs->sph, &s->p); /* sizes may have been split since t = 0 */
  return RHOD_OK;
}

const rhod_scheme_ops rhod_rhodsph_ops = {
    .name = "rhodsph",
    .geometry = rs_geometry,
    .fill_level = rs_fill_level,
    .fill_unjittered = rs_fill_unjittered,
    .initial_state = rs_initial_state,
    .init = rs_init,
    .start = rs_start,
    .free = rs_free,
    .ghost_state = rs_ghost_state,
    .rhs = rs_rhs,
    .dt = rs_dt,
    .end_step = rs_end_step,
    .probe = rs_probe,
    .output = rs_output,
    .outputs = rs_outputs,
    .stats = rs_stats,
    .report = rs_report,
    .save = rs_save,
    .load = rs_load,
};
