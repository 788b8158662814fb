// Gross torque outliers (issue 10): one torque sample of 1e200 made every identified value NaN
// with only a "poorly excited" warning. Oracles: outliers injected at known samples; the planar
// 2R closed form of tests/support/planar2.hpp (Spong et al.) produces the run, so the residual
// after dropping the outlier is compared with the noise level the test added.

#include "dynid/identification/outliers.hpp"
#include "dynid/identification/identify.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "support/estimation_support.hpp"
#include "support/planar2.hpp"

namespace dynid {
namespace {

using estimation_testing::expect_error;

constexpr double kNoise = 0.01;  // N·m

// 20 s at 100 Hz of the planar arm on two sine sums, closed-form torques plus seeded noise.
JointRecord planar2_run(const testing::Planar2& arm) {
  const Eigen::Index m = 2000;
  JointRecord r;
  r.t.resize(m);
  r.q.resize(m, 2);
  r.dq.resize(m, 2);
  r.ddq.resize(m, 2);
  r.tau.resize(m, 2);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, kNoise);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = 0.01 * static_cast<double>(k);
    r.t[k] = t;
    r.q.row(k) << std::sin(0.7 * t) + 0.3 * std::sin(2.1 * t), 0.8 * std::cos(1.3 * t);
    r.dq.row(k) << 0.7 * std::cos(0.7 * t) + 0.63 * std::cos(2.1 * t), -1.04 * std::sin(1.3 * t);
    r.ddq.row(k) << -0.49 * std::sin(0.7 * t) - 1.323 * std::sin(2.1 * t),
        -1.352 * std::cos(1.3 * t);
    const Eigen::Vector2d tau =
        arm.torque(r.q.row(k).transpose(), r.dq.row(k).transpose(), r.ddq.row(k).transpose());
    r.tau.row(k) << tau[0] + noise(rng), tau[1] + noise(rng);
  }
  return r;
}

IdentifyOptions rigid_body_only() {
  IdentifyOptions o;
  o.layout = ParameterLayout{};  // no friction, no armature: the closed form has none
  return o;
}

TEST(Outliers, FindsSpikesButNotSmoothPeaksOrCoulombSteps) {
  const Eigen::Index m = 1000;
  Eigen::MatrixXd tau(m, 2);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = 0.01 * static_cast<double>(k);
    // Joint 1: noiseless sine (MAD of the residual is 0: the signal floor must hold).
    // Joint 2: sine + a Coulomb step of 2·3 N·m at every velocity reversal + noise.
    tau(k, 0) = 10 * std::sin(2 * M_PI * 0.5 * t);
    tau(k, 1) = 5 * std::sin(2 * M_PI * 0.3 * t) + 3 * (std::cos(2 * M_PI * 0.3 * t) > 0 ? 1 : -1) +
                noise(rng);
  }
  EXPECT_TRUE(find_torque_outliers(tau).empty());
  tau(400, 1) = 60.0;  // 60 N·m where the signal is within ±8
  tau(401, 0) = -1e200;
  const std::vector<TorqueOutlier> found = find_torque_outliers(tau);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].sample, 400);
  EXPECT_EQ(found[0].joint, 1);
  EXPECT_EQ(found[0].value, 60.0);
  EXPECT_EQ(found[1].sample, 401);
  EXPECT_EQ(found[1].joint, 0);
  // The replacement is a neighbour: off the true value by at most one sample's change, i.e. the
  // largest slope 10·π N·m/s times 0.01 s.
  EXPECT_NEAR(found[1].local_median, 10 * std::sin(2 * M_PI * 0.5 * 4.01), 1.01 * 10 * M_PI * 0.01);
}

TEST(Outliers, HugeTorqueSampleIsAnErrorNamingItUnlessDropped) {
  const testing::Planar2 arm;
  const Model model = arm.model();
  JointRecord run = planar2_run(arm);
  run.tau(523, 1) = 1e200;
  expect_error([&] { identify(model, run, rigid_body_only()); },
               {"not finite", "tau2 at sample 524", "--outliers drop"});
  IdentifyOptions drop = rigid_body_only();
  drop.outliers.policy = OutlierPolicy::kDrop;
  const IdentificationResult r = identify(model, run, drop);
  ASSERT_TRUE(r.estimate.x.allFinite());
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("1 gross torque outliers replaced"), std::string::npos);
  EXPECT_NE(r.warnings[0].find("tau2 at sample 524 (t = 5.23 s) = 1e+200"), std::string::npos);
  // The closed form explains the cleaned run down to the added noise (filtered: at most kNoise).
  for (int j = 0; j < 2; ++j) EXPECT_LT(r.residual_rms[j], 1.5 * kNoise) << j;
}

TEST(Outliers, ModerateOutlierIsReportedAndKept) {
  const testing::Planar2 arm;
  JointRecord run = planar2_run(arm);
  run.tau(1000, 0) = 500.0;  // the torques of this run stay below ~45 N·m
  const IdentificationResult r = identify(arm.model(), run, rigid_body_only());
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("1 gross torque outliers kept"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("tau1 at sample 1001"), std::string::npos) << r.warnings[0];
  // Kept: the spike is in the residual, far above the noise.
  EXPECT_GT(r.residual_rms[0], 10 * kNoise);
}

}  // namespace
}  // namespace dynid
