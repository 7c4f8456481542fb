// The player core against its double-precision model, MPEG-4 semantics,
// determinism, and the no-allocation-per-frame promise.
#include <afm/draco.h>
#include <afm/format.h>
#include <afm/mpeg4.h>
#include <afm/player.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>

#include "../common/synthetic_doc.h"
#include "afm/analytic_targets.h"
#include "reference_player.h"

// ---- a counting malloc -------------------------------------------------------------
// The test binary interposes malloc to count calls made while posing. Under
// AddressSanitizer the runtime owns malloc, so the count is not available.
#if defined(__SANITIZE_ADDRESS__)
#define AFM_COUNT_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define AFM_COUNT_MALLOC 0
#endif
#endif
#ifndef AFM_COUNT_MALLOC
#define AFM_COUNT_MALLOC 1
#endif

#if AFM_COUNT_MALLOC
extern "C" {
void *__libc_malloc(size_t);
void *__libc_calloc(size_t, size_t);
void *__libc_realloc(void *, size_t);
static unsigned long g_allocations = 0;
void *malloc(size_t n) {
  ++g_allocations;
  return __libc_malloc(n);
}
void *calloc(size_t a, size_t b) {
  ++g_allocations;
  return __libc_calloc(a, b);
}
void *realloc(void *p, size_t n) {
  ++g_allocations;
  return __libc_realloc(p, n);
}
}
#endif

namespace {

struct DocFree {
  void operator()(afm_doc *d) const { afm_free(nullptr, d); }
};

// The reference head with analytic targets, as an AFM document.
struct Model {
  std::unique_ptr<afm_doc, DocFree> doc;
  std::vector<uint64_t> player_memory;
  afm_player *player = nullptr;
  double diagonal_quanta = 0;  // bounding-box diagonal of the neutral mesh

  explicit Model(int skin_vertices, uint32_t player_flags = 0, bool normal_deltas = false) {
    afmb::AnalyticOptions ao;
    ao.normal_deltas = normal_deltas;
    afmb::Expected<std::vector<uint8_t>> bytes = afmb::analytic_reference_afm(skin_vertices, ao);
    EXPECT_TRUE(bytes.is_ok()) << bytes.status().message();
    afm_doc *d = nullptr;
    afm_read_options opt{};
    EXPECT_EQ(afm_doc_read_alloc(bytes->data(), bytes->size(), &opt, nullptr, &d), AFM_OK);
    doc.reset(d);
    init_player(player_flags);
    int16_t lo[3] = {32767, 32767, 32767}, hi[3] = {-32767, -32767, -32767};
    const afm_geometry &g = doc->geometry;
    for (uint32_t v = 0; v < g.vertex_count; ++v) {
      const int16_t p[3] = {g.px[v], g.py[v], g.pz[v]};
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    }
    for (int k = 0; k < 3; ++k) diagonal_quanta += double(hi[k] - lo[k]) * (hi[k] - lo[k]);
    diagonal_quanta = std::sqrt(diagonal_quanta);
  }

  void init_player(uint32_t flags) {
    afm_player_options po{};
    po.flags = flags;
    size_t need = 0;
    ASSERT_EQ(afm_player_measure(doc.get(), &po, &need), AFM_OK);
    // Garbage, not zeros: init must not rely on a cleared buffer.
    player_memory.assign(need / 8 + 1, 0xA5A5A5A5A5A5A5A5ull);
    ASSERT_EQ(afm_player_init(doc.get(), &po, player_memory.data(), need, &player), AFM_OK);
  }

  int target(int kind, int number, bool positive = true) const {
    for (uint32_t i = 0; i < doc->target_count; ++i)
      if (doc->targets[i].kind == kind && doc->targets[i].number == number &&
          (doc->targets[i].reference > 0) == positive)
        return int(i);
    return -1;
  }

  uint32_t fdp_vertex(int group, int index) const {
    for (uint32_t i = 0; i < doc->meta.fdp_count; ++i)
      if (doc->meta.fdps[i].group == group && doc->meta.fdps[i].index == index) return doc->meta.fdps[i].vertex;
    return AFM_NONE;
  }

  const int32_t *pos(uint32_t v) const { return afm_player_positions(player) + 3 * size_t(v); }
};

Model &head2k() {
  static Model m(2000);
  return m;
}

afm_fap_state state(std::initializer_list<std::pair<int, int32_t>> values) {
  afm_fap_state s;
  afm_fap_state_reset(&s);
  for (auto [f, v] : values) s.value[f] = v;
  return s;
}

// A random but plausible state: a dozen FAPs within twice their reference,
// a viseme blend and an expression, eye and head rotations.
afm_fap_state random_state(const Model &m, std::mt19937 &rng) {
  afm_fap_state s;
  afm_fap_state_reset(&s);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < 12; ++n) {
    const afm_target &t = m.doc->targets[rng() % m.doc->target_count];
    if (t.kind != AFM_TARGET_FAP) continue;
    s.value[t.number] = int32_t(std::lround(u(rng) * 2 * std::abs(t.reference)));
  }
  s.value[3] = int32_t(std::lround((u(rng) + 1) * 600));
  s.viseme = {uint8_t(1 + rng() % 14), uint8_t(1 + rng() % 14), uint8_t(rng() % 64), 0};
  s.expression = {uint8_t(1 + rng() % 6), uint8_t(rng() % 64), uint8_t(rng() % 7), uint8_t(rng() % 64), 0, 0};
  for (int f : {23, 24, 25, 26}) s.value[f] = int32_t(std::lround(u(rng) * 52360));  // +-30 degrees
  for (int f : {48, 49, 50}) s.value[f] = int32_t(std::lround(u(rng) * 34907));      // +-20 degrees
  return s;
}

