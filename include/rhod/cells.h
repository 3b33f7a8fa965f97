/* Sorted cell lists by counting sort, and the one neighbour loop every gather uses.
 *
 * The grid covers a box with square cells of side >= R0/reach, R0 the kernel radius
 * of the finest particles, so the (2 reach + 1)^2 block of cells around a particle of
 * radius R0 holds its whole support (reach 2 scans 6.25 R^2 instead of the 9 R^2 of
 * reach 1). Mixed sizes (APR, paper 002 Sec. IV D): a particle of radius R_i scans
 * reach * ceil(R_i / R0) cells on each side of its own, so one grid serves every
 * level. A row of cells is one contiguous range of the sorted index, so the cost of
 * a wider scan is one range per row plus the particles in it (perf/bench_mixed
 * compares this with a grid made for the coarsest radius). Order inside a cell is by
 * particle index, so every sum is taken in the same order run after run
 * (bit-reproducible).
 *
 * Each build sizes the grid to the particles: the cells are those of a fixed lattice
 * over the box, but only the window from the lowest to the highest occupied cell is
 * counted, scanned and kept, so a scene whose box is mostly empty (a patch in a large
 * domain) does not pay for the empty cells. */
#ifndef RHOD_CELLS_H
#define RHOD_CELLS_H

#include "rhod/config.h"
#include "rhod/particles.h"
#include <math.h>

/* Cells scanned on each side by the solver (chosen by perf/bench_passes). */
#ifndef RHOD_CELL_REACH
#define RHOD_CELL_REACH 2
#endif

/* Grid geometry, plain values: safe to pass by value into device regions. */
typedef struct {
  real ox, oy;  /* lower-left corner of the box's lattice */
  real inv;     /* 1 / cell */
  real iR0;     /* 1 / R0 */
  int nx, ny;   /* the window's size in cells (set by each build) */
  int cx0, cy0; /* the window's first cell, in lattice coordinates */
  int reach;    /* cells scanned on each side by a particle of radius R0 */
} rhod_grid;

typedef struct rhod_cells {
  rhod_grid g;
  size_t ncells;      /* cells of the window: g.nx * g.ny */
  int nx_box, ny_box; /* the lattice over the whole box */
  size_t ncells_box;  /* allocated: nx_box * ny_box */
  int32_t *start;     /* ncells + 1: particles of cell c are idx[start[c] .. start[c+1]) */
  int32_t *count;     /* ncells: histogram scratch */
  int32_t *idx;       /* cap: particle indices sorted by cell */
  int32_t *key;       /* cap: cell of each particle */
  size_t cap;
  long nbuilt; /* particles sorted by the last build (of a subset: the flagged ones) */
} rhod_cells;

/* Sets up a grid over [lo, hi] for kernel radii of at least `radius` (R0), with cells
 * of side >= radius / reach. */
int rhod_cells_init(rhod_cells *c, const double lo[2], const double hi[2], double radius, int reach,
                    size_t cap);
int rhod_cells_reserve(rhod_cells *c, size_t cap);
void rhod_cells_free(rhod_cells *c);
/* Sorts particles [0, count) into the cells (positions on the device), the window
 * spanning their cells. Particles outside the box are clamped into its border cells;
 * a later query outside the window is clamped into the window's border cells, which
 * still scans every particle within reach of it. */
void rhod_cells_build(rhod_cells *c, const real *x, const real *y, size_t count);

/* A subset: the particles of `from`'s last build with flag != 0 (flag on the device,
 * one per particle of that build), sorted into the same cells and window as in `from`,
 * in index order inside each; returns how many (sub->nbuilt), or -1 when out of memory.
 * Its idx lists indices of the particles of from's build. The caller owns the subset,
 * one per particle set (free surface, size jumps ...): a zeroed rhod_cells the first
 * time, which this sizes to `from` (and resizes when from's box or capacity grows), freed
 * with rhod_cells_free; it holds no keys of its own (it reads from's) and is not built
 * with rhod_cells_build. A gather over the subset scans its rows, which hold only
 * flagged particles, and a range of a row is tested for any with two reads of its start
 * (rhod_cells_near_any). */
long rhod_cells_build_subset(rhod_cells *sub, const rhod_cells *from, const uint8_t *flag);

/* Cell coordinate of a position along one axis in the window [off, off + n) of the
 * lattice with origin o, relative to the window, clamped to it. */
static inline int rhod_cell_coord(real v, real o, real inv, int off, int n) {
  int k = (int)((v - o) * inv) - off;
  return k < 0 ? 0 : (k >= n ? n - 1 : k);
}

/* Cells scanned on each side for a support of radius R: reach * k with k = R/R0
 * rounded up. Sizes are dx_min e^l (e = 2, or sqrt 3 for the triangle pattern), so
 * R/R0 is a power of e up to rounding; the 1e-4 keeps a rounding excess from adding a
 * ring of cells (at worst it leaves out the outer 1e-4 of a cell, where every kernel is
 * 0 to 16 digits). In single
 * resolution (every size = dx_min) k = 1: the same scan as before APR, bit for bit;
 * with levels > 1 a particle coarser than dx_min scans more cells of a finer grid,
 * which finds the same neighbours in another order (round-off differences). */
