// `dynid average` (issue 13 item 4) through the binary. Oracle: a CSV written here with a known
// periodic signal and Gaussian noise of known std at a fixed seed.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

class AverageCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dynid_avgcli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
    // 10.5 periods of 0.7525 s (150.5 samples) at 200 Hz: q1 with N(0, 0.01²) noise, tau1 with
    // N(0, 0.1²), qr1 noise-free.
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g(0.0, 1.0);
    std::ofstream f(work("run.csv"));
    f.precision(17);
    f << "t,qr1,q1,tau1\n";
    for (int k = 0; k < 1580; ++k) {
      const double t = k * 0.005, r = std::sin(2 * M_PI * t / 0.7525);
      f << t << ',' << r << ',' << r + 0.01 * g(rng) << ',' << 3 * r + 0.1 * g(rng) << '\n';
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string work(const std::string& name) const { return (dir_ / "work" / name).string(); }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  fs::path dir_;
};

TEST_F(AverageCli, WritesTheMeanPeriodAndTheNoiseOfEveryChannel) {
  const auto r = run("average --data " + work("run.csv") + " --f0 " + std::to_string(1.0 / 0.7525) +
                     " --out " + work("avg.csv") + " --json " + work("noise.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("averaged 10 periods"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("incomplete period, not used"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(work("noise.json")));
  EXPECT_EQ(j["periods"], 10);
  EXPECT_TRUE(j["interpolated"].get<bool>());
  ASSERT_EQ(j["channels"].size(), 3u);
  EXPECT_EQ(j["channels"][0]["name"], "qr1");
  EXPECT_LT(j["channels"][0]["std"].get<double>(), 1e-4);  // interpolation floor only
  const double n = j["residual_samples"].get<double>();
  EXPECT_NEAR(j["channels"][1]["std"].get<double>(), 0.01, 4 * 0.01 / std::sqrt(2 * n));
  EXPECT_NEAR(j["channels"][2]["std"].get<double>(), 0.1, 4 * 0.1 / std::sqrt(2 * n));
  EXPECT_GT(j["channels"][2]["normality_p"].get<double>(), 1e-3);
  std::ifstream avg(work("avg.csv"));
  std::string header;
  std::getline(avg, header);
  EXPECT_EQ(header, "t,qr1,q1,tau1");
}

TEST_F(AverageCli, APeriodWithoutTwoPeriodsIsOneErrorLineAndNothingWritten) {
  const auto r = run("average --data " + work("run.csv") + " --period 5 --out " + work("avg.csv") +
                     " --json " + work("noise.json"));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err,
            "error: period 5 s gives 1 complete period(s) in the run of 7.9 s (1580 samples from "
            "t = 0 s, skipping 0); averaging needs at least 2: check --period/--f0 or record more "
            "periods\n");
  EXPECT_FALSE(fs::exists(work("avg.csv")));
  EXPECT_FALSE(fs::exists(work("noise.json")));
  const auto u = run("average --data " + work("run.csv") + " --out " + work("avg.csv"));
  EXPECT_EQ(u.code, 2);
  EXPECT_EQ(u.err, "error: give exactly one of --period S or --f0 HZ (> 0)\n");
}

}  // namespace
}  // namespace dynid
