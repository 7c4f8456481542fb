// The multi-layer skin tissue (method paper section 2, after Lee, Terzopoulos
// and Waters): one prismatic element per skin triangle over four surfaces,
// mass nodes joined by nonlinear springs, a volume term per element.
//
// Surfaces (layers), each a copy of the skin mesh with #V nodes:
//   0 epidermis   the input vertices;
//   1 dermis      the dermis / fat boundary;
//   2 hypodermis  the muscle layer, where sphincters act;
//   3 skull       the bone, fixed (the jaw moves its part rigidly).
// Every inner node lies on the line from its epidermal node to the skin's
// centre of gravity c (the area-weighted centroid of the skin surface):
//   p_k = c + (1 - d_k (1 - s)) (p_0 - c),   d = 0, dermis_depth, hypodermis_depth, 1,
// so every surface is the epidermis scaled around c (the skull by the factor
// s = skull_scale, as the paper makes its skull offset surface), no surface
// intersects itself, and each element is a slice of the cone from c.
//
// Springs, each once however many elements share it (docs/anatomy.md has the
// formulas):
//   layer       along every mesh edge on layers 0, 1 and 2;
//   connecting  from each node to the node below it (0-1, 1-2, 2-3);
//   crossed     the two diagonals of every side face of every slab.
// A spring's stiffness comes from the slab it belongs to (slab k lies between
// layers k and k+1; a layer spring on layer k belongs to the slabs on both
// sides): k = E_slab x V_share / l0^2, where V_share is its share of the slab
// volumes it spans. So stiffness scales with size like a continuum and does
// not depend on the mesh resolution. Biphasic: the force is linear in the
// strain up to `knee` and `ratio` times stiffer beyond it.
//
// Units: positions in model units; moduli are relative (the epidermis slab's
// modulus is 1), so forces are in "modulus x area" and only ratios matter.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "anatomy/lip_contact.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

enum TissueLayer : int { kEpidermis = 0, kDermis = 1, kHypodermis = 2, kSkull = 3 };
constexpr int kTissueLayers = 4;

struct SlabParams {
  double modulus;  // relative Young's modulus
  double knee;     // strain where the spring stiffens (biphasic)
  double ratio;    // stiffness beyond the knee / below it
};

// The defaults (docs/anatomy.md, "The layered skin"): the skin slab loaded
// on both its surfaces, half each; each layer's volume kept with k_v's
// modulus; the collapse floor at a third of the modulus that keeps every
// slab upright without the layers.
constexpr double kLayeredSkinLoadShare = 0.5;
constexpr double kLayeredSkinVolumeModulus = 0.02;
constexpr double kCollapseFloor = 0.1;

struct TissueParams {
  double skull_scale = 0.9;       // s: skull = c + s (p0 - c); tissue is (1 - s) |p0 - c| thick
  double dermis_depth = 0.2;      // depth of layer 1, fraction of the epidermis-to-skull line
  double hypodermis_depth = 0.6;  // depth of layer 2
  // Slab 0 epidermis+dermis (moderately stiff), 1 fat (soft), 2 muscle layer
  // to the bone. The epidermal surface springs get `epidermis_surface` times
  // slab 0's modulus on top (the keratin sheet).
  SlabParams slab[3] = {{1.0, 0.15, 4.0}, {0.15, 0.4, 4.0}, {1.0, 0.3, 4.0}};
  double epidermis_surface = 3.0;
  double crossed_share = 0.5;  // share of a side face's volume given to its two diagonals
  // Lee, Terzopoulos and Waters' volume (k_v) and shape (k_s) terms per
  // element (solver.h gives the formulas; docs/anatomy.md how they were
  // chosen).
  double volume_modulus = 0.02;
  double shape_modulus = 0.1;
  // Each layer's own volume (k_l; solver.h), 0: off: per slab that holds
  // tissue (slab_holds_tissue), the volume term's form on the slab's own
  // volume. The element's term alone lets one slab thin by as much as
  // another thickens (docs/anatomy.md, "The layered skin").
  double layer_volume_modulus = kLayeredSkinVolumeModulus;
  // The epidermis's share of a linear muscle's load, 0..1, the rest on the
  // dermis (muscles.h): the skin slab pulled on both its surfaces. 0: the
  // dermis alone, which a pull drags under the epidermis, turning the skin's
  // slab through its thickness (docs/anatomy.md, "The layered skin").
  double skin_load_share = kLayeredSkinLoadShare;
  // The collapse floor (solver.h), 0: off: a slab holding tissue
  // (slab_holds_tissue) squeezed below `collapse_knee` of its rest volume
  // has the energy collapse_modulus x its share of the element's nominal
  // volume x ((knee - J) / knee)^3, J its volume over its rest volume, so
  // that no slab turns through itself (with the layered skin, none in
  // Song's or the 10k head's targets; docs/anatomy.md gives the cost).
  double collapse_modulus = kCollapseFloor;
  double collapse_knee = 0.5;
  // Lip-lip contact (lip_contact.h): the contact pressure at a crossing of
  // one margin, relative like the slabs' moduli; 0: off.
  double lip_contact_modulus = 1.0;
  double density = 1.0;        // mass per volume, for the lumped masses
};

