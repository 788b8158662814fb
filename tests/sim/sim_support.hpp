#pragma once

#include <cmath>

#include <Eigen/Core>

#include "dynid/model/model.hpp"
#include "dynid/sim/closed_loop.hpp"

namespace dynid::testing {

/// A single revolute joint about z with gravity along −y: a pendulum with a point-like mass m at
/// (l, 0, 0), inertia ic about its centre of mass (all axes) and armature ia. Its equation is
/// J q̈ = −m g l cos(q), J = m l² + ic + ia; equilibrium at q = −π/2 with ω² = m g l / J.
inline Model pendulum(double m = 1.0, double l = 0.5, double ic = 0.01, double ia = 0.0,
                      double g = 9.81) {
  Model model;
  model.name = "pendulum";
  Joint j;
  j.name = "j1";
  j.link_name = "l1";
  j.friction.Ia = ia;
  model.joints = {j};
  model.links = {
      link_params_from_com(m, Eigen::Vector3d(l, 0, 0), ic * Eigen::Matrix3d::Identity())};
  model.gravity = Eigen::Vector3d(0, -g, 0);
  model.finalize();
  return model;
}

/// One period of qr_j(t) = a_j sin(w t) + c_j sampled at ts with n_samples samples.
inline Reference sine_reference(const Eigen::VectorXd& a, const Eigen::VectorXd& c, double w,
                                double ts, int n_samples) {
  const int n = static_cast<int>(a.size());
  Reference r;
  r.t.resize(n_samples);
  r.q.resize(n_samples, n);
  r.dq.resize(n_samples, n);
  r.ddq.resize(n_samples, n);
  for (int k = 0; k < n_samples; ++k) {
    const double t = k * ts;
    r.t[k] = t;
    for (int j = 0; j < n; ++j) {
      r.q(k, j) = a[j] * std::sin(w * t) + c[j];
      r.dq(k, j) = a[j] * w * std::cos(w * t);
      r.ddq(k, j) = -a[j] * w * w * std::sin(w * t);
    }
  }
  return r;
}

}  // namespace dynid::testing