double angle_between(const afm_q14 *n, const std::array<double, 3> &r) {
  double a[3] = {n[0] / 16384.0, n[1] / 16384.0, n[2] / 16384.0};
  double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  double lr = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  double c = (a[0] * r[0] + a[1] * r[1] + a[2] * r[2]) / (la * lr);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

uint64_t fnv1a(uint64_t h, const void *data, size_t n) {
  const uint8_t *p = static_cast<const uint8_t *>(data);
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// The largest |position delta| component of a target, in quanta.
int32_t largest_delta(const afm_target &tg) {
  int32_t md = 0;
  for (uint32_t k = 0; k < tg.delta_count; ++k)
    md = std::max({md, std::abs(int32_t(tg.dx[k])), std::abs(int32_t(tg.dy[k])), std::abs(int32_t(tg.dz[k]))});
  return md;
}

// The weights' part of a pose's error budget, in quanta: `weight_error` (a
// weight's error, as a fraction of 1) times the largest delta of each target
// the double model gives a weight.
double weight_budget(const afm_doc &doc, const afmtest::ReferencePose &ref, double weight_error) {
  double b = 0;
  for (uint32_t i = 0; i < doc.target_count; ++i)
    if (ref.weights[i] != 0) b += largest_delta(doc.targets[i]) * weight_error;
  return b;
}

// Hash of a pose, serialised little-endian so the value is the same on any host.

uint64_t pose_hash(const afm_player *p, uint32_t vertices) {
  uint64_t h = 1469598103934665603ull;
  const int32_t *x = afm_player_positions(p);
  const afm_q14 *n = afm_player_normals(p);
  for (size_t i = 0; i < 3 * size_t(vertices); ++i) {
    uint8_t b[6] = {uint8_t(x[i]), uint8_t(x[i] >> 8), uint8_t(x[i] >> 16), uint8_t(uint32_t(x[i]) >> 24),
                    uint8_t(n[i]), uint8_t(uint16_t(n[i]) >> 8)};
    h = fnv1a(h, b, 6);
  }
  return h;
}

}  // namespace

// ---- fixed point against double ----------------------------------------------------------
//
// Error budget per vertex, in quanta (the grid step of the AFM):
//   weights: each Q12 weight is within 2^-13 of value / reference, so a
//            target adds at most 2^-13 * max|delta| of error;
//   positions: one rounding to integer quanta: 0.5;
//   rigid motion: sin/cos within 1 LSB of Q14 and three rounded Q14 matrix
//            products: each matrix entry within 4 LSB (2.5e-4), times the
//            distance to the pivot, for each of at most two nested rigids,
//            plus 0.5 per rounding of the moved position.
// The test derives the bound of each vertex from these terms and the data.
TEST(Player, FixedPointMatchesTheDoubleModelWithinTheStatedBound) {
  Model &m = head2k();
  std::mt19937 rng(2024);
  double worst_error = 0, worst_ratio = 0, worst_normal = 0;
  for (int trial = 0; trial < 25; ++trial) {
    afm_fap_state a = random_state(m, rng), b = random_state(m, rng);
    const double t = (rng() % 65537) / 65536.0;
    ASSERT_EQ(afm_player_pose(m.player, &a, &b, afm_q16(std::lround(t * 65536))), AFM_OK);
    afmtest::ReferencePose ref = afmtest::reference_pose(*m.doc, a, b, std::lround(t * 65536) / 65536.0);
    const double morph_budget = 0.5 + weight_budget(*m.doc, ref, 1.0 / 8192);
    // Largest distance from any vertex to any pivot, for the rigid term.
    double reach = 0;
    const afm_geometry &g = m.doc->geometry;
    for (uint32_t r = 0; r < m.doc->rigid_count; ++r)
      for (uint32_t v = 0; v < g.vertex_count; v += 7) {
        double d = std::hypot(g.px[v] - m.doc->rigids[r].pivot[0], g.py[v] - m.doc->rigids[r].pivot[1],
                              g.pz[v] - m.doc->rigids[r].pivot[2]);
        reach = std::max(reach, d + 2 * morph_budget);
      }
    const double bound = morph_budget + 2 * (reach * 4 * 3 / 16384.0 + 1.0);
    const afm_q14 *normals = afm_player_normals(m.player);
    for (uint32_t v = 0; v < g.vertex_count; ++v) {
      const int32_t *p = m.pos(v);
      double e = std::max({std::fabs(p[0] - ref.positions[v][0]), std::fabs(p[1] - ref.positions[v][1]),
                           std::fabs(p[2] - ref.positions[v][2])});
      ASSERT_LE(e, bound) << "trial " << trial << " vertex " << v;
      worst_error = std::max(worst_error, e);
      worst_ratio = std::max(worst_ratio, e / bound);
      worst_normal = std::max(worst_normal, angle_between(normals + 3 * size_t(v), ref.normals[v]));
    }
  }
  // Normals: see RecomputedNormalsBeatBlendedNormalDeltas for the bound.
  EXPECT_LT(worst_normal, 1.5 * M_PI / 180);
  const double step = m.doc->geometry.step;
  std::printf("fixed vs double over 25 random poses: worst position error %.2f quanta = %.1f um = "
              "%.1e of the face's diagonal (%.0f%% of the bound); worst normal error %.3f degrees\n",
              worst_error, worst_error * step * 1e6, worst_error / m.diagonal_quanta, 100 * worst_ratio,
              worst_normal * 180 / M_PI);
  EXPECT_LT(worst_error / m.diagonal_quanta, 1e-4);  // stated in formats/fap.md
}

// Normals: recomputed (the default) against blended normal deltas, both
// measured against the double model's recomputed normals. Bound for the
// default: positions are rounded to half a quantum, and the smallest edges
// of the 2k head are about 60 quanta, so a face can turn by up to
// 0.5/60 rad = 0.5 degree, and a vertex normal (a sum of a few faces) by up
// to about 1 degree; max 1.5 degrees, mean 0.05. The comparison is printed.
TEST(Player, RecomputedNormalsBeatBlendedNormalDeltas) {
  static Model with_deltas(2000, 0, true);
  Model deltas_model(2000, AFM_PLAYER_NORMAL_DELTAS, true);
  std::mt19937 rng(99);
  double worst[2] = {0, 0}, mean[2] = {0, 0};
  size_t count = 0;
  for (int trial = 0; trial < 15; ++trial) {
    afm_fap_state s = random_state(with_deltas, rng);
    for (int f : {23, 24, 25, 26, 48, 49, 50}) s.value[f] = 0;  // morphs only
    afmtest::ReferencePose ref = afmtest::reference_pose(*with_deltas.doc, s, s, 0);
    Model *models[2] = {&with_deltas, &deltas_model};
    for (int m = 0; m < 2; ++m) {
      ASSERT_EQ(afm_player_pose(models[m]->player, &s, nullptr, 0), AFM_OK);
      const afm_q14 *n = afm_player_normals(models[m]->player);
      for (uint32_t v = 0; v < with_deltas.doc->geometry.vertex_count; ++v) {
        if (!ref.recomputed[v]) continue;
        double a = angle_between(n + 3 * size_t(v), ref.normals[v]);
        worst[m] = std::max(worst[m], a);
        mean[m] += a;
        if (m == 0) ++count;
      }
    }
  }
  const double deg = 180 / M_PI;
  std::printf("normal error against the double model over %zu moved vertices: recomputed mean %.3f "
              "max %.3f degrees; blended deltas mean %.3f max %.3f degrees\n",
              count, mean[0] / count * deg, worst[0] * deg, mean[1] / count * deg, worst[1] * deg);
  EXPECT_LT(worst[0] * deg, 1.5);
  EXPECT_LT(mean[0] / count * deg, 0.05);
  EXPECT_LT(mean[0], mean[1]);
}

// ---- MPEG-4 semantics ------------------------------------------------------------------------

TEST(Player, WeightIsValueOverReference) {
  Model &m = head2k();
  afm_fap_state s = state({{3, 512}, {12, -128}, {31, -128}, {33, 100}});
  ASSERT_EQ(afm_player_pose(m.player, &s, nullptr, 0), AFM_OK);
  const afm_q12 *w = afm_player_weights(m.player);
  EXPECT_EQ(w[m.target(AFM_TARGET_FAP, 3)], 2048);          // 512 / 1024
  EXPECT_EQ(w[m.target(AFM_TARGET_FAP, 12)], -2048);        // -128 / 256: extrapolated, no negative target
  EXPECT_EQ(w[m.target(AFM_TARGET_FAP, 31, false)], 2048);  // -128 / -256: the negative-side target
  EXPECT_EQ(w[m.target(AFM_TARGET_FAP, 31, true)], 0);
  EXPECT_EQ(w[m.target(AFM_TARGET_FAP, 33)], 1600);         // 100 / 256 = 0.390625
}

TEST(Player, VisemesAndExpressionsBlendBy63rds) {
  Model &m = head2k();
  afm_fap_state s = state({});
  s.viseme = {10, 4, 21, 0};
  s.expression = {1, 63, 6, 21, 1, 0};
  ASSERT_EQ(afm_player_pose(m.player, &s, nullptr, 0), AFM_OK);
  const afm_q12 *w = afm_player_weights(m.player);
  EXPECT_EQ(w[m.target(AFM_TARGET_VISEME, 10)], std::lround(4096 * 21 / 63.0));
  EXPECT_EQ(w[m.target(AFM_TARGET_VISEME, 4)], std::lround(4096 * 42 / 63.0));
  EXPECT_EQ(w[m.target(AFM_TARGET_EXPRESSION, 1)], 4096);
  EXPECT_EQ(w[m.target(AFM_TARGET_EXPRESSION, 6)], std::lround(4096 * 21 / 63.0));
}

// A FAP moves its FDP by value x FAPU along its direction (the analytic
// targets are built so; the player must keep it).
TEST(Player, FapMovesItsFdpAsTheTableSays) {
  Model &m = head2k();
  const afm_meta &meta = m.doc->meta;
  const double step = m.doc->geometry.step;
  struct Case {
    int fap;
    double fapu;
  };
  const Case cases[] = {{3, meta.mns0}, {4, meta.mns0}, {6, meta.mw0}, {19, meta.irisd0}, {31, meta.ens0},
                        {53, meta.mw0}, {61, meta.ens0}};
  for (const Case &c : cases) {
    const afm_fap_info *info = afm_fap(c.fap);
    uint32_t v = m.fdp_vertex(info->fdp_group, info->fdp_index);
    ASSERT_NE(v, AFM_NONE) << c.fap;
    afm_fap_state s = state({{c.fap, 200}});
    ASSERT_EQ(afm_player_pose(m.player, &s, nullptr, 0), AFM_OK);
    const int32_t *p = m.pos(v);
    const afm_geometry &g = m.doc->geometry;
    double moved[3] = {(p[0] - g.px[v]) * step, (p[1] - g.py[v]) * step, (p[2] - g.pz[v]) * step};
    double along = moved[0] * info->direction[0] + moved[1] * info->direction[1] + moved[2] * info->direction[2];
    double expected = 200 * c.fapu / 1024;
    SCOPED_TRACE(std::string("FAP ") + info->name);
    // open_jaw rotates the chin: its path is an arc, the drop is exact.
    EXPECT_NEAR(along, expected, 2 * step);
  }
}

TEST(Player, RigidPartsTurnTheWayMpeg4Says) {
  Model &m = head2k();
  auto moved = [&](int fap, int32_t value, int group, int index) {
    uint32_t v = m.fdp_vertex(group, index);
    EXPECT_NE(v, AFM_NONE);
    afm_fap_state s = state({{fap, value}});
    EXPECT_EQ(afm_player_pose(m.player, &s, nullptr, 0), AFM_OK);
    const afm_geometry &g = m.doc->geometry;
    const int32_t *p = m.pos(v);
    return std::array<int32_t, 3>{p[0] - g.px[v], p[1] - g.py[v], p[2] - g.pz[v]};
  };
  EXPECT_GT(moved(23, 20000, 3, 5)[0], 0);   // yaw_l_eyeball: the left pupil turns to +x (left)
  EXPECT_GT(moved(24, 20000, 3, 6)[0], 0);   // yaw_r_eyeball: also "left"
  EXPECT_LT(moved(25, 20000, 3, 5)[1], 0);   // pitch_l_eyeball: down
  EXPECT_GT(moved(27, 200, 3, 5)[2], 0);     // thrust_l_eyeball: forward
  EXPECT_LT(moved(48, 20000, 9, 3)[1], 0);   // head_pitch: the nose tip goes down
  EXPECT_GT(moved(49, 20000, 9, 3)[0], 0);   // head_yaw: the nose tip turns left
  EXPECT_LT(moved(50, 20000, 11, 4)[0], 0);  // head_roll: the top of the skull tilts right (-x)
  EXPECT_LT(moved(3, 512, 2, 1)[1], 0);      // open_jaw: the chin drops
  EXPECT_LT(moved(15, 200, 2, 1)[0], 0);     // shift_jaw: to the right (-x)
}

// Morph-only FAPs: blended positions are linear in t. (Rigid ones are not:
// their angles interpolate, so points move on arcs.)
TEST(Player, InterpolationHalfwayIsTheAverage) {
  Model &m = head2k();
  afm_fap_state a = state({{12, 100}, {6, -50}}), b = state({{12, -200}, {6, 250}});
  ASSERT_EQ(afm_player_pose(m.player, &a, nullptr, 0), AFM_OK);
  std::vector<int32_t> pa(afm_player_positions(m.player), afm_player_positions(m.player) + 3 * m.doc->geometry.vertex_count);
  ASSERT_EQ(afm_player_pose(m.player, &b, nullptr, 0), AFM_OK);
  std::vector<int32_t> pb(afm_player_positions(m.player), afm_player_positions(m.player) + 3 * m.doc->geometry.vertex_count);
  ASSERT_EQ(afm_player_pose(m.player, &a, &b, 32768), AFM_OK);
  const int32_t *pm = afm_player_positions(m.player);
  int moved = 0;
  for (size_t i = 0; i < pa.size(); ++i) {
    EXPECT_NEAR(pm[i], (pa[i] + pb[i]) / 2.0, 1.0) << i;
    moved += pa[i] != pb[i];
  }
  EXPECT_GT(moved, 20);  // the test is not vacuous
}

TEST(Player, StatePersistsAndMirrorsOnlyWhenAsked) {
  afm_fap_frame f{};
  afm_fap_state s;
  afm_fap_state_reset(&s);
  f.mask[6] = 1, f.value[6] = 120;  // stretch_l_cornerlip only
  afm_fap_state_apply(&s, &f, 0);
  EXPECT_EQ(s.value[6], 120);
  EXPECT_EQ(s.value[7], 0);
  afm_fap_frame empty{};
  afm_fap_state_apply(&s, &empty, 0);
  EXPECT_EQ(s.value[6], 120);  // not sent: keeps its value
  afm_fap_state_reset(&s);
  afm_fap_state_apply(&s, &f, AFM_MIRROR_LEFT_RIGHT);
  EXPECT_EQ(s.value[7], 120);
  EXPECT_EQ(s.value[53], 0);
  afm_fap_state_reset(&s);
  afm_fap_state_apply(&s, &f, AFM_MIRROR_LEFT_RIGHT | AFM_MIRROR_INNER_OUTER);
  EXPECT_EQ(s.value[7], 120);
  EXPECT_EQ(s.value[53], 120);
  EXPECT_EQ(s.value[54], 120);
  // Both sides sent: nothing is copied.
  f.mask[7] = 1, f.value[7] = -30;
  afm_fap_state_reset(&s);
  afm_fap_state_apply(&s, &f, AFM_MIRROR_LEFT_RIGHT);
  EXPECT_EQ(s.value[7], -30);
}

TEST(Player, CursorAppliesEveryFrameAndInterpolates) {
  std::vector<afm_fap_frame> frames(5);
  for (uint32_t i = 0; i < 5; ++i) frames[i].number = i + 1;  // numbered from 1
  frames[0].mask[3] = 1, frames[0].value[3] = 0;
  frames[2].mask[5] = 1, frames[2].value[5] = 77;  // only in frame 3
  frames[3].mask[3] = 1, frames[3].value[3] = 400;
  afm_fap_cursor c;
  ASSERT_EQ(afm_fap_cursor_init(&c, frames.data(), 5, 25, 1, 0), AFM_OK);
  EXPECT_EQ(afm_fap_cursor_duration_us(&c), 160000u);
  const afm_fap_state *a, *b;
  afm_q16 t;
  // Render at 10 fps: 0, 100 ms, 200 ms... frame 3 (80 ms) falls between.
  ASSERT_EQ(afm_fap_cursor_seek(&c, 0, &a, &b, &t), AFM_OK);
  EXPECT_EQ(a->value[5], 0);
  ASSERT_EQ(afm_fap_cursor_seek(&c, 100000, &a, &b, &t), AFM_OK);
  EXPECT_EQ(a->value[5], 77);  // sent only in frame 3, which no render time hits: still there
  EXPECT_EQ(a->value[3], 0);   // 100 ms lies between frame 3 (80 ms) and frame 4 (120 ms)
  EXPECT_EQ(b->value[3], 400);
  EXPECT_EQ(t, 32768);
  ASSERT_EQ(afm_fap_cursor_seek(&c, 500000, &a, &b, &t), AFM_OK);  // past the end: the last state
  EXPECT_EQ(a->value[3], 400);
  EXPECT_EQ(t, 0);
  ASSERT_EQ(afm_fap_cursor_seek(&c, 40000, &a, &b, &t), AFM_OK);  // back in time: replayed
  EXPECT_EQ(a->value[5], 0);
}

// ---- determinism -----------------------------------------------------------------------------

// Golden per-frame hashes of a synthetic model (integer data only, no
// generator in the loop). A change here means the player's output changed:
// if intended, update the values and say why in the commit.
TEST(Player, GoldenPerFrameHash) {
  afmtest::SyntheticDoc s;
  afmtest::SyntheticOptions o;
  o.rows = 40, o.cols = 50;
  const afm_doc *src = afmtest::make_synthetic_doc(s, o);
  std::vector<uint8_t> bytes = afmtest::write_doc(*src, AFM_PROFILE_RAW);
  afm_doc *d = nullptr;
  ASSERT_EQ(afm_doc_read_alloc(bytes.data(), bytes.size(), nullptr, nullptr, &d), AFM_OK);
  std::unique_ptr<afm_doc, DocFree> doc(d);
  size_t need = 0;
  ASSERT_EQ(afm_player_measure(d, nullptr, &need), AFM_OK);
  std::vector<uint64_t> mem(need / 8 + 1, 0x5A5A5A5A5A5A5A5Aull);
  afm_player *p = nullptr;
  ASSERT_EQ(afm_player_init(d, nullptr, mem.data(), need, &p), AFM_OK);
  uint64_t hashes[4];
  const afm_fap_state states[4] = {state({}), state({{3, 512}, {12, 300}}),
                                   state({{3, 1500}, {31, -200}, {23, 40000}, {48, -15000}}),
                                   state({{12, -900}, {31, 400}, {25, 25000}, {27, 300}})};
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(afm_player_pose(p, &states[i], i ? &states[i - 1] : nullptr, 20000), AFM_OK);
    hashes[i] = pose_hash(p, d->geometry.vertex_count);
    std::printf("frame %d hash %016llx\n", i, static_cast<unsigned long long>(hashes[i]));
  }
  const uint64_t golden[4] = {0xdfd3734a4d72cc70ull, 0x6e5dd8af9eee03adull, 0xb758474ffc75ddcfull,
                              0xa865260a27454769ull};
  for (int i = 0; i < 4; ++i) EXPECT_EQ(hashes[i], golden[i]) << "frame " << i;
}

