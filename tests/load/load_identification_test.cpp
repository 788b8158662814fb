// Load identification (seed 1 §III, eqs. 19–31): sensor kinematics against finite differences of
// the forward kinematics, and recovery of a known load from wrenches computed by the recursive
// Newton–Euler algorithm of a robot carrying the load on an extra link (not from K).
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/load/load_identification.hpp"
#include "dynid/model/robots.hpp"
#include "support/estimation_support.hpp"
#include "support/load_rig.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using namespace load_rig;

using estimation_testing::expect_error;

// The sensor frame's pose in the base frame, from forward kinematics alone.
void sensor_pose(const Rig& rig, const Eigen::VectorXd& q, Eigen::Matrix3d& R, Eigen::Vector3d& p) {
  Workspace ws(rig.robot);
  forward_kinematics(rig.robot, ws, q);
  const LinkState& s = ws.links[rig.mount.link];
  R = s.R_WJ * rig.mount.R_LS;
  p = s.p_WJ + s.R_WJ * rig.mount.p_LS;
}

TEST(LoadKinematics, SensorMotionMatchesFiniteDifferencesOfThePose) {
  const Rig rig = random_rig(table_one_load(), 3);
  const double h = 1e-4;
  for (const double t : {0.1, 0.77, 1.9}) {
    JointRecord record;
    Eigen::VectorXd q, dq, ddq;
    trajectory(t, q, dq, ddq);
    record.t = Eigen::VectorXd::Constant(1, t);
    record.q = q.transpose();
    record.dq = dq.transpose();
    record.ddq = ddq.transpose();
    const SensorMotion motion = sensor_motion_from_joints(rig.robot, record, rig.mount);
    // Pose at t-2h..t+2h; derivatives by fourth-order central differences.
    Eigen::Matrix3d R[5];
    Eigen::Vector3d p[5];
    for (int i = 0; i < 5; ++i) {
      trajectory(t + (i - 2) * h, q, dq, ddq);
      sensor_pose(rig, q, R[i], p[i]);
    }
    const Eigen::Matrix3d dR = (R[0] - 8.0 * R[1] + 8.0 * R[3] - R[4]) / (12.0 * h);
    const Eigen::Vector3d dp = (p[0] - 8.0 * p[1] + 8.0 * p[3] - p[4]) / (12.0 * h);
    const Eigen::Vector3d ddp =
        (-p[0] + 16.0 * p[1] - 30.0 * p[2] + 16.0 * p[3] - p[4]) / (12.0 * h * h);
    const Eigen::Matrix3d W = R[2].transpose() * dR;  // [ω_S×]
    const Eigen::Vector3d w(W(2, 1), W(0, 2), W(1, 0));
    EXPECT_LT((motion.w.row(0).transpose() - w).norm(), 1e-8 * (1.0 + w.norm()));
    EXPECT_LT((motion.v.row(0).transpose() - R[2].transpose() * dp).norm(), 1e-8);
    EXPECT_LT((motion.a.row(0).transpose() - R[2].transpose() * ddp).norm(), 1e-5);
    EXPECT_LT((motion.g.row(0).transpose() - R[2].transpose() * rig.robot.gravity).norm(), 1e-12);
    // ω̇ in S: derivative of R·ω_S's world vector, brought back to S.
    Eigen::Vector3d w_world[5];
    for (int i = 0; i < 5; ++i) {
      JointRecord r1;
      trajectory(t + (i - 2) * h, q, dq, ddq);
      r1.t = Eigen::VectorXd::Constant(1, t);
      r1.q = q.transpose();
      r1.dq = dq.transpose();
      r1.ddq = ddq.transpose();
      w_world[i] = R[i] * sensor_motion_from_joints(rig.robot, r1, rig.mount).w.row(0).transpose();
    }
    const Eigen::Vector3d dw_world =
        (w_world[0] - 8.0 * w_world[1] + 8.0 * w_world[3] - w_world[4]) / (12.0 * h);
    EXPECT_LT((motion.dw.row(0).transpose() - R[2].transpose() * dw_world).norm(), 1e-7);
  }
}

