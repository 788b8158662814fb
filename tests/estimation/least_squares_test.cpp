#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <boost/math/distributions/chi_squared.hpp>

#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/estimation/streaming_least_squares.hpp"
#include "support/estimation_support.hpp"

namespace dynid {
namespace {

using estimation_testing::expect_error;
using estimation_testing::gaussian;
using estimation_testing::rel;

TEST(OrdinaryLeastSquares, NoiseFreeExactRecovery) {
  std::mt19937 rng(11);
  const Eigen::MatrixXd W = gaussian(200, 8, rng);
  const Eigen::VectorXd x = gaussian(8, 1, rng);
  const Eigen::VectorXd y = W * x;
  const Estimate e = ordinary_least_squares(W, y);
  EXPECT_LT(rel(e.x, x), 1e-10);
  EXPECT_EQ(e.summary.rank, 8);
  EXPECT_EQ(e.summary.rows, 200);
  EXPECT_EQ(e.summary.columns, 8);
  EXPECT_EQ(e.degrees_of_freedom, 192);
  EXPECT_LT(e.relative_error, 1e-13);
  EXPECT_TRUE(e.unidentifiable.empty());
  const Estimate w = weighted_least_squares(W, y, joint_row_groups(200, 4));
  EXPECT_LT(rel(w.x, x), 1e-10);
  EXPECT_EQ(w.summary.estimator, EstimatorKind::kWeightedLeastSquares);
}

TEST(OrdinaryLeastSquares, MatchesColPivQrAndNormalEquationsOracle) {
  std::mt19937 rng(12);
  const Eigen::Index m = 300, p = 6;
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::VectorXd y = W * gaussian(p, 1, rng) + gaussian(m, 1, rng, 0.1);
  const Estimate e = ordinary_least_squares(W, y);
  const Eigen::VectorXd x_qr = W.colPivHouseholderQr().solve(y);
  EXPECT_LT(rel(e.x, x_qr), 1e-12);
  // Oracle covariance: σ²(WᵀW)⁻¹ with σ² from the oracle residual (W is well conditioned here).
  const double s2 = (y - W * x_qr).squaredNorm() / double(m - p);
  const Eigen::MatrixXd C = s2 * (W.transpose() * W).ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  EXPECT_NEAR(e.residual_variance, s2, 1e-12 * s2);
  EXPECT_LT(rel(e.covariance, C), 1e-10);
  EXPECT_LT(rel(e.std_dev, C.diagonal().cwiseSqrt()), 1e-10);
  for (Eigen::Index j = 0; j < p; ++j) {
    EXPECT_NEAR(e.relative_std_percent(j), 100.0 * std::sqrt(C(j, j)) / std::abs(x_qr(j)),
                1e-8 * e.relative_std_percent(j));
  }
  EXPECT_NEAR(e.residual_rms, std::sqrt((y - W * x_qr).squaredNorm() / double(m)), 1e-12);
  EXPECT_NEAR(e.relative_error, (y - W * x_qr).norm() / y.norm(), 1e-12);
  EXPECT_DOUBLE_EQ(e.confidence_level, 0.999);  // seed 2 Table 3 default
}

TEST(OrdinaryLeastSquares, ConditionNumberMatchesJacobiSvdOfW) {
  std::mt19937 rng(13);
  Eigen::MatrixXd W = gaussian(120, 7, rng);
  for (int j = 0; j < 7; ++j) W.col(j) *= std::pow(10.0, j - 3);  // badly scaled columns
  const Eigen::VectorXd y = gaussian(120, 1, rng);
  const Estimate e = ordinary_least_squares(W, y);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(W);
  const Eigen::VectorXd s = svd.singularValues();
  EXPECT_NEAR(e.summary.condition_number, s(0) / s(6), 1e-8 * s(0) / s(6));
  EXPECT_LT(rel(e.singular_values, s), 1e-10);
  EXPECT_GT(e.summary.condition_number, 1e4);
  bool warned = false;
  for (const auto& w : e.summary.warnings)
    warned |= w.find("condition number") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(OrdinaryLeastSquares, RankDeficiencyNamesUnidentifiableColumns) {
  std::mt19937 rng(14);
  const Eigen::Index m = 80, p = 6;
  Eigen::MatrixXd W = gaussian(m, p, rng);
  W.col(3) = W.col(1);  // only x1 + x3 is identifiable
  W.col(5).setZero();   // x5 does not act on y
  const Eigen::VectorXd y = W * gaussian(p, 1, rng) + gaussian(m, 1, rng, 0.01);
  EstimationOptions o;
  o.names = {"ZZ1", "MX1", "MY1", "MX2", "MY2", "Ia2"};
  const Estimate e = ordinary_least_squares(W, y, Eigen::VectorXi(), o);
  EXPECT_EQ(e.summary.rank, 4);
  EXPECT_EQ(e.unidentifiable, (std::vector<Eigen::Index>{1, 3, 5}));
  ASSERT_EQ(e.dependent_columns.size(), 2u);
  // Dropping the dependent columns leaves a full-rank W (oracle: SVD of the reduced matrix).
  std::vector<Eigen::Index> keep;
  for (Eigen::Index j = 0; j < p; ++j)
    if (std::find(e.dependent_columns.begin(), e.dependent_columns.end(), j) ==
        e.dependent_columns.end())
      keep.push_back(j);
  Eigen::MatrixXd Wr(m, keep.size());
  for (std::size_t k = 0; k < keep.size(); ++k) Wr.col(k) = W.col(keep[k]);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Wr);
  EXPECT_GT(svd.singularValues().minCoeff(), 1e-3 * svd.singularValues().maxCoeff());
  // Minimum-norm solution: oracle CompleteOrthogonalDecomposition.
  const Eigen::VectorXd x_cod = W.completeOrthogonalDecomposition().solve(y);
  EXPECT_LT(rel(e.x, x_cod), 1e-10);
  EXPECT_TRUE(std::isinf(e.std_dev(1)) && std::isinf(e.std_dev(3)) && std::isinf(e.std_dev(5)));
  EXPECT_TRUE(std::isfinite(e.std_dev(0)));
  EXPECT_TRUE(std::isinf(e.summary.condition_number));
  ASSERT_FALSE(e.summary.warnings.empty());
  const std::string& w = e.summary.warnings.front();
  EXPECT_NE(w.find("rank 4 < 6"), std::string::npos) << w;
  EXPECT_NE(w.find("MX1, MX2, Ia2"), std::string::npos) << w;
  EXPECT_EQ(e.degrees_of_freedom, m - 4);
}

TEST(StreamingLeastSquares, EqualsInMemoryBatchForAnyBlocking) {
  std::mt19937 rng(15);
  const Eigen::Index n = 3, samples = 700, m = n * samples, p = 9;
  Eigen::MatrixXd W = gaussian(m, p, rng);
  for (Eigen::Index j = 0; j < p; ++j) W.col(j) *= 1.0 + j;  // mildly scaled
  const Eigen::VectorXd sig = Eigen::Vector3d(0.02, 0.2, 1.0);
  Eigen::VectorXd y = W * gaussian(p, 1, rng);
  std::normal_distribution<double> nd(0.0, 1.0);
  for (Eigen::Index r = 0; r < m; ++r) y(r) += sig(r % n) * nd(rng);

  StreamingLeastSquares s(p, n);
  std::uniform_int_distribution<int> block(1, 97);
  for (Eigen::Index r = 0; r < m;) {
    const Eigen::Index b = std::min<Eigen::Index>(block(rng), m - r);
    s.add(W.middleRows(r, b), y.segment(r, b));
    r += b;
  }
  EXPECT_EQ(s.rows(), m);
  const Eigen::VectorXi groups = joint_row_groups(m, n);
  const Estimate batch = ordinary_least_squares(W, y, groups);
  const Estimate stream = s.solve_ordinary();
  const Eigen::VectorXd x_qr = W.colPivHouseholderQr().solve(y);  // independent in-memory oracle
  EXPECT_LT(rel(stream.x, x_qr), 1e-10);
  EXPECT_LT(rel(batch.x, x_qr), 1e-10);
  EXPECT_LT(rel(stream.covariance, batch.covariance), 1e-10);
  EXPECT_LT(rel(stream.group_rms, batch.group_rms), 1e-10);
  EXPECT_LT(rel(stream.group_variance, batch.group_variance), 1e-10);
  // RᵀR = [W y]ᵀ[W y] (the factor represents the data exactly).
  Eigen::MatrixXd Wy(m, p + 1);
  Wy << W, y;
  const Eigen::MatrixXd R = s.factor();
  EXPECT_LT(rel(R.transpose() * R, Wy.transpose() * Wy), 1e-12);
  EXPECT_TRUE(R.isUpperTriangular(0.0));
  // WLS: streaming == batch == oracle with the same weights applied to the raw rows.
  const Estimate ws = s.solve_weighted(), wb = weighted_least_squares(W, y, groups);
  EXPECT_LT(rel(ws.x, wb.x), 1e-10);
  Eigen::VectorXd rw(m);
  for (Eigen::Index r = 0; r < m; ++r) rw(r) = 1.0 / std::sqrt(ws.group_variance(r % n));
  const Eigen::VectorXd x_w =
      (rw.asDiagonal() * W).colPivHouseholderQr().solve(rw.asDiagonal() * y);
  EXPECT_LT(rel(ws.x, x_w), 1e-10);
  // Explicit groups in a shuffled row order give the same factors.
  StreamingLeastSquares t(p, n);
  t.add(W.bottomRows(m - 5), y.tail(m - 5), groups.tail(m - 5));
  t.add(W.topRows(5), y.head(5), groups.head(5));
  EXPECT_LT(rel(t.solve_ordinary().x, x_qr), 1e-10);
  EXPECT_EQ(t.group_rows(), (std::vector<Eigen::Index>{samples, samples, samples}));
}

TEST(OrdinaryLeastSquares, GroupStatisticsMatchDirectResidualsAndSubsystemFits) {
  std::mt19937 rng(16);
  const Eigen::Index n = 3, m = 3 * 40, p = 5;
  Eigen::MatrixXd W = gaussian(m, p, rng);
  for (Eigen::Index k = 1; k < m; k += n) W(k, 0) = 0.0;  // joint 1 does not see x0: rank 4
  const Eigen::VectorXd y = W * gaussian(p, 1, rng) + gaussian(m, 1, rng, 0.3);
  const Eigen::VectorXi g = joint_row_groups(m, n);
  const Estimate e = ordinary_least_squares(W, y, g);
  const Eigen::VectorXd x = W.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd r = y - W * x;
  for (int j = 0; j < n; ++j) {
    Eigen::MatrixXd Wj(m / n, p);
    Eigen::VectorXd yj(m / n), rj(m / n);
    for (Eigen::Index k = j, i = 0; k < m; k += n, ++i) {
      Wj.row(i) = W.row(k);
      yj(i) = y(k);
      rj(i) = r(k);
    }
    EXPECT_NEAR(e.group_rms(j), std::sqrt(rj.squaredNorm() / double(m / n)), 1e-12);
    EXPECT_NEAR(e.group_relative_error(j), rj.norm() / yj.norm(), 1e-12);
    // Oracle: the subsystem of joint j solved on its own by column-pivoting QR.
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Wj);
    const Eigen::Index rank = qr.rank();
    EXPECT_EQ(rank, j == 1 ? p - 1 : p);
    const double s2 = (yj - Wj * qr.solve(yj)).squaredNorm() / double(m / n - rank);
    EXPECT_NEAR(e.group_variance(j), s2, 1e-12 * s2);
    EXPECT_EQ(e.group_rows(j), double(m / n));
  }
}

TEST(WeightedLeastSquares, RecoversGroupVariancesAndMatchesGaussMarkovCovariance) {
  std::mt19937 rng(17);
  const Eigen::Index n = 3, samples = 2000, m = n * samples, p = 5;
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::Vector3d sig(0.01, 0.1, 1.0);
  Eigen::VectorXd y = W * gaussian(p, 1, rng);
  std::normal_distribution<double> nd(0.0, 1.0);
  for (Eigen::Index r = 0; r < m; ++r) y(r) += sig(r % n) * nd(rng);
  const Estimate e = weighted_least_squares(W, y, joint_row_groups(m, n));
  // σ̂_g²/σ_g² = ‖e_g‖²/(σ_g²(m_g − p)) with e_g the residual of group g's own least-squares fit
  // is exactly χ²(m_g − p)/(m_g − p) for Gaussian noise: require it between the 1e-6 and 1 − 1e-6
  // quantiles (about ±15 %), a failure probability of 2e-6 per group.
  const double d = double(samples - p);
  const boost::math::chi_squared chi(d);
  const double lo = boost::math::quantile(chi, 1e-6) / d;
  const double hi = boost::math::quantile(boost::math::complement(chi, 1e-6)) / d;
  for (int j = 0; j < n; ++j) {
    const double ratio = e.group_variance(j) / (sig(j) * sig(j));
    EXPECT_GT(ratio, lo) << j;
    EXPECT_LT(ratio, hi) << j;
  }
  EXPECT_EQ(e.summary.passes, 2);
  EXPECT_NEAR(e.residual_variance, 1.0, 0.1);  // weighted residuals have unit variance
  // Gauss–Markov oracle with the TRUE variances: C = (WᵀΣ⁻¹W)⁻¹. The reported covariance uses
  // the estimated weights (each σ_g within ~3 % at 1σ, 2000 rows) and σ_w² (~2 % at 1σ, 6000
  // rows), so σ_x agrees within a few %; 10 % is beyond 3σ of both effects combined.
  Eigen::VectorXd iw(m);
  for (Eigen::Index r = 0; r < m; ++r) iw(r) = 1.0 / (sig(r % n) * sig(r % n));
  const Eigen::MatrixXd info = W.transpose() * iw.asDiagonal() * W;
  const Eigen::MatrixXd C = info.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  for (Eigen::Index j = 0; j < p; ++j) {
    EXPECT_NEAR(e.std_dev(j) / std::sqrt(C(j, j)), 1.0, 0.1) << j;
  }
  // Efficiency: the true OLS covariance (sandwich) is larger than the WLS one for every parameter.
  const Eigen::MatrixXd A = (W.transpose() * W).ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::MatrixXd S = A * W.transpose() * iw.cwiseInverse().asDiagonal() * W * A;
  for (Eigen::Index j = 0; j < p; ++j) EXPECT_LT(e.std_dev(j), std::sqrt(S(j, j))) << j;
}

TEST(WeightedLeastSquares, MonteCarloErrorSmallerThanOrdinary) {
  std::mt19937 rng(18);
  const Eigen::Index n = 3, samples = 150, m = n * samples, p = 4;
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::VectorXd x = gaussian(p, 1, rng);
  const Eigen::Vector3d sig(0.02, 0.2, 2.0);
  const Eigen::VectorXi g = joint_row_groups(m, n);
  std::normal_distribution<double> nd(0.0, 1.0);
  double mse_ols = 0, mse_wls = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Eigen::VectorXd y = W * x;
    for (Eigen::Index r = 0; r < m; ++r) y(r) += sig(r % n) * nd(rng);
    mse_ols += (ordinary_least_squares(W, y).x - x).squaredNorm();
    mse_wls += (weighted_least_squares(W, y, g).x - x).squaredNorm();
  }
  // Expected ratio ≈ tr((WᵀΣ⁻¹W)⁻¹)/tr(sandwich) ≈ 3·0.02²/(0.02²+0.2²+2²)·… ≪ 0.1.
  EXPECT_LT(mse_wls, 0.1 * mse_ols);
}

