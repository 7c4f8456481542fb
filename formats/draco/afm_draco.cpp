// Draco encoding of AFM chunks (formats/afm.md, "draco encoding").
//
// GEOM: each part becomes one Draco stream with integer attributes, so the
// quantised values pass through untouched. Two layouts are tried per part and
// the smaller one that decodes back exactly is kept:
//   - edgebreaker, plus a per-point vertex-id attribute that restores the
//     part's vertex order (edgebreaker renumbers points);
//   - sequential connectivity, which keeps the order and needs no ids.
// MTGT: target headers and runs stay as they are; all position deltas (and
// normal deltas) form Draco point clouds in sequential order, where Draco's
// difference prediction and entropy coding work on neighbouring vertices.
// LIFT: counts and runs stay as they are; the bound vertices' control
// triples and weight pairs form one sequential point cloud.
//
// Every encoded chunk is decoded again and compared before it is accepted:
// a file never depends on a Draco round trip that was not checked.
#include "afm/draco.h"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <draco/point_cloud/point_cloud.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <vector>

namespace {

// Attribute unique ids inside our Draco streams (formats/afm.md).
enum : uint32_t {
  kUidPosition = 0,
  kUidNormal = 1,
  kUidTexcoord = 2,
  kUidColor = 3,
  kUidVertexId = 4,
  kUidDelta = 10,
  kUidLiftControls = 11,
  kUidLiftWeights = 12,
};

constexpr int kSpeed = 3;  // Draco encode/decode speed (0 best .. 10 fastest); bench/ measures it

void set_diag(afm_diag *diag, uint32_t kind, const char *format, ...) {
  if (!diag || diag->message[0]) return;
  char name[5];
  for (int i = 0; i < 4; ++i) {
    unsigned c = (kind >> (8 * i)) & 0xFFu;
    name[i] = (c >= 0x20 && c < 0x7F) ? static_cast<char>(c) : '?';
  }
  name[4] = '\0';
  int n = std::snprintf(diag->message, sizeof diag->message, "%s (draco): ", name);
  if (n < 0) n = 0;
  va_list args;
  va_start(args, format);
  std::vsnprintf(diag->message + n, sizeof diag->message - static_cast<size_t>(n), format, args);
  va_end(args);
  diag->chunk = kind;
}

// Little-endian byte builder for our own payload layout.
struct Out {
  std::vector<uint8_t> b;
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void u16(uint16_t v) {
    b.push_back(static_cast<uint8_t>(v & 0xFFu));
    b.push_back(static_cast<uint8_t>(v >> 8));
  }
  void bytes(const void *p, size_t n) {
    const uint8_t *c = static_cast<const uint8_t *>(p);
    b.insert(b.end(), c, c + n);
  }
  void pad4() {
    while (b.size() & 3u) b.push_back(0);
  }
};

// Bounds-checked reader over our own payload layout.
struct In {
  const uint8_t *p;
  size_t n;
  size_t pos = 0;
  bool ok = true;
  uint32_t u32() {
    if (!ok || n - pos < 4) {
      ok = false;
      return 0;
    }
    uint32_t v = static_cast<uint32_t>(p[pos]) | (static_cast<uint32_t>(p[pos + 1]) << 8) |
                 (static_cast<uint32_t>(p[pos + 2]) << 16) |
                 (static_cast<uint32_t>(p[pos + 3]) << 24);
    pos += 4;
    return v;
  }
  uint16_t u16() {
    const uint8_t *q = take(2);
    return q ? static_cast<uint16_t>(q[0] | (q[1] << 8)) : 0;
  }
  const uint8_t *take(size_t k) {
    if (!ok || k > n - pos) {
      ok = false;
      return nullptr;
    }
    const uint8_t *q = p + pos;
    pos += k;
    return q;
  }
  void pad4() {
    while (ok && (pos & 3u)) take(1);
  }
};

afm_result hand_out(const std::vector<uint8_t> &v, const afm_allocator *allocator,
                    uint8_t **out, size_t *size) {
  *out = static_cast<uint8_t *>(afm_alloc(allocator, v.empty() ? 1 : v.size()));
  if (!*out) return AFM_ERR_OUT_OF_MEMORY;
  if (!v.empty()) std::memcpy(*out, v.data(), v.size());
  *size = v.size();
  return AFM_OK;
}

// Decodes a GEOM or MTGT raw payload into C structs backed by `storage`.
template <class Fn>
afm_result decode_with_storage(std::vector<uint64_t> &storage, Fn &&decode) {
  size_t bytes = 0;
  afm_result r = decode(nullptr, 0, &bytes);
  if (r != AFM_OK) return r;
  storage.assign(bytes / 8 + 1, 0);
  return decode(storage.data(), storage.size() * 8, &bytes);
}

// ---- one part of GEOM --------------------------------------------------------

// Vertex data of one part, interleaved per vertex, local indices.
struct PartData {
  uint32_t attributes = 0;
  size_t nv = 0, nt = 0;
  std::vector<int16_t> pos;   // 3 nv
  std::vector<int16_t> nrm;   // 3 nv when AFM_ATTR_NORMALS
  std::vector<uint16_t> uv;   // 2 nv when AFM_ATTR_TEXCOORDS
  std::vector<uint8_t> rgba;  // 4 nv when AFM_ATTR_COLORS
  std::vector<uint32_t> tri;  // 3 nt, canonical order

