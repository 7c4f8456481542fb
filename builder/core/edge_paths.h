// Distances along a mesh's edges (Dijkstra), for weights that follow the
// surface: the lips are far apart across the mouth even where they touch.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <vector>

namespace afmb {

// Vertex adjacency of the triangles F (#F x 3) over n vertices: per vertex,
// its neighbours, sorted and unique.
std::vector<std::vector<int>> vertex_neighbours(const Eigen::MatrixXi &F, int n);

// X: at least #V x 3 positions; neighbours: #V lists (vertex_neighbours()). Returns #V
// lengths of the shortest edge paths from the nearest of `sources`
// (distance 0), infinity where no path shorter than `limit` reaches. A path
// enters a vertex only where `enter` says so (empty: everywhere; sources
// are always in).
std::vector<double> edge_path_distances(const Eigen::MatrixXd &X, const std::vector<std::vector<int>> &neighbours,
                                        const std::vector<int> &sources,
                                        double limit = std::numeric_limits<double>::infinity(),
                                        const std::function<bool(int)> &enter = {});

}  // namespace afmb
