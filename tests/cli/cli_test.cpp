// Runs the built dynid binary (compile definition DYNID_BINARY) and checks stdout, stderr and the
// exit code. Oracles: the planar2 closed form of docs/methods/model.md, the joint-term formula
// tau += Ia ddq + Fv dq + Fc sign(dq) + Fo with the values the model JSON reports, and the robot
// table of docs/methods/model.md for the joint counts.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/io/csv_reader.hpp"
#include "dynid/version.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

using RunResult = testing::CliResult;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("dynid_cli_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Runs `dynid <args>` (args are shell words; paths here contain no spaces).
  RunResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  std::string work(const std::string& name) const { return (dir_ / "work" / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(work(name), std::ios::binary) << text;
    return work(name);
  }
  int work_entries() const {
    int n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_ / "work")) ++n;
    return n;
  }
  /// Exit code `code`, stderr one line starting with "error:" and containing `part`.
  static void expect_error(const RunResult& r, int code, const std::string& part) {
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err << "\nexpected: " << part;
  }

  fs::path dir_;
};

TEST_F(Cli, Version) {
  // The commit as git itself reports it for the checkout the tests were built from; a rebuild
  // after a commit is needed for the two to agree, as for any other change.
  std::string commit = "unknown";
  if (std::FILE* git = ::popen(
          ("git -C '" + std::string(DYNID_SOURCE_DIR) + "' rev-parse --short=12 HEAD 2>/dev/null")
              .c_str(),
          "r")) {
    char line[64] = {};
    if (std::fgets(line, sizeof line, git) && std::strlen(line) > 1) {
      commit.assign(line, std::strcspn(line, "\n"));
    }
    ::pclose(git);
  }
  const RunResult r = run("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, std::string("dynid ") + kVersion + " (commit " + commit + ")\n");
}

TEST_F(Cli, HelpOnEveryCommandDocumentsEveryFlag) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> commands{
      {"", {"--version", "--help", "model", "inverse-dynamics", "demo"}},
      {"model", {"--robot", "--json", "--help"}},
      {"inverse-dynamics", {"--robot", "--in", "--out", "--no-friction", "--columns", "--help"}},
      {"demo", {"--out", "--help"}}};
  for (const auto& [command, flags] : commands) {
    const RunResult r = run(command + " --help");
    EXPECT_EQ(r.code, 0) << command;
    for (const auto& flag : flags) {
      EXPECT_NE(r.out.find(flag), std::string::npos) << command << " --help lacks " << flag;
    }
  }
}

TEST_F(Cli, UsageErrorsExitTwo) {
  expect_error(run(""), 2, "subcommand is required");
  expect_error(run("model"), 2, "--robot is required");
  expect_error(run("model --robot planar2 --bogus"), 2, "--bogus");
  expect_error(run("inverse-dynamics --robot planar2 --in x.csv --out y.csv --columns a"), 2,
               "--columns entry 'a' is not from=to");
}

TEST_F(Cli, ModelJsonForEveryBuiltin) {
  // Joint counts from the robot table of docs/methods/model.md.
  const std::vector<std::pair<std::string, int>> robots{
      {"puma560", 6}, {"planar2", 2}, {"irp6", 3}, {"iiwa14", 7}};
  for (const auto& [robot, dof] : robots) {
    const std::string json_path = work(robot + ".json");
    const RunResult r = run("model --robot " + robot + " --json " + json_path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("dof        " + std::to_string(dof)), std::string::npos) << r.out;
    std::ifstream in(json_path);
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const char* key : {"dof", "joints", "standard_parameters", "friction", "transmission",
                            "gravity", "version"}) {
      EXPECT_TRUE(j.contains(key)) << robot << " lacks " << key;
    }
    EXPECT_EQ(j["dof"].get<int>(), dof);
    EXPECT_EQ(j["version"].get<std::string>(), kVersion);
    ASSERT_EQ(j["joints"].size(), static_cast<std::size_t>(dof));
    for (const auto& joint : j["joints"]) {
      for (const char* key : {"name", "type", "parent", "lower", "upper", "velocity", "effort"}) {
        EXPECT_TRUE(joint.contains(key)) << robot << " joint lacks " << key;
      }
    }
    ASSERT_EQ(j["standard_parameters"].size(), static_cast<std::size_t>(10 * dof));
    EXPECT_EQ(j["standard_parameters"][0]["name"], "XX1");
    EXPECT_EQ(j["standard_parameters"][10 * dof - 1]["name"], "M" + std::to_string(dof));
    EXPECT_EQ(j["friction"].size(), static_cast<std::size_t>(dof));
    EXPECT_EQ(j["transmission"]["N"].size(), static_cast<std::size_t>(dof));
    EXPECT_EQ(j["transmission"]["q_offset"].size(), static_cast<std::size_t>(dof));
  }
  // planar2 (docs/methods/model.md): no limits -> null; M1 = 2, MX2 = 0.6; gravity along -y.
  std::ifstream in(work("planar2.json"));
  const nlohmann::json p = nlohmann::json::parse(in);
  EXPECT_TRUE(p["joints"][0]["lower"].is_null());
  EXPECT_TRUE(p["joints"][1]["effort"].is_null());
  EXPECT_TRUE(p["joints"][0]["parent"].is_null());
  EXPECT_EQ(p["joints"][1]["parent"], "shoulder");
  EXPECT_EQ(p["standard_parameters"][9]["value"].get<double>(), 2.0);
  EXPECT_EQ(p["standard_parameters"][16]["name"], "MX2");
  EXPECT_NEAR(p["standard_parameters"][16]["value"].get<double>(), 0.6, 1e-15);
  EXPECT_EQ(p["gravity"][1].get<double>(), -9.81);
}

