// The player's blend kernel and frame time, fixed point against a float
// implementation of the same algorithm over the same data, in one run.
//
// Model: the reference head at 10k skin vertices with analytic targets
// (afm-import --analytic); 20 FAPs active, each swinging within its
// reference value frame to frame, as speech plus expression does.
#include <afm/format.h>
#include <afm/player.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "../player_c/src/player_internal.h"  // the kernel stage, timed on its own
#include "afm/analytic_targets.h"

using Clock = std::chrono::steady_clock;

namespace {

const int kFaps[] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 16, 17, 18, 31, 32, 33, 34, 53, 54};
const int kFrames = 400;

std::vector<afm_fap_state> make_states(const afm_doc &doc, bool head) {
  std::vector<afm_fap_state> states(kFrames);
  for (int f = 0; f < kFrames; ++f) {
    afm_fap_state &s = states[size_t(f)];
    afm_fap_state_reset(&s);
    for (size_t i = 0; i < sizeof kFaps / sizeof kFaps[0]; ++i) {
      int32_t ref = 256;
      for (uint32_t t = 0; t < doc.target_count; ++t)
        if (doc.targets[t].kind == AFM_TARGET_FAP && doc.targets[t].number == kFaps[i])
          ref = std::abs(doc.targets[t].reference);
      s.value[kFaps[i]] = int32_t(std::lround(ref * (0.6 + 0.4 * std::sin(0.13 * f + i))));
    }
    if (head)
      for (int h : {48, 49, 50}) s.value[h] = int32_t(std::lround(15000 * std::sin(0.05 * f + h)));
  }
  return states;
}

struct Timing {
  double seconds_per_frame;
  double updates_per_frame;
};

// A player with `flags` in its own buffer.
struct Player {
  std::vector<uint64_t> memory;
  afm_player *p = nullptr;
  Player(const afm_doc &doc, uint32_t flags) {
    afm_player_options o{};
    o.flags = flags;
    size_t need = 0;
    afm_player_measure(&doc, &o, &need);
    memory.resize(need / 8 + 1);
    if (afm_player_init(&doc, &o, memory.data(), need, &p) != AFM_OK) std::exit(1);
  }
};

// Whole poses: `pose(state)` for every state, over and over for at least a
// second; `pose` returns the vertex-target updates it made.
template <class Pose>
Timing time_poses(const std::vector<afm_fap_state> &states, Pose pose) {
  double updates = 0;
  int n = 0;
  auto t0 = Clock::now();
  double elapsed = 0;
  do {
    for (const afm_fap_state &s : states) {
      updates += pose(s);
      ++n;
    }
    elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
  } while (elapsed < 1.0);
  return {elapsed / n, updates / n};
}

Timing time_fixed(const afm_doc &doc, uint32_t flags, const std::vector<afm_fap_state> &states) {
  Player player(doc, flags);
  afm_player *p = player.p;
  return time_poses(states, [p](const afm_fap_state &s) {
    afm_player_pose(p, &s, nullptr, 0);
    return double(afm_player_info(p)->updates);
  });
}

// The float side: every positive FAP target's deltas in model units (planar
// x[], y[], z[]), and w * delta added over a target's runs.
struct FloatModel {
  std::vector<std::vector<float>> d;  // per target
  std::vector<int> target_of;         // FAP -> target, or -1

  explicit FloatModel(const afm_doc &doc) : d(doc.target_count), target_of(AFM_FAP_COUNT + 1, -1) {
    for (uint32_t t = 0; t < doc.target_count; ++t) {
      const afm_target &tg = doc.targets[t];
      d[t].resize(3 * size_t(tg.delta_count));
      for (uint32_t k = 0; k < tg.delta_count; ++k) {
        d[t][k] = tg.dx[k] * doc.geometry.step;
        d[t][tg.delta_count + k] = tg.dy[k] * doc.geometry.step;
        d[t][2 * size_t(tg.delta_count) + k] = tg.dz[k] * doc.geometry.step;
      }
      if (tg.kind == AFM_TARGET_FAP && tg.reference > 0) target_of[tg.number] = int(t);
    }
  }

  void blend(const afm_target &tg, int t, float w, float *ax, float *ay, float *az) const {
    const float *dx = d[size_t(t)].data(), *dy = dx + tg.delta_count, *dz = dy + tg.delta_count;
    uint32_t k = 0;
    for (uint32_t r = 0; r < tg.run_count; ++r) {
      const uint32_t st = tg.runs[r].start, len = tg.runs[r].length;
      float *a = ax + st, *b = ay + st, *c = az + st;
      for (uint32_t i = 0; i < len; ++i) a[i] += w * dx[k + i];
      for (uint32_t i = 0; i < len; ++i) b[i] += w * dy[k + i];
      for (uint32_t i = 0; i < len; ++i) c[i] += w * dz[k + i];
      k += len;
    }
  }
};

