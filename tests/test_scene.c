/* Scene loading (src/scene.c): good scenes and their defaults, `--set` overrides, one
 * malformed scene per failure class with the line and key its message must name, the scene
 * as run (YAML and flattened parameters) and the Eq. 2 warning on c0. */
#define _POSIX_C_SOURCE 200809L

#include "rhod/rhodsph/scene.h"
#include "rhod/scene.h"
#include "test_scene_load.h"

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void test_full_scene(void) {
  rhod_scene *s = load_ok(GOOD("full.yaml"), NULL, 0);
  if (!s)
    return;
  CU_ASSERT_STRING_EQUAL(s->name, "full_scene");
  CU_ASSERT_STRING_EQUAL(s->path, GOOD("full.yaml"));
  CLOSE(s->t_end, 1.0);
  CLOSE(s->output_every, 0.05);
  CLOSE(s->rs->cfl, 0.4);
  CLOSE(s->rs->cfl_visc, 0.02);
  CU_ASSERT_FALSE(s->rs->stiffness_limit);
  CLOSE(s->dx, 0.01);
  CLOSE(s->radius_ratio, 3);
  CU_ASSERT_EQUAL(s->kernel, RHOD_KERNEL_QUINTIC);
  CLOSE(s->rs->rho0, 998);
  CLOSE(s->rs->c0, 80);
  CLOSE(s->rs->mu, 0.001);
  CLOSE(s->gravity[0], 0);
  CLOSE(s->gravity[1], -9.81);
  CU_ASSERT_FALSE(s->rs->riemann);
  CU_ASSERT_FALSE(s->rs->reconstruction);
  CU_ASSERT_FALSE(s->rs->shifting);
  CLOSE(s->rs->shift_a, 0.4);
  CLOSE(s->rs->shift_b, 0.04);
  CLOSE(s->rs->shift_eps, 4e-4);
  CU_ASSERT_FALSE(s->rs->acoustic_damper);
  CLOSE(s->rs->alpha_ad, 0.5);
  CU_ASSERT_FALSE(s->rs->damper_step_limit);
  CU_ASSERT_TRUE(s->rs->tensile_control);
  CU_ASSERT_EQUAL(s->rs->shifting_switch, RHOD_SHSW_ALL);
  CU_ASSERT_FALSE(s->rs->free_surface);
  CLOSE(s->rs->fs_lambda_low, 0.25);
  CLOSE(s->rs->fs_lambda_high, 0.7);
  CLOSE(s->rs->shepard_threshold, 0.8);
  CLOSE(s->rs->theta_threshold, 0.9);
  CU_ASSERT_TRUE(s->has_domain);
  CLOSE(s->domain_min[0], 0);
  CLOSE(s->domain_max[0], 4);
  CLOSE(s->domain_max[1], 3);
  CU_ASSERT_TRUE(s->periodic[0]);
  CU_ASSERT_FALSE(s->periodic[1]);

  CU_ASSERT_EQUAL_FATAL(s->n_fluid, 3);
  CU_ASSERT_EQUAL(s->fluid[0].shape.kind, RHOD_SHAPE_RECT);
  CLOSE(s->fluid[0].shape.max[1], 2);
  CLOSE(s->fluid[0].velocity[0], 0.5);
  CU_ASSERT_EQUAL(s->fluid[0].pressure, RHOD_INIT_UNIFORM);
  CU_ASSERT_EQUAL(s->fluid[1].shape.kind, RHOD_SHAPE_CIRCLE);
  CLOSE(s->fluid[1].shape.center[0], 2);
  CLOSE(s->fluid[1].shape.radius, 0.3);
  CU_ASSERT_EQUAL(s->fluid[1].pressure, RHOD_INIT_HYDROSTATIC);
  /* written clockwise, stored counter-clockwise */
  CU_ASSERT_EQUAL(s->fluid[2].shape.kind, RHOD_SHAPE_POLYGON);
  CU_ASSERT_EQUAL_FATAL(s->fluid[2].shape.n_points, 3);
  CLOSE(s->fluid[2].shape.points[0][0], 1);
  CLOSE(s->fluid[2].shape.points[1][1], 1);
  CLOSE(s->fluid[2].shape.points[2][0], 0);

  CU_ASSERT_EQUAL_FATAL(s->n_walls, 2);
  CU_ASSERT_EQUAL(s->walls[0].slip, RHOD_SLIP_NO);
  CU_ASSERT_TRUE(s->walls[0].fluid_inside);
  CU_ASSERT_EQUAL(s->walls[1].shape.kind, RHOD_SHAPE_CIRCLE);
  CU_ASSERT_EQUAL(s->walls[1].slip, RHOD_SLIP_FREE);
  CU_ASSERT_FALSE(s->walls[1].fluid_inside);
  CU_ASSERT_TRUE(s->walls[0].refine); /* the default */
  CU_ASSERT_FALSE(s->walls[1].refine);

  CLOSE(s->probe_every, 0.001);
  CU_ASSERT_EQUAL_FATAL(s->n_probes, 8);
  CU_ASSERT_EQUAL(s->probes[0].kind, RHOD_PROBE_PRESSURE);
  CU_ASSERT_STRING_EQUAL(s->probes[0].name, "P1");
  CLOSE(s->probes[0].at[0], 4.0);
  CLOSE(s->probes[0].at[1], 0.01);
  CU_ASSERT_EQUAL(s->probes[1].kind, RHOD_PROBE_KINETIC_ENERGY);
  CU_ASSERT_STRING_EQUAL(s->probes[1].name, "kinetic_energy");
  CU_ASSERT_EQUAL(s->probes[2].kind, RHOD_PROBE_POTENTIAL_ENERGY);
  CU_ASSERT_EQUAL(s->probes[3].kind, RHOD_PROBE_FRONT);
  CLOSE(s->probes[3].direction[0], 0.6); /* [3, 4] normalised */
  CLOSE(s->probes[3].direction[1], 0.8);
  CU_ASSERT_EQUAL(s->probes[4].kind, RHOD_PROBE_MASS);
  CU_ASSERT_EQUAL(s->probes[5].kind, RHOD_PROBE_MOMENTUM);
  CU_ASSERT_EQUAL(s->probes[6].kind, RHOD_PROBE_ANGULAR_MOMENTUM);
  CU_ASSERT_STRING_EQUAL(s->probes[6].name, "angular_momentum");
  CLOSE(s->probes[6].at[1], 0.5);
  CU_ASSERT_EQUAL(s->probes[7].kind, RHOD_PROBE_TORQUE_BUDGET);
  CU_ASSERT_STRING_EQUAL(s->probes[7].name, "tq");
  CLOSE(s->probes[7].at[1], 0.25);

  CU_ASSERT_EQUAL(s->picture_field, RHOD_FIELD_VELOCITY);
  CU_ASSERT_EQUAL(s->picture_width, 1024);
  CU_ASSERT_TRUE(s->picture_range_set);
  CLOSE(s->picture_range[1], 2);
  CU_ASSERT_PTR_NOT_NULL(s->yaml);
  rhod_scene_free(s);
}

