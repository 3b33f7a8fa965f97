/* Particle store: allocation, device mapping, growth and reordering. */
#include "rhod/particles.h"
#include "rhod/cells.h"
#include "rhod/device.h"
#include "rhod/status.h"
#include <stdlib.h>
#include <string.h>

static int alloc_field(rhod_field_desc *f, size_t cap) {
  void *a = rhod_dev_calloc(cap, f->elem);
  if (!a)
    return RHOD_ERR_MEMORY;
  *f->ptr = a;
  return RHOD_OK;
}

/* Scratch for reordering, as wide as the widest persistent field. */
static size_t scratch_elem(const rhod_particles *p) {
  size_t m = sizeof(double);
  for (int i = 0; i < p->nfields; i++)
    if (p->fields[i].persistent == 1 && p->fields[i].elem > m)
      m = p->fields[i].elem;
  return m;
}

static int alloc_scratch(rhod_particles *p) {
  p->scratch_elem = scratch_elem(p);
  p->scratch = rhod_dev_calloc(p->cap, p->scratch_elem);
  return p->scratch ? RHOD_OK : RHOD_ERR_MEMORY;
}

static void free_scratch(rhod_particles *p) {
  rhod_dev_free(p->scratch, p->cap * p->scratch_elem);
  p->scratch = NULL;
}

int rhod_particles_add_field(rhod_particles *p, const char *name, void **ptr, size_t elem,
                             int persistent) {
  if (p->nfields >= RHOD_MAX_FIELDS)
    return RHOD_ERR_MEMORY;
  rhod_field_desc *f = &p->fields[p->nfields];
  f->name = name;
  f->ptr = ptr;
  f->elem = elem;
  f->persistent = persistent;
  int st = alloc_field(f, p->cap);
  if (st != RHOD_OK)
    return st;
  p->nfields++;
  if (persistent == 1 && p->scratch && elem > p->scratch_elem) {
    free_scratch(p);
    st = alloc_scratch(p);
  }
  return st;
}

int rhod_particles_init(rhod_particles *p, size_t cap) {
  memset(p, 0, sizeof *p);
  p->cap = cap;
  int st = RHOD_OK;
#define ADD(nm, var, el, pers)                                                                     \
  if (st == RHOD_OK)                                                                               \
  st = rhod_particles_add_field(p, nm, (void **)&p->var, el, pers)
  ADD("x", x, sizeof(real), 1);
  ADD("y", y, sizeof(real), 1);
  ADD("ux", ux, sizeof(real), 1);
  ADD("uy", uy, sizeof(real), 1);
  ADD("rho", rho, sizeof(real), 1);
  ADD("m", m, sizeof(real), 1);
  ADD("dx", dx, sizeof(real), 1);
  ADD("id", id, sizeof(uint64_t), 1);
  ADD("gsrc", gsrc, sizeof(int32_t), 0);
  ADD("gJ", gJ, 4 * sizeof(real), 0);
  ADD("gT", gT, 4 * sizeof(real), 0);
  ADD("gU", gU, 2 * sizeof(real), 0);
  ADD("ge", ge, 2 * sizeof(real), 0);
  ADD("perm", perm, sizeof(int32_t), 0);
#undef ADD
  if (st != RHOD_OK)
    return st;
  return alloc_scratch(p);
}

int rhod_particles_add_tags(rhod_particles *p) {
  int st = RHOD_OK;
  if (!p->phase)
    st = rhod_particles_add_field(p, "phase", (void **)&p->phase, 1, 1);
  if (st == RHOD_OK && !p->kind)
    st = rhod_particles_add_field(p, "kind", (void **)&p->kind, 1, 1);
  if (st == RHOD_OK && !p->level)
    st = rhod_particles_add_field(p, "level", (void **)&p->level, 1, 1);
  return st;
}

real rhod_max_real(const real *v, long n) {
  real m = 0;
  RHOD_KERNEL_LOOP_REDUCE(max, m)
  for (long i = 0; i < n; i++)
    m = v[i] > m ? v[i] : m;
  return m;
}

int rhod_particles_add_noslip_fields(rhod_particles *p) {
  int st = RHOD_OK;
  if (!p->gTv)
    st = rhod_particles_add_field(p, "gTv", (void **)&p->gTv, 4 * sizeof(real), 0);
  if (st == RHOD_OK && !p->gUv)
    st = rhod_particles_add_field(p, "gUv", (void **)&p->gUv, 2 * sizeof(real), 0);
  return st;
}

int rhod_particles_add_body_fields(rhod_particles *p) {
  int st = RHOD_OK;
  if (!p->gA)
    st = rhod_particles_add_field(p, "gA", (void **)&p->gA, 2 * sizeof(real), 0);
  if (st == RHOD_OK && !p->gbody)
    st = rhod_particles_add_field(p, "gbody", (void **)&p->gbody, sizeof(int32_t), 0);
  return st;
}

int rhod_particles_reserve(rhod_particles *p, size_t cap) {
  if (cap <= p->cap)
    return RHOD_OK;
  size_t newcap = cap + cap / 4 + 64;
  for (int i = 0; i < p->nfields; i++) {
    rhod_field_desc *f = &p->fields[i];
    void *old = *f->ptr;
    void *a = rhod_dev_calloc(newcap, f->elem);
    if (!a)
      return RHOD_ERR_MEMORY;
    if (f->persistent) {
      /* state lives on the device: bring it back, copy, and send the new array */
      rhod_to_host(old, p->n * f->elem);
      memcpy(a, old, p->n * f->elem);
    }
    rhod_dev_free(old, p->cap * f->elem);
    *f->ptr = a;
    if (f->persistent)
      rhod_to_device(a, p->n * f->elem);
  }
  free_scratch(p);
  p->cap = newcap;
  return alloc_scratch(p);
}

