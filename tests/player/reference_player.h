// A double-precision model of the player's semantics (afm/player.h), for
// tests: exact weights (value / reference), exact sines, no rounding. It
// shares no arithmetic with the fixed-point core; it reads the same afm_doc.
#pragma once

#include <afm/format.h>
#include <afm/player.h>

#include <array>
#include <vector>

namespace afmtest {

struct ReferencePose {
  std::vector<std::array<double, 3>> positions;  // #V, quanta
  std::vector<std::array<double, 3>> normals;    // #V, unit
  std::vector<double> weights;                   // per target
  std::vector<char> recomputed;                  // #V: 1 where the normal was recomputed
};

// Poses the face as afm_player_pose(a, b, t) does (t in [0, 1]); normals
// recomputed like the default player (area-weighted over seam groups) on the
// same set of vertices.
ReferencePose reference_pose(const afm_doc &doc, const afm_fap_state &a, const afm_fap_state &b,
                             double t);

}  // namespace afmtest