// The blend stage alone (afm_blend_targets: every active target's runs
// multiply-added into the accumulators, and the moved spans found), on the
// weights a pose of each state set up. Accumulators are reset between
// repetitions outside the timed region.
Timing time_fixed_kernel(const afm_doc &doc, const std::vector<afm_fap_state> &states) {
  Player player(doc, AFM_PLAYER_NO_NORMALS);
  afm_player *p = player.p;
  double seconds = 0, updates = 0;
  int n = 0;
  while (seconds < 1.0) {
    for (const afm_fap_state &s : states) {
      afm_player_pose(p, &s, nullptr, 0);  // sets weights; its own blend is not timed
      afm_blend_restore(p);
      auto t0 = Clock::now();
      afm_blend_targets(p, kWeightBits);
      seconds += std::chrono::duration<double>(Clock::now() - t0).count();
      updates += afm_player_info(p)->updates;
      ++n;
    }
  }
  return {seconds / n, updates / n};
}

// The same multiply-adds in float over the same runs (deltas in model units).
Timing time_float_kernel(const afm_doc &doc, const std::vector<afm_fap_state> &states) {
  const size_t V = doc.geometry.vertex_count;
  const FloatModel m(doc);
  std::vector<float> acc(3 * V, 0.0f);
  double seconds = 0, updates = 0;
  int n = 0;
  while (seconds < 1.0) {
    for (const afm_fap_state &s : states) {
      auto t0 = Clock::now();
      for (int f = 3; f <= AFM_FAP_COUNT; ++f) {
        int t = m.target_of[size_t(f)];
        if (!s.value[f] || t < 0) continue;
        const afm_target &tg = doc.targets[t];
        m.blend(tg, t, float(s.value[f]) / float(tg.reference), &acc[0], &acc[V], &acc[2 * V]);
        updates += tg.delta_count;
      }
      seconds += std::chrono::duration<double>(Clock::now() - t0).count();
      ++n;
    }
  }
  volatile float sink = acc[0];
  (void)sink;
  return {seconds / n, updates / n};
}

// The same algorithm in float: weights value / reference, the same runs,
// deltas converted to model units once, accumulators initialised on first
// touch, output interleaved.
Timing time_float(const afm_doc &doc, const std::vector<afm_fap_state> &states) {
  const afm_geometry &g = doc.geometry;
  const size_t V = g.vertex_count;
  const FloatModel m(doc);
  std::vector<float> base(3 * V), ax(V), ay(V), az(V), out(3 * V);
  for (size_t v = 0; v < V; ++v) {
    base[3 * v] = g.origin[0] + g.px[v] * g.step;
    base[3 * v + 1] = g.origin[1] + g.py[v] * g.step;
    base[3 * v + 2] = g.origin[2] + g.pz[v] * g.step;
  }
  out = base;
  std::vector<uint32_t> touched, stamp(V, 0);
  uint32_t frame = 0;
  Timing timing = time_poses(states, [&](const afm_fap_state &s) {
    double updates = 0;
    ++frame;
    for (uint32_t v : touched) std::copy(&base[3 * v], &base[3 * v + 3], &out[3 * v]);
    touched.clear();
    for (int f = 3; f <= AFM_FAP_COUNT; ++f) {
      int t = m.target_of[size_t(f)];
      if (!s.value[f] || t < 0) continue;
      const afm_target &tg = doc.targets[t];
      for (uint32_t r = 0; r < tg.run_count; ++r)
        for (uint32_t v = tg.runs[r].start; v < tg.runs[r].start + tg.runs[r].length; ++v)
          if (stamp[v] != frame) {
            stamp[v] = frame;
            touched.push_back(v);
            ax[v] = base[3 * v], ay[v] = base[3 * v + 1], az[v] = base[3 * v + 2];
          }
      m.blend(tg, t, float(s.value[f]) / float(tg.reference), ax.data(), ay.data(), az.data());
      updates += tg.delta_count;
    }
    for (uint32_t v : touched) out[3 * v] = ax[v], out[3 * v + 1] = ay[v], out[3 * v + 2] = az[v];
    return updates;
  });
  volatile float sink = out[0];
  (void)sink;
  return timing;
}

