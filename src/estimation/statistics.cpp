#include "dynid/estimation/statistics.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <boost/math/distributions/students_t.hpp>

#include "dynid/common/error.hpp"

namespace dynid {

double student_t_quantile(double level, double dof) {
  if (!(level > 0.0 && level < 1.0)) {
    throw Error("confidence level " + std::to_string(level) +
                " is outside (0, 1); pass a level such as 0.95 or 0.999");
  }
  if (!(dof > 0.0) || !std::isfinite(dof)) {
    throw Error("Student-t degrees of freedom " + std::to_string(dof) +
                " must be positive and finite; use more rows than parameters");
  }
  const boost::math::students_t dist(dof);
  return boost::math::quantile(boost::math::complement(dist, 0.5 * (1.0 - level)));
}

void fill_parameter_statistics(Estimate& e, const EstimationOptions& options) {
  const double level = options.confidence_level;
  if (!(level > 0.0 && level < 1.0)) {
    throw Error("EstimationOptions::confidence_level " + std::to_string(level) +
                " is outside (0, 1); pass a level such as 0.95 or 0.999");
  }
  const Eigen::Index p = e.x.size();
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  e.confidence_level = level;
  e.std_dev = e.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (Eigen::Index j : e.unidentifiable) e.std_dev(j) = inf;
  if (e.degrees_of_freedom <= 0) {
    e.std_dev.setConstant(nan);
    e.summary.warnings.push_back(
        "no degrees of freedom left (rows = rank): statistics are NaN; "
        "add rows to estimate the noise");
  }
  e.relative_std_percent.resize(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    const double ax = std::abs(e.x(j));
    e.relative_std_percent(j) = ax > 0.0 ? 100.0 * e.std_dev(j) / ax : inf;
  }
  e.t_quantile =
      e.degrees_of_freedom > 0 ? student_t_quantile(level, double(e.degrees_of_freedom)) : nan;
  e.ci_lower = e.x - e.t_quantile * e.std_dev;
  e.ci_upper = e.x + e.t_quantile * e.std_dev;
  e.poorly_excited.clear();
  for (Eigen::Index j = 0; j < p; ++j) {
    if (e.relative_std_percent(j) > options.poorly_excited_percent) e.poorly_excited.push_back(j);
  }
}

}  // namespace dynid
