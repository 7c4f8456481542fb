// What every exporter reads: an AFM and a FAP stream from files, and the
// views of the AFM they share (target names, model-unit positions, the
// vertices a target moves, the neutral face as a Scene).
//
// Units: positions in the AFM's model units (origin + quanta * step,
// formats/afm.md); deltas of a target are the face at the target's reference
// value minus the neutral face.
#pragma once

#include <afm/fap_stream.h>
#include <afm/format.h>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct AfmDocFree {
  void operator()(afm_doc *doc) const;
};
// A decoded AFM: one allocation (afm_doc_read_alloc), freed by the deleter.
using AfmDocPtr = std::unique_ptr<afm_doc, AfmDocFree>;

// Reads and decodes an AFM of either profile (raw or draco). Errors name the
// file and, from the reader, the chunk and field.
Expected<AfmDocPtr> read_afm_file(const std::string &path);

// A FAP stream as parsed by the player's reader (formats/fap.md).
struct FapStream {
  afm_fap_header header{};
  std::vector<afm_fap_frame> frames;  // at least one
};
// Errors name the file and line.
Expected<FapStream> read_fap_file(const std::string &path);

// Seconds from the stream's first frame to frame i: (number_i - number_0) / fps.
double fap_frame_seconds(const FapStream &stream, size_t i);

// The name exporters give a morph target: the MPEG-4 FAP name ("open_jaw"),
// with "_neg" for a FAP's negative-side target (reference < 0);
// "viseme_<name>" ("viseme_p_b_m") and "expression_<name>"
// ("expression_joy"). Names are letters, digits and '_', starting with a
// letter: legal in VRML, OBJ and file names.
std::string target_name(const afm_target &target);

// Every target's name, in doc.targets order: target_name(), and for an
// in-between (a FAP side's target past the one nearest zero) its |reference|
// appended ("close_t_l_eyelid_1024"). Unique within a valid AFM.
std::vector<std::string> target_names(const afm_doc &doc);

// The target's position deltas on one part of doc: #part.vertex_count x 3,
// in quanta, zero where it does not reach. Vertices bound to control points
// (LIFT) get their lifted deltas, which may be fractions of a quantum.
Eigen::MatrixXd target_part_deltas(const afm_doc &doc, const afm_target &target, const afm_part &part);

// Whether the target moves any vertex of the part (a nonzero delta).
bool target_moves_part(const afm_doc &doc, const afm_target &target, const afm_part &part);

// Decimal places that write positions of grid step `step` to within a tenth
// of a step: a file with them reads back to the same quanta, and target
// deltas come back exactly. At most 12.
int position_decimals(float step);

// The neutral face as a Scene: one part per AFM part, named as in the AFM,
// with the part's vertices in AFM order (so indices and FDP vertices carry
// over), positions in model units rounded to `decimals` places, per-vertex
// texture coordinates (TC = #V x 2, FTC = F) and colours (C = #V x 3, alpha
// dropped) when the AFM has them, the part's diffuse colour and texture.
// Kinds are copied.
Scene afm_scene(const afm_doc &doc, int decimals);

// Positions of one part with `target` fully applied (the face at the
// target's reference value), or neutral when `target` is null:
// #part.vertex_count x 3, model units, rounded to `decimals` places.
Eigen::MatrixXd part_positions(const afm_doc &doc, const afm_part &part, const afm_target *target,
                               int decimals);

}  // namespace afmb
