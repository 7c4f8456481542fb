#include "fap/fidelity_report.h"

#include <afm/mpeg4.h>
#include <afm/render.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <system_error>

#include "core/atomic_file.h"
#include "anatomy/jaw.h"
#include "anatomy/tongue.h"
#include "fap/fap_mapping.h"
#include "fap/fap_synthesis.h"
#include "render/scene_render.h"

namespace afmb {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double worst(const std::vector<double> &v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

std::string format(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char *fmt, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return buf;
}

// The table's first column: "12", "v10", "e1".
std::string target_id(const FapOutcome &o) {
  if (o.kind == AFM_TARGET_VISEME) return format("v%d", o.number);
  if (o.kind == AFM_TARGET_EXPRESSION) return format("e%d", o.number);
  if (o.kind == AFM_TARGET_COMBINATION) return format("%d+", o.number);
  return format("%d", o.number);
}

// "fap03", "fap03-neg", "fap05-neg-1024", "fap05-neg-1024-with-fap03",
// "viseme01", "expression1".
std::string file_stem(const FapOutcome &o) {
  if (o.kind == AFM_TARGET_VISEME) return format("viseme%02d", o.number);
  if (o.kind == AFM_TARGET_EXPRESSION) return format("expression%d", o.number);
  if (o.kind == AFM_TARGET_COMBINATION)  // the builder gates its combinations by FAP 3 only
    return format("fap%02d%s-%d-with-fap03", o.number, o.side < 0 ? "-neg" : "", std::abs(o.reference));
  if (o.in_between) return format("fap%02d%s-%d", o.number, o.side < 0 ? "-neg" : "", std::abs(o.reference));
  return format("fap%02d%s", o.number, o.side < 0 ? "-neg" : "");
}

std::string html_escape(const std::string &s) {
  std::string out;
  for (char c : s) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

std::string csv_quote(const std::string &s) {
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// The FDP a FAP target is measured at (skin vertex), or -1.
int fap_fdp_vertex(const FdpSet &fdps, int skin, const FapOutcome &o) {
  if (o.kind != AFM_TARGET_FAP && o.kind != AFM_TARGET_COMBINATION) return -1;
  const afm_fap_info *info = afm_fap(o.number);
  const FdpPoint *p = info ? fdps.find(FdpId{info->fdp_group, info->fdp_index}, skin) : nullptr;
  return p && p->part == skin ? p->vertex : -1;
}

// The jaw's rigid motion at FAP `fap`'s value (identity for FAPs that do
// not move it): the controls the synthesis gave the jaw's parts.
Eigen::Affine3d jaw_at(const FapSynthesis &s, int fap, int value) {
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  // As the player composes them: p' = R (p - pivot) + pivot + translation.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d move = Eigen::Vector3d::Zero();
  for (const RigidPart::Control &c : s.jaw.controls) {
    if (c.fap != fap) continue;
    const double amount = c.gain * value;
    const Eigen::Vector3d a = s.jaw.axes.row(c.dof % 3).transpose();  // rows: local axes
    if (c.dof < 3) R = Eigen::AngleAxisd(amount * 1e-5, a).toRotationMatrix() * R;
    else move += amount * a;
  }
  t.linear() = R;
  t.translation() = s.jaw.pivot - R * s.jaw.pivot + move;
  return t;
}

}  // namespace

std::string target_label(const FapOutcome &o) {
  if (o.kind == AFM_TARGET_VISEME) return "viseme " + std::string(afm_viseme_phonemes(o.number));
  if (o.kind == AFM_TARGET_EXPRESSION) return afm_expression_name(o.number);
  const afm_fap_info *info = afm_fap(o.number);
  return std::string(info ? info->name : "fap") + (o.side < 0 ? " (negative)" : "") +
         (o.kind == AFM_TARGET_COMBINATION ? " (with the jaw)"
          : o.holds || o.from_jaw          ? " (hold)"
          : o.past_reference               ? " (held past)"
          : o.in_between                   ? " (in-between)"
                                           : "");
}

std::string fidelity_table(const FapSynthesis &s) {
  std::string out = format("%-4s %-34s %6s %8s %10s %10s %8s %8s %7s %6s\n", "fap", "name", "ref", "scale",
                           "prescribed", "achieved", "along", "off-axis", "V_d", "turned");
  // The figures count each FAP side once, at the table's reference (a
  // held side by its hold); the targets at a hold's reach, exact along the
  // direction by construction, have their off-axis median apart.
  std::vector<double> along, off, off_face, off_depth, reach, off_at_reach;
  int failed = 0, turning = 0, turned = 0, sinking = 0, kinematic = 0, holds = 0, from_jaw = 0, held_past = 0;
  int slab_turning = 0, slabs = 0, solved = 0;  // targets whose solved poses turn slabs, and how many
  for (const FapOutcome &o : s.outcomes) {
    const std::string id = target_id(o);
    const std::string name = target_label(o);
    if (!o.made) {
      // An in-between past the model's reach is no failure: the last target
      // made serves beyond its reference.
      if (!o.in_between) ++failed;
      out += format("%-4s %-34s %6d  not made: %s\n", id.c_str(), name.c_str(), o.reference, o.message.c_str());
      continue;
    }
    if (o.turned > 0) ++turning, turned += o.turned;
    if (o.sunk > 0) ++sinking;
    if (solved_own_pose(o)) {
      ++solved;
      if (o.slabs > 0) ++slab_turning, slabs += o.slabs;
    }
    if (o.kind == AFM_TARGET_VISEME || o.kind == AFM_TARGET_EXPRESSION) {
      out += format("%-4s %-34s %6d %8s %10s %10.4g %8s %8s %7d %6d%s%s\n", id.c_str(), name.c_str(), o.reference,
                    "-", "-", o.largest, "-", "-", o.dynamic, o.turned, o.message.empty() ? "" : "  ",
                    o.message.c_str());
      continue;
    }
    if (o.from_jaw || o.past_reference) {
      // Made from the jaw's target, exact along the direction by
      // construction, or a lip corner's target held past the table's
      // reference: listed, left out of the summary's figures (measured at
      // the references).
      if (o.kind == AFM_TARGET_COMBINATION) ++from_jaw;
      if (o.past_reference) ++held_past;
      out += format("%-4s %-34s %6d %8s %10.4g %10.4g %7.2f%% %7.1f%% %7s %6d  %s\n", id.c_str(), name.c_str(),
                    o.reference, "-", o.prescribed.norm(), o.achieved.norm(), 100 * o.along_error, 100 * o.off_axis,
                    "-", o.turned, o.message.c_str());
      continue;
    }
    if (!solved_fap_target(o)) {
      // The tongue's or a pupil's: exact at the FDP by construction, not a
      // measure of the face model (and left out of the summary's figures).
      ++kinematic;
      out += format("%-4s %-34s %6d %8s %10.4g %10.4g %7.2f%% %7.1f%% %7s %6s  the %s's own motion\n", id.c_str(),
                    name.c_str(), o.reference, "-", o.prescribed.norm(), o.achieved.norm(), 100 * o.along_error,
                    100 * o.off_axis, "-", "-", is_tongue_fap(o.number) ? "tongue" : "pupil");
      continue;
    }
    if (o.at_reach) {
      off_at_reach.push_back(o.off_axis);
    } else {
      along.push_back(o.along_error);
      off.push_back(o.off_axis);
      off_face.push_back(o.off_face);
      off_depth.push_back(o.off_depth);
      if (o.reached < 1) reach.push_back(o.reached);
      holds += o.holds;
    }
    out += format("%-4s %-34s %6d %8.3f %10.4g %10.4g %7.2f%% %7.1f%% %7d %6d%s%s\n", id.c_str(), name.c_str(),
                  o.reference, o.scale, o.prescribed.norm(), o.achieved.norm(), 100 * o.along_error,
                  100 * o.off_axis, o.dynamic, o.turned, o.message.empty() ? "" : "  ", o.message.c_str());
  }
  out += format("targets: %zu made, %d not made; FAPs along the direction median %.2f%% worst %.2f%%; off-axis "
                "median %.1f%% worst %.1f%% (across the face median %.1f%%, in depth %.1f%%); %zu under-reach "
                "(median %.0f%% of the prescribed motion%s); %d turn %d skin triangles over (visemes and "
                "expressions: achieved = largest motion)%s; slabs of tissue turned through themselves in the "
                "solved poses: %d (in %d of %d targets)%s%s%s\n",
                s.targets.size(), failed, 100 * median(along), 100 * worst(along), 100 * median(off),
                100 * worst(off), 100 * median(off_face), 100 * median(off_depth), reach.size(),
                100 * median(reach),
                holds ? format("; %d of them held past a target at their reach, whose off-axis median is %.1f%% "
                               "of its own motion",
                               holds, 100 * median(off_at_reach))
                            .c_str()
                      : "",
                turning, turned,
                sinking ? format("; %d sink skin below the skull", sinking).c_str() : "", slabs, slab_turning,
                solved,
                kinematic ? format("; %d targets of the tongue and pupils are exact by construction and not in "
                                   "these figures",
                                   kinematic)
                                  .c_str()
                          : "",
                from_jaw ? format("; %d lower lip sides hold their pose past their reach, and with the jaw go "
                                  "on by a combination made from its target (exact along the direction by "
                                  "construction): not in these figures",
                                  from_jaw)
                                 .c_str()
                         : "",
                held_past ? format("; %d in-betweens hold a lip corner's pose past its reference (taken as far "
                                   "with its partners, the skin folds), and are not in these figures",
                                   held_past)
                                  .c_str()
                          : "");
  return out;
}

Status write_fidelity_report(const std::string &dir, const Scene &scene, const FdpSet &fdps, int skin_index,
                             const FapSynthesis &s, const FidelityReportOptions &options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "targets", ec);
  if (ec) return Status::error(dir + ": cannot make the report directory: " + ec.message());
  const std::string sep = "/";

  // The text and CSV tables.
  const std::string table = fidelity_table(s);
  if (Status st = write_file_atomic(dir + sep + "report.txt", table); !st) return st;
  std::string csv =
      "kind,number,name,side,reference,reached,made,scale,prescribed_x,prescribed_y,prescribed_z,achieved_x,"
      "achieved_y,achieved_z,along_error,off_axis,off_face,off_depth,largest,dynamic,turned,sunk,slabs,seconds,"
      "message\n";
  for (const FapOutcome &o : s.outcomes)
    csv += format("%s,%d,%s,%d,%d,%.4g,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%d,%d,"
                  "%.3f,",
                  o.kind == AFM_TARGET_FAP           ? "fap"
                  : o.kind == AFM_TARGET_VISEME      ? "viseme"
                  : o.kind == AFM_TARGET_COMBINATION ? "combination"
                                                     : "expression",
                  o.number, csv_quote(target_label(o)).c_str(), o.side, o.reference, o.reached, o.made ? 1 : 0,
                  o.scale, o.prescribed.x(), o.prescribed.y(), o.prescribed.z(), o.achieved.x(), o.achieved.y(),
                  o.achieved.z(), o.along_error, o.off_axis, o.off_face, o.off_depth, o.largest, o.dynamic,
                  o.turned, o.sunk, o.slabs, o.seconds) +
           csv_quote(o.message) + "\n";
  if (Status st = write_file_atomic(dir + sep + "report.csv", csv); !st) return st;

  // The pictures: the neutral face, then every made target.
  SceneRenderOptions ro;
  ro.width = options.tile_width;
  ro.height = options.tile_height;
  ro.views = {SceneView{}};
  ro.face_closeup = true;
  ro.fdp_dot_pixels = 0;
  const size_t skin = static_cast<size_t>(skin_index);
  const Part &skin_part = scene.parts[skin];
  Eigen::MatrixXd base = skin_part.C;
  if (base.rows() != skin_part.V.rows()) base = skin_part.diffuse.transpose().replicate(skin_part.V.rows(), 1);

  std::vector<std::vector<uint8_t>> tiles;
  std::vector<std::string> tile_names;
  const int total = 1 + static_cast<int>(s.targets.size());
  // One renderer for every picture: its context and shaders are made once.
  afm_renderer *made = nullptr;
  if (afm_renderer_create(&made) != AFM_OK) return Status::error(dir + ": render: " + afm_render_last_error());
  const std::unique_ptr<afm_renderer, void (*)(afm_renderer *)> renderer(made, afm_renderer_destroy);
  // A face picture (the closeup, `markers` over it), or another scene
  // (`views` and framing of `other`).
  auto picture = [&](const std::string &stem, const Scene &posed, const std::vector<SceneMarkers> &markers,
                     const SceneRenderOptions *other = nullptr) -> Status {
    SceneRenderOptions o = other ? *other : ro;
    o.markers = markers;
    const std::string path = dir + sep + "targets" + sep + stem + ".png";
    Expected<std::vector<std::vector<uint8_t>>> img = render_scene(posed, other ? nullptr : &fdps, o, renderer.get());
    if (!img) return img.status().wrap(path);
    afm_render_image image{img->front().data(), o.width, o.height};
    if (afm_png_write(path.c_str(), &image) != AFM_OK)
      return Status::error(path + ": " + afm_render_last_error());
    tiles.push_back(std::move(img->front()));
    tile_names.push_back(stem);
    if (options.progress) options.progress(static_cast<int>(tiles.size()), total, stem);
    return Status::ok();
  };
  if (Status st = picture("neutral", scene, {}); !st) return st;

  // A target of a part the face hides or shows small: the tongue (the
  // closed lips hide it) with the lower teeth, from above and to the side,
  // red where it moves; a pupil, its eye alone from the front in its own
  // colours. The part's rest vertices in grey dots, the tongue's FDP at rest
  // (yellow) and where MPEG-4 puts it (green).
  auto part_picture = [&](const std::string &stem, const Scene &posed, const MorphTarget &t,
                          const FapOutcome &o) -> Status {
    const bool tongue = is_tongue_fap(o.number);
    const PartKind moved = tongue ? PartKind::Tongue : o.number == 29 ? PartKind::EyeLeft : PartKind::EyeRight;
    Scene alone;
    alone.name = posed.name;
    alone.units = posed.units;
    alone.source = posed.source;
    std::vector<SceneMarkers> markers;
    for (size_t p = 0; p < posed.parts.size(); ++p) {
      const PartKind k = posed.parts[p].kind;
      if (k != moved && !(tongue && k == PartKind::TeethLower)) continue;
      Part part = posed.parts[p];
      if (k == moved && p < t.displacement.size() && t.displacement[p].rows() == part.V.rows()) {
        if (tongue) {
          const Eigen::VectorXd len = t.displacement[p].rowwise().norm();
          const double most = std::max(len.maxCoeff(), 1e-30);
          part.C.resize(part.V.rows(), 3);
          for (Eigen::Index v = 0; v < part.V.rows(); ++v) {
            const double w = std::sqrt(std::min(1.0, len(v) / most));
            part.C.row(v) = (1 - w) * Eigen::RowVector3d(0.8, 0.55, 0.55) + w * Eigen::RowVector3d(0.9, 0.1, 0.1);
          }
        }
        SceneMarkers rest;
        rest.points = scene.parts[p].V;
        rest.color = {0.6f, 0.6f, 0.6f};
        rest.size_pixels = 2;
        markers.push_back(rest);
        const afm_fap_info *info = afm_fap(o.number);
        const FdpPoint *f = fdps.find(FdpId{info->fdp_group, info->fdp_index}, static_cast<int>(p));
        if (tongue && f) {
          SceneMarkers at, goal;
          at.points = f->pos.transpose();
          at.color = {1.0f, 0.9f, 0.1f};
          at.size_pixels = 5;
          goal.points = (f->pos + o.prescribed).transpose();
          goal.color = {0.1f, 0.9f, 0.2f};
          goal.size_pixels = 5;
          markers.push_back(at);
          markers.push_back(goal);
        }
      }
      alone.parts.push_back(std::move(part));
    }
    SceneRenderOptions po = ro;
    po.face_closeup = false;
    po.views = {tongue ? SceneView{50.0f, 25.0f} : SceneView{}};
    return picture(stem, alone, markers, &po);
  };

  size_t next = 0;  // targets are the made outcomes, in order
  for (const FapOutcome &o : s.outcomes) {
    if (!o.made) continue;
    const MorphTarget &t = s.targets[next++];
    Scene posed = scene;
    // A combination as played and judged (played_with).
    std::vector<const MorphTarget *> shown = {&t};
    if (t.kind == AFM_TARGET_COMBINATION) {
      shown.clear();
      for (size_t i : played_with(s.targets, next - 1)) shown.push_back(&s.targets[i]);
    }
    const Eigen::Affine3d jaw = t.kind == AFM_TARGET_COMBINATION ? jaw_at(s, t.gate, t.gate_reference)
                                : o.kind == AFM_TARGET_FAP       ? jaw_at(s, o.number, o.reference)
                                                                 : Eigen::Affine3d::Identity();
    for (const MorphTarget *u : shown)
      for (size_t p = 0; p < posed.parts.size() && p < u->displacement.size(); ++p)
        if (u->displacement[p].rows() == posed.parts[p].V.rows()) posed.parts[p].V += u->displacement[p];
    if (!jaw.matrix().isIdentity(0))
      for (int p : s.jaw.parts) {
        Eigen::MatrixXd &V = posed.parts[static_cast<size_t>(p)].V;
        V = moved_points(jaw, V);
      }
    // Red where the skin moves, in proportion to the target's largest motion.
    const Eigen::MatrixXd &D = t.displacement[skin];
    if (D.rows() == base.rows()) {
      const Eigen::VectorXd len = D.rowwise().norm();
      const double most = std::max(len.maxCoeff(), 1e-30);
      Eigen::MatrixXd C = base;
      for (Eigen::Index v = 0; v < C.rows(); ++v) {
        const double w = std::sqrt(std::min(1.0, len(v) / most));
        C.row(v) = (1 - w) * base.row(v) + w * Eigen::RowVector3d(0.9, 0.1, 0.1);
      }
      posed.parts[skin].C = C;
    }
    if (o.kind == AFM_TARGET_FAP && kinematic_fap(o.number)) {
      if (Status st = part_picture(file_stem(o), posed, t, o); !st) return st;
      continue;
    }
    std::vector<SceneMarkers> markers;
    if (const int v = fap_fdp_vertex(fdps, skin_index, o); v >= 0) {
      const Eigen::RowVector3d rest = skin_part.V.row(v);
      SceneMarkers at, goal;
      at.points = rest;
      at.color = {1.0f, 0.9f, 0.1f};
      at.size_pixels = 5;
      goal.points = rest + o.prescribed.transpose();
      goal.color = {0.1f, 0.9f, 0.2f};
      goal.size_pixels = 5;
      markers = {at, goal};
    }
    if (Status st = picture(file_stem(o), posed, markers); !st) return st;
  }

  // The contact sheet.
  std::vector<afm_render_image> images;
  for (const std::vector<uint8_t> &tile : tiles) images.push_back({tile.data(), ro.width, ro.height});
  const uint8_t background[4] = {255, 255, 255, 255};
  const std::string sheet = dir + sep + "sheet.png";
  if (afm_sheet_write_png(sheet.c_str(), images.data(), static_cast<int>(images.size()), 10, 4, background) !=
      AFM_OK)
    return Status::error(sheet + ": " + afm_render_last_error());

  // The page: the summary, then a row per target with its picture.
  std::string html =
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>FAP synthesis: fidelity report</title>\n"
      "<style>body{font-family:sans-serif}td,th{padding:2px 8px;text-align:right}td.l,th.l{text-align:left}"
      "img{width:120px}</style></head><body>\n<h1>FAP synthesis: fidelity report</h1>\n";
  html += "<p>" + html_escape(table.substr(table.rfind("targets:"))) + "</p>\n";
  html += "<p>Pictures: the face at each target's reference value, the skin red where it moves (full red at "
          "its largest motion); a FAP's FDP at rest in yellow, where MPEG-4 puts it in green. "
          "<a href=\"sheet.png\">Contact sheet</a> (neutral first, then this table's order), "
          "<a href=\"report.csv\">CSV</a>.</p>\n<table>\n<tr><th>picture</th><th>#</th><th class=\"l\">name</th>"
          "<th>ref</th><th>scale</th><th>prescribed</th><th>achieved</th><th>along</th><th>off-axis</th>"
          "<th class=\"l\">note</th></tr>\n";
  html += "<tr><td><img src=\"targets/neutral.png\"></td><td></td><td class=\"l\">neutral</td><td colspan=7></td></tr>\n";
  for (const FapOutcome &o : s.outcomes) {
    const std::string num = target_id(o);
    html += "<tr><td>";
    if (o.made) html += "<img src=\"targets/" + file_stem(o) + ".png\">";
    html += "</td><td>" + num + "</td><td class=\"l\">" + html_escape(target_label(o)) + "</td>";
    html += format("<td>%d</td>", o.reference);
    if (!o.made) {
      html += "<td colspan=5></td>";
    } else if (o.kind == AFM_TARGET_VISEME || o.kind == AFM_TARGET_EXPRESSION) {
      html += format("<td></td><td></td><td>%.4g</td><td></td><td></td>", o.largest);
    } else {
      html += format("<td>%.3f</td><td>%.4g</td><td>%.4g</td><td>%.2f%%</td><td>%.1f%% (%.1f%% across, %.1f%% "
                     "depth)</td>",
                     o.scale, o.prescribed.norm(), o.achieved.norm(), 100 * o.along_error, 100 * o.off_axis,
                     100 * o.off_face, 100 * o.off_depth);
    }
    html += "<td class=\"l\">" + html_escape(o.made ? o.message : "not made: " + o.message) + "</td></tr>\n";
  }
  html += "</table></body></html>\n";
  return write_file_atomic(dir + sep + "index.html", html);
}

}  // namespace afmb
