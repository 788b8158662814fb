// The identification pipeline's stages (docs/design.md §8) and the several-run / data-rank
// behaviour of issue 11 items 2–4. Plants: planar2 and irp6 in closed loop under a PID fed by
// encoder noise, a tanh-smoothed Coulomb term in the forward dynamics (simulate_reference), so the
// torques are not the regressor's. Fixed seeds.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "dynid/estimation/least_squares.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/pipeline.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/physical/completed_model.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "support/closed_loop_runs.hpp"
#include "support/estimation_support.hpp"

namespace dynid {
namespace {

constexpr double kRate = 100.0;

// Six periods of a 0.2 Hz reference in closed loop, the first (start-up) period dropped. Joints
// with move[j] false are held at q0[j] by their controller (they jitter by the encoder noise).
JointRecord closed_loop_run(const Model& m, const Eigen::VectorXd& q0,
                            const std::vector<bool>& move, unsigned seed, double scale = 1.0) {
  const int n = m.dof();
  FourierCoefficients c = FourierCoefficients::zeros(std::vector<int>(n, 4), 0.2);
  const double a[3][4] = {{0.8, 0.3, -0.2, 0.1}, {-0.6, 0.4, 0.2, -0.1}, {0.5, -0.3, 0.2, 0.1}};
  const double b[3][4] = {{0.2, -0.3, 0.1, 0.05}, {0.3, 0.2, -0.2, 0.1}, {-0.2, 0.3, 0.1, -0.1}};
  for (int j = 0; j < n; ++j) {
    if (!move[static_cast<size_t>(j)]) continue;
    for (int h = 0; h < 4; ++h) {
      c.a[static_cast<size_t>(j)][h] = scale * a[j % 3][h];
      c.b[static_cast<size_t>(j)][h] = scale * b[j % 3][h];
    }
  }
  c.q0 = q0;
  const TrajectorySamples tr = sample_trajectory(FourierTrajectory(c), kRate, false);
  return testing::closed_loop_run(m, tr, testing::noisy_sensors(1e-5, 0.05, seed, 6));
}

// simulate_reference logs the command it then holds for one period.
IdentifyOptions held_torque() {
  IdentifyOptions o;
  o.signal.torque_time_offset = 0.5 / kRate;
  return o;
}

Model friction_planar2() {
  return testing::planar2_with_friction();
}

// The true base-parameter value of each estimated name (coupled-motor columns are zero in truth).
Eigen::VectorXd truth_of(const Model& m, const IdentificationResult& r) {
  Eigen::VectorXd theta =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(r.base.layout_names.size()));
  const Eigen::VectorXd layout = ParameterLayout::full().parameters(m);
  theta.head(layout.size()) = layout;
  const Eigen::VectorXd all = r.base.reduce(theta);
  auto value = [&](const std::string& name) {
    const auto it = std::find(r.base.names.begin(), r.base.names.end(), name);
    EXPECT_NE(it, r.base.names.end()) << name;
    return all[it - r.base.names.begin()];
  };
  Eigen::VectorXd out(static_cast<Eigen::Index>(r.names.size()));
  Eigen::VectorXd missing(static_cast<Eigen::Index>(r.not_excited.size()));
  for (size_t i = 0; i < r.names.size(); ++i) out[static_cast<Eigen::Index>(i)] = value(r.names[i]);
  for (size_t i = 0; i < r.not_excited.size(); ++i)
    missing[static_cast<Eigen::Index>(i)] = value(r.not_excited[i]);
  // What the data determine: each estimate includes the unexcited parameters' share.
  if (missing.size()) out += r.data_regrouping * missing;
  return out;
}

std::string outside(const Model& m, const IdentificationResult& r) {
  const Eigen::VectorXd truth = truth_of(m, r);
  std::string missed;
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    if (!(r.estimate.ci_lower[i] <= truth[i] && truth[i] <= r.estimate.ci_upper[i])) {
      missed += r.names[static_cast<size_t>(i)] + " ";
    }
  }
  return missed;
}

