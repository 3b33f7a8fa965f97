/* The bodies in the output (issue 51): /Bodies of a snapshot written and read back exactly,
 * none without bodies, the bodies' Polyline grids in the XDMF, their outlines (and light
 * grey insides) in the pictures. */
#define _XOPEN_SOURCE 700

#include "cunit_main.h"
#include "rhod/io.h"
#include "test_io_util.h"

#include <ftw.h>
#include <hdf5.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Two bodies: the square [0.2, 0.4] x [0.6, 0.8] and the triangle (0.6, 0.2), (0.9, 0.2),
 * (0.75, 0.45), as rhod_sim_fetch gives them (x, y interleaved). */
static const unsigned body_start[3] = {0, 4, 7};
static const double body_xy[14] = {0.2, 0.6, 0.4, 0.6, 0.4, 0.8,  0.2,
                                   0.8, 0.6, 0.2, 0.9, 0.2, 0.75, 0.45};

static particles make_particles(size_t n) {
  particles P = alloc_particles(n);
  for (size_t i = 0; i < n; i++) {
    P.x[i] = (real)(0.05 + 0.1 * (double)i);
    P.y[i] = (real)0.05;
    P.rho[i] = (real)1000;
    P.m[i] = (real)0.1;
    P.size[i] = (real)0.02;
    P.id[i] = i;
  }
  return P;
}

static rhod_snapshot_view with_bodies(const particles *P, double t) {
  rhod_snapshot_view v = view_of(P, t);
  v.n_bodies = 2;
  v.body_start = body_start;
  v.body_xy = body_xy;
  return v;
}

/* ------------------------------------------------------------ HDF5 */

static void test_bodies_roundtrip(void) {
  particles P = make_particles(5);
  rhod_snapshot_view v = with_bodies(&P, 0.75);
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 3, &v, NULL, err, sizeof err), RHOD_OK);
  rhod_snapshot_data d;
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0003.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_EQUAL(d.n, 5);
  CU_ASSERT_EQUAL(d.n_bodies, 2);
  CU_ASSERT_EQUAL_FATAL(d.n_body_points, 7);
  CU_ASSERT_EQUAL_FATAL(d.n_body_segments, 7);
  int same = 1;
  for (int k = 0; k < 14; k++)
    same &= d.body_xy[k] == body_xy[k];
  CU_ASSERT(same);
  /* closed rings: the square 0-1-2-3-0, the triangle 4-5-6-4 */
  const uint32_t seg[7][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 4}};
  const uint32_t idx[7] = {0, 0, 0, 0, 1, 1, 1};
  same = 1;
  for (int k = 0; k < 7; k++)
    same &= d.body_segments[2 * k] == seg[k][0] && d.body_segments[2 * k + 1] == seg[k][1] &&
            d.body_index[k] == idx[k];
  CU_ASSERT(same);
  rhod_snapshot_data_free(&d);
  CU_ASSERT_PTR_NULL(d.body_xy);

  /* the layout: plain contiguous datasets, P x 3 with z = 0, Units, NumBodies */
  hid_t f = H5Fopen(spath("snapshot_0003.h5"), H5F_ACC_RDONLY, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  hid_t g = H5Gopen2(f, "/Bodies", H5P_DEFAULT);
  CU_ASSERT_FATAL(g >= 0);
  uint32_t nb = 0;
  hid_t a = H5Aopen(g, "NumBodies", H5P_DEFAULT);
  CU_ASSERT(a >= 0 && H5Aread(a, H5T_NATIVE_UINT32, &nb) >= 0 && nb == 2);
  H5Aclose(a);
  const char *names[3] = {"Points", "Segments", "BodyIndex"};
  const hsize_t want[3][2] = {{7, 3}, {7, 2}, {7, 0}};
  for (int k = 0; k < 3; k++) {
    hid_t ds = H5Dopen2(g, names[k], H5P_DEFAULT);
    CU_ASSERT_FATAL(ds >= 0);
    hid_t sp = H5Dget_space(ds), pl = H5Dget_create_plist(ds);
    hsize_t dims[2] = {0, 0};
    int rank = H5Sget_simple_extent_dims(sp, dims, NULL);
    CU_ASSERT_EQUAL(rank, want[k][1] ? 2 : 1);
    CU_ASSERT(dims[0] == want[k][0] && dims[1] == want[k][1]);
    CU_ASSERT_EQUAL(H5Pget_layout(pl), H5D_CONTIGUOUS);
    CU_ASSERT_EQUAL(H5Pget_nfilters(pl), 0);
    CU_ASSERT(H5Aexists(ds, "Units") > 0);
    if (k == 0) {
      double pts[7][3];
      H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pts);
      int z0 = 1;
      for (int i = 0; i < 7; i++)
        z0 &= pts[i][2] == 0.0;
      CU_ASSERT(z0);
    }
    H5Pclose(pl);
    H5Sclose(sp);
    H5Dclose(ds);
  }
  H5Gclose(g);
  H5Fclose(f);
  free_particles(&P);
}

