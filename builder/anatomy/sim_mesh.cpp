// OpenMesh's VectorT default constructor leaves its elements uninitialised on
// purpose, and GCC 12 flags the copies its property arrays make of them
// (inside the standard headers, so the pragma has to precede every include).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "anatomy/sim_mesh.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/BaseDecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModAspectRatioT.hh>
#include <OpenMesh/Tools/Decimater/ModBaseT.hh>
#include <OpenMesh/Tools/Decimater/ModHausdorffT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalDeviationT.hh>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "anatomy/fdp_completion.h"
#include "anatomy/mirror.h"
#include "anatomy/muscle_table.h"
#include "anatomy/muscles.h"
#include "anatomy/skin_model.h"
#include "core/part_kind.h"
#include "core/validate.h"

namespace afmb {

namespace {

struct Traits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;

// The sizing around the eyes and the mouth, relative to elsewhere: edges
// there count twice as long, so the lids and lips keep about four times the
// vertex density.
constexpr double kFeatureSizing = 0.5;
// How far, in eye separations, the finer sizing reaches from the nearest
// eye or lip FDP (it grows linearly back to 1 over that distance).
constexpr double kFeatureReach = 0.3;
// The lips keep every skin vertex within this many eye separations of a lip
// FDP (group 8 and 2.2-2.9), up to half the budget, nearest first. Song's
// orbicularis oris locks when they are decimated, even finely: at 1,000 and
// 1,500 vertices it reached 2.53 and 2.58 of its 3.06 units with the sizing
// alone, 0.22 with a mouth sizing of 0.3, and calibrated only from 0.15.
constexpr double kLipKeep = 0.2;
// The lids keep every skin vertex within this many eyeball radii outside
// its sphere. Song: 212 vertices (its simulation mesh then stops at 1,147
// vertices instead of 1,000); the generated heads' lids lie farther out
// (0.107 radii) and keep none.
constexpr double kLidKeep = 0.1;
// What a collapse may not do: turn a coarse triangle's normal further than
// this from the skin normals it covers, or leave a skin vertex farther than
// kMaxDistance eye separations from the coarse surface.
constexpr double kMaxNormalTurnDegrees = 60;
constexpr double kMaxDistance = 0.03;
constexpr float kMaxAspectRatio = 5;
// Before the lips are kept, every edge shorter than a share of the skin's
// mean edge is collapsed where legal (FDP, muscle key and lid vertices stay),
// each collapse allowed to turn a normal by up to this many degrees.
// Song's mouth corners hold clusters of triangles a thousandth of its mean
// triangle in area (its lips curl in where they meet); kept whole with the
// lips, the solver turned them over at the table's contractions, and the
// stretched corners stopped at 71 % of their reference. With this pass they
// reach it (the report's worst along error 29.1 -> 5.7 %, under-reaching
// sides 10 -> 3), and Song's whole AFM takes a quarter fewer Newton
// iterations. At 60 degrees the clusters stay (they sit on the crease where
// the lips meet); at 0.3 of the mean edge the 2k head's brows fold sooner
// (worst along 28 -> 56 %); at 0.15 the generated heads' meshes and AFMs are
// the same (docs/notes.md, seventy-fifth session). The share is
// SimMeshOptions::short_edge, kShortEdgeShare by default (sim_mesh.h).
constexpr double kShortEdgeNormalTurnDegrees = 90;

// Priority: the edge's squared length over the squared sizing at its
// midpoint (shortest first). Not binary: it orders the collapses.
template <class MeshT>
class ModSizedLengthT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModSizedLengthT, MeshT, SizedLength);

  explicit ModSizedLengthT(MeshT &mesh) : Base(mesh, false) {}

  std::function<double(const Eigen::Vector3d &)> sizing;
  // Longer edges may not collapse (the first pass, SimMeshOptions::short_edge); model units.
  double max_length = std::numeric_limits<double>::infinity();
  // A value in [0, 1) of the far end that breaks ties between collapses of
  // equal length (1e-4 of the priority: above a float's resolution), or none.
  std::function<double(const Eigen::Vector3d &)> tie;

  float collapse_priority(const CollapseInfo &ci) override {
    const Eigen::Vector3d p0(ci.p0[0], ci.p0[1], ci.p0[2]), p1(ci.p1[0], ci.p1[1], ci.p1[2]);
    if ((p1 - p0).squaredNorm() > max_length * max_length) return Base::ILLEGAL_COLLAPSE;
    const double h = sizing((p0 + p1) / 2);
    return static_cast<float>((p1 - p0).squaredNorm() / (h * h) * (1 + (tie ? 1e-4 * tie(p1) : 0)));
  }
};

