#include "export/gltf_export.h"

#include <afm/player.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>

#include "core/atomic_file.h"
#include "export/json_writer.h"

namespace afmb {
namespace {

namespace fs = std::filesystem;

// glTF enums (glTF 2.0 spec, 5.1 accessor.componentType, 5.11 bufferView.target).
constexpr int kUnsignedByte = 5121, kUnsignedShort = 5123, kUnsignedInt = 5125, kFloat = 5126;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

struct View {
  size_t offset = 0, length = 0;
  int target = 0;  // 0: none
};

struct Accessor {
  int view = -1;  // -1: no data (zeros, or the sparse substitution alone)
  int component = kFloat;
  size_t count = 0;
  const char *type = "SCALAR";
  bool normalized = false;
  std::vector<double> min, max;  // empty: not written
  size_t sparse_count = 0;       // > 0: sparse
  int sparse_index_view = -1, sparse_index_component = kUnsignedInt, sparse_value_view = -1;
};

// The binary chunk and the JSON objects that describe it.
struct Glb {
  std::vector<uint8_t> bin;
  std::vector<View> views;
  std::vector<Accessor> accessors;

  int add_view(const void *data, size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back(0);
    View v;
    v.offset = bin.size();
    v.length = bytes;
    v.target = target;
    const uint8_t *p = static_cast<const uint8_t *>(data);
    bin.insert(bin.end(), p, p + bytes);
    views.push_back(v);
    return int(views.size() - 1);
  }
  int add_accessor(const Accessor &a) {
    accessors.push_back(a);
    return int(accessors.size() - 1);
  }
  // Floats in groups of `width` (1 SCALAR, 2 VEC2, 3 VEC3, 4 VEC4).
  int add_floats(const std::vector<float> &v, int width, int target, bool bounds) {
    static const char *types[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    Accessor a;
    a.view = add_view(v.data(), v.size() * sizeof(float), target);
    a.count = v.size() / size_t(width);
    a.type = types[width];
    if (bounds) set_bounds(&a, v, width, false);
    return add_accessor(a);
  }
  // min/max per component over `v`; with `zeros`, as if some elements were 0.
  static void set_bounds(Accessor *a, const std::vector<float> &v, int width, bool zeros) {
    a->min.assign(size_t(width), zeros ? 0.0 : INFINITY);
    a->max.assign(size_t(width), zeros ? 0.0 : -INFINITY);
    for (size_t i = 0; i < v.size(); ++i) {
      const size_t c = i % size_t(width);
      a->min[c] = std::min(a->min[c], double(v[i]));
      a->max[c] = std::max(a->max[c], double(v[i]));
    }
  }
};

// One entry of the node tree: a rigid's pivot node (rigid >= 0) or a part's
// mesh node (part >= 0).
struct NodeInfo {
  std::string name;
  int mesh = -1;
  int rigid = -1;            // pivot node of doc.rigids[rigid]
  double translation[3] = {0, 0, 0};
  bool has_translation = false;
  double scale = 1;          // the root: units to metres
  std::vector<int> children;
};

double units_to_metres(const std::string &units) {
  if (units == "cm") return 0.01;
  if (units == "mm") return 0.001;
  return 1;  // "m", or unknown: taken as metres
}

const char *rigid_name(uint8_t kind) {
  switch (kind) {
    case AFM_RIGID_EYE_LEFT: return "eye_left";
    case AFM_RIGID_EYE_RIGHT: return "eye_right";
    case AFM_RIGID_JAW: return "jaw";
    case AFM_RIGID_HEAD: return "head";
    default: return "rigid";
  }
}

// The image file a part's texture names, in the given directories; empty
// when not found.
std::string find_texture(const std::string &name, const std::vector<std::string> &dirs) {
  std::error_code ec;
  const fs::path n(name);
  if (n.is_absolute()) return fs::is_regular_file(n, ec) ? n.string() : std::string();
  for (const std::string &d : dirs) {
    const fs::path p = fs::path(d) / n;
    if (fs::is_regular_file(p, ec)) return p.string();
  }
  return {};
}

// "image/png", "image/jpeg" from the file's first bytes, or null.
const char *image_mime(const std::string &bytes) {
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), "\x89PNG\r\n\x1a\n", 8) == 0) return "image/png";
  if (bytes.size() >= 3 && std::memcmp(bytes.data(), "\xFF\xD8\xFF", 3) == 0) return "image/jpeg";
  return nullptr;
}

