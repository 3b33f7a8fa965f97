/* The particle store's append and compaction (src/particles.c): appended particles are
 * copies of their sources in every persistent registered field (the engine's, the tags and
 * a scheme's, of any width) with new consecutive ids from next_id; compaction removes the
 * unflagged particles and keeps the others, and those after the flags, in order with every
 * field. Both run where the particles live (the kernels also run in the offload build). */
#include "cunit_main.h"
#include "rhod/particles.h"
#include "rhod/status.h"

#include <stdio.h>
#include <string.h>

#define N0 6
#define CAP 32

/* A scheme's fields: one real (persistent), three bytes per particle (persistent, the
 * byte-wise copy) and a scratch real. */
static real *sf;
static unsigned char *s3;
static real *scr;

/* A store of N0 particles, every persistent field distinct per particle, ids not in order. */
static void make(rhod_particles *p) {
  CU_ASSERT_EQUAL_FATAL(rhod_particles_init(p, CAP), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_particles_add_tags(p), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_particles_add_field(p, "sf", (void **)&sf, sizeof(real), 1), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_particles_add_field(p, "s3", (void **)&s3, 3, 1), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_particles_add_field(p, "scr", (void **)&scr, sizeof(real), 0),
                        RHOD_OK);
  static const uint64_t ids[N0] = {3, 7, 1, 0, 9, 4};
  for (int i = 0; i < N0; i++) {
    p->x[i] = (real)(0.5 + i), p->y[i] = (real)(10.25 + i), p->ux[i] = (real)(-1 - i);
    p->uy[i] = (real)(2 * i), p->rho[i] = (real)(1000 + i), p->m[i] = (real)(0.01 * (i + 1));
    p->dx[i] = (real)(0.1 / (i + 1)), p->id[i] = ids[i];
    p->phase[i] = (uint8_t)(i % 2), p->kind[i] = (uint8_t)(10 + i), p->level[i] = (uint8_t)(20 + i);
    sf[i] = (real)(-7.5 * i);
    for (int b = 0; b < 3; b++)
      s3[3 * i + b] = (unsigned char)(16 * i + b + 1);
  }
  p->n = N0;
  p->next_id = 12;
  rhod_particles_to_device(p);
}

/* A copy of every persistent field of particle i: byte arrays laid end to end. */
typedef struct {
  unsigned char b[256];
  size_t len;
} record;

static record rec(const rhod_particles *p, size_t i, int with_id) {
  record r = {{0}, 0};
  for (int f = 0; f < p->nfields; f++) {
    const rhod_field_desc *d = &p->fields[f];
    if (d->persistent != 1 || (!with_id && !strcmp(d->name, "id")))
      continue;
    memcpy(r.b + r.len, (const unsigned char *)*d->ptr + i * d->elem, d->elem);
    r.len += d->elem;
  }
  return r;
}

static int same(const record *a, const record *b) {
  return a->len == b->len && !memcmp(a->b, b->b, a->len);
}

/* The persistent fields the store registers: the engine's 8, 3 tags, the scheme's 2. */
static void test_fields_counted(void) {
  rhod_particles p;
  make(&p);
  int np = 0;
  for (int f = 0; f < p.nfields; f++)
    np += p.fields[f].persistent == 1;
  CU_ASSERT_EQUAL(np, 13);
  rhod_particles_free(&p);
}

static void test_append_new_ids(void) {
  rhod_particles p;
  make(&p);
  record before[N0];
  for (int i = 0; i < N0; i++)
    before[i] = rec(&p, (size_t)i, 1);
  /* sources on the device, as a kernel writes them (p->perm) */
  const int32_t src[4] = {4, 1, 1, 0};
  rhod_to_host(p.perm, N0 * sizeof(int32_t));
  memcpy(p.perm, src, sizeof src);
  rhod_to_device(p.perm, sizeof src);
  p.ng = 5;
  rhod_particles_append(&p, p.perm, 4);
  rhod_particles_to_host(&p);
  CU_ASSERT_EQUAL(p.n, (size_t)N0 + 4);
  CU_ASSERT_EQUAL(p.ng, 0);
  CU_ASSERT_EQUAL(p.next_id, (uint64_t)16);
  for (int i = 0; i < N0; i++) { /* the old ones untouched */
    const record r = rec(&p, (size_t)i, 1);
    CU_ASSERT(same(&r, &before[i]));
  }
  for (int k = 0; k < 4; k++) {
    const size_t c = (size_t)N0 + (size_t)k;
    /* the new id, in order from the old next_id */
    CU_ASSERT_EQUAL(p.id[c], (uint64_t)(12 + k));
    /* every other persistent field its source's */
    const record a = rec(&p, c, 0), b = rec(&p, (size_t)src[k], 0);
    CU_ASSERT(same(&a, &b));
  }
  /* a second append goes on from there */
  rhod_to_host(p.perm, sizeof(int32_t));
  p.perm[0] = 9; /* the copy of a copy */
  rhod_to_device(p.perm, sizeof(int32_t));
  rhod_particles_append(&p, p.perm, 1);
  rhod_particles_to_host(&p);
  CU_ASSERT_EQUAL(p.id[N0 + 4], (uint64_t)16);
  CU_ASSERT_EQUAL(p.next_id, (uint64_t)17);
  const record a = rec(&p, N0 + 4, 0), b = rec(&p, 0, 0);
  CU_ASSERT(same(&a, &b));
  rhod_particles_free(&p);
}

