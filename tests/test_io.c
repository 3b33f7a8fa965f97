/* Output writers: HDF5 snapshot round trip and layout, XDMF sidecar, PNG pictures, the
 * probes CSV and atomic file writing, including real write failures (a missing folder,
 * a file where a folder is expected, /dev/full, and RLIMIT_FSIZE to make a write fail
 * half way through a file). */
#define _XOPEN_SOURCE 700

#include "cunit_main.h"
#include "rhod/io.h"
#include "test_io_util.h"

#include <errno.h>
#include <ftw.h>
#include <hdf5.h>
#include <math.h>
#include <png.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static int exists(const char *path) { return access(path, F_OK) == 0; }

static void put_file(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fputs(text, f);
  fclose(f);
}

/* RLIMIT_FSIZE makes write() fail with EFBIG past the limit (SIGXFSZ is ignored). */
static struct rlimit saved_fsize;
static int limit_fsize(rlim_t bytes) {
  if (getrlimit(RLIMIT_FSIZE, &saved_fsize) != 0)
    return 0;
  struct rlimit r = saved_fsize;
  r.rlim_cur = bytes;
  return setrlimit(RLIMIT_FSIZE, &r) == 0;
}
static void unlimit_fsize(void) { setrlimit(RLIMIT_FSIZE, &saved_fsize); }

/* ------------------------------------------------------------ particle data */

static particles make_particles(size_t n) {
  particles P = alloc_particles(n);
  /* exactly representable in float, so that single builds compare exactly */
  for (size_t i = 0; i < n; i++) {
    P.x[i] = (real)(0.25 * (double)i);
    P.y[i] = (real)(0.5 + 0.125 * (double)i);
    P.ux[i] = (real)(-1.0 + 0.5 * (double)i);
    P.uy[i] = (real)(2.0 - 0.25 * (double)i);
    P.rho[i] = (real)(1000.0 + (double)i);
    P.p[i] = (real)(100.0 * (double)i - 50.0);
    P.m[i] = (real)(0.0625 + 0.0625 * (double)(i % 4));
    P.size[i] = (real)(0.03125 * (double)(1 + i % 3));
    P.id[i] = 1000000000000ull + 7 * i;
    P.fs[i] = (uint8_t)(i % 2);
  }
  return P;
}

/* ------------------------------------------------------------ snapshots */

static void check_dataset_layout(hid_t file, const char *name, hid_t want_type, int rank, hsize_t n,
                                 hsize_t cols) {
  hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
  CU_ASSERT_FATAL(d >= 0);
  hid_t dcpl = H5Dget_create_plist(d);
  CU_ASSERT(H5Pget_nfilters(dcpl) == 0);
  CU_ASSERT(H5Pget_layout(dcpl) == H5D_CONTIGUOUS);
  H5Pclose(dcpl);
  hid_t t = H5Dget_type(d);
  CU_ASSERT(H5Tequal(t, want_type) > 0);
  H5Tclose(t);
  hid_t sp = H5Dget_space(d);
  hsize_t dims[2] = {0, 0};
  CU_ASSERT(H5Sget_simple_extent_ndims(sp) == rank);
  H5Sget_simple_extent_dims(sp, dims, NULL);
  CU_ASSERT(dims[0] == n);
  if (rank == 2)
    CU_ASSERT(dims[1] == cols);
  H5Sclose(sp);
  H5Dclose(d);
}

