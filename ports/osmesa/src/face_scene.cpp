// An AFM ready to draw. See afm/face_scene.h.
#include "afm/face_scene.h"

#include <afm/draco.h>
#include <afm/fap_stream.h>
#include <afm/view_options.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace fs = std::filesystem;

namespace afm_face {

namespace {

// The file a part's texture names: in the textures directory, then beside
// the model; an exact name first, then the same name in another case (models
// made on case-insensitive file systems). Empty when not found.
std::string find_texture(const std::string &name, const std::vector<fs::path> &dirs) {
  std::error_code ec;
  const fs::path n(name);
  if (n.is_absolute()) return fs::is_regular_file(n, ec) ? n.string() : std::string();
  for (const fs::path &d : dirs) {
    const fs::path p = d / n;
    if (fs::is_regular_file(p, ec)) return p.string();
  }
  const std::string want = lower(n.filename().string());
  for (const fs::path &d : dirs) {
    const fs::path sub = (d / n).parent_path();
    if (!fs::is_directory(sub, ec)) continue;
    for (fs::directory_iterator it(sub, ec), end; !ec && it != end; it.increment(ec))
      if (lower(it->path().filename().string()) == want && fs::is_regular_file(it->path(), ec))
        return it->path().string();
  }
  return {};
}

// Cut-out textures (hair, lashes) often hold white or black where they are
// transparent, and filtering blends that into the edges of what is drawn: a
// bright fringe. Transparent texels take the mean colour of the opaque ones.
void fill_transparent(afm_image *im) {
  const size_t n = (size_t)im->width * im->height;
  double sum[3] = {0, 0, 0}, count = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t *p = im->rgba + i * 4;
    if (p[3] < 128) continue;
    for (int k = 0; k < 3; ++k) sum[k] += p[k];
    count += 1;
  }
  if (count == 0) return;
  for (size_t i = 0; i < n; ++i) {
    uint8_t *p = im->rgba + i * 4;
    if (p[3] >= 128) continue;
    for (int k = 0; k < 3; ++k) p[k] = (uint8_t)std::lround(sum[k] / count);
  }
}

// Each part's texture (nullptr for none), loaded once per file.
std::vector<const Texture *> load_textures(FaceScene &scene, const FaceOptions &o, bool have_uvs) {
  const afm_geometry &g = scene.doc->geometry;
  std::vector<const Texture *> part_texture(g.part_count, nullptr);
  std::vector<fs::path> dirs;
  if (!o.textures_dir.empty()) {
    std::error_code ec;
    if (!fs::is_directory(o.textures_dir, ec))
      throw InputError("--textures " + o.textures_dir + ": not a directory");
    dirs.push_back(o.textures_dir);
  }
  {
    fs::path beside = fs::path(o.model_path).parent_path();
    dirs.push_back(beside.empty() ? fs::path(".") : beside);
  }
  if (!have_uvs || o.no_textures) return part_texture;
  for (uint32_t p = 0; p < g.part_count; ++p) {
    const afm_part &part = g.parts[p];
    if (!part.texture || !part.texture[0] || part.triangle_count == 0) continue;
    const std::string file = find_texture(part.texture, dirs);
    if (file.empty()) {
      std::string where;
      for (const fs::path &d : dirs) where += (where.empty() ? "" : " or ") + d.string();
      throw InputError(o.model_path + ": part " + part.name + ": texture '" + part.texture +
                       "' is not in " + where + " (give --textures DIR, or --no-textures)");
    }
    auto it = scene.textures.find(file);
    if (it == scene.textures.end()) {
      auto t = std::make_unique<Texture>();
      if (afm_image_read(file.c_str(), &t->image) != AFM_OK)
        throw InputError(std::string(afm_render_last_error()) + " (texture of part " + part.name + ")");
      if (t->image.has_alpha) fill_transparent(&t->image);
      t->view = {t->image.rgba, t->image.width, t->image.height};
      it = scene.textures.emplace(file, std::move(t)).first;
    }
    part_texture[p] = it->second.get();
  }
  return part_texture;
}

// The framing box: the neutral model, or with closeup its face (FDPs without
// spine, ears and skull, with room around them and more above).
void frame_box(FaceScene &scene, const FaceOptions &o) {
  const afm_doc &doc = *scene.doc;
  const afm_geometry &g = doc.geometry;
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  if (o.closeup) {
    for (uint32_t i = 0; i < doc.meta.fdp_count; ++i) {
      const afm_fdp_point &f = doc.meta.fdps[i];
      if (f.group == 7 || f.group == 10 || f.group == 11) continue;  // spine, ears, skull
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], f.pos[k]), hi[k] = std::max(hi[k], f.pos[k]);
    }
    if (lo[0] > hi[0] || hi[1] - lo[1] <= 0)
      throw InputError(o.model_path + ": --closeup frames the face by its FDPs, and the model has none");
    const float pad = 0.15f * (hi[1] - lo[1]);
    for (int k = 0; k < 3; ++k) lo[k] -= pad, hi[k] += pad;
    hi[1] += 2 * pad;
  } else {
    const int16_t *q[3] = {g.px, g.py, g.pz};
    for (size_t v = 0; v < g.vertex_count; ++v)
      for (int k = 0; k < 3; ++k) {
        const float x = (float)(g.origin[k] + (double)q[k][v] * g.step);
        lo[k] = std::min(lo[k], x);
        hi[k] = std::max(hi[k], x);
      }
  }
  for (int k = 0; k < 3; ++k) scene.box_min[k] = lo[k], scene.box_max[k] = hi[k];
}

}  // namespace

