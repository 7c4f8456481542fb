// AFM size at equal error and decode time, on real anatomical targets
// (issue 5): the builder's model and FAP synthesis, as afm-build -o runs them
// (on the simulation mesh, its motion stored on control points: LIFT).
//
// Models: the reference head at 2,000 skin vertices and the Song head when
// ../shared/data is there; their builds take about 10 and 15 seconds on two
// workers (a worker per core by default). The 10k head is left out by
// default; `--vertices 10000` adds it.
//
// Per model:
// - sizes: the AFM file and its targets (the MTGT chunk plus LIFT when the
//   AFM has control points), raw and draco profiles, against dense float32
//   targets (targets x vertices x 3 x 4 bytes over every AFM vertex, seam
//   copies included; normal deltas counted too when the AFM stores them) and
//   against a meshopt-style baseline at equal error:
//     the builder's targets rounded to whole quanta of the AFM's grid per
//     vertex (the AFM's own lifted deltas rounded when measuring a file),
//     each target dense over every vertex in the AFM's vertex order; per
//     component the int16 delta from the previous vertex, zigzagged, split
//     into a low and a high byte plane (meshoptimizer's vertex codec deltas
//     and zigzags each byte lane; whole int16 deltas are the kinder choice on
//     smooth fields); every target's planes then in one zlib stream at level
//     9, where meshoptimizer would be followed by a general compressor. No
//     meshoptimizer code. The baseline is decoded back and must give its
//     quanta exactly.
// - error: every target decoded with the format library to dense float
//   displacements (control points lifted exactly, afm_target_expand), and
//   the baseline's, against the builder's double targets on the same render
//   vertices; the largest component error in grid quanta (0.5 is rounding).
// - times: reading the AFM from memory into a ready player (afm_doc_read_alloc,
//   afm_player_init), raw and draco; a pose per frame over a cycle of states
//   that between them blend every target; a dense float32 blend of the same
//   weights beside it. bench_player measures the kernel itself on analytic
//   targets. Medians of repetitions in one run on a shared machine: read them
//   as ratios.
//
// Usage: bench_afm_size [--threads N] [--vertices N ...] [FILE.afm ...]
// With files, only those are measured (no builds, so no error against the
// builder's floats): `afm-build ... -o face.afm` once, then re-measure fast.
#include <afm/draco.h>
#include <afm/format.h>
#include <afm/player.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "afm/afm_export.h"
#include "anatomy/face_model.h"
#include "anatomy/sim_mesh.h"
#include "core/allocator.h"
#include "fap/fap_synthesis.h"
#include "io/load_face.h"
#include "refhead/refhead.h"

#include "chunk_bytes.h"

using namespace afmb;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

[[noreturn]] void die(const std::string &what) {
  std::fprintf(stderr, "bench_afm_size: %s\n", what.c_str());
  std::exit(1);
}

// A model to measure: its raw-profile AFM and, when built here, the
// builder's targets on the AFM's render vertices (per target, 3V model
// units, x y z per vertex).
struct Input {
  std::string name;
  std::vector<uint8_t> raw;
  std::vector<std::vector<double>> exact;
};

// encode_afm's own vertex order and seam split, so entry r of a target is
// what the AFM's vertex r should hold.
std::vector<std::vector<double>> builder_targets(const AfmContent &content) {
  const RenderVertices rv = afm_render_vertices(content);
  const std::vector<MorphTarget> &targets = content.targets;
  std::vector<std::vector<double>> out(targets.size(), std::vector<double>(3 * rv.count, 0.0));
  for (size_t t = 0; t < targets.size(); ++t)
    for (size_t p = 0; p < targets[t].displacement.size(); ++p) {
      const Eigen::MatrixXd &D = targets[t].displacement[p];
      for (Eigen::Index w = 0; w < D.rows(); ++w)
        for (uint32_t r : rv.copies[p][static_cast<size_t>(w)])
          for (int k = 0; k < 3; ++k) out[t][3 * r + static_cast<size_t>(k)] = D(w, k);
    }
  return out;
}

