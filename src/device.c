/* Device memory management and the run-time check of where kernels run. */
#include "rhod/device.h"
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

/* GCC 12 reports variables used only in map clauses as unused: hence the (void)c. */

void rhod_dev_map(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  char *c = ptr;
  if (c && bytes) {
#pragma omp target enter data map(to : c [0:bytes])
    (void)c;
  }
#else
  (void)ptr;
  (void)bytes;
#endif
}

void rhod_dev_unmap(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  char *c = ptr;
  if (c && bytes) {
#pragma omp target exit data map(delete : c [0:bytes])
    (void)c;
  }
#else
  (void)ptr;
  (void)bytes;
#endif
}

void *rhod_dev_calloc(size_t n, size_t elem) {
  void *p = calloc(n ? n : 1, elem);
  if (p)
    rhod_dev_map(p, n * elem);
  return p;
}

void rhod_dev_free(void *ptr, size_t bytes) {
  if (!ptr)
    return;
  rhod_dev_unmap(ptr, bytes);
  free(ptr);
}

void rhod_to_host(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  char *c = ptr;
  if (c && bytes) {
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
  if (c && bytes) {
#pragma omp target update to(c [0:bytes])
    (void)c;
  }
#else
  (void)ptr;
  (void)bytes;
#endif
}

int rhod_where(char *buf, size_t len) {
  const int ndev = omp_get_num_devices();
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
