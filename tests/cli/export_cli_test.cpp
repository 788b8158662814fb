// dynid export (issue 15 item 3) end to end on a small URDF with a massive link fixed to a moving
// one and elements that carry no dynamics (visual, transmission, gazebo). The identified values are
// written by hand here from masses, centres of mass and inertias about them (parallel-axis theorem
// of the test's own), and read back with dynid's URDF loader.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/model/urdf_loader.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

constexpr const char* kUrdf = R"(<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="2"/>
    <dynamics damping="0.1"/>
  </joint>
  <link name="l1">
    <visual><geometry><box size="0.1 0.1 0.3"/></geometry></visual>
    <inertial><origin xyz="0 0 0.1"/><mass value="2"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="j2" type="revolute">
    <parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.3" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="30" velocity="2"/>
  </joint>
  <link name="l2">
    <inertial><origin xyz="0.2 0 0"/><mass value="1.5"/>
      <inertia ixx="0.005" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/></inertial>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="l2"/><child link="tool"/><origin xyz="0.4 0 0"/>
  </joint>
  <link name="tool">
    <inertial><origin xyz="0 0 0"/><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
  </link>
  <transmission name="t1"><type>transmission_interface/SimpleTransmission</type>
    <joint name="j1"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
  </transmission>
  <gazebo reference="l1"><material>Gazebo/Grey</material></gazebo>
</robot>
)";

// Standard parameters about the link origin, written out: I_O = I_C + m(|c|²·1 − c·cᵀ).
std::vector<double> link(double m, double cx, double cy, double cz, double ixx, double iyy,
                         double izz, double ixy) {
  const double c2 = cx * cx + cy * cy + cz * cz;
  return {ixx + m * (c2 - cx * cx),
          ixy - m * cx * cy,
          -m * cx * cz,
          iyy + m * (c2 - cy * cy),
          -m * cy * cz,
          izz + m * (c2 - cz * cz),
          m * cx,
          m * cy,
          m * cz,
          m};
}

class ExportCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("dynid_export_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
    urdf_ = (dir_ / "work" / "two.urdf").string();
    std::ofstream(urdf_) << kUrdf;
    const std::vector<double> l1 = link(2.4, 0.01, -0.02, 0.12, 0.03, 0.025, 0.012, 0.001);
    const std::vector<double> l2 = link(2.1, 0.25, 0.01, 0.0, 0.006, 0.04, 0.041, -0.002);
    const char* labels[] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"};
    nlohmann::json list = nlohmann::json::array();
    for (int k = 0; k < 10; ++k)
      list.push_back({{"name", labels[k] + std::string("1")}, {"value", l1[k]}});
    for (int k = 0; k < 10; ++k)
      list.push_back({{"name", labels[k] + std::string("2")}, {"value", l2[k]}});
    for (const auto& [name, value] : std::vector<std::pair<std::string, double>>{{"Ia1", 0.3},
                                                                                 {"Fv1", 0.7},
                                                                                 {"Fc1", 1.1},
                                                                                 {"Fo1", -0.2},
                                                                                 {"Fvp2", 0.4},
                                                                                 {"Fvn2", 0.6},
                                                                                 {"Fcp2", 0.9},
                                                                                 {"Fcn2", 1.3}}) {
      list.push_back({{"name", name}, {"value", value}});
    }
    result_ = {{"model", {{"name", "two"}, {"joints", {"j1", "j2"}}}},
               {"standard_parameters", list},
               {"physically_consistent", true}};
    expected_l1_ = l1;
    expected_l2_ = l2;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string work(const std::string& name) const { return (dir_ / "work" / name).string(); }
  std::string write_result(const nlohmann::json& j) const {
    std::ofstream(work("result.json")) << j.dump();
    return work("result.json");
  }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  void expect_refused(const nlohmann::json& j, const std::string& part) const {
    const std::string params = write_result(j);
    const auto r =
        run("export --robot " + urdf_ + " --params " + params + " --out " + work("out.urdf"));
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err << "\nexpected: " << part;
    EXPECT_FALSE(fs::exists(work("out.urdf")));
    EXPECT_FALSE(fs::exists(work("out.urdf.tmp")));
  }

  fs::path dir_;
  std::string urdf_;
  nlohmann::json result_;
  std::vector<double> expected_l1_, expected_l2_;
};