TEST(LoadKinematics, QuaternionLogGivesTheJointKinematicsMotion) {
  const Rig rig = random_rig(table_one_load(), 4);
  const LoadRun run = simulate(rig, 1.0, 2000.0);
  const SensorMotion ref = sensor_motion_from_joints(rig.robot, run.record, rig.mount);
  OrientationLog log;
  log.t = run.record.t;
  log.quaternion.resize(run.record.t.size(), 4);
  for (Eigen::Index k = 0; k < log.t.size(); ++k) {
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    sensor_pose(rig, run.record.q.row(k).transpose(), R, p);
    Eigen::Quaterniond qk(R);
    if (k % 2) qk.coeffs() *= -1.0;  // the sign of a logged quaternion may flip between rows
    log.quaternion.row(k) = qk.coeffs().transpose();  // Eigen's coeffs() are x y z w
  }
  std::vector<std::pair<std::string, std::string>> choices;
  const SensorMotion motion = sensor_motion_from_orientation(log, rig.robot.gravity, choices);
  EXPECT_LT((motion.g - ref.g).cwiseAbs().maxCoeff(), 1e-12);
  // Central differences at 2 kHz: O(h²) error, far inside the test's bound; ends one-sided.
  const Eigen::Index m = log.t.size();
  EXPECT_LT((motion.w - ref.w).middleRows(2, m - 4).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT((motion.dw - ref.dw).middleRows(4, m - 8).cwiseAbs().maxCoeff(), 1e-2);
  EXPECT_GT(ref.dw.cwiseAbs().maxCoeff(), 1.0);
}

TEST(LoadKinematics, NonUnitQuaternionIsAnError) {
  OrientationLog log;
  log.quaternion = Eigen::MatrixXd::Zero(3, 4);
  log.quaternion.col(3).setOnes();
  log.quaternion(1, 3) = 1.2;
  std::vector<std::pair<std::string, std::string>> choices;
  expect_error(
      [&] {
        sensor_motion_from_orientation(log, {0, 0, -9.81}, choices);
      },
      {"row 2", "norm", "not 1"});
}

LoadIdentificationResult identify(const Rig& rig, const LoadRun& run,
                                  const LoadEquationOptions& equations,
                                  LoadEstimator estimator = LoadEstimator::kOls) {
  const SensorMotion motion = sensor_motion_from_joints(rig.robot, run.record, rig.mount);
  LoadIdentificationOptions options;
  options.estimator = estimator;
  return identify_load(load_equations(motion, run.reading, equations), options);
}

TEST(LoadIdentification, DifferentialModelRecoversTheLoadWithoutNoise) {
  const Eigen::VectorXd phi = table_one_load();
  const Rig rig = random_rig(phi, 5);
  const LoadRun run = simulate(rig, 2.0, 200.0);
  const LoadIdentificationResult r = identify(rig, run, {});
  ASSERT_EQ(r.estimate.x.size(), 10);
  EXPECT_LT((r.estimate.x - phi).norm() / phi.norm(), 1e-8);
  EXPECT_TRUE(r.physics.consistent) << r.physics.violated;
  EXPECT_NEAR(r.physics.mass, 1.910, 1e-8);
  EXPECT_TRUE(r.not_excited.empty());
}

TEST(LoadIdentification, SeedOneSignConventionIsTheNegativeReading) {
  const Eigen::VectorXd phi = table_one_load();
  const Rig rig = random_rig(phi, 6);
  LoadRun run = simulate(rig, 2.0, 200.0);
  run.reading *= -1.0;  // logged as the force on the load (seed 1's F, N)
  LoadEquationOptions options;
  expect_error([&] { identify(rig, run, options); }, {"--wrench-sign -1"});
  options.wrench_sign = -1.0;
  EXPECT_LT((identify(rig, run, options).estimate.x - phi).norm() / phi.norm(), 1e-8);
}

TEST(LoadIdentification, IntegralModelRecoversTheLoadWithoutAccelerations) {
  const Eigen::VectorXd phi = table_one_load();
  const Rig rig = random_rig(phi, 7);
  LoadRun run = simulate(rig, 3.0, 1000.0);
  SensorMotion motion = sensor_motion_from_joints(rig.robot, run.record, rig.mount);
  motion.dw.setConstant(std::nan(""));  // eqs. 29–31 must not read accelerations
  motion.a.setConstant(std::nan(""));
  LoadEquationOptions options;
  options.model = LoadModelKind::kIntegral;
  options.interval = 0.1;
  const EquationBlock block = load_equations(motion, run.reading, options);
  EXPECT_EQ(block.W.rows(), 6 * 30);
  const LoadIdentificationResult r = identify_load(block, {});
  // The trapezoidal rule at 1 kHz integrates K and W to O(h²); both sides see the same rule.
  EXPECT_LT((r.estimate.x - phi).norm() / phi.norm(), 1e-5);
}

TEST(LoadIdentification, BiasesAreRecoveredWithTheLoad) {
  const Eigen::VectorXd phi = table_one_load();
  const Rig rig = random_rig(phi, 8);
  LoadRun run = simulate(rig, 2.0, 1000.0);
  Eigen::Matrix<double, 1, 6> bias;
  bias << 1.5, -0.7, 3.2, 0.05, -0.12, 0.02;
  run.reading.rowwise() += bias;
  for (const LoadModelKind model : {LoadModelKind::kDifferential, LoadModelKind::kIntegral}) {
    LoadEquationOptions options;
    options.bias = true;
    options.model = model;
    const LoadIdentificationResult r = identify(rig, run, options);
    ASSERT_EQ(r.estimate.x.size(), 16);
    EXPECT_EQ(r.names[10], "fx0");
    const double tol = model == LoadModelKind::kIntegral ? 1e-4 : 1e-8;
    EXPECT_LT((r.estimate.x.head(10) - phi).norm() / phi.norm(), tol);
    EXPECT_LT((r.estimate.x.tail(6) - bias.transpose()).norm() / bias.norm(), tol);
  }
}

// Truth inside the 99.9 % Student-t intervals at fixed seeds, with the JR3-like noise of a
// wrist sensor; WLS because force and moment channels have different noise.
TEST(LoadIdentification, NoisyWrenchCoverageAtFixedSeeds) {
  const Eigen::VectorXd phi = table_one_load();
  int outside = 0, total = 0;
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Rig rig = random_rig(phi, 20 + seed);
    LoadRun run = simulate(rig, 2.0, 250.0);
    add_noise(run.reading, 100 + seed, 0.05, 0.003);
    for (const LoadModelKind model : {LoadModelKind::kDifferential, LoadModelKind::kIntegral}) {
      LoadEquationOptions options;
      options.model = model;
      options.interval = 0.04;
      const LoadIdentificationResult r = identify(rig, run, options, LoadEstimator::kWls);
      for (int j = 0; j < 10; ++j) {
        ++total;
        if (phi(j) < r.estimate.ci_lower(j) || phi(j) > r.estimate.ci_upper(j)) ++outside;
      }
      EXPECT_NEAR(r.estimate.x(0), phi(0), 0.02) << "seed " << seed;
    }
  }
  // 200 intervals at 99.9 %: 0.2 expected outside; 2 or more would have probability < 2 %.
  EXPECT_LE(outside, 1) << outside << " of " << total;
}

