// The integral model's energy chart (seed 1 Fig. 5: P. Dutkiewicz, K. R. Kozłowski,
// W. S. Wróblewski, "Experimental Identification of Robot and Load Dynamic Parameters", 1993) of a
// result whose run leaves base parameters not excited. The estimate then lives on fewer columns
// than the base set; the chart multiplied every base column by it, reading past the estimate
// (±4e42 J for 0.4 J measured on every integral result of examples/irp6). Oracle: the work the
// logged torques did over each interval of the raw run (trapezoidal rule on the path), not the
// report's own equations.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/report/html_report.hpp"
#include "support/closed_loop_runs.hpp"

namespace dynid {
namespace {

constexpr double kRate = 100.0;
constexpr double kInterval = 0.1;  // s: 10 samples per energy equation

// planar2 with friction: joint 1 follows the identification tests' 0.2 Hz reference for three
// periods, joint 2 stands still at 0.8 rad (a joint held by a brake, or a joint whose encoder
// never leaves its count, as on the IRp-6 runs of examples/irp6). Link 2 then rides on link 1
// as one rigid body: the data leave its own parameters and joint 2's armature and friction
// undetermined. Torques: the model's inverse dynamics (Coulomb sign(dq) included) plus white
// noise of 0.05 N·m, logged at the position time stamps.
const JointRecord& joint1_run() {
  static const JointRecord run = [] {
    const Model m = testing::planar2_with_friction();
    FourierCoefficients c = testing::planar2_reference();
    c.a[1].setZero();
    c.b[1].setZero();
    const FourierTrajectory trajectory(c);
    const Eigen::Index samples = static_cast<Eigen::Index>(3 * 5.0 * kRate);
    JointRecord r;
    r.t = Eigen::VectorXd::LinSpaced(samples, 0.0, (samples - 1) / kRate);
    r.q.resize(samples, 2);
    r.tau.resize(samples, 2);
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 0.05);
    Eigen::VectorXd q(2), dq(2), ddq(2);
    for (Eigen::Index k = 0; k < samples; ++k) {
      trajectory.evaluate(r.t[k], q, dq, ddq);
      r.q.row(k) = q.transpose();
      r.tau.row(k) = rnea(m, q, dq, ddq).transpose();
      r.tau(k, 0) += noise(rng);
      r.tau(k, 1) += noise(rng);
    }
    return r;
  }();
  return run;
}

IdentifyOptions integral_options() {
  IdentifyOptions o;
  o.model = IdentificationModel::kIntegral;
  o.integral.interval = kInterval;
  return o;
}

const IdentificationResult& joint1_result() {
  static const IdentificationResult r =
      identify(testing::planar2_with_friction(), joint1_run(), integral_options());
  return r;
}

// Work of the logged torques over [ta, tb): Σ ½(τ_k + τ_{k+1})ᵀ(q_{k+1} − q_k) over the raw
// samples, the trapezoidal rule on the path (no velocity, no filter).
double logged_work(const JointRecord& r, double ta, double tb) {
  double w = 0.0;
  const double eps = 1e-6;
  for (Eigen::Index k = 0; k + 1 < r.t.size(); ++k) {
    if (r.t[k] < ta - eps || r.t[k] >= tb - eps) continue;
    w += 0.5 * (r.tau.row(k) + r.tau.row(k + 1)).dot(r.q.row(k + 1) - r.q.row(k));
  }
  return w;
}

double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double e2 = 0.0, b2 = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    e2 += (a[i] - b[i]) * (a[i] - b[i]);
    b2 += b[i] * b[i];
  }
  return std::sqrt(e2 / b2);
}

TEST(EnergyPlot, ResultWithParametersNotExcitedDrawsTheMeasuredWork) {
  const Model model = testing::planar2_with_friction();
  const IdentificationResult& r = joint1_result();
  // The case: the estimate has fewer values than the base set.
  ASSERT_FALSE(r.not_excited.empty());
  ASSERT_LT(r.names.size(), r.base.names.size());
  EXPECT_EQ(joint1_run().q.col(1).maxCoeff(), joint1_run().q.col(1).minCoeff());
  ASSERT_EQ(r.estimate.x.size(), static_cast<Eigen::Index>(r.names.size()));
  PredictionPlotOptions every;
  every.max_points = 100000;  // every interval, so that each can be checked against the oracle
  const nlohmann::json plot = energy_plot_json(model, r, integral_options(), every);
  ASSERT_TRUE(plot.is_object()) << plot.dump();
  const auto t = plot["t"].get<std::vector<double>>();
  const auto measured = plot["measured"].get<std::vector<double>>();
  const auto predicted = plot["predicted"].get<std::vector<double>>();
  ASSERT_GT(t.size(), 100u);  // 3 periods of 5 s in 0.1 s intervals
  ASSERT_EQ(measured.size(), t.size());
  ASSERT_EQ(predicted.size(), t.size());
  EXPECT_EQ(plot["decimated_every"], 1);
  std::vector<double> oracle;
  for (double end : t) oracle.push_back(logged_work(joint1_run(), end - kInterval, end));
  double largest = 0.0;
  for (double w : oracle) largest = std::max(largest, std::abs(w));
  ASSERT_GT(largest, 0.1);  // J: the arm does work
  // The chart's measured work is the logged one (filtered at 10 Hz, integrated by Simpson's
  // rule), and the model's prediction explains it: the same joules, not 1e42.
  std::string missing;
  for (const auto& name : r.not_excited) missing += " " + name;
  std::printf("not excited:%s; measured vs logged work %.2g, predicted vs measured %.2g\n",
              missing.c_str(), relative_difference(measured, oracle),
              relative_difference(predicted, measured));
  EXPECT_LT(relative_difference(measured, oracle), 0.05);
  EXPECT_LT(relative_difference(predicted, measured), 0.05);
  for (size_t i = 0; i < predicted.size(); ++i) {
    ASSERT_LT(std::abs(predicted[i]), 2.0 * largest) << "interval ending at " << t[i] << " s";
  }
}

// An estimate that does not match its names is refused before any product is formed (the
// explicit size check; Eigen's own checks of the asan build would abort there too).
TEST(EnergyPlot, EstimateAndNamesOfDifferentSizesAreAnError) {
  const Model model = testing::planar2_with_friction();
  IdentificationResult r = joint1_result();
  ASSERT_FALSE(r.not_excited.empty());
  r.names.push_back(r.not_excited.front());
  EXPECT_THROW(energy_plot_json(model, r, integral_options()), Error);
  // A name that is not a base parameter of the model is an error, not a wrong column.
  r = joint1_result();
  r.names.front() = "ZZ9R";
  EXPECT_THROW(energy_plot_json(model, r, integral_options()), Error);
}

}  // namespace
}  // namespace dynid
