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
// Pivot groups: analyze(pattern, 3) eliminates three consecutive nodes at a
// time, as one 9 x 9 block (the tissue's three free nodes of a skin vertex,
// which share their neighbours: every element couples all nine free nodes
// of its three vertices). The ordering is then AMD on the groups, and a
// block of a group's pattern that K lacks (a lip pair couples only the two
// epidermal nodes) is a stored zero. Mathematically the same factorisation,
// a block update being 729 multiply-adds per index step instead of 27.
//
// The algorithm is the up-looking LDL^T of Davis ("Algorithm 849: a concise
// sparse Cholesky factorization package", 2005) with blocks for scalars:
// row k of L solves a sparse triangular system whose pattern is the reach
// of column k's upper part in the elimination tree; then
// L(k, i) = (D_i^-1 Y_i)^T and D_k = K_kk - sum_i L(k, i) Y_i. D_k^-1 comes
// from D_k's Cholesky factor where D_k is positive definite; where it is
// not, D_k's LDL^T (with pivoting) tells indefinite from singular and an LU
// decomposition inverts it.
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

  // Analyses `pattern` (n x n, n = 3 x nodes, both triangles stored, or
  // with upper_only the upper one alone; the entries of each column grouped in
  // full blocks: rows 3i, 3i + 1, 3i + 2
  // one after the other, and columns 3j, 3j + 1, 3j + 2 with the same rows):
  // the fill-reducing order (AMD on the graph of the pivot groups), the
  // elimination tree and the pattern of L. `group`: nodes per pivot block,
  // 1 or 3 (nodes 3g, 3g + 1, 3g + 2 together; see above). Without
  // upper_only the pattern must be symmetric. Returns false, and stays empty, when the pattern is not
  // made of such blocks or the nodes do not divide into groups.
  // `upper_only`: factorize() reads only K's blocks on and above its
  // diagonal in the caller's node order (those below may hold anything),
  // a block below being read as its mirror's transpose.
  bool analyze(const SpMat &pattern, int group = 1, bool upper_only = false);

  // Factorises K, which must have the analysed pattern (the values may be
  // anything, zeros included). Only the blocks on and above the diagonal (in
  // the analysed order, or with upper_only their mirrors above K's own
  // diagonal) are read, so K must be symmetric in them.
  // `stop_if_indefinite`: returns kIndefinite at the first pivot block that
  // is not positive definite, the factors left incomplete, for a caller
  // that only uses a definite factorisation (the solver's full tangent: an
  // indefinite one is thrown away; on Song's AFM that stop skips a fifth of
  // the factorisations' block updates). Without it, or where K is definite,
  // it runs to the end.
  Result factorize(const SpMat &K, bool stop_if_indefinite = false);

  // Whether the last factorize() ran to the end and was not kSingular:
  // solve() and precondition() may be called only then.
  bool complete() const { return complete_; }

  // x = K^-1 b (n each). Only when complete().
  void solve(const Eigen::VectorXd &b, Eigen::VectorXd &x) const;

  // x ~ K^-1 b in single precision, for preconditioning (only when
  // complete()): a float copy of the factors, made by factorize(), L by
  // rows, read in order by both passes: the forward one goes down the rows
  // summing each in registers, the backward one up the rows, subtracting
  // each block transposed (dot products); 3 x 3 blocks padded to 4 x 3, a
  // block times a vector being three 4-wide multiply-adds (9 x 9 blocks are
  // not padded). Half the memory read by solve(). The passes wait on
  // memory, so one copy read in order beats a second by columns or one read
  // by columns (block_ldlt.cpp has the figures).
  void precondition(const Eigen::VectorXd &b, Eigen::VectorXd &x) const;

  // The cost model of the solver's refresh rule, in scalar terms: the
  // multiply-adds of a factorisation (sum over L's scalar columns of their
  // squared lengths) and the nonzeros of the scalar unit lower triangle,
  // stored zeros of the pivot groups' blocks included.
  double factor_flops() const { return factor_flops_; }
  double nonzeros() const { return nonzeros_; }

 private:
  // A 3 x 3 block of K that lands in an upper block of L's column k.
  struct Gather {
    int row;     // block row (pivot group), in the analysed order (<= the column's)
    int dst;     // offset of the 3 x 3 block's first entry in the b x b block (column-major)
    int node;    // K's node whose three scalar columns hold it
    int offset;  // of its first entry within each of those columns
    bool transpose;  // held as its mirror across K's diagonal (analyze's upper_only)
  };
  template <int B> Result factorize_blocks(const SpMat &K, bool stop_if_indefinite);
  template <int B> void solve_blocks(const Eigen::VectorXd &b, Eigen::VectorXd &x) const;
  template <int B> void precondition_blocks(const Eigen::VectorXd &b, Eigen::VectorXd &x) const;

  int b_ = 3;       // scalars per pivot block, 3 x the nodes in it
  bool complete_ = false;  // complete()
  int blocks_ = 0;  // pivot groups
  std::vector<int> order_;     // order_[new] = old group
  std::vector<int> position_;  // position_[old] = new group
  std::vector<std::vector<Gather>> upper_;  // per new column: its blocks on and above the diagonal
  std::vector<int> parent_;    // elimination tree, -1 at a root
  std::vector<int> col_start_;  // L's blocks of column i: col_start_[i] .. col_start_[i + 1] - 1
  std::vector<int> row_;       // per L block: its block row
  // b x b blocks, column-major, one after the other: L's by columns, D^-1 per
  // group, and the work blocks of factorize().
  std::vector<double> l_, d_inverse_, y_;
  std::vector<int> flag_, reach_, stack_, filled_;
  mutable std::vector<double> solve_work_;
  // precondition()'s factors: b columns of float_rows(b) floats per block
  // (block_ldlt.cpp; the rows past b zero).
  std::vector<float> df_;   // per group: d_inverse_
  std::vector<int> row_start_;  // L's blocks by rows: row k's are row_start_[k] .. row_start_[k + 1] - 1
  std::vector<int> rcol_;       // per block by rows: its block column
  std::vector<float> lrf_;      // per block by rows: L(k, rcol_)
  mutable std::vector<float> solve_work_f_;
  double factor_flops_ = 0, nonzeros_ = 0;
};

}  // namespace afmb
