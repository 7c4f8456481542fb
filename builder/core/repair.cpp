#include "core/repair.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <set>
#include <tuple>

#include "core/part_kind.h"

namespace afmb {

namespace {

// Disjoint sets of indices; each set's root is its lowest index.
struct Unions {
  std::vector<int> up;
  explicit Unions(size_t n) : up(n) { std::iota(up.begin(), up.end(), 0); }
  int root(int v) {
    while (up[static_cast<size_t>(v)] != v) v = up[static_cast<size_t>(v)] = up[static_cast<size_t>(up[static_cast<size_t>(v)])];
    return v;
  }
  bool join(int a, int b) {  // false when already one set
    a = root(a), b = root(b);
    if (a == b) return false;
    up[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    return true;
  }
};

// Every undirected edge of F (lower index first) and how many triangles use it.
std::map<std::pair<int, int>, int> edge_uses(const Eigen::MatrixXi &F) {
  std::map<std::pair<int, int>, int> uses;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  return uses;
}

// Triangles to work on: some, each index a vertex. (check_skin says what is wrong otherwise.)
bool has_valid_triangles(const Part &p) {
  return p.F.rows() > 0 && p.F.minCoeff() >= 0 && p.F.maxCoeff() < p.V.rows();
}

}  // namespace

int repair_coincident_vertices(Scene &scene, int part_index, std::vector<std::string> *log) {
  Part &part = scene.parts[static_cast<size_t>(part_index)];
  Unions sets(static_cast<size_t>(part.V.rows()));
  auto root = [&](int v) { return sets.root(v); };
  std::string welded;
  for (Eigen::Index f = 0; f < part.F.rows(); ++f) {
    Eigen::Vector3d a = part.V.row(part.F(f, 0)), b = part.V.row(part.F(f, 1)), c = part.V.row(part.F(f, 2));
    if ((b - a).cross(c - a).squaredNorm() != 0) continue;
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j) {
        int p = root(part.F(f, i)), q = root(part.F(f, j));
        if (p == q || part.V.row(p) != part.V.row(q)) continue;
        if (p > q) std::swap(p, q);
        sets.join(p, q);
        welded += " " + std::to_string(q) + "->" + std::to_string(p);
      }
  }
  if (welded.empty()) return 0;
  std::vector<Eigen::Index> keep;
  std::string dropped;
  for (Eigen::Index f = 0; f < part.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) part.F(f, k) = root(part.F(f, k));
    if (part.F(f, 0) == part.F(f, 1) || part.F(f, 1) == part.F(f, 2) || part.F(f, 0) == part.F(f, 2))
      dropped += " " + std::to_string(f);
    else
      keep.push_back(f);
  }
  const Eigen::Index nf_before = part.F.rows();
  const int removed = static_cast<int>(part.F.rows() - static_cast<Eigen::Index>(keep.size()));
  Eigen::MatrixXi F(static_cast<Eigen::Index>(keep.size()), 3), FTC;
  const bool has_ftc = part.FTC.rows() == part.F.rows() && part.FTC.rows() > 0;
  if (has_ftc) FTC.resize(static_cast<Eigen::Index>(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) {
    F.row(static_cast<Eigen::Index>(i)) = part.F.row(keep[i]);
    if (has_ftc) FTC.row(static_cast<Eigen::Index>(i)) = part.FTC.row(keep[i]);
  }
  part.F = F;
  if (has_ftc) part.FTC = FTC;
  if (part.face_material.size() == static_cast<size_t>(nf_before)) {
    std::vector<int> fm;
    for (Eigen::Index f : keep) fm.push_back(part.face_material[static_cast<size_t>(f)]);
    part.face_material = std::move(fm);
  }
  if (log) {
    log->push_back("part '" + part.name + "': welded coincident vertices" + welded);
    log->push_back("part '" + part.name + "': dropped " + std::to_string(removed) +
                   " zero-area triangles (input triangles" + dropped + ")");
  }
  return removed;
}

int split_skin_pieces(Scene &scene, int part_index, FdpSet &fdps, std::vector<std::string> *log) {
  const Part whole = scene.parts[static_cast<size_t>(part_index)];
  const Eigen::Index nv = whole.V.rows(), nf = whole.F.rows();
  if (!has_valid_triangles(whole)) return 0;
  Unions sets(static_cast<size_t>(nv));
  auto root = [&](int v) { return sets.root(v); };
  std::vector<char> used(static_cast<size_t>(nv), 0);
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      used[static_cast<size_t>(whole.F(f, k))] = 1;
      if (k) sets.join(whole.F(f, 0), whole.F(f, k));
    }
  // Split seams: vertices at one position on the pieces' open edges. (Closed
  // pieces that touch, as teeth rows at rest, stay apart.)
  std::vector<char> open(static_cast<size_t>(nv), 0);
  for (const auto &[e, n] : edge_uses(whole.F))
    if (n == 1) open[static_cast<size_t>(e.first)] = open[static_cast<size_t>(e.second)] = 1;
  std::map<std::array<double, 3>, int> at;
  for (Eigen::Index v = 0; v < nv; ++v) {
    if (!open[static_cast<size_t>(v)]) continue;
    const auto [it, fresh] = at.insert({{whole.V(v, 0), whole.V(v, 1), whole.V(v, 2)}, static_cast<int>(v)});
    if (!fresh) sets.join(it->second, static_cast<int>(v));
  }
  // Pieces in the order of their first triangle.
  std::vector<int> piece_of_root(static_cast<size_t>(nv), -1), face_piece(static_cast<size_t>(nf));
  int pieces = 0;
  for (Eigen::Index f = 0; f < nf; ++f) {
    int &p = piece_of_root[static_cast<size_t>(root(whole.F(f, 0)))];
    if (p < 0) p = pieces++;
    face_piece[static_cast<size_t>(f)] = p;
  }
  const FdpPoint *chin = nullptr;
  for (const FdpPoint &q : fdps.points)
    if (q.part == part_index && q.id == FdpId{2, 1} && q.vertex >= 0 && used[static_cast<size_t>(q.vertex)]) chin = &q;
  if (pieces < 2 || !chin) return 0;
  auto piece_of_vertex = [&](int v) { return used[static_cast<size_t>(v)] ? piece_of_root[static_cast<size_t>(root(v))] : -1; };
  const int skin_piece = piece_of_vertex(chin->vertex);
  // Each piece's vertices, ascending; the skin piece keeps the unreferenced ones.
  std::vector<std::vector<int>> verts(static_cast<size_t>(pieces));
  std::vector<int> local(static_cast<size_t>(nv));
  for (Eigen::Index v = 0; v < nv; ++v) {
    const int p = piece_of_vertex(static_cast<int>(v));
    std::vector<int> &list = verts[static_cast<size_t>(p < 0 ? skin_piece : p)];
    local[static_cast<size_t>(v)] = static_cast<int>(list.size());
    list.push_back(static_cast<int>(v));
  }
  // The kind each piece's FDPs give it.
  std::vector<PartKind> kind(static_cast<size_t>(pieces), PartKind::Other);
  std::vector<char> mixed(static_cast<size_t>(pieces), 0);
  for (const FdpPoint &q : fdps.points) {
    if (q.part != part_index || q.vertex < 0) continue;
    const int p = piece_of_vertex(q.vertex);
    const PartKind k = fdp_part_kind(q.id);
    if (p < 0 || p == skin_piece || k == PartKind::Skin) continue;
    if (kind[static_cast<size_t>(p)] != PartKind::Other && kind[static_cast<size_t>(p)] != k)
      mixed[static_cast<size_t>(p)] = 1;
    kind[static_cast<size_t>(p)] = k;
  }
  for (int p = 0; p < pieces; ++p)
    if (mixed[static_cast<size_t>(p)]) kind[static_cast<size_t>(p)] = PartKind::Other;  // FDPs of two kinds
  // A piece no FDP names that lies in the mouth, behind the lips (teeth,
  // gums, a tongue: Song's and Alice's files name no teeth), moves with the
  // bone on its side of the lip line: above it the skull's (TeethUpper),
  // below it the jaw's (TeethLower).
  const FdpPoint *lip = nullptr, *corner_l = nullptr, *corner_r = nullptr;
  for (const FdpPoint &q : fdps.points)
    if (q.part == part_index && q.vertex >= 0) {
      if (q.id == FdpId{2, 2}) lip = &q;
      if (q.id == FdpId{2, 4}) corner_l = &q;
      if (q.id == FdpId{2, 5}) corner_r = &q;
    }
  if (lip && corner_l && corner_r) {
    const double w = corner_l->pos.x() - corner_r->pos.x(), drop = lip->pos.y() - chin->pos.y();
    std::vector<Eigen::Vector3d> sum(static_cast<size_t>(pieces), Eigen::Vector3d::Zero());
    std::vector<int> count(static_cast<size_t>(pieces), 0);
    for (Eigen::Index v = 0; v < nv; ++v)
      if (const int p = piece_of_vertex(static_cast<int>(v)); p >= 0)
        sum[static_cast<size_t>(p)] += whole.V.row(v).transpose(), ++count[static_cast<size_t>(p)];
    for (int p = 0; p < pieces; ++p) {
      if (p == skin_piece || kind[static_cast<size_t>(p)] != PartKind::Other || mixed[static_cast<size_t>(p)]) continue;
      const Eigen::Vector3d c = sum[static_cast<size_t>(p)] / count[static_cast<size_t>(p)];
      const bool in_mouth = w > 0 && drop > 0 && c.x() > corner_r->pos.x() - w / 4 && c.x() < corner_l->pos.x() + w / 4 &&
                            c.y() > chin->pos.y() && c.y() < lip->pos.y() + drop && c.z() < lip->pos.z() &&
                            c.z() > lip->pos.z() - 1.5 * w;
      if (in_mouth) kind[static_cast<size_t>(p)] = c.y() > lip->pos.y() ? PartKind::TeethUpper : PartKind::TeethLower;
    }
  }
  const bool has_ftc = whole.FTC.rows() == nf && nf > 0 && whole.TC.rows() > 0;
  const bool has_c = whole.C.rows() == nv && nv > 0;
  std::vector<int> part_of_piece(static_cast<size_t>(pieces));
  std::string said;
  int unnamed = 1;
  for (int p = 0; p < pieces; ++p) {
    Part out;
    if (p == skin_piece) {
      out = whole;
    } else {
      out.kind = kind[static_cast<size_t>(p)];
      out.name = whole.name + (out.kind != PartKind::Other ? std::string("_") + part_kind_name(out.kind)
                                                           : "_piece" + std::to_string(++unnamed));
      for (int k = 2; scene.find_part(out.name) >= 0; ++k)
        out.name = whole.name + "_" + part_kind_name(out.kind) + "_" + std::to_string(k);
      out.diffuse = whole.diffuse;
      out.texture = whole.texture;
    }
    const std::vector<int> &vs = verts[static_cast<size_t>(p)];
    out.V.resize(static_cast<Eigen::Index>(vs.size()), 3);
    if (has_c) out.C.resize(static_cast<Eigen::Index>(vs.size()), 3);
    for (size_t i = 0; i < vs.size(); ++i) {
      out.V.row(static_cast<Eigen::Index>(i)) = whole.V.row(vs[i]);
      if (has_c) out.C.row(static_cast<Eigen::Index>(i)) = whole.C.row(vs[i]);
    }
    std::vector<Eigen::Index> faces;
    for (Eigen::Index f = 0; f < nf; ++f)
      if (face_piece[static_cast<size_t>(f)] == p) faces.push_back(f);
    out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    if (whole.face_material.size() == static_cast<size_t>(nf) && !whole.materials.empty()) {
      // The piece's own material: the one most of its triangles use.
      std::vector<int> uses(whole.materials.size(), 0);
      out.face_material.clear();
      for (Eigen::Index f : faces) {
        const int m = whole.face_material[static_cast<size_t>(f)];
        out.face_material.push_back(m);
        if (m >= 0) ++uses[static_cast<size_t>(m)];
      }
      out.materials = whole.materials;
      const auto most = std::max_element(uses.begin(), uses.end());
      if (*most > 0) {
        out.diffuse = whole.materials[static_cast<size_t>(most - uses.begin())].diffuse;
        out.texture = whole.materials[static_cast<size_t>(most - uses.begin())].texture;
      }
    }
    std::map<int, int> tc;  // the piece's texture coordinates, in first-use order
    if (has_ftc) out.FTC.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (size_t i = 0; i < faces.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        out.F(static_cast<Eigen::Index>(i), k) = local[static_cast<size_t>(whole.F(faces[i], k))];
        if (has_ftc) {
          const auto [it, fresh] = tc.insert({whole.FTC(faces[i], k), static_cast<int>(tc.size())});
          out.FTC(static_cast<Eigen::Index>(i), k) = it->second;
        }
      }
    if (has_ftc) {
      out.TC.resize(static_cast<Eigen::Index>(tc.size()), 2);
      for (const auto &[from, to] : tc) out.TC.row(to) = whole.TC.row(from);
    } else if (whole.TC.rows() == nv && nv > 0) {  // per-vertex texture coordinates
      out.TC.resize(static_cast<Eigen::Index>(vs.size()), 2);
      for (size_t i = 0; i < vs.size(); ++i) out.TC.row(static_cast<Eigen::Index>(i)) = whole.TC.row(vs[i]);
    } else {
      out.TC.resize(0, 2);
      out.FTC.resize(0, 3);
    }
    if (!has_c) out.C.resize(0, 3);
    if (p == skin_piece) {
      part_of_piece[static_cast<size_t>(p)] = part_index;
      scene.parts[static_cast<size_t>(part_index)] = std::move(out);
    } else {
      part_of_piece[static_cast<size_t>(p)] = static_cast<int>(scene.parts.size());
      said += ", '" + out.name + "' (" + std::to_string(out.V.rows()) + " vertices)";
      scene.parts.push_back(std::move(out));
    }
  }
  for (FdpPoint &q : fdps.points) {
    if (q.part != part_index || q.vertex < 0) continue;
    const int p = piece_of_vertex(q.vertex);
    q.part = part_of_piece[static_cast<size_t>(p < 0 ? skin_piece : p)];
    q.part_name = scene.parts[static_cast<size_t>(q.part)].name;
    q.vertex = local[static_cast<size_t>(q.vertex)];
  }
  if (log)
    log->push_back("part '" + whole.name + "': split into its " + std::to_string(pieces) +
                   " separate pieces: the skin (" + std::to_string(scene.parts[static_cast<size_t>(part_index)].V.rows()) +
                   " vertices)" + said);
  return pieces - 1;
}

