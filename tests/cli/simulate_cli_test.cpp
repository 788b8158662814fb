// `dynid simulate --controller/--gains` (issue 13 item 1) through the binary: the gains file
// written next to the run holds the gains given, reads back as --gains, and a bad gains file is one
// error line with nothing written. Oracle: the gains as written in the test.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

class SimulateCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dynid_simcli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
    // One 2 s period of a sine on both planar2 joints at 200 Hz.
    std::ofstream f(work("traj.csv"));
    f << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
    const double w = M_PI;
    for (int k = 0; k < 400; ++k) {
      const double t = k / 200.0;
      f << t << ',' << 0.3 * std::sin(w * t) << ',' << 0.2 * std::sin(w * t) << ','
        << 0.3 * w * std::cos(w * t) << ',' << 0.2 * w * std::cos(w * t) << ','
        << -0.3 * w * w * std::sin(w * t) << ',' << -0.2 * w * w * std::sin(w * t) << '\n';
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string work(const std::string& name) const { return (dir_ / "work" / name).string(); }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  fs::path dir_;
};

TEST_F(SimulateCli, GainsFileRoundTripsThroughTheRun) {
  std::ofstream(work("gains.yaml")) << "kp: [300, 40]\nki: [10, 2.5]\nkd: [30, 4]\n";
  const auto r = run("simulate --robot planar2 --trajectory " + work("traj.csv") + " --out " +
                     work("run.csv") + " --engine native --periods 2 --controller pid --gains " +
                     work("gains.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json g = nlohmann::json::parse(std::ifstream(work("run.gains.json")));
  EXPECT_EQ(g["controller"], "pid");
  EXPECT_EQ(g["kp"], nlohmann::json({300.0, 40.0}));
  EXPECT_EQ(g["ki"], nlohmann::json({10.0, 2.5}));
  EXPECT_EQ(g["kd"], nlohmann::json({30.0, 4.0}));
  EXPECT_DOUBLE_EQ(g["sample_time"].get<double>(), 0.005);
  // The written file is a gains file: a second run with it writes the same gains.
  const auto r2 = run("simulate --robot planar2 --trajectory " + work("traj.csv") + " --out " +
                      work("run2.csv") + " --engine native --periods 2 --controller pid --gains " +
                      work("run.gains.json"));
  ASSERT_EQ(r2.code, 0) << r2.err;
  const nlohmann::json g2 = nlohmann::json::parse(std::ifstream(work("run2.gains.json")));
  EXPECT_EQ(g2["kp"], g["kp"]);
  EXPECT_EQ(g2["ki"], g["ki"]);
  EXPECT_EQ(g2["kd"], g["kd"]);
}

TEST_F(SimulateCli, DefaultControllerIsFeedForwardAndBadInputIsOneErrorLine) {
  const auto r = run("simulate --robot planar2 --trajectory " + work("traj.csv") + " --out " +
                     work("run.csv") + " --engine native --periods 1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(work("run.gains.json")))["controller"],
            "pid-feedforward");
  std::ofstream(work("bad.yaml")) << "kp: [300, -40]\nki: [0, 0]\nkd: [1, 1]\n";
  const auto bad = run("simulate --robot planar2 --trajectory " + work("traj.csv") + " --out " +
                       work("bad.csv") + " --engine native --gains " + work("bad.yaml"));
  EXPECT_EQ(bad.code, 1);
  EXPECT_EQ(bad.err, "error: gains file " + work("bad.yaml") +
                         ": kp[2] = -40 must be a finite number >= 0\n");
  EXPECT_FALSE(fs::exists(work("bad.csv")));
  EXPECT_FALSE(fs::exists(work("bad.gains.json")));
  const auto usage = run("simulate --robot planar2 --trajectory " + work("traj.csv") + " --out " +
                         work("bad.csv") + " --controller lqr");
  EXPECT_EQ(usage.code, 2);
  EXPECT_NE(
      usage.err.find("--controller must be pid, pid-feedforward or computed-torque, not 'lqr'"),
      std::string::npos)
      << usage.err;
}

}  // namespace
}  // namespace dynid
