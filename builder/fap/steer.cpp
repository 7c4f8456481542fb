#include "fap/steer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

namespace afmb {

namespace {

// Node `node`'s motion in `r` (zero where r does not move it) and r's
// largest node motion.
Eigen::Vector3d motion_of(const NodeDisplacement &r, int node, double *largest) {
  *largest = r.displacement.rows() > 0 ? r.displacement.rowwise().norm().maxCoeff() : 0;
  for (size_t k = 0; k < r.nodes.size(); ++k)
    if (r.nodes[k] == node) return r.displacement.row(static_cast<Eigen::Index>(k)).transpose();
  return Eigen::Vector3d::Zero();
}

// Two variables per helper, from its signed contraction c.
std::vector<double> split(const std::vector<double> &c) {
  std::vector<double> x(2 * c.size());
  for (size_t h = 0; h < c.size(); ++h) x[2 * h] = std::max(c[h], 0.0), x[2 * h + 1] = std::max(-c[h], 0.0);
  return x;
}

}  // namespace

std::vector<HelperColumn> helper_columns(const FaceModel &model, const std::vector<std::string> &names,
                                         const std::vector<std::pair<int, double>> &group, int vertex) {
  std::vector<HelperColumn> out;
  const int node = model.tissue.node(kEpidermis, vertex);
  for (const std::string &name : names) {
    const int i = model.find(name);
    if (i < 0) continue;
    if (std::any_of(group.begin(), group.end(), [i](const std::pair<int, double> &g) { return g.first == i; }))
      continue;
    const Muscle &m = model.muscles[static_cast<size_t>(i)];
    HelperColumn c;
    c.muscle = i;
    if (m.name.rfind("lip_protrusion_", 0) == 0) c.cost = kHelperCost * kProtrusionCost;
    if (m.tension_max > 0) c.plus = motion_of(m.response_max, node, &c.largest_plus);
    if (m.tension_min > 0) c.minus = motion_of(m.response_min, node, &c.largest_minus);
    if (c.plus.squaredNorm() > 0 || c.minus.squaredNorm() > 0) out.push_back(c);
  }
  return out;
}

SteerModel steer_model(const std::vector<HelperColumn> &helpers, const Eigen::Matrix3d &measured,
                       const Eigen::Vector3d &along) {
  SteerModel m;
  for (const HelperColumn &h : helpers)
    for (const auto &[r, largest] : {std::pair{h.plus, h.largest_plus}, std::pair{h.minus, h.largest_minus}}) {
      const double back = std::min(r.dot(along), 0.0);
      m.column.push_back(measured * r);
      m.cost.push_back(h.cost * largest * largest + back * back);
    }
  return m;
}

std::vector<double> steer_contractions(const SteerModel &model, const Eigen::Vector3d &error,
                                       const std::vector<double> &current, double *predicted) {
  const std::vector<Eigen::Vector3d> &a = model.column;
  const size_t n = a.size();
  std::vector<double> x = split(current);
  Eigen::Vector3d r = error;  // the counted error at x, kept up to date
  // Coordinate descent, each variable to its exact minimum within its
  // bounds given the others; a sweep never raises the cost.
  for (int sweep = 0; sweep < 200; ++sweep) {
    double moved = 0;
    for (size_t i = 0; i < n; ++i) {
      if (a[i].squaredNorm() == 0) continue;
      const double g = a[i].dot(r) + model.cost[i] * x[i];
      const double next = std::clamp(x[i] - g / (a[i].squaredNorm() + model.cost[i]), 0.0, kHelperBound);
      r += (next - x[i]) * a[i];
      moved = std::max(moved, std::abs(next - x[i]));
      x[i] = next;
    }
    if (moved < 1e-9) break;
  }
  std::vector<double> c(n / 2);
  for (size_t h = 0; h < c.size(); ++h) {
    c[h] = x[2 * h] - x[2 * h + 1];
    if (std::abs(c[h]) < kHelperLeast) {
      r -= a[2 * h] * x[2 * h] + a[2 * h + 1] * x[2 * h + 1];
      c[h] = 0;
    }
  }
  if (predicted) *predicted = r.norm();
  return c;
}

void steer_update(SteerModel &model, const std::vector<double> &from, const std::vector<double> &to,
                  const Eigen::Vector3d &change) {
  const std::vector<double> x0 = split(from), x1 = split(to);
  double step = 0;
  Eigen::Vector3d predicted = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < x0.size(); ++i) {
    step += (x1[i] - x0[i]) * (x1[i] - x0[i]);
    predicted += (x1[i] - x0[i]) * model.column[i];
  }
  if (step == 0) return;
  const Eigen::Vector3d miss = (change - predicted) / step;
  for (size_t i = 0; i < x0.size(); ++i) model.column[i] += (x1[i] - x0[i]) * miss;
}

