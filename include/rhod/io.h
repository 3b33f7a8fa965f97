/* Writers: HDF5 snapshots (SWIFT-like layout), the XDMF sidecar, PNG pictures,
 * probes CSV and summary JSON. Every file is written under a temporary name and
 * renamed, so a crash never leaves a truncated file. Library code: errors are returned
 * (an rhod_status) with a one-line message in err, never printed or exited on. */
#ifndef RHOD_IO_H
#define RHOD_IO_H

#include "rhod/config.h"
#include "rhod/scene.h"
#include <stdint.h>
#include <stdio.h>

/* A dataset beyond the fixed ones (the scene's output.fields): /PartType0/<name> with a
 * Units attribute, and the XDMF node attribute of the same name. */
#define RHOD_MAX_EXTRA_FIELDS RHOD_MAX_OUTPUT_FIELDS
typedef struct {
  const char *name;  /* dataset name: letters, digits and '_', not one of the fixed ones */
  const char *units; /* its Units attribute ("1" for a number) */
  const void *data;  /* n * comps values of the particles, host copies: real, or uint8 */
  int u8;            /* 1: uint8 values (comps 1), written as such; 0: real, as double */
  int comps;         /* 1: N values; 2: a vector (x, y interleaved), written N x 3 with
                        z = 0 like Velocities */
} rhod_snapshot_extra;

/* Host copies of the fluid particle fields for one output time. */
typedef struct {
  double time;
  size_t n;
  const real *x, *y;    /* positions [m] */
  const real *ux, *uy;  /* velocities [m/s] */
  const real *rho;      /* density [kg/m^3] */
  const real *p;        /* pressure [Pa] */
  const real *m;        /* mass [kg/m] */
  const real *size;     /* particle size dx_i [m] */
  const uint64_t *id;   /* persistent particle id */
  const uint8_t *fs;    /* free-surface flag (1: in F), may be NULL */
  const uint8_t *phase; /* phase index (the scene's phases, in order), may be NULL */
  const real *vort;     /* vorticity [1/s] (vorticity.h), may be NULL */
  unsigned nextra;      /* the extra datasets, in this order */
  rhod_snapshot_extra extra[RHOD_MAX_EXTRA_FIELDS];
  /* the bodies (scene's bodies, in order) where they stand at this time, may be none:
   * body k's outline is the closed polygon of points [body_start[k], body_start[k + 1])
   * of body_xy (x, y interleaved); a circle's with segments of at most dx/4 */
  unsigned n_bodies;
  const unsigned *body_start; /* n_bodies + 1 */
  const double *body_xy;
} rhod_snapshot_view;

/* Checks every value of v before it is written: positions, velocities and pressures
 * finite, masses, densities and sizes finite and positive. Errors: RHOD_ERR_UNSTABLE
 * naming the particle, the field and the time. */
int rhod_snapshot_check(const rhod_snapshot_view *v, char *err, size_t errlen);

/* OUT/snapshot_NNNN.h5: /Header attrs Time, Dimension (2), NumPart; /PartType0 datasets
 * Coordinates, Velocities (N x 3, z = 0), Densities, Pressures, Masses, ParticleSizes,
 * ParticleIDs, FreeSurface (if fs), Phase (if phase); /Mesh/Vertices (N x 1, 0..N-1: the XDMF
 * vertex cells); /Parameters/Keys and /Parameters/Values (variable-length strings, the dotted keys
 * in scene order, any number) and, up to 65535 keys, one string attribute per key on /Parameters
 * (dense storage, creation order tracked). Plain contiguous datasets, no filters. Stored as double
 * whatever the build precision. Every dataset has a string attribute Units: Coordinates "m",
 * Velocities "m/s", Densities "kg/m^3", Pressures "Pa", Masses "kg/m" (2D: per unit depth),
 * ParticleSizes "m", ParticleIDs, FreeSurface and Vertices "1", Keys and Values "" (text). Then
 * the view's extra datasets (v->extra, in order) with their units: real ones as double, N or
 * N x 3 (z = 0), uint8 ones as uint8. /Header
 * also carries the strings Code ("rhod"), Precision (RHOD_REAL_NAME), CodeVersion (rhod_version())
 * and GitCommit (rhod_commit()). When the view has bodies (n_bodies > 0), a group /Bodies
 * with the attribute NumBodies (n_bodies) and the datasets Points (P x 3, z = 0, "m": the
 * outlines' points in order, body after body), Segments (S x 2 point indices, uint32, "1":
 * each body's closed polyline as line segments k -> k+1 and its last point -> its first;
 * S = P) and BodyIndex (S, uint32, "1": the body of each segment, its index in the scene's
 * bodies). The file is built in memory, then written through
 * rhod_write_bytes_atomic. Errors: RHOD_ERR_IO ("OUT/snapshot_NNNN.h5: cannot write: reason",
 * also for bodies' outlines that are incomplete: body_start or body_xy missing, body_start
 * not from 0 or decreasing), RHOD_ERR_MEMORY. */