// Monte-Carlo coverage of the Student-t intervals. With dof = 5 the normal quantile would give
// 89 % coverage at the 95 % level, far outside the 3σ binomial band: the test sees the t law.
class ConfidenceCoverage : public ::testing::TestWithParam<double> {};

TEST_P(ConfidenceCoverage, MatchesLevelWithinBinomialBand) {
  const double level = GetParam();
  const int trials = 400;
  const Eigen::Index m = 8, p = 3;
  std::mt19937 rng(19);
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::Vector3d x(1.0, -2.0, 0.5);
  EstimationOptions o;
  o.confidence_level = level;
  std::normal_distribution<double> nd(0.0, 0.3);
  Eigen::Vector3i inside = Eigen::Vector3i::Zero();
  for (int t = 0; t < trials; ++t) {
    Eigen::VectorXd y = W * x;
    for (Eigen::Index r = 0; r < m; ++r) y(r) += nd(rng);
    const Estimate e = ordinary_least_squares(W, y, Eigen::VectorXi(), o);
    for (int j = 0; j < 3; ++j) inside(j) += (e.ci_lower(j) <= x(j) && x(j) <= e.ci_upper(j));
  }
  const double mean = trials * level, sd = std::sqrt(trials * level * (1.0 - level));
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(inside(j), mean, 3.0 * sd) << "parameter " << j;
}

