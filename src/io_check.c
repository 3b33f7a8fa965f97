/* The last check before anything is written: every value of a snapshot view finite (and
 * masses, densities and sizes positive), so that no output ever holds inf or NaN. */
#include "rhod/io.h"

#include <math.h>
#include <stdio.h>

int rhod_snapshot_check(const rhod_snapshot_view *v, char *err, size_t errlen) {
  static const char *const names[] = {"x", "y", "u", "v", "pressure", "mass", "density", "size"};
  for (size_t i = 0; i < v->n; i++) {
    const double f[8] = {v->x[i], v->y[i], v->ux[i],  v->uy[i],
                         v->p[i], v->m[i], v->rho[i], v->size[i]};
    int bad = -1;
    for (int k = 0; k < 8 && bad < 0; k++)
      if (!isfinite(f[k]) || (k >= 5 && !(f[k] > 0)))
        bad = k;
    if (bad >= 0) {
      snprintf(err, errlen,
               "unstable at t = %.6g s: particle id %llu has a %s that is not finite%s (%g); "
               "nothing was written for this time",
               v->time, v->id ? (unsigned long long)v->id[i] : (unsigned long long)i, names[bad],
               bad >= 5 ? " and positive" : "", f[bad]);
      return RHOD_ERR_UNSTABLE;
    }
  }
  return RHOD_OK;
}
