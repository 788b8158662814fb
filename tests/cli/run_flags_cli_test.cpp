// Issue 26 items 2, 3, 6 (validate's keys) and 7 through the dynid binary: one definition of the
// run flags on every command that reads a run, validate reading a run as identify read its own
// (columns, rate, torque scale, bias and time shift stored in the result), the time-units
// diagnosis in validate, --torque-bias and --time-shift (old name --torque-offset).
// Oracle: a planar2 run generated here from the closed form of docs/methods/model.md (not by
// dynid): its torques are predicted exactly by the true parameters, so a run read the right way
// validates to round-off and one read the wrong way does not.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"
#include "support/planar2.hpp"

namespace {

namespace fs = std::filesystem;
using CliRun = dynid::testing::CliResult;

constexpr int kRunFlagSamples = 1500;
constexpr double kRunFlagDt = 0.01;
// ZZ1R = ZZ1 + l1²·M2 of the closed-form arm: I1 + m1·c1² + m2·l1².
constexpr double kRunFlagZz1r = 2.0 / 12 + 2.0 * 0.25 + 1.5;

using Sample = dynid::testing::Planar2Sample;

Sample planar2_sample(int k) {
  return dynid::testing::planar2_sample(k, kRunFlagDt);
}

class RunFlagsCli : public dynid::testing::CliScratchTest {
 protected:
  // A run t,q1,q2,dq1,dq2,ddq1,ddq2,tau1,tau2 (the names in `header`, t left out when `time` is
  // false); logged torque j = tau_j / scale_j + bias_j; t multiplied by `time_unit`.
  std::string write_run(const std::string& name, const std::vector<std::string>& header,
                        bool time = true, double scale = 1.0, double bias1 = 0.0,
                        double time_unit = 1.0) const {
    std::ofstream f(path(name));
    f.precision(17);
    for (std::size_t c = time ? 0 : 1; c < header.size(); ++c)
      f << header[c] << (c + 1 < header.size() ? "," : "\n");
    for (int k = 0; k < kRunFlagSamples; ++k) {
      const Sample s = planar2_sample(k);
      if (time) f << s.t * time_unit << ',';
      f << s.q[0] << ',' << s.q[1] << ',' << s.dq[0] << ',' << s.dq[1] << ',' << s.ddq[0] << ','
        << s.ddq[1] << ',' << s.tau[0] / scale + bias1 << ',' << s.tau[1] / scale << '\n';
    }
    return path(name);
  }
  std::string write_standard_run(const std::string& name) const {
    return write_run(name, kStandard);
  }
  static nlohmann::json load(const std::string& p) {
    return nlohmann::json::parse(std::ifstream(p));
  }
  static double zz1r(const nlohmann::json& result) {
    for (const auto& p : result["parameters"])
      if (p["name"] == "ZZ1R") return p["value"].get<double>();
    return NAN;
  }
  const std::vector<std::string> kStandard = {"t",    "q1",   "q2",   "dq1", "dq2",
                                              "ddq1", "ddq2", "tau1", "tau2"};
  // A recorder's own names: no t column, positions, velocities and currents named otherwise.
  const std::vector<std::string> kVendor = {"t",    "pos1", "pos2", "vel1", "vel2",
                                            "acc1", "acc2", "cur1", "cur2"};
  const std::string kVendorColumns =
      "pos1=q1,pos2=q2,vel1=dq1,vel2=dq2,acc1=ddq1,acc2=ddq2,cur1=tau1,cur2=tau2";
};

// The help line of `flag` in `help` (CLI11 prints one line per flag and its description).
std::string help_line(const std::string& help, const std::string& flag) {
  std::stringstream s(help);
  std::string line;
  while (std::getline(s, line)) {
    const auto at = line.find(flag + " ");
    if (at != std::string::npos && line.find_first_not_of(' ') == at) return line;
  }
  return {};
}

// Item 2: identify, validate, payload and average take the same run flags with the same help
// (validate adds only where its default comes from); the old --torque-offset is not shown.
TEST_F(RunFlagsCli, EveryCommandThatReadsARunTakesTheSameRunFlags) {
  const std::vector<std::string> commands = {"identify", "validate", "payload", "average"};
  const std::vector<std::string> flags = {"--rate", "--columns",    "--torque-scale", "--rows",
                                          "--time", "--time-shift", "--torque-bias",  "--topic"};
  const CliRun reference = run("identify --help");
  ASSERT_EQ(reference.code, 0);
  for (const std::string& command : commands) {
    const CliRun help = run(command + " --help");
    ASSERT_EQ(help.code, 0) << command;
    EXPECT_EQ(help.out.find("--torque-offset"), std::string::npos) << command;
    for (const std::string& flag : flags) {
      const std::string line = help_line(help.out, flag);
      ASSERT_FALSE(line.empty()) << command << " has no " << flag << "\n" << help.out;
      const std::string own = help_line(reference.out, flag);
      if (command == "validate") {
        // The same text, then where the default comes from.
        EXPECT_EQ(line.rfind(own, 0), 0u) << line << "\nvs\n" << own;
      } else {
        EXPECT_EQ(line, own) << command << " " << flag;
      }
    }
  }
}

// Item 3: validate reads the run as identify read its own (--columns, --rate, --torque-scale from
// the result), unless a flag overrides it; without that memory the run would not even be read.
TEST_F(RunFlagsCli, ValidateReadsTheRunAsIdentifyDid) {
  const std::string data = write_run("vendor.csv", kVendor, false, 2.0);
  const std::string result = path("result.json");
  const CliRun id =
      run("identify --robot planar2 --data " + data + " --rate 100 --columns " + kVendorColumns +
          " --torque-scale 2 --filter none --friction none --no-armature --out " + result);
  ASSERT_EQ(id.code, 0) << id.err;
  EXPECT_NEAR(zz1r(load(result)), kRunFlagZz1r, 1e-4);
  const std::string val = path("val.json");
  const CliRun v =
      run("validate --robot planar2 --params " + result + " --data " + data + " --json " + val);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.err.find("--columns as given to identify"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("--torque-scale as given to identify"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("time from the stored rate 100 Hz"), std::string::npos) << v.err;
  EXPECT_EQ(v.err.find("warning"), std::string::npos) << v.err;
  EXPECT_LT(load(val)["relative_error_all_rows"].get<double>(), 1e-6);
  // An override wins: the scale 1 halves the measured torques, 50 % of them unexplained.
  const CliRun scaled = run("validate --robot planar2 --params " + result + " --data " + data +
                            " --torque-scale 1 --json " + val);
  ASSERT_EQ(scaled.code, 0) << scaled.err;
  EXPECT_NEAR(load(val)["relative_error_all_rows"].get<double>(), 1.0, 1e-6);
  // A run of another recorder: the stored rename does not fit, and the error says whose it is.
  const std::string other = write_standard_run("standard.csv");
  expect_error(run("validate --robot planar2 --params " + result + " --data " + other), 1,
               {"--columns", "stored in '" + result + "'", "give --columns for this run"});
  // ...and --columns for this run fixes it (identity renames: t=t is a valid mapping).
  const CliRun fixed = run("validate --robot planar2 --params " + result + " --data " + other +
                           " --columns t=t --torque-scale 1 --json " + val);
  ASSERT_EQ(fixed.code, 0) << fixed.err;
  EXPECT_NE(fixed.err.find("the stored rate 100 Hz has no effect"), std::string::npos) << fixed.err;
  EXPECT_LT(load(val)["relative_error_all_rows"].get<double>(), 1e-6);
}

// Item 3: a result written before these options were stored still validates (the old keys).
TEST_F(RunFlagsCli, AnOlderResultWithoutTheNewKeysStillValidates) {
  const std::string data = write_standard_run("run.csv");
  const std::string result = path("result.json");
  ASSERT_EQ(run("identify --robot planar2 --data " + data +
                " --filter none --friction none --no-armature --out " + result)
                .code,
            0);
  nlohmann::json r = load(result);
  for (const char* key : {"columns", "rate_hz", "torque_bias", "time_shift_s"})
    r["options"].erase(key);
  std::ofstream(path("old.json")) << r.dump();
  const CliRun v = run("validate --robot planar2 --params " + path("old.json") + " --data " + data +
                       " --json " + path("val.json"));
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_LT(load(path("val.json"))["relative_error_all_rows"].get<double>(), 1e-6);
}

// Item 3: a t column in milliseconds is named as a unit problem by validate, as by identify.
TEST_F(RunFlagsCli, ValidateDiagnosesMillisecondsAsIdentifyDoes) {
  const std::string data = write_standard_run("run.csv");
  const std::string ms = write_run("ms.csv", kStandard, true, 1.0, 0.0, 1000.0);
  const std::string result = path("result.json");
  ASSERT_EQ(run("identify --robot planar2 --data " + data + " --out " + result).code, 0);
  const CliRun id = run("identify --robot planar2 --data " + ms + " --out " + path("x.json"));
  expect_error(id, 1, {"milliseconds"});
  const CliRun v = run("validate --robot planar2 --params " + result + " --data " + ms);
  expect_error(v, 1, {"milliseconds"});
  // The same words: one diagnosis.
  EXPECT_EQ(v.err, id.err);
}

// Item 7: --torque-bias subtracts a constant sensor bias (by joint number or name); without it
// the same log gives another ZZ1R when no offset term can absorb it.
TEST_F(RunFlagsCli, TorqueBiasIsSubtractedFromTheLoggedTorque) {
  const std::string data = write_run("biased.csv", kStandard, true, 1.0, 0.7);
  const std::string result = path("result.json");
  const std::string base = "identify --robot planar2 --data " + data +
                           " --filter none --friction none --no-armature --out " + result;
  // planar2's joints are shoulder and elbow.
  for (const std::string bias : {"1=0.7", "1=0.7,2=0", "shoulder=0.7", "elbow=0,shoulder=0.7"}) {
    const CliRun id = run(base + " --torque-bias " + bias);
    ASSERT_EQ(id.code, 0) << bias << id.err;
    EXPECT_NEAR(zz1r(load(result)), kRunFlagZz1r, 1e-4) << bias;
    EXPECT_NE(id.err.find("torque bias"), std::string::npos) << id.err;
    EXPECT_EQ(load(result)["options"]["torque_bias"], bias);
  }
  // validate remembers the bias: the biased log predicted to round-off.
  ASSERT_EQ(run(base + " --torque-bias 1=0.7").code, 0);
  const CliRun v = run("validate --robot planar2 --params " + result + " --data " + data +
                       " --json " + path("val.json"));
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.err.find("--torque-bias as given to identify"), std::string::npos) << v.err;
  EXPECT_LT(load(path("val.json"))["relative_error_all_rows"].get<double>(), 1e-6);
  ASSERT_EQ(run(base).code, 0);
  EXPECT_GT(std::abs(zz1r(load(result)) - kRunFlagZz1r), 1e-3);
  const std::string x = "identify --robot planar2 --data " + data + " --out " + path("x.json");
  expect_error(run(x + " --torque-bias 3=1"), 2, {"--torque-bias", "1 to 2"});
  expect_error(run(x + " --torque-bias wrist=1"), 2,
               {"--torque-bias", "'wrist'", "is not a joint of", "shoulder, elbow"});
  expect_error(run(x + " --torque-bias 1"), 2, {"--torque-bias", "J=VALUE"});
  expect_error(run(x + " --torque-bias 1=nan"), 2, {"--torque-bias", "J=VALUE"});
  expect_error(run(x + " --torque-bias 1=1,1=2"), 2, {"--torque-bias", "twice"});
  EXPECT_FALSE(fs::exists(path("x.json")));
}

// Item 7: --time-shift is the time shift, stored under its own key and the old one;
// --torque-offset is its old name, and both at once is an error.
TEST_F(RunFlagsCli, TimeShiftAndItsOldName) {
  const std::string data = write_standard_run("run.csv");
  const std::string base =
      "identify --robot planar2 --data " + data + " --filter none --friction none --out ";
  ASSERT_EQ(run(base + path("new.json") + " --time-shift 0.005").code, 0);
  ASSERT_EQ(run(base + path("old.json") + " --torque-offset 0.005").code, 0);
  for (const char* file : {"new.json", "old.json"}) {
    const nlohmann::json o = load(path(file))["options"];
    EXPECT_EQ(o["time_shift_s"].get<double>(), 0.005) << file;
    EXPECT_EQ(o["torque_offset_s"].get<double>(), 0.005) << file;
  }
  EXPECT_EQ(zz1r(load(path("new.json"))), zz1r(load(path("old.json"))));
  // The shift changes the estimate (the torque is moved against q by half a sample).
  ASSERT_EQ(run(base + path("none.json")).code, 0);
  EXPECT_NE(zz1r(load(path("new.json"))), zz1r(load(path("none.json"))));
  expect_error(run(base + path("x.json") + " --time-shift 0.005 --torque-offset 0.005"), 2,
               {"--time-shift", "--torque-offset"});
  EXPECT_FALSE(fs::exists(path("x.json")));
  // validate takes the stored shift, and --time-shift overrides it.
  const CliRun v = run("validate --robot planar2 --params " + path("new.json") + " --data " + data);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.err.find("--time-shift as given to identify"), std::string::npos) << v.err;
  const CliRun w = run("validate --robot planar2 --params " + path("new.json") + " --data " + data +
                       " --time-shift 0");
  ASSERT_EQ(w.code, 0) << w.err;
  EXPECT_EQ(w.err.find("--time-shift as given to identify"), std::string::npos) << w.err;
}