// The reference head with analytic targets, decoded (normal deltas stored
// when asked).
afm_doc *make_model(bool normal_deltas, size_t *doc_bytes) {
  afmb::AnalyticOptions ao;
  ao.normal_deltas = normal_deltas;
  afmb::Expected<std::vector<uint8_t>> bytes = afmb::analytic_reference_afm(10000, ao);
  if (!bytes) std::exit(1);
  afm_doc *doc = nullptr;
  afm_doc_measure(bytes->data(), bytes->size(), nullptr, doc_bytes);
  if (afm_doc_read_alloc(bytes->data(), bytes->size(), nullptr, nullptr, &doc) != AFM_OK) std::exit(1);
  return doc;
}

}  // namespace

int main() {
  size_t doc_bytes = 0, doc_bytes_nd = 0;
  afm_doc *doc = make_model(false, &doc_bytes);
  afm_doc *doc_nd = make_model(true, &doc_bytes_nd);

  // Bytes per stored nonzero delta: the MTGT chunk over the deltas that move.
  size_t nonzero = 0, mtgt = 0;
  for (uint32_t t = 0; t < doc->target_count; ++t)
    for (uint32_t k = 0; k < doc->targets[t].delta_count; ++k)
      nonzero += doc->targets[t].dx[k] || doc->targets[t].dy[k] || doc->targets[t].dz[k];
  afm_targets_encoded_size(doc->targets, doc->target_count, &mtgt);

  std::vector<afm_fap_state> morph = make_states(*doc, false), with_head = make_states(*doc, true);
  Timing kernel = time_fixed_kernel(*doc, morph);
  Timing kernel_float = time_float_kernel(*doc, morph);
  Timing fixed = time_fixed(*doc, AFM_PLAYER_NO_NORMALS, morph);
  Timing flt = time_float(*doc, morph);
  Timing full = time_fixed(*doc, 0, morph);
  Timing deltas = time_fixed(*doc_nd, AFM_PLAYER_NORMAL_DELTAS, make_states(*doc_nd, false));
  Timing head_vertices = time_fixed(*doc, 0, with_head);
  Timing head_matrix = time_fixed(*doc, AFM_PLAYER_HEAD_MATRIX, with_head);
  size_t player_bytes = 0;
  afm_player_measure(doc, nullptr, &player_bytes);

  std::printf("player: reference head, %u vertices, %u targets; 20 FAPs active, %.0f vertex-target "
              "updates per frame\n",
              doc->geometry.vertex_count, doc->target_count, fixed.updates_per_frame);
  uint32_t runs = 0;
  for (uint32_t t = 0; t < doc->target_count; ++t) runs += doc->targets[t].run_count;
  std::printf("  blend kernel: fixed %.2f G updates/s, float %.2f G updates/s: fixed/float speed %.2f "
              "(goals: >= 1 G/s, >= 1.0); %.0f vertices per run on average\n",
              kernel.updates_per_frame / kernel.seconds_per_frame * 1e-9,
              kernel_float.updates_per_frame / kernel_float.seconds_per_frame * 1e-9,
              kernel_float.seconds_per_frame / kernel.seconds_per_frame,
              double(nonzero) / runs);
  std::printf("  whole pose, positions only: fixed %.2f G updates/s, float %.2f G updates/s: fixed/float "
              "speed %.2f (restoring, rounding and the jaw's rigid turn included)\n",
              fixed.updates_per_frame / fixed.seconds_per_frame * 1e-9,
              flt.updates_per_frame / flt.seconds_per_frame * 1e-9,
              flt.seconds_per_frame / fixed.seconds_per_frame);
  std::printf("  us per frame: positions only %.1f; normals recomputed %.1f; normal deltas blended %.1f "
              "(recompute / deltas: %.1f times the time; the AFM with normal deltas is %zu bytes "
              "decoded against %zu)\n",
              fixed.seconds_per_frame * 1e6, full.seconds_per_frame * 1e6, deltas.seconds_per_frame * 1e6,
              full.seconds_per_frame / deltas.seconds_per_frame, doc_bytes_nd, doc_bytes);
  std::printf("  us per frame with head rotation: per vertex %.1f, as a matrix for the renderer %.1f\n",
              head_vertices.seconds_per_frame * 1e6, head_matrix.seconds_per_frame * 1e6);
  std::printf("  bytes per stored nonzero delta: %.2f (MTGT %zu bytes, %zu nonzero deltas; goal <= 8)\n",
              double(mtgt) / double(nonzero), mtgt, nonzero);
  std::printf("  memory: decoded AFM %zu bytes, player %zu bytes\n", doc_bytes, player_bytes);
  afm_free(nullptr, doc);
  afm_free(nullptr, doc_nd);
  return 0;
}
