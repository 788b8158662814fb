// `dynid run` never touches what it did not write (issue 27 item 1), through the binary: stage
// output keys land in the output folder (never on a file beside the project, never outside),
// the project folder is never the output, a folder is replaced only when its marker says dynid
// run wrote everything in it, a `.partial` folder dynid run did not create is kept, and joined
// data come from under the project folder only, regular files within the size cap. Every refusal
// is one `error:` line, and the files around are byte for byte what they were.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "dynid/io/csv_reader.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

class RunSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dynid_runsafety_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path work(const std::string& name) const { return dir_ / "work" / name; }
  std::string write(const std::string& name, const std::string& text) const {
    fs::create_directories(work(name).parent_path());
    std::ofstream(work(name), std::ios::binary) << text;
    return work(name).string();
  }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }

  // A planar2 run logged as t, q1, q2, tau1, tau2 (torques of a sum of sines through a simple
  // rigid model: identify only needs to run on it, not to be right).
  std::string planar2_run(const std::string& name) const {
    std::ostringstream s;
    s.precision(17);
    s << "t,q1,q2,tau1,tau2\n";
    for (int k = 0; k < 1500; ++k) {
      const double t = k * 0.01;
      const double q1 = std::sin(0.7 * t) + 0.3 * std::sin(2.1 * t), q2 = 0.8 * std::cos(1.3 * t);
      s << t << ',' << q1 << ',' << q2 << ',' << 30 * std::cos(q1) + 2 * std::sin(3 * t) << ','
        << 5 * std::cos(q1 + q2) + std::cos(2 * t) << '\n';
    }
    return write(name, s.str());
  }

  // Exit `code`, the one error line last on stderr containing `part`.
  static void expect_error(const testing::CliResult& r, int code, const std::string& part) {
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err << "\nexpected: " << part;
  }

  // Every file under work/ with its content (links as "-> target"), to compare before and after.
  std::map<std::string, std::string> snapshot() const {
    std::map<std::string, std::string> files;
    for (auto it = fs::recursive_directory_iterator(dir_ / "work");
         it != fs::recursive_directory_iterator(); ++it) {
      const std::string rel = fs::relative(it->path(), dir_ / "work").string();
      if (it->is_symlink()) {
        files[rel] = "-> " + fs::read_symlink(it->path()).string();
        it.disable_recursion_pending();
      } else if (it->is_regular_file()) {
        files[rel] = testing::slurp(it->path());
      } else if (it->is_directory()) {
        files[rel + "/"] = "";
      } else {
        files[rel] = "special";
      }
    }
    return files;
  }

  fs::path dir_;
};

TEST_F(RunSafety, OutputKeysLandInTheOutputFolderNeverOnTheFilesBesideTheProject) {
  const std::string data = planar2_run("run.csv");
  write("hist.csv", "mine\n");
  // history: run.csv named the input data beside the project; report: hist.csv another file.
  const std::string project =
      write("p.yaml",
            "output: o\nrobot: planar2\ndata: run.csv\n"
            "identify: {estimator: rls, history: run.csv, report: hist.csv}\n");
  const std::string before = testing::slurp(data);
  const auto r = run("run " + project);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(testing::slurp(data), before);
  EXPECT_EQ(testing::slurp(work("hist.csv")), "mine\n");
  EXPECT_EQ(testing::slurp(work("o/run.csv")).rfind("t,", 0), 0u);  // the RLS history
  EXPECT_NE(testing::slurp(work("o/hist.csv")).find("<html"), std::string::npos);
  const std::string commands = testing::slurp(work("o/commands.txt"));
  EXPECT_NE(commands.find("--history run.csv --report hist.csv"), std::string::npos) << commands;
}

TEST_F(RunSafety, OutputNamesOutsideTheFolderAreRefusedWithOneLine) {
  const std::string data = planar2_run("run.csv");
  for (const std::string& name :
       {std::string("../x.csv"), work("abs.csv").string(), std::string("sub/x.csv"),
        std::string(".."), std::string("o/../../x.csv")}) {
    const std::string project =
        write("p.yaml",
              "output: o\nrobot: planar2\ndata: run.csv\nidentify: {estimator: rls, "
              "history: '" +
                  name + "'}\n");
    const auto files = snapshot();
    expect_error(run("run " + project), 2,
                 "p.yaml: identify: 'history: " + name +
                     "' must be a file name in the output folder (no folder, no .., not "
                     "absolute)");
    EXPECT_EQ(snapshot(), files) << name;
  }
  EXPECT_FALSE(fs::exists(dir_ / "x.csv"));
}

