#pragma once

#include <cmath>

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid::testing {

// Planar 2R arm in the x–y plane, gravity along −y, links of length l1, l2 with their centres of
// mass on the link axis at lc1, lc2 and inertia I1, I2 about the centre of mass (z axis). The
// closed form is Spong, Hutchinson & Vidyasagar, "Robot Modeling and Control", eq. 7.87 ff.
struct Planar2 {
  double m1 = 2.0, m2 = 1.5, l1 = 1.0, lc1 = 0.5, lc2 = 0.4, I1 = 0.2, I2 = 0.1, g = 9.81;

  Model model() const {
    Model m;
    m.name = "planar2_test";
    Joint j1, j2;
    j1.name = "j1";
    j2.name = "j2";
    j2.parent = 0;
    j2.p_PJ = Eigen::Vector3d(l1, 0, 0);
    m.joints = {j1, j2};
    Eigen::Matrix3d I1m = Eigen::Matrix3d::Zero(), I2m = Eigen::Matrix3d::Zero();
    I1m(0, 0) = I1m(1, 1) = I1m(2, 2) = I1;  // a body symmetric enough for the planar motion
    I2m(0, 0) = I2m(1, 1) = I2m(2, 2) = I2;
    m.links = {link_params_from_com(m1, Eigen::Vector3d(lc1, 0, 0), I1m),
               link_params_from_com(m2, Eigen::Vector3d(lc2, 0, 0), I2m)};
    m.gravity = Eigen::Vector3d(0, -g, 0);
    m.finalize();
    return m;
  }

  Eigen::Vector2d torque(const Eigen::Vector2d& q, const Eigen::Vector2d& dq,
                         const Eigen::Vector2d& ddq) const {
    const double c2 = std::cos(q[1]), s2 = std::sin(q[1]);
    const double d11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2 * l1 * lc2 * c2) + I1 + I2;
    const double d12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + I2;
    const double d22 = m2 * lc2 * lc2 + I2;
    const double h = -m2 * l1 * lc2 * s2;
    const double g1 =
        (m1 * lc1 + m2 * l1) * g * std::cos(q[0]) + m2 * lc2 * g * std::cos(q[0] + q[1]);
    const double g2 = m2 * lc2 * g * std::cos(q[0] + q[1]);
    return {d11 * ddq[0] + d12 * ddq[1] + h * dq[1] * dq[1] + 2 * h * dq[0] * dq[1] + g1,
            d12 * ddq[0] + d22 * ddq[1] - h * dq[0] * dq[0] + g2};
  }
};

// One sample of a fixed excitation of examples/robots/planar2.yaml (slender rods: I = m·l²/12
// about the centre of mass), torques from the closed form above: the oracle of the CLI tests that
// read real-log style runs (real_logs_cli_test.cpp, run_flags_cli_test.cpp).
struct Planar2Sample {
  double t, q[2], dq[2], ddq[2], tau[2];
};

inline Planar2Sample planar2_sample(int k, double dt) {
  Planar2 arm;
  arm.I1 = 2.0 / 12;
  arm.I2 = 1.5 * 0.64 / 12;
  Planar2Sample s{};
  const double t = k * dt;
  s.t = t;
  s.q[0] = std::sin(0.7 * t) + 0.3 * std::sin(2.1 * t);
  s.q[1] = 0.8 * std::cos(1.3 * t);
  s.dq[0] = 0.7 * std::cos(0.7 * t) + 0.63 * std::cos(2.1 * t);
  s.dq[1] = -1.04 * std::sin(1.3 * t);
  s.ddq[0] = -0.49 * std::sin(0.7 * t) - 1.323 * std::sin(2.1 * t);
  s.ddq[1] = -1.352 * std::cos(1.3 * t);
  const Eigen::Vector2d tau =
      arm.torque({s.q[0], s.q[1]}, {s.dq[0], s.dq[1]}, {s.ddq[0], s.ddq[1]});
  s.tau[0] = tau[0];
  s.tau[1] = tau[1];
  return s;
}

}  // namespace dynid::testing
