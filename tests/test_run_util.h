/* Shared by the unit tests that set up whole runs from scene text (test_apr.c,
 * test_initial_flows.c): the scene written to a file named after the test and the tag,
 * loaded, and the run set up (rhod_sim_init). */
#ifndef RHOD_TEST_RUN_UTIL_H
#define RHOD_TEST_RUN_UTIL_H

#include "rhod/scene.h"
#include "rhod/sim.h"
#include <stdio.h>
#include <stdlib.h>

typedef struct {
  rhod_scene *sc;
  rhod_sim *sim; /* on the heap: the store keeps pointers into it */
} run;

/* Loads the scene text (written to PREFIX_TAG.yaml in the working folder) and sets up the
 * run; 0 (with the message on stderr) when either fails. */
static inline int run_open_in(run *r, const char *prefix, const char *tag, const char *yaml) {
  char path[256], err[1024] = "";
  snprintf(path, sizeof path, "%s_%s.yaml", prefix, tag);
  FILE *f = fopen(path, "w");
  if (!f)
    return 0;
  fputs(yaml, f);
  fclose(f);
  r->sc = NULL;
  r->sim = NULL;
  int st = rhod_scene_load(path, NULL, 0, &r->sc, err, sizeof err);
  remove(path);
  if (st != RHOD_OK) {
    fprintf(stderr, "\n%s: %s\n", tag, err);
    return 0;
  }
  r->sim = calloc(1, sizeof *r->sim);
  st = rhod_sim_init(r->sim, r->sc, err, sizeof err);
  if (st != RHOD_OK) {
    fprintf(stderr, "\n%s: %s\n", tag, err);
    return 0;
  }
  return 1;
}

static inline void run_close(run *r) {
  if (r->sim) {
    rhod_sim_free(r->sim);
    free(r->sim);
  }
  if (r->sc)
    rhod_scene_free(r->sc);
}

#endif
