/* The RHOD-SPH scheme's keys of a scene (paper 002, Michel et al. 2025): the scheme's
 * switches, adaptive particle refinement, its fluid's physics, the initial relaxation and
 * its time step; their schema, value checks, defaults and their part of the scene as run.
 * The mechanism (schema validation, messages, `--set`, the scene as run) is src/scene.c's;
 * every key is documented in docs/scene.md. */
#define _POSIX_C_SOURCE 200809L

#include "scene_rs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- schema --------------------------------------------------------------------------- */

const cyaml_strval_t rhod_rs_relax_where_names[2] = {
    {"all", RHOD_RELAX_ALL},
    {"jumps", RHOD_RELAX_JUMPS},
};
const cyaml_strval_t rhod_rs_shifting_switch_names[5] = {
    {"false", RHOD_SHSW_NONE},
    {"momentum", RHOD_SHSW_MOMENTUM},
    {"true", RHOD_SHSW_ALL},
    {"balanced", RHOD_SHSW_BALANCED},
    {"balanced_momentum", RHOD_SHSW_BALANCED_MOMENTUM},
};
const cyaml_strval_t rhod_rs_viscosity_names[2] = {
    {"monaghan", RHOD_VISCOSITY_MONAGHAN},
    {"consistent", RHOD_VISCOSITY_CONSISTENT},
};
static const cyaml_strval_t pattern_names[] = {
    {"square", RHOD_PATTERN_SQUARE},
    {"triangle", RHOD_PATTERN_TRIANGLE},
};
static const cyaml_strval_t quantity_names[] = {
    {"pressure", RHOD_QTY_PRESSURE},
    {"dynamic_pressure", RHOD_QTY_DYNAMIC_PRESSURE},
    {"hydrodynamic_pressure", RHOD_QTY_HYDRODYNAMIC_PRESSURE},
};

static const cyaml_schema_field_t f_region[] = {
    RHOD_SL_SHAPE_FIELDS(y_rs_region),
    CYAML_FIELD_FLOAT("level", CYAML_FLAG_STRICT, y_rs_region, level),
    RHOD_RS_BOOL_("hold", y_rs_region, hold),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t sch_region = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, y_rs_region, f_region)};

static const cyaml_schema_field_t f_refine_field[] = {
    CYAML_FIELD_ENUM("quantity", CYAML_FLAG_STRICT, y_rs_refine_field, quantity, quantity_names,
                     CYAML_ARRAY_LEN(quantity_names)),
    RHOD_RS_NUM_("above", y_rs_refine_field, above),
    RHOD_RS_NUM_("below", y_rs_refine_field, below),
    RHOD_RS_NUM_("from", y_rs_refine_field, from),
    CYAML_FIELD_SEQUENCE_FIXED("x0", RHOD_RS_OPT_ | CYAML_FLAG_FLOW, y_rs_refine_field, x0,
                               &rhod_sl_sch_float, 2),
    CYAML_FIELD_END,
};

const cyaml_schema_field_t rhod_rs_f_refinement[] = {
    RHOD_RS_NUM_("levels", y_rs_refinement, levels),
    RHOD_RS_ENUM_("pattern", y_rs_refinement, pattern, pattern_names),
    CYAML_FIELD_SEQUENCE_COUNT("regions", RHOD_RS_OPT_, y_rs_refinement, regions, n_regions,
                               &sch_region, 0, CYAML_UNLIMITED),
    RHOD_RS_BOOL_("dynamic", y_rs_refinement, dynamic),
    RHOD_RS_BOOL_("free_surface", y_rs_refinement, free_surface),
    RHOD_RS_NUM_("surface_band", y_rs_refinement, surface_band),
    RHOD_RS_NUM_("crowding", y_rs_refinement, crowding),
    RHOD_RS_BOOL_("walls", y_rs_refinement, walls),
    RHOD_RS_BOOL_("coalesce", y_rs_refinement, coalesce),
    RHOD_RS_BOOL_("absorb", y_rs_refinement, absorb),
    CYAML_FIELD_MAPPING_PTR("field", RHOD_RS_OPT_ | CYAML_FLAG_FLOW, y_rs_refinement, field,
                            f_refine_field),
    CYAML_FIELD_END,
};

