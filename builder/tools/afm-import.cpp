// afm-import: mesh + FDP file -> checked scene, FAPU, FDP summary, neutral AFM.
#include <afm/mpeg4.h>

#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>

#include "afm/afm_export.h"
#include "afm/analytic_targets.h"
#include "core/atomic_file.h"
#include "core/fapu.h"
#include "io/load_face.h"

using namespace afmb;

namespace {

void usage(FILE *out) {
  std::fprintf(out,
      "usage: afm-import MESH FDP -o OUT.afm [options]\n"
      "\n"
      "Reads a face mesh and its MPEG-4 feature points, checks them, prints the FAP\n"
      "units and an FDP summary, and writes a neutral Animatable Face Model (no morph\n"
      "targets unless --analytic: afm-build makes real ones).\n"
      "\n"
      "  MESH                 .wrl/.vrml (VRML97, several named parts), .obj (o/g groups\n"
      "                       become parts), .ply, .off, .stl\n"
      "  FDP                  XfaceEd .fdp XML, or the text or visage line forms\n"
      "                       (formats/fdp.md)\n"
      "  -o, --output FILE    the AFM to write (written completely or not at all)\n"
      "  --orient SPEC        map the input axes to the MPEG-4 frame (+x the face's left,\n"
      "                       +y up, +z forward): three signed input axes for the new\n"
      "                       x, y, z, e.g. 'x,z,-y' for a z-up mesh; or 'auto' to take\n"
      "                       the rotation the FDPs imply. Without it, a mesh that is not\n"
      "                       in the MPEG-4 frame is refused with the value to use.\n"
      "  --fdp-format F       auto (default), xfaceed, text or visage\n"
      "  --flip-v             texture coordinates run downwards in this model (v = 0 at\n"
      "                       the image's top, as Song's): store 1 - v, so the AFM follows\n"
      "                       the VRML/OpenGL convention (formats/afm.md)\n"
      "  --profile P          raw (default) or draco (formats/afm.md)\n"
      "  --analytic           add analytic stand-in morph targets (a smooth bump per\n"
      "                       FAP that moves its FDP exactly as MPEG-4 says; visemes,\n"
      "                       expressions) and rigid eyes, jaw and head: test models\n"
      "                       for players, not anatomy (afm-build makes those)\n"
      "  --normal-deltas      with --analytic: store normal deltas too\n"
      "  --fdps               list every FDP\n"
      "  --help               this text\n"
      "\n"
      "Exit status: 0 on success, 1 on bad input (the message names the file and line,\n"
      "part or FDP), 2 on bad usage.\n");
}

int fail(const Status &s) {
  std::fprintf(stderr, "afm-import: %s\n", s.message().c_str());
  return 1;
}

}  // namespace

