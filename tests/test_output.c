/* Output a user can trust and read: units and provenance in every snapshot, /Parameters
 * holding any number of keys, the XDMF naming every dataset with explicit vertex cells,
 * the walls file, and the pictures' walls, axes and automatic colour range. */
#define _XOPEN_SOURCE 700

#include "cunit_main.h"
#include "rhod/io.h"
#include "rhod/version.h"
#include "test_io_util.h"

#include <ftw.h>
#include <hdf5.h>
#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ------------------------------------------------------------ particles */

static particles make_particles(size_t n) {
  particles P = alloc_particles(n);
  for (size_t i = 0; i < n; i++) {
    P.x[i] = (real)(0.1 + 0.01 * (double)(i % 50));
    P.y[i] = (real)(0.1 + 0.01 * (double)(i / 50));
    P.ux[i] = (real)(0.5 * (double)(i % 7));
    P.uy[i] = (real)(-0.25 * (double)(i % 3));
    P.rho[i] = (real)(1000.0 + (double)(i % 11));
    P.p[i] = (real)(50.0 * (double)(i % 13) - 100.0);
    P.m[i] = (real)0.1;
    P.size[i] = (real)(i % 2 ? 0.01 : 0.005);
    P.id[i] = 7 * i;
    P.fs[i] = (uint8_t)(i % 5 == 0);
  }
  return P;
}

/* ------------------------------------------------------------ HDF5 helpers */

/* A string attribute of an object (fixed or variable length), malloc'd; NULL if none. */
static char *str_attr(hid_t obj, const char *name) {
  if (H5Aexists(obj, name) <= 0)
    return NULL;
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  hid_t t = H5Aget_type(a);
  char *out = NULL;
  if (H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) <= 0) {
    size_t sz = H5Tget_size(t);
    out = calloc(sz + 1, 1);
    H5Aread(a, t, out);
  }
  H5Tclose(t);
  H5Aclose(a);
  return out;
}

typedef struct {
  int datasets, with_units;
  char missing[256];
} units_walk;

/* HDF5 1.10 (Debian 12) and 1.12+ name the visit and info calls differently */
#if H5_VERSION_GE(1, 12, 0)
typedef H5O_info2_t obj_info;
#define VISIT(f, cb, data) H5Ovisit3(f, H5_INDEX_NAME, H5_ITER_INC, cb, data, H5O_INFO_BASIC)
#define NUM_ATTRS(o, info) H5Oget_info3(o, info, H5O_INFO_NUM_ATTRS)
#else
typedef H5O_info_t obj_info;
#define VISIT(f, cb, data) H5Ovisit2(f, H5_INDEX_NAME, H5_ITER_INC, cb, data, H5O_INFO_BASIC)
#define NUM_ATTRS(o, info) H5Oget_info2(o, info, H5O_INFO_NUM_ATTRS)
#endif

static herr_t units_cb(hid_t obj, const char *name, const obj_info *info, void *data) {
  units_walk *w = data;
  if (info->type != H5O_TYPE_DATASET)
    return 0;
  w->datasets++;
  hid_t d = H5Dopen2(obj, name, H5P_DEFAULT);
  char *u = str_attr(d, "Units");
  if (u)
    w->with_units++;
  else
    snprintf(w->missing, sizeof w->missing, "%s", name);
  free(u);
  H5Dclose(d);
  return 0;
}

static void check_units(hid_t f, const char *path, const char *want) {
  hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
  CU_ASSERT_FATAL(d >= 0);
  char *u = str_attr(d, "Units");
  CU_ASSERT_PTR_NOT_NULL_FATAL(u);
  if (strcmp(u, want))
    printf("\n    %s: Units '%s', expected '%s' ", path, u, want);
  CU_ASSERT_STRING_EQUAL(u, want);
  free(u);
  H5Dclose(d);
}

/* ------------------------------------------------------------ snapshot */