  bool operator==(const PartData &o) const {
    return nv == o.nv && nt == o.nt && pos == o.pos && nrm == o.nrm && uv == o.uv &&
           rgba == o.rgba && tri == o.tri;
  }
};

void canonicalize_local(std::vector<uint32_t> &tri) {
  afm_part whole{};
  whole.triangle_count = static_cast<uint32_t>(tri.size() / 3);
  whole.vertex_count = 0xFFFFFFFFu;
  if (!tri.empty()) afm_canonicalize_triangles(tri.data(), &whole, 1);
}

PartData gather_part(const afm_geometry &g, const afm_part &p) {
  PartData d;
  d.attributes = g.attributes;
  d.nv = p.vertex_count;
  d.nt = p.triangle_count;
  d.pos.resize(3 * d.nv);
  for (size_t i = 0; i < d.nv; ++i) {
    size_t v = p.first_vertex + i;
    d.pos[3 * i] = g.px[v];
    d.pos[3 * i + 1] = g.py[v];
    d.pos[3 * i + 2] = g.pz[v];
    if (g.attributes & AFM_ATTR_NORMALS) {
      d.nrm.push_back(g.nx[v]);
      d.nrm.push_back(g.ny[v]);
      d.nrm.push_back(g.nz[v]);
    }
    if (g.attributes & AFM_ATTR_TEXCOORDS) {
      d.uv.push_back(g.u[v]);
      d.uv.push_back(g.v[v]);
    }
    if (g.attributes & AFM_ATTR_COLORS) d.rgba.insert(d.rgba.end(), g.rgba + 4 * v, g.rgba + 4 * v + 4);
  }
  d.tri.resize(3 * d.nt);
  for (size_t t = 0; t < 3 * d.nt; ++t)
    d.tri[t] = g.triangles[3 * static_cast<size_t>(p.first_triangle) + t] - p.first_vertex;
  return d;
}

void add_attribute(draco::PointCloud &pc, draco::GeometryAttribute::Type type, int components,
                   draco::DataType dt, size_t elem_size, uint32_t uid, const void *values,
                   size_t count) {
  draco::GeometryAttribute ga;
  ga.Init(type, nullptr, static_cast<uint8_t>(components), dt, false,
          static_cast<int64_t>(elem_size * components), 0);
  int id = pc.AddAttribute(ga, true, static_cast<uint32_t>(count));
  draco::PointAttribute *pa = pc.attribute(id);
  pa->set_unique_id(uid);
  const uint8_t *v = static_cast<const uint8_t *>(values);
  for (size_t i = 0; i < count; ++i)
    pa->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)),
                          v + i * elem_size * components);
}

// Vertices no triangle uses: edgebreaker drops them, so they travel beside
// the stream ("loose" vertices, formats/afm.md).
std::vector<uint32_t> loose_vertices(const PartData &d) {
  std::vector<uint8_t> used(d.nv, 0);
  for (uint32_t v : d.tri) used[v] = 1;
  std::vector<uint32_t> loose;
  for (size_t v = 0; v < d.nv; ++v)
    if (!used[v]) loose.push_back(static_cast<uint32_t>(v));
  return loose;
}

// Loose vertices in the payload: u32 count, the ids, then per vertex its
// values as the part's attributes say (i16 x3 position, i16 x3 normal, u16 x2
// uv, u8 x4 rgba), then pad4.
void write_loose(Out &o, const PartData &d, const std::vector<uint32_t> &loose) {
  o.u32(static_cast<uint32_t>(loose.size()));
  for (uint32_t v : loose) o.u32(v);
  for (uint32_t v : loose) {
    for (int k = 0; k < 3; ++k) o.u16(static_cast<uint16_t>(d.pos[3 * v + k]));
    if (d.attributes & AFM_ATTR_NORMALS)
      for (int k = 0; k < 3; ++k) o.u16(static_cast<uint16_t>(d.nrm[3 * v + k]));
    if (d.attributes & AFM_ATTR_TEXCOORDS)
      for (int k = 0; k < 2; ++k) o.u16(d.uv[2 * v + k]);
    if (d.attributes & AFM_ATTR_COLORS) o.bytes(&d.rgba[4 * v], 4);
  }
  o.pad4();
}

// Reads the loose ids (bounded by the part's vertex count).
std::vector<uint32_t> read_loose_ids(In &in, size_t nv) {
  uint32_t k = in.u32();
  if (!in.ok || k > nv || k > (in.n - in.pos) / 4) {
    in.ok = false;
    return {};
  }
  std::vector<uint32_t> ids(k);
  for (uint32_t &v : ids) v = in.u32();
  return ids;
}

// Fills the loose vertices' values into `d` (arrays already sized).
void read_loose_values(In &in, const std::vector<uint32_t> &loose, PartData &d) {
  for (uint32_t v : loose) {
    if (v >= d.nv) {
      in.ok = false;
      return;
    }
    for (int k = 0; k < 3; ++k) d.pos[3 * v + k] = static_cast<int16_t>(in.u16());
    if (d.attributes & AFM_ATTR_NORMALS)
      for (int k = 0; k < 3; ++k) d.nrm[3 * v + k] = static_cast<int16_t>(in.u16());
    if (d.attributes & AFM_ATTR_TEXCOORDS)
      for (int k = 0; k < 2; ++k) d.uv[2 * v + k] = in.u16();
    if (d.attributes & AFM_ATTR_COLORS) {
      const uint8_t *c = in.take(4);
      if (c) std::memcpy(&d.rgba[4 * v], c, 4);
    }
  }
  in.pad4();
}

