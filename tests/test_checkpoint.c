/* Checkpoint validation (robustness round 2): a checkpoint whose checksum is right but
 * whose fields are not (NaN or infinite times, zero masses, duplicate ids, an absurd
 * probes.csv length, a negative snapshot count, ...) is refused with RHOD_ERR_CHECKPOINT
 * and a message naming the field. Checkpoints are made by rhod_checkpoint_write from a
 * small particle store (so the hash is the writer's), or patched byte by byte with the
 * hash recomputed (fields the writer cannot express, such as a negative count). */
#define _XOPEN_SOURCE 700
#include "cunit_main.h"
#include "rhod/checkpoint.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define NP 6

static char dir[] = "/tmp/rhod_test_checkpoint_XXXXXX";
static char ckpath[256];

/* A healthy run state and store: NP particles on a line, ids 0..NP-1. */
static double snap_t[2] = {0, 0.5};
static uint64_t snap_n[2] = {NP, NP};
static const char *sets[1] = {"time.end=1"};
static char *keys[1] = {"time.end"}, *values[1] = {"1"};

static void base(rhod_checkpoint *ck, rhod_particles *p) {
  memset(ck, 0, sizeof *ck);
  snap_t[0] = 0, snap_t[1] = 0.5;
  ck->t = 0.75, ck->next_out = 1.0, ck->next_probe = 0.8, ck->next_checkpoint = 1.0;
  ck->checkpoint_every = 0.25;
  ck->step = 40, ck->reflected = 1;
  ck->picture_range[0] = 0, ck->picture_range[1] = 2e4;
  ck->probes_bytes = 123;
  ck->nsnap = 2, ck->snap_t = snap_t, ck->snap_n = snap_n;
  ck->scene_path = "/x/scene.yaml";
  ck->nsets = 1, ck->sets = (char **)sets;
  ck->params.n = 1, ck->params.keys = keys, ck->params.values = values;
  CU_ASSERT_FATAL(rhod_particles_init(p, 16) == RHOD_OK);
  p->n = NP;
  for (size_t i = 0; i < NP; i++) {
    p->x[i] = (real)(0.1 * (double)i), p->y[i] = (real)0.5;
    p->ux[i] = (real)0.25, p->uy[i] = (real)-0.5;
    p->rho[i] = (real)1000, p->m[i] = (real)0.01, p->dx[i] = (real)0.1;
    p->id[i] = i;
  }
  p->next_id = NP;
  rhod_particles_to_device(p);
}

/* Writes ck and p to ckpath and reads it back: the status, the message in err. */
static int round_trip(const rhod_checkpoint *ck, rhod_particles *p, char *err, size_t len) {
  char werr[512];
  rhod_particles_to_device(p);
  CU_ASSERT_FATAL(rhod_checkpoint_write(ckpath, ck, p, werr, sizeof werr) == RHOD_OK);
  rhod_particles_free(p);
  rhod_checkpoint back;
  err[0] = '\0';
  const int rc = rhod_checkpoint_read(ckpath, &back, err, len);
  rhod_checkpoint_free(&back);
  return rc;
}

/* The refusal names the file and the field. */
static void expect_field(int rc, const char *err, const char *field) {
  char want[64];
  snprintf(want, sizeof want, "field %s: ", field);
  CU_ASSERT_EQUAL(rc, RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, ckpath));
  CU_ASSERT_PTR_NOT_NULL(strstr(err, want));
  CU_ASSERT_PTR_NULL(strchr(err, '\n'));
  if (rc != RHOD_ERR_CHECKPOINT || !strstr(err, want))
    printf("\n  expected field %s, got %d: %s\n", field, rc, err);
}

static void test_good_reads(void) {
  rhod_checkpoint ck;
  rhod_particles p;
  char err[512];
  base(&ck, &p);
  CU_ASSERT_EQUAL(round_trip(&ck, &p, err, sizeof err), RHOD_OK);
  if (err[0])
    printf("\n  %s\n", err);
}

/* ---- the run state (through the writer, which recomputes the hash) ---- */

#define STATE_CASE(fn, field, stmt)                                                                \
  static void fn(void) {                                                                           \
    rhod_checkpoint ck;                                                                            \
    rhod_particles p;                                                                              \
    char err[512];                                                                                 \
    base(&ck, &p);                                                                                 \
    stmt;                                                                                          \
    expect_field(round_trip(&ck, &p, err, sizeof err), err, field);                                \
  }

