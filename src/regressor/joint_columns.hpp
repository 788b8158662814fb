#pragma once

#include <Eigen/Core>

#include "dynamics/joint_terms.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid::detail {

/// Writes the per-joint columns of one joint's torque row (layout order) into `out`, starting at
/// `out[0]`: Ia → ddq, Fv → dq, Fc → sign(dq), Fo → 1; asymmetric (seed 2 eq. 2): Fvp → dq·[dq>0],
/// Fvn → dq·[dq<0], Fcp → [dq>0], Fcn → −[dq<0].
template <typename Out>
inline void joint_columns(const ParameterLayout& layout, double dq, double ddq, Out&& out) {
  int c = 0;
  if (layout.armature) out[c++] = ddq;
  if (layout.asymmetric) {
    const double pos = dq > 0.0 ? 1.0 : 0.0;
    const double neg = dq < 0.0 ? 1.0 : 0.0;
    if (layout.viscous) {
      out[c++] = pos * dq;
      out[c++] = neg * dq;
    }
    if (layout.coulomb) {
      out[c++] = pos;
      out[c++] = -neg;
    }
  } else {
    if (layout.viscous) out[c++] = dq;
    if (layout.coulomb) out[c++] = sign(dq);
  }
  if (layout.offset) out[c++] = 1.0;
}

}  // namespace dynid::detail