int rhod_write_snapshot(const char *dir, int index, const rhod_snapshot_view *v,
                        const rhod_param_list *params, char *err, size_t errlen);

/* Reads a snapshot written by rhod_write_snapshot (arrays malloc'd, double), /Bodies when
 * the file has it (a segment's point or body index out of range is an error). Errors:
 * RHOD_ERR_READ (missing or unreadable file, missing dataset or attribute, wrong shape),
 * RHOD_ERR_MEMORY; out is then empty. rhod_snapshot_data_free accepts an emptied one. */
/* An extra dataset read back: every /PartType0 dataset rhod_write_snapshot does not write
 * itself, as rhod_snapshot_extra describes them (a real one with N x 3 values: comps 2,
 * z dropped). */
typedef struct {
  char *name, *units;
  int u8, comps;
  double *v;  /* n * comps values (x, y interleaved), when !u8 */
  uint8_t *b; /* n values, when u8 */
} rhod_snapshot_extra_data;

typedef struct {
  double time;
  size_t n;
  double *x, *y, *ux, *uy, *rho, *p, *m, *size;
  uint64_t *id;
  uint8_t *fs;     /* FreeSurface, NULL when the file has none */
  uint8_t *phase;  /* Phase, NULL when the file has none */
  unsigned nextra; /* the other datasets of /PartType0, in name order */
  rhod_snapshot_extra_data *extra;
  rhod_param_list params; /* /Parameters (Keys and Values; in older files the attributes)
                             in file order; owned here, freed by
                             rhod_snapshot_data_free (not rhod_param_list_free) */
  /* /Bodies as written (all 0 and NULL when the file has none): NumBodies, the Points
   * (x, y interleaved, z dropped), the Segments (2 point indices each) and BodyIndex */
  unsigned n_bodies;
  size_t n_body_points, n_body_segments;
  double *body_xy;
  uint32_t *body_segments, *body_index;
} rhod_snapshot_data;
int rhod_read_snapshot(const char *path, rhod_snapshot_data *out, char *err, size_t errlen);
void rhod_snapshot_data_free(rhod_snapshot_data *d);
/* Reads only /Header's Time and NumPart of a snapshot (a resume checks the snapshots it
 * continues). Errors: RHOD_ERR_READ ("path: reason"). */
int rhod_read_snapshot_header(const char *path, double *time, uint64_t *n, char *err,
                              size_t errlen);

/* Which optional datasets a snapshot of this view holds (bits below). */
#define RHOD_FIELDS_FREE_SURFACE 1u
#define RHOD_FIELDS_PHASE 2u
unsigned rhod_snapshot_fields(const rhod_snapshot_view *v);

/* OUT/snapshots.xdmf: a temporal collection of every snapshot written so far, as a
 * Polyvertex grid (XDMF 3) with explicit connectivity (/Mesh/Vertices), so that ParaView's
 * XDMF readers and meshio's XdmfTimeSeriesReader get one vertex cell per particle, and
 * every field of the snapshot as a node attribute: Velocity, Density, Pressure, Mass,
 * ParticleSize, ParticleID and, when `fields` has RHOD_FIELDS_FREE_SURFACE (every
 * snapshot of a run has the same datasets), FreeSurface, with RHOD_FIELDS_PHASE, Phase.
 * Rewritten (atomically) after each snapshot. */