// ---- memory --------------------------------------------------------------------------------

TEST(Player, PosingAllocatesNothing) {
#if !AFM_COUNT_MALLOC
  GTEST_SKIP() << "malloc is the sanitizer's here; the release build counts";
#else
  Model &m = head2k();
  std::mt19937 rng(7);
  std::vector<afm_fap_state> states;
  for (int i = 0; i < 20; ++i) states.push_back(random_state(m, rng));
  const unsigned long before = g_allocations;
  for (int i = 1; i < 20; ++i) ASSERT_EQ(afm_player_pose(m.player, &states[i - 1], &states[i], 1000 * i), AFM_OK);
  EXPECT_EQ(g_allocations - before, 0u);
  // The counter works: a real allocation is seen.
  void *probe = malloc(16);
  EXPECT_EQ(g_allocations - before, 1u);
  free(probe);
#endif
}

// ---- control points (LIFT) -------------------------------------------------------------------

namespace {

// The synthetic document, with control points unless asked otherwise, read
// back from its raw file, and a player on it.
struct SyntheticModel {
  afmtest::SyntheticDoc source;
  std::unique_ptr<afm_doc, DocFree> doc;
  std::vector<uint64_t> memory;
  afm_player *player = nullptr;

  explicit SyntheticModel(bool lift = true, bool in_betweens = false, bool combination = false) {
    afmtest::SyntheticOptions o;
    o.rows = 40, o.cols = 50;
    o.lift = lift;
    o.in_betweens = in_betweens;
    o.combination = combination;
    const std::vector<uint8_t> bytes = afmtest::write_doc(*afmtest::make_synthetic_doc(source, o), AFM_PROFILE_RAW);
    afm_doc *d = nullptr;
    EXPECT_EQ(afm_doc_read_alloc(bytes.data(), bytes.size(), nullptr, nullptr, &d), AFM_OK);
    doc.reset(d);
    player = make_player();
  }
  afm_player *make_player() {
    size_t need = 0;
    EXPECT_EQ(afm_player_measure(doc.get(), nullptr, &need), AFM_OK);
    memory.assign(need / 8 + 1, 0xA5A5A5A5A5A5A5A5ull);  // garbage: init must not rely on zeros
    afm_player *p = nullptr;
    EXPECT_EQ(afm_player_init(doc.get(), nullptr, memory.data(), need, &p), AFM_OK);
    return p;
  }
};

// Random values of the synthetic targets' FAPs (3, 12, 31) within twice
// their references, a viseme and an expression, and an eye turn.
afm_fap_state lifted_state(std::mt19937 &rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  afm_fap_state s;
  afm_fap_state_reset(&s);
  s.value[3] = int32_t(std::lround(u(rng) * 2048));
  s.value[12] = int32_t(std::lround(u(rng) * 1024));
  s.value[31] = int32_t(std::lround(u(rng) * 512));
  if (rng() % 2) s.viseme = {1, 0, uint8_t(rng() % 64), 0};
  if (rng() % 2) s.expression = {1, uint8_t(rng() % 64), 0, 0, 0, 0};
  s.value[23] = int32_t(std::lround(u(rng) * 30000));
  return s;
}

// Poses four states in turn (each interpolated from the one before at t) and
// compares each pose's hash with its golden value.
void expect_golden_frames(SyntheticModel &m, const afm_fap_state (&states)[4], afm_q16 t,
                          const std::array<uint64_t, 4> &golden) {
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(afm_player_pose(m.player, &states[i], i ? &states[i - 1] : nullptr, t), AFM_OK);
    const uint64_t hash = pose_hash(m.player, m.doc->geometry.vertex_count);
    std::printf("frame %d hash %016llx\n", i, static_cast<unsigned long long>(hash));
    EXPECT_EQ(hash, golden[size_t(i)]) << "frame " << i;
  }
}

}  // namespace