// A player's rigid transform (AFM grid: p' = R p + t, R Q14, t quanta) as
// the pivot node's rotation (unit quaternion x, y, z, w) and translation
// (model units): the node sits at the moved pivot, o + step (R pivot + t).
void pivot_pose(const afm_geometry &g, const afm_rigid &r, const afm_rigid_transform &x,
                float quat[4], float trans[3]) {
  Eigen::Matrix3d R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = x.rotation[i] / 16384.0;
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // one of the two signs, for smooth keys
  quat[0] = float(q.x()), quat[1] = float(q.y()), quat[2] = float(q.z()), quat[3] = float(q.w());
  // Rounding to float can leave |q| a few ulps from 1; renormalise in float.
  const float n = std::sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3]);
  for (int i = 0; i < 4; ++i) quat[i] /= n;
  for (int i = 0; i < 3; ++i) {
    double p = x.translation[i];
    for (int k = 0; k < 3; ++k) p += R(i, k) * double(r.pivot[k]);
    trans[i] = float(double(g.origin[i]) + double(g.step) * p);
  }
}

struct MeshInfo {
  int part = -1;
  int node = -1;
  std::vector<uint32_t> targets;  // doc.targets indices on this mesh
  // Accessors of its one primitive (-1: absent); target_accessors per target.
  int position = -1, normal = -1, texcoord = -1, color = -1, indices = -1;
  std::vector<int> target_accessors;
};

class GltfBuilder {
 public:
  GltfBuilder(const afm_doc &doc, const std::string &source, const GltfOptions &options)
      : doc_(doc), g_(doc.geometry), source_(source), options_(options) {}

  Expected<std::vector<uint8_t>> build(GltfStats *stats) {
    names_ = target_names(doc_);
    add_meshes();
    for (MeshInfo &m : meshes_) add_primitive(&m);
    for (uint32_t pi = 0; pi < g_.part_count; ++pi) part_image_.push_back(image_for(g_.parts[pi]));
    if (Status s = add_nodes(); !s) return s;
    if (options_.stream)
      if (Status s = add_animation(); !s) return s;
    std::string json = write_json();
    if (json.empty()) return Status::error(source_ + ": a value has no JSON form (not finite)");
    if (stats) {
      stats->meshes = meshes_.size();
      stats->nodes = nodes_.size();
      stats->textures = images_.size();
      stats->frames = options_.stream ? options_.stream->frames.size() : 0;
      std::vector<bool> seen(doc_.target_count, false);
      for (const MeshInfo &m : meshes_) {
        stats->mesh_targets += m.targets.size();
        for (uint32_t t : m.targets) seen[t] = true;
      }
      stats->targets = size_t(std::count(seen.begin(), seen.end(), true));
    }
    std::vector<uint8_t> out = container(json);
    if (stats) stats->bytes = out.size();
    return out;
  }

 private:
  const afm_doc &doc_;
  const afm_geometry &g_;
  const std::string &source_;
  const GltfOptions &options_;
  std::vector<std::string> names_;
  Glb glb_;
  std::vector<int> part_image_;     // per part: its image, or -1
  std::vector<int> image_views_;    // per image: its buffer view
  std::vector<std::string> images_, image_mimes_;
  std::vector<MeshInfo> meshes_;
  std::vector<int> part_mesh_;      // per part: mesh index or -1
  std::vector<NodeInfo> nodes_;
  std::vector<std::vector<int>> rigid_nodes_;  // per rigid: its pivot nodes
  // Animation: samplers (input, output accessor, path) and channels.
  struct Sampler {
    int input, output;
  };
  struct Channel {
    int sampler, node;
    const char *path;
  };
  std::vector<Sampler> samplers_;
  std::vector<Channel> channels_;