// Encodes one part; edgebreaker adds the vertex-id attribute. Empty on failure.
std::vector<uint8_t> encode_part(const PartData &d, bool edgebreaker) {
  std::unique_ptr<draco::PointCloud> pc;
  draco::Mesh *mesh = nullptr;
  if (d.nt > 0) {
    auto m = std::make_unique<draco::Mesh>();
    mesh = m.get();
    pc = std::move(m);
  } else {
    pc = std::make_unique<draco::PointCloud>();
  }
  pc->set_num_points(static_cast<uint32_t>(d.nv));
  add_attribute(*pc, draco::GeometryAttribute::POSITION, 3, draco::DT_INT16, 2, kUidPosition,
                d.pos.data(), d.nv);
  if (d.attributes & AFM_ATTR_NORMALS)
    add_attribute(*pc, draco::GeometryAttribute::GENERIC, 3, draco::DT_INT16, 2, kUidNormal,
                  d.nrm.data(), d.nv);
  if (d.attributes & AFM_ATTR_TEXCOORDS)
    add_attribute(*pc, draco::GeometryAttribute::TEX_COORD, 2, draco::DT_UINT16, 2, kUidTexcoord,
                  d.uv.data(), d.nv);
  if (d.attributes & AFM_ATTR_COLORS)
    add_attribute(*pc, draco::GeometryAttribute::COLOR, 4, draco::DT_UINT8, 1, kUidColor,
                  d.rgba.data(), d.nv);
  if (edgebreaker) {
    std::vector<uint32_t> ids(d.nv);
    for (size_t i = 0; i < d.nv; ++i) ids[i] = static_cast<uint32_t>(i);
    add_attribute(*pc, draco::GeometryAttribute::GENERIC, 1, draco::DT_UINT32, 4, kUidVertexId,
                  ids.data(), d.nv);
  }
  if (mesh) {
    mesh->SetNumFaces(d.nt);
    for (size_t t = 0; t < d.nt; ++t) {
      draco::Mesh::Face f;
      for (int k = 0; k < 3; ++k) f[k] = draco::PointIndex(d.tri[3 * t + k]);
      mesh->SetFace(draco::FaceIndex(static_cast<uint32_t>(t)), f);
    }
  }
  draco::Encoder enc;
  enc.SetSpeedOptions(kSpeed, kSpeed);
  draco::EncoderBuffer buf;
  draco::Status s;
  if (mesh) {
    enc.SetEncodingMethod(edgebreaker ? draco::MESH_EDGEBREAKER_ENCODING
                                      : draco::MESH_SEQUENTIAL_ENCODING);
    s = enc.EncodeMeshToBuffer(*mesh, &buf);
  } else {
    if (edgebreaker) return {};
    enc.SetEncodingMethod(draco::POINT_CLOUD_SEQUENTIAL_ENCODING);
    s = enc.EncodePointCloudToBuffer(*pc, &buf);
  }
  if (!s.ok()) return {};
  return std::vector<uint8_t>(buf.data(), buf.data() + buf.size());
}

template <class T>
bool read_values(const draco::PointAttribute *a, int components, size_t nv,
                 const std::vector<uint32_t> &point_to_vertex, std::vector<T> &out) {
  if (!a || a->num_components() != components) return false;
  out.assign(components * nv, 0);
  std::vector<uint8_t> seen(nv, 0);
  T value[4];
  for (size_t p = 0; p < point_to_vertex.size(); ++p) {
    uint32_t v = point_to_vertex[p];
    a->GetMappedValue(draco::PointIndex(static_cast<uint32_t>(p)), value);
    for (int k = 0; k < components; ++k) {
      if (seen[v] && out[components * v + k] != value[k]) return false;  // split point disagrees
      out[components * v + k] = value[k];
    }
    seen[v] = 1;
  }
  return true;
}

// Decodes one part stream into `d` (nv, nt, attributes preset); `loose` lists
// the vertices that come from the loose values instead. False when the stream
// is not what we wrote.
bool decode_part(const uint8_t *data, size_t size, const std::vector<uint32_t> &loose,
                 PartData &d) {
  draco::DecoderBuffer buf;
  buf.Init(reinterpret_cast<const char *>(data), size);
  draco::Decoder dec;
  std::unique_ptr<draco::PointCloud> pc;
  const draco::Mesh *mesh = nullptr;
  if (d.nt > 0) {
    auto r = dec.DecodeMeshFromBuffer(&buf);
    if (!r.ok()) return false;
    mesh = r.value().get();
    pc = std::move(r).value();
  } else {
    auto r = dec.DecodePointCloudFromBuffer(&buf);
    if (!r.ok()) return false;
    pc = std::move(r).value();
  }
  const size_t np = pc->num_points();
  std::vector<uint32_t> p2v(np);
  if (const draco::PointAttribute *ids = pc->GetAttributeByUniqueId(kUidVertexId)) {
    if (ids->data_type() != draco::DT_UINT32 || ids->num_components() != 1) return false;
    std::vector<uint8_t> covered(d.nv, 0);
    for (uint32_t v : loose) {
      if (v >= d.nv || covered[v]) return false;
      covered[v] = 2;
    }
    for (size_t p = 0; p < np; ++p) {
      uint32_t v = 0;
      ids->GetMappedValue(draco::PointIndex(static_cast<uint32_t>(p)), &v);
      if (v >= d.nv || covered[v] == 2) return false;
      p2v[p] = v;
      covered[v] = 1;
    }
    if (std::find(covered.begin(), covered.end(), 0) != covered.end()) return false;
  } else {
    if (np != d.nv || !loose.empty()) return false;
    for (size_t p = 0; p < np; ++p) p2v[p] = static_cast<uint32_t>(p);
  }
  if (!read_values(pc->GetAttributeByUniqueId(kUidPosition), 3, d.nv, p2v, d.pos)) return false;
  if ((d.attributes & AFM_ATTR_NORMALS) &&
      !read_values(pc->GetAttributeByUniqueId(kUidNormal), 3, d.nv, p2v, d.nrm))
    return false;
  if ((d.attributes & AFM_ATTR_TEXCOORDS) &&
      !read_values(pc->GetAttributeByUniqueId(kUidTexcoord), 2, d.nv, p2v, d.uv))
    return false;
  if ((d.attributes & AFM_ATTR_COLORS) &&
      !read_values(pc->GetAttributeByUniqueId(kUidColor), 4, d.nv, p2v, d.rgba))
    return false;
  d.tri.clear();
  if (mesh) {
    if (mesh->num_faces() != d.nt) return false;
    d.tri.resize(3 * d.nt);
    for (uint32_t t = 0; t < mesh->num_faces(); ++t) {
      const draco::Mesh::Face &f = mesh->face(draco::FaceIndex(t));
      for (int k = 0; k < 3; ++k) {
        if (f[k].value() >= np) return false;
        d.tri[3 * t + k] = p2v[f[k].value()];
      }
    }
    canonicalize_local(d.tri);
  }
  return true;
}

