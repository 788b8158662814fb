// Closed loop: PID tracking against the continuous-time transfer function, computed-torque
// feed-forward, sensor delay in the log, periodic reference, errors.
#include <cmath>
#include <complex>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/sim/closed_loop.hpp"
#include "sim/sim_support.hpp"
#include "support/planar2.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

// A joint without gravity (axis along g) and friction is the double integrator J s² y = u. Under
// u = (Kp + Ki/s)(r − y) + Kd (s r − s/(1 + Tf s) y) the error is
//   E/R = (J s² + Kd s/(1 + Tf s) − Kd s) / (J s² + Kp + Ki/s + Kd s/(1 + Tf s)),
// so a sine reference of amplitude A leaves a steady sine error of RMS A|E/R(iω)|/√2. The
// discrete loop adds the zero-order hold and the backward-Euler filter, both phase lags of order
// ω_c·Ts = 0.02 at the loop crossover ω_c ≈ 20 rad/s; 3 % covers them.
TEST(ClosedLoop, PidTrackingErrorMatchesTransferFunction) {
  Model model = testing::pendulum(1.0, 0.5, 0.01, 0.24, 0.0);
  model.gravity = Eigen::Vector3d(0, 0, -9.81);
  const double J = 0.5, kp = 200, ki = 400, kd = 20, tf = 1e-3, ts = 1e-3, A = 0.5;
  const double w = 2 * kPi;
  PidOptions po;
  po.kp = Eigen::VectorXd::Constant(1, kp);
  po.ki = Eigen::VectorXd::Constant(1, ki);
  po.kd = Eigen::VectorXd::Constant(1, kd);
  po.derivative_filter_time = tf;
  PidController pid(model, po);
  PlantOptions plant_options;
  auto plant = make_plant(model, plant_options);
  Sensors sensors(model, {});
  const Reference ref = testing::sine_reference(Eigen::VectorXd::Constant(1, A),
                                                Eigen::VectorXd::Zero(1), w, ts, 1000);
  ClosedLoopOptions lo;
  lo.periods = 6;
  lo.record_truth = true;
  const ClosedLoopResult r = run_closed_loop(ref, pid, *plant, sensors, lo);
  ASSERT_EQ(r.t.size(), 6000);
  EXPECT_EQ(r.q, r.q_true);  // ideal sensors
  const Eigen::VectorXd e = (r.qr - r.q).col(0).tail(1000);
  const double rms = std::sqrt(e.squaredNorm() / 1000);
  const std::complex<double> s(0.0, w);
  const std::complex<double> deriv = kd * s / (1.0 + tf * s);
  const double gain = std::abs((J * s * s + deriv - kd * s) / (J * s * s + kp + ki / s + deriv));
  EXPECT_NEAR(rms, A * gain / std::sqrt(2.0), 0.03 * A * gain / std::sqrt(2.0));
}

// Exact computed-torque feed-forward removes the dynamics from the error: what remains is the
// disturbance of the zero-order hold, (Ts/2)·τ̇, and of the filtered derivative, which lags the
// velocity by Tf + Ts/2, so d ≤ (Ts/2)·max|τ̇| + Kd (Tf + Ts/2) max|q̈r|; below the loop bandwidth
// e ≈ d/Kp. We require max|e| ≤ d/Kp and a 20× gain over the same PID without feed-forward.
TEST(ClosedLoop, ComputedTorqueFeedForwardTracksWithinDisturbanceBound) {
  const testing::Planar2 arm;
  const Model model = arm.model();
  const double ts = 1e-3, kp = 400, kd = 40, tf = 1e-3, w = 2 * kPi * 0.5;
  const Reference ref =
      testing::sine_reference(Eigen::Vector2d(0.8, 1.0), Eigen::Vector2d(-1.0, 0.5), w, ts, 2000);
  double tau_rate = 0.0, max_ddq = ref.ddq.cwiseAbs().maxCoeff();
  for (int k = 0; k + 1 < 2000; ++k) {
    const Eigen::Vector2d a = arm.torque(ref.q.row(k), ref.dq.row(k), ref.ddq.row(k));
    const Eigen::Vector2d b = arm.torque(ref.q.row(k + 1), ref.dq.row(k + 1), ref.ddq.row(k + 1));
    tau_rate = std::max(tau_rate, (b - a).cwiseAbs().maxCoeff() / ts);
  }
  const double bound = (0.5 * ts * tau_rate + kd * (tf + 0.5 * ts) * max_ddq) / kp;
  double max_error[2];
  for (FeedForward ff : {FeedForward::kComputedTorque, FeedForward::kNone}) {
    PidOptions po;
    po.kp = Eigen::Vector2d::Constant(kp);
    po.ki = Eigen::Vector2d::Constant(200.0);
    po.kd = Eigen::Vector2d::Constant(kd);
    po.derivative_filter_time = tf;
    po.feed_forward = ff;
    PidController pid(model, po);
    auto plant = make_plant(model);
    Sensors sensors(model, {});
    ClosedLoopOptions lo;
    lo.periods = 3;
    const ClosedLoopResult r = run_closed_loop(ref, pid, *plant, sensors, lo);
    max_error[ff == FeedForward::kNone] = (r.qr - r.q).bottomRows(2000).cwiseAbs().maxCoeff();
    // The reference repeats every period.
    EXPECT_EQ(r.qr.row(5), r.qr.row(2005));
  }
  EXPECT_LT(max_error[0], bound);
  EXPECT_LT(20 * max_error[0], max_error[1]);
}

