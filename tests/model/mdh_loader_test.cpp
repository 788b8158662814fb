#include "dynid/model/mdh_loader.hpp"
#include "support/error_of.hpp"

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kModelsDir;

using dynid::testing::error_of;

// Elementary homogeneous transforms written out element by element (independent of Eigen's
// AngleAxis used by the loader).
Eigen::Matrix4d rot_x(double a) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(1, 1) = std::cos(a);
  T(1, 2) = -std::sin(a);
  T(2, 1) = std::sin(a);
  T(2, 2) = std::cos(a);
  return T;
}
Eigen::Matrix4d rot_z(double a) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(0, 0) = std::cos(a);
  T(0, 1) = -std::sin(a);
  T(1, 0) = std::sin(a);
  T(1, 1) = std::cos(a);
  return T;
}
Eigen::Matrix4d trans(double x, double y, double z) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(0, 3) = x;
  T(1, 3) = y;
  T(2, 3) = z;
  return T;
}

/// Pose of frame j in its parent at joint value q, from the Model's joint form.
Eigen::Matrix4d joint_pose(const Joint& j, double q) {
  Eigen::Matrix4d X = Eigen::Matrix4d::Identity();
  X.topLeftCorner<3, 3>() = j.R_PJ;
  X.topRightCorner<3, 1>() = j.p_PJ;
  Eigen::Matrix4d motion = Eigen::Matrix4d::Identity();
  if (j.type == JointType::kRevolute) {
    motion.topLeftCorner<3, 3>() = Eigen::AngleAxisd(q, j.axis).toRotationMatrix();
  } else {
    motion.topRightCorner<3, 1>() = q * j.axis;
  }
  return X * motion;
}

const char* kInertia = "inertia: [0.1, 0, 0, 0.1, 0, 0.1, 0, 0, 0, 1]";

TEST(MdhLoader, RowEqualsProductOfElementaryTransforms) {
  const std::string yaml =
      std::string("joints:\n") +
      "  - {name: a, sigma: 0, alpha: 0.4, d: 0.3, theta: -0.7, r: 0.25, " + kInertia + "}\n" +
      "  - {name: b, sigma: 1, alpha: -pi/2, d: 0.1, theta: 1.1, r: -0.2, " + kInertia + "}\n" +
      "  - {name: c, sigma: 0, alpha: 2*pi/3, d: -0.15, theta: 0.3, r: 0.05, "
      "parent: 1, " +
      kInertia + "}\n";
  const Model model = parse_yaml_model(yaml, "rows.yaml", ".");
  ASSERT_EQ(model.dof(), 3);
  EXPECT_EQ(model.joints[1].type, JointType::kPrismatic);
  EXPECT_EQ(model.joints[2].parent, 0);  // explicit parent: 1 (1-based) = joint a
  EXPECT_EQ(model.joints[1].parent, 0);  // default: previous row
  struct Row {
    int sigma;
    double alpha, d, theta, r;
  };
  const Row rows[3] = {{0, 0.4, 0.3, -0.7, 0.25},
                       {1, -M_PI / 2, 0.1, 1.1, -0.2},
                       {0, 2 * M_PI / 3, -0.15, 0.3, 0.05}};
  for (int j = 0; j < 3; ++j) {
    for (double q : {0.0, 0.7, -1.3}) {
      const Row& w = rows[j];
      const double theta = w.theta + (w.sigma == 0 ? q : 0.0);
      const double r = w.r + (w.sigma == 1 ? q : 0.0);
      const Eigen::Matrix4d T = rot_x(w.alpha) * trans(w.d, 0, 0) * rot_z(theta) * trans(0, 0, r);
      EXPECT_LT((joint_pose(model.joints[j], q) - T).norm(), 1e-14) << "row " << j << " q " << q;
    }
  }
}

TEST(MdhLoader, BasePlacementPrecedesRowsAttachedToTheBase) {
  const std::string yaml = std::string(
                               "base: {xyz: [0.1, 0.2, 0.3], rpy: [0, 0, 0.5]}\n"
                               "joints:\n"
                               "  - {sigma: 0, alpha: 0.2, d: 0.4, theta: 0.1, r: 0.3, ") +
                           kInertia + "}\n";
  const Model model = parse_yaml_model(yaml, "base.yaml", ".");
  const Eigen::Matrix4d T = trans(0.1, 0.2, 0.3) * rot_z(0.5) * rot_x(0.2) * trans(0.4, 0, 0) *
                            rot_z(0.1) * trans(0, 0, 0.3);
  EXPECT_LT((joint_pose(model.joints[0], 0.0) - T).norm(), 1e-14);
  EXPECT_EQ(model.joints[0].name, "joint1");
  EXPECT_EQ(model.joints[0].link_name, "link1");
  EXPECT_EQ(model.name, "base");
}

