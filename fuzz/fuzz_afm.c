/* libFuzzer target: the AFM reader (formats/src) on raw-profile files, with
 * no Draco codec. What it checks: fuzz/afm_fuzz.h. Seeds: fuzz/run.sh. */
#include "afm_fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_afm_input(data, size, NULL);
  return 0;
}
