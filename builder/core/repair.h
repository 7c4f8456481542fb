// Unambiguous repairs of real-world skins, reported, never silent.
#pragma once

#include <string>
#include <vector>

#include "core/scene.h"

namespace afmb {

// Welds vertices with bit-identical positions that share a zero-area triangle
// (an exporter's duplicate), rewriting the part's triangles to use the lower
// index, then drops the triangles left with a repeated index. Vertex indices
// do not change: a welded-away vertex stays in V, unreferenced, so FDP
// indices into the part stay valid. Everything else (slivers with distinct
// corners, non-manifold edges) is left for check_skin() to refuse. Appends one
// line per repair to `log`; returns the number of triangles dropped.
int repair_coincident_vertices(Scene &scene, int part, std::vector<std::string> *log);

}  // namespace afmb