JointRecord exact_planar2_run(const Model& m) {
  // Exact derivatives of a smooth trajectory; torques are irrelevant to the row structure.
  const int k = 200;
  JointRecord r;
  r.t = Eigen::VectorXd::LinSpaced(k, 0.0, 1.99);
  r.q.resize(k, 2);
  r.dq.resize(k, 2);
  r.ddq.resize(k, 2);
  for (int i = 0; i < k; ++i) {
    const double t = r.t[i];
    r.q.row(i) << std::sin(t), 0.3 * std::cos(2 * t);
    r.dq.row(i) << std::cos(t), -0.6 * std::sin(2 * t);
    r.ddq.row(i) << -std::sin(t), -1.2 * std::cos(2 * t);
  }
  r.tau = Eigen::MatrixXd::Random(k, 2);
  (void)m;
  return r;
}

TEST(DifferentialEquations, RowsAreTheRegressorRowsOfTheSamplesAboveTheThreshold) {
  const Model m = load_robot("planar2");
  ProcessedRecord p;
  p.record = exact_planar2_run(m);
  const Eigen::VectorXd threshold = Eigen::Vector2d(0.5, 0.2);
  const EquationBlock b = differential_equations(m, ParameterLayout::full(), false, p, threshold);
  const Eigen::MatrixXd Y = stacked_regressor(m, ParameterLayout::full(), false, p.record);
  Eigen::Index i = 0;
  for (Eigen::Index k = 0; k < p.record.t.size(); ++k) {
    for (int j = 0; j < 2; ++j) {
      if (std::abs(p.record.dq(k, j)) < threshold[j]) continue;
      ASSERT_LT(i, b.y.size());
      EXPECT_EQ(b.sample[i], k);
      EXPECT_EQ(b.group[i], j);
      EXPECT_EQ(b.t[i], p.record.t[k]);
      EXPECT_EQ(b.y[i], p.record.tau(k, j));
      EXPECT_EQ((b.W.row(i) - Y.row(k * 2 + j)).norm(), 0.0);
      ++i;
    }
  }
  EXPECT_EQ(i, b.y.size());
  EXPECT_LT(b.y.size(), 2 * p.record.t.size());  // the thresholds removed rows
  // Without Coulomb friction no row is removed.
  ParameterLayout no_coulomb = ParameterLayout::full();
  no_coulomb.coulomb = false;
  EXPECT_EQ(differential_equations(m, no_coulomb, false, p, threshold).y.size(),
            2 * p.record.t.size());
  EXPECT_THROW(
      differential_equations(m, ParameterLayout::full(), false, p, Eigen::Vector3d::Ones()), Error);
}

TEST(StackEquations, RunsKeepTheirRowsAndNoSampleWindowSpansTwoRuns) {
  const Model m = load_robot("planar2");
  ProcessedRecord p;
  p.record = exact_planar2_run(m);
  const EquationBlock a = differential_equations(m, ParameterLayout::full(), false, p, {});
  const EquationBlock s = stack_equations({a, a, a}, 7);
  ASSERT_EQ(s.y.size(), 3 * a.y.size());
  EXPECT_EQ((s.W.bottomRows(a.y.size()) - a.W).norm(), 0.0);
  const int last = a.sample.maxCoeff();
  for (Eigen::Index r = 1; r < 3; ++r) {
    const int end_prev = s.sample[r * a.y.size() - 1], start = s.sample[r * a.y.size()];
    EXPECT_EQ(start - end_prev, 8) << "run " << r;  // 7 empty samples between runs
    EXPECT_EQ(s.sample[(r + 1) * a.y.size() - 1] - start, last);
  }
  EXPECT_THROW(stack_equations({a, a}, 0), Error);
  EquationBlock other = a;
  other.columns.pop_back();
  EXPECT_THROW(stack_equations({a, other}), Error);
  EXPECT_THROW(stack_equations({}), Error);
}