// Error budget of a bound vertex, in quanta: the weight terms as for any
// vertex (2^-13 * max|delta| per target, controls' deltas included), one
// rounding of the lift to Q12 (2^-13) and the output rounding (0.5). The
// double model lifts the controls exactly.
TEST(Player, LiftedVerticesMatchTheDoubleModel) {
  SyntheticModel m;
  ASSERT_NE(m.doc->lift, nullptr);
  const afm_geometry &g = m.doc->geometry;
  std::mt19937 rng(99);
  double worst = 0, largest_motion = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const afm_fap_state a = lifted_state(rng), b = lifted_state(rng);
    const afm_q16 t = afm_q16(rng() % 65537);
    ASSERT_EQ(afm_player_pose(m.player, &a, &b, t), AFM_OK);
    const afmtest::ReferencePose ref = afmtest::reference_pose(*m.doc, a, b, t / 65536.0);
    const double budget = 0.5 + 1.0 / 8192 + weight_budget(*m.doc, ref, 1.0 / 8192);
    // The skin (all bound) only: the eye also turns, which the rigid test covers.
    const uint32_t skin = g.parts[0].vertex_count;
    for (uint32_t v = 0; v < skin; ++v) {
      const int32_t *p = afm_player_positions(m.player) + 3 * size_t(v);
      for (int k = 0; k < 3; ++k) {
        const double e = std::fabs(p[k] - ref.positions[v][size_t(k)]);
        ASSERT_LE(e, budget) << "trial " << trial << " vertex " << v << " axis " << k;
        worst = std::max(worst, e);
      }
      const double moved = std::hypot(ref.positions[v][0] - g.px[v], ref.positions[v][1] - g.py[v],
                                      ref.positions[v][2] - g.pz[v]);
      largest_motion = std::max(largest_motion, moved);
    }
  }
  std::printf("lifted vertices, fixed vs double over 30 random poses: worst error %.3f quanta, largest motion "
              "%.0f quanta\n",
              worst, largest_motion);
  EXPECT_GT(largest_motion, 500);  // the controls really move the skin
}

