// The real Staubli TX40 run of examples/staubli-tx40/dataset (SOURCE.md): identification with the
// default signal processing must reproduce the published friction values (config/T40X_config.yaml)
// and FIGAROH's base parameters (results/TX40_bp_5.csv) within a few percent, with about 5 %
// relative torque error. Skips when the data set is absent.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "dynid/identification/identify.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/transmission.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kTx40DataDir;

// The copy shipped in the repository (examples/staubli-tx40/dataset).

// FIGAROH's OLS value of each base parameter, keyed by the first token of its expression.
std::map<std::string, double> figaroh_ols() {
  std::ifstream f(kTx40DataDir + "/results/TX40_bp_5.csv");
  std::map<std::string, double> out;
  std::string line;
  while (std::getline(f, line)) {
    std::stringstream s(line);
    std::string expr, ols;
    std::getline(s, expr, ',');
    std::getline(s, ols, ',');
    out[expr.substr(0, expr.find(' '))] = std::stod(ols);
  }
  return out;
}

class Tx40Dataset : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(kTx40DataDir + "/data/pos_read_data.csv")) return;
    const Model model =
        load_robot(std::string(DYNID_SOURCE_DIR) + "/examples/staubli-tx40/tx40.yaml");
    const CsvTable pos = read_csv(kTx40DataDir + "/data/pos_read_data.csv");
    const CsvTable cur = read_csv(kTx40DataDir + "/data/curr_data.csv");
    JointRecord r;
    const double ts =
        YAML::LoadFile(kTx40DataDir +
                       "/config/T40X_config.yaml")["identification"]["processing_params"][0]["ts"]
            .as<double>();
    r.t = Eigen::VectorXd::LinSpaced(pos.rows(), 0.0, (pos.rows() - 1) * ts);
    r.q = joint_positions_from_motor(model, pos.data);
    r.tau = joint_torques_from_motor(model, cur.data);
    record_ = r;
    result_ = new IdentificationResult(identify(model, r));
    validation_ = new ValidationResult(
        validate_torques(model, r, result_->names, result_->estimate.x, IdentifyOptions{}));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete validation_;
  }
  void SetUp() override {
    if (result_ == nullptr) GTEST_SKIP() << "data set not found at " << kTx40DataDir;
  }
  static double value(const std::string& name) {
    const auto& names = result_->names;
    const auto it = std::find(names.begin(), names.end(), name);
    EXPECT_NE(it, names.end()) << name;
    return it == names.end() ? NAN : result_->estimate.x[it - names.begin()];
  }
  static IdentificationResult* result_;
  static ValidationResult* validation_;
  static JointRecord record_;
};
JointRecord Tx40Dataset::record_;
IdentificationResult* Tx40Dataset::result_ = nullptr;
ValidationResult* Tx40Dataset::validation_ = nullptr;

TEST_F(Tx40Dataset, RankAndRelativeTorqueError) {
  EXPECT_EQ(result_->rank, 61);  // 60 inertial + 27 extra columns, rank 61 (SOURCE.md)
  EXPECT_GT(result_->relative_error, 0.04);
  EXPECT_LT(result_->relative_error, 0.055);
}

// Validating on the identification run itself compares the same joint rows (near-zero-velocity
// rows left out alike), so the OLS prediction error equals the identification residual; with every
// row kept it is much larger (sign(dq) of a derived velocity is noise near zero).
TEST_F(Tx40Dataset, ValidationOnTheSameRunReproducesTheIdentificationError) {
  EXPECT_EQ(validation_->rows, result_->rows);
  EXPECT_EQ(validation_->rows + validation_->rows_excluded, 6 * result_->samples);
  EXPECT_NEAR(validation_->relative_error_all, result_->relative_error, 1e-9);
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(validation_->rms[j], result_->residual_rms[j], 1e-9 * result_->residual_rms[j]);
  }
  // The rows identify left out (near-still: friction sits on the Coulomb step there) are
  // predicted worse than the kept ones, so the all-rows figure is larger; the filtered
  // expected-sign Coulomb columns keep it within 2× (7.99 % vs 4.94 %; the hard sign(q̇) columns
  // gave more than 2×). Fails if the left-out rows stop being reported or the slow-row model
  // regresses.
  EXPECT_GT(validation_->rows_excluded, 0);
  EXPECT_GT(validation_->relative_error_all_rows, validation_->relative_error_all);
  EXPECT_LT(validation_->relative_error_all_rows, 2.0 * validation_->relative_error_all);
}

