/* Cell lists: key, histogram, scan, scatter, per-cell order by index. Runs where the
 * particles live (device or host). */
#include "rhod/cells.h"
#include "rhod/device.h"
#include "rhod/status.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SCAN_BLOCK 2048

static int32_t *scan_blocks;
static size_t scan_blocks_cap;

static int32_t *blocks_buffer(size_t nb) {
  if (nb > scan_blocks_cap) {
    rhod_dev_free(scan_blocks, scan_blocks_cap * sizeof(int32_t));
    scan_blocks_cap = nb + 64;
    scan_blocks = rhod_dev_calloc(scan_blocks_cap, sizeof(int32_t));
    if (!scan_blocks)
      scan_blocks_cap = 0;
  }
  return scan_blocks;
}

long rhod_scan_exclusive(int32_t *a, size_t n) {
  if (n == 0)
    return 0;
  const long nb = (long)((n + SCAN_BLOCK - 1) / SCAN_BLOCK);
  int32_t *bs = blocks_buffer((size_t)nb);
  if (!bs)
    return -1;
  const long nn = (long)n;
  /* 1. each block's sum */
  RHOD_KERNEL_LOOP
  for (long b = 0; b < nb; b++) {
    long s = 0;
    const long e = (b + 1) * SCAN_BLOCK < nn ? (b + 1) * SCAN_BLOCK : nn;
    for (long k = b * SCAN_BLOCK; k < e; k++)
      s += a[k];
    bs[b] = (int32_t)s;
  }
  /* 2. scan of the block sums (few: one thread) */
  long total = 0;
#ifdef RHOD_OFFLOAD
#pragma omp target map(tofrom : total)
#endif
  {
    long s = 0;
    for (long b = 0; b < nb; b++) {
      const long v = bs[b];
      bs[b] = (int32_t)s;
      s += v;
    }
    total = s;
  }
  /* 3. each block scanned from its offset */
  RHOD_KERNEL_LOOP
  for (long b = 0; b < nb; b++) {
    long s = bs[b];
    const long e = (b + 1) * SCAN_BLOCK < nn ? (b + 1) * SCAN_BLOCK : nn;
    for (long k = b * SCAN_BLOCK; k < e; k++) {
      const long v = a[k];
      a[k] = (int32_t)s;
      s += v;
    }
  }
  return total;
}

static void map_alloc(int32_t **p, size_t n) { *p = rhod_dev_calloc(n, sizeof(int32_t)); }

static void map_free(int32_t **p, size_t n) {
  rhod_dev_free(*p, n * sizeof(int32_t));
  *p = NULL;
}

static int init_lattice(rhod_cells *c, const double lo[2], const double hi[2], double radius,
                        int reach, size_t cap) {
  memset(c, 0, sizeof *c);
  if (reach < 1)
    return RHOD_ERR_SCENE;
  const double cell = radius / reach;
  if (!(cell > 0))
    return RHOD_ERR_SCENE;
  const double w = hi[0] - lo[0], h = hi[1] - lo[1];
  c->g.nx = (int)floor(w / cell);
  c->g.ny = (int)floor(h / cell);
  if (c->g.nx < 1)
    c->g.nx = 1;
  if (c->g.ny < 1)
    c->g.ny = 1;
  /* cells a little larger than asked so that nx cells tile the box exactly */
  const double cw = fmax(w / c->g.nx, h / c->g.ny);
  if ((double)c->g.nx * c->g.ny > 2e9)
    return RHOD_ERR_MEMORY;
  c->g.ox = (real)lo[0];
  c->g.oy = (real)lo[1];
  c->g.inv = (real)(1.0 / cw);
  c->g.reach = reach;
  c->g.iR0 = (real)(1.0 / radius);
  c->nx_box = c->g.nx, c->ny_box = c->g.ny; /* the window starts as the whole box */
  c->ncells_box = c->ncells = (size_t)c->g.nx * (size_t)c->g.ny;
  map_alloc(&c->start, c->ncells_box + 1);
  map_alloc(&c->count, c->ncells_box + 1);
  if (!c->start || !c->count)
    return RHOD_ERR_MEMORY;
  return rhod_cells_reserve(c, cap);
}

int rhod_cells_init(rhod_cells *c, const double lo[2], const double hi[2], double radius, int reach,
                    size_t cap) {
  return init_lattice(c, lo, hi, radius, reach, cap);
}

int rhod_cells_reserve(rhod_cells *c, size_t cap) {
  if (cap <= c->cap && c->idx)
    return RHOD_OK;
  map_free(&c->idx, c->cap);
  map_free(&c->key, c->cap);
  c->cap = cap;
  map_alloc(&c->idx, cap);
  map_alloc(&c->key, cap);
  return (c->idx && c->key) ? RHOD_OK : RHOD_ERR_MEMORY;
}

void rhod_cells_free(rhod_cells *c) {
  map_free(&c->start, c->ncells_box + 1);
  map_free(&c->count, c->ncells_box + 1);
  map_free(&c->idx, c->cap);
  map_free(&c->key, c->cap);
}

static long sort_counted(rhod_cells *c, const int32_t *key, const uint8_t *flag, long n);

/* Zeroes the histogram of c's cells (the window's, and the total's slot). */
static int32_t *clear_counts(rhod_cells *c) {
  int32_t *cnt = c->count;
  const long nc = (long)c->ncells;
  RHOD_KERNEL_LOOP
  for (long k = 0; k <= nc; k++)
    cnt[k] = 0;
  return cnt;
}

