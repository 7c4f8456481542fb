// The simulation mesh: a coarser copy of the skin that the anatomy is built
// and solved on, and the transfer of its motion to every skin vertex.
//
// The cost of a build grows with the skin (every pose factorises a tangent
// of 12 unknowns per dynamic vertex), while what a morph target holds is a
// smooth field of a few centimetres. A 10k-vertex skin is therefore
// simulated on about a thousand of its own vertices and the motion carried
// back, as lashes ride on the skin (skin_binding.h):
//
//   SimMesh sim = *make_sim_mesh(scene, fdps, {1000});
//   Scene coarse = sim_scene(scene, sim);          // the skin replaced
//   FdpSet coarse_fdps = sim_fdps(fdps, sim);      // skin FDPs re-indexed
//   ... build the model and its targets on (coarse, coarse_fdps) ...
//   Eigen::MatrixXd D = lift_displacement(sim, Dc);  // #V x 3 on the skin
//
// The coarse skin is made by half-edge collapses (OpenMesh's decimater), so
// its vertices are skin vertices, at their own positions. Every skin FDP is
// kept, so an FDP moves exactly as the simulation moves it. First every edge
// under 0.15 of the skin's mean edge is collapsed where legal, normals
// allowed to turn up to 90 degrees: triangles a thousandth of the mean in
// area (Song's mouth corners, where the lips curl in) turn over under the
// first pull and would stop a FAP's muscles there. Then edges are
// collapsed shortest first, their length measured against a sizing that is
// half as long around the eyes and the mouth (the lids and lips need the
// resolution). The lips keep every skin vertex within 0.2 eye separations
// of a lip FDP (at most half the budget, nearest first): a decimated mouth
// locks the sphincter of a detailed one (Song's). The lids keep every skin
// vertex within a tenth of an eyeball's radius outside its sphere
// (skin_model.h: fit_eyeballs, near_eyeballs), so the solver holds each of
// them off the eye; the mesh may then stop above the vertex count asked
// for. No collapse may turn a triangle's normal by more than 60 degrees
// from the skin normals it covers, leave a skin vertex more than 0.03 eye
// separations from the coarse surface, or leave a triangle of aspect ratio
// above 5, and the mesh stays a manifold with the same boundaries (the
// mouth slit and eye openings). A mirror-symmetric skin (nine in ten
// vertices with a mirror image) keeps mirror images: FDP vertices lock their
// images, the sizing is symmetric and ties break the same way on both sides
// (docs/anatomy.md).
//
// Each skin vertex is bound to the nearest point of the coarse triangles
// around its nearest kept vertex along the skin's edges, so a vertex of the
// upper lip never binds across the mouth slit to the lower one. Its
// displacement is the same barycentric blend of those corners'. A kept
// vertex binds to itself.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "anatomy/face_model.h"
#include "anatomy/skin_binding.h"
#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

// afm-build's default simulation mesh size.
constexpr int kDefaultSimVertices = 1000;
// The first pass's edges, in shares of the skin's mean edge (above).
constexpr double kShortEdgeShare = 0.15;

struct SimMeshOptions {
  // Coarse vertex count to aim at. 0, or a skin of at most 1.25 times as
  // many vertices: no decimation (the simulation mesh is the skin). The
  // decimation stops earlier when no legal collapse is left.
  int vertices = 0;
  // Skin vertices to keep besides the FDPs' (with their mirror images on a
  // mirror-symmetric skin), e.g. muscle_key_vertices().
  std::vector<int> keep = {};  // (an initializer: SimMeshOptions{N} stays warning-free)
  // The first pass collapses edges shorter than this share of the skin's
  // mean edge; 0: no first pass (the meshes before the seventy-fifth
  // session, for the tests whose case they hold).
  double short_edge = kShortEdgeShare;
};

