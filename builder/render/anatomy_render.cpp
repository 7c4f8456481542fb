#include "render/anatomy_render.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

#include "core/ray_triangle.h"
#include "render/scene_render.h"

// How the overlays are placed. The muscles' nodes lie inside the tissue
// (attachments on the skull, insertions on the dermis, sphincter key nodes
// on the hypodermis), so a picture of the nodes themselves would hide them
// under the skin. Every inner node lies on the line from its epidermal node
// to the skin's centre c (skin_model.h), so a node is drawn at its epidermal
// node and a fibre at its projection onto the epidermis from c: each sample
// of the segment is pushed along its ray from c to the outermost skin
// crossing. A sphincter's ellipse is in the x-y plane (its influence test
// is), so it is drawn where the skin meets the elliptic cylinder: each
// sample is projected along -z onto the frontmost skin. These lie on the
// surface and get a small depth bias (1 % of the skin's box diagonal). The
// influence picture draws the fibre or ellipse without the key-node dots,
// which would vanish in its red and green areas.
//
// The jaw mesh and its pivot are deeper (the skull surface, the condyles'
// axis in the middle of the head) and are drawn "x-ray": their bias brings
// them in front of every skin vertex in both views.
//
// Lines are dense dots (about 1/600 of the skin's diagonal apart) with a
// dark outline (a larger dark dot under each) so white reads on any tone.

namespace afmb {

namespace {

constexpr double kPi = 3.14159265358979323846;

const Eigen::Vector3d kSkinTone(0.80, 0.69, 0.61);
const Eigen::Vector3f kWhite(1.0f, 1.0f, 1.0f);
const Eigen::Vector3f kRed(0.95f, 0.12f, 0.10f);
const Eigen::Vector3f kGreen(0.12f, 0.82f, 0.22f);
const Eigen::Vector3f kYellow(1.0f, 0.88f, 0.05f);
const Eigen::Vector3f kMagenta(0.95f, 0.20f, 0.85f);
const Eigen::Vector3f kOutline(0.07f, 0.07f, 0.07f);
const Eigen::Vector3d kHiRed(0.90, 0.08, 0.06);
const Eigen::Vector3d kHiGreen(0.10, 0.72, 0.18);
const Eigen::Vector3d kHiViolet(0.42, 0.22, 0.90);
const Eigen::Vector3d kHiCyan(0.05, 0.85, 0.92);
const Eigen::Vector3d kHiOrange(1.00, 0.52, 0.00);

// Marker sizes in pixels for 600 x 720 views.
const float kLinePixels = 3.0f, kDotPixels = 9.0f, kOutlinePixels = 2.5f;

// Scale of the picture, from the skin at rest.
struct Scale {
  double diagonal = 1;
  double spacing = 0;  // between the dots of a line
  double bias = 0;     // depth bias of overlays lying on the skin
  double step = 0;     // bias step between overlay layers (outline, core, dots)
};

Scale picture_scale(const Eigen::MatrixXd &skin) {
  Scale s;
  const Eigen::Vector3d lo = skin.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = skin.colwise().maxCoeff().transpose();
  s.diagonal = std::max((hi - lo).norm(), 1e-12);
  s.spacing = s.diagonal / 600.0;
  s.bias = 0.01 * s.diagonal;
  s.step = 0.004 * s.diagonal;
  return s;
}

// The scene, the model and the options fit together.
Status check_inputs(const Scene &scene, const FaceModel &model, const std::string &path,
                    const AnatomyPictureOptions &options) {
  if (options.width <= 0 || options.height <= 0)
    return Status::error(path + ": need a positive picture size (" + std::to_string(options.width) +
                         " x " + std::to_string(options.height) + ")");
  if (model.skin < 0 || model.skin >= (int)scene.parts.size())
    return Status::error(path + ": the model's skin part " + std::to_string(model.skin) +
                         " is not in the scene (" + std::to_string(scene.parts.size()) + " parts)");
  const Part &skin = scene.parts[model.skin];
  const int n = model.tissue.n;
  if (n <= 0 || skin.V.rows() != n || model.tissue.X0.rows() != 4 * (Eigen::Index)n ||
      model.tissue.X0.cols() != 3)
    return Status::error(path + ": the model does not match the scene (skin part '" + skin.name +
                         "' has " + std::to_string(skin.V.rows()) + " vertices, the tissue " +
                         std::to_string(n) + " per layer)");
  return Status::ok();
}

Eigen::MatrixXd rows_of(const std::vector<Eigen::Vector3d> &points) {
  Eigen::MatrixXd m((Eigen::Index)points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) m.row((Eigen::Index)i) = points[i].transpose();
  return m;
}

// Dots of size `pixels` in `color` over a slightly larger dark outline; the
// core is `lift` nearer than the outline (more than the depth between
// neighbouring dots, so no outline covers a core of the same set).
void add_outlined(std::vector<SceneMarkers> &out, const Eigen::MatrixXd &points,
                  const Eigen::Vector3f &color, float pixels, double bias, double lift) {
  if (points.rows() == 0) return;
  SceneMarkers outline;
  outline.points = points;
  outline.color = kOutline;
  outline.size_pixels = pixels + kOutlinePixels;
  outline.depth_bias = (float)bias;
  out.push_back(outline);
  SceneMarkers core;
  core.points = points;
  core.color = color;
  core.size_pixels = pixels;
  core.depth_bias = (float)(bias + lift);
  out.push_back(std::move(core));
}

// The epidermis at rest, for projecting overlays onto it.
class Epidermis {
 public:
  explicit Epidermis(const SkinModel &tissue)
      : V_(tissue.X0.topRows(tissue.n)), F_(tissue.F), centre_(tissue.centre) {}

