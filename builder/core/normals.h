// Vertex normals of a triangle mesh.
#pragma once

#include <Eigen/Core>

namespace afmb {

// V: #V x 3 positions, F: #F x 3 triangles (counter-clockwise from outside).
// Returns #V x 3 unit normals, each the sum of its triangles' normals
// weighted by their areas; zero rows for vertices no triangle uses (or
// whose triangles cancel).
Eigen::MatrixXd vertex_normals(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F);

}  // namespace afmb
