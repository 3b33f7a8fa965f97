/* The XDMF sidecar: OUT/snapshots.xdmf describes every snapshot_NNNN.h5 written so far as
 * one Polyvertex grid each, gathered in a temporal collection, so that ParaView opens the
 * run as a time series of particles with their fields. Rewritten atomically after each
 * snapshot.
 *
 * XDMF 3 (meshio's time-series reader needs Version 3; ParaView's Xdmf3 readers and its
 * legacy "XDMF Reader" read it too). The Polyvertex topology has explicit connectivity,
 * /Mesh/Vertices of the snapshot (0..N-1, N x 1): without it the Xdmf3 readers make no
 * cells and ParaView's default representation shows nothing. Attribute names are
 * singular (Velocity, Pressure, ...), their units those of the datasets' Units
 * attributes (docs/scene.md). Particle ids are declared as 8-byte Int, as SWIFT does,
 * which every XDMF reader maps. A run with bodies gets a second temporal collection, their
 * outlines as Polyline grids at the snapshots' times (the layout of walls.xdmf). */
#define _POSIX_C_SOURCE 200809L

#include "rhod/io.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

unsigned rhod_snapshot_fields(const rhod_snapshot_view *v) {
  return (v && v->fs ? RHOD_FIELDS_FREE_SURFACE : 0u) | (v && v->phase ? RHOD_FIELDS_PHASE : 0u);
}

/* One DataItem pointing into a snapshot (path relative to the XDMF file). */
static void data_item(FILE *f, const char *file, const char *dataset, size_t n, int cols,
                      const char *type, int precision) {
  if (cols)
    fprintf(f, "          <DataItem Dimensions=\"%zu %d\" ", n, cols);
  else
    fprintf(f, "          <DataItem Dimensions=\"%zu\" ", n);
  fprintf(f, "NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">%s:%s</DataItem>\n", type,
          precision, file, dataset);
}

static void attribute(FILE *f, const char *file, const char *name, const char *dataset, size_t n,
                      int vector, const char *type, int precision) {
  fprintf(f, "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n", name,
          vector ? "Vector" : "Scalar");
  data_item(f, file, dataset, n, vector ? 3 : 0, type, precision);
  fprintf(f, "        </Attribute>\n");
}

static void grid(FILE *f, int index, double time, size_t n, unsigned fields,
                 const rhod_snapshot_extra *extra, unsigned nextra) {
  char file[64];
  snprintf(file, sizeof file, "snapshot_%04d.h5", index);
  fprintf(f, "      <Grid Name=\"snapshot_%04d\" GridType=\"Uniform\">\n", index);
  fprintf(f, "        <Time Value=\"%.15g\"/>\n", time);
  fprintf(f,
          "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
          "NodesPerElement=\"1\">\n",
          n);
  /* 4-byte indices while N fits (io_hdf5.c, write_mesh) */
  data_item(f, file, "/Mesh/Vertices", n, 1, "UInt", n <= UINT32_MAX ? 4 : 8);
  fprintf(f, "        </Topology>\n");
  fprintf(f, "        <Geometry GeometryType=\"XYZ\">\n");
  data_item(f, file, "/PartType0/Coordinates", n, 3, "Float", 8);
  fprintf(f, "        </Geometry>\n");
  attribute(f, file, "Velocity", "/PartType0/Velocities", n, 1, "Float", 8);
  attribute(f, file, "Density", "/PartType0/Densities", n, 0, "Float", 8);
  attribute(f, file, "Pressure", "/PartType0/Pressures", n, 0, "Float", 8);
  attribute(f, file, "Mass", "/PartType0/Masses", n, 0, "Float", 8);
  attribute(f, file, "ParticleSize", "/PartType0/ParticleSizes", n, 0, "Float", 8);
  attribute(f, file, "ParticleID", "/PartType0/ParticleIDs", n, 0, "Int", 8);
  if (fields & RHOD_FIELDS_FREE_SURFACE)
    attribute(f, file, "FreeSurface", "/PartType0/FreeSurface", n, 0, "UChar", 1);
  if (fields & RHOD_FIELDS_PHASE)
    attribute(f, file, "Phase", "/PartType0/Phase", n, 0, "UChar", 1);
  for (unsigned k = 0; k < nextra; k++) { /* output.fields: named as their datasets */
    char ds[96];
    snprintf(ds, sizeof ds, "/PartType0/%s", extra[k].name);
    attribute(f, file, extra[k].name, ds, n, extra[k].comps == 2, extra[k].u8 ? "UChar" : "Float",
              extra[k].u8 ? 1 : 8);
  }
  fprintf(f, "      </Grid>\n");
}

