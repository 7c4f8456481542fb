#include "core/orient.h"

#include <afm/mpeg4.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace afmb {

namespace {

const char kAxis[] = "xyz";

std::string vec_str(const Eigen::Vector3d &v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.4g, %.4g, %.4g)", v.x(), v.y(), v.z());
  return buf;
}

// "2.10", without depending on the FDP table code.
std::string id_str(FdpId id) { return std::to_string(id.group) + "." + std::to_string(id.index); }

// A usable position: a free point, or a vertex point bind_fdps() resolved.
const FdpPoint *lookup(const FdpSet &set, FdpId id) {
  for (const FdpPoint &p : set.points)
    if (p.id == id && (p.part_name.empty() || p.part >= 0) && p.pos.allFinite()) return &p;
  return nullptr;
}

// The mean of the first tier with any point present; `ids` lists the points
// used ("3.5 3.6").
struct Landmark {
  bool ok = false;
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  std::string ids;
};

using Tier = std::vector<FdpId>;

Landmark landmark(const FdpSet &set, const std::vector<Tier> &tiers) {
  Landmark l;
  for (const Tier &tier : tiers) {
    int n = 0;
    for (const FdpId &id : tier)
      if (const FdpPoint *p = lookup(set, id)) {
        l.pos += p->pos;
        l.ids += (n++ ? " " : "") + id_str(id);
      }
    if (n > 0) {
      l.pos /= n;
      l.ok = true;
      return l;
    }
  }
  return l;
}

Tier range(int group, int from, int to) {
  Tier t;
  for (int i = from; i <= to; ++i) t.push_back({group, i});
  return t;
}

const std::vector<Tier> &eye_tiers() {
  static const std::vector<Tier> t = {
      {{3, 5}, {3, 6}},                          // pupils
      {{3, 1}, {3, 2}, {3, 3}, {3, 4}},          // inner eyelid centres
      range(3, 7, 14),                           // eye corners, outer lids
      range(4, 1, 6)};                           // brows (higher, still above the mouth)
  return t;
}
const std::vector<Tier> &mouth_tiers() {
  static const std::vector<Tier> t = {
      {{2, 2}, {2, 3}, {8, 1}, {8, 2}},
      {{2, 4}, {2, 5}, {8, 3}, {8, 4}, {2, 6}, {2, 7}, {2, 8}, {2, 9}, {8, 5}, {8, 6}, {8, 7}, {8, 8}}};
  return t;
}
const std::vector<Tier> &chin_tiers() {
  static const std::vector<Tier> t = {{{2, 1}}, {{2, 10}}, {{2, 11}, {2, 12}}};
  return t;
}
const std::vector<Tier> &nose_tiers() {
  static const std::vector<Tier> t = {{{9, 3}}, {{9, 12}}, {{9, 15}}};
  return t;
}
// (face's left, face's right) pairs, most reliable first.
const std::vector<std::pair<FdpId, FdpId>> &side_pairs() {
  static const std::vector<std::pair<FdpId, FdpId>> p = {
      {{3, 5}, {3, 6}},  {{3, 1}, {3, 2}},   {{3, 3}, {3, 4}},   {{3, 7}, {3, 12}},
      {{3, 11}, {3, 8}}, {{3, 9}, {3, 10}},  {{3, 13}, {3, 14}}, {{4, 1}, {4, 2}},
      {{4, 3}, {4, 4}},  {{4, 5}, {4, 6}},   {{5, 1}, {5, 2}},   {{5, 3}, {5, 4}},
      {{8, 3}, {8, 4}},  {{2, 4}, {2, 5}},   {{9, 1}, {9, 2}},   {{9, 5}, {9, 4}},
      {{9, 7}, {9, 6}},  {{9, 13}, {9, 14}}, {{8, 10}, {8, 9}},  {{2, 11}, {2, 12}},
      {{2, 13}, {2, 14}}};
  return p;
}

struct Check {
  Eigen::Vector3d d;  // model-space vector that must point along +axis
  int axis = 1;
  bool dominant = false;  // the axis must also be d's largest component
  std::string what;       // "the eyes (3.5 3.6) are not above the mouth (2.2 2.3)"
};

struct Checks {
  std::vector<Check> list;
  std::vector<std::string> missing;  // axes that cannot be told, with the FDPs that would tell them
  int axes = 0;                      // independent directions known (need 2)
};

