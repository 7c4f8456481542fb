#include "core/fapu.h"

#include <cmath>
#include <cstdio>
#include <vector>

namespace afmb {

namespace {

struct Lookup {
  const FdpSet &set;
  std::string unbound;  // first error about an unbound point, if any

  // The first point of FDP g.i with a usable position, or nullptr.
  const FdpPoint *get(int g, int i) {
    const FdpPoint *p = set.find(FdpId{g, i});
    if (p && !p->part_name.empty() && p->part < 0) {
      if (unbound.empty())
        unbound = fdp_location(set, *p) + ": not bound to the scene's part '" + p->part_name +
                  "' (call bind_fdps first)";
      return nullptr;
    }
    return p;
  }
};

std::string join(const std::vector<std::string> &items, const char *sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

Expected<Fapu> compute_fapu(const FdpSet &bound, std::string *notes) {
  Lookup L{bound, {}};
  const FdpPoint *p35 = L.get(3, 5), *p36 = L.get(3, 6);
  const FdpPoint *p31 = L.get(3, 1), *p32 = L.get(3, 2), *p33 = L.get(3, 3), *p34 = L.get(3, 4);
  const FdpPoint *p915 = L.get(9, 15), *p94 = L.get(9, 4), *p95 = L.get(9, 5);
  const FdpPoint *p93 = L.get(9, 3), *p81 = L.get(8, 1);
  const FdpPoint *p22 = L.get(2, 2), *p83 = L.get(8, 3), *p84 = L.get(8, 4);
  if (!L.unbound.empty()) return Status::error(L.unbound);

  std::vector<std::string> missing;  // one entry per unit that cannot be computed
  // Records the FDPs of `pts` (present?, name) that are missing for `unit`.
  auto need = [&](const char *unit, std::vector<std::pair<bool, const char *>> pts,
                  const char *alternative = nullptr) {
    std::vector<std::string> names;
    for (auto &p : pts)
      if (!p.first) names.push_back(p.second);
    if (names.empty()) return true;
    missing.push_back(std::string(unit) + " needs FDP " + join(names, ", ") +
                      (alternative ? alternative : ""));
    return false;
  };

  // Nose base height N.y: 9.15, else its level neighbours 9.4/9.5, else a
  // quarter of the way from the nose tip 9.3 down to the upper lip 8.1.
  bool have_nose = true;
  double nose_y = 0;
  std::string nose_note;
  if (p915) {
    nose_y = p915->pos.y();
  } else if (p94 && p95) {
    nose_y = 0.5 * (p94->pos.y() + p95->pos.y());
    nose_note = "ENS0, MNS0: 9.15 absent, nose base height from the mean of 9.4 and 9.5";
  } else if (p93 && p81) {
    nose_y = p93->pos.y() + 0.25 * (p81->pos.y() - p93->pos.y());
    nose_note = "ENS0, MNS0: 9.15 absent, nose base height from 9.3 and 8.1 (9.3.y + (8.1.y - 9.3.y) / 4)";
  } else {
    have_nose = false;
  }
  const char *nose_alt = " (or 9.4 and 9.5, or 9.3 and 8.1 in place of 9.15)";

  bool ok_es = need("ES0", {{p35 != nullptr, "3.5"}, {p36 != nullptr, "3.6"}});
  bool left_iris = p31 && p33, right_iris = p32 && p34;
  bool ok_irisd = left_iris || right_iris;
  if (!ok_irisd) {
    std::vector<std::string> names;
    for (auto &p : {std::make_pair(p31, "3.1"), std::make_pair(p33, "3.3"),
                    std::make_pair(p32, "3.2"), std::make_pair(p34, "3.4")})
      if (!p.first) names.push_back(p.second);
    missing.push_back("IRISD0 needs FDP 3.1 and 3.3, or 3.2 and 3.4 (missing " + join(names, ", ") + ")");
  }
  bool ok_ens = need("ENS0", {{p35 != nullptr, "3.5"}, {p36 != nullptr, "3.6"}, {have_nose, "9.15"}},
                     have_nose ? nullptr : nose_alt);
  bool ok_mns = need("MNS0", {{have_nose, "9.15"}, {p22 != nullptr, "2.2"}}, have_nose ? nullptr : nose_alt);
  bool ok_mw = need("MW0", {{p83 != nullptr, "8.3"}, {p84 != nullptr, "8.4"}});
  std::string where = bound.source.empty() ? std::string() : bound.source + ": ";
  if (!(ok_es && ok_irisd && ok_ens && ok_mns && ok_mw))
    return Status::error(where + "cannot compute FAPU: " + join(missing, "; "));

  Fapu f;
  f.es0 = p35->pos.x() - p36->pos.x();
  if (left_iris && right_iris) {
    f.irisd0 = 0.5 * ((p31->pos.y() - p33->pos.y()) + (p32->pos.y() - p34->pos.y()));
  } else if (left_iris) {
    f.irisd0 = p31->pos.y() - p33->pos.y();
    if (notes) *notes += "IRISD0: from the left eye only (3.2 or 3.4 absent)\n";
  } else {
    f.irisd0 = p32->pos.y() - p34->pos.y();
    if (notes) *notes += "IRISD0: from the right eye only (3.1 or 3.3 absent)\n";
  }
  f.ens0 = 0.5 * (p35->pos.y() + p36->pos.y()) - nose_y;
  f.mns0 = nose_y - p22->pos.y();
  f.mw0 = p83->pos.x() - p84->pos.x();
  if (notes && !nose_note.empty()) *notes += nose_note + "\n";

  struct Check {
    const char *unit;
    double value;
    const char *formula;
  };
  const Check checks[] = {
      {"ES0", f.es0, "3.5.x - 3.6.x"},
      {"IRISD0", f.irisd0, "upper minus lower eyelid height (3.1/3.3, 3.2/3.4)"},
      {"ENS0", f.ens0, "mid-eye height minus nose base height"},
      {"MNS0", f.mns0, "nose base height minus 2.2.y"},
      {"MW0", f.mw0, "8.3.x - 8.4.x"},
  };
  for (const Check &c : checks) {
    if (!(std::isfinite(c.value) && c.value > 0))
      return Status::error(where + "FAPU " + c.unit + " = " + c.formula + " = " + fmt(c.value) +
                           " is not positive: the scene is not in the MPEG-4 frame (+x the "
                           "face's own left, +y up) or the FDPs are misplaced");
  }
  return f;
}

double fapu_distance(const Fapu &f, afm_fapu unit) {
  switch (unit) {
    case AFM_FAPU_IRISD: return f.irisd0;
    case AFM_FAPU_ES: return f.es0;
    case AFM_FAPU_ENS: return f.ens0;
    case AFM_FAPU_MNS: return f.mns0;
    case AFM_FAPU_MW: return f.mw0;
    default: return 0;
  }
}

Eigen::Vector3d fap_direction(const afm_fap_info *info) {
  return Eigen::Vector3d(info->direction[0], info->direction[1], info->direction[2]);
}

}  // namespace afmb