// The tissue before the layered skin and the floor (afm-build
// --no-layered-skin --collapse-floor 0): linear muscles on the dermis alone,
// one volume term per element, no floor. Strong pulls turn slabs through
// themselves there; kept to compare with, and for the tests whose case is
// such a slab.
TissueParams unlayered_tissue(TissueParams p = {});

enum class SpringKind : uint8_t { Layer, Connecting, Crossed };

struct Spring {
  int a = 0, b = 0;   // node indices (layer * n + vertex)
  double rest = 0;    // model units
  double k = 0;       // stiffness below the knee
  double knee = 0;    // strain
  double ratio = 1;   // stiffness ratio beyond the knee
  SpringKind kind = SpringKind::Layer;
  uint8_t slab = 0;   // 0..2; a layer spring reports its upper slab
};

// The most a lid is held off its eyeball, in radii (SkinModel::eye_clearance).
constexpr double kEyeClearance = 0.01;
// Skin triangles whose corners are held h off a ball of radius r stay
// outside it when h >= kChordDip l^2 / r, l the longest edge: the plane of
// an acute triangle comes nearest the centre at its circumcentre, R^2 / (2 r)
// below the corners, and R <= l / sqrt(3); an obtuse one at its longest
// edge, l^2 / (8 r) below. With the edge's l^2 / (8 r) alone the 1k head's
// lid, 10 mm triangles over a 12 mm eyeball, let the iris through when shut.
constexpr double kChordDip = 1.0 / 6;

// An eyeball the lids slide over: a sphere fitted to an eye part.
struct EyeSphere {
  int part = -1;                                     // scene part index
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // model units
  double radius = 0;
};

// A pose's displacement on the nodes it moves: global node indices into
// SkinModel::X0, ascending, and their displacement (#nodes x 3, model units).
struct NodeDisplacement {
  std::vector<int> nodes;
  Eigen::MatrixXd displacement;
};

