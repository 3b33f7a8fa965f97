/* The multiphase scheme's sections of a scene (paper 000, Buerkle et al. 2025; paper 001,
 * Wicker et al.): `phases` and `multiphase`, their schema, value checks, defaults and
 * their part of the scene as run. The mechanism (schema validation, messages, `--set`,
 * the scene as run) is src/scene.c's; every key is documented in docs/scene.md. */
#define _POSIX_C_SOURCE 200809L

#include "scene_mp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- schema --------------------------------------------------------------------------- */

#define OPT (CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL)
#define NUM(key, st, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_STRICT, st, member)
#define NUM_OPT(key, st, member) CYAML_FIELD_FLOAT_PTR(key, OPT | CYAML_FLAG_STRICT, st, member)
#define MP_NAME_MAX 64

static const cyaml_schema_value_t sch_name = {
    CYAML_VALUE_STRING(CYAML_FLAG_POINTER, char, 1, MP_NAME_MAX)};

static const cyaml_schema_field_t f_phase[] = {
    CYAML_FIELD_STRING_PTR("name", CYAML_FLAG_POINTER, y_mp_phase, name, 1, MP_NAME_MAX),
    NUM("rho0", y_mp_phase, rho0),
    NUM("c", y_mp_phase, c),
    NUM_OPT("gamma", y_mp_phase, gamma),
    NUM_OPT("mu", y_mp_phase, mu),
    NUM_OPT("colour", y_mp_phase, colour),
    CYAML_FIELD_END,
};
const cyaml_schema_value_t rhod_mp_sch_phase = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_mp_phase, f_phase)};

static const cyaml_schema_field_t f_pair[] = {
    CYAML_FIELD_SEQUENCE_FIXED("phases", CYAML_FLAG_FLOW, y_mp_pair, phases, &sch_name, 2),
    NUM("sigma", y_mp_pair, sigma),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t sch_pair = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_mp_pair, f_pair)};

const cyaml_schema_field_t rhod_mp_f_section[] = {
    NUM_OPT("sigma", y_mp_section, sigma),
    CYAML_FIELD_SEQUENCE_COUNT("sigma_pairs", OPT, y_mp_section, sigma_pairs, n_sigma_pairs,
                               &sch_pair, 0, CYAML_UNLIMITED),
    NUM_OPT("delta", y_mp_section, delta),
    NUM_OPT("shifting", y_mp_section, shifting),
    NUM_OPT("repulsion", y_mp_section, repulsion),
    NUM_OPT("repulsion_power", y_mp_section, repulsion_power),
    NUM_OPT("interface_force", y_mp_section, interface_force),
    NUM_OPT("viscosity_eta", y_mp_section, viscosity_eta),
    CYAML_FIELD_BOOL_PTR("tensile_control", OPT, y_mp_section, tensile_control),
    NUM_OPT("cfl", y_mp_section, cfl),
    NUM_OPT("cfl_visc", y_mp_section, cfl_visc),
    NUM_OPT("cfl_force", y_mp_section, cfl_force),
    NUM_OPT("cfl_surface", y_mp_section, cfl_surface),
    CYAML_FIELD_END,
};

/* ---- checks and defaults ---------------------------------------------------------------- */

int rhod_mp_phase_index(const rhod_mp_scene *mp, const char *name) {
  for (unsigned k = 0; mp && name && k < mp->n_phases; k++)
    if (strcmp(mp->phases[k].name, name) == 0)
      return (int)k;
  return -1;
}

void rhod_mp_scene_free(rhod_mp_scene *mp) {
  if (!mp)
    return;
  for (unsigned k = 0; mp->phases && k < mp->n_phases; k++)
    free(mp->phases[k].name);
  free(mp->phases);
  free(mp->sigma);
  free(mp);
}

/* "water, air": the phase names, for messages */
static void phase_list(const rhod_mp_scene *mp, char *buf, size_t len) {
  size_t used = 0;
  buf[0] = '\0';
  for (unsigned k = 0; k < mp->n_phases && used < len; k++)
    used += (size_t)snprintf(buf + used, len - used, "%s%s", k ? ", " : "", mp->phases[k].name);
}