static void test_defaults(void) {
  rhod_scene *s = load_ok(GOOD("minimal.yaml"), NULL, 0);
  if (!s)
    return;
  CU_ASSERT_STRING_EQUAL(s->name, "minimal"); /* from the file name */
  CLOSE(s->rs->cfl, 0.5);
  CLOSE(s->rs->cfl_visc, 0.025);
  CLOSE(s->radius_ratio, 4);
  CU_ASSERT_EQUAL(s->kernel, RHOD_KERNEL_WENDLAND_C2);
  CLOSE(s->rs->rho0, 1000);
  CLOSE(s->rs->mu, 0);
  CLOSE(s->gravity[0], 0);
  CLOSE(s->gravity[1], 0);
  CU_ASSERT_TRUE(s->rs->riemann);
  CU_ASSERT_TRUE(s->rs->reconstruction);
  CU_ASSERT_TRUE(s->rs->shifting);
  CLOSE(s->rs->shift_a, 0.5);
  CLOSE(s->rs->shift_b, 0.05);
  CLOSE(s->rs->shift_eps, 5e-4);
  CU_ASSERT_TRUE(s->rs->acoustic_damper);
  CLOSE(s->rs->alpha_ad, 1);
  CU_ASSERT_TRUE(s->rs->damper_step_limit);
  CU_ASSERT_TRUE(s->rs->stiffness_limit);
  CU_ASSERT_FALSE(s->rs->tensile_control);
  CU_ASSERT_EQUAL(s->rs->shifting_switch, RHOD_SHSW_NONE);
  CU_ASSERT_TRUE(s->rs->free_surface);
  CLOSE(s->rs->fs_lambda_low, 0.2);
  CLOSE(s->rs->fs_lambda_high, 0.75);
  CLOSE(s->rs->shepard_threshold, 0.85);
  CLOSE(s->rs->theta_threshold, 0.95);
  /* no domain: the bounding box of the fluid (no walls here) */
  CU_ASSERT_FALSE(s->has_domain);
  CLOSE(s->domain_min[0], 0);
  CLOSE(s->domain_max[0], 1);
  CLOSE(s->domain_max[1], 0.5);
  CU_ASSERT_FALSE(s->periodic[0] || s->periodic[1]);
  CU_ASSERT_EQUAL(s->n_fluid, 1);
  CLOSE(s->fluid[0].velocity[0], 0);
  CU_ASSERT_EQUAL(s->fluid[0].pressure, RHOD_INIT_HYDROSTATIC);
  CU_ASSERT_EQUAL(s->n_walls, 0);
  CU_ASSERT_PTR_NULL(s->walls);
  CU_ASSERT_EQUAL(s->n_probes, 0);
  CLOSE(s->probe_every, 0.01); /* output_every / 10 */
  CU_ASSERT_EQUAL(s->picture_field, RHOD_FIELD_PRESSURE);
  CU_ASSERT_EQUAL(s->picture_width, 800);
  CU_ASSERT_FALSE(s->picture_range_set);
  rhod_scene_free(s);
}

static void test_anchors(void) {
  rhod_scene *s = load_ok(GOOD("anchors.yaml"), NULL, 0);
  if (!s)
    return;
  CU_ASSERT_EQUAL(s->n_fluid, 2);
  CU_ASSERT_EQUAL_FATAL(s->n_walls, 3);
  CLOSE(s->walls[1].shape.max[0], 1);
  CU_ASSERT_EQUAL(s->walls[1].slip, RHOD_SLIP_NO);
  CU_ASSERT_FALSE(s->walls[2].fluid_inside);
  /* default domain: bounding box of walls and fluid */
  CLOSE(s->domain_max[1], 1);
  rhod_scene_free(s);
}

