// A synthetic AFM document for format tests: a grid "skin" wrapped on an
// ellipsoid (an open patch, so it has boundaries), a small closed "eye"
// sphere, morph targets from analytic displacement fields, and rigids.
#pragma once

#include <afm/format.h>

#include <cstdint>
#include <string>
#include <vector>

namespace afmtest {

struct SyntheticDoc {
  // Storage the afm_doc points into.
  std::vector<afm_part> parts;
  std::vector<int16_t> px, py, pz, nx, ny, nz;
  std::vector<uint16_t> u, v;
  std::vector<uint8_t> rgba;
  std::vector<uint32_t> tris;
  std::vector<afm_fdp_point> fdps;
  struct Target {
    std::vector<afm_run> runs;
    std::vector<int16_t> dx, dy, dz, nx, ny, nz;
  };
  std::vector<Target> target_data;
  std::vector<afm_target> targets;
  std::vector<uint16_t> rigid_parts;
  std::vector<afm_control> controls;
  std::vector<afm_rigid> rigids;
  // With SyntheticOptions::lift.
  std::vector<afm_run> lift_runs;
  std::vector<uint32_t> lift_c[3];
  std::vector<uint16_t> lift_w[2];
  afm_lift lift{};
  afm_doc doc{};
};

struct SyntheticOptions {
  int rows = 24, cols = 32;   // skin grid
  bool normals = true;
  bool texcoords = true;
  bool colors = true;
  bool normal_deltas = true;
  bool shuffle_triangles = false;  // write triangles in a non-canonical order
  bool loose_vertex = false;       // drop the skin's triangles using vertex 7 (unreferenced)
  // Control points (LIFT): the skin's every other row and column are the
  // controls, every skin vertex is bound to a coarse triangle of them, and
  // the targets move the controls (the eye keeps vertex deltas). No normal
  // deltas then.
  bool lift = false;
  // In-between targets (formats/afm.md, version 1.2): FAP 12 also at 1024
  // and 1800, FAP 31 also at -700, each with a field of its own; and the
  // eye's yaw (23) and pitch (25) bent at knots (version 1.3): half as
  // steep past 20000, twice as steep below -15000.
  bool in_betweens = false;
  // With in_betweens, a combination (version 1.4) on FAP 31's target at
  // -700, gated by FAP 3 at 1024, with a field of its own.
  bool combination = false;
};

// Fills `s` and returns &s.doc (valid while `s` lives and is not moved).
const afm_doc *make_synthetic_doc(SyntheticDoc &s, const SyntheticOptions &o = {});

// Writes with the raw or draco profile; fails the current test on error.
std::vector<uint8_t> write_doc(const afm_doc &doc, afm_profile profile);

// Deep comparison of two documents (every field and array); "" when equal,
// else a description of the first difference.
std::string compare_docs(const afm_doc &a, const afm_doc &b);

}  // namespace afmtest
