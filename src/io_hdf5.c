/* HDF5 snapshots in a SWIFT-like layout (see io.h): built in memory, then written under a
 * temporary name in the output folder and renamed once complete and synced; read back
 * for tests and tools. HDF5's automatic error printing is switched off; failures become
 * one-line messages built from the HDF5 error stack (the system errno where the stack
 * records one). */
#define _POSIX_C_SOURCE 200809L

#include "rhod/io.h"
#include "rhod/version.h"

#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---------------------------------------------------------------- errors */

typedef struct {
  int noted, have_desc, sys_errno;
  char desc[160];
} h5_reason;

static herr_t walk_cb(unsigned n, const H5E_error2_t *e, void *data) {
  h5_reason *r = data;
  if (!e->desc)
    return 0;
  if (n == 0 && !r->have_desc) {
    snprintf(r->desc, sizeof r->desc, "%s", e->desc);
    r->have_desc = 1;
  }
  const char *s = strstr(e->desc, "errno = ");
  if (s && !r->sys_errno) {
    int v = atoi(s + 8);
    if (v > 0)
      r->sys_errno = v;
  }
  return 0;
}

/* Records why the HDF5 call that just failed failed (the first failure only). Must come
 * right after that call: every HDF5 API call clears the error stack on entry. */
static void note(h5_reason *r) {
  if (r->noted)
    return;
  r->noted = 1;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk_cb, r);
  H5Eclear2(H5E_DEFAULT);
}

/* The reason as text: the system error when the stack held one, else the innermost HDF5
 * message. */
static void reason_text(const h5_reason *r, char *buf, size_t len) {
  if (r->sys_errno)
    snprintf(buf, len, "%s", strerror(r->sys_errno));
  else if (r->have_desc)
    snprintf(buf, len, "%s", r->desc);
  else
    snprintf(buf, len, "HDF5 error");
}

static void set_err(char *err, size_t errlen, const char *fmt, ...) {
  if (!err || !errlen)
    return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, errlen, fmt, ap);
  va_end(ap);
}

static void h5_quiet(void) { H5Eset_auto2(H5E_DEFAULT, NULL, NULL); }

/* ---------------------------------------------------------------- writing */

static char *join_path(const char *dir, const char *name) {
  size_t dl = dir ? strlen(dir) : 0, nl = strlen(name);
  char *s = malloc(dl + nl + 2);
  if (!s)
    return NULL;
  size_t k = 0;
  if (dl) {
    memcpy(s, dir, dl);
    k = dl;
    if (s[k - 1] != '/')
      s[k++] = '/';
  }
  memcpy(s + k, name, nl + 1);
  return s;
}

static int write_attr(h5_reason *R, hid_t loc, const char *name, hid_t ftype, hid_t mtype,
                      const void *val) {
  hid_t sp = H5Screate(H5S_SCALAR);
  if (sp < 0) {
    note(R);
    return -1;
  }
  int rc = -1;
  hid_t a = H5Acreate2(loc, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT);
  if (a < 0) {
    note(R);
  } else {
    rc = 0;
    if (H5Awrite(a, mtype, val) < 0) {
      note(R);
      rc = -1;
    }
    if (H5Aclose(a) < 0) {
      note(R);
      rc = -1;
    }
  }
  H5Sclose(sp);
  return rc;
}

static int write_str_attr(h5_reason *R, hid_t loc, const char *name, const char *val) {
  hid_t t = H5Tcopy(H5T_C_S1);
  if (t < 0) {
    note(R);
    return -1;
  }
  int rc = -1;
  if (H5Tset_size(t, strlen(val) + 1) >= 0 && H5Tset_strpad(t, H5T_STR_NULLTERM) >= 0)
    rc = write_attr(R, loc, name, t, t, val);
  else
    note(R);
  H5Tclose(t);
  return rc;
}

/* A contiguous (default creation properties: no chunks, no filters) dataset of rank 1
 * (cols == 0) or n x cols, with a string attribute Units (SI, "1" for a number). */
static int write_dataset(h5_reason *R, hid_t loc, const char *name, hid_t ftype, hid_t mtype,
                         size_t n, unsigned cols, const void *buf, const char *units) {
  hsize_t dims[2] = {(hsize_t)n, (hsize_t)cols};
  hid_t sp = H5Screate_simple(cols ? 2 : 1, dims, NULL);
  if (sp < 0) {
    note(R);
    return -1;
  }
  int rc = -1;
  /* no modification times in the file: the same state gives the same bytes (restarts
   * are checked byte for byte) */
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  hid_t d = -1;
  if (dcpl >= 0 && H5Pset_obj_track_times(dcpl, 0) >= 0)
    d = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  if (dcpl >= 0)
    H5Pclose(dcpl);
  if (d < 0) {
    note(R);
  } else {
    rc = 0;
    if (n > 0 && H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) {
      note(R);
      rc = -1;
    }
    if (!rc && write_str_attr(R, d, "Units", units) < 0)
      rc = -1;
    if (H5Dclose(d) < 0) {
      note(R);
      rc = -1;
    }
  }
  H5Sclose(sp);
  return rc;
}

static void to_double(double *out, const real *in, size_t n) {
  for (size_t i = 0; i < n; i++)
    out[i] = (double)in[i];
}

static void pack_xyz(double *out, const real *a, const real *b, size_t n) {
  for (size_t i = 0; i < n; i++) {
    out[3 * i] = (double)a[i];
    out[3 * i + 1] = (double)b[i];
    out[3 * i + 2] = 0.0;
  }
}

/* gcpl: H5P_DEFAULT or the caller's; times are never tracked (see write_dataset) */
static hid_t create_group(h5_reason *R, hid_t loc, const char *name, hid_t gcpl) {
  hid_t own = gcpl == H5P_DEFAULT ? H5Pcreate(H5P_GROUP_CREATE) : gcpl;
  hid_t g = -1;
  if (own >= 0 && H5Pset_obj_track_times(own, 0) >= 0)
    g = H5Gcreate2(loc, name, H5P_DEFAULT, own, H5P_DEFAULT);
  if (own >= 0 && own != gcpl)
    H5Pclose(own);
  if (g < 0)
    note(R);
  return g;
}

static int close_group(h5_reason *R, hid_t g, int rc) {
  if (H5Gclose(g) < 0) {
    note(R);
    rc = -1;
  }
  return rc;
}

