/* RHOD-SPH's scalars in a checkpoint (src/rhodsph/scheme.c save and load): the APR
 * totals, the energy coalescing took out and the stiffness limit's last measure travel as
 * the checkpoint's named extras (version 7; the engine's checkpoint knows no scheme
 * counters), through a written and read file; a checkpoint without them, or with a value
 * no run makes, is refused with one line naming it. */
#define _XOPEN_SOURCE 700
#include "cunit_main.h"
#include "rhod/checkpoint.h"
#include "rhod/rhodsph/scheme.h"
#include "rhod/sim.h"
#include "test_run_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static char dir[] = "/tmp/rhod_test_rs_checkpoint_XXXXXX";
static char ckpath[256];

static int open_tank(run *r) {
  return run_open_in(r, "test_rhodsph_checkpoint", "tank",
                     "time: {end: 1, output_every: 1}\n"
                     "particles: {dx: 0.02}\n"
                     "physics: {c0: 10, gravity: [0, -9.81]}\n"
                     "fluid:\n"
                     "  - rect: {min: [0, 0], max: [0.2, 0.1]}\n"
                     "walls:\n"
                     "  - rect: {min: [0, 0], max: [0.2, 0.2]}\n"
                     "refinement: {levels: 2, free_surface: true}\n");
}

/* A run state the reader accepts, with the scheme's extras from its save. */
static void save_state(run *r, rhod_checkpoint *ck) {
  memset(ck, 0, sizeof *ck);
  ck->picture_range[0] = ck->picture_range[1] = NAN;
  ck->probes_bytes = 10;
  ck->scene_path = "scene.yaml";
  r->sim->ops->save(r->sim, ck);
}

static void set_counters(rhod_rhodsph *rs, long s, long m, long a, double kem, double kea,
                         real st) {
  rs->apr.split_total = s, rs->apr.merged_total = m, rs->apr.absorbed_total = a;
  rs->apr.ke_merged = kem, rs->apr.ke_absorbed = kea, rs->sph.st_lambda = st;
}

static void test_round_trip(void) {
  run r;
  CU_ASSERT_FATAL(open_tank(&r));
  rhod_rhodsph *rs = rhod_rs(r.sim);
  set_counters(rs, 9007199254740000L, 45, 6, 1.5e-3, -0.0, (real)321.5);
  rhod_checkpoint ck, back;
  save_state(&r, &ck);
  /* the engine holds no counter of its own: only the scheme's named scalars carry them */
  CU_ASSERT_EQUAL(ck.nextra, 6);
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_checkpoint_write(ckpath, &ck, &r.sim->p, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_checkpoint_read(ckpath, &back, err, sizeof err), RHOD_OK);
  set_counters(rs, 0, 0, 0, 0, 0, 0);
  r.sim->dt = 0;
  CU_ASSERT_EQUAL(r.sim->ops->load(r.sim, &back, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rs->apr.split_total, 9007199254740000L);
  CU_ASSERT_EQUAL(rs->apr.merged_total, 45);
  CU_ASSERT_EQUAL(rs->apr.absorbed_total, 6);
  CU_ASSERT_EQUAL(rs->apr.ke_merged, 1.5e-3);
  CU_ASSERT_EQUAL(rs->apr.ke_absorbed, 0.0);
  CU_ASSERT_EQUAL(rs->sph.st_lambda, (real)321.5);
  CU_ASSERT(r.sim->dt > 0); /* and the next dt from the state */
  rhod_checkpoint_free(&back);
  run_close(&r);
}

/* The extras as a version 2-6 file's fixed fields come back (rhod_ck_legacy_extra, after
 * another scheme's extras): loaded as they are. */
static void test_legacy_names(void) {
  run r;
  CU_ASSERT_FATAL(open_tank(&r));
  rhod_checkpoint ck;
  memset(&ck, 0, sizeof ck);
  snprintf(ck.extra_name[0], sizeof ck.extra_name[0], "force_dt");
  ck.extra[0] = 1;
  const double v[RHOD_CK_LEGACY_EXTRAS] = {4, 2, 7.5, 1, 0.25, 0.125};
  for (int i = 0; i < RHOD_CK_LEGACY_EXTRAS; i++) {
    snprintf(ck.extra_name[i + 1], sizeof ck.extra_name[0], "%s", rhod_ck_legacy_extra[i]);
    ck.extra[i + 1] = v[i];
  }
  ck.nextra = RHOD_CK_LEGACY_EXTRAS + 1;
  char err[512] = "";
  CU_ASSERT_EQUAL(r.sim->ops->load(r.sim, &ck, err, sizeof err), RHOD_OK);
  const rhod_rhodsph *rs = rhod_rs(r.sim);
  CU_ASSERT_EQUAL(rs->apr.split_total, 4);
  CU_ASSERT_EQUAL(rs->apr.merged_total, 2);
  CU_ASSERT_EQUAL(rs->sph.st_lambda, (real)7.5);
  CU_ASSERT_EQUAL(rs->apr.absorbed_total, 1);
  CU_ASSERT_EQUAL(rs->apr.ke_merged, 0.25);
  CU_ASSERT_EQUAL(rs->apr.ke_absorbed, 0.125);
  run_close(&r);
}

/* Extra `name` set to v (or removed with drop) in a saved state: refused, the message one
 * line with `want` in it. */
static void refused(const char *name, double v, int drop, const char *want) {
  run r;
  CU_ASSERT_FATAL(open_tank(&r));
  rhod_checkpoint ck;
  save_state(&r, &ck);
  int found = 0;
  for (int i = 0; i < ck.nextra; i++)
    if (!strcmp(ck.extra_name[i], name)) {
      found = 1;
      if (drop)
        snprintf(ck.extra_name[i], sizeof ck.extra_name[i], "other");
      else
        ck.extra[i] = v;
    }
  CU_ASSERT_FATAL(found);
  char err[512] = "";
  CU_ASSERT_EQUAL(r.sim->ops->load(r.sim, &ck, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, want));
  CU_ASSERT_PTR_NULL(strchr(err, '\n'));
  if (!strstr(err, want))
    printf("\n  expected \"%s\", got: %s\n", want, err);
  run_close(&r);
}

static void test_missing(void) {
  refused("splits", 0, 1, "the checkpoint has no splits");
  refused("ke_absorbed", 0, 1, "the checkpoint has no ke_absorbed");
}

static void test_bad_values(void) {
  refused("merges", -1, 0, "the checkpoint's merges: -1, must be a whole number >= 0");
  refused("splits", 2.5, 0, "the checkpoint's splits: 2.5, must be a whole number >= 0");
  refused("absorbed", 1e300, 0, "the checkpoint's absorbed: 1e+300, must be a whole number");
  refused("stiffness", NAN, 0, "the checkpoint's stiffness: nan, must be finite and >= 0");
  refused("stiffness", -3, 0, "the checkpoint's stiffness: -3, must be finite and >= 0");
  refused("ke_merged", -INFINITY, 0, "the checkpoint's ke_merged: -inf, not a finite number");
}

int main(void) {
  if (!mkdtemp(dir))
    return 2;
  snprintf(ckpath, sizeof ckpath, "%s/checkpoint.rhod", dir);
  static const rhod_test_case cases[] = {
      {"counters and stiffness through a checkpoint file", test_round_trip},
      {"the names an older checkpoint's fields get", test_legacy_names},
      {"a checkpoint without them refused", test_missing},
      {"values no run makes refused", test_bad_values},
  };
  const int rc = RHOD_RUN_TESTS("RHOD-SPH checkpoint extras", cases);
  unlink(ckpath);
  rmdir(dir);
  return rc;
}