static void test_no_bodies_and_errors(void) {
  particles P = make_particles(4);
  rhod_snapshot_view v = view_of(&P, 0.0);
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 0, &v, NULL, err, sizeof err), RHOD_OK);
  hid_t f = H5Fopen(spath("snapshot_0000.h5"), H5F_ACC_RDONLY, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  CU_ASSERT(H5Lexists(f, "/Bodies", H5P_DEFAULT) == 0);
  H5Fclose(f);
  rhod_snapshot_data d;
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0000.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT(d.n_bodies == 0 && d.n_body_points == 0 && d.n_body_segments == 0);
  CU_ASSERT(!d.body_xy && !d.body_segments && !d.body_index);
  rhod_snapshot_data_free(&d);

  /* incomplete outlines are refused, nothing written */
  v = with_bodies(&P, 0.0);
  const unsigned bad_start[3] = {0, 5, 4};
  v.body_start = bad_start;
  CU_ASSERT_EQUAL(rhod_write_snapshot(scratch, 1, &v, NULL, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "bodies are incomplete"));
  v = with_bodies(&P, 0.0);
  v.body_xy = NULL;
  CU_ASSERT_EQUAL(rhod_write_snapshot(scratch, 1, &v, NULL, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT(access(spath("snapshot_0001.h5"), F_OK) != 0);

  /* a segment pointing past the points: the reader says so */
  v = with_bodies(&P, 0.0);
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 2, &v, NULL, err, sizeof err), RHOD_OK);
  f = H5Fopen(spath("snapshot_0002.h5"), H5F_ACC_RDWR, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  hid_t ds = H5Dopen2(f, "/Bodies/Segments", H5P_DEFAULT);
  uint32_t seg[7][2];
  H5Dread(ds, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, seg);
  seg[6][1] = 7;
  H5Dwrite(ds, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, seg);
  H5Dclose(ds);
  H5Fclose(f);
  CU_ASSERT_EQUAL(rhod_read_snapshot(spath("snapshot_0002.h5"), &d, err, sizeof err),
                  RHOD_ERR_READ);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "out of range"));
  CU_ASSERT_PTR_NULL(d.body_segments);
  free_particles(&P);
}

/* ------------------------------------------------------------ XDMF */

