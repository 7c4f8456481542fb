#include "anatomy/block_ldlt.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/OrderingMethods>
#include <algorithm>

namespace afmb {

bool BlockLdlt::analyze(const SpMat &pattern) {
  *this = BlockLdlt();
  const Eigen::Index n = pattern.rows();
  if (n != pattern.cols() || n % 3 != 0 || !pattern.isCompressed()) return false;
  const int nodes = static_cast<int>(n / 3);
  const int *outer = pattern.outerIndexPtr(), *inner = pattern.innerIndexPtr();
  // The node graph, checking the block layout on the way.
  std::vector<Eigen::Triplet<double>> graph;
  for (int j = 0; j < nodes; ++j) {
    const int begin = outer[3 * j], count = outer[3 * j + 1] - begin;
    if (count % 3 != 0) return false;
    for (int c = 1; c < 3; ++c)
      if (outer[3 * j + c + 1] - outer[3 * j + c] != count ||
          !std::equal(inner + begin, inner + begin + count, inner + outer[3 * j + c]))
        return false;
    for (int p = 0; p < count; p += 3) {
      const int r = inner[begin + p];
      if (r % 3 != 0 || inner[begin + p + 1] != r + 1 || inner[begin + p + 2] != r + 2) return false;
      graph.emplace_back(r / 3, j, 1.0);
    }
  }
  SpMat g(nodes, nodes);
  g.setFromTriplets(graph.begin(), graph.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> amd;
  Eigen::AMDOrdering<int>()(g, amd);
  nodes_ = nodes;
  order_.assign(amd.indices().data(), amd.indices().data() + nodes);
  position_.assign(static_cast<size_t>(nodes), 0);
  for (int k = 0; k < nodes; ++k) position_[static_cast<size_t>(order_[static_cast<size_t>(k)])] = k;

  upper_.assign(static_cast<size_t>(nodes), {});
  for (int k = 0; k < nodes; ++k) {
    const int old = order_[static_cast<size_t>(k)], begin = outer[3 * old];
    std::vector<UpperBlock> &u = upper_[static_cast<size_t>(k)];
    for (int p = begin; p < outer[3 * old + 1]; p += 3) {
      const int i = position_[static_cast<size_t>(inner[p] / 3)];
      if (i <= k) u.push_back({i, p - begin});
    }
    std::sort(u.begin(), u.end(), [](const UpperBlock &a, const UpperBlock &b) { return a.row < b.row; });
  }
  // The elimination tree (Liu's algorithm, with path compression).
  parent_.assign(static_cast<size_t>(nodes), -1);
  std::vector<int> ancestor(static_cast<size_t>(nodes), -1);
  for (int k = 0; k < nodes; ++k)
    for (const UpperBlock &b : upper_[static_cast<size_t>(k)])
      for (int i = b.row; i != -1 && i < k;) {
        const int next = ancestor[static_cast<size_t>(i)];
        ancestor[static_cast<size_t>(i)] = k;
        if (next == -1) parent_[static_cast<size_t>(i)] = k;
        i = next;
      }
  // L's column counts: row k of L is the reach of column k's upper part.
  flag_.assign(static_cast<size_t>(nodes), -1);
  std::vector<int> count(static_cast<size_t>(nodes), 0);
  row_start_.assign(static_cast<size_t>(nodes) + 1, 0);
  for (int k = 0; k < nodes; ++k) {
    flag_[static_cast<size_t>(k)] = k;
    int in_row = 0;
    for (const UpperBlock &b : upper_[static_cast<size_t>(k)])
      for (int i = b.row; flag_[static_cast<size_t>(i)] != k; i = parent_[static_cast<size_t>(i)]) {
        ++count[static_cast<size_t>(i)];
        ++in_row;
        flag_[static_cast<size_t>(i)] = k;
      }
    row_start_[static_cast<size_t>(k) + 1] = row_start_[static_cast<size_t>(k)] + in_row;
  }
  col_start_.assign(static_cast<size_t>(nodes) + 1, 0);
  for (int i = 0; i < nodes; ++i) {
    const double c = count[static_cast<size_t>(i)];
    col_start_[static_cast<size_t>(i) + 1] = col_start_[static_cast<size_t>(i)] + count[static_cast<size_t>(i)];
    // Scalar column 3i + t holds 3c entries below the block and 2 - t in it.
    for (int t = 0; t < 3; ++t) factor_flops_ += (3 * c + 2 - t) * (3 * c + 2 - t);
    nonzeros_ += 9 * c + 3;
  }
  const size_t blocks = static_cast<size_t>(col_start_.back());
  row_.assign(blocks, 0);
  l_.assign(blocks, M3::Zero());
  d_inverse_.assign(static_cast<size_t>(nodes), M3::Zero());
  y_.assign(static_cast<size_t>(nodes), M3::Zero());
  reach_.assign(static_cast<size_t>(nodes), 0);
  stack_.assign(static_cast<size_t>(nodes), 0);
  filled_.assign(static_cast<size_t>(nodes), 0);
  return true;
}

BlockLdlt::Result BlockLdlt::factorize(const SpMat &K) {
  const int *outer = K.outerIndexPtr();
  const double *val = K.valuePtr();
  std::fill(flag_.begin(), flag_.end(), -1);
  std::fill(filled_.begin(), filled_.end(), 0);
  lrf_.resize(static_cast<size_t>(row_start_.back()));
  rcol_.resize(static_cast<size_t>(row_start_.back()));
  bool definite = true;
  for (int k = 0; k < nodes_; ++k) {
    const int old = order_[static_cast<size_t>(k)];
    M3 dk = M3::Zero();
    // Scatter column k's upper blocks into y and find the reach (the
    // pattern of row k of L) in topological order.
    int top = nodes_;
    flag_[static_cast<size_t>(k)] = k;
    for (const UpperBlock &b : upper_[static_cast<size_t>(k)]) {
      M3 &dst = b.row == k ? dk : y_[static_cast<size_t>(b.row)];
      for (int c = 0; c < 3; ++c) dst.col(c) = Eigen::Map<const Eigen::Vector3d>(val + outer[3 * old + c] + b.offset);
      if (b.row == k) continue;
      int len = 0;
      for (int i = b.row; flag_[static_cast<size_t>(i)] != k; i = parent_[static_cast<size_t>(i)]) {
        stack_[static_cast<size_t>(len++)] = i;
        flag_[static_cast<size_t>(i)] = k;
      }
      while (len > 0) reach_[static_cast<size_t>(--top)] = stack_[static_cast<size_t>(--len)];
    }
    // Row k of L, and D_k.
    for (int p = top; p < nodes_; ++p) {
      const size_t i = static_cast<size_t>(reach_[static_cast<size_t>(p)]);
      const M3 yi = y_[i];
      y_[i].setZero();
      const int end = col_start_[i] + filled_[i];
      for (int q = col_start_[i]; q < end; ++q)
        y_[static_cast<size_t>(row_[static_cast<size_t>(q)])].noalias() -= l_[static_cast<size_t>(q)] * yi;
      const M3 lki = (d_inverse_[i] * yi).transpose();
      dk.noalias() -= lki * yi;
      row_[static_cast<size_t>(end)] = k;
      l_[static_cast<size_t>(end)] = lki;
      const size_t slot = static_cast<size_t>(row_start_[static_cast<size_t>(k)] + (p - top));
      lrf_[slot].setZero();
      lrf_[slot].topRows<3>() = lki.cast<float>();
      rcol_[slot] = static_cast<int>(i);
      ++filled_[i];
    }
    const Eigen::LDLT<M3> pivots(dk);
    const Eigen::Vector3d d = pivots.vectorD();
    if (!d.allFinite() || !(d.array().abs() > 0).all()) return Result::kSingular;
    definite = definite && (d.array() > 0).all();
    d_inverse_[static_cast<size_t>(k)] = dk.inverse();
    if (!d_inverse_[static_cast<size_t>(k)].allFinite()) return Result::kSingular;
  }
  lf_.resize(l_.size());
  for (size_t q = 0; q < l_.size(); ++q) {
    lf_[q].setZero();
    lf_[q].topRows<3>() = l_[q].transpose().cast<float>();
  }
  df_.resize(d_inverse_.size());
  for (size_t q = 0; q < d_inverse_.size(); ++q) {
    df_[q].setZero();
    df_[q].topRows<3>() = d_inverse_[q].cast<float>();
  }
  return definite ? Result::kDefinite : Result::kIndefinite;
}

// x = P^T L^-T D^-1 L^-1 P b.
void BlockLdlt::solve(const Eigen::VectorXd &b, Eigen::VectorXd &x) const {
  std::vector<Eigen::Vector3d> &z = solve_work_;
  const size_t n = order_.size();
  z.resize(n);
  for (size_t i = 0; i < n; ++i) z[i] = b.segment<3>(3 * order_[i]);
  for (size_t i = 0; i < n; ++i)
    for (int q = col_start_[i]; q < col_start_[i + 1]; ++q)
      z[static_cast<size_t>(row_[static_cast<size_t>(q)])].noalias() -= l_[static_cast<size_t>(q)] * z[i];
  for (size_t i = 0; i < n; ++i) z[i] = d_inverse_[i] * z[i];
  for (size_t i = n; i-- > 0;)
    for (int q = col_start_[i]; q < col_start_[i + 1]; ++q)
      z[i].noalias() -= l_[static_cast<size_t>(q)].transpose() * z[static_cast<size_t>(row_[static_cast<size_t>(q)])];
  x.resize(b.size());
  for (size_t i = 0; i < n; ++i) x.segment<3>(3 * order_[i]) = z[i];
}

// As solve(), in single precision.
void BlockLdlt::precondition(const Eigen::VectorXd &b, Eigen::VectorXd &x) const {
  std::vector<V4f, Eigen::aligned_allocator<V4f>> &z = solve_work_f_;
  const size_t n = order_.size();
  z.resize(n);
  // Forward by rows: row k's sum stays in a register, where a pass by
  // columns would read and write z once per block.
  for (size_t k = 0; k < n; ++k) {
    V4f acc(static_cast<float>(b[3 * order_[k]]), static_cast<float>(b[3 * order_[k] + 1]),
            static_cast<float>(b[3 * order_[k] + 2]), 0.f);
    for (int e = row_start_[k]; e < row_start_[k + 1]; ++e) {
      const M43f &l = lrf_[static_cast<size_t>(e)];
      const V4f &zi = z[static_cast<size_t>(rcol_[static_cast<size_t>(e)])];
      acc -= l.col(0) * zi[0] + l.col(1) * zi[1] + l.col(2) * zi[2];
    }
    z[k] = acc;
  }
  for (size_t i = 0; i < n; ++i) {
    const V4f zi = z[i];
    z[i] = df_[i].col(0) * zi[0] + df_[i].col(1) * zi[1] + df_[i].col(2) * zi[2];
  }
  for (size_t i = n; i-- > 0;) {
    V4f acc = z[i];
    for (int q = col_start_[i]; q < col_start_[i + 1]; ++q) {
      const M43f &l = lf_[static_cast<size_t>(q)];
      const V4f &zq = z[static_cast<size_t>(row_[static_cast<size_t>(q)])];
      acc -= l.col(0) * zq[0] + l.col(1) * zq[1] + l.col(2) * zq[2];
    }
    z[i] = acc;
  }
  x.resize(b.size());
  for (size_t i = 0; i < n; ++i) x.segment<3>(3 * order_[i]) = z[i].head<3>().cast<double>();
}

}  // namespace afmb
