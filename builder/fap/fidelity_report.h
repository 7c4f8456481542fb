// The fidelity report of a FAP synthesis (issue 5, `afm-build --report DIR`):
// per target, the prescribed against the achieved FDP displacement and the
// errors along and off the FAP's direction, with the median and the worst,
// the off-axis error also split into its parts across the face (x, y of the
// MPEG-4 frame: what a frontal view shows) and in depth (z); and a picture
// of every target.
//
// Files written into DIR (created when missing; its parent must exist), each
// atomically:
//   report.txt     the table afm-build prints, and the summary
//   report.csv     the same, one row per attempted target, for scripts
//   targets/*.png  one picture per made target: the face at the target
//                  (reference value), the skin tinted red where it moves
//                  (full red at the target's largest motion); for a FAP,
//                  its FDP at rest (yellow) and where MPEG-4 puts it at the
//                  reference (green); a combination (the lower lip past
//                  its reach with the jaw) as played, with the other lower
//                  lip sides' and FAP 3's at its reference, red where it
//                  adds;
//                  neutral.png is the face at rest
//   sheet.png      a contact sheet of those pictures, neutral first, then in
//                  the table's order (row by row)
//   index.html     the table with the pictures beside each row
#pragma once

#include <functional>
#include <string>

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"
#include "fap/fap_synthesis.h"

namespace afmb {

// A target's name in reports and file names: the FAP's MPEG-4 name ("open_jaw",
// "raise_l_cornerlip (negative)"), "viseme p, b, m", or the expression's.
std::string target_label(const FapOutcome &outcome);

// The table: a line per attempted target, ending in its outcome's message
// where it has one (why it was not made, how far it under-reaches, which
// helpers steered it, what was untangled), then one summary line: targets
// made and not, and over the FAP targets the model solved (solved_fap_target:
// the tongue's and the pupils', and the lower lip's holds and combinations
// past its reach, are listed apart, exact by construction) the
// median and worst error along the direction and off it, and the medians of
// the off-axis parts across the face and in depth. Each FAP side counts once,
// at the table's reference: a held side (fap_synthesis.h, "Reach, then
// hold") by its hold; where there are holds, the off-axis median of the
// targets at the reach, against their own motion, is given apart.
std::string fidelity_table(const FapSynthesis &synthesis);

struct FidelityReportOptions {
  int tile_width = 240, tile_height = 288;  // pixels per picture
  // Called after each picture: done of total (from the calling thread).
  std::function<void(int done, int total, const std::string &what)> progress;
};

// Writes the report of `synthesis` into `dir`. Its targets move `scene`;
// `fdps` are the model's (the input's and its estimates) bound to `scene`,
// and `skin` is the skin's part index. Fails when the directory cannot be
// made or a file written, or a picture cannot be rendered; the message
// names the file.
Status write_fidelity_report(const std::string &dir, const Scene &scene, const FdpSet &fdps, int skin,
                             const FapSynthesis &synthesis, const FidelityReportOptions &options = {});

}  // namespace afmb
