#pragma once

// Where the tests find the repository, ../shared and the programs they run. Force-included into
// every test translation unit (tests/CMakeLists.txt), so the macros keep the names the tests have
// always used. The paths are compiled into one object (test_paths.cpp) instead of every test
// file's command line: a test object then does not depend on where the tree is checked out, and
// ccache reuses it across checkouts (CI's fresh clone, worktrees).

namespace dynid {
namespace test_paths {
extern const char* const kSourceDir;             // the repository's top folder
extern const char* const kSharedDir;             // ../shared beside it (data sets, regressions)
extern const char* const kBinary;                // the built dynid tool
extern const char* const kOnlinePayloadExample;  // build/examples/online_payload
}  // namespace test_paths
}  // namespace dynid

#define DYNID_SOURCE_DIR (::dynid::test_paths::kSourceDir)
#define DYNID_SHARED_DIR (::dynid::test_paths::kSharedDir)
#define DYNID_BINARY (::dynid::test_paths::kBinary)
#define DYNID_ONLINE_PAYLOAD_EXAMPLE (::dynid::test_paths::kOnlinePayloadExample)
