// The "Song" head of ../shared/data as afm-build models it, for the tests
// that need a real face model (tests/fap). Callers check for the shared data
// first (AFM_REQUIRE_SHARED_DATA, test_paths.h).
#pragma once

#include <string>
#include <vector>

#include "anatomy/sim_mesh.h"
#include "io/load_face.h"

namespace afmtest {

// Song on a simulation mesh of `vertices` (afm-build's default) whose first
// pass collapses edges under `short_edge` of the skin's mean
// (SimMeshOptions), of `tissue`, with only `muscles` calibrated (none when
// empty) and the jaw when `jaw`; the loaded face (its whole skin) beside it.
struct SongOnSimMesh {
  afmb::LoadedFace face;
  afmb::SimFaceModel built;
};

// Records a test failure (and leaves `built` empty) when Song does not load
// or build.
SongOnSimMesh song_on_sim_mesh(const std::vector<std::string> &muscles, bool jaw = false,
                               int vertices = afmb::kDefaultSimVertices, const afmb::TissueParams &tissue = {},
                               double short_edge = afmb::kShortEdgeShare);

}  // namespace afmtest