static void test_overrides(void) {
  const char *ov[] = {
      "time.end=0.5",
      "particles.dx=0.005",
      "physics.gravity=[0,-1]",
      "fluid.0.velocity=[1,0]",
      "time.cfl=0.3",                                         /* a key the file does not have */
      "output.picture.width=1024",                            /* a mapping the file does not have */
      "physics.gravity.0=0.25",                               /* one entry of a vector */
      "fluid.1={circle: {center: [0.5, 0.25], radius: 0.1}}", /* appended block */
      "probes.list.0.front.name=X",                           /* built from nothing */
      "scheme.riemann=false",
      "scheme.shifting_switch=balanced_momentum",
      "name=renamed",
  };
  int n = (int)(sizeof ov / sizeof ov[0]);
  rhod_scene *s = load_ok(GOOD("minimal.yaml"), ov, n);
  if (!s)
    return;
  CLOSE(s->t_end, 0.5);
  CLOSE(s->dx, 0.005);
  CLOSE(s->gravity[0], 0.25);
  CLOSE(s->gravity[1], -1);
  CLOSE(s->fluid[0].velocity[0], 1);
  CLOSE(s->rs->cfl, 0.3);
  CU_ASSERT_EQUAL(s->picture_width, 1024);
  CU_ASSERT_EQUAL_FATAL(s->n_fluid, 2);
  CU_ASSERT_EQUAL(s->fluid[1].shape.kind, RHOD_SHAPE_CIRCLE);
  CLOSE(s->fluid[1].shape.radius, 0.1);
  CU_ASSERT_EQUAL_FATAL(s->n_probes, 1);
  CU_ASSERT_EQUAL(s->probes[0].kind, RHOD_PROBE_FRONT);
  CU_ASSERT_STRING_EQUAL(s->probes[0].name, "X");
  CU_ASSERT_FALSE(s->rs->riemann);
  CU_ASSERT_EQUAL(s->rs->shifting_switch, RHOD_SHSW_BALANCED_MOMENTUM);
  CU_ASSERT_STRING_EQUAL(s->name, "renamed");
  /* the scene as run holds the overridden values */
  CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "end: 0.5\n"));
  CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "dx: 0.005\n"));
  CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "gravity: [0.25, -1]\n"));
  CU_ASSERT_PTR_NOT_NULL(strstr(s->yaml, "velocity: [1, 0]\n"));
  rhod_scene_free(s);
  /* later overrides win */
  const char *twice[] = {"time.end=2", "time.end=3"};
  s = load_ok(GOOD("minimal.yaml"), twice, 2);
  if (s)
    CLOSE(s->t_end, 3);
  rhod_scene_free(s);
}

/* Override errors: "--set K=V: key: reason". */
static const struct {
  const char *set, *key, *reason;
} bad_overrides[] = {
    {"physics.foo=1", "physics.foo", "unknown key"},
    {"foo=1", "foo", "unknown key"},
    {"time.end.x=1", "time.end.x", "unknown key"},
    {"time.end=abc", "time.end", "invalid number 'abc'"},
    {"particles.dx=-1", "particles.dx", "must be > 0"},
    {"particles.kernel=gauss", "particles.kernel", "invalid value 'gauss'"},
    {"scheme.riemann=perhaps", "scheme.riemann", "invalid boolean"},
    {"physics.gravity=[0]", "physics.gravity", "expected 2 entries, got 1"},
    {"physics.gravity.2=1", "physics.gravity.2", "out of range"},
    {"fluid.3.velocity=[1,0]", "fluid.3", "out of range"},
    {"fluid.x.velocity=[1,0]", "fluid.x", "list index"},
    {"fluid.0.rect.max=[-1,1]", "fluid.0.rect.max", "must exceed rect.min"},
    {"time=3", "time", "expected a mapping, got '3'"},
    {"probes.list.0.mass.name=t", "probes.list.0.mass.name", "time column"},
    {"name=two words", "name", "not a valid name"},
    {"physics.gravity=[0,", "physics.gravity", "invalid YAML value"},
    {"time.end", "(top level)", "expected dotted.key=value"},
    {"=1", "(top level)", "expected dotted.key=value"},
};

static void test_override_errors(void) {
  for (size_t i = 0; i < sizeof bad_overrides / sizeof bad_overrides[0]; i++) {
    char err[1024] = "", want[512];
    rhod_scene *s = (rhod_scene *)1;
    const char *ov[] = {"time.end=2", bad_overrides[i].set};
    int rc = rhod_scene_load(GOOD("minimal.yaml"), ov, 2, &s, err, sizeof err);
    snprintf(want, sizeof want, "--set %s: %s: ", bad_overrides[i].set, bad_overrides[i].key);
    int ok = rc == RHOD_ERR_SCENE && s == NULL && strncmp(err, want, strlen(want)) == 0 &&
             strstr(err, bad_overrides[i].reason);
    if (!ok)
      fprintf(stderr, "\n--set %s: rc %d, message '%s'\n", bad_overrides[i].set, rc, err);
    CU_ASSERT_TRUE(ok);
    CU_ASSERT_PTR_NULL(strchr(err, '\n'));
  }
}

