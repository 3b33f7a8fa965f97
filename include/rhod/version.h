/* Version and provenance of the code that wrote an output: the release number (CMake's
 * project VERSION) and the git commit it was built from (short hash, "-dirty" when the
 * checkout had uncommitted changes to tracked files, "unknown" outside a git checkout).
 * Written into every snapshot's /Header (CodeVersion, GitCommit) and by `rhod --version`. */
#ifndef RHOD_VERSION_H
#define RHOD_VERSION_H

const char *rhod_version(void);
const char *rhod_commit(void);

#endif
