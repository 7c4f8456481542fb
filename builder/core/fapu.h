// FAP units from FDP positions, as the MPEG-4 definitions say.
// formats/fdp.md ("FAP units") documents which distance is measured for each
// unit and why; in short, every X0 is a coordinate difference along one axis
// of the MPEG-4 neutral frame (+x the face's own left, +y up, +z forward):
//
//   ES0    = 3.5.x - 3.6.x                      pupil to pupil
//   IRISD0 = mean(3.1.y - 3.3.y, 3.2.y - 3.4.y)  eyelid to eyelid, both eyes
//            (one eye alone when the other's pair is incomplete)
//   ENS0   = (3.5.y + 3.6.y) / 2 - N.y          mid-eye height to nose base
//   MNS0   = N.y - 2.2.y                        nose base to inner upper lip
//   MW0    = 8.3.x - 8.4.x                      mouth corner to mouth corner
//
// where N.y, the height of 9.15 (bottom middle edge of the nose), is taken
// from 9.15 when present, else the mean of 9.4 and 9.5 (the nose's bottom
// edges, level with 9.15), else 9.3.y + (8.1.y - 9.3.y) / 4 (a quarter of
// the way from the nose tip down to the top of the upper lip; measured on the
// Song and Candide-3 heads, see formats/fdp.md).
#pragma once

#include <afm/mpeg4.h>

#include <Eigen/Core>
#include <string>

#include "core/fdp.h"
#include "core/status.h"

namespace afmb {

// Computes the five FAPU distances (model units) from a bound FDP set; the
// first point of each FDP in file order is used. Fails when a point the
// units need is unbound, naming it; when FDPs are missing, naming every
// missing FDP and the unit that needs it ("song.fdp: cannot compute FAPU:
// ES0 needs FDP 3.6; ..."); and when a distance is not positive, which means
// the scene is not in the MPEG-4 frame or the FDPs are misplaced. When
// `notes` is given, one line per fallback used is appended to it
// ("ENS0, MNS0: 9.15 absent, nose base height from 9.3 and 8.1").
Expected<Fapu> compute_fapu(const FdpSet &bound, std::string *notes = nullptr);

// The distance X0 of a FAP unit, model units (one FAP unit is X0 / 1024);
// 0 for AFM_FAPU_AU and AFM_FAPU_NONE.
double fapu_distance(const Fapu &fapu, afm_fapu unit);

// A FAP's direction (translations) or axis (rotations) as a unit vector;
// zero for FAPs without one.
Eigen::Vector3d fap_direction(const afm_fap_info *info);

}  // namespace afmb
