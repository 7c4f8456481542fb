// What each part of a scene is: a guess from names, then the FDPs' word.
#pragma once

#include <string_view>

#include "core/fdp.h"
#include "core/scene.h"

namespace afmb {

// Guesses a part's kind from one name. The name is split into lower-case words
// at every non-alphanumeric character, letter/digit boundary and lower/upper
// case change ("song_eyeball_left" -> song eyeball left, "LeftEye2" -> left eye
// 2), and the first rule that matches wins:
//   eyelid, lid, eyelash, lash, eyebrow, brow, eyeblow (+plurals)   -> Eyelid
//   eye, eyeball, pupil, iris, cornea (+plurals) with left/l/lt     -> EyeLeft
//                                             with right/r/rt       -> EyeRight
//                                             with neither          -> Other
//   teeth, tooth, dentures with upper/up/top/maxilla                -> TeethUpper
//                          with lower/low/bottom/bot/mandible/jaw   -> TeethLower
//                          with neither                             -> Other
//   tongue                                                          -> Tongue
//   hair, hairs                                                     -> Hair
//   throat, mouth, cavity, palate, gum, gums                        -> Mouth
//   head, face, skin                                                -> Skin
// "left"/"right" are the face's own sides, as in MPEG-4 (FDP 3.5 is the left
// pupil). A Skin guess is only a hint: assign_part_kinds() replaces it with the
// part that holds the chin and lip FDPs.
PartKind guess_part_kind(std::string_view name);

// guess_part_kind() on the part's name, then on each alias while the result is
// still Other (so "song_head" decides before "song_head-FACES").
PartKind guess_part_kind(const Part &part);

// Sets every part's kind from its names (guess_part_kind).
void guess_part_kinds(Scene &scene);

// The kind of part an FDP lies on in MPEG-4's list: 3.5 EyeLeft, 3.6
// EyeRight, 6.1-6.4 Tongue, 9.8 and 9.10 TeethUpper, 9.9 and 9.11
// TeethLower, every other one Skin (7.1, the top of the spine, too: no part
// holds it). 2.1 is also on the lower teeth in Song's file; Skin here.
PartKind fdp_part_kind(FdpId id);

// Corrects the kinds with a bound FDP set:
//   Skin:  the part holding FDP 2.1 (chin) with the most FDPs of groups 2, 4,
//          5, 8 and 9 (Song has 2.1 on the head and on the lower teeth);
//          any other part guessed Skin becomes Other;
//   EyeLeft / EyeRight: a non-skin part holding 3.5 / 3.6;
//   Tongue: a non-skin part holding a 6.x FDP.
// Parts no FDP speaks for keep their guessed kind. Unbound points (part < 0 or
// out of range) are ignored.
void assign_part_kinds(Scene &scene, const FdpSet &bound);

}  // namespace afmb