static void test_bodies_xdmf(void) {
  double times[2] = {0.0, 0.5};
  size_t np[2] = {120, 130};
  char err[512] = "";
  /* without bodies: the file of rhod_write_xdmf_fields, byte for byte */
  CU_ASSERT_EQUAL_FATAL(rhod_write_xdmf_fields(scratch, 2, times, np, RHOD_FIELDS_FREE_SURFACE,
                                               NULL, 0, err, sizeof err),
                        RHOD_OK);
  size_t la = 0, lb = 0;
  char *plain = slurp(spath("snapshots.xdmf"), &la);
  CU_ASSERT_EQUAL_FATAL(rhod_write_xdmf_bodies(scratch, 2, times, np, RHOD_FIELDS_FREE_SURFACE,
                                               NULL, 0, 0, err, sizeof err),
                        RHOD_OK);
  char *s = slurp(spath("snapshots.xdmf"), &lb);
  CU_ASSERT_PTR_NOT_NULL_FATAL(plain);
  CU_ASSERT_PTR_NOT_NULL_FATAL(s);
  CU_ASSERT(la == lb && memcmp(plain, s, la) == 0);
  CU_ASSERT_EQUAL(count_of(s, "bodies"), 0);
  free(s);

  CU_ASSERT_EQUAL_FATAL(rhod_write_xdmf_bodies(scratch, 2, times, np, RHOD_FIELDS_FREE_SURFACE,
                                               NULL, 0, 7, err, sizeof err),
                        RHOD_OK);
  s = slurp(spath("snapshots.xdmf"), NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(s);
  /* two temporal collections, the bodies' first (the particles' the domain's last) */
  CU_ASSERT_EQUAL(count_of(s, "CollectionType=\"Temporal\""), 2);
  const char *cb = strstr(s, "<Grid Name=\"bodies\" GridType=\"Collection\"");
  const char *cp = strstr(s, "<Grid Name=\"particles\" GridType=\"Collection\"");
  CU_ASSERT_FATAL(cb && cp && cb < cp);
  /* the bodies' collection closes before the particles' opens, and holds 2 grids */
  const char *close = strstr(cb, "\n    </Grid>\n");
  CU_ASSERT(close && close < cp);
  CU_ASSERT_EQUAL(count_of(s, "<Grid Name=\"bodies_"), 2);
  CU_ASSERT_EQUAL(count_of(s, "<Grid Name=\"snapshot_"), 2);
  CU_ASSERT_PTR_NOT_NULL(strstr(s, "<Grid Name=\"bodies_0001\" GridType=\"Uniform\">\n"
                                   "        <Time Value=\"0.5\"/>\n"
                                   "        <Topology TopologyType=\"Polyline\" "
                                   "NumberOfElements=\"7\" NodesPerElement=\"2\">\n"
                                   "          <DataItem Dimensions=\"7 2\" NumberType=\"UInt\" "
                                   "Precision=\"4\" Format=\"HDF\">snapshot_0001.h5:/Bodies/"
                                   "Segments</DataItem>\n"));
  CU_ASSERT_PTR_NOT_NULL(strstr(s, "<DataItem Dimensions=\"7 3\" NumberType=\"Float\" "
                                   "Precision=\"8\" Format=\"HDF\">snapshot_0000.h5:/Bodies/"
                                   "Points</DataItem>"));
  CU_ASSERT_EQUAL(count_of(s, "<Attribute Name=\"BodyIndex\" AttributeType=\"Scalar\" "
                              "Center=\"Cell\">\n          <DataItem Dimensions=\"7\" "
                              "NumberType=\"UInt\" Precision=\"4\""),
                  2);
  /* the particles' grids are those of the file without bodies */
  CU_ASSERT_PTR_NOT_NULL(strstr(s, strstr(plain, "<Grid Name=\"particles\"")));
  /* every element opened is closed */
  CU_ASSERT_EQUAL(count_of(s, "<Grid "), count_of(s, "</Grid>"));
  CU_ASSERT_EQUAL(count_of(s, "<Topology "), count_of(s, "</Topology>"));
  CU_ASSERT_EQUAL(count_of(s, "<Geometry "), count_of(s, "</Geometry>"));
  CU_ASSERT_EQUAL(count_of(s, "<Attribute "), count_of(s, "</Attribute>"));
  CU_ASSERT_EQUAL(count_of(s, "<DataItem "), count_of(s, "</DataItem>"));
  free(s);
  free(plain);
}

/* ------------------------------------------------------------ pictures */

static int rgb_at(const rgb_image *im, unsigned x, unsigned y, int r, int g, int b) {
  const unsigned char *p = im->px + 3 * ((size_t)y * im->w + x);
  return p[0] == r && p[1] == g && p[2] == b;
}
static int dark(const rgb_image *im, unsigned x, unsigned y) {
  return rgb_at(im, x, y, 40, 40, 40);
}

static void test_bodies_picture(void) {
  /* frame [0, 1] x [0, 1] at 200 px: the square [40, 80] x [40, 80] px, the triangle
   * (120, 160), (180, 160), (150, 110) px; particles along the bottom, one inside the
   * square at (50, 50) px and one across its left edge at (40, 60) px */
  particles P = make_particles(7);
  P.x[5] = (real)0.25, P.y[5] = (real)0.75, P.p[5] = 10;
  P.x[6] = (real)0.2, P.y[6] = (real)0.7, P.size[6] = (real)0.05;
  rhod_snapshot_view v = with_bodies(&P, 0.25);
  double lo[2] = {0, 0}, hi[2] = {1, 1}, range[2] = {0, 10};
  char err[512] = "";
  rhod_picture_geometry g;
  CU_ASSERT_EQUAL_FATAL(rhod_picture_layout(200, 2, lo, hi, &g), 0);
  const char *path = spath("bodies.png");
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 1, 200, lo, hi, range,
                                           NULL, 0, err, sizeof err),
                        RHOD_OK);
  rgb_image im;
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT_EQUAL_FATAL(im.h, g.pic_h);
  for (unsigned panel = 0; panel < 2; panel++) {
    const unsigned X = g.frame_x, Y = g.frame_y + panel * g.panel_h;
    /* the square's outline: left (over the particle there), right, top, bottom edges */
    CU_ASSERT(dark(&im, X + 39, Y + 60) || dark(&im, X + 40, Y + 60));
    CU_ASSERT(dark(&im, X + 79, Y + 70) || dark(&im, X + 80, Y + 70));
    CU_ASSERT(dark(&im, X + 70, Y + 39) || dark(&im, X + 70, Y + 40));
    CU_ASSERT(dark(&im, X + 70, Y + 79) || dark(&im, X + 70, Y + 80));
    /* its inside light grey where no particle is, the particle drawn over it */
    CU_ASSERT(rgb_at(&im, X + 70, Y + 70, 220, 220, 220));
    CU_ASSERT(!rgb_at(&im, X + 50, Y + 50, 220, 220, 220) && !dark(&im, X + 50, Y + 50));
    /* the triangle: its bottom edge and a slanted one; grey inside, white outside */
    CU_ASSERT(dark(&im, X + 150, Y + 159) || dark(&im, X + 150, Y + 160));
    CU_ASSERT(dark(&im, X + 135, Y + 135) || dark(&im, X + 134, Y + 135) ||
              dark(&im, X + 135, Y + 134));
    CU_ASSERT(rgb_at(&im, X + 150, Y + 145, 220, 220, 220));
    CU_ASSERT(rgb_at(&im, X + 125, Y + 120, 255, 255, 255));
    /* far from both: background */
    CU_ASSERT(rgb_at(&im, X + 150, Y + 40, 255, 255, 255));
    CU_ASSERT(rgb_at(&im, X + 100, Y + 100, 255, 255, 255));
  }
  /* the particle inside the square has the top colour in the first panel */
  CU_ASSERT(rgb_at(&im, g.frame_x + 50, g.frame_y + 50, 253, 231, 37));
  free(im.px);

  /* without bodies: no dark pixel and no grey where they were */
  v.n_bodies = 0;
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, hi, range,
                                           NULL, 0, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT(!dark(&im, g.frame_x + 70, g.frame_y + 79) &&
            !dark(&im, g.frame_x + 70, g.frame_y + 80));
  CU_ASSERT(rgb_at(&im, g.frame_x + 70, g.frame_y + 70, 255, 255, 255));
  free(im.px);

  /* incomplete outlines: refused */
  v = with_bodies(&P, 0.25);
  v.body_start = NULL;
  CU_ASSERT_EQUAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, hi, range, NULL, 0,
                                     err, sizeof err),
                  RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "bodies are incomplete"));
  free_particles(&P);
}

int main(void) {
  snprintf(scratch, sizeof scratch, "%s/test_output_bodies_XXXXXX", RHOD_BINARY_DIR);
  if (!mkdtemp(scratch)) {
    perror(scratch);
    return 2;
  }
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  static const rhod_test_case cases[] = {
      {"bodies: snapshot round trip and layout", test_bodies_roundtrip},
      {"bodies: none, incomplete, corrupt", test_no_bodies_and_errors},
      {"bodies: xdmf grids", test_bodies_xdmf},
      {"bodies: picture outlines", test_bodies_picture},
  };
  int rc = RHOD_RUN_TESTS("output bodies", cases);
  nftw(scratch, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
  H5close();
  return rc;
}