TEST(DataIdentifiability, ZeroAndRepeatedColumnsAreNotExcitedAndTheirShareIsNamed) {
  std::mt19937 rng(7);
  EquationBlock b;
  b.W = estimation_testing::gaussian(50, 4, rng);
  b.W.col(1).setZero();           // never excited
  b.W.col(3) = 2.0 * b.W.col(0);  // indistinguishable from column 0
  b.columns = {"a", "b", "c", "d"};
  const DataIdentifiability d = data_identifiability(b);
  EXPECT_EQ(d.rank, 2);
  EXPECT_EQ(d.kept, (std::vector<int>{0, 2}));
  EXPECT_EQ(d.not_excited, (std::vector<int>{1, 3}));
  // W·θ = W_0·(θ_a + 2θ_d) + W_2·θ_c: the kept "a" absorbs 2·θ_d.
  ASSERT_EQ(d.absorbs[0].size(), 1u);
  EXPECT_EQ(d.absorbs[0][0].first, 3);
  EXPECT_NEAR(d.absorbs[0][0].second, 2.0, 1e-12);
  EXPECT_TRUE(d.absorbs[1].empty());
  // The repeated column is regrouped exactly; the zero one has nothing to regroup.
  EXPECT_EQ(d.regrouped, std::vector<int>{3});
}

