#include "dynid/sim/sensors.hpp"

#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

namespace dynid {

namespace {

constexpr double kPi = 3.14159265358979323846;

void check_non_negative(double v, const char* field) {
  if (!(v >= 0.0) || !std::isfinite(v))
    throw Error(std::string("sensor option ") + field + " must be finite and >= 0 (got " +
                short_number(v) + ")");
}

}  // namespace

void Sensors::DelayLine::push(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> out) {
  const long length = static_cast<long>(buffer.size());
  if (count == 0)
    for (auto& b : buffer) b = x;  // hold the first reading until d samples have been seen
  buffer[count % length] = x;
  out = buffer[(count + 1) % length];  // the sample written d = length − 1 pushes ago
  ++count;
}

Sensors::Sensors(const Model& model, const SensorOptions& options) : options_(options) {
  check_non_negative(options.counts_per_rev, "counts_per_rev");
  check_non_negative(options.prismatic_resolution, "prismatic_resolution");
  check_non_negative(options.position_noise_std, "position_noise_std");
  check_non_negative(options.torque_noise_std, "torque_noise_std");
  if (options.position_delay < 0 || options.torque_delay < 0)
    throw Error("sensor delays position_delay and torque_delay must be >= 0 samples");
  const int n = model.dof();
  step_.resize(n);
  for (int j = 0; j < n; ++j)
    step_[j] = model.joints[j].type == JointType::kRevolute
                   ? (options.counts_per_rev > 0.0 ? 2.0 * kPi / options.counts_per_rev : 0.0)
                   : options.prismatic_resolution;
  scratch_.resize(n);
  position_line_.buffer.assign(options.position_delay + 1, Eigen::VectorXd::Zero(n));
  torque_line_.buffer.assign(options.torque_delay + 1, Eigen::VectorXd::Zero(n));
  reset();
}

void Sensors::reset() {
  rng_.seed(options_.seed);
  normal_.reset();
  position_line_.count = torque_line_.count = 0;
}

void Sensors::measure_position(const Eigen::Ref<const Eigen::VectorXd>& q,
                               Eigen::Ref<Eigen::VectorXd> y) {
  const int n = static_cast<int>(step_.size());
  if (q.size() != n || y.size() != n)
    throw Error("sensor positions must have " + std::to_string(n) + " entries (one per joint)");
  for (int j = 0; j < n; ++j) {
    double v = q[j];
    if (options_.position_noise_std > 0.0) v += options_.position_noise_std * normal_(rng_);
    if (step_[j] > 0.0) v = step_[j] * std::round(v / step_[j]);  // nearest encoder count
    scratch_[j] = v;
  }
  position_line_.push(scratch_, y);
}

void Sensors::measure_torque(const Eigen::Ref<const Eigen::VectorXd>& tau,
                             Eigen::Ref<Eigen::VectorXd> m) {
  const int n = static_cast<int>(step_.size());
  if (tau.size() != n || m.size() != n)
    throw Error("sensor torques must have " + std::to_string(n) + " entries (one per joint)");
  for (int j = 0; j < n; ++j) {
    scratch_[j] = tau[j];
    if (options_.torque_noise_std > 0.0) scratch_[j] += options_.torque_noise_std * normal_(rng_);
  }
  torque_line_.push(scratch_, m);
}

}  // namespace dynid
