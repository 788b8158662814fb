// dynid identify --model integral|gravity|friction|decoupled through the command line: a reference
// from `dynid excite`, a closed-loop run from `dynid simulate` (MuJoCo plant), then identify. The
// gravity truth is RNEA's gravity torque of the robot (not the fit's equations).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/model/robots.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

std::filesystem::path scratch() {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "identify_models";
  std::filesystem::create_directories(dir);
  return dir;
}

testing::CliResult run(const std::string& args) {
  return testing::run_dynid(args, scratch());
}

nlohmann::json load(const std::string& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f);
}

const nlohmann::json& parameter(const nlohmann::json& result, const std::string& name) {
  for (const auto& p : result["parameters"])
    if (p["name"] == name) return p;
  ADD_FAILURE() << "no parameter " << name;
  static const nlohmann::json none;
  return none;
}

// A closed-loop run of planar2 under `excite_args` (one period, 200 Hz, MuJoCo, sensor noise).
std::string simulated(const std::string& name, const std::string& excite_args) {
  const std::string ref = (scratch() / (name + "_ref.csv")).string();
  const std::string out = (scratch() / (name + ".csv")).string();
  auto r = run("excite --robot planar2 " + excite_args + " --rate 200 --out " + ref);
  EXPECT_EQ(r.code, 0) << r.err;
  r = run("simulate --robot planar2 --trajectory " + ref + " --periods 3 --position-noise 1e-4 " +
          "--torque-noise 0.02 --out " + out);
  EXPECT_EQ(r.code, 0) << r.err;
  return out;
}

TEST(IdentifyModelsCli, GravityOfTheElbowFromSlopes) {
  const std::string data =
      simulated("slopes",
                "--family slope --joint 2 --range -1.2:1.2 --velocity 0.6 --acceleration 2 "
                "--pose 0.3,0 --cycles 1");
  const std::string out = (scratch() / "gravity.json").string();
  const auto r = run("identify --robot planar2 --model gravity --joint 2 --data " + data +
                     " --torque-offset 0.0025 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = load(out);
  EXPECT_EQ(j["experiment"], "gravity");
  // Truth: τ_g2 = a·sin q2 + b·cos q2 with the shoulder at 0.3 (RNEA at q2 = π/2 and 0).
  const Model m = load_robot("planar2");
  RneaOptions g;
  g.joint_terms = false;
  const Eigen::Vector2d zero(0, 0);
  const double a = rnea(m, Eigen::Vector2d(0.3, M_PI / 2), zero, zero, g)[1];
  const double b = rnea(m, Eigen::Vector2d(0.3, 0.0), zero, zero, g)[1];
  const nlohmann::json& k = parameter(j, "k2");
  const nlohmann::json& qoff = parameter(j, "qoff2");
  // k·sin(q + q_off) must reproduce a·sin q + b·cos q: compare the fitted curve's (a, b).
  const double ka = k["value"].get<double>() * std::cos(qoff["value"].get<double>());
  const double kb = k["value"].get<double>() * std::sin(qoff["value"].get<double>());
  const double half = k["ci_high"].get<double>() - k["value"].get<double>();
  EXPECT_NEAR(ka, a, half + 1e-9) << j["parameters"].dump();
  EXPECT_NEAR(kb, b,
              half + std::abs(k["value"].get<double>()) *
                         (qoff["ci_high"].get<double>() - qoff["value"].get<double>()));
  EXPECT_EQ(j["slopes"].size(), 2u);
}

TEST(IdentifyModelsCli, FrictionAndDecoupledModelsRunAndNameTheirParameters) {
  const std::string data = simulated(
      "bangbang", "--family bang-bang --joint 1 --range -1:1 --acceleration 4 --pose 0,0.5");
  const std::string friction = (scratch() / "friction.json").string();
  auto r = run("identify --robot planar2 --model friction --joint 1 --data " + data +
               " --torque-offset 0.0025 --out " + friction);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json f = load(friction);
  for (const char* name : {"Fvp1", "Fvn1", "Fcp1", "Fcn1"}) {
    EXPECT_TRUE(parameter(f, name)["value"].is_number()) << name;
  }
  EXPECT_TRUE(f["curve"]["velocity"].is_array());
  // A joint outside the robot and an unknown model: one error line, exit 2, no file.
  const std::string bad = (scratch() / "bad.json").string();
  r = run("identify --robot planar2 --model friction --joint 3 --data " + data + " --out " + bad);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::error_contract_problem(r.err), "");
  EXPECT_FALSE(std::filesystem::exists(bad));
  r = run("identify --robot planar2 --model energy --data " + data + " --out " + bad);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(std::filesystem::exists(bad));
}

// The wiring of --model integral: same base parameters and names as the differential model, and a
// result validate accepts. Whether the two models agree is the library's test
// (tests/estimation/integral_equations_test.cpp); on this short optimised run they do not (6 of
// 13 apart by more than the sum of their half-widths; docs/methods/estimation.md §7).
TEST(IdentifyModelsCli, IntegralModelUsesTheDifferentialBaseParameters) {
  const std::string data =
      simulated("fourier",
                "--harmonics 4 --f0 0.2 --seed 3 --starts 1 --max-time 10 --velocity-limit 3 "
                "--acceleration-limit 20");
  const std::string d = (scratch() / "differential.json").string();
  const std::string i = (scratch() / "integral.json").string();
  auto r = run("identify --robot planar2 --data " + data + " --torque-offset 0.0025 --out " + d);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("identify --robot planar2 --model integral --data " + data + " --out " + i);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json jd = load(d), ji = load(i);
  ASSERT_EQ(jd["parameters"].size(), ji["parameters"].size());
  for (size_t k = 0; k < jd["parameters"].size(); ++k) {
    EXPECT_EQ(jd["parameters"][k]["name"], ji["parameters"][k]["name"]);
    EXPECT_TRUE(ji["parameters"][k]["value"].is_number());
  }
  EXPECT_NE(ji["choices"]["model"].get<std::string>().find("integral"), std::string::npos);
  // validate (torque mode) accepts the integral-model result.
  r = run("validate --robot planar2 --params " + i + " --data " + data);
  EXPECT_EQ(r.code, 0) << r.err;
  // --physical: realisable standard parameters that fit about as well. The MuJoCo plant of planar2
  // has no friction, so the friction-free set is the right model (with friction columns the
  // estimate has Fv1 4 sigma below zero on this short run, and no realisable set is near it).
  const std::string p = (scratch() / "physical.json").string();
  r = run("identify --robot planar2 --physical --friction none --data " + data +
          " --torque-offset 0.0025 --out " + p);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json jp = load(p);
  EXPECT_TRUE(jp["physically_consistent"].get<bool>());
  EXPECT_EQ(jp["standard_parameters"].size(), 2u * 10 + 2);  // links, Ia per joint
  EXPECT_LE(jp["physical"]["relative_error"].get<double>(),
            1.1 * jp["physical"]["relative_error_unconstrained"].get<double>());
  EXPECT_LT(jp["physical"]["mahalanobis"].get<double>(),
            jp["physical"]["chi2_limit"].get<double>());
}

}  // namespace
}  // namespace dynid
