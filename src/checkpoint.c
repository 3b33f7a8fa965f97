/* Checkpoint writing and reading (checkpoint.h). Records in order:
 *   "RHODCKP1" u32 version u32 sizeof(real)
 *   f64 t next_out next_probe next_checkpoint checkpoint_every
 *   i64 step reflected
 *   versions 2 to 6 only: i64 splits merges (version 2), f64 stiffness (version 3),
 *     i64 absorbed, f64 ke_merged ke_absorbed (version 4): RHOD-SPH's counters, read as
 *     extras (checkpoint.h); version 7 has them among the extras RHOD-SPH saves
 *   f64 picture_range[2] (version 5; NaN NaN: no range fixed yet)
 *   i32 nextra, (str name, f64 value)[nextra] (version 6: the scheme's scalars)
 *   u64 probes_bytes   i32 nsnap, f64[nsnap] times, u64[nsnap] counts
 *   str scene_path   i32 nsets, str[nsets]   u32 nparams, (str key, str value)[nparams]
 *   u64 n next_id   i32 nfields, per field: str name, u64 elem, elem * n bytes
 *   u64 FNV-1a hash of all the bytes above
 * where str is a u32 length and that many bytes (no terminator). The reader checks every
 * count against the bytes left, so a damaged or hostile file fails with a message. */
#include "rhod/checkpoint.h"
#include "rhod/io.h"
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CK_MAGIC "RHODCKP1"
/* 2: the split and merge totals; 3: the stiffness limit's measure; 4: the absorbed
 * stragglers' total and the energy coalescing took out; 5: the pictures' colour range
 * fixed at the first picture; 6: the scheme's named scalars; 7: the counters of 2 to 4
 * among them (the engine knows no scheme's counters); 1 to 6 are still read */
#define CK_VERSION 7u

const char *const rhod_ck_legacy_extra[RHOD_CK_LEGACY_EXTRAS] = {
    "splits", "merges", "stiffness", "absorbed", "ke_merged", "ke_absorbed"};
#define CK_MAX_COUNT 100000000u /* sanity bound on any count (particles, strings, ...) */
#define CK_MAX_PROBES_BYTES ((uint64_t)1 << 40) /* probes.csv: 1 TiB */

static uint64_t fnv1a(const unsigned char *b, size_t n) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < n; i++) {
    h ^= b[i];
    h *= 1099511628211ull;
  }
  return h;
}

/* ------------------------------------------------------------------ writing */

typedef struct {
  unsigned char *b;
  size_t len, cap;
  int oom;
} buf;

static void put(buf *w, const void *src, size_t n) {
  if (w->oom || n == 0) /* nothing to copy (src may then be NULL: an empty string, no particles) */
    return;
  if (w->len + n > w->cap) {
    size_t cap = 2 * w->cap + n + 4096;
    unsigned char *b = realloc(w->b, cap);
    if (!b) {
      w->oom = 1;
      return;
    }
    w->b = b, w->cap = cap;
  }
  memcpy(w->b + w->len, src, n);
  w->len += n;
}

static void put_u32(buf *w, uint32_t v) { put(w, &v, sizeof v); }
static void put_i32(buf *w, int32_t v) { put(w, &v, sizeof v); }
static void put_u64(buf *w, uint64_t v) { put(w, &v, sizeof v); }
static void put_i64(buf *w, int64_t v) { put(w, &v, sizeof v); }
static void put_f64(buf *w, double v) { put(w, &v, sizeof v); }
static void put_str(buf *w, const char *s) {
  const size_t n = s ? strlen(s) : 0;
  put_u32(w, (uint32_t)n);
  put(w, s, n);
}

