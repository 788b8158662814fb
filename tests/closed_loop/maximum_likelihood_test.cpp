// Maximum likelihood with errors in variables (seed 2 eqs. 13–16). The sensitivity ∂(W·θ)/∂x is
// checked against the mass matrix (∂τ/∂q̈ = M) and the analytic RNEA derivatives; the estimator on
// runs of the native plant (RK4 of the forward dynamics, not the regressor) whose true q, q̇, q̈
// and torque are then measured with independent white noise of known size, the situation of
// seed 2 §2.2.1 (averaged periods, analytic derivatives). Fixed seeds.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynid/closed_loop/maximum_likelihood.hpp"
#include "dynid/common/error.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea_derivatives.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/identification/processed_slice.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/signal/period_averaging.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "support/closed_loop_runs.hpp"

namespace dynid {
namespace {

ParameterLayout viscous_layout() {
  ParameterLayout l;
  l.armature = true;
  l.viscous = true;
  return l;
}

Model ml_plant_model() {
  Model m = load_robot("planar2");
  m.joints[0].friction.Fv = 1.5;
  m.joints[0].friction.Ia = 0.05;
  m.joints[1].friction.Fv = 0.8;
  m.joints[1].friction.Ia = 0.02;
  return m;
}

TEST(MaximumLikelihood, SensitivityMatchesMassMatrixAndRneaDerivatives) {
  const Model m = ml_plant_model();
  const ParameterLayout layout = viscous_layout();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const int samples = 12, n = m.dof();
  ProcessedRecord p;
  p.record.t = Eigen::VectorXd::LinSpaced(samples, 0.0, 1.0);
  p.record.q = p.record.dq = p.record.ddq = p.record.tau = Eigen::MatrixXd(samples, n);
  for (int k = 0; k < samples; ++k) {
    for (int j = 0; j < n; ++j) {
      p.record.q(k, j) = u(rng);
      p.record.dq(k, j) = u(rng);
      p.record.ddq(k, j) = u(rng);
    }
  }
  std::vector<int> columns(static_cast<size_t>(layout.columns(n)));
  for (size_t c = 0; c < columns.size(); ++c) columns[c] = static_cast<int>(c);
  Eigen::VectorXi sample(samples * n), joint(samples * n);
  for (int i = 0; i < samples * n; ++i) {
    sample[i] = i / n;
    joint[i] = i % n;
  }
  const Eigen::MatrixXd S = differential_sensitivity(m, layout, false, p, columns, sample, joint);
  const Eigen::VectorXd theta = layout.parameters(m);
  for (int k = 0; k < samples; ++k) {
    const Eigen::VectorXd q = p.record.q.row(k), dq = p.record.dq.row(k), ddq = p.record.ddq.row(k);
    Workspace ws(m);
    Eigen::MatrixXd M(n, n), d_q(n, n), d_dq(n, n), d_ddq(n, n);
    mass_matrix(m, ws, q, M);
    rnea_derivatives(m, ws, q, dq, ddq, d_q, d_dq, d_ddq);
    for (int j = 0; j < n; ++j) {
      const Eigen::VectorXd d = S.middleRows(3 * n * (k * n + j), 3 * n) * theta;
      for (int i = 0; i < n; ++i) {
        EXPECT_NEAR(d[2 * n + i], M(j, i), 1e-8) << "dtau/dddq, sample " << k;
        // The analytic derivatives of the RNEA at the model's θ: d(W·θ)/dx = ∂τ/∂x. The
        // sensitivity differences the regressor (O(h²) at h = 1e-5 for q, exact for q̇, q̈).
        EXPECT_NEAR(d[i], d_q(j, i), 1e-8) << "dtau/dq, sample " << k;
        EXPECT_NEAR(d[n + i], d_dq(j, i), 1e-10) << "dtau/ddq, sample " << k;
        EXPECT_NEAR(d[2 * n + i], d_ddq(j, i), 1e-10) << "dtau/dddq, sample " << k;
      }
    }
  }
}

// A slice of a processed record regresses as the same rows of the whole record (row k of W
// depends on sample k only), Coulomb indicator columns included; a range outside is an error.
TEST(ProcessedSlice, RegressesAsTheSameRowsOfTheWholeRecord) {
  const Model m = ml_plant_model();
  ParameterLayout layout = viscous_layout();
  layout.coulomb = true;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int samples = 20, n = m.dof();
  ProcessedRecord p;
  p.record.t = Eigen::VectorXd::LinSpaced(samples, 0.0, 1.0);
  p.record.q = p.record.dq = p.record.ddq = p.record.tau = p.moving_positive = p.moving_negative =
      Eigen::MatrixXd(samples, n);
  for (Eigen::MatrixXd* x : {&p.record.q, &p.record.dq, &p.record.ddq, &p.record.tau,
                             &p.moving_positive, &p.moving_negative})
    for (int k = 0; k < samples; ++k)
      for (int j = 0; j < n; ++j) (*x)(k, j) = u(rng);
  const Eigen::MatrixXd whole = processed_regressor(m, layout, false, p);
  const ProcessedRecord s = processed_slice(p, 7, 9);
  EXPECT_EQ(s.record.tau, p.record.tau.middleRows(7, 9));
  EXPECT_EQ(processed_regressor(m, layout, false, s), whole.middleRows(7 * n, 9 * n));
  EXPECT_THROW(processed_slice(p, 15, 6), Error);
}

struct MeasuredRun {
  ProcessedRecord measured;
  EquationBlock block;
  Eigen::MatrixXd sensitivity;
  BaseParameters base;
  Eigen::VectorXd truth;
};

constexpr double kMlRate = 100.0;

// A closed-loop run of the plant without sensor noise; the true q, q̇, q̈, τ are then measured with
// independent white noise of the given sizes. averaged > 0: that many periods are measured and
// averaged into one (dynid average's mean period, average_periods_in_time()), the record is the
// mean period.
MeasuredRun measured_run(const Model& m, const MeasurementNoise& noise, unsigned seed,
                         int averaged = 0) {
  const TrajectorySamples tr =
      sample_trajectory(FourierTrajectory(testing::planar2_reference()), kMlRate, false);
  SimulateOptions so;
  so.loop.periods = averaged > 0 ? averaged + 1 : 3;
  so.loop.record_truth = true;
  const ClosedLoopResult r = simulate_reference(m, tr.t, tr.q, tr.dq, tr.ddq, so);
  const Eigen::Index skip = tr.t.size(), rows = r.t.size() - skip;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  auto noisy = [&](const Eigen::MatrixXd& x, const Eigen::VectorXd& std) {
    Eigen::MatrixXd out = x.bottomRows(rows);
    for (Eigen::Index k = 0; k < rows; ++k)
      for (Eigen::Index j = 0; j < out.cols(); ++j) out(k, j) += std[j] * z(rng);
    return out;
  };
  MeasuredRun run;
  run.measured.record.t = r.t.tail(rows);
  run.measured.record.q = noisy(r.q_true, noise.q);
  run.measured.record.dq = noisy(r.dq_true, noise.dq);
  run.measured.record.ddq = noisy(r.ddq_true, noise.ddq);
  run.measured.record.tau = noisy(r.tau_true, noise.tau);
  if (averaged > 0) {
    JointRecord& rec = run.measured.record;
    const Eigen::Index n2 = rec.q.cols();
    Eigen::MatrixXd x(rows, 4 * n2);
    x << rec.q, rec.dq, rec.ddq, rec.tau;
    const TimedPeriodAverage a =
        average_periods_in_time(rec.t, x, static_cast<double>(tr.t.size()) / kMlRate);
    EXPECT_EQ(a.periods, averaged);
    EXPECT_FALSE(a.interpolated);
    rec.t = a.phase;
    rec.q = a.mean.leftCols(n2);
    rec.dq = a.mean.middleCols(n2, n2);
    rec.ddq = a.mean.middleCols(2 * n2, n2);
    rec.tau = a.mean.rightCols(n2);
  }
  const ParameterLayout layout = viscous_layout();
  BaseParameterOptions bo;
  bo.layout = layout;
  run.base = compute_base_parameters(m, bo);
  run.truth = run.base.reduce(layout.parameters(m));
  const int n = m.dof();
  const Eigen::MatrixXd W = processed_regressor(m, layout, false, run.measured);
  run.block.W.resize(W.rows(), run.base.rank);
  for (int c2 = 0; c2 < run.base.rank; ++c2) run.block.W.col(c2) = W.col(run.base.base[c2]);
  run.block.y = Eigen::Map<const Eigen::VectorXd>(
      Eigen::MatrixXd(run.measured.record.tau.transpose()).data(), W.rows());
  run.block.group.resize(W.rows());
  run.block.sample.resize(W.rows());
  for (Eigen::Index i = 0; i < W.rows(); ++i) {
    run.block.group[i] = static_cast<int>(i % n);
    run.block.sample[i] = static_cast<int>(i / n);
  }
  run.sensitivity = differential_sensitivity(m, layout, false, run.measured, run.base.base,
                                             run.block.sample, run.block.group);
  return run;
}

MeasurementNoise noise_of_size(double scale) {
  MeasurementNoise noise;
  noise.q = Eigen::Vector2d::Constant(0.01 * scale);
  noise.dq = Eigen::Vector2d::Constant(0.1 * scale);
  noise.ddq = Eigen::Vector2d::Constant(1.5 * scale);
  noise.tau = Eigen::Vector2d::Constant(0.05 * scale + 1e-6);
  return noise;
}

TEST(MaximumLikelihood, NoiseFreeRunGivesTheTruthFromAPerturbedStart) {
  const Model m = ml_plant_model();
  const MeasuredRun run = measured_run(m, noise_of_size(0.0), 1);
  const Eigen::VectorXd start = 1.1 * run.truth;
  MaximumLikelihoodSummary summary;
  // Progress: one call per Levenberg–Marquardt iteration, fractions in [0, 1], never decreasing.
  MaximumLikelihoodOptions options;
  int calls = 0;
  double last = -1.0;
  bool monotone = true;
  options.progress = [&](double fraction, const std::string& what) {
    ++calls;
    monotone = monotone && fraction >= last && fraction <= 1.0 &&
               what.find("maximum likelihood iteration") == 0;
    last = fraction;
  };
  const Estimate e = maximum_likelihood(run.block, run.sensitivity, noise_of_size(1e-3), start, {},
                                        options, &summary);
  for (int i = 0; i < run.base.rank; ++i) {
    EXPECT_NEAR(e.x[i], run.truth[i], 1e-6 * (1.0 + std::abs(run.truth[i]))) << run.base.names[i];
  }
  EXPECT_EQ(e.summary.estimator, EstimatorKind::kMaximumLikelihood);
  EXPECT_EQ(calls, summary.iterations);
  EXPECT_GT(calls, 1);
  EXPECT_TRUE(monotone);
}

// The analytic Jacobian of eq. 15's whitened residual (the one handed to Ceres) against central
// differences of the residual itself, away from the optimum (so that ∂S/∂θ matters) and with
// noise large enough that S_k is far from diagonal.
TEST(MaximumLikelihood, AnalyticJacobianMatchesCentralDifferences) {
  const Model m = ml_plant_model();
  const MeasurementNoise noise = noise_of_size(1.0);
  const MeasuredRun run = measured_run(m, noise, 5);
  const Eigen::VectorXd theta = 1.2 * run.truth + Eigen::VectorXd::Constant(run.truth.size(), 0.05);
  Eigen::MatrixXd jacobian;
  maximum_likelihood_residual(run.block, run.sensitivity, noise, theta, &jacobian);
  Eigen::MatrixXd numeric(jacobian.rows(), jacobian.cols());
  for (Eigen::Index k = 0; k < theta.size(); ++k) {
    const double h = 1e-6 * (1.0 + std::abs(theta[k]));
    Eigen::VectorXd plus = theta, minus = theta;
    plus[k] += h;
    minus[k] -= h;
    numeric.col(k) = (maximum_likelihood_residual(run.block, run.sensitivity, noise, plus) -
                      maximum_likelihood_residual(run.block, run.sensitivity, noise, minus)) /
                     (2.0 * h);
  }
  EXPECT_LT((jacobian - numeric).norm(), 1e-6 * numeric.norm());
  // −L⁻¹W alone (S held at θ): S depends on θ only, so shifting y by −W_k shifts the whitened
  // residual by −L⁻¹W_k.
  const Eigen::VectorXd r = maximum_likelihood_residual(run.block, run.sensitivity, noise, theta);
  Eigen::MatrixXd fixed_s(jacobian.rows(), jacobian.cols());
  for (Eigen::Index k = 0; k < theta.size(); ++k) {
    EquationBlock shifted = run.block;
    shifted.y -= run.block.W.col(k);
    fixed_s.col(k) = maximum_likelihood_residual(shifted, run.sensitivity, noise, theta) - r;
  }
  const double s_part = (jacobian - fixed_s).norm() / jacobian.norm();
  EXPECT_GT(s_part, 1e-2) << s_part;
}

// Over seeds: the OLS estimate of the noisy regressor is attenuated (errors in variables, seed 1
// eqs. 39–45), the ML one is not, and its intervals hold the truth.
TEST(MaximumLikelihood, ErrorsInVariablesBiasOlsButNotMaximumLikelihood) {
  const Model m = ml_plant_model();
  // Half the noise_of_size(1) levels: σ_q̈ = 0.75 rad/s² on q̈ of a few rad/s². At twice this the
  // noise is no longer small against the regressor's curvature (q̇² and sin q terms: eq. 16's
  // linearisation) and 12 of 72 truths fall outside the 99.9 % intervals
  // (docs/methods/closed_loop.md).
  const MeasurementNoise noise = noise_of_size(0.5);
  constexpr int kSeeds = 8;
  Eigen::VectorXd ols_z, ml_z;
  int ml_outside = 0, total = 0;
  for (int s = 0; s < kSeeds; ++s) {
    const MeasuredRun run = measured_run(m, noise, 100 + s);
    const Estimate ols = ordinary_least_squares(run.block.W, run.block.y, run.block.group);
    MaximumLikelihoodSummary summary;
    const Estimate ml =
        maximum_likelihood(run.block, run.sensitivity, noise, ols.x, {}, {}, &summary);
    if (s == 0) {
      ols_z = ml_z = Eigen::VectorXd::Zero(run.base.rank);
      // With the right noise the weighted residual has unit variance.
      EXPECT_NEAR(summary.variance_factor, 1.0, 0.15);
    }
    for (int i = 0; i < run.base.rank; ++i) {
      ols_z[i] += (ols.x[i] - run.truth[i]) / ols.std_dev[i] / kSeeds;
      ml_z[i] += (ml.x[i] - run.truth[i]) / ml.std_dev[i] / kSeeds;
      ml_outside += run.truth[i] < ml.ci_lower[i] || run.truth[i] > ml.ci_upper[i];
      ++total;
    }
  }
  // Mean standardised error over seeds: OLS is biased by several of its own σ on the inertial
  // parameters, ML within about one (sampling spread of a mean of 8 is 1/√8 ≈ 0.35).
  EXPECT_GT(ols_z.cwiseAbs().maxCoeff(), 3.0) << ols_z.transpose();
  EXPECT_LT(ml_z.cwiseAbs().maxCoeff(), 1.5) << ml_z.transpose();
  // 99.9 % intervals: essentially no truth outside.
  EXPECT_LE(ml_outside, 1) << "of " << total;
}

// The noise of averaged data (seed 2 §3.4: periods averaged before the identification). K = 4
// periods of the noise_of_size(1) run, whose raw level is past eq. 16's linear range, averaged:
// the mean's noise is σ/√K (averaged_noise_std(), dynid average's std_averaged). ML fitted with
// the raw σ (dynid average's std, what identify --noise used before) and with σ/√K: eq. 15's
// argmin and the intervals (σ_f²·F⁻¹ and the sandwich) do not depend on a common scale of the
// noise, so both give the same estimate and σ, which match the spread of the estimate over seeds;
// only the variance factor, reported as "about 1 when the noise is right", differs: ≈ 1/K with
// the raw σ, ≈ 1 with the mean's.
TEST(MaximumLikelihood, AveragedPeriodsNeedTheNoiseOfTheMeanOnlyForTheVarianceFactor) {
  const Model m = ml_plant_model();
  constexpr int kPeriods = 4, kSeeds = 5;
  const MeasurementNoise raw = noise_of_size(1.0);
  MeasurementNoise mean = raw;
  for (Eigen::VectorXd* v : {&mean.q, &mean.dq, &mean.ddq, &mean.tau})
    for (Eigen::Index j = 0; j < v->size(); ++j) (*v)[j] = averaged_noise_std((*v)[j], kPeriods);
  double z2 = 0.0, vf_raw = 0.0, vf_mean = 0.0;
  int count = 0;
  for (int s = 0; s < kSeeds; ++s) {
    const MeasuredRun run = measured_run(m, raw, 300 + s, kPeriods);
    const Estimate ols = ordinary_least_squares(run.block.W, run.block.y, run.block.group);
    MaximumLikelihoodSummary with_raw, with_mean;
    const Estimate a =
        maximum_likelihood(run.block, run.sensitivity, raw, ols.x, {}, {}, &with_raw);
    const Estimate b =
        maximum_likelihood(run.block, run.sensitivity, mean, ols.x, {}, {}, &with_mean);
    vf_raw += with_raw.variance_factor / kSeeds;
    vf_mean += with_mean.variance_factor / kSeeds;
    for (int i = 0; i < run.base.rank; ++i) {
      EXPECT_NEAR(a.x[i], b.x[i], 1e-6 * b.std_dev[i]) << run.base.names[i];
      EXPECT_NEAR(a.std_dev[i], b.std_dev[i], 1e-6 * b.std_dev[i]) << run.base.names[i];
      const double z = (b.x[i] - run.truth[i]) / b.std_dev[i];
      z2 += z * z;
      ++count;
    }
  }
  // RMS standardised error over 5 seeds × 7 parameters (35 terms): 1 when σ̂ is the spread of
  // the estimate; a √K = 2 mis-scaling would give 2 or 0.5. Bounds 0.6 and 1.5 hold the chi-square
  // spread of 35 terms (2.5–97.5 %: 0.77–1.21) with room for the HAC's small-sample bias.
  const double rms_z = std::sqrt(z2 / count);
  EXPECT_GT(rms_z, 0.6);
  EXPECT_LT(rms_z, 1.5);
  EXPECT_NEAR(vf_mean, 1.0, 0.2);
  EXPECT_NEAR(vf_raw, 1.0 / kPeriods, 0.2 / kPeriods);
  RecordProperty("rms_z", std::to_string(rms_z));
}

TEST(MaximumLikelihood, BadNoiseIsRefused) {
  const Model m = ml_plant_model();
  const MeasuredRun run = measured_run(m, noise_of_size(0.0), 1);
  MeasurementNoise zero = noise_of_size(1.0);
  zero.tau.setZero();
  EXPECT_THROW(maximum_likelihood(run.block, run.sensitivity, zero, run.truth), Error);
  MeasurementNoise wrong = noise_of_size(1.0);
  wrong.q = Eigen::VectorXd::Ones(3);
  EXPECT_THROW(maximum_likelihood(run.block, run.sensitivity, wrong, run.truth), Error);
}

}  // namespace
}  // namespace dynid
