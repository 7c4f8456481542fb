#include "export/export_model.h"

#include <afm/draco.h>
#include <afm/mpeg4.h>

#include <cmath>

#include "core/atomic_file.h"

namespace afmb {

void AfmDocFree::operator()(afm_doc *doc) const { afm_free(nullptr, doc); }

namespace {

double round_to(double x, int decimals) {
  const double scale = std::pow(10.0, decimals);
  return std::round(x * scale) / scale;
}

}  // namespace

Expected<AfmDocPtr> read_afm_file(const std::string &path) {
  Expected<std::string> bytes = read_file(path);
  if (!bytes) return bytes.status();
  const uint8_t *data = reinterpret_cast<const uint8_t *>(bytes->data());
  afm_diag diag{};
  afm_read_options options{};
  options.draco = afm_draco_codec();
  options.diag = &diag;
  afm_doc *doc = nullptr;
  const afm_result r = afm_doc_read_alloc(data, bytes->size(), &options, nullptr, &doc);
  if (r != AFM_OK)
    return Status::error(path + ": " + (diag.message[0] ? diag.message : afm_result_string(r)));
  return AfmDocPtr(doc);
}

Expected<FapStream> read_fap_file(const std::string &path) {
  Expected<std::string> bytes = read_file(path);
  if (!bytes) return bytes.status();
  const uint8_t *data = reinterpret_cast<const uint8_t *>(bytes->data());
  FapStream s;
  afm_diag diag{};
  uint32_t count = 0;
  afm_result r = afm_fap_parse(data, bytes->size(), nullptr, nullptr, 0, &count, nullptr,
                               nullptr, &diag);
  if (r == AFM_OK && count > 0) {
    s.frames.resize(count);
    r = afm_fap_parse(data, bytes->size(), nullptr, s.frames.data(), count, &count,
                      &s.header, nullptr, &diag);
  }
  if (r != AFM_OK) {
    // The reader's messages start with "line N: " when they have a line.
    std::string msg = diag.message[0] ? diag.message : afm_result_string(r);
    if (diag.line && msg.rfind("line ", 0) == 0 && msg.find(": ") != std::string::npos)
      msg = msg.substr(msg.find(": ") + 2);
    return Status::error(path + (diag.line ? ":" + std::to_string(diag.line) : std::string()) +
                         ": " + msg);
  }
  if (count == 0) return Status::error(path + ": the stream has no frames");
  s.frames.resize(count);
  return s;
}

double fap_frame_seconds(const FapStream &stream, size_t i) {
  const double frames = double(stream.frames[i].number) - double(stream.frames[0].number);
  return frames * stream.header.fps_den / stream.header.fps_num;
}

std::string target_name(const afm_target &t) {
  if (t.kind == AFM_TARGET_VISEME) {
    const char *n = afm_viseme_name(t.number);
    return std::string("viseme_") + (n ? n : std::to_string(t.number));
  }
  if (t.kind == AFM_TARGET_EXPRESSION) {
    const char *n = afm_expression_name(t.number);
    return std::string("expression_") + (n ? n : std::to_string(t.number));
  }
  const afm_fap_info *f = afm_fap(t.number);
  std::string name = f ? f->name : "fap_" + std::to_string(t.number);
  if (t.reference < 0) name += "_neg";
  if (t.kind == AFM_TARGET_COMBINATION) {
    const afm_fap_info *g = afm_fap(t.gate);
    name += "_" + std::to_string(std::abs(t.reference)) + "_with_" + (g ? g->name : "fap_" + std::to_string(t.gate));
  }
  return name;
}

std::vector<std::string> target_names(const afm_doc &doc) {
  std::vector<std::string> names;
  for (uint32_t i = 0; i < doc.target_count; ++i) names.push_back(target_name(doc.targets[i]));
  // In-betweens: every target of a FAP side but the one nearest zero.
  for (uint32_t i = 0; i < doc.target_count; ++i) {
    const afm_target &t = doc.targets[i];
    if (t.kind != AFM_TARGET_FAP) continue;
    for (uint32_t j = 0; j < doc.target_count; ++j) {
      const afm_target &u = doc.targets[j];
      if (j != i && u.kind == t.kind && u.number == t.number && (u.reference > 0) == (t.reference > 0) &&
          std::abs(u.reference) < std::abs(t.reference)) {
        names[i] += "_" + std::to_string(std::abs(t.reference));
        break;
      }
    }
  }
  return names;
}

Eigen::MatrixXd target_part_deltas(const afm_doc &doc, const afm_target &t, const afm_part &part) {
  std::vector<int32_t> q15(3 * static_cast<size_t>(afm_doc_entry_count(&doc)));
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(part.vertex_count, 3);
  if (afm_target_expand(&doc, &t, q15.data()) != AFM_OK) return d;  // a doc the reader accepted
  for (uint32_t i = 0; i < part.vertex_count; ++i)
    for (int c = 0; c < 3; ++c) d(i, c) = q15[3 * size_t(part.first_vertex + i) + size_t(c)] / 32768.0;
  return d;
}

bool target_moves_part(const afm_doc &doc, const afm_target &t, const afm_part &part) {
  return (target_part_deltas(doc, t, part).array() != 0).any();
}

int position_decimals(float step) {
  int d = 0;
  while (d < 12 && std::pow(10.0, -d) > step / 10.0) ++d;
  return d;
}

Eigen::MatrixXd part_positions(const afm_doc &doc, const afm_part &part, const afm_target *target,
                               int decimals) {
  const afm_geometry &g = doc.geometry;
  Eigen::MatrixXd q(part.vertex_count, 3);
  for (uint32_t i = 0; i < part.vertex_count; ++i) {
    const uint32_t v = part.first_vertex + i;
    q(i, 0) = g.px[v], q(i, 1) = g.py[v], q(i, 2) = g.pz[v];
  }
  if (target) q += target_part_deltas(doc, *target, part);
  Eigen::MatrixXd p(part.vertex_count, 3);
  for (uint32_t i = 0; i < part.vertex_count; ++i)
    for (int c = 0; c < 3; ++c)
      p(i, c) = round_to(double(g.origin[c]) + q(i, c) * double(g.step), decimals);
  return p;
}

Scene afm_scene(const afm_doc &doc, int decimals) {
  const afm_geometry &g = doc.geometry;
  Scene scene;
  scene.name = doc.meta.name;
  scene.units = doc.meta.units;
  for (uint32_t pi = 0; pi < g.part_count; ++pi) {
    const afm_part &ap = g.parts[pi];
    Part p;
    p.name = ap.name;
    p.kind = static_cast<PartKind>(ap.kind < AFM_PART_KIND_COUNT ? ap.kind : 0);
    p.V = part_positions(doc, ap, nullptr, decimals);
    p.F.resize(ap.triangle_count, 3);
    for (uint32_t t = 0; t < ap.triangle_count; ++t)
      for (int c = 0; c < 3; ++c)
        p.F(t, c) = int(g.triangles[3 * size_t(ap.first_triangle + t) + c] - ap.first_vertex);
    if (g.u && g.v) {
      p.TC.resize(ap.vertex_count, 2);
      for (uint32_t i = 0; i < ap.vertex_count; ++i) {
        const uint32_t v = ap.first_vertex + i;
        // uv quanta are 16-bit: 6 decimals keep them apart on any sane grid.
        p.TC(i, 0) = round_to(g.uv_origin[0] + double(g.u[v]) * g.uv_step[0], 6);
        p.TC(i, 1) = round_to(g.uv_origin[1] + double(g.v[v]) * g.uv_step[1], 6);
      }
      p.FTC = p.F;
    }
    if (g.rgba) {
      p.C.resize(ap.vertex_count, 3);
      for (uint32_t i = 0; i < ap.vertex_count; ++i)
        for (int c = 0; c < 3; ++c)
          p.C(i, c) = round_to(g.rgba[4 * size_t(ap.first_vertex + i) + c] / 255.0, 4);
    }
    p.diffuse = Eigen::Vector3d(ap.diffuse[0], ap.diffuse[1], ap.diffuse[2]) / 255.0;
    for (int c = 0; c < 3; ++c) p.diffuse[c] = round_to(p.diffuse[c], 4);
    p.texture = ap.texture;
    scene.parts.push_back(std::move(p));
  }
  return scene;
}

}  // namespace afmb
