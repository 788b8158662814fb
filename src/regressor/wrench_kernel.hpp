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
  // Written out entry by entry: Eigen's 3×3 and 3×3·3×6 products of the skew and dot matrices
  // cost ≈ 70 ns per link, more than all the rest of a link's regressor columns.
  const double x = w.x(), y = w.y(), z = w.z();
  const double xx = x * x, yy = y * y, zz = z * z, xy = x * y, xz = x * z, yz = y * z;
  // K_mc = [dω×] + [ω×]² with [ω×]² = ωωᵀ − |ω|²·1.
  b.K_mc << -yy - zz, xy - dw.z(), xz + dw.y(),  //
      xy + dw.z(), -xx - zz, yz - dw.x(),        //
      xz - dw.y(), yz + dw.x(), -xx - yy;
  // L_I = [·dω] + [ω×][·ω].
  b.L_I << dw.x(), dw.y() - xz, dw.z() + xy, -yz, yy - zz, yz,  //
      xz, dw.x() + yz, zz - xx, dw.y(), dw.z() - xy, -xz,       //
      -xy, xx - yy, dw.x() - yz, xy, dw.y() + xz, dw.z();
  b.A_skew << 0.0, a.z(), -a.y(),  //
      -a.z(), 0.0, a.x(),          //
      a.y(), -a.x(), 0.0;
  b.a = a;
}

}  // namespace dynid::detail