Checks make_checks(const FdpSet &set) {
  Checks c;
  const Landmark eye = landmark(set, eye_tiers());
  const Landmark mouth = landmark(set, mouth_tiers());
  const Landmark chin = landmark(set, chin_tiers());
  const Landmark nose = landmark(set, nose_tiers());

  const Landmark *top = eye.ok ? &eye : mouth.ok ? &mouth : nullptr;
  const Landmark *bottom = chin.ok ? &chin : mouth.ok ? &mouth : nullptr;
  const char *top_name = eye.ok ? "eyes" : "mouth";
  const char *bottom_name = chin.ok ? "chin" : "mouth";
  if (top && bottom && top != bottom) {
    c.list.push_back({top->pos - bottom->pos, 1, true,
                      std::string("the face is not upright: from the ") + bottom_name + " (" +
                          bottom->ids + ") to the " + top_name + " (" + top->ids + ") is " +
                          vec_str(top->pos - bottom->pos) + ", expected mostly +y"});
    ++c.axes;
  } else {
    c.missing.push_back("up (two of: eyes 3.5/3.6, 3.1-3.4, 3.7-3.14 or brows 4.1-4.6; mouth "
                        "2.2/2.3/8.1/8.2 or lip corners; chin 2.1, 2.10 or 2.11/2.12)");
  }
  if (eye.ok && mouth.ok)
    c.list.push_back({eye.pos - mouth.pos, 1, false,
                      "the eyes (" + eye.ids + ") are not above the mouth (" + mouth.ids +
                          "): eyes - mouth = " + vec_str(eye.pos - mouth.pos) + ", expected +y"});
  if (mouth.ok && chin.ok)
    c.list.push_back({mouth.pos - chin.pos, 1, false,
                      "the mouth (" + mouth.ids + ") is not above the chin (" + chin.ids +
                          "): mouth - chin = " + vec_str(mouth.pos - chin.pos) + ", expected +y"});

  bool side = false;
  for (const auto &[l, r] : side_pairs()) {
    const FdpPoint *pl = lookup(set, l), *pr = lookup(set, r);
    if (!pl || !pr) continue;
    const Eigen::Vector3d d = pl->pos - pr->pos;
    c.list.push_back({d, 0, true,
                      "the face's left (" + id_str(l) + ") is not at +x of its right (" + id_str(r) +
                          "): left - right = " + vec_str(d) + ", expected mostly +x"});
    side = true;
    ++c.axes;
    break;
  }
  if (!side)
    c.missing.push_back("left-right (a pair such as 3.5/3.6, 3.1/3.2, 4.1/4.2, 8.3/8.4)");

  if (nose.ok && eye.ok) {
    const Eigen::Vector3d d = nose.pos - eye.pos;
    c.list.push_back({d, 2, false,
                      "the nose tip (" + nose.ids + ") is not in front of the eyes (" + eye.ids +
                          "): nose - eyes = " + vec_str(d) + ", expected +z"});
    ++c.axes;
  } else {
    c.missing.push_back("forward (nose 9.3, 9.12 or 9.15, and the eyes)");
  }
  return c;
}

struct Verdict {
  int failed = -1;  // first failed check, -1 when all pass
  double score = 0;
};

Verdict evaluate(const Checks &c, const Eigen::Matrix3d &R) {
  Verdict v;
  for (size_t i = 0; i < c.list.size(); ++i) {
    const Check &k = c.list[i];
    const Eigen::Vector3d e = R * k.d;
    const double len = e.norm();
    bool pass = len > 0 && e[k.axis] > 0;
    if (pass && k.dominant)
      for (int a = 0; a < 3; ++a)
        if (a != k.axis && std::fabs(e[a]) > e[k.axis]) pass = false;
    if (len > 0) v.score += e[k.axis] / len;
    if (!pass && v.failed < 0) v.failed = static_cast<int>(i);
  }
  return v;
}

std::string join(const std::vector<std::string> &v, const char *sep) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

Status not_enough(const FdpSet &set, const Checks &c) {
  return Status::error((set.source.empty() ? std::string() : set.source + ": ") +
                       "too few FDPs to tell the orientation (two directions are needed); missing: " +
                       join(c.missing, "; "));
}

struct Detection {
  bool ok = false;
  Orientation o;
  std::string message;  // why nothing was found, when !ok
};

