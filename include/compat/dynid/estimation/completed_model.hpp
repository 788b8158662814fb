#pragma once
// Moved to dynid/physical/completed_model.hpp (issue 24, docs/design.md §2); this forwarding header
// is kept for one release.
#include "dynid/physical/completed_model.hpp"
