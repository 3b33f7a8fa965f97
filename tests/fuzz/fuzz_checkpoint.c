/* Fuzz target: checkpoint reading (restart input). Parses the bytes; a checkpoint that
 * parses is also applied to a particle store with the engine's standard fields. */
#include "rhod/checkpoint.h"
#include <stdint.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  rhod_checkpoint ck;
  char err[512];
  if (rhod_checkpoint_parse(data, size, "fuzz", &ck, err, sizeof err) != RHOD_OK)
    return 0;
  rhod_particles p;
  if (ck.n < 100000 && rhod_particles_init(&p, 16) == RHOD_OK) {
    (void)rhod_checkpoint_apply(&ck, &p, err, sizeof err);
    rhod_particles_free(&p);
  }
  rhod_checkpoint_free(&ck);
  return 0;
}
