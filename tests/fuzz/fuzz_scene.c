/* Fuzz target: the scene loader (YAML through libyaml/libcyaml, then every check). The
 * loader reads a path, so each input goes through one temporary file. */
#include "rhod/scene.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static char path[64] = "";
  if (!path[0]) {
    snprintf(path, sizeof path, "/tmp/rhod_fuzz_scene_%ld.yaml", (long)getpid());
  }
  FILE *f = fopen(path, "wb");
  if (!f)
    return 0;
  const size_t w = fwrite(data, 1, size, f);
  fclose(f);
  if (w != size)
    return 0;
  rhod_scene *s = NULL;
  char err[1024];
  const int rc = rhod_scene_load(path, NULL, 0, &s, err, sizeof err);
  unlink(path);
  if (rc == RHOD_OK) {
    char warn[1024];
    rhod_param_list params;
    (void)rhod_scene_warnings(s, warn, sizeof warn);
    if (rhod_scene_params(s, &params) == RHOD_OK)
      rhod_param_list_free(&params);
    rhod_scene_free(s);
  }
  return 0;
}