// With a position delay of d samples the logged position is the true one d samples earlier; the
// torque log (noise-free, delay d') is the applied torque d' samples earlier.
TEST(ClosedLoop, SensorDelaysShiftTheLog) {
  const Model model = testing::pendulum();
  PidOptions po;
  po.kp = Eigen::VectorXd::Constant(1, 50.0);
  po.kd = Eigen::VectorXd::Constant(1, 5.0);
  PidController pid(model, po);
  auto plant = make_plant(model);
  SensorOptions so;
  so.position_delay = 4;
  so.torque_delay = 2;
  Sensors sensors(model, so);
  const Reference ref = testing::sine_reference(Eigen::VectorXd::Constant(1, 0.3),
                                                Eigen::VectorXd::Zero(1), 2 * kPi, 1e-3, 1000);
  ClosedLoopOptions lo;
  lo.samples = 1500;
  lo.record_truth = true;
  const ClosedLoopResult r = run_closed_loop(ref, pid, *plant, sensors, lo);
  ASSERT_EQ(r.t.size(), 1500);
  EXPECT_NEAR(r.t[1499], 1.499, 1e-12);
  for (int k = 4; k < 1500; ++k) EXPECT_EQ(r.q(k, 0), r.q_true(k - 4, 0));
  for (int k = 2; k < 1500; ++k) EXPECT_EQ(r.tau(k, 0), r.tau_true(k - 2, 0));
  // The true accelerations satisfy the inverse dynamics under the applied torque (RNEA, an
  // algorithm independent of the plant's mass-matrix solve; the pendulum has no joint terms).
  for (int k = 0; k < 1500; k += 50) {
    const Eigen::VectorXd tau = rnea(model, r.q_true.row(k).transpose(),
                                     r.dq_true.row(k).transpose(), r.ddq_true.row(k).transpose());
    EXPECT_NEAR(tau[0], r.tau_true(k, 0), 1e-10 * std::max(1.0, std::abs(tau[0])));
  }
}

TEST(ClosedLoop, RejectsMismatchedTimingAndBadReference) {
  const Model model = testing::pendulum();
  PidOptions po;
  po.kp = Eigen::VectorXd::Constant(1, 10.0);
  PidController pid(model, po);
  Sensors sensors(model, {});
  Reference ref = testing::sine_reference(Eigen::VectorXd::Constant(1, 0.3),
                                          Eigen::VectorXd::Zero(1), 2 * kPi, 1e-3, 100);
  PlantOptions slow;
  slow.dt = 2e-3;
  auto wrong_dt = make_plant(model, slow);
  EXPECT_THROW(run_closed_loop(ref, pid, *wrong_dt, sensors), Error);
  auto plant = make_plant(model);
  Reference bad = ref;
  bad.t[50] += 1e-4;
  EXPECT_THROW(run_closed_loop(bad, pid, *plant, sensors), Error);
  bad = ref;
  bad.q(3, 0) = NAN;
  EXPECT_THROW(run_closed_loop(bad, pid, *plant, sensors), Error);
  bad = ref;
  bad.ddq.resize(100, 2);
  EXPECT_THROW(run_closed_loop(bad, pid, *plant, sensors), Error);
  ClosedLoopOptions lo;
  lo.periods = 0;
  EXPECT_THROW(run_closed_loop(ref, pid, *plant, sensors, lo), Error);
}

}  // namespace
}  // namespace dynid
