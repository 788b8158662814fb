// Sensor models: Gaussian noise statistics, encoder quantisation, delays, reproducibility.
#include <cmath>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/sim/sensors.hpp"
#include "support/random_models.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

// Sample mean and std of N draws: mean within 5σ/√N, std within 5·σ/√(2N) (its standard error).
TEST(Sensors, NoiseHasRequestedMeanAndStd) {
  const Model model = testing::random_tree(2, 1, false, true);
  SensorOptions o;
  o.position_noise_std = 1e-3;
  o.torque_noise_std = 0.2;
  o.seed = 42;
  Sensors sensors(model, o);
  const int n = 20000;
  const Eigen::Vector2d q(0.3, -1.2), tau(5.0, -2.0);
  Eigen::Vector2d y, m;
  Eigen::Array2d sy = Eigen::Array2d::Zero(), syy = sy, sm = sy, smm = sy;
  for (int k = 0; k < n; ++k) {
    sensors.measure_position(q, y);
    sensors.measure_torque(tau, m);
    sy += (y - q).array();
    syy += (y - q).array().square();
    sm += (m - tau).array();
    smm += (m - tau).array().square();
  }
  for (int j = 0; j < 2; ++j) {
    const double my = sy[j] / n, mm = sm[j] / n;
    EXPECT_NEAR(my, 0.0, 5 * 1e-3 / std::sqrt(n));
    EXPECT_NEAR(std::sqrt(syy[j] / n - my * my), 1e-3, 5 * 1e-3 / std::sqrt(2.0 * n));
    EXPECT_NEAR(mm, 0.0, 5 * 0.2 / std::sqrt(n));
    EXPECT_NEAR(std::sqrt(smm[j] / n - mm * mm), 0.2, 5 * 0.2 / std::sqrt(2.0 * n));
  }
}

TEST(Sensors, SameSeedSameNoiseAndResetReplays) {
  const Model model = testing::random_tree(3, 1, false, true);
  SensorOptions o;
  o.position_noise_std = 0.1;
  o.seed = 7;
  Sensors a(model, o), b(model, o);
  Eigen::VectorXd ya(3), yb(3), first(3);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  a.measure_position(q, first);
  b.measure_position(q, yb);
  EXPECT_EQ(first, yb);
  a.reset();
  a.measure_position(q, ya);
  EXPECT_EQ(ya, first);
  o.seed = 8;
  Sensors c(model, o);
  c.measure_position(q, yb);
  EXPECT_NE(yb, first);
}

// Encoder with 4096 counts/rev: readings are integer multiples of 2π/4096 within half a count of
// the truth; prismatic joints use their own resolution.
TEST(Sensors, QuantisesToEncoderCounts) {
  const Model model = testing::random_tree(3, 2, true, true);  // joint 3 prismatic
  ASSERT_EQ(model.joints[2].type, JointType::kPrismatic);
  SensorOptions o;
  o.counts_per_rev = 4096;
  o.prismatic_resolution = 1e-5;
  Sensors sensors(model, o);
  const double step = 2 * kPi / 4096;
  EXPECT_DOUBLE_EQ(sensors.resolution()[0], step);
  EXPECT_DOUBLE_EQ(sensors.resolution()[2], 1e-5);
  Eigen::VectorXd y(3);
  for (double v = -3.0; v < 3.0; v += 0.001237) {
    const Eigen::Vector3d q(v, 0.5 * v, 0.01 * v);
    sensors.measure_position(q, y);
    for (int j = 0; j < 3; ++j) {
      const double s = j == 2 ? 1e-5 : step;
      EXPECT_LE(std::abs(y[j] - q[j]), 0.5 * s * (1 + 1e-9));
      EXPECT_NEAR(y[j] / s, std::round(y[j] / s), 1e-6);
    }
  }
}

// A delay of d samples returns the input of d calls ago (the first input before that).
TEST(Sensors, DelayShiftsByWholeSamples) {
  const Model model = testing::random_tree(1, 2, false, true);
  SensorOptions o;
  o.position_delay = 3;
  o.torque_delay = 1;
  Sensors sensors(model, o);
  Eigen::VectorXd y(1), m(1);
  for (int k = 0; k < 10; ++k) {
    sensors.measure_position(Eigen::VectorXd::Constant(1, k), y);
    sensors.measure_torque(Eigen::VectorXd::Constant(1, 10.0 * k), m);
    EXPECT_EQ(y[0], std::max(0, k - 3));
    EXPECT_EQ(m[0], 10.0 * std::max(0, k - 1));
  }
}

TEST(Sensors, RejectsBadOptions) {
  const Model model = testing::random_tree(1, 2, false, true);
  SensorOptions o;
  o.position_noise_std = -1.0;
  EXPECT_THROW(Sensors(model, o), Error);
  o = {};
  o.counts_per_rev = NAN;
  EXPECT_THROW(Sensors(model, o), Error);
  o = {};
  o.position_delay = -1;
  EXPECT_THROW(Sensors(model, o), Error);
  Sensors ok(model, {});
  Eigen::VectorXd y(2);
  EXPECT_THROW(ok.measure_position(Eigen::VectorXd::Zero(2), y), Error);
}

}  // namespace
}  // namespace dynid
