// The integral (energy) model as equations (identification/integral_equations.hpp): rows against
// the power of the differential model's regressor, identification on simulated runs whose data come
// from a plant (dynid's RK4 forward dynamics, MuJoCo), not from the energy equations.
#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/QR>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/recursive_least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identification/integral_equations.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "identification/integral_support.hpp"

namespace dynid {
namespace {

using integral_testing::base_of;
using integral_testing::estimate_with_intervals;
using integral_testing::multisine;
using integral_testing::simulate;
using integral_testing::truth_record;

Model tx40() {
  return load_robot(std::string(DYNID_SOURCE_DIR) + "/examples/staubli-tx40/tx40.yaml");
}

// Oracle: energy derivative = power. Each row must equal ∫ (Y(q, q̇, q̈) | coupling columns)ᵀ q̇ dt
// over its interval, computed from the differential model's regressor on a 200× finer grid with
// Simpson's rule, for an analytic trajectory (the TX40 with its coupled wrist, symmetric and
// asymmetric friction). Velocity reversals inside intervals are included.
TEST(IntegralEquations, RowsAreTheIntegratedPowerOfTheTorqueRegressor) {
  const Model model = tx40();
  const int n = model.dof();
  const double ts = 2e-3, duration = 0.4;
  const int fine = 200;
  auto state = [&](double t, Eigen::VectorXd& q, Eigen::VectorXd& dq, Eigen::VectorXd& ddq) {
    for (int j = 0; j < n; ++j) {
      const double w = 2 * M_PI * (1.0 + 0.7 * j), a = 0.5 / (1 + j), phi = 0.3 * j;
      q[j] = a * std::sin(w * t + phi);
      dq[j] = a * w * std::cos(w * t + phi);
      ddq[j] = -a * w * w * std::sin(w * t + phi);
    }
  };
  const Eigen::Index m = std::llround(duration / ts) + 1;
  ProcessedRecord p;
  p.rate_hz = 1 / ts;
  p.record.t = Eigen::VectorXd::LinSpaced(m, 0.0, duration);
  p.record.q.resize(m, n);
  p.record.dq.resize(m, n);
  p.record.tau.setZero(m, n);
  Eigen::VectorXd q(n), dq(n), ddq(n);
  for (Eigen::Index k = 0; k < m; ++k) {
    state(p.record.t[k], q, dq, ddq);
    p.record.q.row(k) = q.transpose();
    p.record.dq.row(k) = dq.transpose();
  }
  ParameterLayout asym = ParameterLayout::full();
  asym.asymmetric = true;
  for (const ParameterLayout& layout : {ParameterLayout::full(), asym}) {
    IntegralOptions o;
    o.interval = 5 * ts;
    o.weighting = IntegralWeighting::kNone;  // the oracle is the unweighted power integral
    const EquationBlock b = integral_equations(model, layout, true, p, o);
    ASSERT_EQ(b.W.rows(), (m - 1) / 5);
    ASSERT_EQ(b.columns, stacked_regressor_names(model, layout, true));
    const int cols = layout.columns(n);
    const std::vector<int> motors = coupled_motors(model);
    Workspace ws(model);
    Eigen::MatrixXd Y(n, cols), C(n, 3 * motors.size());
    for (Eigen::Index i = 0; i < b.W.rows(); ++i) {
      const double a = p.record.t[5 * i], e = p.record.t[5 * i + 5];
      const int N = 5 * fine;  // even: composite Simpson
      Eigen::VectorXd row = Eigen::VectorXd::Zero(b.W.cols());
      for (int k = 0; k <= N; ++k) {
        state(a + (e - a) * k / N, q, dq, ddq);
        torque_regressor(model, ws, layout, q, dq, ddq, Y);
        coupling_regressor(model, motors, dq, ddq, C);
        const double wk = (k == 0 || k == N) ? 1.0 : (k % 2 ? 4.0 : 2.0);
        row.head(cols) += wk * Y.transpose() * dq;
        row.tail(C.cols()) += wk * C.transpose() * dq;
      }
      row *= (e - a) / N / 3.0;
      for (Eigen::Index c = 0; c < row.size(); ++c) {
        EXPECT_NEAR(b.W(i, c), row[c], 1e-7 * row.cwiseAbs().maxCoeff())
            << b.columns[c] << " interval " << i;
      }
      EXPECT_EQ(b.sample[i], i);
      EXPECT_EQ(b.group[i], 0);
      EXPECT_DOUBLE_EQ(b.t[i], e);
    }
    EXPECT_EQ(b.group_names, std::vector<std::string>{"energy"});
  }
}

// A puma560 with armature, viscous friction and offsets, closed loop on the native plant at 2 kHz
// (0.5 ms, seed 1's logger), the applied (held) torque and the true states recorded.
struct PumaRun {
  Model model;
  ParameterLayout layout = ParameterLayout::full();
  BaseParameters base;
  Eigen::VectorXd truth;
  ClosedLoopResult run;
  double ts = 5e-4;
  PumaRun() : model(load_robot("puma560")) {
    for (int j = 0; j < model.dof(); ++j) {
      model.joints[j].friction.Ia = 0.05 * (j + 1);
      model.joints[j].friction.Fv = 0.4 + 0.1 * j;
      model.joints[j].friction.Fc = 0.0;  // the plant's Coulomb law is a tanh, not sign(q̇)
      model.joints[j].friction.Fo = 0.1 * (j + 1);
    }
    base = base_of(model, layout);
    truth = base.reduce(layout.parameters(model));
    PlantOptions plant;
    run = simulate(model, multisine(model.dof(), 8.0, ts, 11), ts, {}, plant);
  }
};
const PumaRun& puma() {
  static const PumaRun r;
  return r;
}

// Noise-free: the held torque's work over a step is exactly τ_kᵀ(q_{k+1} − q_k), so with the
// zero-order-hold rule the remaining error is the plant's RK4 step and the friction quadrature
// (exact for cubic q per step), both O(h⁵) per step: 5 ms intervals recover every base
// parameter to 1e-6 of the largest. Simpson's rule on the same data misreads the held torque
// (O(h) per step) and is far off: the limit is the integration rule, not the simulator.
TEST(IntegralEquations, NoiseFreeShortIntegralsRecoverBaseParameters) {
  const PumaRun& r = puma();
  IntegralOptions o;
  o.interval = 0.005;
  o.rule = IntegrationRule::kZeroOrderHold;
  const EquationBlock b =
      integral_equations(r.model, r.layout, false, truth_record(r.run, r.ts), o);
  ASSERT_EQ(b.W.rows(), (r.run.t.size() - 1) / 10);
  const Estimate e = ordinary_least_squares(r.base.select(b.W), b.y);
  ASSERT_EQ(e.summary.rank, r.base.rank);  // the data excite every base parameter
  const double scale = r.truth.cwiseAbs().maxCoeff();
  std::cout << "largest error / largest parameter: zero-order hold "
            << (e.x - r.truth).cwiseAbs().maxCoeff() / scale;
  for (int i = 0; i < r.base.rank; ++i) {
    EXPECT_NEAR(e.x[i], r.truth[i], 1e-6 * scale) << r.base.names[i];
  }
  o.long_integrals = true;
  const EquationBlock l =
      integral_equations(r.model, r.layout, false, truth_record(r.run, r.ts), o);
  const Estimate el = ordinary_least_squares(r.base.select(l.W), l.y);
  EXPECT_LT((el.x - r.truth).cwiseAbs().maxCoeff(), 1e-6 * scale);
  o.long_integrals = false;
  o.rule = IntegrationRule::kSimpson;
  const EquationBlock s =
      integral_equations(r.model, r.layout, false, truth_record(r.run, r.ts), o);
  const Estimate es = ordinary_least_squares(r.base.select(s.W), s.y);
  std::cout << ", long " << (el.x - r.truth).cwiseAbs().maxCoeff() / scale << ", Simpson "
            << (es.x - r.truth).cwiseAbs().maxCoeff() / scale << "\n";
  EXPECT_GT((es.x - r.truth).cwiseAbs().maxCoeff(), 1e-4 * scale);
}

// White torque-sensor noise (σ = 0.3 N·m) on the held torque, true positions and velocities:
// each interval's error is a sum of independent terms whose variance grows with the joint speed,
// which the default row weighting evens out; the 99.9 % intervals then hold the truth (at most
// one of the 58 base parameters outside, per seed). Without the weighting seed 3 had 12 outside:
// the white σ² of the unweighted rows is an average that fast intervals exceed.
TEST(IntegralEquations, NoisyTorquesTruthInsideIntervals) {
  const PumaRun& r = puma();
  for (unsigned seed : {1u, 2u, 3u}) {
    ProcessedRecord p = truth_record(r.run, r.ts);
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.3);
    for (Eigen::Index i = 0; i < p.record.tau.size(); ++i) p.record.tau.data()[i] += noise(rng);
    IntegralOptions o;
    o.interval = 0.005;
    o.rule = IntegrationRule::kZeroOrderHold;
    const Estimate e =
        estimate_with_intervals(integral_equations(r.model, r.layout, false, p, o), r.base);
    int outside = 0;
    for (int i = 0; i < r.base.rank; ++i) {
      const bool in = e.ci_lower[i] <= r.truth[i] && r.truth[i] <= e.ci_upper[i];
      outside += !in;
      if (!in) std::cout << "seed " << seed << ": " << r.base.names[i] << " outside\n";
    }
    EXPECT_LE(outside, 1) << "seed " << seed << " of " << r.base.rank;
  }
}

// The same run identified by the differential model (identify(), default processing) and by
// the integral model on identify()'s processed record: MuJoCo plant (its own integrator and
// dynamics), encoder noise 1e-5 rad and torque noise 0.1 N·m. Each base parameter's two estimates
// differ by less than the sum of their 99.9 % half-widths.
TEST(IntegralEquations, IntegralAndDifferentialEstimatesAgreeWithinIntervals) {
  Model model = load_robot("planar2");
  ParameterLayout layout = ParameterLayout::rigid();
  layout.armature = layout.viscous = layout.offset = true;
  for (int j = 0; j < model.dof(); ++j) {
    model.joints[j].friction = {0.02 * (j + 1), 0.3, 0.0, 0.2 * (j + 1)};
  }
  const double ts = 1e-3;
  SensorOptions so;
  so.position_noise_std = 1e-5;
  so.torque_noise_std = 0.1;
  so.seed = 4;
  PlantOptions plant;
  plant.engine = PlantEngine::kMujoco;
  const ClosedLoopResult run = simulate(model, multisine(2, 10.0, ts, 5, 1.0), ts, so, plant, 2);
  JointRecord rec{run.t, run.q, {}, {}, run.tau};
  IdentifyOptions io;
  io.layout = layout;
  io.signal.torque_time_offset = 0.5 * ts;  // the logged torque is held for one period
  const IdentificationResult diff = identify(model, rec, io);
  const BaseParameters base = base_of(model, layout);
  ASSERT_EQ(diff.names, base.names);
  IntegralOptions o;
  o.interval = 0.0;  // two steps of identify()'s decimated record
  const Estimate in =
      estimate_with_intervals(integral_equations(model, layout, false, diff.processed, o), base);
  const Eigen::VectorXd truth = base.reduce(layout.parameters(model));
  for (int i = 0; i < base.rank; ++i) {
    const double hw_d = diff.estimate.ci_upper[i] - diff.estimate.x[i];
    const double hw_i = in.ci_upper[i] - in.x[i];
    EXPECT_LT(std::abs(in.x[i] - diff.estimate.x[i]), hw_d + hw_i)
        << base.names[i] << ": integral " << in.x[i] << " ± " << hw_i << ", differential "
        << diff.estimate.x[i] << " ± " << hw_d << ", truth " << truth[i];
  }
}

// Integral-model RLS (U-D, seed 1 eqs. 36–37) equals the batch solution of the same problem,
// (WᵀW + I/c)⁻¹(Wᵀy), to 1e-9.
TEST(IntegralEquations, RecursiveLeastSquaresEqualsBatch) {
  const PumaRun& r = puma();
  ProcessedRecord p = truth_record(r.run, r.ts);
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (Eigen::Index i = 0; i < p.record.tau.size(); ++i) p.record.tau.data()[i] += noise(rng);
  IntegralOptions o;
  o.interval = 0.005;
  const EquationBlock b = integral_equations(r.model, r.layout, false, p, o);
  const Eigen::MatrixXd Wb = r.base.select(b.W);
  for (double c : {1e8, 1e12}) {
    RecursiveLeastSquaresOptions ro;
    ro.initial_covariance = c;
    const Estimate rls = recursive_least_squares(Wb, b.y, ro);
    // Batch: least squares on [W; I/√c]·x = [y; 0] by Householder QR (no normal equations).
    Eigen::MatrixXd A(Wb.rows() + Wb.cols(), Wb.cols());
    A << Wb, Eigen::MatrixXd::Identity(Wb.cols(), Wb.cols()) / std::sqrt(c);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(A.rows());
    rhs.head(b.y.size()) = b.y;
    const Eigen::VectorXd batch = A.householderQr().solve(rhs);
    EXPECT_LT((rls.x - batch).norm(), 1e-9 * batch.norm()) << "c = " << c;
  }
}

TEST(IntegralEquations, BadInputIsOneClearError) {
  const PumaRun& r = puma();
  const ProcessedRecord p = truth_record(r.run, r.ts);
  auto expect = [&](const IntegralOptions& o, const std::string& fragment, bool usage) {
    try {
      integral_equations(r.model, r.layout, false, p, o);
      ADD_FAILURE() << "no error for " << fragment;
    } catch (const UsageError& e) {
      EXPECT_TRUE(usage) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    } catch (const Error& e) {
      EXPECT_FALSE(usage) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  IntegralOptions o;
  o.interval = 0.2e-3;  // less than one 0.5 ms step
  expect(o, "shorter than two samples", true);
  o.interval = 9.0;  // the run lasts 8 s
  expect(o, "longer than the run", true);
  o.interval = -1.0;
  expect(o, "not a length", true);
  o = IntegralOptions{};
  o.endpoint_window = -0.01;
  expect(o, "endpoint window", true);
  ProcessedRecord still = p;
  still.record.q.rowwise() = p.record.q.row(0);
  still.record.dq.setZero();
  try {
    integral_equations(r.model, r.layout, false, still, {});
    ADD_FAILURE() << "no error for a run without motion";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no joint moves"), std::string::npos) << e.what();
  }
  ProcessedRecord no_tau = p;
  no_tau.record.tau.resize(0, 0);
  EXPECT_THROW(integral_equations(r.model, r.layout, false, no_tau, {}), Error);
}

// Oracle for IntegralOptions::endpoint_window: on positions that are a quadratic in time (per
// joint, non-uniform steps), the local quadratic fit's slope is the exact velocity, so the energy
// columns equal those built from the exact velocities even when the record's dq is wrong; at the
// record's ends the window is shifted inward. The friction columns still use dq.
TEST(IntegralEquations, EndpointWindowSlopeIsExactOnQuadraticMotion) {
  const Model model = tx40();
  const int n = model.dof();
  const Eigen::Index m = 201;
  ProcessedRecord exact;
  exact.record.t.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) exact.record.t[k] = 1e-3 * k + 2e-4 * std::sin(0.7 * k);
  exact.record.q.resize(m, n);
  exact.record.dq.resize(m, n);
  exact.record.tau.setZero(m, n);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = exact.record.t[k];
    for (int j = 0; j < n; ++j) {
      const double a = 0.3 - 0.1 * j, b = 1.0 + 0.2 * j, c = -2.0 + 0.5 * j;
      exact.record.q(k, j) = a + b * t + c * t * t;
      exact.record.dq(k, j) = b + 2 * c * t;
    }
  }
  ProcessedRecord wrong = exact;
  wrong.record.dq *= 1.1;
  IntegralOptions o;
  o.interval = 0.02;
  o.weighting = IntegralWeighting::kNone;
  const EquationBlock reference =
      integral_equations(model, ParameterLayout::full(), true, exact, o);
  o.endpoint_window = 0.015;
  const EquationBlock fitted = integral_equations(model, ParameterLayout::full(), true, wrong, o);
  const Eigen::Index link = kLinkParams * n;
  const double scale = reference.W.leftCols(link).cwiseAbs().maxCoeff();
  EXPECT_LT((fitted.W.leftCols(link) - reference.W.leftCols(link)).cwiseAbs().maxCoeff(),
            1e-9 * scale);
  // Negative control: without the window the wrong velocities change the energy columns.
  o.endpoint_window = 0.0;
  const EquationBlock unfitted = integral_equations(model, ParameterLayout::full(), true, wrong, o);
  EXPECT_GT((unfitted.W.leftCols(link) - reference.W.leftCols(link)).cwiseAbs().maxCoeff(),
            1e-3 * scale);
}

// The default row weights follow the endpoint-momentum noise model: row i of the weighted block is
// the unweighted row divided by s_i/rms(s), s_i² = Σ_j σ_j²((M q̇)_a,j² + (M q̇)_b,j²), with M from
// mass_matrix (the builder computes M q̇ by RNEA). Without a velocity noise estimate the rows are
// weighted for torque noise instead.
TEST(IntegralEquations, EndpointMomentumWeightsFollowTheMassMatrix) {
  const PumaRun& r = puma();
  ProcessedRecord p = truth_record(r.run, r.ts);
  p.velocity_noise_std = Eigen::VectorXd::LinSpaced(r.model.dof(), 1e-3, 6e-3);
  IntegralOptions o;
  o.weighting = IntegralWeighting::kNone;
  const EquationBlock plain = integral_equations(r.model, r.layout, false, p, o);
  o.weighting = IntegralWeighting::kEndpointMomentum;
  const EquationBlock weighted = integral_equations(r.model, r.layout, false, p, o);
  const Eigen::Index steps = 20, rows = plain.y.size();  // 10 ms at 2 kHz
  Workspace ws(r.model);
  Eigen::MatrixXd M(r.model.dof(), r.model.dof());
  auto end_variance = [&](Eigen::Index k) {
    mass_matrix(r.model, ws, p.record.q.row(k).transpose(), M);
    const Eigen::VectorXd mom = M * p.record.dq.row(k).transpose();
    return (mom.array().square() * p.velocity_noise_std.array().square()).sum();
  };
  Eigen::VectorXd s(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    s[i] = std::sqrt(end_variance(i * steps) + end_variance((i + 1) * steps));
  }
  s /= std::sqrt(s.squaredNorm() / static_cast<double>(rows));
  for (Eigen::Index i = 0; i < rows; i += 37) {
    EXPECT_NEAR(weighted.y[i], plain.y[i] / s[i], 1e-9 * std::abs(plain.y[i] / s[i])) << i;
    EXPECT_LT((weighted.W.row(i) - plain.W.row(i) / s[i]).norm(),
              1e-9 * plain.W.row(i).norm() / s[i])
        << i;
  }
  p.velocity_noise_std.resize(0);
  o.weighting = IntegralWeighting::kTorqueNoise;
  const EquationBlock torque = integral_equations(r.model, r.layout, false, p, o);
  o.weighting = IntegralWeighting::kEndpointMomentum;
  const EquationBlock fallback = integral_equations(r.model, r.layout, false, p, o);
  EXPECT_EQ(fallback.y, torque.y);
}

}  // namespace
}  // namespace dynid