/* One malformed scene per case: the message must be "FILE:LINE:COL: key: reason". */
static const struct {
  const char *file;
  int line;
  const char *key;
  const char *reason;
} bad_scenes[] = {
    {"missing_time_end.yaml", 1, "time.end", "missing required key"},
    {"missing_fluid.yaml", 2, "fluid", "missing required key"},
    {"missing_rect_min.yaml", 9, "fluid.0.rect.min", "missing required key"},
    {"probe_missing_at.yaml", 12, "probes.list.0.pressure.at", "missing required key"},
    {"wrong_type_number.yaml", 2, "time.end", "invalid number 'abc'"},
    {"wrong_type_mapping.yaml", 1, "time", "expected a mapping"},
    {"top_level_list.yaml", 1, "(top level)", "expected a mapping"},
    {"unknown_key.yaml", 8, "physics.foo", "unknown key"},
    {"unknown_top_key.yaml", 10, "colour", "unknown key"},
    {"commented_unknown_key.yaml", 26, "walls.1.colour", "unknown key"},
    {"negative_dx.yaml", 5, "particles.dx", "must be > 0"},
    {"zero_dx.yaml", 5, "particles.dx", "must be > 0"},
    {"end_zero.yaml", 2, "time.end", "must be > 0"},
    {"negative_mu.yaml", 8, "physics.mu", "must be >= 0"},
    {"cfl_range.yaml", 4, "time.cfl", "must be in (0, 1]"},
    {"radius_ratio_range.yaml", 6, "particles.radius_ratio", "must be in [2, 8]"},
    {"rect_min_max.yaml", 9, "fluid.0.rect.max", "must exceed rect.min"},
    {"radius_zero.yaml", 9, "fluid.0.circle.radius", "must be > 0"},
    {"polygon_two_points.yaml", 9, "fluid.0.polygon", "expected at least 3 entries, got 2"},
    {"polygon_self_intersect.yaml", 9, "fluid.0.polygon", "cross"},
    {"two_shapes.yaml", 10, "fluid.0.circle", "one shape per entry"},
    {"no_shape.yaml", 9, "fluid.0", "needs a shape"},
    {"empty_fluid_list.yaml", 8, "fluid", "expected at least 1 entry, got 0"},
    {"fluid_outside_domain.yaml", 9, "fluid.0", "outside the domain"},
    {"dx_too_coarse.yaml", 5, "particles.dx", "too coarse for fluid.0"},
    {"periodic_without_domain.yaml", 11, "domain.periodic", "needs domain.min and domain.max"},
    {"domain_min_only.yaml", 11, "domain.min", "given together"},
    {"unknown_enum.yaml", 6, "particles.kernel", "invalid value 'gaussian'"},
    {"wall_unknown_slip.yaml", 12, "walls.0.slip", "invalid value 'sticky'"},
    {"anchored_bad_value.yaml", 13, "walls.1.slip", "invalid value 'glue'"},
    {"vector_length.yaml", 8, "physics.gravity", "expected 2 entries, got 3"},
    {"bad_bool.yaml", 11, "scheme.riemann", "invalid boolean 'maybe'"},
    {"trailing_garbage.yaml", 7, "physics.c0", "invalid number '50x'"},
    {"not_finite.yaml", 8, "physics.mu", "finite"},
    {"lambda_order.yaml", 11, "scheme.free_surface_lambda", "must be below high"},
    {"front_zero_direction.yaml", 12, "probes.list.0.front.direction", "must not be zero"},
    {"duplicate_probe_names.yaml", 13, "probes.list.1.pressure.name", "duplicate probe column"},
    {"probe_two_kinds.yaml", 13, "probes.list.0.momentum", "one probe per entry"},
    {"probe_columns_total.yaml", 12, "probes.list", "at most 64"},
    {"picture_width.yaml", 12, "output.picture.width", "[64, 8192]"},
    {"range_order.yaml", 12, "output.picture.range", "must be below high"},
    {"refine_criterion_one_level.yaml", 11, "refinement.levels", "need at least 2 levels"},
    {"refine_field_no_threshold.yaml", 12, "refinement.field", "needs a threshold"},
    {"refine_field_quantity.yaml", 12, "refinement.field.quantity", "invalid value"},
    {"refine_field_no_x0.yaml", 12, "refinement.field", "needs x0"},
    {"refine_field_x0_unused.yaml", 12, "refinement.field.x0", "hydrodynamic_pressure only"},
    {"refine_free_surface_no_detection.yaml", 14, "refinement.free_surface",
     "needs the free-surface detection"},
    {"refine_coalesce_static.yaml", 13, "refinement.coalesce", "needs dynamic refinement"},
    {"refine_absorb_no_coalesce.yaml", 12, "refinement.absorb", "needs refinement.coalesce"},
    {"refine_surface_band_range.yaml", 13, "refinement.surface_band", "must be in [0.5, 1]"},
    {"refine_surface_band_triangle.yaml", 14, "refinement.surface_band", "must be in [0.5774, 1]"},
    {"refine_surface_band_no_criterion.yaml", 12, "refinement.surface_band", "needs criterion 3"},
    {"refine_crowding_range.yaml", 12, "refinement.crowding", "must be in [0, 1)"},
    {"refine_pattern_unknown.yaml", 12, "refinement.pattern", "hexagon"},
    {"shifting_switch_unknown.yaml", 11, "scheme.shifting_switch", "continuity"},
    {"refine_triangle_regions.yaml", 14, "refinement.regions", "need refinement.pattern: square"},
    {"viscosity_unknown.yaml", 12, "scheme.viscosity", "invalid value 'morris'"},
    {"refine_levels_fraction.yaml", 11, "refinement.levels", "whole number"},
    {"refine_levels_zero.yaml", 11, "refinement.levels", "whole number"},
    {"relax_fraction.yaml", 6, "particles.relax", "whole number"},
    {"relax_where_unknown.yaml", 7, "particles.relax_where", "surface"},
    {"relax_where_no_relax.yaml", 6, "particles.relax_where", "needs particles.relax"},
    {"refine_region_level.yaml", 14, "refinement.regions.0.level", "whole number"},
    {"refine_region_no_shape.yaml", 13, "refinement.regions.0", "needs a shape"},
    {"refine_region_hold_static.yaml", 16, "refinement.regions.0.hold", "needs dynamic refinement"},
    {"duplicate_key.yaml", 6, "particles.dx", "duplicate key"},
    {"syntax_unclosed.yaml", 10, "fluid.0.rect", "YAML syntax"},
    {"syntax_tab.yaml", 2, "time", "YAML syntax"},
    {"two_documents.yaml", 10, "(top level)", "one YAML document"},
    {"unknown_alias.yaml", 9, "fluid.0.rect", "unknown alias"},
    {"empty.yaml", 1, "time", "missing required key"},
    {"missing_c0.yaml", 6, "physics.c0", "missing required key"},
    {"missing_physics.yaml", 1, "physics", "missing required key"},
    {"scheme_unknown.yaml", 9, "scheme.name", "invalid value 'sph2'"},
    /* the multiphase scheme's keys (src/multiphase/scene_mp.c) and the schemes' own keys */
    {"mp_unknown_phase.yaml", 13, "fluid.0.phase", "unknown phase 'oil' (phases: water, air)"},
    {"mp_block_without_phase.yaml", 14, "fluid.1", "no phase"},
    {"mp_gamma_zero.yaml", 10, "phases.1.gamma", "must be > 0, got 0"},
    {"mp_negative_sigma.yaml", 12, "multiphase.sigma", "must be >= 0"},
    {"mp_sigma_one_phase.yaml", 11, "multiphase.sigma", "needs at least two phases"},
    {"mp_sigma_pairs_one_phase.yaml", 12, "multiphase.sigma_pairs", "needs at least two phases"},
    {"mp_duplicate_phase.yaml", 10, "phases.1.name", "duplicate phase name 'water'"},
    {"mp_pair_unknown_phase.yaml", 13, "multiphase.sigma_pairs.0.phases.1", "unknown phase 'oil'"},
    {"mp_pair_same_phase.yaml", 13, "multiphase.sigma_pairs.0.phases", "names phase 'air' twice"},
    {"mp_pair_twice.yaml", 14, "multiphase.sigma_pairs.1.phases", "given twice"},
    {"mp_rhod_c0.yaml", 6, "physics.c0", "belongs to the rhodsph scheme"},
    {"mp_rhod_refinement.yaml", 14, "refinement.levels", "belongs to the rhodsph scheme"},
    {"mp_rhod_scheme_key.yaml", 8, "scheme.riemann", "belongs to the rhodsph scheme"},
    {"mp_rhod_stiffness_limit.yaml", 4, "time.stiffness_limit", "belongs to the rhodsph scheme"},
    {"mp_no_phases.yaml", 1, "phases", "missing required key"},
    {"mp_phase_name.yaml", 9, "phases.0.name", "not an identifier"},
    {"mp_colour.yaml", 9, "phases.0.colour", "must be 1 (liquid) or 0 (gas)"},
    {"mp_nine_phases.yaml", 9, "phases", "expected at most 8 entries, got 9"},
    {"rhod_phases.yaml", 8, "phases", "belongs to the multiphase scheme"},
    {"rhod_fluid_phase.yaml", 10, "fluid.0.phase", "belongs to the multiphase scheme"},
    /* moving walls */
    {"wall_velocity_not_along.yaml", 13, "walls.0.velocity", "is not along edge 3"},
    {"wall_circle_moving.yaml", 12, "walls.0.velocity", "a circle wall cannot move"},
    {"wall_edge_out_of_range.yaml", 13, "walls.0.edges.1", "edge 3 out of range"},
    {"wall_edge_fraction.yaml", 13, "walls.0.edges.0", "whole edge index"},
    {"wall_velocity_periodic.yaml", 17, "walls.0.velocity",
     "a wall velocity on a periodic axis"}, /* bodies (src/scene_bodies.c) */
    {"body_bad_name.yaml", 17, "bodies.0.name", "'2cyl' is not a body name"},
    {"body_crosses_wall.yaml", 17, "bodies.0", "crosses the boundary of walls.0"},
    {"body_duplicate_name.yaml", 19, "bodies.1", "the name 'body1' is also bodies.0's"},
    {"body_free_no_mass.yaml", 17, "bodies.0.mass", "missing required key (or density"},
    {"body_added_mass_negative.yaml", 20, "bodies.0.added_mass", "must be >= 0"},
    {"body_added_mass_fixed.yaml", 18, "bodies.0.added_mass", "only for motion: free"},
    {"body_in_obstacle.yaml", 19, "bodies.0", "overlaps the obstacle walls.1 at t = 0"},
    {"body_inside_body.yaml", 18, "bodies.1", "overlaps bodies.0 at t = 0 (one lies inside"},
    {"body_law_not_finite.yaml", 20, "bodies.0.law.theta",
     "its first derivative at t = 0 is inf, not finite"},
    {"body_law_not_imposed.yaml", 18, "bodies.0.law",
     "only for motion: imposed (this body's motion is fixed)"},
    {"body_law_outside_domain.yaml", 17, "bodies.0", "the body spans [0.5, 2.9]-[0.7, 3.1]"},
    {"body_law_bad_char.yaml", 20, "bodies.0.law.x", "unexpected '@ 2' at character 17"},
    {"body_law_syntax.yaml", 20, "bodies.0.law.x", "'0.1*sin(2*pi*t' is not an expression of t"},
    {"body_law_variable.yaml", 20, "bodies.0.law.y", "unknown variable 'w' in '0.1*sin(w*t)'"},
    {"body_lock_twice.yaml", 20, "bodies.0.lock.1", "'x' is named twice"},
    {"body_mass_and_density.yaml", 20, "bodies.0.mass", "give mass or density, not both"},
    {"body_mass_not_free.yaml", 19, "bodies.0.mass",
     "only for motion: free (this body's motion is imposed)"},
    {"body_negative_density.yaml", 19, "bodies.0.density", "must be > 0, got -1000"},
    {"body_no_shape.yaml", 17, "bodies.0", "needs a shape: one of rect, circle, polygon"},
    {"body_outside_container.yaml", 17, "bodies.0", "lies outside the container walls.0 at t = 0"},
    {"body_outside_domain.yaml", 17, "bodies.0",
     "outside the domain [-1, -1]-[3, 3] (at t = 0 the body spans"},
    {"body_overlap.yaml", 18, "bodies.1", "overlaps bodies.0 at t = 0 (their outlines meet)"},
    {"body_unknown_lock.yaml", 20, "bodies.0.lock.0", "invalid value 'z' (one of: x, y, theta)"},
    {"body_unknown_motion.yaml", 18, "bodies.0.motion", "invalid value 'floating'"},
    {"body_zero_inertia.yaml", 20, "bodies.0.inertia", "must be > 0, got 0"},
    {"body_zero_mass.yaml", 19, "bodies.0.mass", "must be > 0, got 0"},
    /* open boundaries (src/scene_open.c; the others in test_scene_open.c) */
    {"open_facing_fluid.yaml", 20, "open_boundaries.0", "the fluid (fluid.0) extends behind it"},
    {"open_no_kind.yaml", 20, "open_boundaries.0.kind", "missing required key"},
    {"open_on_wall.yaml", 20, "open_boundaries.0", "lies on walls.1: remove that wall edge"},
    {"open_outside_domain.yaml", 20, "open_boundaries.0", "to [0, 0.3] lies outside the domain"},
    {"open_overlap.yaml", 23, "open_boundaries.1", "overlaps open_boundaries.0"},
    {"open_velocity_syntax.yaml", 23, "open_boundaries.0.velocity",
     "'2*sin(t' is not an expression of t"},
};

