// libFuzzer harness for the YAML model loader (parse_yaml_model: MDH tables and the `urdf:`
// wrapper). A relative `urdf:` path resolves against the URDF seed corpus, so the wrapper form
// reaches a real URDF. An accepted model must satisfy require_valid_model.

#include <cstdint>
#include <string>

#include "dynid/model/mdh_loader.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string yaml(reinterpret_cast<const char*>(data), size);
  dynid::fuzz::expect_clean([&] {
    dynid::fuzz::require_valid_model(
        dynid::parse_yaml_model(yaml, "fuzz.yaml", DYNID_FUZZ_URDF_DIR));
  });
  return 0;
}