// The player restores only what a pose changed (controls included): any
// sequence of poses ends where one pose from a fresh player does.
TEST(Player, LiftedPoseSequenceEqualsAFreshPose) {
  SyntheticModel seq, fresh_model;
  std::mt19937 rng(5);
  afm_fap_state neutral;
  afm_fap_state_reset(&neutral);
  for (int i = 0; i < 12; ++i) {
    // Every third pose is neutral, or moves the eye alone (no control).
    afm_fap_state s = lifted_state(rng);
    if (i % 3 == 1) s = neutral;
    if (i % 3 == 2) s = neutral, s.value[23] = 20000;
    ASSERT_EQ(afm_player_pose(seq.player, &s, nullptr, 0), AFM_OK);
    afm_player *fresh = fresh_model.make_player();
    ASSERT_EQ(afm_player_pose(fresh, &s, nullptr, 0), AFM_OK);
    const size_t n = 3 * size_t(seq.doc->geometry.vertex_count);
    ASSERT_TRUE(std::equal(afm_player_positions(seq.player), afm_player_positions(seq.player) + n,
                           afm_player_positions(fresh)))
        << "pose " << i;
    ASSERT_TRUE(std::equal(afm_player_normals(seq.player), afm_player_normals(seq.player) + n,
                           afm_player_normals(fresh)))
        << "pose " << i;
  }
}

