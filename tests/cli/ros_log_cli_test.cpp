// Issue 26 item 9 through the dynid binary: a run given as a ROS log (ROS 1 bag, ROS 2 .db3,
// rostopic echo -p and PlotJuggler CSV) identifies and validates as the same run given as a CSV.
// Oracle: a planar2 run generated from the closed form of docs/methods/model.md (not by dynid),
// in messages that name the joints in another order than the model and carry epoch stamps; the
// result must equal that of the same numbers written as a t,q_<joint>,dq_<joint>,tau_<joint>
// CSV (to 1e-9), which is itself within 1e-3 of the closed form's ZZ1R.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"
#include "support/planar2.hpp"
#include "support/ros_logs.hpp"

namespace {

using RosCliRun = dynid::testing::CliResult;
using dynid::testing::TestJointState;

constexpr int kRosCliSamples = 1500;
constexpr double kRosCliDt = 0.01;
constexpr std::int64_t kRosCliEpochNs = 1'733'580'000'000'000'000;
// ZZ1R = ZZ1 + l1²·M2 of the closed-form arm: I1 + m1·c1² + m2·l1².
constexpr double kRosCliZz1r = 2.0 / 12 + 2.0 * 0.25 + 1.5;

// Sample k as a JointState naming elbow first (the model's order is shoulder, elbow).
TestJointState ros_cli_message(int k) {
  const dynid::testing::Planar2Sample s = dynid::testing::planar2_sample(k, kRosCliDt);
  TestJointState m;
  m.stamp_ns = kRosCliEpochNs + 10'000'000LL * k;
  m.frame_id = "base_link";
  m.name = {"elbow", "shoulder"};
  m.position = {s.q[1], s.q[0]};
  m.velocity = {s.dq[1], s.dq[0]};
  m.effort = {s.tau[1], s.tau[0]};
  return m;
}

class RosLogCli : public dynid::testing::CliScratchTest {
 protected:
  static double zz1r(const std::string& result) {
    const nlohmann::json r = nlohmann::json::parse(std::ifstream(result));
    for (const auto& p : r["parameters"])
      if (p["name"] == "ZZ1R") return p["value"].get<double>();
    return NAN;
  }
  // ZZ1R identified from `data` (extra flags `more`); `echo` receives stderr.
  double identify(const std::string& data, const std::string& more = "",
                  std::string* echo = nullptr) const {
    const std::string result = path("result.json");
    const RosCliRun id = run("identify --robot planar2 --data " + data + more +
                             " --filter none --friction none --no-armature --out " + result);
    EXPECT_EQ(id.code, 0) << id.err;
    if (echo) *echo = id.err;
    return zz1r(result);
  }
  // The same run as a CSV with the same numbers (t as the readers compute it from the stamps):
  // the ROS readers must give exactly its result. Against the closed form, ZZ1R is within 1e-3:
  // a JointState has no accelerations, and central differences of q̇ at 100 Hz err by
  // O(dt²·ω²/6) ≈ 1e-4 relative.
  void expect_as_csv(const std::string& data, const std::string& more = "",
                     std::string* echo = nullptr) const {
    std::ofstream csv(path("same.csv"));
    csv << "t,q_shoulder,q_elbow,dq_shoulder,dq_elbow,tau_shoulder,tau_elbow\n";
    for (int k = 0; k < kRosCliSamples; ++k) {
      const TestJointState m = ros_cli_message(k);
      char line[400];
      std::snprintf(line, sizeof(line), "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                    static_cast<double>(m.stamp_ns - kRosCliEpochNs) * 1e-9, m.position[1],
                    m.position[0], m.velocity[1], m.velocity[0], m.effort[1], m.effort[0]);
      csv << line;
    }
    csv.close();
    const double reference = identify(path("same.csv"));
    EXPECT_NEAR(reference, kRosCliZz1r, 1e-3);
    EXPECT_NEAR(identify(data, more, echo), reference, 1e-9 * reference) << data;
  }
  std::string write_bag(const std::string& name, const std::string& topic) const {
    std::vector<dynid::testing::TestLogEntry> entries;
    for (int k = 0; k < kRosCliSamples; ++k) {
      const TestJointState m = ros_cli_message(k);
      entries.push_back({topic, m.stamp_ns + 2'000'000, m});
    }
    dynid::testing::write_ros1_bag(path(name), entries, dynid::testing::BagCompression::kLz4);
    return path(name);
  }
};

TEST_F(RosLogCli, IdentifyAndValidateFromARos1Bag) {
  const std::string bag = write_bag("run.bag", "/joint_states");
  std::string echo;
  expect_as_csv(bag, "", &echo);
  EXPECT_NE(echo.find("t = header.stamp - 1733580000.000000000 s"), std::string::npos) << echo;
  // validate reads the bag as the CSV of the same numbers.
  double error[2] = {};
  for (int i = 0; i < 2; ++i) {
    const RosCliRun v =
        run("validate --robot planar2 --params " + path("result.json") + " --data " +
            (i ? path("same.csv") : bag) + " --json " + path("val.json"));
    ASSERT_EQ(v.code, 0) << v.err;
    error[i] = nlohmann::json::parse(std::ifstream(path("val.json")))["relative_error_all_rows"]
                   .get<double>();
  }
  EXPECT_LT(error[0], 1e-5);
  EXPECT_NEAR(error[0], error[1], 1e-9);
  // --stream reads CSV in chunks; a log is read in memory, and the flag is refused.
  expect_error(run("identify --robot planar2 --data " + bag + " --stream --out " + path("x.json")),
               2, {"--stream", "is a ROS log", "drop --stream"});
  // Another topic, chosen with --topic; a wrong one is one error line naming the topics.
  const std::string arm = write_bag("arm.bag", "/arm/joint_states");
  expect_as_csv(arm, " --topic /arm/joint_states");
  expect_error(
      run("identify --robot planar2 --data " + arm + " --topic /js --out " + path("x.json")), 1,
      {"has no topic /js", "/arm/joint_states", "--topic"});
  EXPECT_FALSE(std::ifstream(path("x.json")).good());
}

TEST_F(RosLogCli, IdentifyFromARos2Bag) {
  std::vector<dynid::testing::TestRecord> records;
  for (int k = 0; k < kRosCliSamples; ++k) {
    const TestJointState m = ros_cli_message(k);
    records.push_back({0, m.stamp_ns + 1'000'000, dynid::testing::cdr_joint_state(m)});
  }
  // The bag folder as ros2 bag record writes it, given as the folder and as its .db3 file.
  std::filesystem::create_directories(path("bag"));
  std::ofstream(path("bag/metadata.yaml")) << "rosbag2_bagfile_information:\n";
  dynid::testing::write_ros2_db3(path("bag/bag_0.db3"),
                                 {{"/joint_states", "sensor_msgs/msg/JointState"}}, records);
  expect_as_csv(path("bag"));
  expect_as_csv(path("bag/bag_0.db3"));
}

TEST_F(RosLogCli, IdentifyFromRostopicAndPlotJugglerCsv) {
  std::ofstream rostopic(path("rostopic.csv"));
  rostopic << "%time,field.header.seq,field.header.stamp,field.header.frame_id,field.name0,"
              "field.name1,field.position0,field.position1,field.velocity0,field.velocity1,"
              "field.effort0,field.effort1\n";
  std::ofstream pj(path("pj.csv"));
  pj << "__time,/joint_states/elbow/position,/joint_states/elbow/velocity,"
        "/joint_states/elbow/effort,/joint_states/shoulder/position,"
        "/joint_states/shoulder/velocity,/joint_states/shoulder/effort\n";
  for (int k = 0; k < kRosCliSamples; ++k) {
    const TestJointState m = ros_cli_message(k);
    char line[600];
    std::snprintf(
        line, sizeof(line), "%lld,%d,%lld,,elbow,shoulder,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
        static_cast<long long>(m.stamp_ns + 3'000'000), k, static_cast<long long>(m.stamp_ns),
        m.position[0], m.position[1], m.velocity[0], m.velocity[1], m.effort[0], m.effort[1]);
    rostopic << line;
    std::snprintf(line, sizeof(line), "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", k * kRosCliDt,
                  m.position[0], m.velocity[0], m.effort[0], m.position[1], m.velocity[1],
                  m.effort[1]);
    pj << line;
  }
  rostopic.close();
  pj.close();
  std::string echo;
  expect_as_csv(path("rostopic.csv"), "", &echo);
  EXPECT_NE(echo.find("rostopic echo -p output"), std::string::npos) << echo;
  expect_as_csv(path("pj.csv"), "", &echo);
  EXPECT_NE(echo.find("PlotJuggler CSV"), std::string::npos) << echo;
}

// validate reads the topic identify read (stored in the result), unless --topic says otherwise.
TEST_F(RosLogCli, ValidateReadsTheTopicIdentifyRead) {
  std::vector<dynid::testing::TestLogEntry> entries;
  for (int k = 0; k < kRosCliSamples; ++k) {
    const TestJointState m = ros_cli_message(k);
    entries.push_back({"/right/joint_states", m.stamp_ns, m});
    TestJointState other = m;
    for (double& x : other.effort) x *= 2;  // another arm: not what the parameters predict
    entries.push_back({"/left/joint_states", m.stamp_ns + 1, other});
  }
  dynid::testing::write_ros1_bag(path("two.bag"), entries);
  const std::string result = path("result.json");
  const RosCliRun id = run("identify --robot planar2 --data " + path("two.bag") +
                           " --topic /right/joint_states --filter none --friction none "
                           "--no-armature --out " +
                           result);
  ASSERT_EQ(id.code, 0) << id.err;
  EXPECT_NEAR(zz1r(result), kRosCliZz1r, 1e-3);
  const std::string val = path("val.json");
  const RosCliRun v = run("validate --robot planar2 --params " + result + " --data " +
                          path("two.bag") + " --json " + val);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.err.find("--topic as given to identify"), std::string::npos) << v.err;
  EXPECT_LT(nlohmann::json::parse(std::ifstream(val))["relative_error_all_rows"].get<double>(),
            1e-5);
  // The other arm, by --topic: half its torque unexplained.
  const RosCliRun left = run("validate --robot planar2 --params " + result + " --data " +
                             path("two.bag") + " --topic /left/joint_states --json " + val);
  ASSERT_EQ(left.code, 0) << left.err;
  EXPECT_NEAR(nlohmann::json::parse(std::ifstream(val))["relative_error_all_rows"].get<double>(),
              0.5, 1e-3);
}