/* A coefficient with its lower bound: >= lo (lo_open 0) or > lo (lo_open 1). */
static int check_low(lctx *c, const char *path, double v, double lo, int lo_open) {
  if (lo_open ? v > lo : v >= lo)
    return RHOD_OK;
  return rhod_sl_fail(c, path, "must be %s %g, got %g", lo_open ? ">" : ">=", lo, v);
}

static int load_phases(lctx *c, const y_mp_phase *y, unsigned n, rhod_mp_scene *mp) {
  char path[96];
  if (!y || n == 0)
    return rhod_sl_fail_missing(c, "", "phases", "the multiphase scheme needs at least one phase");
  mp->phases = calloc(n, sizeof *mp->phases);
  if (!mp->phases)
    return rhod_sl_fail_oom(c);
  mp->n_phases = n;
  for (unsigned k = 0; k < n; k++) {
    rhod_mp_phase_desc *ph = &mp->phases[k];
    snprintf(path, sizeof path, "phases.%u.name", k);
    if (!rhod_sl_identifier(y[k].name))
      return rhod_sl_fail(c, path,
                          "'%s' is not an identifier (a letter or '_', then letters, digits "
                          "or '_')",
                          y[k].name);
    for (unsigned j = 0; j < k; j++)
      if (strcmp(mp->phases[j].name, y[k].name) == 0)
        return rhod_sl_fail(c, path, "duplicate phase name '%s' (also phases.%u)", y[k].name, j);
    ph->name = strdup(y[k].name);
    if (!ph->name)
      return rhod_sl_fail_oom(c);
    /* paper 000 Eq. 3 (= paper 001 Eq. 1) */
    ph->rho0 = y[k].rho0;
    ph->c = y[k].c;
    ph->gamma = opt(y[k].gamma, 7);
    ph->mu = opt(y[k].mu, 0);
    ph->colour = opt(y[k].colour, k == 0 ? 1 : 0);
    snprintf(path, sizeof path, "phases.%u.rho0", k);
    TRY(check_low(c, path, ph->rho0, 0, 1));
    snprintf(path, sizeof path, "phases.%u.c", k);
    TRY(check_low(c, path, ph->c, 0, 1));
    snprintf(path, sizeof path, "phases.%u.gamma", k);
    TRY(check_low(c, path, ph->gamma, 0, 1));
    snprintf(path, sizeof path, "phases.%u.mu", k);
    TRY(check_low(c, path, ph->mu, 0, 0));
    snprintf(path, sizeof path, "phases.%u.colour", k);
    if (!(ph->colour == 0 || ph->colour == 1))
      return rhod_sl_fail(c, path, "must be 1 (liquid) or 0 (gas), got %g", ph->colour);
  }
  return RHOD_OK;
}