  void note(const std::string &text) const {
    if (options_.note) options_.note(text);
  }

  int image_for(const afm_part &p) {
    if (!p.texture[0] || !g_.u) return -1;
    const std::string file = find_texture(p.texture, options_.texture_dirs);
    if (file.empty()) {
      note("part '" + std::string(p.name) + "': texture " + p.texture + " not found: not embedded");
      return -1;
    }
    for (size_t i = 0; i < images_.size(); ++i)
      if (images_[i] == file) return int(i);
    Expected<std::string> bytes = read_file(file);
    const char *mime = bytes ? image_mime(*bytes) : nullptr;
    if (!mime) {
      note("part '" + std::string(p.name) + "': texture " + file +
           (bytes ? " is not PNG or JPEG" : " cannot be read") + ": not embedded");
      return -1;
    }
    image_views_.push_back(glb_.add_view(bytes->data(), bytes->size(), 0));
    images_.push_back(file);
    image_mimes_.push_back(mime);
    return int(images_.size() - 1);
  }

  void add_meshes() {
    part_mesh_.assign(g_.part_count, -1);
    for (uint32_t pi = 0; pi < g_.part_count; ++pi) {
      const afm_part &p = g_.parts[pi];
      if (p.triangle_count == 0) {
        note("part '" + std::string(p.name) + "' has no triangles: left out");
        continue;
      }
      MeshInfo m;
      m.part = int(pi);
      for (uint32_t t = 0; t < doc_.target_count; ++t)
        if (target_moves_part(doc_, doc_.targets[t], p)) m.targets.push_back(t);
      part_mesh_[pi] = int(meshes_.size());
      meshes_.push_back(m);
    }
    // A target that moves no part still gets its name on the first mesh,
    // with an all-zero target, so every AFM target is in the file.
    if (!meshes_.empty())
      for (uint32_t t = 0; t < doc_.target_count; ++t) {
        bool found = false;
        for (const MeshInfo &m : meshes_)
          found = found || std::find(m.targets.begin(), m.targets.end(), t) != m.targets.end();
        if (!found) meshes_[0].targets.push_back(t);
      }
    for (MeshInfo &m : meshes_) std::sort(m.targets.begin(), m.targets.end());
  }

  // The accessors of one mesh's primitive.
  void add_primitive(MeshInfo *mesh) {
    MeshInfo &m = *mesh;
    const afm_part &p = g_.parts[m.part];
    const uint32_t first = p.first_vertex, n = p.vertex_count;
    std::vector<float> pos(3 * size_t(n));
    for (uint32_t i = 0; i < n; ++i) {
      const int16_t q[3] = {g_.px[first + i], g_.py[first + i], g_.pz[first + i]};
      for (int c = 0; c < 3; ++c) pos[3 * i + c] = float(g_.origin[c] + double(q[c]) * g_.step);
    }
    m.position = glb_.add_floats(pos, 3, kArrayBuffer, true);
    if (g_.nx) {
      std::vector<float> nrm(3 * size_t(n));
      for (uint32_t i = 0; i < n; ++i) {
        Eigen::Vector3d v(g_.nx[first + i], g_.ny[first + i], g_.nz[first + i]);
        v = v.norm() > 0 ? v.normalized() : Eigen::Vector3d(0, 0, 1);
        for (int c = 0; c < 3; ++c) nrm[3 * i + c] = float(v[c]);
      }
      m.normal = glb_.add_floats(nrm, 3, kArrayBuffer, false);
    }
    if (g_.u) {
      std::vector<float> uv(2 * size_t(n));
      for (uint32_t i = 0; i < n; ++i) {
        uv[2 * i] = float(g_.uv_origin[0] + double(g_.u[first + i]) * g_.uv_step[0]);
        // glTF's uv origin is the image's top-left corner, the AFM's its bottom-left.
        uv[2 * i + 1] = float(1.0 - (g_.uv_origin[1] + double(g_.v[first + i]) * g_.uv_step[1]));
      }
      m.texcoord = glb_.add_floats(uv, 2, kArrayBuffer, false);
    }
    if (g_.rgba) {
      Accessor a;
      a.view = glb_.add_view(g_.rgba + 4 * size_t(first), 4 * size_t(n), kArrayBuffer);
      a.component = kUnsignedByte;
      a.normalized = true;
      a.count = n;
      a.type = "VEC4";
      m.color = glb_.add_accessor(a);
    }
    {
      Accessor a;
      a.count = 3 * size_t(p.triangle_count);
      const uint32_t *tri = g_.triangles + 3 * size_t(p.first_triangle);
      if (n <= 65535) {
        std::vector<uint16_t> idx(a.count);
        for (size_t k = 0; k < a.count; ++k) idx[k] = uint16_t(tri[k] - first);
        a.view = glb_.add_view(idx.data(), idx.size() * 2, kElementArrayBuffer);
        a.component = kUnsignedShort;
      } else {
        std::vector<uint32_t> idx(a.count);
        for (size_t k = 0; k < a.count; ++k) idx[k] = tri[k] - first;
        a.view = glb_.add_view(idx.data(), idx.size() * 4, kElementArrayBuffer);
        a.component = kUnsignedInt;
      }
      m.indices = glb_.add_accessor(a);
    }
    for (uint32_t t : m.targets) m.target_accessors.push_back(target_accessor(doc_.targets[t], p));
  }

