// dynid excite when the optimiser finds no trajectory that meets the limits (issue 28 item 9): it
// used to write the least-violating trajectory and exit 0 ("constraints VIOLATED"). Now that is
// one `error:` line naming the tightest constraint, what it reaches and the flag that relaxes it,
// exit 1, nothing written; with --allow-violations the trajectory is written with a warning, and
// the JSON's margins say by how much (oracle: the inverse dynamics of the written trajectory).
// `dynid run` stops at such an excite stage: tests/cli/run_cli_test.cpp.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/model/robots.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

class ExciteCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("excite_cli_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  fs::path dir_;
};

// planar2 cannot hold its own weight with 0.5 N·m at the shoulder (gravity needs about 14 N·m
// there on any trajectory that leaves the hanging pose); velocity and acceleration limits bound
// the coefficients. One short start, no wall-clock budget: deterministic.
const std::string kInfeasible =
    "excite --robot planar2 --harmonics 3 --f0 0.5 --velocity-limit 2 --acceleration-limit 8 "
    "--torque-limit 0.5 --starts 1 --max-evaluations 100 --max-time 0";

TEST_F(ExciteCli, ConstraintsThatCannotBeMetAreOneErrorNamingTheTightestAndItsFlag) {
  const auto r = run(kInfeasible + " --out " + path("traj.csv") + " --json " + path("c.json"));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
  const std::string line = r.err.substr(r.err.rfind("error: "));
  EXPECT_NE(line.find("meets its constraints"), std::string::npos) << line;
  EXPECT_NE(line.find("the tightest, torque q1, reaches"), std::string::npos) << line;
  EXPECT_NE(line.find("above its limit 0.5 N·m"), std::string::npos) << line;
  EXPECT_NE(line.find("raise --torque-limit"), std::string::npos) << line;
  EXPECT_NE(line.find("--allow-violations"), std::string::npos) << line;
  EXPECT_FALSE(fs::exists(path("traj.csv")));
  EXPECT_FALSE(fs::exists(path("c.json")));
  EXPECT_EQ(r.out.find("wrote"), std::string::npos) << r.out;
}

TEST_F(ExciteCli, AllowViolationsWritesTheTrajectoryWithAWarningAndItsMargins) {
  const auto r = run(kInfeasible + " --allow-violations --rate 1000 --out " + path("traj.csv") +
                     " --json " + path("c.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("warning: no excitation of 'planar2' found meets its constraints"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("torque q1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("written anyway: --allow-violations"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("constraints VIOLATED"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(std::ifstream(path("c.json")));
  EXPECT_FALSE(j["constraints_satisfied"].get<bool>());
  nlohmann::json torque;
  for (const auto& m : j["margins"])
    if (m["name"] == "torque q1") torque = m;
  ASSERT_TRUE(torque.is_object()) << j["margins"].dump();
  EXPECT_EQ(torque["unit"], "N·m");
  EXPECT_DOUBLE_EQ(torque["limit"].get<double>(), 0.5);
  EXPECT_NEAR(torque["margin"].get<double>(),
              torque["limit"].get<double>() - torque["reached"].get<double>(), 1e-9);
  EXPECT_NEAR(torque["relative"].get<double>(), torque["margin"].get<double>() / 0.5, 1e-9);
  // The written trajectory does reach that torque: the model's inverse dynamics on its samples
  // (at 1 kHz, finer than the check grid, so within a fraction of a percent of the peak).
  const Model model = load_robot("planar2");
  const CsvTable t = read_csv(path("traj.csv"));
  double peak = 0.0;
  for (Eigen::Index k = 0; k < t.data.rows(); ++k) {
    const Eigen::Vector2d q(t.data(k, 1), t.data(k, 2)), dq(t.data(k, 3), t.data(k, 4)),
        ddq(t.data(k, 5), t.data(k, 6));
    peak = std::max(peak, std::abs(rnea(model, q, dq, ddq)[0]));
  }
  EXPECT_NEAR(peak, torque["reached"].get<double>(), 0.01 * peak);
  EXPECT_GT(peak, 10.0 * 0.5);
}

TEST_F(ExciteCli, AllowViolationsIsForTheOptimisedExcitationOnly) {
  const auto r =
      run("excite --robot planar2 --family bang-bang --joint 1 --range 0:1 --acceleration 2 "
          "--allow-violations --out " +
          path("ref.csv"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
  EXPECT_NE(r.err.find("--allow-violations is for the optimised --family fourier"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(path("ref.csv")));
}

}  // namespace
}  // namespace dynid