bool is_lip(const FdpId &id) { return id.group == 8 || (id.group == 2 && id.index >= 2 && id.index <= 9); }
bool is_feature(const FdpId &id) { return id.group == 3 || is_lip(id); }

// Locks the skin vertices within `reach` of a lip FDP, at most `budget` of
// them, nearest first (ties to the lower index); collapsed ones are not
// counted.
template <class MeshT>
void keep_lips(MeshT &mesh, const Part &skin, const std::vector<Eigen::Vector3d> &lips, double reach, int budget) {
  std::vector<std::pair<double, int>> near;
  for (int v = 0; v < static_cast<int>(skin.V.rows()); ++v) {
    double d = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d &f : lips) d = std::min(d, (skin.V.row(v).transpose() - f).norm());
    if (d < reach && !mesh.status(typename MeshT::VertexHandle(v)).deleted()) near.emplace_back(d, v);
  }
  std::sort(near.begin(), near.end());
  near.resize(std::min(near.size(), static_cast<size_t>(std::max(budget, 0))));
  for (const auto &[d, v] : near) mesh.status(typename MeshT::VertexHandle(v)).set_locked(true);
}

// Locks the skin vertices within kLidKeep radii outside an eyeball's sphere
// (near_eyeballs): the lids. The solver holds each simulated node there off
// the eye (SkinModel::eye_near); a lid vertex carried from coarse corners
// instead sank into it as the lid turned over the ball (Song's upper lid
// margin 0.3 units in at FAP 19 = 600, with only the coarse nodes held).
template <class MeshT>
void keep_lids(MeshT &mesh, const Part &skin, const std::vector<EyeSphere> &eyes) {
  std::vector<uint8_t> used(static_cast<size_t>(skin.V.rows()), 0);
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[static_cast<size_t>(skin.F(f, k))] = 1;
  const std::vector<int8_t> lid = near_eyeballs(skin.V, used, eyes, kLidKeep);
  for (size_t v = 0; v < lid.size(); ++v)
    if (lid[v] >= 0) mesh.status(typename MeshT::VertexHandle(static_cast<int>(v))).set_locked(true);
}

// OpenMesh's decimater (the same modules, priorities and legality) with
// each collapse made together with its mirror image: the collapse of the
// images of its two vertices (`mirror`, one entry per vertex, -1 for none),
// so that a mirror-symmetric skin keeps a mirror-symmetric simulation mesh.
// A collapse is legal only with its image: none moves a vertex of the
// mid-plane off it or joins a vertex to its own image, and one with an image
// needs the image's collapse legal too (re-checked after the first; a
// region without images collapses alone). Ties between equal priorities go
// to the lower vertex index.
class MirroredDecimater : public OpenMesh::Decimater::BaseDecimaterT<TriMesh> {
 public:
  using Base = OpenMesh::Decimater::BaseDecimaterT<TriMesh>;
  MirroredDecimater(TriMesh &mesh, std::vector<int> mirror) : Base(mesh), mesh_(mesh), mirror_(std::move(mirror)) {}

  // The priority module (the one that is not binary), whose priority
  // orders a vertex's candidates before their legality is checked (heap()).
  // Needed before decimate_to().
  void set_order(OpenMesh::Decimater::ModBaseT<TriMesh> *order) { order_ = order; }

