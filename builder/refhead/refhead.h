// The reference head: a procedural, plausible human head at any resolution.
//
// The project's own face, for the demo, for tests on a machine without
// ../shared/data, and as the size knob for benchmarks. Parts: skin (with a
// closed mouth slit separating the lips, eye openings, nose, chin, ears), two
// eyeballs, upper and lower teeth, a tongue. It comes with its full FDP set.
// Units are metres, in the MPEG-4 neutral frame.
#pragma once

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct RefHeadOptions {
  int skin_vertices = 10000;  // target skin vertex count, 1000..100000 (met within a few %)
};

struct RefHead {
  Scene scene;
  FdpSet fdps;  // bound to `scene`
};

Expected<RefHead> make_reference_head(const RefHeadOptions &options);

}  // namespace afmb
