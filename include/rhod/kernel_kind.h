/* The smoothing kernels the engine has (include/rhod/kernel.h holds their formulas). */
#ifndef RHOD_KERNEL_KIND_H
#define RHOD_KERNEL_KIND_H

typedef enum {
  RHOD_KERNEL_WENDLAND_C2 = 0,
  RHOD_KERNEL_WENDLAND_C4,
  RHOD_KERNEL_QUINTIC
} rhod_kernel_kind;

#endif