TEST(MdhLoader, CraigFormEqualsKhalilKleinfingerForm) {
  const std::string kk =
      std::string("joints:\n") + "  - {sigma: 0, alpha: 0, d: 0, theta: 0, r: 0.3, " + kInertia +
      "}\n" + "  - {sigma: 0, alpha: -pi/2, d: 0.2, theta: 0.4, r: 0.15, " + kInertia + "}\n" +
      "  - {sigma: 1, alpha: pi/2, d: -0.02, theta: 0, r: 0.43, " + kInertia + "}\n";
  const std::string craig =
      std::string("joints:\n") + "  - {sigma: 0, alpha_prev: 0, a_prev: 0, theta: 0, d: 0.3, " +
      kInertia + "}\n" + "  - {sigma: 0, alpha_prev: -pi/2, a_prev: 0.2, theta: 0.4, d: 0.15, " +
      kInertia + "}\n" + "  - {sigma: 1, alpha_prev: pi/2, a_prev: -0.02, theta: 0, d: 0.43, " +
      kInertia + "}\n";
  const Model a = parse_yaml_model(kk, "kk.yaml", ".");
  const Model b = parse_yaml_model(craig, "craig.yaml", ".");
  ASSERT_EQ(a.dof(), 3);
  ASSERT_EQ(b.dof(), 3);
  for (int j = 0; j < 3; ++j) {
    EXPECT_EQ(a.joints[j].type, b.joints[j].type);
    EXPECT_EQ(a.joints[j].parent, b.joints[j].parent);
    EXPECT_EQ(a.joints[j].R_PJ, b.joints[j].R_PJ);
    EXPECT_EQ(a.joints[j].p_PJ, b.joints[j].p_PJ);
    EXPECT_EQ(a.joints[j].axis, b.joints[j].axis);
  }
}

TEST(MdhLoader, InertiaFormsAndFrictionAndLimits) {
  const std::string yaml =
      "gravity: [0.1, 0.2, -9.7]\n"
      "joints:\n"
      "  - {sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, mass: 2.5, com: [0.1, -0.2, 0.3],\n"
      "     inertia_com: [0.05, 0.001, -0.002, 0.06, 0.003, 0.07], Ia: 0.3, Fv: 1.2, Fc: 0.8,\n"
      "     Fo: -0.1, limits: {lower: -2, upper: 1.5, velocity: 3, effort: 40}}\n";
  const Model model = parse_yaml_model(yaml, "inertia.yaml", ".");
  const double m = 2.5;
  const Eigen::Vector3d c(0.1, -0.2, 0.3);
  Eigen::Matrix3d I_C;
  I_C << 0.05, 0.001, -0.002, 0.001, 0.06, 0.003, -0.002, 0.003, 0.07;
  const Eigen::Matrix3d I_O =
      I_C + m * (c.dot(c) * Eigen::Matrix3d::Identity() - c * c.transpose());
  const LinkParams& p = model.links[0];
  EXPECT_LT((inertia_about_origin(p) - I_O).norm(), 1e-15);
  EXPECT_TRUE(p.segment<3>(6).isApprox(m * c, 1e-15));
  EXPECT_DOUBLE_EQ(p(9), m);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Ia, 0.3);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fv, 1.2);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fc, 0.8);
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fo, -0.1);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.lower, -2.0);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.upper, 1.5);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.velocity, 3.0);
  EXPECT_DOUBLE_EQ(model.joints[0].limits.effort, 40.0);
  EXPECT_TRUE(model.gravity.isApprox(Eigen::Vector3d(0.1, 0.2, -9.7)));

  // The same body given as the 10 standard parameters gives the same link.
  const std::string full = "joints:\n  - {sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, inertia: [" +
                           std::to_string(I_O(0, 0)) + ", " + std::to_string(I_O(0, 1)) + ", " +
                           std::to_string(I_O(0, 2)) + ", " + std::to_string(I_O(1, 1)) + ", " +
                           std::to_string(I_O(1, 2)) + ", " + std::to_string(I_O(2, 2)) +
                           ", 0.25, -0.5, 0.75, 2.5]}\n";
  const Model model2 = parse_yaml_model(full, "full.yaml", ".");
  EXPECT_LT((model2.links[0] - p).norm(), 1e-6);  // std::to_string keeps 6 decimals
}

TEST(MdhLoader, Transmissions) {
  const std::string rows = std::string("joints:\n") +
                           "  - {sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, " + kInertia + "}\n" +
                           "  - {sigma: 0, alpha: 0, d: 1, theta: 0, r: 0, " + kInertia + "}\n";
  const Model a = parse_yaml_model(rows + "gear_ratios: [10, -20]\n", "g.yaml", ".");
  EXPECT_EQ(a.transmission.N, Eigen::Vector2d(10, -20).asDiagonal().toDenseMatrix());
  EXPECT_TRUE(a.transmission.q_offset.isZero());
  const Model b = parse_yaml_model(
      rows + "transmission: {N: [[1, 0], [1, 1]], q_offset: [0.1, -0.2]}\n", "n.yaml", ".");
  Eigen::Matrix2d N;
  N << 1, 0, 1, 1;
  EXPECT_EQ(b.transmission.N, N);
  EXPECT_EQ(b.transmission.q_offset, Eigen::Vector2d(0.1, -0.2));
  EXPECT_FALSE(b.transmission.is_identity());
}

