// Issue 26 item 8 through the binary: `dynid simulate` with its default gains holds every built-in
// robot and a 6-joint URDF without rotor inertia on a trajectory `dynid excite` made for it, on
// both engines; a run that diverges, does not track or chatters is one error line naming --gains
// with nothing written; planar2's default excite → simulate → identify chain, which chattered
// (1136 N·m, 28.6 % for an exact model), identifies the exact model. Oracles: the reference
// itself (a tracking loop follows it; its torque is as smooth as the reference's dynamics) and the
// model simulated (identify on an exact model's MuJoCo run leaves a small relative error).

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

namespace {

namespace fs = std::filesystem;
using dynid::testing::CliResult;

const std::string kArm6Urdf =
    std::string(DYNID_SHARED_DIR) + "/regressions/arm6-closed-loop/arm6_odd.urdf";

// A CSV with a header, as columns by name (read here, not by dynid).
struct GainsCsv {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  std::vector<double> column(const std::string& name) const {
    const auto at = std::find(names.begin(), names.end(), name) - names.begin();
    std::vector<double> out;
    for (const auto& r : rows) out.push_back(r[static_cast<size_t>(at)]);
    return out;
  }
  bool has(const std::string& name) const {
    return std::find(names.begin(), names.end(), name) != names.end();
  }
};

GainsCsv read_gains_csv(const std::string& path) {
  GainsCsv out;
  std::ifstream f(path);
  std::string line, field;
  std::getline(f, line);
  std::stringstream h(line);
  while (std::getline(h, field, ',')) out.names.push_back(field);
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream s(line);
    out.rows.emplace_back();
    while (std::getline(s, field, ',')) out.rows.back().push_back(std::stod(field));
  }
  return out;
}

class SimGainsCli : public dynid::testing::CliScratchTest {
 protected:
  // A short reproducible excitation of `robot` (3 harmonics, 2 s period, 200 Hz: seed 2's
  // controller rate; at excite's default 100 Hz the rule does not hold every arm,
  // docs/methods/sim.md).
  std::string excite(const std::string& robot, const std::string& name) const {
    // planar2's model has no joint limits: the velocity and acceleration bounds.
    const std::string limits =
        robot == "planar2" ? " --velocity-limit 2 --acceleration-limit 8" : "";
    const CliResult r = run("excite --robot " + robot + limits + " --out " + path(name) +
                            " --harmonics 3 --f0 0.5 --rate 200 --max-time 0 --starts 1 "
                            "--max-evaluations 60 --quiet");
    EXPECT_EQ(r.code, 0) << r.err;
    return path(name);
  }
};

// Max |q − qr| after the first period against the reference's span, and how often the torque's
// torque's change reverses from one sample to the next, per joint of a run with n joints.
void expect_tracking_without_chatter(const GainsCsv& run, int n, size_t period) {
  for (int j = 1; j <= n; ++j) {
    const std::vector<double> q = run.column("q" + std::to_string(j));
    const std::vector<double> qr = run.column("qr" + std::to_string(j));
    const std::vector<double> tau = run.column("tau" + std::to_string(j));
    const auto [lo, hi] = std::minmax_element(qr.begin(), qr.end());
    double error = 0.0;
    for (size_t k = period; k < q.size(); ++k) error = std::max(error, std::abs(q[k] - qr[k]));
    // The exact feed-forward leaves the discrete loop's lag (the derivative filter's, measured up
    // to 8.6 % of the span on arm6_odd): a tenth of the motion.
    EXPECT_LT(error, 0.1 * (*hi - *lo) + 1e-3) << "joint " << j;
    // Chatter is a sample-to-sample swing: the torque's change reverses from one sample to the
    // next, both changes large. A Coulomb step of the feed-forward at a velocity reversal is one
    // large change. So: such reversals (changes above 5 % of the torque's range) in under 1 % of
    // the samples (measured: at most 1 in 800 on every robot here).
    const auto [tlo, thi] = std::minmax_element(tau.begin(), tau.end());
    const double big = 0.05 * (*thi - *tlo);
    size_t reversals = 0;
    for (size_t k = 1; k + 1 < tau.size(); ++k) {
      const double before = tau[k] - tau[k - 1], after = tau[k + 1] - tau[k];
      reversals += before * after < 0 && std::min(std::abs(before), std::abs(after)) > big;
    }
    EXPECT_LT(reversals, tau.size() / 100) << "joint " << j;
  }
}