static void test_snapshot_roundtrip(void) {
  particles P = make_particles(7);
  rhod_snapshot_view v = view_of(&P, 1.5);
  char *keys[] = {"time.end", "physics.gravity", "output.picture.field", "empty.value"};
  char *vals[] = {"2.5", "[0, -9.81]", "pressure", ""};
  rhod_param_list params = {keys, vals, 4};
  char err[512] = "";
  int rc = rhod_write_snapshot(scratch, 3, &v, &params, err, sizeof err);
  CU_ASSERT_EQUAL_FATAL(rc, RHOD_OK);
  CU_ASSERT_STRING_EQUAL(err, "");
  const char *path = spath("snapshot_0003.h5");
  CU_ASSERT(exists(path));
  CU_ASSERT(!exists(spath("snapshot_0003.h5.tmp")));

  rhod_snapshot_data d;
  rc = rhod_read_snapshot(path, &d, err, sizeof err);
  CU_ASSERT_EQUAL_FATAL(rc, RHOD_OK);
  CU_ASSERT_EQUAL(d.time, 1.5);
  CU_ASSERT_EQUAL_FATAL(d.n, 7);
  CU_ASSERT_PTR_NOT_NULL_FATAL(d.fs);
  for (size_t i = 0; i < d.n; i++) {
    CU_ASSERT_EQUAL(d.x[i], (double)P.x[i]);
    CU_ASSERT_EQUAL(d.y[i], (double)P.y[i]);
    CU_ASSERT_EQUAL(d.ux[i], (double)P.ux[i]);
    CU_ASSERT_EQUAL(d.uy[i], (double)P.uy[i]);
    CU_ASSERT_EQUAL(d.rho[i], (double)P.rho[i]);
    CU_ASSERT_EQUAL(d.p[i], (double)P.p[i]);
    CU_ASSERT_EQUAL(d.m[i], (double)P.m[i]);
    CU_ASSERT_EQUAL(d.size[i], (double)P.size[i]);
    CU_ASSERT(d.id[i] == P.id[i]);
    CU_ASSERT_EQUAL(d.fs[i], P.fs[i]);
  }
  CU_ASSERT_EQUAL_FATAL(d.params.n, 4);
  for (unsigned k = 0; k < 4; k++) {
    CU_ASSERT_STRING_EQUAL(d.params.keys[k], keys[k]);
    CU_ASSERT_STRING_EQUAL(d.params.values[k], vals[k]);
  }
  rhod_snapshot_data_free(&d);
  CU_ASSERT_PTR_NULL(d.x);
  CU_ASSERT_EQUAL(d.params.n, 0);

  /* The layout itself, through the HDF5 API. */
  hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  hid_t h = H5Gopen2(f, "/Header", H5P_DEFAULT);
  CU_ASSERT_FATAL(h >= 0);
  double t = 0;
  int dim = 0;
  uint64_t np = 0;
  hid_t a = H5Aopen(h, "Time", H5P_DEFAULT);
  hid_t at = H5Aget_type(a);
  CU_ASSERT(H5Tequal(at, H5T_IEEE_F64LE) > 0);
  H5Tclose(at);
  H5Aread(a, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(a);
  a = H5Aopen(h, "Dimension", H5P_DEFAULT);
  at = H5Aget_type(a);
  CU_ASSERT(H5Tget_class(at) == H5T_INTEGER);
  H5Tclose(at);
  H5Aread(a, H5T_NATIVE_INT, &dim);
  H5Aclose(a);
  a = H5Aopen(h, "NumPart", H5P_DEFAULT);
  at = H5Aget_type(a);
  CU_ASSERT(H5Tequal(at, H5T_STD_U64LE) > 0);
  H5Tclose(at);
  hid_t asp = H5Aget_space(a);
  CU_ASSERT(H5Sget_simple_extent_type(asp) == H5S_SCALAR);
  H5Sclose(asp);
  H5Aread(a, H5T_NATIVE_UINT64, &np);
  H5Aclose(a);
  H5Gclose(h);
  CU_ASSERT_EQUAL(t, 1.5);
  CU_ASSERT_EQUAL(dim, 2);
  CU_ASSERT(np == 7);

  check_dataset_layout(f, "/PartType0/Coordinates", H5T_IEEE_F64LE, 2, 7, 3);
  check_dataset_layout(f, "/PartType0/Velocities", H5T_IEEE_F64LE, 2, 7, 3);
  const char *scalars[] = {"Densities", "Pressures", "Masses", "ParticleSizes"};
  for (int k = 0; k < 4; k++) {
    char name[64];
    snprintf(name, sizeof name, "/PartType0/%s", scalars[k]);
    check_dataset_layout(f, name, H5T_IEEE_F64LE, 1, 7, 0);
  }
  check_dataset_layout(f, "/PartType0/ParticleIDs", H5T_STD_U64LE, 1, 7, 0);
  check_dataset_layout(f, "/PartType0/FreeSurface", H5T_STD_U8LE, 1, 7, 0);

  /* z = 0 in the N x 3 arrays */
  double xyz[7][3];
  hid_t dc = H5Dopen2(f, "/PartType0/Coordinates", H5P_DEFAULT);
  H5Dread(dc, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, xyz);
  H5Dclose(dc);
  for (int i = 0; i < 7; i++) {
    CU_ASSERT_EQUAL(xyz[i][0], (double)P.x[i]);
    CU_ASSERT_EQUAL(xyz[i][2], 0.0);
  }

  /* /Parameters: one fixed-length string attribute per dotted key */
  hid_t g = H5Gopen2(f, "/Parameters", H5P_DEFAULT);
  CU_ASSERT_FATAL(g >= 0);
  a = H5Aopen(g, "physics.gravity", H5P_DEFAULT);
  CU_ASSERT_FATAL(a >= 0);
  at = H5Aget_type(a);
  CU_ASSERT(H5Tget_class(at) == H5T_STRING);
  char sval[64] = "";
  CU_ASSERT_FATAL(H5Tget_size(at) < sizeof sval);
  H5Aread(a, at, sval);
  CU_ASSERT_STRING_EQUAL(sval, "[0, -9.81]");
  H5Tclose(at);
  H5Aclose(a);
  H5Gclose(g);
  H5Fclose(f);
  free_particles(&P);
}

static void test_snapshot_minimal(void) {
  /* no free-surface flags, no parameters; then an empty snapshot */
  particles P = make_particles(4);
  rhod_snapshot_view v = view_of(&P, 0.0);
  v.fs = NULL;
  char err[512];
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 12, &v, NULL, err, sizeof err), RHOD_OK);
  rhod_snapshot_data d;
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0012.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_EQUAL(d.n, 4);
  CU_ASSERT_PTR_NULL(d.fs);
  CU_ASSERT_PTR_NULL(d.phase);
  CU_ASSERT_EQUAL(d.params.n, 0);
  CU_ASSERT_EQUAL(d.p[3], (double)P.p[3]);
  rhod_snapshot_data_free(&d);

  /* a multiphase scheme's phase tags: the Phase dataset, read back */
  const uint8_t phase[4] = {0, 1, 7, 1};
  v.phase = phase;
  CU_ASSERT_EQUAL(rhod_snapshot_fields(&v), RHOD_FIELDS_PHASE);
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 15, &v, NULL, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0015.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_PTR_NOT_NULL_FATAL(d.phase);
  for (int i = 0; i < 4; i++)
    CU_ASSERT_EQUAL(d.phase[i], phase[i]);
  rhod_snapshot_data_free(&d);
  v.phase = NULL;

  v.n = 0;
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 13, &v, NULL, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0013.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_EQUAL(d.n, 0);
  rhod_snapshot_data_free(&d);

  /* a trailing slash on the folder */
  char dir[4200];
  snprintf(dir, sizeof dir, "%s/", scratch);
  v.n = 4;
  CU_ASSERT_EQUAL(rhod_write_snapshot(dir, 14, &v, NULL, err, sizeof err), RHOD_OK);
  CU_ASSERT(exists(spath("snapshot_0014.h5")));
  free_particles(&P);
}

