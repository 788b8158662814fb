#include "dynid/excitation/trajectory_samples.hpp"

#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

namespace dynid {

void check_trajectory_samples(double duration, double rate, const std::string& what) {
  if (!(duration * rate > kMaxTrajectorySamples)) return;
  throw Error(what + " " + short_number(duration) + " s, " + short_number(duration * rate) +
              " samples at " + short_number(rate) + " Hz, more than the " +
              short_number(kMaxTrajectorySamples) +
              " a trajectory may have; shorten it (a higher fundamental frequency, a shorter "
              "duration) or lower the rate");
}

TrajectorySamples sample_trajectory(const Trajectory& trajectory, double rate, bool include_end) {
  if (!std::isfinite(rate) || rate <= 0.0)
    throw Error("sampling rate: must be finite and > 0 Hz; got " + std::to_string(rate));
  const double duration = trajectory.duration();
  if (!(duration > 0.0) || !std::isfinite(duration))
    throw Error("trajectory: duration must be finite and > 0 s to be sampled");
  check_trajectory_samples(duration, rate, "the trajectory lasts");
  // Guard against t = k/rate landing a rounding error beyond the end.
  const double steps = duration * rate;
  Eigen::Index m = static_cast<Eigen::Index>(std::floor(steps + 1e-9));
  if (include_end) {
    m += 1;
  } else if (std::abs(steps - std::round(steps)) > 1e-9 * std::max(1.0, steps)) {
    m += 1;  // duration not a multiple of the step: the last sample before the end is kept
  }
  if (m < 1) m = 1;
  const int n = trajectory.dof();
  TrajectorySamples s;
  s.t.resize(m);
  s.q.resize(m, n);
  s.dq.resize(m, n);
  s.ddq.resize(m, n);
  Eigen::VectorXd q(n), dq(n), ddq(n);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = static_cast<double>(k) / rate;
    s.t[k] = t;
    trajectory.evaluate(t, q, dq, ddq);
    s.q.row(k) = q.transpose();
    s.dq.row(k) = dq.transpose();
    s.ddq.row(k) = ddq.transpose();
  }
  return s;
}

}  // namespace dynid
