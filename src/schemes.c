/* The application's registry of schemes: the one file that names every scheme the build
 * has (the engine knows them only through include/rhod/scheme.h). */
#include "rhod/rhodsph/scheme.h"
#include "rhod/scheme.h"

const rhod_scheme_ops *rhod_scheme_for(const rhod_scene *sc) {
  (void)sc;
  return &rhod_rhodsph_ops;
}