  void write_primitive(JsonWriter &j, const MeshInfo &m) const {
    j.begin_object();
    j.key("attributes").begin_object().field("POSITION", m.position);
    if (m.normal >= 0) j.field("NORMAL", m.normal);
    if (m.texcoord >= 0) j.field("TEXCOORD_0", m.texcoord);
    if (m.color >= 0) j.field("COLOR_0", m.color);
    j.end_object();
    j.field("indices", m.indices).field("material", m.part).field("mode", 4);
    if (!m.target_accessors.empty()) {
      j.key("targets").begin_array();
      for (int a : m.target_accessors) j.begin_object().field("POSITION", a).end_object();
      j.end_array();
    }
    j.end_object();
  }

  // A sparse POSITION morph target: the vertices the target moves in this
  // part, with their displacement in model units.
  int target_accessor(const afm_target &t, const afm_part &p) {
    const Eigen::MatrixXd d = target_part_deltas(doc_, t, p);
    std::vector<uint32_t> idx;
    std::vector<float> val;
    for (uint32_t i = 0; i < p.vertex_count; ++i) {
      if ((d.row(i).array() == 0).all()) continue;
      idx.push_back(i);
      for (int c = 0; c < 3; ++c) val.push_back(float(d(i, c) * g_.step));
    }
    Accessor a;
    a.count = p.vertex_count;
    a.type = "VEC3";
    // The vertices left out are zeros; where the target moves every vertex of
    // the part (the jaw's teeth in a viseme) there are none.
    Glb::set_bounds(&a, val, 3, idx.size() < p.vertex_count);
    if (!idx.empty()) {
      a.sparse_count = idx.size();
      if (p.vertex_count <= 65535) {
        std::vector<uint16_t> i16(idx.begin(), idx.end());
        a.sparse_index_view = glb_.add_view(i16.data(), i16.size() * 2, 0);
        a.sparse_index_component = kUnsignedShort;
      } else {
        a.sparse_index_view = glb_.add_view(idx.data(), idx.size() * 4, 0);
      }
      a.sparse_value_view = glb_.add_view(val.data(), val.size() * sizeof(float), 0);
    }
    return glb_.add_accessor(a);
  }

  int add_node(NodeInfo n, int parent) {
    nodes_.push_back(std::move(n));
    const int i = int(nodes_.size() - 1);
    if (parent >= 0) nodes_[parent].children.push_back(i);
    return i;
  }