TEST(MdhLoader, UrdfWrapperAppliesOverrides) {
  const Model model = load_yaml_model(kModelsDir + "wrapper.yaml");
  ASSERT_EQ(model.dof(), 2);
  EXPECT_EQ(model.name, "wrapped");
  EXPECT_TRUE(model.gravity.isApprox(Eigen::Vector3d(0, -9.81, 0)));
  EXPECT_EQ(model.transmission.N, Eigen::Vector2d(100, -50).asDiagonal().toDenseMatrix());
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fv, 0.2);  // from the URDF, not overridden
  EXPECT_DOUBLE_EQ(model.joints[0].friction.Fc, 0.3);
  EXPECT_DOUBLE_EQ(model.joints[1].friction.Ia, 0.05);
  EXPECT_DOUBLE_EQ(model.joints[1].friction.Fv, 1.5);
  EXPECT_DOUBLE_EQ(model.joints[1].friction.Fc, 2.5);
  EXPECT_DOUBLE_EQ(model.joints[1].friction.Fo, -0.1);
}

// Issue 10: an absolute determinant test rejected N = 0.001·I as singular, and took O(n³).
TEST(MdhLoader, TransmissionTestIsScaleInvariant) {
  const std::string rows = std::string("joints:\n") +
                           "  - {sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, " + kInertia + "}\n" +
                           "  - {sigma: 0, alpha: 0, d: 1, theta: 0, r: 0, " + kInertia + "}\n" +
                           "  - {sigma: 0, alpha: 0, d: 1, theta: 0, r: 0, " + kInertia + "}\n";
  const Model small =
      parse_yaml_model(rows + "gear_ratios: [0.001, 0.001, 0.001]\n", "s.yaml", ".");
  EXPECT_EQ(small.transmission.N, 0.001 * Eigen::Matrix3d::Identity());
  // det = 1e-12·(1·1 − 0.5·0.5)·… tiny, but well conditioned: accepted.
  const Model coupled = parse_yaml_model(
      rows + "transmission: {N: [[1e-4, 0, 0], [0, 1e-4, 0], [0, 5e-5, 1e-4]]}\n", "c.yaml", ".");
  EXPECT_FALSE(coupled.transmission.is_identity());
  // Rank-deficient whatever the scale: row 3 = row 2 (coupled block), or a zero gear ratio.
  std::string msg = error_of([&] {
    parse_yaml_model(rows + "transmission: {N: [[1e6, 0, 0], [0, 2e6, 1e6], [0, 2e6, 1e6]]}\n",
                     "d.yaml", ".");
  });
  EXPECT_NE(msg.find("singular transmission matrix"), std::string::npos) << msg;
  msg = error_of([&] { parse_yaml_model(rows + "gear_ratios: [100, 0, 50]\n", "z.yaml", "."); });
  EXPECT_NE(msg.find("singular transmission matrix"), std::string::npos) << msg;
}

// Issue 10: duplicate joint names were accepted and failed later inside MuJoCo.
TEST(MdhLoaderErrors, DuplicateJointNames) {
  const std::string yaml =
      std::string("joints:\n") + "  - {name: a, sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, " +
      kInertia + "}\n" + "  - {name: b, sigma: 0, alpha: 0, d: 1, theta: 0, r: 0, " + kInertia +
      "}\n" + "  - {name: a, sigma: 0, alpha: 0, d: 1, theta: 0, r: 0, " + kInertia + "}\n";
  const std::string msg = error_of([&] { parse_yaml_model(yaml, "dup.yaml", "."); });
  EXPECT_NE(msg.find("robot file 'dup.yaml': joints[3] ('a').name: repeats the name of joints[1]"),
            std::string::npos)
      << msg;
  // Models built by hand get the same check in Model::finalize.
  Model m = parse_yaml_model(
      std::string("joints:\n") + "  - {name: a, sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, " +
          kInertia + "}\n" + "  - {name: b, sigma: 0, alpha: 0, d: 1, theta: 0, r: 0, " + kInertia +
          "}\n",
      "ok.yaml", ".");
  m.joints[1].name = "a";
  const std::string fin = error_of([&] { m.finalize(); });
  EXPECT_NE(fin.find("two joints named 'a' (joints 1 and 2)"), std::string::npos) << fin;
}