int rhod_checkpoint_write(const char *path, const rhod_checkpoint *ck, rhod_particles *p, char *err,
                          size_t errlen) {
  buf w = {0};
  put(&w, CK_MAGIC, 8);
  put_u32(&w, CK_VERSION);
  put_u32(&w, (uint32_t)sizeof(real));
  put_f64(&w, ck->t);
  put_f64(&w, ck->next_out);
  put_f64(&w, ck->next_probe);
  put_f64(&w, ck->next_checkpoint);
  put_f64(&w, ck->checkpoint_every);
  put_i64(&w, ck->step);
  put_i64(&w, ck->reflected);
  put_f64(&w, ck->picture_range[0]);
  put_f64(&w, ck->picture_range[1]);
  put_i32(&w, ck->nextra);
  for (int i = 0; i < ck->nextra; i++) {
    put_str(&w, ck->extra_name[i]);
    put_f64(&w, ck->extra[i]);
  }
  put_u64(&w, ck->probes_bytes);
  put_i32(&w, ck->nsnap);
  put(&w, ck->snap_t, sizeof(double) * (size_t)ck->nsnap);
  put(&w, ck->snap_n, sizeof(uint64_t) * (size_t)ck->nsnap);
  put_str(&w, ck->scene_path);
  put_i32(&w, ck->nsets);
  for (int i = 0; i < ck->nsets; i++)
    put_str(&w, ck->sets[i]);
  put_u32(&w, ck->params.n);
  for (unsigned i = 0; i < ck->params.n; i++) {
    put_str(&w, ck->params.keys[i]);
    put_str(&w, ck->params.values[i]);
  }
  put_u64(&w, p->n);
  put_u64(&w, p->next_id);
  int32_t nf = 0;
  for (int f = 0; f < p->nfields; f++)
    nf += p->fields[f].persistent == 1;
  put_i32(&w, nf);
  for (int f = 0; f < p->nfields; f++) {
    const rhod_field_desc *d = &p->fields[f];
    if (d->persistent != 1)
      continue;
    rhod_to_host(*d->ptr, p->n * d->elem);
    put_str(&w, d->name);
    put_u64(&w, d->elem);
    put(&w, *d->ptr, p->n * d->elem);
  }
  if (!w.oom)
    put_u64(&w, fnv1a(w.b, w.len));
  int rc;
  if (w.oom) {
    snprintf(err, errlen, "%s: cannot write: out of memory", path);
    rc = RHOD_ERR_MEMORY;
  } else {
    rc = rhod_write_bytes_atomic(path, w.b, w.len, err, errlen);
  }
  free(w.b);
  return rc;
}

/* ------------------------------------------------------------------ reading */

typedef struct {
  const unsigned char *b;
  size_t len, pos;
  int bad;
  const char *what; /* the first record that did not fit */
} rd;

static void get(rd *r, void *dst, size_t n, const char *what) {
  if (r->bad)
    return;
  if (n > r->len - r->pos) {
    r->bad = 1;
    r->what = what;
    return;
  }
  memcpy(dst, r->b + r->pos, n);
  r->pos += n;
}

static uint32_t get_count(rd *r, const char *what) {
  uint32_t v = 0;
  get(r, &v, sizeof v, what);
  if (!r->bad && v > CK_MAX_COUNT) {
    r->bad = 1;
    r->what = what;
    return 0;
  }
  return v;
}

static char *get_str(rd *r, const char *what) {
  if (r->bad) /* keep the first record that did not fit */
    return NULL;
  const uint32_t n = get_count(r, what);
  if (r->bad)
    return NULL;
  if (n > r->len - r->pos) {
    r->bad = 1;
    r->what = what;
    return NULL;
  }
  char *s = malloc((size_t)n + 1);
  if (!s) {
    r->bad = 2;
    return NULL;
  }
  memcpy(s, r->b + r->pos, n);
  s[n] = 0;
  r->pos += n;
  if (strlen(s) != n) { /* an embedded NUL */
    r->bad = 1;
    r->what = what;
  }
  return s;
}

