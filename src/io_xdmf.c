/* The XDMF sidecar: OUT/snapshots.xdmf describes every snapshot_NNNN.h5 written so far as
 * one Polyvertex grid each, gathered in a temporal collection, so that ParaView opens the
 * run as a time series of particles with their fields. Rewritten atomically after each
 * snapshot.
 *
 * The layout follows SWIFT's .xmf files (XDMF 2): the Polyvertex topology has no
 * connectivity array, so ParaView's "XDMF Reader" gives every particle its own vertex
 * cell (Xdmf2's default connectivity 0..N-1). The Xdmf3 readers load the same points
 * and fields without cells: use the Point Gaussian representation there. Particle ids
 * are declared as 8-byte Int, as SWIFT does, which every XDMF reader maps. */
#define _POSIX_C_SOURCE 200809L

#include "rhod/io.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* One DataItem pointing into /PartType0 of a snapshot (path relative to the XDMF file). */
static void data_item(FILE *f, const char *file, const char *dataset, size_t n, int cols,
                      const char *type) {
  if (cols)
    fprintf(f, "          <DataItem Dimensions=\"%zu %d\" ", n, cols);
  else
    fprintf(f, "          <DataItem Dimensions=\"%zu\" ", n);
  fprintf(f, "NumberType=\"%s\" Precision=\"8\" Format=\"HDF\">%s:/PartType0/%s</DataItem>\n", type,
          file, dataset);
}

static void attribute(FILE *f, const char *file, const char *name, const char *dataset, size_t n,
                      int vector, const char *type) {
  fprintf(f, "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n", name,
          vector ? "Vector" : "Scalar");
  data_item(f, file, dataset, n, vector ? 3 : 0, type);
  fprintf(f, "        </Attribute>\n");
}

static void grid(FILE *f, int index, double time, size_t n) {
  char file[64];
  snprintf(file, sizeof file, "snapshot_%04d.h5", index);
  fprintf(f, "      <Grid Name=\"snapshot_%04d\" GridType=\"Uniform\">\n", index);
  fprintf(f, "        <Time Value=\"%.15g\"/>\n", time);
  fprintf(f,
          "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
          "NodesPerElement=\"1\"/>\n",
          n);
  fprintf(f, "        <Geometry GeometryType=\"XYZ\">\n");
  data_item(f, file, "Coordinates", n, 3, "Float");
  fprintf(f, "        </Geometry>\n");
  attribute(f, file, "Velocity", "Velocities", n, 1, "Float");
  attribute(f, file, "Density", "Densities", n, 0, "Float");
  attribute(f, file, "Pressure", "Pressures", n, 0, "Float");
  attribute(f, file, "Mass", "Masses", n, 0, "Float");
  attribute(f, file, "ParticleSize", "ParticleSizes", n, 0, "Float");
  attribute(f, file, "ParticleID", "ParticleIDs", n, 0, "Int");
  fprintf(f, "      </Grid>\n");
}

int rhod_write_xdmf(const char *dir, int count, const double *times, const size_t *nparts,
                    char *err, size_t errlen) {
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
             "<Xdmf Version=\"2.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
             "  <Domain>\n"
             "    <Grid Name=\"particles\" GridType=\"Collection\" "
             "CollectionType=\"Temporal\">\n");
  for (int i = 0; i < count; i++)
    grid(f, i, times[i], nparts[i]);
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