static void test_bad_scenes(void) {
  for (size_t i = 0; i < sizeof bad_scenes / sizeof bad_scenes[0]; i++) {
    char path[512], err[1024] = "", prefix[600], key[128];
    snprintf(path, sizeof path, "%s/tests/scenes/bad/%s", RHOD_SOURCE_DIR, bad_scenes[i].file);
    rhod_scene *s = (rhod_scene *)1;
    int rc = rhod_scene_load(path, NULL, 0, &s, err, sizeof err);
    snprintf(prefix, sizeof prefix, "%s:%d:", path, bad_scenes[i].line);
    snprintf(key, sizeof key, ": %s: ", bad_scenes[i].key);
    int ok = rc == RHOD_ERR_SCENE && s == NULL && strncmp(err, prefix, strlen(prefix)) == 0 &&
             strstr(err, key) && strstr(err, bad_scenes[i].reason) && !strchr(err, '\n');
    if (!ok)
      fprintf(stderr, "\n%s: rc %d, message '%s', expected line %d key %s\n", bad_scenes[i].file,
              rc, err, bad_scenes[i].line, bad_scenes[i].key);
    CU_ASSERT_TRUE(ok);
  }
}

/* Every file in tests/scenes/bad is in the table above. */
static void test_bad_table_complete(void) {
  char cmd[512];
  snprintf(cmd, sizeof cmd, "ls %s/tests/scenes/bad/*.yaml | wc -l", RHOD_SOURCE_DIR);
  FILE *p = popen(cmd, "r");
  CU_ASSERT_PTR_NOT_NULL_FATAL(p);
  unsigned n = 0;
  CU_ASSERT_EQUAL(fscanf(p, "%u", &n), 1);
  pclose(p);
  CU_ASSERT_EQUAL(n, sizeof bad_scenes / sizeof bad_scenes[0]);
  CU_ASSERT_TRUE(n >= 20);
}