std::vector<uint8_t> read_whole(const std::string &path) {
  uint8_t *data = nullptr;
  size_t size = 0;
  errno = 0;
  const afm_result r = afm_file_read(path.c_str(), nullptr, &data, &size);
  if (r != AFM_OK) {
    const int e = errno;
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw InputError(path + ": is a directory, not a file");
    throw InputError(path + ": cannot read: " + (e ? std::strerror(e) : afm_result_string(r)));
  }
  std::vector<uint8_t> out(data, data + size);
  afm_free(nullptr, data);
  return out;
}

Doc load_model(const std::string &path) {
  const std::vector<uint8_t> bytes = read_whole(path);
  afm_diag diag{};
  afm_read_options ro{};
  ro.draco = afm_draco_codec();
  ro.diag = &diag;
  afm_doc *doc = nullptr;
  const afm_result r = afm_doc_read_alloc(bytes.data(), bytes.size(), &ro, nullptr, &doc);
  if (r != AFM_OK)
    throw InputError(path + ": " + (diag.message[0] ? diag.message : afm_result_string(r)));
  Doc d(doc);
  if (doc->geometry.vertex_count == 0 || doc->geometry.triangle_count == 0)
    throw InputError(path + ": the model has no triangles to draw");
  return d;
}

Stream load_stream(const std::string &path) {
  const std::vector<uint8_t> bytes = read_whole(path);
  Stream s;
  afm_diag diag{};
  uint32_t count = 0;
  afm_result r = afm_fap_parse(bytes.data(), bytes.size(), nullptr, nullptr, 0, &count, nullptr,
                               nullptr, &diag);
  if (r == AFM_OK) {
    if (count == 0) throw InputError(path + ": the stream has no frames");
    s.frames.resize(count);
    r = afm_fap_parse(bytes.data(), bytes.size(), nullptr, s.frames.data(), count, &count, &s.header,
                      &s.stats, &diag);
  }
  if (r != AFM_OK) {
    const std::string msg = diag.message[0] ? diag.message : afm_result_string(r);
    // The reader's messages may already start with "line N:".
    if (diag.line && msg.rfind("line ", 0) != 0)
      throw InputError(path + ":" + std::to_string(diag.line) + ": " + msg);
    if (diag.line)
      throw InputError(path + ":" + std::to_string(diag.line) + ": " + msg.substr(msg.find(':') + 2));
    throw InputError(path + ": " + msg);
  }
  s.frames.resize(count);
  return s;
}

