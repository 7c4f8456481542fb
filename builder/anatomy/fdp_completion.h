// Estimating the FDPs the anatomy needs but a face's FDP file lacks.
//
// Real FDP files are partial (Song's has 45 of the 84: no hairline 11.x, no
// eye corners 3.7-3.14, no jaw corners 2.11-2.14, no 9.4-9.7, 9.15, 8.9,
// 8.10). The muscles and the jaw need some of these. Each missing one is
// taken from a template, the FDPs of the 1000-vertex reference head
// (builder/refhead, which has all 84) frozen in fdp_completion.cpp so that
// changes to the generator's mesh leave real faces' estimates alone: an
// affine map is fitted by weighted least squares from the template's FDPs to
// the face's FDPs they share, each weighted by a Gaussian of its
// distance from the missing FDP (30 mm on the reference head) plus a small
// constant (the global fit underneath); the missing FDP's reference position
// is mapped through it, and the result is snapped to the nearest skin vertex.
// The estimate is as good as the face resembles an adult human head up to an
// affine map; tests/anatomy measures it by deleting FDPs that are present.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

// Every FDP the muscles (muscle_table(): the paper's 25 and our drivers) and
// the jaw use.
std::vector<FdpId> anatomy_fdps();

// The template: 82 FDPs (all but 7.1 and 11.5, which are not surface points)
// in metres, in the reference head's frame (formats/fdp.md: y up, z forward).
std::vector<std::pair<FdpId, Eigen::Vector3d>> fdp_template();

// Adds an estimate for each FDP of `wanted` that `fdps` lacks, as a point on
// skin part `skin` (vertex and position set, line 0). Appends one line per
// estimate to `notes` ("FDP 3.7 absent: estimated from the reference head
// (local affine fit to 41 FDPs, rms 2.1): skin vertex 1180"; the rms is the
// weighted residual of the fit, in model units). Fails when fewer
// than 8 FDPs are shared with the reference head. Returns the ids added.
Expected<std::vector<FdpId>> complete_fdps(const Scene &scene, int skin, FdpSet &fdps,
                                           const std::vector<FdpId> &wanted,
                                           std::vector<std::string> *notes);

}  // namespace afmb
