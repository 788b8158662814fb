// simulate must fail with a clear error instead of writing ±inf or a run gone unstable (issue 10:
// `simulate --torque-noise 1e308` wrote ±inf; a corrupt reference drove MuJoCo unstable, its
// warning went to stdout and the run exited 0 with |q| up to 1.6e7 rad). Oracle: the pendulum of
// sim_support.hpp on a sine reference it tracks; the faults are injected at known samples.

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "dynid/sim/simulate_reference.hpp"
#include "sim_support.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

Reference pendulum_reference() {
  // One 2 s period of q = 0.5 sin(π t) − π/2 at 100 Hz.
  return testing::sine_reference(Eigen::VectorXd::Constant(1, 0.5),
                                 Eigen::VectorXd::Constant(1, -M_PI / 2), M_PI, 0.01, 200);
}

SimulateOptions options(PlantEngine engine) {
  SimulateOptions o;
  o.plant.engine = engine;
  o.loop.periods = 2;
  return o;
}

std::string simulate_error(const Reference& ref, const SimulateOptions& o) {
  return testing::error_of(
      [&] { simulate_reference(testing::pendulum(), ref.t, ref.q, ref.dq, ref.ddq, o); });
}

TEST(SimulateDivergence, CleanReferenceRunsWithinItsBand) {
  const Reference ref = pendulum_reference();
  for (PlantEngine engine : {PlantEngine::kNative, PlantEngine::kMujoco}) {
    const ClosedLoopResult r =
        simulate_reference(testing::pendulum(), ref.t, ref.q, ref.dq, ref.ddq, options(engine));
    ASSERT_TRUE(r.q.allFinite());
    EXPECT_LT((r.q - r.qr).cwiseAbs().maxCoeff(), 0.1);
  }
}

TEST(SimulateDivergence, OverflowingTorqueNoiseIsAnError) {
  SimulateOptions o = options(PlantEngine::kNative);
  o.sensors.torque_noise_std = 1e308;
  const std::string e = simulate_error(pendulum_reference(), o);
  EXPECT_NE(e.find("logged torques are not finite (torque noise std 1e+308"), std::string::npos)
      << e;
}

TEST(SimulateDivergence, CorruptReferenceRowIsNamed) {
  Reference ref = pendulum_reference();
  ref.q(50, 0) = 1.6e7;
  const std::string e = simulate_error(ref, options(PlantEngine::kMujoco));
  EXPECT_NE(e.find("reference sample 51: joint j1 at q = 1.6e+07"), std::string::npos) << e;
}

TEST(SimulateDivergence, CorruptFeedForwardDivergesWithAnError) {
  Reference ref = pendulum_reference();
  ref.ddq(50, 0) = 1e12;  // the computed-torque feed-forward saturates at the 1e6 N·m limit
  for (PlantEngine engine : {PlantEngine::kNative, PlantEngine::kMujoco}) {
    const std::string e = simulate_error(ref, options(engine));
    EXPECT_NE(e.find("diverged"), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace dynid