uint64_t frame_time_us(uint64_t k, uint32_t num, uint32_t den) {
  const uint64_t ticks = k * den;
  return ticks / num * 1000000u + ticks % num * 1000000u / num;
}

void init_face(FaceScene &scene, const afm_doc &doc, const FaceOptions &o) {
  scene.doc = &doc;
  const afm_geometry &g = doc.geometry;
  const bool have_uvs = g.u && g.v && (g.attributes & AFM_ATTR_TEXCOORDS);
  const std::vector<const Texture *> part_texture = load_textures(scene, o, have_uvs);

  afm_player_options po{};
  size_t bytes = 0;
  afm_result res = afm_player_measure(&doc, &po, &bytes);
  if (res == AFM_OK) {
    scene.player_memory = std::malloc(bytes ? bytes : 1);
    if (!scene.player_memory) res = AFM_ERR_OUT_OF_MEMORY;
  }
  if (res == AFM_OK) res = afm_player_init(&doc, &po, scene.player_memory, bytes, &scene.player);
  if (res != AFM_OK) throw InputError(o.model_path + ": cannot play: " + afm_result_string(res));

  // One mesh per part over shared vertex arrays (triangles index the whole
  // vertex list).
  const size_t V = g.vertex_count;
  scene.positions.assign(V * 3, 0.0f);
  scene.normals.assign(V * 3, 0.0f);
  if (have_uvs) {
    scene.uvs.resize(V * 2);
    for (size_t v = 0; v < V; ++v) {
      scene.uvs[v * 2] = (float)(g.uv_origin[0] + (double)g.u[v] * g.uv_step[0]);
      const double tv = g.uv_origin[1] + (double)g.v[v] * g.uv_step[1];
      scene.uvs[v * 2 + 1] = (float)(o.flip_v ? 1.0 - tv : tv);
    }
  }
  for (uint32_t p = 0; p < g.part_count; ++p) {
    const afm_part &part = g.parts[p];
    if (part.triangle_count == 0) continue;
    afm_render_mesh m{};
    m.positions = scene.positions.data();
    m.vertex_count = V;
    m.triangles = g.triangles + (size_t)part.first_triangle * 3;
    m.triangle_count = part.triangle_count;
    m.normals = scene.normals.data();
    const bool colours = g.rgba && (g.attributes & AFM_ATTR_COLORS);
    m.colors = colours ? g.rgba : nullptr;
    if (part_texture[p]) {
      // VRML: a texture replaces the diffuse colour (vertex colours still modulate).
      m.uvs = scene.uvs.data();
      m.texture = &part_texture[p]->view;
      m.texture_static = 1;  // loaded once, never changed
      for (int k = 0; k < 4; ++k) m.color[k] = 1.0f;
      if (part_texture[p]->image.has_alpha) m.alpha_cutoff = 0.5f;
      ++scene.textured_parts;
    } else {
      for (int k = 0; k < 4; ++k) m.color[k] = part.diffuse[k] / 255.0f;
      m.color[3] = 1.0f;
    }
    scene.meshes.push_back(m);
  }
  frame_box(scene, o);
  afm_fap_state neutral;
  afm_fap_state_reset(&neutral);
  res = pose_face(scene, &neutral, nullptr, 0);
  if (res != AFM_OK) throw InputError(o.model_path + ": cannot pose the neutral face: " + afm_result_string(res));
}

afm_result pose_face(FaceScene &scene, const afm_fap_state *a, const afm_fap_state *b, afm_q16 t) {
  const afm_result res = afm_player_pose(scene.player, a, b, t);
  if (res != AFM_OK) return res;
  const afm_geometry &g = scene.doc->geometry;
  const int32_t *x = afm_player_positions(scene.player);
  const afm_q14 *n = afm_player_normals(scene.player);
  for (size_t i = 0; i < (size_t)g.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) {
      scene.positions[i * 3 + (size_t)k] = (float)(g.origin[k] + (double)x[i * 3 + (size_t)k] * g.step);
      scene.normals[i * 3 + (size_t)k] = (float)n[i * 3 + (size_t)k] * (1.0f / 16384.0f);
    }
  return AFM_OK;
}

}  // namespace afm_face