// Issue 10: yaml-cpp text was echoed raw; input text in messages is escaped (no control characters,
// valid UTF-8 only) and the message names file and line.
TEST(MdhLoaderErrors, YamlMessagesNameLineAndEscapeInput) {
  const std::string msg = error_of([] {
    parse_yaml_model(
        "joints:\n  - {sigma: 0, alpha: \"x\\ty\\u0007\\xff\", d: 0, theta: 0, r: 0}\n", "e.yaml",
        ".");
  });
  EXPECT_NE(msg.find("'x\\ty\\x07\xc3\xbf' is not a number"), std::string::npos) << msg;
  for (char c : msg) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20) << msg;
  const std::string bad = error_of([] { parse_yaml_model("joints: [1, 2\n\n", "f.yaml", "."); });
  EXPECT_NE(bad.find("robot file 'f.yaml', line "), std::string::npos) << bad;
  for (char c : bad) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20) << bad;
}

// Issue 10: `urdf: /dev/zero` read until memory ran out; more rows than kMaxJoints are refused
// before any is read.
TEST(MdhLoaderErrors, SizeLimits) {
  std::string msg = error_of([] { parse_yaml_model("urdf: /dev/zero\n", "z.yaml", "."); });
  // A device is refused before it is opened (issue 27 item 4).
  EXPECT_NE(msg.find("robot file '/dev/zero' is not a regular file (a device)"), std::string::npos)
      << msg;
  std::string rows = "joints:\n";
  for (int j = 0; j <= kMaxJoints; ++j) rows += "  - {sigma: 0}\n";
  msg = error_of([&] { parse_yaml_model(rows, "big.yaml", "."); });
  EXPECT_NE(
      msg.find("joints: has " + std::to_string(kMaxJoints + 1) + " rows; dynid handles at most"),
      std::string::npos)
      << msg;
}

TEST(MdhLoaderErrors, WrongTransmissionSize) {
  const std::string msg = error_of([] { load_yaml_model(kModelsDir + "bad_transmission.yaml"); });
  EXPECT_NE(msg.find("transmission.N"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must be a 2x2 matrix"), std::string::npos) << msg;
}

TEST(MdhLoaderErrors, MissingKeyNamesKeyAndRow) {
  const std::string msg = error_of([] { load_yaml_model(kModelsDir + "missing_key.yaml"); });
  EXPECT_NE(msg.find("joints[2] ('b')"), std::string::npos) << msg;
  EXPECT_NE(msg.find("missing key 'alpha'"), std::string::npos) << msg;
}

TEST(MdhLoaderErrors, NanValue) {
  const std::string msg = error_of([] { load_yaml_model(kModelsDir + "nan_value.yaml"); });
  EXPECT_NE(msg.find("joints[1] ('a').d"), std::string::npos) << msg;
  EXPECT_NE(msg.find("give a finite value"), std::string::npos) << msg;
}

TEST(MdhLoaderErrors, UnknownKeyNegativeMassBadYamlAndUnknownJoint) {
  std::string msg = error_of([] {
    parse_yaml_model("joints:\n  - {sigma: 0, alpah: 0, d: 0, theta: 0, r: 0}\n", "t.yaml", ".");
  });
  EXPECT_NE(msg.find("unknown key 'alpah'"), std::string::npos) << msg;
  msg = error_of([] {
    parse_yaml_model(
        "joints:\n  - {sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, mass: -1, com: [0, 0, 0], "
        "inertia_com: [1, 0, 0, 1, 0, 1]}\n",
        "t.yaml", ".");
  });
  EXPECT_NE(msg.find("joints[1].mass: is negative"), std::string::npos) << msg;
  msg = error_of([] { parse_yaml_model("joints: [ {sigma: 0", "t.yaml", "."); });
  EXPECT_NE(msg.find("robot file 't.yaml', line 1, column "), std::string::npos) << msg;
  EXPECT_NE(msg.find(": not valid YAML ("), std::string::npos) << msg;
  msg = error_of([] {
    parse_yaml_model("urdf: two_link.urdf\nfriction: {j9: {Fv: 1}}\n", "w.yaml", kModelsDir);
  });
  EXPECT_NE(msg.find("friction.j9: no joint of that name; joints are j1, j2"), std::string::npos)
      << msg;
  msg = error_of([] { parse_yaml_model("urdf: missing.urdf\n", "w.yaml", kModelsDir); });
  EXPECT_NE(msg.find("cannot open robot file"), std::string::npos) << msg;
  msg = error_of([] {
    parse_yaml_model("joints:\n  - {sigma: 2, alpha: 0, d: 0, theta: 0, r: 0}\n", "t.yaml", ".");
  });
  EXPECT_NE(msg.find("sigma: must be 0 (revolute) or 1 (prismatic)"), std::string::npos) << msg;
}

}  // namespace
}  // namespace dynid
