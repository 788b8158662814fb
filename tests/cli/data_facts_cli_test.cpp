// Issue 26 item 5 through the binary: what the data show, said plainly. Joints that move in
// lockstep are named with what that leaves undetermined (identify's warnings, its JSON and the
// physical fit's advice, never "a run in which the joint moves"); torque channels that are mostly
// exact zeros are flagged; every base parameter carries the nominal model's value beside the
// estimate (null where the model has none). Oracle: planar2 runs generated here from the closed
// form of tests/support/planar2.hpp (not by dynid), whose ZZ1R = I1 + m1·c1² + m2·l1² is known.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"
#include "support/planar2.hpp"

namespace {

using dynid::testing::CliResult;

// ZZ1R of examples/robots/planar2.yaml: I1 + m1·c1² + m2·l1² (slender rods).
constexpr double kFactsZz1r = 2.0 / 12 + 2.0 * 0.25 + 1.5;

class DataFactsCli : public dynid::testing::CliScratchTest {
 protected:
  // 20 s at 100 Hz of planar2 (closed-form torques). lockstep: the elbow follows the shoulder,
  // q2 = 0.6·q1 + 0.2; else the independent excitation of planar2_sample(). zero_fraction: that
  // share of tau2's samples written as exact zeros (an unlogged channel).
  std::string write_run(const std::string& name, bool lockstep, double zero_fraction = 0.0) const {
    dynid::testing::Planar2 arm;
    arm.I1 = 2.0 / 12;
    arm.I2 = 1.5 * 0.64 / 12;
    std::ofstream f(path(name));
    f.precision(17);
    f << "t,q1,q2,dq1,dq2,ddq1,ddq2,tau1,tau2\n";
    const int m = 2000;
    for (int k = 0; k < m; ++k) {
      dynid::testing::Planar2Sample s = dynid::testing::planar2_sample(k, 0.01);
      if (lockstep) {
        s.q[1] = 0.6 * s.q[0] + 0.2;
        s.dq[1] = 0.6 * s.dq[0];
        s.ddq[1] = 0.6 * s.ddq[0];
        const Eigen::Vector2d tau =
            arm.torque({s.q[0], s.q[1]}, {s.dq[0], s.dq[1]}, {s.ddq[0], s.ddq[1]});
        s.tau[0] = tau[0];
        s.tau[1] = tau[1];
      }
      if (k < zero_fraction * m) s.tau[1] = 0.0;
      f << s.t << ',' << s.q[0] << ',' << s.q[1] << ',' << s.dq[0] << ',' << s.dq[1] << ','
        << s.ddq[0] << ',' << s.ddq[1] << ',' << s.tau[0] << ',' << s.tau[1] << '\n';
    }
    return path(name);
  }
  static nlohmann::json load(const std::string& p) {
    return nlohmann::json::parse(std::ifstream(p));
  }
  static std::vector<std::string> warning_lines(const std::string& err) {
    std::vector<std::string> out;
    size_t at = 0;
    while ((at = err.find("warning: ", at)) != std::string::npos) {
      const size_t end = err.find('\n', at);
      out.push_back(err.substr(at, end - at));
      at = end;
    }
    return out;
  }
};

TEST_F(DataFactsCli, LockstepJointsAreNamedWithWhatTheyLeaveUndetermined) {
  const std::string data = write_run("lockstep.csv", true);
  const CliResult r = run("identify --robot planar2 --data " + data +
                          " --filter none --friction viscous --physical --out " + path("r.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = load(path("r.json"));
  ASSERT_EQ(j.at("lockstep").size(), 1u) << j.at("lockstep").dump();
  const auto& pair = j.at("lockstep")[0];
  EXPECT_EQ(pair.at("joints"), nlohmann::json({"shoulder", "elbow"}));
  EXPECT_NEAR(pair.at("correlation").get<double>(), 1.0, 1e-6);
  // Whatever the data leave undetermined of the two joints is named, and only that.
  for (const auto& name : pair.at("undetermined")) {
    const auto& ne = j.at("not_excited");
    const bool not_excited = std::find(ne.begin(), ne.end(), name) != ne.end();
    bool wide = false;
    for (const auto& p : j.at("parameters")) {
      if (p.at("name") == name) wide = !(p.at("relative_std_percent").get<double>() <= 100.0);
    }
    EXPECT_TRUE(not_excited || wide) << name;
  }
  // The warnings say it once, and never advise a run in which a joint moves: both moved.
  int lockstep_lines = 0;
  // identify's warnings end its table on stdout; the physical fit's are on stderr.
  for (const std::string& w : warning_lines(r.out + r.err)) {
    if (w.find("shoulder and elbow move in lockstep (velocity correlation 1)") != std::string::npos)
      ++lockstep_lines;
    EXPECT_EQ(w.find("a run in which"), std::string::npos) << w;
  }
  EXPECT_GE(lockstep_lines, 2) << r.out << r.err;  // identify's warning, the fit's advice
  EXPECT_NE(r.err.find("warning: --physical: "), std::string::npos) << r.err;

  // The independent excitation has no lockstep.
  const CliResult free = run("identify --robot planar2 --data " + write_run("free.csv", false) +
                             " --filter none --friction viscous --out " + path("f.json"));
  ASSERT_EQ(free.code, 0) << free.err;
  EXPECT_TRUE(load(path("f.json")).at("lockstep").empty());
  EXPECT_EQ((free.out + free.err).find("lockstep"), std::string::npos) << free.out;
}

TEST_F(DataFactsCli, MostlyZeroTorqueChannelIsFlagged) {
  const std::string data = write_run("gaps.csv", false, 0.7);
  const CliResult r = run("identify --robot planar2 --data " + data +
                          " --filter none --friction none --no-armature --out " + path("r.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("warning: torque exactly zero in most samples for elbow (70 %)"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("for shoulder"), std::string::npos) << r.out;
  // A fully logged run is not flagged.
  const CliResult full =
      run("identify --robot planar2 --data " + write_run("full.csv", false) +
          " --filter none --friction none --no-armature --out " + path("f.json"));
  ASSERT_EQ(full.code, 0) << full.err;
  EXPECT_EQ((full.out + full.err).find("exactly zero"), std::string::npos) << full.out;
}

TEST_F(DataFactsCli, BaseParametersCarryTheNominalValue) {
  const CliResult r =
      run("identify --robot planar2 --data " + write_run("run.csv", false) +
          " --filter none --friction viscous --no-armature --out " + path("r.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = load(path("r.json"));
  bool zz1r = false, fv = false;
  for (const auto& p : j.at("parameters")) {
    ASSERT_TRUE(p.contains("nominal")) << p.dump();
    if (p.at("name") == "ZZ1R") {
      zz1r = true;
      EXPECT_NEAR(p.at("nominal").get<double>(), kFactsZz1r, 1e-9);
      // Exact data of the nominal model: the estimate lands on it.
      EXPECT_NEAR(p.at("value").get<double>(), kFactsZz1r, 1e-6);
    }
    if (p.at("name") == "Fv1" || p.at("name") == "Fv2") {
      fv = true;
      EXPECT_TRUE(p.at("nominal").is_null()) << p.dump();  // planar2.yaml gives no friction
    }
  }
  EXPECT_TRUE(zz1r && fv) << j.at("parameters").dump();
  // The table on stdout has the nominal column, "-" where there is none.
  EXPECT_NE(r.out.find("nominal"), std::string::npos) << r.out;
  // The HTML report's parameter table has it too.
  const CliResult html = run("report --in " + path("r.json") + " --out " + path("r.html"));
  ASSERT_EQ(html.code, 0) << html.err;
  const std::string page = dynid::testing::slurp(path("r.html"));
  EXPECT_NE(page.find("\"nominal\""), std::string::npos);
}

}  // namespace