STATE_CASE(test_nan_time, "t", ck.t = NAN)
STATE_CASE(test_negative_time, "t", ck.t = -1)
STATE_CASE(test_inf_next_out, "next_out", ck.next_out = INFINITY)
STATE_CASE(test_next_out_before_t, "next_out", ck.next_out = 0.1)
STATE_CASE(test_nan_next_probe, "next_probe", ck.next_probe = NAN)
STATE_CASE(test_inf_interval, "checkpoint_every", ck.checkpoint_every = INFINITY)
STATE_CASE(test_tiny_interval, "checkpoint_every", ck.checkpoint_every = 1e-300)
STATE_CASE(test_next_checkpoint_before_t, "next_checkpoint", ck.next_checkpoint = 0.5)
STATE_CASE(test_negative_step, "step", ck.step = -5)
STATE_CASE(test_negative_reflected, "reflected", ck.reflected = -1)
STATE_CASE(test_picture_range_reversed, "picture_range", ck.picture_range[0] = 3e4)
STATE_CASE(test_picture_range_half, "picture_range", ck.picture_range[1] = NAN)
STATE_CASE(test_absurd_probes_bytes, "probes_bytes", ck.probes_bytes = (uint64_t)1 << 50)
STATE_CASE(test_zero_probes_bytes, "probes_bytes", ck.probes_bytes = 0)
STATE_CASE(test_snapshot_after_t, "snap_t", snap_t[1] = 2.0)
STATE_CASE(test_snapshots_out_of_order, "snap_t", snap_t[0] = 0.6)

/* ---- the particles ---- */

STATE_CASE(test_zero_mass, "m", p.m[3] = 0)
STATE_CASE(test_negative_density, "rho", p.rho[0] = -1000)
STATE_CASE(test_nan_position, "x", p.x[5] = (real)NAN)
STATE_CASE(test_inf_velocity, "uy", p.uy[2] = (real)INFINITY)
STATE_CASE(test_zero_size, "dx", p.dx[1] = 0)
STATE_CASE(test_duplicate_ids, "id", p.id[4] = p.id[1])
STATE_CASE(test_id_at_next_id, "next_id", p.id[4] = NP + 3)
STATE_CASE(test_next_id_below_n, "next_id", p.next_id = 2)

/* ---- byte patches with the hash recomputed ---- */

static unsigned char *slurp(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fseek(f, 0, SEEK_END);
  *len = (size_t)ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *b = malloc(*len);
  CU_ASSERT_FATAL(b && fread(b, 1, *len, f) == *len);
  fclose(f);
  return b;
}

/* Overwrites n bytes at off and recomputes the FNV-1a hash at the end. */
static void patch(unsigned char *b, size_t len, size_t off, const void *v, size_t n) {
  memcpy(b + off, v, n);
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < len - 8; i++) {
    h ^= b[i];
    h *= 1099511628211ull;
  }
  memcpy(b + len - 8, &h, 8);
}

/* Offsets in a version-7 file without extras: magic 8, version 4, precision 4, then the
 * records (src/checkpoint.c: 7 eight-byte values, the picture range, nextra, then
 * probes_bytes). Versions 2 to 6 had RHOD-SPH's six counters after `reflected`. */
enum {
  OFF_VERSION = 8,
  OFF_T = 16,
  OFF_NEXT_OUT = 24,
  OFF_LEGACY = 72,
  OFF_NEXTRA = 88,
  OFF_PROBES_BYTES = 92,
  OFF_NSNAP = 100
};

static int parse_patched(size_t off, const void *v, size_t n, char *err, size_t len) {
  rhod_checkpoint ck;
  rhod_particles p;
  base(&ck, &p);
  char werr[512];
  CU_ASSERT_FATAL(rhod_checkpoint_write(ckpath, &ck, &p, werr, sizeof werr) == RHOD_OK);
  rhod_particles_free(&p);
  size_t blen;
  unsigned char *b = slurp(ckpath, &blen);
  patch(b, blen, off, v, n);
  rhod_checkpoint back;
  const int rc = rhod_checkpoint_parse(b, blen, ckpath, &back, err, len);
  rhod_checkpoint_free(&back);
  free(b);
  return rc;
}

