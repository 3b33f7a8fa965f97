/* The multiphase scheme of paper 000 (regular particles, one resolution; its passes in
 * kernels/multiphase/mp.c) behind the engine's scheme hooks (include/rhod/scheme.h). */
#include "rhod/multiphase/scheme.h"
#include "rhod/multiphase/scene.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One resolution: the finest size is particles.dx, and wall mirrors reach R_i. */
static int mp_geometry(const rhod_scene *sc, double *dx_min, double *mirror_reach, char *err,
                       size_t errlen) {
  (void)err, (void)errlen;
  *dx_min = sc->dx;
  *mirror_reach = 1;
  return RHOD_OK;
}

/* Particle k of block b: the block's phase and flow, the hydrostatic pressure where asked
 * (rho0 g depth of the block's phase: our choice, docs/choices.md "multiphase initial
 * state") and its ambient pressure, the density of the Tait EOS (paper 000 Eq. 3)
 * inverted, and m = rho dx^2. */
static void mp_initial_state(rhod_sim *s, unsigned b, size_t k, double x, double y, double dx) {
  const rhod_scene *sc = s->sc;
  const rhod_fluid_block *B = &sc->fluid[b];
  rhod_mp *m = rhod_mps(s);
  rhod_particles *p = &s->p;
  const int ph = B->phase;
  const double rho0 = sc->mp->phases[ph].rho0;
  double u, v, P;
  rhod_sim_initial_flow(s, b, x, y, rho0, &u, &v, &P);
  if (B->pressure == RHOD_INIT_HYDROSTATIC) {
    double g;
    const double depth = rhod_sim_block_depth(s, b, x, y, &g);
    P += rho0 * g * depth;
  }
  P += B->ambient_pressure; /* fluid.N.ambient_pressure (docs/choices.md "ambient pressure") */
  const double rho = rhod_mp_density(&m->prm, ph, (real)P);
  p->x[k] = (real)x;
  p->y[k] = (real)y;
  p->ux[k] = (real)u;
  p->uy[k] = (real)v;
  p->rho[k] = (real)rho;
  p->m[k] = (real)(rho * dx * dx);
  p->dx[k] = (real)dx;
  p->phase[k] = (uint8_t)ph;
  p->kind[k] = 0; /* regular particle (paper 000 Sec. 2) */
  p->level[k] = 0;
}

/* The kernels' parameters from the scene's phases and multiphase section. */
static void mp_params(const rhod_scene *sc, rhod_mp_params *prm) {
  const rhod_mp_scene *ms = sc->mp;
  memset(prm, 0, sizeof *prm);
  prm->nphase = (int)ms->n_phases;
  for (unsigned a = 0; a < ms->n_phases; a++) {
    const rhod_mp_phase_desc *d = &ms->phases[a];
    prm->ph[a] =
        (rhod_mp_phase){(real)d->rho0, (real)d->c, (real)d->gamma, (real)d->mu, (real)d->colour};
    for (unsigned c = 0; c < ms->n_phases; c++)
      prm->sigma[a * RHOD_MP_MAX_PHASES + c] = (real)rhod_mp_sigma(ms, a, c);
  }
  prm->kernel = sc->kernel;
  prm->ratio = (real)sc->radius_ratio;
  prm->gx = (real)sc->gravity[0];
  prm->gy = (real)sc->gravity[1];
  prm->delta = (real)ms->delta;
  prm->xi_shift = (real)ms->xi_shift;
  prm->xi_rep = (real)ms->xi_rep;
  prm->rep_n = (real)ms->rep_n;
  prm->xi_rif = (real)ms->xi_rif;
  prm->eta2 = (real)ms->eta2;
  prm->tensile = ms->tensile_control;
  prm->cfl = (real)ms->cfl;
  prm->cfl_visc = (real)ms->cfl_visc;
  prm->cfl_force = (real)ms->cfl_force;
  prm->cfl_surface = (real)ms->cfl_surface;
}

