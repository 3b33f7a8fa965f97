/* Status codes of the library and exit codes of `rhod`, one per class of failure
 * (documented in docs/scene.md and the README). Engine level: every module returns these. */
#ifndef RHOD_STATUS_H
#define RHOD_STATUS_H

enum rhod_status {
  RHOD_OK = 0,
  RHOD_ERR_USAGE = 2,       /* bad command line */
  RHOD_ERR_READ = 3,        /* scene file missing or unreadable */
  RHOD_ERR_SCENE = 4,       /* scene malformed: syntax, unknown key, wrong type, bad value */
  RHOD_ERR_OUTPUT = 5,      /* output folder cannot be created or written */
  RHOD_ERR_UNSTABLE = 6,    /* the run went unstable: NaN/inf or a particle left the domain */
  RHOD_ERR_IO = 7,          /* an output file could not be written during the run */
  RHOD_ERR_MEMORY = 8,      /* allocation failed */
  RHOD_ERR_INTERRUPTED = 9, /* stopped by SIGINT/SIGTERM after writing a checkpoint */
  RHOD_ERR_CHECKPOINT = 10, /* a checkpoint is missing, corrupt or does not fit the scene */
};

#endif