static void test_patch_unchanged_reads(void) {
  char err[512];
  const double t = 0.75; /* the value already there: the patch helper itself is right */
  CU_ASSERT_EQUAL(parse_patched(OFF_T, &t, 8, err, sizeof err), RHOD_OK);
}

static void test_patch_nan_time(void) {
  char err[512];
  const double v = NAN;
  expect_field(parse_patched(OFF_T, &v, 8, err, sizeof err), err, "t");
}

static void test_patch_inf_next_out(void) {
  char err[512];
  const double v = INFINITY;
  expect_field(parse_patched(OFF_NEXT_OUT, &v, 8, err, sizeof err), err, "next_out");
}

static void test_patch_negative_nsnap(void) {
  char err[512];
  const int32_t v = -1;
  expect_field(parse_patched(OFF_NSNAP, &v, 4, err, sizeof err), err, "nsnap");
}

static void test_patch_absurd_probes_bytes(void) {
  char err[512];
  const uint64_t v = (uint64_t)1 << 40 << 1; /* 2 TiB, the "1 TB sparse file" */
  expect_field(parse_patched(OFF_PROBES_BYTES, &v, 8, err, sizeof err), err, "probes_bytes");
}

static void test_patch_huge_probes_bytes(void) {
  char err[512];
  const uint64_t v = UINT64_MAX; /* negative as an off_t */
  expect_field(parse_patched(OFF_PROBES_BYTES, &v, 8, err, sizeof err), err, "probes_bytes");
}

static void test_patch_too_many_extras(void) {
  char err[512];
  const int32_t v = RHOD_CK_MAX_EXTRAS + 1;
  expect_field(parse_patched(OFF_NEXTRA, &v, 4, err, sizeof err), err, "nextra");
}

/* A scheme's named scalars (version 6) come back by name and value, all RHOD_CK_MAX_EXTRAS
 * of them; a name of 32 bytes or more cannot be stored. */
static void test_extras_round_trip(void) {
  rhod_checkpoint ck;
  rhod_particles p;
  base(&ck, &p);
  ck.nextra = RHOD_CK_MAX_EXTRAS;
  for (int i = 0; i < ck.nextra; i++) {
    snprintf(ck.extra_name[i], sizeof ck.extra_name[i], "scalar_%d", i);
    ck.extra[i] = 0.5 + i;
  }
  char err[512];
  CU_ASSERT_FATAL(rhod_checkpoint_write(ckpath, &ck, &p, err, sizeof err) == RHOD_OK);
  rhod_particles_free(&p);
  rhod_checkpoint back;
  CU_ASSERT_EQUAL_FATAL(rhod_checkpoint_read(ckpath, &back, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(back.nextra, RHOD_CK_MAX_EXTRAS);
  for (int i = 0; i < back.nextra; i++) {
    char want[32];
    snprintf(want, sizeof want, "scalar_%d", i);
    CU_ASSERT_STRING_EQUAL(back.extra_name[i], want);
    CU_ASSERT_EQUAL(back.extra[i], 0.5 + i);
  }
  rhod_checkpoint_free(&back);
}

/* ---- older versions: RHOD-SPH's fixed counters come back as named extras ---- */

static void rehash(unsigned char *b, size_t len) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < len - 8; i++) {
    h ^= b[i];
    h *= 1099511628211ull;
  }
  memcpy(b + len - 8, &h, 8);
}

/* The counters of a version 2-6 file, in file order: i64 splits merges, f64 stiffness,
 * i64 absorbed, f64 ke_merged ke_absorbed. */
static const int64_t L_SPLITS = 17, L_MERGES = 3, L_ABSORBED = 5;
static const double L_STIFF = 2.5e3, L_KEM = 1.25e-4, L_KEA = -0.0;

/* A file of version `version` (2, 5 or 6) made from a version-7 one with `nextra` extras
 * (0 below version 6): the counters inserted after `reflected` (only splits and merges
 * in version 2), nextra dropped below 6, the picture range below 5. Parsed into back. */