static void test_snapshot_errors(void) {
  particles P = make_particles(5);
  rhod_snapshot_view v = view_of(&P, 0.25);
  char err[512] = "";
  rhod_snapshot_data d;

  /* missing file */
  const char *missing = spath("no_such_snapshot.h5");
  CU_ASSERT_EQUAL(rhod_read_snapshot(missing, &d, err, sizeof err), RHOD_ERR_READ);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, missing));
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "No such file"));
  CU_ASSERT_PTR_NULL(strchr(err, '\n'));

  /* not an HDF5 file */
  put_file(spath("not_hdf5.h5"), "hello\n");
  CU_ASSERT_EQUAL(rhod_read_snapshot(spath("not_hdf5.h5"), &d, err, sizeof err), RHOD_ERR_READ);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "not_hdf5.h5"));

  /* a missing dataset */
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 20, &v, NULL, err, sizeof err), RHOD_OK);
  hid_t f = H5Fopen(spath("snapshot_0020.h5"), H5F_ACC_RDWR, H5P_DEFAULT);
  CU_ASSERT_FATAL(f >= 0);
  CU_ASSERT(H5Ldelete(f, "/PartType0/Pressures", H5P_DEFAULT) >= 0);
  H5Fclose(f);
  CU_ASSERT_EQUAL(rhod_read_snapshot(spath("snapshot_0020.h5"), &d, err, sizeof err),
                  RHOD_ERR_READ);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "/PartType0/Pressures"));
  CU_ASSERT_PTR_NULL(d.x); /* nothing left allocated */

  /* a folder that does not exist, and a file where a folder is expected */
  char dir[4200];
  snprintf(dir, sizeof dir, "%s/no_such_dir", scratch);
  CU_ASSERT_EQUAL(rhod_write_snapshot(dir, 1, &v, NULL, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "no_such_dir/snapshot_0001.h5: cannot write: "));
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "No such file"));
  put_file(spath("plainfile"), "x");
  snprintf(dir, sizeof dir, "%s/plainfile", scratch);
  CU_ASSERT_EQUAL(rhod_write_snapshot(dir, 1, &v, NULL, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "plainfile/snapshot_0001.h5: cannot write: Not a directory"));

  /* duplicate parameter keys are an HDF5 failure half way through the file */
  char *keys[] = {"a.b", "a.b"};
  char *vals[] = {"1", "2"};
  rhod_param_list dup = {keys, vals, 2};
  CU_ASSERT_EQUAL(rhod_write_snapshot(scratch, 21, &v, &dup, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "snapshot_0021.h5: cannot write: "));
  CU_ASSERT_PTR_NULL(strchr(err, '\n'));
  CU_ASSERT(!exists(spath("snapshot_0021.h5")));
  CU_ASSERT(!exists(spath("snapshot_0021.h5.tmp")));
  CU_ASSERT_EQUAL(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0); /* no handle left open */
  free_particles(&P);
}

static void test_snapshot_write_failure(void) {
  /* A write that fails half way (EFBIG past RLIMIT_FSIZE, like a full disk) leaves the
   * previous snapshot of that index intact and no temporary file. */
  particles small = make_particles(3), big = make_particles(20000);
  rhod_snapshot_view vs = view_of(&small, 0.5), vb = view_of(&big, 1.0);
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 30, &vs, NULL, err, sizeof err), RHOD_OK);
  if (limit_fsize(64 * 1024)) {
    int rc = rhod_write_snapshot(scratch, 30, &vb, NULL, err, sizeof err);
    unlimit_fsize();
    CU_ASSERT_EQUAL(rc, RHOD_ERR_IO);
    CU_ASSERT_PTR_NOT_NULL(strstr(err, "snapshot_0030.h5: cannot write: File too large"));
    CU_ASSERT(!exists(spath("snapshot_0030.h5.tmp")));
    rhod_snapshot_data d;
    CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0030.h5"), &d, err, sizeof err),
                          RHOD_OK);
    CU_ASSERT_EQUAL(d.n, 3);
    CU_ASSERT_EQUAL(d.time, 0.5);
    rhod_snapshot_data_free(&d);
  }
  CU_ASSERT_EQUAL(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0); /* no handle left open */
  /* and without the limit the big one goes through */
  CU_ASSERT_EQUAL(rhod_write_snapshot(scratch, 30, &vb, NULL, err, sizeof err), RHOD_OK);
  free_particles(&small);
  free_particles(&big);
}

/* ------------------------------------------------------------ XDMF */

