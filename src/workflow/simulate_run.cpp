#include "dynid/workflow/simulate_run.hpp"

#include "dynid/common/error.hpp"
#include "dynid/signal/differentiation.hpp"

namespace dynid {

SimulatedRun simulate_run(const Model& model, const Eigen::VectorXd& t, const Eigen::MatrixXd& q,
                          Eigen::MatrixXd dq, Eigen::MatrixXd ddq,
                          const SimulateRunOptions& options) {
  if (options.wrench_noise.size() > 2)
    throw UsageError("--wrench-noise takes one std for all six components or two: FORCE,MOMENT");
  if (dq.size() == 0) dq = central_difference(t, q, 1);
  if (ddq.size() == 0) ddq = central_difference(t, dq, 1);
  const std::optional<MountedLoad>& load = options.load;
  SimulateOptions s = options.simulate;
  s.loop.record_truth = options.truth || load.has_value();  // the wrench follows the true motion
  SimulatedRun out;
  const ClosedLoopResult r =
      simulate_reference(load ? model_with_load(model, *load) : model, t, q, dq, ddq, s, &out.pid);
  const Eigen::Index n = model.dof();
  out.columns = {"t"};
  std::vector<const char*> prefixes = {"qr", "q", "tau"};
  if (options.truth) prefixes.insert(prefixes.end(), {"dq", "ddq"});
  for (const char* p : prefixes)
    for (Eigen::Index j = 0; j < n; ++j) out.columns.push_back(p + std::to_string(j + 1));
  if (load) out.columns.insert(out.columns.end(), {"fx", "fy", "fz", "mx", "my", "mz"});
  out.data.resize(r.t.size(), static_cast<Eigen::Index>(out.columns.size()));
  if (options.truth) {
    out.data.leftCols(1 + 5 * n) << r.t, r.qr, r.q, r.tau, r.dq_true, r.ddq_true;
  } else {
    out.data.leftCols(1 + 3 * n) << r.t, r.qr, r.q, r.tau;
  }
  if (load) {
    Eigen::MatrixXd wrench = load_sensor_wrench(model, *load, r.q_true, r.dq_true, r.ddq_true);
    const std::vector<double>& noise = options.wrench_noise;
    add_wrench_noise(wrench, noise.empty() ? 0.0 : noise.front(),
                     noise.empty() ? 0.0 : noise.back(), s.sensors.seed + 1);
    out.data.rightCols(6) = wrench;
  }
  return out;
}

}  // namespace dynid
