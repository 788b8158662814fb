#include "dynid/sim/closed_loop.hpp"

#include <cmath>
#include <string>

#include "dynid/common/error.hpp"

namespace dynid {

void check_reference(const Reference& reference, int dof, double ts) {
  const long rows = reference.t.size();
  if (rows < 2)
    throw Error("reference must have at least 2 samples (one period), got " + std::to_string(rows));
  auto check = [&](const Eigen::MatrixXd& m, const char* name) {
    if (m.rows() != rows || m.cols() != dof)
      throw Error(std::string("reference ") + name + " is " + std::to_string(m.rows()) + "x" +
                  std::to_string(m.cols()) + " but must be " + std::to_string(rows) + "x" +
                  std::to_string(dof) + " (samples x joints)");
    if (!m.allFinite()) throw Error(std::string("reference ") + name + " has NaN or Inf values");
  };
  check(reference.q, "q");
  check(reference.dq, "dq");
  check(reference.ddq, "ddq");
  if (!reference.t.allFinite()) throw Error("reference t has NaN or Inf values");
  for (long k = 1; k < rows; ++k) {
    const double step = reference.t[k] - reference.t[k - 1];
    if (std::abs(step - ts) > 1e-6 * ts)
      throw Error("reference t must be uniformly spaced by the controller sample time " +
                  std::to_string(ts) + " s, but t[" + std::to_string(k) + "] - t[" +
                  std::to_string(k - 1) + "] = " + std::to_string(step) +
                  " s: resample the reference");
  }
}

ClosedLoopResult run_closed_loop(const Reference& reference, PidController& controller,
                                 Plant& plant, Sensors& sensors, const ClosedLoopOptions& options) {
  const int n = plant.dof();
  const double ts = controller.sample_time();
  if (std::abs(plant.dt() - ts) > 1e-6 * ts)
    throw Error("plant dt (" + std::to_string(plant.dt()) +
                " s) must equal the controller sample_time (" + std::to_string(ts) + " s)");
  if (controller.integral().size() != n)
    throw Error("controller and plant have different joint counts: build both from one model");
  check_reference(reference, n, ts);
  const long period = reference.t.size();
  if (options.samples < 0 || (options.samples == 0 && options.periods < 1))
    throw Error("closed loop needs periods >= 1 or samples >= 1");
  const long total = options.samples > 0 ? options.samples : options.periods * period;

  const Eigen::VectorXd q0 =
      options.q0.size() == 0 ? Eigen::VectorXd(reference.q.row(0).transpose()) : options.q0;
  const Eigen::VectorXd dq0 =
      options.dq0.size() == 0 ? Eigen::VectorXd(reference.dq.row(0).transpose()) : options.dq0;
  plant.reset(q0, dq0);
  sensors.reset();

  ClosedLoopResult out;
  out.t.resize(total);
  out.qr.resize(total, n);
  out.q.resize(total, n);
  out.tau.resize(total, n);
  if (options.record_truth) {
    out.q_true.resize(total, n);
    out.dq_true.resize(total, n);
    out.ddq_true.resize(total, n);
    out.tau_true.resize(total, n);
  }
  Eigen::VectorXd qr(n), dqr(n), ddqr(n), y(n), tau(n), measured(n), ddq(n);
  for (long k = 0; k < total; ++k) {
    if (options.progress && k % 1000 == 0) {
      options.progress(static_cast<double>(k) / total,
                       "sample " + std::to_string(k) + "/" + std::to_string(total));
    }
    const long i = k % period;
    qr = reference.q.row(i).transpose();
    dqr = reference.dq.row(i).transpose();
    ddqr = reference.ddq.row(i).transpose();
    sensors.measure_position(plant.q(), y);
    if (k == 0) controller.reset(y);
    controller.update(qr, dqr, ddqr, y, tau);
    sensors.measure_torque(tau, measured);
    out.t[k] = reference.t[0] + static_cast<double>(k) * ts;
    out.qr.row(k) = qr.transpose();
    out.q.row(k) = y.transpose();
    out.tau.row(k) = measured.transpose();
    if (options.record_truth) {
      plant.acceleration(tau, ddq);
      out.q_true.row(k) = plant.q().transpose();
      out.dq_true.row(k) = plant.dq().transpose();
      out.ddq_true.row(k) = ddq.transpose();
      out.tau_true.row(k) = tau.transpose();
    }
    plant.step(tau);
  }
  return out;
}

}  // namespace dynid