INSTANTIATE_TEST_SUITE_P(Levels, ConfidenceCoverage, ::testing::Values(0.95, 0.99));

TEST(Statistics, StudentQuantileMatchesTables) {
  // Printed t tables (e.g. Abramowitz & Stegun 26.10): t_{0.975}(5) = 2.5706, t_{0.995}(10) =
  // 3.1693, t_{0.9995}(30) = 3.6460; large dof tends to the normal 1.95996.
  EXPECT_NEAR(student_t_quantile(0.95, 5), 2.5706, 1e-4);
  EXPECT_NEAR(student_t_quantile(0.99, 10), 3.1693, 1e-4);
  EXPECT_NEAR(student_t_quantile(0.999, 30), 3.6460, 1e-4);
  EXPECT_NEAR(student_t_quantile(0.95, 1e7), 1.959964, 1e-5);
}

TEST(Statistics, PoorlyExcitedParametersAreListed) {
  std::mt19937 rng(20);
  const Eigen::Index m = 200, p = 4;
  Eigen::MatrixXd W = gaussian(m, p, rng);
  W.col(2) *= 1e-3;  // hardly excited: its σ_x is 1000× larger
  const Eigen::VectorXd y = W * Eigen::Vector4d(1, 1, 1, 1) + gaussian(m, 1, rng, 0.1);
  EstimationOptions o;
  o.names = {"a", "b", "c", "d"};
  o.condition_warning = 1e9;  // only the relative-σ rule here
  const Estimate e = ordinary_least_squares(W, y, Eigen::VectorXi(), o);
  EXPECT_EQ(e.poorly_excited, (std::vector<Eigen::Index>{2}));
  EXPECT_GT(e.relative_std_percent(2), 30.0);
  bool named = false;
  for (const auto& w : e.summary.warnings)
    named |= w.find("poorly excited parameters: c") != std::string::npos;
  EXPECT_TRUE(named);
  // Weak-direction rule: two nearly collinear columns dominate the smallest singular vector.
  Eigen::MatrixXd V = gaussian(m, p, rng);
  V.col(1) = V.col(0) + 1e-6 * V.col(1);
  const Eigen::VectorXd z = V * Eigen::Vector4d(1, 1, 1, 1);  // noise free: relative σ ≈ 0
  const Estimate f = ordinary_least_squares(V, z);
  EXPECT_GT(f.summary.condition_number, 1e4);
  EXPECT_EQ(f.poorly_excited, (std::vector<Eigen::Index>{0, 1}));
}

