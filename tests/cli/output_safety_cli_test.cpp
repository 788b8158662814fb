// No command writes over what it reads (issue 27 item 2), through the binary: an output that is
// one of the command's inputs (the same path, another spelling, a hard or symbolic link) or
// another of its outputs is a usage error before any work, and an output that is a FIFO is
// refused without being opened. The list of file flags (apps/dynid/file_flags.cpp) is checked
// against the flags the commands register, so that a new output flag cannot be forgotten.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "commands.hpp"
#include "file_flags.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

class OutputSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dynid_outsafety_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
    // Inputs of every kind; their content does not matter, the check comes before any reading.
    for (const char* name : {"a.csv", "r.json", "robot.yaml", "g.yaml", "load.yaml"}) {
      std::ofstream(work(name)) << "original " << name << '\n';
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string work(const std::string& name) const { return (dir_ / "work" / name).string(); }
  testing::CliResult run(const std::string& args) const { return testing::run_dynid(args, dir_); }
  void expect_inputs_unchanged() const {
    for (const char* name : {"a.csv", "r.json", "robot.yaml", "g.yaml", "load.yaml"}) {
      EXPECT_EQ(testing::slurp(work(name)), std::string("original ") + name + "\n") << name;
    }
  }
  static void expect_error(const testing::CliResult& r, int code, const std::string& part) {
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err << "\nexpected: " << part;
  }
  fs::path dir_;
};

TEST_F(OutputSafety, EveryCommandRefusesToWriteOverItsInput) {
  const std::string a = work("a.csv"), r = work("r.json"), robot = work("robot.yaml"),
                    g = work("g.yaml");
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"export -r planar2 -p " + r + " -o " + r, "--out '" + r + "' is the input --params '" + r},
      {"model -r " + robot + " --json " + robot, "--json '" + robot + "' is the input --robot"},
      {"inverse-dynamics -r planar2 -i " + a + " -o " + a, "--out '" + a + "' is the input --in"},
      {"identify -r planar2 -d " + a + " -o " + r + " --report " + a,
       "--report '" + a + "' is the input --data"},
      {"identify -r planar2 -d " + a + " -o " + work("x.json") + " --estimator rls --history " + a,
       "--history '" + a + "' is the input --data"},
      {"identify -r planar2 -d " + work("b.csv") + " -d " + a + " -o " + a,
       "is the input --data '" + a},
      {"validate -r planar2 -p " + r + " -d " + a + " --json " + r,
       "--json '" + r + "' is the input --params"},
      {"validate -r planar2 -p " + r + " -d " + a + " --predicted " + a, "is the input --data"},
      {"validate -r planar2 -p " + r + " -d " + a + " --mode simulation --trajectory " + a +
           " --histograms " + g + " --gains " + g,
       "--histograms '" + g + "' is the input --gains"},
      {"excite -r " + robot + " -o " + robot, "--out '" + robot + "' is the input --robot"},
      {"simulate -r planar2 -t " + a + " -o " + a, "--out '" + a + "' is the input --trajectory"},
      {"simulate -r planar2 -t " + a + " -o " + work("load.yaml") + " --payload " +
           work("load.yaml"),
       "--out '" + work("load.yaml") + "' is the input --payload"},
      {"compare-control -r planar2 -p " + r + " -t " + a + " --json " + a,
       "--json '" + a + "' is the input --trajectory"},
      {"average -d " + a + " --period 1 -o " + a, "--out '" + a + "' is the input --data"},
      {"average -d " + a + " --period 1 -o " + work("m.csv") + " --json " + a,
       "--json '" + a + "' is the input --data"},
      {"payload -d " + a + " -o " + a, "--out '" + a + "' is the input --data"},
      {"payload -d " + a + " -o " + work("p.json") + " --link l2 -r planar2 --reference " + r +
           " --report " + r,
       "--report '" + r + "' is the input --reference"},
      {"report --in " + r + " -o " + r, "--out '" + r + "' is the input --in"},
      {"demo -r " + robot + " --report " + robot, "--report '" + robot + "' is the input --robot"},
  };
  for (const Case& c : cases) {
    const auto res = run(c.args);
    expect_error(res, 2, c.message);
    EXPECT_NE(res.err.find("writing it would replace what the command reads; give"),
              std::string::npos)
        << res.err;
    expect_inputs_unchanged();
  }
  // simulate writes <out>.gains.json beside its run: that file is an output too.
  std::ofstream(work("s.gains.json")) << "kp: [1, 1]\n";
  expect_error(run("simulate -r planar2 -t " + a + " -o " + work("s.csv") + " --gains " +
                   work("s.gains.json")),
               2, "--out (its gains file) '" + work("s.gains.json") + "' is the input --gains");
  EXPECT_EQ(testing::slurp(work("s.gains.json")), "kp: [1, 1]\n");
  // validate reads <data>.gains.json beside the run when --gains is not given.
  std::ofstream(work("a.gains.json")) << "kp: [1, 1]\n";
  expect_error(
      run("validate -r planar2 -p " + r + " -d " + a + " --predicted " + work("a.gains.json")), 2,
      "is the input --data (its gains file)");
  EXPECT_EQ(testing::slurp(work("a.gains.json")), "kp: [1, 1]\n");
  EXPECT_FALSE(fs::exists(work("x.json")));
}

