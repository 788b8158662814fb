#pragma once

// Closed-loop test runs on a simulated plant (simulate_reference: PID, sensor noise fed back,
// native RK4 plant with tanh-smoothed Coulomb friction by default), shared by the estimation
// tests so that they differ only in what they vary.

#include <string>
#include <utility>
#include <vector>

#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/sim/simulate_reference.hpp"

namespace dynid::testing {

// planar2 with viscous, Coulomb and offset friction on both joints.
inline Model planar2_with_friction() {
  Model m = load_robot("planar2");
  m.joints[0].friction.Fv = 1.5;
  m.joints[0].friction.Fc = 2.0;
  m.joints[0].friction.Fo = 0.3;
  m.joints[1].friction.Fv = 0.8;
  m.joints[1].friction.Fc = 1.0;
  m.joints[1].friction.Fo = -0.2;
  return m;
}

// The 0.2 Hz, 4-harmonic planar2 reference the identification tests excite with.
inline FourierCoefficients planar2_reference() {
  FourierCoefficients c = FourierCoefficients::zeros({4, 4}, 0.2);
  c.a[0] << 0.8, 0.3, -0.2, 0.1;
  c.b[0] << 0.2, -0.3, 0.1, 0.05;
  c.a[1] << -0.6, 0.4, 0.2, -0.1;
  c.b[1] << 0.3, 0.2, -0.2, 0.1;
  c.q0 = Eigen::Vector2d(-0.5, 0.8);
  return c;
}

// `so.loop.periods` periods of one reference period `tr` in closed loop; the first (start-up)
// period is dropped. Velocities and accelerations are left to the signal processing.
inline JointRecord closed_loop_run(const Model& m, const TrajectorySamples& tr,
                                   const SimulateOptions& so) {
  const ClosedLoopResult run = simulate_reference(m, tr.t, tr.q, tr.dq, tr.ddq, so);
  const Eigen::Index skip = tr.t.size(), rows = run.t.size() - skip;
  return {run.t.tail(rows), run.q.bottomRows(rows), {}, {}, run.tau.bottomRows(rows)};
}

// Sensor options: encoder noise `position_noise` [rad], torque noise `torque_noise` [N·m].
inline SimulateOptions noisy_sensors(double position_noise, double torque_noise, unsigned seed,
                                     int periods) {
  SimulateOptions so;
  so.sensors.position_noise_std = position_noise;
  so.sensors.torque_noise_std = torque_noise;
  so.sensors.seed = seed;
  so.loop.periods = periods;
  return so;
}

// A run prepared by preprocess() with its defaults, the logged command (held over the next step
// by simulate_reference) re-timed by half a period.
inline ProcessedRecord prepared(const JointRecord& record, double rate) {
  std::vector<std::pair<std::string, std::string>> choices;
  SignalOptions signal;
  signal.torque_time_offset = 0.5 / rate;
  return preprocess(record, signal, choices);
}

}  // namespace dynid::testing
