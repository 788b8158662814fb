// Implausible units (issue 10): a run with its time in milliseconds identified parameters 10⁶×
// too large with small %σ and no warning; all-zero torques gave "-nan %". Oracle: the rates and
// ranges below are set by construction.

#include "dynid/signal/plausibility.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "support/error_of.hpp"

namespace dynid {
namespace {

struct Log {
  Eigen::VectorXd t;
  Eigen::MatrixXd q, tau;
};

// m samples at `rate` Hz (t in seconds times `time_unit`), two joints moving, torques non-zero.
Log run(double rate, double time_unit = 1.0, Eigen::Index m = 500) {
  Log r;
  r.t = Eigen::VectorXd::LinSpaced(m, 0.0, static_cast<double>(m - 1) / rate) * time_unit;
  r.q.resize(m, 2);
  r.tau.resize(m, 2);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = static_cast<double>(k) / rate;
    r.q.row(k) << std::sin(t), std::cos(t);
    r.tau.row(k) << 3 * std::sin(t) + 1, 2 * std::cos(t);
  }
  return r;
}

const std::vector<std::string> kJoints = {"shoulder", "elbow"};

TEST(Plausibility, PlainRunPasses) {
  const Log r = run(200.0);
  EXPECT_TRUE(check_run_plausibility(r.t, r.q, r.tau, kJoints).empty());
}

TEST(Plausibility, MillisecondsAndMicrosecondsAreErrors) {
  Log r = run(200.0, 1000.0);  // 200 Hz logged in ms: 0.2 Hz
  std::string e = testing::error_of([&] { check_run_plausibility(r.t, r.q, r.tau, kJoints); });
  EXPECT_NE(e.find("sample rate of 0.2 Hz"), std::string::npos) << e;
  EXPECT_NE(e.find("divide milliseconds by 1000"), std::string::npos) << e;
  r = run(200.0, 1e-3);  // time stamps 1000× too small: 200 kHz
  e = testing::error_of([&] { check_run_plausibility(r.t, r.q, r.tau, kJoints); });
  EXPECT_NE(e.find("outside 1 Hz to 1e+05 Hz"), std::string::npos) << e;
}

TEST(Plausibility, OneKilohertzInMillisecondsWarns) {
  const Log r = run(1000.0, 1000.0);  // 1 Hz: inside the limits, but suspicious
  const auto w = check_run_plausibility(r.t, r.q, r.tau, kJoints);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("low sample rate 1 Hz"), std::string::npos) << w[0];
}

TEST(Plausibility, ZeroTorquesAndStillRuns) {
  Log r = run(100.0);
  r.tau.setZero();
  std::string e = testing::error_of([&] { check_run_plausibility(r.t, r.q, r.tau, kJoints); });
  EXPECT_NE(e.find("torque is zero in every sample of every joint"), std::string::npos) << e;
  r = run(100.0);
  r.tau.col(1).setZero();
  r.q.col(0).setConstant(0.3);
  const auto w = check_run_plausibility(r.t, r.q, r.tau, kJoints);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[0].find("torque zero in every sample for elbow"), 0u) << w[0];
  EXPECT_EQ(w[1].find("shoulder do not move"), 0u) << w[1];
  r.q.col(1).setConstant(-1.0);
  e = testing::error_of([&] { check_run_plausibility(r.t, r.q, r.tau, kJoints); });
  EXPECT_NE(e.find("the run does not move"), std::string::npos) << e;
}

// find_corrupt_sample (issue 27 item 3): one sample of 1e200 in a torque column, or 1e155 in a
// position column, is found; a real run's extremes (a sine's peaks, a joint held still and then
// moved) are not. Oracle: samples injected at known rows.
TEST(Plausibility, CorruptSampleIsFoundAndRealMotionIsNot) {
  Log r = run(100.0, 1.0, 2000);
  EXPECT_FALSE(find_corrupt_sample(r.q, 1.0));
  EXPECT_FALSE(find_corrupt_sample(r.tau, 1.0));
  // Held still for 90 % of the run (MAD 0), then a 3 rad move: the floor keeps it plausible.
  Eigen::MatrixXd held = Eigen::MatrixXd::Zero(2000, 1);
  held.bottomRows(200).setConstant(3.0);
  EXPECT_FALSE(find_corrupt_sample(held, 1.0));
  r.tau(523, 1) = 1e200;
  r.q(900, 0) = 1e155;
  const auto tau = find_corrupt_sample(r.tau, 1.0);
  ASSERT_TRUE(tau);
  EXPECT_EQ(tau->sample, 523);
  EXPECT_EQ(tau->column, 1);
  EXPECT_EQ(tau->value, 1e200);
  const auto q = find_corrupt_sample(r.q, 1.0);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->sample, 900);
  EXPECT_EQ(q->column, 0);
  // The first by row: a later row of another column does not hide it.
  r.q(1500, 1) = -1e100;
  EXPECT_EQ(find_corrupt_sample(r.q, 1.0)->sample, 900);
}

}  // namespace
}  // namespace dynid
