/* Checkpoints: everything a run needs to continue bit for bit (issue 5): the
 * persistent particle arrays as stored (full precision, in their current order), the
 * particle store's id counter, the run's clock and output bookkeeping, and the scene as
 * run (path, --set overrides and the flattened parameters, so that a resume can refuse a
 * scene that changed). Engine level: it knows registered fields, not physics.
 *
 * File layout (native byte order, this build's `real`): "RHODCKP1", u32 version,
 * u32 sizeof(real), then length-prefixed records (see checkpoint.c), then a 64-bit
 * FNV-1a hash of everything before it. Written in memory and through
 * rhod_write_bytes_atomic, so a crash or a full disk never leaves a torn file. */
#ifndef RHOD_CHECKPOINT_H
#define RHOD_CHECKPOINT_H

#include "rhod/particles.h"
#include "rhod/scene.h"
#include <stdint.h>

/* the scheme's, 9 a body (body.h), and the open boundaries' (open.h: a carried imbalance per
 * marker, at most 4096, and 7 totals) */
#define RHOD_CK_MAX_EXTRAS (16 + 9 * RHOD_MAX_BODIES + 4096 + 7)
/* The fixed fields of versions 2 to 6, in their file order, as the reader names them among
 * the extras: the APR totals (splits, merges: version 2; absorbed and the kinetic energy
 * merges and absorptions took out: version 4) and the stiffness limit's measure (1/s,
 * version 3). */
#define RHOD_CK_LEGACY_EXTRAS 6
extern const char *const rhod_ck_legacy_extra[RHOD_CK_LEGACY_EXTRAS];

typedef struct {
  /* run state */
  double t, next_out, next_probe, next_checkpoint, checkpoint_every;
  int64_t step, reflected;
  double picture_range[2]; /* the pictures' colour range, fixed at the first picture that
                              had one (version 5); NaN, NaN: none fixed yet */
  /* The scheme's scalars (its ops->save and ops->load), by name (version 6). Versions 2 to 6
   * held RHOD-SPH's counters in fixed fields; the reader gives them as the extras RHOD-SPH
   * saves since version 7 (RHOD_CK_LEGACY_EXTRAS, 0 where the version had none), after the
   * file's own. */
  int32_t nextra;
  char extra_name[RHOD_CK_MAX_EXTRAS][32];
  double extra[RHOD_CK_MAX_EXTRAS];
  uint64_t probes_bytes; /* length of probes.csv when the checkpoint was taken */
  int32_t nsnap;
  double *snap_t;
  uint64_t *snap_n;
  /* scene as run */
  char *scene_path;
  int32_t nsets;
  char **sets;
  rhod_param_list params;
  /* particles (filled by rhod_checkpoint_read; the writer takes them from the store) */
  uint64_t n, next_id;
  int32_t nfields;
  char **fname;
  uint64_t *felem;
  void **fdata;
} rhod_checkpoint;

/* Writes ck's run state and scene plus every persistent field of p ([0, n), copied
 * from the device first) to path. Errors: RHOD_ERR_IO ("path: cannot write: reason"),
 * RHOD_ERR_MEMORY. */
int rhod_checkpoint_write(const char *path, const rhod_checkpoint *ck, rhod_particles *p, char *err,
                          size_t errlen);
/* Reads and validates a checkpoint (every length against the file, the hash, the
 * precision). Errors: RHOD_ERR_CHECKPOINT ("path: reason"), RHOD_ERR_MEMORY; ck is
 * then empty. */
int rhod_checkpoint_read(const char *path, rhod_checkpoint *ck, char *err, size_t errlen);
/* The same from bytes in memory (`name` is used in messages); the fuzz target. */
int rhod_checkpoint_parse(const void *bytes, size_t len, const char *name, rhod_checkpoint *ck,
                          char *err, size_t errlen);
/* Puts the checkpoint's particles into p (same persistent fields, in the same order,
 * with the same sizes) and onto the device. Errors: RHOD_ERR_CHECKPOINT, RHOD_ERR_MEMORY. */
int rhod_checkpoint_apply(const rhod_checkpoint *ck, rhod_particles *p, char *err, size_t errlen);
/* Frees what rhod_checkpoint_read allocated (an emptied or zeroed one is fine). */
void rhod_checkpoint_free(rhod_checkpoint *ck);

#endif
