// identify --closed-loop projection|spectral, --estimator ml, --repeat through the command line:
// a 4-harmonic planar2 reference written here, run by `dynid simulate --controller pid` (native
// plant, noise fed back), then identify; and the bad inputs of issue 13 item 8, one error line
// each.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/io/csv_writer.hpp"
#include "support/cli_run.hpp"
#include "support/closed_loop_runs.hpp"

namespace dynid {
namespace {

std::filesystem::path scratch() {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "closed_loop_cli";
  std::filesystem::create_directories(dir);
  return dir;
}

testing::CliResult run(const std::string& args) {
  return testing::run_dynid(args, scratch());
}

nlohmann::json load(const std::string& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f);
}

std::string path(const std::string& name) {
  return (scratch() / name).string();
}

// One period of the planar2 test reference at 100 Hz, then 4 periods under a plain PID.
std::string plain_pid_run() {
  static const std::string out = [] {
    const TrajectorySamples tr =
        sample_trajectory(FourierTrajectory(testing::planar2_reference()), 100.0, false);
    Eigen::MatrixXd data(tr.t.size(), 7);
    data << tr.t, tr.q, tr.dq, tr.ddq;
    write_csv(path("reference.csv"), {"t", "q1", "q2", "dq1", "dq2", "ddq1", "ddq2"}, data);
    const auto r = run("simulate --robot planar2 --trajectory " + path("reference.csv") +
                       " --engine native --controller pid --periods 4 --position-noise 1e-3 "
                       "--torque-noise 0.1 --seed 5 --out " +
                       path("run.csv"));
    EXPECT_EQ(r.code, 0) << r.err;
    return path("run.csv");
  }();
  return out;
}

TEST(ClosedLoopCli, ProjectionSpectralAndRepeatWriteTheirJson) {
  const std::string data = plain_pid_run();
  auto r = run("identify --robot planar2 --data " + data +
               " --closed-loop projection --repeat periods --out " + path("projection.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = load(path("projection.json"));
  EXPECT_EQ(j["closed_loop"]["method"], "projection");
  EXPECT_GE(j["closed_loop"]["M1"].get<int>(), 2);
  ASSERT_EQ(j["closed_loop"]["correlation"].size(), 2u);
  EXPECT_LT(std::abs(j["closed_loop"]["correlation"][0].get<double>()), 1e-6);
  EXPECT_EQ(j["options"]["closed_loop"], "projection");
  EXPECT_EQ(j["repeated"]["n"], 4);
  ASSERT_EQ(j["repeated"]["parameters"].size(), j["parameters"].size());
  const auto& first = j["repeated"]["parameters"][0];
  // Table 3's column: t_0.9995(3)/sqrt(3) = 12.924/1.7321 = 7.4617 times the std.
  EXPECT_NEAR(first["ci_half_width"].get<double>() / first["std"].get<double>(), 7.4617, 1e-3);

  r = run("identify --robot planar2 --data " + data + " --closed-loop spectral --out " +
          path("spectral.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  j = load(path("spectral.json"));
  EXPECT_EQ(j["closed_loop"]["method"], "spectral");
  EXPECT_NEAR(j["closed_loop"]["spectrum"]["f0_hz"].get<double>(), 0.2, 1e-9);
  EXPECT_EQ(j["closed_loop"]["spectrum"]["lines"], nlohmann::json({1, 2, 3, 4}));
  EXPECT_EQ(j["closed_loop"]["dimensions_per_channel"], 9);
  // The lines kept and the rest of the spectrum are orthogonal: corr(û, ũ) is round-off, per joint.
  ASSERT_EQ(j["closed_loop"]["correlation"].size(), 2u);
  for (const auto& c : j["closed_loop"]["correlation"]) EXPECT_LT(std::abs(c.get<double>()), 1e-9);
  // validate says that a closed-loop result is checked against the measured, unprojected torques.
  r = run("validate --robot planar2 --params " + path("spectral.json") + " --data " + data +
          " --json " + path("validate_spectral.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  j = load(path("validate_spectral.json"));
  EXPECT_NE(j["choices"]["closed_loop"].get<std::string>().find("not projected"),
            std::string::npos);

  r = run("identify --robot planar2 --data " + data +
          " --estimator ml --noise-std q=1e-3,tau=0.1 --out " + path("ml.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  j = load(path("ml.json"));
  EXPECT_NE(j["choices"]["noise"].get<std::string>().find("given"), std::string::npos);
  EXPECT_NE(j["choices"]["covariance"].get<std::string>().find("maximum likelihood"),
            std::string::npos);

  // After the spectral projection (period given), with the noise of the projected signals.
  r = run("identify --robot planar2 --data " + data +
          " --closed-loop spectral --f0 0.2 --estimator ml --out " + path("spectral_ml.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  j = load(path("spectral_ml.json"));
  EXPECT_NE(j["choices"]["noise"].get<std::string>().find("through the projection"),
            std::string::npos);
  EXPECT_NE(j["choices"]["covariance"].get<std::string>().find("degrees of freedom"),
            std::string::npos);
  EXPECT_NE(j["choices"]["period"].get<std::string>().find("given: 5 s"), std::string::npos);

  // Flags the closed-loop preparation does not use: one warning naming each, the same result.
  const std::string spectral =
      "identify --robot planar2 --data " + data + " --closed-loop spectral --f0 0.2 --out ";
  r = run(spectral + path("plain.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(spectral + path("flags.json") + " --filter chebyshev:8 --cutoff 40 --decimate 2");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* flag : {"--filter", "--cutoff", "--decimate"})
    EXPECT_NE(r.err.find(std::string("warning: ") + flag + " has no effect with --closed-loop"),
              std::string::npos)
        << r.err;
  const nlohmann::json plain = load(path("plain.json")), flags = load(path("flags.json"));
  ASSERT_EQ(plain["parameters"].size(), flags["parameters"].size());
  for (size_t i = 0; i < plain["parameters"].size(); ++i)
    EXPECT_EQ(plain["parameters"][i]["value"], flags["parameters"][i]["value"]);
}

// One `error:` line, the exit code, and no result file.
void expect_error(const std::string& args, int code, const std::string& text) {
  std::filesystem::remove(path("bad.json"));
  const auto r = run(args + " --out " + path("bad.json"));
  EXPECT_EQ(r.code, code) << args << "\n" << r.err;
  EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
  EXPECT_NE(r.err.find(text), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("bad.json")));
}

TEST(ClosedLoopCli, BadInputIsOneErrorLine) {
  const std::string data = plain_pid_run();
  const std::string id = "identify --robot planar2 --data ";
  // No reference columns: the reference itself has no qr*.
  Eigen::MatrixXd plain(200, 5);
  for (int k = 0; k < 200; ++k) {
    const double t = 0.01 * k;
    plain.row(k) << t, std::sin(t), std::cos(t), 0.1 * std::sin(3 * t), 0.2;
  }
  write_csv(path("no_qr.csv"), {"t", "q1", "q2", "tau1", "tau2"}, plain);
  expect_error(id + path("no_qr.csv") + " --closed-loop projection", 1,
               "error: closed-loop identification needs the reference columns qr1..qr2");
  // One joint held is seed 2's one-joint run; every joint held excites nothing.
  Eigen::MatrixXd flat(200, 7);
  flat << plain.leftCols(3), Eigen::VectorXd::Constant(200, 0.1),
      Eigen::VectorXd::Constant(200, 0.3), plain.rightCols(2);
  write_csv(path("flat_qr.csv"), {"t", "q1", "q2", "qr1", "qr2", "tau1", "tau2"}, flat);
  expect_error(id + path("flat_qr.csv") + " --closed-loop projection", 1,
               "error: every reference qr1..qr2 is constant: the run excites nothing");
  // The repeat's checks run before the whole-run estimate (368 s on seed 2's 25-period run
  // before the refusal): the repeat's error, not the spectral preparation's, although both fail.
  Eigen::MatrixXd drifting(200, 7);
  drifting << plain.leftCols(3), plain.col(1), plain.col(2), plain.rightCols(2);
  write_csv(path("drifting_qr.csv"), {"t", "q1", "q2", "qr1", "qr2", "tau1", "tau2"}, drifting);
  expect_error(id + path("drifting_qr.csv") + " --closed-loop spectral --repeat periods", 1,
               "error: --repeat periods needs a periodic reference with at least two periods");
  expect_error(id + data + " --closed-loop projection --fir 5000,5000", 1,
               "error: FIR orders M1 = 5000, M2 = 5000 need at least");
  expect_error(id + data + " --fir 4,4", 2, "error: --fir sets the projection's FIR orders");
  expect_error(id + data + " --closed-loop projection --fir 4", 2, "error: --fir '4' is not M1,M2");
  expect_error(id + data + " --closed-loop nonsense", 2, "error: --closed-loop must be none");
  expect_error(id + data + " --estimator ml --noise-std q=1e-3,tau=0", 1,
               "error: maximum likelihood needs a torque noise standard deviation > 0");
  expect_error(id + data + " --estimator ml --noise-std q=-1", 2,
               "error: --noise-std q=-1 is not a finite std >= 0");
  expect_error(id + data + " --noise-std tau=1", 2, "error: --noise and --noise-std are the noise");
  expect_error(id + path("no_qr.csv") + " --repeat periods", 1,
               "error: --repeat periods finds the period from the reference");
  expect_error(id + data + " --repeat runs", 1, "error: --repeat needs at least 2 runs");
  expect_error(id + data + " --f0 0.2", 2, "error: --period/--f0 give the reference's period");
  expect_error(id + data + " --closed-loop spectral --f0 0.2 --period 5", 2,
               "error: give one of --period S or --f0 HZ");
  expect_error(id + data + " --closed-loop spectral --period 3", 1,
               "error: qr1 does not repeat with --period 3 s");
}

// Issue 25 item 3's case through the binary: a plain-PID 3-joint arm (irp6, native plant) on a
// 3-harmonic reference over 3 periods projects onto 21 dimensions for 27 base parameters, and
// identify refused ("no degrees of freedom are left for the intervals"). Now both methods return
// the estimate with intervals from the torque remainder, say so in `interval_source` and a
// warning, and validate accepts the result.
TEST(ClosedLoopCli, NoIntervalDegreesOfFreedomLeftIsAWarningNotARefusal) {
  auto r =
      run("excite --robot irp6 --harmonics 3 --f0 0.2 --seed 2 --starts 1 --max-time 2 "
          "--rate 200 --out " +
          path("irp6_ref3.csv"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("simulate --robot irp6 --engine native --controller pid --trajectory " +
          path("irp6_ref3.csv") + " --periods 3 --position-noise 1e-4 --torque-noise 0.5 --out " +
          path("irp6_run3.csv"));
  ASSERT_EQ(r.code, 0) << r.err;
  for (const std::string method : {"projection", "spectral"}) {
    const std::string out = path("irp6_" + method + ".json");
    r = run("identify --robot irp6 --data " + path("irp6_run3.csv") + " --closed-loop " + method +
            " --out " + out);
    ASSERT_EQ(r.code, 0) << method << ": " << r.err;
    EXPECT_NE(r.err.find("no degrees of freedom are left in the projected residual"),
              std::string::npos)
        << r.err;
    const nlohmann::json j = load(out);
    EXPECT_EQ(j["interval_source"], "torque_remainder") << method;
    for (const auto& p : j["parameters"]) {
      ASSERT_TRUE(p["std"].is_number()) << p.dump();
      EXPECT_GT(p["std"].get<double>(), 0.0) << p.dump();
    }
    r = run("validate --robot irp6 --params " + out + " --data " + path("irp6_run3.csv"));
    EXPECT_EQ(r.code, 0) << r.err;
  }
}

// Issue 28 item 2: seed 2's one-joint Fourier run (joint 1 on the 4-harmonic test reference, joint
// 2 held at 0.8 rad by its PID), 3 periods, through the binary: the spectral preparation with
// Table 3's repeated statistic (it was refused, "reference qr2 is constant ... excite every
// joint") and the projection (issue 28 item 3) with it.
TEST(ClosedLoopCli, OneJointRunRepeatsOverItsPeriods) {
  FourierCoefficients c = testing::planar2_reference();
  c.a[1].setZero();
  c.b[1].setZero();
  const TrajectorySamples tr = sample_trajectory(FourierTrajectory(c), 100.0, false);
  Eigen::MatrixXd data(tr.t.size(), 7);
  data << tr.t, tr.q, tr.dq, tr.ddq;
  write_csv(path("one_joint_ref.csv"), {"t", "q1", "q2", "dq1", "dq2", "ddq1", "ddq2"}, data);
  auto r = run("simulate --robot planar2 --trajectory " + path("one_joint_ref.csv") +
               " --engine native --controller pid --periods 3 --position-noise 1e-3 "
               "--torque-noise 0.1 --seed 7 --out " +
               path("one_joint_run.csv"));
  ASSERT_EQ(r.code, 0) << r.err;
  for (const std::string method : {"spectral", "projection"}) {
    const std::string out = path("one_joint_" + method + ".json");
    r = run("identify --robot planar2 --data " + path("one_joint_run.csv") + " --closed-loop " +
            method + " --repeat periods --out " + out);
    ASSERT_EQ(r.code, 0) << method << ": " << r.err;
    const nlohmann::json j = load(out);
    EXPECT_EQ(j["closed_loop"]["held_joints"], nlohmann::json({2})) << method;
    EXPECT_EQ(j["closed_loop"]["dimensions_per_channel"], 9) << method;
    EXPECT_EQ(j["repeated"]["n"], 3) << method;
    EXPECT_FALSE(j["repeated"]["parameters"].empty()) << method;
    for (const auto& p : j["repeated"]["parameters"]) {
      EXPECT_TRUE(p["mean"].is_number()) << method << " " << p.dump();
      EXPECT_TRUE(p["std"].is_number()) << method << " " << p.dump();
    }
  }
}

}  // namespace
}  // namespace dynid
