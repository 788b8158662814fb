#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"

namespace dynid::detail {

// I_P += R·I·Rᵀ + 2(p·u)·1 − (u·pᵀ + p·uᵀ), h_P += R·h + m·p, m_P += m with u = R·h + m·p/2:
// a subtree's inertia about origin j moved to the parent's origin and axes. R·I·Rᵀ is taken as
// I_zz·1 + Σ (v_k·r_kᵀ + r_k·v_kᵀ) over the columns r_0, r_1 of R (docs/methods/dynamics.md,
// "Mass matrix"): 53 products for the six distinct entries of I_P instead of 57, and shorter
// dependency chains than R·I followed by (R·I)·Rᵀ.
inline void add_to_parent(const Eigen::Matrix3d& R, const Eigen::Vector3d& p, const BodyInertia& c,
                          BodyInertia& cp) {
  const Eigen::Vector3d hR = R * c.h;
  const Eigen::Vector3d u = hR + 0.5 * c.m * p;
  const double izz = c.I(2, 2);
  const Eigen::Vector3d v0 =
      (0.5 * (c.I(0, 0) - izz)) * R.col(0) + c.I(0, 1) * R.col(1) + c.I(0, 2) * R.col(2);
  const Eigen::Vector3d v1 = (0.5 * (c.I(1, 1) - izz)) * R.col(1) + c.I(1, 2) * R.col(2);
  const double d = izz + 2.0 * p.dot(u);
  for (int r = 0; r < 3; ++r) {
    for (int k = r; k < 3; ++k) {
      const double v = v0[r] * R(k, 0) + R(r, 0) * v0[k] + v1[r] * R(k, 1) + R(r, 1) * v1[k] -
                       (u[r] * p[k] + p[r] * u[k]);
      cp.I(r, k) += r == k ? v + d : v;
      if (r != k) cp.I(k, r) = cp.I(r, k);
    }
  }
  cp.h += hR + c.m * p;
  cp.m += c.m;
}

}  // namespace dynid::detail
