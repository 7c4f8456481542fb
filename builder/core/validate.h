// Checks that a part is a usable skin surface.
#pragma once

#include "core/scene.h"
#include "core/status.h"

namespace afmb {

// The skin must be an edge-manifold, consistently oriented triangle mesh
// (boundaries allowed: neck, eye openings, mouth slit) with no degenerate
// (zero-area or repeated-index) triangles. Checked in this order, each
// reporting the first offender in triangle order:
//   - finite vertex coordinates, indices in range;
//   - no triangle repeating a vertex;
//   - no zero-area triangle: area <= 1e-10 * d^2, d the diagonal of the part's
//     bounding box (a 20 cm head: triangles under about 3 um across);
//   - every edge in at most two triangles;
//   - every directed edge in at most one triangle (neighbours wind the same
//     way; also catches duplicated triangles).
// Distinct vertices at the same position (lips in contact along a closed
// mouth slit) are fine, as are unreferenced vertices. Vertex manifoldness
// (two fans meeting at one vertex) is not checked. Errors name the part and
// the offending edge, vertex or triangle (0-based).
Status check_skin(const Scene &scene, int part);

}  // namespace afmb
