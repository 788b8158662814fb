#pragma once

#include <cmath>

#include "dynid/model/model.hpp"

namespace dynid::detail {

/// sign(x) with sign(0) = 0, the Coulomb convention of seed 1 eq. 3 and seed 2 eq. 2.
inline double sign(double x) {
  return static_cast<double>((x > 0.0) - (x < 0.0));
}

/// Joint-side actuator and friction torque Ia·ddq + Fv·dq + Fc·sign(dq) + Fo (seed 1 eq. 3), plus
/// the asymmetry Fva·|dq| + Fca·|sign(dq)| of seed 2 eq. 2.
inline double joint_torque(const JointFriction& f, double dq, double ddq) {
  return f.Ia * ddq + f.Fv * dq + f.Fc * sign(dq) + f.Fo + f.Fva * std::abs(dq) +
         f.Fca * std::abs(sign(dq));
}

}  // namespace dynid::detail