static void test_xdmf(void) {
  double times[3] = {0.0, 0.25, 1.5};
  size_t np[3] = {10, 10, 9};
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_xdmf(scratch, 3, times, np, 0, err, sizeof err), RHOD_OK);
  const char *path = spath("snapshots.xdmf");
  CU_ASSERT(!exists(spath("snapshots.xdmf.tmp")));
  char *s = slurp(path, NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(s);
  CU_ASSERT(strncmp(s, "<?xml", 5) == 0);
  CU_ASSERT_PTR_NOT_NULL(strstr(s, "CollectionType=\"Temporal\""));
  CU_ASSERT_EQUAL(count_of(s, "<Grid "), 4);
  CU_ASSERT_EQUAL(count_of(s, "</Grid>"), 4);
  CU_ASSERT_EQUAL(count_of(s, "TopologyType=\"Polyvertex\""), 3);
  CU_ASSERT_EQUAL(count_of(s, "GeometryType=\"XYZ\""), 3);
  CU_ASSERT_EQUAL(count_of(s, "<Attribute "), 18);
  CU_ASSERT_EQUAL(count_of(s, "</Attribute>"), 18);
  CU_ASSERT_EQUAL(count_of(s, "<DataItem "), count_of(s, "</DataItem>"));
  CU_ASSERT_EQUAL(count_of(s, "<Xdmf "), 1);
  CU_ASSERT_EQUAL(count_of(s, "</Xdmf>"), 1);
  for (int i = 0; i < 3; i++) {
    char want[128];
    snprintf(want, sizeof want, "snapshot_%04d.h5:/PartType0/Coordinates", i);
    CU_ASSERT_PTR_NOT_NULL(strstr(s, want));
    snprintf(want, sizeof want, "<Time Value=\"%g\"/>", times[i]);
    CU_ASSERT_PTR_NOT_NULL(strstr(s, want));
  }
  CU_ASSERT_PTR_NOT_NULL(strstr(s, "Dimensions=\"9 3\""));
  const char *attrs[] = {"Velocity", "Density", "Pressure", "Mass", "ParticleSize", "ParticleID"};
  for (int k = 0; k < 6; k++) {
    char want[64];
    snprintf(want, sizeof want, "Name=\"%s\"", attrs[k]);
    CU_ASSERT_EQUAL(count_of(s, want), 3);
  }
  CU_ASSERT_EQUAL(count_of(s, "AttributeType=\"Vector\""), 3);
  free(s);

  /* rewritten after each snapshot: one more grid */
  CU_ASSERT_EQUAL(rhod_write_xdmf(scratch, 2, times, np, 0, err, sizeof err), RHOD_OK);
  s = slurp(path, NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(s);
  CU_ASSERT_EQUAL(count_of(s, "<Grid "), 3);
  CU_ASSERT_PTR_NULL(strstr(s, "snapshot_0002.h5"));
  free(s);

  /* the optional fields: FreeSurface and Phase as UChar attributes */
  CU_ASSERT_EQUAL(rhod_write_xdmf(scratch, 2, times, np,
                                  RHOD_FIELDS_FREE_SURFACE | RHOD_FIELDS_PHASE, err, sizeof err),
                  RHOD_OK);
  s = slurp(path, NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(s);
  CU_ASSERT_EQUAL(count_of(s, "Name=\"FreeSurface\""), 2);
  CU_ASSERT_EQUAL(count_of(s, "Name=\"Phase\""), 2);
  CU_ASSERT_EQUAL(count_of(s, "snapshot_0001.h5:/PartType0/Phase"), 1);
  free(s);

  char dir[4200];
  snprintf(dir, sizeof dir, "%s/no_such_dir", scratch);
  CU_ASSERT_EQUAL(rhod_write_xdmf(dir, 3, times, np, 0, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "no_such_dir/snapshots.xdmf: cannot write"));
}

/* ------------------------------------------------------------ extra fields */

/* The view's extra datasets (output.fields): a real scalar, a real vector and a uint8 flag
 * written under /PartType0 with their units and read back as the generic list (name
 * order), beside the fixed fields; the XDMF lists each as a node attribute. */
static void test_extra_fields(void) {
  const size_t n = 5;
  particles P = make_particles(n);
  rhod_snapshot_view v = view_of(&P, 0.75);
  real gam[5], nrm[10];
  uint8_t lev[5];
  for (size_t i = 0; i < n; i++) { /* exact in float too */
    gam[i] = (real)(1 - 0.125 * (double)i);
    nrm[2 * i] = (real)(0.5 * (double)i), nrm[2 * i + 1] = (real)(-0.25 * (double)i);
    lev[i] = (uint8_t)(3 * i);
  }
  v.nextra = 3;
  v.extra[0] = (rhod_snapshot_extra){"ShepardGamma", "1", gam, 0, 1};
  v.extra[1] = (rhod_snapshot_extra){"Normals", "1", nrm, 0, 2};
  v.extra[2] = (rhod_snapshot_extra){"Level", "1", lev, 1, 1};
  char err[512] = "";
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 40, &v, NULL, err, sizeof err), RHOD_OK);
  hid_t file = H5Fopen(spath("snapshot_0040.h5"), H5F_ACC_RDONLY, H5P_DEFAULT);
  CU_ASSERT_FATAL(file >= 0);
  check_dataset_layout(file, "/PartType0/ShepardGamma", H5T_IEEE_F64LE, 1, n, 0);
  check_dataset_layout(file, "/PartType0/Normals", H5T_IEEE_F64LE, 2, n, 3);
  check_dataset_layout(file, "/PartType0/Level", H5T_STD_U8LE, 1, n, 0);
  H5Fclose(file);
  rhod_snapshot_data d;
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0040.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(d.nextra, 3);
  /* name order: Level, Normals, ShepardGamma */
  const rhod_snapshot_extra_data *L = &d.extra[0], *N = &d.extra[1], *G = &d.extra[2];
  CU_ASSERT_STRING_EQUAL(L->name, "Level");
  CU_ASSERT_STRING_EQUAL(N->name, "Normals");
  CU_ASSERT_STRING_EQUAL(G->name, "ShepardGamma");
  CU_ASSERT(L->u8 == 1 && L->comps == 1 && L->b && !L->v);
  CU_ASSERT(N->u8 == 0 && N->comps == 2 && N->v && !N->b);
  CU_ASSERT(G->u8 == 0 && G->comps == 1 && G->v && !G->b);
  CU_ASSERT_STRING_EQUAL(G->units, "1");
  int bad = 0;
  for (size_t i = 0; i < n && L->b && N->v && G->v; i++)
    bad += L->b[i] != lev[i] || N->v[2 * i] != (double)nrm[2 * i] ||
           N->v[2 * i + 1] != (double)nrm[2 * i + 1] || G->v[i] != (double)gam[i] ||
           d.x[i] != (double)P.x[i];
  CU_ASSERT_EQUAL(bad, 0);
  rhod_snapshot_data_free(&d);
  /* a file without extras reads none; one with units on a vector of reals */
  v.nextra = 0;
  CU_ASSERT_EQUAL_FATAL(rhod_write_snapshot(scratch, 41, &v, NULL, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_read_snapshot(spath("snapshot_0041.h5"), &d, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_EQUAL(d.nextra, 0);
  CU_ASSERT_PTR_NULL(d.extra);
  rhod_snapshot_data_free(&d);
  /* refused: a uint8 vector, a missing array */
  v.nextra = 1;
  v.extra[0] = (rhod_snapshot_extra){"Level", "1", lev, 1, 2};
  CU_ASSERT_EQUAL(rhod_write_snapshot(scratch, 42, &v, NULL, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "extra field 0 (Level) is incomplete"));
  v.extra[0] = (rhod_snapshot_extra){"Level", "1", NULL, 1, 1};
  CU_ASSERT_EQUAL(rhod_write_snapshot(scratch, 42, &v, NULL, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT(!exists(spath("snapshot_0042.h5")));
  /* the XDMF: one attribute per extra and snapshot, pointing at the dataset */
  v.nextra = 3;
  v.extra[0] = (rhod_snapshot_extra){"ShepardGamma", "1", gam, 0, 1};
  double times[2] = {0, 0.75};
  size_t np[2] = {n, n};
  CU_ASSERT_EQUAL_FATAL(
      rhod_write_xdmf_fields(scratch, 2, times, np, 0, v.extra, v.nextra, err, sizeof err),
      RHOD_OK);
  char *x = slurp(spath("snapshots.xdmf"), NULL);
  CU_ASSERT_PTR_NOT_NULL_FATAL(x);
  CU_ASSERT_EQUAL(count_of(x, "<Attribute "), 2 * (6 + 3));
  CU_ASSERT_EQUAL(count_of(x, "Name=\"Normals\" AttributeType=\"Vector\""), 2);
  CU_ASSERT_EQUAL(count_of(x, "Name=\"ShepardGamma\" AttributeType=\"Scalar\""), 2);
  CU_ASSERT_EQUAL(count_of(x, "Name=\"Level\" AttributeType=\"Scalar\""), 2);
  CU_ASSERT_PTR_NOT_NULL(strstr(x, "Dimensions=\"5 3\" NumberType=\"Float\" Precision=\"8\" "
                                   "Format=\"HDF\">snapshot_0001.h5:/PartType0/Normals<"));
  CU_ASSERT_PTR_NOT_NULL(strstr(x, "Dimensions=\"5\" NumberType=\"UChar\" Precision=\"1\" "
                                   "Format=\"HDF\">snapshot_0000.h5:/PartType0/Level<"));
  free(x);
  free_particles(&P);
}

/* ------------------------------------------------------------ PNG */

static int pixel_is(const rgb_image *im, unsigned x, unsigned y, int r, int g, int b) {
  const unsigned char *p = im->px + 3 * ((size_t)y * im->w + x);
  return p[0] == r && p[1] == g && p[2] == b;
}

static void test_picture(void) {
  /* frame [0, 2] x [0, 1] at 200 px: 100 px per metre, frame 200 x 100 */
  particles P = make_particles(4);
  real xs[4] = {0.5, 1.5, 1.0, 1.9}, ys[4] = {0.5, 0.5, 0.9, 0.1};
  real ps[4] = {10, 0, 5, 2}, sizes[4] = {0.2, 0.2, 0.1, 0.001};
  for (int i = 0; i < 4; i++) {
    P.x[i] = xs[i];
    P.y[i] = ys[i];
    P.p[i] = ps[i];
    P.size[i] = sizes[i];
  }
  rhod_snapshot_view v = view_of(&P, 0.125);
  double lo[2] = {0, 0}, hi[2] = {2, 1};
  char err[512] = "";
  /* where the frames are (the axes take a margin around them) */
  rhod_picture_geometry g, g1;
  CU_ASSERT_EQUAL_FATAL(rhod_picture_layout(200, 1, lo, hi, &g), 0);
  CU_ASSERT_EQUAL(g.frame_w, 200);
  CU_ASSERT_EQUAL(g.frame_h, 100);
  CU_ASSERT_EQUAL_FATAL(rhod_picture_layout(100, 1, lo, hi, &g1), 0);
  const char *path = spath("pressure.png");
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, hi, NULL,
                                           NULL, 0, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT(!exists(spath("pressure.png.tmp")));
  size_t len = 0;
  char *raw = slurp(path, &len);
  CU_ASSERT_PTR_NOT_NULL_FATAL(raw);
  CU_ASSERT(len > 8 && memcmp(raw, "\x89PNG\r\n\x1a\n", 8) == 0);
  free(raw);

  rgb_image im = {0, 0, NULL};
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT_EQUAL(im.w, g.pic_w);
  CU_ASSERT_EQUAL(im.h, g.pic_h); /* frame plus the axes and the colour bar strip */
  /* auto range [0, 10]: particle 0 (p = 10) at pixel (50, 50) is the top colour of
   * viridis, particle 1 (p = 0) at (150, 50) the bottom one; y is up. */
  CU_ASSERT(pixel_is(&im, g.frame_x + 50, g.frame_y + 50, 253, 231, 37));
  CU_ASSERT(pixel_is(&im, g.frame_x + 59, g.frame_y + 50, 253, 231, 37)); /* disc of radius 10 px */
  CU_ASSERT(pixel_is(&im, g.frame_x + 150, g.frame_y + 50, 68, 1, 84));
  CU_ASSERT(pixel_is(&im, g.frame_x + 100, g.frame_y + 10, 33, 144,
                     140)); /* p = 5: the middle stop, y = 0.9 */
  CU_ASSERT(pixel_is(&im, g.frame_x + 100, g.frame_y + 90, 255, 255, 255)); /* background */
  CU_ASSERT(pixel_is(&im, g.frame_x + 50, g.frame_y + 62, 255, 255, 255));  /* outside the disc */
  /* a tiny particle (0.1 px) still covers its pixel: p = 2 -> t = 0.2, 60 % of the way
   * from the second stop (71, 45, 123) to the third (59, 82, 139) */
  CU_ASSERT(pixel_is(&im, g.frame_x + 190, g.frame_y + 90, 64, 67, 133));
  CU_ASSERT(pixel_is(&im, g.frame_x + 191, g.frame_y + 90, 255, 255, 255));
  /* the colour bar spans the strip: dark at the left, yellow at the right */
  int found_lo = 0, found_hi = 0;
  for (unsigned y = g.frame_y + 100; y < im.h; y++)
    for (unsigned x = g.frame_x; x < g.frame_x + 20; x++) {
      found_lo |= pixel_is(&im, x, y, 68, 1, 84);
      found_hi |= pixel_is(&im, g.frame_x + 199 - (x - g.frame_x), y, 253, 231, 37);
    }
  CU_ASSERT(found_lo);
  CU_ASSERT(found_hi);
  /* text in black somewhere in the strip */
  int ink = 0;
  for (unsigned y = g.frame_y + 100; y < im.h; y++)
    for (unsigned x = 0; x < im.w; x++)
      ink |= pixel_is(&im, x, y, 0, 0, 0);
  CU_ASSERT(ink);
  free(im.px);

  /* a given range: p = 10 in [0, 20] is the middle stop */
  double range[2] = {0, 20};
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, hi, range,
                                           NULL, 0, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT(pixel_is(&im, g.frame_x + 50, g.frame_y + 50, 33, 144, 140));
  free(im.px);

  /* velocity magnitude and free surface; fs NULL means every particle is inner */
  P.ux[0] = 3;
  P.uy[0] = 4;
  P.ux[1] = 0;
  P.uy[1] = 0;
  double r2[2] = {0, 5};
  CU_ASSERT_EQUAL(rhod_write_picture(path, &v, RHOD_FIELD_VELOCITY, 0, 200, lo, hi, r2, NULL, 0,
                                     err, sizeof err),
                  RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT(pixel_is(&im, g.frame_x + 50, g.frame_y + 50, 253, 231, 37));
  CU_ASSERT(pixel_is(&im, g.frame_x + 150, g.frame_y + 50, 68, 1, 84));
  free(im.px);
  /* coloured by phase: particle 0 of phase 1 the top colour, particle 1 of phase 0 the
   * bottom one over [0, 1]; without phases every particle is phase 0 */
  const uint8_t ph[4] = {1, 0, 0, 0};
  v.phase = ph;
  double r01[2] = {0, 1};
  CU_ASSERT_EQUAL(
      rhod_write_picture(path, &v, RHOD_FIELD_PHASE, 0, 200, lo, hi, r01, NULL, 0, err, sizeof err),
      RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT(pixel_is(&im, g.frame_x + 50, g.frame_y + 50, 253, 231, 37));
  CU_ASSERT(pixel_is(&im, g.frame_x + 150, g.frame_y + 50, 68, 1, 84));
  free(im.px);
  v.phase = NULL;
  CU_ASSERT_EQUAL(
      rhod_write_picture(path, &v, RHOD_FIELD_PHASE, 0, 200, lo, hi, r01, NULL, 0, err, sizeof err),
      RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT(pixel_is(&im, g.frame_x + 50, g.frame_y + 50, 68, 1, 84));
  free(im.px);
  v.fs = NULL;
  CU_ASSERT_EQUAL(rhod_write_picture(path, &v, RHOD_FIELD_FREE_SURFACE, 0, 100, lo, hi, NULL, NULL,
                                     0, err, sizeof err),
                  RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT_EQUAL(im.w, g1.pic_w);
  CU_ASSERT(pixel_is(&im, g1.frame_x + 25, g1.frame_y + 25, 68, 1, 84));
  free(im.px);

  /* the size panel: the same frame below, coloured by size on a log scale over
   * [0.001, 0.2]: particle 0 (0.2) the top colour, particle 3 (0.001) the bottom one,
   * particle 2 (0.1) at log(100)/log(200) = 0.869 of the scale (between the stops
   * (93, 200, 99) and (170, 220, 50)); the field's panel above unchanged */
  const unsigned h1 = im.h;
  CU_ASSERT_EQUAL_FATAL(rhod_write_picture(path, &v, RHOD_FIELD_FREE_SURFACE, 1, 100, lo, hi, NULL,
                                           NULL, 0, err, sizeof err),
                        RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT_EQUAL(im.h, 2 * h1);
  CU_ASSERT(pixel_is(&im, g1.frame_x + 25, g1.frame_y + 25, 68, 1, 84));
  CU_ASSERT(pixel_is(&im, g1.frame_x + 25, g1.panel_h + g1.frame_y + 25, 253, 231, 37));
  CU_ASSERT(pixel_is(&im, g1.frame_x + 95, g1.panel_h + g1.frame_y + 45, 68, 1, 84));
  {
    const double t = log(100.0) / log(200.0) * 8 - 6;
    const int r = (int)lround(93 + t * (170 - 93)), g = (int)lround(200 + t * (220 - 200)),
              b = (int)lround(99 + t * (50 - 99));
    CU_ASSERT(pixel_is(&im, g1.frame_x + 50, g1.panel_h + g1.frame_y + 5, r, g, b));
  }
  free(im.px);
  /* no second panel when the field is the size itself */
  CU_ASSERT_EQUAL_FATAL(
      rhod_write_picture(path, &v, RHOD_FIELD_SIZE, 1, 100, lo, hi, NULL, NULL, 0, err, sizeof err),
      RHOD_OK);
  CU_ASSERT_FATAL(read_png(path, &im));
  CU_ASSERT_EQUAL(im.h, h1);
  CU_ASSERT(pixel_is(&im, g1.frame_x + 25, g1.frame_y + 25, 253, 231, 37));
  free(im.px);

  /* errors: an empty frame; a folder that does not exist (nothing left behind) */
  double bad_hi[2] = {0, 1};
  CU_ASSERT_EQUAL(rhod_write_picture(path, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, bad_hi, NULL, NULL,
                                     0, err, sizeof err),
                  RHOD_ERR_SCENE);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, path));
  const char *nodir = spath("no_such_dir/p.png");
  CU_ASSERT_EQUAL(rhod_write_picture(nodir, &v, RHOD_FIELD_PRESSURE, 0, 200, lo, hi, NULL, NULL, 0,
                                     err, sizeof err),
                  RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, nodir));
  free_particles(&P);
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void test_picture_speed(void) {
  /* 1e5 particles (a 500 x 200 lattice of a 4 m x 1.6 m tank) at 800 px */
  size_t nx = 500, ny = 200;
  particles P = make_particles(nx * ny);
  for (size_t j = 0; j < ny; j++)
    for (size_t i = 0; i < nx; i++) {
      size_t k = j * nx + i;
      P.x[k] = (real)(0.008 * (i + 0.5));
      P.y[k] = (real)(0.008 * (j + 0.5));
      P.size[k] = (real)0.008;
      P.p[k] = (real)(9810.0 * (1.6 - P.y[k]));
    }
  rhod_snapshot_view v = view_of(&P, 2.0);
  double lo[2] = {0, 0}, hi[2] = {4, 2};
  char err[512];
  double t0 = now();
  int rc = rhod_write_picture(spath("speed.png"), &v, RHOD_FIELD_PRESSURE, 0, 800, lo, hi, NULL,
                              NULL, 0, err, sizeof err);
  double dt = now() - t0;
  CU_ASSERT_EQUAL(rc, RHOD_OK);
  printf("\n    picture of 1e5 particles at 800 px: %.1f ms ", 1e3 * dt);
  CU_ASSERT(dt < 1.0); /* target well under 0.1 s; loose here for sanitizer builds */
  free_particles(&P);
}

/* ------------------------------------------------------------ atomic writes */

static void test_atomic_write(void) {
  char err[512] = "";
  const char *a = spath("a.txt");
  CU_ASSERT_EQUAL_FATAL(rhod_write_file_atomic(a, "hello\n", err, sizeof err), RHOD_OK);
  char *s = slurp(a, NULL);
  CU_ASSERT_STRING_EQUAL(s, "hello\n");
  free(s);
  CU_ASSERT(!exists(spath("a.txt.tmp")));
  CU_ASSERT_EQUAL(rhod_write_file_atomic(a, "world, longer\n", err, sizeof err), RHOD_OK);
  s = slurp(a, NULL);
  CU_ASSERT_STRING_EQUAL(s, "world, longer\n");
  free(s);

  /* a folder that does not exist */
  const char *p = spath("no_such_dir/x.txt");
  CU_ASSERT_EQUAL(rhod_write_file_atomic(p, "x", err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, p));
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "cannot write: No such file or directory"));
  /* a file where a folder is expected */
  p = spath("a.txt/x.txt");
  CU_ASSERT_EQUAL(rhod_write_file_atomic(p, "x", err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, p));
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "Not a directory"));
  /* /proc takes no new files, even from root */
  CU_ASSERT_EQUAL(rhod_write_file_atomic("/proc/rhod_test_io.txt", "x", err, sizeof err),
                  RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "/proc/rhod_test_io.txt: cannot write: "));
  CU_ASSERT(!exists("/proc/rhod_test_io.txt.tmp"));

  /* the temporary name is taken by a folder: the existing file is untouched */
  const char *b = spath("b.txt");
  put_file(b, "old content\n");
  CU_ASSERT_EQUAL_FATAL(mkdir(spath("b.txt.tmp"), 0755), 0);
  CU_ASSERT_EQUAL(rhod_write_file_atomic(b, "new", err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, b));
  s = slurp(b, NULL);
  CU_ASSERT_STRING_EQUAL(s, "old content\n");
  free(s);
  rmdir(spath("b.txt.tmp"));

  /* the target is a folder: the rename fails and the temporary file is removed */
  CU_ASSERT_EQUAL_FATAL(mkdir(spath("cdir"), 0755), 0);
  CU_ASSERT_EQUAL(rhod_write_file_atomic(spath("cdir"), "x", err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "cdir: cannot write: "));
  CU_ASSERT(!exists(spath("cdir.tmp")));

  /* a write failing half way: old file intact, no temporary file */
  size_t big = 100000;
  char *text = malloc(big + 1);
  CU_ASSERT_PTR_NOT_NULL_FATAL(text);
  memset(text, 'x', big);
  text[big] = '\0';
  if (limit_fsize(16384)) {
    int rc = rhod_write_file_atomic(b, text, err, sizeof err);
    unlimit_fsize();
    CU_ASSERT_EQUAL(rc, RHOD_ERR_IO);
    CU_ASSERT_PTR_NOT_NULL(strstr(err, "b.txt: cannot write: File too large"));
    s = slurp(b, NULL);
    CU_ASSERT_STRING_EQUAL(s, "old content\n");
    free(s);
    CU_ASSERT(!exists(spath("b.txt.tmp")));
  }
  free(text);

  /* bytes, including NULs */
  const unsigned char bytes[5] = {1, 0, 2, 0, 3};
  CU_ASSERT_EQUAL(rhod_write_bytes_atomic(spath("bin"), bytes, 5, err, sizeof err), RHOD_OK);
  size_t n = 0;
  s = slurp(spath("bin"), &n);
  CU_ASSERT(n == 5 && memcmp(s, bytes, 5) == 0);
  free(s);
}

/* ------------------------------------------------------------ CSV */

static void test_csv(void) {
  rhod_csv c;
  char err[512] = "";
  const char *names[3] = {"p_gauge", "kinetic_energy", "odd,name"};
  const char *path = spath("probes.csv");
  CU_ASSERT_EQUAL_FATAL(rhod_csv_open(&c, path, 3, names, err, sizeof err), RHOD_OK);
  double r1[3] = {1, 2.5, -3}, r2[3] = {1.0 / 3.0, 1e-12, 123456789012.0};
  CU_ASSERT_EQUAL(rhod_csv_row(&c, 0.0, r1, err, sizeof err), RHOD_OK);
  /* flushed after every row: readable while open */
  char *s = slurp(path, NULL);
  CU_ASSERT_STRING_EQUAL(s, "t,p_gauge,kinetic_energy,\"odd,name\"\n0,1,2.5,-3\n");
  free(s);
  CU_ASSERT_EQUAL(rhod_csv_row(&c, 0.1, r2, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_csv_close(&c, err, sizeof err), RHOD_OK);
  CU_ASSERT_PTR_NULL(c.f);
  CU_ASSERT_PTR_NULL(c.path);
  s = slurp(path, NULL);
  CU_ASSERT_STRING_EQUAL(s, "t,p_gauge,kinetic_energy,\"odd,name\"\n0,1,2.5,-3\n"
                            "0.1,0.333333333,1e-12,1.23456789e+11\n");
  free(s);

  /* no probe columns at all */
  CU_ASSERT_EQUAL_FATAL(rhod_csv_open(&c, path, 0, NULL, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_csv_row(&c, 2.0, NULL, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_csv_close(&c, err, sizeof err), RHOD_OK);
  s = slurp(path, NULL);
  CU_ASSERT_STRING_EQUAL(s, "t\n2\n");
  free(s);

  /* a full disk: /dev/full fails every write with ENOSPC */
  CU_ASSERT_EQUAL(rhod_csv_open(&c, "/dev/full", 3, names, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_STRING_EQUAL(err, "/dev/full: cannot write: No space left on device");
  CU_ASSERT_PTR_NULL(c.f);
  CU_ASSERT_PTR_NULL(c.path);
  CU_ASSERT_EQUAL(rhod_csv_close(&c, err, sizeof err), RHOD_OK);

  /* a row that cannot be written (file size limit right after the header) */
  CU_ASSERT_EQUAL_FATAL(rhod_csv_open(&c, path, 3, names, err, sizeof err), RHOD_OK);
  struct stat st;
  CU_ASSERT_EQUAL_FATAL(stat(path, &st), 0);
  if (limit_fsize((rlim_t)st.st_size)) {
    int rc = rhod_csv_row(&c, 0.5, r1, err, sizeof err);
    CU_ASSERT_EQUAL(rc, RHOD_ERR_IO);
    CU_ASSERT_PTR_NOT_NULL(strstr(err, "probes.csv: cannot write: File too large"));
    rc = rhod_csv_close(&c, err, sizeof err);
    unlimit_fsize();
    CU_ASSERT_EQUAL(rc, RHOD_ERR_IO);
  } else {
    rhod_csv_close(&c, err, sizeof err);
  }
  CU_ASSERT_PTR_NULL(c.path);

  /* a folder that does not exist */
  const char *nodir = spath("no_such_dir/probes.csv");
  CU_ASSERT_EQUAL(rhod_csv_open(&c, nodir, 3, names, err, sizeof err), RHOD_ERR_IO);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, nodir));
}

/* ------------------------------------------------------------ main */

int main(void) {
  signal(SIGXFSZ, SIG_IGN);
  snprintf(scratch, sizeof scratch, "%s/test_io_XXXXXX", RHOD_BINARY_DIR);
  if (!mkdtemp(scratch)) {
    perror(scratch);
    return 2;
  }
  static const rhod_test_case cases[] = {
      {"snapshot round trip and layout", test_snapshot_roundtrip},
      {"snapshot without flags, params, particles", test_snapshot_minimal},
      {"snapshot errors", test_snapshot_errors},
      {"snapshot write failing half way", test_snapshot_write_failure},
      {"xdmf sidecar", test_xdmf},
      {"extra fields: round trip and xdmf", test_extra_fields},
      {"png picture", test_picture},
      {"png picture speed", test_picture_speed},
      {"atomic file writes", test_atomic_write},
      {"probes csv", test_csv},
  };
  int rc = RHOD_RUN_TESTS("io", cases);
  nftw(scratch, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
  H5close();
  return rc;
}