static inline int rhod_cell_reach(rhod_grid G, real R) {
  const int k = (int)ceil(R * G.iR0 - (real)1e-4);
  return G.reach * (k > 1 ? k : 1);
}

/* The gather loop. Inside a device region only plain locals may be used, so the
 * caller copies the arrays to locals first:
 *
 *   const rhod_grid G = cells->g; const int32_t *CS = cells->start, *CI = cells->idx;
 *   RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, Ri, j) { ... uses j ... } RHOD_END_NEIGHBOURS
 *
 * j runs over every particle (fluid and ghost, i itself included) in the cells
 * around (xi, yi) that can lie within Ri (the gathering particle's radius); the body
 * tests the distance against it. */
#define RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, Ri, j)                                              \
  RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0_, k1_, kv_)                                                  \
    for (int k_ = k0_; k_ < k1_; k_++) {                                                           \
      const int j = (CI)[k_];
#define RHOD_END_NEIGHBOURS                                                                        \
  }                                                                                                \
  RHOD_END_ROWS

/* The same scan as ranges: for each row of cells, [k0, k1) is its contiguous range of
 * the sorted index (particle CI[k] for k in it). The gathers read copies of the fields
 * packed in this order (rhod_sph's pk arrays) and run to kv: where they vectorise
 * (RHOD_VLANES > 1, config.h), k1 rounded up to whole vectors from k0 but not past the
 * end of the window's row of cells; elsewhere k1. The candidates in [k1, kv) are in the
 * row's cells to the right of the scanned ones, so farther from xi than rc cells =
 * ceil(R/R0 - 1e-4) R0, i.e. than R less the 1e-4 R0 that rhod_cell_reach already leaves
 * out: the body's own test r < R rejects them, no extra test is needed, and none is
 * counted twice (each row is scanned once). */
#if RHOD_VLANES > 1
#define RHOD_ROW_END_(k0, k1, kn, kv)                                                              \
  const int kv##_r_ = (k0) + ((k1) - (k0) + RHOD_VLANES - 1) / RHOD_VLANES * RHOD_VLANES;          \
  const int kv = kv##_r_ < (kn) ? kv##_r_ : (kn);                                                  \
  (void)kv;
#else
#define RHOD_ROW_END_(k0, k1, kn, kv)                                                              \
  const int kv = (k1);                                                                             \
  (void)kv;
#endif
#define RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv)                                               \
  {                                                                                                \
    const int rc_ = rhod_cell_reach((G), (Ri));                                                    \
    const int cx_ = rhod_cell_coord((xi), (G).ox, (G).inv, (G).cx0, (G).nx);                       \
    const int cy_ = rhod_cell_coord((yi), (G).oy, (G).inv, (G).cy0, (G).ny);                       \
    const int y0_ = cy_ - rc_ > 0 ? cy_ - rc_ : 0;                                                 \
    const int y1_ = cy_ + rc_ < (G).ny - 1 ? cy_ + rc_ : (G).ny - 1;                               \
    const int x0_ = cx_ - rc_ > 0 ? cx_ - rc_ : 0;                                                 \
    const int x1_ = cx_ + rc_ < (G).nx - 1 ? cx_ + rc_ : (G).nx - 1;                               \
    for (int yy_ = y0_; yy_ <= y1_; yy_++) {                                                       \
      const int k0 = (CS)[yy_ * (G).nx + x0_], k1 = (CS)[yy_ * (G).nx + x1_ + 1];                  \
      RHOD_ROW_END_(k0, k1, (CS)[yy_ * (G).nx + (G).nx], kv)
#define RHOD_END_ROWS                                                                              \
  }                                                                                                \
  }

/* A gather's sums, kept per vector lane. On the host with RHOD_VLANES > 1 each sum is an
 * array of one partial sum per lane; the candidates of a row are taken a vector at a
 * time (an `omp simd` loop of RHOD_VLANES lanes, lane l adding to its own element), and
 * the lanes are added once, after the last row. An `omp simd reduction` over each row
 * instead adds its lanes at the end of every row, which GCC 12 does one element at a
 * time: with AVX-512, 8 lanes times 17 sums of pass A, five to 33 times per particle.
 * Kept per lane, the sums made pass A 1.5 to 3 times as fast (perf/RESULTS.md
 * "Gather sums kept per lane"). A vector whose candidates are all outside the support
 * costs a distance test. Elsewhere (the device, whose lanes are particles, or a host
 * without vectors) each sum is a plain scalar and the loop a plain loop over [k0, kv):
 *
 *   real RHOD_LANES(s);                  (declared and set to 0; RHOD_LANES_SET(s, v) sets v)
 *   RHOD_FOR_ROWS(G, CS, xi, yi, Ri, k0, k1, kv) {
 *     RHOD_FOR_LANES(k0, kv, k) {
 *       if (!(r2 < R2)) continue;
 *       RHOD_LANE(s) += ...;
 *     } RHOD_END_LANES
 *   } RHOD_END_ROWS
 *   const real sum = RHOD_LANES_SUM(s);
 *
 * The order of the additions differs between the two, so their sums differ in the last
 * digits; each is the same from run to run. */
