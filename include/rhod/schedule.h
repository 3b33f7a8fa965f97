/* Output schedules (snapshots, probes, checkpoints): times next, next + d, ... that the
 * run loop reaches and passes. Tolerances are relative to the interval and to the
 * floating-point resolution of t, never to the end time, and every advance ends. */
#ifndef RHOD_SCHEDULE_H
#define RHOD_SCHEDULE_H

/* The tolerance within which t has reached a time of a schedule of this interval:
 * max(1e-9 interval, 16 units in the last place of t). It never exceeds the interval
 * (for t below 1e15 intervals) and does not depend on the end time. */
double rhod_schedule_tol(double t, double interval);

/* Whether t has reached target (within rhod_schedule_tol). */
int rhod_schedule_reached(double t, double target, double interval);

/* The first time of next, next + d, next + 2d, ... beyond t + rhod_schedule_tol(t, d):
 * up to 64 intervals by repeated addition (the arithmetic of a run that samples every
 * interval), beyond that in one jump; if d is below the resolution of t, the next
 * representable time after t + tol. Always returns, in a bounded number of operations.
 * d must be finite and > 0. */
double rhod_schedule_advance(double next, double d, double t);

#endif
