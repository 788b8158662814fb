#pragma once

#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/signal/integration.hpp"

namespace dynid::detail {

/// Adds one step's friction work of one joint to its per-joint columns (layout order, the
/// armature column skipped: its energy is in h), from the step's velocity integrals (seed 1
/// eqs. 15–17): Fv += ∫v², Fc += ∫|v|, Fo += ∫v; asymmetric (seed 2 eq. 2) Fvp += ∫v²[v>0],
/// Fvn += ∫v²[v<0], Fcp += ∫v[v>0], Fcn += −∫v[v<0]. `out[0]` is the joint's first column.
template <typename Out>
inline void add_friction_work(const ParameterLayout& layout, const StepVelocityIntegrals& s,
                              Out&& out) {
  int c = layout.armature ? 1 : 0;
  if (layout.asymmetric) {
    if (layout.viscous) {
      out[c++] += s.positive_square;
      out[c++] += s.negative_square;
    }
    if (layout.coulomb) {
      out[c++] += s.positive;
      out[c++] -= s.negative;
    }
  } else {
    if (layout.viscous) out[c++] += s.positive_square + s.negative_square;
    if (layout.coulomb) out[c++] += s.positive - s.negative;
  }
  if (layout.offset) out[c++] += s.positive + s.negative;
}

}  // namespace dynid::detail
