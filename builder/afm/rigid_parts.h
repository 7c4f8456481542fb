// The rigid parts every AFM builder shares: the eyeballs (FAPs 23-28) and the
// head (FAPs 48-50), as RigidPart controls (afm_export.h).
#pragma once

#include <vector>

#include "afm/afm_export.h"
#include "core/fdp.h"
#include "core/scene.h"

namespace afmb {

// Eyes: each eye part (PartKind::EyeLeft / EyeRight) turns about its
// vertices' centroid, yaw and pitch by the FAP's axis and sign (AU), thrust
// along z (ES units); a scene without eye parts gets none. Head: every part
// turns about the top of the spine (FDP 7.1), else half ES0 below the skin's
// centroid. `fdps` bound to `scene`; `skin` its skin part.
std::vector<RigidPart> eye_and_head_rigids(const Scene &scene, const FdpSet &fdps, const Fapu &fapu, int skin);

}  // namespace afmb