static int mp_init(rhod_sim *s, char *err, size_t errlen) {
  const rhod_scene *sc = s->sc;
  if (!sc->mp) {
    snprintf(err, errlen, "%s: phases: the multiphase scheme needs its phases", sc->path);
    return RHOD_ERR_SCENE;
  }
  rhod_mps_state *ms = calloc(1, sizeof *ms);
  if (!ms) {
    snprintf(err, errlen, "out of memory setting up the scheme");
    return RHOD_ERR_MEMORY;
  }
  s->sch = ms;
  rhod_mp_params prm;
  mp_params(sc, &prm);
  rhod_particles *p = &s->p;
  rhod_mp *m = &ms->mp;
  int st = rhod_mp_init(m, &prm, p);
  /* the open boundaries' nominal mass per phase (open.h) */
  _Static_assert(RHOD_MP_MAX_PHASES <= RHOD_SIM_PHASES, "a reference density for every phase");
  for (unsigned k = 0; k < sc->mp->n_phases && k < RHOD_SIM_PHASES; k++)
    s->rho0[k] = sc->mp->phases[k].rho0, s->c0[k] = prm.ph[k].c;
  if (st == RHOD_ERR_SCENE) {
    snprintf(err, errlen, "%s: particles.kernel: not available with the multiphase scheme",
             sc->path);
    return st;
  }
  /* paper 000 Eqs. 9-10: x moves with u + u_s, u and rho by their rates */
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->x, &m->vel, 2, 0);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->y, &m->vel, 2, 1);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->ux, &m->acc, 2, 0);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->uy, &m->acc, 2, 1);
  if (st == RHOD_OK)
    st = rhod_rk_add(&s->rk, p, &p->rho, &m->drho, 1, 0);
  if (st != RHOD_OK) {
    snprintf(err, errlen, "out of memory setting up the scheme");
    return st;
  }
  s->P = &m->P;
  s->V = &m->V;
  /* the bodies' viscous force with each particle's nu (paper 001 Eq. 6's pair coefficient) */
  for (int k = 0; k < m->prm.nphase; k++)
    if (m->prm.ph[k].mu > 0)
      s->body_nu = &m->nu;
  return RHOD_OK;
}

/* Before t = 0: every phase holds particles, and the first dt. */
static int mp_start(rhod_sim *s, char *err, size_t errlen) {
  const rhod_mp_scene *ms = s->sc->mp;
  rhod_particles *p = &s->p;
  size_t count[RHOD_MP_MAX_PHASES] = {0};
  rhod_to_host(p->phase, p->n);
  for (size_t i = 0; i < p->n; i++)
    count[p->phase[i]]++;
  for (unsigned a = 0; a < ms->n_phases; a++)
    if (count[a] == 0) {
      snprintf(err, errlen,
               "%s: phases.%u (%s): no particle of this phase: no fluid block names it, or its "
               "blocks hold no particle",
               s->sc->path, a, ms->phases[a].name);
      return RHOD_ERR_SCENE;
    }
  s->dt = rhod_mp_dt(rhod_mps(s), p);
  return RHOD_OK;
}

static void mp_free(rhod_sim *s) {
  if (s->sch)
    rhod_mp_free(rhod_mps(s));
}

static void mp_ghost_state(rhod_sim *s) { rhod_mp_fill_state(rhod_mps(s), &s->p); }

static int mp_rhs(rhod_sim *s, int stage, double t, real dt) {
  (void)t;
  rhod_mps_state *ms = rhod_mps_of(s);
  rhod_mp_rhs(&ms->mp, &s->p, &s->cells, dt);
  if (ms->mp.us_max > ms->us_max)
    ms->us_max = ms->mp.us_max;
  /* paper 001 Eq. 15 for the next step, from this last stage's accelerations while they
   * are in the particles' order */
  if (stage == s->rk.stages - 1)
    ms->mp.force_dt = rhod_mp_force_dt(&ms->mp, &s->p);
  return RHOD_OK;
}

/* paper 001 Eqs. 14-17 */
static int mp_dt(rhod_sim *s) {
  rhod_mps_state *ms = rhod_mps_of(s);
  s->dt = rhod_mp_dt(&ms->mp, &s->p);
  ms->dt_by[ms->mp.dt_by]++;
  return RHOD_OK;
}

static int mp_probe(rhod_sim *s, const rhod_probe *pr, double *values) {
  (void)s, (void)pr, (void)values;
  return RHOD_ERR_SCENE; /* every probe this scheme has is the engine's */
}

static void mp_output(rhod_sim *s, rhod_snapshot_view *v) {
  rhod_mp *m = rhod_mps(s);
  rhod_particles *p = &s->p;
  rhod_mp_fill_state(m, p);
  /* with output.fields (mp_outputs), the colour pass's fields of this state: it writes
   * only scratch that the next right-hand side computes again before reading it */
  if (s->sc->n_output_fields && m->surface && s->neighbours_fresh) {
    rhod_mp_pack(m, p, &s->cells);
    rhod_mp_pass_colour(m, p, &s->cells);
  }
  rhod_to_host(m->P, p->n * sizeof(real));
  v->p = m->P;
}