TEST(Errors, EveryBadInputHasAOneLineMessage) {
  Eigen::MatrixXd W = Eigen::MatrixXd::Ones(4, 3);
  Eigen::VectorXd y = Eigen::VectorXd::Ones(4);
  expect_error([&] { ordinary_least_squares(Eigen::MatrixXd(4, 0), y); }, {"no columns"});
  expect_error([&] { ordinary_least_squares(W.topRows(2), y.head(2)); },
               {"2 rows for 3 parameters", "at least 3 rows", "4 for the statistics"});
  expect_error([&] { ordinary_least_squares(W, Eigen::VectorXd::Ones(5)); },
               {"y has 5 rows but W has 4"});
  Eigen::MatrixXd Wn = W;
  Wn(2, 1) = std::nan("");
  expect_error([&] { ordinary_least_squares(Wn, y); }, {"W row 2", "NaN or Inf"});
  Eigen::VectorXd yn = y;
  yn(3) = INFINITY;
  expect_error([&] { ordinary_least_squares(W, yn); }, {"y row 3", "NaN or Inf"});
  expect_error([&] { weighted_least_squares(W, y, Eigen::VectorXi::Zero(3)); },
               {"groups has 3 entries but W has 4 rows"});
  expect_error([&] { weighted_least_squares(W, y, Eigen::Vector4i(0, 1, -1, 0)); },
               {"groups row 2 is -1"});
  EstimationOptions bad_names;
  bad_names.names = {"a"};
  expect_error([&] { ordinary_least_squares(W, y, Eigen::VectorXi(), bad_names); },
               {"names has 1 entries but W has 3 columns"});
  EstimationOptions bad_level;
  bad_level.confidence_level = 1.0;
  expect_error([&] { ordinary_least_squares(W, y, Eigen::VectorXi(), bad_level); },
               {"confidence_level", "outside (0, 1)"});
  expect_error([&] { joint_row_groups(4, 0); }, {"joints is 0"});
  expect_error([&] { student_t_quantile(0.95, 0.0); }, {"degrees of freedom"});

  expect_error([&] { StreamingLeastSquares(0, 1); }, {"parameters is 0"});
  expect_error([&] { StreamingLeastSquares(3, 0); }, {"groups is 0"});
  StreamingLeastSquares s(3, 2);
  s.add(W, y);
  expect_error([&] { s.add(Eigen::MatrixXd::Ones(2, 4), Eigen::VectorXd::Ones(2)); },
               {"W has 4 columns but the estimator has 3 parameters"});
  expect_error([&] { s.add(Wn, y); }, {"W row 6", "NaN or Inf"});  // stream row 4 + 2
  expect_error([&] { s.add(W, y, Eigen::Vector4i(0, 1, 2, 0)); }, {"groups row 6 is 2", "[0, 2)"});
  expect_error([&] { s.solve_weighted(Eigen::Vector2d(1.0, 0.0)); },
               {"group_std(1)", "positive finite"});
  expect_error([&] { s.solve_weighted(Eigen::Vector3d(1.0, 1.0, 1.0)); },
               {"group_std has 3 entries for 2 groups"});
  StreamingLeastSquares few(3, 1);
  few.add(W.topRows(2), y.head(2));
  expect_error([&] { few.solve_ordinary(); }, {"2 rows for 3 parameters"});
}

