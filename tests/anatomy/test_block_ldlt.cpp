// The solver's block factorisation (anatomy/block_ldlt.h) against Eigen's
// dense factorisations of the same matrices: an independent reference.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <limits>
#include <random>
#include <vector>

#include "anatomy/block_ldlt.h"

using namespace afmb;

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// A symmetric matrix of full 3 x 3 blocks on the nodes of an nx x ny x nz
// grid (each node coupled to its 26 neighbours, as the tissue's prisms
// couple nodes across layers), diagonally dominant by `margin` times the
// off-diagonal sum: positive definite for margin > 1. Node numbers are
// shuffled so that the ordering has work to do. With `columns`, the (x, y)
// columns are shuffled and each column's nz nodes numbered together, as the
// solver numbers a skin vertex's tissue nodes.
SpMat grid_matrix(int nx, int ny, int nz, double margin, unsigned seed, bool columns = false) {
  const int n = nx * ny * nz;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<int> label(static_cast<size_t>(columns ? nx * ny : n));
  for (size_t i = 0; i < label.size(); ++i) label[i] = static_cast<int>(i);
  std::shuffle(label.begin(), label.end(), rng);
  auto id = [&](int x, int y, int z) {
    return columns ? label[static_cast<size_t>(y * nx + x)] * nz + z : label[static_cast<size_t>((z * ny + y) * nx + x)];
  };
  Eigen::MatrixXd rowsum = Eigen::MatrixXd::Zero(3 * n, 1);
  std::vector<Eigen::Triplet<double>> t;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int X = x + dx, Y = y + dy, Z = z + dz;
              if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
              const int i = id(x, y, z), j = id(X, Y, Z);
              if (j <= i && !(dx == 0 && dy == 0 && dz == 0)) continue;  // each pair once
              if (i == j) continue;
              Eigen::Matrix3d B;
              for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) B(a, b) = u(rng);
              for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) {
                  t.emplace_back(3 * i + a, 3 * j + b, B(a, b));
                  t.emplace_back(3 * j + b, 3 * i + a, B(a, b));
                  rowsum(3 * i + a) += std::abs(B(a, b));
                  rowsum(3 * j + b) += std::abs(B(a, b));
                }
            }
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix3d S;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) S(a, b) = 0.1 * u(rng);
    S = 0.5 * (S + S.transpose()).eval();
    for (int a = 0; a < 3; ++a) {
      double off = 0;
      for (int b = 0; b < 3; ++b) off += b == a ? 0 : std::abs(S(a, b));
      S(a, a) = margin * (rowsum(3 * i + a) + off);
    }
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) t.emplace_back(3 * i + a, 3 * i + b, S(a, b));
  }
  SpMat K(3 * n, 3 * n);
  K.setFromTriplets(t.begin(), t.end());
  K.makeCompressed();
  return K;
}

Eigen::VectorXd random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) b(i) = u(rng);
  return b;
}

}  // namespace

TEST(BlockLdlt, SolvesAPositiveDefiniteSystemAsADenseCholeskyDoes) {
  const SpMat K = grid_matrix(6, 5, 4, 1.05, 1);
  BlockLdlt f;
  ASSERT_TRUE(f.analyze(K));
  EXPECT_EQ(f.factorize(K), BlockLdlt::Result::kDefinite);
  const Eigen::VectorXd b = random_vector(K.rows(), 2);
  Eigen::VectorXd x;
  f.solve(b, x);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(K);
  const Eigen::VectorXd ref = dense.llt().solve(b);
  EXPECT_LT((x - ref).norm(), 1e-10 * ref.norm());
  // The single-precision copy the solver preconditions with: the same
  // solution to float accuracy.
  Eigen::VectorXd xf;
  f.precondition(b, xf);
  EXPECT_LT((xf - ref).norm(), 1e-5 * ref.norm());
  // The ordering keeps the fill near a scalar AMD ordering's (Eigen's
  // simplicial factorisation of the same matrix); a second factorisation
  // of the same pattern gives the same solution.
  Eigen::SimplicialLDLT<SpMat> scalar(K);
  ASSERT_EQ(scalar.info(), Eigen::Success);
  const double scalar_nonzeros = static_cast<double>(scalar.matrixL().nestedExpression().nonZeros());
  EXPECT_LT(f.nonzeros(), 1.3 * scalar_nonzeros) << "scalar AMD: " << scalar_nonzeros;
  const SpMat K2 = 2.0 * K;
  EXPECT_EQ(f.factorize(K2), BlockLdlt::Result::kDefinite);
  Eigen::VectorXd x2;
  f.solve(b, x2);
  EXPECT_LT((2 * x2 - ref).norm(), 1e-10 * ref.norm());
  // The preconditioner's float copy is renewed too.
  f.precondition(b, xf);
  EXPECT_LT((2 * xf - ref).norm(), 1e-5 * ref.norm());
}

