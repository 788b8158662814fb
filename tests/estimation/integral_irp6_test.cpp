// Seed 1's IRp-6 experiment (§VI) in simulation, the integral-model part of issue 11 item 6: the
// built-in irp6 moved by rest-to-rest quintic-spline moves of joint 1 alone, joint 2 alone and
// joints 1 and 3 together (seed 1 §VI-A), in one closed-loop run on MuJoCo at 2 kHz (0.5 ms, the
// IRp-6 logger) with encoder and torque noise. Identified with short and long integrals and with
// the differential model; the truth must lie inside the 99.9 % intervals of the short-integral
// and differential estimates; seed 1 found long integrals worse than short ones, and here they are
// better (see the second test).
// (Several runs stacked into one identification is issue 11 item 2, not here.)
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "dynid/estimation/integral_equations.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/excitation/polynomial_spline.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/model/robots.hpp"
#include "estimation/integral_support.hpp"

namespace dynid {
namespace {

Reference seed1_moves(double ts) {
  // Via-points (q1, q2, q3) [rad], 1.2 s per move, at rest at every via-point.
  Eigen::MatrixXd points(3, 8);
  points << 0.0, 1.0, -0.5, -0.5, -0.5, 0.7, -0.3, 0.0,  //
      -1.3, -1.3, -1.3, -0.9, -1.6, -1.6, -1.6, -1.3,    //
      0.0, 0.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0;
  const Eigen::VectorXd times = Eigen::VectorXd::LinSpaced(8, 0.0, 7 * 1.2);
  SplineOptions so;
  so.order = SplineOrder::kQuintic;
  so.velocities = Eigen::MatrixXd::Zero(3, 8);
  so.accelerations = Eigen::MatrixXd::Zero(3, 8);
  const TrajectorySamples s =
      sample_trajectory(PolynomialSpline(times, points, so), 1.0 / ts, false);
  return Reference{s.t, s.q, s.dq, s.ddq};
}

struct Irp6Results {
  BaseParameters base;
  Eigen::VectorXd truth;
  Estimate short_integrals, long_integrals;
  IdentificationResult differential;
  /// Torque-prediction error of each estimate on the run (validate_torques, differential
  /// processing): short integrals, long integrals, differential.
  double short_torque = 0.0, long_torque = 0.0, differential_torque = 0.0;
};

Estimate integral_estimate(const Model& model, const ParameterLayout& layout,
                           const ProcessedRecord& p, const BaseParameters& base,
                           bool long_integrals) {
  IntegralOptions o;
  o.long_integrals = long_integrals;
  return integral_testing::estimate_with_intervals(integral_equations(model, layout, true, p, o),
                                                   base);
}

const Irp6Results& results() {
  static const Irp6Results r = [] {
    Irp6Results out;
    const Model model = load_robot("irp6");
    const double ts = 5e-4;
    SensorOptions so;
    so.position_noise_std = 2e-5;
    so.torque_noise_std = 0.5;
    so.seed = 7;
    PlantOptions plant;
    plant.engine = PlantEngine::kMujoco;
    const ClosedLoopResult run = integral_testing::simulate(model, seed1_moves(ts), ts, so, plant);
    const JointRecord rec{run.t, run.q, {}, {}, run.tau};
    IdentifyOptions io;
    io.signal.torque_time_offset = 0.5 * ts;  // the logged torque is held for one period
    out.differential = identify(model, rec, io);
    out.base = out.differential.base;
    out.truth = out.base.reduce(
        Eigen::VectorXd((Eigen::VectorXd(io.layout.columns(3) + 3) << io.layout.parameters(model),
                         Eigen::VectorXd::Zero(3))
                            .finished()));
    std::vector<std::pair<std::string, std::string>> choices;
    const ProcessedRecord p = preprocess(rec, integral_signal_options(), choices);
    out.short_integrals = integral_estimate(model, io.layout, p, out.base, false);
    out.long_integrals = integral_estimate(model, io.layout, p, out.base, true);
    auto torque = [&](const Estimate& e) {
      return validate_torques(model, rec, out.base.names, e.x, io).relative_error_all;
    };
    out.short_torque = torque(out.short_integrals);
    out.long_torque = torque(out.long_integrals);
    out.differential_torque = torque(out.differential.estimate);
    return out;
  }();
  return r;
}

int outside(const Estimate& e, const Eigen::VectorXd& truth, const std::vector<std::string>& names,
            const char* what) {
  int count = 0;
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    const bool in = e.ci_lower[i] <= truth[i] && truth[i] <= e.ci_upper[i];
    count += !in;
    std::cout << what << " " << names[i] << " " << e.x[i] << " ± " << e.ci_upper[i] - e.x[i]
              << " (truth " << truth[i] << ")" << (in ? "" : " OUTSIDE") << "\n";
  }
  return count;
}

TEST(IntegralIrp6, TruthInsideIntervalsShortIntegralsAndDifferential) {
  const Irp6Results& r = results();
  EXPECT_EQ(r.short_integrals.summary.rank, r.base.rank);
  EXPECT_LE(outside(r.short_integrals, r.truth, r.base.names, "short"), 1);
  EXPECT_LE(outside(r.differential.estimate, r.truth, r.base.names, "differential"), 1);
}

// Seed 1 §VI found long integrals worse than short ones on the real IRp-6. In this simulation
// they are better: over 10 ms intervals of these slow 1.2 s moves the kinetic-energy change is
// small against the endpoint velocity noise, which enters every short row twice (e_{i+1} − e_i)
// but a long row only through its two ends while its energy change grows; the friction and
// torque-noise errors that long integrals accumulate stay small here (no torque bias, white
// noise). The test pins the measured order (short 6.3 %, long 0.70 %, differential 0.54 % torque
// prediction error on the run); docs/methods/estimation.md §7 has the puma560 and TX40 figures.
TEST(IntegralIrp6, LongIntegralsBeatShortOnesHereUnlikeSeed1) {
  const Irp6Results& r = results();
  std::cout << "torque prediction error on the run: short integrals " << r.short_torque
            << ", long integrals " << r.long_torque << ", differential " << r.differential_torque
            << "\n";
  EXPECT_LT(r.long_torque, 0.5 * r.short_torque);
  EXPECT_GT(r.long_torque, r.differential_torque);
  // Long rows' errors are a random walk (lag-1 autocorrelation ≈ 1): the HAC intervals are then
  // only a rough guide; how many parameters they miss is reported, not asserted.
  std::cout << outside(r.long_integrals, r.truth, r.base.names, "long")
            << " parameters outside the long-integral intervals\n";
}

}  // namespace
}  // namespace dynid