// The CLI's joint-data path: q only, identify's filtering and differentiation, the wrench filtered
// alike, HAC intervals (the filter correlates neighbouring residuals).
TEST(LoadIdentification, FilteredJointDataCoverageAtFixedSeeds) {
  const Eigen::VectorXd phi = table_one_load();
  int outside = 0, outside_white = 0, total = 0;
  for (unsigned seed = 0; seed < 6; ++seed) {
    const Rig rig = random_rig(phi, 40 + seed);
    LoadRun run = simulate(rig, 3.0, 500.0);
    add_noise(run.reading, 200 + seed, 0.05, 0.003);
    JointRecord record;
    record.t = run.record.t;
    record.q = run.record.q;
    std::vector<std::pair<std::string, std::string>> choices;
    const PreparedLoadRun prepared = prepare_load_run(record, run.reading, {}, choices);
    ASSERT_EQ(prepared.wrench.rows(), prepared.record.t.size());
    ASSERT_LT(prepared.record.t.size(), record.t.size());  // filter edges trimmed
    const SensorMotion motion = sensor_motion_from_joints(rig.robot, prepared.record, rig.mount);
    LoadIdentificationOptions options;
    options.estimator = LoadEstimator::kWls;
    options.hac_covariance = true;
    const LoadIdentificationResult r =
        identify_load(load_equations(motion, prepared.wrench, {}), options);
    EXPECT_NE(r.estimate.covariance_kind, "white");
    for (int j = 0; j < 10; ++j) {
      ++total;
      outside += phi(j) < r.estimate.ci_lower(j) || phi(j) > r.estimate.ci_upper(j);
      outside_white +=
          phi(j) < r.estimate.ci_lower_white(j) || phi(j) > r.estimate.ci_upper_white(j);
    }
  }
  // 60 intervals at 99.9 %: 0.06 expected outside.
  EXPECT_LE(outside, 1) << outside << " of " << total << " (white: " << outside_white << ")";
}