  // The node tree: root, then per part the chain of rigids that move it,
  // outermost first (the head, then the others in reverse order of
  // application), each as a pivot node holding an offset node.
  Status add_nodes() {
    NodeInfo root;
    root.name = doc_.meta.name[0] ? doc_.meta.name : "face";
    root.scale = units_to_metres(doc_.meta.units);
    add_node(root, -1);
    rigid_nodes_.assign(doc_.rigid_count, {});
    std::map<std::vector<int>, int> chain_node;  // rigid chain -> the node holding its parts
    chain_node[{}] = 0;
    for (const MeshInfo &m : meshes_) {
      std::vector<int> chain;  // outermost first
      for (uint32_t r = doc_.rigid_count; r-- > 0;) {
        const afm_rigid &rg = doc_.rigids[r];
        if (std::find(rg.parts, rg.parts + rg.part_count, uint16_t(m.part)) == rg.parts + rg.part_count)
          continue;
        if (rg.kind == AFM_RIGID_HEAD)
          chain.insert(chain.begin(), int(r));
        else
          chain.push_back(int(r));
      }
      int parent = 0;
      std::vector<int> prefix;
      for (int r : chain) {
        prefix.push_back(r);
        auto it = chain_node.find(prefix);
        if (it == chain_node.end()) {
          const afm_rigid &rg = doc_.rigids[r];
          NodeInfo pivot, offset;
          pivot.name = std::string(rigid_name(rg.kind)) + "_pivot";
          pivot.rigid = r;
          pivot.has_translation = offset.has_translation = true;
          offset.name = pivot.name + "_offset";
          for (int c = 0; c < 3; ++c) {
            pivot.translation[c] = double(float(g_.origin[c] + double(g_.step) * rg.pivot[c]));
            offset.translation[c] = -pivot.translation[c];
          }
          const int pn = add_node(pivot, parent);
          rigid_nodes_[r].push_back(pn);
          it = chain_node.emplace(prefix, add_node(offset, pn)).first;
        }
        parent = it->second;
      }
      NodeInfo part;
      part.name = g_.parts[m.part].name;
      part.mesh = part_mesh_[m.part];
      meshes_[part.mesh].node = add_node(part, parent);
    }
    return Status::ok();
  }

  Status add_animation() {
    const FapStream &s = *options_.stream;
    const size_t frames = s.frames.size();
    afm_player_options po{};
    po.flags = AFM_PLAYER_NO_NORMALS;
    size_t bytes = 0;
    afm_result r = afm_player_measure(&doc_, &po, &bytes);
    std::vector<uint64_t> buffer(r == AFM_OK ? bytes / 8 + 1 : 0);
    afm_player *player = nullptr;
    if (r == AFM_OK) r = afm_player_init(&doc_, &po, buffer.data(), buffer.size() * 8, &player);
    if (r != AFM_OK)
      return Status::error(source_ + ": the player refuses the model: " + afm_result_string(r));

    std::vector<float> times(frames);
    std::vector<std::vector<float>> weights(meshes_.size());
    std::vector<std::vector<float>> rot(doc_.rigid_count), trans(doc_.rigid_count);
    afm_fap_state state;
    afm_fap_state_reset(&state);
    for (size_t f = 0; f < frames; ++f) {
      times[f] = float(fap_frame_seconds(s, f));
      afm_fap_state_apply(&state, &s.frames[f], 0);
      afm_player_pose(player, &state, nullptr, 0);
      const afm_q12 *w = afm_player_weights(player);
      for (size_t m = 0; m < meshes_.size(); ++m)
        for (uint32_t t : meshes_[m].targets) weights[m].push_back(float(w[t] / 4096.0));
      for (uint32_t k = 0; k < doc_.rigid_count; ++k) {
        afm_rigid_transform x;
        afm_rigid_pose(&doc_.rigids[k], &state, nullptr, 0, &x);
        float q[4], tr[3];
        pivot_pose(g_, doc_.rigids[k], x, q, tr);
        rot[k].insert(rot[k].end(), q, q + 4);
        trans[k].insert(trans[k].end(), tr, tr + 3);
      }
      if (options_.progress) options_.progress(f + 1, frames);
    }
    for (size_t f = 1; f < frames; ++f)
      if (!(times[f] > times[f - 1]))
        return Status::error(options_.stream_path + ": frames " + std::to_string(s.frames[f - 1].number) +
                             " and " + std::to_string(s.frames[f].number) +
                             " fall on the same time in single precision");
    const int input = glb_.add_floats(times, 1, 0, true);
    for (size_t m = 0; m < meshes_.size(); ++m) {
      if (meshes_[m].targets.empty()) continue;
      samplers_.push_back({input, glb_.add_floats(weights[m], 1, 0, false)});
      channels_.push_back({int(samplers_.size() - 1), meshes_[m].node, "weights"});
    }
    for (uint32_t k = 0; k < doc_.rigid_count; ++k) {
      if (rigid_nodes_[k].empty()) continue;
      samplers_.push_back({input, glb_.add_floats(rot[k], 4, 0, false)});
      const int rs = int(samplers_.size() - 1);
      samplers_.push_back({input, glb_.add_floats(trans[k], 3, 0, false)});
      const int ts = int(samplers_.size() - 1);
      for (int node : rigid_nodes_[k]) {
        channels_.push_back({rs, node, "rotation"});
        channels_.push_back({ts, node, "translation"});
      }
    }
    return Status::ok();
  }