static int parse_legacy(uint32_t version, int nextra, rhod_checkpoint *back, char *err,
                        size_t len) {
  rhod_checkpoint ck;
  rhod_particles p;
  base(&ck, &p);
  ck.nextra = nextra;
  for (int i = 0; i < nextra; i++) {
    snprintf(ck.extra_name[i], sizeof ck.extra_name[i], "own_%d", i);
    ck.extra[i] = 10.0 + i;
  }
  char werr[512];
  CU_ASSERT_FATAL(rhod_checkpoint_write(ckpath, &ck, &p, werr, sizeof werr) == RHOD_OK);
  rhod_particles_free(&p);
  size_t n7;
  unsigned char *b7 = slurp(ckpath, &n7);
  unsigned char legacy[48];
  memcpy(legacy, &L_SPLITS, 8), memcpy(legacy + 8, &L_MERGES, 8);
  memcpy(legacy + 16, &L_STIFF, 8), memcpy(legacy + 24, &L_ABSORBED, 8);
  memcpy(legacy + 32, &L_KEM, 8), memcpy(legacy + 40, &L_KEA, 8);
  const size_t nleg = version >= 4 ? 48 : 16;
  /* what follows `reflected` in version 7: the picture range (16), nextra (4) with the
   * extras, then the rest; versions below 6 have no nextra (kept at 0 here), below 5 no
   * picture range */
  const size_t skip = (version < 6 ? 4 : 0) + (version < 5 ? 16 : 0);
  CU_ASSERT_FATAL(version >= 6 || nextra == 0);
  unsigned char *b = malloc(n7 + nleg);
  CU_ASSERT_PTR_NOT_NULL_FATAL(b);
  size_t o = OFF_LEGACY;
  memcpy(b, b7, OFF_LEGACY); /* up to `reflected` */
  memcpy(b + o, legacy, nleg), o += nleg;
  if (version >= 5) { /* the picture range, right after `reflected` in version 7 */
    memcpy(b + o, b7 + OFF_LEGACY, 16);
    o += 16;
  }
  const size_t from = version >= 6 ? OFF_NEXTRA : OFF_PROBES_BYTES;
  memcpy(b + o, b7 + from, n7 - from), o += n7 - from;
  CU_ASSERT_EQUAL_FATAL(o, n7 + nleg - skip);
  memcpy(b + OFF_VERSION, &version, 4);
  rehash(b, o);
  const int rc = rhod_checkpoint_parse(b, o, ckpath, back, err, len);
  free(b);
  free(b7);
  return rc;
}

/* The extras from k on are the six counters, named as RHOD-SPH saves them. */
static void expect_legacy(const rhod_checkpoint *ck, int k, int version) {
  static const char *names[6] = {"splits",   "merges",    "stiffness",
                                 "absorbed", "ke_merged", "ke_absorbed"};
  const double want[6] = {(double)L_SPLITS,           (double)L_MERGES,
                          version >= 3 ? L_STIFF : 0, version >= 4 ? (double)L_ABSORBED : 0,
                          version >= 4 ? L_KEM : 0,   version >= 4 ? L_KEA : 0};
  CU_ASSERT_EQUAL_FATAL(ck->nextra, k + 6);
  for (int i = 0; i < 6; i++) {
    CU_ASSERT_STRING_EQUAL(ck->extra_name[k + i], names[i]);
    CU_ASSERT_STRING_EQUAL(ck->extra_name[k + i], rhod_ck_legacy_extra[i]);
    CU_ASSERT_EQUAL(ck->extra[k + i], want[i]);
  }
}

static void test_version6_counters(void) {
  rhod_checkpoint back;
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(parse_legacy(6, 2, &back, err, sizeof err), RHOD_OK);
  /* the file's own extras first, as written */
  CU_ASSERT_STRING_EQUAL(back.extra_name[0], "own_0");
  CU_ASSERT_EQUAL(back.extra[1], 11.0);
  expect_legacy(&back, 2, 6);
  CU_ASSERT_EQUAL(back.t, 0.75);
  CU_ASSERT_EQUAL(back.picture_range[1], 2e4);
  CU_ASSERT_EQUAL(back.n, (uint64_t)NP);
  rhod_checkpoint_free(&back);
}