static void test_units_and_provenance(void) {
  particles P = make_particles(120);
  rhod_snapshot_view v = view_of(&P, 0.5);
  char *keys[] = {"time.end"}, *vals[] = {"1"};
  rhod_param_list params = {keys, vals, 1};
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 0, &v, &params, err, sizeof err), RHOD_OK);
  hid_t f = H5Fopen(spath("snapshot_0000.h5"), H5F_ACC_RDONLY, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  /* provenance */
  hid_t h = H5Gopen2(f, "/Header", H5P_DEFAULT);
  char *ver = str_attr(h, "CodeVersion"), *commit = str_attr(h, "GitCommit");
  CU_ASSERT_PTR_NOT_NULL_FATAL(ver);
  CU_ASSERT_PTR_NOT_NULL_FATAL(commit);
  CU_ASSERT_STRING_EQUAL(ver, rhod_version());
  CU_ASSERT_STRING_EQUAL(commit, rhod_commit());
  CU_ASSERT_STRING_EQUAL(rhod_version(), "0.2.0");
  /* a short hash (maybe "-dirty") or "unknown" */
  CU_ASSERT(strlen(commit) >= 4);
  CU_ASSERT(strspn(commit, "0123456789abcdef") >= 4 || !strcmp(commit, "unknown"));
  free(ver);
  free(commit);
  H5Gclose(h);
  /* every dataset in the file has Units */
  units_walk w = {0, 0, ""};
  VISIT(f, units_cb, &w);
  CU_ASSERT_EQUAL(w.datasets, 11); /* 8 in PartType0, Mesh/Vertices, Parameters/Keys, Values */
  CU_ASSERT_EQUAL(w.with_units, w.datasets);
  if (w.with_units != w.datasets)
    printf("\n    dataset without Units: %s ", w.missing);
  check_units(f, "/PartType0/Coordinates", "m");
  check_units(f, "/PartType0/Velocities", "m/s");
  check_units(f, "/PartType0/Densities", "kg/m^3");
  check_units(f, "/PartType0/Pressures", "Pa");
  check_units(f, "/PartType0/Masses", "kg/m");
  check_units(f, "/PartType0/ParticleSizes", "m");
  check_units(f, "/PartType0/ParticleIDs", "1");
  check_units(f, "/PartType0/FreeSurface", "1");
  check_units(f, "/Mesh/Vertices", "1");
  check_units(f, "/Parameters/Keys", ""); /* text */
  check_units(f, "/Parameters/Values", "");
  /* the vertex cells: N x 1, 0..N-1 */
  hid_t d = H5Dopen2(f, "/Mesh/Vertices", H5P_DEFAULT);
  hid_t sp = H5Dget_space(d);
  hsize_t dims[2] = {0, 0};
  CU_ASSERT_EQUAL(H5Sget_simple_extent_ndims(sp), 2);
  H5Sget_simple_extent_dims(sp, dims, NULL);
  CU_ASSERT(dims[0] == 120 && dims[1] == 1);
  uint64_t ix[120];
  H5Dread(d, H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, ix);
  int seq = 1;
  for (int i = 0; i < 120; i++)
    seq &= ix[i] == (uint64_t)i;
  CU_ASSERT(seq);
  H5Sclose(sp);
  H5Dclose(d);
  H5Fclose(f);
  free_particles(&P);
}

/* NP parameters: 20000, more than an object header holds as compact attributes, and
 * 70000, more than HDF5 can number in creation order (65535): read back in scene order
 * from /Parameters/Keys and Values; the attributes as well up to 65535. */