// Golden per-frame hashes of the lifted synthetic model: the lift kernel's
// arithmetic pinned (int64 products, one rounding to Q12). Update with a
// reason, as GoldenPerFrameHash.
TEST(Player, LiftedGoldenPerFrameHash) {
  SyntheticModel m;
  const afm_fap_state states[4] = {state({}), state({{3, 512}, {12, 300}}),
                                   state({{3, 1500}, {31, -200}, {23, 40000}, {48, -15000}}),
                                   state({{12, -900}, {31, 400}, {25, 25000}, {27, 300}})};
  expect_golden_frames(m, states, 20000,
                       {0xdfd3734a4d72cc70ull, 0x03c0cf172fab673aull, 0x4c146d0f8a0b8223ull, 0xa19f9cbee7731fb6ull});
}

// ---- in-between targets ------------------------------------------------------------------------

namespace {

// The Q12 weight of the FAP target (or the combination) at `reference`.
int weight_at(const SyntheticModel &m, int fap, int32_t reference, int kind = AFM_TARGET_FAP) {
  for (uint32_t i = 0; i < m.doc->target_count; ++i)
    if (m.doc->targets[i].kind == kind && m.doc->targets[i].number == fap &&
        m.doc->targets[i].reference == reference)
      return afm_player_weights(m.player)[i];
  ADD_FAILURE() << "no target of FAP " << fap << " at " << reference;
  return 0;
}

}  // namespace