static void test_version5_counters(void) {
  rhod_checkpoint back;
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(parse_legacy(5, 0, &back, err, sizeof err), RHOD_OK);
  expect_legacy(&back, 0, 5);
  CU_ASSERT_EQUAL(back.picture_range[1], 2e4);
  CU_ASSERT_EQUAL(back.probes_bytes, (uint64_t)123);
  rhod_checkpoint_free(&back);
}

static void test_version2_counters(void) {
  rhod_checkpoint back;
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(parse_legacy(2, 0, &back, err, sizeof err), RHOD_OK);
  expect_legacy(&back, 0, 2);
  CU_ASSERT(isnan(back.picture_range[0]) && isnan(back.picture_range[1]));
  CU_ASSERT_EQUAL(back.step, 40);
  rhod_checkpoint_free(&back);
}

/* A version-6 file whose own extras leave no room for the six: refused. */
static void test_version6_no_room(void) {
  rhod_checkpoint back;
  char err[512] = "";
  const int rc = parse_legacy(6, RHOD_CK_MAX_EXTRAS - 5, &back, err, sizeof err);
  CU_ASSERT_EQUAL(rc, RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "nextra"));
  /* one fewer fits */
  CU_ASSERT_EQUAL(parse_legacy(6, RHOD_CK_MAX_EXTRAS - 6, &back, err, sizeof err), RHOD_OK);
  expect_legacy(&back, RHOD_CK_MAX_EXTRAS - 6, 6);
  rhod_checkpoint_free(&back);
}

/* A version from the future: refused with one line. */
static void test_version_too_new(void) {
  char err[512] = "";
  const uint32_t v = 8;
  CU_ASSERT_EQUAL(parse_patched(OFF_VERSION, &v, 4, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "checkpoint version 8, this rhod reads 1 to 7"));
}

int main(void) {
  if (!mkdtemp(dir))
    return 2;
  snprintf(ckpath, sizeof ckpath, "%s/checkpoint.rhod", dir);
  static const rhod_test_case cases[] = {
      {"a healthy checkpoint reads", test_good_reads},
      {"NaN t", test_nan_time},
      {"negative t", test_negative_time},
      {"infinite next_out", test_inf_next_out},
      {"next_out before t", test_next_out_before_t},
      {"NaN next_probe", test_nan_next_probe},
      {"infinite checkpoint interval", test_inf_interval},
      {"checkpoint interval below the clock's resolution", test_tiny_interval},
      {"next_checkpoint before t", test_next_checkpoint_before_t},
      {"negative step", test_negative_step},
      {"negative reflection count", test_negative_reflected},
      {"picture range reversed", test_picture_range_reversed},
      {"picture range half unset", test_picture_range_half},
      {"absurd probes.csv length", test_absurd_probes_bytes},
      {"zero probes.csv length", test_zero_probes_bytes},
      {"snapshot after t", test_snapshot_after_t},
      {"snapshots out of order", test_snapshots_out_of_order},
      {"zero mass", test_zero_mass},
      {"negative density", test_negative_density},
      {"NaN position", test_nan_position},
      {"infinite velocity", test_inf_velocity},
      {"zero particle size", test_zero_size},
      {"duplicate ids", test_duplicate_ids},
      {"an id not below next_id", test_id_at_next_id},
      {"next_id below the particle count", test_next_id_below_n},
      {"patch helper: unchanged bytes read", test_patch_unchanged_reads},
      {"patched: NaN t", test_patch_nan_time},
      {"patched: infinite next_out", test_patch_inf_next_out},
      {"patched: negative nsnap", test_patch_negative_nsnap},
      {"patched: 2 TiB probes.csv", test_patch_absurd_probes_bytes},
      {"patched: probes.csv length 2^64-1", test_patch_huge_probes_bytes},
      {"patched: more extras than a checkpoint holds", test_patch_too_many_extras},
      {"a scheme's named scalars round trip", test_extras_round_trip},
      {"version 6: the fixed counters as named extras", test_version6_counters},
      {"version 5: the fixed counters as named extras", test_version5_counters},
      {"version 2: splits and merges, the rest 0", test_version2_counters},
      {"version 6: no room left for the counters", test_version6_no_room},
      {"a version from the future refused", test_version_too_new},
  };
  const int rc = RHOD_RUN_TESTS("checkpoint validation", cases);
  unlink(ckpath);
  rmdir(dir);
  return rc;
}
