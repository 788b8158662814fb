// The error contract and "no NaN or Inf leaves dynid" at the command line (issue 10). Each test
// reproduces a failure of the issue: the exit code, one `error:` line naming the input and the fix,
// no library text, no control characters, no output file left behind. Runs are generated here
// from the planar 2R closed form (tests/support/planar2.hpp with the numbers of the built-in
// planar2, docs/methods/model.md), not by dynid.

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/model/model.hpp"
#include "support/chain_urdf.hpp"
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
    // `timeout`: a command that hangs (a FIFO read, unbounded work) fails its test instead of
    // stopping the suite.
    const std::string command = std::string("timeout 600 '") + DYNID_BINARY + "' " + args + " >'" +
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

// Issue 27 item 3: one corrupt sample gave an all-NaN result with exit 0 on every path but the
// in-memory differential model, and one q sample of 1e155 a garbage fit blamed on the
// excitation. Every path now refuses the sample by name, and writes nothing.
TEST_F(Contract, CorruptSampleIsRefusedOnEveryPath) {
  const std::string tau =
      planar2_run("tau.csv", [](int k, double* row) { row[8] = k == 523 ? 1e200 : row[8]; });
  const std::string q =
      planar2_run("q.csv", [](int k, double* row) { row[1] = k == 523 ? 1e155 : row[1]; });
  const std::string dq =
      planar2_run("dq.csv", [](int k, double* row) { row[3] = k == 523 ? -1e150 : row[3]; });
  const std::string out = work("result.json");
  for (const std::string model : {"", "--stream --filter none", "--model friction --joint 1",
                                  "--model gravity --joint 1", "--model decoupled --joint 1"}) {
    const bool stream = model.rfind("--stream", 0) == 0;
    expect_error(run("identify --robot planar2 " + model + " --data " + tau + " --out " + out), 1,
                 stream ? "'" + tau + "' data row 524: tau2 = 1e+200"
                        : "tau2 at sample 524 (t = 5.23 s) = 1e+200 is a corrupt sample");
    EXPECT_FALSE(fs::exists(out)) << model;
    expect_error(run("identify --robot planar2 " + model + " --data " + q + " --out " + out), 1,
                 stream ? "'" + q + "' data row 524: q1 = 1e+155"
                        : "q1 at sample 524 (t = 5.23 s) = 1e+155 is a corrupt sample");
    EXPECT_FALSE(fs::exists(out)) << model;
    // A velocity column given in the file is screened as well (it is used as given).
    expect_error(run("identify --robot planar2 " + model + " --data " + dq + " --out " + out), 1,
                 stream ? "'" + dq + "' data row 524: dq1 = -1e+150"
                        : "dq1 at sample 524 (t = 5.23 s) = -1e+150 is a corrupt sample");
    EXPECT_FALSE(fs::exists(out)) << model;
  }
  // validate's simulation statistics: the measured run is screened too.
  const std::string clean = planar2_run("clean.csv");
  const std::string params = work("params.json");
  ASSERT_EQ(run("identify --robot planar2 --data " + clean + " --out " + params).code, 0);
  std::ostringstream reference;
  reference << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
  std::ifstream in(clean);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::stringstream fields(line);
    std::string field;
    for (int c = 0; c < 7 && std::getline(fields, field, ','); ++c) {
      reference << (c ? "," : "") << field;
    }
    reference << '\n';
  }
  const std::string trajectory = write("reference.csv", reference.str());
  const std::string json = work("validation.json");
  expect_error(run("validate --robot planar2 --params " + params +
                   " --mode simulation --engine native --trajectory " + trajectory + " --data " +
                   tau + " --json " + json),
               1, "measured tau2 at sample 524 = 1e+200 is a corrupt sample");
  EXPECT_FALSE(fs::exists(json));
}