/* sigma of every pair of distinct phases, then the pairs that override it */
static int load_sigma(lctx *c, const y_mp_section *sec, rhod_mp_scene *mp) {
  const unsigned n = mp->n_phases;
  mp->sigma = calloc((size_t)n * n, sizeof *mp->sigma);
  if (!mp->sigma)
    return rhod_sl_fail_oom(c);
  const double sigma = opt(sec ? sec->sigma : NULL, 0);
  if (sec && sec->sigma) {
    TRY(check_low(c, "multiphase.sigma", sigma, 0, 0));
    if (n < 2)
      return rhod_sl_fail(c, "multiphase.sigma",
                          "a surface tension needs at least two phases, phases has %u", n);
  }
  for (unsigned a = 0; a < n; a++)
    for (unsigned b = 0; b < n; b++)
      mp->sigma[a * n + b] = a == b ? 0 : sigma;
  const unsigned np = sec ? sec->n_sigma_pairs : 0;
  if (np && n < 2)
    return rhod_sl_fail(c, "multiphase.sigma_pairs",
                        "a surface tension needs at least two phases, phases has %u", n);
  /* pairs already given, as a bit per (a, b) with a < b: at most 8 phases, 28 pairs */
  unsigned long long seen = 0;
  for (unsigned k = 0; k < np; k++) {
    const y_mp_pair *pr = &sec->sigma_pairs[k];
    char path[96], names[RHOD_MP_MAX_PHASES * (MP_NAME_MAX + 2) + 1];
    int idx[2];
    for (int e = 0; e < 2; e++) {
      idx[e] = rhod_mp_phase_index(mp, pr->phases[e]);
      if (idx[e] < 0) {
        snprintf(path, sizeof path, "multiphase.sigma_pairs.%u.phases.%d", k, e);
        phase_list(mp, names, sizeof names);
        return rhod_sl_fail(c, path, "unknown phase '%s' (phases: %s)", pr->phases[e], names);
      }
    }
    snprintf(path, sizeof path, "multiphase.sigma_pairs.%u.phases", k);
    if (idx[0] == idx[1])
      return rhod_sl_fail(c, path, "names phase '%s' twice: a pair is two distinct phases",
                          pr->phases[0]);
    const unsigned lo = (unsigned)(idx[0] < idx[1] ? idx[0] : idx[1]);
    const unsigned hi = (unsigned)(idx[0] < idx[1] ? idx[1] : idx[0]);
    const unsigned long long bit = 1ull << (lo * RHOD_MP_MAX_PHASES + hi);
    if (seen & bit)
      return rhod_sl_fail(c, path, "the pair %s, %s is given twice", pr->phases[0], pr->phases[1]);
    seen |= bit;
    snprintf(path, sizeof path, "multiphase.sigma_pairs.%u.sigma", k);
    TRY(check_low(c, path, pr->sigma, 0, 0));
    mp->sigma[lo * n + hi] = mp->sigma[hi * n + lo] = pr->sigma;
  }
  return RHOD_OK;
}

int rhod_mp_load(lctx *c, const y_mp_phase *phases, unsigned n_phases, const y_mp_section *sec,
                 rhod_scene *s) {
  rhod_mp_scene *mp = calloc(1, sizeof *mp);
  if (!mp)
    return rhod_sl_fail_oom(c);
  s->mp = mp;
  TRY(load_phases(c, phases, n_phases, mp));
  TRY(load_sigma(c, sec, mp));
  static const y_mp_section none = {0};
  if (!sec)
    sec = &none;
  /* paper 000 Eq. 1 */
  mp->delta = opt(sec->delta, 0.1);
  TRY(check_low(c, "multiphase.delta", mp->delta, 0, 0));
  /* paper 000 Eqs. 4-7: xi_Shift, xi_Rep, n, xi_RIF */
  mp->xi_shift = opt(sec->shifting, 0.5);
  mp->xi_rep = opt(sec->repulsion, 0.1);
  mp->rep_n = opt(sec->repulsion_power, 2);
  mp->xi_rif = opt(sec->interface_force, 0.01);
  TRY(check_low(c, "multiphase.shifting", mp->xi_shift, 0, 0));
  TRY(check_low(c, "multiphase.repulsion", mp->xi_rep, 0, 0));
  TRY(check_low(c, "multiphase.repulsion_power", mp->rep_n, 0, 1));
  TRY(check_low(c, "multiphase.interface_force", mp->xi_rif, 0, 0));
  /* paper 001 Eq. 6: eta^2 = viscosity_eta h^2 (printed "eta = 0.01/h", a TYPO) */
  mp->eta2 = opt(sec->viscosity_eta, 0.01);
  TRY(check_low(c, "multiphase.viscosity_eta", mp->eta2, 0, 1));
  /* paper 001 Eq. 5 */
  mp->tensile_control = sec->tensile_control ? *sec->tensile_control : 1;
  /* paper 001 Eqs. 14-17 */
  mp->cfl = opt(sec->cfl, 0.25);
  mp->cfl_visc = opt(sec->cfl_visc, 0.125);
  mp->cfl_force = opt(sec->cfl_force, 0.25);
  mp->cfl_surface = opt(sec->cfl_surface, 0.25);
  if (!(mp->cfl > 0 && mp->cfl <= 1))
    return rhod_sl_fail(c, "multiphase.cfl", "must be in (0, 1], got %g", mp->cfl);
  TRY(check_low(c, "multiphase.cfl_visc", mp->cfl_visc, 0, 1));
  TRY(check_low(c, "multiphase.cfl_force", mp->cfl_force, 0, 1));
  TRY(check_low(c, "multiphase.cfl_surface", mp->cfl_surface, 0, 1));
  return RHOD_OK;
}