TEST(LoadIdentification, RecursiveLeastSquaresAgreesWithBatch) {
  const Eigen::VectorXd phi = table_one_load();
  const Rig rig = random_rig(phi, 9);
  LoadRun run = simulate(rig, 2.0, 200.0);
  add_noise(run.reading, 9, 0.05, 0.003);
  const SensorMotion motion = sensor_motion_from_joints(rig.robot, run.record, rig.mount);
  const EquationBlock block = load_equations(motion, run.reading, {});
  LoadIdentificationOptions rls;
  rls.estimator = LoadEstimator::kRls;
  rls.record_history = true;
  const LoadIdentificationResult a = identify_load(block, {}), b = identify_load(block, rls);
  EXPECT_LT((a.estimate.x - b.estimate.x).norm() / a.estimate.x.norm(), 1e-6);
  EXPECT_EQ(b.history.rows(), block.W.rows());
  EXPECT_EQ(b.history.cols(), 10);
}

OrientationLog standing_poses(int count, unsigned seed) {
  std::mt19937 rng(seed);
  OrientationLog log;
  log.quaternion.resize(count, 4);
  for (int k = 0; k < count; ++k) {
    log.quaternion.row(k) = Eigen::Quaterniond(Eigen::Vector4d(testing::random_vector(4, rng)))
                                .normalized()
                                .coeffs()
                                .transpose();
  }
  return log;
}

// Standing poses: the wrench of a load at rest, computed directly (F = −m g_S, N = c × F).
Eigen::MatrixXd standing_reading(const Eigen::VectorXd& phi, const SensorMotion& motion) {
  Eigen::MatrixXd reading(motion.g.rows(), 6);
  const Eigen::Vector3d c = phi.segment<3>(1) / phi(0);
  for (Eigen::Index k = 0; k < reading.rows(); ++k) {
    const Eigen::Vector3d on_sensor = phi(0) * motion.g.row(k).transpose();
    reading.row(k) << on_sensor.transpose(), c.cross(on_sensor).transpose();
  }
  return reading;
}

TEST(LoadIdentification, StaticPosesRecoverMassCentreOfMassAndBiases) {
  const Eigen::VectorXd phi = table_one_load();
  std::vector<std::pair<std::string, std::string>> choices;
  const SensorMotion motion =
      sensor_motion_from_orientation(standing_poses(12, 1), {0, 0, -9.81}, choices);
  Eigen::MatrixXd reading = standing_reading(phi, motion);
  Eigen::Matrix<double, 1, 6> bias;
  bias << -2.0, 0.4, 1.1, 0.03, 0.01, -0.02;
  reading.rowwise() += bias;
  add_noise(reading, 11, 0.05, 0.003);
  LoadEquationOptions options;
  options.model = LoadModelKind::kStatic;
  options.bias = true;
  const LoadIdentificationResult r =
      identify_load(load_equations(motion, reading, options), {LoadEstimator::kWls});
  ASSERT_EQ(r.names.size(), 10u);
  EXPECT_EQ(r.names[4], "fx0");
  Eigen::VectorXd truth(10);
  truth << phi.head(4), bias.transpose();
  for (int j = 0; j < 10; ++j) {
    EXPECT_GE(truth(j), r.estimate.ci_lower(j)) << r.names[j];
    EXPECT_LE(truth(j), r.estimate.ci_upper(j)) << r.names[j];
  }
  EXPECT_TRUE(r.physics.consistent);
  EXPECT_LT((r.physics.com - phi.segment<3>(1) / phi(0)).norm(), 2e-3);
  // Standing poses do not excite the inertias: named, not estimated (issue 25 item 8).
  EXPECT_EQ(r.not_excited, (std::vector<std::string>{"Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz"}));
}

