/* Sorted cell lists by counting sort, and the one neighbour loop every gather uses.
 *
 * The grid covers a box with square cells of side `cell` >= the largest kernel radius,
 * so the 3x3 block of cells around a particle holds its whole support. Order inside a
 * cell is by particle index, so every sum is taken in the same order run after run
 * (bit-reproducible). A per-refinement-level grid is a set of these with their own
 * cell size (APR). */
#ifndef RHOD_CELLS_H
#define RHOD_CELLS_H

#include "rhod/config.h"
#include "rhod/particles.h"

/* Grid geometry, plain values: safe to pass by value into device regions. */
typedef struct {
  real ox, oy; /* lower-left corner */
  real inv;    /* 1 / cell */
  int nx, ny;
} rhod_grid;

typedef struct {
  rhod_grid g;
  size_t ncells;
  int32_t *start; /* ncells + 1: particles of cell c are idx[start[c] .. start[c+1]) */
  int32_t *count; /* ncells: histogram scratch */
  int32_t *idx;   /* cap: particle indices sorted by cell */
  int32_t *key;   /* cap: cell of each particle */
  size_t cap;
} rhod_cells;

/* Sets up a grid over [lo, hi] with cells of side >= cell. */
int rhod_cells_init(rhod_cells *c, const double lo[2], const double hi[2], double cell, size_t cap);
int rhod_cells_reserve(rhod_cells *c, size_t cap);
void rhod_cells_free(rhod_cells *c);
/* Sorts particles [0, count) into the cells (positions on the device). Particles
 * outside the grid are clamped into the border cells. */
void rhod_cells_build(rhod_cells *c, const real *x, const real *y, size_t count);

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
 * j runs over every particle (fluid and ghost, i itself included) in the 3x3 cells
 * around (xi, yi); the body tests the distance against its own radius. */
#define RHOD_FOR_NEIGHBOURS(G, CS, CI, xi, yi, j)                                                  \
  {                                                                                                \
    const int cx_ = rhod_cell_coord((xi), (G).ox, (G).inv, (G).nx);                                \
    const int cy_ = rhod_cell_coord((yi), (G).oy, (G).inv, (G).ny);                                \
    const int y0_ = cy_ > 0 ? cy_ - 1 : 0, y1_ = cy_ < (G).ny - 1 ? cy_ + 1 : cy_;                 \
    const int x0_ = cx_ > 0 ? cx_ - 1 : 0, x1_ = cx_ < (G).nx - 1 ? cx_ + 1 : cx_;                 \
    for (int yy_ = y0_; yy_ <= y1_; yy_++) {                                                       \
      const int k0_ = (CS)[yy_ * (G).nx + x0_], k1_ = (CS)[yy_ * (G).nx + x1_ + 1];                \
      for (int k_ = k0_; k_ < k1_; k_++) {                                                         \
        const int j = (CI)[k_];
#define RHOD_END_NEIGHBOURS                                                                        \
  }                                                                                                \
  }                                                                                                \
  }

/* Exclusive prefix sum of n ints in place on the device; returns the total. */
long rhod_scan_exclusive(int32_t *a, size_t n);

#endif