// Pivot groups of three nodes (the solver's: a skin vertex's three free
// nodes). The grid's node numbers are shuffled, so a group's three nodes lie
// apart and have different neighbours: its 9 x 9 blocks hold stored zeros
// where K has no 3 x 3 block. The same solution as one node at a time and as
// a dense factorisation, on a definite and an indefinite matrix; a singular
// one is refused.
TEST(BlockLdlt, PivotGroupsOfThreeNodesSolveTheSameSystems) {
  const SpMat K = grid_matrix(6, 5, 4, 1.05, 1);
  const Eigen::VectorXd b = random_vector(K.rows(), 2);
  const Eigen::VectorXd ref = Eigen::MatrixXd(K).llt().solve(b);
  BlockLdlt one, three;
  ASSERT_TRUE(one.analyze(K, 1));
  ASSERT_TRUE(three.analyze(K, 3));
  EXPECT_EQ(one.factorize(K), BlockLdlt::Result::kDefinite);
  EXPECT_EQ(three.factorize(K), BlockLdlt::Result::kDefinite);
  Eigen::VectorXd x1, x3, xf;
  one.solve(b, x1);
  three.solve(b, x3);
  EXPECT_LT((x3 - ref).norm(), 1e-10 * ref.norm());
  EXPECT_LT((x3 - x1).norm(), 1e-10 * ref.norm());
  three.precondition(b, xf);
  EXPECT_LT((xf - ref).norm(), 1e-5 * ref.norm());
  // Groups of nodes that are not neighbours fill more (stored zeros
  // counted). Groups that are (a column of three layers, as the tissue's
  // vertices): about the fill of one node at a time, and the same solution.
  EXPECT_GE(three.nonzeros(), one.nonzeros());
  const SpMat Kc = grid_matrix(9, 8, 3, 1.05, 8, true);
  ASSERT_TRUE(one.analyze(Kc, 1));
  ASSERT_TRUE(three.analyze(Kc, 3));
  EXPECT_LT(three.nonzeros(), 1.25 * one.nonzeros()) << "one node at a time: " << one.nonzeros();
  EXPECT_EQ(three.factorize(Kc), BlockLdlt::Result::kDefinite);
  const Eigen::VectorXd bc = random_vector(Kc.rows(), 9);
  const Eigen::VectorXd refc = Eigen::MatrixXd(Kc).llt().solve(bc);
  three.solve(bc, x3);
  EXPECT_LT((x3 - refc).norm(), 1e-10 * refc.norm());
  three.precondition(bc, xf);
  EXPECT_LT((xf - refc).norm(), 1e-5 * refc.norm());

  SpMat Ki = grid_matrix(4, 4, 3, 1.05, 3);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(Ki);
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues();
  SpMat I(Ki.rows(), Ki.cols());
  I.setIdentity();
  Ki = Ki - 0.5 * (ev(ev.size() / 2) + ev(ev.size() / 2 + 1)) * I;
  ASSERT_TRUE(three.analyze(Ki, 3));
  EXPECT_EQ(three.factorize(Ki), BlockLdlt::Result::kIndefinite);
  const Eigen::VectorXd bi = random_vector(Ki.rows(), 4);
  const Eigen::VectorXd refi = Eigen::MatrixXd(Ki).partialPivLu().solve(bi);
  three.solve(bi, x3);
  EXPECT_LT((x3 - refi).norm(), 1e-8 * refi.norm());

  SpMat Ks = grid_matrix(3, 3, 2, 1.05, 5);
  for (int k = 0; k < Ks.outerSize(); ++k)
    for (SpMat::InnerIterator it(Ks, k); it; ++it)
      if (it.row() / 3 == 7 || it.col() / 3 == 7) it.valueRef() = 0;
  ASSERT_TRUE(three.analyze(Ks, 3));
  EXPECT_EQ(three.factorize(Ks), BlockLdlt::Result::kSingular);

  // Nodes that do not divide into groups, and a group size not offered.
  const SpMat K5 = grid_matrix(5, 1, 1, 1.05, 7);
  EXPECT_FALSE(three.analyze(K5, 3));
  EXPECT_TRUE(three.analyze(K5, 1));
  EXPECT_FALSE(three.analyze(K, 2));
}