/// planar2 closed form, docs/methods/model.md ("planar2: closed-form dynamics").
Eigen::Vector2d planar2_tau(const Eigen::Vector2d& q, const Eigen::Vector2d& dq,
                            const Eigen::Vector2d& ddq) {
  const double m1 = 2, m2 = 1.5, l1 = 1, l2 = 0.8, lc1 = 0.5, lc2 = 0.4, g = 9.81;
  const double c2 = std::cos(q(1));
  Eigen::Matrix2d M;
  M(0, 0) = m1 * l1 * l1 / 3 + m2 * (l1 * l1 + l2 * l2 / 3 + l1 * l2 * c2);
  M(0, 1) = M(1, 0) = m2 * (l2 * l2 / 3 + l1 * lc2 * c2);
  M(1, 1) = m2 * l2 * l2 / 3;
  const double h = m2 * l1 * lc2 * std::sin(q(1));
  const Eigen::Vector2d c(-h * (2 * dq(0) * dq(1) + dq(1) * dq(1)), h * dq(0) * dq(0));
  const Eigen::Vector2d gv(
      g * ((m1 * lc1 + m2 * l1) * std::cos(q(0)) + m2 * lc2 * std::cos(q(0) + q(1))),
      g * m2 * lc2 * std::cos(q(0) + q(1)));
  return M * ddq + c + gv;
}

TEST_F(Cli, InverseDynamicsPlanar2MatchesClosedForm) {
  // Shuffled, joint-named and extra columns; row 1 is the gravity-only check g = (30.411, 5.886).
  const std::string in = write("states.csv",
                               "# planar2 states\n"
                               "ddq2,q_shoulder,extra,t,dq1,q2,dq_elbow,ddq_shoulder\n"
                               "0,0,99,0.0,0,0,0,0\n"
                               "0.9,0.3,99,0.01,0.7,-0.8,-1.1,0.4\n"
                               "-2,1.2,99,0.02,-1.5,2.1,0.25,3\n");
  const std::string out = work("tau.csv");
  const RunResult r = run("inverse-dynamics --robot planar2 --in " + in + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const CsvTable tau = read_csv(out);
  EXPECT_EQ(tau.columns, (std::vector<std::string>{"t", "tau1", "tau2"}));
  ASSERT_EQ(tau.rows(), 3);
  EXPECT_NEAR(tau.data(0, 1), 3.1 * 9.81, 1e-12);  // (m1 lc1 + m2 l1 + m2 lc2) g
  EXPECT_NEAR(tau.data(0, 2), 0.6 * 9.81, 1e-12);  // m2 lc2 g
  const double rows[3][7] = {{0, 0, 0, 0, 0, 0, 0},
                             {0.01, 0.3, -0.8, 0.7, -1.1, 0.4, 0.9},
                             {0.02, 1.2, 2.1, -1.5, 0.25, 3, -2}};
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2d expected =
        planar2_tau({rows[i][1], rows[i][2]}, {rows[i][3], rows[i][4]}, {rows[i][5], rows[i][6]});
    EXPECT_EQ(tau.data(i, 0), rows[i][0]);
    EXPECT_NEAR(tau.data(i, 1), expected(0), 1e-11) << "row " << i;
    EXPECT_NEAR(tau.data(i, 2), expected(1), 1e-11) << "row " << i;
  }
  // --columns renames before lookup; no t column -> no t output.
  const std::string renamed = write("renamed.csv",
                                    "a,b,c,d,e,f\n"
                                    "0.3,-0.8,0.7,-1.1,0.4,0.9\n");
  const std::string out2 = work("tau2.csv");
  const RunResult r2 = run("inverse-dynamics -r planar2 -i " + renamed + " -o " + out2 +
                           " --columns a=q1,b=q2,c=dq1,d=dq2,e=ddq1,f=ddq2");
  ASSERT_EQ(r2.code, 0) << r2.err;
  const CsvTable tau2 = read_csv(out2);
  EXPECT_EQ(tau2.columns, (std::vector<std::string>{"tau1", "tau2"}));
  const Eigen::Vector2d expected = planar2_tau({0.3, -0.8}, {0.7, -1.1}, {0.4, 0.9});
  EXPECT_NEAR(tau2.data(0, 0), expected(0), 1e-11);
  EXPECT_NEAR(tau2.data(0, 1), expected(1), 1e-11);
}