  // Collapses until at most `target` vertices are left (one fewer where the
  // last collapse's image follows it) or no collapse is legal. Returns the
  // collapses made; *unpaired gets those whose image could not follow. The
  // vertices counted include those collapsed by an earlier call (no garbage
  // collection).
  size_t decimate_to(size_t target, size_t *unpaired) {
    const size_t n = mesh_.n_vertices();
    best_.assign(n, TriMesh::HalfedgeHandle());
    stamp_.assign(n, 0);
    for (TriMesh::VertexHandle v : mesh_.vertices()) heap(v);
    size_t alive = n, made = 0;
    *unpaired = 0;
    while (alive > target && !queue_.empty()) {
      const Entry e = queue_.top();
      queue_.pop();
      const TriMesh::VertexHandle v(e.vertex);
      if (e.stamp != stamp_[static_cast<size_t>(e.vertex)] || mesh_.status(v).deleted()) continue;
      // As OpenMesh's decimater: the queued collapse's topology again (the
      // modules' verdicts were renewed with every change around it), and
      // its image's.
      const TriMesh::HalfedgeHandle h = best_[static_cast<size_t>(e.vertex)];
      TriMesh::HalfedgeHandle image;
      if (!h.is_valid() || !this->is_collapse_legal(CollapseInfo(mesh_, h)) || !pair_legal(h, &image)) {
        heap(v);
        continue;
      }
      std::vector<TriMesh::VertexHandle> support;
      const int m0 = image.is_valid() ? mesh_.from_vertex_handle(image).idx() : -1;
      const int m1 = image.is_valid() ? mesh_.to_vertex_handle(image).idx() : -1;
      collapse(h, support);
      ++made, --alive;
      if (m0 >= 0) {  // even past the target by one: the pair stays whole
        const TriMesh::HalfedgeHandle again =
            mesh_.find_halfedge(TriMesh::VertexHandle(m0), TriMesh::VertexHandle(m1));
        CollapseInfo ci(mesh_, again);
        if (again.is_valid() && this->is_collapse_legal(ci) && this->collapse_priority(ci) >= 0) {
          collapse(again, support);
          ++made, --alive;
        } else {
          ++*unpaired;
        }
      }
      std::sort(support.begin(), support.end());
      support.erase(std::unique(support.begin(), support.end()), support.end());
      for (TriMesh::VertexHandle u : support)
        if (!mesh_.status(u).deleted()) heap(u);
    }
    return made;
  }

 private:
  struct Entry {
    float priority;
    int vertex;
    unsigned stamp;
    bool operator<(const Entry &o) const {  // std::priority_queue pops the largest
      return priority != o.priority ? priority > o.priority : vertex > o.vertex;
    }
  };

  int image_of(int v) const { return v >= 0 && static_cast<size_t>(v) < mirror_.size() ? mirror_[v] : -1; }

  // Whether collapsing h is legal alone (*priority: its priority).
  bool legal_alone(TriMesh::HalfedgeHandle h, float *priority) {
    CollapseInfo ci(mesh_, h);
    if (!this->is_collapse_legal(ci)) return false;
    *priority = this->collapse_priority(ci);
    return *priority >= 0;
  }

  // Whether h's image may collapse with it (*image: the image's halfedge,
  // invalid when h collapses alone), for an h legal alone.
  bool pair_legal(TriMesh::HalfedgeHandle h, TriMesh::HalfedgeHandle *image) {
    *image = TriMesh::HalfedgeHandle();
    const int v0 = mesh_.from_vertex_handle(h).idx(), v1 = mesh_.to_vertex_handle(h).idx();
    const int m0 = image_of(v0), m1 = image_of(v1);
    if (m0 < 0 && m1 < 0) return true;       // no images here: alone
    if (m0 < 0 || m1 < 0) return false;       // half a pair
    if (m0 == v1 && m1 == v0) return false;   // a vertex onto its own image
    if (m0 == v0) return m1 == v1;            // on the mid-plane: alone, and stays on it
    const TriMesh::HalfedgeHandle hm = mesh_.find_halfedge(TriMesh::VertexHandle(m0), TriMesh::VertexHandle(m1));
    if (!hm.is_valid()) return false;
    CollapseInfo cm(mesh_, hm);
    if (!this->is_collapse_legal(cm) || this->collapse_priority(cm) < 0) return false;
    *image = hm;
    return true;
  }

  void collapse(TriMesh::HalfedgeHandle h, std::vector<TriMesh::VertexHandle> &support) {
    CollapseInfo ci(mesh_, h);
    for (TriMesh::VertexHandle u : mesh_.vv_range(ci.v0)) support.push_back(u);
    this->preprocess_collapse(ci);
    mesh_.collapse(h);
    for (TriMesh::FaceHandle f : mesh_.vf_range(ci.v1))
      if (!mesh_.status(f).deleted()) mesh_.set_normal(f, mesh_.calc_face_normal(f));
    this->postprocess_collapse(ci);
  }

