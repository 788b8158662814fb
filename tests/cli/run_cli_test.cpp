// `dynid run project.yaml` (issue 15 item 5) through the binary: a short simulated study end to
// end, its folder (the project copy, every stage's files, nothing partial), a rerun with identical
// results, the identify stage against the same `dynid identify` typed by hand (the oracle: the
// project runner must add nothing to a command), and bad projects as one error line with nothing
// written.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

// Excite -> simulate (MuJoCo, noisy sensors) -> identify on t in [2, 6] s -> validate on the rest.
const char* const kStudy = R"(output: study
robot: planar2
excite:
  harmonics: 3
  f0: 0.5
  rate: 500
  starts: 1
  max-evaluations: 150
  seed: 3
  velocity-limit: 2.0
  acceleration-limit: 8.0
simulate:
  periods: 4
  seed: 11
  torque-noise: 0.05
identify:
  estimator: wls
  time: "2:6"
validate:
  time: "6:"
)";

class RunCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dynid_runcli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path work(const std::string& name) const { return dir_ / "work" / name; }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(work(name), std::ios::binary) << text;
    return work(name).string();
  }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  // Exit `code` and one error line naming `part`, last on stderr after the progress lines of the
  // stages that ran.
  static void expect_error(const testing::CliResult& r, int code, const std::string& part) {
    EXPECT_EQ(r.code, code) << r.err;
    ASSERT_FALSE(r.err.empty());
    const std::string last = r.err.substr(r.err.rfind('\n', r.err.size() - 2) == std::string::npos
                                              ? 0
                                              : r.err.rfind('\n', r.err.size() - 2) + 1);
    EXPECT_EQ(last.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find("error:"), r.err.rfind("error:")) << r.err;
    EXPECT_NE(last.find(part), std::string::npos) << r.err << "\nexpected: " << part;
  }
  // Nothing but the project files: no output folder, no partial one.
  void expect_nothing_written(size_t files) const {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_ / "work")) ++n;
    EXPECT_EQ(n, files);
  }
  fs::path dir_;
};

nlohmann::json read_json(const fs::path& p) {
  return nlohmann::json::parse(std::ifstream(p));
}

TEST_F(RunCli, SimulatedStudyEndToEndAndRerunIsIdentical) {
  const std::string project = write("study.yaml", kStudy);
  const auto r = run("run " + project);
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path out = work("study");
  EXPECT_FALSE(fs::exists(work("study.partial")));
  EXPECT_EQ(testing::slurp(out / "study.yaml"), kStudy);
  for (const char* f : {"commands.txt", "trajectory.csv", "excitation.json", "run.csv",
                        "result.json", "validation.json", "predicted.csv", "identify.txt"}) {
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  }
  const nlohmann::json result = read_json(out / "result.json");
  EXPECT_EQ(result["options"]["estimator"], "wls");
  EXPECT_EQ(result["options"]["time"], "2:6");
  EXPECT_EQ(read_json(out / "validation.json")["joints"].size(), 2u);
  const std::string commands = testing::slurp(out / "commands.txt");
  EXPECT_NE(commands.find("dynid validate --robot planar2 --params result.json --data run.csv"),
            std::string::npos)
      << commands;

  // Oracle: the same identify typed by hand on the study's run gives the same estimate.
  const auto direct = run("identify --robot planar2 --data " + (out / "run.csv").string() +
                          " --out " + work("direct.json").string() + " --estimator wls --time 2:6");
  ASSERT_EQ(direct.code, 0) << direct.err;
  const nlohmann::json hand = read_json(work("direct.json"));
  EXPECT_EQ(hand["parameters"], result["parameters"]);
  EXPECT_EQ(hand["relative_error"], result["relative_error"]);

  // A rerun replaces the folder and writes byte-identical results.
  const std::string first = testing::slurp(out / "result.json"),
                    first_validation = testing::slurp(out / "validation.json");
  const auto again = run("run " + project);
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(testing::slurp(out / "result.json"), first);
  EXPECT_EQ(testing::slurp(out / "validation.json"), first_validation);
}

TEST_F(RunCli, UnknownTopLevelKeyNamesTheValidOnes) {
  const std::string project = write("p.yaml", std::string(kStudy) + "identfy:\n  estimator: ols\n");
  expect_error(run("run " + project), 2,
               "unknown key 'identfy'; valid keys are output, robot, data, model, excite, "
               "simulate, identify, validate");
  expect_nothing_written(1);
}

