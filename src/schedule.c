/* Output schedules: include/rhod/schedule.h. */
#include "rhod/schedule.h"

#include <float.h>
#include <math.h>

double rhod_schedule_tol(double t, double interval) {
  return fmax(1e-9 * interval, 16 * DBL_EPSILON * fabs(t));
}

int rhod_schedule_reached(double t, double target, double interval) {
  return t >= target - rhod_schedule_tol(t, interval);
}

double rhod_schedule_advance(double next, double d, double t) {
  const double lim = t + rhod_schedule_tol(t, d);
  for (int i = 0; i < 64 && next <= lim; i++)
    next += d;
  if (next <= lim) {
    next += ceil((lim - next) / d) * d;
    if (!(next > lim) || !isfinite(next))
      next = nextafter(lim, INFINITY);
  }
  return next;
}
