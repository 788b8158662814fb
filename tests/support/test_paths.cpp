// The one translation unit whose compile definitions name this checkout's paths
// (tests/CMakeLists.txt); test_paths.hpp says why.
#include "support/test_paths.hpp"

namespace dynid {
namespace test_paths {
// Pointers to literals: constant-initialised, so tests may use them in their own static
// initialisers whatever the order of initialisation across translation units.
extern const char* const kSourceDir = DYNID_TEST_SOURCE_DIR;
extern const char* const kSharedDir = DYNID_TEST_SHARED_DIR;
extern const char* const kBinary = DYNID_TEST_BINARY;
extern const char* const kOnlinePayloadExample = DYNID_TEST_ONLINE_PAYLOAD_EXAMPLE;
}  // namespace test_paths
}  // namespace dynid