int cut_fused_lips(Scene &scene, int part_index, FdpSet &fdps, std::vector<std::string> *log) {
  Part &p = scene.parts[static_cast<size_t>(part_index)];
  const int nv = static_cast<int>(p.V.rows());
  const Eigen::Index nf = p.F.rows();
  if (!has_valid_triangles(p)) return 0;
  auto vertex_of = [&](const char *id) {
    const FdpPoint *q = fdps.find(*FdpId::parse(id), part_index);
    return q && q->part == part_index ? q->vertex : -1;
  };
  const int upper = vertex_of("2.2"), lower = vertex_of("2.3");
  if (upper < 0 || upper != lower) return 0;
  std::vector<int> stops;
  for (const char *id : {"2.4", "2.6", "2.2", "2.7", "2.5"}) {
    const int v = vertex_of(id);
    if (v < 0) return 0;
    stops.push_back(v);
  }
  // The inner edges (in two triangles; one in a single triangle is the
  // skin's edge) from each vertex, and the triangles about each vertex.
  std::vector<std::vector<int>> faces_at(static_cast<size_t>(nv)), next(static_cast<size_t>(nv));
  for (const auto &[e, n] : edge_uses(p.F))
    if (n == 2) next[static_cast<size_t>(e.first)].push_back(e.second), next[static_cast<size_t>(e.second)].push_back(e.first);
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) faces_at[static_cast<size_t>(p.F(f, k))].push_back(static_cast<int>(f));
  // Shortest paths between the stops over inner edges (Dijkstra).
  std::vector<int> line = {stops[0]};
  for (size_t s = 1; s < stops.size(); ++s) {
    const int from = stops[s - 1], to = stops[s];
    if (from == to) continue;
    std::vector<double> dist(static_cast<size_t>(nv), std::numeric_limits<double>::infinity());
    std::vector<int> back(static_cast<size_t>(nv), -1);
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    dist[static_cast<size_t>(from)] = 0;
    queue.push({0, from});
    while (!queue.empty()) {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > dist[static_cast<size_t>(v)] || v == to) continue;
      for (int w : next[static_cast<size_t>(v)]) {
        const double dw = d + (p.V.row(v) - p.V.row(w)).norm();
        if (dw < dist[static_cast<size_t>(w)]) dist[static_cast<size_t>(w)] = dw, back[static_cast<size_t>(w)] = v, queue.push({dw, w});
      }
    }
    if (back[static_cast<size_t>(to)] < 0) return 0;
    std::vector<int> leg;
    for (int v = to; v != from; v = back[static_cast<size_t>(v)]) leg.push_back(v);
    line.insert(line.end(), leg.rbegin(), leg.rend());
  }
  if (line.size() < 3 || std::set<int>(line.begin(), line.end()).size() != line.size()) return 0;
  // Each inner vertex of the line: its triangles fall into two fans, split
  // by the line's two edges; the lower fan (by its corners' mean height)
  // takes the copy.
  std::vector<std::pair<int, int>> copies;  // (vertex, copy)
  std::vector<std::vector<int>> lower_fans;
  for (size_t i = 1; i + 1 < line.size(); ++i) {
    const int v = line[i], a = line[i - 1], b = line[i + 1];
    const std::vector<int> &fan = faces_at[static_cast<size_t>(v)];
    // Triangles of the fan sharing an edge at v that is not the line's are
    // on one side.
    Unions fans(fan.size());
    int sides = static_cast<int>(fan.size());
    std::map<int, int> first_at;  // the fan's other corner -> the first triangle holding it
    for (size_t x = 0; x < fan.size(); ++x)
      for (int k = 0; k < 3; ++k) {
        const int w = p.F(fan[x], k);
        if (w == v || w == a || w == b) continue;
        const auto [it, fresh] = first_at.insert({w, static_cast<int>(x)});
        if (!fresh && fans.join(it->second, static_cast<int>(x))) --sides;
      }
    if (sides != 2) return 0;
    std::vector<int> side(fan.size());
    for (size_t x = 0; x < fan.size(); ++x) side[x] = fans.root(static_cast<int>(x)) == 0 ? 0 : 1;
    double height[2] = {0, 0}, count[2] = {0, 0};
    for (size_t x = 0; x < fan.size(); ++x)
      for (int k = 0; k < 3; ++k) height[side[x]] += p.V(p.F(fan[x], k), 1), count[side[x]] += 1;
    const int low = height[0] / count[0] < height[1] / count[1] ? 0 : 1;
    std::vector<int> lower_fan;
    for (size_t x = 0; x < fan.size(); ++x)
      if (side[x] == low) lower_fan.push_back(fan[x]);
    copies.push_back({v, nv + static_cast<int>(copies.size())});
    lower_fans.push_back(std::move(lower_fan));
  }
  const int added = static_cast<int>(copies.size());
  p.V.conservativeResize(nv + added, 3);
  const bool has_c = p.C.rows() == nv, has_tc = p.TC.rows() == nv && p.FTC.rows() == 0;
  if (has_c) p.C.conservativeResize(nv + added, 3);
  if (has_tc) p.TC.conservativeResize(nv + added, 2);
  for (size_t i = 0; i < copies.size(); ++i) {
    const auto [v, c] = copies[i];
    p.V.row(c) = p.V.row(v);
    if (has_c) p.C.row(c) = p.C.row(v);
    if (has_tc) p.TC.row(c) = p.TC.row(v);
    for (int f : lower_fans[i])
      for (int k = 0; k < 3; ++k)
        if (p.F(f, k) == v) p.F(f, k) = c;
  }
  for (FdpPoint &q : fdps.points)
    if (q.part == part_index && (q.id == FdpId{2, 3} || q.id == FdpId{2, 8} || q.id == FdpId{2, 9}))
      for (const auto &[v, c] : copies)
        if (q.vertex == v) q.vertex = c;
  if (log)
    log->push_back("part '" + p.name + "': the lips are one surface (FDPs 2.2 and 2.3 on vertex " +
                   std::to_string(upper) + "): cut along the lip line from 2.4 to 2.5 (" + std::to_string(added + 1) +
                   " edges), its " + std::to_string(added) + " inner vertices doubled, so that the mouth can open");
  return added;
}

