/* Particle store: allocation, device mapping, growth and reordering. */
#include "rhod/particles.h"
#include "rhod/scene.h"
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void dev_alloc(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  char *c = ptr;
#pragma omp target enter data map(alloc : c [0:bytes])
  (void)c; /* GCC 12 flags map-only variables as unused */
#else
  (void)ptr;
  (void)bytes;
#endif
}

static void dev_free(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  char *c = ptr;
#pragma omp target exit data map(delete : c [0:bytes])
  (void)c; /* GCC 12 flags map-only variables as unused */
#else
  (void)ptr;
  (void)bytes;
#endif
}

void rhod_to_host(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  char *c = ptr;
  if (bytes) {
#pragma omp target update from(c [0:bytes])
    (void)c;
  }
#else
  (void)ptr;
  (void)bytes;
#endif
}

void rhod_to_device(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  char *c = ptr;
  if (bytes) {
#pragma omp target update to(c [0:bytes])
    (void)c;
  }
#else
  (void)ptr;
  (void)bytes;
#endif
}

int rhod_where(char *buf, size_t len) {
  int ndev = omp_get_num_devices();
  int initial = 1;
#ifdef RHOD_OFFLOAD
#pragma omp target map(from : initial)
  { initial = omp_is_initial_device(); }
#endif
  if (initial)
    snprintf(buf, len, "host, %d OpenMP threads (%s build, %d offload devices)",
             omp_get_max_threads(),
#ifdef RHOD_OFFLOAD
             "offload",
#else
             "host-only",
#endif
             ndev);
  else
    snprintf(buf, len, "GPU, OpenMP device %d of %d (nvptx offload)", omp_get_default_device(),
             ndev);
  return !initial;
}

static int alloc_field(rhod_field_desc *f, size_t cap) {
  void *a = calloc(cap ? cap : 1, f->elem);
  if (!a)
    return RHOD_ERR_MEMORY;
  *f->ptr = a;
  dev_alloc(a, cap * f->elem);
  return RHOD_OK;
}

/* Scratch for reordering, as wide as the widest persistent field. */
static size_t scratch_elem(const rhod_particles *p) {
  size_t m = sizeof(double);
  for (int i = 0; i < p->nfields; i++)
    if (p->fields[i].persistent && p->fields[i].elem > m)
      m = p->fields[i].elem;
  return m;
}

static int alloc_scratch(rhod_particles *p) {
  p->scratch_elem = scratch_elem(p);
  p->scratch = calloc(p->cap ? p->cap : 1, p->scratch_elem);
  if (!p->scratch)
    return RHOD_ERR_MEMORY;
  dev_alloc(p->scratch, p->cap * p->scratch_elem);
  return RHOD_OK;
}

static void free_scratch(rhod_particles *p) {
  if (!p->scratch)
    return;
  dev_free(p->scratch, p->cap * p->scratch_elem);
  free(p->scratch);
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
  if (persistent && p->scratch && elem > p->scratch_elem) {
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
  ADD("ge", ge, 2 * sizeof(real), 0);
  ADD("perm", perm, sizeof(int32_t), 0);
#undef ADD
  if (st != RHOD_OK)
    return st;
  return alloc_scratch(p);
}

int rhod_particles_reserve(rhod_particles *p, size_t cap) {
  if (cap <= p->cap)
    return RHOD_OK;
  size_t newcap = cap + cap / 4 + 64;
  for (int i = 0; i < p->nfields; i++) {
    rhod_field_desc *f = &p->fields[i];
    void *old = *f->ptr;
    void *a = calloc(newcap, f->elem);
    if (!a)
      return RHOD_ERR_MEMORY;
    if (f->persistent) {
      /* state lives on the device: bring it back, copy, and send the new array */
      rhod_to_host(old, p->n * f->elem);
      memcpy(a, old, p->n * f->elem);
    }
    dev_free(old, p->cap * f->elem);
    free(old);
    *f->ptr = a;
    dev_alloc(a, newcap * f->elem);
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
    if (*f->ptr) {
      dev_free(*f->ptr, p->cap * f->elem);
      free(*f->ptr);
      *f->ptr = NULL;
    }
  }
  free_scratch(p);
  memset(p, 0, sizeof *p);
}

/* Gathers one array through perm into scratch and copies it back. Sorting happens
 * once per step, so the extra copy is cheap next to the neighbour passes, and every
 * array keeps its own (mapped) buffer. */
static void permute_bytes(void *arr, void *scratch, const int32_t *perm, size_t n, size_t elem) {
  const long nn = (long)n;
  if (elem == 8) {
    uint64_t *a = arr, *d = scratch;
    RHOD_KERNEL_LOOP
    for (long k = 0; k < nn; k++)
      d[k] = a[perm[k]];
    RHOD_KERNEL_LOOP
    for (long k = 0; k < nn; k++)
      a[k] = d[k];
    return;
  }
  if (elem == 4) {
    uint32_t *a = arr, *d = scratch;
    RHOD_KERNEL_LOOP
    for (long k = 0; k < nn; k++)
      d[k] = a[perm[k]];
    RHOD_KERNEL_LOOP
    for (long k = 0; k < nn; k++)
      a[k] = d[k];
    return;
  }
  char *dst = scratch;
  char *a = arr;
  const long el = (long)elem;
  RHOD_KERNEL_LOOP
  for (long k = 0; k < nn; k++)
    for (long b = 0; b < el; b++)
      dst[el * k + b] = a[el * (long)perm[k] + b];
  const long bytes = nn * el;
  RHOD_KERNEL_LOOP
  for (long b = 0; b < bytes; b++)
    a[b] = dst[b];
}

void rhod_particles_permute(rhod_particles *p) {
  for (int i = 0; i < p->nfields; i++) {
    rhod_field_desc *f = &p->fields[i];
    if (f->persistent)
      permute_bytes(*f->ptr, p->scratch, p->perm, p->n, f->elem);
  }
}
