// The jaw's opening leaves the mouth closed.
//
// MPEG-4 defines FAP 3, open_jaw, as "vertical jaw displacement (does not
// affect mouth opening)" (the FAP table of ISO/IEC 14496-2, as toolkits
// carry it), and the lower lip's FAPs (5, 10, 11, 52, 57, 58) as the lip's
// whole motion, not motion on top of the jaw's. Both implementations in
// ../shared read it so: Candide-3's FAP 3 block moves the chin only (FDPs
// 2.1, 2.11, 2.12), Song's XfaceEd open_jaw region leaves out 2.3's and
// 8.2's vertices; and the real streams send the lip down with the jaw
// (raise_b_midlip at -1.14 to -1.47 times open_jaw, median per file). A jaw
// target that carried the lip lowered it twice: Song's 2.3 went 1.6-1.7
// times the streams' prescription.
//
// So FAP 3's targets keep the lower lip's height. The vertical (y) part of
// their skin motion is scaled per vertex by
//
//     s(v) = 0 on the lower lip,  S(d(v) / band) off it,  S(t) = 3t^2 - 2t^3 (t <= 1), 1 beyond,
//
// d the length of the shortest edge path from the lip (core/edge_paths.h),
// band = kJawLipBand x the path from the lip to the chin's FDP 2.1, so that
// the chin keeps its motion and the FAP its calibration. The lip keeps the
// jaw's motion forward and sideways: the lower teeth, a rigid part of the
// jaw, come forward under it as the condyles glide (jaw.h). The lower lip:
// the vertices of the lower mouth-window search (mouth_lips(): from 2.3,
// the lip and the chin) at or above the outer lower lip line less
// kJawLipMargin of the lip's height (2.3 to 8.2). That line is the
// least-squares parabola y(x) through 8.3, 8.7, 8.2, 8.8 and 8.4 (those the
// face has, at least three), constant beyond the outermost: the polyline
// through them held the lip in a V at 8.2, the chin creased along it, and
// the lip's red, which bulges below it, smeared downward (Song, rendered).
//
// Past the lip's reach (fap_synthesis.cpp): the lower lip's muscles take it
// about 315 FAP units down on Song (5 negative), and a stream may ask for
// more with the jaw open (Xface's fear.fap: -870, with the jaw at 713). So
// each of those six FAPs' negative sides gets, at FAP 3's farthest
// reference R3 (1024), an in-between holding its side's pose (the hold,
// where it holds), and a combination target (formats/afm.md, AFM 1.4)
// gated by FAP 3 at R3: E - H, H that pose and
//
//     E = (1 - s) H + alpha x w x G   (y; z less alpha x w x the teeth's push),
//
// G the height FAP 3's target at R3 gave up here ((1 - s) times its y
// motion), w the FAP's share of the skin the lip's FAPs split
// (fap_partition.h), alpha such that the FDP moves by R3 FAP units. Below
// the lip (s > 0) the side's own motion gives way to the jaw's: taken down
// by both, the skin above Song's chin went past the chin. The combination's
// weight is the in-between's, capped by FAP 3's value / R3: sent with the
// jaw, as the streams send them, the lip goes on as the jaw would have
// carried it, as far as the jaw opens; sent alone, it holds (until AFM 1.4
// the in-between was E itself, and alone at -1024 it carried the lip most
// of the way to the chin, turning 5-19 skin triangles on Song). The push
// that kept FAP 3's target at R3 in front of the lower teeth
// (teeth_clearance.h) goes back the same way, by alpha x w, and E keeps its
// own clearance over the closed teeth: left in, the push took the generated
// 2,000-vertex head's outer lip 5 points further from Xface's fear.fap
// (median distance from the prescription). Played together, FAP 3 at R3
// and the six sides at -R3 are untangled once, the change shared among the
// combinations by w (fap_synthesis.cpp).
//
// The visemes and expressions are whole poses, the lip's motion included:
// their jaw carries the lip as before.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "anatomy/face_model.h"

namespace afmb {

// The share of the path from the lower lip to 2.1 over which the jaw's
// vertical motion comes back in full.
constexpr double kJawLipBand = 0.6;
// How far below the outer lower lip line the held lip reaches, in lip
// heights (2.3 to 8.2).
constexpr double kJawLipMargin = 0.25;

struct JawLipHold {
  std::vector<int> lip;  // the lower lip's skin vertices, sorted
  Eigen::VectorXd share;  // per skin vertex (skin.n), s(v) above, in [0, 1]
};

// Empty (no lip, shares empty) when the face lacks 2.1 on the skin, three of
// the outer lower lip's FDPs or the mouth window's, or no path joins the lip
// to the chin.
JawLipHold jaw_lip_hold(const FaceModel &model);

// D: #n x 3 skin displacement of an open_jaw target; its y column scaled by
// hold.share (nothing when the hold is empty).
void keep_lip_height(const JawLipHold &hold, Eigen::MatrixXd &D);

}  // namespace afmb
