// dynid identify --model integral|gravity|friction|decoupled through the command line: a reference
// from `dynid excite`, a closed-loop run from `dynid simulate` (MuJoCo plant), then identify. The
// gravity truth is RNEA's gravity torque of the robot (not the fit's equations).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

// Item 2's general form through the command line: slopes of the shoulder with the elbow held at
// two poses give the shoulder's 4 gravity base parameters and k, qoff per pose; the truth per pose
// is RNEA's gravity torque.
TEST(IdentifyModelsCli, GravityOfTheShoulderAtTwoElbowPoses) {
  std::vector<std::string> data;
  for (const char* pose : {"0,-0.5", "0,0.9"}) {
    data.push_back(simulated("shoulder_slopes_" + std::to_string(data.size()),
                             "--family slope --joint 1 --range -1.2:1.2 --velocity 0.6 "
                             "--acceleration 2 --pose " +
                                 std::string(pose) + " --cycles 1"));
  }
  const std::string out = (scratch() / "gravity_poses.json").string();
  const auto r = run("identify --robot planar2 --model gravity --joint 1 --data " + data[0] +
                     " --data " + data[1] + " --torque-offset 0.0025 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = load(out);
  EXPECT_EQ(j["experiment"], "gravity");
  EXPECT_EQ(j["parameters"].size(), 4u) << j["base_parameters"].dump();
  ASSERT_EQ(j["poses"].size(), 2u);
  const Model m = load_robot("planar2");
  RneaOptions g;
  g.joint_terms = false;
  const Eigen::Vector2d zero(0, 0);
  for (const auto& p : j["poses"]) {
    const double elbow = p["pose"][1].get<double>();
    const double a = rnea(m, Eigen::Vector2d(M_PI / 2, elbow), zero, zero, g)[0];
    const double b = rnea(m, Eigen::Vector2d(0.0, elbow), zero, zero, g)[0];
    const double k = p["k"].get<double>(), qoff = p["qoff"].get<double>();
    const double dk = p["k_ci_half_width"].get<double>();
    const double dq = p["qoff_ci_half_width"].get<double>();
    EXPECT_NEAR(k * std::cos(qoff), a, dk + std::abs(k) * dq) << p.dump();
    EXPECT_NEAR(k * std::sin(qoff), b, dk + std::abs(k) * dq) << p.dump();
  }
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

// Issue 25 item 7, Bona & Curatella's chain (seed 2 §3.2): the friction runs are compensated with
// the gravity the slopes identified. `--model friction --params` takes a `--model gravity` result
// of the same joint (it was refused: "k1 is not a base parameter") and a `--model decoupled` one,
// refuses one of another joint, and on a plant that is the nominal model gives the friction the
// nominal compensation gives, to within their intervals (the identified gravity is the plant's).
TEST(IdentifyModelsCli, FrictionIsCompensatedWithTheGravityOrDecoupledResultOfItsJoint) {
  const std::string slopes = simulated(
      "chain_slopes",
      "--family slope --joint 1 --range -1.2:1.2 --velocity 0.6 --acceleration 2 --pose 0,0.5 "
      "--cycles 1");
  const std::string bang = simulated(
      "chain_bang", "--family bang-bang --joint 1 --range -1:1 --acceleration 4 --pose 0,0.5");
  const std::string gravity = (scratch() / "chain_gravity.json").string();
  auto r = run("identify --robot planar2 --model gravity --joint 1 --data " + slopes +
               " --torque-offset 0.0025 --out " + gravity);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string nominal = (scratch() / "chain_friction_nominal.json").string();
  const std::string chained = (scratch() / "chain_friction_gravity.json").string();
  r = run("identify --robot planar2 --model friction --joint 1 --data " + bang +
          " --torque-offset 0.0025 --out " + nominal);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("identify --robot planar2 --model friction --joint 1 --data " + bang +
          " --torque-offset 0.0025 --params " + gravity + " --out " + chained);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json fn = load(nominal), fg = load(chained);
  EXPECT_NE(fg["choices"]["compensation"].get<std::string>().find("gravity identified"),
            std::string::npos)
      << fg["choices"].dump();
  for (const char* name : {"Fvp1", "Fvn1", "Fcp1", "Fcn1"}) {
    const double a = parameter(fn, name)["value"].get<double>();
    const double b = parameter(fg, name)["value"].get<double>();
    const double half = parameter(fn, name)["ci_high"].get<double>() - a +
                        parameter(fg, name)["ci_high"].get<double>() - b;
    EXPECT_NEAR(a, b, half) << name;
  }
  // The gravity of another joint is refused, naming both.
  r = run("identify --robot planar2 --model friction --joint 2 --data " + bang + " --params " +
          gravity + " --out " + (scratch() / "chain_bad.json").string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(testing::error_contract_problem(r.err), "") << r.err;
  EXPECT_NE(r.err.find("gravity result of joint 1; give the one of joint 2"), std::string::npos)
      << r.err;
  // A decoupled result (equivalent inertia and gravity of the joint) compensates too.
  const std::string decoupled = (scratch() / "chain_decoupled.json").string();
  r = run("identify --robot planar2 --model decoupled --joint 1 --data " + bang +
          " --torque-offset 0.0025 --out " + decoupled);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("identify --robot planar2 --model friction --joint 1 --data " + bang +
          " --torque-offset 0.0025 --params " + decoupled + " --out " +
          (scratch() / "chain_friction_decoupled.json").string());
  EXPECT_EQ(r.code, 0) << r.err;
}

// The wiring of --model integral: same base parameters and names as the differential model, and a
// result validate accepts. Whether the two models agree is the library's test
// (tests/identification/integral_equations_test.cpp); on this short optimised run they do not (6 of
// 13 apart by more than the sum of their half-widths; docs/methods/identification.md §4).
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
  // Its distance in sigma is reported, and judged against the chi-square limit with a warning
  // beyond it (issue 25 item 6). The distance itself depends on the loop's bias (issue 28 item 8):
  // with stiffer default gains that track this reference closely, the unconstrained estimate came
  // out biased by about 3 sigma (ZZ1R 2.146 +- 0.007 against 2.167) and the nearest consistent set
  // 6.7 sigma away for a limit of 4.9. The contract is tested, not the distance.
  const double distance = jp["physical"]["distance_sigma"].get<double>();
  EXPECT_TRUE(std::isfinite(distance));
  EXPECT_EQ(jp["physical"]["within_limit"].get<bool>(),
            distance <= jp["physical"]["chi2_limit"].get<double>());
  if (!jp["physical"]["within_limit"].get<bool>()) {
    EXPECT_NE((r.out + r.err).find("sigma from the estimate"), std::string::npos) << r.out << r.err;
  }
}

// The lines of a CSV file (header first, comments dropped).
std::vector<std::string> csv_lines(const std::string& path) {
  std::ifstream f(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(f, line);)
    if (!line.empty() && line[0] != '#') out.push_back(line);
  return out;
}

// Column `name` of a CSV data line.
double csv_value(const std::string& header, const std::string& line, const std::string& name) {
  std::istringstream h(header), l(line);
  std::string column, value;
  while (std::getline(h, column, ',') && std::getline(l, value, ','))
    if (column == name) return std::stod(value);
  ADD_FAILURE() << "no column " << name << " in " << header;
  return 0.0;
}

// Rows [from, to) of a CSV run written as a new run file.
std::string csv_slice(const std::vector<std::string>& lines, size_t from, size_t to,
                      const std::string& name) {
  const std::string path = (scratch() / name).string();
  std::ofstream f(path);
  f << lines[0] << '\n';
  for (size_t i = from; i < to && i < lines.size(); ++i) f << lines[i] << '\n';
  return path;
}

// Issue 14 item 10: each experiment input a user can get wrong gives one error line, exit 1 for
// data (2 for usage), no result file. The runs are cut from one simulated bang-bang run of the
// shoulder (-1 -> 1 -> -1 rad): its rising half (one direction only), and the speeding-up parts
// of each direction (no deceleration).
TEST(IdentifyModelsCli, BadExperimentRunsGiveOneErrorLine) {
  const std::string data = simulated(
      "bangbang_bad", "--family bang-bang --joint 1 --range -1:1 --acceleration 4 --pose 0,0.5");
  const std::vector<std::string> lines = csv_lines(data);
  ASSERT_GT(lines.size(), 100u);
  // The first rise of q1: from the start to its first maximum; its midpoint crossing q1 = 0.
  size_t top = 1, mid_up = 0, mid_down = 0;
  for (size_t i = 1; i < lines.size(); ++i) {
    const double q = csv_value(lines[0], lines[i], "q1");
    if (q > csv_value(lines[0], lines[top], "q1") + 1e-9) top = i;
    if (mid_up == 0 && q > 0.0) mid_up = i;
    if (top > 1 && q < csv_value(lines[0], lines[top], "q1") - 0.5) break;  // past the top
  }
  for (size_t i = top; i < lines.size(); ++i)
    if (csv_value(lines[0], lines[i], "q1") < 0.0) {
      mid_down = i;
      break;
    }
  ASSERT_GT(mid_up, 1u);
  ASSERT_GT(mid_down, top);
  const std::string rising = csv_slice(lines, 1, top, "rising.csv");
  const std::string speeding_up = csv_slice(lines, 1, mid_up, "speeding_up.csv");
  const std::string speeding_down = csv_slice(lines, top, mid_down, "speeding_down.csv");
  const std::string bad = (scratch() / "bad_experiment.json").string();
  struct Case {
    std::string args, message;
    int code;
  };
  const std::vector<Case> cases = {
      {"--model gravity --joint 1 --data " + data, "without a constant-velocity part", 1},
      {"--model friction --joint 3 --data " + data, "--joint 3", 2},
      {"--model friction --joint 1 --data " + rising, "both directions", 1},
      {"--model friction --joint 1 --data " + speeding_up + " --data " + speeding_down,
       "never decelerates", 1},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = run("identify --robot planar2 " + c.args + " --out " + bad);
    EXPECT_EQ(r.code, c.code) << r.err;
    EXPECT_EQ(testing::error_contract_problem(r.err), "");
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(bad));
  }
}

// Issue 14 items 4 and 5: `identify --friction-known` on planar2 with asymmetric friction (a model
// file with Fv, Fc and an offset Fo per joint, so Fcp = Fc + Fo and Fcn = Fc - Fo), friction from
// a bang-bang run of each joint, then a multi-sine run of both joints. The result stores the known
// friction, and validate predicts the full torque with it: its error is well below that of the
// same result with the stored friction removed (the rigid body alone, as before the fix).
TEST(IdentifyModelsCli, FrictionKnownResultIsValidatedWithItsFriction) {
  std::ifstream in(std::string(DYNID_SOURCE_DIR) + "/examples/robots/planar2.yaml");
  std::stringstream yaml;
  yaml << in.rdbuf();
  std::string text = yaml.str();
  const std::string robot = (scratch() / "planar2_friction.yaml").string();
  {
    const std::string shoulder =
        "inertia_com: [0, 0, 0, 0.16666666666666666, 0, 0.16666666666666666]";
    const std::string elbow = "inertia_com: [0, 0, 0, 0.08, 0, 0.08]";
    text.replace(text.find(shoulder), shoulder.size(), shoulder + ", Fv: 1.5, Fc: 2.0, Fo: 0.4");
    text.replace(text.find(elbow), elbow.size(), elbow + ", Fv: 0.8, Fc: 1.0, Fo: -0.2");
    std::ofstream(robot) << text;
  }
  std::vector<std::string> known;
  for (int joint : {1, 2}) {
    const std::string j = std::to_string(joint);
    const std::string ref = (scratch() / ("bb" + j + "_ref.csv")).string();
    const std::string run_file = (scratch() / ("bb" + j + ".csv")).string();
    auto r = run("excite --robot " + robot + " --family bang-bang --joint " + j +
                 " --range -1:1 --acceleration 4 --pose 0.4,0.4 --rate 200 --out " + ref);
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("simulate --robot " + robot + " --trajectory " + ref +
            " --periods 2 --position-noise 1e-5 --torque-noise 0.02 --out " + run_file);
    ASSERT_EQ(r.code, 0) << r.err;
    known.push_back((scratch() / ("friction" + j + ".json")).string());
    r = run("identify --robot " + robot + " --model friction --joint " + j + " --data " + run_file +
            " --torque-offset 0.0025 --out " + known.back());
    ASSERT_EQ(r.code, 0) << r.err;
  }
  // A 3-sine reference of both joints (period 5 s), written directly: q, dq, ddq exact.
  const std::string ref = (scratch() / "multisine_ref.csv").string();
  {
    std::ofstream f(ref);
    f << "t,q1,q2,dq1,dq2,ddq1,ddq2\n";
    const double w = 2 * M_PI * 0.2;
    const double a[2][3] = {{0.8, 0.3, 0.15}, {0.9, -0.4, 0.2}};
    for (int k = 0; k < 1000; ++k) {
      const double t = k / 200.0;
      double q[2] = {0, 0.3}, dq[2] = {0, 0}, ddq[2] = {0, 0};
      for (int j = 0; j < 2; ++j)
        for (int h = 0; h < 3; ++h) {
          const double wh = (h + 1) * w, ph = 0.7 * j + 0.4 * h;
          q[j] += a[j][h] / wh * std::sin(wh * t + ph);
          dq[j] += a[j][h] * std::cos(wh * t + ph);
          ddq[j] -= a[j][h] * wh * std::sin(wh * t + ph);
        }
      f << t << ',' << q[0] << ',' << q[1] << ',' << dq[0] << ',' << dq[1] << ',' << ddq[0] << ','
        << ddq[1] << '\n';
    }
  }
  const std::string data = (scratch() / "multisine.csv").string();
  auto r = run("simulate --robot " + robot + " --trajectory " + ref +
               " --periods 3 --position-noise 1e-5 --torque-noise 0.02 --out " + data);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string result = (scratch() / "known.json").string();
  r = run("identify --robot " + robot + " --data " + data + " --friction-known " + known[0] +
          " --friction-known " + known[1] + " --torque-offset 0.0025 --out " + result);
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = load(result);
  for (const auto& p : j["parameters"])  // only the rigid body (and armature) was estimated
    EXPECT_EQ(p["name"].get<std::string>().rfind("F", 0), std::string::npos) << p["name"];
  ASSERT_EQ(j["options"]["known_friction"].size(), 8u);
  EXPECT_EQ(j["options"]["known_friction"][0]["name"], "Fvp1");
  const std::string with = (scratch() / "validate_with.json").string();
  r = run("validate --robot " + robot + " --params " + result + " --data " + data + " --json " +
          with);
  ASSERT_EQ(r.code, 0) << r.err;
  // Negative control: the same result without its stored friction.
  j["options"].erase("known_friction");
  const std::string stripped = (scratch() / "known_stripped.json").string();
  std::ofstream(stripped) << j.dump();
  const std::string without = (scratch() / "validate_without.json").string();
  r = run("validate --robot " + robot + " --params " + stripped + " --data " + data + " --json " +
          without);
  ASSERT_EQ(r.code, 0) << r.err;
  const double e_with = load(with)["relative_error"].get<double>();
  const double e_without = load(without)["relative_error"].get<double>();
  EXPECT_LT(e_with, 0.5 * e_without) << "with " << e_with << ", without " << e_without;
  EXPECT_LT(e_with, 0.1);
  // A hand-edited stored friction is one error line, and nothing is written.
  j["options"]["known_friction"] = "Fvp1=0.3";
  const std::string edited = (scratch() / "known_edited.json").string();
  std::ofstream(edited) << j.dump();
  const std::string none = (scratch() / "validate_edited.json").string();
  r = run("validate --robot " + robot + " --params " + edited + " --data " + data + " --json " +
          none);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(testing::error_contract_problem(r.err), "");
  EXPECT_NE(r.err.find("options.known_friction"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(none));
}

}  // namespace
}  // namespace dynid
