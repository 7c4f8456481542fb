// Pictures of the anatomical model, for people to look at: the muscle map
// (method paper Figure 5), a muscle's influence area and elastic-wave nodes
// (Figure 7), the jaw mapping (Figure 6), and posed faces.
//
// Each writes one PNG (atomically) with a front view and, unless
// `front_only`, a three-quarter view beside it, framed on the face.
#pragma once

#include <string>

#include "anatomy/face_model.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct AnatomyPictureOptions {
  int width = 600, height = 720;  // of each view, pixels
  bool front_only = false;
};

// Figure 5: the skin shaded, the other parts as they are; for every linear
// muscle its attachment (green dot) and insertion (red dot) nodes joined by
// its fibre (a white line); for every sphincter its key-point ellipse (white)
// around its epicentre and its semi-axis nodes (red).
Status render_muscle_map_png(const Scene &scene, const FaceModel &model, const std::string &path,
                             const AnatomyPictureOptions &options = {});

// Figure 7: muscle `muscle` (index into model.muscles): its influence area's
// skin vertices red, the other vertices of its dynamic set V_d green, its
// fibre or ellipse as in the muscle map.
Status render_influence_png(const Scene &scene, const FaceModel &model, int muscle,
                            const std::string &path, const AnatomyPictureOptions &options = {});

// The jaw: skin vertices carried by the jaw blue-violet (those the segments
// hit and the breadth-first fix kept), vertices the fix added cyan, ray hits
// it removed orange; its followers (Jaw::followers) blue-violet blended
// into the skin tone by their share; the jaw mesh's edges (white) and its
// pivot (yellow); the lips' contact pairs (SkinModel::lip_pairs) as magenta
// dots.
Status render_jaw_map_png(const Scene &scene, const FaceModel &model, const std::string &path,
                          const AnatomyPictureOptions &options = {});

// The face in a pose: the skin at the pose's epidermis in the skin tone, red
// over the slabs of tissue the pose turns through itself (turned_slabs,
// skin_model.h: the corners of their triangles), the lower teeth and tongue
// moved by the jaw motion `jaw` (identity when the jaw is at rest).
Status render_pose_png(const Scene &scene, const FaceModel &model, const Pose &pose,
                       const Eigen::Affine3d &jaw, const std::string &path,
                       const AnatomyPictureOptions &options = {});

}  // namespace afmb