// A log of some of the robot's joints (an arm's driver, a robot file with more joints): the
// joints the messages do not name are held at 0, as for a CSV header naming some joints.
// Oracle: the shoulder alone moving, the elbow at 0, from the closed form; the merged link's ZZ
// about the shoulder is I1 + m1·c1² + I2 + m2·(l1 + c2)².
TEST_F(RosLogCli, ABagOfSomeJointsLocksTheOthers) {
  dynid::testing::Planar2 arm;
  arm.I1 = 2.0 / 12;
  arm.I2 = 1.5 * 0.64 / 12;
  std::vector<dynid::testing::TestLogEntry> entries;
  std::ofstream csv(path("shoulder.csv"));
  csv << "t,q_shoulder,dq_shoulder,tau_shoulder\n";
  for (int k = 0; k < kRosCliSamples; ++k) {
    const dynid::testing::Planar2Sample s = dynid::testing::planar2_sample(k, kRosCliDt);
    TestJointState m;
    m.stamp_ns = kRosCliEpochNs + 10'000'000LL * k;
    m.name = {"shoulder"};
    m.position = {s.q[0]};
    m.velocity = {s.dq[0]};
    m.effort = {arm.torque({s.q[0], 0.0}, {s.dq[0], 0.0}, {s.ddq[0], 0.0})[0]};
    entries.push_back({"/joint_states", m.stamp_ns, m});
    char line[200];
    std::snprintf(line, sizeof(line), "%.17g,%.17g,%.17g,%.17g\n",
                  static_cast<double>(m.stamp_ns - kRosCliEpochNs) * 1e-9, m.position[0],
                  m.velocity[0], m.effort[0]);
    csv << line;
  }
  csv.close();
  dynid::testing::write_ros1_bag(path("shoulder.bag"), entries);
  nlohmann::json result[2];
  for (int i = 0; i < 2; ++i) {
    const RosCliRun id =
        run("identify --robot planar2 --data " + path(i ? "shoulder.csv" : "shoulder.bag") +
            " --filter none --friction none --no-armature --out " + path("result.json"));
    ASSERT_EQ(id.code, 0) << id.err;
    EXPECT_NE(id.err.find("locked joints"), std::string::npos) << id.err;
    EXPECT_NE(id.err.find("elbow=0"), std::string::npos) << id.err;
    result[i] = nlohmann::json::parse(std::ifstream(path("result.json")));
  }
  ASSERT_EQ(result[0]["parameters"].size(), result[1]["parameters"].size());
  bool zz = false;
  for (std::size_t p = 0; p < result[0]["parameters"].size(); ++p) {
    const auto& a = result[0]["parameters"][p];
    EXPECT_EQ(a["name"], result[1]["parameters"][p]["name"]);
    EXPECT_NEAR(a["value"].get<double>(), result[1]["parameters"][p]["value"].get<double>(),
                1e-9 * (1 + std::abs(a["value"].get<double>())));
    if (a["name"].get<std::string>().rfind("ZZ1", 0) == 0) {
      zz = true;
      EXPECT_NEAR(a["value"].get<double>(), 2.0 / 12 + 2.0 * 0.25 + 0.08 + 1.5 * 1.4 * 1.4, 1e-3);
    }
  }
  EXPECT_TRUE(zz) << result[0].dump();
}

// A log without efforts cannot be identified: the error names the topic and the field.
TEST_F(RosLogCli, MissingEffortIsOneErrorNamingTheField) {
  std::vector<dynid::testing::TestLogEntry> entries;
  for (int k = 0; k < 10; ++k) {
    TestJointState m = ros_cli_message(k);
    m.effort.clear();
    entries.push_back({"/joint_states", m.stamp_ns, m});
  }
  dynid::testing::write_ros1_bag(path("no_effort.bag"), entries);
  expect_error(
      run("identify --robot planar2 --data " + path("no_effort.bag") + " --out " + path("x.json")),
      1, {"topic /joint_states message 1: the effort array is empty"});
}

}  // namespace