int rhod_mp_fluid_phase(lctx *c, const rhod_scene *s, unsigned block, const char *phase,
                        int *index) {
  char path[64], names[RHOD_MP_MAX_PHASES * (MP_NAME_MAX + 2) + 1];
  phase_list(s->mp, names, sizeof names);
  if (!phase) {
    snprintf(path, sizeof path, "fluid.%u", block);
    return rhod_sl_fail(
        c, path, "no phase: a block of a multiphase scene names its phase (one of %s)", names);
  }
  *index = rhod_mp_phase_index(s->mp, phase);
  if (*index < 0) {
    snprintf(path, sizeof path, "fluid.%u.phase", block);
    return rhod_sl_fail(c, path, "unknown phase '%s' (phases: %s)", phase, names);
  }
  return RHOD_OK;
}

/* ---- the scene as run ------------------------------------------------------------------- */

void rhod_mp_tree(rhod_sl_tb *t, ry_node *root, const rhod_mp_scene *mp) {
  if (!mp)
    return;
  ry_node *list = rhod_sl_coll(t, root, "phases", RY_SEQ, 0);
  for (unsigned k = 0; k < mp->n_phases; k++) {
    const rhod_mp_phase_desc *ph = &mp->phases[k];
    ry_node *e = rhod_sl_coll(t, list, NULL, RY_MAP, 1);
    rhod_sl_word(t, e, "name", ph->name);
    rhod_sl_num(t, e, "rho0", ph->rho0);
    rhod_sl_num(t, e, "c", ph->c);
    rhod_sl_num(t, e, "gamma", ph->gamma);
    rhod_sl_num(t, e, "mu", ph->mu);
    rhod_sl_num(t, e, "colour", ph->colour);
  }
  ry_node *m = rhod_sl_coll(t, root, "multiphase", RY_MAP, 0);
  const unsigned n = mp->n_phases;
  /* sigma: the value most pairs share (the first pair's) and the others as pairs, so
   * that the scene loads back to the same matrix */
  if (n >= 2) {
    const double common = mp->sigma[0 * n + 1];
    rhod_sl_num(t, m, "sigma", common);
    ry_node *pairs = NULL;
    for (unsigned a = 0; a < n; a++)
      for (unsigned b = a + 1; b < n; b++) {
        if (mp->sigma[a * n + b] == common)
          continue;
        if (!pairs)
          pairs = rhod_sl_coll(t, m, "sigma_pairs", RY_SEQ, 0);
        ry_node *e = rhod_sl_coll(t, pairs, NULL, RY_MAP, 1);
        ry_node *names = rhod_sl_coll(t, e, "phases", RY_SEQ, 1);
        rhod_sl_word(t, names, NULL, mp->phases[a].name);
        rhod_sl_word(t, names, NULL, mp->phases[b].name);
        rhod_sl_num(t, e, "sigma", mp->sigma[a * n + b]);
      }
  }
  rhod_sl_num(t, m, "delta", mp->delta);
  rhod_sl_num(t, m, "shifting", mp->xi_shift);
  rhod_sl_num(t, m, "repulsion", mp->xi_rep);
  rhod_sl_num(t, m, "repulsion_power", mp->rep_n);
  rhod_sl_num(t, m, "interface_force", mp->xi_rif);
  rhod_sl_num(t, m, "viscosity_eta", mp->eta2);
  rhod_sl_bool(t, m, "tensile_control", mp->tensile_control);
  rhod_sl_num(t, m, "cfl", mp->cfl);
  rhod_sl_num(t, m, "cfl_visc", mp->cfl_visc);
  rhod_sl_num(t, m, "cfl_force", mp->cfl_force);
  rhod_sl_num(t, m, "cfl_surface", mp->cfl_surface);
}
