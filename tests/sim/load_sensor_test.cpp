// `dynid simulate --payload` (issue 12 item 4): a rigid load mounted on the plant behind a wrist
// force/torque sensor. The simulated reading (recursive Newton–Euler with the load as one more
// link) is checked against the load regressor K·Φ of seed 1 eq. 28, a second, independent
// computation, on the motion each plant (native, MuJoCo) actually produced; the MuJoCo plant's
// joint torques check that it carries the load (MuJoCo's own dynamics as the oracle).
#include <algorithm>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/load/load_identification.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/sim/load_sensor.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "sim/sim_support.hpp"
#include "support/load_rig.hpp"

namespace dynid {
namespace {

// A 1.91 kg cuboid-like load with its centre of mass off every sensor axis (about the sensor
// origin, sensor frame): seed 1 Table I's mass and first moments.
MountedLoad table_one_like_load() {
  MountedLoad load;
  load.mount.link = 5;
  load.mount.p_LS = Eigen::Vector3d(0.01, -0.02, 0.05);
  load.mount.R_LS = roll_pitch_yaw(0.3, -0.2, 0.5);
  const double m = 1.910;
  const Eigen::Vector3d c = Eigen::Vector3d(0.0573, -0.0210, 0.1394) / m;
  const Eigen::Matrix3d I_C = Eigen::Vector3d(1.9e-3, 1.9e-3, 8.0e-4).asDiagonal();
  const LinkParams p = link_params_from_com(m, c, I_C);
  load.phi.resize(10);
  load.phi << p(9), p(6), p(7), p(8), p(0), p(1), p(2), p(3), p(4), p(5);
  return load;
}

// The puma560 without friction (so that MuJoCo's joint torques are rigid body plus armature).
Model frictionless_puma() {
  Model model = load_robot("puma560");
  for (Joint& j : model.joints) j.friction.Fv = j.friction.Fc = j.friction.Fo = 0.0;
  return model;
}

ClosedLoopResult loaded_run(const Model& robot, const MountedLoad& load, PlantEngine engine) {
  Eigen::VectorXd a(6), c(6);
  a << 0.8, 0.6, 0.7, 1.2, 1.0, 1.5;
  c << 0.0, -0.3, 0.4, 0.2, 0.5, -0.1;
  const Reference ref = testing::sine_reference(a, c, 2.0 * M_PI / 1.0, 2e-3, 500);
  SimulateOptions s;
  s.plant.engine = engine;
  s.loop.periods = 1;
  s.loop.record_truth = true;
  return simulate_reference(model_with_load(robot, load), ref.t, ref.q, ref.dq, ref.ddq, s);
}

TEST(LoadSensor, SimulatedWrenchEqualsTheLoadRegressorOnBothPlants) {
  const Model robot = frictionless_puma();
  const MountedLoad load = table_one_like_load();
  for (const PlantEngine engine : {PlantEngine::kNative, PlantEngine::kMujoco}) {
    const ClosedLoopResult r = loaded_run(robot, load, engine);
    const Eigen::MatrixXd wrench = load_sensor_wrench(robot, load, r.q_true, r.dq_true, r.ddq_true);
    JointRecord record;
    record.t = r.t;
    record.q = r.q_true;
    record.dq = r.dq_true;
    record.ddq = r.ddq_true;
    const SensorMotion motion = sensor_motion_from_joints(robot, record, load.mount);
    // y = −reading (the sensor's force on the load, seed 1's W), rows = K per sample.
    const EquationBlock block = load_equations(motion, wrench, {});
    const Eigen::VectorXd K_phi = block.W * load.phi;
    ASSERT_EQ(K_phi.size(), 6 * r.t.size());
    EXPECT_LT((K_phi - block.y).cwiseAbs().maxCoeff(), 1e-9 * block.y.cwiseAbs().maxCoeff())
        << (engine == PlantEngine::kMujoco ? "mujoco" : "native");
    // The motion moved the load: gravity and inertial forces both matter.
    EXPECT_GT(block.y.cwiseAbs().maxCoeff(), 10.0);
  }
}

TEST(LoadSensor, MujocoPlantCarriesTheLoad) {
  const Model robot = frictionless_puma();
  const MountedLoad load = table_one_like_load();
  const ClosedLoopResult r = loaded_run(robot, load, PlantEngine::kMujoco);
  // Oracle: RNEA of the robot with the load as a seventh link held at the sensor frame (not the
  // merged link parameters the plant was built from).
  const Model carried = load_rig::make_rig(robot, load.phi, load.mount).loaded;
  const Model unloaded_plant_model = robot;
  double worst = 0.0, load_effect = 0.0;
  for (Eigen::Index k = 0; k < r.t.size(); k += 7) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(7), dq = q, ddq = q;
    q.head(6) = r.q_true.row(k).transpose();
    dq.head(6) = r.dq_true.row(k).transpose();
    ddq.head(6) = r.ddq_true.row(k).transpose();
    const Eigen::VectorXd tau = rnea(carried, q, dq, ddq).head(6);
    const Eigen::VectorXd tau_unloaded =
        rnea(unloaded_plant_model, q.head(6), dq.head(6), ddq.head(6));
    worst = std::max(worst, (tau - r.tau_true.row(k).transpose()).cwiseAbs().maxCoeff());
    load_effect = std::max(load_effect, (tau - tau_unloaded).cwiseAbs().maxCoeff());
  }
  // MuJoCo's floor on massless links (bound_mass 1e-6 kg) is far below this.
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(load_effect, 1.0);
}

TEST(LoadSensor, LoadFileErrorsNameTheKey) {
  const std::string dir = ::testing::TempDir();
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + name) << text;
    return dir + name;
  };
  const std::string good = write("good_load.yaml",
                                 "mass: 1.91\ncom: [0.03, -0.011, 0.073]\n"
                                 "inertia_com: [1.9e-3, 0, 0, 1.9e-3, 0, 8e-4]\n");
  const Eigen::VectorXd phi = read_load_file(good);
  EXPECT_DOUBLE_EQ(phi(0), 1.91);
  EXPECT_NEAR(phi(3), 1.91 * 0.073, 1e-15);
  // Izz about the sensor origin = Izz_C + m(cx² + cy²) (seed 1 eq. 24).
  EXPECT_NEAR(phi(9), 8e-4 + 1.91 * (0.03 * 0.03 + 0.011 * 0.011), 1e-15);
  const auto expect_error = [](const std::string& path, const std::string& part) {
    try {
      read_load_file(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  expect_error(write("zero.yaml", "mass: 0\ncom: [0, 0, 0]\ninertia_com: [1, 0, 0, 1, 0, 1]\n"),
               "must be > 0");
  expect_error(write("tri.yaml", "mass: 1\ncom: [0, 0, 0]\ninertia_com: [1, 0, 0, 1, 0, 3]\n"),
               "not a rigid body");
  expect_error(write("short.yaml", "mass: 1\ncom: [0, 0]\ninertia_com: [1, 0, 0, 1, 0, 1]\n"),
               "'com'");
  expect_error(write("key.yaml", "mass: 1\ncog: [0, 0, 0]\ninertia_com: [1, 0, 0, 1, 0, 1]\n"),
               "'cog'");
  expect_error(dir + "absent.yaml", "cannot read");
  MountedLoad load = table_one_like_load();
  load.mount.link = 6;
  EXPECT_THROW(model_with_load(frictionless_puma(), load), Error);
}

}  // namespace
}  // namespace dynid