/* The fields output.fields may name: those of the equation of state (rhod_mp_fill_state)
 * and, with surface tension, the colour pass's (paper 001 Eqs. 8-9), which mp_output
 * computes. Not the curvature (Eq. 10): the main pass computes it with the accelerations,
 * which the next time step may read. */
static const rhod_output_field mp_outputs[] = {
    {"mp_V", "Volumes", "m^2"}, {"mp_nu", "KinematicViscosities", "m^2/s"},
    {"mp_col", "Colours", "1"}, {"mp_gC", "ColourGradients", "1/m"},
    {"mp_nrm", "Normals", "1"}, {"mp_sig", "SurfaceTensions", "N/m"},
    {NULL, NULL, NULL},
};

static int mp_stats(const rhod_sim *s, rhod_stat *out, int max) {
  const rhod_mps_state *ms = rhod_mps_of(s);
  const rhod_stat st[] = {
      {"max_shift_over_dx", ms->us_max, 0},
      {"dt_viscous_steps", (double)ms->dt_by[RHOD_MP_DT_VISC], 1},
      {"dt_force_steps", (double)ms->dt_by[RHOD_MP_DT_FORCE], 1},
      {"dt_sound_steps", (double)ms->dt_by[RHOD_MP_DT_SOUND], 1},
      {"dt_surface_steps", (double)ms->dt_by[RHOD_MP_DT_SURFACE], 1},
  };
  int k = 0;
  for (; k < (int)(sizeof st / sizeof st[0]) && k < max; k++)
    out[k] = st[k];
  return k;
}

static void mp_report(const rhod_sim *s, long steps, rhod_warn_buf *w) {
  const rhod_mps_state *ms = rhod_mps_of(s);
  rhod_warn(w,
            "the transport velocity moved a particle by at most %.3g of its size in a step "
            "(paper 000 Eq. 7, not capped)",
            ms->us_max);
  rhod_warn(w,
            "time step limits of the %ld steps run here (paper 001 Eqs. 14-17): viscous %ld, "
            "force %ld, sound %ld, surface tension %ld",
            steps, ms->dt_by[RHOD_MP_DT_VISC], ms->dt_by[RHOD_MP_DT_FORCE],
            ms->dt_by[RHOD_MP_DT_SOUND], ms->dt_by[RHOD_MP_DT_SURFACE]);
}

/* The scalars a resume needs to go on bit for bit: Eq. 15's limit from the last step's
 * accelerations (scratch, not in the checkpoint's fields) and the run's largest shift. */
static void mp_save(const rhod_sim *s, rhod_checkpoint *ck) {
  const rhod_mps_state *ms = rhod_mps_of(s);
  ck->nextra = 2;
  snprintf(ck->extra_name[0], sizeof ck->extra_name[0], "force_dt");
  ck->extra[0] = ms->mp.force_dt;
  snprintf(ck->extra_name[1], sizeof ck->extra_name[1], "max_shift_over_dx");
  ck->extra[1] = ms->us_max;
}

static int mp_load(rhod_sim *s, const rhod_checkpoint *ck, char *err, size_t errlen) {
  rhod_mps_state *ms = rhod_mps_of(s);
  const char *want[2] = {"force_dt", "max_shift_over_dx"};
  for (int k = 0; k < 2; k++) {
    int i = 0;
    while (i < ck->nextra && strcmp(ck->extra_name[i], want[k]))
      i++;
    if (i == ck->nextra || !(ck->extra[i] >= 0 && ck->extra[i] < HUGE_VAL)) {
      snprintf(err, errlen, "the checkpoint has no valid %s (not a multiphase run's?)", want[k]);
      return RHOD_ERR_CHECKPOINT;
    }
    if (k == 0)
      ms->mp.force_dt = (real)ck->extra[i];
    else
      ms->us_max = ck->extra[i];
  }
  s->dt = rhod_mp_dt(&ms->mp, &s->p);
  return RHOD_OK;
}

const rhod_scheme_ops rhod_multiphase_ops = {
    .name = "multiphase",
    .geometry = mp_geometry,
    .initial_state = mp_initial_state,
    .init = mp_init,
    .start = mp_start,
    .free = mp_free,
    .ghost_state = mp_ghost_state,
    .rhs = mp_rhs,
    .dt = mp_dt,
    .end_step = NULL,
    .probe = mp_probe,
    .output = mp_output,
    .outputs = mp_outputs,
    .stats = mp_stats,
    .report = mp_report,
    .save = mp_save,
    .load = mp_load,
};
