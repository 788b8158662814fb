// Issue 25 item 1 through the binary: `dynid identify` then `dynid validate` on
// ../shared/regressions/arm6-closed-loop (a KDL-simulated closed-loop run of a 6-joint arm in
// which every joint moves, README there). dynid 0.1.0 declared Fc6 (Fo6 with an offset) not
// excited and validate refused; now nothing is left out and validate predicts the held-out run
// within 1.5x of what an independent least-squares fit does (0.91 %). Skips without ../shared.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using dynid::testing::run_dynid;

const std::string kDir = std::string(DYNID_SHARED_DIR) + "/regressions/arm6-closed-loop";

class Arm6ClosedLoopCli : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (!fs::exists(kDir + "/ident.csv.gz") || !fs::exists(kDir + "/valid.csv.gz")) {
      GTEST_SKIP() << "regression run not found at " << kDir;
    }
    scratch_ = fs::path(::testing::TempDir()) / ("arm6_cli_" + std::to_string(::getpid()));
    fs::create_directories(scratch_);
    for (const char* name : {"ident.csv", "valid.csv"}) {
      const std::string command =
          "gzip -dc '" + kDir + "/" + name + ".gz' > '" + (scratch_ / name).string() + "'";
      if (std::system(command.c_str()) != 0) GTEST_SKIP() << "gzip could not unpack " << name;
    }
  }
  void TearDown() override {
    std::error_code ec;
    if (!scratch_.empty()) fs::remove_all(scratch_, ec);
  }
  fs::path scratch_;
};

TEST_P(Arm6ClosedLoopCli, IdentifyExcitesEveryParameterAndValidatePredictsTheHeldOutRun) {
  const std::string robot = kDir + "/arm6_odd.urdf";
  const std::string result = (scratch_ / "r.json").string();
  const auto id =
      run_dynid("identify --robot " + robot + " --data " + (scratch_ / "ident.csv").string() +
                    " --friction " + GetParam() + " --out " + result,
                scratch_);
  ASSERT_EQ(id.code, 0) << id.err;
  EXPECT_EQ(id.err.find("not excited"), std::string::npos) << id.err;
  const auto r = nlohmann::json::parse(std::ifstream(result));
  EXPECT_TRUE(r.at("not_excited").empty()) << r.at("not_excited").dump();
  EXPECT_EQ(r.at("data_rank"), r.at("rank"));
  EXPECT_EQ(r.at("parameters").size(), r.at("rank").get<size_t>());

  const std::string json = (scratch_ / "v.json").string();
  const auto val = run_dynid("validate --robot " + robot + " --params " + result + " --data " +
                                 (scratch_ / "valid.csv").string() + " --json " + json,
                             scratch_);
  ASSERT_EQ(val.code, 0) << val.err;
  const auto v = nlohmann::json::parse(std::ifstream(json));
  // The README's independent OLS (every row, sign(dq)) predicts valid.csv.gz at 0.91 %.
  EXPECT_LT(v.at("relative_error_all_rows").get<double>(), 1.5 * 0.0091) << v.dump();
  EXPECT_LT(v.at("relative_error").get<double>(), 1.5 * 0.0091) << v.dump();
}

INSTANTIATE_TEST_SUITE_P(Friction, Arm6ClosedLoopCli,
                         ::testing::Values("viscous,coulomb", "viscous,coulomb,offset"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param == "viscous,coulomb" ? std::string("ViscousCoulomb")
                                                                  : std::string("WithOffset");
                         });

}  // namespace