Detection detect(const Checks &c) {
  Detection best_proper, best_mirror;
  double proper_score = -1e300, mirror_score = -1e300;
  Eigen::Matrix3d best_any = Eigen::Matrix3d::Identity();
  double any_score = -1e300;
  int any_failed = -1;
  int perm[3] = {0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) R(i, perm[i]) = (signs >> i & 1) ? -1.0 : 1.0;
      const Verdict v = evaluate(c, R);
      if (v.score > any_score) {
        any_score = v.score;
        best_any = R;
        any_failed = v.failed;
      }
      if (v.failed >= 0) continue;
      const bool proper = R.determinant() > 0;
      if (proper && v.score > proper_score) {
        proper_score = v.score;
        best_proper.ok = true;
        best_proper.o.R = R;
      } else if (!proper && v.score > mirror_score) {
        mirror_score = v.score;
        best_mirror.ok = true;
        best_mirror.o.R = R;
      }
    }
  } while (std::next_permutation(perm, perm + 3));

  if (best_proper.ok) return best_proper;
  Detection d;
  if (best_mirror.ok) {
    d.message = "no rotation satisfies every check, only the mirror --orient " +
                best_mirror.o.spec() +
                ": the model looks mirrored, or its left and right FDPs are swapped (3.5 is the "
                "face's own left eye, at +x). A mirror swaps the face's sides, so it is not applied "
                "automatically: pass --orient " +
                best_mirror.o.spec() + " yourself only if the mesh really is mirrored";
    return d;
  }
  Orientation any;
  any.R = best_any;
  d.message = "no signed axis permutation satisfies every check (the closest, --orient " +
              any.spec() + ", still fails: " + c.list[any_failed].what +
              "); the head may be tilted by more than 45 degrees or FDPs misplaced";
  return d;
}

}  // namespace

std::string Orientation::spec() const {
  std::string s;
  for (int i = 0; i < 3; ++i) {
    if (i) s += ',';
    int j = 0;
    for (int k = 1; k < 3; ++k)
      if (std::fabs(R(i, k)) > std::fabs(R(i, j))) j = k;
    if (R(i, j) < 0) s += '-';
    s += kAxis[j];
  }
  return s;
}

