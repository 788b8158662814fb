#pragma once

// Simulated runs for the integral-model tests: closed-loop runs of dynid's native plant (RK4 on
// the mass matrix and RNEA, not on the energy equations) or MuJoCo, tracking a multi-sine.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "dynid/estimation/equation_block.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/processed_slice.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/model/model.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/transmission.hpp"
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
/// the given plant, truth recorded. `derivative_filter_time` is the PID's Tf [s] (PidOptions): the
/// default 1 ms passes the encoder noise's derivative up to ~160 Hz into the torque (Kd = 40,
/// 1 kHz, 1e-4 rad on the puma560 runs: 2.4 N·m rms); a real controller filters its derivative
/// more (10 ms: 0.43, 20 ms: 0.24 N·m rms; bench/integral_error_bench eiv).
inline ClosedLoopResult simulate(const Model& model, const Reference& ref, double ts,
                                 const SensorOptions& sensor_options, const PlantOptions& plant,
                                 int periods = 1, double derivative_filter_time = 1e-3) {
  const int n = model.dof();
  PidOptions po;
  po.kp = Eigen::VectorXd::Constant(n, 400.0);
  po.kd = Eigen::VectorXd::Constant(n, 40.0);
  po.sample_time = ts;
  po.derivative_filter_time = derivative_filter_time;
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

/// `processed` with its torques replaced by those a rigid model explains exactly: base parameters
/// `x` (of `base`) through processed_regressor on the record's own q, dq, ddq and filtered Coulomb
/// indicators. Built in chunks of samples to bound the regressor's memory.
inline ProcessedRecord with_model_torques(const Model& model, const ParameterLayout& layout,
                                          bool coupling, const BaseParameters& base,
                                          const Eigen::VectorXd& x, ProcessedRecord processed) {
  const Eigen::Index m = processed.record.t.size();
  const int n = model.dof();
  for (Eigen::Index first = 0; first < m; first += 4096) {
    const Eigen::Index len = std::min<Eigen::Index>(4096, m - first);
    const Eigen::VectorXd tau =
        base.select(
            processed_regressor(model, layout, coupling, processed_slice(processed, first, len))) *
        x;
    for (Eigen::Index k = 0; k < len; ++k)
      processed.record.tau.row(first + k) = tau.segment(k * n, n).transpose();
  }
  return processed;
}

/// The real Stäubli TX40 run of examples/staubli-tx40/dataset (SOURCE.md): joint-side record
/// (motor positions and torques through the coupled transmission), the model, and the published
/// friction (config robot_params). `found` is false when the data set is absent.
struct Tx40Run {
  bool found = false;
  Model model;
  JointRecord record;
  YAML::Node published;
};

inline Tx40Run load_tx40(const std::string& source_dir) {
  Tx40Run r;
  const std::string data = source_dir + "/examples/staubli-tx40/dataset";
  if (!std::filesystem::exists(data + "/data/pos_read_data.csv")) return r;
  r.found = true;
  r.model = load_robot(source_dir + "/examples/staubli-tx40/tx40.yaml");
  const CsvTable pos = read_csv(data + "/data/pos_read_data.csv");
  const CsvTable cur = read_csv(data + "/data/curr_data.csv");
  const YAML::Node config = YAML::LoadFile(data + "/config/T40X_config.yaml")["identification"];
  r.published = config["robot_params"][0];
  const double ts = config["processing_params"][0]["ts"].as<double>();
  r.record.t = Eigen::VectorXd::LinSpaced(pos.rows(), 0.0, (pos.rows() - 1) * ts);
  r.record.q = joint_positions_from_motor(r.model, pos.data);
  r.record.tau = joint_torques_from_motor(r.model, cur.data);
  return r;
}

}  // namespace dynid::integral_testing
