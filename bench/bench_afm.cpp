// AFM sizes and load times, raw against draco, measured in one run.
//
// Models: the reference head at about 2k, 10k and 50k skin vertices, and the
// Song head when ../shared/data is there. Each is written neutral and with 20
// analytic FAP-like morph targets (smooth bumps around FDPs along the FAP's
// direction, 1 cm at the centre, zero at 3 cm, scaled by ES0 / 6.3 cm), so
// both GEOM and MTGT are measured.
#include <afm/draco.h>
#include <afm/format.h>
#include <afm/mpeg4.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "afm/afm_export.h"
#include "core/fapu.h"
#include "core/part_kind.h"
#include "io/fdp_io.h"
#include "io/mesh_io.h"
#include "refhead/refhead.h"

#include "chunk_bytes.h"

using namespace afmb;
using Clock = std::chrono::steady_clock;

namespace {

struct Model {
  std::string name;
  Scene scene;
  FdpSet fdps;
};

// 20 FAP targets: FAP n moves the skin around its FDP along its direction.
std::vector<MorphTarget> analytic_targets(const Model &m, double scale) {
  static const int faps[] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 16, 17, 19, 21, 31, 33, 35, 51, 53};
  std::vector<MorphTarget> out;
  const int skin = m.scene.find_kind(PartKind::Skin);
  for (int fap : faps) {
    const afm_fap_info *info = afm_fap(fap);
    FdpId id{info->fdp_group, info->fdp_index};
    const FdpPoint *p = m.fdps.find(id, skin);
    if (!p) continue;
    MorphTarget t;
    t.kind = AFM_TARGET_FAP;
    t.number = fap;
    t.reference = 1024;
    t.normals = true;
    t.displacement.resize(m.scene.parts.size());
    const Part &part = m.scene.parts[static_cast<size_t>(skin)];
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(part.V.rows(), 3);
    Eigen::RowVector3d dir(info->direction[0], info->direction[1], info->direction[2]);
    for (Eigen::Index i = 0; i < part.V.rows(); ++i) {
      double r = (part.V.row(i) - p->pos.transpose()).norm() / (0.03 * scale);
      if (r < 1) D.row(i) = 0.01 * scale * (1 - r * r) * (1 - r * r) * dir;
    }
    t.displacement[static_cast<size_t>(skin)] = D;
    out.push_back(std::move(t));
  }
  return out;
}

double seconds_per_load(const std::vector<uint8_t> &bytes) {
  afm_read_options ro{};
  ro.draco = afm_draco_codec();
  int n = 0;
  auto t0 = Clock::now();
  double elapsed = 0;
  do {
    afm_doc *doc = nullptr;
    if (afm_doc_read_alloc(bytes.data(), bytes.size(), &ro, nullptr, &doc) != AFM_OK) {
      std::fprintf(stderr, "bench_afm: decode failed\n");
      std::exit(1);
    }
    afm_free(nullptr, doc);
    ++n;
    elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
  } while (elapsed < 0.3 || n < 3);
  return elapsed / n;
}

void measure(const Model &m) {
  Expected<Fapu> fapu = compute_fapu(m.fdps);
  // Bumps sized for a real head: ES0 is about 6.3 cm.
  const double scale = fapu ? fapu->es0 / 0.063 : 1.0;
  AfmContent content;
  content.scene = &m.scene;
  content.fdps = &m.fdps;
  if (fapu) content.fapu = *fapu;
  for (bool with_targets : {false, true}) {
    if (with_targets) content.targets = analytic_targets(m, scale);
    auto t0 = Clock::now();
    Expected<std::vector<uint8_t>> raw = encode_afm(content, AFM_PROFILE_RAW);
    auto t1 = Clock::now();
    Expected<std::vector<uint8_t>> draco = encode_afm(content, AFM_PROFILE_DRACO);
    auto t2 = Clock::now();
    if (!raw || !draco) {
      std::fprintf(stderr, "bench_afm: %s: %s\n", m.name.c_str(),
                   (!raw ? raw.status() : draco.status()).message().c_str());
      std::exit(1);
    }
    double load_raw = seconds_per_load(*raw), load_draco = seconds_per_load(*draco);
    std::printf("%-22s %-8s %8zu %10zu %10zu  %5.3f  GEOM %5.3f  MTGT %5.3f  %8.2f %8.2f  %5.1fx"
                "  %7.1f %7.1f\n",
                m.name.c_str(), with_targets ? "20 FAPs" : "neutral", m.scene.vertex_count(),
                raw->size(), draco->size(), double(draco->size()) / double(raw->size()),
                double(chunk_bytes(*draco, AFM_CHUNK_GEOM)) / double(chunk_bytes(*raw, AFM_CHUNK_GEOM)),
                with_targets ? double(chunk_bytes(*draco, AFM_CHUNK_MTGT)) /
                                   double(chunk_bytes(*raw, AFM_CHUNK_MTGT))
                             : 0.0,
                load_raw * 1e3, load_draco * 1e3, load_draco / load_raw,
                std::chrono::duration<double, std::milli>(t1 - t0).count(),
                std::chrono::duration<double, std::milli>(t2 - t1).count());
  }
}

}  // namespace

int main() {
  std::printf("AFM size and load time, raw vs draco (ratios are draco/raw; times in ms)\n");
  std::printf("%-22s %-8s %8s %10s %10s  %5s  %10s  %10s  %8s %8s  %6s  %7s %7s\n", "model", "targets",
              "vertices", "raw B", "draco B", "ratio", "GEOM ratio", "MTGT ratio", "load raw",
              "load drc", "slower", "enc raw", "enc drc");
  for (int n : {2000, 10000, 50000}) {
    RefHeadOptions o;
    o.skin_vertices = n;
    Expected<RefHead> head = make_reference_head(o);
    if (!head) {
      std::fprintf(stderr, "bench_afm: %s\n", head.status().message().c_str());
      return 1;
    }
    Model m{"refhead-" + std::to_string(n / 1000) + "k", std::move(head->scene), std::move(head->fdps)};
    measure(m);
  }
  const char *shared = std::getenv("AFM_SHARED_DIR");
  std::filesystem::path song =
      std::filesystem::path(shared ? shared : AFM_SOURCE_DIR "/../shared") / "data/faces/song";
  if (std::filesystem::exists(song / "song.WRL")) {
    Expected<Scene> scene = read_scene((song / "song.WRL").string());
    Expected<FdpSet> fdps = read_fdp((song / "song.fdp").string());
    if (scene && fdps && bind_fdps(*fdps, *scene)) {
      guess_part_kinds(*scene);
      assign_part_kinds(*scene, *fdps);
      Model m{"song", std::move(*scene), std::move(*fdps)};
      measure(m);
    }
  } else {
    std::printf("(Song head skipped: ../shared/data is absent)\n");
  }
  return 0;
}