// Issue 27 item 4: every reader opened a FIFO and waited for a writer forever.
TEST_F(Contract, FifoInputsAreRefusedNotWaitedOn) {
  const std::string fifo = work("fifo.csv"), urdf = work("fifo.urdf"), out = work("r.json");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(urdf.c_str(), 0600), 0);
  const std::string data = planar2_run("run.csv");
  expect_error(run("identify --robot planar2 --data " + fifo + " --out " + out), 1,
               "not a regular file (a FIFO)");
  expect_error(run("identify --robot " + urdf + " --data " + data + " --out " + out), 1,
               "robot file '" + urdf + "' is not a regular file (a FIFO)");
  expect_error(run("report --in " + fifo + " --out " + work("r.html")), 1,
               "'" + fifo + "' is not a regular file");
  expect_error(run("validate --robot planar2 --params " + fifo + " --data " + data), 1,
               "is not a regular file");
  EXPECT_FALSE(fs::exists(out));
}

// Issue 27 item 4: `report --in` read a result file of any size; it and `validate --params` have
// the cap of every other JSON reader (a sparse file: nothing is really read).
TEST_F(Contract, ResultFilesHaveTheSizeCap) {
  const std::string huge = write("huge.json", "{}");
  fs::resize_file(huge, (std::size_t{256} << 20) + 1);
  const std::string html = work("r.html");
  expect_error(run("report --in " + huge + " --out " + html), 1,
               "'" + huge + "' is larger than 256 MiB");
  EXPECT_FALSE(fs::exists(html));
  expect_error(run("validate --robot planar2 --params " + huge + " --data " + planar2_run("r.csv")),
               1, "'" + huge + "' is larger than 256 MiB");
}

// Issue 27 item 3: a mimic joint was silently a free joint with its own parameters.
TEST_F(Contract, MimicJointIsRefusedByName) {
  const std::string urdf = write("mimic.urdf", R"(<?xml version="1.0"?>
<robot name="gripper">
  <link name="base"/>
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/><mimic joint="j1" multiplier="-1"/></joint>
</robot>
)");
  expect_error(run("model --robot " + urdf), 1, "joint 'j2' in '" + urdf + "' mimics joint 'j1'");
}

// Issue 27 items 3-5: excite --f0 1e-300 wrote an absurd trajectory with exit 0, and --json was
// left behind when the trajectory could not be written.
TEST_F(Contract, ExciteBoundsItsWorkAndWritesBothFilesOrNeither) {
  const std::string out = work("traj.csv"), json = work("excitation.json");
  const std::string excite =
      "excite --robot planar2 --harmonics 3 --velocity-limit 2 --acceleration-limit 8 "
      "--starts 1 --max-evaluations 100 --max-time 0 ";
  expect_error(run(excite + "--f0 1e-300 --out " + out + " --json " + json), 2,
               "--f0 1e-300 Hz gives a period of 1e+300 s");
  expect_error(run(excite + "--f0 0.5 --rate 1e9 --out " + out), 2, "more than the 1e+07");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(json));
  const CliRun r = run(excite + "--f0 0.5 --out " + work("missing/traj.csv") + " --json " + json);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("missing"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(json));
  // A spline through 20 000 via-points: a dense solve of O(m³) did not finish.
  std::string via = "0";
  for (int k = 1; k < 20000; ++k) via += k % 2 ? ",0.5" : ",0";
  const CliRun spline = run("excite --robot planar2 --family spline --joint 1 --via " + via +
                            " --duration 20000 --rate 10 --velocity-limit 100 "
                            "--acceleration-limit 1000 --out " +
                            out);
  EXPECT_EQ(spline.code, 0) << spline.err;
}

