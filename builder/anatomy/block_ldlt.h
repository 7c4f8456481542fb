// The sparse factorisation under the solver (solver.h): K = P^T L D L^T P
// for a symmetric matrix made of 3 x 3 blocks, one block row and column per
// node (its x, y and z), L unit lower triangular in blocks and D block
// diagonal.
//
// Why our own: the tangents are made of full 3 x 3 blocks, and Eigen's
// SimplicialLDLT works entry by entry. Eliminating a node at a time does the
// same arithmetic with a ninth of the index work: on Song's 1,000-vertex
// simulation mesh (8,982 unknowns, both at -O2) a factorisation took 19 ms
// against 50 ms and a solve 0.8 ms against 1.6 ms, with the same fill (the
// ordering is AMD on the nodes). The arithmetic is fixed by the pattern
// alone (no pivoting, no threads), so results are the same on any run.
//
// The algorithm is the up-looking LDL^T of Davis ("Algorithm 849: a concise
// sparse Cholesky factorization package", 2005) with blocks for scalars:
// row k of L solves a sparse triangular system whose pattern is the reach
// of column k's upper part in the elimination tree; then
// L(k, i) = (D_i^-1 Y_i)^T and D_k = K_kk - sum_i L(k, i) Y_i.
//
// Usage (solver.cpp): analyze() once per pattern, factorize() per matrix of
// that pattern, solve() or precondition() as often as needed. Not
// thread-safe (the solves too use work space); copyable.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

namespace afmb {

class BlockLdlt {
 public:
  using SpMat = Eigen::SparseMatrix<double>;  // column-major

  // What factorize() found.
  enum class Result {
    kDefinite,    // every D block positive definite: K is positive definite
    kIndefinite,  // factorised, but K is not positive definite (solves still work)
    kSingular,    // a D block is singular or not finite: nothing to solve with
  };

  // Analyses `pattern` (n x n, n = 3 x nodes, both triangles stored, the
  // entries of each column grouped in full blocks: rows 3i, 3i + 1, 3i + 2
  // one after the other, and columns 3j, 3j + 1, 3j + 2 with the same rows):
  // the nodes' fill-reducing order (AMD on the node graph), the elimination
  // tree and the pattern of L. Returns false, and stays empty, when the
  // pattern is not made of such blocks.
  bool analyze(const SpMat &pattern);

  // Factorises K, which must have the analysed pattern (the values may be
  // anything, zeros included). Only the blocks on and above the diagonal (in
  // the analysed order) are read, so K must be symmetric.
  Result factorize(const SpMat &K);

  // x = K^-1 b (n each). Only after a factorize() that was not kSingular.
  void solve(const Eigen::VectorXd &b, Eigen::VectorXd &x) const;

  // x ~ K^-1 b in single precision, for preconditioning: float copies of
  // the factors, made by factorize(), L by rows for the forward pass and by
  // columns for the backward one, so that both sum in registers (gathers);
  // each 3 x 3 block padded to 4 x 3, a block times a vector being three
  // 4-wide multiply-adds. Two thirds of the memory read by solve(); on
  // Song's AFM their share of the CPU fell from 19.8 to 16.8 % against
  // unpadded blocks scattered by columns (perf, one worker).
  void precondition(const Eigen::VectorXd &b, Eigen::VectorXd &x) const;

  // The cost model of the solver's refresh rule, in scalar terms: the
  // multiply-adds of a factorisation (sum over L's scalar columns of their
  // squared lengths) and the nonzeros of the scalar unit lower triangle.
  double factor_flops() const { return factor_flops_; }
  double nonzeros() const { return nonzeros_; }

 private:
  using M3 = Eigen::Matrix3d;
  struct UpperBlock {
    int row;     // block row, in the analysed order (<= the column's)
    int offset;  // of the block's first entry within each of its column's three scalar columns
  };
  int nodes_ = 0;
  std::vector<int> order_;     // order_[new] = old node
  std::vector<int> position_;  // position_[old] = new node
  std::vector<std::vector<UpperBlock>> upper_;  // per new column: its blocks on and above the diagonal
  std::vector<int> parent_;    // elimination tree, -1 at a root
  std::vector<int> col_start_;  // L's blocks of column i: col_start_[i] .. col_start_[i + 1] - 1
  std::vector<int> row_;       // per L block: its block row
  std::vector<M3, Eigen::aligned_allocator<M3>> l_, d_inverse_;
  // Work space of factorize().
  std::vector<M3, Eigen::aligned_allocator<M3>> y_;
  std::vector<int> flag_, reach_, stack_, filled_;
  mutable std::vector<Eigen::Vector3d> solve_work_;
  // precondition()'s factors: 3 x 3 blocks in the top of 4 x 3 (the last
  // row zero).
  using M43f = Eigen::Matrix<float, 4, 3>;
  using V4f = Eigen::Vector4f;
  std::vector<M43f, Eigen::aligned_allocator<M43f>> lf_;   // per L block (by columns, as l_): its transpose
  std::vector<M43f, Eigen::aligned_allocator<M43f>> df_;   // per node: d_inverse_
  std::vector<int> row_start_;  // L's blocks by rows: row k's are row_start_[k] .. row_start_[k + 1] - 1
  std::vector<int> rcol_;       // per block by rows: its block column
  std::vector<M43f, Eigen::aligned_allocator<M43f>> lrf_;  // per block by rows: L(k, rcol_)
  mutable std::vector<V4f, Eigen::aligned_allocator<V4f>> solve_work_f_;
  double factor_flops_ = 0, nonzeros_ = 0;
};

}  // namespace afmb
