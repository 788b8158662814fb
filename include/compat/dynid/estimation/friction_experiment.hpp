#pragma once
// Moved to dynid/experiments/friction_experiment.hpp (issue 24, docs/design.md §2); this forwarding
// header is kept for one release.
#include "dynid/experiments/friction_experiment.hpp"
