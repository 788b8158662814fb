#include "dynid/sim/simulate_reference.hpp"

#include <cmath>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/signal/sampling_check.hpp"

namespace dynid {

PidOptions default_pid_options(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q0,
                               double rate_hz) {
  Workspace ws(model);
  Eigen::MatrixXd M(model.dof(), model.dof());
  mass_matrix(model, ws, q0, M);
  // A discrete loop needs its bandwidth well below the sample rate (rate/40) and a derivative
  // filter of at least two samples.
  const double w = 2 * M_PI * std::min(8.0, rate_hz / 40.0);
  PidOptions o;
  o.kp = M.diagonal() * w * w;
  o.kd = M.diagonal() * 2 * 0.9 * w;
  o.ki = o.kp * 0.5;
  o.sample_time = 1.0 / rate_hz;
  o.derivative_filter_time = std::max(o.derivative_filter_time, 2.0 / rate_hz);
  o.feed_forward = FeedForward::kComputedTorque;
  o.effort_limit = Eigen::VectorXd::Constant(model.dof(), 1e6);
  return o;
}

namespace {

// One period of a uniformly sampled reference; a last sample equal to the first ends the period.
Reference periodic_reference(const Eigen::Ref<const Eigen::VectorXd>& t,
                             const Eigen::Ref<const Eigen::MatrixXd>& q,
                             const Eigen::Ref<const Eigen::MatrixXd>& dq,
                             const Eigen::Ref<const Eigen::MatrixXd>& ddq) {
  Eigen::Index m = t.size();
  if (m > 2 && (q.row(m - 1) - q.row(0)).norm() < 1e-9 * std::max(1.0, q.row(0).norm())) --m;
  return Reference{t.head(m), q.topRows(m), dq.topRows(m), ddq.topRows(m)};
}

}  // namespace

ClosedLoopResult simulate_reference(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& t,
                                    const Eigen::Ref<const Eigen::MatrixXd>& q,
                                    const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
                                    SimulateOptions options) {
  const SamplingInfo info = require_uniform_sampling(t, 1e-6, "closed-loop simulation");
  const Reference ref = periodic_reference(t, q, dq, ddq);
  options.plant.dt = info.mean_period;
  auto plant = make_plant(model, options.plant);
  PidController pid(model, default_pid_options(model, q.row(0).transpose(), info.rate_hz()));
  Sensors sensors(model, options.sensors);
  return run_closed_loop(ref, pid, *plant, sensors, options.loop);
}

SimulationValidation validate_run_by_simulation(
    const Model& identified, const Eigen::Ref<const Eigen::VectorXd>& t,
    const Eigen::Ref<const Eigen::MatrixXd>& q, const Eigen::Ref<const Eigen::MatrixXd>& dq,
    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
    const Eigen::Ref<const Eigen::MatrixXd>& q_measured,
    const Eigen::Ref<const Eigen::MatrixXd>& tau_measured, const PlantOptions& plant) {
  const SamplingInfo info = require_uniform_sampling(t, 1e-6, "validation by simulation");
  const Reference ref = periodic_reference(t, q, dq, ddq);
  SimulationValidationOptions options;
  options.plant = plant;
  options.plant.dt = info.mean_period;
  options.skip_samples = std::min<long>(ref.t.size(), q_measured.rows() / 2);
  return validate_by_simulation(
      identified, ref, default_pid_options(identified, q.row(0).transpose(), info.rate_hz()),
      q_measured, tau_measured, options);
}

}  // namespace dynid
