#pragma once
// Moved to dynid/closed_loop/closed_loop.hpp (issue 24, docs/design.md §2); this forwarding header
// is kept for one release.
#include "dynid/closed_loop/closed_loop.hpp"
