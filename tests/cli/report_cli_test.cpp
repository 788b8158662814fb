// `dynid report` and the --report flags end to end: every result kind dynid writes becomes a page
// that headless Chromium renders without a script error and with points in every chart.
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

namespace dynid {
namespace {

namespace fs = std::filesystem;

class ReportCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("dynid_report_" + std::to_string(::getpid()) + "_" + info->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // A planar2-like run: sines on both joints, torques of an arbitrary smooth law plus Gaussian
  // noise (the report shows whatever identify makes of it; nothing here checks the fit).
  void write_run(const std::string& file) const {
    std::ofstream f(file);
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 0.05);
    f << "t,q1,q2,tau1,tau2\n";
    for (int k = 0; k < 1500; ++k) {
      const double t = k * 0.01;
      const double q1 = std::sin(0.7 * t) + 0.3 * std::sin(2.1 * t), q2 = 0.8 * std::cos(1.3 * t);
      f << t << ',' << q1 << ',' << q2 << ','
        << 20.0 * std::cos(q1) + 3.0 * std::sin(2.1 * t) + noise(rng) << ','
        << 4.0 * std::cos(q1 + q2) - 1.5 * std::cos(1.3 * t) + noise(rng) << '\n';
    }
  }

  void expect_renders(const std::string& html, const std::vector<std::string>& kinds) const {
    const testing::RenderedReport r = testing::render_in_chromium(html, dir_);
    ASSERT_EQ(r.exit_code, 0) << r.log;
    EXPECT_EQ(r.body.count("data-report-status") ? r.body.at("data-report-status") : "", "ok")
        << "errors " << r.body.count("data-errors") << "\n"
        << r.log;
    EXPECT_EQ(r.body.at("data-errors"), "0") << r.log;
    EXPECT_EQ(r.body.at("data-empty-charts"), "0");
    EXPECT_EQ(r.log.find("Uncaught"), std::string::npos) << r.log;
    ASSERT_EQ(r.sections.size(), kinds.size());
    for (size_t i = 0; i < kinds.size(); ++i) {
      SCOPED_TRACE(kinds[i]);
      EXPECT_EQ(r.sections[i].at("data-kind"), kinds[i]);
      EXPECT_GT(std::stoi(r.sections[i].at("data-charts")), 0);
      EXPECT_EQ(r.sections[i].at("data-empty-charts"), "0");
    }
  }