Expected<Orientation> parse_orientation(std::string_view spec) {
  const std::string quoted = "orientation '" + std::string(spec) + "'";
  const char *form = ": expected three comma-separated signed axes, such as x,y,z or -x,y,-z or x,z,-y";
  std::vector<std::string_view> parts;
  size_t start = 0;
  for (;;) {
    size_t comma = spec.find(',', start);
    parts.push_back(spec.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (parts.size() != 3) return Status::error(quoted + form);
  Orientation o;
  o.R.setZero();
  bool used[3] = {false, false, false};
  for (int i = 0; i < 3; ++i) {
    std::string_view t = parts[i];
    while (!t.empty() && (t.front() == ' ' || t.front() == '\t')) t.remove_prefix(1);
    while (!t.empty() && (t.back() == ' ' || t.back() == '\t')) t.remove_suffix(1);
    double sign = 1;
    if (!t.empty() && (t[0] == '+' || t[0] == '-')) {
      sign = t[0] == '-' ? -1 : 1;
      t.remove_prefix(1);
    }
    const char c = t.size() == 1 ? static_cast<char>(std::tolower(static_cast<unsigned char>(t[0]))) : 0;
    const int axis = c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : -1;
    if (axis < 0)
      return Status::error(quoted + ": '" + std::string(parts[i]) +
                           "' is not an axis (x, y or z, optionally signed)" + form);
    if (used[axis])
      return Status::error(quoted + ": axis " + std::string(1, kAxis[axis]) +
                           " appears twice; each of x, y and z must appear once");
    used[axis] = true;
    o.R(i, axis) = sign;
  }
  return o;
}

Status check_orientation(const FdpSet &bound) {
  const Checks c = make_checks(bound);
  if (c.axes < 2) return not_enough(bound, c);
  const Verdict v = evaluate(c, Eigen::Matrix3d::Identity());
  if (v.failed < 0) return Status::ok();
  std::string msg = (bound.source.empty() ? std::string() : bound.source + ": ") +
                    "orientation check failed: " + c.list[v.failed].what;
  const Detection d = detect(c);
  if (d.ok)
    msg += "; --orient " + d.o.spec() + " fixes it";
  else
    msg += "; " + d.message;
  return Status::error(msg);
}

std::vector<std::string> fdp_order_notes(const FdpSet &bound) {
  // (first, second): first above second (y), or on the face's left of it (x).
  struct Pair {
    FdpId first, second;
  };
  static const Pair kAbove[] = {
      {{9, 3}, {8, 1}}, {{8, 1}, {2, 2}}, {{2, 2}, {2, 3}},  {{2, 3}, {8, 2}}, {{8, 2}, {2, 10}}, {{2, 10}, {2, 1}},
      {{8, 5}, {2, 6}}, {{8, 6}, {2, 7}}, {{2, 6}, {2, 8}},  {{2, 7}, {2, 9}}, {{2, 8}, {8, 7}},  {{2, 9}, {8, 8}},
      {{3, 1}, {3, 3}}, {{3, 2}, {3, 4}}, {{4, 3}, {3, 1}},  {{4, 4}, {3, 2}}, {{3, 5}, {9, 3}},  {{3, 6}, {9, 3}},
  };
  static const Pair kLeft[] = {
      {{3, 5}, {3, 6}},  {{3, 1}, {3, 2}}, {{3, 3}, {3, 4}}, {{3, 7}, {3, 11}}, {{3, 8}, {3, 12}}, {{4, 1}, {4, 2}},
      {{4, 5}, {4, 3}},  {{4, 3}, {4, 1}}, {{4, 2}, {4, 4}}, {{4, 4}, {4, 6}},  {{5, 1}, {5, 2}},  {{5, 3}, {5, 4}},
      {{2, 4}, {2, 5}},  {{2, 4}, {2, 6}}, {{2, 6}, {2, 7}}, {{2, 7}, {2, 5}},  {{2, 4}, {2, 8}},  {{2, 8}, {2, 9}},
      {{2, 9}, {2, 5}},  {{8, 3}, {8, 4}}, {{8, 3}, {8, 5}}, {{8, 5}, {8, 6}},  {{8, 6}, {8, 4}},  {{8, 3}, {8, 7}},
      {{8, 7}, {8, 8}},  {{8, 8}, {8, 4}}, {{9, 1}, {9, 2}}, {{2, 11}, {2, 12}}, {{2, 13}, {2, 14}},
  };
  // The extent of the FDPs along each axis, the first usable point of each.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const FdpPoint &p : bound.points)
    if (lookup(bound, p.id) == &p) lo = lo.cwiseMin(p.pos), hi = hi.cwiseMax(p.pos);
  std::vector<std::string> notes;
  auto describe = [](FdpId id) {  // "2.10 (Chin boss)"
    const afm_fdp_info *info = afm_fdp_find(id.group, id.index);
    return id_str(id) + (info ? std::string(" (") + info->description + ")" : std::string());
  };
  auto check = [&](const Pair &pair, int axis, const char *wrong, const char *right) {
    const FdpPoint *a = lookup(bound, pair.first), *b = lookup(bound, pair.second);
    if (!a || !b || !(hi[axis] > lo[axis])) return;
    const double by = b->pos[axis] - a->pos[axis];
    if (!(by > 0.01 * (hi[axis] - lo[axis]))) return;
    char far[32];
    std::snprintf(far, sizeof far, "%.3g", by);
    notes.push_back("FDP " + describe(pair.first) + " lies " + far + " " + wrong + " " + describe(pair.second) +
                    "; MPEG-4 puts it " + right + ": the file may have them swapped or misplaced");
  };
  for (const Pair &pair : kAbove) check(pair, 1, "below", "above");
  for (const Pair &pair : kLeft) check(pair, 0, "on the face's right of", "on its left");
  return notes;
}

Expected<Orientation> detect_orientation(const FdpSet &bound) {
  const Checks c = make_checks(bound);
  if (c.axes < 2) return not_enough(bound, c);
  const Detection d = detect(c);
  if (!d.ok)
    return Status::error((bound.source.empty() ? std::string() : bound.source + ": ") + d.message);
  return d.o;
}

void apply_orientation(const Orientation &o, Scene &scene, FdpSet &fdps) {
  const bool mirror = o.R.determinant() < 0;
  for (Part &p : scene.parts) {
    if (p.V.rows() > 0) p.V = (p.V * o.R.transpose()).eval();
    // A mirror turns counter-clockwise into clockwise: swap two corners so
    // the normals still point out.
    if (mirror) {
      if (p.F.rows() > 0) p.F.col(1).swap(p.F.col(2));
      if (p.FTC.rows() > 0) p.FTC.col(1).swap(p.FTC.col(2));
    }
  }
  for (FdpPoint &p : fdps.points) p.pos = o.R * p.pos;
}

}  // namespace afmb