struct SkinModel {
  int part = -1;           // the scene part the skin is
  int n = 0;               // nodes per surface (= the skin part's vertex count)
  TissueParams params;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // c
  Eigen::MatrixXd X0;      // 4n x 3 rest positions, row layer * n + vertex
  Eigen::MatrixXi F;       // #F x 3 skin triangles
  std::vector<Spring> springs;
  std::vector<std::vector<int>> node_springs;  // 4n: springs at each node
  Eigen::VectorXd mass;    // 4n lumped masses
  Eigen::VectorXd area;    // n: epidermal area per vertex (a third of each triangle)
  Eigen::MatrixXd normal;  // n x 3: epidermal vertex normals at rest (area-weighted, unit)
  Eigen::VectorXd thickness;  // n: epidermis to skull distance
  Eigen::VectorXd rest_volume;  // #F: signed volume of each element (all three slabs)
  // #F: the volume the element would have if its tissue lay straight under
  // its skin: triangle area x mean thickness of its corners (> 0). Where the
  // line to the centre grazes the skin (lip curls, nostrils) the prism is
  // seen edge-on and |rest_volume| is a small part of it.
  Eigen::VectorXd nominal_volume;
  std::vector<std::vector<int>> neighbours;    // n: vertex adjacency of the skin mesh
  std::vector<std::vector<int>> vertex_faces;  // n: triangles at each vertex
  // Per vertex: 1 = not tied to the bone (lips, cheeks; lids over an eyeball): its springs from
  // the hypodermis to the skull have zero stiffness and the skull does not
  // reject its nodes.
  std::vector<uint8_t> skull_free;
  std::vector<uint8_t> in_mesh;  // per vertex: used by a triangle (others are never simulated)
  // The eyeballs: spheres fitted to the scene's eye parts (an eye part whose
  // vertices are not a sphere, within a tenth of its radius, is left out).
  std::vector<EyeSphere> eyes;
  // Per vertex: the eyeball it lies over, or -1. A vertex lies over an
  // eyeball when it is outside the sphere at rest, within half a radius of
  // its surface, and the line inward along its normal meets the sphere: the
  // lids and the skin around them. The solver holds its epidermal node off
  // the sphere instead of above the skull (what lies under a lid is the eye).
  std::vector<int8_t> eye_of;
  // Per vertex: the eyeball whose sphere the solver holds its epidermal node
  // outside of, or -1 (near_eyeballs(): eye_of and the skin facing away from
  // the eye around it, such as the lid margin's underside, which meets the
  // ball as the lid turns over it). A node of these that is not over the
  // eyeball keeps its skull plane until it meets the sphere.
  std::vector<int8_t> eye_near;
  // Per vertex: how far off its eyeball's sphere the epidermal node is held
  // at rest (model units): its distance at rest, up to kEyeClearance radii or
  // its longest edge's chord dip kChordDip l^2 / r, whichever is more. On the
  // sphere itself the skin between nodes, a chord, and the eye part's
  // vertices cross: Song's eyeball showed through the lid as dark specks.
  // In a pose it grows as the edges stretch (eye_clearance_in).
  std::vector<double> eye_clearance;
  // The lips' contact pairs (lip_contact.h), made by build_face_model from
  // the mouth-window searches; empty: no contact.
  std::vector<LipPair> lip_pairs;

  int node(int layer, int vertex) const { return layer * n + vertex; }
  int layer_of(int node) const { return node / n; }
  int vertex_of(int node) const { return node % n; }
  // The stiffness a spring has now (0 for a bone tie of a skull-free vertex).
  double stiffness(const Spring &s) const;
};

// How far off an eyeball of radius `radius` skin is held at rest whose
// distance from the sphere is `rest` and whose longest edge's square is
// `longest_sq` (model units): `rest`, up to kEyeClearance radii or the
// edge's chord dip (kChordDip), whichever is more; never below 0.
double rest_eye_clearance(double rest, double longest_sq, double radius);

// Makes the solver hold vertex v's epidermal node off eyeball `eye`
// (SkinModel::eye_near, with its eye_clearance: rest_eye_clearance). X0 and
// neighbours must be set.
void hold_off_eyeball(SkinModel &m, int v, int eye);

// How far off its eyeball's sphere the solver holds vertex v's epidermal
// node in pose X (4n x 3; v must have eye_near[v] >= 0), model units:
// eye_clearance[v] plus what the chords to its neighbours held by the same
// eyeball dip further as they stretch, kChordDip (l^2 - l0^2) / r for the
// longest growth (`among`, when given, one flag per skin vertex: only the
// chords to the neighbours flagged). A closing lid stretches: on the 2k
// head its triangles grew to 11 mm over a 12.2 mm eyeball, and held at their
// rest clearance the eye part showed through them.
double eye_clearance_in(const SkinModel &m, int v, const Eigen::MatrixXd &X,
                        const std::vector<char> *among = nullptr);

// The eyeballs of a scene: a sphere fitted to each eye part (left, then
// right; an eye part whose vertices are not a sphere, within a tenth of its
// radius rms, or with fewer than 8 vertices, is left out). `part` is set.
std::vector<EyeSphere> fit_eyeballs(const Scene &scene);