// Item 6: the validate JSON names its moving-rows figure (relative_error_moving, with the old
// key relative_error kept) beside the all-rows headline.
TEST_F(RunFlagsCli, ValidateJsonNamesTheMovingRowsFigure) {
  const std::string data = write_standard_run("run.csv");
  const std::string result = path("result.json");
  ASSERT_EQ(run("identify --robot planar2 --data " + data +
                " --filter none --friction viscous,coulomb --out " + result)
                .code,
            0);
  // Noise on the torque so that the two figures differ (fixed, known values).
  std::ifstream in(data);
  std::ofstream noisy(path("noisy.csv"));
  std::string line;
  std::getline(in, line);
  noisy << line << '\n';
  for (int k = 0; std::getline(in, line); ++k) {
    noisy << line.substr(0, line.rfind(',')) << ','
          << std::stod(line.substr(line.rfind(',') + 1)) + (k % 2 ? 0.05 : -0.05) << '\n';
  }
  noisy.close();
  const CliRun v = run("validate --robot planar2 --params " + result + " --data " +
                       path("noisy.csv") + " --json " + path("val.json"));
  ASSERT_EQ(v.code, 0) << v.err;
  const nlohmann::json j = load(path("val.json"));
  ASSERT_TRUE(j.contains("relative_error_moving"));
  EXPECT_EQ(j["relative_error_moving"], j["relative_error"]);
  EXPECT_GT(j["rows_excluded_zero_velocity"].get<long>(), 0);
  EXPECT_NE(j["relative_error_moving"], j["relative_error_all_rows"]);
  for (const auto& joint : j["joints"])
    EXPECT_EQ(joint["relative_error_moving"], joint["relative_error"]);
  // The headline (first figure printed) is the all-rows one.
  char headline[64];
  std::snprintf(headline, sizeof(headline), "every row: %.2f %%",
                100 * j["relative_error_all_rows"].get<double>());
  EXPECT_NE(v.out.find(headline), std::string::npos) << v.out;
}

