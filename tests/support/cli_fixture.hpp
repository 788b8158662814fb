#pragma once

// A fixture for the CLI tests: a scratch folder per test case and process, the dynid binary run
// in it, and the error contract of docs/cli.md checked on a failed run.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli_run.hpp"

namespace dynid::testing {

class CliScratchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("dynid_" + std::string(info->test_suite_name()) + "_" + std::to_string(::getpid()) +
            "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// `dynid <args>` with its output files in the scratch folder.
  CliResult run(const std::string& args) const { return run_dynid(args, dir_); }
  /// A file of the scratch folder.
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// A failed run: exit `code`, one `error:` line last (error_contract_problem), each of `parts`
  /// in stderr.
  static void expect_error(const CliResult& r, int code, const std::vector<std::string>& parts) {
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(error_contract_problem(r.err), "") << r.err;
    for (const auto& part : parts)
      EXPECT_NE(r.err.find(part), std::string::npos) << r.err << "\nexpected: " << part;
  }

  std::filesystem::path dir_;
};

}  // namespace dynid::testing