static int write_particles(h5_reason *R, hid_t file, const rhod_snapshot_view *v, double *buf) {
  hid_t g = create_group(R, file, "PartType0", H5P_DEFAULT);
  if (g < 0)
    return -1;
  const hid_t F = H5T_IEEE_F64LE, M = H5T_NATIVE_DOUBLE;
  size_t n = v->n;
  pack_xyz(buf, v->x, v->y, n);
  int rc = write_dataset(R, g, "Coordinates", F, M, n, 3, buf, "m");
  if (!rc) {
    pack_xyz(buf, v->ux, v->uy, n);
    rc = write_dataset(R, g, "Velocities", F, M, n, 3, buf, "m/s");
  }
  struct {
    const char *name;
    const real *a;
    const char *units;
  } scalars[] = {{"Densities", v->rho, "kg/m^3"},
                 {"Pressures", v->p, "Pa"},
                 {"Masses", v->m, "kg/m"}, /* 2D: mass per unit depth */
                 {"ParticleSizes", v->size, "m"}};
  for (size_t k = 0; k < sizeof scalars / sizeof scalars[0] && !rc; k++) {
    to_double(buf, scalars[k].a, n);
    rc = write_dataset(R, g, scalars[k].name, F, M, n, 0, buf, scalars[k].units);
  }
  if (!rc)
    rc = write_dataset(R, g, "ParticleIDs", H5T_STD_U64LE, H5T_NATIVE_UINT64, n, 0, v->id, "1");
  if (!rc && v->fs)
    rc = write_dataset(R, g, "FreeSurface", H5T_STD_U8LE, H5T_NATIVE_UINT8, n, 0, v->fs, "1");
  if (!rc && v->phase)
    rc = write_dataset(R, g, "Phase", H5T_STD_U8LE, H5T_NATIVE_UINT8, n, 0, v->phase, "1");
  /* the extra datasets (output.fields): reals as double, vectors N x 3 like Velocities */
  for (unsigned k = 0; k < v->nextra && !rc; k++) {
    const rhod_snapshot_extra *e = &v->extra[k];
    if (e->u8) {
      rc = write_dataset(R, g, e->name, H5T_STD_U8LE, H5T_NATIVE_UINT8, n, 0, e->data, e->units);
    } else if (e->comps == 2) {
      const real *a = e->data;
      for (size_t i = 0; i < n; i++) {
        buf[3 * i] = (double)a[2 * i];
        buf[3 * i + 1] = (double)a[2 * i + 1];
        buf[3 * i + 2] = 0.0;
      }
      rc = write_dataset(R, g, e->name, F, M, n, 3, buf, e->units);
    } else {
      to_double(buf, e->data, n);
      rc = write_dataset(R, g, e->name, F, M, n, 0, buf, e->units);
    }
  }
  return close_group(R, g, rc);
}

/* /Mesh/Vertices: N x 1 indices 0..N-1, one vertex cell per particle, the connectivity
 * of the XDMF Polyvertex topology (io_xdmf.c): readers that need explicit cells (meshio,
 * ParaView's Xdmf3 readers) get one cell per particle. 4-byte indices while N fits. */
static int write_mesh(h5_reason *R, hid_t file, size_t n, void *buf) {
  hid_t g = create_group(R, file, "Mesh", H5P_DEFAULT);
  if (g < 0)
    return -1;
  int rc;
  if (n <= UINT32_MAX) {
    uint32_t *ix = buf;
    for (size_t i = 0; i < n; i++)
      ix[i] = (uint32_t)i;
    rc = write_dataset(R, g, "Vertices", H5T_STD_U32LE, H5T_NATIVE_UINT32, n, 1, ix, "1");
  } else {
    uint64_t *ix = buf;
    for (size_t i = 0; i < n; i++)
      ix[i] = (uint64_t)i;
    rc = write_dataset(R, g, "Vertices", H5T_STD_U64LE, H5T_NATIVE_UINT64, n, 1, ix, "1");
  }
  return close_group(R, g, rc);
}

/* The bodies' points in all (P), when the view's outlines are complete: body_start from
 * 0, never decreasing; (size_t)-1 when not. */
static size_t body_points(const rhod_snapshot_view *v) {
  if (v->n_bodies == 0)
    return 0;
  if (!v->body_start || v->body_start[0] != 0)
    return (size_t)-1;
  for (unsigned k = 0; k < v->n_bodies; k++)
    if (v->body_start[k + 1] < v->body_start[k])
      return (size_t)-1;
  size_t np = v->body_start[v->n_bodies];
  return np > 0 && !v->body_xy ? (size_t)-1 : np;
}

/* /Bodies (io.h): each body's outline, the closed polygon body_start[k] .. body_start[k +
 * 1] - 1 of body_xy, as points and the line segments k -> k+1, last -> first (so S = P,
 * the layout of walls.h5), the body of each segment and NumBodies. */
static int write_bodies(h5_reason *R, hid_t file, const rhod_snapshot_view *v, size_t np,
                        int *oom) {
  double *pts = malloc(sizeof(double) * 3 * (np ? np : 1));
  uint32_t *seg = malloc(sizeof(uint32_t) * 2 * (np ? np : 1));
  uint32_t *bidx = malloc(sizeof(uint32_t) * (np ? np : 1));
  int rc = -1;
  if (!pts || !seg || !bidx) {
    *oom = 1;
    goto done;
  }
  for (unsigned b = 0; b < v->n_bodies; b++) {
    const size_t s = v->body_start[b], m = v->body_start[b + 1] - s;
    for (size_t k = 0; k < m; k++) {
      pts[3 * (s + k)] = v->body_xy[2 * (s + k)];
      pts[3 * (s + k) + 1] = v->body_xy[2 * (s + k) + 1];
      pts[3 * (s + k) + 2] = 0.0;
      seg[2 * (s + k)] = (uint32_t)(s + k);
      seg[2 * (s + k) + 1] = (uint32_t)(s + (k + 1) % m);
      bidx[s + k] = b;
    }
  }
  hid_t g = create_group(R, file, "Bodies", H5P_DEFAULT);
  if (g < 0)
    goto done;
  uint32_t nb = v->n_bodies;
  rc = write_attr(R, g, "NumBodies", H5T_STD_U32LE, H5T_NATIVE_UINT32, &nb);
  if (!rc)
    rc = write_dataset(R, g, "Points", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, np, 3, pts, "m");
  if (!rc)
    rc = write_dataset(R, g, "Segments", H5T_STD_U32LE, H5T_NATIVE_UINT32, np, 2, seg, "1");
  if (!rc)
    rc = write_dataset(R, g, "BodyIndex", H5T_STD_U32LE, H5T_NATIVE_UINT32, np, 0, bidx, "1");
  rc = close_group(R, g, rc);
done:
  free(pts);
  free(seg);
  free(bidx);
  return rc;
}