  const Eigen::MatrixXd &V() const { return V_; }
  Eigen::Vector3d vertex(int v) const { return V_.row(v).transpose(); }

  // Samples of segment a-b (inner positions) projected from the centre onto
  // the outermost skin; a ray that meets no skin keeps the point of the
  // chord a0-b0 (the ends' epidermal positions).
  std::vector<Eigen::Vector3d> project_segment(const Eigen::Vector3d &a, const Eigen::Vector3d &b,
                                               const Eigen::Vector3d &a0, const Eigen::Vector3d &b0,
                                               double spacing) const {
    const int count = std::clamp((int)std::ceil((a0 - b0).norm() / spacing) + 1, 16, 4000);
    // Every ray lies in the plane through c, a and b: only triangles
    // straddling it, on the side of the segment, can be hit.
    const Eigen::Vector3d da = a - centre_, db = b - centre_;
    const Eigen::Vector3d normal = da.cross(db);
    const Eigen::Vector3d ahead = da.normalized() + db.normalized();
    const bool planar = normal.norm() > 1e-12 * da.norm() * db.norm();
    std::vector<int> candidates;
    for (int f = 0; f < F_.rows(); ++f) {
      double lo = std::numeric_limits<double>::max(), hi = -lo;
      bool front = false;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d p = V_.row(F_(f, k)).transpose() - centre_;
        const double s = normal.dot(p);
        lo = std::min(lo, s);
        hi = std::max(hi, s);
        front = front || p.dot(ahead) > 0;
      }
      if (front && (!planar || (lo <= 0 && hi >= 0))) candidates.push_back(f);
    }
    std::vector<Eigen::Vector3d> out;
    out.reserve((size_t)count);
    for (int i = 0; i < count; ++i) {
      const double s = (double)i / (count - 1);
      const Eigen::Vector3d p = a + s * (b - a);
      const Eigen::Vector3d dir = p - centre_;
      double best = -1;
      for (int f : candidates) {
        double t;
        if (ray_triangle(centre_, dir, corner(f, 0), corner(f, 1), corner(f, 2), &t) && t > best)
          best = t;
      }
      out.push_back(best > 0 ? Eigen::Vector3d(centre_ + best * dir)
                             : Eigen::Vector3d(a0 + s * (b0 - a0)));
    }
    return out;
  }