/* Keys of the rhodsph scheme (paper 002) that a multiphase scene refuses: the scheme's
 * switches, refinement (APR), its single fluid's state law and viscosity, the initial
 * relaxation, and its time step (Eq. 11 and the RK4 stiffness limit; the multiphase
 * scheme has multiphase.cfl*). */
int rhod_rs_owns(const char *section, const char *key) {
  if (strcmp(section, "scheme") == 0)
    return strcmp(key, "name") != 0;
  if (strcmp(section, "refinement") == 0)
    return 1;
  if (strcmp(section, "physics") == 0)
    return strcmp(key, "rho0") == 0 || strcmp(key, "c0") == 0 || strcmp(key, "mu") == 0;
  if (strcmp(section, "particles") == 0)
    return strncmp(key, "relax", 5) == 0;
  if (strcmp(section, "time") == 0)
    return strcmp(key, "stiffness_limit") == 0 || strcmp(key, "cfl") == 0 ||
           strcmp(key, "cfl_visc") == 0;
  return 0;
}

/* ---- checks and defaults ---------------------------------------------------------------- */

void rhod_rs_scene_free(rhod_rs_scene *rs) {
  if (!rs)
    return;
  for (unsigned i = 0; i < rs->n_regions; i++)
    free(rs->regions[i].shape.points);
  free(rs->regions);
  free(rs);
}

static int check_positive(lctx *c, const char *path, double v) {
  return v > 0 ? RHOD_OK : rhod_sl_fail(c, path, "must be > 0, got %g", v);
}

