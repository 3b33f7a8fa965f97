/* Device memory: the one place that maps host buffers to the offload device. Without
 * offload every call is plain host memory management (or a no-op). */
#ifndef RHOD_DEVICE_H
#define RHOD_DEVICE_H

#include <stddef.h>

/* calloc(n, elem) that is also allocated (zeroed) on the device; NULL on failure. */
void *rhod_dev_calloc(size_t n, size_t elem);
/* Unmaps and frees a buffer from rhod_dev_calloc (NULL is fine). */
void rhod_dev_free(void *ptr, size_t bytes);
/* Maps an existing host buffer to the device with its content, and back off. */
void rhod_dev_map(void *ptr, size_t bytes);
void rhod_dev_unmap(void *ptr, size_t bytes);
/* Copies between host and device (no-ops without offload). */
void rhod_to_host(void *ptr, size_t bytes);
void rhod_to_device(void *ptr, size_t bytes);
/* Where the kernels run, checked at run time by a probe region: fills `buf` with e.g.
 * "host, 2 OpenMP threads ..." or "GPU, OpenMP device 0 of 1"; returns 1 on a GPU. */
int rhod_where(char *buf, size_t len);

#endif
