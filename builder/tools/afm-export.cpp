// afm-export: an AFM (and a FAP stream) -> glTF 2.0 binary, VRML97 AFM, OBJ per target.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "export/export_model.h"
#include "export/gltf_export.h"
#include "export/obj_export.h"
#include "export/vrml_export.h"

using namespace afmb;

namespace {

void usage(FILE *out) {
  std::fprintf(out,
      "usage: afm-export FACE.afm [--gltf FILE.glb [--fap STREAM.fap] [--textures DIR]]\n"
      "                           [--vrml FILE.wrl] [--obj DIR] [--quiet]\n"
      "\n"
      "Writes an Animatable Face Model in formats other tools read (formats/export.md).\n"
      "At least one output is needed; several may be given.\n"
      "\n"
      "  FACE.afm             the model (raw or draco profile)\n"
      "  --gltf FILE.glb      glTF 2.0 binary: a mesh per part with its colours,\n"
      "                       texture coordinates and (PNG or JPEG) texture, a named\n"
      "                       morph target per FAP, viseme and expression target the\n"
      "                       AFM holds (mesh.extras.targetNames: \"open_jaw\",\n"
      "                       \"viseme_A\", \"expression_joy\"), and the eyes, jaw and head\n"
      "                       as nodes turning about their pivots\n"
      "  --fap STREAM.fap     with --gltf: an animation of the stream, keyed at each of\n"
      "                       its frames: the player's morph weights and the rigid\n"
      "                       parts' rotations (FAPs 23-28, 48-50, the jaw's 3, 14, 15)\n"
      "  --textures DIR       with --gltf: look for texture files here first, then\n"
      "                       beside FACE.afm\n"
      "  --vrml FILE.wrl      VRML97 AFM: the neutral face, which any VRML viewer\n"
      "                       shows, with every morph target stored in a Switch that\n"
      "                       is not drawn (whichChoice -1), each target's parts at\n"
      "                       its reference value\n"
      "  --obj DIR            DIR/neutral.obj and DIR/<target>.obj per morph target,\n"
      "                       each the whole face with the target fully applied (at its\n"
      "                       reference value), and DIR/materials.mtl with each\n"
      "                       part's colour and texture name; DIR is created when\n"
      "                       missing\n"
      "  --quiet              no progress and no summary\n"
      "  --help               this text\n"
      "\n"
      "Every file is written completely or not at all, and when one output fails\n"
      "the others this run wrote are removed. Exit status: 0 on success,\n"
      "1 on bad input (the message names the file and line, chunk or field) or a\n"
      "failed write, 2 on bad usage.\n");
}

int fail(const Status &s) {
  std::fprintf(stderr, "afm-export: %s\n", s.message().c_str());
  return 1;
}

int usage_error(const std::string &message) {
  std::fprintf(stderr, "afm-export: %s (see --help)\n", message.c_str());
  return 2;
}

// Progress on stderr: every `every` items, and the last one.
std::function<void(size_t, size_t)> progress_printer(bool quiet, const char *what, size_t every) {
  if (quiet) return {};
  return [what, every](size_t done, size_t total) {
    if (total >= 2 * every && (done % every == 0 || done == total))
      std::fprintf(stderr, "afm-export: %s %zu of %zu\n", what, done, total);
  };
}

}  // namespace

