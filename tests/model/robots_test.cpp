#include "dynid/model/robots.hpp"
#include "support/error_of.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kModelsDir;

using dynid::testing::error_of;

std::vector<std::string> joint_names(const Model& m) {
  std::vector<std::string> v;
  for (const auto& j : m.joints) v.push_back(j.name);
  return v;
}

TEST(Robots, BuiltinNamesAreListed) {
  const std::vector<std::string> names = builtin_robot_names();
  for (const char* n : {"iiwa14", "irp6", "planar2", "puma560"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  }
}

TEST(Robots, EveryBuiltinLoadsWithItsDofAndNames) {
  for (const auto& name : builtin_robot_names()) {
    const Model m = load_robot(name);
    EXPECT_EQ(m.name, name);
    EXPECT_GT(m.dof(), 0) << name;
  }
  const Model puma = load_robot("puma560");
  EXPECT_EQ(joint_names(puma),
            (std::vector<std::string>{"joint1", "joint2", "joint3", "joint4", "joint5", "joint6"}));
  EXPECT_EQ(load_robot("planar2").dof(), 2);
  EXPECT_EQ(joint_names(load_robot("planar2")), (std::vector<std::string>{"shoulder", "elbow"}));
  EXPECT_EQ(joint_names(load_robot("irp6")),
            (std::vector<std::string>{"joint1", "joint2", "joint3"}));
  const Model iiwa = load_robot("iiwa14");
  ASSERT_EQ(iiwa.dof(), 7);
  for (int j = 0; j < 7; ++j) {
    EXPECT_EQ(iiwa.joints[j].name, "iiwa_joint_" + std::to_string(j + 1));
    EXPECT_EQ(iiwa.joints[j].parent, j - 1);
    EXPECT_TRUE(std::isfinite(iiwa.joints[j].limits.lower));
    EXPECT_TRUE(std::isfinite(iiwa.joints[j].limits.effort));
    EXPECT_DOUBLE_EQ(iiwa.joints[j].friction.Fv, 0.5);
  }
}

TEST(Robots, PathsAndSourcesAndEnvironmentOverride) {
  const std::string path = std::string(DYNID_SOURCE_DIR) + "/examples/robots/planar2.yaml";
  const Model m = load_robot(path);
  EXPECT_EQ(m.source, path);
  EXPECT_EQ(load_robot("planar2").source, path);

  ASSERT_EQ(setenv("DYNID_ROBOTS_DIR", (kModelsDir + "robots_dir").c_str(), 1), 0);
  EXPECT_EQ(builtin_robot_names(), std::vector<std::string>{"tiny"});
  EXPECT_EQ(load_robot("tiny").dof(), 2);
  const std::string msg = error_of([] { load_robot("puma560"); });
  unsetenv("DYNID_ROBOTS_DIR");
  EXPECT_NE(msg.find("unknown built-in robot 'puma560'; built-in robots are: tiny"),
            std::string::npos)
      << msg;
}

TEST(RobotsErrors, UnknownBuiltinListsNames) {
  const std::string msg = error_of([] { load_robot("puma9000"); });
  EXPECT_NE(msg.find("unknown built-in robot 'puma9000'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("iiwa14, irp6, planar2, puma560"), std::string::npos) << msg;
}

TEST(RobotsErrors, UnsupportedExtensionAndMissingFile) {
  std::string msg = error_of([] { load_robot("robot.sdf"); });
  EXPECT_NE(msg.find("extension '.sdf'"), std::string::npos) << msg;
  msg = error_of([] { load_robot(kModelsDir + "nope.yaml"); });
  EXPECT_NE(msg.find("cannot open robot file '" + kModelsDir + "nope.yaml'"), std::string::npos)
      << msg;
}

// planar2: the link parameters are the closed-form ones stated in docs/methods/model.md.
TEST(BuiltinRobots, Planar2MatchesItsClosedFormParameters) {
  const Model m = load_robot("planar2");
  const double l1 = 1.0, l2 = 0.8, m1 = 2.0, m2 = 1.5;
  // Slender rod about its end, axis perpendicular: m l² / 3; first moment m l / 2.
  EXPECT_NEAR(m.links[0](5), m1 * l1 * l1 / 3.0, 1e-15);  // ZZ1
  EXPECT_NEAR(m.links[0](3), m1 * l1 * l1 / 3.0, 1e-15);  // YY1
  EXPECT_NEAR(m.links[0](0), 0.0, 1e-15);                 // XX1
  EXPECT_NEAR(m.links[0](6), m1 * l1 / 2.0, 1e-15);       // MX1
  EXPECT_NEAR(m.links[1](5), m2 * l2 * l2 / 3.0, 1e-15);  // ZZ2
  EXPECT_NEAR(m.links[1](6), m2 * l2 / 2.0, 1e-15);       // MX2
  EXPECT_DOUBLE_EQ(m.links[1](9), m2);
  EXPECT_TRUE(m.joints[1].p_PJ.isApprox(Eigen::Vector3d(l1, 0, 0)));
  EXPECT_TRUE(m.joints[1].R_PJ.isIdentity());
  EXPECT_TRUE(m.gravity.isApprox(Eigen::Vector3d(0, -9.81, 0)));
}

// puma560: joint-side actuator and friction terms recomputed from the published motor-side
// values (Armstrong et al. 1986 Jm; Corke & Armstrong-Helouvry 1994 B, Tc) and gear ratios.
TEST(BuiltinRobots, Puma560ReflectedMotorTermsMatchPublishedValues) {
  const Model m = load_robot("puma560");
  const double G[6] = {-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686};
  const double Jm[6] = {291e-6, 409e-6, 299e-6, 35e-6, 35e-6, 35e-6};
  const double B[6] = {1.48e-3, .817e-3, 1.38e-3, 71.2e-6, 82.6e-6, 36.7e-6};
  const double Tp[6] = {0.395, 0.126, 0.132, 11.2e-3, 9.26e-3, 3.96e-3};
  const double Tn[6] = {-0.435, -0.071, -0.105, -16.9e-3, -14.5e-3, -10.5e-3};
  const double masses[6] = {0, 17.4, 4.8, 0.82, 0.34, 0.09};
  for (int j = 0; j < 6; ++j) {
    const JointFriction& f = m.joints[j].friction;
    EXPECT_NEAR(f.Ia, Jm[j] * G[j] * G[j], 5e-6 * f.Ia) << j;
    EXPECT_NEAR(f.Fv, B[j] * G[j] * G[j], 5e-6 * f.Fv) << j;
    EXPECT_NEAR(f.Fc, 0.5 * (std::abs(Tp[j]) + std::abs(Tn[j])) * std::abs(G[j]), 5e-6 * f.Fc) << j;
    EXPECT_DOUBLE_EQ(m.transmission.N(j, j), G[j]);
    EXPECT_DOUBLE_EQ(m.links[j](9), masses[j]);
  }
  // a2 = 0.4318 along x2, d3 = -0.0934 along z3 (AKB modified DH).
  EXPECT_TRUE(m.joints[2].p_PJ.isApprox(Eigen::Vector3d(0.4318, 0, -0.0934), 1e-15));
  EXPECT_NEAR(m.joints[1].limits.upper, 45.0 * M_PI / 180.0, 1e-15);
}

// irp6: the numbers reproduce seed 1's identified aggregated parameters for joint 2.
TEST(BuiltinRobots, Irp6ReproducesSeedAggregates) {
  const Model m = load_robot("irp6");
  const double l2 = 0.455;
  EXPECT_TRUE(m.joints[2].p_PJ.isApprox(Eigen::Vector3d(l2, 0, 0)));
  // X1 = m2 c2x + m3 l2 = 8.125 kg·m, X2 = I2zz + Ia2 + m3 l2² = 5.5 kg·m² (seed 1, Fig. 6).
  EXPECT_NEAR(m.links[1](6) + m.links[2](9) * l2, 8.125, 1e-12);
  EXPECT_NEAR(m.links[1](5) + m.joints[1].friction.Ia + m.links[2](9) * l2 * l2, 5.5, 1e-6);
  EXPECT_DOUBLE_EQ(m.joints[1].friction.Fv, 26.0);
  EXPECT_DOUBLE_EQ(m.joints[1].friction.Fc, 28.75);
  EXPECT_DOUBLE_EQ(m.transmission.N(2, 1), 1.0);
  EXPECT_DOUBLE_EQ(m.transmission.N(2, 2), 1.0);
}

// iiwa14: the world-fixed link_0 is dropped and the massless end-effector frames add nothing.
TEST(BuiltinRobots, Iiwa14InertiaFromDrake) {
  const Model m = load_robot("iiwa14");
  const double masses[7] = {5.76, 6.35, 3.5, 3.5, 3.5, 1.8, 1.2};
  for (int j = 0; j < 7; ++j) EXPECT_DOUBLE_EQ(m.links[j](9), masses[j]);
  EXPECT_NEAR(m.links[6](8), 1.2 * 0.02, 1e-15);  // MZ7
  EXPECT_NEAR(m.links[6](5), 0.001, 1e-15);       // ZZ7: COM on the z axis
  EXPECT_NEAR(m.links[6](0), 0.001 + 1.2 * 0.02 * 0.02, 1e-15);
  EXPECT_TRUE(m.joints[0].p_PJ.isApprox(Eigen::Vector3d(0, 0, 0.1575)));
  EXPECT_NEAR(m.joints[0].limits.effort, 320.0, 0.0);
}

}  // namespace
}  // namespace dynid
