#include "anatomy/block_ldlt.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>

namespace afmb {

namespace {

template <int B>
using MatB = Eigen::Matrix<double, B, B>;
template <int B>
using MapB = Eigen::Map<MatB<B>>;
template <int B>
using ConstMapB = Eigen::Map<const MatB<B>>;

// The float copies' column length for b x b blocks: a 3 x 3 block's
// columns padded to 4 (a block times a vector is three 4-wide
// multiply-adds), a 9 x 9 block's left at 9 (padded to 12 they are a third
// more memory to read, and the solves are then memory-bound: Song's AFM took
// 6 % more CPU).
constexpr int float_rows(int b) { return b == 3 ? 4 : b; }

// acc -= M z: M is b columns of P floats, z has at least b.
template <int B, int P>
inline void subtract_product(float *acc, const float *M, const float *z) {
  for (int c = 0; c < B; ++c) {
    const float s = z[c];
    for (int r = 0; r < P; ++r) acc[r] -= M[c * P + r] * s;
  }
}

// y -= M^T x: M is b columns of P floats, x has at least b; entry c of
// M^T x is column c of M dotted with x.
template <int B, int P>
inline void subtract_transposed_product(float *y, const float *M, const float *x) {
  for (int c = 0; c < B; ++c) {
    float s = 0;
    for (int r = 0; r < B; ++r) s += M[c * P + r] * x[r];
    y[c] -= s;
  }
}

// out = M z: M is b columns of P floats, z has at least b.
template <int B, int P>
inline void product(float *out, const float *M, const float *z) {
  for (int r = 0; r < P; ++r) out[r] = M[r] * z[0];
  for (int c = 1; c < B; ++c)
    for (int r = 0; r < P; ++r) out[r] += M[c * P + r] * z[c];
}

// The float copy of a b x b block M as b columns of P.
template <int B, int P>
inline void to_float(const double *M, float *out) {
  for (int c = 0; c < B; ++c) {
    for (int r = 0; r < B; ++r) out[c * P + r] = static_cast<float>(M[c * B + r]);
    for (int r = B; r < P; ++r) out[c * P + r] = 0.f;
  }
}

// The hot loops of 9 x 9 blocks are compiled twice, for AVX2 and for the
// baseline, and the CPU picks one when the program loads (GCC's
// target_clones). Each entry is the same sequence of multiplies and adds at
// any vector width (no fused multiply-add: the "avx2" target does not
// include FMA), so both give the same bits: Song's AFM built with
// AFM_NO_KERNEL_CLONES is byte for byte the same file.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(AFM_NO_KERNEL_CLONES)
#define AFM_KERNEL_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define AFM_KERNEL_CLONES
#endif
// y[rows[q]] -= L_q Y for q < count: 9 x 9 blocks, column-major (the
// factorisation's inner loop). A column of the result is summed in
// registers; __restrict lets the compiler vectorise it.
AFM_KERNEL_CLONES void column_update9(double *__restrict y, const int *__restrict rows, const double *__restrict L,
                                         int count, const double *__restrict Y) {
  for (int q = 0; q < count; ++q) {
    double *__restrict C = y + static_cast<size_t>(rows[q]) * 81;
    const double *__restrict A = L + static_cast<size_t>(q) * 81;
    for (int j = 0; j < 9; ++j) {
      double c[9];
      for (int i = 0; i < 9; ++i) c[i] = C[j * 9 + i];
      for (int k = 0; k < 9; ++k) {
        const double s = Y[j * 9 + k];
        for (int i = 0; i < 9; ++i) c[i] -= A[k * 9 + i] * s;
      }
      for (int i = 0; i < 9; ++i) C[j * 9 + i] = c[i];
    }
  }
}

template <int B>
void column_update(double *y, const int *rows, const double *L, int count, const double *Y) {
  if constexpr (B == 9) {
    column_update9(y, rows, L, count, Y);
  } else {
    const Eigen::Map<const MatB<B>> Ym(Y);
    for (int q = 0; q < count; ++q)
      MapB<B>(y + static_cast<size_t>(rows[q]) * B * B).noalias() -= ConstMapB<B>(L + static_cast<size_t>(q) * B * B) * Ym;
  }
}

// The inverse of a pivot block A (symmetric; its lower triangle is read)
// into `inv` when A is positive definite: A = C C^T (Cholesky), W = C^-1,
// A^-1 = W^T W, in plain loops. Eigen's LDLT (for D's signs) and its LU
// inverse did the same for every pivot through their general machinery:
// 3.7 % of the instructions of Song's AFM, these loops about 0.8 %. False
// when a pivot of C is not positive (A not definite, or singular): the
// caller then classifies A by its LDLT and inverts it by LU.
template <int B>
bool definite_inverse(const MatB<B> &A, MapB<B> &inv) {
  double C[B][B] = {}, W[B][B] = {};  // [row][column], lower triangles
  for (int j = 0; j < B; ++j) {
    double s = A(j, j);
    for (int k = 0; k < j; ++k) s -= C[j][k] * C[j][k];
    if (!(s > 0) || !std::isfinite(s)) return false;
    C[j][j] = std::sqrt(s);
    W[j][j] = 1.0 / C[j][j];
    for (int i = j + 1; i < B; ++i) {
      double t = A(i, j);
      for (int k = 0; k < j; ++k) t -= C[i][k] * C[j][k];
      C[i][j] = t * W[j][j];
    }
  }
  for (int j = 0; j < B; ++j)
    for (int i = j + 1; i < B; ++i) {
      double t = 0;
      for (int k = j; k < i; ++k) t -= C[i][k] * W[k][j];
      W[i][j] = t * W[i][i];
    }
  for (int c = 0; c < B; ++c)
    for (int r = c; r < B; ++r) {
      double t = 0;
      for (int k = r; k < B; ++k) t += W[k][r] * W[k][c];
      inv(r, c) = t;
      inv(c, r) = t;
    }
  return inv.allFinite();
}

}  // namespace

bool BlockLdlt::analyze(const SpMat &pattern, int group, bool upper_only) {
  *this = BlockLdlt();
  const Eigen::Index n = pattern.rows();
  if (n != pattern.cols() || n % 3 != 0 || !pattern.isCompressed() || (group != 1 && group != 3)) return false;
  const int nodes = static_cast<int>(n / 3);
  if (nodes % group != 0) return false;
  const int groups = nodes / group;
  const int *outer = pattern.outerIndexPtr(), *inner = pattern.innerIndexPtr();
  // Each node's blocks (node, r) as where K holds them, checking the block
  // layout on the way: stored in the node's column, or, with upper_only,
  // for r > node, as the mirror (r's column, row node) transposed. Blocks
  // stored below the diagonal are then skipped, so a pattern of both
  // triangles or of the upper one alone will do.
  struct Source {
    int other, node, offset;
    bool transpose;
  };
  std::vector<std::vector<Source>> blocks_of(static_cast<size_t>(nodes));
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
      if (upper_only && r / 3 > j) continue;
      blocks_of[static_cast<size_t>(j)].push_back({r / 3, j, p, false});
      if (upper_only && r / 3 < j) blocks_of[static_cast<size_t>(r / 3)].push_back({j, j, p, true});
    }
  }
  // The groups' graph.
  std::vector<Eigen::Triplet<double>> graph;
  for (int j = 0; j < nodes; ++j)
    for (const Source &b : blocks_of[static_cast<size_t>(j)]) graph.emplace_back(b.other / group, j / group, 1.0);
  SpMat g(groups, groups);
  g.setFromTriplets(graph.begin(), graph.end());  // repeats summed: the pattern is what counts
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> amd;
  Eigen::AMDOrdering<int>()(g, amd);
  b_ = 3 * group;
  blocks_ = groups;
  order_.assign(amd.indices().data(), amd.indices().data() + groups);
  position_.assign(static_cast<size_t>(groups), 0);
  for (int k = 0; k < groups; ++k) position_[static_cast<size_t>(order_[static_cast<size_t>(k)])] = k;

  upper_.assign(static_cast<size_t>(groups), {});
  for (int k = 0; k < groups; ++k) {
    std::vector<Gather> &u = upper_[static_cast<size_t>(k)];
    for (int cc = 0; cc < group; ++cc) {
      const int node = order_[static_cast<size_t>(k)] * group + cc;
      for (const Source &b : blocks_of[static_cast<size_t>(node)]) {
        const int i = position_[static_cast<size_t>(b.other / group)];
        if (i <= k)
          u.push_back({i, 3 * cc * b_ + 3 * (b.other % group), b.node, b.offset, b.transpose});
      }
    }
    std::sort(u.begin(), u.end(), [](const Gather &a, const Gather &b) { return a.row < b.row || (a.row == b.row && a.dst < b.dst); });
  }
  // The elimination tree (Liu's algorithm, with path compression).
  parent_.assign(static_cast<size_t>(groups), -1);
  std::vector<int> ancestor(static_cast<size_t>(groups), -1);
  for (int k = 0; k < groups; ++k)
    for (const Gather &b : upper_[static_cast<size_t>(k)])
      for (int i = b.row; i != -1 && i < k;) {
        const int next = ancestor[static_cast<size_t>(i)];
        ancestor[static_cast<size_t>(i)] = k;
        if (next == -1) parent_[static_cast<size_t>(i)] = k;
        i = next;
      }
  // L's column counts: row k of L is the reach of column k's upper part.
  flag_.assign(static_cast<size_t>(groups), -1);
  std::vector<int> count(static_cast<size_t>(groups), 0);
  row_start_.assign(static_cast<size_t>(groups) + 1, 0);
  for (int k = 0; k < groups; ++k) {
    flag_[static_cast<size_t>(k)] = k;
    int in_row = 0;
    for (const Gather &b : upper_[static_cast<size_t>(k)])
      for (int i = b.row; flag_[static_cast<size_t>(i)] != k; i = parent_[static_cast<size_t>(i)]) {
        ++count[static_cast<size_t>(i)];
        ++in_row;
        flag_[static_cast<size_t>(i)] = k;
      }
    row_start_[static_cast<size_t>(k) + 1] = row_start_[static_cast<size_t>(k)] + in_row;
  }
  col_start_.assign(static_cast<size_t>(groups) + 1, 0);
  for (int i = 0; i < groups; ++i) {
    const double c = count[static_cast<size_t>(i)];
    col_start_[static_cast<size_t>(i) + 1] = col_start_[static_cast<size_t>(i)] + count[static_cast<size_t>(i)];
    // Scalar column b i + t holds b c entries below the block and b - 1 - t in it.
    for (int t = 0; t < b_; ++t) factor_flops_ += (b_ * c + b_ - 1 - t) * (b_ * c + b_ - 1 - t);
    nonzeros_ += b_ * b_ * c + b_ * (b_ - 1) / 2.0;
  }
  const size_t blocks = static_cast<size_t>(col_start_.back()), bb = static_cast<size_t>(b_ * b_),
               fb = static_cast<size_t>(b_ * float_rows(b_));
  row_.assign(blocks, 0);
  l_.assign(blocks * bb, 0.0);
  d_inverse_.assign(static_cast<size_t>(groups) * bb, 0.0);
  y_.assign(static_cast<size_t>(groups) * bb, 0.0);
  reach_.assign(static_cast<size_t>(groups), 0);
  stack_.assign(static_cast<size_t>(groups), 0);
  filled_.assign(static_cast<size_t>(groups), 0);
  lrf_.assign(blocks * fb, 0.f);
  rcol_.assign(blocks, 0);
  df_.assign(static_cast<size_t>(groups) * fb, 0.f);
  return true;
}