TEST(LoadIdentification, IdenticalStandingPosesAreAnError) {
  const Eigen::VectorXd phi = table_one_load();
  OrientationLog log = standing_poses(1, 2);
  log.quaternion = log.quaternion.replicate(8, 1).eval();
  std::vector<std::pair<std::string, std::string>> choices;
  const SensorMotion motion = sensor_motion_from_orientation(log, {0, 0, -9.81}, choices);
  Eigen::MatrixXd reading = standing_reading(phi, motion);
  add_noise(reading, 12, 0.05, 0.003);
  LoadEquationOptions options;
  options.model = LoadModelKind::kStatic;
  options.bias = true;
  const EquationBlock block = load_equations(motion, reading, options);
  expect_error([&] { identify_load(block, {}); }, {"orientations", "fz0"});
}

TEST(LoadIdentification, SlowMotionLeavesTheInertiasNotExcited) {
  const Eigen::VectorXd phi = table_one_load();
  Rig rig = random_rig(phi, 13);
  // The same path twenty times slower: gravity dominates, inertial forces vanish in the noise.
  const Motion slow = [](double t, Eigen::VectorXd& q, Eigen::VectorXd& dq, Eigen::VectorXd& ddq) {
    trajectory(t / 20.0, q, dq, ddq);
    dq /= 20.0;
    ddq /= 400.0;
  };
  LoadRun run = simulate(rig, 40.0, 10.0, 0.0, slow);
  add_noise(run.reading, 13, 0.05, 0.003);
  const LoadIdentificationResult r = identify(rig, run, {}, LoadEstimator::kWls);
  EXPECT_EQ(r.not_excited, (std::vector<std::string>{"Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz"}));
  EXPECT_NEAR(r.estimate.x(0), phi(0), 0.01);
}

// Seed 1 §VI-B: the load from a subset of the six scalar equations. The sensor reading is the
// Newton–Euler wrench of the loaded robot's last body (load_rig), not eq. 28's K·Φ. Forces carry
// m and mc, moments mc and the inertias: each subset recovers what it carries inside its 99.9 %
// intervals and names the rest not excited, without an error.
TEST(LoadIdentification, ForceOrMomentEquationsAloneGiveWhatTheyCarry) {
  const Eigen::VectorXd phi = table_one_load();
  const Rig rig = random_rig(phi, 9);
  LoadRun run = simulate(rig, 2.0, 250.0);
  add_noise(run.reading, 9, 0.05, 0.003);
  const auto inside = [&](const LoadIdentificationResult& r, int j) {
    return r.estimate.ci_lower(j) <= phi(j) && phi(j) <= r.estimate.ci_upper(j);
  };
  LoadEquationOptions forces;
  forces.components = {true, true, true, false, false, false};
  const LoadIdentificationResult f = identify(rig, run, forces, LoadEstimator::kWls);
  EXPECT_EQ(f.estimate.summary.rows, 3 * run.reading.rows());
  for (int j = 0; j < 4; ++j) EXPECT_TRUE(inside(f, j)) << j;
  EXPECT_EQ(f.not_excited, (std::vector<std::string>{"Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz"}));
  EXPECT_TRUE(f.physics.consistent) << f.physics.violated;  // m > 0 is all the forces can show

  LoadEquationOptions moments;
  moments.components = {false, false, false, true, true, true};
  const LoadIdentificationResult n = identify(rig, run, moments, LoadEstimator::kWls);
  EXPECT_EQ(n.not_excited, (std::vector<std::string>{"m"}));
  for (int j = 1; j < 10; ++j) EXPECT_TRUE(inside(n, j)) << j;
  EXPECT_FALSE(n.physics.consistent);
  EXPECT_NE(n.physics.violated.find("not determined"), std::string::npos) << n.physics.violated;

  // Offsets only for the chosen components: fx0 fy0 fz0 beside m, mc.
  forces.bias = true;
  EXPECT_EQ(load_parameter_names(forces),
            (std::vector<std::string>{"m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Ixz", "Iyy", "Iyz",
                                      "Izz", "fx0", "fy0", "fz0"}));
  EXPECT_EQ(load_components_from_text("mz,fx", "--components"),
            (std::array<bool, 6>{true, false, false, false, false, true}));
  expect_error([] { load_components_from_text("fx,fq", "--components"); },
               {"--components", "'fq'", "fx, fy, fz, mx, my, mz"});
  expect_error([] { load_components_from_text("fx,fx", "--components"); }, {"twice"});
  expect_error([] { load_components_from_text("", "--components"); }, {"--components"});
}

