#pragma once
// Moved to dynid/identification/pipeline.hpp (issue 24, docs/design.md §2); this forwarding header
// is kept for one release.
#include "dynid/identification/pipeline.hpp"
