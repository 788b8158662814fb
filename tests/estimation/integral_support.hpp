#pragma once

// Simulated runs for the integral-model tests: closed-loop runs of dynid's native plant (RK4 on
// the mass matrix and RNEA, not on the energy equations) or MuJoCo, tracking a multi-sine.

#include <cmath>
#include <random>

#include <Eigen/Core>

#include "dynid/estimation/equation_block.hpp"
#include "dynid/estimation/identification.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/model.hpp"
#include "dynid/sim/closed_loop.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "dynid/sim/plant.hpp"
#include "dynid/sim/sensors.hpp"

namespace dynid::integral_testing {

/// One period (duration s) of a multi-sine reference: 5 harmonics of 1/duration Hz with random
/// amplitudes (≤ amplitude/k) and phases, sampled every ts.
inline Reference multisine(int n, double duration, double ts, unsigned seed,
                           double amplitude = 0.8) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Index m = std::llround(duration / ts);
  Reference r;
  r.t = Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) * ts);
  r.q.setZero(m, n);
  r.dq.setZero(m, n);
  r.ddq.setZero(m, n);
  for (int j = 0; j < n; ++j) {
    for (int k = 1; k <= 5; ++k) {
      const double w = 2 * M_PI * k / duration, a = amplitude * u(rng) / k, phi = M_PI * u(rng);
      for (Eigen::Index i = 0; i < m; ++i) {
        const double s = std::sin(w * r.t[i] + phi), c = std::cos(w * r.t[i] + phi);
        r.q(i, j) += a * s;
        r.dq(i, j) += a * w * c;
        r.ddq(i, j) -= a * w * w * s;
      }
    }
  }
  return r;
}

/// Closed-loop run (PID with computed-torque feed-forward, zero-order-hold torque) of `model` on
/// the given plant, truth recorded.
inline ClosedLoopResult simulate(const Model& model, const Reference& ref, double ts,
                                 const SensorOptions& sensor_options, const PlantOptions& plant,
                                 int periods = 1) {
  const int n = model.dof();
  PidOptions po;
  po.kp = Eigen::VectorXd::Constant(n, 400.0);
  po.kd = Eigen::VectorXd::Constant(n, 40.0);
  po.sample_time = ts;
  po.feed_forward = FeedForward::kComputedTorque;
  po.effort_limit = Eigen::VectorXd::Constant(n, 1e6);
  PidController pid(model, po);
  PlantOptions p = plant;
  p.dt = ts;
  auto sim = make_plant(model, p);
  Sensors sensors(model, sensor_options);
  ClosedLoopOptions lo;
  lo.periods = periods;
  lo.record_truth = true;
  return run_closed_loop(ref, pid, *sim, sensors, lo);
}

/// The true run as a processed record (no filtering): t, q_true, dq_true, the applied torque.
inline ProcessedRecord truth_record(const ClosedLoopResult& run, double ts) {
  ProcessedRecord p;
  p.record.t = run.t;
  p.record.q = run.q_true;
  p.record.dq = run.dq_true;
  p.record.tau = run.tau_true;
  p.rate_hz = 1.0 / ts;
  return p;
}

/// Base parameters of the model for a layout (torque regressor; the integral model shares them).
inline BaseParameters base_of(const Model& model, const ParameterLayout& layout,
                              bool coupling = false) {
  BaseParameterOptions o;
  o.layout = layout;
  o.coupling = coupling;
  return compute_base_parameters(model, o);
}

/// Estimate and intervals of a block as identify() computes them: OLS on the base columns, then the
/// HAC sandwich over the block's samples.
inline Estimate estimate_with_intervals(const EquationBlock& b, const BaseParameters& base) {
  const Eigen::MatrixXd Wb = base.select(b.W);
  EstimationOptions eo;
  eo.names = base.names;
  Estimate e = ordinary_least_squares(Wb, b.y, b.group, eo);
  const Eigen::VectorXd res = b.y - Wb * e.x;
  apply_hac_covariance(e, Wb, res, b.sample, eo);
  return e;
}

}  // namespace dynid::integral_testing