// ---- GEOM -------------------------------------------------------------------

afm_result geom_from_raw(const uint8_t *raw, size_t raw_size, const afm_allocator *allocator,
                         uint8_t **out, size_t *out_size, afm_diag *diag) {
  std::vector<uint64_t> storage;
  afm_geometry g;
  afm_result r = decode_with_storage(storage, [&](void *buf, size_t n, size_t *bytes) {
    return afm_geometry_decode(raw, raw_size, buf, n, bytes, &g, diag);
  });
  if (r != AFM_OK) return r;
  size_t header_size = 0;
  r = afm_geometry_decode_header(raw, raw_size, nullptr, 0, nullptr, &header_size, nullptr, diag);
  if (r != AFM_OK) return r;

  Out o;
  o.u32(static_cast<uint32_t>(raw_size));
  o.u32(static_cast<uint32_t>(header_size));
  o.bytes(raw, header_size);
  o.pad4();
  for (uint32_t p = 0; p < g.part_count; ++p) {
    PartData d = gather_part(g, g.parts[p]);
    std::vector<uint8_t> best;
    std::vector<uint32_t> best_loose;
    for (bool eb : {true, false}) {
      std::vector<uint8_t> s = encode_part(d, eb);
      std::vector<uint32_t> loose = eb ? loose_vertices(d) : std::vector<uint32_t>{};
      if (s.empty() || (!best.empty() && s.size() + 4 * loose.size() >= best.size() + 4 * best_loose.size()))
        continue;
      PartData back;
      back.attributes = d.attributes;
      back.nv = d.nv;
      back.nt = d.nt;
      if (!decode_part(s.data(), s.size(), loose, back)) continue;
      Out lo;  // the loose values travel raw: check the whole part through them
      write_loose(lo, d, loose);
      In li{lo.b.data(), lo.b.size()};
      std::vector<uint32_t> ids = read_loose_ids(li, d.nv);
      read_loose_values(li, ids, back);
      if (li.ok && back == d) {
        best = std::move(s);
        best_loose = std::move(loose);
      }
    }
    if (best.empty()) {
      *out = nullptr;  // Draco cannot carry this part exactly: keep the chunk raw
      return AFM_OK;
    }
    o.u32(static_cast<uint32_t>(best.size()));
    o.bytes(best.data(), best.size());
    o.pad4();
    write_loose(o, d, best_loose);
  }
  if (o.b.size() * 100 > raw_size * (100 - AFM_DRACO_MIN_SAVING_PERCENT)) {
    *out = nullptr;
    return AFM_OK;
  }
  return hand_out(o.b, allocator, out, out_size);
}

