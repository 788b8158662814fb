// Discrete PID: derivative filter recurrence, saturation, anti-windup, computed-torque
// feed-forward.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "sim/sim_support.hpp"
#include "support/planar2.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

PidOptions gains(double kp, double ki, double kd, int n = 1) {
  PidOptions o;
  o.kp = Eigen::VectorXd::Constant(n, kp);
  o.ki = Eigen::VectorXd::Constant(n, ki);
  o.kd = Eigen::VectorXd::Constant(n, kd);
  return o;
}

// A measured ramp y_k = c·k·Ts through the backward-Euler filter s/(1 + Tf s) gives
// v_k = c·(1 − a^k), a = Tf/(Tf + Ts) (solution of the linear recurrence); D output = −Kd·v_k.
TEST(PidController, DerivativeFilterFollowsClosedForm) {
  const Model model = testing::pendulum();
  PidOptions o = gains(0.0, 0.0, 2.0);
  o.sample_time = 1e-3;
  o.derivative_filter_time = 4e-3;
  PidController pid(model, o);
  const double c = 0.7, a = 4e-3 / 5e-3;
  pid.reset(Eigen::VectorXd::Zero(1));
  Eigen::VectorXd tau(1), y(1), zero = Eigen::VectorXd::Zero(1);
  for (int k = 0; k < 50; ++k) {
    y[0] = c * k * 1e-3;
    pid.update(y, zero, zero, y, tau);  // zero position error, zero reference velocity
    EXPECT_NEAR(tau[0], -2.0 * c * (1.0 - std::pow(a, k)), 1e-12) << k;
  }
}

TEST(PidController, ProportionalIntegralAndReferenceVelocity) {
  const Model model = testing::pendulum();
  PidOptions o = gains(5.0, 20.0, 0.5);
  o.sample_time = 1e-2;
  PidController pid(model, o);
  pid.reset(Eigen::VectorXd::Zero(1));
  Eigen::VectorXd tau(1);
  const Eigen::VectorXd qr = Eigen::VectorXd::Constant(1, 0.1),
                        dqr = Eigen::VectorXd::Constant(1, 0.3), zero = Eigen::VectorXd::Zero(1);
  for (int k = 1; k <= 10; ++k) {
    pid.update(qr, dqr, zero, zero, tau);
    // u_k = Kp e + k Ts Ki e + Kd dqr (y constant: filtered velocity 0).
    EXPECT_NEAR(tau[0], 5.0 * 0.1 + k * 1e-2 * 20.0 * 0.1 + 0.5 * 0.3, 1e-14);
  }
}

// Output clamped at the limit; conditional integration freezes I while saturated by the error,
// whereas without anti-windup I_k = k·Ts·Ki·e keeps growing (to 100 N·m after 1000 samples), so
// that when the error reverses the output stays at +1 (−10 + 100 > 1).
TEST(PidController, SaturatesAndPreventsWindup) {
  const Model model = testing::pendulum();
  for (bool anti_windup : {true, false}) {
    PidOptions o = gains(10.0, 100.0, 0.0);
    o.effort_limit = Eigen::VectorXd::Constant(1, 1.0);
    o.anti_windup = anti_windup;
    PidController pid(model, o);
    pid.reset(Eigen::VectorXd::Zero(1));
    Eigen::VectorXd tau(1), zero = Eigen::VectorXd::Zero(1), qr = Eigen::VectorXd::Ones(1);
    for (int k = 1; k <= 1000; ++k) {
      pid.update(qr, zero, zero, zero, tau);
      EXPECT_EQ(tau[0], 1.0);
    }
    EXPECT_NEAR(pid.integral()[0], anti_windup ? 0.0 : 1000 * 1e-3 * 100.0, 1e-9);
    // The error reverses: the output leaves saturation at once only with anti-windup.
    pid.update(-qr, zero, zero, zero, tau);
    if (anti_windup)
      EXPECT_EQ(tau[0], -1.0);
    else
      EXPECT_EQ(tau[0], 1.0);
  }
}

// With zero gains the output is the computed torque of the reference: compared with the planar
// 2R closed form (Spong et al. eq. 7.87), an independent oracle for rnea on the reference.
TEST(PidController, ComputedTorqueFeedForwardMatchesClosedForm) {
  const testing::Planar2 arm;
  const Model model = arm.model();
  PidOptions o = gains(0.0, 0.0, 0.0, 2);
  o.feed_forward = FeedForward::kComputedTorque;
  PidController pid(model, o);
  std::mt19937 rng(3);
  Eigen::VectorXd tau(2);
  pid.reset(Eigen::VectorXd::Zero(2));
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector2d q = testing::random_vector(2, rng, 3.0),
                          dq = testing::random_vector(2, rng, 2.0),
                          ddq = testing::random_vector(2, rng, 5.0);
    pid.update(q, dq, ddq, q, tau);
    EXPECT_LT((tau - arm.torque(q, dq, ddq)).norm(), 1e-10);
  }
}

TEST(PidController, RejectsBadOptions) {
  const Model model = testing::pendulum();
  PidOptions o = gains(1.0, 0.0, 0.0, 2);
  EXPECT_THROW(PidController(model, o), Error);
  o = gains(-1.0, 0.0, 0.0);
  EXPECT_THROW(PidController(model, o), Error);
  o = gains(1.0, 0.0, 0.0);
  o.sample_time = 0.0;
  EXPECT_THROW(PidController(model, o), Error);
  o = gains(1.0, 0.0, 0.0);
  o.effort_limit = Eigen::VectorXd::Zero(1);
  EXPECT_THROW(PidController(model, o), Error);
  o = gains(1.0, 0.0, 0.0);
  o.kp.resize(0);
  EXPECT_THROW(PidController(model, o), Error);
}

}  // namespace
}  // namespace dynid
