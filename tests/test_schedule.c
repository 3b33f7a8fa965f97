/* Output schedules (include/rhod/schedule.h): every advance ends and passes t, whatever
 * the interval against t; tolerances do not grow with the end time or exceed the
 * interval; the arithmetic of ordinary runs (repeated addition) is kept. */
#include "cunit_main.h"
#include "rhod/schedule.h"
#include <float.h>
#include <math.h>

/* Intervals tiny against t, or t near 1e25: one call, a result beyond t. (The run loop
 * of earlier versions added the interval until it passed t: 1e300 iterations here.) */
static void test_advance_ends(void) {
  const double cases[][3] = {{0, 1e-300, 1e25},  {0, 1e-300, 1.0},  {1e25, 1e-3, 1e25},
                             {0, 1e-12, 1e6},    {0.5, 0.1, 1e300}, {0, 5e-324, 1e-300},
                             {0, 1e-9, 123.456}, {1e25, 1e9, 1e25}, {0, 1.0, 1e15}};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    const double next = cases[k][0], d = cases[k][1], t = cases[k][2];
    const double r = rhod_schedule_advance(next, d, t);
    CU_ASSERT(isfinite(r));
    CU_ASSERT(r > t);
    CU_ASSERT(!rhod_schedule_reached(t, r, d));
  }
}

/* Ordinary runs: sampling every interval by repeated addition, as before. */
static void test_advance_adds(void) {
  double next = 0, sum = 0;
  for (int i = 0; i < 100; i++) {
    const double t = next; /* the run landed on the time */
    CU_ASSERT(rhod_schedule_reached(t, next, 0.003));
    next = rhod_schedule_advance(next, 0.003, t);
    sum += 0.003;
    CU_ASSERT_EQUAL(next, sum);
  }
  /* a resume or an interval below the step: several intervals passed at once, landing
   * on the first one after t */
  const double r = rhod_schedule_advance(0, 0.25, 1000.1);
  CU_ASSERT_DOUBLE_EQUAL(r, 1000.25, 1e-9);
}

/* The tolerance belongs to the interval and to t's resolution, not to the end time: a
 * time 1e-6 of an interval short of the target has not reached it, at any t. */
static void test_tolerance(void) {
  const double d = 0.01;
  for (double t0 = 1; t0 < 1e7; t0 *= 10) {
    const double target = t0 + d;
    CU_ASSERT(rhod_schedule_tol(t0, d) < 1e-3 * d);
    CU_ASSERT(!rhod_schedule_reached(target - 1e-4 * d, target, d));
    CU_ASSERT(rhod_schedule_reached(target, target, d));
    CU_ASSERT(rhod_schedule_reached(nextafter(target, 0), target, d));
  }
  CU_ASSERT(rhod_schedule_tol(0, 1e-3) < 2e-12);
}

int main(void) {
  const rhod_test_case cases[] = {{"advance ends and passes t", test_advance_ends},
                                  {"advance by repeated addition", test_advance_adds},
                                  {"tolerance relative to the interval", test_tolerance}};
  return RHOD_RUN_TESTS("schedule", cases);
}