  fs::path dir_;
};

TEST_F(ReportCli, EveryResultKindRendersInChromium) {
  write_run(path("run.csv"));
  auto r = run("identify -r planar2 -d " + path("run.csv") +
               " --friction viscous --estimator rls --history " + path("history.csv") + " --out " +
               path("id.json") + " --report " + path("id.html"));
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(fs::exists(path("id.html")));
  const auto id = nlohmann::json::parse(std::ifstream(path("id.json")));
  ASSERT_TRUE(id.contains("plot"));
  EXPECT_EQ(id["plot"]["joints"].size(), 2u);
  EXPECT_EQ(id["plot"]["history"]["parameters"].size(), id["parameters"].size());
  r = run("validate -r planar2 -p " + path("id.json") + " -d " + path("run.csv") + " --json " +
          path("val.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("average -d " + path("run.csv") + " --period 5 -o " + path("avg.csv") + " --json " +
          path("avg.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r =
      run("excite -r planar2 --harmonics 3 --f0 0.2 --velocity-limit 2 --acceleration-limit 8 "
          "--rate 50 --max-time 0 --starts 1 --max-evaluations 100 -o " +
          path("traj.csv") + " --json " + path("ex.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  // stderr is a file here: no progress line (its carriage-return redraws are for terminals).
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  // A result of a kind the report does not know: its scalar facts and parameters.
  std::ofstream(path("other.json"))
      << R"({"command": "future", "rms": 0.5, "parameters": [{"name": "k1", "value": 2.0,
             "std": 0.1, "relative_std_percent": 5.0, "ci_low": 1.7, "ci_high": 2.3}]})";
  r = run("report --in " + path("id.json") + " --in " + path("val.json") + " --in " +
          path("avg.json") + " --in " + path("ex.json") + " --in " + path("other.json") +
          " --out " + path("all.html"));
  ASSERT_EQ(r.code, 0) << r.err;
  expect_renders(path("all.html"), {"identify", "validate", "average", "excite", "generic"});
  // identify --report is the same page as dynid report of its result alone.
  r = run("report --in " + path("id.json") + " --out " + path("one.html"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(testing::slurp(path("id.html")).size(), testing::slurp(path("one.html")).size());
}

// The kinds that come from simulated experiments, in one page (one Chromium start): the integral
// model's energy fit (seed 1 Fig. 5), the gravity, friction and decoupled experiments, validation
// by simulation and the controller comparison. Native plant, short runs.
TEST_F(ReportCli, ExperimentSimulationAndControlKindsRenderInChromium) {
  // One 4 s period of two harmonics per joint at 200 Hz (as tests/cli/control_cli_test.cpp).
  {
    std::ofstream f(path("traj.csv"));
    f << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
    const double w = M_PI / 2;
    for (int k = 0; k < 800; ++k) {
      const double t = k / 200.0;
      f << t << ',' << 0.6 * std::sin(w * t) + 0.2 * std::sin(3 * w * t + 1) << ','
        << 0.4 * std::sin(2 * w * t) + 0.3 * std::cos(w * t) - 0.3 << ','
        << 0.6 * w * std::cos(w * t) + 0.6 * w * std::cos(3 * w * t + 1) << ','
        << 0.8 * w * std::cos(2 * w * t) - 0.3 * w * std::sin(w * t) << ','
        << -0.6 * w * w * std::sin(w * t) - 1.8 * w * w * std::sin(3 * w * t + 1) << ','
        << -1.6 * w * w * std::sin(2 * w * t) - 0.3 * w * w * std::cos(w * t) << '\n';
    }
  }
  const std::string noise = " --engine native --torque-noise 0.02 --position-noise 1e-5";
  auto r = run("simulate --robot planar2 --trajectory " + path("traj.csv") + " --out " +
               path("pid.csv") + " --periods 3 --controller pid" + noise);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("identify -r planar2 -d " + path("pid.csv") + " --out " + path("id.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("identify -r planar2 --model integral -d " + path("pid.csv") + " --out " +
          path("integral.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  // The energy section: measured work per interval against the fitted model's. Independent of
  // the report: the model explains the measured work (a wrong column or sign would not).
  const auto integral = nlohmann::json::parse(std::ifstream(path("integral.json")));
  ASSERT_TRUE(integral["plot"]["energy"].is_object()) << integral["plot"].dump().substr(0, 300);
  const auto& measured = integral["plot"]["energy"]["measured"];
  const auto& predicted = integral["plot"]["energy"]["predicted"];
  ASSERT_GT(measured.size(), 50u);
  ASSERT_EQ(measured.size(), predicted.size());
  ASSERT_EQ(measured.size(), integral["plot"]["energy"]["t"].size());
  double e2 = 0.0, y2 = 0.0;
  for (size_t i = 0; i < measured.size(); ++i) {
    e2 += std::pow(measured[i].get<double>() - predicted[i].get<double>(), 2);
    y2 += std::pow(measured[i].get<double>(), 2);
  }
  EXPECT_LT(std::sqrt(e2 / y2), 0.05) << "energy fit " << std::sqrt(e2 / y2);  // 0.003 measured
  // Dedicated experiments: gravity of the elbow from slopes, friction of the shoulder from
  // bang-bang moves (as tests/cli/identify_models_cli_test.cpp).
  const std::pair<std::string, std::string> experiments[] = {
      {"gravity",
       "--family slope --joint 2 --range -1.2:1.2 --velocity 0.6 --acceleration 2 --pose 0.3,0 "
       "--cycles 1"},
      {"friction", "--family bang-bang --joint 1 --range -1:1 --acceleration 4 --pose 0,0.5"}};
  const std::string joint[] = {"2", "1"};
  for (int e = 0; e < 2; ++e) {
    const std::string& name = experiments[e].first;
    r = run("excite --robot planar2 " + experiments[e].second + " --rate 200 --out " +
            path(name + "_ref.csv"));
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("simulate --robot planar2 --trajectory " + path(name + "_ref.csv") +
            " --periods 2 --out " + path(name + ".csv") + noise);
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("identify --robot planar2 --model " + name + " --joint " + joint[e] + " --data " +
            path(name + ".csv") + " --out " + path(name + ".json"));
    ASSERT_EQ(r.code, 0) << r.err;
  }
  // The joint-decoupled model (eqs. 21–22) of the shoulder from the same one-joint run.
  r = run("identify --robot planar2 --model decoupled --joint 1 --data " + path("friction.csv") +
          " --out " + path("decoupled.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("simulate --robot planar2 --trajectory " + path("traj.csv") + " --out " + path("ct.csv") +
          " --periods 2 --controller computed-torque --params " + path("id.json") + noise);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("validate --mode simulation --robot planar2 --params " + path("id.json") + " --data " +
          path("ct.csv") + " --trajectory " + path("traj.csv") + " --engine native --json " +
          path("valsim.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("compare-control --robot planar2 --params " + path("id.json") + " --trajectory " +
          path("traj.csv") + " --engine native --json " + path("cmp.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("report --in " + path("integral.json") + " --in " + path("gravity.json") + " --in " +
          path("friction.json") + " --in " + path("decoupled.json") + " --in " +
          path("valsim.json") + " --in " + path("cmp.json") + " --out " + path("kinds.html"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string page = testing::slurp(path("kinds.html"));
  EXPECT_NE(page.find("Energy over the intervals"), std::string::npos);
  EXPECT_NE(page.find("Tracking error RMS per joint"), std::string::npos);
  expect_renders(path("kinds.html"), {"identify", "experiment", "experiment", "experiment",
                                      "validate-simulation", "compare-control"});
}

TEST_F(ReportCli, BadInputsGiveOneErrorLineAndNoPage) {
  std::ofstream(path("broken.json")) << "{\"parameters\": [";
  std::ofstream(path("list.json")) << "[1, 2]";
  const std::pair<std::string, std::string> cases[] = {
      {"report --in " + path("missing.json") + " --out " + path("r.html"), "cannot open"},
      {"report --in " + path("broken.json") + " --out " + path("r.html"), "is not valid JSON"},
      {"report --in " + path("list.json") + " --out " + path("r.html"), "not an object"},
      {"report --in " + dir_.string() + " --out " + path("r.html"), "is a folder"},
      {"report --in " + path("list.json") + " --out " + path("no/r.html"), "does not exist"}};
  for (const auto& [args, part] : cases) {
    SCOPED_TRACE(args);
    const auto r = run(args);
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("r.html")));
  }
  const auto usage = run("report --out " + path("r.html"));
  EXPECT_EQ(usage.code, 2) << usage.err;
}

}  // namespace
}  // namespace dynid
