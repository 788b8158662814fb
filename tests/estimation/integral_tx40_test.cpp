// The real Stäubli TX40 run of examples/staubli-tx40/dataset (SOURCE.md) identified with the
// integral (energy) model: friction against the published values, and the torque prediction of
// the integral estimate beside the differential model's. Skips when the data set is absent.
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "dynid/estimation/integral_equations.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/transmission.hpp"
#include "estimation/integral_support.hpp"

namespace dynid {
namespace {

const std::string kData = std::string(DYNID_SOURCE_DIR) + "/examples/staubli-tx40/dataset";

struct Tx40Integral {
  Model model;
  JointRecord record;
  BaseParameters base;
  Estimate estimate;
  ValidationResult integral_validation, differential_validation;
  double differential_relative_error = 0.0;
  YAML::Node published;
};

const Tx40Integral* load() {
  if (!std::filesystem::exists(kData + "/data/pos_read_data.csv")) return nullptr;
  auto* r = new Tx40Integral;
  r->model = load_robot(std::string(DYNID_SOURCE_DIR) + "/examples/staubli-tx40/tx40.yaml");
  const CsvTable pos = read_csv(kData + "/data/pos_read_data.csv");
  const CsvTable cur = read_csv(kData + "/data/curr_data.csv");
  const YAML::Node config = YAML::LoadFile(kData + "/config/T40X_config.yaml")["identification"];
  r->published = config["robot_params"][0];
  const double ts = config["processing_params"][0]["ts"].as<double>();
  r->record.t = Eigen::VectorXd::LinSpaced(pos.rows(), 0.0, (pos.rows() - 1) * ts);
  r->record.q = joint_positions_from_motor(r->model, pos.data);
  r->record.tau = joint_torques_from_motor(r->model, cur.data);
  IdentifyOptions io;
  io.signal = integral_signal_options();
  std::vector<std::pair<std::string, std::string>> choices;
  const ProcessedRecord p = preprocess(r->record, io.signal, choices);
  BaseParameterOptions bo;
  bo.layout = io.layout;
  bo.coupling = true;
  r->base = compute_base_parameters(r->model, bo);
  r->estimate = integral_testing::estimate_with_intervals(
      integral_equations(r->model, io.layout, true, p, IntegralOptions{}), r->base);
  // Torque prediction on the run with the default (differential) processing, as dynid validate.
  r->integral_validation =
      validate_torques(r->model, r->record, r->base.names, r->estimate.x, IdentifyOptions{});
  const IdentificationResult diff = identify(r->model, r->record);
  r->differential_relative_error = diff.relative_error;
  r->differential_validation =
      validate_torques(r->model, r->record, diff.names, diff.estimate.x, IdentifyOptions{});
  return r;
}

const Tx40Integral* data() {
  static const Tx40Integral* r = load();
  return r;
}

double value(const Tx40Integral& r, const std::string& name) {
  const auto it = std::find(r.base.names.begin(), r.base.names.end(), name);
  EXPECT_NE(it, r.base.names.end()) << name;
  return it == r.base.names.end() ? NAN : r.estimate.x[it - r.base.names.begin()];
}

// What the integral model gets on this run with its defaults (issue 11 item 7; numbers in
// docs/methods/estimation.md, "Integral model"): of the 12 joint friction values, Fv1, Fv2 and Fv5
// are within 10 % of the published ones (and Fvm6); the Coulomb values are not (Fc4 with the
// wrong sign), and the torque prediction is ~7× worse than the differential model's. One scalar
// equation per interval sums the power of all six joints, so the small joints' friction is
// weakly determined. Parallel filtering of the Coulomb work raised the count from 1 to 3 and cut
// the torque error from 41 % to 35 %. The test pins these numbers so that a change to the builder
// or the defaults that moves them is seen.
TEST(IntegralTx40, FrictionAgainstPublishedValues) {
  const Tx40Integral* r = data();
  if (r == nullptr) GTEST_SKIP() << "data set not found at " << kData;
  int within = 0;
  for (int j = 0; j < 6; ++j) {
    const std::string k = std::to_string(j + 1);
    const double fv = r->published["fv"][j].as<double>(), fs = r->published["fs"][j].as<double>();
    const double ev = value(*r, "Fv" + k), ec = value(*r, "Fc" + k);
    std::cout << "Fv" << k << " " << ev << " (published " << fv << "), Fc" << k << " " << ec
              << " (published " << fs << ")\n";
    within += std::abs(ev - fv) <= 0.1 * fv;
    within += std::abs(ec - fs) <= 0.1 * fs;
  }
  const double fvm = r->published["fvm6"].as<double>(), fsm = r->published["fsm6"].as<double>();
  std::cout << "Fvm6 " << value(*r, "Fvm6") << " (published " << fvm << "), Fcm6 "
            << value(*r, "Fcm6") << " (published " << fsm << ")\n";
  for (int j : {0, 1, 4}) {
    const double fv = r->published["fv"][j].as<double>();
    EXPECT_NEAR(value(*r, "Fv" + std::to_string(j + 1)), fv, 0.1 * fv);
  }
  EXPECT_NEAR(value(*r, "Fvm6"), fvm, 0.1 * fvm);
  EXPECT_EQ(within, 3) << "of the 12 joint friction values within 10 %";
  std::cout << "energy equations: relative error " << r->estimate.relative_error << "\n";
  EXPECT_LT(r->estimate.relative_error, 0.05);
}

TEST(IntegralTx40, TorqueValidationBesideTheDifferentialModel) {
  const Tx40Integral* r = data();
  if (r == nullptr) GTEST_SKIP() << "data set not found at " << kData;
  std::cout << "torque validation on the run (differential processing): integral model "
            << r->integral_validation.relative_error_all << ", differential model "
            << r->differential_validation.relative_error_all << "\n";
  EXPECT_NEAR(r->differential_validation.relative_error_all, r->differential_relative_error, 1e-9);
  EXPECT_GT(r->integral_validation.relative_error_all,
            5.0 * r->differential_validation.relative_error_all);
  EXPECT_LT(r->integral_validation.relative_error_all, 0.5);
}

}  // namespace
}  // namespace dynid