namespace dynid {
namespace {

// Oracle: a torque that is pure Coulomb friction, τ_j = Fc_j·sign(q̇_j), low-pass filtered by
// preprocess() like any run. Its filtered power is exactly Fc·q̇_f·filter(sign q̇) (the filter is
// linear), so with parallel filtering every row must satisfy y = Σ_j Fc_j·W(Fc_j), reversals
// included — to 1e-4 relative, not rounding: preprocess takes the sign from the velocity it
// derives from q, which at a sample next to a reversal can differ from the analytic velocity
// that made the torque (measured 2.8e-5). The Coulomb work of the filtered velocity, ∫|q̇_f|, misses
// the smeared step at each reversal (checked to be off by more than 1 %, so the test can tell them
// apart).
TEST(IntegralEquations, ParallelFilteredCoulombWorkMatchesTheFilteredTorque) {
  const Model model = load_robot("planar2");
  const double ts = 1e-3, fc[2] = {3.0, 1.5};
  const Eigen::Index m = 4001;
  JointRecord rec;
  rec.t = Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) * ts);
  rec.q.resize(m, 2);
  rec.dq.resize(m, 2);
  rec.tau.resize(m, 2);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = rec.t[k];
    rec.q.row(k) << 0.8 * std::sin(2.0 * t) + 0.1, 0.5 * std::sin(3.1 * t + 0.4);
    rec.dq.row(k) << 1.6 * std::cos(2.0 * t), 1.55 * std::cos(3.1 * t + 0.4);
    for (int j = 0; j < 2; ++j) rec.tau(k, j) = fc[j] * ((rec.dq(k, j) > 0) - (rec.dq(k, j) < 0));
  }
  SignalOptions so = integral_signal_options();
  so.cutoff_hz = 5.0;
  std::vector<std::pair<std::string, std::string>> choices;
  const ProcessedRecord p = preprocess(rec, so, choices);
  ASSERT_EQ(p.moving_positive.rows(), p.record.t.size());
  const ParameterLayout layout = ParameterLayout::full();
  IntegralOptions io;
  io.weighting = IntegralWeighting::kNone;
  const auto coulomb_residual = [&](const ProcessedRecord& record) {
    const EquationBlock b = integral_equations(model, layout, false, record, io);
    Eigen::VectorXd predicted = Eigen::VectorXd::Zero(b.y.size());
    for (int j = 0; j < 2; ++j) {
      const auto it = std::find(b.columns.begin(), b.columns.end(), "Fc" + std::to_string(j + 1));
      EXPECT_NE(it, b.columns.end());
      predicted += fc[j] * b.W.col(it - b.columns.begin());
    }
    return (b.y - predicted).norm() / b.y.norm();
  };
  EXPECT_LT(coulomb_residual(p), 1e-4);
  ProcessedRecord serial = p;
  serial.moving_positive.resize(0, 0);
  serial.moving_negative.resize(0, 0);
  const double serial_residual = coulomb_residual(serial);
  std::cout << "Coulomb work of the filtered torque: parallel filtering " << coulomb_residual(p)
            << ", |dq_f| " << serial_residual << " relative\n";
  EXPECT_GT(serial_residual, 0.01);
}

}  // namespace
}  // namespace dynid
