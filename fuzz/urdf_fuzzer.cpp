// libFuzzer harness for the URDF loader (parse_urdf: urdfdom's parser, then dynid's tree building,
// fixed-joint merging and Model::finalize). An accepted model must satisfy require_valid_model.

#include <cstdint>
#include <string>

#include "dynid/model/urdf_loader.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string xml(reinterpret_cast<const char*>(data), size);
  dynid::fuzz::expect_clean(
      [&] { dynid::fuzz::require_valid_model(dynid::parse_urdf(xml, "fuzz.urdf")); });
  return 0;
}