afm_result geom_to_raw(const uint8_t *data, size_t size, const afm_allocator *allocator,
                       uint8_t **raw, size_t *raw_size, afm_diag *diag) {
  In in{data, size};
  uint32_t expect_size = in.u32();
  uint32_t header_size = in.u32();
  const uint8_t *header = in.take(header_size);
  in.pad4();
  if (!in.ok) {
    set_diag(diag, AFM_CHUNK_GEOM, "payload header truncated");
    return AFM_ERR_TRUNCATED;
  }
  std::vector<uint64_t> storage;
  afm_geometry g;
  afm_result r = decode_with_storage(storage, [&](void *buf, size_t n, size_t *bytes) {
    return afm_geometry_decode_header(header, header_size, buf, n, bytes, nullptr, &g, diag);
  });
  if (r != AFM_OK) return r;

  const size_t V = g.vertex_count, T = g.triangle_count;
  // Every vertex costs Draco at least a bit; bound the untrusted counts.
  if (V > 8 * (size - in.pos) + 64 || T > 8 * (size - in.pos) + 64) {
    set_diag(diag, AFM_CHUNK_GEOM, "%zu vertices, %zu triangles: more than the data can hold", V, T);
    return AFM_ERR_RANGE;
  }
  std::vector<int16_t> px(V), py(V), pz(V), nx, ny, nz;
  std::vector<uint16_t> u, v;
  std::vector<uint8_t> rgba;
  std::vector<uint32_t> tri(3 * T);
  if (g.attributes & AFM_ATTR_NORMALS) nx.resize(V), ny.resize(V), nz.resize(V);
  if (g.attributes & AFM_ATTR_TEXCOORDS) u.resize(V), v.resize(V);
  if (g.attributes & AFM_ATTR_COLORS) rgba.resize(4 * V);
  for (uint32_t p = 0; p < g.part_count; ++p) {
    const afm_part &part = g.parts[p];
    uint32_t len = in.u32();
    const uint8_t *stream = in.take(len);
    in.pad4();
    PartData d;
    d.attributes = g.attributes;
    d.nv = part.vertex_count;
    d.nt = part.triangle_count;
    std::vector<uint32_t> loose = read_loose_ids(in, d.nv);
    bool ok = in.ok && decode_part(stream, len, loose, d);
    if (ok) read_loose_values(in, loose, d);
    if (!ok || !in.ok) {
      set_diag(diag, AFM_CHUNK_GEOM, "part %u '%s': Draco stream truncated or invalid", p,
               part.name);
      return AFM_ERR_DRACO;
    }
    for (size_t i = 0; i < d.nv; ++i) {
      size_t w = part.first_vertex + i;
      px[w] = d.pos[3 * i], py[w] = d.pos[3 * i + 1], pz[w] = d.pos[3 * i + 2];
      if (!nx.empty()) nx[w] = d.nrm[3 * i], ny[w] = d.nrm[3 * i + 1], nz[w] = d.nrm[3 * i + 2];
      if (!u.empty()) u[w] = d.uv[2 * i], v[w] = d.uv[2 * i + 1];
      if (!rgba.empty()) std::memcpy(&rgba[4 * w], &d.rgba[4 * i], 4);
    }
    for (size_t t = 0; t < 3 * d.nt; ++t)
      tri[3 * static_cast<size_t>(part.first_triangle) + t] = d.tri[t] + part.first_vertex;
  }
  if (in.pos != size) {
    set_diag(diag, AFM_CHUNK_GEOM, "%zu bytes after the last part", size - in.pos);
    return AFM_ERR_TRAILING_BYTES;
  }
  g.px = px.data(), g.py = py.data(), g.pz = pz.data();
  if (!nx.empty()) g.nx = nx.data(), g.ny = ny.data(), g.nz = nz.data();
  if (!u.empty()) g.u = u.data(), g.v = v.data();
  if (!rgba.empty()) g.rgba = rgba.data();
  g.triangles = tri.data();
  size_t n = 0;
  r = afm_geometry_encoded_size(&g, &n);
  if (r != AFM_OK) return r;
  if (n != expect_size) {
    set_diag(diag, AFM_CHUNK_GEOM, "decodes to %zu raw bytes, header says %u", n, expect_size);
    return AFM_ERR_DRACO;
  }
  *raw = static_cast<uint8_t *>(afm_alloc(allocator, n ? n : 1));
  if (!*raw) return AFM_ERR_OUT_OF_MEMORY;
  r = afm_geometry_encode(&g, *raw, n);
  if (r != AFM_OK) {
    afm_free(allocator, *raw);
    *raw = nullptr;
    return r;
  }
  *raw_size = n;
  return AFM_OK;
}

// ---- MTGT -------------------------------------------------------------------

// A point cloud in sequential order (empty on failure).
std::vector<uint8_t> encode_sequential(const draco::PointCloud &pc) {
  draco::Encoder enc;
  enc.SetSpeedOptions(kSpeed, kSpeed);
  enc.SetEncodingMethod(draco::POINT_CLOUD_SEQUENTIAL_ENCODING);
  draco::EncoderBuffer buf;
  if (!enc.EncodePointCloudToBuffer(pc, &buf).ok()) return {};
  return std::vector<uint8_t>(buf.data(), buf.data() + buf.size());
}

// All values of `n` points with 3 int16 components as a sequential point cloud.
std::vector<uint8_t> encode_triples(const std::vector<int16_t> &values) {
  size_t n = values.size() / 3;
  if (n == 0) return {};
  draco::PointCloud pc;
  pc.set_num_points(static_cast<uint32_t>(n));
  add_attribute(pc, draco::GeometryAttribute::GENERIC, 3, draco::DT_INT16, 2, kUidDelta,
                values.data(), n);
  return encode_sequential(pc);
}

// A point cloud from a Draco stream; null when it does not decode.
std::unique_ptr<draco::PointCloud> decode_cloud(const uint8_t *data, size_t size) {
  draco::DecoderBuffer buf;
  buf.Init(reinterpret_cast<const char *>(data), size);
  draco::Decoder dec;
  auto r = dec.DecodePointCloudFromBuffer(&buf);
  if (!r.ok()) return nullptr;
  return std::move(r).value();
}

bool decode_triples(const uint8_t *data, size_t size, size_t n, std::vector<int16_t> &out) {
  out.assign(3 * n, 0);
  if (n == 0) return size == 0;
  const std::unique_ptr<draco::PointCloud> cloud = decode_cloud(data, size);
  if (!cloud) return false;
  const draco::PointCloud &pc = *cloud;
  const draco::PointAttribute *a = pc.GetAttributeByUniqueId(kUidDelta);
  if (!a || pc.num_points() != n || a->num_components() != 3 || a->data_type() != draco::DT_INT16)
    return false;
  for (uint32_t p = 0; p < n; ++p) a->GetMappedValue(draco::PointIndex(p), &out[3 * p]);
  return true;
}