// The solver stores its tangent on and above the diagonal only: with
// upper_only, the blocks below may hold anything and the factors are those
// of the symmetric matrix the upper blocks make (a block below read as its
// mirror's transpose; within a pivot group too).
TEST(BlockLdlt, ReadsOnlyTheUpperTriangleWhenAsked) {
  const SpMat K = grid_matrix(7, 6, 3, 1.05, 10, true);
  SpMat junk = K;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int k = 0; k < junk.outerSize(); ++k)
    for (SpMat::InnerIterator it(junk, k); it; ++it)
      if (it.row() / 3 > it.col() / 3) it.valueRef() = u(rng);
  const Eigen::VectorXd b = random_vector(K.rows(), 12);
  const Eigen::VectorXd ref = Eigen::MatrixXd(K).llt().solve(b);
  for (int group : {1, 3}) {
    BlockLdlt f;
    ASSERT_TRUE(f.analyze(junk, group, true));
    EXPECT_EQ(f.factorize(junk), BlockLdlt::Result::kDefinite) << "group " << group;
    Eigen::VectorXd x, xf;
    f.solve(b, x);
    EXPECT_LT((x - ref).norm(), 1e-10 * ref.norm()) << "group " << group;
    f.precondition(b, xf);
    EXPECT_LT((xf - ref).norm(), 1e-5 * ref.norm()) << "group " << group;
    // Without upper_only the junk is read, and the solution is another.
    ASSERT_TRUE(f.analyze(junk, group, false));
    if (f.factorize(junk) != BlockLdlt::Result::kSingular) {
      f.solve(b, x);
      EXPECT_GT((x - ref).norm(), 1e-3 * ref.norm()) << "group " << group;
    }
  }
}

TEST(BlockLdlt, SaysWhenTheMatrixIsIndefiniteAndStillSolvesIt) {
  // Shifting by the middle eigenvalue leaves about half of them negative.
  SpMat K = grid_matrix(4, 4, 3, 1.05, 3);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(K);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(dense);
  const Eigen::VectorXd ev = eig.eigenvalues();
  const double shift = 0.5 * (ev(ev.size() / 2) + ev(ev.size() / 2 + 1));
  SpMat I(K.rows(), K.cols());
  I.setIdentity();
  K = K - shift * I;  // the same pattern: the identity's entries are in it
  BlockLdlt f;
  ASSERT_TRUE(f.analyze(K));
  EXPECT_EQ(f.factorize(K), BlockLdlt::Result::kIndefinite);
  const Eigen::VectorXd b = random_vector(K.rows(), 4);
  Eigen::VectorXd x;
  f.solve(b, x);
  const Eigen::VectorXd ref = Eigen::MatrixXd(K).partialPivLu().solve(b);
  EXPECT_LT((x - ref).norm(), 1e-8 * ref.norm());
}

