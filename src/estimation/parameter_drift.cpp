#include "dynid/estimation/parameter_drift.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <regex>
#include <string>

#include <boost/math/distributions/normal.hpp>

#include "dynid/common/error.hpp"

namespace dynid {

const char* to_string(ParameterRole role) {
  switch (role) {
    case ParameterRole::kArmature:
      return "armature";
    case ParameterRole::kFriction:
      return "friction";
    case ParameterRole::kPayload:
      return "payload";
    case ParameterRole::kInertial:
      break;
  }
  return "inertial";
}

ParameterRole parameter_role(const std::string& name) {
  static const std::regex friction("(Fv|Fc|Fo|Fvp|Fvn|Fcp|Fcn|Fvm|Fcm)[0-9]+R?");
  static const std::regex armature("(Ia|Iam)[0-9]+R?");
  static const std::regex payload("m|mcx|mcy|mcz|Ixx|Ixy|Ixz|Iyy|Iyz|Izz");
  if (std::regex_match(name, friction)) return ParameterRole::kFriction;
  if (std::regex_match(name, armature)) return ParameterRole::kArmature;
  if (std::regex_match(name, payload)) return ParameterRole::kPayload;
  return ParameterRole::kInertial;
}

DriftComparison compare_estimates(const std::vector<DriftInput>& inputs,
                                  const DriftOptions& options) {
  if (inputs.size() < 2) {
    throw Error("a comparison needs at least two results (the baseline first)");
  }
  if (!(options.alpha > 0.0 && options.alpha < 1.0)) {
    throw Error("the false-alarm rate alpha must be in (0, 1), e.g. 0.01");
  }
  for (const DriftInput& in : inputs) {
    const auto n = static_cast<Eigen::Index>(in.names.size());
    if (in.values.size() != n || in.std_devs.size() != n) {
      throw Error("'" + in.label + "': " + std::to_string(n) + " names but " +
                  std::to_string(in.values.size()) + " values and " +
                  std::to_string(in.std_devs.size()) + " standard deviations");
    }
  }
  DriftComparison out;
  out.alpha = options.alpha;
  const auto index_of = [](const DriftInput& in, const std::string& name) -> Eigen::Index {
    const auto it = std::find(in.names.begin(), in.names.end(), name);
    return it == in.names.end() ? -1 : static_cast<Eigen::Index>(it - in.names.begin());
  };
  const DriftInput& base = inputs.front();
  for (std::size_t r = 1; r < inputs.size(); ++r) {
    for (const std::string& name : inputs[r].names) {
      if (index_of(base, name) < 0 &&
          std::find(out.not_shared.begin(), out.not_shared.end(), name) == out.not_shared.end())
        out.not_shared.push_back(name);
    }
  }
  for (std::size_t i = 0; i < base.names.size(); ++i) {
    const std::string& name = base.names[i];
    const bool shared = std::all_of(inputs.begin(), inputs.end(),
                                    [&](const DriftInput& in) { return index_of(in, name) >= 0; });
    if (!shared) {
      out.not_shared.push_back(name);
      continue;
    }
    for (std::size_t r = 1; r < inputs.size(); ++r) {
      const Eigen::Index k = index_of(inputs[r], name);
      ParameterDrift d;
      d.name = name;
      d.role = parameter_role(name);
      d.result = static_cast<int>(r);
      d.before = base.values[static_cast<Eigen::Index>(i)];
      d.after = inputs[r].values[k];
      d.change = d.after - d.before;
      const double s0 = base.std_devs[static_cast<Eigen::Index>(i)], s1 = inputs[r].std_devs[k];
      d.std_dev = std::sqrt(s0 * s0 + s1 * s1);
      d.tested = std::isfinite(d.std_dev) && d.std_dev > 0.0 && std::isfinite(d.change);
      if (d.tested) {
        d.z = d.change / d.std_dev;
        d.p_value = std::erfc(std::abs(d.z) / std::sqrt(2.0));
      } else {
        d.z = std::numeric_limits<double>::quiet_NaN();
        d.p_value = d.p_adjusted = std::numeric_limits<double>::quiet_NaN();
      }
      out.rows.push_back(d);
    }
  }
  // Holm's step-down: the k-th smallest p-value (1-based) is multiplied by (m − k + 1), made
  // non-decreasing, and compared with alpha.
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < out.rows.size(); ++i)
    if (out.rows[i].tested) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return out.rows[a].p_value < out.rows[b].p_value;
  });
  const auto m = static_cast<double>(order.size());
  out.tests = static_cast<int>(order.size());
  double running = 0.0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    ParameterDrift& d = out.rows[order[k]];
    running = std::max(running, std::min(1.0, (m - static_cast<double>(k)) * d.p_value));
    d.p_adjusted = running;
    d.flagged = d.p_adjusted <= options.alpha;
  }
  if (out.tests > 0) {
    const boost::math::normal normal;
    out.first_critical_z =
        boost::math::quantile(boost::math::complement(normal, options.alpha / (2.0 * m)));
  }
  return out;
}

}  // namespace dynid
