#include "afm/rigid_parts.h"

#include <afm/mpeg4.h>

#include <algorithm>
#include <tuple>
#include <utility>

#include "core/fapu.h"

namespace afmb {

std::vector<RigidPart> eye_and_head_rigids(const Scene &scene, const FdpSet &fdps, const Fapu &fapu, int skin) {
  std::vector<RigidPart> out;
  // Eyeballs turn about their centres; FAP directions give axes and signs.
  for (auto [kind, part_kind, yaw, pitch, thrust] :
       {std::tuple{AFM_RIGID_EYE_LEFT, PartKind::EyeLeft, 23, 25, 27},
        std::tuple{AFM_RIGID_EYE_RIGHT, PartKind::EyeRight, 24, 26, 28}}) {
    int part = scene.find_kind(part_kind);
    if (part < 0) continue;
    RigidPart eye;
    eye.kind = kind;
    eye.pivot = scene.parts[static_cast<size_t>(part)].V.colwise().mean().transpose();
    eye.parts.push_back(part);
    for (int fap : {yaw, pitch, thrust}) {
      const afm_fap_info *info = afm_fap(fap);
      Eigen::Vector3d a = fap_direction(info);
      int axis = a.x() != 0 ? 0 : a.y() != 0 ? 1 : 2;
      double sign = a[axis];
      if (info->motion == AFM_MOTION_ROTATE)
        eye.controls.push_back({fap, static_cast<afm_dof>(AFM_DOF_ROTATE_X + axis), sign});
      else
        eye.controls.push_back({fap, static_cast<afm_dof>(AFM_DOF_TRANSLATE_X + axis),
                                sign * fapu_distance(fapu, info->unit) / 1024.0});
    }
    out.push_back(eye);
  }

  // The head turns about the top of the spine (7.1), moving every part.
  RigidPart head;
  head.kind = AFM_RIGID_HEAD;
  if (const FdpPoint *spine = fdps.find(FdpId{7, 1}))
    head.pivot = spine->pos;
  else
    head.pivot = scene.parts[static_cast<size_t>(skin)].V.colwise().mean().transpose() -
                 Eigen::Vector3d(0, 0.5 * fapu.es0, 0);
  for (size_t p = 0; p < scene.parts.size(); ++p) head.parts.push_back(static_cast<int>(p));
  for (int fap : {48, 49, 50}) {
    Eigen::Vector3d a = fap_direction(afm_fap(fap));
    int axis = a.x() != 0 ? 0 : a.y() != 0 ? 1 : 2;
    head.controls.push_back({fap, static_cast<afm_dof>(AFM_DOF_ROTATE_X + axis), a[axis]});
  }
  out.push_back(head);
  return out;
}

std::vector<RigidPart::Control> piecewise_controls(const std::vector<RigidSample> &samples) {
  std::vector<std::pair<int, afm_dof>> keys;  // (FAP, dof) in first appearance
  for (const RigidSample &s : samples)
    if (s.value > 0 && std::find(keys.begin(), keys.end(), std::pair{s.fap, s.dof}) == keys.end())
      keys.emplace_back(s.fap, s.dof);
  std::vector<RigidPart::Control> first, knots;
  for (const auto &[fap, dof] : keys) {
    std::vector<std::pair<int, double>> at;  // (value, motion), ascending
    for (const RigidSample &s : samples)
      if (s.fap == fap && s.dof == dof && s.value > 0 &&
          std::none_of(at.begin(), at.end(), [&s](const auto &a) { return a.first == s.value; }))
        at.emplace_back(s.value, s.motion);
    std::stable_sort(at.begin(), at.end(), [](const auto &a, const auto &b) { return a.first < b.first; });
    double slope = at[0].second / at[0].first;
    first.push_back({fap, dof, slope, 0});
    for (size_t k = 1; k < at.size(); ++k) {
      const double next = (at[k].second - at[k - 1].second) / (at[k].first - at[k - 1].first);
      knots.push_back({fap, dof, next - slope, at[k - 1].first});
      slope = next;
    }
  }
  first.insert(first.end(), knots.begin(), knots.end());
  return first;
}

}  // namespace afmb