// formats/afm.md: between a side's references the face is linear in the
// value, each reference shows its target alone, and past the farthest the
// last segment goes on. Exact Q12 values: every quotient here is exact or
// rounds as stated.
TEST(Player, InBetweenTargetsBlendPiecewiseLinearly) {
  SyntheticModel m(false, true);
  struct Case {
    int32_t v12, v31;
    int w512, w1024, w1800, w31p, w31n, w31n700;
  };
  const Case cases[] = {
      {256, 128, 2048, 0, 0, 2048, 0, 0},          // first segment: value / reference
      {512, -256, 4096, 0, 0, 0, 4096, 0},         // at the first references
      {768, -478, 2048, 2048, 0, 0, 2048, 2048},   // halfway between 512 and 1024, -256 and -700
      {1024, -700, 0, 4096, 0, 0, 0, 4096},        // at the second references: alone
      {1412, -1144, 0, 2048, 2048, 0, -4096, 8192},  // halfway to 1800; -1144: past -700 by its segment
      {2576, 0, 0, -4096, 8192, 0, 0, 0},          // past the farthest by its segment
      {-256, 0, -2048, 0, 0, 0, 0, 0},             // no negative side: the first segment extrapolated
  };
  for (const Case &c : cases) {
    const afm_fap_state s = state({{12, c.v12}, {31, c.v31}});
    ASSERT_EQ(afm_player_pose(m.player, &s, nullptr, 0), AFM_OK);
    EXPECT_EQ(weight_at(m, 12, 512), c.w512) << c.v12;
    EXPECT_EQ(weight_at(m, 12, 1024), c.w1024) << c.v12;
    EXPECT_EQ(weight_at(m, 12, 1800), c.w1800) << c.v12;
    EXPECT_EQ(weight_at(m, 31, 256), c.w31p) << c.v31;
    EXPECT_EQ(weight_at(m, 31, -256), c.w31n) << c.v31;
    EXPECT_EQ(weight_at(m, 31, -700), c.w31n700) << c.v31;
  }
}

// The fixed-point blend of in-betweens against the double model, over
// values spanning every segment and past the farthest reference. Budget per
// target in use: one Q12 unit of weight times its largest delta; plus the
// output's rounding.
TEST(Player, InBetweenTargetsMatchTheDoubleModel) {
 for (bool combination : {false, true}) {
  SCOPED_TRACE(combination ? "with a combination" : "in-betweens");
  SyntheticModel m(false, true, combination);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0;
  for (int trial = 0; trial < 30; ++trial) {
    afm_fap_state a = state({}), b = state({});
    for (afm_fap_state *s : {&a, &b}) {
      s->value[12] = int32_t(std::lround(u(rng) * 2400));
      s->value[31] = int32_t(std::lround(u(rng) * 1000));
      s->value[3] = int32_t(std::lround(u(rng) * 1024));
    }
    const afm_q16 t = afm_q16(rng() % 65537);
    ASSERT_EQ(afm_player_pose(m.player, &a, &b, t), AFM_OK);
    const afmtest::ReferencePose ref = afmtest::reference_pose(*m.doc, a, b, t / 65536.0);
    // Half a Q12 unit of weight from the weight's rounding, half from the lerp's.
    const double budget = 0.5 + weight_budget(*m.doc, ref, 1.0 / 4096);
    const uint32_t skin = m.doc->geometry.parts[0].vertex_count;
    for (uint32_t v = 0; v < skin; ++v)
      for (int k = 0; k < 3; ++k) {
        const double e = std::fabs(afm_player_positions(m.player)[3 * size_t(v) + size_t(k)] - ref.positions[v][size_t(k)]);
        ASSERT_LE(e, budget) << "trial " << trial << " vertex " << v << " axis " << k;
        worst = std::max(worst, e);
      }
  }
  std::printf("%s, fixed vs double over 30 random poses: worst error %.3f quanta\n",
              combination ? "a combination target" : "in-between targets", worst);
 }
}

// A combination target (formats/afm.md, version 1.4) takes the weight of
// the FAP target it follows (FAP 31 at -700), capped by its gate's value /
// gate reference (FAP 3 at 1024), never below 0. Exact Q12 values.
TEST(Player, ACombinationFollowsItsTargetAsFarAsItsGateGoes) {
  SyntheticModel m(false, true, true);
  struct Case {
    int32_t v31, v3;
    int w700, combination;
  };
  const Case cases[] = {
      {-478, 512, 2048, 2048},    // halfway to -700, the gate halfway: both 1/2
      {-700, 256, 4096, 1024},    // at -700, the gate at a quarter: the gate's
      {-700, 2048, 4096, 4096},   // the gate past its reference: the target's
      {-1144, 1024, 8192, 4096},  // past -700 by its segment, the gate at 1: the gate's
      {-1144, 3072, 8192, 8192},  // both past: the target's
      {-700, 0, 4096, 0},         // the gate closed: nothing
      {-700, -512, 4096, 0},      // the gate negative: nothing, not a negative weight
      {-256, 1024, 0, 0},         // short of the segment before -700: nothing
      {256, 1024, 0, 0},          // the other side
  };
  for (const Case &c : cases) {
    const afm_fap_state s = state({{31, c.v31}, {3, c.v3}});
    ASSERT_EQ(afm_player_pose(m.player, &s, nullptr, 0), AFM_OK);
    EXPECT_EQ(weight_at(m, 31, -700), c.w700) << c.v31 << " " << c.v3;
    EXPECT_EQ(weight_at(m, 31, -700, AFM_TARGET_COMBINATION), c.combination) << c.v31 << " " << c.v3;
  }
}