TEST_F(Cli, NoFrictionRemovesExactlyTheJointTerms) {
  // puma560 has Ia, Fv, Fc; the difference must be Ia ddq + Fv dq + Fc sign(dq) + Fo per joint.
  ASSERT_EQ(run("model --robot puma560 --json " + work("puma.json")).code, 0);
  std::ifstream in(work("puma.json"));
  const nlohmann::json model = nlohmann::json::parse(in);
  std::string header = "q1,q2,q3,q4,q5,q6,dq1,dq2,dq3,dq4,dq5,dq6,ddq1,ddq2,ddq3,ddq4,ddq5,ddq6\n";
  const double q[6] = {0.1, -0.4, 0.9, 0.2, -0.3, 0.5};
  const double dq[6] = {0.5, -1.0, 0.25, -0.75, 2.0, -0.1};
  const double ddq[6] = {1.0, 2.0, -3.0, 0.5, -0.5, 4.0};
  std::ostringstream row;
  row.precision(17);
  for (const double* v : {q, dq, ddq}) {
    for (int j = 0; j < 6; ++j) row << v[j] << ((v == ddq && j == 5) ? "\n" : ",");
  }
  const std::string states = write("s.csv", header + row.str());
  ASSERT_EQ(run("inverse-dynamics -r puma560 -i " + states + " -o " + work("with.csv")).code, 0);
  ASSERT_EQ(run("inverse-dynamics -r puma560 -i " + states + " -o " + work("without.csv") +
                " --no-friction")
                .code,
            0);
  const CsvTable with = read_csv(work("with.csv"));
  const CsvTable without = read_csv(work("without.csv"));
  double total = 0;
  for (int j = 0; j < 6; ++j) {
    const auto& f = model["friction"][static_cast<std::size_t>(j)];
    const double expected = f["Ia"].get<double>() * ddq[j] + f["Fv"].get<double>() * dq[j] +
                            f["Fc"].get<double>() * (dq[j] > 0 ? 1 : -1) + f["Fo"].get<double>();
    total += std::abs(expected);
    EXPECT_NEAR(with.data(0, j) - without.data(0, j), expected, 1e-9) << "joint " << j + 1;
  }
  EXPECT_GT(total, 1.0);  // the check is not vacuous
}

TEST_F(Cli, BadInputsGiveOneErrorLineAndNoOutputFile) {
  const std::string out = work("tau.csv");
  expect_error(run("inverse-dynamics -r planar2 -i " + work("missing.csv") + " -o " + out), 1,
               "missing.csv: cannot open");
  const std::string five = write("five.csv",
                                 "q1,q2,q3,q4,q5,dq1,dq2,dq3,dq4,dq5,ddq1,ddq2,ddq3,ddq4,ddq5\n"
                                 "0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n");
  expect_error(run("inverse-dynamics -r puma560 -i " + five + " -o " + out), 1,
               "the file has columns q1..q5 (5 joints) but the model has 6 joints");
  const std::string nan = write("nan.csv", "q1,q2,dq1,dq2,ddq1,ddq2\n0,0,0,0,0,0\n0,nan,0,0,0,0\n");
  expect_error(run("inverse-dynamics -r planar2 -i " + nan + " -o " + out), 1,
               "nan.csv:3: column 'q2' (field 2) of data row 2 is NaN");
  const std::string back =
      write("back.csv", "t,q1,q2,dq1,dq2,ddq1,ddq2\n0,0,0,0,0,0,0\n0,0,0,0,0,0,0\n");
  expect_error(run("inverse-dynamics -r planar2 -i " + back + " -o " + out), 1,
               "back.csv:3: time t = 0 is not greater than 0");
  expect_error(run("inverse-dynamics -r nosuchrobot -i " + nan + " -o " + out), 1,
               "unknown built-in robot 'nosuchrobot'");
  expect_error(run("model --robot nosuchrobot"), 1, "nosuchrobot");
  const std::string ok = write("ok.csv", "q1,q2,dq1,dq2,ddq1,ddq2\n0,0,0,0,0,0\n");
  expect_error(run("inverse-dynamics -r planar2 -i " + ok + " -o " + work("no/dir/t.csv")), 1,
               "t.csv: cannot write");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(work_entries(), 4);  // only the four inputs: no output or temporary file
}

TEST_F(Cli, DemoRunsTheLoopAndWritesFiles) {
  // Fewer periods than the default 25 keep the test short; the loop is the same.
  const RunResult r = run("demo --periods 6 --out " + work("demo"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("identified vs true base parameters"), std::string::npos);
  EXPECT_NE(r.err.find("6/6 done"), std::string::npos);  // progress lines go to stderr
  for (const char* f : {"traj.csv", "excitation.json", "run.csv", "averaged.csv", "result.json",
                        "validation_run.csv", "validation.json"}) {
    EXPECT_TRUE(fs::exists(work("demo") + "/" + f)) << f;
  }
}

}  // namespace
}  // namespace dynid