static int write_header(h5_reason *R, hid_t file, const rhod_snapshot_view *v) {
  hid_t g = create_group(R, file, "Header", H5P_DEFAULT);
  if (g < 0)
    return -1;
  int dim = RHOD_DIM;
  uint64_t np = (uint64_t)v->n;
  int rc = write_attr(R, g, "Time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &v->time);
  if (!rc)
    rc = write_attr(R, g, "Dimension", H5T_STD_I32LE, H5T_NATIVE_INT, &dim);
  if (!rc)
    rc = write_attr(R, g, "NumPart", H5T_STD_U64LE, H5T_NATIVE_UINT64, &np);
  if (!rc)
    rc = write_str_attr(R, g, "Code", "rhod");
  if (!rc)
    rc = write_str_attr(R, g, "Precision", RHOD_REAL_NAME);
  if (!rc)
    rc = write_str_attr(R, g, "CodeVersion", rhod_version());
  if (!rc)
    rc = write_str_attr(R, g, "GitCommit", rhod_commit());
  return close_group(R, g, rc);
}

/* HDF5 numbers an object's attributes in creation order with 16 bits: past this many, a
 * group cannot track their order ("attribute creation index can't be incremented"). */
#define MAX_TRACKED_ATTRS 65535u

/* A 1D dataset of variable-length strings (NULL written as ""). */
static int write_strings(h5_reason *R, hid_t loc, const char *name, char *const *s, unsigned n) {
  const char **v = malloc((n ? n : 1) * sizeof *v);
  if (!v)
    return -2;
  for (unsigned i = 0; i < n; i++)
    v[i] = s[i] ? s[i] : "";
  hid_t t = H5Tcopy(H5T_C_S1);
  int rc = -1;
  if (t >= 0 && H5Tset_size(t, H5T_VARIABLE) >= 0)
    rc = write_dataset(R, loc, name, t, t, n, 0, v, "");
  else
    note(R);
  if (t >= 0)
    H5Tclose(t);
  free(v);
  return rc;
}

/* /Parameters: the scene as run, as two datasets Keys and Values (variable-length strings,
 * in scene order: any number of keys) and, for h5py's f["Parameters"].attrs and older
 * readers, one string attribute per key, in creation order, while there are at most
 * 65535 keys (HDF5's limit for a tracked order; without it, HDF5 1.10 takes minutes to
 * add that many). The attributes are kept in dense storage (a heap and B-trees beside
 * the group): compact storage in the group's object header overflows at 64 KiB. */
static int write_params(h5_reason *R, hid_t file, const rhod_param_list *params, int *oom) {
  const unsigned n = params ? params->n : 0;
  hid_t gcpl = H5Pcreate(H5P_GROUP_CREATE);
  if (gcpl < 0) {
    note(R);
    return -1;
  }
  if (H5Pset_attr_creation_order(gcpl, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED) < 0 ||
      H5Pset_attr_phase_change(gcpl, 0, 0) < 0) {
    note(R);
    H5Pclose(gcpl);
    return -1;
  }
  hid_t g = create_group(R, file, "Parameters", gcpl);
  H5Pclose(gcpl);
  if (g < 0)
    return -1;
  int rc = 0;
  for (unsigned i = 0; n <= MAX_TRACKED_ATTRS && i < n && !rc; i++)
    rc = write_str_attr(R, g, params->keys[i], params->values[i] ? params->values[i] : "");
  if (!rc)
    rc = write_strings(R, g, "Keys", n ? params->keys : NULL, n);
  if (!rc)
    rc = write_strings(R, g, "Values", n ? params->values : NULL, n);
  if (rc == -2)
    *oom = 1;
  return close_group(R, g, rc);
}

/* An HDF5 file in memory (core driver, no backing store, growing by `increment`). */
static hid_t core_file(h5_reason *R, const char *name, size_t increment) {
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  hid_t file = -1;
  if (fapl >= 0 && H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) >= 0 &&
      H5Pset_fapl_core(fapl, increment, 0) >= 0)
    file = H5Fcreate(name, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  if (file < 0)
    note(R);
  if (fapl >= 0)
    H5Pclose(fapl);
  return file;
}

/* Closes an in-memory file and returns its image (NULL on failure, *oom set when out of
 * memory); bad: the file's content failed already (close it only). */
static void *close_image(h5_reason *R, hid_t file, int bad, size_t *size, int *oom) {
  void *image = NULL;
  *size = 0;
  if (!bad && H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) {
    note(R);
    bad = 1;
  }
  if (!bad) {
    ssize_t len = H5Fget_file_image(file, NULL, 0);
    if (len <= 0) {
      note(R);
    } else if ((image = malloc((size_t)len)) == NULL) {
      *oom = 1;
    } else if (H5Fget_file_image(file, image, (size_t)len) != len) {
      note(R);
      free(image);
      image = NULL;
    } else {
      *size = (size_t)len;
    }
  }
  if (file >= 0 && H5Fclose(file) < 0) {
    note(R);
    free(image);
    image = NULL;
  }
  return image;
}

/* Builds the whole file in memory (core driver, no backing store) and returns its image.
 * HDF5 never touches the disk, so a full disk cannot leave a half-closed HDF5 file behind
 * (HDF5 1.10 keeps such a file open and crashes at exit); the image is then written with
 * rhod_write_bytes_atomic, whose errors are plain errno values. */
static void *build_image(h5_reason *R, const char *name, const rhod_snapshot_view *v,
                         const rhod_param_list *params, size_t *size, int *oom) {
  *size = 0;
  *oom = 0;
  size_t n = v->n;
  double *buf = malloc(3 * (n ? n : 1) * sizeof *buf);
  if (!buf) {
    *oom = 1;
    return NULL;
  }
  /* one allocation of the core driver for the whole file, most of the time */
  size_t increment = n * (6 * sizeof(double) + 4 * sizeof(double) + 9 + 8) + (1u << 16);
  for (unsigned k = 0; k < v->nextra; k++)
    increment += n * (v->extra[k].u8 ? 1 : 3 * sizeof(double));
  const size_t nbp = body_points(v); /* checked by rhod_write_snapshot */
  if (v->n_bodies)
    increment += nbp * (3 * sizeof(double) + 3 * sizeof(uint32_t));
  hid_t file = core_file(R, name, increment);
  int bad = file < 0;
  if (!bad)
    bad = write_header(R, file, v) != 0;
  if (!bad)
    bad = write_particles(R, file, v, buf) != 0;
  if (!bad)
    bad = write_mesh(R, file, n, buf) != 0;
  free(buf);
  if (!bad && v->n_bodies)
    bad = write_bodies(R, file, v, nbp, oom) != 0;
  if (!bad)
    bad = write_params(R, file, params, oom) != 0;
  if (file < 0)
    return NULL;
  return close_image(R, file, bad, size, oom);
}

int rhod_write_snapshot(const char *dir, int index, const rhod_snapshot_view *v,
                        const rhod_param_list *params, char *err, size_t errlen) {
  char name[64];
  if (index < 0) {
    set_err(err, errlen, "snapshot index %d: must not be negative", index);
    return RHOD_ERR_IO;
  }
  snprintf(name, sizeof name, "snapshot_%04d.h5", index);
  char *path = join_path(dir, name);
  if (!path) {
    set_err(err, errlen, "%s: cannot write: out of memory", name);
    return RHOD_ERR_MEMORY;
  }
  if (v->n > 0 &&
      (!v->x || !v->y || !v->ux || !v->uy || !v->rho || !v->p || !v->m || !v->size || !v->id)) {
    set_err(err, errlen, "%s: cannot write: a particle field is missing", path);
    free(path);
    return RHOD_ERR_IO;
  }
  if (v->nextra > RHOD_MAX_EXTRA_FIELDS) {
    set_err(err, errlen, "%s: cannot write: %u extra fields, more than %d", path, v->nextra,
            RHOD_MAX_EXTRA_FIELDS);
    free(path);
    return RHOD_ERR_IO;
  }
  const size_t nbp = body_points(v);
  if (nbp == (size_t)-1 || nbp > UINT32_MAX) {
    set_err(err, errlen, "%s: cannot write: the outlines of the %u bodies are incomplete", path,
            v->n_bodies);
    free(path);
    return RHOD_ERR_IO;
  }
  for (unsigned k = 0; k < v->nextra; k++) {
    const rhod_snapshot_extra *e = &v->extra[k];
    if (!e->name || !e->name[0] || !e->units || (v->n > 0 && !e->data) ||
        !(e->comps == 1 || (e->comps == 2 && !e->u8))) {
      set_err(err, errlen, "%s: cannot write: extra field %u (%s) is incomplete", path, k,
              e->name ? e->name : "no name");
      free(path);
      return RHOD_ERR_IO;
    }
  }
  h5_quiet();
  h5_reason R = {0, 0, 0, ""};
  size_t size = 0;
  int oom = 0;
  void *image = build_image(&R, path, v, params, &size, &oom);
  int rc;
  if (!image) {
    char reason[200] = "out of memory";
    if (!oom)
      reason_text(&R, reason, sizeof reason);
    set_err(err, errlen, "%s: cannot write: %s", path, reason);
    rc = oom ? RHOD_ERR_MEMORY : RHOD_ERR_IO;
  } else {
    rc = rhod_write_bytes_atomic(path, image, size, err, errlen);
  }
  H5Eclear2(H5E_DEFAULT);
  free(image);
  free(path);
  return rc;
}

/* ---------------------------------------------------------------- walls */

unsigned rhod_shape_outline(const rhod_shape *sh, unsigned circle_segments, double (*out)[2]) {
  switch (sh->kind) {
  case RHOD_SHAPE_RECT:
    if (out) {
      const double c[4][2] = {{sh->min[0], sh->min[1]},
                              {sh->max[0], sh->min[1]},
                              {sh->max[0], sh->max[1]},
                              {sh->min[0], sh->max[1]}};
      memcpy(out, c, sizeof c);
    }
    return 4;
  case RHOD_SHAPE_POLYGON:
    if (out && sh->n_points)
      memcpy(out, sh->points, sizeof(double[2]) * sh->n_points);
    return sh->n_points;
  case RHOD_SHAPE_CIRCLE: {
    const unsigned n = circle_segments < 8 ? 8 : circle_segments;
    const double two_pi = 6.283185307179586476925286766559;
    for (unsigned k = 0; out && k < n; k++) {
      out[k][0] = sh->center[0] + sh->radius * cos(two_pi * k / n);
      out[k][1] = sh->center[1] + sh->radius * sin(two_pi * k / n);
    }
    return n;
  }
  }
  return 0;
}

/* Segments of a circle of radius r: no longer than dx/4, 64 to 65536. */
static unsigned circle_segments(double r, double dx) {
  double n = dx > 0 ? ceil(6.283185307179586 * r / (0.25 * dx)) : 64;
  if (!(n >= 64))
    n = 64;
  if (n > 65536)
    n = 65536;
  return (unsigned)n;
}

static const char WALLS_XDMF[] =
    "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
    "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
    "  <Domain>\n"
    "    <Grid Name=\"walls\" GridType=\"Uniform\">\n"
    "      <Topology TopologyType=\"Polyline\" NumberOfElements=\"%zu\" NodesPerElement=\"2\">\n"
    "        <DataItem Dimensions=\"%zu 2\" NumberType=\"UInt\" Precision=\"4\" "
    "Format=\"HDF\">walls.h5:/Walls/Segments</DataItem>\n"
    "      </Topology>\n"
    "      <Geometry GeometryType=\"XYZ\">\n"
    "        <DataItem Dimensions=\"%zu 3\" NumberType=\"Float\" Precision=\"8\" "
    "Format=\"HDF\">walls.h5:/Walls/Points</DataItem>\n"
    "      </Geometry>\n"
    "      <Attribute Name=\"WallIndex\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
    "        <DataItem Dimensions=\"%zu\" NumberType=\"UInt\" Precision=\"4\" "
    "Format=\"HDF\">walls.h5:/Walls/WallIndex</DataItem>\n"
    "      </Attribute>\n"
    "    </Grid>\n"
    "  </Domain>\n"
    "</Xdmf>\n";

int rhod_write_walls(const char *dir, const rhod_scene *sc, char *err, size_t errlen) {
  char *h5 = join_path(dir, "walls.h5"), *xdmf = join_path(dir, "walls.xdmf");
  if (!h5 || !xdmf) {
    free(h5);
    free(xdmf);
    set_err(err, errlen, "walls.h5: cannot write: out of memory");
    return RHOD_ERR_MEMORY;
  }
  int rc = RHOD_OK;
  if (sc->n_walls == 0) {
    /* none: no empty grid for readers to choke on; no file left from an earlier run */
    const char *paths[2] = {xdmf, h5};
    for (int k = 0; k < 2 && !rc; k++)
      if (remove(paths[k]) != 0 && errno != ENOENT) {
        set_err(err, errlen, "%s: cannot remove: %s", paths[k], strerror(errno));
        rc = RHOD_ERR_IO;
      }
    free(h5);
    free(xdmf);
    return rc;
  }
  size_t np = 0;
  for (unsigned w = 0; w < sc->n_walls; w++)
    np += rhod_shape_outline(&sc->walls[w].shape,
                             circle_segments(sc->walls[w].shape.radius, sc->dx), NULL);
  double *pts = malloc(sizeof(double) * 3 * np);
  double(*ring)[2] = malloc(sizeof(double[2]) * np);
  uint32_t *seg = malloc(sizeof(uint32_t) * 2 * np), *widx = malloc(sizeof(uint32_t) * np);
  uint8_t *inside = malloc(sc->n_walls);
  if (!pts || !ring || !seg || !widx || !inside || np > UINT32_MAX) {
    set_err(err, errlen, "%s: cannot write: out of memory", h5);
    rc = RHOD_ERR_MEMORY;
    goto done;
  }
  /* each wall a closed ring: its points, then segments k -> k+1 and last -> first */
  size_t at = 0;
  for (unsigned w = 0; w < sc->n_walls; w++) {
    const rhod_shape *sh = &sc->walls[w].shape;
    unsigned m = rhod_shape_outline(sh, circle_segments(sh->radius, sc->dx), ring);
    for (unsigned k = 0; k < m; k++) {
      pts[3 * (at + k)] = ring[k][0];
      pts[3 * (at + k) + 1] = ring[k][1];
      pts[3 * (at + k) + 2] = 0.0;
      seg[2 * (at + k)] = (uint32_t)(at + k);
      seg[2 * (at + k) + 1] = (uint32_t)(at + (k + 1) % m);
      widx[at + k] = w;
    }
    inside[w] = (uint8_t)(sc->walls[w].fluid_inside != 0);
    at += m;
  }
  h5_quiet();
  h5_reason R = {0, 0, 0, ""};
  hid_t file = core_file(&R, h5, np * 40 + (1u << 16));
  int bad = file < 0;
  if (!bad) {
    hid_t g = create_group(&R, file, "Header", H5P_DEFAULT);
    bad = g < 0;
    if (!bad) {
      uint32_t nw = sc->n_walls;
      int r = write_attr(&R, g, "NumWalls", H5T_STD_U32LE, H5T_NATIVE_UINT32, &nw);
      if (!r)
        r = write_str_attr(&R, g, "Code", "rhod");
      if (!r)
        r = write_str_attr(&R, g, "CodeVersion", rhod_version());
      if (!r)
        r = write_str_attr(&R, g, "GitCommit", rhod_commit());
      bad = close_group(&R, g, r) != 0;
    }
  }
  if (!bad) {
    hid_t g = create_group(&R, file, "Walls", H5P_DEFAULT);
    bad = g < 0;
    if (!bad) {
      int r = write_dataset(&R, g, "Points", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, np, 3, pts, "m");
      if (!r)
        r = write_dataset(&R, g, "Segments", H5T_STD_U32LE, H5T_NATIVE_UINT32, np, 2, seg, "1");
      if (!r)
        r = write_dataset(&R, g, "WallIndex", H5T_STD_U32LE, H5T_NATIVE_UINT32, np, 0, widx, "1");
      if (!r)
        r = write_dataset(&R, g, "FluidInside", H5T_STD_U8LE, H5T_NATIVE_UINT8, sc->n_walls, 0,
                          inside, "1");
      bad = close_group(&R, g, r) != 0;
    }
  }
  size_t size = 0;
  int oom = 0;
  void *image = file < 0 ? NULL : close_image(&R, file, bad, &size, &oom);
  H5Eclear2(H5E_DEFAULT);
  if (!image) {
    char reason[200] = "out of memory";
    if (!oom)
      reason_text(&R, reason, sizeof reason);
    set_err(err, errlen, "%s: cannot write: %s", h5, reason);
    rc = oom ? RHOD_ERR_MEMORY : RHOD_ERR_IO;
    goto done;
  }
  rc = rhod_write_bytes_atomic(h5, image, size, err, errlen);
  free(image);
  if (rc == RHOD_OK) {
    char text[sizeof WALLS_XDMF + 96];
    snprintf(text, sizeof text, WALLS_XDMF, np, np, np, np);
    rc = rhod_write_file_atomic(xdmf, text, err, errlen);
  }
done:
  free(pts);
  free(ring);
  free(seg);
  free(widx);
  free(inside);
  free(h5);
  free(xdmf);
  return rc;
}

/* ---------------------------------------------------------------- reading */

typedef struct {
  hid_t file;
  const char *path;
  char *err;
  size_t errlen;
} reader;

/* Reports the HDF5 failure that just happened (call it before any other HDF5 call). */
static int rfail(reader *r, const char *what) {
  char reason[200];
  h5_reason R = {0, 0, 0, ""};
  note(&R);
  reason_text(&R, reason, sizeof reason);
  set_err(r->err, r->errlen, "%s: cannot read %s: %s", r->path, what, reason);
  return RHOD_ERR_READ;
}

/* Opens /PartType0/name, checks its shape (n rows; cols columns, 0 for rank 1). */
static hid_t open_dataset(reader *r, const char *name, size_t n, unsigned cols, int *rc) {
  char full[96];
  snprintf(full, sizeof full, "/PartType0/%s", name);
  if (H5Lexists(r->file, full, H5P_DEFAULT) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    set_err(r->err, r->errlen, "%s: missing dataset %s", r->path, full);
    *rc = RHOD_ERR_READ;
    return -1;
  }
  hid_t d = H5Dopen2(r->file, full, H5P_DEFAULT);
  if (d < 0) {
    *rc = rfail(r, full);
    return -1;
  }
  hid_t sp = H5Dget_space(d);
  hsize_t dims[3] = {0, 0, 0};
  int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
  if (rank >= 1 && rank <= 2)
    H5Sget_simple_extent_dims(sp, dims, NULL);
  if (sp >= 0)
    H5Sclose(sp);
  int want_rank = cols ? 2 : 1;
  if (rank != want_rank || dims[0] != (hsize_t)n || (cols && dims[1] != cols)) {
    H5Dclose(d);
    set_err(r->err, r->errlen, "%s: dataset %s has the wrong shape (expected %zu%s)", r->path, full,
            n, cols == 3 ? " x 3" : "");
    *rc = RHOD_ERR_READ;
    return -1;
  }
  return d;
}

static int read_dataset(reader *r, const char *name, size_t n, unsigned cols, hid_t mtype,
                        void *buf) {
  int rc = RHOD_OK;
  hid_t d = open_dataset(r, name, n, cols, &rc);
  if (d < 0)
    return rc;
  if (n > 0 && H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) {
    char full[96];
    snprintf(full, sizeof full, "/PartType0/%s", name);
    rc = rfail(r, full);
  }
  H5Dclose(d);
  return rc;
}

static int read_attr(reader *r, hid_t loc, const char *name, hid_t mtype, void *val) {
  char what[64];
  snprintf(what, sizeof what, "/Header/%s", name);
  if (H5Aexists(loc, name) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    set_err(r->err, r->errlen, "%s: missing attribute %s", r->path, what);
    return RHOD_ERR_READ;
  }
  hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
  if (a < 0)
    return rfail(r, what);
  int rc = H5Aread(a, mtype, val) < 0 ? rfail(r, what) : RHOD_OK;
  H5Aclose(a);
  return rc;
}

typedef struct {
  rhod_param_list *list;
  unsigned cap;
  int failed;
} param_iter;

static char *read_string_attr(hid_t a) {
  hid_t ft = H5Aget_type(a);
  if (ft < 0)
    return NULL;
  char *out = NULL;
  if (H5Tget_class(ft) == H5T_STRING) {
    if (H5Tis_variable_str(ft) > 0) {
      hid_t mt = H5Tcopy(H5T_C_S1);
      char *s = NULL;
      if (mt >= 0 && H5Tset_size(mt, H5T_VARIABLE) >= 0 && H5Aread(a, mt, &s) >= 0) {
        out = strdup(s ? s : "");
        hid_t sp = H5Aget_space(a);
        if (sp >= 0) {
#if H5_VERSION_GE(1, 12, 0)
          H5Treclaim(mt, sp, H5P_DEFAULT, &s);
#else
          H5Dvlen_reclaim(mt, sp, H5P_DEFAULT, &s);
#endif
          H5Sclose(sp);
        }
      }
      if (mt >= 0)
        H5Tclose(mt);
    } else {
      size_t sz = H5Tget_size(ft);
      char *s = calloc(sz + 1, 1);
      if (s && H5Aread(a, ft, s) >= 0)
        out = s;
      else
        free(s);
    }
  }
  H5Tclose(ft);
  return out;
}

static herr_t param_cb(hid_t loc, const char *name, const H5A_info_t *info, void *data) {
  (void)info;
  param_iter *it = data;
  hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
  if (a < 0) {
    it->failed = 1;
    return -1;
  }
  char *val = read_string_attr(a);
  H5Aclose(a);
  if (!val)
    return 0; /* not a string attribute: not a parameter */
  rhod_param_list *l = it->list;
  if (l->n == it->cap) {
    unsigned cap = it->cap ? 2 * it->cap : 16;
    char **k = realloc(l->keys, cap * sizeof *k);
    if (k)
      l->keys = k;
    char **v = realloc(l->values, cap * sizeof *v);
    if (v)
      l->values = v;
    if (!k || !v) {
      free(val);
      it->failed = 2;
      return -1;
    }
    it->cap = cap;
  }
  char *key = strdup(name);
  if (!key) {
    free(val);
    it->failed = 2;
    return -1;
  }
  l->keys[l->n] = key;
  l->values[l->n] = val;
  l->n++;
  return 0;
}

/* A 1D dataset of strings (variable or fixed length) into malloc'd strings; *n its
 * length. Returns RHOD_OK, RHOD_ERR_READ or RHOD_ERR_MEMORY. */
static int read_strings(reader *r, hid_t g, const char *name, char ***out, size_t *n) {
  char what[64];
  snprintf(what, sizeof what, "/Parameters/%s", name);
  *out = NULL;
  *n = 0;
  hid_t d = H5Dopen2(g, name, H5P_DEFAULT);
  if (d < 0)
    return rfail(r, what);
  hid_t sp = H5Dget_space(d), ft = H5Dget_type(d);
  hsize_t dims[1] = {0};
  int rc = RHOD_OK;
  if (sp < 0 || ft < 0 || H5Sget_simple_extent_ndims(sp) != 1 || H5Tget_class(ft) != H5T_STRING ||
      H5Tis_variable_str(ft) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    set_err(r->err, r->errlen, "%s: %s is not a list of variable-length strings", r->path, what);
    rc = RHOD_ERR_READ;
  }
  if (!rc)
    H5Sget_simple_extent_dims(sp, dims, NULL);
  size_t len = (size_t)dims[0];
  char **raw = rc ? NULL : calloc(len ? len : 1, sizeof *raw);
  char **copy = rc ? NULL : calloc(len ? len : 1, sizeof *copy);
  hid_t mt = -1;
  if (!rc && (!raw || !copy))
    rc = RHOD_ERR_MEMORY;
  if (!rc) {
    mt = H5Tcopy(H5T_C_S1);
    if (mt < 0 || H5Tset_size(mt, H5T_VARIABLE) < 0 ||
        (len && H5Dread(d, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw) < 0))
      rc = rfail(r, what);
  }
  for (size_t i = 0; !rc && i < len; i++)
    if (!(copy[i] = strdup(raw[i] ? raw[i] : "")))
      rc = RHOD_ERR_MEMORY;
  if (mt >= 0 && raw && len) {
#if H5_VERSION_GE(1, 12, 0)
    H5Treclaim(mt, sp, H5P_DEFAULT, raw);
#else
    H5Dvlen_reclaim(mt, sp, H5P_DEFAULT, raw);
#endif
  }
  if (mt >= 0)
    H5Tclose(mt);
  free(raw);
  if (rc == RHOD_ERR_MEMORY)
    set_err(r->err, r->errlen, "%s: out of memory reading %s", r->path, what);
  if (rc) {
    for (size_t i = 0; copy && i < len; i++)
      free(copy[i]);
    free(copy);
  } else {
    *out = copy;
    *n = len;
  }
  if (ft >= 0)
    H5Tclose(ft);
  if (sp >= 0)
    H5Sclose(sp);
  H5Dclose(d);
  return rc;
}

static int read_params(reader *r, rhod_param_list *out) {
  if (H5Lexists(r->file, "/Parameters", H5P_DEFAULT) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    return RHOD_OK;
  }
  hid_t g = H5Gopen2(r->file, "/Parameters", H5P_DEFAULT);
  if (g < 0)
    return rfail(r, "/Parameters");
  if (H5Lexists(g, "Keys", H5P_DEFAULT) > 0 && H5Lexists(g, "Values", H5P_DEFAULT) > 0) {
    /* the datasets: in scene order, any number of keys */
    size_t nk = 0, nv = 0;
    char **k = NULL, **v = NULL;
    int rc = read_strings(r, g, "Keys", &k, &nk);
    if (!rc)
      rc = read_strings(r, g, "Values", &v, &nv);
    if (!rc && (nk != nv || nk > UINT_MAX)) {
      set_err(r->err, r->errlen, "%s: /Parameters has %zu Keys and %zu Values", r->path, nk, nv);
      rc = RHOD_ERR_READ;
    }
    if (rc) {
      for (size_t i = 0; k && i < nk; i++)
        free(k[i]);
      for (size_t i = 0; v && i < nv; i++)
        free(v[i]);
      free(k);
      free(v);
    } else {
      out->keys = k;
      out->values = v;
      out->n = (unsigned)nk;
    }
    H5Gclose(g);
    return rc;
  }
  H5Eclear2(H5E_DEFAULT);
  /* written before the datasets: one attribute per key */
  param_iter it = {out, 0, 0};
  hsize_t idx = 0;
  herr_t h = H5Aiterate2(g, H5_INDEX_CRT_ORDER, H5_ITER_INC, &idx, param_cb, &it);
  if (h < 0 && !it.failed && out->n == 0) {
    /* written without creation-order tracking: name order */
    H5Eclear2(H5E_DEFAULT);
    idx = 0;
    h = H5Aiterate2(g, H5_INDEX_NAME, H5_ITER_INC, &idx, param_cb, &it);
  }
  int rc = RHOD_OK;
  if (it.failed == 2) {
    set_err(r->err, r->errlen, "%s: out of memory reading /Parameters", r->path);
    rc = RHOD_ERR_MEMORY;
  } else if (h < 0 || it.failed) {
    rc = rfail(r, "/Parameters");
  }
  H5Gclose(g);
  return rc;
}

/* The datasets rhod_write_snapshot writes itself; every other one of /PartType0 is an
 * extra. */
static int fixed_dataset(const char *name) {
  static const char *const fixed[] = {"Coordinates", "Velocities",  "Densities",
                                      "Pressures",   "Masses",      "ParticleSizes",
                                      "ParticleIDs", "FreeSurface", "Phase"};
  for (size_t k = 0; k < sizeof fixed / sizeof fixed[0]; k++)
    if (!strcmp(name, fixed[k]))
      return 1;
  return 0;
}

typedef struct {
  char **names;
  unsigned n, cap;
  int oom;
} name_list;

static herr_t extra_name_cb(hid_t g, const char *name, const H5L_info_t *info, void *data) {
  (void)g, (void)info;
  name_list *l = data;
  if (fixed_dataset(name))
    return 0;
  if (l->n == l->cap) {
    unsigned cap = l->cap ? 2 * l->cap : 8;
    char **a = realloc(l->names, cap * sizeof *a);
    if (!a) {
      l->oom = 1;
      return -1;
    }
    l->names = a, l->cap = cap;
  }
  if (!(l->names[l->n] = strdup(name))) {
    l->oom = 1;
    return -1;
  }
  l->n++;
  return 0;
}

/* One extra dataset: uint8 of N, or float of N or N x 3 (a vector, z dropped), with a
 * string attribute Units. */
static int read_extra(reader *r, size_t n, rhod_snapshot_extra_data *e) {
  char full[96];
  snprintf(full, sizeof full, "/PartType0/%s", e->name);
  hid_t d = H5Dopen2(r->file, full, H5P_DEFAULT);
  if (d < 0)
    return rfail(r, full);
  hid_t sp = H5Dget_space(d), ft = H5Dget_type(d);
  hsize_t dims[3] = {0, 0, 0};
  const int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
  if (rank >= 1 && rank <= 2)
    H5Sget_simple_extent_dims(sp, dims, NULL);
  const H5T_class_t cl = ft >= 0 ? H5Tget_class(ft) : H5T_NO_CLASS;
  const int u8 = cl == H5T_INTEGER && H5Tget_size(ft) == 1 && H5Tget_sign(ft) == H5T_SGN_NONE;
  int rc = RHOD_OK;
  if (!(dims[0] == (hsize_t)n && (rank == 1 || (rank == 2 && dims[1] == 3 && cl == H5T_FLOAT)) &&
        (u8 || cl == H5T_FLOAT))) {
    H5Eclear2(H5E_DEFAULT);
    set_err(r->err, r->errlen,
            "%s: dataset %s is neither N uint8 nor N or N x 3 floating-point values (N = %zu)",
            r->path, full, n);
    rc = RHOD_ERR_READ;
  }
  e->u8 = u8;
  e->comps = rank == 2 ? 2 : 1;
  const size_t nn = n ? n : 1;
  double *buf = NULL;
  if (!rc) {
    if (u8)
      e->b = malloc(nn);
    else
      e->v = malloc(nn * (size_t)e->comps * sizeof(double));
    buf = rank == 2 ? malloc(3 * nn * sizeof *buf) : NULL;
    if ((u8 ? !e->b : !e->v) || (rank == 2 && !buf)) {
      set_err(r->err, r->errlen, "%s: out of memory reading %s", r->path, full);
      rc = RHOD_ERR_MEMORY;
    }
  }
  if (!rc && n > 0) {
    void *to = u8 ? (void *)e->b : rank == 2 ? (void *)buf : (void *)e->v;
    if (H5Dread(d, u8 ? H5T_NATIVE_UINT8 : H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, to) <
        0)
      rc = rfail(r, full);
  }
  for (size_t i = 0; !rc && buf && i < n; i++)
    e->v[2 * i] = buf[3 * i], e->v[2 * i + 1] = buf[3 * i + 1];
  free(buf);
  if (!rc) {
    hid_t a = H5Aexists(d, "Units") > 0 ? H5Aopen(d, "Units", H5P_DEFAULT) : -1;
    e->units = a >= 0 ? read_string_attr(a) : NULL;
    if (a >= 0)
      H5Aclose(a);
    if (!e->units) {
      H5Eclear2(H5E_DEFAULT);
      set_err(r->err, r->errlen, "%s: dataset %s has no string attribute Units", r->path, full);
      rc = RHOD_ERR_READ;
    }
  }
  if (ft >= 0)
    H5Tclose(ft);
  if (sp >= 0)
    H5Sclose(sp);
  H5Dclose(d);
  return rc;
}

/* Every dataset of /PartType0 that is not a fixed one, in name order. */
static int read_extras(reader *r, rhod_snapshot_data *out) {
  hid_t g = H5Gopen2(r->file, "/PartType0", H5P_DEFAULT);
  if (g < 0)
    return rfail(r, "/PartType0");
  name_list l = {NULL, 0, 0, 0};
  hsize_t at = 0;
  const herr_t it = H5Literate(g, H5_INDEX_NAME, H5_ITER_INC, &at, extra_name_cb, &l);
  int rc = RHOD_OK;
  if (l.oom) {
    set_err(r->err, r->errlen, "%s: out of memory reading /PartType0", r->path);
    rc = RHOD_ERR_MEMORY;
  } else if (it < 0) {
    rc = rfail(r, "/PartType0");
  }
  H5Gclose(g);
  if (!rc && l.n) {
    out->extra = calloc(l.n, sizeof *out->extra);
    if (!out->extra) {
      set_err(r->err, r->errlen, "%s: out of memory reading /PartType0", r->path);
      rc = RHOD_ERR_MEMORY;
    }
  }
  for (unsigned k = 0; k < l.n; k++) {
    if (!rc) {
      out->extra[k].name = l.names[k];
      out->nextra = k + 1;
      rc = read_extra(r, out->n, &out->extra[k]);
    } else {
      free(l.names[k]);
    }
  }
  free(l.names);
  return rc;
}

/* /Bodies/name: rank 1 (cols 0) or rows x cols of a floating-point (flt) or unsigned integer
 * type; *rows its length. -1 (error set) when missing or of another shape or type. */
static hid_t open_body_dataset(reader *r, const char *name, unsigned cols, int flt, size_t *rows,
                               int *rc) {
  char full[64];
  snprintf(full, sizeof full, "/Bodies/%s", name);
  if (H5Lexists(r->file, full, H5P_DEFAULT) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    set_err(r->err, r->errlen, "%s: missing dataset %s", r->path, full);
    *rc = RHOD_ERR_READ;
    return -1;
  }
  hid_t d = H5Dopen2(r->file, full, H5P_DEFAULT);
  if (d < 0) {
    *rc = rfail(r, full);
    return -1;
  }
  hid_t sp = H5Dget_space(d), ft = H5Dget_type(d);
  hsize_t dims[3] = {0, 0, 0};
  const int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
  if (rank >= 1 && rank <= 2)
    H5Sget_simple_extent_dims(sp, dims, NULL);
  const H5T_class_t cl = ft >= 0 ? H5Tget_class(ft) : H5T_NO_CLASS;
  const int type_ok = flt ? cl == H5T_FLOAT : cl == H5T_INTEGER && H5Tget_sign(ft) == H5T_SGN_NONE;
  if (ft >= 0)
    H5Tclose(ft);
  if (sp >= 0)
    H5Sclose(sp);
  if (rank != (cols ? 2 : 1) || (cols && dims[1] != cols) || !type_ok ||
      dims[0] > (hsize_t)UINT32_MAX) {
    H5Eclear2(H5E_DEFAULT);
    H5Dclose(d);
    set_err(r->err, r->errlen, "%s: dataset %s is not %s%s", r->path, full,
            flt ? "floating-point" : "unsigned integer",
            cols == 3   ? ", P x 3"
            : cols == 2 ? ", S x 2"
                        : ", S");
    *rc = RHOD_ERR_READ;
    return -1;
  }
  *rows = (size_t)dims[0];
  return d;
}

/* /Bodies when the file has it (older snapshots have none): NumBodies, Points, Segments,
 * BodyIndex, checked against each other. */
static int read_bodies(reader *r, rhod_snapshot_data *out) {
  if (H5Lexists(r->file, "/Bodies", H5P_DEFAULT) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    return RHOD_OK;
  }
  hid_t g = H5Gopen2(r->file, "/Bodies", H5P_DEFAULT);
  if (g < 0)
    return rfail(r, "/Bodies");
  uint32_t nb = 0;
  int rc = RHOD_OK;
  if (H5Aexists(g, "NumBodies") <= 0) {
    H5Eclear2(H5E_DEFAULT);
    set_err(r->err, r->errlen, "%s: missing attribute /Bodies/NumBodies", r->path);
    rc = RHOD_ERR_READ;
  } else {
    hid_t a = H5Aopen(g, "NumBodies", H5P_DEFAULT);
    if (a < 0 || H5Aread(a, H5T_NATIVE_UINT32, &nb) < 0)
      rc = rfail(r, "/Bodies/NumBodies");
    if (a >= 0)
      H5Aclose(a);
  }
  H5Gclose(g);
  if (rc)
    return rc;
  size_t np = 0, ns = 0, ni = 0;
  hid_t dp = open_body_dataset(r, "Points", 3, 1, &np, &rc);
  hid_t ds = rc ? -1 : open_body_dataset(r, "Segments", 2, 0, &ns, &rc);
  hid_t di = rc ? -1 : open_body_dataset(r, "BodyIndex", 0, 0, &ni, &rc);
  if (!rc && ni != ns) {
    set_err(r->err, r->errlen, "%s: /Bodies has %zu Segments and %zu BodyIndex values", r->path, ns,
            ni);
    rc = RHOD_ERR_READ;
  }
  double *pts = NULL;
  if (!rc) {
    pts = malloc(sizeof(double) * 3 * (np ? np : 1));
    out->body_xy = malloc(sizeof(double) * 2 * (np ? np : 1));
    out->body_segments = malloc(sizeof(uint32_t) * 2 * (ns ? ns : 1));
    out->body_index = malloc(sizeof(uint32_t) * (ns ? ns : 1));
    if (!pts || !out->body_xy || !out->body_segments || !out->body_index) {
      set_err(r->err, r->errlen, "%s: out of memory reading /Bodies", r->path);
      rc = RHOD_ERR_MEMORY;
    }
  }
  if (!rc && np && H5Dread(dp, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pts) < 0)
    rc = rfail(r, "/Bodies/Points");
  if (!rc && ns &&
      H5Dread(ds, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, out->body_segments) < 0)
    rc = rfail(r, "/Bodies/Segments");
  if (!rc && ns &&
      H5Dread(di, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, out->body_index) < 0)
    rc = rfail(r, "/Bodies/BodyIndex");
  for (size_t k = 0; !rc && k < np; k++)
    out->body_xy[2 * k] = pts[3 * k], out->body_xy[2 * k + 1] = pts[3 * k + 1];
  for (size_t k = 0; !rc && k < ns; k++)
    if (out->body_segments[2 * k] >= np || out->body_segments[2 * k + 1] >= np ||
        out->body_index[k] >= nb) {
      set_err(r->err, r->errlen,
              "%s: /Bodies segment %zu (%u, %u) of body %u is out of range (%zu points, %u "
              "bodies)",
              r->path, k, (unsigned)out->body_segments[2 * k],
              (unsigned)out->body_segments[2 * k + 1], (unsigned)out->body_index[k], np,
              (unsigned)nb);
      rc = RHOD_ERR_READ;
    }
  free(pts);
  if (dp >= 0)
    H5Dclose(dp);
  if (ds >= 0)
    H5Dclose(ds);
  if (di >= 0)
    H5Dclose(di);
  if (!rc) {
    out->n_bodies = nb;
    out->n_body_points = np;
    out->n_body_segments = ns;
  }
  return rc;
}

static int read_all(reader *r, rhod_snapshot_data *out) {
  if (H5Lexists(r->file, "/Header", H5P_DEFAULT) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    set_err(r->err, r->errlen, "%s: missing group /Header", r->path);
    return RHOD_ERR_READ;
  }
  hid_t h = H5Gopen2(r->file, "/Header", H5P_DEFAULT);
  if (h < 0)
    return rfail(r, "/Header");
  uint64_t np = 0;
  int dim = 0;
  int rc = read_attr(r, h, "Time", H5T_NATIVE_DOUBLE, &out->time);
  if (!rc)
    rc = read_attr(r, h, "NumPart", H5T_NATIVE_UINT64, &np);
  if (!rc)
    rc = read_attr(r, h, "Dimension", H5T_NATIVE_INT, &dim);
  H5Gclose(h);
  if (rc)
    return rc;
  if (dim != RHOD_DIM) {
    set_err(r->err, r->errlen, "%s: Dimension is %d, expected %d", r->path, dim, RHOD_DIM);
    return RHOD_ERR_READ;
  }
  if (np > (uint64_t)(SIZE_MAX / (3 * sizeof(double)))) {
    set_err(r->err, r->errlen, "%s: NumPart %llu is too large", r->path, (unsigned long long)np);
    return RHOD_ERR_READ;
  }
  size_t n = (size_t)np, nn = n ? n : 1;
  out->n = n;
  double **fields[] = {&out->x,   &out->y, &out->ux, &out->uy,
                       &out->rho, &out->p, &out->m,  &out->size};
  for (size_t k = 0; k < sizeof fields / sizeof fields[0]; k++)
    if (!(*fields[k] = malloc(nn * sizeof(double))))
      rc = RHOD_ERR_MEMORY;
  out->id = malloc(nn * sizeof *out->id);
  double *buf = malloc(3 * nn * sizeof *buf);
  if (!out->id || !buf)
    rc = RHOD_ERR_MEMORY;
  if (rc) {
    free(buf);
    set_err(r->err, r->errlen, "%s: out of memory reading %zu particles", r->path, n);
    return rc;
  }
  const char *vec[2] = {"Coordinates", "Velocities"};
  double *dst[2][2] = {{out->x, out->y}, {out->ux, out->uy}};
  for (int k = 0; k < 2 && !rc; k++) {
    rc = read_dataset(r, vec[k], n, 3, H5T_NATIVE_DOUBLE, buf);
    for (size_t i = 0; i < n && !rc; i++) {
      dst[k][0][i] = buf[3 * i];
      dst[k][1][i] = buf[3 * i + 1];
    }
  }
  free(buf);
  const char *sc[4] = {"Densities", "Pressures", "Masses", "ParticleSizes"};
  double *sd[4] = {out->rho, out->p, out->m, out->size};
  for (int k = 0; k < 4 && !rc; k++)
    rc = read_dataset(r, sc[k], n, 0, H5T_NATIVE_DOUBLE, sd[k]);
  if (!rc)
    rc = read_dataset(r, "ParticleIDs", n, 0, H5T_NATIVE_UINT64, out->id);
  if (!rc && H5Lexists(r->file, "/PartType0/FreeSurface", H5P_DEFAULT) > 0) {
    out->fs = malloc(nn);
    if (!out->fs) {
      set_err(r->err, r->errlen, "%s: out of memory reading %zu particles", r->path, n);
      return RHOD_ERR_MEMORY;
    }
    rc = read_dataset(r, "FreeSurface", n, 0, H5T_NATIVE_UINT8, out->fs);
  }
  if (!rc && H5Lexists(r->file, "/PartType0/Phase", H5P_DEFAULT) > 0) {
    out->phase = malloc(nn);
    if (!out->phase) {
      set_err(r->err, r->errlen, "%s: out of memory reading %zu particles", r->path, n);
      return RHOD_ERR_MEMORY;
    }
    rc = read_dataset(r, "Phase", n, 0, H5T_NATIVE_UINT8, out->phase);
  }
  H5Eclear2(H5E_DEFAULT);
  if (!rc)
    rc = read_extras(r, out);
  if (!rc)
    rc = read_params(r, &out->params);
  if (!rc)
    rc = read_bodies(r, out);
  return rc;
}

/* Opens path for reading into r. A plain open first, for a clean "No such file or
 * directory" style reason. */
static int open_reader(reader *r, const char *path, char *err, size_t errlen) {
  h5_quiet();
  *r = (reader){-1, path, err, errlen};
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    set_err(err, errlen, "%s: cannot read: %s", path, strerror(errno));
    return RHOD_ERR_READ;
  }
  close(fd);
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (fapl >= 0 && H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) >= 0)
    r->file = H5Fopen(path, H5F_ACC_RDONLY, fapl);
  h5_reason R = {0, 0, 0, ""};
  if (r->file < 0)
    note(&R);
  if (fapl >= 0)
    H5Pclose(fapl);
  if (r->file < 0) {
    char reason[200];
    reason_text(&R, reason, sizeof reason);
    set_err(err, errlen, "%s: cannot read: %s", path, reason);
    return RHOD_ERR_READ;
  }
  return RHOD_OK;
}

