/* The application's registry of schemes: the one file that names every scheme the build
 * has (the engine knows them only through include/rhod/scheme.h). */
#include "rhod/multiphase/scheme.h"
#include "rhod/rhodsph/scheme.h"
#include "rhod/scheme.h"

const rhod_scheme_ops *rhod_scheme_for(const rhod_scene *sc) {
  switch (sc->scheme) {
  case RHOD_SCHEME_RHODSPH:
    return &rhod_rhodsph_ops;
  case RHOD_SCHEME_MULTIPHASE:
    return &rhod_multiphase_ops;
  }
  return NULL;
}
