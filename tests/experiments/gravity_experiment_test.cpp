// Gravity experiment (seed 2 §3.2.1, eq. 23, Table 1): slopes of one joint of planar2 at ±v, run
// in closed loop on the native plant (RK4 of the forward dynamics, tanh-smoothed Coulomb friction)
// with encoder and torque noise, prepared by preprocess() with its defaults. The truth k, q_off
// comes from RNEA's gravity torque at q_J = 0 and π/2 (τ_g = a·sin q + b·cos q), not from the fit's
// equations. Fixed seeds.
#include <cmath>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/slope_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/experiments/gravity_experiment.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "support/closed_loop_runs.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

constexpr double kGravityRate = 200.0;

Model gravity_plant_model() {
  Model m = load_robot("planar2");
  m.joints[0].friction.Fv = 1.5;
  m.joints[0].friction.Fc = 2.0;
  m.joints[1].friction.Fv = 0.8;
  m.joints[1].friction.Fc = 1.0;
  return m;
}

// k and q_off of joint J with the other joints at `pose`, from RNEA's gravity torque.
std::pair<double, double> true_gravity(const Model& m, int joint, Eigen::VectorXd pose) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.dof());
  RneaOptions g;
  g.joint_terms = false;
  pose[joint] = 0.0;
  const double b = rnea(m, pose, zero, zero, g)[joint];
  pose[joint] = kPi / 2;
  const double a = rnea(m, pose, zero, zero, g)[joint];
  double q_off = std::atan2(b, a), k = std::hypot(a, b);
  if (q_off > kPi / 2) {
    q_off -= kPi;
    k = -k;
  } else if (q_off <= -kPi / 2) {
    q_off += kPi;
    k = -k;
  }
  return {k, q_off};
}

// (k, q_off) and (−k, q_off ± π) are one curve; q_off is reported in (−π/2, π/2], so a truth at
// the boundary may come back as its twin: compare on the truth's side.
std::pair<double, double> same_side(double k, double q_off, double q_off_truth) {
  if (q_off - q_off_truth > kPi / 2) return {-k, q_off - kPi};
  if (q_off_truth - q_off > kPi / 2) return {-k, q_off + kPi};
  return {k, q_off};
}

ProcessedRecord prepared(const Model& m, const TrajectorySamples& tr, unsigned seed) {
  return testing::prepared(
      testing::closed_loop_run(m, tr, testing::noisy_sensors(1e-4, 0.05, seed, 3)), kGravityRate);
}

TrajectorySamples slopes(int joint, const Eigen::Vector2d& pose, double velocity) {
  Eigen::Vector2d from = pose, to = pose;
  from[joint] = -1.2;
  to[joint] = 1.2;
  const SlopeTrajectory tr(from, to, Eigen::Vector2d::Constant(velocity),
                           Eigen::Vector2d::Constant(2.0), 1, 0.5);
  return sample_trajectory(tr, kGravityRate, false);
}

TEST(GravityExperiment, RecoversTheGravityOfEachJointInsideItsInterval) {
  const Model m = gravity_plant_model();
  const Eigen::Vector2d pose(0.3, 0.6);
  for (int joint : {0, 1}) {
    for (unsigned seed : {1u, 2u}) {
      const GravityExperimentResult r =
          fit_gravity_experiment({prepared(m, slopes(joint, pose, 0.6), seed)}, joint);
      const auto [k, q_off] = true_gravity(m, joint, pose);
      SCOPED_TRACE("joint " + std::to_string(joint + 1) + ", seed " + std::to_string(seed));
      const auto [rk, rq] = same_side(r.k, r.q_off, q_off);
      EXPECT_NEAR(rk, k, r.k_ci_half_width) << "k std " << r.k_std;
      EXPECT_NEAR(rq, q_off, r.q_off_ci_half_width) << "q_off std " << r.q_off_std;
      // Intervals that are informative, not merely wide: within 5 % of |k| and 0.02 rad.
      EXPECT_LT(r.k_ci_half_width, 0.05 * std::abs(k));
      EXPECT_LT(r.q_off_ci_half_width, 0.02);
      ASSERT_EQ(r.slope_names.size(), 2u);  // one run, both directions
      // The offsets are the friction of each direction: c± = ±(Fv·v + Fc) (the plant's tanh is
      // saturated at these speeds); checked loosely, they are nuisance parameters.
      const JointFriction& f = m.joints[joint].friction;
      for (size_t s = 0; s < 2; ++s) {
        const double v = r.slope_velocity[s];
        EXPECT_NEAR(v, s == 0 ? 0.6 : -0.6, 0.01);
        EXPECT_NEAR(r.offset[s], f.Fv * v + f.Fc * (v > 0 ? 1 : -1), 0.05 * (f.Fv * 0.6 + f.Fc));
      }
    }
  }
}

