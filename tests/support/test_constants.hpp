#pragma once

// Constants that several test files of one module share. Test files of a module are compiled
// together in unity batches (tests/CMakeLists.txt), so a name defined in two files' anonymous
// namespaces would collide: shared values live here, once.

#include <string>

namespace dynid {
namespace test_support {

inline constexpr double kPi = 3.14159265358979323846;

/// The repository's model files used by the model tests.
inline const std::string kModelsDir = std::string(DYNID_SOURCE_DIR) + "/tests/data/models/";

/// The shipped Staubli TX40 data set (examples/staubli-tx40/dataset, SOURCE.md there).
inline const std::string kTx40DataDir =
    std::string(DYNID_SOURCE_DIR) + "/examples/staubli-tx40/dataset";

}  // namespace test_support
}  // namespace dynid