static void many_parameters(unsigned NP) {
  char **keys = malloc(NP * sizeof *keys), **vals = malloc(NP * sizeof *vals);
  CU_ASSERT_FATAL(keys && vals);
  for (unsigned i = 0; i < NP; i++) {
    char k[64], v[64];
    /* not in name order, so that scene order is checked */
    snprintf(k, sizeof k, "fluid.%u.rect.min", (NP - 1 - i) * 7919u % NP);
    snprintf(v, sizeof v, "[%u, %u.5]", i, i);
    keys[i] = strdup(k);
    vals[i] = strdup(v);
  }
  rhod_param_list params = {keys, vals, NP};
  particles P = make_particles(10);
  rhod_snapshot_view v = view_of(&P, 1.0);
  char err[512] = "";
  int rc = rhod_write_snapshot(scratch, 1, &v, &params, err, sizeof err);
  if (rc)
    printf("\n    %s ", err);
  CU_ASSERT_EQUAL_FATAL(rc, RHOD_OK);
  rhod_snapshot_data d;
  rc = rhod_read_snapshot(spath("snapshot_0001.h5"), &d, err, sizeof err);
  if (rc)
    printf("\n    %s ", err);
  CU_ASSERT_EQUAL_FATAL(rc, RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(d.params.n, NP);
  int same = 1;
  for (unsigned i = 0; i < NP; i++)
    same &= !strcmp(d.params.keys[i], keys[i]) && !strcmp(d.params.values[i], vals[i]);
  CU_ASSERT(same);
  CU_ASSERT_EQUAL(d.n, 10);
  rhod_snapshot_data_free(&d);
  /* one attribute through plain HDF5, as h5py reads it */
  hid_t f = H5Fopen(spath("snapshot_0001.h5"), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t g = H5Gopen2(f, "/Parameters", H5P_DEFAULT);
  char *s = str_attr(g, keys[NP - 1]);
  if (NP <= 65535) {
    CU_ASSERT_PTR_NOT_NULL(s);
    if (s)
      CU_ASSERT_STRING_EQUAL(s, vals[NP - 1]);
  }
  free(s);
  obj_info oi;
  NUM_ATTRS(g, &oi);
  CU_ASSERT_EQUAL(oi.num_attrs, NP <= 65535 ? NP : 0);
  H5Gclose(g);
  H5Fclose(f);
  for (unsigned i = 0; i < NP; i++) {
    free(keys[i]);
    free(vals[i]);
  }
  free(keys);
  free(vals);
  free_particles(&P);
}

/* ------------------------------------------------------------ XDMF */

static void test_xdmf_fields(void) {
  double times[2] = {0.0, 0.5};
  size_t np[2] = {120, 130};
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(
      rhod_write_xdmf(scratch, 2, times, np, RHOD_FIELDS_FREE_SURFACE, err, sizeof err), RHOD_OK);
  char *s = slurp(spath("snapshots.xdmf"), NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(s);
  CU_ASSERT_PTR_NOT_NULL(strstr(s, "<Xdmf Version=\"3.0\""));
  CU_ASSERT_EQUAL(count_of(s, "Name=\"FreeSurface\""), 2);
  CU_ASSERT_EQUAL(count_of(s, "<Attribute "), 14);
  /* explicit connectivity in every topology, N x 1 */
  CU_ASSERT_EQUAL(count_of(s, "NodesPerElement=\"1\">"), 2);
  CU_ASSERT_EQUAL(count_of(s, "</Topology>"), 2);
  CU_ASSERT_PTR_NOT_NULL(strstr(s, "Dimensions=\"130 1\" NumberType=\"UInt\" Precision=\"4\" "
                                   "Format=\"HDF\">snapshot_0001.h5:/Mesh/Vertices<"));
  CU_ASSERT_PTR_NOT_NULL(strstr(s, "snapshot_0000.h5:/PartType0/FreeSurface<"));
  free(s);
  /* without the flag: no FreeSurface */
  CU_ASSERT_EQUAL_FATAL(rhod_write_xdmf(scratch, 2, times, np, 0, err, sizeof err), RHOD_OK);
  s = slurp(spath("snapshots.xdmf"), NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(s);
  CU_ASSERT_EQUAL(count_of(s, "FreeSurface"), 0);
  free(s);
  particles P = make_particles(3);
  rhod_snapshot_view v = view_of(&P, 0);
  CU_ASSERT_EQUAL(rhod_snapshot_fields(&v), RHOD_FIELDS_FREE_SURFACE);
  v.fs = NULL;
  CU_ASSERT_EQUAL(rhod_snapshot_fields(&v), 0);
  free_particles(&P);
}

/* ------------------------------------------------------------ walls */

static double square[4][2] = {{0.7, 0.7}, {0.9, 0.7}, {0.9, 0.9}, {0.7, 0.9}};

static void make_walls(rhod_wall w[3]) {
  memset(w, 0, 3 * sizeof *w);
  w[0].shape.kind = RHOD_SHAPE_RECT; /* the container: [0, 1] x [0, 1] */
  w[0].shape.max[0] = w[0].shape.max[1] = 1.0;
  w[0].fluid_inside = 1;
  w[1].shape.kind = RHOD_SHAPE_CIRCLE;
  w[1].shape.center[0] = 0.5;
  w[1].shape.center[1] = 0.4;
  w[1].shape.radius = 0.1;
  w[2].shape.kind = RHOD_SHAPE_POLYGON;
  w[2].shape.points = square;
  w[2].shape.n_points = 4;
}

static void test_walls_file(void) {
  rhod_wall w[3];
  make_walls(w);
  rhod_scene *sc = calloc(1, sizeof *sc);
  CU_ASSERT_PTR_NOT_NULL_FATAL(sc);
  sc->walls = w;
  sc->n_walls = 3;
  sc->dx = 0.01;
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_walls(scratch, sc, err, sizeof err), RHOD_OK);
  CU_ASSERT(access(spath("walls.h5.tmp"), F_OK) != 0);
  hid_t f = H5Fopen(spath("walls.h5"), H5F_ACC_RDONLY, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  /* circle: segments no longer than dx/4: 2 pi 0.1 / 0.0025 = 252 */
  const size_t nc = 252, np = 4 + nc + 4;
  hid_t d = H5Dopen2(f, "/Walls/Points", H5P_DEFAULT);
  hid_t sp = H5Dget_space(d);
  hsize_t dims[2] = {0, 0};
  H5Sget_simple_extent_dims(sp, dims, NULL);
  CU_ASSERT(dims[0] == np && dims[1] == 3);
  double(*pts)[3] = malloc(sizeof(double[3]) * np);
  H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pts);
  H5Sclose(sp);
  H5Dclose(d);
  CU_ASSERT(pts[2][0] == 1.0 && pts[2][1] == 1.0 && pts[2][2] == 0.0);
  int on_circle = 1;
  for (size_t k = 4; k < 4 + nc; k++)
    on_circle &= fabs(hypot(pts[k][0] - 0.5, pts[k][1] - 0.4) - 0.1) < 1e-12;
  CU_ASSERT(on_circle);
  CU_ASSERT(pts[np - 1][0] == 0.7 && pts[np - 1][1] == 0.9);
  free(pts);
  uint32_t(*seg)[2] = malloc(sizeof(uint32_t[2]) * np);
  uint32_t *wi = malloc(sizeof(uint32_t) * np);
  d = H5Dopen2(f, "/Walls/Segments", H5P_DEFAULT);
  H5Dread(d, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, seg);
  H5Dclose(d);
  d = H5Dopen2(f, "/Walls/WallIndex", H5P_DEFAULT);
  H5Dread(d, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, wi);
  H5Dclose(d);
  /* closed rings: the rect 0-1, 1-2, 2-3, 3-0; the circle's last segment back to 4 */
  CU_ASSERT(seg[3][0] == 3 && seg[3][1] == 0);
  CU_ASSERT(seg[4 + nc - 1][0] == 4 + nc - 1 && seg[4 + nc - 1][1] == 4);
  CU_ASSERT(seg[np - 1][1] == 4 + nc);
  CU_ASSERT(wi[0] == 0 && wi[4] == 1 && wi[np - 1] == 2);
  free(seg);
  free(wi);
  uint8_t inside[3] = {9, 9, 9};
  d = H5Dopen2(f, "/Walls/FluidInside", H5P_DEFAULT);
  H5Dread(d, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, inside);
  H5Dclose(d);
  CU_ASSERT(inside[0] == 1 && inside[1] == 0 && inside[2] == 0);
  hid_t h = H5Gopen2(f, "/Header", H5P_DEFAULT);
  char *commit = str_attr(h, "GitCommit");
  CU_ASSERT_PTR_NOT_NULL(commit);
  if (commit)
    CU_ASSERT_STRING_EQUAL(commit, rhod_commit());
  free(commit);
  H5Gclose(h);
  units_walk uw = {0, 0, ""};
  VISIT(f, units_cb, &uw);
  CU_ASSERT_EQUAL(uw.datasets, 4);
  CU_ASSERT_EQUAL(uw.with_units, 4);
  H5Fclose(f);
  char *x = slurp(spath("walls.xdmf"), NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(x);
  CU_ASSERT_PTR_NOT_NULL(strstr(x, "TopologyType=\"Polyline\" NumberOfElements=\"260\" "
                                   "NodesPerElement=\"2\""));
  CU_ASSERT_PTR_NOT_NULL(strstr(x, "walls.h5:/Walls/Segments<"));
  free(x);

  /* a folder that does not exist: the error names the file */
  char dir[4200];
  snprintf(dir, sizeof dir, "%s/no_such_dir", scratch);
  CU_ASSERT_EQUAL(rhod_write_walls(dir, sc, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "no_such_dir/walls.h5"));
  /* no walls: both files removed */
  sc->n_walls = 0;
  CU_ASSERT_EQUAL(rhod_write_walls(scratch, sc, err, sizeof err), RHOD_OK);
  CU_ASSERT(access(spath("walls.h5"), F_OK) != 0);
  CU_ASSERT(access(spath("walls.xdmf"), F_OK) != 0);
  free(sc);
}

/* ------------------------------------------------------------ pictures */

static const unsigned char *pix(const rgb_image *im, unsigned x, unsigned y) {
  return im->px + 3 * ((size_t)y * im->w + x);
}
static int is_rgb(const rgb_image *im, unsigned x, unsigned y, int r, int g, int b) {
  const unsigned char *p = pix(im, x, y);
  return p[0] == r && p[1] == g && p[2] == b;
}
static int is_wall(const rgb_image *im, unsigned x, unsigned y) {
  return is_rgb(im, x, y, 40, 40, 40);
}
/* black text pixels in [x0, x1) x [y0, y1) */
static int ink_in(const rgb_image *im, unsigned x0, unsigned x1, unsigned y0, unsigned y1) {
  int n = 0;
  for (unsigned y = y0; y < y1 && y < im->h; y++)
    for (unsigned x = x0; x < x1 && x < im->w; x++)
      n += is_rgb(im, x, y, 0, 0, 0);
  return n;
}

static void test_picture_walls_axes(void) {
  /* frame [0, 1] x [0, 1] at 200 px: 200 px per metre; no particles near the walls */
  particles P = make_particles(2);
  P.x[0] = (real)0.25, P.y[0] = (real)0.75, P.p[0] = 10;
  P.x[1] = (real)0.75, P.y[1] = (real)0.25, P.p[1] = 0;
  P.size[0] = P.size[1] = (real)0.05;
  rhod_snapshot_view v = view_of(&P, 0.25);
  rhod_wall w[3];
  make_walls(w);
  double lo[2] = {0, 0}, hi[2] = {1, 1};
  char err[512] = "";
  rhod_picture_geometry g;
  CU_ASSERT_EQUAL_FATAL(rhod_picture_layout(200, 1, lo, hi, &g), 0);
  CU_ASSERT(g.frame_x > 0 && g.frame_y > 0 && g.frame_w == 200 && g.frame_h == 200);
  CU_ASSERT(g.pic_w > g.frame_x + 200 && g.pic_h > g.frame_y + 200);
  const char *path = spath("walls.png");
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, hi, NULL, w,
                                           3, err, sizeof err),
                        RHOD_OK);
  rgb_image im;
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT_EQUAL(im.w, g.pic_w);
  CU_ASSERT_EQUAL(im.h, g.pic_h);
  const unsigned X = g.frame_x, Y = g.frame_y;
  /* the container on the frame's edges: its two outermost pixel columns and rows */
  for (unsigned k = 10; k < 190; k += 30) {
    CU_ASSERT(is_wall(&im, X + 0, Y + k) && is_wall(&im, X + 1, Y + k));
    CU_ASSERT(is_wall(&im, X + 198, Y + k) && is_wall(&im, X + 199, Y + k));
    CU_ASSERT(is_wall(&im, X + k, Y + 0) && is_wall(&im, X + k, Y + 1));
    CU_ASSERT(is_wall(&im, X + k, Y + 198) && is_wall(&im, X + k, Y + 199));
    CU_ASSERT(!is_wall(&im, X + 2, Y + k) && !is_wall(&im, X + 197, Y + k));
  }
  /* the circle (centre (100, 120) px, radius 20 px): at its left and top, not inside */
  CU_ASSERT(is_wall(&im, X + 80, Y + 120) || is_wall(&im, X + 79, Y + 120));
  CU_ASSERT(is_wall(&im, X + 100, Y + 100) || is_wall(&im, X + 100, Y + 99));
  CU_ASSERT(is_rgb(&im, X + 100, Y + 120, 255, 255, 255));
  /* the square [140, 180] x [20, 60] px */
  CU_ASSERT(is_wall(&im, X + 160, Y + 59) || is_wall(&im, X + 160, Y + 60));
  CU_ASSERT(is_wall(&im, X + 140, Y + 40) || is_wall(&im, X + 139, Y + 40));
  CU_ASSERT(is_rgb(&im, X + 160, Y + 40, 255, 255, 255));
  /* the particles are still drawn: p = 10 the top colour, p = 0 the bottom one */
  CU_ASSERT(is_rgb(&im, X + 50, Y + 50, 253, 231, 37));
  CU_ASSERT(is_rgb(&im, X + 150, Y + 150, 68, 1, 84));
  /* axes: tick labels left of the frame and below it, the titles; none above */
  CU_ASSERT(ink_in(&im, 0, X - 1, Y, Y + 200) > 100);
  CU_ASSERT(ink_in(&im, X, X + 200, Y + 201, Y + 230) > 100);
  CU_ASSERT(ink_in(&im, 0, g.pic_w, 0, Y / 2) == 0);
  free(im.px);

  /* without walls the frame's edge is particle or background, never wall ink */
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, hi, NULL,
                                           NULL, 0, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  int any = 0;
  for (unsigned k = 0; k < 200; k++)
    any |= is_wall(&im, X, Y + k) || is_wall(&im, X + k, Y + 199);
  CU_ASSERT(!any);
  free(im.px);

  /* a box that leaves the obstacles out: only the container's part inside is drawn */
  double blo[2] = {0, 0}, bhi[2] = {0.3, 0.3};
  CU_ASSERT_EQUAL_FATAL(rhod_picture_layout(300, 1, blo, bhi, &g), 0);
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 300, blo, bhi, NULL, w,
                                           3, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT(is_wall(&im, g.frame_x, g.frame_y + 150));        /* x = 0 */
  CU_ASSERT(is_wall(&im, g.frame_x + 150, g.frame_y + 299));  /* y = 0 */
  CU_ASSERT(!is_wall(&im, g.frame_x + 299, g.frame_y + 150)); /* x = 0.3: no wall */
  CU_ASSERT(!is_wall(&im, g.frame_x + 150, g.frame_y));       /* y = 0.3: no wall */
  free(im.px);
  free_particles(&P);
}

static void test_field_range(void) {
  particles P = make_particles(4);
  real ps[4] = {3, -2, 7, 1}, sz[4] = {0.01, 0.005, 0.0025, 0.01};
  for (int i = 0; i < 4; i++)
    P.p[i] = ps[i], P.size[i] = sz[i], P.ux[i] = (real)(i == 2 ? 3 : 0),
    P.uy[i] = (real)(i == 2 ? 4 : 0);
  rhod_snapshot_view v = view_of(&P, 0);
  double r[2];
  CU_ASSERT_EQUAL(rhod_picture_field_range(&v, RHOD_FIELD_PRESSURE, r), 0);
  CU_ASSERT(r[0] == -2 && r[1] == 7);
  CU_ASSERT_EQUAL(rhod_picture_field_range(&v, RHOD_FIELD_VELOCITY, r), 0);
  CU_ASSERT(r[0] == 0 && r[1] == 5);
  CU_ASSERT_EQUAL(rhod_picture_field_range(&v, RHOD_FIELD_SIZE, r), 0);
  CU_ASSERT(r[0] == (double)(real)0.0025 && r[1] == (double)(real)0.01);
  /* non-finite values are left out */
  P.p[0] = (real)NAN; /* first: it must not seed the range */
  P.p[2] = (real)INFINITY;
  CU_ASSERT_EQUAL(rhod_picture_field_range(&v, RHOD_FIELD_PRESSURE, r), 0);
  CU_ASSERT(r[0] == -2 && r[1] == 1);
  v.n = 0;
  CU_ASSERT_EQUAL(rhod_picture_field_range(&v, RHOD_FIELD_PRESSURE, r), -1);
  CU_ASSERT(r[0] == 0 && r[1] == 0);
  free_particles(&P);
}

/* A snapshot of an earlier version, with /Parameters as attributes only: read in order. */
static void test_parameters_attributes_only(void) {
  char *keys[] = {"time.end", "physics.gravity", "name"}, *vals[] = {"2", "[0, -9.81]", "z"};
  rhod_param_list params = {keys, vals, 3};
  particles P = make_particles(5);
  rhod_snapshot_view v = view_of(&P, 0.0);
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 2, &v, &params, err, sizeof err), RHOD_OK);
  hid_t f = H5Fopen(spath("snapshot_0002.h5"), H5F_ACC_RDWR, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  CU_ASSERT(H5Ldelete(f, "/Parameters/Keys", H5P_DEFAULT) >= 0);
  CU_ASSERT(H5Ldelete(f, "/Parameters/Values", H5P_DEFAULT) >= 0);
  H5Fclose(f);
  rhod_snapshot_data d;
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0002.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(d.params.n, 3);
  for (unsigned i = 0; i < 3; i++) {
    CU_ASSERT_STRING_EQUAL(d.params.keys[i], keys[i]);
    CU_ASSERT_STRING_EQUAL(d.params.values[i], vals[i]);
  }
  rhod_snapshot_data_free(&d);
  free_particles(&P);
}

static void test_many_parameters(void) {
  many_parameters(20000);
  many_parameters(70000);
}

int main(void) {
  snprintf(scratch, sizeof scratch, "%s/test_output_XXXXXX", RHOD_BINARY_DIR);
  if (!mkdtemp(scratch)) {
    perror(scratch);
    return 2;
  }
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  static const rhod_test_case cases[] = {
      {"units and provenance in every snapshot", test_units_and_provenance},
      {"20000 and 70000 parameters", test_many_parameters},
      {"parameters of an older snapshot", test_parameters_attributes_only},
      {"xdmf: every field, vertex cells", test_xdmf_fields},
      {"walls file", test_walls_file},
      {"picture: walls and axes", test_picture_walls_axes},
      {"picture: automatic field range", test_field_range},
  };
  int rc = RHOD_RUN_TESTS("output", cases);
  nftw(scratch, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
  H5close();
  return rc;
}
