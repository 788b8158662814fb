// Normal-equation accumulation, per-group column subsets and merging of StreamingLeastSquares,
// checked against the Householder accumulation of all columns and against an in-memory QR oracle.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/QR>

#include "dynid/estimation/streaming_least_squares.hpp"
#include "estimation/gram_update.hpp"
#include "support/estimation_support.hpp"

namespace dynid {
namespace {

using estimation_testing::expect_error;
using estimation_testing::gaussian;
using estimation_testing::rel;

// A sample-major problem with a joint-like sparsity: group g sees columns g..p-1 only (links of
// its subtree), group 0 sees all. Group noise levels differ so that WLS matters.
// Group variances depend on the rank of each group's own subsystem (Gautier), so the rank-deficient
// last group checks that the normal equations find the same group rank as Householder QR.
struct SparseProblem {
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
  Eigen::VectorXi groups;
  std::vector<std::vector<Eigen::Index>> columns;
};

SparseProblem sparse_problem(Eigen::Index samples, int G, Eigen::Index p, double noise,
                             unsigned seed) {
  std::mt19937 rng(seed);
  SparseProblem s;
  s.W = gaussian(samples * G, p, rng);
  s.groups.resize(samples * G);
  s.columns.resize(G);
  for (int g = 0; g < G; ++g)
    for (Eigen::Index c = 2 * g; c < p; ++c) s.columns[g].push_back(c);
  for (Eigen::Index r = 0; r < s.W.rows(); ++r) {
    const int g = static_cast<int>(r % G);
    s.groups(r) = g;
    for (Eigen::Index c = 0; c < 2 * g; ++c) s.W(r, c) = 0.0;
    for (Eigen::Index c = 0; c < p; ++c) s.W(r, c) *= 1.0 + c;  // unequal column scales
    // The last group alone cannot separate the last two columns (a joint that does not see
    // every parameter): its subsystem is rank deficient, the whole system is not.
    if (G > 2 && g == G - 1) s.W(r, p - 1) = 1.7 * s.W(r, p - 2) - 0.3 * s.W(r, p - 3);
  }
  const Eigen::VectorXd x = gaussian(p, 1, rng);
  s.y = s.W * x;
  std::normal_distribution<double> nd(0.0, 1.0);
  for (Eigen::Index r = 0; r < s.W.rows(); ++r) s.y(r) += noise * (1.0 + 4.0 * (r % G)) * nd(rng);
  return s;
}

TEST(StreamingAccumulation, NormalEquationsAndColumnSubsetsEqualHouseholderOnAllColumns) {
  const SparseProblem s = sparse_problem(3000, 3, 9, 0.1, 31);
  StreamingLeastSquares full(9, 3);  // Householder, every column
  full.add(s.W, s.y, s.groups);
  StreamingOptions o;
  o.group_columns = s.columns;
  o.accumulation = Accumulation::kNormalEquations;
  StreamingLeastSquares ne(9, 3, o);
  ne.add(s.W, s.y, s.groups);
  o.accumulation = Accumulation::kHouseholder;
  StreamingLeastSquares hh(9, 3, o);
  hh.add(s.W, s.y, s.groups);
  const Eigen::VectorXd x_qr = s.W.colPivHouseholderQr().solve(s.y);  // in-memory oracle
  for (const StreamingLeastSquares* a : {&full, &ne, &hh}) {
    const Estimate e = a->solve_ordinary();
    EXPECT_LT(rel(e.x, x_qr), 1e-10);
    const Estimate f = full.solve_ordinary();
    EXPECT_LT(rel(e.covariance, f.covariance), 1e-10);
    EXPECT_LT(rel(e.group_variance, f.group_variance), 1e-10);
    EXPECT_LT(rel(e.group_rms, f.group_rms), 1e-10);
    EXPECT_NEAR(e.relative_error, f.relative_error, 1e-12);
    const Estimate w = a->solve_weighted(), wf = full.solve_weighted();
    EXPECT_LT(rel(w.x, wf.x), 1e-10);
    EXPECT_LT(rel(w.std_dev, wf.std_dev), 1e-9);
    // The factor still represents the data: RᵀR = [W y]ᵀ[W y].
    Eigen::MatrixXd Wy(s.W.rows(), 10);
    Wy << s.W, s.y;
    const Eigen::MatrixXd R = a->factor();
    EXPECT_LT(rel(R.transpose() * R, Wy.transpose() * Wy), 1e-12);
  }
}

TEST(StreamingAccumulation, MergeEqualsOneAccumulatorAndRowByRowEqualsBlocks) {
  const SparseProblem s = sparse_problem(2000, 3, 9, 0.1, 32);
  for (auto acc : {Accumulation::kHouseholder, Accumulation::kNormalEquations}) {
    StreamingOptions o;
    o.group_columns = s.columns;
    o.accumulation = acc;
    StreamingLeastSquares one(9, 3, o), a(9, 3, o), b(9, 3, o), rows(9, 3, o);
    one.add(s.W, s.y, s.groups);
    const Eigen::Index half = 2999;  // not a multiple of the group count
    a.add(s.W.topRows(half), s.y.head(half), s.groups.head(half));
    b.add(s.W.bottomRows(s.W.rows() - half), s.y.tail(s.W.rows() - half),
          s.groups.tail(s.W.rows() - half));
    a.merge(b);
    // add_row_gathered reads the row out of W's storage (column-major: entry (r, c) at c·m + r).
    StreamingLeastSquares gathered(9, 3, o);
    const Eigen::Index m = s.W.rows();
    for (Eigen::Index r = 0; r < m; ++r) {
      const int g = s.groups(r);
      Eigen::VectorXd w(s.columns[g].size());
      std::vector<Eigen::Index> offsets;
      for (std::size_t c = 0; c < s.columns[g].size(); ++c) {
        w(c) = s.W(r, s.columns[g][c]);
        offsets.push_back(s.columns[g][c] * m + r);
      }
      rows.add_row(g, w, s.y(r));
      gathered.add_row_gathered(g, s.W.data(), offsets, s.y(r));
      if (r == 7) {  // a refused row leaves no trace
        const double bad[1] = {std::nan("")};
        const std::vector<Eigen::Index> zeros(s.columns[g].size(), 0);
        expect_error([&] { gathered.add_row_gathered(g, bad, zeros, 1.0); }, {"NaN or Inf"});
      }
    }
    const Estimate e1 = one.solve_weighted();
    EXPECT_EQ(a.rows(), one.rows());
    EXPECT_EQ(a.group_rows(), one.group_rows());
    EXPECT_EQ(gathered.group_rows(), one.group_rows());
    EXPECT_LT(rel(a.solve_weighted().x, e1.x), 1e-11);
    EXPECT_LT(rel(rows.solve_weighted().x, e1.x), 1e-11);
    EXPECT_LT(rel(gathered.solve_weighted().x, e1.x), 1e-11);
    EXPECT_LT(rel(gathered.factor().transpose() * gathered.factor(),
                  rows.factor().transpose() * rows.factor()),
              1e-12);
    EXPECT_LT(rel(a.solve_weighted().std_dev, e1.std_dev), 1e-10);
  }
}

// The blocked Gram kernel against sums in long double, for sizes around its 8×4 tiles and
// 64-column panels; entries below the diagonal are left alone.
TEST(StreamingAccumulation, GramKernelEqualsLongDoubleSums) {
  std::mt19937 rng(36);
  for (const Eigen::Index q : {1, 3, 4, 5, 8, 9, 13, 31, 70, 71}) {
    for (const Eigen::Index k : {1, 7, 64, 65, 256}) {
      const Eigen::Index ldb = estimation_detail::gram_padded_rows(q);
      Eigen::MatrixXd B = Eigen::MatrixXd::Zero(ldb, k);
      B.topRows(q) = gaussian(q, k, rng);
      Eigen::MatrixXd G = gaussian(q, q, rng);
      const Eigen::MatrixXd G0 = G;
      estimation_detail::gram_update_upper(q, k, B.data(), ldb, G.data());
      double worst = 0.0;
      for (Eigen::Index j = 0; j < q; ++j) {
        for (Eigen::Index i = 0; i < q; ++i) {
          if (i > j) {
            ASSERT_EQ(G(i, j), G0(i, j)) << "lower entry (" << i << ", " << j << ") written";
            continue;
          }
          long double sum = G0(i, j), scale = std::abs(G0(i, j));
          for (Eigen::Index s = 0; s < k; ++s) {
            sum += static_cast<long double>(B(i, s)) * B(j, s);
            scale += std::abs(B(i, s) * B(j, s));
          }
          worst = std::max(worst, static_cast<double>(std::abs(G(i, j) - sum) / scale));
        }
      }
      // Higham's bound for a sum of k + 1 terms in any order: γ_{k+1} ≈ (k + 1)·u of Σ|terms|;
      // a wrong index or a missed tile is off by O(1).
      EXPECT_LT(worst, (k + 1) * std::numeric_limits<double>::epsilon() / 2)
          << "q = " << q << ", k = " << k;
    }
  }
}

TEST(StreamingAccumulation, NormalEquationsRefuseIllConditionedOrNoiseFreeData) {
  SparseProblem s = sparse_problem(500, 3, 9, 0.0, 33);  // y exactly in the range of W
  StreamingOptions o;
  o.accumulation = Accumulation::kNormalEquations;
  StreamingLeastSquares ne(9, 3, o);
  ne.add(s.W, s.y, s.groups);
  EXPECT_THROW(ne.solve_ordinary(), NormalEquationsError);
  EXPECT_THROW(ne.solve_weighted(), NormalEquationsError);
  // Householder accumulation of the same rows is exact.
  StreamingLeastSquares hh(9, 3);
  hh.add(s.W, s.y, s.groups);
  EXPECT_LT(rel(hh.solve_ordinary().x, s.W.colPivHouseholderQr().solve(s.y)), 1e-12);
  // Nearly collinear columns (κ ≈ 1e7 after equilibration) with noise: refused as well.
  s = sparse_problem(500, 1, 4, 0.1, 34);
  std::mt19937 rng(35);
  s.W.col(3) = s.W.col(2) + 1e-7 * gaussian(s.W.rows(), 1, rng);
  StreamingLeastSquares bad(4, 1, o);
  bad.add(s.W, s.y);
  expect_error([&] { bad.solve_ordinary(); },
               {"too ill-conditioned", "Accumulation::kHouseholder"});
}

TEST(StreamingAccumulation, BadColumnListsAndRowsGiveClearErrors) {
  StreamingOptions o;
  o.group_columns = {{0, 2}, {1}};
  expect_error([&] { StreamingLeastSquares(3, 3, o); }, {"2 lists for 3 groups"});
  o.group_columns = {{0, 2}, {2, 1}};
  expect_error([&] { StreamingLeastSquares(3, 2, o); }, {"group_columns[1]", "sorted", "entry 1"});
  o.group_columns = {{0, 2}, {1, 3}};
  expect_error([&] { StreamingLeastSquares(3, 2, o); }, {"group_columns[1]", "[0, 3)"});
  o.group_columns = {{0, 2}, {1}};
  StreamingLeastSquares s(3, 2, o);
  expect_error([&] { s.add(Eigen::RowVector3d(1, 1, 1), Eigen::VectorXd::Ones(1)); },
               {"W row 0 (group 0)", "column 1", "excludes"});
  expect_error([&] { s.add_row(1, Eigen::Vector2d(1, 2), 0.0); },
               {"w has 2 entries", "group 1 has 1 columns"});
  expect_error([&] { s.add_row(2, Eigen::VectorXd::Ones(1), 0.0); }, {"group 2 is outside"});
  expect_error([&] { s.add_row(1, Eigen::VectorXd::Ones(1), std::nan("")); }, {"NaN or Inf"});
  const double row[2] = {1.0, 2.0};
  expect_error(
      [&] {
        s.add_row_gathered(1, row, {0, 1}, 0.0);
      },
      {"2 offsets", "group 1 has 1 columns"});
  expect_error([&] { s.add_row_gathered(-1, row, {0}, 0.0); }, {"group -1 is outside"});
  StreamingLeastSquares other(3, 2);
  expect_error([&] { s.merge(other); }, {"merge: group 0 keeps different columns"});
  StreamingOptions ne;
  ne.accumulation = Accumulation::kNormalEquations;
  StreamingLeastSquares third(3, 2, ne);
  expect_error([&] { other.merge(third); }, {"merge:", "accumulation"});
}

}  // namespace
}  // namespace dynid
