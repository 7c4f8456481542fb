#include "render/scene_render.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "afm/render.h"

namespace afmb {

namespace {

struct MeshData {
  std::vector<float> pos;
  std::vector<uint32_t> tris;
  std::vector<uint8_t> rgba;
};

uint8_t to_byte(double c) { return (uint8_t)std::lround(std::clamp(c, 0.0, 1.0) * 255.0); }

MeshData part_data(const Part &p) {
  MeshData m;
  m.pos.resize((size_t)p.V.rows() * 3);
  for (int i = 0; i < p.V.rows(); ++i)
    for (int k = 0; k < 3; ++k) m.pos[(size_t)i * 3 + k] = (float)p.V(i, k);
  m.tris.resize((size_t)p.F.rows() * 3);
  for (int f = 0; f < p.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) m.tris[(size_t)f * 3 + k] = (uint32_t)p.F(f, k);
  if (p.C.rows() == p.V.rows() && p.C.cols() == 3) {
    m.rgba.resize((size_t)p.V.rows() * 4);
    for (int i = 0; i < p.V.rows(); ++i) {
      for (int k = 0; k < 3; ++k) m.rgba[(size_t)i * 4 + k] = to_byte(p.C(i, k));
      m.rgba[(size_t)i * 4 + 3] = 255;
    }
  }
  return m;
}

// FDPs on the skin red, on other parts green, free points blue.
void fdp_dots(const FdpSet &fdps, const Scene &scene, MeshData dots[3]) {
  for (const FdpPoint &p : fdps.points) {
    int kind = 2;
    if (p.part >= 0 && p.part < (int)scene.parts.size())
      kind = scene.parts[p.part].kind == PartKind::Skin ? 0 : 1;
    for (int k = 0; k < 3; ++k) dots[kind].pos.push_back((float)p.pos[k]);
  }
}

bool in_face(const FdpId &id) { return id.group != 10 && id.group != 11 && id.group != 7; }

}  // namespace

Expected<std::vector<std::vector<uint8_t>>> render_scene(const Scene &scene, const FdpSet *fdps,
                                                         const SceneRenderOptions &options,
                                                         afm_renderer *renderer) {
  if (options.width <= 0 || options.height <= 0 || options.views.empty())
    return Status::error("render: need a positive image size and at least one view");
  std::vector<MeshData> data;
  for (const Part &p : scene.parts) {
    if (p.V.rows() == 0 || p.F.rows() == 0) continue;
    data.push_back(part_data(p));
  }
  std::vector<afm_render_mesh> meshes;
  size_t di = 0;
  for (const Part &p : scene.parts) {
    if (p.V.rows() == 0 || p.F.rows() == 0) continue;
    const MeshData &d = data[di++];
    afm_render_mesh m{};
    m.positions = d.pos.data();
    m.vertex_count = (size_t)p.V.rows();
    m.triangles = d.tris.data();
    m.triangle_count = (size_t)p.F.rows();
    m.colors = d.rgba.empty() ? nullptr : d.rgba.data();
    for (int k = 0; k < 3; ++k) m.color[k] = (float)p.diffuse[k];
    m.color[3] = 1.0f;
    m.wireframe = options.wireframe && p.kind == PartKind::Skin;
    meshes.push_back(m);
  }
  MeshData dots[3];
  const float dot_colour[3][4] = {{0.95f, 0.1f, 0.1f, 1}, {0.1f, 0.85f, 0.2f, 1}, {0.2f, 0.4f, 1.0f, 1}};
  if (fdps && options.fdp_dot_pixels > 0) {
    fdp_dots(*fdps, scene, dots);
    for (int k = 0; k < 3; ++k) {
      if (dots[k].pos.empty()) continue;
      afm_render_mesh m{};
      m.positions = dots[k].pos.data();
      m.vertex_count = dots[k].pos.size() / 3;
      for (int c = 0; c < 4; ++c) m.color[c] = dot_colour[k][c];
      m.unlit = 1;
      m.point_size = options.fdp_dot_pixels;
      m.depth_bias = 0.002f;  // model units: FDPs lie on surfaces
      meshes.push_back(m);
    }
  }
  // Overlay markers; their positions live in marker_pos while meshes points at them.
  std::vector<std::vector<float>> marker_pos(options.markers.size());
  float auto_bias = -1.0f;
  for (size_t i = 0; i < options.markers.size(); ++i) {
    const SceneMarkers &mk = options.markers[i];
    if (mk.points.rows() == 0) continue;
    if (mk.points.cols() != 3)
      return Status::error("render: marker set " + std::to_string(i) + " has " +
                           std::to_string(mk.points.cols()) + " columns, not 3");
    std::vector<float> &pos = marker_pos[i];
    pos.resize((size_t)mk.points.rows() * 3);
    for (int r = 0; r < mk.points.rows(); ++r)
      for (int k = 0; k < 3; ++k) pos[(size_t)r * 3 + k] = (float)mk.points(r, k);
    float bias = mk.depth_bias;
    if (bias == 0.0f) {
      if (auto_bias < 0.0f) {
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300);
        Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e300);
        for (const Part &p : scene.parts)
          if (p.V.rows() > 0 && p.V.cols() == 3) {
            lo = lo.cwiseMin(p.V.colwise().minCoeff().transpose());
            hi = hi.cwiseMax(p.V.colwise().maxCoeff().transpose());
          }
        auto_bias = lo.x() <= hi.x() ? (float)(0.01 * (hi - lo).norm()) : 0.0f;
      }
      bias = auto_bias;
    }
    afm_render_mesh m{};
    m.positions = pos.data();
    m.vertex_count = (size_t)mk.points.rows();
    for (int c = 0; c < 3; ++c) m.color[c] = std::clamp(mk.color[c], 0.0f, 1.0f);
    m.color[3] = 1.0f;
    m.unlit = 1;
    m.point_size = mk.size_pixels;
    m.depth_bias = bias;
    meshes.push_back(m);
  }
  if (meshes.empty()) return Status::error("render: the scene has no triangles");

  afm_render_view view;
  afm_render_view_init(&view, options.width, options.height);
  if (options.face_closeup && fdps) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (const FdpPoint &p : fdps->points) {
      if (!in_face(p.id)) continue;
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], (float)p.pos[k]);
        hi[k] = std::max(hi[k], (float)p.pos[k]);
      }
    }
    if (lo[0] <= hi[0])  // markers stay in the picture
      for (const std::vector<float> &pos : marker_pos)
        for (size_t i = 0; i < pos.size(); ++i) {
          lo[i % 3] = std::min(lo[i % 3], pos[i]);
          hi[i % 3] = std::max(hi[i % 3], pos[i]);
        }
    if (lo[0] <= hi[0]) {
      const float pad = 0.15f * (hi[1] - lo[1]);
      for (int k = 0; k < 3; ++k) {
        view.box_min[k] = lo[k] - pad;
        view.box_max[k] = hi[k] + pad;
      }
    }
  }

  afm_renderer *own = nullptr;
  if (!renderer) {
    if (afm_renderer_create(&own) != AFM_OK) return Status::error(std::string("render: ") + afm_render_last_error());
    renderer = own;
  }
  std::vector<std::vector<uint8_t>> images;
  for (const SceneView &v : options.views) {
    view.yaw_deg = v.yaw_deg;
    view.pitch_deg = v.pitch_deg;
    std::vector<uint8_t> rgba((size_t)options.width * options.height * 4);
    if (afm_renderer_draw(renderer, meshes.data(), meshes.size(), &view, rgba.data()) != AFM_OK) {
      std::string msg = afm_render_last_error();
      afm_renderer_destroy(own);
      return Status::error("render: " + msg);
    }
    images.push_back(std::move(rgba));
  }
  afm_renderer_destroy(own);
  return images;
}

Status render_scene_png(const Scene &scene, const FdpSet *fdps, const SceneRenderOptions &options,
                        const std::string &path) {
  Expected<std::vector<std::vector<uint8_t>>> images = render_scene(scene, fdps, options);
  if (!images) return images.status();
  std::vector<afm_render_image> tiles;
  for (const auto &im : *images) tiles.push_back({im.data(), options.width, options.height});
  const uint8_t bg[4] = {60, 60, 60, 255};
  if (afm_sheet_write_png(path.c_str(), tiles.data(), (int)tiles.size(), (int)tiles.size(), 0, bg) !=
      AFM_OK)
    return Status::error(std::string("render: ") + afm_render_last_error());
  return Status::ok();
}

}  // namespace afmb