  // The ellipse (x - e.x)^2 / ra^2 + (y - e.y)^2 / rb^2 = 1 projected along -z
  // onto the frontmost skin; a sample that meets no skin stays at e.z.
  std::vector<Eigen::Vector3d> project_ellipse(const Eigen::Vector3d &e, double ra, double rb,
                                               double spacing) const {
    const double perimeter =
        kPi * (3 * (ra + rb) - std::sqrt((3 * ra + rb) * (ra + 3 * rb)));  // Ramanujan
    const int count = std::clamp((int)std::ceil(perimeter / spacing), 32, 8000);
    const double xlo = e.x() - ra, xhi = e.x() + ra, ylo = e.y() - rb, yhi = e.y() + rb;
    std::vector<int> candidates;
    for (int f = 0; f < F_.rows(); ++f) {
      double bx0 = std::numeric_limits<double>::max(), bx1 = -bx0, by0 = bx0, by1 = -bx0;
      for (int k = 0; k < 3; ++k) {
        bx0 = std::min(bx0, V_(F_(f, k), 0));
        bx1 = std::max(bx1, V_(F_(f, k), 0));
        by0 = std::min(by0, V_(F_(f, k), 1));
        by1 = std::max(by1, V_(F_(f, k), 1));
      }
      if (bx1 >= xlo && bx0 <= xhi && by1 >= ylo && by0 <= yhi) candidates.push_back(f);
    }
    const double top = V_.col(2).maxCoeff() + 1.0 + std::abs(V_.col(2).maxCoeff());
    const Eigen::Vector3d down(0, 0, -1);
    std::vector<Eigen::Vector3d> out;
    out.reserve((size_t)count);
    for (int i = 0; i < count; ++i) {
      const double angle = 2 * kPi * i / count;
      const double x = e.x() + ra * std::cos(angle), y = e.y() + rb * std::sin(angle);
      const Eigen::Vector3d o(x, y, top);
      double best = std::numeric_limits<double>::max();
      for (int f : candidates) {
        double t;
        if (ray_triangle(o, down, corner(f, 0), corner(f, 1), corner(f, 2), &t) && t > 0 &&
            t < best)
          best = t;
      }
      out.emplace_back(x, y, best < std::numeric_limits<double>::max() ? top - best : e.z());
    }
    return out;
  }

 private:
  Eigen::Vector3d corner(int f, int k) const { return V_.row(F_(f, k)).transpose(); }

