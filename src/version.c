/* rhod_version and rhod_commit (version.h). RHOD_VERSION_STRING comes from CMake's
 * project VERSION; RHOD_GIT_COMMIT from the header cmake/git_commit.cmake regenerates at
 * every build (only when the commit changes, so that only this file recompiles). */
#include "rhod/version.h"

#include "rhod_commit.h"

#ifndef RHOD_VERSION_STRING
#error "RHOD_VERSION_STRING is set by CMakeLists.txt"
#endif

const char *rhod_version(void) { return RHOD_VERSION_STRING; }
const char *rhod_commit(void) { return RHOD_GIT_COMMIT; }