TEST(GravityExperiment, TwoRunsOneDirectionEach) {
  // The form: --data up.csv --data down.csv. Each run here has both directions; the fit
  // uses every slope it finds and keeps one offset per (run, direction).
  const Model m = gravity_plant_model();
  const Eigen::Vector2d pose(0.0, -0.4);
  const GravityExperimentResult r = fit_gravity_experiment(
      {prepared(m, slopes(1, pose, 0.4), 3), prepared(m, slopes(1, pose, 0.8), 4)}, 1);
  const auto [k, q_off] = true_gravity(m, 1, pose);
  EXPECT_EQ(r.slope_names.size(), 4u);
  const auto [rk, rq] = same_side(r.k, r.q_off, q_off);
  EXPECT_NEAR(rk, k, r.k_ci_half_width);
  EXPECT_NEAR(rq, q_off, r.q_off_ci_half_width);
}

TEST(GravityExperiment, ARunWithoutConstantVelocityIsRefused) {
  const Model m = gravity_plant_model();
  FourierCoefficients c = FourierCoefficients::zeros({3, 3}, 0.2);
  c.a[0] << 0.8, 0.3, -0.2;
  c.b[1] << 0.2, -0.1, 0.1;
  const TrajectorySamples tr = sample_trajectory(FourierTrajectory(c), kGravityRate, false);
  try {
    fit_gravity_experiment({prepared(m, tr, 1)}, 0);
    FAIL() << "a Fourier run was accepted as slopes";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("without a constant-velocity part"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(fit_gravity_experiment({prepared(m, slopes(0, {0, 0}, 0.6), 1)}, 2), UsageError);
  EXPECT_THROW(fit_gravity_experiment({}, 0), UsageError);
}

// The value of a base parameter from its expression ("MX1R = MX1 + 0.5*M2 - MY2") and the
// standard parameters of the model: the truth of fit_gravity_poses() without its own reduction.
double expression_value(const std::string& expression, const std::map<std::string, double>& theta) {
  std::istringstream in(expression.substr(expression.find('=') + 1));
  double value = 0.0, sign = 1.0;
  std::string token;
  while (in >> token) {
    if (token == "+" || token == "-") {
      sign = token == "-" ? -1.0 : 1.0;
      continue;
    }
    const size_t star = token.find('*');
    const double c = star == std::string::npos ? 1.0 : std::stod(token.substr(0, star));
    value += sign * c * theta.at(star == std::string::npos ? token : token.substr(star + 1));
    sign = 1.0;
  }
  return value;
}

// Item 2's general form: the shoulder's gravity depends on the elbow too (4 base parameters:
// first moments of both links, the elbow's mass regrouped into the shoulder's), so slopes at one
// elbow pose give k and q_off only; three elbow poses determine all four.
TEST(GravityPoses, ShoulderGravityFromSlopesAtThreeElbowPoses) {
  const Model m = gravity_plant_model();
  const std::vector<double> elbow = {-0.6, 0.3, 1.0};
  std::vector<ProcessedRecord> runs;
  for (size_t i = 0; i < elbow.size(); ++i)
    runs.push_back(prepared(m, slopes(0, {0.0, elbow[i]}, 0.6), 11 + static_cast<unsigned>(i)));
  const GravityPosesResult r = fit_gravity_poses(m, runs, 0);
  ASSERT_EQ(r.names.size(), 4u) << ::testing::PrintToString(r.expressions);
  std::map<std::string, double> theta;
  const std::vector<std::string> names = ParameterLayout::rigid().names(m.dof());
  const Eigen::VectorXd values = ParameterLayout::rigid().parameters(m);
  for (size_t i = 0; i < names.size(); ++i) theta[names[i]] = values[static_cast<Eigen::Index>(i)];
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    const double truth = expression_value(r.expressions[i], theta);
    const double half = r.estimate.ci_upper[c] - r.estimate.x[c];
    EXPECT_NEAR(r.estimate.x[c], truth, half) << r.expressions[i];
    // Informative, not merely wide: within 3 % of the largest gravity parameter.
    EXPECT_LT(half, 0.03 * values.cwiseAbs().maxCoeff()) << r.names[i];
  }
  // Per pose, k and q_off agree with RNEA's gravity torque at that pose.
  ASSERT_EQ(r.k.size(), elbow.size());
  for (size_t p = 0; p < elbow.size(); ++p) {
    SCOPED_TRACE("elbow at " + std::to_string(elbow[p]));
    EXPECT_NEAR(r.pose[p][1], elbow[p], 1e-2);
    const auto [k, q_off] = true_gravity(m, 0, r.pose[p]);
    const auto [rk, rq] = same_side(r.k[p], r.q_off[p], q_off);
    EXPECT_NEAR(rk, k, r.k_ci_half_width[p]);
    EXPECT_NEAR(rq, q_off, r.q_off_ci_half_width[p]);
  }
  EXPECT_EQ(r.slope_names.size(), 2 * elbow.size());
}

// The gravity a poses result stands for, as `identify --model friction --params gravity.json`
// compensates it (issue 25 item 7): with the true values of the fitted base parameters (from
// their expressions), JointGravityModel::poses() gives RNEA's gravity torque of the shoulder at
// poses the fit never saw; names of another joint are an error.
TEST(GravityPoses, PosesModelPredictsTheGravityTorqueAtAnyPose) {
  const Model m = gravity_plant_model();
  std::vector<ProcessedRecord> runs;
  for (const double elbow : {-0.6, 0.3, 1.0})
    runs.push_back(prepared(m, slopes(0, {0.0, elbow}, 0.6), 31));
  const GravityPosesResult r = fit_gravity_poses(m, runs, 0);
  std::map<std::string, double> theta;
  const std::vector<std::string> names = ParameterLayout::rigid().names(m.dof());
  const Eigen::VectorXd values = ParameterLayout::rigid().parameters(m);
  for (size_t i = 0; i < names.size(); ++i) theta[names[i]] = values[static_cast<Eigen::Index>(i)];
  Eigen::VectorXd truth(static_cast<Eigen::Index>(r.names.size()));
  for (size_t i = 0; i < r.names.size(); ++i)
    truth[static_cast<Eigen::Index>(i)] = expression_value(r.expressions[i], theta);
  const JointGravityModel g = JointGravityModel::poses(m, 0, r.names, truth);
  RneaOptions gravity_only;
  gravity_only.joint_terms = false;
  const Eigen::Vector2d zero(0.0, 0.0);
  for (const auto& q :
       {Eigen::Vector2d(0.4, -1.3), Eigen::Vector2d(-2.0, 2.5), Eigen::Vector2d(1.1, 0.2)}) {
    const double expected = rnea(m, q, zero, zero, gravity_only)[0];
    EXPECT_NEAR(g.torque(q), expected, 1e-9 * std::max(1.0, std::abs(expected))) << q.transpose();
  }
  EXPECT_THROW(JointGravityModel::poses(m, 1, r.names, truth), Error);
}

TEST(GravityPoses, OnePoseOfTheOtherJointsIsRefusedNamingWhatIsMissing) {
  const Model m = gravity_plant_model();
  const std::vector<ProcessedRecord> runs = {prepared(m, slopes(0, {0.0, 0.3}, 0.6), 21),
                                             prepared(m, slopes(0, {0.0, 0.3}, 0.4), 22)};
  try {
    fit_gravity_poses(m, runs, 0);
    FAIL() << "one elbow pose was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("1 distinct pose,"), std::string::npos) << what;
    EXPECT_NE(what.find("undetermined"), std::string::npos) << what;
    EXPECT_NE(what.find("with joint 2 held at 2 or more different poses"), std::string::npos)
        << what;
  }
  // The elbow's own gravity needs no other pose: its two parameters come from one.
  EXPECT_EQ(fit_gravity_poses(m, {prepared(m, slopes(1, {0.3, 0.0}, 0.6), 23)}, 1).names.size(),
            2u);
}

}  // namespace
}  // namespace dynid
