// Mirror symmetry of a skin: which vertex is which one's image in the face's
// mid-plane, the plane x = mid of the MPEG-4 frame (x runs across the face).
//
// Faces are close to symmetric, and so are their muscles: the right ones are
// placed from the mirrored FDPs by the same table rows. The simulation mesh
// keeps a symmetric skin symmetric (sim_mesh.h), and the solves use that: a
// right muscle's calibration starts from its left twin's pose mirrored
// (face_model.h). The mirror is a first guess only; every pose is still
// solved to equilibrium on its own muscles, so an asymmetric face (Song's
// FDPs are a few hundredths off symmetric) gets its own right side.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace afmb {

// Two skin vertices are mirror images when one lies within this many eye
// separations of the other's reflection in the face's mid-plane.
constexpr double kMirrorTolerance = 1e-3;

struct SkinMirror {
  double mid = 0;          // the mid-plane's x, model units
  // Per vertex: the vertex at its image (itself on the mid-plane), or -1.
  // Empty: the skin is not mirror-symmetric.
  std::vector<int> image;
  bool symmetric() const { return !image.empty(); }
};

// For every row of V (#V x 3), the row nearest its reflection in the plane
// x = mid, when within `tolerance` (model units), or -1. Ties go to the
// lower index.
std::vector<int> mirror_vertices(const Eigen::MatrixXd &V, double mid, double tolerance);

// The mirror of the vertices V (#V x 3) whose `used` flag is set (empty: all),
// about the plane x = mid_guess (e.g. between the pupils): symmetric when
// nine in ten of them have an image within `tolerance` (model units); `mid`
// is then the median of the pairs' midpoints. Not symmetric: an empty image
// list. With `neighbours` (the mesh's vertex adjacency), a vertex with
// several candidates within the tolerance (coincident vertices: a seam, the
// corners of a slit) takes the one whose neighbours are the images of most
// of its own; else the nearest (mirror_vertices).
SkinMirror skin_mirror(const Eigen::MatrixXd &V, const std::vector<uint8_t> &used, double mid_guess, double tolerance,
                       const std::vector<std::vector<int>> *neighbours = nullptr);

// A muscle's twin on the other side: "..._left" for "..._right" and back;
// "" for a muscle on the midline.
std::string twin_name(const std::string &muscle);
// Whether a muscle is on the right side ("..._right").
bool right_side(const std::string &muscle);

}  // namespace afmb
