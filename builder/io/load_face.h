// Mesh + FDP file -> a checked scene in the MPEG-4 frame, the one import
// pipeline every builder tool runs.
#pragma once

#include <string>
#include <vector>

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"
#include "io/fdp_io.h"

namespace afmb {

struct LoadOptions {
  std::string orient;  // --orient: "" (check only), "auto" or a spec ("x,z,-y")
  FdpFormat fdp_format = FdpFormat::Auto;
  bool flip_v = false;  // store 1 - v (textures whose v runs down)
};

struct LoadedFace {
  Scene scene;
  FdpSet fdps;  // bound to scene
  int skin = -1;
};

// Free FDPs (coordinates) within this share of the model's size (the
// diagonal of the box around every part) of a vertex are attached to it
// (attach_free_fdps): a file's printed coordinates of its own mesh's
// vertices lie far closer, and 7.1 (inside the neck) far farther.
constexpr double kFreeFdpShare = 0.005;

// Reads the mesh and the FDPs, binds them, applies or checks the
// orientation, attaches free FDPs that lie on the mesh, assigns part kinds,
// splits a skin made of several pieces into a part per piece, cuts fused
// lips apart, repairs coincident skin vertices and
// checks the skin. `log` gets one line per thing done on the user's behalf
// ("orientation: applied x,z,-y", "FDPs: 84 free points attached ...",
// "repaired: ...") and one per pair of FDPs out of MPEG-4's order
// ("note: song.fdp: FDP 2.10 (Chin boss) lies 2.37 below 2.1 ...":
// fdp_order_notes, orient.h). Errors name the file and
// line, part or FDP; an orientation error is wrapped with the mesh's path.
Expected<LoadedFace> load_face(const std::string &mesh_path, const std::string &fdp_path,
                               const LoadOptions &options, std::vector<std::string> *log);

}  // namespace afmb
