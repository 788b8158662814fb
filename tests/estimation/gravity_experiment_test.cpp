// Gravity experiment (seed 2 §3.2.1, eq. 23, Table 1): slopes of one joint of planar2 at ±v, run
// in closed loop on the native plant (RK4 of the forward dynamics, tanh-smoothed Coulomb friction)
// with encoder and torque noise, prepared by preprocess() with its defaults. The truth k, q_off
// comes from RNEA's gravity torque at q_J = 0 and π/2 (τ_g = a·sin q + b·cos q), not from the fit's
// equations. Fixed seeds.
#include <cmath>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/estimation/gravity_experiment.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/slope_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "support/closed_loop_runs.hpp"

namespace dynid {
namespace {

constexpr double kRate = 200.0;
constexpr double kPi = 3.14159265358979323846;

Model plant_model() {
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
      testing::closed_loop_run(m, tr, testing::noisy_sensors(1e-4, 0.05, seed, 3)), kRate);
}

TrajectorySamples slopes(int joint, const Eigen::Vector2d& pose, double velocity) {
  Eigen::Vector2d from = pose, to = pose;
  from[joint] = -1.2;
  to[joint] = 1.2;
  const SlopeTrajectory tr(from, to, Eigen::Vector2d::Constant(velocity),
                           Eigen::Vector2d::Constant(2.0), 1, 0.5);
  return sample_trajectory(tr, kRate, false);
}

TEST(GravityExperiment, RecoversTheGravityOfEachJointInsideItsInterval) {
  const Model m = plant_model();
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
  const Model m = plant_model();
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
  const Model m = plant_model();
  FourierCoefficients c = FourierCoefficients::zeros({3, 3}, 0.2);
  c.a[0] << 0.8, 0.3, -0.2;
  c.b[1] << 0.2, -0.1, 0.1;
  const TrajectorySamples tr = sample_trajectory(FourierTrajectory(c), kRate, false);
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

}  // namespace
}  // namespace dynid
