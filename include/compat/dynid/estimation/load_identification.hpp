#pragma once
// Moved to dynid/load/load_identification.hpp (issue 24, docs/design.md §2); this forwarding header
// is kept for one release.
#include "dynid/load/load_identification.hpp"