  std::string write_json() const {
    JsonWriter j;
    j.begin_object();
    j.key("asset").begin_object().field("version", "2.0").field("generator", "afm-export").end_object();
    j.field("scene", 0);
    j.key("scenes").begin_array().begin_object().key("nodes").begin_array().value(0).end_array().end_object().end_array();

    j.key("nodes").begin_array();
    for (const NodeInfo &n : nodes_) {
      j.begin_object().field("name", n.name);
      if (n.mesh >= 0) j.field("mesh", n.mesh);
      if (n.has_translation) j.key("translation").numbers(n.translation, 3);
      if (n.scale != 1) {
        const double s[3] = {n.scale, n.scale, n.scale};
        j.key("scale").numbers(s, 3);
      }
      if (!n.children.empty()) {
        j.key("children").begin_array();
        for (int c : n.children) j.value(c);
        j.end_array();
      }
      j.end_object();
    }
    j.end_array();

    j.key("meshes").begin_array();
    for (const MeshInfo &m : meshes_) {
      j.begin_object().field("name", std::string(g_.parts[m.part].name));
      j.key("primitives").begin_array();
      write_primitive(j, m);
      j.end_array();
      if (!m.targets.empty()) {
        j.key("weights").begin_array();
        for (size_t k = 0; k < m.targets.size(); ++k) j.value(0.0);
        j.end_array();
        j.key("extras").begin_object().key("targetNames").begin_array();
        for (uint32_t t : m.targets) j.value(names_[t]);
        j.end_array().end_object();
      }
      j.end_object();
    }
    j.end_array();

    j.key("materials").begin_array();
    for (uint32_t pi = 0; pi < g_.part_count; ++pi) {
      const afm_part &p = g_.parts[pi];
      // Vertex colours and textures multiply the base colour: white then.
      const bool white = g_.rgba || part_image_[pi] >= 0;
      const double c[4] = {white ? 1.0 : p.diffuse[0] / 255.0, white ? 1.0 : p.diffuse[1] / 255.0,
                           white ? 1.0 : p.diffuse[2] / 255.0, p.diffuse[3] / 255.0};
      j.begin_object().field("name", std::string(p.name));
      j.key("pbrMetallicRoughness").begin_object().key("baseColorFactor").numbers(c, 4);
      if (part_image_[pi] >= 0)
        j.key("baseColorTexture").begin_object().field("index", part_image_[pi]).end_object();
      j.field("metallicFactor", 0.0).field("roughnessFactor", 0.7).end_object();
      if (p.diffuse[3] < 255) j.field("alphaMode", "BLEND");
      j.end_object();
    }
    j.end_array();
    if (!images_.empty()) {
      j.key("images").begin_array();
      for (size_t i = 0; i < images_.size(); ++i)
        j.begin_object()
            .field("name", fs::path(images_[i]).filename().string())
            .field("bufferView", image_views_[i])
            .field("mimeType", image_mimes_[i])
            .end_object();
      j.end_array();
      j.key("textures").begin_array();
      for (size_t i = 0; i < images_.size(); ++i) j.begin_object().field("source", i).end_object();
      j.end_array();
    }

    if (!channels_.empty()) {
      j.key("animations").begin_array().begin_object();
      const std::string name = options_.stream->header.name;
      j.field("name", name.empty() ? std::string("fap") : name);
      j.key("samplers").begin_array();
      for (const Sampler &s : samplers_)
        j.begin_object().field("input", s.input).field("output", s.output).field("interpolation", "LINEAR").end_object();
      j.end_array();
      j.key("channels").begin_array();
      for (const Channel &c : channels_)
        j.begin_object()
            .field("sampler", c.sampler)
            .key("target")
            .begin_object()
            .field("node", c.node)
            .field("path", c.path)
            .end_object()
            .end_object();
      j.end_array();
      j.end_object().end_array();
    }

    j.key("accessors").begin_array();
    for (const Accessor &a : glb_.accessors) {
      j.begin_object();
      if (a.view >= 0) j.field("bufferView", a.view);
      j.field("componentType", a.component);
      if (a.normalized) j.field("normalized", true);
      j.field("count", a.count).field("type", a.type);
      if (!a.min.empty()) {
        j.key("min").numbers(a.min.data(), a.min.size());
        j.key("max").numbers(a.max.data(), a.max.size());
      }
      if (a.sparse_count) {
        j.key("sparse").begin_object().field("count", a.sparse_count);
        j.key("indices").begin_object().field("bufferView", a.sparse_index_view)
            .field("componentType", a.sparse_index_component).end_object();
        j.key("values").begin_object().field("bufferView", a.sparse_value_view).end_object();
        j.end_object();
      }
      j.end_object();
    }
    j.end_array();

    j.key("bufferViews").begin_array();
    for (const View &v : glb_.views) {
      j.begin_object().field("buffer", 0).field("byteLength", v.length);
      if (v.offset) j.field("byteOffset", v.offset);
      if (v.target) j.field("target", v.target);
      j.end_object();
    }
    j.end_array();
    j.key("buffers").begin_array().begin_object().field("byteLength", glb_.bin.size()).end_object().end_array();
    j.end_object();
    if (j.failed() || !j.complete()) return {};
    return j.text();
  }