/* Flags over [0, nflag) with values other than 1 (any non-zero keeps), the rest kept. */
static void compact_case(size_t nflag, const int32_t *flags, const int *want, size_t nwant) {
  rhod_particles p;
  make(&p);
  const int32_t src[2] = {2, 5}; /* two appended particles, kept after the flagged ones */
  rhod_to_host(p.perm, 2 * sizeof(int32_t));
  memcpy(p.perm, src, sizeof src);
  rhod_to_device(p.perm, sizeof src);
  rhod_particles_append(&p, p.perm, 2);
  rhod_particles_to_host(&p);
  record before[N0 + 2];
  for (size_t i = 0; i < p.n; i++)
    before[i] = rec(&p, i, 1);
  int32_t *keep = rhod_dev_calloc(N0 + 3, sizeof(int32_t));
  CU_ASSERT_PTR_NOT_NULL_FATAL(keep);
  memcpy(keep, flags, nflag * sizeof(int32_t));
  keep[nflag] = 77; /* garbage where the scan's end goes */
  rhod_to_device(keep, (N0 + 3) * sizeof(int32_t));
  p.ng = 3;
  const long n = rhod_particles_compact(&p, keep, nflag);
  CU_ASSERT_EQUAL(n, (long)nwant);
  CU_ASSERT_EQUAL(p.n, nwant);
  CU_ASSERT_EQUAL(p.ng, 0);
  CU_ASSERT_EQUAL(p.next_id, (uint64_t)14);
  rhod_particles_to_host(&p);
  for (size_t k = 0; k < nwant && k < p.n; k++) {
    const record r = rec(&p, k, 1);
    CU_ASSERT(same(&r, &before[want[k]]));
    if (!same(&r, &before[want[k]]))
      printf("\n  slot %zu: not particle %d\n", k, want[k]);
  }
  /* the flags became the kept particles' new slots */
  rhod_to_host(keep, (N0 + 3) * sizeof(int32_t));
  int32_t slot = 0;
  for (size_t i = 0; i < nflag; i++) {
    CU_ASSERT_EQUAL(keep[i], slot);
    slot += flags[i] != 0;
  }
  rhod_dev_free(keep, (N0 + 3) * sizeof(int32_t));
  rhod_particles_free(&p);
}

static void test_compact_prefix(void) {
  /* the flags cover the first N0; particles N0, N0 + 1 (the appended) stay behind */
  const int32_t flags[N0] = {1, 0, 3, 1, 0, 1};
  const int want[] = {0, 2, 3, 5, N0, N0 + 1};
  compact_case(N0, flags, want, sizeof want / sizeof want[0]);
}

static void test_compact_all_flagged(void) {
  const int32_t flags[N0 + 2] = {0, 1, 1, 0, 0, 1, 0, 1};
  const int want[] = {1, 2, 5, N0 + 1};
  compact_case(N0 + 2, flags, want, sizeof want / sizeof want[0]);
}

static void test_compact_none_flagged(void) {
  const int32_t flags[1] = {0};
  const int want[] = {0, 1, 2, 3, 4, 5, N0, N0 + 1};
  compact_case(0, flags, want, sizeof want / sizeof want[0]);
}

static void test_compact_drop_all(void) {
  const int32_t flags[N0 + 2] = {0};
  compact_case(N0 + 2, flags, NULL, 0);
}

/* More flags than particles: refused, the store unchanged. */
static void test_compact_too_many_flags(void) {
  rhod_particles p;
  make(&p);
  int32_t *keep = rhod_dev_calloc(N0 + 2, sizeof(int32_t));
  CU_ASSERT_EQUAL(rhod_particles_compact(&p, keep, N0 + 1), -1);
  CU_ASSERT_EQUAL(p.n, (size_t)N0);
  rhod_particles_to_host(&p);
  CU_ASSERT_EQUAL(p.id[1], (uint64_t)7);
  rhod_dev_free(keep, (N0 + 2) * sizeof(int32_t));
  rhod_particles_free(&p);
}

int main(void) {
  static const rhod_test_case cases[] = {
      {"the store's persistent fields", test_fields_counted},
      {"append: copies of every persistent field, new consecutive ids", test_append_new_ids},
      {"compact: flagged prefix, the rest kept in order", test_compact_prefix},
      {"compact: every particle flagged", test_compact_all_flagged},
      {"compact: no flags, all kept", test_compact_none_flagged},
      {"compact: all dropped", test_compact_drop_all},
      {"compact: more flags than particles refused", test_compact_too_many_flags},
  };
  return RHOD_RUN_TESTS("particle store: append and compaction", cases);
}
