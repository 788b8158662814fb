// examples/online-payload (issue 16 item 4): on-line identification inside a simulated 1 kHz
// computed-torque loop that picks up a 3 kg load at t = 4 s. Runs the built example program and
// reads its CSV: the estimate must predict the unloaded arm before the pick-up, miss by the load's
// whole effect at it, and settle after it (seed 1 Fig. 6 shows the same for its off-line
// recursive least squares).

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "support/cli_run.hpp"

namespace {

namespace fs = std::filesystem;

struct ExampleRun {
  int code = -1;
  std::string out, err;
};

ExampleRun run_example(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = std::string(DYNID_ONLINE_PAYLOAD_EXAMPLE) + " " + args + " > '" +
                              out.string() + "' 2> '" + err.string() + "' < /dev/null";
  const int status = std::system(command.c_str());
  ExampleRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = dynid::testing::slurp(out);
  r.err = dynid::testing::slurp(err);
  return r;
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) /
                       ("online_payload_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// RMS of the CSV's column `c` over the rows with from <= t < to.
double window_rms(const std::vector<std::vector<double>>& rows, int c, double from, double to) {
  double sum = 0.0;
  int count = 0;
  for (const auto& row : rows) {
    if (row[0] >= from && row[0] < to) {
      sum += row[static_cast<std::size_t>(c)] * row[static_cast<std::size_t>(c)];
      ++count;
    }
  }
  return count > 0 ? std::sqrt(sum / count) : NAN;
}

TEST(OnlinePayloadExample, EstimateSettlesAfterThePickUp) {
  const fs::path dir = scratch("run");
  const fs::path csv = dir / "online.csv";
  const ExampleRun r = run_example("'" + csv.string() + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("settled"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("did not settle"), std::string::npos) << r.out;

  std::ifstream in(csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "t,tracking_error,prediction_error,payload_effect");
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::vector<double> row;
    std::string field;
    while (std::getline(ss, field, ',')) row.push_back(std::stod(field));
    ASSERT_EQ(row.size(), 4u) << line;
    for (double x : row) ASSERT_TRUE(std::isfinite(x)) << line;
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), 800u);  // 8 s at one row per 10 ms

  const double effect_last = window_rms(rows, 3, 7.0, 8.0);
  EXPECT_GT(effect_last, 1.0);  // the load matters [N·m]
  // Before the pick-up the estimate predicts the unloaded arm; at the pick-up it cannot know the
  // load (its error is then the load's whole effect); in the last second it has learnt it.
  EXPECT_LT(window_rms(rows, 2, 3.0, 4.0), 0.01 * effect_last);
  EXPECT_GT(window_rms(rows, 2, 4.0, 4.05), 0.5 * window_rms(rows, 3, 4.0, 4.05));
  EXPECT_LT(window_rms(rows, 2, 7.0, 8.0), 0.1 * effect_last);
  // The nominal controller does not know the load: its tracking degrades.
  EXPECT_GT(window_rms(rows, 1, 7.0, 8.0), 10.0 * window_rms(rows, 1, 3.0, 4.0));
  std::printf(
      "prediction error: 3-4 s %.3g, 4.00-4.05 s %.3g, 7-8 s %.3g N·m; load effect 7-8 s "
      "%.3g N·m\n",
      window_rms(rows, 2, 3.0, 4.0), window_rms(rows, 2, 4.0, 4.05), window_rms(rows, 2, 7.0, 8.0),
      effect_last);
}

TEST(OnlinePayloadExample, BadArgumentsAreOneErrorLine) {
  const fs::path dir = scratch("bad");
  ExampleRun r = run_example("a.csv b.csv", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(dynid::testing::error_contract_problem(r.err), "") << r.err;
  r = run_example("'" + (dir / "no-such-folder" / "x.csv").string() + "'", dir);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(dynid::testing::error_contract_problem(r.err), "") << r.err;
  EXPECT_FALSE(fs::exists(dir / "no-such-folder"));
}

}  // namespace
