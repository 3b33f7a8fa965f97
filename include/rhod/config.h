/* Build-wide choices: floating-point precision and the loop pragmas that make one
 * loop text compile for the CPU (OpenMP threads) and for NVIDIA GPUs (GCC nvptx
 * offload). See ../shared/design/offload.md for why each flag is there. */
#ifndef RHOD_CONFIG_H
#define RHOD_CONFIG_H

#include <stddef.h>
#include <stdint.h>

#ifdef RHOD_SINGLE
typedef float real;
#define RHOD_REAL_NAME "single"
#else
typedef double real;
#define RHOD_REAL_NAME "double"
#endif

/* Dimension of the particle data. The scheme is written for 2D (paper 002, Sec. VI is
 * 2D throughout); 3D is a later step. */
#define RHOD_DIM 2

/* RHOD_KERNEL_LOOP opens a loop over particles that runs on the device when the build
 * offloads (arrays must be present there: rhod_device_* in device.h), on the host
 * threads otherwise. `simd` is needed on nvptx, or only one lane in 32 works. */
#ifdef RHOD_OFFLOAD
#define RHOD_PRAGMA(x) _Pragma(#x)
#define RHOD_KERNEL_LOOP RHOD_PRAGMA(omp target teams distribute parallel for simd)
#define RHOD_KERNEL_LOOP_REDUCE(op, var)                                                           \
  RHOD_PRAGMA(omp target teams distribute parallel for simd reduction(op : var))
#define RHOD_KERNEL_LOOP_REDUCE2(op, v1, v2)                                                       \
  RHOD_PRAGMA(omp target teams distribute parallel for simd reduction(op : v1, v2))
/* RHOD_GATHER_LOOP: a loop over particles whose work per particle varies (a gather over
 * the support): on the device as RHOD_KERNEL_LOOP. */
#define RHOD_GATHER_LOOP RHOD_KERNEL_LOOP
/* On the device the particle loop is already the simd loop (one particle per lane), so a
 * gather's loop over candidates is a plain one: RHOD_VLANES is 1 (below). */
#else
#define RHOD_PRAGMA(x) _Pragma(#x)
#define RHOD_KERNEL_LOOP RHOD_PRAGMA(omp parallel for schedule(static))
/* On the host the threads take chunks of 64 particles as they come free: with mixed sizes
 * a coarse particle's gather visits up to 4 times the neighbours of a fine one, and the
 * sorted order groups them, so equal static shares leave threads waiting at the loop's
 * end (perf/RESULTS.md "gather schedule"). Each particle's sums are its own, so the
 * results do not depend on the schedule; loops with reductions stay static. */
#define RHOD_GATHER_LOOP RHOD_PRAGMA(omp parallel for schedule(dynamic, 64))
#define RHOD_KERNEL_LOOP_REDUCE(op, var)                                                           \
  RHOD_PRAGMA(omp parallel for schedule(static) reduction(op : var))
#define RHOD_KERNEL_LOOP_REDUCE2(op, v1, v2)                                                       \
  RHOD_PRAGMA(omp parallel for schedule(static) reduction(op : v1, v2))
/* RHOD_VLANES: the lanes of the vectors in which a gather takes its candidates on the
 * host (cells.h, RHOD_FOR_LANES), those GCC uses for them (512 or 256 bits). Only where
 * the CPU has masked vector loads (AVX2 and up, e.g. with -DRHOD_NATIVE=ON): without
 * them the masked loop is slower than the scalar one, which skips the candidates
 * outside the support (perf/RESULTS.md), and RHOD_VLANES is 1. */
#if defined(__AVX2__)
#if defined(__AVX512F__) && defined(RHOD_SINGLE)
#define RHOD_VLANES 16
#elif defined(__AVX512F__) || defined(RHOD_SINGLE)
#define RHOD_VLANES 8
#else
#define RHOD_VLANES 4
#endif
#endif
#endif
#ifndef RHOD_VLANES
#define RHOD_VLANES 1
#endif

#endif