static int check_range(lctx *c, const char *path, double v, double lo, int lo_open, double hi,
                       int hi_open) {
  int ok = (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  if (ok)
    return RHOD_OK;
  return rhod_sl_fail(c, path, "must be in %s%g, %g%s, got %g", lo_open ? "(" : "[", lo, hi,
                      hi_open ? ")" : "]", v);
}

int rhod_rs_load_time(lctx *c, const y_rs_time *y, rhod_scene *s) {
  rhod_rs_scene *rs = calloc(1, sizeof *rs);
  if (!rs)
    return rhod_sl_fail_oom(c);
  s->rs = rs;
  /* Eq. 11: CFL_h and CFL_mu */
  rs->cfl = opt(y->cfl, 0.5);
  rs->cfl_visc = opt(y->cfl_visc, 0.025);
  rs->stiffness_limit = opt_bool(y->stiffness_limit, 1);
  TRY(check_range(c, "time.cfl", rs->cfl, 0, 1, 1, 0));
  TRY(check_positive(c, "time.cfl_visc", rs->cfl_visc));
  return RHOD_OK;
}

int rhod_rs_load_particles(lctx *c, const y_rs_particles *y, rhod_scene *s) {
  rhod_rs_scene *rs = s->rs;
  const double relax = opt(y->relax, 0);
  if (!(relax >= 0 && relax <= RHOD_RELAX_MAX && relax == floor(relax)))
    return rhod_sl_fail(c, "particles.relax", "must be a whole number in [0, %d], got %g",
                        RHOD_RELAX_MAX, relax);
  rs->relax = (int)relax;
  rs->relax_where = y->relax_where ? (rhod_relax_where)*y->relax_where : RHOD_RELAX_ALL;
  if (y->relax_where && rs->relax == 0)
    return rhod_sl_fail(c, "particles.relax_where", "needs particles.relax (iterations) above 0");
  return RHOD_OK;
}

int rhod_rs_load_physics(lctx *c, const y_rs_physics *y, rhod_scene *s) {
  rhod_rs_scene *rs = s->rs;
  if (!rhod_sl_given(c, "physics"))
    return rhod_sl_fail_missing(c, "", "physics", NULL);
  if (!y->c0)
    return rhod_sl_fail_missing(c, "physics", "c0", NULL);
  /* Eq. 2: rho0, c0; Eq. 10: mu */
  rs->rho0 = opt(y->rho0, 1000);
  rs->c0 = *y->c0;
  rs->mu = opt(y->mu, 0);
  TRY(check_positive(c, "physics.rho0", rs->rho0));
  TRY(check_positive(c, "physics.c0", rs->c0));
  if (!(rs->mu >= 0))
    return rhod_sl_fail(c, "physics.mu", "must be >= 0, got %g", rs->mu);
  return RHOD_OK;
}

int rhod_rs_load_scheme(lctx *c, const y_rs_scheme *sc, rhod_scene *s) {
  rhod_rs_scene *rs = s->rs;
  static const y_rs_scheme none = {0};
  if (!sc)
    sc = &none;
  /* paper 002 Sec. IV A: Eqs. 23-24 (riemann), 13-16 (reconstruction), 25-29 (shifting),
   * 9 (acoustic damper), 6 (free surface, Shepard threshold) */
  rs->riemann = opt_bool(sc->riemann, 1);
  rs->reconstruction = opt_bool(sc->reconstruction, 1);
  rs->shifting = opt_bool(sc->shifting, 1);
  rs->shift_a = opt(sc->shifting_a, 0.5);
  rs->shift_b = opt(sc->shifting_b, 0.05);
  rs->shift_eps = opt(sc->shifting_eps, 5e-4);
  rs->acoustic_damper = opt_bool(sc->acoustic_damper, 1);
  rs->alpha_ad = opt(sc->alpha_ad, 1);
  rs->damper_step_limit = opt_bool(sc->damper_step_limit, 1);
  rs->tensile_control = opt_bool(sc->tensile_control, 0);
  rs->shifting_switch =
      sc->shifting_switch ? (rhod_shifting_switch)*sc->shifting_switch : RHOD_SHSW_NONE;
  rs->free_surface = opt_bool(sc->free_surface, 1);
  rs->fs_lambda_low = sc->free_surface_lambda ? sc->free_surface_lambda[0] : 0.2;
  rs->fs_lambda_high = sc->free_surface_lambda ? sc->free_surface_lambda[1] : 0.75;
  rs->shepard_threshold = opt(sc->shepard_threshold, 0.85);
  rs->theta_threshold = opt(sc->theta_threshold, 0.95);
  rs->viscosity = sc->viscosity ? (rhod_viscosity)*sc->viscosity : RHOD_VISCOSITY_MONAGHAN;
  TRY(check_positive(c, "scheme.shifting_a", rs->shift_a));
  if (!(rs->shift_b >= 0))
    return rhod_sl_fail(c, "scheme.shifting_b", "must be >= 0, got %g", rs->shift_b);
  TRY(check_positive(c, "scheme.shifting_eps", rs->shift_eps));
  TRY(check_positive(c, "scheme.alpha_ad", rs->alpha_ad));
  for (int i = 0; i < 2; i++) {
    double v = i ? rs->fs_lambda_high : rs->fs_lambda_low;
    if (!(v > 0 && v < 1.5))
      return rhod_sl_fail(c, "scheme.free_surface_lambda",
                          "%s threshold must be in (0, 1.5), got %g", i ? "high" : "low", v);
  }
  if (!(rs->fs_lambda_low < rs->fs_lambda_high))
    return rhod_sl_fail(c, "scheme.free_surface_lambda", "low (%g) must be below high (%g)",
                        rs->fs_lambda_low, rs->fs_lambda_high);
  TRY(check_range(c, "scheme.shepard_threshold", rs->shepard_threshold, 0, 1, 1, 0));
  TRY(check_range(c, "scheme.theta_threshold", rs->theta_threshold, 0, 1, 1, 0));
  return RHOD_OK;
}

/* refinement: levels, initial regions and the switchable criteria of Sec. V B. */
int rhod_rs_load_refinement(lctx *c, const y_rs_refinement *r, rhod_scene *s) {
  rhod_rs_scene *rs = s->rs;
  char path[128];
  const double levels = r && r->levels ? *r->levels : 1;
  if (!(levels >= 1 && levels <= RHOD_MAX_LEVELS && levels == floor(levels)))
    return rhod_sl_fail(c, "refinement.levels", "must be a whole number in [1, %d], got %g",
                        RHOD_MAX_LEVELS, levels);
  rs->levels = (int)levels;
  rs->pattern = r && r->pattern ? (rhod_pattern)*r->pattern : RHOD_PATTERN_SQUARE;
  rs->refine_dynamic = rs->levels > 1 && opt_bool(r ? r->dynamic : NULL, 1);
  rs->refine_free_surface = opt_bool(r ? r->free_surface : NULL, 0);
  /* criterion 3's reach, no lower than 1/e (e the size ratio of adjacent levels): a
   * free-surface particle's support then holds only the finest size */
  rs->refine_band = opt(r ? r->surface_band : NULL, 1);
  const double band_min = 1 / rhod_pattern_ratio(rs->pattern);
  if (!(rs->refine_band >= band_min * (1 - 1e-12) && rs->refine_band <= 1))
    return rhod_sl_fail(c, "refinement.surface_band",
                        "must be in [%.4g, 1] (a fraction of the particle's support radius, at "
                        "least 1 over the size ratio of adjacent levels), got %g",
                        band_min, rs->refine_band);
  if (r && r->surface_band && !rs->refine_free_surface)
    return rhod_sl_fail(c, "refinement.surface_band",
                        "needs criterion 3 (refinement.free_surface: true)");
  /* our criterion against a finer particle inside a coarser one's share of the plane
   * (docs/choices.md "crowding at size jumps"): a fraction of the mean of the two sizes */
  rs->refine_crowding = opt(r ? r->crowding : NULL, RHOD_CROWDING_DEFAULT);
  if (!(rs->refine_crowding >= 0 && rs->refine_crowding < 1))
    return rhod_sl_fail(c, "refinement.crowding",
                        "must be in [0, 1) (a fraction of the mean of the two particles' sizes; "
                        "0: off), got %g",
                        rs->refine_crowding);
  rs->refine_walls = opt_bool(r ? r->walls : NULL, 0);
  rs->refine_coalesce = opt_bool(r ? r->coalesce : NULL, 0);
  rs->refine_absorb = rs->refine_coalesce && opt_bool(r ? r->absorb : NULL, 1);
  if (r && r->absorb && !rs->refine_coalesce)
    return rhod_sl_fail(c, "refinement.absorb",
                        "needs refinement.coalesce: true (it is the coalescing's absorption of "
                        "stragglers)");
  if (r && r->n_regions && rs->pattern != RHOD_PATTERN_SQUARE)
    return rhod_sl_fail(c, "refinement.regions",
                        "need refinement.pattern: square (initial levels are nested lattices, "
                        "halved in each region); with triangle the criteria refine at t = 0");
  if (r && r->n_regions) {
    rs->regions = calloc(r->n_regions, sizeof *rs->regions);
    if (!rs->regions)
      return rhod_sl_fail_oom(c);
    rs->n_regions = r->n_regions;
  }
  for (unsigned i = 0; i < rs->n_regions; i++) {
    const y_rs_region *y = &r->regions[i];
    snprintf(path, sizeof path, "refinement.regions.%u", i);
    TRY(rhod_sl_load_shape(c, path, y->rect, y->circle, y->polygon, y->n_polygon,
                           &rs->regions[i].shape));
    snprintf(path, sizeof path, "refinement.regions.%u.level", i);
    if (!(y->level >= 1 && y->level <= rs->levels - 1 && y->level == floor(y->level)))
      return rhod_sl_fail(c, path,
                          "must be a whole number in [1, refinement.levels - 1 = %d] (level 0 "
                          "is particles.dx), got %g",
                          rs->levels - 1, y->level);
    rs->regions[i].level = (int)y->level;
    rs->regions[i].hold = opt_bool(y->hold, 0);
    if (rs->regions[i].hold && !rs->refine_dynamic) {
      snprintf(path, sizeof path, "refinement.regions.%u.hold", i);
      return rhod_sl_fail(c, path,
                          "needs dynamic refinement (refinement.dynamic: true): a held region "
                          "is kept at its level by splitting during the run");
    }
  }
  const y_rs_refine_field *f = r ? r->field : NULL;
  if (f) {
    if (!f->above && !f->below)
      return rhod_sl_fail(c, "refinement.field", "needs a threshold: above, below or both");
    rs->refine_field = 1;
    rs->field_quantity = (rhod_quantity)f->quantity;
    rs->field_above = f->above ? *f->above : HUGE_VAL;
    rs->field_below = f->below ? *f->below : -HUGE_VAL;
    rs->field_from = opt(f->from, 0);
    const int hyd = rs->field_quantity == RHOD_QTY_HYDRODYNAMIC_PRESSURE;
    if (hyd != (f->x0 != NULL))
      return rhod_sl_fail(c, hyd ? "refinement.field" : "refinement.field.x0",
                          hyd ? "quantity hydrodynamic_pressure needs x0, the reference "
                                "point of the free surface (P - rho0 g.(x - x0))"
                              : "is the reference point of quantity hydrodynamic_pressure only");
    for (int d = 0; d < 2; d++)
      rs->field_x0[d] = hyd ? f->x0[d] : 0;
    if (f->above && f->below && !(rs->field_below < rs->field_above))
      return rhod_sl_fail(c, "refinement.field.below",
                          "(%g) must be below refinement.field.above (%g)", rs->field_below,
                          rs->field_above);
  }
  if (rs->refine_free_surface && !rs->free_surface)
    return rhod_sl_fail(c, "refinement.free_surface",
                        "criterion 3 needs the free-surface detection (scheme.free_surface: "
                        "true)");
  if (rs->refine_coalesce && !rs->refine_dynamic)
    return rhod_sl_fail(c, "refinement.coalesce",
                        "needs dynamic refinement (refinement.dynamic: true and levels >= 2)");
  const int any = rs->refine_free_surface || rs->refine_walls || rs->refine_field;
  if (rs->levels == 1 && (any || rs->n_regions))
    return rhod_sl_fail(c, "refinement.levels",
                        "is 1 (single resolution): regions and criteria need at least 2 levels");
  return RHOD_OK;
}

/* Area of the overlap of two boxes. */
static double box_overlap(const double alo[2], const double ahi[2], const double blo[2],
                          const double bhi[2]) {
  double a = 1;
  for (int d = 0; d < 2; d++)
    a *= fmax(0, fmin(ahi[d], bhi[d]) - fmax(alo[d], blo[d]));
  return a;
}

void rhod_rs_region_estimate(const rhod_rs_scene *rs, const double lo[2], const double hi[2],
                             double cell, double *n) {
  for (unsigned r = 0; rs && r < rs->n_regions; r++) {
    double rlo[2], rhi[2];
    rhod_sl_shape_bbox(&rs->regions[r].shape, rlo, rhi);
    const double area =
        fmin(box_overlap(lo, hi, rlo, rhi), rhod_sl_shape_area(&rs->regions[r].shape));
    *n += area / cell * (ldexp(1, 2 * rs->regions[r].level) - 1);
  }
}

/* ---- the scene as run ------------------------------------------------------------------- */

void rhod_rs_tree_time_step(rhod_sl_tb *t, ry_node *m, const rhod_rs_scene *rs) {
  rhod_sl_num(t, m, "cfl", rs->cfl);
  rhod_sl_num(t, m, "cfl_visc", rs->cfl_visc);
}

void rhod_rs_tree_time_limit(rhod_sl_tb *t, ry_node *m, const rhod_rs_scene *rs) {
  if (!rs->stiffness_limit) /* present only when off, so checkpoints made before the key
                               resume */
    rhod_sl_bool(t, m, "stiffness_limit", rs->stiffness_limit);
}

void rhod_rs_tree_particles(rhod_sl_tb *t, ry_node *m, const rhod_rs_scene *rs) {
  if (rs->relax > 0) /* absent at 0, so checkpoints made before the key resume */
    rhod_sl_num(t, m, "relax", rs->relax);
  if (rs->relax_where != RHOD_RELAX_ALL) /* likewise absent at its default */
    rhod_sl_word(t, m, "relax_where",
                 rhod_sl_enum_name(rhod_rs_relax_where_names,
                                   CYAML_ARRAY_LEN(rhod_rs_relax_where_names),
                                   (int)rs->relax_where));
}

void rhod_rs_tree_physics(rhod_sl_tb *t, ry_node *m, const rhod_rs_scene *rs) {
  rhod_sl_num(t, m, "rho0", rs->rho0);
  rhod_sl_num(t, m, "c0", rs->c0);
  rhod_sl_num(t, m, "mu", rs->mu);
}

void rhod_rs_tree_scheme(rhod_sl_tb *t, ry_node *m, const rhod_rs_scene *rs) {
  rhod_sl_bool(t, m, "riemann", rs->riemann);
  rhod_sl_bool(t, m, "reconstruction", rs->reconstruction);
  rhod_sl_bool(t, m, "shifting", rs->shifting);
  rhod_sl_num(t, m, "shifting_a", rs->shift_a);
  rhod_sl_num(t, m, "shifting_b", rs->shift_b);
  rhod_sl_num(t, m, "shifting_eps", rs->shift_eps);
  rhod_sl_bool(t, m, "acoustic_damper", rs->acoustic_damper);
  rhod_sl_num(t, m, "alpha_ad", rs->alpha_ad);
  rhod_sl_bool(t, m, "damper_step_limit", rs->damper_step_limit);
  rhod_sl_bool(t, m, "tensile_control", rs->tensile_control);
  rhod_sl_word(t, m, "shifting_switch",
               rhod_sl_enum_name(rhod_rs_shifting_switch_names,
                                 CYAML_ARRAY_LEN(rhod_rs_shifting_switch_names),
                                 (int)rs->shifting_switch));
  rhod_sl_bool(t, m, "free_surface", rs->free_surface);
  const double lambda[2] = {rs->fs_lambda_low, rs->fs_lambda_high};
  rhod_sl_vec(t, m, "free_surface_lambda", lambda);
  rhod_sl_num(t, m, "shepard_threshold", rs->shepard_threshold);
  rhod_sl_num(t, m, "theta_threshold", rs->theta_threshold);
  rhod_sl_word(t, m, "viscosity",
               rhod_sl_enum_name(rhod_rs_viscosity_names, CYAML_ARRAY_LEN(rhod_rs_viscosity_names),
                                 (int)rs->viscosity));
}

void rhod_rs_tree_refinement(rhod_sl_tb *t, ry_node *root, const rhod_rs_scene *rs) {
  ry_node *m = rhod_sl_coll(t, root, "refinement", RY_MAP, 0), *e;
  rhod_sl_num(t, m, "levels", rs->levels);
  rhod_sl_word(t, m, "pattern",
               rhod_sl_enum_name(pattern_names, CYAML_ARRAY_LEN(pattern_names), (int)rs->pattern));
  e = rhod_sl_coll(t, m, "regions", RY_SEQ, rs->n_regions == 0);
  for (unsigned i = 0; i < rs->n_regions; i++) {
    ry_node *r = rhod_sl_coll(t, e, NULL, RY_MAP, 0);
    rhod_sl_shape(t, r, &rs->regions[i].shape);
    rhod_sl_num(t, r, "level", rs->regions[i].level);
    if (rs->regions[i].hold)
      rhod_sl_bool(t, r, "hold", 1);
  }
  rhod_sl_bool(t, m, "dynamic", rs->refine_dynamic);
  rhod_sl_bool(t, m, "free_surface", rs->refine_free_surface);
  if (rs->refine_free_surface)
    rhod_sl_num(t, m, "surface_band", rs->refine_band);
  rhod_sl_num(t, m, "crowding", rs->refine_crowding);
  rhod_sl_bool(t, m, "walls", rs->refine_walls);
  rhod_sl_bool(t, m, "coalesce", rs->refine_coalesce);
  if (rs->refine_coalesce)
    rhod_sl_bool(t, m, "absorb", rs->refine_absorb);
  if (rs->refine_field) {
    e = rhod_sl_coll(t, m, "field", RY_MAP, 1);
    rhod_sl_word(t, e, "quantity",
                 rhod_sl_enum_name(quantity_names, CYAML_ARRAY_LEN(quantity_names),
                                   (int)rs->field_quantity));
    if (rs->field_above != HUGE_VAL)
      rhod_sl_num(t, e, "above", rs->field_above);
    if (rs->field_below != -HUGE_VAL)
      rhod_sl_num(t, e, "below", rs->field_below);
    rhod_sl_num(t, e, "from", rs->field_from);
    if (rs->field_quantity == RHOD_QTY_HYDRODYNAMIC_PRESSURE)
      rhod_sl_vec(t, e, "x0", rs->field_x0);
  }
}
