// The reference head: a procedural, plausible human head at any resolution.
//
// The project's own face, for the demo, for tests on a machine without
// ../shared/data, and as the size knob for benchmarks. Parts (name, kind):
//   skin (Skin): head and neck, open at the neck's end, with a closed mouth
//     slit (the upper and lower lips' vertices are distinct along it, in
//     contact, curled a little into the mouth) and two almond eye openings
//     whose lid margins rest on the eyeballs, tangent to the irises;
//     per-vertex colours (skin, lips, brows, nostrils, short hair painted on
//     the scalp) and a cylindrical UV map with its seam at the back;
//   eye_left (EyeLeft, at +x), eye_right (EyeRight): spheres looking along
//     +z, coloured pupil, iris, limbus and sclera;
//   teeth_upper (TeethUpper), teeth_lower (TeethLower): dental arches
//     touching edge to edge behind the lips;
//   tongue (Tongue): in the lower arch.
// Units are metres, in the MPEG-4 neutral frame (+x the face's own left, +y
// up, +z gaze), origin between the pupils. Adult proportions; the FAP units
// come out the same at every resolution: ES0 63 mm, IRISD0 11.8 mm, ENS0
// 39.5 mm, MNS0 20.5 mm, MW0 about 50.5 mm (core/fapu.h's definitions).
//
// The same options give bit-identical output. The skin is symmetric in x,
// vertex for vertex, and its vertices run row by row from the neck up.
//
// FDPs: all 84 of the standard, each once, bound to the scene:
//   - on the skin unless noted; 3.5 / 3.6 the front poles of the eyeballs;
//     6.1-6.4 on the tongue (tip, middle of the top, left and right border);
//     9.8 / 9.10 on the upper teeth (gum side and incisal edge, front
//     middle), 9.11 / 9.9 on the lower teeth (edge and gum side);
//     7.1 (top of the spine) a free point inside the neck;
//   - 2.2 / 2.3 the upper and lower copies of the slit's middle vertex
//     (same position, different vertices); 2.4 / 2.5 the slit's ends, which
//     are also 8.3 / 8.4; 2.6 and 2.8 (2.7 and 2.9) halfway toward 2.4 (2.5),
//     on the left (right) as the standard's FAP table and figure have it;
//   - 3.1 / 3.3 (3.2 / 3.4) the lid margins above and below the pupil,
//     3.7 / 3.11 (3.12 / 3.8) the eye openings' outer and inner corners;
//   - 9.15 on a row of vertices placed on the subnasale;
//   - 11.1-11.3 on the painted hairline; 11.5 (hair thickness over 11.4) is
//     the vertex of 11.4, as the head has no hair part.
#pragma once

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct RefHeadOptions {
  int skin_vertices = 10000;  // target skin vertex count, 1000..100000 (met within about 2 %)
};

struct RefHead {
  Scene scene;
  FdpSet fdps;  // bound to `scene`
};

// Fails only for a skin_vertices outside 1000..100000.
Expected<RefHead> make_reference_head(const RefHeadOptions &options);

}  // namespace afmb
