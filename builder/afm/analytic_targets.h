// Analytic stand-in targets: morph targets and rigid parts from closed-form
// displacement fields, for testing players, renderers and the format before
// (and beside) the anatomical builder.
//
// Each low-level FAP with an FDP on the skin gets a smooth bump: every skin
// vertex within radius r of the FDP moves along the FAP's MPEG-4 direction by
//     amplitude * (1 - (d / r)^2)^2,
// with the amplitude chosen so that the FDP itself moves by exactly
// reference x FAPU / 1024: the MPEG-4 semantics hold at the FDP by
// construction. The jaw opens by rotation about a hinge between the ears;
// eyes, jaw and head are RIGD transforms. Visemes and expressions are fixed
// sums of FAP fields. Not anatomy: a known answer for tests.
#pragma once

#include <vector>

#include "afm/afm_export.h"
#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct AnalyticOptions {
  bool normal_deltas = false;     // store normal deltas with each target
  bool negative_targets = true;   // give FAP 31 and 32 (inner brows) a negative-side target
};

struct AnalyticModel {
  std::vector<MorphTarget> targets;
  std::vector<RigidPart> rigids;
};

// `fdps` bound to `scene`; `fapu` from compute_fapu. Parts are found by kind
// (skin, eyes, lower teeth, tongue); missing ones simply get no targets.
Expected<AnalyticModel> make_analytic_model(const Scene &scene, const FdpSet &fdps,
                                            const Fapu &fapu, const AnalyticOptions &options = {});

// The reference head (refhead.h) at `skin_vertices`, with analytic targets,
// encoded as an AFM: the model the player's tests and benchmarks use.
Expected<std::vector<uint8_t>> analytic_reference_afm(int skin_vertices,
                                                      const AnalyticOptions &options = {},
                                                      afm_profile profile = AFM_PROFILE_RAW);

}  // namespace afmb