  Eigen::MatrixXd V_;
  Eigen::MatrixXi F_;
  Eigen::Vector3d centre_;
};

bool node_ok(const FaceModel &model, int node) {
  return node >= 0 && node < model.tissue.X0.rows();
}

Status check_muscle(const FaceModel &model, const Muscle &m, const std::string &path) {
  if (!node_ok(model, m.node_a) || !node_ok(model, m.node_b))
    return Status::error(path + ": muscle " + m.name + " has a node out of range (" +
                         std::to_string(m.node_a) + ", " + std::to_string(m.node_b) + " of " +
                         std::to_string(model.tissue.X0.rows()) + ")");
  if (m.kind == MuscleKind::Sphincter && !(m.area_a > 0 && m.area_b > 0))
    return Status::error(path + ": sphincter " + m.name + " has no semi-axes");
  return Status::ok();
}

// A muscle's fibre or ellipse (white) and, with `key_dots`, its key nodes:
// linear attachment green and insertion red, sphincter semi-axis nodes red;
// a lid driver's line from its margin (red) to the other lid's. A muscle
// inside the tissue it moves (MuscleDef::whole_thickness: the lips' and the
// nose's drivers, the cheek puffs) shows its insertion only: its fibre
// starts at a point inside the mouth or the nose, or beside the nose's
// tip, not on the skull.
void muscle_overlay(const FaceModel &model, const Epidermis &skin, const Scale &scale,
                    const Muscle &m, bool key_dots, std::vector<SceneMarkers> &lines,
                    std::vector<SceneMarkers> &dots) {
  const SkinModel &t = model.tissue;
  const Eigen::Vector3d a = t.X0.row(m.node_a).transpose(), b = t.X0.row(m.node_b).transpose();
  const Eigen::Vector3d a0 = skin.vertex(t.vertex_of(m.node_a));
  const Eigen::Vector3d b0 = skin.vertex(t.vertex_of(m.node_b));
  const double dot_bias = scale.bias + 2 * scale.step;  // key dots over the lines
  if (muscle_table()[static_cast<size_t>(m.def)].whole_thickness) {
    if (key_dots) add_outlined(dots, rows_of({b0}), kRed, kDotPixels, dot_bias, scale.step);
  } else if (m.kind != MuscleKind::Sphincter) {
    add_outlined(lines, rows_of(skin.project_segment(a, b, a0, b0, scale.spacing)), kWhite,
                 kLinePixels, scale.bias, scale.step);
    if (key_dots && m.kind == MuscleKind::Lid) {
      add_outlined(dots, rows_of({a0}), kRed, kDotPixels, dot_bias, scale.step);
    } else if (key_dots) {
      add_outlined(dots, rows_of({a0}), kGreen, kDotPixels, dot_bias, scale.step);
      add_outlined(dots, rows_of({b0}), kRed, kDotPixels, dot_bias, scale.step);
    }
  } else {
    const Eigen::MatrixXd ellipse =
        rows_of(skin.project_ellipse(m.epicentre, m.area_a, m.area_b, scale.spacing));
    add_outlined(lines, ellipse, kWhite, kLinePixels, scale.bias, scale.step);
    if (key_dots)
      add_outlined(dots, rows_of({a0, b0}), kRed, kDotPixels, dot_bias, scale.step);
  }
}

std::vector<SceneView> picture_views(const AnatomyPictureOptions &options) {
  std::vector<SceneView> views{SceneView{0.0f, 0.0f}};
  if (!options.front_only) views.push_back(SceneView{35.0f, 5.0f});
  return views;
}

// A depth bias that brings every point in front of every skin vertex, seen
// from each view (the camera's direction from the target as the renderer
// computes it).
double xray_bias(const Eigen::MatrixXd &points, const Eigen::MatrixXd &skin, const Scale &scale,
                 const std::vector<SceneView> &views) {
  double bias = scale.bias;
  for (const SceneView &v : views) {
    const double yaw = v.yaw_deg * kPi / 180, pitch = v.pitch_deg * kPi / 180;
    const Eigen::Vector3d toward(std::sin(yaw) * std::cos(pitch), std::sin(pitch),
                                 std::cos(yaw) * std::cos(pitch));
    const double front = (skin * toward).maxCoeff();
    const double deepest = (points * toward).minCoeff();
    bias = std::max(bias, front - deepest + 0.02 * scale.diagonal);
  }
  return bias;
}

// The scene with the skin in a neutral tone and `paint` (vertex, colour)
// applied over it.
Scene painted(const Scene &scene, const FaceModel &model,
              const std::vector<std::pair<const std::vector<int> *, Eigen::Vector3d>> &paint) {
  Scene out = scene;
  Part &skin = out.parts[model.skin];
  skin.C.resize(skin.V.rows(), 3);
  skin.C.rowwise() = kSkinTone.transpose();
  for (const auto &[vertices, colour] : paint)
    for (int v : *vertices)
      if (v >= 0 && v < skin.C.rows()) skin.C.row(v) = colour.transpose();
  return out;
}

Status draw(const Scene &scene, const FaceModel &model, std::vector<SceneMarkers> markers,
            const std::string &path, const AnatomyPictureOptions &options) {
  SceneRenderOptions ro;
  ro.width = options.width;
  ro.height = options.height;
  ro.views = picture_views(options);
  ro.fdp_dot_pixels = 0;
  ro.face_closeup = true;
  // Sizes are for 600 x 720 views; smaller or larger pictures scale them.
  const float zoom =
      std::clamp(std::min(options.width / 600.0f, options.height / 720.0f), 0.5f, 3.0f);
  for (SceneMarkers &m : markers) m.size_pixels *= zoom;
  ro.markers = std::move(markers);
  Status st = render_scene_png(scene, &model.fdps, ro, path);
  if (!st && st.message().find(path) == std::string::npos) return st.wrap(path);
  return st;
}

void append(std::vector<SceneMarkers> &to, std::vector<SceneMarkers> &from) {
  for (SceneMarkers &m : from) to.push_back(std::move(m));
  from.clear();
}

}  // namespace