  // v's best legal collapse, queued (or none). The candidates go in order
  // of the priority module's priority, which is the decimater's where the
  // binary modules pass, until one is legal alone and with its image: the
  // legality checks cost several times the priority (callgrind on Song's
  // decimation: 1.15 -> 0.84 billion instructions, checking every
  // candidate's legality first; the same collapses).
  void heap(TriMesh::VertexHandle v) {
    const size_t i = static_cast<size_t>(v.idx());
    std::vector<std::pair<float, int>> order;  // priority, halfedge index
    if (!mesh_.status(v).locked())  // is_collapse_legal's first test
      for (TriMesh::HalfedgeHandle h : mesh_.voh_range(v)) {
        const float p = order_->collapse_priority(CollapseInfo(mesh_, h));
        if (p >= 0) order.emplace_back(p, h.idx());
      }
    std::sort(order.begin(), order.end());
    TriMesh::HalfedgeHandle target;
    float best = 0;
    for (const auto &[p, h] : order) {
      float q = 0;
      TriMesh::HalfedgeHandle image;
      if (legal_alone(TriMesh::HalfedgeHandle(h), &q) && q == p && pair_legal(TriMesh::HalfedgeHandle(h), &image)) {
        best = p, target = TriMesh::HalfedgeHandle(h);
        break;
      }
    }
    best_[i] = target;
    ++stamp_[i];
    if (target.is_valid()) queue_.push(Entry{best, v.idx(), stamp_[i]});
  }

  TriMesh &mesh_;
  std::vector<int> mirror_;
  std::vector<TriMesh::HalfedgeHandle> best_;
  std::vector<unsigned> stamp_;
  std::priority_queue<Entry> queue_;
  OpenMesh::Decimater::ModBaseT<TriMesh> *order_ = nullptr;
};

// For every skin vertex, the kept vertex nearest along the skin's edges
// (-1 where none is reachable), by Dijkstra from all kept vertices at once.
std::vector<int> nearest_kept(const Part &skin, const std::vector<int> &kept) {
  const int n = static_cast<int>(skin.V.rows());
  std::vector<std::vector<int>> adj(static_cast<size_t>(n));
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = skin.F(f, k), b = skin.F(f, (k + 1) % 3);
      adj[static_cast<size_t>(a)].push_back(b);
      adj[static_cast<size_t>(b)].push_back(a);
    }
  std::vector<double> dist(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<int> label(static_cast<size_t>(n), -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (size_t c = 0; c < kept.size(); ++c) {
    dist[static_cast<size_t>(kept[c])] = 0;
    label[static_cast<size_t>(kept[c])] = static_cast<int>(c);
    queue.emplace(0.0, kept[c]);
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[static_cast<size_t>(v)]) continue;
    for (int u : adj[static_cast<size_t>(v)]) {
      const double du = d + (skin.V.row(u) - skin.V.row(v)).norm();
      // Ties go to the lower coarse index, so the labels do not depend on
      // the order the queue pops equal distances in.
      if (du < dist[static_cast<size_t>(u)] ||
          (du == dist[static_cast<size_t>(u)] && label[static_cast<size_t>(v)] < label[static_cast<size_t>(u)])) {
        dist[static_cast<size_t>(u)] = du;
        label[static_cast<size_t>(u)] = label[static_cast<size_t>(v)];
        queue.emplace(du, u);
      }
    }
  }
  return label;
}

// For each of the skin's `n` vertices, its coarse index, or -1.
std::vector<int> coarse_index(const SimMesh &sim, int n) {
  std::vector<int> out(static_cast<size_t>(n), -1);
  for (size_t c = 0; c < sim.kept.size(); ++c) out[static_cast<size_t>(sim.kept[c])] = static_cast<int>(c);
  return out;
}