// Item 6: excite names the flags that fix missing limits, not the library's fields.
TEST_F(RunFlagsCli, ExciteNamesTheFlagsThatBoundTheExcitation) {
  // planar2 has no joint limits in its model.
  const CliRun r = run("excite --robot planar2 --out " + path("traj.csv"));
  expect_error(r, 1, {"--velocity-limit", "--acceleration-limit", "shoulder"});
  EXPECT_EQ(r.err.find("q_min"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("dq_max"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("traj.csv")));
}

// Item 6: "(given)" only for values the user gave: validate's stored cut-off and thresholds
// say where they come from.
TEST_F(RunFlagsCli, GivenOnlyForValuesTheUserGave) {
  const std::string data = write_standard_run("run.csv");
  const std::string result = path("result.json");
  const CliRun id = run("identify --robot planar2 --data " + data +
                        " --cutoff 4 --zero-velocity 0.05 --out " + result);
  ASSERT_EQ(id.code, 0) << id.err;
  EXPECT_NE(id.err.find("4 Hz (given)"), std::string::npos) << id.err;
  const CliRun v = run("validate --robot planar2 --params " + result + " --data " + data);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_EQ(v.err.find("(given)"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("4 Hz (as identify used it)"), std::string::npos) << v.err;
  const CliRun w =
      run("validate --robot planar2 --params " + result + " --data " + data + " --cutoff 5");
  ASSERT_EQ(w.code, 0) << w.err;
  EXPECT_NE(w.err.find("5 Hz (given)"), std::string::npos) << w.err;
}

}  // namespace