int split_touching_surfaces(Eigen::MatrixXd &V, Eigen::MatrixXi &F) {
  std::map<std::pair<int, int>, std::vector<int>> edges;
  for (int t = 0; t < F.rows(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int a = F(t, c), b = F(t, (c + 1) % 3);
      edges[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  // The triangle's corner that is neither end of edge (a, b); whether it
  // runs the edge a -> b.
  auto third = [&](int t, int a, int b) {
    for (int c = 0; c < 3; ++c)
      if (F(t, c) != a && F(t, c) != b) return F(t, c);
    return -1;
  };
  auto runs_forward = [&](int t, int a, int b) {
    for (int c = 0; c < 3; ++c)
      if (F(t, c) == a) return F(t, (c + 1) % 3) == b;
    return false;
  };
  Unions surfaces(static_cast<size_t>(F.rows()));
  for (const auto &[edge, ts] : edges) {
    if (ts.size() % 2 == 1 && ts.size() > 2) return 0;
    if (ts.size() == 2) surfaces.join(ts[0], ts[1]);
    if (ts.size() < 4) continue;
    const auto [a, b] = edge;
    const Eigen::Vector3d origin = V.row(a).transpose(), axis = (V.row(b) - V.row(a)).transpose().normalized();
    Eigen::Vector3d ref = Eigen::Vector3d::Zero();
    // (angle about the axis, runs b -> a, triangle). Two triangles in one
    // half-plane (surfaces in contact over a face) meet outside either
    // surface: the one that closes its surface's inside (a -> b) first.
    std::vector<std::tuple<double, bool, int>> round;
    for (int t : ts) {
      Eigen::Vector3d u = V.row(third(t, a, b)).transpose() - origin;
      u -= u.dot(axis) * axis;
      if (ref.isZero()) ref = u.normalized();
      round.emplace_back(std::atan2(axis.cross(ref).dot(u), ref.dot(u)), !runs_forward(t, a, b), t);
    }
    std::sort(round.begin(), round.end());
    // Start at a b -> a triangle; then they must alternate.
    size_t first = 0;
    while (first < round.size() && !std::get<1>(round[first])) ++first;
    for (size_t k = 0; k < round.size(); k += 2) {
      const int from = std::get<2>(round[(first + k) % round.size()]);
      const int to = std::get<2>(round[(first + k + 1) % round.size()]);
      if (runs_forward(from, a, b) || !runs_forward(to, a, b)) return 0;
      surfaces.join(from, to);
    }
  }
  const int nv = static_cast<int>(V.rows());
  std::vector<std::map<int, int>> copy_of(static_cast<size_t>(nv));  // per vertex: surface -> its vertex
  std::vector<Eigen::RowVector3d> copies;
  int split = 0;
  for (int t = 0; t < F.rows(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int v = F(t, c), surface = surfaces.root(t);
      std::map<int, int> &m = copy_of[static_cast<size_t>(v)];
      auto it = m.find(surface);
      if (it == m.end()) {
        if (m.size() == 1) ++split;
        const int id = m.empty() ? v : nv + static_cast<int>(copies.size());
        if (!m.empty()) copies.push_back(V.row(v));
        it = m.insert({surface, id}).first;
      }
      F(t, c) = it->second;
    }
  V.conservativeResize(nv + static_cast<Eigen::Index>(copies.size()), 3);
  for (size_t k = 0; k < copies.size(); ++k) V.row(nv + static_cast<Eigen::Index>(k)) = copies[k];
  return split;
}

}  // namespace afmb