// Binds every skin vertex to the coarse mesh (see the header).
SkinBinding bind_fine_to_coarse(const Part &skin, const SimMesh &sim) {
  const int n = static_cast<int>(skin.V.rows());
  const int nc = static_cast<int>(sim.V.rows());
  std::vector<std::vector<int>> faces_of(static_cast<size_t>(nc));  // coarse faces at each coarse vertex
  for (Eigen::Index f = 0; f < sim.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) faces_of[static_cast<size_t>(sim.F(f, k))].push_back(static_cast<int>(f));
  const std::vector<int> coarse_of = coarse_index(sim, n);
  // Every vertex is kept when the mesh is the skin: nothing to search.
  const std::vector<int> label =
      sim.decimated ? nearest_kept(skin, sim.kept) : std::vector<int>(static_cast<size_t>(n), -1);

  SkinBinding b;
  b.part = sim.skin;
  b.corner.resize(n, 3);
  b.weight.resize(n, 3);
  std::vector<int> candidates;
  std::vector<uint8_t> seen(static_cast<size_t>(sim.F.rows()), 0);
  for (int v = 0; v < n; ++v) {
    const int self = coarse_of[static_cast<size_t>(v)];
    if (self >= 0 && !faces_of[static_cast<size_t>(self)].empty()) {
      const int f = faces_of[static_cast<size_t>(self)].front();
      b.corner.row(v) = sim.F.row(f);
      for (int k = 0; k < 3; ++k) b.weight(v, k) = sim.F(f, k) == self ? 1.0 : 0.0;
      continue;
    }
    // The coarse triangles around the nearest kept vertex and its coarse
    // neighbours; every coarse triangle when no kept vertex is reachable
    // (a skin component the decimation left without one).
    candidates.clear();
    const int c = label[static_cast<size_t>(v)];
    if (c >= 0) {
      for (int f : faces_of[static_cast<size_t>(c)])
        for (int k = 0; k < 3; ++k)
          for (int g : faces_of[static_cast<size_t>(sim.F(f, k))])
            if (!seen[static_cast<size_t>(g)]) seen[static_cast<size_t>(g)] = 1, candidates.push_back(g);
      for (int g : candidates) seen[static_cast<size_t>(g)] = 0;
      std::sort(candidates.begin(), candidates.end());  // ties go to the lowest face
    }
    if (candidates.empty())
      for (int g = 0; g < static_cast<int>(sim.F.rows()); ++g) candidates.push_back(g);
    const Eigen::Vector3d x = skin.V.row(v).transpose();
    double best = std::numeric_limits<double>::infinity();
    for (int f : candidates) {
      Eigen::Vector3d w;
      const double d = nearest_on_face(x, sim.V, sim.F, f, &w);
      if (d < best) {
        best = d;
        b.corner.row(v) = sim.F.row(f);
        b.weight.row(v) = w.transpose();
      }
    }
  }
  return b;
}

SimMesh identity_sim(const Part &skin, int index) {
  SimMesh sim;
  sim.skin = index;
  sim.V = skin.V;
  sim.F = skin.F;
  sim.kept.resize(static_cast<size_t>(skin.V.rows()));
  for (size_t v = 0; v < sim.kept.size(); ++v) sim.kept[v] = static_cast<int>(v);
  return sim;
}

}  // namespace

