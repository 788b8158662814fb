// lock_joints (issue 26 item 1): a robot file's joints a log does not have, held fixed.
// Oracle: the same robot written by hand with each locked joint replaced by two fixed joints, its
// <origin> and then the joint's motion at the locked value (rpy about the joint's axis, or xyz
// along it), loaded through the URDF loader's fixed-joint merge. Inverse dynamics of both must
// agree at random states, with a kept joint mounted below a locked one and a fixed link below a
// locked one.
#include "dynid/model/joint_lock.hpp"

#include <random>
#include <string>

#include <gtest/gtest.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/urdf_loader.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

using dynid::testing::error_of;

// base -j1 (revolute z)-> l1 -slide (prismatic z, LOCKED)-> ls -j2 (revolute y)-> l2
//   -head (revolute x, LOCKED)-> lh -fixed-> lh2;  l1 -j3 (revolute x)-> l3
const std::string kLinks = R"(
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0.1 0.02 0.3" rpy="0.1 0.2 0.3"/><mass value="3"/>
    <inertia ixx="0.05" ixy="0.001" ixz="0.002" iyy="0.04" iyz="0.003" izz="0.03"/></inertial></link>
  <link name="ls"><inertial><origin xyz="0.03 -0.02 0.05"/><mass value="1.2"/>
    <inertia ixx="0.01" ixy="0" ixz="0.001" iyy="0.012" iyz="0" izz="0.008"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0.01 -0.03" rpy="0 0.3 0"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0.002" izz="0.025"/></inertial></link>
  <link name="lh"><inertial><origin xyz="0.05 0.04 0.02"/><mass value="0.7"/>
    <inertia ixx="0.003" ixy="0.0002" ixz="0" iyy="0.004" iyz="0" izz="0.002"/></inertial></link>
  <link name="lh2"><inertial><origin xyz="0 0.1 0"/><mass value="0.3"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0 0.15 0"/><mass value="1.1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.006" iyz="0" izz="0.009"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="ls"/><child link="l2"/>
    <origin xyz="0.1 0 0.2" rpy="0.2 0 0.1"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="lh_fixed" type="fixed"><parent link="lh"/><child link="lh2"/><origin xyz="0.1 0 0" rpy="0 0 0.4"/></joint>
  <joint name="j3" type="revolute"><parent link="l1"/><child link="l3"/>
    <origin xyz="0 0.2 0.1" rpy="0 0.5 0"/><axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
)";

// The robot file: slide and head move.
const std::string kFull = R"(<robot name="lockable">)" + kLinks + R"(
  <joint name="slide" type="prismatic"><parent link="l1"/><child link="ls"/>
    <origin xyz="0.3 0 0.4" rpy="0.3 -0.2 0.1"/><axis xyz="0 0 1"/><limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="head" type="revolute"><parent link="l2"/><child link="lh"/>
    <origin xyz="0.4 0 0" rpy="0 0.1 0.2"/><axis xyz="1 0 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>)";

// The same robot edited by hand with slide held at 0.12 m and head at -0.7 rad.
const std::string kHandFixed = R"(<robot name="lockable">)" + kLinks + R"(
  <link name="slide_at"/><link name="head_at"/>
  <joint name="slide" type="fixed"><parent link="l1"/><child link="slide_at"/>
    <origin xyz="0.3 0 0.4" rpy="0.3 -0.2 0.1"/></joint>
  <joint name="slide_value" type="fixed"><parent link="slide_at"/><child link="ls"/>
    <origin xyz="0 0 0.12"/></joint>
  <joint name="head" type="fixed"><parent link="l2"/><child link="head_at"/>
    <origin xyz="0.4 0 0" rpy="0 0.1 0.2"/></joint>
  <joint name="head_value" type="fixed"><parent link="head_at"/><child link="lh"/>
    <origin rpy="-0.7 0 0"/></joint>
</robot>)";

Eigen::VectorXd random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

Model full() {
  return parse_urdf(kFull, "full.urdf");
}

TEST(LockJoints, InverseDynamicsEqualsTheHandEditedFixedRobot) {
  const Model model = full();
  ASSERT_EQ(model.dof(), 5);
  JointSelection s;
  s.locks = {{"slide", 0.12}, {"head", -0.7}};
  const Model locked = lock_joints(model, s);
  const Model hand = parse_urdf(kHandFixed, "hand.urdf");
  ASSERT_EQ(locked.dof(), 3);
  ASSERT_EQ(hand.dof(), 3);
  for (int j = 0; j < 3; ++j) EXPECT_EQ(locked.joints[j].name, hand.joints[j].name);
  ASSERT_EQ(locked.locked_joints.size(), 2u);
  EXPECT_EQ(locked.locked_joints[0].name, "slide");
  EXPECT_EQ(locked.locked_joints[0].value, 0.12);
  EXPECT_EQ(locked.locked_joints[1].name, "head");
  std::mt19937 rng(26);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(rng, 3, 2.0), dq = random_vector(rng, 3, 1.5),
                          ddq = random_vector(rng, 3, 3.0);
    const Eigen::VectorXd a = rnea(locked, q, dq, ddq), b = rnea(hand, q, dq, ddq);
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + b.cwiseAbs().maxCoeff())) << k;
  }
  // The lock changes the answer: the same robot locked elsewhere is another robot.
  s.locks = {{"slide", 0.0}, {"head", -0.7}};
  const Eigen::VectorXd q = random_vector(rng, 3, 2.0), dq = random_vector(rng, 3, 1.5),
                        ddq = random_vector(rng, 3, 3.0);
  EXPECT_GT((rnea(lock_joints(model, s), q, dq, ddq) - rnea(hand, q, dq, ddq)).norm(), 1e-3);
}