TEST_F(RunCli, UnknownStageKeyNamesTheCommandsFlags) {
  std::string text = kStudy;
  text.replace(text.find("  estimator: wls"), 16, "  estimatr: wls");
  const std::string project = write("p.yaml", text);
  const auto r = run("run " + project);
  expect_error(r, 2, "identify: unknown key 'estimatr'; valid keys are robot, data, ");
  EXPECT_NE(r.err.find(", history,"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("estimator"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("help"), std::string::npos) << r.err;
  expect_nothing_written(1);
}

TEST_F(RunCli, OutputFlagsBelongToTheRunner) {
  const std::string project =
      write("p.yaml", "output: o\nrobot: planar2\nidentify:\n  out: mine.json\n  data: x.csv\n");
  expect_error(run("run " + project), 2, "identify: 'out' is set by the project runner");
  expect_nothing_written(1);
}

TEST_F(RunCli, MissingDataFileIsNamedAndNothingIsWritten) {
  const std::string project = write(
      "p.yaml", "output: o\nrobot: planar2\ndata: [missing.csv]\nidentify:\n  estimator: ols\n");
  expect_error(run("run " + project), 1, "data file 'missing.csv' not found");
  expect_nothing_written(1);
}

TEST_F(RunCli, FailingStageLeavesNoFolderAndAForeignFolderIsKept) {
  // The excitation has no finite limit to bound it: excite fails after the model stage ran.
  const std::string project =
      write("p.yaml", "output: o\nrobot: planar2\nmodel: {}\nexcite:\n  harmonics: 2\n");
  expect_error(run("run " + project), 1, "p.yaml: excite: ");
  expect_nothing_written(1);
  fs::create_directories(work("o"));
  write("o/notes.txt", "mine");
  const std::string ok = write("q.yaml", "output: o\nrobot: planar2\nmodel: {}\n");
  expect_error(run("run " + ok), 1, "exists and was not written by dynid run");
  EXPECT_EQ(testing::slurp(work("o/notes.txt")), "mine");
}

// An excitation that cannot meet its limits stops the study there (it used to be written with
// "constraints VIOLATED" and simulated): the error names the stage, the tightest constraint and
// its flag, and no folder is left.
TEST_F(RunCli, ExcitationThatViolatesItsLimitsStopsTheStudy) {
  const std::string project =
      write("p.yaml",
            "output: o\nrobot: planar2\nexcite:\n  harmonics: 3\n  f0: 0.5\n  starts: 1\n"
            "  max-evaluations: 100\n  max-time: 0\n  velocity-limit: 2.0\n"
            "  acceleration-limit: 8.0\n  torque-limit: 0.5\nsimulate:\n  periods: 2\n");
  const auto r = run("run " + project);
  expect_error(r, 1, "p.yaml: excite: no excitation of 'planar2' found meets its constraints");
  EXPECT_NE(r.err.find("torque q1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--torque-limit"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("simulate"), std::string::npos) << r.err;
  expect_nothing_written(1);
}

TEST_F(RunCli, Tx40ExampleProjectIdentifiesAndValidatesOnUnseenSeconds) {
  const fs::path project = fs::path(DYNID_SOURCE_DIR) / "examples/project/tx40.yaml";
  if (!fs::exists(fs::path(DYNID_SOURCE_DIR) / "examples/staubli-tx40/dataset/data")) {
    GTEST_SKIP() << "the TX40 data set is not in this checkout";
  }
  const auto r = run("run " + project.string() + " --out " + work("tx40").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json result = read_json(work("tx40") / "result.json");
  const nlohmann::json validation = read_json(work("tx40") / "validation.json");
  EXPECT_EQ(result["options"]["time"], "0:6");
  EXPECT_EQ(testing::slurp(work("tx40") / "run1.csv").substr(0, 10), "qm1,qm2,qm");
  // 7.2 % on the moving rows of the last 3 s when written; a model that does not carry over to
  // unseen data (or a broken join of the two files) is far above 10 %.
  EXPECT_LT(validation["relative_error"].get<double>(), 0.10);
}

}  // namespace
}  // namespace dynid
