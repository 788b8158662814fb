// The real Stäubli TX40 run of examples/staubli-tx40/dataset (SOURCE.md) identified with the
// integral (energy) model: friction against the published values, and the torque prediction of
// the integral estimate beside the differential model's. Skips when the data set is absent.
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identification/integral_equations.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/transmission.hpp"
#include "identification/integral_support.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kTx40DataDir;

struct Tx40Integral {
  Model model;
  JointRecord record;
  BaseParameters base;
  Estimate estimate;
  /// The integral estimate on torques the differential estimate explains exactly (control), and
  /// the differential estimate on the integral model's base parameters.
  Estimate rigid_estimate;
  Eigen::VectorXd differential_x;
  int differential_missing = 0;  ///< integral base parameters the differential result lacks
  ValidationResult integral_validation, differential_validation;
  double differential_relative_error = 0.0;
  YAML::Node published;
};

const Tx40Integral* load() {
  integral_testing::Tx40Run run = integral_testing::load_tx40(DYNID_SOURCE_DIR);
  if (!run.found) return nullptr;
  auto* r = new Tx40Integral;
  r->model = std::move(run.model);
  r->record = std::move(run.record);
  r->published = run.published;
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
  r->differential_x.resize(r->base.names.size());
  for (size_t i = 0; i < r->base.names.size(); ++i) {
    const auto it = std::find(diff.names.begin(), diff.names.end(), r->base.names[i]);
    r->differential_missing += it == diff.names.end();
    r->differential_x[i] = it == diff.names.end() ? 0.0 : diff.estimate.x[it - diff.names.begin()];
  }
  r->rigid_estimate = integral_testing::estimate_with_intervals(
      integral_equations(r->model, io.layout, true,
                         integral_testing::with_model_torques(r->model, io.layout, true, r->base,
                                                              r->differential_x, p),
                         IntegralOptions{}),
      r->base);
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
// docs/methods/identification.md, "Integral model"): of the 12 joint friction values, Fv1, Fv2 and
// Fv5 are within 10 % of the published ones (and Fvm6); the Coulomb values are not (Fc4 with the
// wrong sign), and the torque prediction is ~7× worse than the differential model's. Why: the run
// does not determine them to 10 % — the intervals are wider than that, and contain 11 of the 12
// published values — and the control test below shows that the builder is not the cause. The test
// pins these numbers so that a change to the builder or the defaults that moves them is seen.
TEST(IntegralTx40, FrictionAgainstPublishedValues) {
  const Tx40Integral* r = data();
  if (r == nullptr) GTEST_SKIP() << "data set not found at " << kTx40DataDir;
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
  // Why 10 % is out of reach: the run does not determine the Coulomb values that closely. Every
  // Coulomb value's 99.9 % interval (HAC) is wider than ± its published value, and the published
  // values lie inside the intervals except Fc4's (just outside: −4.2 to 2.2 against 2.48).
  int inside = 0;
  for (int j = 0; j < 6; ++j) {
    const std::string k = std::to_string(j + 1);
    const double fs = r->published["fs"][j].as<double>();
    const Eigen::Index c =
        std::find(r->base.names.begin(), r->base.names.end(), "Fc" + k) - r->base.names.begin();
    EXPECT_GT(0.5 * (r->estimate.ci_upper[c] - r->estimate.ci_lower[c]), fs) << "Fc" << k;
    for (const char* kind : {"Fv", "Fc"}) {
      const double truth = r->published[kind[1] == 'v' ? "fv" : "fs"][j].as<double>();
      const Eigen::Index i =
          std::find(r->base.names.begin(), r->base.names.end(), kind + k) - r->base.names.begin();
      inside += truth >= r->estimate.ci_lower[i] && truth <= r->estimate.ci_upper[i];
    }
  }
  EXPECT_EQ(inside, 11) << "published friction values inside the 99.9 % intervals";
  std::cout << "energy equations: relative error " << r->estimate.relative_error << "\n";
  EXPECT_LT(r->estimate.relative_error, 0.05);
}

// Control for the test above: with the measured torques replaced by those the differential
// estimate explains exactly (its prediction on the integral processing's own states), the energy
// equations return the differential estimate's friction. The builder is faithful on this robot,
// coupled wrist included; what moves the integral estimate on the measured torques is the part of
// them the rigid model does not explain (the differential model's 4.9 % torque residual), which
// the weakly determined directions of one scalar equation per interval absorb.
TEST(IntegralTx40, RecoversTheFrictionOfTorquesARigidModelExplains) {
  const Tx40Integral* r = data();
  if (r == nullptr) GTEST_SKIP() << "data set not found at " << kTx40DataDir;
  ASSERT_EQ(r->differential_missing, 0);
  std::cout << "energy equations on rigid-model torques: relative error "
            << r->rigid_estimate.relative_error << "\n";
  EXPECT_LT(r->rigid_estimate.relative_error, 2e-5);
  double worst = 0.0;
  for (int j = 0; j < 6; ++j) {
    for (const char* kind : {"Fv", "Fc"}) {
      const std::string name = kind + std::to_string(j + 1);
      const Eigen::Index i =
          std::find(r->base.names.begin(), r->base.names.end(), name) - r->base.names.begin();
      const double d = r->differential_x[i];
      worst = std::max(worst, std::abs(r->rigid_estimate.x[i] - d) / std::abs(d));
      EXPECT_NEAR(r->rigid_estimate.x[i], d, 2e-3 * std::abs(d)) << name;
    }
  }
  std::cout << "largest relative friction difference to the differential estimate " << worst
            << "\n";
}

TEST(IntegralTx40, TorqueValidationBesideTheDifferentialModel) {
  const Tx40Integral* r = data();
  if (r == nullptr) GTEST_SKIP() << "data set not found at " << kTx40DataDir;
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