TEST_F(ExportCli, WritesInertialsAndFrictionAndKeepsEverythingElse) {
  const std::string params = write_result(result_);
  const auto r =
      run("export --robot " + urdf_ + " --params " + params + " --out " + work("out.urdf"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("not in the URDF: Ia1 = 0.3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not in the URDF: Fo1 = -0.2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("link tool"), std::string::npos) << r.out;
  std::ifstream in(work("out.urdf"));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* kept : {"<box size=\"0.1 0.1 0.3\"/>", "SimpleTransmission",
                           "EffortJointInterface", "Gazebo/Grey", "<limit lower=\"-2\""}) {
    EXPECT_NE(text.find(kept), std::string::npos) << kept << "\n" << text;
  }
  EXPECT_NE(text.find("Ia1 = 0.3 (armature"), std::string::npos) << text;

  const Model m = load_urdf(work("out.urdf"));
  ASSERT_EQ(m.dof(), 2);
  for (int k = 0; k < 10; ++k) {
    EXPECT_NEAR(m.links[0][k], expected_l1_[k], 1e-14) << k;
    // The tool's inertial is gone: link 2's identified inertia is the whole rigid group's.
    EXPECT_NEAR(m.links[1][k], expected_l2_[k], 1e-14) << k;
  }
  EXPECT_EQ(m.joints[0].friction.Fv, 0.7);
  EXPECT_EQ(m.joints[0].friction.Fc, 1.1);
  EXPECT_EQ(m.joints[0].friction.Ia, 0.0);  // no URDF element holds it
  EXPECT_DOUBLE_EQ(m.joints[1].friction.Fv, 0.5);
  EXPECT_DOUBLE_EQ(m.joints[1].friction.Fc, 1.1);
}

TEST_F(ExportCli, MdhRobotIsWrittenWithItsFrames) {
  // planar2 is an MDH table: the export is a generated URDF with the same joint names.
  nlohmann::json j = result_;
  j["model"] = {{"name", "planar2"}};
  j["standard_parameters"].erase(j["standard_parameters"].begin() + 20,
                                 j["standard_parameters"].end());
  const std::string params = write_result(j);
  const auto r =
      run("export --robot planar2 --params " + params + " --out " + work("planar2.urdf"));
  ASSERT_EQ(r.code, 0) << r.err;
  // planar2's gravity is along −y; URDF cannot say so.
  EXPECT_NE(r.out.find("not in the URDF: gravity = (0, -9.81, 0)"), std::string::npos) << r.out;
  const Model m = load_urdf(work("planar2.urdf"));
  ASSERT_EQ(m.dof(), 2);
  for (int k = 0; k < 10; ++k) EXPECT_NEAR(m.links[1][k], expected_l2_[k], 1e-14) << k;
}

TEST_F(ExportCli, RefusesResultsItCannotExport) {
  nlohmann::json j = result_;
  j.erase("standard_parameters");
  expect_refused(j, "has no standard_parameters; identify with --physical");
  j = result_;
  j["physically_consistent"] = false;
  expect_refused(j, "is not physically consistent");
  j = result_;
  j["model"]["name"] = "puma560";
  expect_refused(j, "was identified on robot 'puma560'");
  j = result_;
  j["model"]["joints"] = {"j1", "jx"};
  expect_refused(j, "names other joints");
  j = result_;
  j["standard_parameters"].erase(j["standard_parameters"].begin() + 19);  // M2
  expect_refused(j, "M2 is missing");
  j = result_;
  j["standard_parameters"][0]["value"] = -1.0;  // XX1 < 0 breaks the triangle inequality
  expect_refused(j, "non-physical inertia");
  j = result_;
  j["standard_parameters"][0]["name"] = "QQ1";
  expect_refused(j, "'QQ1' is not a standard parameter name");
}

// identify --physical with a URDF that has no <inertial> blocks (issue 15 item 8): the fit has
// no nominal inertias to stay close to, so one error line, exit 1, and no result file, instead of
// a "distance to the nominal model" divided by zero.
TEST_F(ExportCli, PhysicalFitRefusesAUrdfWithoutInertials) {
  std::string text = kUrdf;
  for (std::size_t a; (a = text.find("<inertial>")) != std::string::npos;)
    text.erase(a, text.find("</inertial>", a) + std::string("</inertial>").size() - a);
  const std::string bare = work("bare.urdf");
  std::ofstream(bare) << text;
  std::ofstream data(work("run.csv"));
  data << "t,q1,q2,dq1,dq2,ddq1,ddq2,tau1,tau2\n";
  for (int k = 0; k < 2000; ++k) {  // any smooth motion and torque: the fit is refused before use
    const double t = 0.01 * k, s1 = std::sin(0.9 * t), s2 = std::sin(1.7 * t + 0.4);
    data << t << ',' << s1 << ',' << s2 << ',' << 0.9 * std::cos(0.9 * t) << ','
         << 1.7 * std::cos(1.7 * t + 0.4) << ',' << -0.81 * s1 << ',' << -2.89 * s2 << ','
         << 0.3 * s1 + 0.05 * std::cos(5.0 * t) << ',' << 0.2 * s2 + 0.04 * std::sin(4.0 * t)
         << '\n';
  }
  data.close();
  const auto r = run("identify --robot " + bare + " --data " + work("run.csv") +
                     " --filter none --friction viscous --physical --out " + work("p.json"));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
  EXPECT_NE(r.err.find("has no mass on any moving link (a URDF without <inertial> blocks?)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(work("p.json")));
}

}  // namespace
}  // namespace dynid
