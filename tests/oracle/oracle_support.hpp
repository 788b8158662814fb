#pragma once

#include <string>

#include "dynid/model/model.hpp"

namespace dynid::testing {

/// Relative agreement required against another implementation (issue 3: 1e-9 relative).
inline constexpr double kOracleTolerance = 1e-9;

}  // namespace dynid::testing