int rhod_read_snapshot(const char *path, rhod_snapshot_data *out, char *err, size_t errlen) {
  memset(out, 0, sizeof *out);
  reader r;
  int rc = open_reader(&r, path, err, errlen);
  if (rc)
    return rc;
  rc = read_all(&r, out);
  H5Fclose(r.file);
  H5Eclear2(H5E_DEFAULT);
  if (rc)
    rhod_snapshot_data_free(out);
  return rc;
}

void rhod_snapshot_data_free(rhod_snapshot_data *d) {
  if (!d)
    return;
  free(d->x);
  free(d->y);
  free(d->ux);
  free(d->uy);
  free(d->rho);
  free(d->p);
  free(d->m);
  free(d->size);
  free(d->id);
  free(d->fs);
  free(d->phase);
  for (unsigned i = 0; i < d->nextra; i++) {
    free(d->extra[i].name);
    free(d->extra[i].units);
    free(d->extra[i].v);
    free(d->extra[i].b);
  }
  free(d->extra);
  for (unsigned i = 0; i < d->params.n; i++) {
    free(d->params.keys[i]);
    free(d->params.values[i]);
  }
  free(d->params.keys);
  free(d->params.values);
  free(d->body_xy);
  free(d->body_segments);
  free(d->body_index);
  memset(d, 0, sizeof *d);
}

int rhod_read_snapshot_header(const char *path, double *time, uint64_t *n, char *err,
                              size_t errlen) {
  reader r;
  int rc = open_reader(&r, path, err, errlen);
  if (rc)
    return rc;
  hid_t h = -1;
  if (H5Lexists(r.file, "/Header", H5P_DEFAULT) <= 0) {
    set_err(err, errlen, "%s: missing group /Header", path);
    rc = RHOD_ERR_READ;
  } else if ((h = H5Gopen2(r.file, "/Header", H5P_DEFAULT)) < 0) {
    rc = rfail(&r, "/Header");
  }
  if (!rc)
    rc = read_attr(&r, h, "Time", H5T_NATIVE_DOUBLE, time);
  if (!rc)
    rc = read_attr(&r, h, "NumPart", H5T_NATIVE_UINT64, n);
  if (h >= 0)
    H5Gclose(h);
  H5Fclose(r.file);
  H5Eclear2(H5E_DEFAULT);
  return rc;
}
