#include "anatomy/fdp_completion.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "anatomy/muscle_table.h"

namespace afmb {

namespace {
// The local fit's reach on the reference head (metres), and the weight every
// shared FDP keeps however far (the global fit underneath). Leave-one-out on
// Song's 39 skin FDPs: mean error 4.6 (global fit) -> 3.5 model units.
constexpr double kSigma = 0.03;
constexpr double kFloor = 0.02;

// The template: the 1000-vertex reference head's FDPs (builder/refhead) in
// metres, rounded to the micrometre, first point of each; 7.1 and 11.5 are
// not surface points. Frozen here so that the generator's mesh can change
// (its rows, its resolution) without moving a real face's estimates and so
// its AFM. tests/anatomy compares it with the generator's FDPs.
struct TemplateFdp {
  int group, index;
  double pos[3];
};
constexpr TemplateFdp kTemplate[] = {
    {2, 1, {0.000000, -0.111016, 0.073890}},
    {2, 2, {0.000000, -0.060000, 0.094624}},
    {2, 3, {0.000000, -0.060000, 0.094624}},
    {2, 4, {0.025247, -0.060000, 0.080910}},
    {2, 5, {-0.025247, -0.060000, 0.080910}},
    {2, 6, {0.015898, -0.060000, 0.087073}},
    {2, 7, {-0.015898, -0.060000, 0.087073}},
    {2, 8, {0.015898, -0.060000, 0.087073}},
    {2, 9, {-0.015898, -0.060000, 0.087073}},
    {2, 10, {0.000000, -0.096664, 0.091423}},
    {2, 11, {0.020229, -0.109218, 0.067777}},
    {2, 12, {-0.020229, -0.109218, 0.067777}},
    {2, 13, {0.055431, -0.078685, 0.002705}},
    {2, 14, {-0.055431, -0.078685, 0.002705}},
    {3, 1, {0.031480, 0.005900, 0.078142}},
    {3, 2, {-0.031480, 0.005900, 0.078142}},
    {3, 3, {0.031480, -0.005900, 0.078142}},
    {3, 4, {-0.031480, -0.005900, 0.078142}},
    {3, 5, {0.031500, 0.000000, 0.078200}},
    {3, 6, {-0.031500, 0.000000, 0.078200}},
    {3, 7, {0.044752, 0.000000, 0.063425}},
    {3, 8, {-0.020796, 0.000000, 0.074226}},
    {3, 9, {0.033938, -0.012486, 0.079862}},
    {3, 10, {-0.033938, -0.012486, 0.079862}},
    {3, 11, {0.020796, 0.000000, 0.074226}},
    {3, 12, {-0.044752, 0.000000, 0.063425}},
    {3, 13, {0.030973, 0.011346, 0.073837}},
    {3, 14, {-0.030973, 0.011346, 0.073837}},
    {4, 1, {0.018455, 0.013848, 0.087899}},
    {4, 2, {-0.018455, 0.013848, 0.087899}},
    {4, 3, {0.034541, 0.026797, 0.079659}},
    {4, 4, {-0.034541, 0.026797, 0.079659}},
    {4, 5, {0.053624, 0.017435, 0.060274}},
    {4, 6, {-0.053624, 0.017435, 0.060274}},
    {5, 1, {0.049345, -0.050696, 0.067463}},
    {5, 2, {-0.049345, -0.050696, 0.067463}},
    {5, 3, {0.044660, -0.021320, 0.080822}},
    {5, 4, {-0.044660, -0.021320, 0.080822}},
    {6, 1, {0.000000, -0.070200, 0.080000}},
    {6, 2, {0.000000, -0.064200, 0.050000}},
    {6, 3, {0.018500, -0.070200, 0.050000}},
    {6, 4, {-0.018500, -0.070200, 0.050000}},
    {8, 1, {0.000000, -0.052318, 0.100365}},
    {8, 2, {0.000000, -0.075336, 0.091536}},
    {8, 3, {0.025247, -0.060000, 0.080910}},
    {8, 4, {-0.025247, -0.060000, 0.080910}},
    {8, 5, {0.015014, -0.049221, 0.090524}},
    {8, 6, {-0.015014, -0.049221, 0.090524}},
    {8, 7, {0.015517, -0.070974, 0.088086}},
    {8, 8, {-0.015517, -0.070974, 0.088086}},
    {8, 9, {-0.008094, -0.048783, 0.096292}},
    {8, 10, {0.008094, -0.048783, 0.096292}},
    {9, 1, {0.019268, -0.030279, 0.086804}},
    {9, 2, {-0.019268, -0.030279, 0.086804}},
    {9, 3, {0.000000, -0.015132, 0.110196}},
    {9, 4, {-0.014717, -0.030833, 0.093339}},
    {9, 5, {0.014717, -0.030833, 0.093339}},
    {9, 6, {-0.008430, 0.005510, 0.090345}},
    {9, 7, {0.008430, 0.005510, 0.090345}},
    {9, 8, {0.000000, -0.050700, 0.087945}},
    {9, 9, {0.000000, -0.071300, 0.087945}},
    {9, 10, {0.000000, -0.061500, 0.085868}},
    {9, 11, {0.000000, -0.061500, 0.085868}},
    {9, 12, {0.000000, -0.015132, 0.110196}},
    {9, 13, {0.008434, -0.012377, 0.099693}},
    {9, 14, {-0.008434, -0.012377, 0.099693}},
    {9, 15, {0.000000, -0.039500, 0.087553}},
    {10, 1, {0.081730, 0.017780, -0.024370}},
    {10, 2, {-0.081730, 0.017780, -0.024370}},
    {10, 3, {0.088596, -0.011574, -0.024882}},
    {10, 4, {-0.088596, -0.011574, -0.024882}},
    {10, 5, {0.074876, -0.033242, -0.008737}},
    {10, 6, {-0.074876, -0.033242, -0.008737}},
    {10, 7, {0.068501, -0.021228, 0.004034}},
    {10, 8, {-0.068501, -0.021228, 0.004034}},
    {10, 9, {0.079297, 0.007488, -0.011456}},
    {10, 10, {-0.079297, 0.007488, -0.011456}},
    {11, 1, {0.000000, 0.085785, 0.062003}},
    {11, 2, {-0.041684, 0.065913, 0.055998}},
    {11, 3, {0.041684, 0.065913, 0.055998}},
    {11, 4, {0.000000, 0.120980, -0.012000}},
    {11, 6, {0.000000, 0.022875, -0.110853}},
};

const TemplateFdp *template_fdp(const FdpId &id) {
  for (const TemplateFdp &t : kTemplate)
    if (t.group == id.group && t.index == id.index) return &t;
  return nullptr;
}
Eigen::Vector3d template_pos(const TemplateFdp &t) { return Eigen::Vector3d(t.pos[0], t.pos[1], t.pos[2]); }
}  // namespace

std::vector<FdpId> anatomy_fdps() {
  std::vector<FdpId> out;
  auto add = [&](const FdpId &id) {
    if (std::find(out.begin(), out.end(), id) == out.end()) out.push_back(id);
  };
  for (const MuscleDef &d : muscle_table())
    for (const char *text : {d.attachment_or_major, d.insertion_or_minor, d.epicentre, d.corner_outer, d.corner_inner}) {
      if (!text) continue;
      Expected<Keypoint> k = parse_keypoint(text);
      if (k)
        for (const auto &t : k->terms) add(t.first);
    }
  for (const char *id : {"2.1", "2.2", "2.3", "2.4", "2.5", "2.8", "2.9", "2.11", "2.12", "2.13", "2.14",
                         "5.3", "5.4", "9.15"})
    add(*FdpId::parse(id));
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<FdpId, Eigen::Vector3d>> fdp_template() {
  std::vector<std::pair<FdpId, Eigen::Vector3d>> out;
  for (const TemplateFdp &t : kTemplate) out.emplace_back(FdpId{t.group, t.index}, template_pos(t));
  return out;
}

Expected<std::vector<FdpId>> complete_fdps(const Scene &scene, int skin, FdpSet &fdps,
                                           const std::vector<FdpId> &wanted,
                                           std::vector<std::string> *notes) {
  std::vector<FdpId> missing;
  for (const FdpId &id : wanted)
    if (!fdps.find(id)) missing.push_back(id);
  if (missing.empty()) return missing;
  if (skin < 0 || skin >= static_cast<int>(scene.parts.size()))
    return Status::error("FDP estimates: no skin part");

  // Shared FDPs (vertex points of the face, or free points).
  std::vector<Eigen::Vector3d> from, to;
  for (const TemplateFdp &t : kTemplate) {
    const FdpPoint *q = fdps.find(FdpId{t.group, t.index});
    if (!q || (q->part >= 0 && q->vertex < 0)) continue;
    from.push_back(template_pos(t));
    to.push_back(q->pos);
  }
  if (from.size() < 8)
    return Status::error("FDP estimates need at least 8 FDPs shared with the reference head, the file has " +
                         std::to_string(from.size()));
  const Eigen::Index nf = static_cast<Eigen::Index>(from.size());
  Eigen::MatrixXd A(nf, 4), B(nf, 3);
  for (Eigen::Index i = 0; i < nf; ++i) {
    A.row(i) << from[static_cast<size_t>(i)].transpose(), 1.0;
    B.row(i) = to[static_cast<size_t>(i)].transpose();
  }
  // The affine map near `at` (a reference-head point): each shared FDP
  // weighted by a Gaussian of its distance from there, plus a small constant
  // that keeps the fit determined where few FDPs are near.
  auto fit = [&](const Eigen::Vector3d &at, double *rms) {
    Eigen::VectorXd w(nf);
    for (Eigen::Index i = 0; i < nf; ++i) {
      const double d = (from[static_cast<size_t>(i)] - at).norm() / kSigma;
      w[i] = std::sqrt(std::exp(-d * d) + kFloor);
    }
    const Eigen::MatrixXd M = (w.asDiagonal() * A).colPivHouseholderQr().solve(w.asDiagonal() * B);  // 4 x 3
    *rms = std::sqrt((w.asDiagonal() * (A * M - B)).squaredNorm() / w.squaredNorm());
    return M;
  };

  const Part &part = scene.parts[static_cast<size_t>(skin)];
  std::vector<uint8_t> used(static_cast<size_t>(part.V.rows()), 0);
  for (int f = 0; f < part.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[static_cast<size_t>(part.F(f, k))] = 1;
  for (const FdpId &id : missing) {
    const TemplateFdp *r = template_fdp(id);
    if (!r) return Status::error("FDP estimates: the reference head's template lacks FDP " + id.str());
    const Eigen::Vector3d at = template_pos(*r);
    Eigen::RowVector4d h;
    h << at.transpose(), 1.0;
    double rms = 0;
    const Eigen::Vector3d est = (h * fit(at, &rms)).transpose();
    int best = -1;
    double bd = 0;
    for (int v = 0; v < part.V.rows(); ++v) {
      if (!used[static_cast<size_t>(v)]) continue;
      const double d = (part.V.row(v).transpose() - est).squaredNorm();
      if (best < 0 || d < bd) best = v, bd = d;
    }
    if (best < 0) return Status::error("FDP estimates: the skin has no triangles");
    FdpPoint p;
    p.id = id;
    p.part_name = part.name;
    p.part = skin;
    p.vertex = best;
    p.pos = part.V.row(best).transpose();
    fdps.points.push_back(p);
    if (notes) {
      char line[256];
      std::snprintf(line, sizeof line,
                    "FDP %s absent: estimated from the reference head (local affine fit to %zu FDPs, rms %.3g): "
                    "skin vertex %d",
                    id.str().c_str(), from.size(), rms, best);
      notes->push_back(line);
    }
  }
  return missing;
}

}  // namespace afmb