struct SimMesh {
  int skin = -1;            // scene part index of the skin
  bool decimated = false;   // false: V, F are the skin's own, kept is the identity
  Eigen::MatrixXd V;        // #Vc x 3 coarse vertex positions, model units
  Eigen::MatrixXi F;        // #Fc x 3 coarse triangles into V, counter-clockwise from outside
  std::vector<int> kept;    // #Vc: the skin vertex each coarse vertex is
  SkinBinding binding;      // #V rows: each skin vertex's coarse triangle and weights
  Eigen::MatrixXd skin_V;   // #V x 3 the skin's own rest positions, model units
  Eigen::MatrixXi skin_F;   // #F x 3 the skin's own triangles into skin_V
  RestFaces skin_rest;      // rest_faces(skin_V, skin_F), for lifted_turned_faces (make_sim_mesh sets it)
  // A mirror-symmetric skin (nine in ten vertices with an image) is
  // decimated in mirror pairs; `unpaired`: collapses whose image could not
  // follow (0: the coarse mesh is as symmetric as the skin).
  bool mirrored = false;
  int unpaired = 0;
  int short_edges = 0;      // collapses of the first pass, the skin's shortest edges (above)
  double seconds = 0;       // time taken
};

// The simulation mesh of the skin part (the one holding FDP 2.1) of a scene
// whose FDPs are bound (bind_fdps). Fails when there is no skin part.
Expected<SimMesh> make_sim_mesh(const Scene &scene, const FdpSet &fdps, const SimMeshOptions &options);

// `scene` with its skin part's geometry replaced by the coarse mesh: V and F
// from `sim`, per-vertex colours of the kept vertices, no texture
// coordinates. Other parts are copied unchanged, in the same order.
Scene sim_scene(const Scene &scene, const SimMesh &sim);

// `fdps` with each point on the skin re-indexed into the coarse mesh (every
// skin FDP is a kept vertex); other points unchanged.
FdpSet sim_fdps(const FdpSet &fdps, const SimMesh &sim);

// The inverse: points on the coarse skin re-indexed into the skin.
FdpSet lift_fdps(const FdpSet &coarse, const SimMesh &sim);

// The skin displacement (#V x 3) carried from a coarse one (#Vc x 3).
Eigen::MatrixXd lift_displacement(const SimMesh &sim, const Eigen::MatrixXd &Dc);

// The skin's own triangles that a coarse displacement Dc (#Vc x 3), lifted,
// turns over (face_model.h, turned_faces); *share: their rest area over the
// skin's. A fine triangle can turn where no coarse one does: its corners
// move as the points of the coarse surface they are bound to, so a fine
// triangle steep against its coarse one is squashed flat, then over, as the
// coarse one turns (Song's lips pushed back, FAP 16 negative).
std::vector<int> lifted_turned_faces(const SimMesh &sim, const Eigen::MatrixXd &Dc, double *share = nullptr);

// The skin vertices whose nodes the muscles' key points map to on the skin
// itself (muscles.h: attachments to the skull layer, insertions to the
// dermis, sphincters' ends to the hypodermis), built with `tissue`; in
// table order, once each. Kept by the simulation mesh, the key points map
// as on the skin: a key point inside the tissue (depressor anguli's lies 5.6
// units under Song's skin) is otherwise near several coarse nodes, and which
// one is nearest differed from side to side on Song's simulation mesh.
// Fails on no skin part, one that check_skin() refuses, or a tissue that
// cannot be built; muscles lacking FDPs are left out.
Expected<std::vector<int>> muscle_key_vertices(const Scene &scene, const FdpSet &fdps, const TissueParams &tissue);

// The face model built on a simulation mesh, as afm-build makes it.
struct SimFaceModel {
  SimMesh sim;
  Scene scene;       // the input with the simulation mesh as its skin: what `model` is built on
  FaceModel model;   // its FDPs index the coarse skin (lift_fdps maps them back); its
                     // notes begin with the FDP estimates, made on the skin itself
  std::vector<std::string> notes;  // one per retry: the mesh that failed and why
};

// The missing FDPs estimated on the skin (when options.estimate_missing_fdps;
// the decimation keeps them), make_sim_mesh keeping muscle_key_vertices()
// too, then build_face_model on it. A
// decimated mesh on which the model does not build (a coarse tissue that
// cannot calibrate an essential muscle) is made again 1.5 times as fine, up
// to the skin itself, whose failure is returned. `on_mesh`, when given, is
// called with each simulation mesh before its model is built.
Expected<SimFaceModel> build_sim_face_model(const Scene &scene, const FdpSet &fdps, SimMeshOptions sim_options,
                                            const FaceModelOptions &options,
                                            const std::function<void(const SimMesh &)> &on_mesh = {});

}  // namespace afmb
