#include "dynid/sim/simulation_validation.hpp"

#include <string>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/signal/plausibility.hpp"

namespace dynid {

SimulationValidation validate_by_simulation(const Model& identified, const Reference& reference,
                                            const PidOptions& controller,
                                            const Eigen::Ref<const Eigen::MatrixXd>& q_measured,
                                            const Eigen::Ref<const Eigen::MatrixXd>& tau_measured,
                                            const SimulationValidationOptions& options) {
  const int n = identified.dof();
  const long rows = q_measured.rows();
  if (q_measured.cols() != n || tau_measured.cols() != n || tau_measured.rows() != rows)
    throw Error("measured q and tau must both be N x " + std::to_string(n) +
                " (samples x joints of the identified model), got " +
                std::to_string(q_measured.rows()) + "x" + std::to_string(q_measured.cols()) +
                " and " + std::to_string(tau_measured.rows()) + "x" +
                std::to_string(tau_measured.cols()));
  if (!q_measured.allFinite() || !tau_measured.allFinite())
    throw Error("measured q or tau has NaN or Inf values: clean or trim the measured run");
  // One corrupt sample (1e200) makes the error statistics NaN or meaningless: refused like
  // preprocess() refuses it for a fit (the same floors: 1 rad, 1 N·m).
  for (const auto& [x, what] : {std::pair{&q_measured, "q"}, std::pair{&tau_measured, "tau"}}) {
    if (const std::optional<CorruptSample> c = find_corrupt_sample(*x, 1.0)) {
      throw Error("measured " + std::string(what) + std::to_string(c->column + 1) + " at sample " +
                  std::to_string(c->sample + 1) + " = " + short_number(c->value) +
                  " is a corrupt sample: it lies more than " + short_number(c->limit) +
                  " from the median " + short_number(c->median) +
                  " of its column; remove or repair that row of the measured run");
    }
  }
  if (options.skip_samples < 0 || rows - options.skip_samples < 2)
    throw Error("skip_samples = " + std::to_string(options.skip_samples) +
                " leaves fewer than 2 of " + std::to_string(rows) +
                " measured samples: lower skip_samples");
  PlantOptions plant_options = options.plant;
  plant_options.dt = controller.sample_time;
  auto plant = make_plant(identified, plant_options);
  PidController pid(identified, controller);
  Sensors sensors(identified, SensorOptions{});
  ClosedLoopOptions loop;
  loop.samples = rows;
  if (options.start_at_measured) loop.q0 = q_measured.row(0).transpose();
  SimulationValidation out;
  out.simulated = run_closed_loop(reference, pid, *plant, sensors, loop);
  out.position_error = q_measured - out.simulated.q;
  out.torque_error = tau_measured - out.simulated.tau;
  const long used = rows - options.skip_samples;
  for (int j = 0; j < n; ++j) {
    out.position.push_back(error_statistics(out.position_error.col(j).tail(used)));
    out.torque.push_back(error_statistics(out.torque_error.col(j).tail(used)));
  }
  return out;
}

}  // namespace dynid
