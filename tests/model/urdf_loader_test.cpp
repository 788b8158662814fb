#include "dynid/model/urdf_loader.hpp"
#include "support/chain_urdf.hpp"
#include "support/error_of.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kModelsDir;

/// Runs f and returns the dynid::Error message (fails the test if nothing or something else is
/// thrown).
using dynid::testing::error_of;

Eigen::Matrix3d rpy(double r, double p, double y) {
  // URDF: fixed-axis roll about x, then pitch about y, then yaw about z.
  return (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// Standard parameters of a set of point masses {m_i, r_i} about the frame origin, straight from
/// the definitions I = Σ m (|r|² 1 − r rᵀ), h = Σ m r.
LinkParams point_cloud_params(const std::vector<double>& m, const std::vector<Eigen::Vector3d>& r) {
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  double M = 0.0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    I += m[i] * (r[i].squaredNorm() * Eigen::Matrix3d::Identity() - r[i] * r[i].transpose());
    h += m[i] * r[i];
    M += m[i];
  }
  LinkParams p;
  p << I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2), h.x(), h.y(), h.z(), M;
  return p;
}

TEST(TransformLinkParams, MatchesPointMassCloudInBothFrames) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> m;
  std::vector<Eigen::Vector3d> rB, rA;
  const Eigen::Matrix3d R = Eigen::Quaterniond(0.3, -0.5, 0.7, 0.2).normalized().toRotationMatrix();
  const Eigen::Vector3d t(0.4, -0.2, 0.9);
  for (int i = 0; i < 7; ++i) {
    m.push_back(0.5 + 0.5 * u(rng));
    rB.emplace_back(u(rng), u(rng), u(rng));
    rA.push_back(R * rB.back() + t);
  }
  const LinkParams pB = point_cloud_params(m, rB);
  const LinkParams pA = point_cloud_params(m, rA);
  EXPECT_LT((transform_link_params(pB, R, t) - pA).norm(), 1e-12 * pA.norm());
}

TEST(UrdfLoader, FixedJointMergesInertiaAndReparentsChildren) {
  const std::string xml = R"(<?xml version="1.0"?>
<robot name="merge">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <link name="l1">
    <inertial><origin xyz="0.1 0 0"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
  </link>
  <joint name="weld" type="fixed">
    <parent link="l1"/><child link="l1b"/>
    <origin xyz="0.3 0.1 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <link name="l1b">
    <inertial><origin xyz="0.05 0 0" rpy="0.3 0 0"/><mass value="1"/>
      <inertia ixx="0.004" ixy="0.001" ixz="0" iyy="0.005" iyz="0" izz="0.006"/></inertial>
  </link>
  <joint name="j2" type="revolute">
    <parent link="l1b"/><child link="l2"/>
    <origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <link name="l2">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
  </link>
</robot>)";
  const Model model = parse_urdf(xml, "merge.urdf");
  ASSERT_EQ(model.dof(), 2);
  EXPECT_EQ(model.joints[1].name, "j2");
  EXPECT_EQ(model.joints[1].parent, 0);

  // Hand computation of the combined body l1 + l1b in frame l1.
  const Eigen::Matrix3d Rw = rpy(0, 0, M_PI / 2);  // weld rotation
  const Eigen::Vector3d pw(0.3, 0.1, 0.0);
  EXPECT_TRUE(model.joints[1].R_PJ.isApprox(Rw, 1e-12));
  EXPECT_TRUE(model.joints[1].p_PJ.isApprox(pw + Rw * Eigen::Vector3d(0.2, 0, 0), 1e-12));
  EXPECT_TRUE(model.joints[1].p_PJ.isApprox(Eigen::Vector3d(0.3, 0.3, 0.0), 1e-12));

  const double m1 = 2.0, m2 = 1.0;
  const Eigen::Vector3d c1(0.1, 0, 0);
  const Eigen::Vector3d c2 = pw + Rw * Eigen::Vector3d(0.05, 0, 0);  // = (0.3, 0.15, 0)
  Eigen::Matrix3d I1 = Eigen::Vector3d(0.01, 0.02, 0.03).asDiagonal();
  Eigen::Matrix3d I2_in;
  I2_in << 0.004, 0.001, 0, 0.001, 0.005, 0, 0, 0, 0.006;
  const Eigen::Matrix3d R2 = Rw * rpy(0.3, 0, 0);
  const Eigen::Matrix3d I2 = R2 * I2_in * R2.transpose();
  const auto steiner = [](double m, const Eigen::Vector3d& c) {
    return Eigen::Matrix3d(m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose()));
  };
  const Eigen::Matrix3d I_O = I1 + steiner(m1, c1) + I2 + steiner(m2, c2);
  const Eigen::Vector3d h = m1 * c1 + m2 * c2;
  const LinkParams& p = model.links[0];
  EXPECT_NEAR(p(9), 3.0, 1e-14);
  EXPECT_NEAR(p(6), h.x(), 1e-14);
  EXPECT_NEAR(p(7), h.y(), 1e-14);
  EXPECT_NEAR(p(8), h.z(), 1e-14);
  EXPECT_LT((inertia_about_origin(p) - I_O).norm(), 1e-14);
  // The first moment in plain numbers: 2·(0.1,0,0) + 1·(0.3,0.15,0).
  EXPECT_NEAR(p(6), 0.5, 1e-14);
  EXPECT_NEAR(p(7), 0.15, 1e-14);
}