void progress(const char *stage, int done, int total, const std::string &what) {
  std::fprintf(stderr, "\r  %s [%3d/%3d] %-40.40s", stage, done, total, what.c_str());
  if (done == total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

Input build(const std::string &name, const Scene &scene, const FdpSet &fdps, int threads) {
  std::printf("-- %s: building the model and its targets (progress on stderr)\n", name.c_str());
  std::fflush(stdout);
  const Clock::time_point t0 = Clock::now();
  FaceModelOptions fo;
  fo.threads = threads;
  fo.progress = [](int d, int n, const std::string &w) { progress("model  ", d, n, w); };
  // As afm-build makes it: on the simulation mesh, targets carried to the skin.
  Expected<SimFaceModel> model = build_sim_face_model(scene, fdps, SimMeshOptions{kDefaultSimVertices}, fo);
  if (!model) die(name + ": " + model.status().message());
  const double t_model = since(t0);
  FapSynthesisOptions so;
  so.threads = threads;
  so.sim = &model->sim;
  so.progress = [](int d, int n, const std::string &w) { progress("targets", d, n, w); };
  Expected<FapSynthesis> syn = synthesize_faps(model->scene, model->model, so);
  if (!syn) die(name + ": " + syn.status().message());
  AfmContent content = fap_afm_content(scene, fdps, model->model, std::move(*syn));
  Expected<std::vector<uint8_t>> raw = encode_afm(content, AFM_PROFILE_RAW);
  if (!raw) die(name + ": " + raw.status().message());
  const double t_all = since(t0);
  std::printf("   built in %.1f s (model %.1f s on %zu simulation vertices, targets and AFM %.1f s)\n", t_all,
              t_model, static_cast<size_t>(model->sim.V.rows()), t_all - t_model);
  return {name, std::move(*raw), builder_targets(content)};
}

std::vector<uint8_t> transcode(const std::vector<uint8_t> &bytes, afm_profile profile) {
  uint8_t *out = nullptr;
  size_t size = 0;
  afm_diag diag{};
  if (afm_transcode(bytes.data(), bytes.size(), profile, afm_draco_codec(), nullptr, &out, &size, &diag) != AFM_OK)
    die(std::string("transcode: ") + diag.message);
  std::vector<uint8_t> v(out, out + size);
  afm_free(nullptr, out);
  return v;
}

afm_doc *read_doc(const std::vector<uint8_t> &bytes) {
  afm_read_options ro{};
  ro.draco = afm_draco_codec();
  afm_doc *doc = nullptr;
  if (afm_doc_read_alloc(bytes.data(), bytes.size(), &ro, nullptr, &doc) != AFM_OK) die("AFM read failed");
  return doc;
}

// Components a target stores per vertex: positions, and normals when it has them.
int components(const afm_target &t) { return t.nx ? 6 : 3; }

// Every target dense over all vertices as the AFM defines it (control
// points lifted), in Q15 quanta: x y z per vertex.
std::vector<std::vector<int32_t>> dense_q15(const afm_doc &doc) {
  const size_t V = doc.geometry.vertex_count;
  std::vector<std::vector<int32_t>> out(doc.target_count);
  std::vector<int32_t> all(3 * static_cast<size_t>(afm_doc_entry_count(&doc)));
  for (uint32_t t = 0; t < doc.target_count; ++t) {
    if (afm_target_expand(&doc, &doc.targets[t], all.data()) != AFM_OK) die("afm_target_expand");
    out[t].assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(3 * V));
  }
  return out;
}

// Every target dense over all vertices in whole quanta, as a per-vertex
// quantised store holds it (x y z [nx ny nz] per vertex): the lifted deltas
// rounded, normal deltas as stored.
std::vector<std::vector<int16_t>> dense_quanta(const afm_doc &doc, const std::vector<std::vector<int32_t>> &q15) {
  const size_t V = doc.geometry.vertex_count;
  std::vector<std::vector<int16_t>> out(doc.target_count);
  for (uint32_t t = 0; t < doc.target_count; ++t) {
    const afm_target &tg = doc.targets[t];
    const size_t c = static_cast<size_t>(components(tg));
    out[t].assign(c * V, 0);
    for (size_t v = 0; v < V; ++v)
      for (size_t j = 0; j < 3; ++j)
        out[t][c * v + j] = static_cast<int16_t>(std::lround(q15[t][3 * v + j] / 32768.0));
    if (c == 3) continue;
    const int16_t *src[3] = {tg.nx, tg.ny, tg.nz};
    uint32_t k = 0;
    for (uint32_t r = 0; r < tg.run_count; ++r)
      for (uint32_t i = 0; i < tg.runs[r].length; ++i, ++k)
        for (size_t j = 0; j < 3; ++j) out[t][c * (tg.runs[r].start + i) + 3 + j] = src[j][k];
  }
  return out;
}

// The baseline's byte planes (see the header).
std::vector<uint8_t> baseline_planes(const std::vector<std::vector<int16_t>> &dense, size_t V) {
  std::vector<uint8_t> planes;
  for (const std::vector<int16_t> &d : dense) {
    const size_t c = d.size() / std::max<size_t>(V, 1);
    for (size_t j = 0; j < c; ++j) {
      const size_t at = planes.size();
      planes.resize(at + 2 * V);
      uint16_t prev = 0;
      for (size_t v = 0; v < V; ++v) {
        const uint16_t cur = static_cast<uint16_t>(d[c * v + j]);
        const int16_t delta = static_cast<int16_t>(static_cast<uint16_t>(cur - prev));
        const uint16_t zz = static_cast<uint16_t>((static_cast<uint16_t>(delta) << 1) ^ (delta < 0 ? 0xFFFF : 0));
        planes[at + v] = static_cast<uint8_t>(zz & 0xFF);
        planes[at + V + v] = static_cast<uint8_t>(zz >> 8);
        prev = cur;
      }
    }
  }
  return planes;
}

// The inverse: planes back to dense quanta shaped like `like`.
std::vector<std::vector<int16_t>> baseline_unplane(const std::vector<uint8_t> &planes,
                                                   const std::vector<std::vector<int16_t>> &like, size_t V) {
  std::vector<std::vector<int16_t>> out;
  size_t at = 0;
  for (const std::vector<int16_t> &d : like) {
    const size_t c = d.size() / std::max<size_t>(V, 1);
    out.emplace_back(d.size());
    for (size_t j = 0; j < c; ++j, at += 2 * V) {
      uint16_t prev = 0;
      for (size_t v = 0; v < V; ++v) {
        const uint16_t zz = static_cast<uint16_t>(planes[at + v] | planes[at + V + v] << 8);
        const uint16_t delta = static_cast<uint16_t>((zz >> 1) ^ (zz & 1 ? 0xFFFF : 0));
        prev = static_cast<uint16_t>(prev + delta);
        out.back()[c * v + j] = static_cast<int16_t>(prev);
      }
    }
  }
  return out;
}

// Baseline size in bytes; dies unless it decodes to `dense` exactly.
size_t baseline_bytes(const std::vector<std::vector<int16_t>> &dense, size_t V) {
  const std::vector<uint8_t> planes = baseline_planes(dense, V);
  uLongf size = compressBound(planes.size());
  std::vector<uint8_t> z(size);
  if (compress2(z.data(), &size, planes.data(), planes.size(), Z_BEST_COMPRESSION) != Z_OK) die("zlib compress");
  std::vector<uint8_t> back(planes.size());
  uLongf back_size = back.size();
  if (uncompress(back.data(), &back_size, z.data(), size) != Z_OK || back_size != planes.size() ||
      baseline_unplane(back, dense, V) != dense)
    die("the baseline does not decode to the AFM's quanta");
  return size;
}

// Positions of every target dense in model units (x y z per vertex): what
// a dense float32 store of the AFM's targets would hold.
std::vector<std::vector<float>> dense_floats(const afm_doc &doc, const std::vector<std::vector<int32_t>> &q15) {
  std::vector<std::vector<float>> out(q15.size());
  for (size_t t = 0; t < q15.size(); ++t)
    for (int32_t q : q15[t]) out[t].push_back(static_cast<float>(q / 32768.0 * double(doc.geometry.step)));
  return out;
}

// The same from whole quanta (the baseline's values).
std::vector<std::vector<float>> quanta_floats(const afm_doc &doc, const std::vector<std::vector<int16_t>> &dense) {
  const size_t V = doc.geometry.vertex_count;
  std::vector<std::vector<float>> out(dense.size(), std::vector<float>(3 * V));
  for (size_t t = 0; t < dense.size(); ++t) {
    const size_t c = static_cast<size_t>(components(doc.targets[t]));
    for (size_t v = 0; v < V; ++v)
      for (size_t k = 0; k < 3; ++k) out[t][3 * v + k] = dense[t][c * v + k] * doc.geometry.step;
  }
  return out;
}

// Largest |decoded - builder's double| over every target and component, in
// quanta; -1 without the builder's targets.
double max_error_quanta(const afm_doc &doc, const std::vector<std::vector<float>> &decoded,
                        const std::vector<std::vector<double>> &exact) {
  if (exact.empty()) return -1;
  double worst = 0;
  for (size_t t = 0; t < decoded.size(); ++t) {
    if (t >= exact.size() || exact[t].size() != decoded[t].size()) die("builder targets and AFM differ in shape");
    for (size_t i = 0; i < decoded[t].size(); ++i)
      worst = std::max(worst, std::abs(static_cast<double>(decoded[t][i]) - exact[t][i]));
  }
  return worst / static_cast<double>(doc.geometry.step);
}

// Median over `reps` repetitions of seconds per call of f; each repetition
// calls f for at least 10 ms, so the clock's resolution does not count.
double median_seconds(const std::function<void()> &f, int reps = 15) {
  std::vector<double> per;
  for (int r = 0; r < reps; ++r) {
    int n = 0;
    const Clock::time_point t0 = Clock::now();
    double elapsed = 0;
    do {
      f();
      ++n;
      elapsed = since(t0);
    } while (elapsed < 0.01);
    per.push_back(elapsed / n);
  }
  std::nth_element(per.begin(), per.begin() + reps / 2, per.end());
  return per[static_cast<size_t>(reps / 2)];
}

struct Player {
  std::vector<uint64_t> memory;
  afm_player *p = nullptr;
};

void init_player(const afm_doc &doc, uint32_t flags, Player *pl) {
  afm_player_options o{};
  o.flags = flags;
  size_t need = 0;
  if (afm_player_measure(&doc, &o, &need) != AFM_OK) die("player measure");
  pl->memory.resize(need / 8 + 1);
  if (afm_player_init(&doc, &o, pl->memory.data(), need, &pl->p) != AFM_OK) die("player init");
}

// What an application does at start: the file's bytes to a ready player.
void load_into_player(const std::vector<uint8_t> &bytes) {
  afm_doc *doc = read_doc(bytes);
  Player pl;
  init_player(*doc, 0, &pl);
  afm_free(nullptr, doc);
}

// A cycle of 42 states that between them blend every target: each sets every
// FAP that has a target to half that target's reference (on odd frames the
// negative side's, where the FAP has one), a pair of visemes half and half
// and a pair of expressions at half intensity, stepping through all 14
// visemes and 6 expressions.
std::vector<afm_fap_state> all_target_states(const afm_doc &doc) {
  int32_t pos[AFM_FAP_COUNT + 1] = {}, neg[AFM_FAP_COUNT + 1] = {};
  for (uint32_t t = 0; t < doc.target_count; ++t)
    if (doc.targets[t].kind == AFM_TARGET_FAP)
      (doc.targets[t].reference > 0 ? pos : neg)[doc.targets[t].number] = doc.targets[t].reference;
  std::vector<afm_fap_state> states(42);
  for (size_t f = 0; f < states.size(); ++f) {
    afm_fap_state &s = states[f];
    afm_fap_state_reset(&s);
    for (int fap = 3; fap <= AFM_FAP_COUNT; ++fap)
      s.value[fap] = ((f % 2 && neg[fap]) || !pos[fap] ? neg[fap] : pos[fap]) / 2;
    s.viseme.select1 = static_cast<uint8_t>(2 * (f % 7) + 1);
    s.viseme.select2 = static_cast<uint8_t>(2 * (f % 7) + 2);
    s.viseme.blend = 32;
    s.expression.select1 = static_cast<uint8_t>(2 * (f % 3) + 1);
    s.expression.select2 = static_cast<uint8_t>(2 * (f % 3) + 2);
    s.expression.intensity1 = s.expression.intensity2 = 32;
  }
  return states;
}

void measure(const Input &in) {
  const std::vector<uint8_t> raw = transcode(in.raw, AFM_PROFILE_RAW);
  const std::vector<uint8_t> draco = transcode(in.raw, AFM_PROFILE_DRACO);
  afm_doc *doc = read_doc(raw);
  const size_t V = doc->geometry.vertex_count, T = doc->target_count;
  if (!T) die(in.name + ": no morph targets");
  const std::vector<std::vector<int32_t>> q15 = dense_q15(*doc);
  // The baseline's quanta: the builder's own targets rounded per vertex when
  // built here (the same half-quantum error as the AFM's), else the AFM's.
  size_t with_normals = 0;
  for (size_t t = 0; t < T; ++t) with_normals += components(doc->targets[t]) == 6;
  std::vector<std::vector<int16_t>> dense = dense_quanta(*doc, q15);
  if (in.exact.size() == T && !with_normals)
    for (size_t t = 0; t < T; ++t)
      for (size_t i = 0; i < 3 * V; ++i)
        dense[t][i] = static_cast<int16_t>(std::lround(in.exact[t][i] / double(doc->geometry.step)));
  const size_t dense_bytes = (T + with_normals) * V * 3 * 4;
  const size_t base_bytes = baseline_bytes(dense, V);
  const std::vector<std::vector<float>> dense_f = dense_floats(*doc, q15);
  const double err = max_error_quanta(*doc, dense_f, in.exact);
  const double base_err = max_error_quanta(*doc, quanta_floats(*doc, dense), in.exact);

  const std::string units = *doc->meta.units ? std::string(" ") + doc->meta.units : " model units";
  std::printf("-- %s: %zu targets, %zu vertices, grid step %.3g%s; ", in.name.c_str(), T, V,
              static_cast<double>(doc->geometry.step), units.c_str());
  if (with_normals) std::printf("%zu targets store normal deltas (dense float counts them)\n", with_normals);
  else std::printf("no normal deltas stored (dense float counts positions only)\n");
  if (doc->lift)
    std::printf("   control points (LIFT): %u controls drive %u vertices; the targets move the controls\n",
                doc->lift->control_count, doc->lift->bound_count);
  std::printf("   %-16s %11s %11s %13s %11s %16s\n", "", "targets B", "file B", "dense/targets", "dense/file",
              "baseline/targets");
  for (int d = 0; d < 2; ++d) {
    const std::vector<uint8_t> &f = d ? draco : raw;
    // What the targets take: MTGT, and LIFT when there is one.
    const size_t m = chunk_bytes(f, AFM_CHUNK_MTGT) + chunk_bytes(f, AFM_CHUNK_LIFT);
    std::printf("   %-16s %11zu %11zu %12.1fx %10.1fx %15.2fx\n", d ? "AFM draco" : "AFM raw", m, f.size(),
                double(dense_bytes) / double(m), double(dense_bytes) / double(f.size()),
                double(base_bytes) / double(m));
  }
  std::printf("   %-16s %11zu\n   %-16s %11zu\n", "dense float32", dense_bytes, "baseline (zlib)", base_bytes);
  if (err >= 0)
    std::printf("   max error against the builder's float targets: AFM %.3f quanta (%.3g%s), baseline %.3f quanta "
                "(the builder's targets rounded to whole quanta per vertex)\n",
                err, err * static_cast<double>(doc->geometry.step), units.c_str(), base_err);
  else
    std::printf("   max error against the builder's float targets: not known (a file, not built here); the baseline "
                "holds the AFM's deltas rounded to whole quanta per vertex\n");

  const double load_raw = median_seconds([&] { load_into_player(raw); });
  const double load_draco = median_seconds([&] { load_into_player(draco); });
  std::printf("   read + player init from memory: raw %.2f ms, draco %.2f ms (draco/raw %.1fx)\n", load_raw * 1e3,
              load_draco * 1e3, load_draco / load_raw);

  // Poses: the fixed-point player with normals recomputed (its default) and
  // positions only; the dense float32 blend of the same weights.
  const std::vector<afm_fap_state> states = all_target_states(*doc);
  Player pl, pl_pos;
  init_player(*doc, 0, &pl);
  init_player(*doc, AFM_PLAYER_NO_NORMALS, &pl_pos);
  std::vector<std::vector<float>> weights(states.size(), std::vector<float>(T));
  std::vector<bool> used(T);
  double updates = 0, active = 0;
  for (size_t f = 0; f < states.size(); ++f) {
    afm_player_pose(pl.p, &states[f], nullptr, 0);
    updates += afm_player_info(pl.p)->updates;
    active += afm_player_info(pl.p)->active_targets;
    for (size_t t = 0; t < T; ++t) {
      weights[f][t] = static_cast<float>(afm_player_weights(pl.p)[t]) / 4096.0f;
      used[t] = used[t] || weights[f][t] != 0;
    }
  }
  size_t frame = 0;
  const double pose_full = median_seconds([&] {
    afm_player_pose(pl.p, &states[frame++ % states.size()], nullptr, 0);
  });
  const double pose_pos = median_seconds([&] {
    afm_player_pose(pl_pos.p, &states[frame++ % states.size()], nullptr, 0);
  });
  std::vector<float> out(3 * V);
  const double pose_dense = median_seconds([&] {
    const std::vector<float> &w = weights[frame++ % states.size()];
    std::fill(out.begin(), out.end(), 0.0f);
    for (size_t t = 0; t < T; ++t) {
      if (w[t] == 0) continue;
      const float *d = dense_f[t].data();
      for (size_t i = 0; i < 3 * V; ++i) out[i] += w[t] * d[i];
    }
  });
  volatile float sink = out[0];
  (void)sink;
  std::printf("   pose per frame over %zu states blending %zu of %zu targets (%.0f active, %.0f vertex-target "
              "updates per frame): fixed point %.1f us with normals recomputed, %.1f us positions only; dense "
              "float32 blend of the same weights %.1f us (%.1fx positions only)\n",
              states.size(), static_cast<size_t>(std::count(used.begin(), used.end(), true)), T,
              active / double(states.size()), updates / double(states.size()), pose_full * 1e6, pose_pos * 1e6,
              pose_dense * 1e6, pose_dense / pose_pos);
  std::fflush(stdout);
  afm_free(nullptr, doc);
}

}  // namespace