int main(int argc, char **argv) {
  std::string afm_path, gltf_path, fap_path, vrml_path, obj_dir, textures_dir;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](std::string *out) -> bool {
      if (i + 1 >= argc) return false;
      *out = argv[++i];
      return true;
    };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "--gltf") {
      if (!value(&gltf_path)) return usage_error("--gltf needs a file name");
    } else if (a == "--fap") {
      if (!value(&fap_path)) return usage_error("--fap needs a file name");
    } else if (a == "--textures") {
      if (!value(&textures_dir)) return usage_error("--textures needs a directory");
    } else if (a == "--vrml") {
      if (!value(&vrml_path)) return usage_error("--vrml needs a file name");
    } else if (a == "--obj") {
      if (!value(&obj_dir)) return usage_error("--obj needs a directory");
    } else if (a == "--quiet") {
      quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      return usage_error("unknown option " + a);
    } else if (afm_path.empty()) {
      afm_path = a;
    } else {
      return usage_error("more than one model: " + afm_path + " and " + a);
    }
  }
  if (afm_path.empty()) return usage_error("no model given");
  if (gltf_path.empty() && vrml_path.empty() && obj_dir.empty())
    return usage_error("no output: give --gltf, --vrml or --obj");
  if (gltf_path.empty() && (!fap_path.empty() || !textures_dir.empty()))
    return usage_error(std::string(fap_path.empty() ? "--textures" : "--fap") + " needs --gltf");

  Expected<AfmDocPtr> doc = read_afm_file(afm_path);
  if (!doc) return fail(doc.status());
  const afm_doc &d = **doc;
  if (d.geometry.triangle_count == 0) return fail(Status::error(afm_path + ": the model has no triangles"));

  // Read every input before writing anything.
  FapStream stream;
  if (!fap_path.empty()) {
    Expected<FapStream> s = read_fap_file(fap_path);
    if (!s) return fail(s.status());
    stream = std::move(*s);
  }

  // Files of this run, removed again when a later output fails; the
  // summary is printed once every output is written.
  std::vector<std::string> written;
  std::string summary;
  char line[512];
  auto fail_run = [&written](const Status &s) {
    std::error_code ec;
    for (const std::string &f : written) std::filesystem::remove(f, ec);
    return fail(s);
  };
  if (!gltf_path.empty()) {
    GltfOptions o;
    if (!fap_path.empty()) {
      o.stream = &stream;
      o.stream_path = fap_path;
    }
    if (!textures_dir.empty()) o.texture_dirs.push_back(textures_dir);
    o.texture_dirs.push_back(std::filesystem::path(afm_path).parent_path().string());
    if (o.texture_dirs.back().empty()) o.texture_dirs.back() = ".";
    o.note = [](const std::string &text) { std::fprintf(stderr, "afm-export: note: %s\n", text.c_str()); };
    o.progress = progress_printer(quiet, "frame", 250);
    GltfStats st;
    if (Status s = export_gltf(d, afm_path, gltf_path, o, &st); !s) return fail_run(s);
    written.push_back(gltf_path);
    std::snprintf(line, sizeof line,
                  "%s: glTF, %zu bytes: %zu meshes, %zu nodes, %zu of %u morph targets (%zu on meshes), "
                  "%zu animation keys, %zu textures\n",
                  gltf_path.c_str(), st.bytes, st.meshes, st.nodes, st.targets, d.target_count,
                  st.mesh_targets, st.frames, st.textures);
    summary += line;
  }
  if (!vrml_path.empty()) {
    VrmlExportStats st;
    if (Status s = export_vrml(d, afm_path, vrml_path, &st); !s) return fail_run(s);
    written.push_back(vrml_path);
    std::snprintf(line, sizeof line, "%s: VRML97, %zu bytes: %u parts, %u morph targets in %zu shapes\n",
                  vrml_path.c_str(), st.bytes, d.geometry.part_count, d.target_count, st.target_shapes);
    summary += line;
  }
  if (!obj_dir.empty()) {
    ObjExportStats st;
    if (Status s = export_obj(d, obj_dir, progress_printer(quiet, "OBJ", 50), &st); !s) return fail_run(s);
    std::snprintf(line, sizeof line, "%s: %zu OBJ files (neutral + %u targets), %zu bytes\n",
                  obj_dir.c_str(), st.files, d.target_count, st.bytes);
    summary += line;
  }
  if (!quiet) std::fputs(summary.c_str(), stdout);
  return 0;
}