TEST_F(SimGainsCli, DefaultGainsHoldEveryBuiltinRobotAndAUrdfWithoutRotorInertia) {
  std::vector<std::pair<std::string, int>> robots = {
      {"puma560", 6}, {"planar2", 2}, {"irp6", 6}, {"iiwa14", 7}, {"comau-s2", 6}};
  if (fs::exists(kArm6Urdf)) robots.emplace_back(kArm6Urdf, 6);
  for (const auto& [robot, n] : robots) {
    SCOPED_TRACE(robot);
    const std::string traj = excite(robot, "traj.csv");
    for (const std::string engine : {"mujoco", "native"}) {
      SCOPED_TRACE(engine);
      const CliResult r = run("simulate --robot " + robot + " --trajectory " + traj + " --out " +
                              path("run.csv") + " --engine " + engine + " --periods 2 --quiet");
      ASSERT_EQ(r.code, 0) << r.err;
      // Two periods (the reference's last row, equal to its first, ends the period).
      const GainsCsv csv = read_gains_csv(path("run.csv"));
      ASSERT_EQ(csv.rows.size() + 2, 2 * read_gains_csv(traj).rows.size());
      expect_tracking_without_chatter(csv, n, csv.rows.size() / 2);
    }
  }
}

// Gains far beyond the discrete loop's limit diverge or chatter; gains too soft to hold planar2
// against gravity leave it bounded but hanging away from the reference. Both are errors naming
// --gains, and neither leaves the run or its gains file behind.
TEST_F(SimGainsCli, GainsThatDoNotHoldTheArmAreOneErrorNamingTheFlag) {
  const std::string traj = excite("planar2", "traj.csv");
  std::ofstream(path("stiff.yaml")) << "kp: [4e6, 4e6]\nki: [0, 0]\nkd: [2e3, 2e3]\n";
  std::ofstream(path("soft.yaml")) << "kp: [1, 1]\nki: [0, 0]\nkd: [0.5, 0.5]\n";
  for (const std::string gains : {"stiff.yaml", "soft.yaml"}) {
    for (const std::string controller : {"pid", "pid-feedforward"}) {
      SCOPED_TRACE(gains + " " + controller);
      const CliResult r =
          run("simulate --robot planar2 --trajectory " + traj + " --out " + path("bad.csv") +
              " --controller " + controller + " --gains " + path(gains) + " --periods 2 --quiet");
      EXPECT_EQ(r.code, 1) << r.err;
      EXPECT_EQ(r.err.rfind("error: simulate: ", 0), 0u) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_NE(r.err.find("--gains FILE"), std::string::npos) << r.err;
      if (gains == "soft.yaml") {
        EXPECT_NE(r.err.find("does not track the reference"), std::string::npos) << r.err;
      }
      EXPECT_FALSE(fs::exists(path("bad.csv")));
      EXPECT_FALSE(fs::exists(path("bad.gains.json")));
    }
  }
}

// The chain of the issue: planar2's excitation as a -march=native build optimised it chattered
// under the historical gains (torque swings of 1136 N·m, identify 28.6 % for the exact model).
// With the rule the run is smooth and identify on the exact model's MuJoCo run fits it.
TEST_F(SimGainsCli, Planar2DefaultChainIdentifiesTheExactModel) {
  const CliResult e = run("excite --robot planar2 --out " + path("traj.csv") +
                          " --harmonics 3 --f0 0.2 --velocity-limit 2 --acceleration-limit 8 "
                          "--rate 200 --max-time 0 --starts 1 --max-evaluations 300 --quiet");
  ASSERT_EQ(e.code, 0) << e.err;
  const CliResult s = run("simulate --robot planar2 --trajectory " + path("traj.csv") + " --out " +
                          path("run.csv") + " --periods 3 --quiet");
  ASSERT_EQ(s.code, 0) << s.err;
  const GainsCsv csv = read_gains_csv(path("run.csv"));
  expect_tracking_without_chatter(csv, 2, csv.rows.size() / 3);
  const CliResult id = run("identify --robot planar2 --data " + path("run.csv") + " --out " +
                           path("r.json") + " --quiet");
  ASSERT_EQ(id.code, 0) << id.err;
  const auto r = nlohmann::json::parse(std::ifstream(path("r.json")));
  EXPECT_LT(r.at("relative_error").get<double>(), 0.01) << id.out;
}

}  // namespace