TEST(LockJoints, JointsListedInTheLogsOrderPermuteTheModel) {
  const Model model = full();  // model order j1, j3, slide, j2, head (l1's joints in file order)
  JointSelection s;
  s.joints = {"j1", "j2", "j3"};
  s.locks = {{"slide", 0.12}, {"head", -0.7}};
  const Model reordered = lock_joints(model, s);
  const Model hand = parse_urdf(kHandFixed, "hand.urdf");  // j1, j3, j2
  ASSERT_EQ(hand.joints[1].name, "j3");
  ASSERT_EQ(reordered.joints[1].name, "j2");
  std::mt19937 rng(27);
  const Eigen::VectorXd q = random_vector(rng, 3, 2.0), dq = random_vector(rng, 3, 1.5),
                        ddq = random_vector(rng, 3, 3.0);
  Eigen::PermutationMatrix<3> p;  // hand index of each reordered joint
  p.indices() << 0, 2, 1;
  const Eigen::VectorXd a =
      rnea(reordered, p.transpose() * q, p.transpose() * dq, p.transpose() * ddq);
  const Eigen::VectorXd b = rnea(hand, q, dq, ddq);
  EXPECT_LT((p * a - b).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + b.cwiseAbs().maxCoeff()));
}

TEST(LockJoints, UnlistedJointsAreHeldAtZero) {
  JointSelection s;
  s.joints = {"j1", "j2", "j3"};
  const Model locked = lock_joints(full(), s);
  ASSERT_EQ(locked.locked_joints.size(), 2u);
  EXPECT_EQ(locked.locked_joints[0].value, 0.0);
  EXPECT_EQ(locked.locked_joints[1].value, 0.0);
  EXPECT_TRUE(lock_joints(full(), JointSelection{}).locked_joints.empty());
}

TEST(LockJoints, BadSelectionsNameTheJoint) {
  const Model model = full();
  auto lock = [&](JointSelection s) { return error_of([&] { lock_joints(model, s); }); };
  std::string msg = lock({{"j1", "gripper"}, {}});
  EXPECT_NE(msg.find("joint 'gripper' is not a moving joint of robot 'lockable'"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("j1, j3, slide, j2, head"), std::string::npos) << msg;
  msg = lock({{"j1", "j1"}, {}});
  EXPECT_NE(msg.find("'j1' is listed twice"), std::string::npos) << msg;
  msg = lock({{"j1"}, {{"j1", 0.0}}});
  EXPECT_NE(msg.find("'j1' is both identified and locked"), std::string::npos) << msg;
  msg = lock({{}, {{"slide", 0.9}}});
  EXPECT_NE(msg.find("'slide' is locked at 0.9, outside its limits [-0.5, 0.5]"), std::string::npos)
      << msg;
  msg = lock({{}, {{"head", 0.1}, {"head", 0.2}}});
  EXPECT_NE(msg.find("'head' is locked twice"), std::string::npos) << msg;
  msg = lock({{}, {{"j1", 0}, {"slide", 0}, {"j2", 0}, {"head", 0}, {"j3", 0}}});
  EXPECT_NE(msg.find("every moving joint"), std::string::npos) << msg;
  msg = lock({{"j2", "j1", "j3"}, {}});  // j2 is carried by j1 (through the locked slide)
  EXPECT_NE(msg.find("joint 'j2' is listed before the joint it is carried by, 'j1'"),
            std::string::npos)
      << msg;
}

TEST(LockJoints, TransmissionKeepsTheKeptJointsAndRefusesACoupledLock) {
  Model model = full();
  model.transmission.N = Eigen::MatrixXd::Identity(5, 5);
  model.transmission.N(0, 0) = 100.0;
  model.transmission.N(3, 3) = 50.0;  // j2
  model.transmission.q_offset = Eigen::VectorXd::LinSpaced(5, 0.1, 0.5);
  const Model locked = lock_joints(model, {{}, {{"slide", 0.0}, {"head", 0.0}}});
  EXPECT_EQ(locked.transmission.N.diagonal(), Eigen::Vector3d(100.0, 1.0, 50.0));
  EXPECT_TRUE(locked.transmission.q_offset.isApprox(Eigen::Vector3d(0.1, 0.2, 0.4)));
  model.transmission.N(2, 3) = 0.5;  // slide and j2 share a motor
  const std::string msg = error_of([&] { lock_joints(model, {{}, {{"slide", 0.0}}}); });
  EXPECT_NE(msg.find("couples locked joint 'slide' with joint 'j2'"), std::string::npos) << msg;
}

TEST(LoadRobotOptions, LocksThroughTheLoader) {
  const std::string path =
      std::string(DYNID_SOURCE_DIR) + "/tests/data/models/planar2_gripper.yaml";
  RobotOptions options;
  options.selection.joints = {"shoulder", "elbow"};
  const LoadedRobot r = load_robot(path, options);
  EXPECT_EQ(r.model.dof(), 2);
  ASSERT_EQ(r.model.locked_joints.size(), 2u);
  EXPECT_EQ(r.model.locked_joints[0].name, "finger");  // model order: depth-first, file order
  EXPECT_EQ(r.model.locked_joints[1].name, "camera_pan");
  EXPECT_NE(r.model.urdf.find("planar2_gripper.urdf"), std::string::npos);
  EXPECT_TRUE(r.warnings.empty());
}

}  // namespace
}  // namespace dynid