TEST(WeightedLeastSquares, GroupWithoutDegreesOfFreedomUsesPooledVariance) {
  std::mt19937 rng(22);
  const Eigen::Index m = 60, p = 3;
  const Eigen::MatrixXd W = gaussian(m, p, rng);
  const Eigen::VectorXd y = W * Eigen::Vector3d(1, 2, 3) + gaussian(m, 1, rng, 0.1);
  Eigen::VectorXi g = Eigen::VectorXi::Zero(m);
  g.tail(2).setOnes();  // group 1: 2 rows for 3 parameters, no noise estimate of its own
  const Estimate ols = ordinary_least_squares(W, y, g);
  EXPECT_TRUE(std::isnan(ols.group_variance(1)));
  const Estimate e = weighted_least_squares(W, y, g);
  EXPECT_DOUBLE_EQ(e.group_variance(1), ols.residual_variance);
  ASSERT_FALSE(e.summary.warnings.empty());
  EXPECT_NE(e.summary.warnings.front().find("group 1 has too few rows"), std::string::npos);
  const std::string report = e.summary.brief_report();
  EXPECT_NE(report.find("weighted_least_squares: 60 rows, 3 parameters, rank 3"), std::string::npos)
      << report;
}

TEST(OrdinaryLeastSquares, SquareSystemHasNoStatistics) {
  std::mt19937 rng(21);
  const Eigen::MatrixXd W = gaussian(3, 3, rng);
  const Eigen::VectorXd x(Eigen::Vector3d(1, 2, 3));
  const Estimate e = ordinary_least_squares(W, W * x);
  EXPECT_LT(rel(e.x, x), 1e-10);
  EXPECT_EQ(e.degrees_of_freedom, 0);
  EXPECT_TRUE(std::isnan(e.std_dev(0)));
  EXPECT_FALSE(e.summary.warnings.empty());
}