void rhod_particles_free(rhod_particles *p) {
  for (int i = 0; i < p->nfields; i++) {
    rhod_field_desc *f = &p->fields[i];
    rhod_dev_free(*f->ptr, p->cap * f->elem);
    *f->ptr = NULL;
  }
  free_scratch(p);
  memset(p, 0, sizeof *p);
}

/* dst[d0 + k] = src[idx[k]] for k < count, elements of `elem` bytes (dst may be src
 * when no dst slot is an idx source). The offset stays inside the loops: inside a
 * device region only mapped base pointers are translated. */
static void gather_bytes(void *dst, size_t dst0, const void *src, const int32_t *idx, size_t count,
                         size_t elem) {
  const long nn = (long)count, d0 = (long)dst0;
  if (elem == 8) {
    uint64_t *d = dst;
    const uint64_t *a = src;
    RHOD_KERNEL_LOOP
    for (long k = 0; k < nn; k++)
      d[d0 + k] = a[idx[k]];
    return;
  }
  if (elem == 4) {
    uint32_t *d = dst;
    const uint32_t *a = src;
    RHOD_KERNEL_LOOP
    for (long k = 0; k < nn; k++)
      d[d0 + k] = a[idx[k]];
    return;
  }
  char *d = dst;
  const char *a = src;
  const long el = (long)elem;
  RHOD_KERNEL_LOOP
  for (long k = 0; k < nn; k++)
    for (long b = 0; b < el; b++)
      d[el * (d0 + k) + b] = a[el * (long)idx[k] + b];
}

/* Gathers one array through perm into scratch and copies it back. Sorting happens
 * once per step, so the extra copy is cheap next to the neighbour passes, and every
 * array keeps its own (mapped) buffer. */
static void permute_bytes(void *arr, void *scratch, const int32_t *perm, size_t n, size_t elem) {
  gather_bytes(scratch, 0, arr, perm, n, elem);
  const long words = (long)(n * elem / 4), bytes = (long)(n * elem);
  if (elem % 4 == 0) {
    uint32_t *a = arr;
    const uint32_t *d = scratch;
    RHOD_KERNEL_LOOP
    for (long b = 0; b < words; b++)
      a[b] = d[b];
    return;
  }
  char *a = arr;
  const char *d = scratch;
  RHOD_KERNEL_LOOP
  for (long b = 0; b < bytes; b++)
    a[b] = d[b];
}

void rhod_particles_append(rhod_particles *p, const int32_t *src, size_t count) {
  for (int i = 0; i < p->nfields; i++) {
    rhod_field_desc *f = &p->fields[i];
    if (f->persistent == 1)
      gather_bytes(*f->ptr, p->n, *f->ptr, src, count, f->elem);
  }
  /* new particles: new ids, in order from next_id (a copied id would be a duplicate) */
  uint64_t *id = p->id;
  const uint64_t id0 = p->next_id;
  const long n0 = (long)p->n, nn = (long)count;
  RHOD_KERNEL_LOOP
  for (long k = 0; k < nn; k++)
    id[n0 + k] = id0 + (uint64_t)k;
  p->next_id += (uint64_t)count;
  p->n += count;
  p->ng = 0;
}

long rhod_particles_compact(rhod_particles *p, int32_t *keep, size_t nflag) {
  const long n = (long)p->n, nf = (long)nflag;
  if (nf > n)
    return -1;
  /* flags 0 or 1, and keep[nf] = 0 to close the scan: keep[i] becomes the new slot of
   * a kept i < nf */
  RHOD_KERNEL_LOOP
  for (long i = 0; i <= nf; i++)
    keep[i] = i < nf && keep[i] != 0;
  const long kept = rhod_scan_exclusive(keep, (size_t)nf + 1);
  if (kept < 0)
    return -1;
  int32_t *perm = p->perm;
  /* a kept particle's slot is where the scan steps up to the next (keep[i + 1] > keep[i]) */
  RHOD_KERNEL_LOOP
  for (long i = 0; i < nf; i++)
    if (keep[i + 1] > keep[i])
      perm[keep[i]] = (int32_t)i;
  /* the particles after the flagged ones stay behind, in order */
  RHOD_KERNEL_LOOP
  for (long t = nf; t < n; t++)
    perm[kept + t - nf] = (int32_t)t;
  p->n = (size_t)(kept + n - nf);
  p->ng = 0;
  rhod_particles_permute(p);
  return (long)p->n;
}

void rhod_particles_permute(rhod_particles *p) {
  for (int i = 0; i < p->nfields; i++) {
    rhod_field_desc *f = &p->fields[i];
    if (f->persistent == 1)
      permute_bytes(*f->ptr, p->scratch, p->perm, p->n, f->elem);
  }
}

void rhod_particles_to_device(rhod_particles *p) {
  for (int f = 0; f < p->nfields; f++)
    if (p->fields[f].persistent == 1)
      rhod_to_device(*p->fields[f].ptr, p->n * p->fields[f].elem);
}

void rhod_particles_to_host(rhod_particles *p) {
  for (int f = 0; f < p->nfields; f++)
    if (p->fields[f].persistent == 1)
      rhod_to_host(*p->fields[f].ptr, p->n * p->fields[f].elem);
}
