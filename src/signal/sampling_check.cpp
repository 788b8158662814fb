#include "dynid/signal/sampling_check.hpp"

#include <cmath>
#include <sstream>

#include "dynid/common/error.hpp"

namespace dynid {

SamplingInfo check_sampling(const Eigen::Ref<const Eigen::VectorXd>& t, double relative_tolerance) {
  const Eigen::Index m = t.size();
  if (m < 2) {
    throw Error("time vector has " + std::to_string(m) + " samples: give at least 2 time stamps");
  }
  for (Eigen::Index k = 0; k < m; ++k) {
    if (!std::isfinite(t(k))) {
      throw Error("time t[" + std::to_string(k) + "] is NaN or Inf: fix or drop that sample (row " +
                  std::to_string(k) + ", 0-based)");
    }
    if (k > 0 && !(t(k) > t(k - 1))) {
      std::ostringstream msg;
      msg.precision(17);
      msg << "time is not strictly increasing at row " << k << " (0-based): t[" << k
          << "] = " << t(k) << " <= t[" << k - 1 << "] = " << t(k - 1)
          << "; sort the samples and remove duplicates";
      throw Error(msg.str());
    }
  }
  SamplingInfo info;
  info.mean_period = (t(m - 1) - t(0)) / static_cast<double>(m - 1);
  double dev = 0.0;
  for (Eigen::Index k = 1; k < m; ++k) {
    dev = std::max(dev, std::abs((t(k) - t(k - 1)) - info.mean_period));
  }
  info.max_relative_deviation = dev / info.mean_period;
  info.uniform = info.max_relative_deviation <= relative_tolerance;
  return info;
}

SamplingInfo require_uniform_sampling(const Eigen::Ref<const Eigen::VectorXd>& t,
                                      double relative_tolerance, const char* what) {
  const SamplingInfo info = check_sampling(t, relative_tolerance);
  if (!info.uniform) {
    std::ostringstream msg;
    msg << what << " needs uniform sampling but the time steps deviate up to "
        << 100.0 * info.max_relative_deviation << " % from the mean period " << info.mean_period
        << " s (tolerance " << 100.0 * relative_tolerance
        << " %): resample onto a uniform grid first (resample_uniform)";
    throw Error(msg.str());
  }
  return info;
}

void check_time_rows(const char* what, const Eigen::Ref<const Eigen::VectorXd>& t,
                     const Eigen::Ref<const Eigen::MatrixXd>& x) {
  if (t.size() != x.rows()) {
    throw Error(std::string(what) + ": time vector has " + std::to_string(t.size()) +
                " samples but the data has " + std::to_string(x.rows()) +
                " rows: give one time stamp per row");
  }
}

}  // namespace dynid