Expected<SimMesh> make_sim_mesh(const Scene &scene, const FdpSet &fdps, const SimMeshOptions &options) {
  const auto t0 = std::chrono::steady_clock::now();
  const int skin_index = scene.find_kind(PartKind::Skin);
  if (skin_index < 0) return Status::error(scene.source + ": no skin part (the part holding FDP 2.1)");
  const Part &skin = scene.parts[static_cast<size_t>(skin_index)];
  const int n = static_cast<int>(skin.V.rows());
  auto identity = [&] {
    SimMesh sim = identity_sim(skin, skin_index);
    sim.binding = bind_fine_to_coarse(skin, sim);
    sim.skin_V = skin.V;
    sim.skin_F = skin.F;
    sim.skin_rest = rest_faces(sim.skin_V, sim.skin_F);
    sim.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return sim;
  };
  if (options.vertices <= 0 || n * 4 <= options.vertices * 5) return identity();

  // Every skin FDP stays, and sets the finer sizing around eyes and mouth.
  std::vector<Eigen::Vector3d> features, lips;
  std::vector<char> locked(static_cast<size_t>(n), 0);
  Eigen::Vector3d eye_l = Eigen::Vector3d::Zero(), eye_r = Eigen::Vector3d::Zero();
  bool has_l = false, has_r = false;
  for (const FdpPoint &p : fdps.points) {
    if (p.id == FdpId{3, 5}) eye_l = p.pos, has_l = true;
    if (p.id == FdpId{3, 6}) eye_r = p.pos, has_r = true;
    if (p.part != skin_index || p.vertex < 0 || p.vertex >= n) continue;
    locked[static_cast<size_t>(p.vertex)] = 1;
    if (is_feature(p.id)) features.push_back(p.pos);
    if (is_lip(p.id)) lips.push_back(p.pos);
  }
  for (int v : options.keep)
    if (v >= 0 && v < n) locked[static_cast<size_t>(v)] = 1;
  // Without both pupils, a tenth of the skin's diagonal stands in for the
  // eye separation.
  Eigen::Vector3d lo = skin.V.colwise().minCoeff(), hi = skin.V.colwise().maxCoeff();
  const double es0 = has_l && has_r ? (eye_l - eye_r).norm() : 0.1 * (hi - lo).norm();
  const double reach = kFeatureReach * es0;

  // A mirror-symmetric skin gets a mirror-symmetric simulation mesh. Song's
  // FDPs are a few hundredths off symmetric, and OpenMesh's decimater breaks
  // ties by handle order: its left eye came out a sixth coarser than its
  // right (55 against 63 vertices within 20 units of the pupils), its eye
  // sphincter with a smaller influence and a narrower range. So, when nine in
  // ten skin vertices have a mirror image: the FDPs' vertices lock their
  // images too, the sizing sees the features and their images, the priority
  // breaks ties by a function of the far end that the mirror keeps, and the
  // collapses are made in mirror pairs (MirroredDecimater).
  double mid = 0;
  std::vector<int> mirror;
  if (has_l && has_r) {
    SkinMirror sm = skin_mirror(skin.V, {}, 0.5 * (eye_l.x() + eye_r.x()), kMirrorTolerance * es0);
    mid = sm.mid;
    mirror = std::move(sm.image);
  }
  if (!mirror.empty()) {
    for (int v = 0; v < n; ++v)
      if (locked[static_cast<size_t>(v)] && mirror[static_cast<size_t>(v)] >= 0)
        locked[static_cast<size_t>(mirror[static_cast<size_t>(v)])] = 1;
    for (std::vector<Eigen::Vector3d> *set : {&features, &lips}) {
      const size_t k = set->size();
      for (size_t i = 0; i < k; ++i) {
        Eigen::Vector3d image = (*set)[i];
        image.x() = 2 * mid - image.x();
        set->push_back(image);
      }
    }
  }

  TriMesh mesh;
  std::vector<TriMesh::VertexHandle> vh(static_cast<size_t>(n));
  for (int v = 0; v < n; ++v)
    vh[static_cast<size_t>(v)] = mesh.add_vertex(TriMesh::Point(skin.V(v, 0), skin.V(v, 1), skin.V(v, 2)));
  auto corner = [&](Eigen::Index f, int k) { return vh[static_cast<size_t>(skin.F(f, k))]; };
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f) {
    const TriMesh::FaceHandle fh = mesh.add_face(corner(f, 0), corner(f, 1), corner(f, 2));
    // check_skin() refuses non-manifold skins before a model is built; one
    // that gets here anyway is simulated as it is.
    if (!fh.is_valid()) return identity();
  }
  mesh.request_vertex_status();
  mesh.request_edge_status();
  mesh.request_halfedge_status();
  mesh.request_face_status();
  mesh.request_face_normals();
  mesh.update_face_normals();
  for (int v = 0; v < n; ++v)
    if (locked[static_cast<size_t>(v)]) mesh.status(vh[static_cast<size_t>(v)]).set_locked(true);
  keep_lids(mesh, skin, fit_eyeballs(scene));

  MirroredDecimater dec(mesh, mirror);
  ModSizedLengthT<TriMesh>::Handle length;
  OpenMesh::Decimater::ModNormalDeviationT<TriMesh>::Handle normal;
  OpenMesh::Decimater::ModHausdorffT<TriMesh>::Handle distance;
  OpenMesh::Decimater::ModAspectRatioT<TriMesh>::Handle aspect;
  dec.add(length);
  dec.add(normal);
  dec.add(distance);
  dec.add(aspect);
  dec.module(length).sizing = [&features, reach](const Eigen::Vector3d &x) {
    // One square root for the nearest: the same distance (sqrt is monotone),
    // without one per feature in every collapse's priority.
    double d2 = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d &f : features) d2 = std::min(d2, (x - f).squaredNorm());
    return kFeatureSizing + (1 - kFeatureSizing) * std::min(1.0, std::sqrt(d2) / reach);
  };
  // In [0, 1): height first, then depth, then distance from the mid-plane.
  const double extent = std::max((hi - lo).maxCoeff(), 1e-12);
  dec.module(length).tie = [lo, extent, mid](const Eigen::Vector3d &x) {
    return (0.5 * (x.y() - lo.y()) + 0.3 * (x.z() - lo.z()) + 0.2 * std::abs(x.x() - mid)) / (1.01 * extent);
  };
  dec.module(normal).set_normal_deviation(kMaxNormalTurnDegrees);
  dec.module(distance).set_tolerance(kMaxDistance * es0);
  dec.module(aspect).set_aspect_ratio(kMaxAspectRatio);
  dec.module(aspect).set_binary(true);
  if (!dec.initialize()) return identity();
  dec.set_order(&dec.module(length));
  // The shortest edges first (SimMeshOptions::short_edge), then the lips
  // kept and the rest.
  double edges = 0;
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) edges += (skin.V.row(skin.F(f, k)) - skin.V.row(skin.F(f, (k + 1) % 3))).norm();
  const double mean_edge = edges / std::max<double>(1, 3.0 * static_cast<double>(skin.F.rows()));
  dec.module(length).max_length = std::max(options.short_edge, 0.0) * mean_edge;
  dec.module(normal).set_normal_deviation(kShortEdgeNormalTurnDegrees);
  size_t micro_unpaired = 0, unpaired = 0;
  const size_t micro = options.short_edge > 0 ? dec.decimate_to(0, &micro_unpaired) : 0;
  dec.module(length).max_length = std::numeric_limits<double>::infinity();
  dec.module(normal).set_normal_deviation(kMaxNormalTurnDegrees);
  keep_lips(mesh, skin, lips, kLipKeep * es0, options.vertices / 2);
  dec.decimate_to(static_cast<size_t>(options.vertices) + micro, &unpaired);
  unpaired += micro_unpaired;

  // The survivors, in skin order, and their triangles (no garbage
  // collection: a handle's index is still its skin vertex).
  SimMesh sim;
  sim.skin = skin_index;
  sim.decimated = true;
  sim.mirrored = !mirror.empty();
  sim.unpaired = static_cast<int>(unpaired);
  sim.short_edges = static_cast<int>(micro);
  std::vector<int> coarse_of(static_cast<size_t>(n), -1);
  for (int v = 0; v < n; ++v)
    if (!mesh.status(vh[static_cast<size_t>(v)]).deleted()) {
      coarse_of[static_cast<size_t>(v)] = static_cast<int>(sim.kept.size());
      sim.kept.push_back(v);
    }
  sim.V.resize(static_cast<Eigen::Index>(sim.kept.size()), 3);
  for (size_t c = 0; c < sim.kept.size(); ++c) sim.V.row(static_cast<Eigen::Index>(c)) = skin.V.row(sim.kept[c]);
  std::vector<Eigen::Vector3i> tris;
  for (TriMesh::FaceHandle fh : mesh.faces()) {
    if (mesh.status(fh).deleted()) continue;
    Eigen::Vector3i t;
    int k = 0;
    for (TriMesh::VertexHandle v : mesh.fv_range(fh)) t[k++] = coarse_of[static_cast<size_t>(v.idx())];
    tris.push_back(t);
  }
  // A fixed face order whatever the decimater's internal one: by corners.
  for (Eigen::Vector3i &t : tris) {
    int m = 0;
    for (int k = 1; k < 3; ++k) if (t[k] < t[m]) m = k;
    t = Eigen::Vector3i(t[m], t[(m + 1) % 3], t[(m + 2) % 3]);
  }
  std::sort(tris.begin(), tris.end(), [](const Eigen::Vector3i &a, const Eigen::Vector3i &b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  sim.F.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t f = 0; f < tris.size(); ++f) sim.F.row(static_cast<Eigen::Index>(f)) = tris[f].transpose();
  sim.binding = bind_fine_to_coarse(skin, sim);
  sim.skin_V = skin.V;
  sim.skin_F = skin.F;
  sim.skin_rest = rest_faces(sim.skin_V, sim.skin_F);
  sim.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sim;
}