void rhod_cells_build(rhod_cells *c, const real *x, const real *y, size_t count) {
  int32_t *key = c->key;
  const long n = (long)count;
  c->nbuilt = n;
  /* the window: the lowest and highest occupied cells of the box's lattice */
  {
    const real ox = c->g.ox, oy = c->g.oy, inv = c->g.inv;
    const int bx = c->nx_box, by = c->ny_box;
    int lx = bx - 1, ly = by - 1, hx = 0, hy = 0;
    RHOD_KERNEL_LOOP_REDUCE2(min, lx, ly)
    for (long i = 0; i < n; i++) {
      const int cx = rhod_cell_coord(x[i], ox, inv, 0, bx),
                cy = rhod_cell_coord(y[i], oy, inv, 0, by);
      lx = cx < lx ? cx : lx;
      ly = cy < ly ? cy : ly;
    }
    RHOD_KERNEL_LOOP_REDUCE2(max, hx, hy)
    for (long i = 0; i < n; i++) {
      const int cx = rhod_cell_coord(x[i], ox, inv, 0, bx),
                cy = rhod_cell_coord(y[i], oy, inv, 0, by);
      hx = cx > hx ? cx : hx;
      hy = cy > hy ? cy : hy;
    }
    if (n == 0)
      lx = ly = hx = hy = 0;
    c->g.cx0 = lx, c->g.cy0 = ly;
    c->g.nx = hx - lx + 1, c->g.ny = hy - ly + 1;
    c->ncells = (size_t)c->g.nx * (size_t)c->g.ny;
  }
  const rhod_grid G = c->g;
  int32_t *cnt = clear_counts(c);
  /* each particle's key and the histogram in one loop */
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    const int cx = rhod_cell_coord(x[i], G.ox, G.inv, G.cx0, G.nx);
    const int cy = rhod_cell_coord(y[i], G.oy, G.inv, G.cy0, G.ny);
    const int k = cy * G.nx + cx;
    key[i] = k;
#pragma omp atomic update
    cnt[k] += 1;
  }
  (void)sort_counted(c, key, NULL, n);
}

/* The rest of the counting sort, from the histogram of the keys in c->count: particles
 * [0, n) (those with flag != 0 only, unless flag is NULL) into c's start and idx;
 * returns how many were sorted. */
static long sort_counted(rhod_cells *c, const int32_t *key, const uint8_t *flag, long n) {
  int32_t *cnt = c->count, *start = c->start, *idx = c->idx;
  const long nc = (long)c->ncells;
  const int all = flag == NULL;

  const long total = rhod_scan_exclusive(cnt, (size_t)nc + 1);

  RHOD_KERNEL_LOOP
  for (long k = 0; k <= nc; k++)
    start[k] = cnt[k];

  /* scatter; the slot order inside a cell depends on thread timing ... */
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    if (all || flag[i]) {
      int slot;
#pragma omp atomic capture
      slot = cnt[key[i]]++;
      idx[slot] = (int32_t)i;
    }
  }

  /* ... so each cell is then put in index order (insertion sort: cells are small),
   * which makes every neighbour sum reproducible bit for bit. */
  RHOD_KERNEL_LOOP
  for (long k = 0; k < nc; k++) {
    const int a = start[k], b = start[k + 1];
    for (int s = a + 1; s < b; s++) {
      const int32_t v = idx[s];
      int t = s - 1;
      while (t >= a && idx[t] > v) {
        idx[t + 1] = idx[t];
        t--;
      }
      idx[t + 1] = v;
    }
  }
  return total;
}

/* Sizes a subset to `from`: start and count for from's whole box, idx for its capacity
 * (the subset keeps no keys). */
static int fit_subset(rhod_cells *u, const rhod_cells *from) {
  if (!u->start || u->ncells_box < from->ncells_box) {
    map_free(&u->start, u->ncells_box + 1);
    map_free(&u->count, u->ncells_box + 1);
    u->ncells_box = from->ncells_box;
    map_alloc(&u->start, u->ncells_box + 1);
    map_alloc(&u->count, u->ncells_box + 1);
  }
  if (!u->idx || u->cap < from->cap) {
    map_free(&u->idx, u->cap);
    u->cap = from->cap;
    map_alloc(&u->idx, u->cap);
  }
  u->nx_box = from->nx_box, u->ny_box = from->ny_box;
  return u->start && u->count && u->idx ? RHOD_OK : RHOD_ERR_MEMORY;
}

long rhod_cells_build_subset(rhod_cells *u, const rhod_cells *from, const uint8_t *flag) {
  if (fit_subset(u, from) != RHOD_OK)
    return -1;
  u->g = from->g, u->ncells = from->ncells; /* the window of from's last build */
  int32_t *cnt = clear_counts(u);
  const int32_t *key = from->key;
  const long n = from->nbuilt;
  RHOD_KERNEL_LOOP
  for (long i = 0; i < n; i++) {
    if (flag[i]) {
#pragma omp atomic update
      cnt[key[i]] += 1;
    }
  }
  return u->nbuilt = sort_counted(u, key, flag, n);
}

void rhod_cells_pack(const rhod_cells *c, long nt, real *row, const real *src, int stride,
                     int comp) {
  const int32_t *CI = c->idx;
  RHOD_KERNEL_LOOP
  for (long k = 0; k < nt; k++)
    row[k] = src[(long)stride * CI[k] + comp];
}

void rhod_cells_pack_u8(const rhod_cells *c, long nt, real *row, const uint8_t *src) {
  const int32_t *CI = c->idx;
  RHOD_KERNEL_LOOP
  for (long k = 0; k < nt; k++)
    row[k] = (real)src[CI[k]];
}
