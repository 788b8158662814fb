// Seed 2's experiments in simulation (B. Bona, A. Curatella, "Closed-loop rigid model
// identification of an industrial robot", 2005, section 3): examples/comau-s2/run.sh end to end on
// the built-in comau-s2 under a plain PID, shortened (2 periods per Fourier run after the
// transient, 200 Hz) but with every step of the chain. The truth in summary.json comes from the
// model file and dynid inverse-dynamics, never from an estimate.
#include <unistd.h>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

nlohmann::json load(const std::filesystem::path& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f);
}

TEST(ComauS2Example, TruthInsideTheIntervalsAndComputedTorqueTracksBetter) {
  // Per process: checkouts built side by side must not share (and delete) one folder.
  const auto out =
      std::filesystem::path(::testing::TempDir()) / ("comau_s2_" + std::to_string(::getpid()));
  std::filesystem::remove_all(out);
  const std::string command =
      std::string("DYNID='") + DYNID_BINARY + "' PERIODS=3 RATE=200 SEED=1 '" + DYNID_SOURCE_DIR +
      "/examples/comau-s2/run.sh' '" + out.string() + "' > '" + (out.string() + ".log") + "' 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << "see " << out.string() << ".log";
  const nlohmann::json s = load(out / "summary.json");
  int table[4] = {0, 0, 0, 0};
  std::vector<std::string> outside;
  for (const auto& p : s["parameters"]) {
    const double truth = p["truth"], lo = p["ci_low"], hi = p["ci_high"];
    const std::string name = p["name"], t = p["table"];
    if (!(lo <= truth && truth <= hi)) outside.push_back("Table " + t + " " + name);
    ++table[std::stoi(t)];
  }
  // Every interval holds the truth. MY3R is still biased (a held joint slides by its tracking
  // error inside the plant's Coulomb smoothing band; docs/methods/experiments.md, "Seed 2's case
  // in simulation"), but its interval says so: the channels disagree about it and the
  // channel-clustered covariance widens it (checked below through the result's warning).
  EXPECT_EQ(outside, std::vector<std::string>{});
  EXPECT_EQ(table[1], 4);                          // k, q_off of joints 2 and 3
  EXPECT_EQ(table[2], 6 * 4);                      // Fvp Fvn Fcp Fcn of every joint
  EXPECT_EQ(table[3], s["data_rank"].get<int>());  // every excited base parameter checked
  // The model error is named, not hidden: MY3R's interval is the one widened.
  const nlohmann::json result = load(out / "result.json");
  std::string widened;
  for (const auto& w : result["warnings"])
    if (w.get<std::string>().find("channels (joints x runs) disagree") != std::string::npos)
      widened = w;
  EXPECT_NE(widened.find("MY3R x"), std::string::npos) << widened;
  // Seed 2 Fig. 9: the model-based controller's peak tracking error is below the PID's.
  const nlohmann::json c = load(out / "control.json");
  double peak[2] = {0.0, 0.0};
  for (const auto& controller : c["controllers"]) {
    double m = 0.0;
    for (const auto& j : controller["joints"]) m = std::max(m, j["max"].get<double>());
    peak[controller["name"] == "pid" ? 0 : 1] = m;
  }
  EXPECT_GT(peak[0], 0.0);
  EXPECT_LT(peak[1], peak[0]);
  // Validation by simulation of joints 2 and 4 (issue 14 item 2): the badly determined XX2R, XX4R
  // made the identified model's mass matrix indefinite there; completed with the nominal values
  // (named in parameter_sources) it tracks the plant's run to well under 0.06 deg.
  for (int j : {2, 4}) {
    const nlohmann::json v = load(out / ("validation_" + std::to_string(j) + ".json"));
    const auto& bad = v["parameter_sources"]["nominal_badly_determined"];
    const std::string xx = "XX" + std::to_string(j) + "R";
    EXPECT_NE(std::find(bad.begin(), bad.end(), xx), bad.end()) << xx;
    EXPECT_LT(v["joints"][j - 1]["position"]["max"].get<double>(), 1e-3) << "joint " << j;
  }
}

}  // namespace