TEST(UrdfLoader, FixedJointOffTheRootBecomesPartOfTheChildOrigin) {
  const std::string xml = R"(<robot name="offroot">
  <link name="world"><inertial><mass value="100"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="pedestal"/>
    <origin xyz="0 0 1" rpy="0 0 0.5"/></joint>
  <link name="pedestal"><inertial><mass value="50"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j1" type="continuous"><parent link="pedestal"/><child link="l1"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 0 1"/></joint>
  <link name="l1"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
</robot>)";
  const Model model = parse_urdf(xml, "offroot.urdf");
  ASSERT_EQ(model.dof(), 1);
  EXPECT_EQ(model.joints[0].parent, -1);
  EXPECT_TRUE(model.joints[0].R_PJ.isApprox(rpy(0, 0, 0.5), 1e-12));
  EXPECT_TRUE(model.joints[0].p_PJ.isApprox(
      Eigen::Vector3d(0, 0, 1) + rpy(0, 0, 0.5) * Eigen::Vector3d(0.1, 0, 0), 1e-12));
  EXPECT_DOUBLE_EQ(model.links[0](9), 1.0);  // world and pedestal masses are not added
}

TEST(UrdfLoader, JointOrderIsDepthFirstInFileOrderNotAlphabetical) {
  // Joints in file order: zeta (base->A), beta (A->B), alpha (base->C), delta (A->D),
  // gamma (B->E). Depth-first, children in file order: zeta, beta, gamma, delta, alpha.
  std::string xml = "<robot name='tree'><link name='base'/>";
  const auto link = [](const std::string& n) {
    return "<link name='" + n +
           "'><inertial><mass value='1'/><inertia ixx='0.1' ixy='0' ixz='0' iyy='0.1' iyz='0' "
           "izz='0.1'/></inertial></link>";
  };
  const auto joint = [](const std::string& n, const std::string& parent, const std::string& child) {
    return "<joint name='" + n + "' type='continuous'><parent link='" + parent +
           "'/><child link='" + child + "'/><axis xyz='0 1 0'/></joint>";
  };
  xml += joint("zeta", "base", "A") + joint("beta", "A", "B") + joint("alpha", "base", "C") +
         joint("delta", "A", "D") + joint("gamma", "B", "E");
  for (const char* n : {"A", "B", "C", "D", "E"}) xml += link(n);
  xml += "</robot>";
  const Model model = parse_urdf(xml, "tree.urdf");
  ASSERT_EQ(model.dof(), 5);
  const std::vector<std::string> names = {"zeta", "beta", "gamma", "delta", "alpha"};
  const std::vector<std::string> links = {"A", "B", "E", "D", "C"};
  const std::vector<int> parents = {-1, 0, 1, 0, -1};
  for (int j = 0; j < 5; ++j) {
    EXPECT_EQ(model.joints[j].name, names[j]);
    EXPECT_EQ(model.joints[j].link_name, links[j]);
    EXPECT_EQ(model.joints[j].parent, parents[j]);
  }
}