#if RHOD_VLANES > 1
#define RHOD_LANES(s) s[RHOD_VLANES] = {0}
#define RHOD_LANE(s) s[l_]
#define RHOD_LANES_SET(s, v)                                                                       \
  for (int l_ = 0; l_ < RHOD_VLANES; l_++)                                                         \
  s[l_] = (v)
#define RHOD_FOR_LANES(k0, kv, k)                                                                  \
  for (int m_ = (k0); m_ < (kv); m_ += RHOD_VLANES) {                                              \
    const int n_ = (kv)-m_ < RHOD_VLANES ? (kv)-m_ : RHOD_VLANES;                                  \
    RHOD_PRAGMA(omp simd)                                                                          \
    for (int l_ = 0; l_ < n_; l_++) {                                                              \
      const int k = m_ + l_;
#define RHOD_END_LANES                                                                             \
  }                                                                                                \
  }
#define RHOD_LANES_SUM(s) rhod_lanes_sum_(s)
#define RHOD_LANES_MAX(s) rhod_lanes_max_(s)
#define RHOD_LANES_MIN(s) rhod_lanes_min_(s)
static inline real rhod_lanes_sum_(const real *s) {
  real t = 0;
  for (int l = 0; l < RHOD_VLANES; l++)
    t += s[l];
  return t;
}
static inline real rhod_lanes_max_(const real *s) {
  real t = s[0];
  for (int l = 1; l < RHOD_VLANES; l++)
    t = s[l] > t ? s[l] : t;
  return t;
}
static inline real rhod_lanes_min_(const real *s) {
  real t = s[0];
  for (int l = 1; l < RHOD_VLANES; l++)
    t = s[l] < t ? s[l] : t;
  return t;
}
#else
#define RHOD_LANES(s) s = 0
#define RHOD_LANE(s) s
#define RHOD_LANES_SET(s, v) s = (v)
#define RHOD_FOR_LANES(k0, kv, k)                                                                  \
  {                                                                                                \
    for (int k = (k0); k < (kv); k++) {
#define RHOD_END_LANES                                                                             \
  }                                                                                                \
  }
#define RHOD_LANES_SUM(s) (s)
#define RHOD_LANES_MAX(s) (s)
#define RHOD_LANES_MIN(s) (s)
#endif

/* 1 when a cell within reach of a support of radius R at (x, y) holds a particle, for
 * the cell starts CS of a grid G (inside device regions: pass local copies; the
 * subset's (rhod_cells_build_subset), for "a flagged particle in reach"): two reads per
 * row. */
static inline int rhod_cells_near_any_(const int32_t *CS, real ox, real oy, real inv, int cx0,
                                       int cy0, int nx, int ny, int rc, real x, real y) {
  const int cx = rhod_cell_coord(x, ox, inv, cx0, nx);
  const int cy = rhod_cell_coord(y, oy, inv, cy0, ny);
  const int y0 = cy - rc > 0 ? cy - rc : 0;
  const int y1 = cy + rc < ny - 1 ? cy + rc : ny - 1;
  const int x0 = cx - rc > 0 ? cx - rc : 0;
  const int x1 = cx + rc < nx - 1 ? cx + rc : nx - 1;
  for (int yy = y0; yy <= y1; yy++) {
    const int32_t *row = CS + (long)yy * nx;
    if (row[x1 + 1] > row[x0])
      return 1;
  }
  return 0;
}
/* (the grid's fields are passed one by one: GCC 12's nvptx offload compiler fails with
 * an internal error on this struct passed by value to an inline function here) */
#define rhod_cells_near_any(G, CS, x, y, R)                                                        \
  rhod_cells_near_any_((CS), (G).ox, (G).oy, (G).inv, (G).cx0, (G).cy0, (G).nx, (G).ny,            \
                       rhod_cell_reach((G), (R)), (x), (y))

/* Neighbour-side fields copied into the order of the last build (cell order), so that a
 * gather's inner loop over a row of cells reads them contiguously and vectorises
 * (RHOD_FOR_ROWS, RHOD_FOR_LANES): row[k] = src[stride * idx[k] + comp] for k < nt (the
 * particles of the build), or from a uint8 field as a real. On the device. */
void rhod_cells_pack(const rhod_cells *c, long nt, real *row, const real *src, int stride,
                     int comp);
void rhod_cells_pack_u8(const rhod_cells *c, long nt, real *row, const uint8_t *src);

/* Exclusive prefix sum of n ints in place on the device; returns the total. */
long rhod_scan_exclusive(int32_t *a, size_t n);

#endif
