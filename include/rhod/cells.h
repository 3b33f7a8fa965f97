/* Sorted cell lists by counting sort, and the one neighbour loop every gather uses.
 *
 * The grid covers a box with square cells of side >= R/reach, R the largest kernel
 * radius, so the (2 reach + 1)^2 block of cells around a particle holds its whole
 * support (reach 2 scans 6.25 R^2 instead of the 9 R^2 of reach 1). Order inside a
 * cell is by particle index, so every sum is taken in the same order run after run
 * (bit-reproducible). A per-refinement-level grid is a set of these with their own
 * cell size (APR). */
#ifndef RHOD_CELLS_H
#define RHOD_CELLS_H

#include "rhod/config.h"
#include "rhod/particles.h"

/* Cells scanned on each side by the solver (chosen by perf/bench_passes). */
#ifndef RHOD_CELL_REACH
#define RHOD_CELL_REACH 2
#endif

/* Grid geometry, plain values: safe to pass by value into device regions. */
typedef struct {
  real ox, oy; /* lower-left corner */
  real inv;    /* 1 / cell */
  int nx, ny;
  int reach; /* cells scanned on each side */
} rhod_grid;

typedef struct {
  rhod_grid g;
  size_t ncells;
  int32_t *start; /* ncells + 1: particles of cell c are idx[start[c] .. start[c+1]) */
  int32_t *count; /* ncells: histogram scratch */
  int32_t *idx;   /* cap: particle indices sorted by cell */
  int32_t *key;   /* cap: cell of each particle */
  uint8_t *mark;  /* ncells: per-cell flag (rhod_cells_mark) */
  size_t cap;
} rhod_cells;

/* Sets up a grid over [lo, hi] for kernel radii up to `radius`, with cells of side
 * >= radius / reach. */
int rhod_cells_init(rhod_cells *c, const double lo[2], const double hi[2], double radius, int reach,
                    size_t cap);
int rhod_cells_reserve(rhod_cells *c, size_t cap);
void rhod_cells_free(rhod_cells *c);
/* Sorts particles [0, count) into the cells (positions on the device). Particles
 * outside the grid are clamped into the border cells. */
void rhod_cells_build(rhod_cells *c, const real *x, const real *y, size_t count);

/* mark[c] = 1 when some particle of cell c has flag != 0 (flags of the particles
 * sorted by the last build). Lets a gather skip particles with no flagged
 * particle in reach (rhod_cells_near_mark). */
void rhod_cells_mark(rhod_cells *c, const uint8_t *flag);

/* Cell coordinate of a position along one axis, clamped to the grid. */
static inline int rhod_cell_coord(real v, real o, real inv, int n) {
  int k = (int)((v - o) * inv);
  return k < 0 ? 0 : (k >= n ? n - 1 : k);
}

/* The gather loop. Inside a device region only plain locals may be used, so the
 * caller copies the arrays to locals first:
 *
 *   const rhod_grid G = cells->g; const int32_t *CS = cells->start, *CI = cells->idx;
 *   RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, j) { ... uses j ... } RHOD_END_NEIGHBOURS
 *
 * j runs over every particle (fluid and ghost, i itself included) in the cells
 * around (xi, yi); the body tests the distance against its own radius. */
#define RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, j)                                                  \
  {                                                                                                \
    const int cx_ = rhod_cell_coord((xi), (G).ox, (G).inv, (G).nx);                                \
    const int cy_ = rhod_cell_coord((yi), (G).oy, (G).inv, (G).ny);                                \
    const int y0_ = cy_ - (G).reach > 0 ? cy_ - (G).reach : 0;                                     \
    const int y1_ = cy_ + (G).reach < (G).ny - 1 ? cy_ + (G).reach : (G).ny - 1;                   \
    const int x0_ = cx_ - (G).reach > 0 ? cx_ - (G).reach : 0;                                     \
    const int x1_ = cx_ + (G).reach < (G).nx - 1 ? cx_ + (G).reach : (G).nx - 1;                   \
    for (int yy_ = y0_; yy_ <= y1_; yy_++) {                                                       \
      const int k0_ = (CS)[yy_ * (G).nx + x0_], k1_ = (CS)[yy_ * (G).nx + x1_ + 1];                \
      for (int k_ = k0_; k_ < k1_; k_++) {                                                         \
        const int j = (CI)[k_];
#define RHOD_END_NEIGHBOURS                                                                        \
  }                                                                                                \
  }                                                                                                \
  }

/* 1 when a cell in reach of (x, y) is marked (inside device regions: pass a local
 * copy of c->mark). */
static inline int rhod_cells_near_mark(rhod_grid G, const uint8_t *mark, real x, real y) {
  const int cx = rhod_cell_coord(x, G.ox, G.inv, G.nx), cy = rhod_cell_coord(y, G.oy, G.inv, G.ny);
  const int y0 = cy - G.reach > 0 ? cy - G.reach : 0;
  const int y1 = cy + G.reach < G.ny - 1 ? cy + G.reach : G.ny - 1;
  const int x0 = cx - G.reach > 0 ? cx - G.reach : 0;
  const int x1 = cx + G.reach < G.nx - 1 ? cx + G.reach : G.nx - 1;
  for (int yy = y0; yy <= y1; yy++)
    for (int xx = x0; xx <= x1; xx++)
      if (mark[yy * G.nx + xx])
        return 1;
  return 0;
}

/* Exclusive prefix sum of n ints in place on the device; returns the total. */
long rhod_scan_exclusive(int32_t *a, size_t n);

#endif
