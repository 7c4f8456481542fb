#include "export/vrml_export.h"

#include <set>

#include "core/atomic_file.h"
#include "export/export_model.h"
#include "io/vrml.h"

namespace afmb {

namespace {

const char *kind_word(uint8_t kind) {
  return kind == AFM_TARGET_VISEME        ? "viseme"
         : kind == AFM_TARGET_EXPRESSION  ? "expression"
         : kind == AFM_TARGET_COMBINATION ? "combination"
                                          : "fap";
}

// A DEF name not yet used in the file (target names are legal VRML ids).
std::string unique_name(const std::string &name, std::set<std::string> *used) {
  std::string id = name;
  for (int k = 2; used->count(id); ++k) id = name + "_" + std::to_string(k);
  used->insert(id);
  return id;
}

}  // namespace

Expected<std::string> vrml_afm_text(const afm_doc &doc, const std::string &source,
                                    VrmlExportStats *stats) {
  const afm_geometry &g = doc.geometry;
  const int decimals = position_decimals(g.step);
  const Scene neutral = afm_scene(doc, decimals);
  const std::vector<std::string> names = target_names(doc);

  // Per target, the parts it moves: a Scene of "<target>__<part>" parts.
  std::vector<Scene> targets(doc.target_count);
  size_t shapes = 0;
  for (uint32_t t = 0; t < doc.target_count; ++t) {
    for (uint32_t pi = 0; pi < g.part_count; ++pi) {
      const afm_part &ap = g.parts[pi];
      const Eigen::MatrixXd d = target_part_deltas(doc, doc.targets[t], ap);
      if ((d.array() == 0).all()) continue;
      Part p;
      p.name = names[t] + "__" + neutral.parts[pi].name;
      p.kind = neutral.parts[pi].kind;
      p.diffuse = neutral.parts[pi].diffuse;
      p.V = part_positions(doc, ap, &doc.targets[t], decimals);
      const Eigen::MatrixXi &F = neutral.parts[pi].F;
      std::vector<int> rows;
      for (Eigen::Index f = 0; f < F.rows(); ++f)
        if (d.row(F(f, 0)).any() || d.row(F(f, 1)).any() || d.row(F(f, 2)).any()) rows.push_back(int(f));
      p.F.resize(Eigen::Index(rows.size()), 3);
      for (size_t k = 0; k < rows.size(); ++k) p.F.row(Eigen::Index(k)) = F.row(rows[k]);
      targets[t].parts.push_back(std::move(p));
      ++shapes;
    }
  }

  std::string out = "#VRML V2.0 utf8\n";
  out += "# " + std::string(doc.meta.name) +
         ": an Animatable Face Model written by afm-export. The neutral face is drawn;\n"
         "# the morph targets are in the Switch afm_morph_targets (formats/export.md).\n\n";
  out += "WorldInfo {\n  title " + vrml_string(doc.meta.name) + "\n  info [\n";
  out += "    \"afm-vrml 1\",\n";
  out += "    " + vrml_string(std::string("units ") + (doc.meta.units[0] ? doc.meta.units : "?")) + ",\n";
  out += "    " + vrml_string("fapu ES0 " + std::to_string(doc.meta.es0) + " IRISD0 " +
                              std::to_string(doc.meta.irisd0) + " ENS0 " + std::to_string(doc.meta.ens0) +
                              " MNS0 " + std::to_string(doc.meta.mns0) + " MW0 " +
                              std::to_string(doc.meta.mw0)) + ",\n";
  for (uint32_t t = 0; t < doc.target_count; ++t) {
    const afm_target &at = doc.targets[t];
    std::string line = "target " + names[t] + " " + kind_word(at.kind) + " " + std::to_string(at.number) +
                       " reference " + std::to_string(at.reference) +
                       (at.kind == AFM_TARGET_COMBINATION ? " gate " + std::to_string(at.gate) + " gate_reference " +
                                                                std::to_string(at.gate_reference)
                                                          : std::string()) +
                       " parts";
    for (const Part &p : targets[t].parts) line += " " + p.name.substr(names[t].size() + 2);
    out += "    " + vrml_string(line) + ",\n";
  }
  out += "  ]\n}\n\n";

  std::set<std::string> used = {"afm_morph_targets"};
  Expected<std::string> body = vrml_parts_text(neutral, &used, source);
  if (!body) return body.status();
  out += *body;

  out += "DEF afm_morph_targets Switch {\n  whichChoice -1\n  choice [\n";
  for (uint32_t t = 0; t < doc.target_count; ++t) {
    const afm_target &at = doc.targets[t];
    out += "# " + names[t] + ": " + kind_word(at.kind) + " " + std::to_string(at.number) +
           ", reference " + std::to_string(at.reference) + "\n";
    out += "DEF " + unique_name(names[t], &used) + " Group {\n children [\n";
    Expected<std::string> parts = vrml_parts_text(targets[t], &used, source);
    if (!parts) return parts.status();
    out += *parts;
    out += " ]\n}\n";
  }
  out += "  ]\n}\n";
  if (stats) {
    stats->bytes = out.size();
    stats->target_shapes = shapes;
  }
  return out;
}

Status export_vrml(const afm_doc &doc, const std::string &source, const std::string &path,
                   VrmlExportStats *stats) {
  Expected<std::string> text = vrml_afm_text(doc, source, stats);
  if (!text) return text.status();
  return write_file_atomic(path, *text);
}

}  // namespace afmb