TEST_F(OutputSafety, OtherSpellingsAndLinksOfAnInputAreTheSameFile) {
  const std::string r = work("r.json");
  fs::create_directories(work("sub"));
  fs::create_hard_link(r, work("hard.json"));
  fs::create_symlink(r, work("soft.json"));
  for (const std::string& out :
       {work("sub/../r.json"), work("./r.json"), work("hard.json"), work("soft.json")}) {
    expect_error(run("export -r planar2 -p " + r + " -o " + out), 2, "is the input --params");
  }
  expect_inputs_unchanged();
  EXPECT_TRUE(fs::is_symlink(work("soft.json")));
}

TEST_F(OutputSafety, TwoOutputsToOneFileAreRefused) {
  const std::string a = work("a.csv"), out = work("new.json");
  expect_error(
      run("identify -r planar2 -d " + a + " -o " + out + " --report " + work("./new.json")), 2,
      "--report '" + work("./new.json") + "' is the same file as --out '" + out +
          "'; give each output its own file");
  expect_error(run("excite -r planar2 -o " + work("t.csv") + " --json " + work("t.csv")), 2,
               "is the same file as --out");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(work("t.csv")));
}

TEST_F(OutputSafety, AFifoOutputIsRefusedWithoutBeingOpened) {
  // As root, `-o /dev/null` replaced the system's /dev/null; a FIFO made here stands for it (a
  // writer opening it would block for a reader: the run must end at once).
  const std::string fifo = work("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::ofstream(work("ok.csv")) << "q1,q2,dq1,dq2,ddq1,ddq2\n0,0,0,0,0,0\n";
  expect_error(run("inverse-dynamics -r planar2 -i " + work("ok.csv") + " -o " + fifo), 1,
               "--out '" + fifo + "' is a FIFO (named pipe), not a regular file");
  expect_error(run("model -r planar2 --json " + fifo), 1, "is a FIFO");
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  for (const auto& e : fs::directory_iterator(dir_ / "work")) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  }
}

// Every text flag whose help names a file (a CSV, JSON, YAML, URDF, HTML or a folder) is in the
// list of file flags, or listed here as naming no file the command reads or writes.
TEST(FileFlags, EveryFlagThatNamesAFileIsListed) {
  // Flags whose help mentions a file without naming one; each must still match (kept exact).
  const std::set<std::string> no_file = {
      "identify --columns",      // renames the columns "for a file without a header"
      "validate --columns",      // the same
      "identify --rate",         // the sample rate "when the file has no t column"
      "validate --rate",         // the same
      "payload --columns",       // the run flags are one definition (apps/dynid/run_flags.cpp)
      "payload --rate",          // the same
      "average --columns",       // the same
      "average --rate",          // the same
      "simulate --sensor-pose",  // numbers (a pose in the link frame)
      "payload --sensor-pose",   // the same
      "validate --controller",   // a controller name ("default: the one named in the gains file")
  };
  CLI::App app{"dynid", "dynid"};
  cli::add_commands(app);
  const std::regex names_file(R"(\b(file|CSV|JSON|json|YAML|HTML|URDF|urdf|folder)\b)");
  std::set<std::string> listed;
  for (const cli::FileFlag& f : cli::file_flags())
    listed.insert(std::string(f.command) + " " + f.flag);
  std::vector<std::string> missing;
  for (CLI::App* sub : app.get_subcommands({})) {
    for (const CLI::Option* o : sub->get_options()) {
      if (o->get_expected_max() == 0 || o->get_name() == "--help") continue;
      const std::string key = sub->get_name() + " " + o->get_name();
      const bool mentions = std::regex_search(o->get_description(), names_file);
      if (no_file.count(key)) {
        EXPECT_TRUE(mentions) << key << " no longer mentions a file: remove it from no_file";
        EXPECT_FALSE(listed.count(key)) << key;
        continue;
      }
      if (mentions && !listed.count(key)) missing.push_back(key);
    }
  }
  EXPECT_TRUE(missing.empty()) << "flags whose help names a file but that are not in "
                                  "apps/dynid/file_flags.cpp (or the no_file list here): "
                               << ::testing::PrintToString(missing);
  // And every listed flag exists.
  for (const cli::FileFlag& f : cli::file_flags()) {
    CLI::App* sub = app.get_subcommand(f.command);
    EXPECT_NE(sub->get_option_no_throw(f.flag), nullptr) << f.command << " " << f.flag;
  }
  EXPECT_TRUE(cli::writes_file("identify", "history"));
  EXPECT_FALSE(cli::writes_file("identify", "data"));
}

}  // namespace
}  // namespace dynid