// Issue 27 item 4: simulate --periods and --delay, compare-control --reversal-window set work
// without bound.
TEST_F(Contract, SimulationWorkIsBounded) {
  std::ostringstream s;
  s << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
  for (int k = 0; k < 200; ++k) {
    const double t = 0.01 * k, w = 2 * M_PI / 2.0;
    s << t << "," << 0.3 * std::sin(w * t) << "," << 0.2 * std::sin(w * t) << ","
      << 0.3 * w * std::cos(w * t) << "," << 0.2 * w * std::cos(w * t) << ","
      << -0.3 * w * w * std::sin(w * t) << "," << -0.2 * w * w * std::sin(w * t) << "\n";
  }
  const std::string reference = write("reference.csv", s.str());
  const std::string out = work("sim.csv");
  const std::string simulate =
      "simulate --robot planar2 --engine native --trajectory " + reference + " --out " + out;
  expect_error(run(simulate + " --periods 2000000000"), 1, "lower --periods");
  expect_error(run(simulate + " --delay 2000000000"), 1, "give a --delay below 200");
  EXPECT_FALSE(fs::exists(out));
  const std::string params = work("params.json");
  ASSERT_EQ(
      run("identify --robot planar2 --data " + planar2_run("run.csv") + " --out " + params).code,
      0);
  expect_error(run("compare-control --robot planar2 --engine native --params " + params +
                   " --trajectory " + reference + " --reversal-window 1e300"),
               1, "give --reversal-window below 2");
}

// Issue 27 item 5: a '"' in a name broke the URDF dynid writes, and "<!--<script>" in a name
// blanked the HTML report (the script data block's escape states swallowed its end tag).
TEST_F(Contract, OddNamesKeepTheUrdfAndTheReportIntact) {
  const std::string robot = write("odd.yaml", R"(name: 'odd"arm'
gravity: [0, -9.81, 0]
joints:
  - {name: 'sh"oulder<!--<script>', link: 'upper"arm&', sigma: 0, alpha: 0, d: 0, theta: 0, r: 0,
     mass: 2.0, com: [0.5, 0, 0], inertia_com: [0, 0, 0, 0.16666666666666666, 0, 0.16666666666666666]}
  - {name: elbow, link: forearm, sigma: 0, alpha: 0, d: 1.0, theta: 0, r: 0,
     mass: 1.5, com: [0.4, 0, 0], inertia_com: [0, 0, 0, 0.08, 0, 0.08]}
)");
  const std::string result = work("result.json");
  // Seeded torque noise: noiseless torques give intervals so narrow that no physically
  // consistent set lies inside them.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  const std::string run_csv = planar2_run("run.csv", [&](int, double* row) {
    row[7] += noise(rng);
    row[8] += noise(rng);
  });
  const CliRun fit = run("identify --physical --friction none --no-armature --robot " + robot +
                         " --data " + run_csv + " --out " + result);
  ASSERT_EQ(fit.code, 0) << fit.err;
  const std::string urdf = work("odd.urdf");
  const CliRun exported = run("export --robot " + robot + " --params " + result + " --out " + urdf);
  ASSERT_EQ(exported.code, 0) << exported.err;
  const CliRun back = run("model --robot " + urdf);
  EXPECT_EQ(back.code, 0) << back.err;
  EXPECT_NE(back.out.find("sh\"oulder<!--<script>"), std::string::npos) << back.out;
  const std::string html = work("report.html");
  ASSERT_EQ(run("report --in " + result + " --out " + html).code, 0);
  const std::string page = slurp(html);
  const std::string open = "id=\"dynid-data\">";
  const auto begin = page.find(open);
  ASSERT_NE(begin, std::string::npos);
  const auto end = page.find("</script>", begin);
  ASSERT_NE(end, std::string::npos);
  const std::string data = page.substr(begin + open.size(), end - begin - open.size());
  // No '<' at all inside the data block: no comment, tag or end tag can start there.
  EXPECT_EQ(data.find('<'), std::string::npos) << data.substr(0, 200);
  // The same text to JSON.parse: the name is there as it was given.
  EXPECT_NE(nlohmann::json::parse(data).dump().find("sh\\\"oulder<!--<script>"), std::string::npos);
}

