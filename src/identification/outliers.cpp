#include "dynid/identification/outliers.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/signal/plausibility.hpp"
#include "identification/preparation.hpp"

namespace dynid {
namespace {

// 1.4826·MAD estimates σ of Gaussian data.
constexpr double kMadToSigma = 1.4826;
// Outliers listed by name in a warning; the rest are counted.
constexpr std::size_t kListed = 5;

double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::string describe(const std::vector<TorqueOutlier>& outliers, const JointRecord& record) {
  std::string s;
  for (std::size_t i = 0; i < outliers.size() && i < kListed; ++i) {
    const TorqueOutlier& o = outliers[i];
    s += (i ? ", " : "") + std::string("tau") + std::to_string(o.joint + 1) + " at sample " +
         std::to_string(o.sample + 1) + " (t = " + short_number(record.t[o.sample]) +
         " s) = " + short_number(o.value);
  }
  if (outliers.size() > kListed) s += " and " + std::to_string(outliers.size() - kListed) + " more";
  return s;
}

}  // namespace

std::vector<TorqueOutlier> find_torque_outliers(const Eigen::Ref<const Eigen::MatrixXd>& tau,
                                                const OutlierOptions& options) {
  std::vector<TorqueOutlier> out;
  const Eigen::Index m = tau.rows();
  const Eigen::Index w = std::max(1, options.half_window);
  if (m < 2 * w + 1) return out;
  std::vector<double> window, residual(static_cast<std::size_t>(m)), local(residual.size()),
      spread(residual.size());
  for (Eigen::Index j = 0; j < tau.cols(); ++j) {
    for (Eigen::Index k = 0; k < m; ++k) {
      // Windows are shifted, not shrunk, at the ends: always 2w+1 samples.
      const Eigen::Index first = std::clamp<Eigen::Index>(k - w, 0, m - 2 * w - 1);
      window.assign(tau.col(j).data() + first, tau.col(j).data() + first + 2 * w + 1);
      local[k] = median(window);
      residual[k] = std::abs(tau(k, j) - local[k]);
    }
    std::vector<double> r = residual;
    const double noise = kMadToSigma * median(r);
    std::vector<double> x(tau.col(j).data(), tau.col(j).data() + m);
    const double centre = median(x);
    for (Eigen::Index k = 0; k < m; ++k) spread[k] = std::abs(tau(k, j) - centre);
    const double signal = kMadToSigma * median(spread);
    const double limit = options.threshold * std::max(noise, options.signal_fraction * signal);
    if (!(limit > 0.0)) continue;  // constant column: nothing stands out
    for (Eigen::Index k = 0; k < m; ++k) {
      if (residual[k] > limit) out.push_back({k, j, tau(k, j), local[k]});
    }
  }
  std::sort(out.begin(), out.end(), [](const TorqueOutlier& a, const TorqueOutlier& b) {
    return a.sample != b.sample ? a.sample < b.sample : a.joint < b.joint;
  });
  return out;
}

ScreenedRun screen_run(const Model& model, const JointRecord& record,
                       const OutlierOptions& options) {
  ScreenedRun s;
  std::vector<std::string> names;
  for (const auto& joint : model.joints) names.push_back(one_line(joint.name));
  if (record.q.allFinite() && record.tau.allFinite() && record.t.allFinite()) {
    s.warnings = check_run_plausibility(record.t, record.q, record.tau, names);
  }
  s.record = record;
  if (!record.tau.allFinite()) return s;  // identify() names the NaN itself
  if (options.policy == OutlierPolicy::kReport) {
    // Kept, a corrupt torque would stop preprocess() later; here the fix can name the flag.
    JointRecord torques;
    torques.t = record.t;
    torques.tau = record.tau;
    check_corrupt_samples(torques, "pass --outliers drop or clean the log");
  }
  s.outliers = find_torque_outliers(record.tau, options);
  if (s.outliers.empty()) return s;
  const std::string list = describe(s.outliers, record);
  if (options.policy == OutlierPolicy::kDrop) {
    for (const TorqueOutlier& o : s.outliers) s.record.tau(o.sample, o.joint) = o.local_median;
    s.warnings.push_back(std::to_string(s.outliers.size()) +
                         " gross torque outliers replaced by the median of their neighbours "
                         "(--outliers drop): " +
                         list);
  } else {
    s.warnings.push_back(std::to_string(s.outliers.size()) +
                         " gross torque outliers kept (they bias the estimate): " + list +
                         "; check the log, or pass --outliers drop");
  }
  return s;
}

void check_finite_estimate(const Estimate& estimate, const ScreenedRun& screened) {
  if (estimate.x.allFinite() && std::isfinite(estimate.residual_variance)) return;
  std::string cause;
  if (!screened.outliers.empty()) {
    cause = "the run has gross torque outliers (" + describe(screened.outliers, screened.record) +
            "); pass --outliers drop or clean the log";
  } else {
    const double largest = screened.record.tau.cwiseAbs().maxCoeff();
    cause = "the torques reach " + short_number(largest) +
            " in magnitude, too large to square in double precision; check their units";
  }
  throw Error("the estimate is not finite: " + cause);
}

}  // namespace dynid