afm_result mtgt_from_raw(const uint8_t *raw, size_t raw_size, const afm_allocator *allocator,
                         uint8_t **out, size_t *out_size, afm_diag *diag) {
  std::vector<uint64_t> storage;
  uint32_t count = 0;
  afm_target *targets = nullptr;
  // Run ranges are checked against the geometry by the document reader.
  afm_result r = decode_with_storage(storage, [&](void *buf, size_t n, size_t *bytes) {
    return afm_targets_decode(raw, raw_size, 0xFFFFFFFFu, buf, n, bytes, &count, &targets, diag);
  });
  if (r != AFM_OK) return r;
  Out o;
  o.u32(static_cast<uint32_t>(raw_size));
  o.u32(count);
  std::vector<int16_t> deltas, normals;
  for (uint32_t i = 0; i < count; ++i) {
    const afm_target &t = targets[i];
    uint8_t head[4] = {t.kind, t.number, t.flags, 0};
    o.bytes(head, 4);
    o.u32(static_cast<uint32_t>(t.reference));
    o.u32(t.run_count);
    o.u32(t.delta_count);
    if (t.kind == AFM_TARGET_COMBINATION) {
      o.u32(t.gate);  // as raw: u8 gate, u8 0, u16 0
      o.u32(static_cast<uint32_t>(t.gate_reference));
    }
    for (uint32_t k = 0; k < t.run_count; ++k) {
      o.u32(t.runs[k].start);
      o.u32(t.runs[k].length);
    }
    for (uint32_t k = 0; k < t.delta_count; ++k) {
      deltas.insert(deltas.end(), {t.dx[k], t.dy[k], t.dz[k]});
      if (t.flags & AFM_TARGET_NORMALS) normals.insert(normals.end(), {t.nx[k], t.ny[k], t.nz[k]});
    }
  }
  for (const std::vector<int16_t> *v : {&deltas, &normals}) {
    std::vector<uint8_t> s = encode_triples(*v);
    std::vector<int16_t> back;
    if ((!v->empty() && s.empty()) || !decode_triples(s.data(), s.size(), v->size() / 3, back) ||
        back != *v) {
      *out = nullptr;  // keep raw
      return AFM_OK;
    }
    o.u32(static_cast<uint32_t>(s.size()));
    o.bytes(s.data(), s.size());
    o.pad4();
  }
  if (o.b.size() * 100 > raw_size * (100 - AFM_DRACO_MIN_SAVING_PERCENT)) {
    *out = nullptr;
    return AFM_OK;
  }
  return hand_out(o.b, allocator, out, out_size);
}

afm_result mtgt_to_raw(const uint8_t *data, size_t size, const afm_allocator *allocator,
                       uint8_t **raw, size_t *raw_size, afm_diag *diag) {
  In in{data, size};
  uint32_t expect_size = in.u32();
  uint32_t count = in.u32();
  if (!in.ok || count > (size - in.pos) / 16) {
    set_diag(diag, AFM_CHUNK_MTGT, "target count truncated or too large");
    return AFM_ERR_TRUNCATED;
  }
  std::vector<afm_target> targets(count);
  std::vector<std::vector<afm_run>> runs(count);
  size_t total = 0, total_normals = 0;
  for (uint32_t i = 0; i < count && in.ok; ++i) {
    afm_target &t = targets[i];
    const uint8_t *head = in.take(4);
    if (!head) break;
    t.kind = head[0], t.number = head[1], t.flags = head[2];
    t.reference = static_cast<int32_t>(in.u32());
    t.run_count = in.u32();
    t.delta_count = in.u32();
    if (t.kind == AFM_TARGET_COMBINATION) {
      const uint32_t gate = in.u32();
      t.gate = static_cast<uint8_t>(gate);  // the raw reader checks the rest
      t.gate_reference = static_cast<int32_t>(in.u32());
      if (gate > 0xFFu) in.ok = false;
    }
    if (!in.ok || t.run_count > (size - in.pos) / 8) {
      in.ok = false;
      break;
    }
    runs[i].resize(t.run_count);
    for (auto &run : runs[i]) run.start = in.u32(), run.length = in.u32();
    t.runs = runs[i].data();
    total += t.delta_count;
    if (t.flags & AFM_TARGET_NORMALS) total_normals += t.delta_count;
  }
  // Draco needs at least a bit per value: bound the untrusted totals.
  if (!in.ok || total > 8 * size + 64 || total_normals > 8 * size + 64) {
    set_diag(diag, AFM_CHUNK_MTGT, "target headers truncated or inconsistent");
    return AFM_ERR_TRUNCATED;
  }
  std::vector<int16_t> deltas, normals;
  for (auto [v, n] : {std::pair{&deltas, total}, std::pair{&normals, total_normals}}) {
    uint32_t len = in.u32();
    const uint8_t *s = in.take(len);
    in.pad4();
    if (!in.ok || !decode_triples(s, len, n, *v)) {
      set_diag(diag, AFM_CHUNK_MTGT, "Draco delta stream truncated or invalid");
      return AFM_ERR_DRACO;
    }
  }
  if (in.pos != size) {
    set_diag(diag, AFM_CHUNK_MTGT, "%zu bytes after the delta streams", size - in.pos);
    return AFM_ERR_TRAILING_BYTES;
  }
  // Planar arrays per target, as the raw encoding stores them.
  std::vector<int16_t> planar(3 * total + 3 * total_normals);
  size_t at = 0, nat = 0, out_at = 0;
  for (afm_target &t : targets) {
    int16_t *base = planar.data() + out_at;
    for (uint32_t k = 0; k < t.delta_count; ++k)
      for (int c = 0; c < 3; ++c) base[c * t.delta_count + k] = deltas[3 * (at + k) + c];
    t.dx = base, t.dy = base + t.delta_count, t.dz = base + 2 * t.delta_count;
    out_at += 3 * t.delta_count;
    at += t.delta_count;
    if (t.flags & AFM_TARGET_NORMALS) {
      int16_t *nb = planar.data() + out_at;
      for (uint32_t k = 0; k < t.delta_count; ++k)
        for (int c = 0; c < 3; ++c) nb[c * t.delta_count + k] = normals[3 * (nat + k) + c];
      t.nx = nb, t.ny = nb + t.delta_count, t.nz = nb + 2 * t.delta_count;
      out_at += 3 * t.delta_count;
      nat += t.delta_count;
    }
  }
  size_t n = 0;
  afm_result r = afm_targets_encoded_size(targets.data(), count, &n);
  if (r != AFM_OK) return r;
  if (n != expect_size) {
    set_diag(diag, AFM_CHUNK_MTGT, "decodes to %zu raw bytes, header says %u", n, expect_size);
    return AFM_ERR_DRACO;
  }
  *raw = static_cast<uint8_t *>(afm_alloc(allocator, n ? n : 1));
  if (!*raw) return AFM_ERR_OUT_OF_MEMORY;
  r = afm_targets_encode(targets.data(), count, *raw, n);
  if (r != AFM_OK) {
    afm_free(allocator, *raw);
    *raw = nullptr;
    return r;
  }
  *raw_size = n;
  return AFM_OK;
}