// Seed 1 §VI-B: "as a consequence of integration, large errors coming from cumulated
// low-frequency measurement disturbances" — the integral model improved on a subset of eq. 29's
// scalar equations. A strain-gauge moment drift (0.004 N·m/s on mx, my, mz, as temperature gives)
// enters every moment row of ∫W dt; the force rows do not see it, so on the forces alone the mass
// and centre of mass stay unbiased while on all six the drift biases what the moments carry.
TEST(LoadIdentification, IntegralForcesAloneEscapeAMomentDrift) {
  const Eigen::VectorXd phi = table_one_load();
  const Rig rig = random_rig(phi, 11);
  LoadRun run = simulate(rig, 3.0, 500.0);
  add_noise(run.reading, 11, 0.05, 0.003);
  for (Eigen::Index k = 0; k < run.reading.rows(); ++k) {
    run.reading.row(k).tail<3>().array() += 0.004 * run.record.t(k);
  }
  LoadEquationOptions all;
  all.model = LoadModelKind::kIntegral;
  all.interval = 0.05;
  LoadEquationOptions forces = all;
  forces.components = {true, true, true, false, false, false};
  const LoadIdentificationResult a = identify(rig, run, all, LoadEstimator::kWls);
  const LoadIdentificationResult f = identify(rig, run, forces, LoadEstimator::kWls);
  const auto inside = [&](const LoadIdentificationResult& r, int j) {
    return r.estimate.ci_lower(j) <= phi(j) && phi(j) <= r.estimate.ci_upper(j);
  };
  // Where the drift lands depends on the motion: on gcc's random arm all six equations put mcx at
  // +8.7 σ, mcy at −10.3 σ and Ixx, Iyz, Izz beyond 3.6 σ; on clang's (its arguments are drawn in
  // another order) Ixy, Ixz and Izz at 3.5–4 σ. Some estimate leaves its 99.9 % interval either
  // way; on the forces alone m and mc stay within 1.3 σ on both.
  int outside = 0;
  for (int j = 0; j < 10; ++j) outside += !inside(a, j);
  EXPECT_GT(outside, 0) << a.estimate.x.transpose();
  for (int j = 0; j < 4; ++j) EXPECT_TRUE(inside(f, j)) << j << ": " << f.estimate.x(j);
}

TEST(LoadIdentification, PhysicalConsistencyNamesTheViolatedCondition) {
  Eigen::VectorXd phi = table_one_load();
  EXPECT_TRUE(load_physics(phi, true).consistent);
  Eigen::VectorXd table_one(10);  // seed 1 Table I, computed values
  table_one << 1.910, 0.0573, -0.0210, 0.1394, 0.01050, 0.00094, -0.00450, 0.01635, 0.00169,
      0.00520;
  EXPECT_NE(load_physics(table_one, true).violated.find("triangle"), std::string::npos);
  // I_C of the computed load, then a principal moment above the sum of the other two.
  const LoadPhysics good = load_physics(phi, true);
  EXPECT_NEAR(good.com.z(), 0.1394 / 1.910, 1e-15);
  Eigen::VectorXd bad = phi;
  bad(4) += 0.05;  // Ixx far above Iyy + Izz about the centre of mass
  const LoadPhysics b = load_physics(bad, true);
  EXPECT_FALSE(b.consistent);
  EXPECT_NE(b.violated.find("triangle"), std::string::npos) << b.violated;
  bad = phi;
  bad(9) = 0.0;  // Izz about the CoM then negative
  EXPECT_NE(load_physics(bad, true).violated.find("positive definite"), std::string::npos);
  bad = phi;
  bad(0) = -1.0;
  EXPECT_NE(load_physics(bad, true).violated.find("mass not positive"), std::string::npos);
}

