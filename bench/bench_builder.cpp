// Builder benchmarks (issue 4): time to equilibrium per muscle, dynamic sets
// against whole-mesh solves, iterations when the epidermis is 10 times
// stiffer, and the paper's solver beside the default, all in one run.
//
// Usage: bench_builder [SKIN_VERTICES] (default 2000). The Song head runs too
// when ../shared/data is present. Three muscles are calibrated (a linear one
// of the mouth, a small one of the brow, the mouth's sphincter) to keep the
// run short; figures are wall times of one run on a shared machine, so read
// them as ratios.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "anatomy/face_model.h"
#include "io/load_face.h"
#include "refhead/refhead.h"

using namespace afmb;

namespace {

const char *kMuscles[] = {"zygomaticus_major_left", "corrugator_left", "orbicularis_oris"};

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

Expected<FaceModel> build(const Scene &scene, const FdpSet &fdps, const TissueParams &tissue) {
  FaceModelOptions fo;
  fo.tissue = tissue;
  fo.calibrate_only.assign(std::begin(kMuscles), std::end(kMuscles));
  fo.calibrate_jaw = false;
  return build_face_model(scene, fdps, fo);
}

void run(const char *label, const Scene &scene, const FdpSet &fdps) {
  std::printf("-- %s\n", label);
  double t0 = now();
  Expected<FaceModel> m = build(scene, fdps, TissueParams{});
  if (!m) {
    std::printf("build failed: %s\n", m.status().message().c_str());
    std::exit(1);
  }
  std::printf("model (%d skin vertices, 3 muscles calibrated): %.2f s\n", m->tissue.n, now() - t0);
  std::printf("%-24s %9s %9s %7s %6s %9s %9s %7s %8s\n", "muscle (+100 %)", "V_d", "dyn s", "iters",
              "CG", "whole s", "speed-up", "iters", "max diff");
  for (const char *name : kMuscles) {
    Activation a;
    a.muscles = {{m->find(name), 100.0}};
    FactorCache cache;  // fresh: each time includes its factorisation
    Expected<Pose> dyn = solve_pose(*m, a, &cache);
    FactorCache cache2;
    PoseOptions whole;
    whole.whole_mesh = true;
    Expected<Pose> all = solve_pose(*m, a, &cache2, whole);
    if (!dyn || !all) {
      std::printf("%-24s failed: %s\n", name, (!dyn ? dyn : all).status().message().c_str());
      continue;
    }
    const double diff = (pose_epidermis(*m, *dyn) - pose_epidermis(*m, *all)).cwiseAbs().maxCoeff();
    std::printf("%-24s %9zu %9.3f %7d %6d %9.3f %8.1fx %7d %7.2fq\n", name, dyn->dynamic.size(),
                dyn->stats.seconds, dyn->stats.iterations, dyn->stats.cg_iterations, all->stats.seconds,
                all->stats.seconds / dyn->stats.seconds, all->stats.iterations, diff / m->quantum);
  }

  // The paper's scheme and Newton-Jacobi beside the default, on one muscle's
  // set at its calibrated +100 % tension, at two epidermis stiffnesses.
  std::printf("%-16s %10s %8s %8s %10s %8s %8s %8s\n", "solver", "stiffness", "seconds", "iters", "CG", "x10 s",
              "x10 it", "x10 CG");
  const int zi = m->find("zygomaticus_major_left");
  const Muscle &zm = m->muscles[static_cast<size_t>(zi)];
  TissueParams stiff;
  stiff.slab[0].modulus *= 10;
  Expected<FaceModel> ms = build(scene, fdps, stiff);
  if (!ms) {
    std::printf("stiff build failed: %s\n", ms.status().message().c_str());
    return;
  }
  for (SolverKind k : {SolverKind::Newton, SolverKind::ImplicitEuler, SolverKind::NewtonJacobi}) {
    SolveStats st[2];
    for (int s = 0; s < 2; ++s) {
      const FaceModel &fm = s == 0 ? *m : *ms;
      // The same force field on both: the default model's calibrated tension.
      ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F) {
        return muscle_load(fm.tissue, zm, zm.tension_max, X, F);
      };
      Eigen::MatrixXd X = fm.tissue.X0;
      SolverOptions so = fm.solver;
      so.kind = k;
      FactorCache cache;
      st[s] = solve_equilibrium(fm.tissue, zm.dynamic, f, fm.tissue.X0, X, so, &cache);
    }
    std::printf("%-16s %10s %8.3f %8d %10d %8.3f %8d %8d%s\n", solver_name(k), "1 / 10", st[0].seconds,
                st[0].iterations, st[0].cg_iterations, st[1].seconds, st[1].iterations, st[1].cg_iterations,
                st[0].converged && st[1].converged ? "" : "  (did not converge)");
  }
}

}  // namespace

int main(int argc, char **argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 2000;
  RefHeadOptions o;
  o.skin_vertices = n;
  Expected<RefHead> h = make_reference_head(o);
  if (!h) return 1;
  run(("reference head, " + std::to_string(n) + " skin vertices").c_str(), h->scene, h->fdps);
  const char *shared = std::getenv("AFM_SHARED_DIR");
  const std::string dir = std::string(shared ? shared : AFM_SOURCE_DIR "/../shared") + "/data/faces/song/";
  LoadOptions lo;
  lo.flip_v = true;
  Expected<LoadedFace> song = load_face(dir + "song.WRL", dir + "song.fdp", lo, nullptr);
  if (song) run("Song head", song->scene, song->fdps);
  else std::printf("-- Song head: skipped (%s)\n", song.status().message().c_str());
  return 0;
}