int main(int argc, char **argv) {
  std::string mesh_path, fdp_path, out_path, orient_spec;
  FdpFormat fdp_format = FdpFormat::Auto;
  afm_profile profile = AFM_PROFILE_RAW;
  bool list_fdps = false, analytic = false, normal_deltas = false, flip_v = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&](const char *name) -> const char * {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "afm-import: %s needs a value (see --help)\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "-o" || a == "--output") {
      out_path = value("-o");
    } else if (a == "--orient") {
      orient_spec = value("--orient");
    } else if (a == "--fdp-format") {
      std::string f = value("--fdp-format");
      if (f == "auto") fdp_format = FdpFormat::Auto;
      else if (f == "xfaceed") fdp_format = FdpFormat::XfaceEd;
      else if (f == "text") fdp_format = FdpFormat::Text;
      else if (f == "visage") fdp_format = FdpFormat::Visage;
      else {
        std::fprintf(stderr, "afm-import: --fdp-format '%s': use auto, xfaceed, text or visage\n", f.c_str());
        return 2;
      }
    } else if (a == "--profile") {
      std::string p = value("--profile");
      if (p == "raw") profile = AFM_PROFILE_RAW;
      else if (p == "draco") profile = AFM_PROFILE_DRACO;
      else {
        std::fprintf(stderr, "afm-import: --profile '%s': use raw or draco\n", p.c_str());
        return 2;
      }
    } else if (a == "--fdps") {
      list_fdps = true;
    } else if (a == "--flip-v") {
      flip_v = true;
    } else if (a == "--analytic") {
      analytic = true;
    } else if (a == "--normal-deltas") {
      normal_deltas = true;
    } else if (a.size() > 1 && a[0] == '-') {
      std::fprintf(stderr, "afm-import: unknown option '%s' (see --help)\n", a.c_str());
      return 2;
    } else if (mesh_path.empty()) {
      mesh_path = a;
    } else if (fdp_path.empty()) {
      fdp_path = a;
    } else {
      std::fprintf(stderr, "afm-import: too many arguments (see --help)\n");
      return 2;
    }
  }
  if (mesh_path.empty() || fdp_path.empty() || out_path.empty()) {
    usage(stderr);
    return 2;
  }

  LoadOptions lo;
  lo.orient = orient_spec;
  lo.fdp_format = fdp_format;
  lo.flip_v = flip_v;
  std::vector<std::string> log;
  Expected<LoadedFace> face = load_face(mesh_path, fdp_path, lo, &log);
  for (const std::string &line : log) std::printf("%s\n", line.c_str());
  if (!face) return fail(face.status());
  Scene *scene = &face->scene;
  FdpSet *fdps = &face->fdps;

  std::printf("mesh: %s: %zu parts, %zu vertices, %zu triangles%s%s\n", mesh_path.c_str(),
              scene->parts.size(), scene->vertex_count(), scene->triangle_count(),
              scene->units.empty() ? "" : ", units ", scene->units.c_str());
  std::printf("  %-26s %-12s %9s %10s  %s\n", "part", "kind", "vertices", "triangles", "texture");
  for (const Part &p : scene->parts)
    std::printf("  %-26s %-12s %9lld %10lld  %s\n", p.name.c_str(), part_kind_name(p.kind),
                static_cast<long long>(p.V.rows()), static_cast<long long>(p.F.rows()),
                p.texture.empty() ? "-" : p.texture.c_str());

  // FDP summary: coverage per group of the standard's 84 points.
  std::map<int, std::set<int>> present;
  for (const FdpPoint &p : fdps->points) present[p.id.group].insert(p.id.index);
  std::printf("FDPs: %s: %zu points, %zu distinct of %d\n", fdp_path.c_str(), fdps->points.size(),
              fdps->distinct_count(), AFM_FDP_COUNT);
  std::map<int, int> per_group;
  const afm_fdp_info *table = afm_fdp_table();
  for (int i = 0; i < AFM_FDP_COUNT; ++i) per_group[table[i].group]++;
  std::string missing;
  for (auto [group, total] : per_group) {
    std::printf("  group %2d: %2zu of %2d", group, present[group].size(), total);
    std::string miss;
    for (int i = 0; i < AFM_FDP_COUNT; ++i)
      if (table[i].group == group && !present[group].count(table[i].index))
        miss += " " + std::to_string(group) + "." + std::to_string(table[i].index);
    std::printf("%s%s\n", miss.empty() ? "" : "   missing:", miss.c_str());
  }
  if (list_fdps)
    for (const FdpPoint &p : fdps->points)
      std::printf("  %-5s %-24s vertex %-6d (%+.5g %+.5g %+.5g)\n", p.id.str().c_str(),
                  p.part >= 0 ? scene->parts[static_cast<size_t>(p.part)].name.c_str() : "(free)",
                  p.vertex, p.pos.x(), p.pos.y(), p.pos.z());

  std::string notes;
  Expected<Fapu> fapu = compute_fapu(*fdps, &notes);
  if (!fapu) return fail(fapu.status());
  const char *u = scene->units.empty() ? "model units" : scene->units.c_str();
  std::printf("FAPU X0 (%s), computed from FDPs:\n", u);
  const Fapu &f = *fapu;
  const double computed[5] = {f.es0, f.irisd0, f.ens0, f.mns0, f.mw0};
  const char *names[5] = {"ES0", "IRISD0", "ENS0", "MNS0", "MW0"};
  for (int k = 0; k < 5; ++k) {
    std::printf("  %-7s %10.5g", names[k], computed[k]);
    if (fdps->stored_fapu) {
      const Fapu &s = *fdps->stored_fapu;
      const double stored[5] = {s.es0, s.irisd0, s.ens0, s.mns0, s.mw0};
      std::printf("   file states %10.5g (computed/stated %.3f)", stored[k],
                  stored[k] != 0 ? computed[k] / stored[k] : 0.0);
    }
    std::printf("\n");
  }
  for (size_t at = 0, end; at < notes.size(); at = end + 1) {
    end = notes.find('\n', at);
    if (end == std::string::npos) end = notes.size();
    if (end > at) std::printf("  note: %s\n", notes.substr(at, end - at).c_str());
  }

  AfmContent content;
  content.scene = &*scene;
  content.fdps = &*fdps;
  content.fapu = f;
  content.generator = analytic ? "afm-import --analytic" : "afm-import";
  if (analytic) {
    AnalyticOptions ao;
    ao.normal_deltas = normal_deltas;
    Expected<AnalyticModel> model = make_analytic_model(*scene, *fdps, f, ao);
    if (!model) return fail(model.status());
    content.targets = std::move(model->targets);
    content.rigids = std::move(model->rigids);
  }
  Expected<std::vector<uint8_t>> bytes = encode_afm(content, profile);
  if (!bytes) return fail(bytes.status().wrap(out_path));
  if (Status s = write_file_atomic(out_path, bytes->data(), bytes->size()); !s) return fail(s);
  if (analytic)
    std::printf("wrote %s: %zu bytes, %s profile, %zu analytic morph targets, %zu rigid parts\n",
                out_path.c_str(), bytes->size(), profile == AFM_PROFILE_RAW ? "raw" : "draco",
                content.targets.size(), content.rigids.size());
  else
    std::printf("wrote %s: %zu bytes, %s profile, neutral (no morph targets)\n", out_path.c_str(),
                bytes->size(), profile == AFM_PROFILE_RAW ? "raw" : "draco");
  return 0;
}