// The solver's full tangent is kept only where definite, so its
// factorisation may stop at the first pivot that is not (factorize's
// stop_if_indefinite). A definite matrix is factorised whole, the same to
// the bit; an indefinite one stops incomplete, and the next factorisation
// starts clean. A pivot block of NaN shows where it stopped: on a negative
// definite matrix the first pivot already stops it, so a NaN at one of two
// nodes (at most one of them pivots first) goes unread, which a
// factorisation to the end reports as singular.
TEST(BlockLdlt, StopsAtTheFirstIndefinitePivotWhenAsked) {
  const SpMat K = grid_matrix(5, 4, 3, 1.05, 21);
  const Eigen::VectorXd b = random_vector(K.rows(), 22);
  BlockLdlt f;
  ASSERT_TRUE(f.analyze(K));
  Eigen::VectorXd whole, stopping;
  ASSERT_EQ(f.factorize(K), BlockLdlt::Result::kDefinite);
  EXPECT_TRUE(f.complete());
  f.solve(b, whole);
  ASSERT_EQ(f.factorize(K, true), BlockLdlt::Result::kDefinite);
  EXPECT_TRUE(f.complete());
  f.solve(b, stopping);
  EXPECT_EQ(whole, stopping) << "a definite matrix is factorised whole either way";

  const SpMat negative = -K;
  int unread = 0;
  for (int node : {0, 1}) {
    SpMat poisoned = negative;
    for (int k = 3 * node; k < 3 * node + 3; ++k)
      for (SpMat::InnerIterator it(poisoned, k); it; ++it)
        if (it.row() / 3 == node) it.valueRef() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(f.factorize(poisoned), BlockLdlt::Result::kSingular) << "node " << node;
    EXPECT_FALSE(f.complete());
    const BlockLdlt::Result r = f.factorize(poisoned, true);
    EXPECT_FALSE(f.complete());
    unread += r == BlockLdlt::Result::kIndefinite;
  }
  EXPECT_GE(unread, 1) << "the factorisation went on past an indefinite pivot";
  EXPECT_EQ(f.factorize(negative, true), BlockLdlt::Result::kIndefinite);
  EXPECT_FALSE(f.complete());
  // After a stop, a whole factorisation solves as one from scratch.
  ASSERT_EQ(f.factorize(K), BlockLdlt::Result::kDefinite);
  EXPECT_TRUE(f.complete());
  f.solve(b, stopping);
  EXPECT_EQ(whole, stopping);
}

TEST(BlockLdlt, RefusesASingularMatrix) {
  SpMat K = grid_matrix(3, 3, 2, 1.05, 5);
  // One node's rows and columns zero: its pivot block vanishes.
  for (int k = 0; k < K.outerSize(); ++k)
    for (SpMat::InnerIterator it(K, k); it; ++it)
      if (it.row() / 3 == 7 || it.col() / 3 == 7) it.valueRef() = 0;
  BlockLdlt f;
  ASSERT_TRUE(f.analyze(K));
  EXPECT_EQ(f.factorize(K), BlockLdlt::Result::kSingular);
}

TEST(BlockLdlt, RefusesAPatternThatIsNotMadeOfBlocks) {
  SpMat K = grid_matrix(3, 2, 2, 1.05, 6);
  BlockLdlt f;
  ASSERT_TRUE(f.analyze(K));
  // One entry less: its block is no longer full.
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < K.outerSize(); ++k)
    for (SpMat::InnerIterator it(K, k); it; ++it)
      if (!(it.row() == 4 && it.col() == 3)) t.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
  SpMat holed(K.rows(), K.cols());
  holed.setFromTriplets(t.begin(), t.end());
  EXPECT_FALSE(f.analyze(holed));
  // Not a multiple of three.
  SpMat odd(7, 7);
  odd.setIdentity();
  odd.makeCompressed();
  EXPECT_FALSE(f.analyze(odd));
}