/* One snapshot's bodies (io_hdf5.c, write_bodies): np points, as many segments. */
static void body_grid(FILE *f, int index, double time, size_t np) {
  char file[64];
  snprintf(file, sizeof file, "snapshot_%04d.h5", index);
  fprintf(f, "      <Grid Name=\"bodies_%04d\" GridType=\"Uniform\">\n", index);
  fprintf(f, "        <Time Value=\"%.15g\"/>\n", time);
  fprintf(f,
          "        <Topology TopologyType=\"Polyline\" NumberOfElements=\"%zu\" "
          "NodesPerElement=\"2\">\n",
          np);
  data_item(f, file, "/Bodies/Segments", np, 2, "UInt", 4);
  fprintf(f, "        </Topology>\n");
  fprintf(f, "        <Geometry GeometryType=\"XYZ\">\n");
  data_item(f, file, "/Bodies/Points", np, 3, "Float", 8);
  fprintf(f, "        </Geometry>\n");
  fprintf(f, "        <Attribute Name=\"BodyIndex\" AttributeType=\"Scalar\" Center=\"Cell\">\n");
  data_item(f, file, "/Bodies/BodyIndex", np, 0, "UInt", 4);
  fprintf(f, "        </Attribute>\n");
  fprintf(f, "      </Grid>\n");
}

int rhod_write_xdmf(const char *dir, int count, const double *times, const size_t *nparts,
                    unsigned fields, char *err, size_t errlen) {
  return rhod_write_xdmf_fields(dir, count, times, nparts, fields, NULL, 0, err, errlen);
}

int rhod_write_xdmf_fields(const char *dir, int count, const double *times, const size_t *nparts,
                           unsigned fields, const rhod_snapshot_extra *extra, unsigned nextra,
                           char *err, size_t errlen) {
  return rhod_write_xdmf_bodies(dir, count, times, nparts, fields, extra, nextra, 0, err, errlen);
}

int rhod_write_xdmf_bodies(const char *dir, int count, const double *times, const size_t *nparts,
                           unsigned fields, const rhod_snapshot_extra *extra, unsigned nextra,
                           size_t body_points, char *err, size_t errlen) {
  size_t dl = dir ? strlen(dir) : 0;
  const char *name = "snapshots.xdmf";
  char *path = malloc(dl + strlen(name) + 2);
  if (!path) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot write: out of memory", name);
    return RHOD_ERR_MEMORY;
  }
  if (dl)
    snprintf(path, dl + strlen(name) + 2, "%s%s%s", dir, dir[dl - 1] == '/' ? "" : "/", name);
  else
    strcpy(path, name);

  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (!f) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
    free(path);
    return RHOD_ERR_MEMORY;
  }
  fprintf(f, "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
             "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
             "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
             "  <Domain>\n");
  if (body_points > 0) {
    /* the bodies first: meshio's time-series reader takes the domain's last collection */
    fprintf(f, "    <Grid Name=\"bodies\" GridType=\"Collection\" "
               "CollectionType=\"Temporal\">\n");
    for (int i = 0; i < count; i++)
      body_grid(f, i, times[i], body_points);
    fprintf(f, "    </Grid>\n");
  }
  fprintf(f, "    <Grid Name=\"particles\" GridType=\"Collection\" "
             "CollectionType=\"Temporal\">\n");
  for (int i = 0; i < count; i++)
    grid(f, i, times[i], nparts[i], fields, extra, nextra);
  fprintf(f, "    </Grid>\n"
             "  </Domain>\n"
             "</Xdmf>\n");
  int bad = ferror(f);
  if (fclose(f) != 0)
    bad = 1;
  int rc;
  if (bad || !text) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot write: out of memory", path);
    rc = RHOD_ERR_MEMORY;
  } else {
    rc = rhod_write_bytes_atomic(path, text, len, err, errlen);
  }
  free(text);
  free(path);
  return rc;
}