BlockLdlt::Result BlockLdlt::factorize(const SpMat &K, bool stop_if_indefinite) {
  complete_ = false;
  const Result res = b_ == 9 ? factorize_blocks<9>(K, stop_if_indefinite) : factorize_blocks<3>(K, stop_if_indefinite);
  complete_ = res == Result::kDefinite || (res == Result::kIndefinite && !stop_if_indefinite);
  return res;
}

template <int B>
BlockLdlt::Result BlockLdlt::factorize_blocks(const SpMat &K, bool stop_if_indefinite) {
  constexpr int BB = B * B, P = float_rows(B);
  const int *outer = K.outerIndexPtr();
  const double *val = K.valuePtr();
  std::fill(flag_.begin(), flag_.end(), -1);
  std::fill(filled_.begin(), filled_.end(), 0);
  bool definite = true;
  MatB<B> dk;
  for (int k = 0; k < blocks_; ++k) {
    dk.setZero();
    // Scatter column k's upper blocks into y and find the reach (the
    // pattern of row k of L) in topological order.
    int top = blocks_;
    flag_[static_cast<size_t>(k)] = k;
    for (const Gather &b : upper_[static_cast<size_t>(k)]) {
      double *dst = (b.row == k ? dk.data() : &y_[static_cast<size_t>(b.row) * BB]) + b.dst;
      for (int c = 0; c < 3; ++c) {
        const double *src = val + outer[3 * b.node + c] + b.offset;
        if (b.transpose) dst[c] = src[0], dst[B + c] = src[1], dst[2 * B + c] = src[2];
        else dst[c * B] = src[0], dst[c * B + 1] = src[1], dst[c * B + 2] = src[2];
      }
      if (b.row == k) continue;
      int len = 0;
      for (int i = b.row; flag_[static_cast<size_t>(i)] != k; i = parent_[static_cast<size_t>(i)]) {
        stack_[static_cast<size_t>(len++)] = i;
        flag_[static_cast<size_t>(i)] = k;
      }
      while (len > 0) reach_[static_cast<size_t>(--top)] = stack_[static_cast<size_t>(--len)];
    }
    // Row k of L, and D_k.
    for (int p = top; p < blocks_; ++p) {
      const size_t i = static_cast<size_t>(reach_[static_cast<size_t>(p)]);
      MapB<B> yref(&y_[i * BB]);
      const MatB<B> yi = yref;
      yref.setZero();
      const int end = col_start_[i] + filled_[i];
      column_update<B>(y_.data(), &row_[static_cast<size_t>(col_start_[i])], &l_[static_cast<size_t>(col_start_[i]) * BB],
                       end - col_start_[i], yi.data());
      // -(D_i^-1 Y_i), then L(k, i) its transpose negated (exact).
      MatB<B> minus = MatB<B>::Zero();
      const int zero = 0;
      column_update<B>(minus.data(), &zero, &d_inverse_[i * BB], 1, yi.data());
      const MatB<B> lki = -minus.transpose();
      column_update<B>(dk.data(), &zero, lki.data(), 1, yi.data());
      row_[static_cast<size_t>(end)] = k;
      MapB<B> lslot(&l_[static_cast<size_t>(end) * BB]);
      lslot = lki;
      const size_t slot = static_cast<size_t>(row_start_[static_cast<size_t>(k)] + (p - top));
      to_float<B, P>(lki.data(), &lrf_[slot * B * P]);
      rcol_[slot] = static_cast<int>(i);
      ++filled_[i];
    }
    MapB<B> dinv(&d_inverse_[static_cast<size_t>(k) * BB]);
    if (!definite_inverse<B>(dk, dinv)) {
      const Eigen::LDLT<MatB<B>> pivots(dk);
      const Eigen::Matrix<double, B, 1> d = pivots.vectorD();
      if (!d.allFinite() || !(d.array().abs() > 0).all()) return Result::kSingular;
      definite = definite && (d.array() > 0).all();
      // The caller throws an indefinite factorisation away: skip its rest.
      if (!definite && stop_if_indefinite) return Result::kIndefinite;
      dinv = dk.inverse();
      if (!dinv.allFinite()) return Result::kSingular;
    }
    to_float<B, P>(dinv.data(), &df_[static_cast<size_t>(k) * B * P]);
  }
  return definite ? Result::kDefinite : Result::kIndefinite;
}

