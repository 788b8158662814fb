// Issue 31 through the binary: identify --stream --partial and dynid merge give the result of one
// stream over all the runs; parts of other options and damaged parts are refused with one error
// line and nothing written; dynid compare flags a changed friction parameter and writes its page.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"
#include "support/headless_chromium.hpp"
#include "support/planar2.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

class FleetCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("dynid_fleet_" + std::to_string(::getpid()) + "_" + info->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // A planar2 run from the closed form of tests/support/planar2.hpp (not by dynid) with viscous
  // friction fv2·dq on joint 2 and white torque noise (σ 0.1 N·m, about 1 % of the torques);
  // `phase` [s] and `seed` make runs differ.
  std::string planar2_fleet_run(const std::string& name, double fv2, double phase,
                                unsigned seed) const {
    const std::string file = path(name);
    std::ofstream f(file);
    f.precision(12);
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.1);
    f << "t,q1,q2,dq1,dq2,ddq1,ddq2,tau1,tau2\n";
    const int offset = static_cast<int>(std::lround(phase / 0.01));
    for (int k = 0; k < 1500; ++k) {
      const testing::Planar2Sample s = testing::planar2_sample(k + offset, 0.01);
      f << k * 0.01 << ',' << s.q[0] << ',' << s.q[1] << ',' << s.dq[0] << ',' << s.dq[1] << ','
        << s.ddq[0] << ',' << s.ddq[1] << ',' << s.tau[0] + noise(rng) << ','
        << s.tau[1] + fv2 * s.dq[1] + noise(rng) << '\n';
    }
    return file;
  }

  static nlohmann::json load(const std::string& file) {
    return nlohmann::json::parse(std::ifstream(file));
  }

  fs::path dir_;
};

const std::string kFleetStream =
    " -r planar2 --stream --filter none --friction viscous --no-armature";

// Estimates and σ equal up to the round-off of another summation order (1e-10 of the larger of
// |value| and σ), and the same runs.
void expect_same_merged_result(const nlohmann::json& a, const nlohmann::json& b) {
  ASSERT_EQ(a["parameters"].size(), b["parameters"].size());
  for (std::size_t i = 0; i < a["parameters"].size(); ++i) {
    const auto& p = a["parameters"][i];
    const auto& q = b["parameters"][i];
    ASSERT_EQ(p["name"], q["name"]);
    const double v = p["value"], s = p["std"];
    EXPECT_LE(std::abs(v - q["value"].get<double>()), 1e-10 * std::max(std::abs(v), s)) << p;
    EXPECT_LE(std::abs(s - q["std"].get<double>()), 1e-10 * s) << p;
  }
  EXPECT_EQ(a["rows"], b["rows"]);
  EXPECT_EQ(a["samples"], b["samples"]);
  EXPECT_NEAR(a["relative_error"].get<double>(), b["relative_error"].get<double>(), 1e-12);
  EXPECT_EQ(a["runs"].size(), b["runs"].size());
}