// Per vertex of a surface (V #V x 3; `used`: #V, 0 for a vertex no triangle
// uses): the eyeball in `eyes` whose sphere it lies outside of, within `band`
// radii of its surface, or -1 (the first that qualifies). With the default
// band, a superset of SkinModel::eye_of: it takes in the lid margin's
// underside and the skin turning into the socket, which face away from the
// eye but meet it as the lid turns over the ball.
std::vector<int8_t> near_eyeballs(const Eigen::MatrixXd &V, const std::vector<uint8_t> &used,
                                  const std::vector<EyeSphere> &eyes, double band = 0.5);

// What build_skin_model fills in: the whole tissue, or its surfaces alone
// (SkinModel::springs, node_springs and mass left empty): enough to place
// the muscles on (muscles.h), as muscle_key_vertices (sim_mesh.h) does on
// the whole skin before the decimation (Song's: 1.3 ms instead of 43; the
// 10k head's 3.4 instead of 165).
enum class SkinBuild { Tissue, Surfaces };

// Builds the tissue for scene part `part`; the scene's eye parts (if any)
// become its eyeballs (fit_eyeballs, near_eyeballs). Fails when the part has no
// triangles, when its centre of gravity is on the surface (not a closed-ish
// head), or when parameters are out of range (depths not 0 < d1 < d2 < 1,
// skull_scale not in (0, 1)).
Expected<SkinModel> build_skin_model(const Scene &scene, int part, const TissueParams &params,
                                     SkinBuild build = SkinBuild::Tissue);

// The node of `layer` nearest p (global node index), among vertices used by
// a triangle; -1 when there are none.
int nearest_node(const SkinModel &m, int layer, const Eigen::Vector3d &p);

// Signed volume of element f (all three slabs, 9 tetrahedra; or, with
// slab 0..2, that slab's 3) at positions X (4n x 3), and optionally its
// gradient: 9 x 3, rows for the nodes layer * 3 + corner of layers 0..2
// (the skull's are not needed: it is fixed or moved, never solved for).
double element_volume(const SkinModel &m, const Eigen::MatrixXd &X, int f,
                      Eigen::Matrix<double, 9, 3> *gradient = nullptr, int slab = -1);

// The Hessian of element_volume() (27 x 27, indefinite: the volume is cubic
// in the positions). Each 3 x 3 block is a cross-product matrix, so it is kept
// as one vector per pair of gradient rows (layers 0..2): block (i, j) applied
// to a vector x is w(i, j) x x, with w(j, i) = -w(i, j) and zero blocks on the
// diagonal. A ninth of the dense matrix's numbers.
struct VolumeHessian {
  Eigen::Vector3d upper[36];  // w(i, j) for i < j, row by row: (0,1) .. (0,8), (1,2) ..
  static int pair(int i, int j) { return i * (17 - i) / 2 + j - i - 1; }  // i < j
  // The block's cross-product matrix, any i and j in 0..8.
  Eigen::Matrix3d block(int i, int j) const;
};
void element_volume_hessian(const SkinModel &m, const Eigen::MatrixXd &X, int f, VolumeHessian *H);

// Per-tetrahedron signed volumes of element f: 9 values. An element is
// inverted when one of its tetrahedra changed sign from the rest state.
void element_tet_volumes(const SkinModel &m, const Eigen::MatrixXd &X, int f, double out[9]);

// Slab 0..2's share of element f's nominal volume (SkinModel::
// nominal_volume), by the depths of its two surfaces.
double slab_nominal_volume(const SkinModel &m, int f, int slab);

// Whether slab 0..2 of element f holds tissue whose facing its volume
// tells: not a slab seen edge-on from the centre (its rest volume under a
// quarter of its depth's share of the element's nominal volume: lip curls,
// nostrils), and not the bone slab under skin that is not tied to the bone
// (lips, cheeks, lids: nothing lies between there).
bool slab_holds_tissue(const SkinModel &m, int f, int slab);

// The slabs of the tissue turned through themselves at X (4n x 3): the
// (element, slab) pairs that hold tissue and whose signed volume (three
// tetrahedra) has the other sign than at rest. Coarser than
// element_tet_volumes' test: a twisted slab may turn one of its tetrahedra
// and keep its volume. Ascending by element.
std::vector<std::pair<int, int>> turned_slabs(const SkinModel &m, const Eigen::MatrixXd &X);

}  // namespace afmb
