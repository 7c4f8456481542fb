// afm-build: mesh + FDPs -> the anatomical face model, its pictures and poses.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <algorithm>
#include <unistd.h>

#include "afm/afm_export.h"
#include "anatomy/face_model.h"
#include "anatomy/muscle_table.h"
#include "anatomy/sim_mesh.h"
#include "core/allocator.h"
#include "core/atomic_file.h"
#include "fap/fap_mapping.h"
#include "fap/fap_synthesis.h"
#include "fap/fidelity_report.h"
#include "io/load_face.h"
#include "render/anatomy_render.h"

using namespace afmb;

namespace {

void usage(FILE *out) {
  std::fprintf(out,
      "usage: afm-build MESH FDP [options]\n"
      "\n"
      "Builds the anatomical face model of a face mesh and its MPEG-4 feature points\n"
      "(docs/anatomy.md): a four-layer mass-spring skin over a skull, the 25 muscles\n"
      "placed from the FDPs (and drivers of our own for the lids, the lips' pout, the\n"
      "nose's wings and tip, the cheeks' puff, the chin, the inner brows and the lower\n"
      "lip), the jaw; calibrates every muscle and prints the model.\n"
      "Draws pictures of it and solves poses on request. With -o, makes a morph target\n"
      "per FAP (docs/fap_mapping.md) and writes the Animatable Face Model. A muscle\n"
      "that is not essential and cannot reach its table range calibrates to a half, a\n"
      "quarter or an eighth of it, with a warning; one that lacks FDPs or cannot reach\n"
      "even that is skipped with a warning, and the FAPs that need it are reported.\n"
      "\n"
      "  MESH, FDP               as afm-import (.wrl/.obj/.ply/.off/.stl; XfaceEd, text or\n"
      "                          visage FDPs)\n"
      "  --orient SPEC|auto      map the input axes to the MPEG-4 frame (see afm-import)\n"
      "  --fdp-format F          auto (default), xfaceed, text or visage\n"
      "  --flip-v                texture v runs down in this model (as afm-import)\n"
      "  --solver S              newton (default), newton-rest, implicit-euler (the\n"
      "                          paper's scheme) or newton-jacobi (solver.h; calibration,\n"
      "                          the jaw's full opening too, always runs a newton solver)\n"
      "  --collapse-floor K      resist each slab of tissue squeezed below half its\n"
      "                          rest volume with modulus K (default %g; 0: off), so\n"
      "                          that none turns through itself (docs/anatomy.md,\n"
      "                          \"Tissue\")\n"
      "  --no-layered-skin       the skin before the layered skin: linear muscles pull\n"
      "                          the dermis alone and only each element keeps its\n"
      "                          volume (by default the epidermis and the dermis take\n"
      "                          half the pull each and each layer keeps its own;\n"
      "                          docs/anatomy.md, \"The layered skin\"); with\n"
      "                          --collapse-floor 0, strong pulls turn slabs through\n"
      "                          themselves\n"
      "  --sim-vertices N|full   simulate on a coarser copy of the skin of about N\n"
      "                          vertices (its own, every skin FDP among them; finer\n"
      "                          around eyes and mouth; mirror-symmetric where the\n"
      "                          skin is; the skin's shortest edges, under %g of its\n"
      "                          mean, collapsed first) and carry the motion to every\n"
      "                          skin vertex (default %d; full: the skin itself, as is\n"
      "                          any skin of at most 1.25 N vertices). The\n"
      "                          pictures of the model show the simulation mesh. A\n"
      "                          mesh too coarse to calibrate an essential muscle is\n"
      "                          tried again 1.5 times as fine, up to the whole skin\n"
      "  --threads N             calibration and synthesis workers (default: one per\n"
      "                          core; the model and the AFM are the same for any N)\n"
      "  --no-estimates          do not estimate missing FDPs from the reference head:\n"
      "                          muscles lacking FDPs are skipped (or, if essential, the\n"
      "                          build fails)\n"
      "  --no-calibrate          place muscles and jaw only (fast; for --muscle-map)\n"
      "  --muscle-map FILE.png   muscles on the face: attachments green, insertions red,\n"
      "                          fibres and sphincter ellipses white\n"
      "  --influence MUSCLE FILE.png\n"
      "                          one muscle's influence area red and the nodes its elastic\n"
      "                          wave moves green (repeatable)\n"
      "  --jaw-map FILE.png      skin carried by the jaw (violet; paler below and beside\n"
      "                          it, where the skin follows in part), the jaw mesh and\n"
      "                          its pivot, the lips' contact pairs\n"
      "  --contract MUSCLE=PCT   contract a muscle, -100..100 %% of its calibrated range\n"
      "                          (repeatable; positive is the muscle's action)\n"
      "  --jaw PCT               open the jaw, 0..100 %% (100 %% is 20 degrees)\n"
      "  --pose FILE.png         solve the pose given by --contract/--jaw and draw it,\n"
      "                          red over the slabs of tissue it turns through themselves\n"
      "  -o FACE.afm             synthesize the morph targets (each FAP, viseme and\n"
      "                          expression; the eyelids also at 600 and, upper, 1024:\n"
      "                          in-betweens, where the lid reaches them, or at the value\n"
      "                          where the lids meet; a lid whose driver cannot turn it\n"
      "                          that far turns as a whole; open_jaw also at 640 and\n"
      "                          1024, the jaw's rigid controls bent there, without\n"
      "                          opening the mouth, the skin pushed out over the lower\n"
      "                          teeth; the lower lip's FAPs held to -1024 past\n"
      "                          their muscles' reach, with a combination there\n"
      "                          gated by open_jaw: the lip goes on as the jaw\n"
      "                          would carry it, as far as it opens) and write the\n"
      "                          AFM; prints, per target, the prescribed and achieved\n"
      "                          FDP motion and the error along and off the FAP's\n"
      "                          direction (a muscle group short of the FAP's reference\n"
      "                          may pass its calibrated range, up to %g\n"
      "                          times, and a weak one still short there up to %g\n"
      "                          times, while the skin stays a face once the triangles\n"
      "                          it turns are untangled, as the target stores them (raw\n"
      "                          at the lip corners); where a side falls\n"
      "                          short and the mapping has a second group for it, that\n"
      "                          group is tried too and the target nearer the FAP's\n"
      "                          motion kept; else the target\n"
      "                          under-reaches, and says so: its pose is then stored at\n"
      "                          the FAP units it reaches and held from there to the\n"
      "                          reference, as an in-between; a lip corner's side whose\n"
      "                          target, with its partners' (the inner and outer lip's)\n"
      "                          taken %g times as far, folds the skin is held past its\n"
      "                          reference (an in-between there with the same pose);\n"
      "                          a viseme or expression whose table pose tears the skin,\n"
      "                          or keeps a triangle turned once untangled, is made with\n"
      "                          the largest share of the muscles to blame that does\n"
      "                          neither, and says so)\n"
      "  --profile P             draco (default: compressed) or raw\n"
      "  --faps LIST             only these targets: FAP numbers, vN visemes, eN\n"
      "                          expressions, e.g. 3,12,31,v1,e1 (default: every mapped one);\n"
      "                          calibrates only the muscles they use (and those of\n"
      "                          --contract and --influence), and the jaw when one opens\n"
      "                          it or --jaw does: the poses are the same; FAPs made\n"
      "                          together split the skin they share (evened out where a\n"
      "                          share would turn it over), so a FAP listed without its\n"
      "                          partners keeps their share (FAP 12 without 59 raises\n"
      "                          the lip corner all the way)\n"
      "  --no-steer              each FAP's muscle group acts alone: no helper muscles\n"
      "                          steer its FDP back onto the FAP's direction\n"
      "                          (--list-faps names each FAP's helpers)\n"
      "  --report DIR            with -o, also write the fidelity report into DIR:\n"
      "                          report.txt, report.csv, a picture per target\n"
      "                          (targets/*.png), a contact sheet (sheet.png) and\n"
      "                          index.html showing them together\n"
      "  --list-faps             how each FAP, viseme and expression is made: muscles\n"
      "                          (and second groups), jaw, rigid or not at all\n"
      "  --list-muscles          the 25 muscles, the 4 lid drivers, the 2 lip protrusion\n"
      "                          drivers, the 2 nostril dilators, the 2 cheek puffs\n"
      "                          (air pressure in the mouth), the chin raiser, the 2\n"
      "                          depressores supercilii, the 2 depressores labii\n"
      "                          inferioris and the nose's 4 tip drivers, their key\n"
      "                          points\n"
      "  --stats                 also print the solver's work, summed over every solve\n"
      "                          (calibration, then targets): solves, Newton iterations,\n"
      "                          CG iterations, factorisations, tangents assembled,\n"
      "                          energies; the same on every run with --threads 1\n"
      "  -q, --quiet             no progress on stderr (else one line rewritten in\n"
      "                          place, or a line per tenth of the work when stderr\n"
      "                          is not a terminal)\n"
      "  --help                  this text\n"
      "\n"
      "Every output (-o, --report, the pictures) is checked before the work starts:\n"
      "a path that cannot be written is refused at once, not after the build. Files\n"
      "appear whole or not at all.\n"
      "\n"
      "Exit status: 0 on success (FAPs that cannot be made are reported, not fatal), 1\n"
      "on bad input, an output that cannot be written or a solve that does not\n"
      "converge (the message says which and why), 2 on bad usage.\n", kCollapseFloor, kShortEdgeShare, kDefaultSimVertices,
      kMaxFapScale, kFurtherFapScale, kCornerStreamReach);
}

bool stderr_is_terminal() {
  static const bool tty = isatty(fileno(stderr)) != 0;
  return tty;
}

// Progress on stderr, "[done/total] what": on a terminal one line rewritten
// in place; in a log (not a terminal) a line at each tenth of the work.
void progress_line(int done, int total, const std::string &what) {
  if (stderr_is_terminal()) {
    std::fprintf(stderr, "\r[%3d/%3d] %-40s", done, total, what.c_str());
    if (done == total) std::fprintf(stderr, "\n");
  } else if (done == total || done * 10 / total != (done - 1) * 10 / total) {
    std::fprintf(stderr, "[%3d/%3d] %s\n", done, total, what.c_str());
  }
  std::fflush(stderr);
}

// Ends a progress line cut short (a terminal's only).
void end_progress() {
  if (stderr_is_terminal()) std::fprintf(stderr, "\n");
}

int fail(const Status &s) {
  std::fprintf(stderr, "afm-build: %s\n", s.message().c_str());
  return 1;
}

int usage_error(const std::string &msg) {
  std::fprintf(stderr, "afm-build: %s (see --help)\n", msg.c_str());
  return 2;
}

}  // namespace