void BlockLdlt::solve(const Eigen::VectorXd &b, Eigen::VectorXd &x) const {
  if (b_ == 9) solve_blocks<9>(b, x);
  else solve_blocks<3>(b, x);
}

// x = P^T L^-T D^-1 L^-1 P b.
template <int B>
void BlockLdlt::solve_blocks(const Eigen::VectorXd &b, Eigen::VectorXd &x) const {
  using Vb = Eigen::Matrix<double, B, 1>;
  constexpr int BB = B * B;
  std::vector<double> &zs = solve_work_;
  const size_t n = order_.size();
  zs.resize(n * B);
  auto z = [&](size_t i) { return Eigen::Map<Vb>(&zs[i * B]); };
  for (size_t i = 0; i < n; ++i) z(i) = b.segment<B>(B * order_[i]);
  for (size_t i = 0; i < n; ++i) {
    const Vb zi = z(i);
    for (int q = col_start_[i]; q < col_start_[i + 1]; ++q)
      z(static_cast<size_t>(row_[static_cast<size_t>(q)])).noalias() -= ConstMapB<B>(&l_[static_cast<size_t>(q) * BB]) * zi;
  }
  for (size_t i = 0; i < n; ++i) z(i) = (ConstMapB<B>(&d_inverse_[i * BB]) * z(i)).eval();
  for (size_t i = n; i-- > 0;) {
    Vb acc = z(i);
    for (int q = col_start_[i]; q < col_start_[i + 1]; ++q)
      acc.noalias() -= ConstMapB<B>(&l_[static_cast<size_t>(q) * BB]).transpose() * z(static_cast<size_t>(row_[static_cast<size_t>(q)]));
    z(i) = acc;
  }
  x.resize(b.size());
  for (size_t i = 0; i < n; ++i) x.segment<B>(B * order_[i]) = z(i);
}