TEST_F(RunSafety, OutputNamesTheRunnerWritesAreRefused) {
  planar2_run("run.csv");
  const std::map<std::string, std::string> cases = {
      {"identify: {report: p.yaml}\n", "'p.yaml' is already the copy of the project file"},
      {"identify: {report: commands.txt}\n", "'commands.txt' is already the command lines"},
      {"identify: {report: result.json}\n", "'result.json' is already identify's out"},
      {"identify: {history: identify.txt}\n", "'identify.txt' is already what identify printed"},
      {"identify: {report: r.html}\nvalidate: {report: r.html}\n",
       "validate: report: 'r.html' is already identify: report"},
  };
  for (const auto& [stages, message] : cases) {
    const std::string project =
        write("p.yaml", "output: o\nrobot: planar2\ndata: run.csv\n" + stages);
    const auto files = snapshot();
    expect_error(run("run " + project), 2, message);
    EXPECT_EQ(snapshot(), files) << stages;
  }
}

TEST_F(RunSafety, TheProjectFolderIsNeverTheOutput) {
  // A project folder that looks like an earlier study (commands.txt in it): `output: .` deleted
  // the project, its data and everything beside it.
  planar2_run("run.csv");
  write("commands.txt", "dynid model --robot planar2\n");
  write("notes/today.txt", "mine\n");
  for (const std::string output : {".", "./", "..", "../.."}) {
    const std::string project =
        write("p.yaml", "output: " + output + "\nrobot: planar2\ndata: run.csv\nmodel: {}\n");
    const auto files = snapshot();
    expect_error(run("run " + project), 2,
                 output.rfind("..", 0) == 0 ? "is a folder holding the project"
                                            : "is the folder of the project file");
    EXPECT_EQ(snapshot(), files) << output;
  }
  const std::string project = write("p.yaml", "output: o\nrobot: planar2\nmodel: {}\n");
  const auto files = snapshot();
  expect_error(run("run " + project + " --out " + work("").string()), 2,
               "dynid run replaces its output folder as a whole, so give a new folder");
  expect_error(run("run " + project + " --out " + dir_.string()), 2,
               "a folder holding the project");
  EXPECT_EQ(snapshot(), files);
}

TEST_F(RunSafety, AFolderIsReplacedOnlyWhenItsMarkerListsEverythingInIt) {
  const std::string project = write("p.yaml", "output: o\nrobot: planar2\nmodel: {}\n");
  // A folder that merely holds a commands.txt is not dynid's.
  write("o/commands.txt", "# written by dynid run p.yaml\n");
  write("o/mine.csv", "1\n");
  auto files = snapshot();
  expect_error(run("run " + project), 1, "exists and was not written by dynid run");
  EXPECT_EQ(snapshot(), files);
  // Nor one whose marker is forged.
  write("o/.dynid-run", "state: complete\nfile: mine.csv\nfile: commands.txt\n");
  files = snapshot();
  expect_error(run("run " + project), 1, "exists and was not written by dynid run");
  EXPECT_EQ(snapshot(), files);
  fs::remove_all(work("o"));

  ASSERT_EQ(run("run " + project).code, 0);
  EXPECT_TRUE(fs::is_regular_file(work("o/.dynid-run")));
  EXPECT_TRUE(fs::is_regular_file(work("o/model.json")));
  ASSERT_EQ(run("run " + project).code, 0);  // its own folder: replaced
  // A file the user put into the study is not replaced with it.
  write("o/notes.txt", "mine\n");
  files = snapshot();
  expect_error(run("run " + project), 1,
               "holds notes.txt, which dynid run did not write; move it out of the folder");
  EXPECT_EQ(snapshot(), files);
  fs::remove(work("o/notes.txt"));
  EXPECT_EQ(run("run " + project).code, 0);
}