Status render_muscle_map_png(const Scene &scene, const FaceModel &model, const std::string &path,
                             const AnatomyPictureOptions &options) {
  if (Status st = check_inputs(scene, model, path, options); !st) return st;
  const Epidermis skin(model.tissue);
  const Scale scale = picture_scale(skin.V());
  std::vector<SceneMarkers> lines, dots;
  for (const Muscle &m : model.muscles) {
    if (Status st = check_muscle(model, m, path); !st) return st;
    muscle_overlay(model, skin, scale, m, true, lines, dots);
  }
  append(lines, dots);
  return draw(painted(scene, model, {}), model, std::move(lines), path, options);
}

Status render_influence_png(const Scene &scene, const FaceModel &model, int muscle,
                            const std::string &path, const AnatomyPictureOptions &options) {
  if (Status st = check_inputs(scene, model, path, options); !st) return st;
  if (muscle < 0 || muscle >= (int)model.muscles.size())
    return Status::error(path + ": muscle index " + std::to_string(muscle) + " out of range (" +
                         std::to_string(model.muscles.size()) + " muscles)");
  const Muscle &m = model.muscles[muscle];
  if (Status st = check_muscle(model, m, path); !st) return st;
  const Epidermis skin(model.tissue);
  const Scale scale = picture_scale(skin.V());
  std::vector<SceneMarkers> lines, dots;
  muscle_overlay(model, skin, scale, m, false, lines, dots);
  // V_d green first, the influence area red over it.
  const Scene s = painted(scene, model, {{&m.dynamic, kHiGreen}, {&m.influence, kHiRed}});
  return draw(s, model, std::move(lines), path, options);
}