static void test_unreadable(void) {
  char err[1024];
  rhod_scene *s = (rhod_scene *)1;
  int rc = rhod_scene_load(BAD("does_not_exist.yaml"), NULL, 0, &s, err, sizeof err);
  CU_ASSERT_EQUAL(rc, RHOD_ERR_READ);
  CU_ASSERT_PTR_NULL(s);
  CU_ASSERT_STRING_EQUAL(err,
                         BAD("does_not_exist.yaml") ": cannot read: No such file or directory");
  rc = rhod_scene_load(RHOD_SOURCE_DIR "/tests/scenes", NULL, 0, &s, err, sizeof err);
  CU_ASSERT_EQUAL(rc, RHOD_ERR_READ);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "/tests/scenes: cannot read: "));
  /* a short error buffer is cut, not overrun */
  char small[8];
  rc = rhod_scene_load(BAD("zero_dx.yaml"), NULL, 0, &s, small, sizeof small);
  CU_ASSERT_EQUAL(rc, RHOD_ERR_SCENE);
  CU_ASSERT_EQUAL(strlen(small), sizeof small - 1);
  CU_ASSERT_EQUAL(rhod_scene_load(BAD("zero_dx.yaml"), NULL, 0, &s, NULL, 0), RHOD_ERR_SCENE);
}