// Issue 26 item 6: the warnings a user reads give numbers in 4 significant digits (not
// "69928.253607 exceeds 10000.000000") and end a rank deficiency with the caller's remedy.
TEST(OrdinaryLeastSquares, WarningsUseShortNumbersAndTheCallersRemedy) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  Eigen::MatrixXd W(200, 3);
  for (Eigen::Index i = 0; i < W.rows(); ++i) {
    const double a = g(rng), b = g(rng), c = g(rng);
    // cond(W) ~ 1e6, above the 1e4 warning, at full rank (a third column a + 1e-6·b would be an
    // exact combination of the first two: rank 2, cond 1e15 from round-off).
    W.row(i) << a, b, a + 1e-6 * c;
  }
  Eigen::VectorXd y = W * Eigen::Vector3d(1, 2, 3);
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] += 0.01 * g(rng);
  const Estimate e = ordinary_least_squares(W, y);
  ASSERT_EQ(e.summary.rank, 3);
  std::string condition;
  for (const auto& w : e.summary.warnings)
    if (w.rfind("condition number ", 0) == 0) condition = w;
  ASSERT_FALSE(condition.empty()) << ::testing::PrintToString(e.summary.warnings);
  EXPECT_NE(condition.find(" exceeds 1e+04:"), std::string::npos) << condition;
  const std::string value = condition.substr(17, condition.find(' ', 17) - 17);
  // At most 4 significant digits: the mantissa before any exponent has at most 5 characters.
  EXPECT_LE(value.substr(0, value.find('e')).size(), 5u) << condition;
  EXPECT_NEAR(std::stod(value), e.summary.condition_number, 1e-3 * e.summary.condition_number);

  Eigen::MatrixXd Z = W;
  Z.col(2).setZero();  // a column the data do not determine
  EstimationOptions options;
  options.names = {"a", "b", "c"};
  const auto rank_warning = [](const Estimate& x) {
    for (const auto& w : x.summary.warnings)
      if (w.rfind("W is rank deficient", 0) == 0) return w;
    return std::string();
  };
  const Estimate zero_column = ordinary_least_squares(Z, y, Eigen::VectorXi(), options);
  const std::string plain = rank_warning(zero_column);
  EXPECT_NE(plain.find("regroup them into base parameters"), std::string::npos) << plain;
  // The zero column is named by the rank warning; no warning speaks of an infinite condition
  // number, and the determined columns a and b are well conditioned (independent Gaussians).
  EXPECT_TRUE(std::isinf(zero_column.summary.condition_number));
  for (const auto& w : zero_column.summary.warnings)
    EXPECT_EQ(w.find("number inf"), std::string::npos) << w;
  Eigen::MatrixXd Zc = W;
  Zc.col(1) = Zc.col(0) + 1e-6 * Zc.col(1);  // columns 1, 2 nearly collinear: cond ~ 1e6 ...
  Zc.col(2).setZero();                       // ... beside a column zero by design
  std::string weak;
  for (const auto& w : ordinary_least_squares(Zc, y, Eigen::VectorXi(), options).summary.warnings)
    if (w.rfind("condition number ", 0) == 0) weak = w;
  EXPECT_NE(weak.find(" of the 2 determined directions exceeds 1e+04"), std::string::npos) << weak;
  options.rank_deficient_remedy = "record a longer run";
  const std::string own = rank_warning(ordinary_least_squares(Z, y, Eigen::VectorXi(), options));
  EXPECT_NE(own.find("parameters c are not identifiable individually; record a longer run"),
            std::string::npos)
      << own;
  EXPECT_EQ(own.find("regroup"), std::string::npos) << own;
}

}  // namespace
}  // namespace dynid
