#pragma once
// Split and moved (issue 24, docs/design.md §2): the run record to dynid/identification/record.hpp,
// identify() to dynid/identification/identify.hpp, validate_torques() to
// dynid/identification/validation.hpp and identified_model() to
// dynid/physical/identified_model.hpp. This forwarding header is kept for one release.
#include "dynid/identification/identify.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/physical/identified_model.hpp"