/* The scene as run loads back to the same scene, and writes the same text again. */
static void test_as_run_round_trip(void) {
  const char *ov[] = {"physics.c0=90"};
  rhod_scene *a = load_ok(GOOD("full.yaml"), ov, 1);
  if (!a)
    return;
  const char *tmp = "test_scene_as_run.yaml";
  FILE *f = fopen(tmp, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fputs(a->yaml, f);
  fclose(f);
  rhod_scene *b = load_ok(tmp, NULL, 0);
  remove(tmp);
  if (b) {
    CU_ASSERT_STRING_EQUAL(a->yaml, b->yaml);
    CLOSE(b->rs->c0, 90);
    CU_ASSERT_EQUAL(b->n_probes, a->n_probes);
    CU_ASSERT_EQUAL(b->fluid[2].shape.n_points, 3);
    CLOSE(b->fluid[2].shape.points[0][0], a->fluid[2].shape.points[0][0]);
    CU_ASSERT_STRING_EQUAL(b->name, "full_scene");
  }
  rhod_scene_free(a);
  rhod_scene_free(b);
  /* no domain given: none written, so the default stays the bounding box */
  a = load_ok(GOOD("minimal.yaml"), NULL, 0);
  if (a)
    CU_ASSERT_PTR_NULL(strstr(a->yaml, "min: [0, 0]\n  max"));
  rhod_scene_free(a);
}

static void test_params(void) {
  rhod_scene *s = load_ok(GOOD("full.yaml"), NULL, 0);
  if (!s)
    return;
  rhod_param_list p;
  CU_ASSERT_EQUAL_FATAL(rhod_scene_params(s, &p), RHOD_OK);
  const struct {
    const char *key, *value;
  } want[] = {
      {"name", "full_scene"},
      {"time.end", "1"},
      {"time.output_every", "0.05"},
      {"particles.kernel", "quintic"},
      {"physics.gravity", "[0, -9.81]"},
      {"scheme.riemann", "false"},
      {"scheme.shifting_eps", "0.0004"},
      {"scheme.free_surface_lambda", "[0.25, 0.7]"},
      {"domain.periodic", "[true, false]"},
      {"fluid.0.rect.min", "[0, 0]"},
      {"fluid.0.rect.max", "[1, 2]"},
      {"fluid.0.pressure", "uniform"},
      {"fluid.1.circle.radius", "0.3"},
      {"fluid.2.polygon", "[[1, 0], [0.5, 1], [0, 0]]"},
      {"walls.0.slip", "no"},
      {"walls.1.fluid_inside", "false"},
      {"walls.1.refine", "false"},
      {"probes.every", "0.001"},
      {"probes.list.0.pressure.name", "P1"},
      {"probes.list.3.front.direction", "[0.6, 0.8]"},
      {"output.picture.width", "1024"},
      {"output.picture.range", "[0, 2]"},
  };
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
    const char *v = param(&p, want[i].key);
    if (!v || strcmp(v, want[i].value) != 0)
      fprintf(stderr, "\n%s: '%s', expected '%s'\n", want[i].key, v ? v : "(none)", want[i].value);
    CU_ASSERT_TRUE(v && strcmp(v, want[i].value) == 0);
  }
  /* walls.N.refine at its default (true) is not written, so older checkpoints resume */
  CU_ASSERT_PTR_NULL(param(&p, "walls.0.refine"));
  for (unsigned i = 0; i < p.n; i++) /* leaves only */
    for (unsigned j = 0; j < p.n; j++)
      if (i != j) {
        size_t l = strlen(p.keys[i]);
        CU_ASSERT_FALSE(strncmp(p.keys[i], p.keys[j], l) == 0 && p.keys[j][l] == '.');
      }
  rhod_param_list_free(&p);
  CU_ASSERT_EQUAL(p.n, 0);
  rhod_param_list_free(&p);
  rhod_scene_free(s);
}

/* full.yaml: |g| = 9.81, fluid from y = 0 to 2.3 (circle top), max |u0| = 0.5:
 * bound = 10 (sqrt(2 g H) + 0.5) = 72.18 m/s. */
static void test_c0_warning(void) {
  double H = 2.3, g = 9.81, bound = 10 * (sqrt(2 * g * H) + 0.5);
  char low[64], high[64], buf[2048];
  snprintf(low, sizeof low, "physics.c0=%.6f", bound * 0.999);
  snprintf(high, sizeof high, "physics.c0=%.6f", bound * 1.001);
  const char *ov_low[] = {low}, *ov_high[] = {high}, *ov_5[] = {"physics.c0=5"};

  rhod_scene *s = load_ok(GOOD("full.yaml"), ov_low, 1);
  if (s) {
    CU_ASSERT_EQUAL(rhod_scene_warnings(s, buf, sizeof buf), 1);
    CU_ASSERT_PTR_NOT_NULL(strstr(buf, GOOD("full.yaml") ": physics.c0: "));
    CU_ASSERT_PTR_NOT_NULL(strstr(buf, "Eq. 2"));
    char b[32];
    snprintf(b, sizeof b, "%.4g m/s", bound);
    CU_ASSERT_PTR_NOT_NULL(strstr(buf, b));
    CU_ASSERT_PTR_NULL(strchr(buf, '\n'));
  }
  rhod_scene_free(s);
  s = load_ok(GOOD("full.yaml"), ov_5, 1);
  if (s) {
    CU_ASSERT_EQUAL(rhod_scene_warnings(s, buf, sizeof buf), 1);
    CU_ASSERT_PTR_NOT_NULL(strstr(buf, "physics.c0: 5 m/s is below"));
    CU_ASSERT_EQUAL(rhod_scene_warnings(s, NULL, 0), 1); /* counts without a buffer */
    char tiny[16];
    CU_ASSERT_EQUAL(rhod_scene_warnings(s, tiny, sizeof tiny), 1);
    CU_ASSERT_EQUAL(strlen(tiny), sizeof tiny - 1);
  }
  rhod_scene_free(s);
  s = load_ok(GOOD("full.yaml"), ov_high, 1);
  if (s) {
    CU_ASSERT_EQUAL(rhod_scene_warnings(s, buf, sizeof buf), 0);
    CU_ASSERT_STRING_EQUAL(buf, "");
  }
  rhod_scene_free(s);
  /* without gravity the bound is 10 max|u0| */
  const char *ov_u[] = {"fluid.0.velocity=[3,4]", "physics.c0=49"};
  s = load_ok(GOOD("minimal.yaml"), ov_u, 2);
  if (s)
    CU_ASSERT_EQUAL(rhod_scene_warnings(s, buf, sizeof buf), 1);
  rhod_scene_free(s);
}

