/* Shared CUnit runner: a test file defines its suites with RHOD_SUITE entries and
 * calls rhod_test_main. Exits non-zero when any assertion fails. */
#ifndef RHOD_CUNIT_MAIN_H
#define RHOD_CUNIT_MAIN_H
#include <CUnit/Basic.h>
#include <stdio.h>

typedef struct {
  const char *name;
  void (*fn)(void);
} rhod_test_case;

static inline int rhod_test_main(const char *suite, const rhod_test_case *cases, int n) {
  if (CU_initialize_registry() != CUE_SUCCESS)
    return 2;
  CU_pSuite s = CU_add_suite(suite, NULL, NULL);
  if (!s)
    return 2;
  for (int i = 0; i < n; i++)
    if (!CU_add_test(s, cases[i].name, cases[i].fn))
      return 2;
  CU_basic_set_mode(CU_BRM_VERBOSE);
  CU_basic_run_tests();
  unsigned failed = CU_get_number_of_failures() + CU_get_number_of_tests_failed();
  CU_cleanup_registry();
  return failed ? 1 : 0;
}
#define RHOD_RUN_TESTS(suite, arr) rhod_test_main(suite, arr, (int)(sizeof(arr) / sizeof(arr[0])))
#endif
