// The error contract and "no NaN or Inf leaves dynid" at the command line (issue 10). Each test
// reproduces a failure of the issue: the exit code, one `error:` line naming the input and the fix,
// no library text, no control characters, no output file left behind. Runs are generated here
// from the planar 2R closed form (tests/support/planar2.hpp with the numbers of the built-in
// planar2, docs/methods/model.md), not by dynid.

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"
#include "support/planar2.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Contract : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dynid_contract_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// `dynid <args>`: args are shell words (single-quote paths with odd bytes).
  CliRun run(const std::string& args) const {
    const std::string command = std::string("'") + DYNID_BINARY + "' " + args + " >'" +
                                (dir_ / "out.txt").string() + "' 2>'" +
                                (dir_ / "err.txt").string() + "' </dev/null";
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir_ / "out.txt"),
            slurp(dir_ / "err.txt")};
  }
  std::string work(const std::string& name) const { return (dir_ / "work" / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(work(name), std::ios::binary) << text;
    return work(name);
  }
  /// A planar2 run (2000 samples at 100 Hz); `edit(k, row)` may change sample k's values
  /// t, q1, q2, dq1, dq2, ddq1, ddq2, tau1, tau2 before it is written.
  std::string planar2_run(const std::string& name,
                          const std::function<void(int, double*)>& edit = {}) const {
    testing::Planar2 arm;  // the built-in planar2: uniform rods of 1 m and 0.8 m
    arm.I1 = 2.0 / 12;
    arm.I2 = 1.5 * 0.64 / 12;
    std::ostringstream s;
    s.precision(17);
    s << "t,q1,q2,dq1,dq2,ddq1,ddq2,tau1,tau2\n";
    for (int k = 0; k < 2000; ++k) {
      const double t = k * 0.01;
      const Eigen::Vector2d q(std::sin(0.7 * t) + 0.3 * std::sin(2.1 * t), 0.8 * std::cos(1.3 * t));
      const Eigen::Vector2d dq(0.7 * std::cos(0.7 * t) + 0.63 * std::cos(2.1 * t),
                               -1.04 * std::sin(1.3 * t));
      const Eigen::Vector2d ddq(-0.49 * std::sin(0.7 * t) - 1.323 * std::sin(2.1 * t),
                                -1.352 * std::cos(1.3 * t));
      const Eigen::Vector2d tau = arm.torque(q, dq, ddq);
      double row[9] = {t, q[0], q[1], dq[0], dq[1], ddq[0], ddq[1], tau[0], tau[1]};
      if (edit) edit(k, row);
      for (int c = 0; c < 9; ++c) s << (c ? "," : "") << row[c];
      s << '\n';
    }
    return write(name, s.str());
  }

  /// Exit `code`; stderr ends in the one "error: " line (after the command's echo, if any),
  /// containing `part`, printable ASCII or UTF-8 only, no bracketed library tag.
  static void expect_error(const CliRun& r, int code, const std::string& part) {
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(dynid::testing::error_contract_problem(r.err), "") << r.err;
    EXPECT_EQ(r.err.find("[json.exception"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err << "\nexpected: " << part;
  }

  fs::path dir_;
};

TEST_F(Contract, UnknownCommandIsNamed) {
  expect_error(run("foo --robot planar2"), 2, "unknown command 'foo'; commands are model,");
}

TEST_F(Contract, NamesWithNewlinesAndRawBytesAreEscaped) {
  const CliRun r = run("model --robot '/no/such\nrobot\xff.urdf'");
  expect_error(r, 1, "such\\nrobot\\xFF.urdf");
}

TEST_F(Contract, FileNameThatIsNotUtf8IsWrittenAsReplacement) {
  const std::string data = planar2_run("run\xff.csv");
  const std::string out = work("result.json");
  const CliRun r = run("identify --robot planar2 --friction none --no-armature --data '" + data +
                       "' --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_NE(j["options"]["data"].get<std::string>().find("run\xEF\xBF\xBD.csv"), std::string::npos);
}

TEST_F(Contract, ResultFileWithWrongTypesOrValuesIsBlamedOnTheFile) {
  const std::string data = planar2_run("run.csv");
  const std::string result = work("result.json");
  ASSERT_EQ(run("identify --robot planar2 --data " + data + " --out " + result).code, 0);
  std::ifstream in(result);
  nlohmann::json j = nlohmann::json::parse(in);
  j["options"]["friction"] = 5;
  write("typed.json", j.dump());
  expect_error(run("validate --robot planar2 --params " + work("typed.json") + " --data " + data),
               1, "typed.json': options.friction has the wrong type (number)");
  j["options"]["friction"] = "magic";
  write("valued.json", j.dump());
  expect_error(run("validate --robot planar2 --params " + work("valued.json") + " --data " + data),
               1, "valued.json': options.friction: unknown term 'magic'");
  j["options"]["friction"] = "viscous,coulomb,offset";
  j["options"]["zero_velocity"] = {0.1, 0.2, 0.3};  // three values for two joints
  j.erase("zero_velocity_threshold");  // an older result: validate falls back to the option
  write("counted.json", j.dump());
  expect_error(run("validate --robot planar2 --params " + work("counted.json") + " --data " + data),
               1, "counted.json': options.zero_velocity takes 1 or 2 values, got 3");
  j["options"] = "none";
  write("options.json", j.dump());
  expect_error(run("validate --robot planar2 --params " + work("options.json") + " --data " + data),
               1, "'options' must be an object");
}

TEST_F(Contract, ExtremeParameterValuesGiveAnErrorNotNullErrors) {
  const std::string data = planar2_run("run.csv");
  const std::string result = work("result.json");
  ASSERT_EQ(run("identify --robot planar2 --data " + data + " --out " + result).code, 0);
  std::ifstream in(result);
  nlohmann::json j = nlohmann::json::parse(in);
  for (auto& p : j["parameters"]) p["value"] = 1e300;
  write("extreme.json", j.dump());
  const std::string errors = work("errors.json");
  expect_error(run("validate --robot planar2 --params " + work("extreme.json") + " --data " + data +
                   " --json " + errors),
               1, "the predicted torques overflow");
  EXPECT_FALSE(fs::exists(errors));
}

TEST_F(Contract, InverseDynamicsOnHugeVelocityNamesTheRow) {
  const std::string in = write("states.csv",
                               "q1,q2,dq1,dq2,ddq1,ddq2\n"
                               "0,0,0,0,0,0\n"
                               "0.1,0.2,1e155,0,0,0\n");
  const std::string out = work("tau.csv");
  expect_error(run("inverse-dynamics --robot planar2 --in " + in + " --out " + out), 1,
               "states.csv line 3: the torques overflow");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Contract, HugeTorqueSampleIsReportedAndCanBeDropped) {
  const std::string data =
      planar2_run("run.csv", [](int k, double* row) { row[8] = k == 523 ? 1e200 : row[8]; });
  const std::string out = work("result.json");
  expect_error(run("identify --robot planar2 --data " + data + " --out " + out), 1,
               "tau2 at sample 524 (t = 5.23 s) = 1e+200");
  EXPECT_FALSE(fs::exists(out));
  const CliRun r = run("identify --robot planar2 --outliers drop --data " + data + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_FALSE(j["warnings"].empty());
  EXPECT_NE(j["warnings"][0].get<std::string>().find("replaced by the median"), std::string::npos);
  EXPECT_EQ(j["options"]["outliers"], "drop");
  for (const auto& p : j["parameters"]) EXPECT_TRUE(p["value"].is_number()) << p;
  expect_error(run("identify --robot planar2 --outliers maybe --data " + data + " --out " + out), 2,
               "--outliers must be report or drop");
}

TEST_F(Contract, ImplausibleUnitsAreErrors) {
  const std::string out = work("result.json");
  const std::string ms =
      planar2_run("ms.csv", [](int, double* row) { row[0] *= 1000.0; });  // 100 Hz in ms
  expect_error(run("identify --robot planar2 --data " + ms + " --out " + out), 1,
               "divide milliseconds by 1000");
  const std::string zero = planar2_run("zero.csv", [](int, double* row) { row[7] = row[8] = 0; });
  expect_error(run("identify --robot planar2 --data " + zero + " --out " + out), 1,
               "torque is zero in every sample");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Contract, StreamRejectsTheFlagsItCannotHonour) {
  const std::string data = planar2_run("run.csv");
  const std::string out = work("result.json");
  const std::string stream =
      "identify --robot planar2 --stream --filter none --data " + data + " --out " + out + " ";
  for (const std::string flag : {"--time-shift 0.005", "--decimate 2", "--trim 3", "--savgol",
                                 "--filter-coulomb", "--cutoff 5"}) {
    const std::string name = flag.substr(0, flag.find(' '));
    expect_error(run(stream + flag), 2, name + " cannot be used with --stream");
  }
  expect_error(run(stream + "--outliers drop"), 2, "--outliers drop cannot be used with --stream");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Contract, NonFiniteAndNegativeNumericFlagsAreUsageErrors) {
  const std::string data = planar2_run("run.csv");
  const std::string out = work("result.json");
  const std::string identify =
      "identify --robot planar2 --data " + data + " --out " + out + " --stream --filter none ";
  expect_error(run(identify + "--torque-offset nan"), 2, "--torque-offset");
  expect_error(run(identify + "--zero-velocity nan"), 2, "--zero-velocity");
  expect_error(run(identify + "--rate nan"), 2, "--rate");
  expect_error(run(identify + "--rate inf"), 2, "is not a finite number");
  expect_error(run(identify + "--cutoff -3"), 2, "--cutoff: must be >= 0, not -3");
  expect_error(run("simulate --robot planar2 -t " + data + " -o " + out + " --torque-noise -1"), 2,
               "--torque-noise");
  expect_error(run("excite --robot planar2 -o " + out + " --f0 1e999"), 2, "--f0");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Contract, ExciteWithOneHarmonicIsRefused) {
  const std::string out = work("traj.csv");
  expect_error(run("excite --robot puma560 --harmonics 1 --max-time 0 -o " + out), 2,
               "--harmonics 1 leaves no free coefficient");
  EXPECT_FALSE(fs::exists(out));
}

// One period (4 s) of a planar2 reference at 100 Hz: t, q*, dq*, ddq*; `corrupt` puts 1e12 in
// ddq1 at t = 1 s (the computed-torque feed-forward then saturates).
std::string planar2_reference(bool corrupt) {
  std::ostringstream ref;
  ref.precision(17);
  ref << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
  const double w = M_PI / 2;
  for (int k = 0; k < 400; ++k) {
    const double t = k * 0.01;
    ref << t << ',' << 0.5 * std::sin(w * t) << ',' << 0.3 * std::sin(w * t) << ','
        << 0.5 * w * std::cos(w * t) << ',' << 0.3 * w * std::cos(w * t) << ','
        << (corrupt && k == 100 ? 1e12 : -0.5 * w * w * std::sin(w * t)) << ','
        << -0.3 * w * w * std::sin(w * t) << '\n';
  }
  return ref.str();
}

TEST_F(Contract, SimulateOverflowAndDivergenceAreErrorsWithoutMujocoOutput) {
  const std::string out = work("sim.csv");
  const std::string corrupt = write("corrupt.csv", planar2_reference(true));
  CliRun r = run("simulate --robot planar2 --periods 1 -t " + corrupt + " -o " + out);
  expect_error(r, 1, "diverged");
  EXPECT_EQ(r.out.find("WARNING"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out));
  const std::string clean = write("clean.csv", planar2_reference(false));
  r = run("simulate --robot planar2 --periods 1 --torque-noise 1e308 -t " + clean + " -o " + out);
  expect_error(r, 1, "logged torques are not finite");
  EXPECT_FALSE(fs::exists(out));
  r = run("simulate --robot planar2 --periods 1 -t " + clean + " -o " + out);
  EXPECT_EQ(r.code, 0) << r.err;
}

}  // namespace
}  // namespace dynid
