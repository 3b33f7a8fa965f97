/* Device memory management and the run-time check of where kernels run. */
#include "rhod/device.h"
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#ifdef RHOD_OFFLOAD
#include <dlfcn.h>
#endif

/* GCC 12 reports variables used only in map clauses as unused: hence the (void)c. */

#ifdef RHOD_OFFLOAD
/* The GPU call stack. GCC 12's nvptx code keeps a kernel's spilled registers in its call
 * frames (pass C: 888 bytes, behind the libgomp frames that launch it; `ptxas -v` on the
 * offload PTX lists them), and CUDA's default limit of 1 KiB per thread overflows (an
 * "illegal memory access" at the first pass A; compute-sanitizer says "Stack overflow").
 * GCC 12's plugin never raises the limit, so we do, in the CUDA context libgomp made
 * current on this thread, through the driver loaded at run time (no CUDA at build time).
 * RHOD_GPU_STACK (bytes) overrides our default. */
#define RHOD_GPU_STACK_DEFAULT 4096
static char stack_note[96] = "";

static void gpu_stack_setup(void) {
  static int done = 0;
  if (done)
    return;
  done = 1;
  if (omp_get_num_devices() < 1)
    return;
  int initial = 1;
#pragma omp target map(from : initial)
  { initial = omp_is_initial_device(); } /* makes libgomp open the device */
  if (initial)
    return;
  size_t want = RHOD_GPU_STACK_DEFAULT;
  const char *env = getenv("RHOD_GPU_STACK");
  if (env && atol(env) > 0)
    want = (size_t)atol(env);
  typedef int (*get_current_fn)(void **);
  typedef int (*set_limit_fn)(int, size_t);
  typedef int (*get_limit_fn)(size_t *, int);
  enum { CU_LIMIT_STACK_SIZE = 0 };
  void *cuda = dlopen("libcuda.so.1", RTLD_NOW | RTLD_GLOBAL);
  void *ctx = NULL;
  size_t got = 0;
  if (cuda) {
    get_current_fn get_current = (get_current_fn)dlsym(cuda, "cuCtxGetCurrent");
    set_limit_fn set_limit = (set_limit_fn)dlsym(cuda, "cuCtxSetLimit");
    get_limit_fn get_limit = (get_limit_fn)dlsym(cuda, "cuCtxGetLimit");
    if (get_current && set_limit && get_limit && get_current(&ctx) == 0 && ctx &&
        set_limit(CU_LIMIT_STACK_SIZE, want) == 0)
      get_limit(&got, CU_LIMIT_STACK_SIZE);
  }
  if (got >= want)
    snprintf(stack_note, sizeof stack_note, ", GPU stack %zu B per thread", got);
  else
    snprintf(stack_note, sizeof stack_note,
             ", GPU stack limit NOT raised to %zu B (kernels may overflow)", want);
}
#endif

void rhod_dev_map(void *ptr, size_t bytes) {
#ifdef RHOD_OFFLOAD
  gpu_stack_setup();
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
  const char *note = "";
#ifdef RHOD_OFFLOAD
  gpu_stack_setup();
  note = stack_note;
#pragma omp target map(from : initial)
  { initial = omp_is_initial_device(); }
#endif
#ifdef RHOD_OFFLOAD
  /* GCC 12's libgomp runs a target region without a device as host fallback in a fresh
   * thread pool that it frees after the region: every kernel starts its threads anew
   * (cli_extremes: 203 s on 2 threads, 36 s on 1, 2.7 s in the host-only build). */
  if (initial && omp_get_max_threads() > 1)
    note = "; no GPU: host fallback starts threads at every kernel, run with "
           "OMP_NUM_THREADS=1 or use the host-only build";
#endif
  if (initial)
    snprintf(buf, len, "host, %d OpenMP threads (%s build, %d offload devices%s)",
             omp_get_max_threads(),
#ifdef RHOD_OFFLOAD
             "offload",
#else
             "host-only",
#endif
             ndev, note);
  else
    snprintf(buf, len, "GPU, OpenMP device %d of %d (nvptx offload%s)", omp_get_default_device(),
             ndev, note);
  return !initial;
}
