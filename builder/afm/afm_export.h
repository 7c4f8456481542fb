// Scene + FDPs (+ morph targets and rigids) -> AFM file (formats/afm.md).
//
// The scene's welded vertices become AFM render vertices: a vertex is split
// once per distinct texture coordinate it carries (a UV seam), so a render
// vertex has one position, normal, uv and colour. With morph targets, the
// vertices are reordered so each target covers few, long runs
// (run_friendly_order): the player's blend loops then stream. Positions are quantised to
// int16 on one grid centred on the scene's bounding box; normals are computed
// on the welded mesh (area-weighted, so seams do not show) and stored Q14.
#pragma once

#include <afm/format.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "anatomy/skin_binding.h"
#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

// A morph target as the builder computes it: displacements of welded vertices.
struct MorphTarget {
  afm_target_kind kind = AFM_TARGET_FAP;
  int number = 0;          // FAP 3..68, viseme 1..14, expression 1..6
  int32_t reference = 0;   // FAP units (63 for visemes and expressions); < 0: negative side
  // AFM_TARGET_COMBINATION: a correction on top of the FAP target at
  // (number, reference), gated by FAP `gate` at `gate_reference` (formats/afm.md,
  // MTGT "Combinations"); 0 for other kinds.
  int gate = 0;
  int32_t gate_reference = 0;
  // Per part: #V x 3 displacement in model units, or an empty matrix when the
  // part does not move.
  std::vector<Eigen::MatrixXd> displacement;
  bool normals = false;    // also store normal deltas
  // With AfmContent::lift: #C x 3 displacement of the control points, model
  // units (empty: they do not move). The bound parts' displacement must be
  // its lift; the AFM stores the controls instead.
  Eigen::MatrixXd controls;
};

// Control points (formats/afm.md, LIFT): whole parts whose every vertex
// moves as a blend of three controls (the simulation mesh's vertices).
struct ControlLift {
  int control_count = 0;            // #C
  std::vector<SkinBinding> parts;   // per bound part: corners index the controls
};

// A rigid transform (eyeball, jaw, head) in model units.
struct RigidPart {
  afm_rigid_kind kind = AFM_RIGID_HEAD;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();     // model units
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // rows: local x, y, z
  std::vector<int> parts;                              // scene part indices
  struct Control {
    int fap = 0;
    afm_dof dof = AFM_DOF_ROTATE_X;
    double gain = 0;  // AU per FAP unit (rotations), model units per FAP unit (translations)
    int knot = 0;     // FAP units, |knot| < 2^15: the control acts on the value's part beyond it
                      // (afm_control; 0: on the whole value)
  };
  std::vector<Control> controls;
};

struct AfmContent {
  const Scene *scene = nullptr;
  const FdpSet *fdps = nullptr;  // bound to scene
  Fapu fapu;
  std::vector<MorphTarget> targets;
  std::vector<RigidPart> rigids;
  ControlLift lift;  // control_count 0: none; then no target may have normals
  std::string generator = "afm toolkit";
};

// Where each welded scene vertex went in the AFM.
struct RenderVertices {
  std::vector<int> first;   // per part: its first render vertex
  // Per part, per welded vertex: the render vertices carrying it (>= 1 unless
  // the vertex is in no triangle and has no texcoord, then exactly 1).
  std::vector<std::vector<std::vector<uint32_t>>> copies;
  size_t count = 0;         // total render vertices
};

// `order`, when given, lists each part's welded vertices in the order their
// render vertices should take (a permutation per part); else file order.
RenderVertices split_render_vertices(const Scene &scene,
                                     const std::vector<std::vector<int>> *order = nullptr);

// The vertex order that keeps each target's vertices in few runs: within
// each part, welded vertices sorted by which targets move them (targets
// taken largest first), ties in file order so that still regions keep their
// spatial order. On the reference head this makes runs about 5 times longer
// (tests/builder and bench/ measure it).
std::vector<std::vector<int>> run_friendly_order(const Scene &scene,
                                                 const std::vector<MorphTarget> &targets,
                                                 double quantum);

// Where encode_afm puts each welded vertex of `content`'s scene: its vertex
// order (run_friendly_order, with parts bound to control points kept in file
// order) and seam split.
RenderVertices afm_render_vertices(const AfmContent &content);

// The model units per quantum of the AFM position grid encode_afm() uses for
// this scene (positions and morph target deltas alike): the largest half
// extent of the scene's bounding box / 32766.5. The builder's solver
// tolerance derives from it.
double afm_position_quantum(const Scene &scene);

// Encodes the content; `profile` AFM_PROFILE_DRACO uses the Draco codec.
// Fails, saying which target and part, on a displacement that is not
// #V x 3 or not finite, and on a lift the format cannot hold.
Expected<std::vector<uint8_t>> encode_afm(const AfmContent &content, afm_profile profile);

// encode_afm, then an atomic write.
Status write_afm(const std::string &path, const AfmContent &content, afm_profile profile);

}  // namespace afmb