// Issue 27 item 5: a failed demo left its folder and first files behind.
TEST_F(Contract, FailedDemoLeavesNoFileBehind) {
  const std::string folder = work("demo");
  const CliRun r = run("demo --robot " + work("no_such_robot.urdf") + " --out " + folder);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_FALSE(fs::exists(folder));
  // A demo that fails at stage 4 of 6, after the excitation, the run, the averaged run and the
  // result were written: a folder stands where its validation run goes. None of those files
  // appears in the user's folder, which keeps exactly what it held.
  fs::create_directories(work("demo/validation_run.csv"));
  write("demo/notes.txt", "mine\n");
  // (validation_run.csv is the demo's sixth file: workflow/demo.cpp writes it after result.json.)
  const CliRun late = run("demo --robot planar2 --native --periods 3 --quiet --out " + folder);
  expect_error(late, 1, "validation_run.csv' is a directory");
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(folder)) left.push_back(e.path().filename());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"notes.txt", "validation_run.csv"}));
  EXPECT_EQ(slurp(work("demo/notes.txt")), "mine\n");
}

// Issue 27 item 5: yaml-cpp's "bad conversion" reached the user as the reason.
TEST_F(Contract, WrongYamlTypeIsNamedInDynidsWords) {
  const std::string robot = write("typed.yaml", R"(name: [not, a, name]
joints:
  - {name: j1, sigma: 0, alpha: 0, d: 0, theta: 0, r: 0, mass: 1.0, com: [0.5, 0, 0],
     inertia_com: [0, 0, 0, 0.1, 0, 0.1]}
)");
  const CliRun r = run("model --robot " + robot);
  expect_error(r, 1, "a value has the wrong type");
  EXPECT_EQ(r.err.find("bad conversion"), std::string::npos) << r.err;
}

// Issue 27 item 4: `model --base` at the old 5000-joint limit took 100 s and 7.6 GB (a chain's
// regrouping is transitive: O(n²) terms). The limit came down to 1000 joints, where it takes
// seconds (docs/performance.md); one more joint is one error line naming the file and the limit,
// from either loader, before any work. The base parameters at the limit itself are computed in
// BaseParametersTree.ThousandJointChainLoadsAndGetsItsBaseParameters (library, no 77 MB of
// expressions to print); here a 200-joint chain goes through the command.
TEST_F(Contract, JointLimitIsOneErrorLineAndModelBaseBelowItFinishes) {
  const std::string limit = std::to_string(kMaxJoints);
  // The documented limit is the one the loaders apply.
  const std::string docs = slurp(fs::path(DYNID_SOURCE_DIR) / "docs" / "cli.md");
  EXPECT_NE(docs.find("| moving joints per model (URDF or YAML rows) | " + limit + " |"),
            std::string::npos);

  const std::string urdf = write("long.urdf", testing::chain_urdf(kMaxJoints + 1, 4));
  expect_error(run("model --base --robot " + urdf), 1,
               "robot file '" + urdf + "' has more than " + limit + " moving joints");
  std::string rows = "joints:\n";
  for (int j = 0; j <= kMaxJoints; ++j)
    rows += "  - {sigma: 0, alpha: 0, d: 0.1, theta: 0, r: 0}\n";
  const std::string mdh = write("long.yaml", rows);
  expect_error(run("model --robot " + mdh), 1,
               "robot file '" + mdh + "': joints: has " + std::to_string(kMaxJoints + 1) +
                   " rows; dynid handles at most " + limit + " joints");

  const std::string at_limit = write("limit.urdf", testing::chain_urdf(kMaxJoints, 4));
  const CliRun loaded = run("model --robot " + at_limit);
  EXPECT_EQ(loaded.code, 0) << loaded.err;
  // The dense sweep finds 80 = 7·12 − 4 base parameters on the first 12 links of this chain, and
  // each further generic revolute link adds 7 (BaseParametersTree tests): 7·200 − 4.
  const std::string chain = write("chain200.urdf", testing::chain_urdf(200, 11));
  const std::string json = work("model.json");
  const CliRun base = run("model --base --robot " + chain + " --json " + json);
  ASSERT_EQ(base.code, 0) << base.err;
  EXPECT_NE(base.out.find("1396 base parameters"), std::string::npos) << base.out.substr(0, 400);
  EXPECT_EQ(nlohmann::json::parse(slurp(json)).at("rank"), 1396);
}

}  // namespace
}  // namespace dynid