Status render_jaw_map_png(const Scene &scene, const FaceModel &model, const std::string &path,
                          const AnatomyPictureOptions &options) {
  if (Status st = check_inputs(scene, model, path, options); !st) return st;
  const Jaw &jaw = model.jaw;
  if (jaw.V.cols() != 3 || jaw.F.cols() != 3 || jaw.V.rows() == 0)
    return Status::error(path + ": the model has no jaw mesh");
  if (jaw.F.rows() > 0 && (jaw.F.minCoeff() < 0 || jaw.F.maxCoeff() >= jaw.V.rows()))
    return Status::error(path + ": the jaw mesh has a triangle out of range");
  std::vector<int> kept, added, removed;
  std::set_intersection(jaw.ray_hits.begin(), jaw.ray_hits.end(), jaw.vertices.begin(),
                        jaw.vertices.end(), std::back_inserter(kept));
  std::set_difference(jaw.vertices.begin(), jaw.vertices.end(), jaw.ray_hits.begin(),
                      jaw.ray_hits.end(), std::back_inserter(added));
  std::set_difference(jaw.ray_hits.begin(), jaw.ray_hits.end(), jaw.vertices.begin(),
                      jaw.vertices.end(), std::back_inserter(removed));
  Scene s = painted(scene, model, {{&kept, kHiViolet}, {&added, kHiCyan}, {&removed, kHiOrange}});
  // The followers in violet by their share of the jaw's motion.
  Eigen::MatrixXd &colour = s.parts[model.skin].C;
  for (const auto &[v, share] : jaw.followers)
    if (v >= 0 && v < colour.rows())
      colour.row(v) = ((1 - share) * kSkinTone + share * kHiViolet).transpose();

  const Epidermis skin(model.tissue);
  const Scale scale = picture_scale(skin.V());
  // The mesh's edges, each once, as dots.
  std::vector<std::pair<int, int>> edges;
  for (int f = 0; f < jaw.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = jaw.F(f, k), j = jaw.F(f, (k + 1) % 3);
      edges.emplace_back(std::min(i, j), std::max(i, j));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<Eigen::Vector3d> edge_dots;
  for (const auto &[i, j] : edges) {
    const Eigen::Vector3d a = jaw.V.row(i).transpose(), b = jaw.V.row(j).transpose();
    const int count = std::clamp((int)std::ceil((b - a).norm() / scale.spacing) + 1, 2, 4000);
    for (int c = 0; c < count; ++c) edge_dots.push_back(a + (b - a) * ((double)c / (count - 1)));
  }
  const Eigen::MatrixXd edge_points = rows_of(edge_dots), pivot = rows_of({jaw.pivot});
  const std::vector<SceneView> views = picture_views(options);
  std::vector<SceneMarkers> markers;
  const double edge_bias = xray_bias(edge_points, skin.V(), scale, views);
  // (Where edges cross, the nearer one's outline cuts the farther one: a
  // larger lift would push the cores past the camera's near plane.)
  add_outlined(markers, edge_points, kWhite, kLinePixels, edge_bias, scale.step);
  const double pivot_bias =
      std::max(xray_bias(pivot, skin.V(), scale, views), edge_bias + scale.step) + scale.step;
  add_outlined(markers, pivot, kYellow, kDotPixels + 2, pivot_bias, scale.step);
  // The lips' contact pairs: both vertices of each (one dot where they
  // coincide, as on a seam of cut lips).
  std::vector<Eigen::Vector3d> lip_dots;
  for (const LipPair &p : model.tissue.lip_pairs)
    for (int g : {p.upper, p.lower}) lip_dots.push_back(model.tissue.X0.row(g).transpose());
  if (!lip_dots.empty()) {
    const Eigen::MatrixXd lips = rows_of(lip_dots);
    add_outlined(markers, lips, kMagenta, kDotPixels - 3, std::max(xray_bias(lips, skin.V(), scale, views), pivot_bias),
                 scale.step);
  }
  return draw(s, model, std::move(markers), path, options);
}

Status render_pose_png(const Scene &scene, const FaceModel &model, const Pose &pose,
                       const Eigen::Affine3d &jaw, const std::string &path,
                       const AnatomyPictureOptions &options) {
  if (Status st = check_inputs(scene, model, path, options); !st) return st;
  if (pose.X.rows() != 4 * model.tissue.n || pose.X.cols() != 3)
    return Status::error(path + ": the pose has " + std::to_string(pose.X.rows()) + " x " +
                         std::to_string(pose.X.cols()) + " node positions, the model " +
                         std::to_string(4 * model.tissue.n) + " x 3");
  if (!pose.X.allFinite()) return Status::error(path + ": the pose has non-finite positions");
  // The skin over each slab of tissue the pose turns through itself: the
  // corners of its triangle.
  std::vector<int> over;
  for (const auto &[f, slab] : turned_slabs(model.tissue, pose.X))
    for (int k = 0; k < 3; ++k) over.push_back(model.tissue.F(f, k));
  Scene s = painted(scene, model, {{&over, kHiRed}});
  s.parts[model.skin].V = pose_epidermis(model, pose);
  for (Part &p : s.parts) {
    if (p.kind == PartKind::TeethLower || p.kind == PartKind::Tongue) p.V = moved_points(jaw, p.V);
  }
  return draw(s, model, {}, path, options);
}

}  // namespace afmb