// ---- LIFT -------------------------------------------------------------------

// The raw LIFT payload's parts (formats/afm.md); `ok` false when it does not
// parse. The document reader checks the values themselves.
struct LiftRaw {
  uint32_t controls = 0, run_count = 0, bound = 0;
  std::vector<uint32_t> runs;      // 2 per run
  std::vector<uint32_t> c;         // 3 per bound vertex: c0 c1 c2
  std::vector<uint16_t> w;         // 2 per bound vertex: w1 w2
  bool ok = false;
};

LiftRaw parse_lift(const uint8_t *raw, size_t size) {
  LiftRaw l;
  In in{raw, size};
  l.controls = in.u32(), l.run_count = in.u32(), l.bound = in.u32();
  if (!in.ok || l.run_count > (size - in.pos) / 8 || l.bound > (size - in.pos) / 16) return l;
  l.runs.resize(2 * static_cast<size_t>(l.run_count));
  for (uint32_t &v : l.runs) v = in.u32();
  l.c.resize(3 * static_cast<size_t>(l.bound));
  for (int k = 0; k < 3; ++k)
    for (uint32_t b = 0; b < l.bound; ++b) l.c[3 * b + static_cast<size_t>(k)] = in.u32();
  l.w.resize(2 * static_cast<size_t>(l.bound));
  for (int k = 0; k < 2; ++k) {
    for (uint32_t b = 0; b < l.bound; ++b) l.w[2 * b + static_cast<size_t>(k)] = in.u16();
    in.pad4();
  }
  l.ok = in.ok && in.pos == size;
  return l;
}

std::vector<uint8_t> lift_raw_bytes(const LiftRaw &l) {
  Out o;
  o.u32(l.controls), o.u32(l.run_count), o.u32(l.bound);
  for (uint32_t v : l.runs) o.u32(v);
  for (int k = 0; k < 3; ++k)
    for (uint32_t b = 0; b < l.bound; ++b) o.u32(l.c[3 * b + static_cast<size_t>(k)]);
  for (int k = 0; k < 2; ++k) {
    for (uint32_t b = 0; b < l.bound; ++b) o.u16(l.w[2 * b + static_cast<size_t>(k)]);
    o.pad4();
  }
  return o.b;
}

std::vector<uint8_t> encode_lift_cloud(const LiftRaw &l) {
  if (l.bound == 0) return {};
  draco::PointCloud pc;
  pc.set_num_points(l.bound);
  add_attribute(pc, draco::GeometryAttribute::GENERIC, 3, draco::DT_UINT32, 4, kUidLiftControls, l.c.data(), l.bound);
  add_attribute(pc, draco::GeometryAttribute::GENERIC, 2, draco::DT_UINT16, 2, kUidLiftWeights, l.w.data(), l.bound);
  return encode_sequential(pc);
}

bool decode_lift_cloud(const uint8_t *data, size_t size, LiftRaw &l) {
  l.c.assign(3 * static_cast<size_t>(l.bound), 0);
  l.w.assign(2 * static_cast<size_t>(l.bound), 0);
  if (l.bound == 0) return size == 0;
  const std::unique_ptr<draco::PointCloud> cloud = decode_cloud(data, size);
  if (!cloud) return false;
  const draco::PointCloud &pc = *cloud;
  const draco::PointAttribute *c = pc.GetAttributeByUniqueId(kUidLiftControls);
  const draco::PointAttribute *w = pc.GetAttributeByUniqueId(kUidLiftWeights);
  if (!c || !w || pc.num_points() != l.bound || c->num_components() != 3 || c->data_type() != draco::DT_UINT32 ||
      w->num_components() != 2 || w->data_type() != draco::DT_UINT16)
    return false;
  for (uint32_t p = 0; p < l.bound; ++p) {
    c->GetMappedValue(draco::PointIndex(p), &l.c[3 * p]);
    w->GetMappedValue(draco::PointIndex(p), &l.w[2 * p]);
  }
  return true;
}