static void test_other_warnings(void) {
  const char *ov[] = {"time.output_every=2",        "output.picture.field=free_surface",
                      "output.picture.range=[0,1]", "domain.min=[0,0]",
                      "domain.max=[1.005,1]",       "domain.periodic=[true,false]"};
  char buf[4096];
  rhod_scene *s = load_ok(GOOD("minimal.yaml"), ov, 6);
  if (!s)
    return;
  CU_ASSERT_EQUAL(rhod_scene_warnings(s, buf, sizeof buf), 3);
  CU_ASSERT_PTR_NOT_NULL(strstr(buf, "time.output_every"));
  CU_ASSERT_PTR_NOT_NULL(strstr(buf, "output.picture.range"));
  CU_ASSERT_PTR_NOT_NULL(strstr(buf, "domain.periodic"));
  rhod_scene_free(s);
}

/* Default name for cases/<name>/scene.yaml is <name>. */
static void test_default_name(void) {
  const char *dir = "test_scene_case_dir";
  mkdir(dir, 0755);
  FILE *in = fopen(GOOD("minimal.yaml"), "r"), *out = fopen("test_scene_case_dir/scene.yaml", "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(in);
  CU_ASSERT_PTR_NOT_NULL_FATAL(out);
  int ch;
  while ((ch = fgetc(in)) != EOF)
    fputc(ch, out);
  fclose(in);
  fclose(out);
  rhod_scene *s = load_ok("test_scene_case_dir/scene.yaml", NULL, 0);
  if (s)
    CU_ASSERT_STRING_EQUAL(s->name, "test_scene_case_dir");
  rhod_scene_free(s);
  remove("test_scene_case_dir/scene.yaml");
  rmdir(dir);
}

/* The library writes nothing on stdout or stderr, even for errors. */
static void test_silent(void) {
  fflush(stdout);
  fflush(stderr);
  FILE *cap = tmpfile();
  CU_ASSERT_PTR_NOT_NULL_FATAL(cap);
  int o = dup(1), e = dup(2);
  dup2(fileno(cap), 1);
  dup2(fileno(cap), 2);
  char err[1024];
  rhod_scene *s;
  const char *ov[] = {"physics.foo=1"};
  for (size_t i = 0; i < sizeof bad_scenes / sizeof bad_scenes[0]; i++) {
    char path[512];
    snprintf(path, sizeof path, "%s/tests/scenes/bad/%s", RHOD_SOURCE_DIR, bad_scenes[i].file);
    rhod_scene_load(path, NULL, 0, &s, err, sizeof err);
  }
  rhod_scene_load(GOOD("minimal.yaml"), ov, 1, &s, err, sizeof err);
  if (rhod_scene_load(GOOD("full.yaml"), NULL, 0, &s, err, sizeof err) == RHOD_OK) {
    rhod_scene_warnings(s, err, sizeof err);
    rhod_scene_free(s);
  }
  fflush(stdout);
  fflush(stderr);
  dup2(o, 1);
  dup2(e, 2);
  close(o);
  close(e);
  fseek(cap, 0, SEEK_END);
  long size = ftell(cap);
  fclose(cap);
  CU_ASSERT_EQUAL(size, 0);
}

static void test_null_safety(void) {
  rhod_scene_free(NULL);
  rhod_param_list_free(NULL);
  CU_ASSERT_EQUAL(rhod_scene_warnings(NULL, NULL, 0), 0);
  CU_ASSERT_EQUAL(rhod_scene_load(GOOD("minimal.yaml"), NULL, 0, NULL, NULL, 0), RHOD_ERR_USAGE);
  const char *null_set[] = {NULL};
  char err[256];
  rhod_scene *s;
  CU_ASSERT_EQUAL(rhod_scene_load(GOOD("minimal.yaml"), null_set, 1, &s, err, sizeof err),
                  RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "expected dotted.key=value"));
  CU_ASSERT_EQUAL(rhod_scene_load(NULL, NULL, 0, &s, err, sizeof err), RHOD_ERR_READ);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"full scene: every key read", test_full_scene},
      {"minimal scene: every default filled", test_defaults},
      {"anchors and aliases", test_anchors},
      {"--set overrides: list index, vector, new keys", test_overrides},
      {"--set errors name the override and the key", test_override_errors},
      {"bad scenes: code, file, line and key", test_bad_scenes},
      {"every bad scene is in the table", test_bad_table_complete},
      {"missing or unreadable file", test_unreadable},
      {"scene as run loads back identically", test_as_run_round_trip},
      {"flattened parameters", test_params},
      {"c0 warning of Eq. 2", test_c0_warning},
      {"other warnings", test_other_warnings},
      {"default name from the case folder", test_default_name},
      {"no output on stdout or stderr", test_silent},
      {"NULL arguments", test_null_safety},
  };
  return RHOD_RUN_TESTS("scene", cases);
}
