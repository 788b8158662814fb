#pragma once
// Moved to dynid/physical/physical_parameters.hpp (issue 24, docs/design.md §2); this forwarding
// header is kept for one release.
#include "dynid/physical/physical_parameters.hpp"