afm_result lift_from_raw(const uint8_t *raw, size_t raw_size, const afm_allocator *allocator, uint8_t **out,
                         size_t *out_size) {
  const LiftRaw l = parse_lift(raw, raw_size);
  if (!l.ok) return AFM_OK;  // keep raw; the reader reports what is wrong
  const std::vector<uint8_t> cloud = encode_lift_cloud(l);
  LiftRaw back = l;
  if ((l.bound && cloud.empty()) || !decode_lift_cloud(cloud.data(), cloud.size(), back) || back.c != l.c ||
      back.w != l.w)
    return AFM_OK;
  Out o;
  o.u32(static_cast<uint32_t>(raw_size));
  o.u32(l.controls), o.u32(l.run_count), o.u32(l.bound);
  for (uint32_t v : l.runs) o.u32(v);
  o.u32(static_cast<uint32_t>(cloud.size()));
  o.bytes(cloud.data(), cloud.size());
  o.pad4();
  if (o.b.size() * 100 > raw_size * (100 - AFM_DRACO_MIN_SAVING_PERCENT)) return AFM_OK;
  return hand_out(o.b, allocator, out, out_size);
}

afm_result lift_to_raw(const uint8_t *data, size_t size, const afm_allocator *allocator, uint8_t **raw,
                       size_t *raw_size, afm_diag *diag) {
  In in{data, size};
  LiftRaw l;
  const uint32_t expect_size = in.u32();
  l.controls = in.u32(), l.run_count = in.u32(), l.bound = in.u32();
  // Draco needs at least a bit per value: bound the untrusted count.
  if (!in.ok || l.run_count > (size - in.pos) / 8 || l.bound > 8 * size + 64) {
    set_diag(diag, AFM_CHUNK_LIFT, "counts truncated or too large");
    return AFM_ERR_TRUNCATED;
  }
  l.runs.resize(2 * static_cast<size_t>(l.run_count));
  for (uint32_t &v : l.runs) v = in.u32();
  const uint32_t len = in.u32();
  const uint8_t *cloud = in.take(len);
  in.pad4();
  if (!in.ok || !decode_lift_cloud(cloud, len, l)) {
    set_diag(diag, AFM_CHUNK_LIFT, "Draco stream truncated or invalid");
    return AFM_ERR_DRACO;
  }
  if (in.pos != size) {
    set_diag(diag, AFM_CHUNK_LIFT, "%zu bytes after the Draco stream", size - in.pos);
    return AFM_ERR_TRAILING_BYTES;
  }
  const std::vector<uint8_t> bytes = lift_raw_bytes(l);
  if (bytes.size() != expect_size) {
    set_diag(diag, AFM_CHUNK_LIFT, "decodes to %zu raw bytes, header says %u", bytes.size(), expect_size);
    return AFM_ERR_DRACO;
  }
  return hand_out(bytes, allocator, raw, raw_size);
}

// ---- C ABI ------------------------------------------------------------------

afm_result to_raw(void *, uint32_t kind, const uint8_t *data, size_t size,
                  const afm_allocator *allocator, uint8_t **raw, size_t *raw_size,
                  afm_diag *diag) {
  if (!data || !raw || !raw_size) return AFM_ERR_ARGUMENT;
  *raw = nullptr;
  *raw_size = 0;
  try {
    if (kind == AFM_CHUNK_GEOM) return geom_to_raw(data, size, allocator, raw, raw_size, diag);
    if (kind == AFM_CHUNK_MTGT) return mtgt_to_raw(data, size, allocator, raw, raw_size, diag);
    if (kind == AFM_CHUNK_LIFT) return lift_to_raw(data, size, allocator, raw, raw_size, diag);
  } catch (const std::bad_alloc &) {
    return AFM_ERR_OUT_OF_MEMORY;
  } catch (...) {
    set_diag(diag, kind, "Draco decoder threw");
    return AFM_ERR_DRACO;
  }
  set_diag(diag, kind, "no Draco encoding is defined for this chunk");
  return AFM_ERR_UNKNOWN_REQUIRED;
}

afm_result from_raw(void *, uint32_t kind, const uint8_t *raw, size_t raw_size,
                    const afm_allocator *allocator, uint8_t **out, size_t *out_size,
                    afm_diag *diag) {
  if (!raw || !out || !out_size) return AFM_ERR_ARGUMENT;
  *out = nullptr;
  *out_size = 0;
  try {
    if (kind == AFM_CHUNK_GEOM) return geom_from_raw(raw, raw_size, allocator, out, out_size, diag);
    if (kind == AFM_CHUNK_MTGT) return mtgt_from_raw(raw, raw_size, allocator, out, out_size, diag);
    if (kind == AFM_CHUNK_LIFT) return lift_from_raw(raw, raw_size, allocator, out, out_size);
  } catch (const std::bad_alloc &) {
    return AFM_ERR_OUT_OF_MEMORY;
  } catch (...) {
    set_diag(diag, kind, "Draco encoder threw");
    return AFM_ERR_DRACO;
  }
  return AFM_OK;  // other chunks stay raw
}

const afm_chunk_codec kCodec = {to_raw, from_raw, nullptr};

}  // namespace

extern "C" const afm_chunk_codec *afm_draco_codec(void) { return &kCodec; }