TEST(UrdfLoader, InertialRpyRotatesTheTensorIntoTheLinkFrame) {
  const std::string xml = R"(<robot name="rpy">
  <link name="base"/>
  <joint name="j1" type="prismatic"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 2"/><limit lower="-0.5" upper="0.5" velocity="1" effort="100"/></joint>
  <link name="l1"><inertial><origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.4 0.5"/><mass value="1.7"/>
    <inertia ixx="0.05" ixy="0.004" ixz="-0.003" iyy="0.06" iyz="0.002" izz="0.07"/></inertial></link>
</robot>)";
  const Model model = parse_urdf(xml, "rpy.urdf");
  ASSERT_EQ(model.dof(), 1);
  EXPECT_EQ(model.joints[0].type, JointType::kPrismatic);
  EXPECT_TRUE(model.joints[0].axis.isApprox(Eigen::Vector3d::UnitZ(), 1e-15));
  Eigen::Matrix3d I_in;
  I_in << 0.05, 0.004, -0.003, 0.004, 0.06, 0.002, -0.003, 0.002, 0.07;
  // Hand rotation: R = Rz(0.5) Ry(-0.4) Rx(0.3), each written out element by element.
  const double cr = std::cos(0.3), sr = std::sin(0.3), cp = std::cos(-0.4), sp = std::sin(-0.4),
               cy = std::cos(0.5), sy = std::sin(0.5);
  Eigen::Matrix3d Rx, Ry, Rz;
  Rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
  Ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
  Rz << cy, -sy, 0, sy, cy, 0, 0, 0, 1;
  const Eigen::Matrix3d R = Rz * Ry * Rx;
  const Eigen::Vector3d c(0.1, -0.2, 0.3);
  const double m = 1.7;
  const Eigen::Matrix3d I_O =
      R * I_in * R.transpose() + m * (c.dot(c) * Eigen::Matrix3d::Identity() - c * c.transpose());
  EXPECT_LT((inertia_about_origin(model.links[0]) - I_O).norm(), 1e-14);
  EXPECT_TRUE(model.links[0].segment<3>(6).isApprox(m * c, 1e-14));
  EXPECT_DOUBLE_EQ(model.joints[0].limits.lower, -0.5);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.effort, 100.0);
}

TEST(UrdfLoader, ContinuousLimitsAndDynamics) {
  const std::string xml = R"(<robot name="cont">
  <link name="base"/>
  <joint name="spin" type="continuous"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit velocity="3" effort="12"/>
    <dynamics damping="0.7" friction="1.25"/></joint>
  <link name="l1"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
</robot>)";
  const Model model = parse_urdf(xml, "cont.urdf");
  ASSERT_EQ(model.dof(), 1);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(model.joints[0].type, JointType::kRevolute);
  EXPECT_EQ(model.joints[0].limits.lower, -inf);
  EXPECT_EQ(model.joints[0].limits.upper, inf);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.velocity, 3.0);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.effort, 12.0);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fv, 0.7);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fc, 1.25);
  EXPECT_EQ(model.name, "cont");
  EXPECT_EQ(model.source, "cont.urdf");
}

TEST(UrdfLoader, LoadsFileAndKeepsLimits) {
  const Model model = load_urdf(kModelsDir + "two_link.urdf");
  ASSERT_EQ(model.dof(), 2);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.lower, -1.0);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.upper, 1.0);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fv, 0.2);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fc, 0.3);
  EXPECT_TRUE(model.joints[1].p_PJ.isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_TRUE(model.transmission.is_identity());
}

