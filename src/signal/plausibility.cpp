#include "dynid/signal/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

namespace dynid {
namespace {

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

double median(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

std::optional<CorruptSample> find_corrupt_sample(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                                 double floor) {
  // 1.4826·MAD estimates σ of Gaussian data.
  constexpr double kMadToSigma = 1.4826;
  std::optional<CorruptSample> first;
  std::vector<double> v;
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    if (x.rows() == 0) break;
    v.assign(x.col(j).data(), x.col(j).data() + x.rows());
    const double centre = median(v);
    for (double& d : v) d = std::abs(d - centre);
    const double limit = kCorruptSpreads * std::max(kMadToSigma * median(v), floor);
    for (Eigen::Index k = 0; k < x.rows(); ++k) {
      if (first && k >= first->sample) break;
      // Written so that NaN counts as corrupt too.
      if (!(std::abs(x(k, j) - centre) <= limit)) {
        first = CorruptSample{k, j, x(k, j), centre, limit};
        break;
      }
    }
  }
  return first;
}

std::optional<std::string> check_sample_rate(const Eigen::Ref<const Eigen::VectorXd>& t,
                                             const PlausibilityOptions& options) {
  const Eigen::Index m = t.size();
  if (m < 2 || !(t[m - 1] > t[0])) return std::nullopt;
  const double rate = static_cast<double>(m - 1) / (t[m - 1] - t[0]);
  if (rate < options.min_rate_hz || rate > options.max_rate_hz) {
    throw Error("the time stamps give a sample rate of " + short_number(rate) + " Hz, outside " +
                short_number(options.min_rate_hz) + " Hz to " + short_number(options.max_rate_hz) +
                " Hz: t must be in seconds (divide milliseconds by 1000, microseconds by 1e6) "
                "or --rate must be in Hz");
  }
  if (rate < options.low_rate_hz) {
    return "low sample rate " + short_number(rate) +
           " Hz: accelerations from so few samples are unreliable; if t is in milliseconds, "
           "convert it to seconds";
  }
  return std::nullopt;
}

std::vector<std::string> check_run_plausibility(const Eigen::Ref<const Eigen::VectorXd>& t,
                                                const Eigen::Ref<const Eigen::MatrixXd>& q,
                                                const Eigen::Ref<const Eigen::MatrixXd>& tau,
                                                const std::vector<std::string>& joints,
                                                const PlausibilityOptions& options) {
  std::vector<std::string> warnings;
  const Eigen::Index m = t.size();
  if (auto w = check_sample_rate(t, options)) warnings.push_back(std::move(*w));
  if (m == 0 || q.cols() == 0) return warnings;
  std::vector<std::string> zero_torque, still, mostly_zero;
  for (Eigen::Index j = 0; j < tau.cols(); ++j) {
    const std::string name =
        j < static_cast<Eigen::Index>(joints.size()) ? joints[j] : "joint " + std::to_string(j + 1);
    const auto zeros = (tau.col(j).array() == 0.0).count();
    if (zeros == tau.rows()) {
      zero_torque.push_back(name);
    } else if (static_cast<double>(zeros) > options.unlogged_zero_fraction * tau.rows()) {
      mostly_zero.push_back(name + " (" +
                            short_number(100.0 * static_cast<double>(zeros) / tau.rows()) + " %)");
    }
    if (q.col(j).maxCoeff() - q.col(j).minCoeff() < options.still_range) still.push_back(name);
  }
  if (static_cast<Eigen::Index>(zero_torque.size()) == tau.cols()) {
    throw Error(
        "the torque is zero in every sample of every joint: the torque columns were not "
        "logged or hold something else; check the tau columns of the run");
  }
  if (static_cast<Eigen::Index>(still.size()) == q.cols()) {
    throw Error("the run does not move (every joint's position range is below " +
                short_number(options.still_range) +
                " rad): record a run on an excitation trajectory (dynid excite, dynid simulate)");
  }
  if (!zero_torque.empty()) {
    warnings.push_back("torque zero in every sample for " + join(zero_torque) +
                       ": their parameters cannot be identified; check those tau columns");
  }
  if (!mostly_zero.empty()) {
    warnings.push_back("torque exactly zero in most samples for " + join(mostly_zero) +
                       ": a measured torque is rarely exactly 0, so those channels were not "
                       "logged or only part of the time; their rows pull the parameters towards "
                       "zero torque: check those tau columns, or keep only the logged rows "
                       "(--rows, --time)");
  }
  if (!still.empty()) {
    warnings.push_back(join(still) + " do not move (position range below " +
                       short_number(options.still_range) +
                       " rad): their parameters are not excited by this run");
  }
  return warnings;
}

}  // namespace dynid