int main(int argc, char **argv) {
  keep_freed_memory();  // as afm-build does
  int threads = 0;
  std::vector<int> sizes;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (a == "--vertices" && i + 1 < argc)
      sizes.push_back(std::atoi(argv[++i]));
    else if (!a.empty() && a[0] != '-')
      files.push_back(a);
    else
      die("usage: bench_afm_size [--threads N] [--vertices N ...] [FILE.afm ...]");
  }
  std::printf("AFM size at equal error and decode time, real anatomical targets (bench/bench_afm_size.cpp)\n"
              "  dense float32: targets x vertices x 3 x 4 bytes, every AFM vertex\n"
              "  baseline (meshopt-style, at the AFM's error): the AFM's quanta, dense per target in its vertex\n"
              "    order; per component int16 delta from the previous vertex, zigzag, low and high byte planes;\n"
              "    all targets in one zlib stream, level 9\n"
              "  times: medians of 15 repetitions, one run on a shared machine: read them as ratios\n");
  for (const std::string &f : files) {
    std::vector<uint8_t> bytes;
    uint8_t *data = nullptr;
    size_t size = 0;
    if (afm_file_read(f.c_str(), nullptr, &data, &size) != AFM_OK) die(f + ": cannot read");
    bytes.assign(data, data + size);
    afm_free(nullptr, data);
    measure({std::filesystem::path(f).filename().string(), transcode(bytes, AFM_PROFILE_RAW), {}});
  }
  if (!files.empty()) return 0;

  if (sizes.empty()) sizes.push_back(2000);
  for (int n : sizes) {
    RefHeadOptions o;
    o.skin_vertices = n;
    Expected<RefHead> h = make_reference_head(o);
    if (!h) die(h.status().message());
    measure(build("reference head, " + std::to_string(n) + " skin vertices", h->scene, h->fdps, threads));
  }
  if (std::find(sizes.begin(), sizes.end(), 10000) == sizes.end())
    std::printf("(the 10k reference head is left out to keep make bench short; --vertices 10000 adds it)\n");

  const char *shared = std::getenv("AFM_SHARED_DIR");
  const std::filesystem::path dir =
      std::filesystem::path(shared ? shared : AFM_SOURCE_DIR "/../shared") / "data/faces/song";
  if (!std::filesystem::exists(dir / "song.WRL")) {
    std::printf("-- Song head: skipped (%s is absent)\n", dir.string().c_str());
    return 0;
  }
  LoadOptions lo;
  lo.flip_v = true;
  Expected<LoadedFace> song = load_face((dir / "song.WRL").string(), (dir / "song.fdp").string(), lo, nullptr);
  if (!song) die("Song head: " + song.status().message());
  measure(build("Song head", song->scene, song->fdps, threads));
  return 0;
}
