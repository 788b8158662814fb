// `dynid simulate --controller computed-torque`, `dynid compare-control` and `dynid validate
// --mode simulation --controller/--gains/--histograms` (issue 14 items 6 and 8) through the binary,
// on planar2 with the native plant: the JSON contract, the gains file read beside the run, and
// bad input as one error line with nothing written.
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

class ControlCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("dynid_controlcli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
    // One 4 s period of two harmonics per joint at 200 Hz.
    std::ofstream f(work("traj.csv"));
    f << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
    const double w = M_PI / 2;
    for (int k = 0; k < 800; ++k) {
      const double t = k / 200.0;
      const double q1 = 0.6 * std::sin(w * t) + 0.2 * std::sin(3 * w * t + 1);
      const double q2 = 0.4 * std::sin(2 * w * t) + 0.3 * std::cos(w * t) - 0.3;
      const double dq1 = 0.6 * w * std::cos(w * t) + 0.6 * w * std::cos(3 * w * t + 1);
      const double dq2 = 0.8 * w * std::cos(2 * w * t) - 0.3 * w * std::sin(w * t);
      const double ddq1 = -0.6 * w * w * std::sin(w * t) - 1.8 * w * w * std::sin(3 * w * t + 1);
      const double ddq2 = -1.6 * w * w * std::sin(2 * w * t) - 0.3 * w * w * std::cos(w * t);
      f << t << ',' << q1 << ',' << q2 << ',' << dq1 << ',' << dq2 << ',' << ddq1 << ',' << ddq2
        << '\n';
    }
    f.close();
    // A PID run with noise, identified: the model of the computed-torque controller.
    const auto sim = run("simulate --robot planar2 --trajectory " + work("traj.csv") + " --out " +
                         work("pid.csv") +
                         " --engine native --periods 5 --controller pid --torque-noise 0.02 "
                         "--position-noise 1e-5");
    ASSERT_EQ(sim.code, 0) << sim.err;
    const auto id =
        run("identify --robot planar2 --data " + work("pid.csv") + " --out " + work("result.json"));
    ASSERT_EQ(id.code, 0) << id.err;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string work(const std::string& name) { return (dir_ / "work" / name).string(); }
  static testing::CliResult run(const std::string& args) { return testing::run_dynid(args, dir_); }
  static fs::path dir_;
};

fs::path ControlCli::dir_;

TEST_F(ControlCli, CompareControlWritesTheControllersContract) {
  const auto r =
      run("compare-control --robot planar2 --params " + work("result.json") + " --trajectory " +
          work("traj.csv") + " --engine native --json " + work("cmp.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(work("cmp.json")));
  ASSERT_EQ(j["controllers"].size(), 2u);
  EXPECT_EQ(j["controllers"][0]["name"], "pid");
  EXPECT_EQ(j["controllers"][1]["name"], "computed-torque");
  for (const auto& c : j["controllers"]) {
    ASSERT_EQ(c["joints"].size(), 2u);
    for (const auto& joint : c["joints"]) {
      EXPECT_GT(joint["rms"].get<double>(), 0.0);
      EXPECT_GE(joint["max"].get<double>(), joint["rms"].get<double>());
      EXPECT_LE(joint["max_at_reversal"].get<double>(), joint["max"].get<double>());
    }
  }
  // The identified model's controller cuts the peak at reversals (seed 2 Fig. 9).
  for (int k = 0; k < 2; ++k)
    EXPECT_LT(j["controllers"][1]["joints"][k]["max_at_reversal"].get<double>(),
              j["controllers"][0]["joints"][k]["max_at_reversal"].get<double>());
  EXPECT_NE(r.out.find("computed-torque"), std::string::npos) << r.out;
  // A run of both joints determines every base parameter: nothing from the nominal model.
  EXPECT_EQ(j["parameter_sources"]["nominal_not_excited"].size(), 0u);
  EXPECT_GT(j["parameter_sources"]["identified"].size(), 0u);
}

TEST_F(ControlCli, SimulateComputedTorqueAndValidateReadTheGainsBesideTheRun) {
  const auto sim =
      run("simulate --robot planar2 --trajectory " + work("traj.csv") + " --out " + work("ct.csv") +
          " --engine native --periods 2 --controller "
          "computed-torque --params " +
          work("result.json"));
  ASSERT_EQ(sim.code, 0) << sim.err;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(work("ct.gains.json")))["controller"],
            "computed-torque");
  const auto v = run("validate --mode simulation --robot planar2 --params " + work("result.json") +
                     " --data " + work("ct.csv") + " --trajectory " + work("traj.csv") +
                     " --engine native --histograms " + work("h.csv"));
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.err.find("ct.gains.json"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("computed-torque"), std::string::npos) << v.err;
  std::ifstream h(work("h.csv"));
  std::string header, line;
  std::getline(h, header);
  EXPECT_EQ(header.rfind("q_err1,q_pdf1,q_gauss1,tau_err1,tau_pdf1,tau_gauss1,q_err2", 0), 0u)
      << header;
  int rows = 0;
  while (std::getline(h, line))
    if (!line.empty() && line[0] != '#') ++rows;
  EXPECT_EQ(rows, 30);
}

TEST_F(ControlCli, BadInputIsOneErrorLine) {
  const auto no_params = run("simulate --robot planar2 --trajectory " + work("traj.csv") +
                             " --out " + work("x.csv") + " --controller computed-torque");
  EXPECT_EQ(no_params.code, 2);
  EXPECT_EQ(testing::error_contract_problem(no_params.err), "") << no_params.err;
  EXPECT_FALSE(fs::exists(work("x.csv")));
  const auto periods =
      run("compare-control --robot planar2 --params " + work("result.json") + " --trajectory " +
          work("traj.csv") + " --periods 1 --json " + work("y.json"));
  EXPECT_EQ(periods.code, 2);
  EXPECT_EQ(testing::error_contract_problem(periods.err), "") << periods.err;
  EXPECT_FALSE(fs::exists(work("y.json")));
  const auto missing = run("compare-control --robot planar2 --params " + work("none.json") +
                           " --trajectory " + work("traj.csv"));
  EXPECT_EQ(missing.code, 1);
  EXPECT_EQ(testing::error_contract_problem(missing.err), "") << missing.err;
  // A hand-edited covariance_matrix of the wrong size is blamed on the file (exit 1, no output).
  nlohmann::json result = nlohmann::json::parse(std::ifstream(work("result.json")));
  result["covariance_matrix"] = nlohmann::json::array({nlohmann::json::array({1.0})});
  std::ofstream(work("edited.json")) << result.dump();
  const auto edited =
      run("compare-control --robot planar2 --params " + work("edited.json") + " --trajectory " +
          work("traj.csv") + " --engine native --json " + work("z.json"));
  EXPECT_EQ(edited.code, 1);
  EXPECT_EQ(testing::error_contract_problem(edited.err), "") << edited.err;
  EXPECT_NE(edited.err.find("covariance_matrix"), std::string::npos) << edited.err;
  EXPECT_FALSE(fs::exists(work("z.json")));
}

}  // namespace
}  // namespace dynid