Scene sim_scene(const Scene &scene, const SimMesh &sim) {
  Scene out = scene;
  if (!sim.decimated) return out;
  Part &p = out.parts[static_cast<size_t>(sim.skin)];
  const Part &s = scene.parts[static_cast<size_t>(sim.skin)];
  p.V = sim.V;
  p.F = sim.F;
  p.TC.resize(0, 2);
  p.FTC.resize(0, 3);
  if (s.C.rows() == s.V.rows()) {
    p.C.resize(sim.V.rows(), 3);
    for (size_t c = 0; c < sim.kept.size(); ++c) p.C.row(static_cast<Eigen::Index>(c)) = s.C.row(sim.kept[c]);
  }
  return out;
}

FdpSet sim_fdps(const FdpSet &fdps, const SimMesh &sim) {
  FdpSet out = fdps;
  if (!sim.decimated) return out;
  const std::vector<int> coarse_of = coarse_index(sim, static_cast<int>(sim.binding.corner.rows()));
  for (FdpPoint &p : out.points)
    if (p.part == sim.skin && p.vertex >= 0) p.vertex = coarse_of[static_cast<size_t>(p.vertex)];
  return out;
}

FdpSet lift_fdps(const FdpSet &coarse, const SimMesh &sim) {
  FdpSet out = coarse;
  if (!sim.decimated) return out;
  for (FdpPoint &p : out.points)
    if (p.part == sim.skin && p.vertex >= 0) p.vertex = sim.kept[static_cast<size_t>(p.vertex)];
  return out;
}