void BlockLdlt::precondition(const Eigen::VectorXd &b, Eigen::VectorXd &x) const {
  if (b_ == 9) precondition_blocks<9>(b, x);
  else precondition_blocks<3>(b, x);
}

namespace {

// The passes of precondition() on z (n blocks of P floats, b's entries
// gathered into it in the analysed order), both over the one float copy of
// L, stored by rows: forward, row k's sum kept in registers (a pass by
// columns would read and write z once per block); D^-1; backward going up
// the rows, row k's final x_k subtracted from each z_j as L(k, j)^T x_k
// (column c of L(k, j) dotted with x_k). Reading L by rows backwards streams
// it: on a tangent of Song's (10,557 unknowns, 3.6 MB of float L) a
// precondition took 552 us against 857 us by columns, each block found
// through an index and transposed (the seventy-first session); an AVX2
// transpose in registers was no faster by columns, so the order is what
// counts. The backward sums differ from a pass by columns in their
// rounding only.
template <int B, int P>
inline void precondition_passes(size_t n, const int *row_start, const int *rcol, const float *lrf, const float *df,
                                float *z) {
  constexpr size_t FB = B * P;
  for (size_t k = 0; k < n; ++k) {
    float acc[P];
    std::copy(z + k * P, z + k * P + P, acc);
    for (int e = row_start[k]; e < row_start[k + 1]; ++e)
      subtract_product<B, P>(acc, lrf + static_cast<size_t>(e) * FB, z + static_cast<size_t>(rcol[e]) * P);
    std::copy(acc, acc + P, z + k * P);
  }
  for (size_t i = 0; i < n; ++i) {
    float zi[P];
    std::copy(z + i * P, z + i * P + P, zi);
    product<B, P>(z + i * P, df + i * FB, zi);
  }
  for (size_t k = n; k-- > 0;) {
    float xk[P];
    std::copy(z + k * P, z + k * P + P, xk);
    for (int e = row_start[k]; e < row_start[k + 1]; ++e)
      subtract_transposed_product<B, P>(z + static_cast<size_t>(rcol[e]) * P, lrf + static_cast<size_t>(e) * FB, xk);
  }
}

AFM_KERNEL_CLONES void precondition_passes9(size_t n, const int *row_start, const int *rcol, const float *lrf,
                                            const float *df, float *z) {
  precondition_passes<9, float_rows(9)>(n, row_start, rcol, lrf, df, z);
}

}  // namespace

// As solve(), in single precision.
template <int B>
void BlockLdlt::precondition_blocks(const Eigen::VectorXd &b, Eigen::VectorXd &x) const {
  constexpr int P = float_rows(B);
  std::vector<float> &z = solve_work_f_;
  const size_t n = order_.size();
  z.resize(n * P);
  for (size_t k = 0; k < n; ++k)
    for (int r = 0; r < P; ++r) z[k * P + r] = r < B ? static_cast<float>(b[static_cast<Eigen::Index>(B) * order_[k] + r]) : 0.f;
  if constexpr (B == 9)
    precondition_passes9(n, row_start_.data(), rcol_.data(), lrf_.data(), df_.data(), z.data());
  else
    precondition_passes<B, P>(n, row_start_.data(), rcol_.data(), lrf_.data(), df_.data(), z.data());
  x.resize(b.size());
  for (size_t i = 0; i < n; ++i)
    for (int r = 0; r < B; ++r) x[static_cast<Eigen::Index>(B) * order_[i] + r] = z[i * P + r];
}

}  // namespace afmb