// Load from joint torques (no sensor): a loaded and an unloaded run of the puma560 over different
// stretches of the motion, torques by RNEA of the robot with and without the load link.
TEST(LoadFromTorques, RobotAndLoadTogetherRecoverWhatTheTorquesDetermine) {
  const Eigen::VectorXd phi = table_one_load();
  SensorMount flange;
  flange.link = kJoints - 1;
  flange.p_LS = Eigen::Vector3d(0.0, 0.0, 0.05);
  flange.R_LS = roll_pitch_yaw(0.0, 0.0, 0.4);
  const Model puma = load_robot("puma560");
  const Rig loaded = make_rig(puma, phi, flange);
  const Rig unloaded = make_rig(puma, Eigen::VectorXd::Zero(10), flange);
  const LoadRun a = simulate(loaded, 4.0, 100.0), b = simulate(unloaded, 4.0, 100.0, 7.0);
  LoadFrame frame;  // the load's parameters at the flange frame (the sensor pose of the rig)
  frame.R_LF = flange.R_LS;
  frame.p_LF = flange.p_LS;
  const LoadIdentificationResult r = identify_load_from_torques(
      puma, kJoints - 1, frame, ParameterLayout::rigid(), a.record, b.record, {});
  ASSERT_EQ(r.names.size(), 10u);
  // On the last link all ten are determined: the parameters it shares with link 5 in the
  // regrouped base set (its mass, MZ6, YY6) are pinned by the unloaded run, so their change is
  // the load's.
  EXPECT_TRUE(r.not_excited.empty());
  EXPECT_LT((r.estimate.x - phi).norm() / phi.norm(), 1e-8);
  EXPECT_TRUE(r.physics.consistent) << r.physics.violated;
  // On link 1, which only turns about the vertical axis, the torques see the load's inertia
  // about that axis and nothing else: the other nine are listed and get no finite σ.
  const Rig base_loaded = make_rig(puma, phi, [] {
    SensorMount m;
    m.link = 0;
    return m;
  }());
  const Rig base_unloaded = make_rig(puma, Eigen::VectorXd::Zero(10), base_loaded.mount);
  const LoadRun c = simulate(base_loaded, 4.0, 100.0), d = simulate(base_unloaded, 4.0, 100.0, 7.0);
  const LoadIdentificationResult r1 =
      identify_load_from_torques(puma, 0, {}, ParameterLayout::rigid(), c.record, d.record, {});
  EXPECT_EQ(r1.not_excited, (std::vector<std::string>{"m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Ixz",
                                                      "Iyy", "Iyz"}));
  EXPECT_NEAR(r1.estimate.x(9), phi(9), 1e-8);
  EXPECT_TRUE(std::isinf(r1.estimate.std_dev(0)));
  EXPECT_FALSE(r1.physics.consistent);
}

TEST(LoadFromTorques, LoadOnAnInnerLinkIsFullyDeterminedWithNoise) {
  const Eigen::VectorXd phi = table_one_load();
  SensorMount mount;
  mount.link = 2;  // on the forearm of the puma560
  mount.p_LS = Eigen::Vector3d(0.1, 0.02, 0.0);
  const Model puma = load_robot("puma560");
  const Rig loaded = make_rig(puma, phi, mount);
  const Rig unloaded = make_rig(puma, Eigen::VectorXd::Zero(10), mount);
  LoadRun a = simulate(loaded, 6.0, 100.0), b = simulate(unloaded, 6.0, 100.0, 9.0);
  add_noise(a.record.tau, 1, 0.02, 0.02);
  add_noise(b.record.tau, 2, 0.02, 0.02);
  LoadFrame frame;
  frame.p_LF = mount.p_LS;
  LoadIdentificationOptions options;
  options.estimator = LoadEstimator::kWls;
  const LoadIdentificationResult r = identify_load_from_torques(
      puma, 2, frame, ParameterLayout::rigid(), a.record, b.record, options);
  for (int j = 0; j < 10; ++j) {
    if (std::find(r.not_excited.begin(), r.not_excited.end(), r.names[j]) != r.not_excited.end()) {
      continue;
    }
    EXPECT_GE(phi(j), r.estimate.ci_lower(j)) << r.names[j];
    EXPECT_LE(phi(j), r.estimate.ci_upper(j)) << r.names[j];
  }
  EXPECT_EQ(std::find(r.not_excited.begin(), r.not_excited.end(), "m"), r.not_excited.end());
}

