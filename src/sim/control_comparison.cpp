#include "dynid/sim/control_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/signal/sampling_check.hpp"

namespace dynid {

std::vector<bool> reversal_mask(const Eigen::Ref<const Eigen::VectorXd>& dqr, long window,
                                int* count) {
  const long n = dqr.size();
  std::vector<bool> mask(static_cast<size_t>(n), false);
  int changes = 0;
  // A sign below 1e-9 of the peak speed is a rest, not a direction.
  const double still = 1e-9 * (n > 0 ? dqr.cwiseAbs().maxCoeff() : 0.0);
  auto sign = [&](long k) { return dqr[k] > still ? 1 : (dqr[k] < -still ? -1 : 0); };
  long first = -1;
  for (long k = 0; k < n && first < 0; ++k)
    if (sign(k) != 0) first = k;
  if (first >= 0) {
    // Walk one full period from the first moving sample, so the change across the end counts.
    int last = sign(first);
    for (long i = 1; i <= n; ++i) {
      const long k = (first + i) % n;
      const int s = sign(k);
      if (s == 0 || s == last) continue;
      last = s;
      ++changes;
      for (long d = -window; d <= window; ++d)
        mask[static_cast<size_t>(((k + d) % n + n) % n)] = true;
    }
  }
  if (count != nullptr) *count = changes;
  return mask;
}

namespace {

TrackingErrors tracking_errors(const std::string& name, const ClosedLoopResult& run, long period,
                               const std::vector<std::vector<bool>>& masks,
                               const Eigen::VectorXi& reversals) {
  const long n = run.q_true.cols(), rows = run.t.size() - period;
  TrackingErrors out;
  out.controller = name;
  out.rms = Eigen::VectorXd::Zero(n);
  out.max = Eigen::VectorXd::Zero(n);
  out.max_at_reversal = Eigen::VectorXd::Zero(n);
  out.reversals = reversals;
  for (long j = 0; j < n; ++j) {
    for (long k = period; k < run.t.size(); ++k) {
      const double e = std::abs(run.qr(k, j) - run.q_true(k, j));
      out.rms[j] += e * e;
      out.max[j] = std::max(out.max[j], e);
      if (masks[static_cast<size_t>(j)][static_cast<size_t>(k % period)])
        out.max_at_reversal[j] = std::max(out.max_at_reversal[j], e);
    }
    out.rms[j] = std::sqrt(out.rms[j] / static_cast<double>(rows));
  }
  return out;
}

}  // namespace

ControlComparison compare_control(const Model& plant_model, const Model& controller_model,
                                  const Eigen::Ref<const Eigen::VectorXd>& t,
                                  const Eigen::Ref<const Eigen::MatrixXd>& q,
                                  const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                  const Eigen::Ref<const Eigen::MatrixXd>& ddq,
                                  const ControlComparisonOptions& options) {
  if (options.simulate.loop.periods < 2 || options.simulate.loop.samples != 0)
    throw Error("compare-control needs at least 2 periods (the first is the start-up, left out)");
  if (!(options.reversal_window >= 0.0) || !std::isfinite(options.reversal_window))
    throw Error("the reversal window must be finite and >= 0 s, got " +
                short_number(options.reversal_window));
  const SamplingInfo info = require_uniform_sampling(t, 1e-6, "control comparison");
  // A window as long as the period masks every sample (and costs samples × window): refused
  // before the two simulations, not after them.
  const double span = static_cast<double>(t.size()) / info.rate_hz();
  if (!(options.reversal_window < span)) {
    throw Error("the reversal window " + short_number(options.reversal_window) +
                " s is not shorter than one period of the reference (" + short_number(span) +
                " s); give --reversal-window below " + short_number(span));
  }
  SimulateOptions so = options.simulate;
  so.loop.record_truth = true;
  so.feed_forward = FeedForward::kNone;
  so.controller_model.reset();
  // One set of gains for both: the comparison is then about the model, not the tuning.
  const PidOptions pid =
      simulation_pid_options(plant_model, q.row(0).transpose(), info.rate_hz(), so);
  ControlComparison out;
  out.gains = {pid.kp, pid.ki, pid.kd, "pid"};
  so.gains = out.gains;
  const ClosedLoopResult plain = simulate_reference(plant_model, t, q, dq, ddq, so);
  so.feed_forward = FeedForward::kInverseDynamics;
  so.controller_model = controller_model;
  const ClosedLoopResult model_based = simulate_reference(plant_model, t, q, dq, ddq, so);

  const long period = plain.t.size() / so.loop.periods;
  const long window = std::lround(options.reversal_window * info.rate_hz());
  std::vector<std::vector<bool>> masks;
  Eigen::VectorXi reversals(plant_model.dof());
  for (int j = 0; j < plant_model.dof(); ++j)
    masks.push_back(reversal_mask(dq.col(j).head(period), window, &reversals[j]));
  out.controllers.push_back(tracking_errors("pid", plain, period, masks, reversals));
  out.controllers.push_back(
      tracking_errors("computed-torque", model_based, period, masks, reversals));
  out.samples = plain.t.size() - period;
  return out;
}

}  // namespace dynid