TEST_F(Tx40Dataset, FrictionMatchesPublishedValues) {
  const YAML::Node p = YAML::LoadFile(
      kTx40DataDir + "/config/T40X_config.yaml")["identification"]["robot_params"][0];
  for (int j = 0; j < 6; ++j) {
    const std::string k = std::to_string(j + 1);
    const double fv = p["fv"][j].as<double>(), fs = p["fs"][j].as<double>();
    EXPECT_NEAR(value("Fv" + k), fv, 0.04 * fv) << "Fv" << k;
    // Joint 6's Coulomb level is 0.28 N·m with 20 % relative σ here (55 % in FIGAROH's fit).
    EXPECT_NEAR(value("Fc" + k), fs, (j == 5 ? 0.15 : 0.04) * fs) << "Fc" << k;
  }
  EXPECT_NEAR(value("Fvm6"), p["fvm6"].as<double>(), 0.04 * p["fvm6"].as<double>());
  EXPECT_NEAR(value("Fcm6"), p["fsm6"].as<double>(), 0.04 * p["fsm6"].as<double>());
}

// Every row kept, the Coulomb columns the smooth law with v_c = 0.5 % of max|q̇_j| (and the coupled
// wrist motor's with the same law): no row is removed and Fv, Fc1…5 and the wrist motor's friction
// still reach the published values within 4 % (measured within 1.5 %; with v_c = 0 and every row
// kept Fc is 7–25 % low; docs/methods/identification.md §3). Fc6 (0.28 N·m) is not determined
// with every row kept (103 % relative σ), so it is not compared.
TEST_F(Tx40Dataset, SmoothCoulombLawKeepsEveryRowAndReachesThePublishedFriction) {
  const Model model =
      load_robot(std::string(DYNID_SOURCE_DIR) + "/examples/staubli-tx40/tx40.yaml");
  IdentifyOptions o;
  o.signal.zero_velocity_fraction = 0.0;
  o.signal.zero_velocity_noise_multiple = 0.0;
  o.signal.coulomb_width_fraction = 0.005;
  const IdentificationResult r = identify(model, record_, o);
  EXPECT_EQ(r.rows, 6 * r.samples);
  const YAML::Node p = YAML::LoadFile(
      kTx40DataDir + "/config/T40X_config.yaml")["identification"]["robot_params"][0];
  const auto at = [&r](const std::string& name) {
    const auto it = std::find(r.names.begin(), r.names.end(), name);
    EXPECT_NE(it, r.names.end()) << name;
    return it == r.names.end() ? NAN : r.estimate.x[it - r.names.begin()];
  };
  for (int j = 0; j < 6; ++j) {
    const std::string k = std::to_string(j + 1);
    const double fv = p["fv"][j].as<double>(), fs = p["fs"][j].as<double>();
    EXPECT_NEAR(at("Fv" + k), fv, 0.04 * fv) << "Fv" << k;
    if (j < 5) {
      EXPECT_NEAR(at("Fc" + k), fs, 0.04 * fs) << "Fc" << k;
    }
  }
  EXPECT_NEAR(at("Fvm6"), p["fvm6"].as<double>(), 0.04 * p["fvm6"].as<double>());
  EXPECT_NEAR(at("Fcm6"), p["fsm6"].as<double>(), 0.04 * p["fsm6"].as<double>());
}

TEST_F(Tx40Dataset, DominantBaseParametersMatchFigaroh) {
  const auto figaroh = figaroh_ols();
  const std::vector<std::pair<std::string, std::string>> pairs = {
      {"ZZ1R", "Izz1"}, {"XX2R", "Ixx2"}, {"XZ2R", "Ixz2"}, {"ZZ2R", "Izz2"}, {"MX2R", "mx2"},
      {"XX3R", "Ixx3"}, {"ZZ3R", "Izz3"}, {"MY3R", "my3"},  {"Ia3", "Ia3"},   {"Ia4", "Ia4"}};
  for (const auto& [ours, theirs] : pairs) {
    ASSERT_TRUE(figaroh.count(theirs)) << theirs;
    EXPECT_NEAR(value(ours), figaroh.at(theirs), 0.05 * std::abs(figaroh.at(theirs))) << ours;
  }
}

}  // namespace
}  // namespace dynid