// Issue 28 item 7: a column equal to a kept one up to round-off is a regrouping of the data; a
// column the noise leaves undetermined (nearly, not exactly, collinear: the statistical rule of
// issue 25) is not, and keeps being only not excited.
TEST(DataIdentifiability, ExactlyCollinearColumnsAreRegroupedNoisyOnesOnlyNotDetermined) {
  std::mt19937 rng(11);
  EquationBlock b;
  b.W = estimation_testing::gaussian(200, 4, rng);
  const Eigen::MatrixXd wiggle = estimation_testing::gaussian(200, 1, rng);
  b.W.col(2) = b.W.col(0) + b.W.col(1) + 1e-15 * wiggle;  // = a + b to round-off
  b.W.col(3) = b.W.col(1) + 1e-4 * wiggle;                // not exact: 1e-4 off
  b.columns = {"a", "b", "c", "d"};
  const Eigen::Vector4d theta(1.0, 2.0, 3.0, 4.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  b.y = b.W * theta;
  for (Eigen::Index i = 0; i < b.y.size(); ++i) b.y[i] += noise(rng);
  const DataIdentifiability d = data_identifiability(b);
  EXPECT_EQ(d.kept, (std::vector<int>{0, 1}));
  EXPECT_EQ(d.not_excited, (std::vector<int>{2, 3}));
  EXPECT_EQ(d.regrouped, std::vector<int>{2});
  // Without noise the 1e-4 difference is determined (only the round-off floor applies).
  b.y = b.W * theta;
  const DataIdentifiability exact = data_identifiability(b);
  EXPECT_EQ(exact.kept, (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(exact.regrouped, std::vector<int>{2});
}

// Issue 25 item 1, the statistical rule: columns a, a + δ·e and c (2000 Gaussian rows, y = their
// sum + noise). Scaled to unit norm, a and a + δ·e differ by δ: the direction separating them has
// singular value δ/√2, and its coefficient in the scaled parameters is fitted with standard
// deviation ŝ/σ. It is determined when that is below its plausible magnitude ‖y‖ (σ ≥ ŝ/‖y‖),
// whatever σ/σ_max is (the former rule: above 1e-6). docs/methods/identification.md tabulates
// the sweep over δ; three points of it here.
EquationBlock near_pair(double delta, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const int m = 2000;
  EquationBlock b;
  b.W.resize(m, 3);
  for (int i = 0; i < m; ++i) {
    const double a = g(rng), e = g(rng), c = g(rng);
    b.W.row(i) << a, a + delta * e, c;
  }
  b.y = b.W * Eigen::Vector3d::Ones();
  const double rms = b.y.norm() / std::sqrt(static_cast<double>(m));
  for (int i = 0; i < m; ++i) b.y[i] += noise * rms * g(rng);
  b.group = Eigen::VectorXi::Zero(m);
  b.sample = Eigen::VectorXi::LinSpaced(m, 0, m - 1);
  b.t = b.sample.cast<double>();
  b.columns = {"a", "b", "c"};
  b.group_names = {"g"};
  return b;
}

TEST(DataIdentifiability, ADirectionIsDeterminedWhenItsStdIsBelowItsPlausibleMagnitude) {
  BlockEstimationOptions white;
  white.hac_bandwidth = 0;
  // Nearly noise-free (1e-9): σ/σ_max = 5e-7 is below the former 1e-6, yet the data fix θ_b to
  // 5e-5: kept, and the truth (1) inside its interval.
  {
    const EquationBlock b = near_pair(1e-6, 1e-9, 1);
    const DataIdentifiability d = data_identifiability(b);
    EXPECT_EQ(d.rank, 3);
    EXPECT_TRUE(d.not_excited.empty());
    EXPECT_LT(d.tolerance, 5e-7);
    const BlockEstimate e = estimate_block(b, white);
    EXPECT_LT(e.estimate.std_dev[1], 1e-3);
    EXPECT_LE(e.estimate.ci_lower[1], 1.0);
    EXPECT_GE(e.estimate.ci_upper[1], 1.0);
  }
  // 1 % noise: σ/σ_max = 5e-6 passed the former rule, but the separating direction's standard
  // deviation is 30x the whole torque (θ_b = 1 ± 50): not determined; "a" absorbs "b".
  {
    const EquationBlock b = near_pair(1e-5, 0.01, 2);
    const DataIdentifiability d = data_identifiability(b);
    EXPECT_EQ(d.rank, 2);
    EXPECT_EQ(d.not_excited, (std::vector<int>{1}));
    EXPECT_NEAR(d.noise_std, 0.01 * b.y.norm() / std::sqrt(2000.0), 0.1 * d.noise_std);
    EXPECT_NEAR(d.plausible_magnitude, b.y.norm(), 1e-9 * b.y.norm());
    const BlockEstimate forced = estimate_block(b, white);
    EXPECT_GT(forced.estimate.std_dev[1], b.y.norm() / b.W.col(1).norm());
    ASSERT_EQ(d.absorbs[0].size(), 1u);
    EXPECT_NEAR(d.absorbs[0][0].second, 1.0, 1e-3);
  }
  // 1 % noise, δ = 1e-2: σ well above ŝ/‖y‖; kept, the truth inside its interval.
  {
    const EquationBlock b = near_pair(1e-2, 0.01, 3);
    const DataIdentifiability d = data_identifiability(b);
    EXPECT_EQ(d.rank, 3);
    const BlockEstimate e = estimate_block(b, white);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(e.estimate.ci_lower[i], 1.0) << i;
      EXPECT_GE(e.estimate.ci_upper[i], 1.0) << i;
    }
  }
}

// Over 25 seeds at 1 % noise the rule's boundary is σ = ŝ/‖y‖: every δ whose separating
// direction has σ below half of it is left out, every δ with σ above twice it is kept, and where
// kept the forced estimate's standard deviation is below the plausible magnitude ‖y‖/‖W_b‖.
TEST(DataIdentifiability, TheBoundaryIsWhereTheStdReachesThePlausibleMagnitude) {
  BlockEstimationOptions white;
  white.hac_bandwidth = 0;
  for (const double delta : {1e-5, 1e-4, 1e-3, 1e-2}) {
    for (unsigned seed = 10; seed < 35; ++seed) {
      const EquationBlock b = near_pair(delta, 0.01, seed);
      const DataIdentifiability d = data_identifiability(b);
      const double boundary = d.noise_std / d.plausible_magnitude;  // absolute σ
      const double sigma = delta / std::sqrt(2.0);
      if (sigma < 0.5 * boundary) {
        EXPECT_EQ(d.rank, 2) << delta << " seed " << seed;
      } else if (sigma > 2.0 * boundary) {
        EXPECT_EQ(d.rank, 3) << delta << " seed " << seed;
        const BlockEstimate e = estimate_block(b, white);
        EXPECT_LT(e.estimate.std_dev[1], b.y.norm() / b.W.col(1).norm()) << delta;
      }
    }
  }
}

// The columns an estimate lives on, by name and in the names' order.
TEST(SelectNamedColumns, TakesTheNamedColumnsInTheirOrderAndRefusesOthers) {
  std::mt19937 rng(5);
  EquationBlock b;
  b.W = estimation_testing::gaussian(6, 4, rng);
  b.y = Eigen::VectorXd::LinSpaced(6, 1.0, 6.0);
  b.columns = {"a", "b", "c", "d"};
  const EquationBlock s = select_named_columns(b, {"d", "a"});
  EXPECT_EQ(s.columns, (std::vector<std::string>{"d", "a"}));
  ASSERT_EQ(s.W.cols(), 2);
  EXPECT_EQ(s.W.col(0), b.W.col(3));
  EXPECT_EQ(s.W.col(1), b.W.col(0));
  EXPECT_EQ(s.y, b.y);
  EXPECT_THROW(select_named_columns(b, {"a", "e"}), Error);
}

// What each estimate of a data-deficient result stands for: its own base value plus the data
// regrouping of the ones not excited (the demo's truth column and the tests' truths).
TEST(EstimatedBaseValues, KeptValuesPlusTheShareOfTheNotExcitedOnes) {
  IdentificationResult r;
  r.base.names = {"A", "B", "C"};
  r.names = {"A", "C"};
  r.not_excited = {"B"};
  r.data_regrouping = (Eigen::MatrixXd(2, 1) << 2.0, 0.5).finished();
  const Eigen::VectorXd v = estimated_base_values(r, Eigen::Vector3d(1.0, 10.0, 100.0));
  ASSERT_EQ(v.size(), 2);
  EXPECT_DOUBLE_EQ(v[0], 1.0 + 2.0 * 10.0);
  EXPECT_DOUBLE_EQ(v[1], 100.0 + 0.5 * 10.0);
  EXPECT_THROW(estimated_base_values(r, Eigen::Vector2d(1.0, 10.0)), Error);
  r.data_regrouping.resize(3, 1);  // one row per estimate or it is an error
  EXPECT_THROW(estimated_base_values(r, Eigen::Vector3d(1.0, 10.0, 100.0)), Error);
  // Every parameter excited: the base values themselves, in the result's order.
  IdentificationResult all;
  all.base.names = {"A", "B"};
  all.names = {"A", "B"};
  EXPECT_EQ(estimated_base_values(all, Eigen::Vector2d(3.0, 4.0)), Eigen::Vector2d(3.0, 4.0));
}

TEST(EstimateBlock, OrdinaryLeastSquaresOfTheBlockAndItsGroupResiduals) {
  std::mt19937 rng(3);
  EquationBlock b;
  b.W = estimation_testing::gaussian(400, 3, rng);
  const Eigen::Vector3d x(1.0, -2.0, 0.5);
  b.y = b.W * x + estimation_testing::gaussian(400, 1, rng, 0.01);
  b.group = Eigen::VectorXi::LinSpaced(400, 0, 399).unaryExpr([](int i) { return i % 2; });
  b.sample = Eigen::VectorXi::LinSpaced(400, 0, 399).unaryExpr([](int i) { return i / 2; });
  b.t = b.sample.cast<double>();
  b.columns = {"x1", "x2", "x3"};
  b.group_names = {"even", "odd"};
  const BlockEstimate e = estimate_block(b, {});
  // Oracle: normal equations.
  const Eigen::Vector3d normal = (b.W.transpose() * b.W).ldlt().solve(b.W.transpose() * b.y);
  EXPECT_LT((e.estimate.x - normal).norm(), 1e-10);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(e.estimate.ci_lower[i], x[i]);
    EXPECT_GE(e.estimate.ci_upper[i], x[i]);
  }
  const Eigen::VectorXd r = b.y - b.W * normal;
  double even = 0.0;
  for (int i = 0; i < 400; i += 2) even += r[i] * r[i];
  EXPECT_NEAR(e.group_rms[0], std::sqrt(even / 200.0), 1e-12);
}

TEST(EstimateBlock, RlsHistoryEndsAtTheBatchEstimateAndNarrows) {
  std::mt19937 rng(5);
  EquationBlock b;
  b.W = estimation_testing::gaussian(300, 3, rng);
  b.y = b.W * Eigen::Vector3d(1.0, 2.0, 3.0) + estimation_testing::gaussian(300, 1, rng, 0.1);
  b.group = Eigen::VectorXi::Zero(300);
  b.sample = Eigen::VectorXi::LinSpaced(300, 0, 299);
  b.t = b.sample.cast<double>() * 0.01;
  b.columns = {"a", "b", "c"};
  b.group_names = {"g"};
  BlockEstimationOptions o;
  o.estimator = IdentificationEstimator::kRls;
  o.record_history = true;
  const BlockEstimate e = estimate_block(b, o);
  ASSERT_EQ(e.history_x.rows(), 300);
  EXPECT_LT((e.history_x.row(299).transpose() - e.estimate.x).norm(), 1e-12);
  // σ after all rows equals the estimate's white σ (same σ²·P).
  const Eigen::VectorXd white =
      e.estimate.std_dev_white.size() ? e.estimate.std_dev_white : e.estimate.std_dev;
  EXPECT_LT((e.history_std.row(299).transpose() - white).norm() / white.norm(), 1e-9);
  EXPECT_TRUE(std::isnan(e.history_std(1, 0)));  // fewer rows than parameters: no σ
  EXPECT_GT(e.history_std(20, 0), e.history_std(299, 0));
}

TEST(PersistentExcitation, HoldsFromTheTimeEveryColumnIsExcited) {
  std::mt19937 rng(9);
  EquationBlock b;
  b.W = estimation_testing::gaussian(400, 3, rng);
  b.W.col(2).head(200).setZero();  // the third parameter is excited only from row 200 on
  b.t = Eigen::VectorXd::LinSpaced(400, 0.0, 3.99);
  const ExcitationSummary s = persistent_excitation(b, 40);
  EXPECT_EQ(s.window, 40);
  EXPECT_EQ(s.min_eigenvalue, 0.0);
  EXPECT_GT(s.max_eigenvalue, 0.0);
  // Windows of 40 rows at a stride of 20: the first to reach row 200 is rows 180–219, and every
  // later one has rows of the third column too.
  EXPECT_NEAR(s.holds_from_t, b.t[219], 1e-12);
}

// Issue 11 item 2: two runs of a simulated robot identified together equal the least-squares
// solution of their stacked equations, and the truth lies inside the intervals.
TEST(SeveralRuns, TwoRunsGiveTheStackedSolutionAndCoverTheTruth) {
  const Model m = friction_planar2();
  const JointRecord a = closed_loop_run(m, Eigen::Vector2d(-0.5, 0.8), {true, true}, 11);
  const JointRecord b = closed_loop_run(m, Eigen::Vector2d(0.4, -0.6), {true, true}, 12);
  const IdentificationResult both = identify(m, std::vector<JointRecord>{a, b}, held_torque());
  ASSERT_EQ(both.runs.size(), 2u);
  EXPECT_EQ(both.rows, both.runs[0].rows + both.runs[1].rows);
  EXPECT_EQ(both.data_rank, both.rank);
  EXPECT_TRUE(both.not_excited.empty());
  // Oracle: each run alone through identify() gives its processed run; normal equations of
  // the two runs' base rows together.
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(both.rank, both.rank);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(both.rank);
  for (const JointRecord* run : {&a, &b}) {
    const IdentificationResult one = identify(m, *run, held_torque());
    const EquationBlock e =
        select_base_columns(differential_equations(m, ParameterLayout::full(), false, one.processed,
                                                   one.zero_velocity_threshold),
                            one.base);
    EXPECT_EQ(e.y.size(), one.rows);
    N += e.W.transpose() * e.W;
    rhs += e.W.transpose() * e.y;
  }
  const Eigen::VectorXd x = N.ldlt().solve(rhs);
  EXPECT_LT((both.estimate.x - x).norm() / x.norm(), 1e-8);
  EXPECT_TRUE(both.estimate.std_dev.allFinite());
}

// Each run alone covers the truth (|z| < 2.5 for every base parameter, z = (x − truth)/σ);
// together one parameter, ZZ1R, lies 3.6 σ from it (99.9 % critical value 3.46): the robot-level
// coverage check of docs/methods/estimation.md §5 (at most one of the ~13 base parameters outside,
// as FrictionSelection uses) holds. The union's extra information exposes a small plant-versus-
// model mismatch of the closed-loop simulation (tanh Coulomb, held command) that one run hides in
// its correlated directions; not yet explained.
TEST(SeveralRuns, TwoRunsCoverTheTruthAtRobotLevel) {
  const Model m = friction_planar2();
  const JointRecord a = closed_loop_run(m, Eigen::Vector2d(-0.5, 0.8), {true, true}, 11);
  const JointRecord b = closed_loop_run(m, Eigen::Vector2d(0.4, -0.6), {true, true}, 12);
  const std::string missed = outside(m, identify(m, std::vector<JointRecord>{a, b}, held_torque()));
  EXPECT_LE(std::count(missed.begin(), missed.end(), ' '), 1) << missed;
}

// Issue 11 item 3, seed 1 §VI-A: runs that move a few joints of the 3-joint IRp-6 each excite
// only part of the base set (data rank below the model rank, the rest named, no σ = inf);
// together they excite what none does alone. Coverage of the truth (with data_regrouping) is not
// asserted: the joint-1-and-3 run alone puts ZZ3R 4.8 σ from it, the union 6.5 σ and Fv3 4.3 σ
// (see the two-run test: the same unexplained plant mismatch, larger here).
TEST(SeveralRuns, FewJointRunsOfTheIrp6AreDataDeficientAloneAndCompleteTogether) {
  const Model m = load_robot("irp6");
  const Eigen::Vector3d q0(0.2, -0.3, 0.4);
  const JointRecord j1 = closed_loop_run(m, q0, {true, false, false}, 21);
  const JointRecord j2 =
      closed_loop_run(m, Eigen::Vector3d(0.5, -0.1, -0.3), {false, true, false}, 22);
  const JointRecord j13 =
      closed_loop_run(m, Eigen::Vector3d(-0.4, 0.3, 0.1), {true, false, true}, 23);
  int best_alone = 0;
  for (const JointRecord* run : {&j1, &j2, &j13}) {
    const IdentificationResult r = identify(m, *run, held_torque());
    EXPECT_LT(r.data_rank, r.rank);
    EXPECT_EQ(static_cast<int>(r.names.size()), r.data_rank);
    EXPECT_EQ(static_cast<int>(r.not_excited.size()), r.rank - r.data_rank);
    EXPECT_TRUE(r.estimate.std_dev.allFinite());
    best_alone = std::max(best_alone, r.data_rank);
  }
  const IdentificationResult all =
      identify(m, std::vector<JointRecord>{j1, j2, j13}, held_torque());
  EXPECT_GT(all.data_rank, best_alone);
  // Motor 3 turns with q2 + q3 and no run moves joints 2 and 3 together: its viscous column and
  // Ia3R stay tied to the joints' own (seed 1 moved single joints of a model without them).
  // XZ2R and YZ2 act only through the coupling of joints 1 and 2 moving together, which no run
  // has: their columns are zero up to round-off (1e-17), not data. XX2R (the sin²q2 part of
  // joint 1's inertia) is told from ZZ1R only by the two fixed q2 of the joint-1 runs: a
  // column-scaled singular value of 1.4e-5, whose standard deviation is 3x the whole torque
  // (issue 25's statistical rule; the 1e-6 ratio kept it: XX2R = 1501 ± 11997 for a true -3.2,
  // and ZZ1R = -126 ± 1048 for 5.7). Now ZZ1R absorbs it and is determined.
  EXPECT_EQ(all.not_excited, (std::vector<std::string>{"XX2R", "XZ2R", "YZ2", "Ia3R", "Fvm3"}));
  EXPECT_TRUE(all.estimate.std_dev.allFinite());
  const auto zz1 = std::find(all.names.begin(), all.names.end(), "ZZ1R") - all.names.begin();
  ASSERT_LT(zz1, static_cast<long>(all.names.size()));
  EXPECT_LT(all.estimate.std_dev[zz1], 0.02 * std::abs(all.estimate.x[zz1]));
}

// A result whose data did not move joints 2 and 3 holds data regroupings: it predicts a run
// that leaves them still as well as it fits its own. On a run that moves them the estimates alone
// predict a wrong number (found with examples/irp6, errors up to 1e28); issue 25 item 2: that run
// is predicted with the undetermined parameters at their nominal values (here the plant's own, so
// the completed model should predict it about as well as the true model does), said in
// `completed` and `filled_share`; only without nominal values is it refused.
TEST(SeveralRuns, ValidationPredictsARunThatExcitesWhatTheResultDoesNotDetermineFromNominal) {
  const Model m = load_robot("irp6");
  const JointRecord j1 =
      closed_loop_run(m, Eigen::Vector3d(0.2, -0.3, 0.4), {true, false, false}, 21);
  const JointRecord j1_again =
      closed_loop_run(m, Eigen::Vector3d(0.2, -0.3, 0.4), {true, false, false}, 24, 0.8);
  const JointRecord j13 =
      closed_loop_run(m, Eigen::Vector3d(-0.4, 0.3, 0.1), {true, false, true}, 23);
  const IdentificationResult r = identify(m, j1, held_torque());
  ASSERT_FALSE(r.not_excited.empty());
  IdentifyOptions same = held_torque();
  same.signal.cutoff_hz = r.processed.cutoff_hz;
  ModelCompletionOptions only_not_excited;
  only_not_excited.max_relative_std = 0.0;
  const CompletedModel c =
      complete_identified_model(m, r.names, r.estimate.x, r.estimate.std_dev, r.not_excited,
                                r.data_regrouping, r.estimate.covariance, same, only_not_excited);
  const ParameterCompletion nominal{c.names, c.values};
  const ValidationResult own =
      validate_torques(m, j1_again, r.names, r.estimate.x, same, r.not_excited, nominal);
  EXPECT_LT(own.relative_error_all, 0.05);
  EXPECT_TRUE(own.completed.empty()) << "a run like the identification run needs no filling";
  EXPECT_EQ(own.filled_share, 0.0);
  // The oracle: the plant's own base parameters (the nominal model is the plant here).
  IdentificationResult every = r;
  every.names = r.base.names;
  every.not_excited.clear();
  const ValidationResult truth = validate_torques(m, j13, every.names, truth_of(m, every), same);
  const ValidationResult filled =
      validate_torques(m, j13, r.names, r.estimate.x, same, r.not_excited, nominal);
  EXPECT_EQ(filled.completed, r.not_excited);
  EXPECT_GT(filled.filled_share, 0.01) << "moving joint 3 needs the filled parameters";
  EXPECT_LT(filled.filled_share, 1.0);
  ASSERT_EQ(filled.warnings.size(), 1u);
  EXPECT_NE(filled.warnings[0].find("nominal"), std::string::npos) << filled.warnings[0];
  std::cout << "joint-1 result on a joint-1-and-3 run: relative error "
            << filled.relative_error_all_rows << " (true model " << truth.relative_error_all_rows
            << "), filled share " << filled.filled_share << "\n";
  EXPECT_LT(filled.relative_error_all_rows, 1.5 * truth.relative_error_all_rows + 0.01);
  try {
    validate_torques(m, j13, r.names, r.estimate.x, same, r.not_excited);
    ADD_FAILURE() << "a run moving joint 3 was validated without nominal values";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not determine"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dynid