static void *get_array(rd *r, uint64_t count, size_t elem, const char *what) {
  if (r->bad)
    return NULL;
  if (count > CK_MAX_COUNT || (elem && count > (r->len - r->pos) / elem)) {
    r->bad = 1;
    r->what = what;
    return NULL;
  }
  const size_t bytes = (size_t)count * elem;
  void *a = malloc(bytes ? bytes : 1);
  if (!a) {
    r->bad = 2;
    return NULL;
  }
  get(r, a, bytes, what);
  return a;
}

static int read_fail(char *err, size_t errlen, const char *path, const char *fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  snprintf(err, errlen, "%s: %s", path, msg);
  return RHOD_ERR_CHECKPOINT;
}

/* ------------------------------------------------------------------ validation */

/* A checksum only says the bytes are as written; a file written (or rewritten with a new
 * checksum) by anything else must still not resume into NaN times, an endless catch-up
 * loop, zero masses or a probes.csv padded to a terabyte. Every field is range-checked;
 * the message names it: "path: field NAME: reason". */
static int bad_field(char *err, size_t errlen, const char *path, const char *field, const char *fmt,
                     ...) {
  char msg[400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  snprintf(err, errlen, "%s: field %s: %s", path, field, msg);
  return RHOD_ERR_CHECKPOINT;
}

/* A clock value: finite and >= 0. */
static int bad_time(double v) { return !(v >= 0 && v < HUGE_VAL); }

/* The clock after adding step to v moves (a step below v's resolution would make the
 * run's "advance to the next output" loop endless). */
static int too_fine(double v, double step) { return !(v + step > v); }

static int cmp_u64(const void *a, const void *b) {
  const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

/* The engine's own fields (particles.c): the real-valued ones are finite, the mass,
 * density and size positive; ids unique and below next_id. */
static int validate_particles(const rhod_checkpoint *ck, const char *path, char *err,
                              size_t errlen) {
  static const struct {
    const char *name;
    int positive;
  } reals[] = {{"x", 0}, {"y", 0}, {"ux", 0}, {"uy", 0}, {"rho", 1}, {"m", 1}, {"dx", 1}};
  for (int f = 0; f < ck->nfields; f++) {
    const char *name = ck->fname[f];
    if (!strcmp(name, "id")) {
      if (ck->felem[f] != sizeof(uint64_t))
        return bad_field(err, errlen, path, name, "%llu bytes per particle, expected %zu",
                         (unsigned long long)ck->felem[f], sizeof(uint64_t));
      const uint64_t *id = ck->fdata[f];
      uint64_t *sorted = malloc(sizeof(uint64_t) * (size_t)(ck->n ? ck->n : 1));
      if (!sorted) {
        snprintf(err, errlen, "%s: out of memory", path);
        return RHOD_ERR_MEMORY;
      }
      memcpy(sorted, id, sizeof(uint64_t) * (size_t)ck->n);
      qsort(sorted, (size_t)ck->n, sizeof(uint64_t), cmp_u64);
      int rc = RHOD_OK;
      for (uint64_t i = 1; i < ck->n && rc == RHOD_OK; i++)
        if (sorted[i] == sorted[i - 1])
          rc = bad_field(err, errlen, path, name, "id %llu appears more than once",
                         (unsigned long long)sorted[i]);
      if (rc == RHOD_OK && ck->n > 0 && sorted[ck->n - 1] >= ck->next_id)
        rc = bad_field(err, errlen, path, "next_id", "%llu, not above the largest id %llu",
                       (unsigned long long)ck->next_id, (unsigned long long)sorted[ck->n - 1]);
      free(sorted);
      if (rc != RHOD_OK)
        return rc;
      continue;
    }
    for (size_t k = 0; k < sizeof reals / sizeof reals[0]; k++) {
      if (strcmp(name, reals[k].name) != 0)
        continue;
      if (ck->felem[f] != sizeof(real))
        return bad_field(err, errlen, path, name, "%llu bytes per particle, expected %zu",
                         (unsigned long long)ck->felem[f], sizeof(real));
      const real *v = ck->fdata[f];
      for (uint64_t i = 0; i < ck->n; i++) {
        const double x = (double)v[i];
        if (!isfinite(x))
          return bad_field(err, errlen, path, name, "particle %llu: not a finite number",
                           (unsigned long long)i);
        if (reals[k].positive && !(x > 0))
          return bad_field(err, errlen, path, name, "particle %llu: %g, must be > 0",
                           (unsigned long long)i, x);
      }
    }
  }
  return RHOD_OK;
}

static int validate(const rhod_checkpoint *ck, const char *path, char *err, size_t errlen) {
  const double t = ck->t;
  if (bad_time(t))
    return bad_field(err, errlen, path, "t", "%g, must be a finite time >= 0", t);
  const struct {
    const char *name;
    double v;
  } next[] = {{"next_out", ck->next_out}, {"next_probe", ck->next_probe}};
  for (int i = 0; i < 2; i++) {
    if (bad_time(next[i].v))
      return bad_field(err, errlen, path, next[i].name, "%g, must be a finite time >= 0",
                       next[i].v);
    if (next[i].v < t)
      return bad_field(err, errlen, path, next[i].name, "%.17g, before the time t = %.17g",
                       next[i].v, t);
  }
  const double every = ck->checkpoint_every, nck = ck->next_checkpoint;
  if (bad_time(every))
    return bad_field(err, errlen, path, "checkpoint_every", "%g, must be a finite time >= 0",
                     every);
  if (bad_time(nck))
    return bad_field(err, errlen, path, "next_checkpoint", "%g, must be a finite time >= 0", nck);
  if (every > 0 && nck < t)
    return bad_field(err, errlen, path, "next_checkpoint", "%.17g, before the time t = %.17g", nck,
                     t);
  if (every > 0 && too_fine(nck, every))
    return bad_field(err, errlen, path, "checkpoint_every",
                     "%g, too small to advance the clock from %g", every, nck);
  const struct {
    const char *name;
    int64_t v;
  } counts[] = {{"step", ck->step}, {"reflected", ck->reflected}};
  for (int i = 0; i < 2; i++)
    if (counts[i].v < 0)
      return bad_field(err, errlen, path, counts[i].name, "%lld, must be >= 0",
                       (long long)counts[i].v);
  /* the scheme's scalars: its load judges their values */
  const double *pr = ck->picture_range;
  if (!(isnan(pr[0]) && isnan(pr[1])) && !(isfinite(pr[0]) && isfinite(pr[1]) && pr[0] < pr[1]))
    return bad_field(err, errlen, path, "picture_range",
                     "neither unset (NaN, NaN) nor finite with low < high");
  /* the header line at least; at most 1 TiB (a longer probes.csv is not a real run's) */
  if (ck->probes_bytes < 2 || ck->probes_bytes > CK_MAX_PROBES_BYTES)
    return bad_field(err, errlen, path, "probes_bytes", "%llu, must be 2 to %llu",
                     (unsigned long long)ck->probes_bytes, (unsigned long long)CK_MAX_PROBES_BYTES);
  if (ck->nsnap < 0)
    return bad_field(err, errlen, path, "nsnap", "%d, must be >= 0", (int)ck->nsnap);
  for (int32_t i = 0; i < ck->nsnap; i++) {
    const double ts = ck->snap_t[i];
    if (bad_time(ts) || ts > t)
      return bad_field(err, errlen, path, "snap_t", "snapshot %d at %g, must be 0 to t = %g",
                       (int)i, ts, t);
    if (i > 0 && ts < ck->snap_t[i - 1])
      return bad_field(err, errlen, path, "snap_t", "snapshot %d at %g, before snapshot %d", (int)i,
                       ts, (int)i - 1);
    if (ck->snap_n[i] > CK_MAX_COUNT)
      return bad_field(err, errlen, path, "snap_n", "snapshot %d: %llu particles, at most %u",
                       (int)i, (unsigned long long)ck->snap_n[i], CK_MAX_COUNT);
  }
  if (ck->n > CK_MAX_COUNT)
    return bad_field(err, errlen, path, "n", "%llu particles, at most %u",
                     (unsigned long long)ck->n, CK_MAX_COUNT);
  if (ck->next_id < ck->n)
    return bad_field(err, errlen, path, "next_id", "%llu, fewer than the %llu particles",
                     (unsigned long long)ck->next_id, (unsigned long long)ck->n);
  return validate_particles(ck, path, err, errlen);
}

static int parse(rd *r, rhod_checkpoint *ck, const char *path, char *err, size_t errlen) {
  char magic[8];
  uint32_t version = 0, rsize = 0;
  get(r, magic, 8, "magic");
  if (r->bad || memcmp(magic, CK_MAGIC, 8) != 0)
    return read_fail(err, errlen, path, "not an rhod checkpoint");
  get(r, &version, 4, "version");
  get(r, &rsize, 4, "precision");
  if (r->bad)
    return read_fail(err, errlen, path, "truncated header");
  if (version < 1 || version > CK_VERSION)
    return read_fail(err, errlen, path, "checkpoint version %u, this rhod reads 1 to %u", version,
                     CK_VERSION);
  if (rsize != sizeof(real))
    return read_fail(err, errlen, path, "written by a %s-precision build, this one is %s",
                     rsize == 4 ? "single" : "double", RHOD_REAL_NAME);
  get(r, &ck->t, 8, "t");
  get(r, &ck->next_out, 8, "next_out");
  get(r, &ck->next_probe, 8, "next_probe");
  get(r, &ck->next_checkpoint, 8, "next_checkpoint");
  get(r, &ck->checkpoint_every, 8, "checkpoint_every");
  get(r, &ck->step, 8, "step");
  get(r, &ck->reflected, 8, "reflected");
  /* versions 2 to 6: RHOD-SPH's counters in fixed fields, kept for the extras below */
  int64_t splits = 0, merges = 0, absorbed = 0;
  double stiffness = 0, ke_merged = 0, ke_absorbed = 0;
  if (version >= 2 && version < 7) {
    get(r, &splits, 8, "splits");
    get(r, &merges, 8, "merges");
  }
  if (version >= 3 && version < 7)
    get(r, &stiffness, 8, "stiffness");
  if (version >= 4 && version < 7) {
    get(r, &absorbed, 8, "absorbed");
    get(r, &ke_merged, 8, "ke_merged");
    get(r, &ke_absorbed, 8, "ke_absorbed");
  }
  ck->picture_range[0] = ck->picture_range[1] = NAN;
  if (version >= 5) {
    get(r, &ck->picture_range[0], 8, "picture_range");
    get(r, &ck->picture_range[1], 8, "picture_range");
  }
  if (version >= 6) {
    get(r, &ck->nextra, 4, "nextra");
    if (!r->bad && (ck->nextra < 0 || ck->nextra > RHOD_CK_MAX_EXTRAS)) {
      r->bad = 1;
      r->what = "nextra";
    }
    for (int i = 0; i < ck->nextra && !r->bad; i++) {
      char *name = get_str(r, "extra name");
      if (!r->bad && (!name || strlen(name) >= sizeof ck->extra_name[i])) {
        r->bad = 1;
        r->what = "extra name";
      }
      if (!r->bad)
        strcpy(ck->extra_name[i], name);
      free(name);
      get(r, &ck->extra[i], 8, "extra value");
    }
  }
  if (version < 7 && !r->bad) {
    /* the fixed fields as the extras RHOD-SPH saves since version 7 (in the order of
     * rhod_ck_legacy_extra), after the file's own */
    const double v[RHOD_CK_LEGACY_EXTRAS] = {(double)splits,   (double)merges, stiffness,
                                             (double)absorbed, ke_merged,      ke_absorbed};
    if (ck->nextra > RHOD_CK_MAX_EXTRAS - RHOD_CK_LEGACY_EXTRAS) {
      r->bad = 1;
      r->what = "nextra";
    }
    for (int i = 0; i < RHOD_CK_LEGACY_EXTRAS && !r->bad; i++) {
      snprintf(ck->extra_name[ck->nextra], sizeof ck->extra_name[0], "%s", rhod_ck_legacy_extra[i]);
      ck->extra[ck->nextra++] = v[i];
    }
  }
  get(r, &ck->probes_bytes, 8, "probes_bytes");
  ck->nsnap = (int32_t)get_count(r, "nsnap");
  ck->snap_t = get_array(r, (uint64_t)ck->nsnap, sizeof(double), "snap_t");
  ck->snap_n = get_array(r, (uint64_t)ck->nsnap, sizeof(uint64_t), "snap_n");
  ck->scene_path = get_str(r, "scene_path");
  ck->nsets = (int32_t)get_count(r, "nsets");
  /* every string takes at least its 4-byte length: bound counts by the bytes left
   * before allocating (a hostile count must not cost memory) */
  if (!r->bad && (size_t)ck->nsets > (r->len - r->pos) / 4) {
    r->bad = 1;
    r->what = "nsets";
  }
  if (!r->bad && !(ck->sets = calloc((size_t)ck->nsets + 1, sizeof(char *))))
    r->bad = 2;
  for (int i = 0; i < ck->nsets && !r->bad && ck->sets; i++)
    ck->sets[i] = get_str(r, "sets");
  const uint32_t np = get_count(r, "nparams");
  if (!r->bad && np > (r->len - r->pos) / 8) {
    r->bad = 1;
    r->what = "nparams";
  }
  if (!r->bad) {
    ck->params.keys = calloc((size_t)np + 1, sizeof(char *));
    ck->params.values = calloc((size_t)np + 1, sizeof(char *));
    if (!ck->params.keys || !ck->params.values)
      r->bad = 2;
  }
  for (uint32_t i = 0; i < np && !r->bad; i++) {
    ck->params.keys[i] = get_str(r, "param key");
    ck->params.values[i] = get_str(r, "param value");
    ck->params.n = i + 1;
  }
  get(r, &ck->n, 8, "n");
  get(r, &ck->next_id, 8, "next_id");
  ck->nfields = (int32_t)get_count(r, "nfields");
  if (!r->bad && ck->nfields > RHOD_MAX_FIELDS) {
    r->bad = 1;
    r->what = "nfields";
  }
  if (!r->bad) {
    ck->fname = calloc((size_t)ck->nfields + 1, sizeof(char *));
    ck->felem = calloc((size_t)ck->nfields + 1, sizeof(uint64_t));
    ck->fdata = calloc((size_t)ck->nfields + 1, sizeof(void *));
    if (!ck->fname || !ck->felem || !ck->fdata)
      r->bad = 2;
  }
  for (int f = 0; f < ck->nfields && !r->bad; f++) {
    ck->fname[f] = get_str(r, "field name");
    get(r, &ck->felem[f], 8, "field elem");
    if (!r->bad && (ck->felem[f] == 0 || ck->felem[f] > 4096)) {
      r->bad = 1;
      r->what = "field elem";
      break;
    }
    ck->fdata[f] = get_array(r, ck->n, (size_t)ck->felem[f], "field data");
  }
  if (r->bad == 2) {
    snprintf(err, errlen, "%s: out of memory", path);
    return RHOD_ERR_MEMORY;
  }
  if (r->bad)
    return read_fail(err, errlen, path, "damaged: field %s: does not fit in the file", r->what);
  if (r->len - r->pos != 8)
    return read_fail(err, errlen, path, "damaged: the checksum is missing or not at the end");
  uint64_t h;
  memcpy(&h, r->b + r->pos, 8);
  if (h != fnv1a(r->b, r->pos))
    return read_fail(err, errlen, path, "damaged: checksum mismatch");
  return validate(ck, path, err, errlen);
}

int rhod_checkpoint_read(const char *path, rhod_checkpoint *ck, char *err, size_t errlen) {
  memset(ck, 0, sizeof *ck);
  char *b = NULL;
  size_t len = 0;
  const size_t max =
      RHOD_CHECKPOINT_MAX_BYTES < SIZE_MAX / 2 ? (size_t)RHOD_CHECKPOINT_MAX_BYTES : SIZE_MAX / 2;
  const int e = rhod_read_file(path, max, &b, &len);
  if (e == ENOMEM) {
    snprintf(err, errlen, "%s: out of memory", path);
    return RHOD_ERR_MEMORY;
  }
  if (e == RHOD_READ_TOO_LARGE)
    return read_fail(err, errlen, path, "cannot read the checkpoint: larger than %llu GiB",
                     (unsigned long long)(max >> 30));
  if (e)
    return read_fail(err, errlen, path, "cannot read the checkpoint: %s", rhod_read_strerror(e));
  int rc = rhod_checkpoint_parse(b, len, path, ck, err, errlen);
  free(b);
  return rc;
}

int rhod_checkpoint_parse(const void *bytes, size_t len, const char *name, rhod_checkpoint *ck,
                          char *err, size_t errlen) {
  memset(ck, 0, sizeof *ck);
  rd r = {bytes, len, 0, 0, NULL};
  int rc = parse(&r, ck, name, err, errlen);
  if (rc != RHOD_OK)
    rhod_checkpoint_free(ck);
  return rc;
}

int rhod_checkpoint_apply(const rhod_checkpoint *ck, rhod_particles *p, char *err, size_t errlen) {
  int k = 0;
  for (int f = 0; f < p->nfields; f++) {
    const rhod_field_desc *d = &p->fields[f];
    if (d->persistent != 1)
      continue;
    if (k >= ck->nfields || strcmp(ck->fname[k], d->name) != 0 || ck->felem[k] != d->elem) {
      snprintf(err, errlen, "checkpoint fields do not match this build's (field %d: %s)", k,
               k < ck->nfields ? ck->fname[k] : "missing");
      return RHOD_ERR_CHECKPOINT;
    }
    k++;
  }
  if (k != ck->nfields) {
    snprintf(err, errlen, "checkpoint has %d fields, this build %d", ck->nfields, k);
    return RHOD_ERR_CHECKPOINT;
  }
  if (ck->n + 1 > p->cap && rhod_particles_reserve(p, (size_t)ck->n + 1) != RHOD_OK) {
    snprintf(err, errlen, "out of memory for %llu particles", (unsigned long long)ck->n);
    return RHOD_ERR_MEMORY;
  }
  p->n = (size_t)ck->n;
  p->ng = 0;
  p->next_id = ck->next_id;
  k = 0;
  for (int f = 0; f < p->nfields; f++) {
    const rhod_field_desc *d = &p->fields[f];
    if (d->persistent != 1)
      continue;
    memcpy(*d->ptr, ck->fdata[k], p->n * d->elem);
    rhod_to_device(*d->ptr, p->n * d->elem);
    k++;
  }
  return RHOD_OK;
}

void rhod_checkpoint_free(rhod_checkpoint *ck) {
  if (!ck)
    return;
  free(ck->snap_t);
  free(ck->snap_n);
  free(ck->scene_path);
  for (int i = 0; ck->sets && i < ck->nsets; i++)
    free(ck->sets[i]);
  free(ck->sets);
  rhod_param_list_free(&ck->params);
  for (int f = 0; f < ck->nfields; f++) {
    if (ck->fname)
      free(ck->fname[f]);
    if (ck->fdata)
      free(ck->fdata[f]);
  }
  free(ck->fname);
  free(ck->felem);
  free(ck->fdata);
  memset(ck, 0, sizeof *ck);
}
