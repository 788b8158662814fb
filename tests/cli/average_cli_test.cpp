// `dynid average` (issue 13 item 4) through the binary. Oracle: a CSV written here with a known
// periodic signal and Gaussian noise of known std at a fixed seed.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
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
  // The mean period's noise, unfiltered: the raw std over √(periods) (averaged_noise_std()).
  EXPECT_EQ(j["out"], work("avg.csv"));
  for (int c = 1; c < 3; ++c)
    EXPECT_NEAR(j["channels"][c]["std_averaged"].get<double>(),
                j["channels"][c]["std"].get<double>() / std::sqrt(10.0), 1e-15);
  std::ifstream avg(work("avg.csv"));
  std::string header;
  std::getline(avg, header);
  EXPECT_EQ(header, "t,qr1,q1,tau1");
}

// Issue 26 item 2: average takes the run flags of every command that reads a run. The run
// written here without t, its torque logged as tau1/2 + 0.25: --rate 200 gives its time,
// --torque-scale 2 --torque-bias 1=0.5 give tau1 back (noise std 0.1, mean 0 over a period of a
// sine), --rows keeps the rows asked for.
TEST_F(AverageCli, TakesTheRunFlags) {
  std::ifstream in(work("run.csv"));
  std::ofstream logged(work("logged.csv"));
  std::string line;
  std::getline(in, line);
  logged << "qr1,q1,cur1\n";
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string t, qr, q, tau;
    std::getline(s, t, ',');
    std::getline(s, qr, ',');
    std::getline(s, q, ',');
    std::getline(s, tau, ',');
    logged.precision(17);
    logged << qr << ',' << q << ',' << std::stod(tau) / 2 + 0.25 << '\n';
  }
  logged.close();
  const auto r = run("average --data " + work("logged.csv") +
                     " --rate 200 --columns cur1=tau1 "
                     "--torque-scale 2 --torque-bias 1=0.5 --rows 1:1400 --period 0.7525 --out " +
                     work("avg.csv") + " --json " + work("noise.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(work("noise.json")));
  // 1400 rows at 200 Hz span 6.995 s: 9 periods of 0.7525 s (the whole run holds 10).
  EXPECT_EQ(j["periods"], 9);
  ASSERT_EQ(j["channels"][2]["name"], "tau1");
  const double n = j["residual_samples"].get<double>();
  EXPECT_NEAR(j["channels"][2]["std"].get<double>(), 0.1, 4 * 0.1 / std::sqrt(2 * n));
  std::ifstream avg(work("avg.csv"));
  std::getline(avg, line);
  double sum = 0.0;
  int rows = 0;
  while (std::getline(avg, line)) {
    sum += std::stod(line.substr(line.rfind(',') + 1));
    ++rows;
  }
  ASSERT_GT(rows, 100);
  EXPECT_NEAR(sum / rows, 0.0, 0.02);  // without the bias: 0.5 (times the scale)
  const auto none =
      run("average --data " + work("logged.csv") + " --period 0.7525 --out " + work("x.csv"));
  EXPECT_EQ(none.code, 2) << none.err;
  EXPECT_NE(none.err.find("--rate HZ"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(work("x.csv")));
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

// A period that is not the run's averages unrelated samples: the noise-free reference shows it,
// so it is one error line with the reference's own period, not a mean and noise written.
TEST_F(AverageCli, APeriodTheReferenceDoesNotRepeatWithIsOneErrorLine) {
  const auto r = run("average --data " + work("run.csv") + " --period 0.5 --out " +
                     work("avg.csv") + " --json " + work("noise.json"));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err.rfind("error: the reference qr1 does not repeat with the period 0.5 s", 0), 0u)
      << r.err;
  EXPECT_NE(r.err.find("its own period is 0.75"), std::string::npos) << r.err;  // to a sample
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(work("avg.csv")));
  EXPECT_FALSE(fs::exists(work("noise.json")));
}

// Seed 2's chain (25 periods averaged, Chebyshev 8 at 80 Hz, 200 Hz) through the binary: three
// 2 s periods at 1 kHz of q1 = an in-band line (0.5 Hz) plus a 150 Hz tone, and its noise-free
// reference qr1. The averaged period comes out at 200 Hz (400 rows) with the line scaled by the
// documented passband ripple only (two-pass gain in [1, 1 + eps^2], no shift), the tone gone,
// and qr1 as logged.
TEST_F(AverageCli, FilterAndDecimateKeepTheBandAndRemoveAnOutOfBandTone) {
  {
    std::ofstream f(work("fast.csv"));
    f.precision(17);
    f << "t,qr1,q1\n";
    for (int k = 0; k < 6000; ++k) {
      const double t = k * 0.001, line = std::sin(2 * M_PI * 0.5 * t);
      f << t << ',' << line << ',' << line + 0.3 * std::sin(2 * M_PI * 150.0 * t) << '\n';
    }
  }
  const std::string base =
      "average --data " + work("fast.csv") + " --period 2 --out " + work("avg.csv");
  const auto r = run(base + " --json " + work("noise.json") +
                     " --filter chebyshev:8 --cutoff 80 --decimate 5");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("kept every 5th sample (200 Hz, 400 rows)"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(work("noise.json")));
  EXPECT_EQ(j["filter"]["rate_hz"], 200.0);
  EXPECT_EQ(j["filter"]["unfiltered"], nlohmann::json::array({"qr1"}));
  std::ifstream avg(work("avg.csv"));
  std::string line;
  std::getline(avg, line);
  EXPECT_EQ(line, "t,qr1,q1");
  const double eps2 = std::pow(10.0, 0.05) - 1.0;  // 0.5 dB ripple
  int rows = 0;
  double worst_gain = 0.0, worst_shape = 0.0, worst_reference = 0.0, gain = 0.0;
  while (std::getline(avg, line)) {
    double t = 0, qr = 0, q = 0;
    char c1 = 0, c2 = 0;
    std::istringstream(line) >> t >> c1 >> qr >> c2 >> q;
    EXPECT_NEAR(t, rows * 0.005, 1e-12);
    const double truth = std::sin(2 * M_PI * 0.5 * t);
    worst_reference = std::max(worst_reference, std::abs(qr - truth));
    if (std::abs(truth) > 0.5) {
      gain = q / truth;  // one gain for the whole line: zero phase
      worst_gain = std::max(worst_gain, std::abs(gain - 1.0));
    }
    ++rows;
  }
  EXPECT_EQ(rows, 400);
  EXPECT_LT(worst_reference, 1e-12);  // not filtered
  EXPECT_GE(gain, 1.0 - 1e-9);
  EXPECT_LE(worst_gain, eps2);  // in-band: the passband ripple, no more
  // The tone (0.3) would move q1/sin by up to 0.6 where |sin| > 0.5; what is left is < 1e-6.
  std::ifstream again(work("avg.csv"));
  std::getline(again, line);
  for (int k = 0; std::getline(again, line); ++k) {
    double t = 0, qr = 0, q = 0;
    char c1 = 0, c2 = 0;
    std::istringstream(line) >> t >> c1 >> qr >> c2 >> q;
    worst_shape = std::max(worst_shape, std::abs(q - gain * std::sin(2 * M_PI * 0.5 * t)));
  }
  EXPECT_LT(worst_shape, 1e-6);
  // A factor that does not divide the 2000 samples, and an aliasing one: one error, no output.
  fs::remove(work("avg.csv"));
  const auto bad = run(base + " --filter chebyshev:8 --cutoff 80 --decimate 3");
  EXPECT_EQ(bad.code, 1);
  EXPECT_EQ(bad.err.rfind("error: decimation by 3 does not divide the period's 2000 samples", 0),
            0u)
      << bad.err;
  const auto alias = run(base + " --filter chebyshev:8 --cutoff 80 --decimate 10");
  EXPECT_EQ(alias.code, 1);
  EXPECT_NE(alias.err.find("would alias"), std::string::npos) << alias.err;
  const auto usage = run(base + " --decimate 5");
  EXPECT_EQ(usage.code, 2);
  EXPECT_EQ(usage.err,
            "error: --decimate 5 needs a low-pass against aliasing: give --filter and --cutoff "
            "too\n");
  EXPECT_FALSE(fs::exists(work("avg.csv")));
}

}  // namespace
}  // namespace dynid