int main(int argc, char **argv) {
  keep_freed_memory();
  std::string mesh_path, fdp_path, muscle_map, jaw_map, pose_png;
  std::vector<std::pair<std::string, std::string>> influences;
  std::vector<std::pair<std::string, double>> contractions;
  double jaw_open = 0;
  LoadOptions lo;
  FaceModelOptions fo;
  bool quiet = false, list = false, list_faps = false, stats = false;
  SolveTotals totals;
  std::string out_path, report_dir;
  afm_profile profile = AFM_PROFILE_DRACO;
  FapSynthesisOptions so;
  SimMeshOptions sm;
  sm.vertices = kDefaultSimVertices;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char *name) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "afm-build: %s needs a value (see --help)\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "--orient") {
      lo.orient = value("--orient");
    } else if (a == "--fdp-format") {
      const std::string f = value("--fdp-format");
      if (f == "auto") lo.fdp_format = FdpFormat::Auto;
      else if (f == "xfaceed") lo.fdp_format = FdpFormat::XfaceEd;
      else if (f == "text") lo.fdp_format = FdpFormat::Text;
      else if (f == "visage") lo.fdp_format = FdpFormat::Visage;
      else return usage_error("--fdp-format '" + f + "': use auto, xfaceed, text or visage");
    } else if (a == "--flip-v") {
      lo.flip_v = true;
    } else if (a == "--solver") {
      const std::string s = value("--solver");
      if (!solver_from_name(s, &fo.solver.kind))
        return usage_error("--solver '" + s + "': use newton, newton-rest, implicit-euler or newton-jacobi");
    } else if (a == "--collapse-floor") {
      const std::string k = value("--collapse-floor");
      char *end = nullptr;
      const double v = std::strtod(k.c_str(), &end);
      if (k.empty() || *end || !(v >= 0 && v <= 100))
        return usage_error("--collapse-floor '" + k + "': use a modulus, 0..100 (0: off)");
      fo.tissue.collapse_modulus = v;
    } else if (a == "--no-layered-skin") {
      fo.tissue.skin_load_share = 0;
      fo.tissue.layer_volume_modulus = 0;
    } else if (a == "--threads") {
      const std::string t = value("--threads");
      char *end = nullptr;
      const long n = std::strtol(t.c_str(), &end, 10);
      if (t.empty() || *end || n < 1 || n > 256) return usage_error("--threads '" + t + "': use a count, 1..256");
      fo.threads = static_cast<int>(n);
    } else if (a == "--sim-vertices") {
      const std::string t = value("--sim-vertices");
      char *end = nullptr;
      const long n = std::strtol(t.c_str(), &end, 10);
      if (t == "full") sm.vertices = 0;
      else if (t.empty() || *end || n < 200 || n > 10000000)
        return usage_error("--sim-vertices '" + t + "': use a vertex count of at least 200, or full");
      else sm.vertices = static_cast<int>(n);
    } else if (a == "--no-estimates") {
      fo.estimate_missing_fdps = false;
    } else if (a == "--no-calibrate") {
      fo.calibrate = false;
    } else if (a == "--muscle-map") {
      muscle_map = value("--muscle-map");
    } else if (a == "--influence") {
      const std::string m = value("--influence");
      influences.emplace_back(m, value("--influence"));
    } else if (a == "--jaw-map") {
      jaw_map = value("--jaw-map");
    } else if (a == "--contract") {
      const std::string c = value("--contract");
      const size_t eq = c.find('=');
      char *end = nullptr;
      const double pct = eq == std::string::npos ? 0 : std::strtod(c.c_str() + eq + 1, &end);
      if (eq == std::string::npos || end == c.c_str() + eq + 1 || *end)
        return usage_error("--contract '" + c + "': use MUSCLE=PERCENT, e.g. zygomaticus_major_left=60");
      contractions.emplace_back(c.substr(0, eq), pct);
    } else if (a == "--jaw") {
      const std::string v = value("--jaw");
      char *end = nullptr;
      jaw_open = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end || jaw_open < 0 || jaw_open > 100)
        return usage_error("--jaw '" + v + "': a percentage 0..100");
    } else if (a == "--pose") {
      pose_png = value("--pose");
    } else if (a == "--list-muscles") {
      list = true;
    } else if (a == "-o") {
      out_path = value("-o");
    } else if (a == "--profile") {
      const std::string p = value("--profile");
      if (p == "draco") profile = AFM_PROFILE_DRACO;
      else if (p == "raw") profile = AFM_PROFILE_RAW;
      else return usage_error("--profile '" + p + "': use draco or raw");
    } else if (a == "--faps") {
      const std::string l = value("--faps");
      size_t at = 0;
      while (at <= l.size()) {
        const size_t comma = std::min(l.find(',', at), l.size());
        const std::string item = l.substr(at, comma - at);
        const bool high = !item.empty() && (item[0] == 'v' || item[0] == 'e');
        char *end = nullptr;
        const long n = std::strtol(item.c_str() + (high ? 1 : 0), &end, 10);
        const bool number = item.size() > (high ? 1u : 0u) && !*end;
        if (high) {
          if (!number || !find_high_level_mapping(item[0] == 'e', static_cast<int>(n)))
            return usage_error("--faps '" + l + "': '" + item + "' is not a viseme v1..v14 or an expression e1..e6");
          (item[0] == 'e' ? so.only_expressions : so.only_visemes).push_back(static_cast<int>(n));
          at = comma + 1;
          continue;
        }
        const FapMapping *m = number ? find_fap_mapping(static_cast<int>(n)) : nullptr;
        if (!m) return usage_error("--faps '" + l + "': '" + item + "' is not a FAP number 3..68");
        if (m->driver == FapDriver::Rigid || m->driver == FapDriver::None)
          return usage_error("--faps: FAP " + item + " has no morph target (--list-faps)");
        so.only.push_back(static_cast<int>(n));
        at = comma + 1;
      }
    } else if (a == "--no-steer") {
      so.steer = false;
    } else if (a == "--report") {
      report_dir = value("--report");
    } else if (a == "--list-faps") {
      list_faps = true;
    } else if (a == "--stats") {
      stats = true;
    } else if (a == "-q" || a == "--quiet") {
      quiet = true;
    } else if (a.size() > 1 && a[0] == '-') {
      return usage_error("unknown option '" + a + "'");
    } else if (mesh_path.empty()) {
      mesh_path = a;
    } else if (fdp_path.empty()) {
      fdp_path = a;
    } else {
      return usage_error("too many arguments");
    }
  }
  if (list) {
    std::printf("%-26s %-9s %-36s %-26s %s\n", "muscle", "kind", "attachment / semi-major end",
                "insertion / semi-minor end", "epicentre");
    for (const MuscleDef &d : muscle_table())
      std::printf("%-26s %-9s %-36s %-26s %s\n", d.name, muscle_kind_name(d.kind),
                  d.attachment_or_major, d.insertion_or_minor, d.epicentre ? d.epicentre : d.kind == MuscleKind::Lid ? "the eyeball's centre" : "-");
    if (mesh_path.empty() && !list_faps) return 0;
  }
  if (list_faps) {
    std::printf("%s", fap_mapping_text().c_str());
    if (mesh_path.empty()) return 0;
  }
  if (mesh_path.empty() || fdp_path.empty()) {
    usage(stderr);
    return 2;
  }
  for (const auto &[name, pct] : contractions) {
    if (find_muscle(name) < 0) return usage_error("--contract: no muscle '" + name + "' (--list-muscles)");
    if (pct < -100 || pct > 100) return usage_error("--contract " + name + ": percent must be within -100..100");
  }
  for (const auto &inf : influences)
    if (find_muscle(inf.first) < 0) return usage_error("--influence: no muscle '" + inf.first + "' (--list-muscles)");
  if (!pose_png.empty() && !fo.calibrate) return usage_error("--pose needs calibrated muscles (drop --no-calibrate)");
  if (!out_path.empty() && !fo.calibrate) return usage_error("-o needs calibrated muscles (drop --no-calibrate)");
  if (!report_dir.empty() && out_path.empty()) return usage_error("--report needs -o");
  // Every output checked before the work: a build takes seconds to minutes.
  {
    std::vector<std::string> files = {out_path, muscle_map, jaw_map, pose_png};
    for (const auto &inf : influences) files.push_back(inf.second);
    for (const std::string &f : files)
      if (!f.empty())
        if (Status s = check_writable(f); !s) return fail(s);
    if (!report_dir.empty())
      if (Status s = check_fillable_directory(report_dir); !s) return fail(s);
  }

  // A subset of targets calibrates only what it poses (each muscle
  // calibrates on its own: the poses are the same).
  if (const CalibrationNeeds need = calibration_needs(so); !need.all && fo.calibrate) {
    fo.calibrate_only = need.muscles;
    for (const auto &c : contractions) fo.calibrate_only.push_back(c.first);
    for (const auto &inf : influences) fo.calibrate_only.push_back(inf.first);
    fo.calibrate_muscles = !fo.calibrate_only.empty();
    fo.calibrate_jaw = need.jaw || jaw_open > 0;
  }

  if (stats) fo.solver.totals = &totals;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> log;
  Expected<LoadedFace> face = load_face(mesh_path, fdp_path, lo, &log);
  for (const std::string &line : log) std::printf("%s\n", line.c_str());
  if (!face) return fail(face.status());

  // The model on the simulation mesh (retried finer if it cannot be built).
  if (!quiet) fo.progress = progress_line;
  int meshes = 0;
  Expected<SimFaceModel> built = build_sim_face_model(face->scene, face->fdps, sm, fo, [&](const SimMesh &m) {
    if (!quiet && meshes++ > 0) end_progress();  // after the failed build's progress
    if (m.decimated)
      std::printf("simulation mesh: %zu of the skin's %lld vertices, %lld triangles%s%s (%.2f s)\n", m.kept.size(),
                  static_cast<long long>(m.binding.corner.rows()), static_cast<long long>(m.F.rows()),
                  !m.mirrored         ? ""
                  : m.unpaired == 0 ? ", mirror-symmetric"
                                    : (", mirror-symmetric but for " + std::to_string(m.unpaired) + " collapses").c_str(),
                  m.short_edges > 0 ? (", " + std::to_string(m.short_edges) + " of the shortest edges collapsed first").c_str()
                                    : "",
                  m.seconds);
  });
  if (!quiet) end_progress();
  if (!built) return fail(built.status().wrap(mesh_path));
  for (const std::string &n : built->notes) std::printf("note: %s\n", n.c_str());
  const SimMesh *sim = &built->sim;
  const Scene &scene = built->scene;
  const FaceModel *model = &built->model;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const SkinModel &t = model->tissue;
  int counts[3] = {0, 0, 0};
  for (const Spring &s : t.springs) counts[static_cast<int>(s.kind)]++;
  std::printf("skin: part '%s', %d vertices, %lld elements, %zu springs (layer %d, connecting %d, crossed %d)\n",
              scene.parts[static_cast<size_t>(model->skin)].name.c_str(), t.n,
              static_cast<long long>(t.F.rows()), t.springs.size(), counts[0], counts[1], counts[2]);
  int free_count = 0;
  for (uint8_t f : t.skull_free) free_count += f;
  std::printf("  tissue thickness %.4g..%.4g, %d vertices not tied to the skull (lips, cheeks, lids)\n",
              t.thickness.minCoeff(), t.thickness.maxCoeff(), free_count);
  for (size_t e = 0; e < t.eyes.size(); ++e) {
    int over = 0;
    for (int8_t k : t.eye_of) over += k == static_cast<int8_t>(e);
    std::printf("  eyeball '%s': radius %.4g, %d skin vertices slide on it (the lids)\n",
                scene.parts[static_cast<size_t>(t.eyes[e].part)].name.c_str(), t.eyes[e].radius, over);
  }
  if (!t.lip_pairs.empty())
    std::printf("  lips: %zu vertex pairs kept from passing into each other in visemes and expressions\n",
                t.lip_pairs.size());
  std::printf("solver: %s, tolerance %.3g (half the AFM quantum %.3g), wave threshold %.3g\n",
              solver_name(model->solver.kind), model->solver.tolerance, model->quantum, model->wave_threshold);
  for (const std::string &n : model->notes) std::printf("note: %s\n", n.c_str());
  for (const std::string &w : model->warnings) std::printf("warning: %s\n", w.c_str());
  std::printf("%-26s %9s %8s %8s %11s %11s\n", "muscle", "length", "area", "V_d", "tension+", "tension-");
  for (const Muscle &m : model->muscles) {
    std::printf("%-26s %9.4g %8zu %8zu", m.name.c_str(), m.kind != MuscleKind::Sphincter ? m.length : m.semi_a,
                m.influence.size(), m.dynamic.size());
    if (m.tension_max > 0 || m.tension_min > 0)
      std::printf(" %11.4g %11.4g\n", m.tension_max, m.tension_min);
    else
      std::printf(" %11s %11s\n", "-", "-");  // not calibrated (--no-calibrate, --faps)
  }
  const Jaw &j = model->jaw;
  std::printf("jaw: %zu skin vertices (%zu ray hits, %d removed and %d added by the mouth-window search), "
              "%zu below and %d beside them follow in part, V_d %zu, pivot (%.4g %.4g %.4g)\n",
              j.vertices.size(), j.ray_hits.size(), j.removed, j.added, j.followers.size() - static_cast<size_t>(j.beside),
              j.beside, j.dynamic.size(), j.pivot.x(),
              j.pivot.y(), j.pivot.z());
  std::printf("built in %.2f s\n", seconds);
  const SolveCounts before = totals.counts();
  if (stats) std::printf("solver work (the model): %s\n", before.text().c_str());

  if (!muscle_map.empty()) {
    if (Status s = render_muscle_map_png(scene, *model, muscle_map); !s) return fail(s);
    std::printf("wrote %s\n", muscle_map.c_str());
  }
  for (const auto &[name, path] : influences) {
    const int i = model->find(name);
    if (i < 0) return fail(Status::error("--influence: muscle " + name + " was skipped (see the warnings)"));
    if (Status s = render_influence_png(scene, *model, i, path); !s) return fail(s);
    std::printf("wrote %s\n", path.c_str());
  }
  if (!jaw_map.empty()) {
    if (Status s = render_jaw_map_png(scene, *model, jaw_map); !s) return fail(s);
    std::printf("wrote %s\n", jaw_map.c_str());
  }
  if (!contractions.empty() || jaw_open > 0) {
    Activation act;
    for (const auto &[name, pct] : contractions) {
      const int i = model->find(name);
      if (i < 0) return fail(Status::error("--contract: muscle " + name + " was skipped (see the warnings)"));
      act.muscles.emplace_back(i, pct);
    }
    act.jaw_open = jaw_open;
    FactorCache cache;
    Expected<Pose> pose = solve_pose(*model, act, &cache);
    if (!pose) return fail(pose.status());
    const Eigen::MatrixXd E = pose_epidermis(*model, *pose);
    double worst = 0;
    int at = 0;
    for (int v = 0; v < t.n; ++v) {
      const double d = (E.row(v) - t.X0.row(v)).norm();
      if (d > worst) worst = d, at = v;
    }
    std::printf("pose: %zu dynamic vertices, %d iterations (%d CG), %.3f s; largest motion %.4g at vertex %d; "
                "slabs of tissue turned through themselves: %zu\n",
                pose->dynamic.size(), pose->stats.iterations, pose->stats.cg_iterations, pose->stats.seconds,
                worst, at, turned_slabs(t, pose->X).size());
    if (!pose_png.empty()) {
      if (Status s = render_pose_png(scene, *model, *pose, jaw_motion(model->jaw, jaw_open, 0, 0), pose_png); !s)
        return fail(s);
      std::printf("wrote %s\n", pose_png.c_str());
    }
  }
  if (!out_path.empty()) {
    const auto t1 = std::chrono::steady_clock::now();
    if (!quiet) so.progress = progress_line;
    so.threads = fo.threads;
    so.sim = sim;
    Expected<FapSynthesis> syn = synthesize_faps(scene, *model, so);
    if (!syn) return fail(syn.status());
    std::printf("%s", fidelity_table(*syn).c_str());
    if (!report_dir.empty()) {
      FidelityReportOptions ro;
      if (!quiet) ro.progress = progress_line;
      const FdpSet fdps = lift_fdps(model->fdps, *sim);  // the model's FDPs on the input's skin
      if (Status st = write_fidelity_report(report_dir, face->scene, fdps, model->skin, *syn, ro); !st) return fail(st);
      std::printf("wrote the fidelity report into %s/ (index.html, sheet.png, report.txt, report.csv)\n",
                  report_dir.c_str());
    }
    AfmContent content = fap_afm_content(face->scene, face->fdps, *model, std::move(*syn));
    content.generator = "afm-build";
    if (Status s = write_afm(out_path, content, profile); !s) return fail(s);
    std::printf("wrote %s (%zu targets, %zu rigid parts) in %.2f s\n", out_path.c_str(), content.targets.size(),
                content.rigids.size(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
  }
  if (stats && (!out_path.empty() || !pose_png.empty() || !contractions.empty() || jaw_open > 0))
    std::printf("solver work (after the model): %s\n", (totals.counts() - before).text().c_str());
  return 0;
}
