/* The Draco codec for AFM chunks, behind a C ABI.
 *
 * Link libafm_draco.a with libdraco and libstdc++ (a C program does this with
 * `-lafm_draco -lafm_format -ldraco -lstdc++`). Pass afm_draco_codec() as
 * the `draco` member of afm_read_options / afm_write_options or to
 * afm_transcode. formats/afm.md ("draco encoding") gives the bitstream
 * layout: GEOM parts become Draco meshes with integer attributes, MTGT deltas
 * and LIFT bindings Draco point clouds; every quantised value survives exactly.
 *
 * The encoder keeps the raw encoding for a chunk unless Draco makes it at
 * least AFM_DRACO_MIN_SAVING_PERCENT smaller: below that, decoding time is
 * not worth the bytes. Thread-safe: the codec holds no state.
 */
#ifndef AFM_DRACO_H
#define AFM_DRACO_H

#include "afm/format.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AFM_DRACO_MIN_SAVING_PERCENT 10

/* A static codec instance; never NULL. */
const afm_chunk_codec *afm_draco_codec(void);

#ifdef __cplusplus
}
#endif

#endif /* AFM_DRACO_H */
