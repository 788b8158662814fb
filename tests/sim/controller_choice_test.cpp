// simulate's controllers (issue 13 item 1): plain PID (seed 2's closed loop) or PID with
// computed-torque feed-forward, the default gain rule's stability with a measurement delay on every
// built-in robot and both engines, user gains and their file. Oracles: the reference itself (a
// stable loop tracks it; feed-forward from the true model removes the tracking error a plain PID
// must have, since PID output is zero only at zero error), and the gains as written in the test.
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "dynid/model/robots.hpp"
#include "dynid/sim/pid_gains.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "sim/sim_support.hpp"
#include "support/error_of.hpp"
#include "support/planar2.hpp"

namespace dynid {
namespace {

constexpr double kControllerRate = 200.0;  // seed 2's controller rate

// One 4 s period of a sine per joint inside the joint limits (centred at 60 % of the range: away
// from the straight-up pose at mid-range, where a 7-joint arm's inertias about joints 1, 3, 5, 7
// vary a hundredfold; amplitude ≤ 0.3 rad or a quarter of the range), sampled at kControllerRate.
Reference reference_for(const Model& model) {
  const int n = model.dof();
  Eigen::VectorXd a(n), c(n);
  for (int j = 0; j < n; ++j) {
    const JointLimits& l = model.joints[j].limits;
    const bool bounded = std::isfinite(l.lower) && std::isfinite(l.upper);
    c[j] = bounded ? l.lower + 0.6 * (l.upper - l.lower) : 0.0;
    a[j] = bounded ? std::min(0.3, 0.25 * (l.upper - l.lower)) : 0.3;
  }
  return testing::sine_reference(a, c, 2 * M_PI / 4.0, 1.0 / kControllerRate,
                                 static_cast<int>(4 * kControllerRate));
}

double rms_tracking_error(const ClosedLoopResult& r) {
  return std::sqrt((r.q - r.qr).squaredNorm() / static_cast<double>(r.q.size()));
}

TEST(ControllerChoice, DefaultGainsAreStableForEveryBuiltinRobotWithAndWithoutDelay) {
  const auto names = builtin_robot_names();
  ASSERT_GE(names.size(), 4u);
  for (const std::string& name : names) {
    const Model model = load_robot(name);
    const Reference ref = reference_for(model);
    for (PlantEngine engine : {PlantEngine::kNative, PlantEngine::kMujoco}) {
      for (int delay : {0, 1, 2}) {
        for (FeedForward ff : {FeedForward::kNone, FeedForward::kComputedTorque}) {
          SCOPED_TRACE(name + (engine == PlantEngine::kNative ? " native" : " mujoco") + " delay " +
                       std::to_string(delay) +
                       (ff == FeedForward::kNone ? " pid" : " pid-feedforward"));
          SimulateOptions o;
          o.plant.engine = engine;
          o.sensors.position_delay = delay;
          o.feed_forward = ff;
          o.loop.periods = 3;
          if (name == "iiwa14" && (ff == FeedForward::kNone || delay > 0)) {
            // KNOWN LIMITATION (docs/methods/sim.md): without feed-forward or with a measurement
            // delay the rule does not hold iiwa14 within the tracking bound (joints 1 and 3 drift
            // to 0.2 rad from a 0.3 rad sine); simulate_reference says so, naming --gains, instead
            // of writing the run. The delay-free feed-forward loop, simulate's default, holds it.
            const std::string e = testing::error_of(
                [&] { simulate_reference(model, ref.t, ref.q, ref.dq, ref.ddq, o); });
            if (!e.empty()) {
              EXPECT_NE(e.find("--gains FILE"), std::string::npos) << e;
            }
            continue;
          }
          ClosedLoopResult r;
          ASSERT_NO_THROW(r = simulate_reference(model, ref.t, ref.q, ref.dq, ref.ddq, o));
          // Stable and tracking: the last period's error is a fraction of the 0.3 rad amplitude
          // and no larger than the first period's (a slowly growing oscillation would be).
          const Eigen::Index p = ref.t.size();
          const Eigen::MatrixXd e = r.q - r.qr;
          const double first = e.topRows(p).cwiseAbs().maxCoeff();
          const double last = e.bottomRows(p).cwiseAbs().maxCoeff();
          EXPECT_LT(last, 0.15);
          EXPECT_LE(last, first + 1e-3);
        }
      }
    }
  }
}

// Gains that cannot hold the arm (ten times the default rule's: every mode ~3x beyond the
// discrete loop's limit) make the loop diverge on both engines: one error line naming the flag
// that replaces them, not the plant's numerical failure alone.
TEST(ControllerChoice, UnstableUserGainsNameTheGainsFlag) {
  const Model model = load_robot("iiwa14");
  const Reference ref = reference_for(model);
  for (PlantEngine engine : {PlantEngine::kNative, PlantEngine::kMujoco}) {
    SimulateOptions o;
    o.plant.engine = engine;
    o.loop.periods = 1;
    const PidOptions rule = reference_pid_options(model, ref.q, kControllerRate);
    o.gains = {10.0 * rule.kp, 10.0 * rule.ki, 10.0 * rule.kd, ""};
    const std::string e =
        testing::error_of([&] { simulate_reference(model, ref.t, ref.q, ref.dq, ref.ddq, o); });
    EXPECT_NE(e.find("--gains FILE"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(ControllerChoice, PlainPidHasTrackingErrorThatFeedForwardRemoves) {
  const Model model = load_robot("puma560");
  const Reference ref = reference_for(model);
  SimulateOptions o;
  o.plant.engine = PlantEngine::kMujoco;
  o.loop.periods = 2;
  o.feed_forward = FeedForward::kNone;
  const double pid =
      rms_tracking_error(simulate_reference(model, ref.t, ref.q, ref.dq, ref.ddq, o));
  o.feed_forward = FeedForward::kComputedTorque;
  const double ff = rms_tracking_error(simulate_reference(model, ref.t, ref.q, ref.dq, ref.ddq, o));
  std::printf("puma560 rms tracking error: pid %.3g rad, pid-feedforward %.3g rad\n", pid, ff);
  EXPECT_GT(pid, 1e-3);       // a PID needs an error to produce the torque that moves the arm
  EXPECT_GT(pid, 10.0 * ff);  // the true model's feed-forward supplies that torque itself
}

TEST(ControllerChoice, RuleBoundsTheCoupledModeAndTheLag) {
  // Oracle: the closed-form planar2 mass matrix at q = 0, M = [[a, b], [b, c]]. The free inertias
  // are 1/(M⁻¹)_jj: D1 = a − b²/c, D2 = c − b²/a; D^½·M⁻¹·D^½ has unit diagonal and off-diagonal
  // −b/√(ac), so μ_max = 1 + |b|/√(ac).
  const testing::Planar2 arm;
  const Model model = arm.model();
  const Eigen::Vector2d q0 = Eigen::Vector2d::Zero();
  const double a =
      arm.m1 * arm.lc1 * arm.lc1 + arm.m2 * std::pow(arm.l1 + arm.lc2, 2) + arm.I1 + arm.I2;
  const double b = arm.m2 * (arm.lc2 * arm.lc2 + arm.l1 * arm.lc2) + arm.I2;
  const double c = arm.m2 * arm.lc2 * arm.lc2 + arm.I2;
  const double d1 = a - b * b / c, d2 = c - b * b / a;
  const double mu_max = 1.0 + b / std::sqrt(a * c);
  const double w = 2 * M_PI * 5.0;  // 2π·rate/40 at 200 Hz
  const PidOptions ff = reference_pid_options(model, q0.transpose(), kControllerRate, 0);
  const PidOptions delayed = reference_pid_options(model, q0.transpose(), kControllerRate, 1);
  EXPECT_NEAR(ff.kp[0], d1 * w * w / mu_max, 1e-9 * ff.kp[0]);
  EXPECT_NEAR(ff.kp[1], d2 * w * w / mu_max, 1e-9 * ff.kp[1]);
  EXPECT_NEAR(ff.kd[0], ff.kp[0] * 2 * 0.9 / w, 1e-9 * ff.kd[0]);
  EXPECT_NEAR(ff.ki[1], ff.kp[1] / 2, 1e-12 * ff.ki[1]);
  // One sample of delay: lag (1 + 1)·Ts + 2·Ts = 20 ms instead of 15 ms, so ω scales by 15/20.
  EXPECT_NEAR(delayed.kp[0] / ff.kp[0], std::pow(15.0 / 20.0, 2), 1e-12);
  EXPECT_NEAR(delayed.kd[1] / ff.kd[1], 15.0 / 20.0, 1e-12);
  EXPECT_EQ(ff.feed_forward, FeedForward::kComputedTorque);
  // Plain PID: the gravity floor. At q = 0 joint 2 carries g·m2·lc2 (closed form), so
  // kp2 = max(rule, min(g·m2·lc2/0.02, D2·ω²)); joint 1 carries g·(m1·lc1 + m2·(l1 + lc2)).
  const PidOptions pid =
      reference_pid_options(model, q0.transpose(), kControllerRate, 0, FeedForward::kNone);
  EXPECT_EQ(pid.feed_forward, FeedForward::kNone);
  const double g2 = arm.g * arm.m2 * arm.lc2;
  const double g1 = arm.g * (arm.m1 * arm.lc1 + arm.m2 * (arm.l1 + arm.lc2));
  EXPECT_NEAR(pid.kp[1], std::max(ff.kp[1], std::min(g2 / 0.02, d2 * w * w)), 1e-9 * pid.kp[1]);
  EXPECT_NEAR(pid.kp[0], std::max(ff.kp[0], std::min(g1 / 0.02, d1 * w * w)), 1e-9 * pid.kp[0]);
  EXPECT_GT(pid.kp[1], ff.kp[1]);  // the floor is active on this arm
  EXPECT_NE(testing::error_of([&] {
              reference_pid_options(model, q0.transpose(), kControllerRate, -1);
            }).find("measurement delay must be >= 0"),
            std::string::npos);
}

// Along a reference, the rule takes the smallest free inertia and the largest μ it meets. Oracle:
// the closed-form planar2 M(q2) = [[a, b], [b, c]] at 13 elbow angles, D_j the minimum of the
// closed-form free inertias and μ the largest eigenvalue of the 2x2 D^½·M⁻¹·D^½ in closed form.
TEST(ControllerChoice, RuleReadsTheInertiasAlongTheReference) {
  const testing::Planar2 arm;
  const Model model = arm.model();
  Eigen::MatrixXd sweep(13, 2);
  for (int k = 0; k < 13; ++k) sweep.row(k) << 0.3, 0.1 * k;
  const auto abc = [&](double q2) {
    const double c2 = std::cos(q2);
    return Eigen::Vector3d(
        arm.m1 * arm.lc1 * arm.lc1 +
            arm.m2 * (arm.l1 * arm.l1 + arm.lc2 * arm.lc2 + 2 * arm.l1 * arm.lc2 * c2) + arm.I1 +
            arm.I2,
        arm.m2 * (arm.lc2 * arm.lc2 + arm.l1 * arm.lc2 * c2) + arm.I2,
        arm.m2 * arm.lc2 * arm.lc2 + arm.I2);
  };
  double d1 = INFINITY, d2 = INFINITY;
  for (int k = 0; k < 13; ++k) {
    const Eigen::Vector3d m = abc(sweep(k, 1));
    d1 = std::min(d1, m[0] - m[1] * m[1] / m[2]);
    d2 = std::min(d2, m[2] - m[1] * m[1] / m[0]);
  }
  double mu = 1.0;
  for (int k = 0; k < 13; ++k) {
    const Eigen::Vector3d m = abc(sweep(k, 1));
    const double det = m[0] * m[2] - m[1] * m[1];
    const double p = d1 * m[2] / det, r = d2 * m[0] / det, o = m[1] * std::sqrt(d1 * d2) / det;
    mu = std::max(mu, 0.5 * (p + r) + std::sqrt(0.25 * (p - r) * (p - r) + o * o));
  }
  const double w = 2 * M_PI * 5.0;
  const PidOptions along = reference_pid_options(model, sweep, kControllerRate);
  EXPECT_NEAR(along.kp[0], d1 * w * w / mu, 1e-9 * along.kp[0]);
  EXPECT_NEAR(along.kp[1], d2 * w * w / mu, 1e-9 * along.kp[1]);
  EXPECT_NE(testing::error_of([&] {
              reference_pid_options(model, Eigen::MatrixXd::Zero(4, 3), kControllerRate);
            }).find("samples x 2 joints"),
            std::string::npos);
}

// Largest sample-to-sample change of any logged torque after a 1 mrad step of joint 1's reference
// at 0.5 s, planar2 held at elbow angle q2 by the default delay-free feed-forward loop (2 s, one
// period). A stable loop's largest change is the proportional kick kp1·1 mrad at the step; an
// unstable mode grows from it instead (chatter, docs/methods/sim.md "torque chatter").
double torque_jump_after_step(double q2, double* kick) {
  const Model model = load_robot("planar2");
  const int m = static_cast<int>(2 * kControllerRate);
  Eigen::VectorXd t(m);
  Eigen::MatrixXd q(m, 2), zero = Eigen::MatrixXd::Zero(m, 2);
  for (int k = 0; k < m; ++k) {
    t[k] = k / kControllerRate;
    q.row(k) << 0.2 + (k >= m / 4 ? 1e-3 : 0.0), q2;
  }
  SimulateOptions o;
  o.loop.periods = 1;
  PidOptions used;
  const ClosedLoopResult r = simulate_reference(model, t, q, zero, zero, o, &used);
  *kick = used.kp[0] * 1e-3;
  return (r.tau.bottomRows(m - 1) - r.tau.topRows(m - 1)).cwiseAbs().maxCoeff();
}

TEST(ControllerChoice, FeedForwardLoopIsStableWithTheElbowBent) {
  // Positive control of the test below: at q2 = 1 rad the loop holds (measured: 3.1 N·m, kick
  // 3.6 N·m).
  double kick = 0.0;
  const double jump = torque_jump_after_step(1.0, &kick);
  EXPECT_LE(jump, 2.0 * kick);
}

// The historical delay-free feed-forward gains ∝ diag(M(q0)) left planar2's coupled mode unstable
// for |q2| < 0.58 rad (at q2 = 0 the 1 mrad step grew to 3.8e3 N·m swings in 1.5 s, on both
// engines, docs/methods/sim.md); the rule's μ division holds it.
TEST(ControllerChoice, FeedForwardLoopIsStableWithTheArmStretched) {
  double kick = 0.0;
  const double jump = torque_jump_after_step(0.0, &kick);
  EXPECT_LE(jump, 2.0 * kick);
}

class GainsFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("dynid_gains_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& text) const {
    const std::string path = (dir_ / "gains.yaml").string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
  Model model_ = load_robot("planar2");
};

TEST_F(GainsFile, UserGainsDriveTheRunAndReadBackFromTheWrittenFile) {
  const PidGains given =
      read_pid_gains(write("kp: [300, 40]\nki: [0, 2.5]\nkd: [30, 4]\n"), model_);
  EXPECT_EQ(given.kp, Eigen::Vector2d(300, 40));
  EXPECT_EQ(given.ki, Eigen::Vector2d(0, 2.5));
  EXPECT_EQ(given.kd, Eigen::Vector2d(30, 4));
  const Reference ref = reference_for(model_);
  SimulateOptions o;
  o.plant.engine = PlantEngine::kNative;
  o.loop.periods = 1;
  o.gains = given;
  // With the feed-forward these soft gains track; the plain PID leaves the elbow 0.19 rad behind,
  // which simulate_reference refuses (not tracking).
  o.feed_forward = FeedForward::kComputedTorque;
  PidOptions used;
  simulate_reference(model_, ref.t, ref.q, ref.dq, ref.ddq, o, &used);
  EXPECT_EQ(used.kp, given.kp);
  EXPECT_EQ(used.ki, given.ki);
  EXPECT_EQ(used.kd, given.kd);
  const std::string out = (dir_ / "run.gains.json").string();
  write_pid_gains(out, model_, used, 0);
  const PidGains back = read_pid_gains(out, model_);
  EXPECT_EQ(back.kp, given.kp);  // JSON doubles round-trip exactly
  EXPECT_EQ(back.ki, given.ki);
  EXPECT_EQ(back.kd, given.kd);
}

TEST_F(GainsFile, BadFilesNameTheFileAndTheFault) {
  const auto error = [&](const std::string& text) {
    return testing::error_of([&] { read_pid_gains(write(text), model_); });
  };
  const std::string path = (dir_ / "gains.yaml").string();
  EXPECT_EQ(error("kp: [300, 40]\nki: [0, 0]\n"),
            "gains file " + path + " has no 'kd': give kp, ki and kd, one value per joint");
  EXPECT_EQ(
      error("kp: [300]\nki: [0, 0]\nkd: [1, 1]\n"),
      "gains file " + path + ": 'kp' must be a list of 2 values (one per joint), got 1 values");
  EXPECT_EQ(error("kp: 300\nki: [0, 0]\nkd: [1, 1]\n"),
            "gains file " + path +
                ": 'kp' must be a list of 2 values (one per joint), got a single value");
  EXPECT_EQ(error("kp: [300, -1]\nki: [0, 0]\nkd: [1, 1]\n"),
            "gains file " + path + ": kp[2] = -1 must be a finite number >= 0");
  EXPECT_NE(error("kp: [300, .nan]\nki: [0, 0]\nkd: [1, 1]\n").find("kp[2] = nan must be a finite"),
            std::string::npos);
  EXPECT_EQ(error("kp: [300, 1]\nki: [0, x]\nkd: [1, 1]\n"),
            "gains file " + path + ": ki[2] is not a number");
  EXPECT_EQ(error("kp: [300, 1]\nki: [0, 0]\nkd: [1, 1]\nKp: [1, 1]\n"),
            "gains file " + path + ": unknown key 'Kp'; the gains are kp, ki, kd");
  EXPECT_NE(error("kp: [300, 1\n").find("gains file " + path + " is not valid YAML"),
            std::string::npos);
  EXPECT_EQ(error("- 1\n- 2\n"),
            "gains file " + path + " must be a mapping with kp, ki, kd lists, e.g. kp: [400, 120]");
  const std::string missing = (dir_ / "none.yaml").string();
  EXPECT_EQ(testing::error_of([&] { read_pid_gains(missing, model_); }),
            "cannot read gains file " + missing + ": check the path");
}

}  // namespace
}  // namespace dynid