TEST(UrdfLoaderErrors, MalformedXml) {
  const std::string msg = error_of([] { load_urdf(kModelsDir + "malformed.urdf"); });
  EXPECT_NE(msg.find("malformed.urdf"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not well-formed XML"), std::string::npos) << msg;
}

TEST(UrdfLoaderErrors, UnsupportedFloatingJoint) {
  const std::string msg = error_of([] { load_urdf(kModelsDir + "floating.urdf"); });
  EXPECT_NE(msg.find("joint 'free_flyer'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unsupported type 'floating'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("revolute, continuous, prismatic and fixed"), std::string::npos) << msg;
}

TEST(UrdfLoaderErrors, NegativeMass) {
  const std::string msg = error_of([] { load_urdf(kModelsDir + "negative_mass.urdf"); });
  EXPECT_NE(msg.find("link 'l1' has negative mass"), std::string::npos) << msg;
}

TEST(UrdfLoaderErrors, TriangleInequality) {
  const std::string msg = error_of([] { load_urdf(kModelsDir + "triangle.urdf"); });
  EXPECT_NE(msg.find("link 'l1' has a non-physical inertia"), std::string::npos) << msg;
  EXPECT_NE(msg.find("triangle inequality"), std::string::npos) << msg;
}

TEST(UrdfLoaderErrors, MissingFile) {
  const std::string msg = error_of([] { load_urdf(kModelsDir + "no_such_robot.urdf"); });
  EXPECT_NE(msg.find("cannot open robot file '" + kModelsDir + "no_such_robot.urdf'"),
            std::string::npos)
      << msg;
}

TEST(UrdfLoaderErrors, NoMovingJoint) {
  const std::string xml = R"(<robot name="statue"><link name="a"/><link name="b"/>
    <joint name="w" type="fixed"><parent link="a"/><child link="b"/></joint></robot>)";
  const std::string msg = error_of([&] { parse_urdf(xml, "statue.urdf"); });
  EXPECT_NE(msg.find("no revolute, continuous or prismatic joint"), std::string::npos) << msg;
}

TEST(UrdfLoaderErrors, NotAUrdf) {
  const std::string msg = error_of([] { parse_urdf("<robotx/>", "x.urdf"); });
  EXPECT_NE(msg.find("no <robot> element"), std::string::npos) << msg;
}

// Issue 10: a joint whose child is its own parent recursed without end in the tree builder.
TEST(UrdfLoaderErrors, JointWhoseChildIsItsOwnParentIsACycle) {
  const std::string xml = R"(<robot name="loop"><link name="a"/><link name="b"/>
    <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    <joint name="j2" type="continuous"><parent link="b"/><child link="b"/></joint></robot>)";
  const std::string msg = error_of([&] { parse_urdf(xml, "loop.urdf"); });
  EXPECT_NE(msg.find("joint 'j2' in 'loop.urdf' leads back to link 'b'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must be a tree"), std::string::npos) << msg;
}

TEST(UrdfLoaderErrors, CycleBelowTheRoot) {
  const std::string xml = R"(<robot name="ring"><link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>
    <joint name="j2" type="continuous"><parent link="b"/><child link="c"/></joint>
    <joint name="j3" type="fixed"><parent link="c"/><child link="b"/></joint></robot>)";
  std::string msg;
  ::testing::internal::CaptureStderr();
  ::testing::internal::CaptureStdout();
  msg = error_of([&] { parse_urdf(xml, "ring.urdf"); });
  const std::string err = ::testing::internal::GetCapturedStderr();
  const std::string out = ::testing::internal::GetCapturedStdout();
  // urdfdom may reject the file itself (two parents for b) or leave the cycle to the tree builder;
  // either way one dynid error and no console output.
  EXPECT_NE(msg.find("ring.urdf"), std::string::npos) << msg;
  EXPECT_EQ(err, "");
  EXPECT_EQ(out, "");
}

// Issue 10: a chain of ~12 000 links overflowed the stack of the recursive builder. 1000 moving
// joints (kMaxJoints), each followed by eleven fixed links: 12 000 links deep.
TEST(UrdfLoader, TwelveThousandLinksDeepLoadIteratively) {
  const Model model = parse_urdf(testing::chain_urdf(1000, 3, 11), "deep.urdf");
  ASSERT_EQ(model.dof(), 1000);
  EXPECT_EQ(model.joints[999].parent, 998);
  // Each moving link (1 to 2 kg) carries its eleven fixed bodies of 0.01 kg.
  for (int j = 0; j < model.dof(); ++j) {
    EXPECT_GE(model.links[j](9), 1.11 - 1e-12) << j;
    EXPECT_LE(model.links[j](9), 2.11 + 1e-12) << j;
  }
  EXPECT_TRUE(model.transmission.is_identity());
}

TEST(UrdfLoaderErrors, MoreThanTheJointLimit) {
  const std::string msg =
      error_of([] { parse_urdf(testing::chain_urdf(kMaxJoints + 1, 4), "huge.urdf"); });
  EXPECT_NE(msg.find("more than " + std::to_string(kMaxJoints) + " moving joints"),
            std::string::npos)
      << msg;
}

// Issue 10: urdfdom's console_bridge lines preceded dynid's error for every rejected URDF.
TEST(UrdfLoaderErrors, UrdfdomMessageBecomesPartOfTheOneLineError) {
  const std::string xml = R"(<robot name="r"><link name="a"/>
    <joint name="j1" type="revolute"><parent link="a"/><child link="nowhere"/>
      <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>)";
  ::testing::internal::CaptureStderr();
  ::testing::internal::CaptureStdout();
  const std::string msg = error_of([&] { parse_urdf(xml, "r.urdf"); });
  const std::string err = ::testing::internal::GetCapturedStderr();
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(err, "");
  EXPECT_EQ(out, "");
  EXPECT_NE(msg.find("robot file 'r.urdf' is not a valid URDF ("), std::string::npos) << msg;
  EXPECT_NE(msg.find("nowhere"), std::string::npos) << msg;  // urdfdom's reason, in dynid's line
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

// Issue 10: reading /dev/zero as a robot file read until memory ran out.
TEST(UrdfLoaderErrors, DeviceWithoutEndIsCutAtTheSizeLimit) {
  const std::string msg = error_of([] { load_urdf("/dev/zero"); });
  // A device is refused before it is opened (issue 27 item 4).
  EXPECT_NE(msg.find("robot file '/dev/zero' is not a regular file (a device)"), std::string::npos)
      << msg;
  const std::string dir = error_of([] { load_urdf(kModelsDir); });
  EXPECT_NE(dir.find("is a directory"), std::string::npos) << dir;
}

// Issue 26 item 4: a vendor URDF's slightly non-physical inertia loads with one warning naming the
// link and the violation; without a warning list (the --strict path) it is refused.
TEST(UrdfLoaderTolerance, TriangleViolationOfAFewPercentIsAWarning) {
  std::vector<std::string> warnings;
  const Model m = load_urdf(kModelsDir + "vendor_triangle.urdf", &warnings);
  EXPECT_EQ(m.dof(), 2);
  ASSERT_EQ(warnings.size(), 1u);
  // 0.0206 > 0.01 + 0.01 by 0.0006 / 0.0206 = 2.913 %.
  EXPECT_NE(warnings[0].find("link 'wrist' has a non-physical inertia"), std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("triangle inequality (0.0206 > 0.01 + 0.01 by 2.913 %)"),
            std::string::npos)
      << warnings[0];
  // The inertia is kept as given: ZZ2 about the origin = 0.0206 + 0.8 * 0.05^2.
  EXPECT_NEAR(m.links[1](5), 0.0206 + 0.8 * 0.0025, 1e-15);
  const std::string msg = error_of([] { load_urdf(kModelsDir + "vendor_triangle.urdf"); });
  EXPECT_NE(msg.find("link 'wrist' has a non-physical inertia"), std::string::npos) << msg;
}

TEST(UrdfLoaderTolerance, GrossViolationIsStillNamedWithItsSize) {
  std::vector<std::string> warnings;
  load_urdf(kModelsDir + "triangle.urdf", &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("(0.5 > 0.1 + 0.1 by 60 %)"), std::string::npos) << warnings[0];
}

TEST(UrdfLoaderTolerance, IdentificationToolStyleLoads) {
  std::vector<std::string> warnings;
  const Model m = load_urdf(kModelsDir + "figaroh_style.urdf", &warnings);
  ASSERT_EQ(m.dof(), 2);
  EXPECT_EQ(m.joints[0].friction.Fv, 0.12);
  EXPECT_EQ(m.joints[0].friction.Fc, 0.3);
  EXPECT_DOUBLE_EQ(m.links[0](9), 3.2);
  EXPECT_EQ(m.joints[1].limits.lower, -2.0);
  EXPECT_EQ(m.joints[1].limits.effort, std::numeric_limits<double>::infinity());
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("joint 'joint_2'"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("<limit> without effort and velocity; read as unlimited"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("link 'link_2'"), std::string::npos) << warnings[1];
  EXPECT_NE(warnings[1].find("one is negative: 0.07 % of the largest"), std::string::npos)
      << warnings[1];
  // Strict: the limit is refused first, naming the joint.
  const std::string msg = error_of([] { load_urdf(kModelsDir + "figaroh_style.urdf"); });
  EXPECT_NE(msg.find("joint 'joint_2'"), std::string::npos) << msg;
}

TEST(UrdfLoaderErrors, UnexpandedXacroInInertialNamesTheLink) {
  const std::string msg = error_of([] { load_urdf(kModelsDir + "xacro_leftover.urdf"); });
  EXPECT_NE(msg.find("link 'forearm'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("<origin xyz=\"${l/2} 0 0\"> is not 3 numbers"), std::string::npos) << msg;
  EXPECT_NE(msg.find("xacro"), std::string::npos) << msg;
  const std::string mass = error_of([] {
    parse_urdf(R"(<robot name="r"><link name="b"/><link name="l"><inertial><mass value="1kg"/>
      </inertial></link><joint name="j" type="continuous"><parent link="b"/><child link="l"/>
      </joint></robot>)",
               "r.urdf");
  });
  EXPECT_NE(mass.find("link 'l' in 'r.urdf': <inertial> <mass value=\"1kg\"> is not a number"),
            std::string::npos)
      << mass;
}

}  // namespace
}  // namespace dynid
