#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/recursive_least_squares.hpp"
#include "support/estimation_support.hpp"

namespace dynid {
namespace {

using estimation_testing::expect_error;
using estimation_testing::gaussian;
using estimation_testing::rel;

// Oracle: exact minimiser of Σ λ^{m−k}(y_k − w_kᵀx)² + λ^m‖x − x0‖²/c by normal equations
// (well-conditioned problems only).
Eigen::VectorXd regularised(const Eigen::MatrixXd& W, const Eigen::VectorXd& y, double c,
                            double lambda, const Eigen::VectorXd& x0) {
  const Eigen::Index m = W.rows(), p = W.cols();
  Eigen::VectorXd w(m);
  for (Eigen::Index k = 0; k < m; ++k) w(k) = std::pow(lambda, double(m - 1 - k));
  const double prior = std::pow(lambda, double(m)) / c;
  const Eigen::MatrixXd A =
      W.transpose() * w.asDiagonal() * W + prior * Eigen::MatrixXd::Identity(p, p);
  return A.ldlt().solve(W.transpose() * w.asDiagonal() * y + prior * x0);
}

class RlsPrior : public ::testing::TestWithParam<double> {};

TEST_P(RlsPrior, EqualsRegularisedBatchSolutionAndCovariance) {
  const double c = GetParam();
  std::mt19937 rng(31);
  const Eigen::Index m = 300, p = 6;
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::VectorXd y = W * gaussian(p, 1, rng) + gaussian(m, 1, rng, 0.05);
  RecursiveLeastSquaresOptions o;
  o.initial_covariance = c;
  RecursiveLeastSquares rls(p, o);
  rls.update(W, y);
  const Eigen::VectorXd x0 = Eigen::VectorXd::Zero(p);
  EXPECT_LT(rel(rls.x(), regularised(W, y, c, 1.0, x0)), 1e-9);
  // P = (WᵀW + I/c)⁻¹ and the factor structure U unit upper triangular, D > 0.
  const Eigen::MatrixXd A = W.transpose() * W + Eigen::MatrixXd::Identity(p, p) / c;
  EXPECT_LT(rel(rls.P(), A.ldlt().solve(Eigen::MatrixXd::Identity(p, p))), 1e-9);
  const Eigen::MatrixXd U = rls.covariance_factor();
  EXPECT_TRUE(U.isUpperTriangular(0.0));
  EXPECT_TRUE(U.diagonal().isOnes(0.0));
  EXPECT_GT(rls.covariance_diagonal().minCoeff(), 0.0);
  // Cost recursion equals the directly evaluated minimum of the regularised cost.
  const Eigen::VectorXd x = rls.x();
  const double J = (y - W * x).squaredNorm() + x.squaredNorm() / c;
  EXPECT_NEAR(rls.cost(), J, 1e-9 * J);
  // Prior bias bound: x_ls − x_rls = (WᵀW + I/c)⁻¹ x_ls / c, so
  // ‖x_rls − x_ls‖ ≤ ‖x_ls‖/(1 + c·σ_min(W)²).
  const Eigen::VectorXd x_ls = W.colPivHouseholderQr().solve(y);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(W);
  const double smin = svd.singularValues()(p - 1);
  EXPECT_LE((x - x_ls).norm(), x_ls.norm() / (1.0 + c * smin * smin) * (1 + 1e-6) + 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Priors, RlsPrior, ::testing::Values(1.0, 1e4, 1e8));

TEST(RecursiveLeastSquares, HistoryCallbackAndStatistics) {
  std::mt19937 rng(32);
  const Eigen::Index m = 120, p = 4;
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::VectorXd y = W * gaussian(p, 1, rng) + gaussian(m, 1, rng, 0.1);
  const double c = 1e10;
  RecursiveLeastSquaresOptions o;
  o.initial_covariance = c;
  Eigen::MatrixXd history;
  EstimationOptions eo;
  eo.confidence_level = 0.95;
  const Estimate e = recursive_least_squares(W, y, o, eo, &history);
  ASSERT_EQ(history.rows(), m);
  ASSERT_EQ(history.cols(), p);
  EXPECT_LT(rel(history.row(m - 1).transpose(), e.x), 1e-15);
  // After one sample: x1 = c·w·y/(1 + c·wᵀw) (eqs. 36–37 with P0 = cI, x0 = 0).
  const Eigen::VectorXd w0 = W.row(0).transpose();
  EXPECT_LT(rel(history.row(0).transpose(), c * w0 * y(0) / (1.0 + c * w0.squaredNorm())), 1e-12);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(p);
  for (Eigen::Index k : {9, 50, 99}) {
    EXPECT_LT(
        rel(history.row(k).transpose(), regularised(W.topRows(k + 1), y.head(k + 1), c, 1.0, zero)),
        1e-9)
        << k;
  }
  // Callback sees every sample with the current estimate.
  RecursiveLeastSquares rls(p, o);
  std::vector<Eigen::Index> seen;
  Eigen::VectorXd last;
  rls.set_callback([&](Eigen::Index k, const Eigen::VectorXd& x) {
    seen.push_back(k);
    last = x;
  });
  rls.update(W, y);
  ASSERT_EQ(seen.size(), std::size_t(m));
  EXPECT_EQ(seen.front(), 1);
  EXPECT_EQ(seen.back(), m);
  EXPECT_LT(rel(last, e.x), 1e-15);
  EXPECT_EQ(rls.samples(), m);
  EXPECT_EQ(rls.history().rows(), 0);  // not recorded unless asked
  // Statistics agree with OLS up to the (vanishing) prior: σ, intervals, level.
  const Estimate ols = ordinary_least_squares(W, y, Eigen::VectorXi(), eo);
  EXPECT_EQ(e.summary.estimator, EstimatorKind::kRecursiveLeastSquares);
  EXPECT_EQ(e.degrees_of_freedom, m - p);
  EXPECT_LT(rel(e.std_dev, ols.std_dev), 1e-6);
  EXPECT_LT(rel(e.ci_upper, ols.ci_upper), 1e-6);
  EXPECT_NEAR(e.summary.condition_number, ols.summary.condition_number,
              1e-6 * ols.summary.condition_number);
}

TEST(RecursiveLeastSquares, ForgettingFactorTracksAParameterStep) {
  std::mt19937 rng(33);
  const Eigen::Index half = 400, m = 2 * half, p = 3;
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::Vector3d x1(1.0, -1.0, 2.0), x2(1.5, -1.0, 0.5);
  Eigen::VectorXd y(m);
  y.head(half) = W.topRows(half) * x1;
  y.tail(half) = W.bottomRows(half) * x2;
  RecursiveLeastSquaresOptions o;
  o.initial_covariance = 1e6;
  o.forgetting_factor = 0.9;
  o.record_history = true;
  RecursiveLeastSquares rls(p, o);
  rls.update(W, y);
  // Oracle: exponentially weighted regularised least squares, closed form.
  EXPECT_LT(rel(rls.x(), regularised(W, y, 1e6, 0.9, Eigen::VectorXd::Zero(p))), 1e-9);
  EXPECT_LT(rel(rls.x(), x2), 1e-8);  // old data weighted by 0.9^400 ≈ 5e-19
  // Before the step it had converged to x1; 60 samples after the step it is already at x2.
  EXPECT_LT(rel(rls.history().row(half - 1).transpose(), x1), 1e-8);
  EXPECT_LT(rel(rls.history().row(half + 59).transpose(), x2), 1e-2);
  // Without forgetting the estimate stays between the two.
  RecursiveLeastSquaresOptions plain;
  plain.initial_covariance = 1e6;
  RecursiveLeastSquares rls1(p, plain);
  rls1.update(W, y);
  EXPECT_GT(rel(rls1.x(), x2), 0.1);
  // Non-zero prior mean x0 enters the oracle as λ^m x0/c.
  RecursiveLeastSquares rls0(p, o);
  const Eigen::Vector3d x0(3.0, 3.0, 3.0);
  rls0.set_initial_estimate(x0);
  rls0.update(W.topRows(5), y.head(5));
  EXPECT_LT(rel(rls0.x(), regularised(W.topRows(5), y.head(5), 1e6, 0.9, x0)), 1e-9);
}

TEST(RecursiveLeastSquares, ErrorsNameTheInput) {
  RecursiveLeastSquaresOptions bad;
  bad.forgetting_factor = 0.0;
  expect_error([&] { RecursiveLeastSquares(3, bad); }, {"forgetting_factor", "(0, 1]"});
  bad.forgetting_factor = 1.5;
  expect_error([&] { RecursiveLeastSquares(3, bad); }, {"forgetting_factor"});
  RecursiveLeastSquaresOptions badc;
  badc.initial_covariance = -1.0;
  expect_error([&] { RecursiveLeastSquares(3, badc); }, {"initial_covariance", "c > 0"});
  expect_error([&] { RecursiveLeastSquares(0); }, {"parameters is 0"});
  RecursiveLeastSquares rls(3);
  expect_error([&] { rls.estimate(); }, {"no samples"});
  expect_error([&] { rls.update(Eigen::VectorXd::Ones(2), 1.0); },
               {"sample 0", "has 2 entries; pass 3"});
  expect_error([&] { rls.update(Eigen::Vector3d(1, NAN, 0), 1.0); }, {"sample 0", "NaN or Inf"});
  expect_error([&] { rls.update(Eigen::MatrixXd::Ones(2, 3), Eigen::VectorXd::Ones(3)); },
               {"y has 3 rows but W has 2"});
  expect_error([&] { rls.update(Eigen::MatrixXd::Ones(2, 4), Eigen::VectorXd::Ones(2)); },
               {"W has 4 columns"});
  rls.update(Eigen::Vector3d(1, 0, 0), 1.0);
  expect_error([&] { rls.set_initial_estimate(Eigen::Vector3d::Zero()); },
               {"after 1 samples", "before the first update"});
  expect_error([&] { rls.update(Eigen::Vector3d(1, 0, 0), INFINITY); }, {"sample 1", "NaN or Inf"});
  expect_error([&] { recursive_least_squares(Eigen::MatrixXd(3, 0), Eigen::VectorXd(3)); },
               {"no columns"});
}

}  // namespace
}  // namespace dynid