// Load from the torque a model of the unloaded robot does not explain (a `dynid identify` result
// as reference): the prediction here is the true unloaded robot's RNEA, the loaded torques RNEA
// of the robot with the load link; on the puma560 flange all ten are determined, also on link 1
// only Izz (its rows see nothing else), and with noise the truth lies inside the intervals.
TEST(LoadFromTorques, UnexplainedTorqueOfAReferenceModelGivesTheLoad) {
  const Eigen::VectorXd phi = table_one_load();
  const Model puma = load_robot("puma560");
  RneaOptions rigid;
  rigid.joint_terms = false;
  const auto prediction = [&](const JointRecord& record) {
    Eigen::MatrixXd tau(record.q.rows(), puma.dof());
    for (Eigen::Index k = 0; k < record.q.rows(); ++k) {
      tau.row(k) = rnea(puma, record.q.row(k).transpose(), record.dq.row(k).transpose(),
                        record.ddq.row(k).transpose(), rigid)
                       .transpose();
    }
    return tau;
  };
  SensorMount flange;
  flange.link = kJoints - 1;
  flange.p_LS = Eigen::Vector3d(0.0, 0.0, 0.05);
  flange.R_LS = roll_pitch_yaw(0.0, 0.0, 0.4);
  LoadFrame frame;
  frame.R_LF = flange.R_LS;
  frame.p_LF = flange.p_LS;
  LoadRun a = simulate(make_rig(puma, phi, flange), 4.0, 100.0);
  const LoadIdentificationResult r = identify_load_from_unexplained_torques(
      puma, kJoints - 1, frame, a.record, prediction(a.record), Eigen::VectorXd(), {});
  EXPECT_TRUE(r.not_excited.empty());
  EXPECT_LT((r.estimate.x - phi).norm() / phi.norm(), 1e-8);
  EXPECT_TRUE(r.physics.consistent) << r.physics.violated;
  SensorMount base;
  base.link = 0;
  const LoadRun c = simulate(make_rig(puma, phi, base), 4.0, 100.0);
  const LoadIdentificationResult r1 = identify_load_from_unexplained_torques(
      puma, 0, {}, c.record, prediction(c.record), Eigen::VectorXd(), {});
  EXPECT_EQ(r1.not_excited, (std::vector<std::string>{"m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Ixz",
                                                      "Iyy", "Iyz"}));
  EXPECT_NEAR(r1.estimate.x(9), phi(9), 1e-8);
  // Noise on the loaded torques; rows of joints below a (large) velocity threshold left out.
  add_noise(a.record.tau, 3, 0.02, 0.02);
  LoadIdentificationOptions options;
  options.estimator = LoadEstimator::kWls;
  const Eigen::VectorXd threshold = Eigen::VectorXd::Constant(kJoints, 0.05);
  const LoadIdentificationResult rn = identify_load_from_unexplained_torques(
      puma, kJoints - 1, frame, a.record, prediction(a.record), threshold, options);
  for (int j = 0; j < 10; ++j) {
    EXPECT_GE(phi(j), rn.estimate.ci_lower(j)) << rn.names[j];
    EXPECT_LE(phi(j), rn.estimate.ci_upper(j)) << rn.names[j];
  }
  EXPECT_THROW(identify_load_from_unexplained_torques(puma, 6, frame, a.record,
                                                      prediction(a.record), threshold, options),
               Error);
  EXPECT_THROW(identify_load_from_unexplained_torques(
                   puma, 5, frame, a.record, prediction(a.record).topRows(3), threshold, options),
               Error);
}

TEST(LoadIdentification, BadInputErrors) {
  const Rig rig = random_rig(table_one_load(), 14);
  LoadRun run = simulate(rig, 1.0, 100.0);
  const SensorMotion motion = sensor_motion_from_joints(rig.robot, run.record, rig.mount);
  expect_error([&] { load_equations(motion, run.reading.leftCols(5), {}); }, {"fx fy fz mx my mz"});
  LoadEquationOptions integral;
  integral.model = LoadModelKind::kIntegral;
  integral.interval = 1e-4;
  expect_error([&] { load_equations(motion, run.reading, integral); }, {"--interval", "step"});
  integral.interval = 0.6;
  expect_error([&] { load_equations(motion, run.reading, integral); }, {"too few"});
  LoadRun empty = run;
  empty.reading.setZero();
  add_noise(empty.reading, 1, 0.05, 0.003);
  expect_error([&] { identify(rig, empty, {}); }, {"no load"});
  expect_error([&] { find_link(rig.robot, "tool0"); }, {"'tool0'", "l6"});
}

}  // namespace
}  // namespace dynid