Expected<std::vector<int>> muscle_key_vertices(const Scene &scene, const FdpSet &fdps, const TissueParams &tissue) {
  const int skin = scene.find_kind(PartKind::Skin);
  if (skin < 0) return Status::error("no skin part: no part holds FDP 2.1 (chin)");
  if (Status s = check_skin(scene, skin); !s) return s;
  Expected<SkinModel> t = build_skin_model(scene, skin, tissue, SkinBuild::Surfaces);
  if (!t) return t.status();
  std::vector<int> out;
  auto add = [&](int node) {
    if (node < 0) return;
    const int v = t->vertex_of(node);
    if (std::find(out.begin(), out.end(), v) == out.end()) out.push_back(v);
  };
  for (size_t d = 0; d < muscle_table().size(); ++d) {
    Expected<Muscle> m = place_muscle(*t, fdps, static_cast<int>(d));
    if (!m) continue;  // build_face_model says why
    add(m->node_a);
    add(m->node_b);
  }
  return out;
}

Expected<SimFaceModel> build_sim_face_model(const Scene &scene, const FdpSet &fdps, SimMeshOptions sim_options,
                                            const FaceModelOptions &options,
                                            const std::function<void(const SimMesh &)> &on_mesh) {
  std::vector<std::string> notes;
  // Missing FDPs are estimated on the skin itself, before the decimation,
  // which then keeps them: snapped to a coarse mesh, two estimates can
  // land on one vertex (Song's 9.6 and 9.7 did in a trial).
  FdpSet complete = fdps;
  std::vector<std::string> estimates;
  if (options.estimate_missing_fdps) {
    if (const int skin = scene.find_kind(PartKind::Skin); skin >= 0) {
      Expected<std::vector<FdpId>> added = complete_fdps(scene, skin, complete, anatomy_fdps(), &estimates);
      if (!added) return added.status();
    }
  }
  // (A skin they cannot be placed on fails build_face_model below, which
  // says why.)
  if (sim_options.vertices > 0)
    if (Expected<std::vector<int>> keys = muscle_key_vertices(scene, complete, options.tissue); keys)
      sim_options.keep.insert(sim_options.keep.end(), keys->begin(), keys->end());
  for (;;) {
    Expected<SimMesh> sim = make_sim_mesh(scene, complete, sim_options);
    if (!sim) return sim.status();
    if (on_mesh) on_mesh(*sim);
    Scene coarse = sim_scene(scene, *sim);
    Expected<FaceModel> model = build_face_model(coarse, sim_fdps(complete, *sim), options);
    if (model) {
      model->notes.insert(model->notes.begin(), estimates.begin(), estimates.end());
      return SimFaceModel{std::move(*sim), std::move(coarse), std::move(*model), std::move(notes)};
    }
    if (!sim->decimated) return model.status();
    const int skin_vertices = static_cast<int>(sim->binding.corner.rows());
    const int finer = sim_options.vertices * 3 / 2;
    sim_options.vertices = finer * 5 < skin_vertices * 4 ? finer : 0;
    notes.push_back("on the " + std::to_string(sim->kept.size()) + "-vertex simulation mesh: " +
                    model.status().message() + "; tried " +
                    (sim_options.vertices ? std::to_string(sim_options.vertices) + " vertices" : "the whole skin"));
  }
}

Eigen::MatrixXd lift_displacement(const SimMesh &sim, const Eigen::MatrixXd &Dc) {
  if (Dc.rows() == 0) return Dc;
  return carried_displacement(sim.binding, Dc);
}

std::vector<int> lifted_turned_faces(const SimMesh &sim, const Eigen::MatrixXd &Dc, double *share) {
  Eigen::MatrixXd V = lift_displacement(sim, Dc);
  V += sim.skin_V;
  return turned_faces(sim.skin_rest, sim.skin_F, V, share);
}

}  // namespace afmb
