#pragma once

#include <Eigen/Core>

#include "dynamics/spatial.hpp"

namespace dynid::detail {

/// [·ω] of seed 1 eq. 27: I·ω = dot_matrix(ω)·[Ixx Ixy Ixz Iyy Iyz Izz]ᵀ.
inline Eigen::Matrix<double, 3, 6> dot_matrix(const Eigen::Vector3d& w) {
  Eigen::Matrix<double, 3, 6> L;
  L << w.x(), w.y(), w.z(), 0.0, 0.0, 0.0,  //
      0.0, w.x(), 0.0, w.y(), w.z(), 0.0,   //
      0.0, 0.0, w.x(), 0.0, w.y(), w.z();
  return L;
}

/// The Newton–Euler wrench of one rigid body about a body-fixed point O, linear in its inertial
/// parameters (seed 1 eqs. 22, 25, 28): f = Af·phi, n = An·phi, with phi in the link standard order
/// [XX XY XZ YY YZ ZZ MX MY MZ M]. w, dw: angular velocity/acceleration; a: acceleration of O minus
/// gravity; all in the body frame.
struct WrenchBlocks {
  Eigen::Matrix3d K_mc;             ///< f = K_mc·mc + a·m, K_mc = [dω×] + [ω×][ω×]
  Eigen::Matrix<double, 3, 6> L_I;  ///< n = L_I·I + [mc×]a…, L_I = [·dω] + [ω×][·ω]
  Eigen::Matrix3d A_skew;           ///< n contribution of mc: −[a×]
  Eigen::Vector3d a;                ///< f contribution of m
};

inline void wrench_blocks(const Eigen::Vector3d& w, const Eigen::Vector3d& dw,
                          const Eigen::Vector3d& a, WrenchBlocks& b) {
  const Eigen::Matrix3d W = skew(w);
  b.K_mc.noalias() = skew(dw) + W * W;
  b.L_I.noalias() = dot_matrix(dw) + W * dot_matrix(w);
  b.A_skew = -skew(a);
  b.a = a;
}

}  // namespace dynid::detail