int rhod_write_xdmf(const char *dir, int count, const double *times, const size_t *nparts,
                    unsigned fields, char *err, size_t errlen);
/* The same with the extra datasets of the snapshots (every snapshot of a run has the same):
 * after the fixed attributes, one node attribute each, named as the dataset (Scalar, or
 * Vector for comps 2; UChar for uint8). */
int rhod_write_xdmf_fields(const char *dir, int count, const double *times, const size_t *nparts,
                           unsigned fields, const rhod_snapshot_extra *extra, unsigned nextra,
                           char *err, size_t errlen);
/* The same with the bodies' outlines: body_points > 0 (the bodies' points, and segments,
 * of every snapshot: a run's bodies keep their outlines) puts before the particles'
 * collection a second temporal collection "bodies", for each snapshot a Uniform grid at
 * the same time with Topology Polyline (2 nodes per element, /Bodies/Segments), Geometry
 * XYZ (/Bodies/Points) and the cell attribute BodyIndex; the particles' collection stays
 * the last grid of the domain (meshio's time-series reader reads the last collection).
 * body_points 0: the file of rhod_write_xdmf_fields, byte for byte. */
int rhod_write_xdmf_bodies(const char *dir, int count, const double *times, const size_t *nparts,
                           unsigned fields, const rhod_snapshot_extra *extra, unsigned nextra,
                           size_t body_points, char *err, size_t errlen);

/* The closed outline of a shape as a polygon: a rect's 4 corners, a polygon's points,
 * a circle as `circle_segments` points (at least 8). out (may be NULL: count only) holds
 * at least the returned count of points. */
unsigned rhod_shape_outline(const rhod_shape *sh, unsigned circle_segments, double (*out)[2]);

/* OUT/walls.h5 and OUT/walls.xdmf: the walls of the scene (each wall's boundary as a
 * closed polyline; circles with segments no longer than dx/4) as line segments that
 * ParaView opens beside the particles, written once per run. walls.h5: /Header attrs
 * NumWalls, CodeVersion, GitCommit; /Walls/Points (P x 3, z = 0, "m"), /Walls/Segments
 * (S x 2 point indices), /Walls/WallIndex (S: the wall's index in the scene's `walls`),
 * /Walls/FluidInside (one per wall: 1 container, 0 obstacle). walls.xdmf: one Uniform
 * grid, Topology Polyline (2 nodes per element), cell attribute WallIndex. A scene
 * without walls writes neither (and removes old ones). Both written atomically.
 * Errors: RHOD_ERR_IO, RHOD_ERR_MEMORY. */
int rhod_write_walls(const char *dir, const rhod_scene *sc, char *err, size_t errlen);

/* A PNG picture of one field: each particle a disc of its own size, coloured by a
 * perceptual colour map (particle size: on a log scale); the frame is the box [lo, hi],
 * `width` pixels wide (its height keeps the aspect ratio); the walls (n_walls of them,
 * may be NULL when 0) drawn as dark 2-pixel lines inside the frame; the view's bodies
 * filled light grey (220, 220, 220) under the particles and their outlines drawn as
 * dark 2-pixel lines (as the walls) over them, in every panel; axes with tick labels
 * in metres along the frame's left and bottom edges ("x [m]", "y [m]"); below, a colour
 * bar with its range, the field's name and unit (e.g. "p [Pa]") and the time. range
 * NULL: automatic (rhod_picture_field_range). size_panel (ignored when the field is the
 * size): a second panel below, the same frame coloured by particle size.
 * rhod_picture_layout says where the frames are. Errors: RHOD_ERR_SCENE (empty frame,
 * picture side outside 1..16384), RHOD_ERR_IO (cannot write; incomplete bodies' outlines,
 * as rhod_write_snapshot). */