// Golden per-frame hashes with in-betweens: the segment choice and its
// weights pinned. Update with a reason, as GoldenPerFrameHash.
TEST(Player, InBetweenGoldenPerFrameHash) {
  SyntheticModel m(false, true);
  const afm_fap_state states[4] = {state({{12, 700}}), state({{12, 1500}, {31, -500}}),
                                   state({{12, 3000}, {31, -1200}, {3, 400}}), state({{12, -300}, {31, 300}})};
  expect_golden_frames(m, states, 30000,
                       {0x5b18097c2add03a2ull, 0x7dfeb00c08335741ull, 0x7938bfe3781c57ebull, 0xb9b0726dd6640126ull});
}

// Golden per-frame hashes with a combination: its weight, the followed
// target's capped by the gate's, pinned. Update with a reason, as
// GoldenPerFrameHash.
TEST(Player, CombinationGoldenPerFrameHash) {
  SyntheticModel m(false, true, true);
  const afm_fap_state states[4] = {state({{31, -500}, {3, 200}}), state({{31, -900}, {3, 700}}),
                                   state({{31, -1200}, {3, 1400}, {12, 800}}), state({{31, -700}, {3, -300}})};
  expect_golden_frames(m, states, 30000,
                       {0x842f386e6ababeb8ull, 0xe6692ec85913691eull, 0xa607f11d1726c0eaull, 0x31ea78af1b2aaed3ull});
}

// Control knots (formats/afm.md, RIGD, version 1.3): the synthetic eye's
// yaw (FAP 23, 1 AU per unit) is half as steep past 20000 and its pitch
// (FAP 25) twice as steep below -15000. The angles are read back from the
// pose's rotation, whose Q14 entries resolve 6 AU: a slope that did not
// bend would be 5000 AU or more off at the values below.
TEST(Player, ControlKnotsBendTheRigidMotionWhereTheyLie) {
  SyntheticModel m(false, true);
  const afm_rigid *eye = nullptr;
  for (uint32_t r = 0; r < m.doc->rigid_count; ++r)
    if (m.doc->rigids[r].kind == AFM_RIGID_EYE_LEFT) eye = &m.doc->rigids[r];
  ASSERT_NE(eye, nullptr);
  // The angle in AU about y (yaw) or x (pitch) for states a..b at t.
  auto angle = [&](const afm_fap_state &a, const afm_fap_state &b, afm_q16 t, bool yaw) {
    afm_rigid_transform x;
    EXPECT_EQ(afm_rigid_pose(eye, &a, &b, t, &x), AFM_OK);
    return (yaw ? std::atan2(x.rotation[2], x.rotation[0]) : std::atan2(x.rotation[7], x.rotation[4])) / 1e-5;
  };
  struct Case {
    int fap;
    int32_t value;
    double au;
  };
  const Case cases[] = {
      {23, 10000, 10000},  {23, 20000, 20000},   {23, 30000, 25000},   {23, 60000, 40000},
      {23, -30000, -30000},  // the knot lies on the positive side only
      {25, 10000, 10000},  {25, -15000, -15000}, {25, -20000, -25000}, {25, -25000, -35000},
  };
  for (const Case &c : cases) {
    const afm_fap_state s = state({{c.fap, c.value}});
    EXPECT_NEAR(angle(s, s, 0, c.fap == 23), c.au, 8) << "FAP " << c.fap << " at " << c.value;
  }
  // Between frames the value is interpolated first, then taken beyond the
  // knot: halfway from 10000 to 30000 is 20000, at the knot (not the mean
  // of 10000 and 25000 AU).
  EXPECT_NEAR(angle(state({{23, 10000}}), state({{23, 30000}}), 32768, true), 20000, 8);
  // The whole pose against the double model, the eye's vertices included:
  // the weights' budget and the rigid term of FixedPointMatchesTheDoubleModel.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const afm_geometry &g = m.doc->geometry;
  double worst = 0;
  for (int trial = 0; trial < 30; ++trial) {
    afm_fap_state a = state({}), b = state({});
    for (afm_fap_state *s : {&a, &b}) {
      s->value[12] = int32_t(std::lround(u(rng) * 2400));
      s->value[23] = int32_t(std::lround(u(rng) * 45000));
      s->value[25] = int32_t(std::lround(u(rng) * 30000));
    }
    const afm_q16 t = afm_q16(rng() % 65537);
    ASSERT_EQ(afm_player_pose(m.player, &a, &b, t), AFM_OK);
    const afmtest::ReferencePose ref = afmtest::reference_pose(*m.doc, a, b, t / 65536.0);
    const double morph = 0.5 + weight_budget(*m.doc, ref, 1.0 / 4096);
    for (uint32_t v = 0; v < g.vertex_count; ++v) {
      const double reach = std::hypot(g.px[v] - eye->pivot[0], g.py[v] - eye->pivot[1], g.pz[v] - eye->pivot[2]);
      const double bound = morph + (reach + 2 * morph) * 4 * 3 / 16384.0 + 1.0;
      for (int k = 0; k < 3; ++k) {
        const double e = std::fabs(afm_player_positions(m.player)[3 * size_t(v) + size_t(k)] - ref.positions[v][size_t(k)]);
        ASSERT_LE(e, bound) << "trial " << trial << " vertex " << v << " axis " << k;
        worst = std::max(worst, e);
      }
    }
  }
  std::printf("control knots, fixed vs double over 30 random poses: worst error %.3f quanta\n", worst);
}