  // GLB container (glTF 2.0 spec, 4.4): header, JSON chunk padded with
  // spaces, BIN chunk padded with zeros.
  std::vector<uint8_t> container(const std::string &json) {
    std::string js = json;
    while (js.size() % 4) js += ' ';
    while (glb_.bin.size() % 4) glb_.bin.push_back(0);
    std::vector<uint8_t> out;
    auto u32 = [&out](uint32_t v) {
      for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
    };
    const size_t total = 12 + 8 + js.size() + 8 + glb_.bin.size();
    u32(0x46546C67);  // "glTF"
    u32(2);
    u32(uint32_t(total));
    u32(uint32_t(js.size()));
    u32(0x4E4F534A);  // "JSON"
    out.insert(out.end(), js.begin(), js.end());
    u32(uint32_t(glb_.bin.size()));
    u32(0x004E4942);  // "BIN\0"
    out.insert(out.end(), glb_.bin.begin(), glb_.bin.end());
    return out;
  }
};

}  // namespace

Expected<std::vector<uint8_t>> gltf_bytes(const afm_doc &doc, const std::string &source,
                                          const GltfOptions &options, GltfStats *stats) {
  if (doc.geometry.triangle_count == 0) return Status::error(source + ": the model has no triangles");
  GltfBuilder b(doc, source, options);
  Expected<std::vector<uint8_t>> out = b.build(stats);
  if (out && out->size() > 0xFFFFFFFFu)
    return Status::error(source + ": the glTF file would pass 4 GiB, the GLB limit");
  return out;
}

Status export_gltf(const afm_doc &doc, const std::string &source, const std::string &path,
                   const GltfOptions &options, GltfStats *stats) {
  Expected<std::vector<uint8_t>> bytes = gltf_bytes(doc, source, options, stats);
  if (!bytes) return bytes.status();
  return write_file_atomic(path, bytes->data(), bytes->size());
}

}  // namespace afmb
