/* Shared by the scene loader's tests (test_scene.c, test_scene_mp.c): the test scenes'
 * paths, a load that must succeed, and a key's value in the flattened parameters. */
#ifndef RHOD_TEST_SCENE_LOAD_H
#define RHOD_TEST_SCENE_LOAD_H

#include "cunit_main.h"
#include "rhod/scene.h"
#include <stdio.h>
#include <string.h>

#define GOOD(name) RHOD_SOURCE_DIR "/tests/scenes/good/" name
#define BAD(name) RHOD_SOURCE_DIR "/tests/scenes/bad/" name
#define CLOSE(a, b) CU_ASSERT_DOUBLE_EQUAL((a), (b), 1e-12)

static inline rhod_scene *load_ok(const char *path, const char *const *ov, int n) {
  char err[1024] = "";
  rhod_scene *s = NULL;
  int rc = rhod_scene_load(path, ov, n, &s, err, sizeof err);
  if (rc != RHOD_OK)
    fprintf(stderr, "\nunexpected failure: %s\n", err);
  CU_ASSERT_EQUAL(rc, RHOD_OK);
  CU_ASSERT_PTR_NOT_NULL(s);
  return s;
}

/* The value of `key` in p, NULL when absent. */
static inline const char *param(const rhod_param_list *p, const char *key) {
  for (unsigned i = 0; i < p->n; i++)
    if (strcmp(p->keys[i], key) == 0)
      return p->values[i];
  return NULL;
}

#endif