int rhod_write_picture(const char *path, const rhod_snapshot_view *v, rhod_field field,
                       int size_panel, unsigned width, const double lo[2], const double hi[2],
                       const double *range, const rhod_wall *walls, unsigned n_walls, char *err,
                       size_t errlen);

/* The colour range a picture of `field` uses when given none: the smallest and largest
 * finite value over the particles (the size field: of the sizes, drawn on a log scale).
 * Returns 0, or -1 when no particle has a finite value (range set to [0, 0]). */
int rhod_picture_field_range(const rhod_snapshot_view *v, rhod_field f, double range[2]);

/* Where rhod_write_picture puts things, in pixels from the top-left corner: the first
 * panel's frame at (frame_x, frame_y), frame_w x frame_h (frame_w = width); the next
 * panel's frame panel_h rows lower; the picture is pic_w x pic_h. Returns 0, or -1 for
 * an empty frame or a side outside 1..16384. */
typedef struct {
  unsigned frame_x, frame_y, frame_w, frame_h, panel_h, pic_w, pic_h, panels;
} rhod_picture_geometry;
int rhod_picture_layout(unsigned width, int panels, const double lo[2], const double hi[2],
                        rhod_picture_geometry *g);

/* probes.csv: a header row (first column t) then one row per sample. The file is kept
 * open and flushed after every row. */
typedef struct {
  FILE *f;
  char *path;
  unsigned ncols;
} rhod_csv;
int rhod_csv_open(rhod_csv *c, const char *path, unsigned ncols, const char *const *names,
                  char *err, size_t errlen);
/* Reopens an existing probes.csv for appending after cutting it to `bytes` (its length
 * at a checkpoint: rows written after it are dropped, the resumed run writes them again).
 * Never lengthens it: a file shorter than `bytes`, missing, not a regular file, whose
 * header does not hold t and ncols columns or whose byte `bytes` does not end a row is
 * refused with RHOD_ERR_CHECKPOINT ("path: reason"); failing writes give RHOD_ERR_IO. */
int rhod_csv_reopen(rhod_csv *c, const char *path, unsigned ncols, uint64_t bytes, char *err,
                    size_t errlen);
/* The same checks (but the header's column count) without changing anything: for a
 * resume to refuse a probes.csv before it writes anything. */
int rhod_csv_check(const char *path, uint64_t bytes, char *err, size_t errlen);
int rhod_csv_row(rhod_csv *c, double t, const double *values, char *err, size_t errlen);
int rhod_csv_close(rhod_csv *c, char *err, size_t errlen);

/* Reads a whole regular file of at most max bytes into a malloc'd buffer, NUL-terminated
 * (len excludes the NUL). The open never blocks (a FIFO), and a device, FIFO, socket or
 * directory is refused before anything is read. Returns 0, an errno value (ENOMEM and
 * EISDIR included), RHOD_READ_NOT_REGULAR or RHOD_READ_TOO_LARGE (more than max bytes,
 * also when the file grows while it is read); *text is untouched on failure. */
#define RHOD_READ_NOT_REGULAR (-1)
#define RHOD_READ_TOO_LARGE (-2)
int rhod_read_file(const char *path, size_t max, char **text, size_t *len);
/* The reason for rhod_read_file's return value e, for "path: cannot read: REASON". */
const char *rhod_read_strerror(int e);
/* The largest scene file (its text, before aliases are expanded) and checkpoint read. */
#define RHOD_SCENE_MAX_BYTES ((size_t)16 << 20)
#define RHOD_CHECKPOINT_MAX_BYTES ((uint64_t)64 << 30)
/* Writes `text` to path through path.tmp + rename. */
int rhod_write_file_atomic(const char *path, const char *text, char *err, size_t errlen);
/* The same for `len` bytes of any data: path.tmp in the same folder is written, fsync'd,
 * closed and renamed onto path; on failure it is removed and path is left untouched. */
int rhod_write_bytes_atomic(const char *path, const void *data, size_t len, char *err,
                            size_t errlen);

#endif