std::string steer_group(const FaceModel &model, const std::vector<std::string> &names,
                        const std::vector<std::pair<int, double>> &pattern, int vertex, const Eigen::Vector3d &along,
                        const PoseAction &action, double value, double cap, FactorCache *cache,
                        const std::function<SkinFaults(const Eigen::MatrixXd &)> &faults, Pose &pose, double &scale,
                        bool &capped, std::vector<std::pair<int, double>> *steered_pattern) {
  if (steered_pattern) *steered_pattern = pattern;
  const std::vector<HelperColumn> columns = helper_columns(model, names, pattern, vertex);
  if (columns.empty()) return std::string();
  const int node = model.tissue.node(kEpidermis, vertex);
  auto motion = [&](const Pose &p) -> Eigen::Vector3d {
    return (p.X.row(node) - model.tissue.X0.row(node)).transpose();
  };
  const Eigen::Matrix3d off_axis = Eigen::Matrix3d::Identity() - along * along.transpose();
  // Reached: only the off-axis motion counts. Capped: the whole distance
  // to the prescribed motion.
  const Eigen::Matrix3d measured = capped ? Eigen::Matrix3d::Identity() : off_axis;
  const Eigen::Vector3d wanted = capped ? Eigen::Vector3d(value * along) : Eigen::Vector3d::Zero();
  struct Faults {
    size_t sunk = 0;
    bool tears = false;
  };
  auto faults_of = [&](const Pose &p) {
    const SkinFaults f = faults(pose_epidermis(model, p));
    return Faults{f.sunk_vertices.size(), f.tears()};
  };
  SteerModel linear = steer_model(columns, measured, along);
  std::vector<double> c(columns.size(), 0);
  const Eigen::Vector3d m0 = motion(pose);
  const double off_start = (off_axis * m0).norm();
  double off_now = off_start;
  std::optional<Faults> faults_now;
  for (int round = 0; round < kSteerRounds && off_now > kSteerAbove * value; ++round) {
    const Eigen::Vector3d m = motion(pose);
    const Eigen::Vector3d error = measured * (m - wanted);
    double predicted = 0;
    const std::vector<double> next = steer_contractions(linear, error, c, &predicted);
    if (error.norm() - predicted < kSteerGain * value) break;
    // The pattern is scaled by s as a whole: a helper at c is c / s of its
    // range in it.
    std::vector<std::pair<int, double>> with = pattern;
    for (size_t h = 0; h < c.size(); ++h)
      if (next[h] != 0) with.push_back({columns[h].muscle, std::clamp(100 * next[h] / scale, -100.0, 100.0)});
    // Under load control either way: a group at its cap stays there unless
    // the helpers take it to the value.
    SteerFrom from;
    from.pose = &pose;
    from.scale = scale;
    double s2 = 0;
    bool capped2 = false;
    Expected<Pose> q = solve_pose_to(model, with, action, value, cache, &s2, cap, &capped2, &from);
    if (!q) break;
    std::vector<double> reached(c.size(), 0);  // the helpers' contractions in q
    for (size_t h = 0; h < c.size(); ++h)
      for (size_t j = pattern.size(); j < with.size(); ++j)
        if (with[j].first == columns[h].muscle) reached[h] = s2 * with[j].second / 100;
    const Eigen::Vector3d mq = motion(*q);
    steer_update(linear, c, reached, measured * (mq - m));
    const double off_q = (off_axis * mq).norm();
    bool keep = !(capped2 && !capped) && off_q < off_now &&
                !(capped2 && mq.dot(along) < m.dot(along) - model.solver.tolerance);
    std::optional<Faults> faults_q;
    if (keep) {
      if (!faults_now) faults_now = faults_of(pose);
      faults_q = faults_of(*q);
      keep = faults_q->sunk <= faults_now->sunk && (!faults_q->tears || faults_now->tears);
    }
    if (!keep) continue;  // the next round chooses again, from the corrected model
    const bool small = off_now - off_q < kSteerGain * value;
    pose = std::move(*q);
    scale = s2, capped = capped2;
    if (steered_pattern) *steered_pattern = with;
    off_now = off_q, faults_now = faults_q;
    c = reached;
    if (small) break;
  }
  std::string out;
  for (size_t h = 0; h < c.size(); ++h) {
    if (c[h] == 0) continue;
    char b[96];
    std::snprintf(b, sizeof b, "%s%s %+.0f %%", out.empty() ? "" : ", ",
                  model.muscles[static_cast<size_t>(columns[h].muscle)].name.c_str(), 100 * c[h]);
    out += b;
  }
  if (out.empty()) return out;
  char b[96];
  std::snprintf(b, sizeof b, " (off-axis %.0f %% -> %.0f %%", 100 * off_start / value, 100 * off_now / value);
  out = "steered by " + out + b;
  // A group short of its value may have got further along.
  const double along0 = m0.dot(along), along1 = motion(pose).dot(along);
  if (along1 > along0 + model.solver.tolerance) {
    std::snprintf(b, sizeof b, ", along %.0f %% -> %.0f %%", 100 * along0 / value, 100 * along1 / value);
    out += b;
  }
  return out + ")";
}

}  // namespace afmb