TEST_F(RunSafety, APartialFolderIsRemovedOnlyWhenDynidRunLeftIt) {
  const std::string project = write("p.yaml", "output: o\nrobot: planar2\nmodel: {}\n");
  write("o.partial/mine.txt", "mine\n");
  auto files = snapshot();
  expect_error(run("run " + project), 1, "o.partial exists and was not created by dynid run");
  EXPECT_EQ(snapshot(), files);
  fs::remove_all(work("o.partial"));

  // The marker of a real run, turned into the one a run killed halfway would leave.
  ASSERT_EQ(run("run " + project + " --out " + work("done").string()).code, 0);
  std::string marker = testing::slurp(work("done/.dynid-run"));
  const auto state = marker.find("state: complete");
  ASSERT_NE(state, std::string::npos) << marker;
  const auto leftover = [&](long pid) {
    std::string m = marker;
    m.replace(state, std::string("state: complete").size(),
              "state: writing " + std::to_string(pid));
    write("o.partial/.dynid-run", m);
    write("o.partial/model.txt", "half\n");
  };
  // Its writer still runs (this test process stands for it): kept.
  leftover(static_cast<long>(::getpid()));
  files = snapshot();
  expect_error(run("run " + project), 1, "is being written by another dynid run (pid ");
  EXPECT_EQ(snapshot(), files);
  // Its writer is gone: removed, and the run goes through.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  leftover(static_cast<long>(child));
  ASSERT_EQ(run("run " + project).code, 0);
  EXPECT_FALSE(fs::exists(work("o.partial")));
  EXPECT_TRUE(fs::is_regular_file(work("o/model.json")));
}

TEST_F(RunSafety, JoinedFilesComeFromUnderTheProjectFolderOnly) {
  // Two logs of one run side by side, kept outside the project folder.
  const CsvTable whole = read_csv(planar2_run("../elsewhere/whole.csv"));
  std::ostringstream pos, tau;
  pos.precision(17);
  tau.precision(17);
  pos << "time,a,b\n";
  tau << "c1,c2\n";
  for (Eigen::Index i = 0; i < whole.rows(); ++i) {
    pos << whole.data(i, 0) << ',' << whole.data(i, 1) << ',' << whole.data(i, 2) << '\n';
    tau << whole.data(i, 3) << ',' << whole.data(i, 4) << '\n';
  }
  write("../elsewhere/pos.csv", pos.str());
  write("../elsewhere/tau.csv", tau.str());
  const auto project_joining = [&](const std::string& a, const std::string& b) {
    return write("p.yaml", "output: o\nrobot: planar2\ndata:\n  join: ['" + a + "', '" + b +
                               "']\n  columns: [t, q1, q2, tau1, tau2]\nidentify: {}\n");
  };
  for (const std::string& outside :
       {std::string("../elsewhere/pos.csv"), (dir_ / "elsewhere/pos.csv").string(),
        std::string("sub/../../elsewhere/pos.csv")}) {
    const std::string project = project_joining(outside, "tau.csv");
    const auto files = snapshot();
    expect_error(run("run " + project), 2,
                 "joined file '" + outside + "' is outside the project folder");
    EXPECT_EQ(snapshot(), files);
  }
  // A FIFO under the folder is refused at once instead of blocking the run.
  ASSERT_EQ(::mkfifo(work("pipe.csv").c_str(), 0600), 0);
  expect_error(run("run " + project_joining("pipe.csv", "tau.csv")), 1,
               "pipe.csv' is not a regular file");
  fs::remove(work("pipe.csv"));
  // The size cap of every other CSV input (a sparse file: nothing is really read).
  write("huge.csv", "a\n");
  fs::resize_file(work("huge.csv"), kMaxCsvFileBytes + 1);
  expect_error(run("run " + project_joining("huge.csv", "tau.csv")), 1, "is larger than 256 MiB");
  fs::remove(work("huge.csv"));
  EXPECT_FALSE(fs::exists(work("o")));
  EXPECT_FALSE(fs::exists(work("o.partial")));

  // The way to use data kept elsewhere: a link under the project folder.
  fs::create_directory_symlink(dir_ / "elsewhere", work("logs"));
  const auto r = run("run " + project_joining("logs/pos.csv", "logs/tau.csv"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(testing::slurp(work("o/run1.csv")).substr(0, 19), "t,q1,q2,tau1,tau2\n0");
}

}  // namespace
}  // namespace dynid