TEST_F(FleetCli, PartialsMergeToTheStreamOverAllRuns) {
  const std::string r1 = planar2_fleet_run("r1.csv", 0.8, 0.0, 1),
                    r2 = planar2_fleet_run("r2.csv", 0.8, 3.0, 2),
                    r3 = planar2_fleet_run("r3.csv", 0.8, 7.0, 3);
  auto r = run("identify" + kFleetStream + " -d " + r1 + " -d " + r2 + " -d " + r3 + " -o " +
               path("all.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("identify" + kFleetStream + " -d " + r1 + " --partial " + path("p1.dpart"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("identify" + kFleetStream + " -d " + r2 + " -d " + r3 + " --partial " +
          path("p23.dpart") + " -o " + path("r23.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(path("r23.json")));
  r = run("merge " + path("p23.dpart") + " " + path("p1.dpart") + " -o " + path("m.json") +
          " --partial " + path("m.dpart") + " --report " + path("m.html"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json all = load(path("all.json")), merged = load(path("m.json"));
  expect_same_merged_result(all, merged);
  EXPECT_EQ(merged["options"]["data_runs"], nlohmann::json::array({r2, r3, r1}));
  EXPECT_EQ(merged["options"]["robot"], "planar2");
  // The merged part is a part like any other: solved alone, the same result.
  r = run("merge " + path("m.dpart") + " -o " + path("m2.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  expect_same_merged_result(all, load(path("m2.json")));

  // --partial and --householder belong to --stream; --out or --partial is needed.
  r = run("identify -r planar2 --filter none -d " + r1 + " --partial " + path("x.dpart"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::error_contract_problem(r.err), "");
  r = run("identify" + kFleetStream + " -d " + r1);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--out is required"), std::string::npos) << r.err;
  r = run("merge " + path("p1.dpart"));
  EXPECT_EQ(r.code, 2);
}

TEST_F(FleetCli, PartsOfOtherOptionsOrDamagedAreRefusedWithNothingWritten) {
  const std::string r1 = planar2_fleet_run("r1.csv", 0.8, 0.0, 1);
  ASSERT_EQ(run("identify" + kFleetStream + " -d " + r1 + " --partial " + path("p1.dpart")).code,
            0);
  auto r = run("identify -r planar2 --stream --filter none --friction none -d " + r1 +
               " --partial " + path("other.dpart"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("merge " + path("p1.dpart") + " " + path("other.dpart") + " -o " + path("bad.json"));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(testing::error_contract_problem(r.err), "");
  EXPECT_NE(r.err.find("cannot merge"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("layout"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("bad.json")));
  // Another robot whose parameter names differ: the merge refuses to solve with it.
  r = run("merge " + path("p1.dpart") + " -r puma560 -o " + path("bad.json"));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(testing::error_contract_problem(r.err), "");
  EXPECT_FALSE(fs::exists(path("bad.json")));
  // No output over an input (file_flags.cpp).
  const std::string before = testing::slurp(path("p1.dpart"));
  r = run("merge " + path("p1.dpart") + " --partial " + path("p1.dpart"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is the input"), std::string::npos) << r.err;
  EXPECT_EQ(testing::slurp(path("p1.dpart")), before);
  // Truncated copies, cut in the header, in the summaries and just before the end.
  const std::string bytes = testing::slurp(path("p1.dpart"));
  for (const std::size_t cut :
       {std::size_t{5}, std::size_t{14}, std::size_t{40}, bytes.size() / 2, bytes.size() - 1}) {
    std::ofstream(path("cut.dpart"), std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(cut));
    r = run("merge " + path("p1.dpart") + " " + path("cut.dpart") + " -o " + path("bad.json"));
    EXPECT_EQ(r.code, 1) << cut;
    EXPECT_EQ(testing::error_contract_problem(r.err), "") << cut;
    EXPECT_NE(r.err.find(path("cut.dpart")), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("bad.json")));
  }
}

TEST_F(FleetCli, CompareFlagsTheChangedFrictionAndWritesItsPage) {
  // Three nights of one arm; on the third its joint-2 viscous friction is 50 % higher.
  const double fv[] = {0.8, 0.8, 1.2};
  std::string results;
  for (int night = 0; night < 3; ++night) {
    const std::string run_file = planar2_fleet_run("night" + std::to_string(night) + ".csv",
                                                   fv[night], 2.0 * night, 10 + night);
    const std::string out = path("night" + std::to_string(night) + ".json");
    const auto r = run("identify" + kFleetStream + " -d " + run_file + " -o " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    results += " " + out;
  }
  auto r = run("compare" + results + " --alpha 0.01 --json " + path("cmp.json") + " --report " +
               path("cmp.html"));
  ASSERT_EQ(r.code, 0) << r.err;
  // The streamed results have white-noise σ: said once per result.
  EXPECT_NE(r.err.find("white-noise"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("Fv2 (friction)"), std::string::npos) << r.out;
  const nlohmann::json c = load(path("cmp.json"));
  EXPECT_EQ(c["command"], "compare");
  EXPECT_EQ(c["correction"], "holm");
  ASSERT_EQ(c["flagged"].size(), 1u) << c["flagged"];
  EXPECT_EQ(c["flagged"][0]["name"], "Fv2");
  EXPECT_EQ(c["flagged"][0]["result"], 2);
  EXPECT_EQ(c["flagged_friction"], nlohmann::json::array({"Fv2"}));
  const testing::RenderedReport page = testing::render_in_chromium(path("cmp.html"), dir_);
  ASSERT_EQ(page.exit_code, 0) << page.log;
  EXPECT_EQ(page.body.at("data-report-status"), "ok") << page.log;
  EXPECT_EQ(page.body.at("data-empty-charts"), "0");
  ASSERT_EQ(page.sections.size(), 1u);
  EXPECT_EQ(page.sections[0].at("data-kind"), "compare");
  // z-scores plus the trends of the friction parameters Fv1 and Fv2.
  EXPECT_EQ(page.sections[0].at("data-charts"), "3");

  r = run("compare" + results + " --json " + path("night0.json"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is the input"), std::string::npos) << r.err;
  r = run("compare " + path("night0.json"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::error_contract_problem(r.err), "");
  r = run("compare" + results + " --alpha 1.5");
  EXPECT_EQ(r.code, 2);
}

}  // namespace
}  // namespace dynid
