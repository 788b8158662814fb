// Joint-decoupled model (seed 2 §3.1, eqs. 21–22): one joint of planar2 moves under a Fourier
// reference while the other is held, in closed loop on the native plant (RK4, tanh-smoothed
// Coulomb friction with an offset), prepared with preprocess()'s defaults. The truth comes from
// the model: M_JJ at the held pose from CRBA, gravity from RNEA at q_J = 0 and π/2, friction
// from the plant. Fixed seeds.
#include <cmath>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/experiments/decoupled_model.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "support/closed_loop_runs.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

constexpr double kRate = 200.0;

Model plant_model() {
  Model m = load_robot("planar2");
  m.joints[0].friction = {0.05, 1.5, 2.0, 0.4};
  m.joints[1].friction = {0.02, 0.8, 1.0, -0.2};
  return m;
}

// Joint `moving` follows a 3-harmonic Fourier reference about the pose; `also` (if ≥ 0) moves too.
ProcessedRecord run(const Model& m, int moving, const Eigen::Vector2d& pose, unsigned seed,
                    int also = -1) {
  FourierCoefficients c = FourierCoefficients::zeros({3, 3}, 0.25);
  c.a[moving] << 0.9, 0.4, -0.3;
  c.b[moving] << 0.3, -0.2, 0.15;
  if (also >= 0) c.a[also] << 0.3, 0.1, 0.0;
  c.q0 = pose;
  const TrajectorySamples tr = sample_trajectory(FourierTrajectory(c), kRate, false);
  return testing::prepared(
      testing::closed_loop_run(m, tr, testing::noisy_sensors(1e-4, 0.05, seed, 4)), kRate);
}

TEST(DecoupledModel, RecoversInertiaGravityAndFrictionOfEachJoint) {
  const Model m = plant_model();
  const Eigen::Vector2d pose(0.3, 0.7);
  for (int joint : {0, 1}) {
    for (unsigned seed : {1u, 2u}) {
      SCOPED_TRACE("joint " + std::to_string(joint + 1) + ", seed " + std::to_string(seed));
      const ProcessedRecord p = run(m, joint, pose, seed);
      const DecoupledJointResult r = fit_decoupled_joint({p}, joint);
      // Truth: M_JJ at the held pose (it does not depend on q_J), gravity a, b, friction.
      Workspace ws(m);
      Eigen::MatrixXd M(2, 2);
      mass_matrix(m, ws, pose, M);
      RneaOptions g;
      g.joint_terms = false;
      Eigen::VectorXd q = pose;
      q[joint] = kPi / 2;
      const double a = rnea(m, q, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), g)[joint];
      q[joint] = 0.0;
      const double b = rnea(m, q, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), g)[joint];
      const JointFriction& f = m.joints[joint].friction;
      const Eigen::VectorXd truth =
          (Eigen::VectorXd(7) << M(joint, joint), a, b, f.Fv, f.Fv, f.Fc + f.Fo, f.Fc - f.Fo)
              .finished();
      for (int i = 0; i < 7; ++i) {
        EXPECT_LE(r.estimate.ci_lower[i], truth[i]) << r.names[i] << " = " << r.estimate.x[i];
        EXPECT_GE(r.estimate.ci_upper[i], truth[i]) << r.names[i] << " = " << r.estimate.x[i];
      }
      EXPECT_LT(r.estimate.ci_upper[0] - r.estimate.x[0], 0.1 * truth[0]);  // informative
      // The coupling the result reports equals the model's: RMS of the other joint's torque
      // variation over joint J's, on the same processed samples, from RNEA's rigid body, the
      // armatures and the moving joint's friction (the held joint's Coulomb term is ~0 in the
      // plant at its jitter speeds, and its offset is constant).
      Eigen::MatrixXd tau(p.record.t.size(), 2);
      for (Eigen::Index k = 0; k < p.record.t.size(); ++k) {
        const Eigen::Vector2d qk = p.record.q.row(k), dqk = p.record.dq.row(k),
                              ddqk = p.record.ddq.row(k);
        Eigen::Vector2d t = rnea(m, qk, dqk, ddqk, g);
        for (int i = 0; i < 2; ++i) t[i] += m.joints[i].friction.Ia * ddqk[i];
        t[joint] += f.Fv * dqk[joint] + f.Fc * (dqk[joint] > 0 ? 1.0 : -1.0);
        tau.row(k) = t.transpose();
      }
      const Eigen::MatrixXd centred = tau.rowwise() - tau.colwise().mean();
      const int other = 1 - joint;
      const double expected = centred.col(other).norm() / centred.col(joint).norm();
      EXPECT_NEAR(r.coupling_ratio[other], expected, 0.1 * expected);
      EXPECT_EQ(r.coupling_ratio[joint], 0.0);
    }
  }
}

TEST(DecoupledModel, SaysWhenTheHeldJointMoves) {
  const Model m = plant_model();
  const DecoupledJointResult r = fit_decoupled_joint({run(m, 0, {0.3, 0.7}, 1, 1)}, 0);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings.front().find("joint 2 moved"), std::string::npos) << r.warnings.front();
  EXPECT_GT(r.held_span[1], 0.1);
}

TEST(DecoupledModel, NoMotionOfTheJointIsRefused) {
  const Model m = plant_model();
  const ProcessedRecord p = run(m, 0, {0.3, 0.7}, 1);
  try {
    fit_decoupled_joint({p}, 1);
    FAIL() << "a held joint was fitted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not move"), std::string::npos) << e.what();
  }
  EXPECT_THROW(fit_decoupled_joint({p}, 5), UsageError);
}

}  // namespace
}  // namespace dynid
