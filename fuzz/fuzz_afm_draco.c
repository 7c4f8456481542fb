/* libFuzzer target: the AFM reader with the Draco codec (formats/draco,
 * libdraco), on raw- and draco-profile files. What it checks:
 * fuzz/afm_fuzz.h. libdraco itself is not instrumented: ASan sees its heap
 * through the allocator only. Seeds: fuzz/run.sh. */
#include "afm/draco.h"
#include "afm_fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_afm_input(data, size, afm_draco_codec());
  return 0;
}
