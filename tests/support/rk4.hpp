#pragma once

#include <functional>

#include <Eigen/Core>

namespace dynid::testing {

/// One classical Runge–Kutta step of dx/dt = f(t, x); returns x(t + h). Also gives the stage
/// derivative k1 = f(t, x) through `k1_out` (for dense output) when not null.
inline Eigen::VectorXd rk4_step(
    const std::function<Eigen::VectorXd(double, const Eigen::VectorXd&)>& f, double t,
    const Eigen::VectorXd& x, double h, Eigen::VectorXd* k1_out = nullptr) {
  const Eigen::VectorXd k1 = f(t, x), k2 = f(t + h / 2, x + h / 2 * k1),
                        k3 = f(t + h / 2, x + h / 2 * k2), k4 = f(t + h, x + h * k3);
  if (k1_out) *k1_out = k1;
  return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
}

}  // namespace dynid::testing
