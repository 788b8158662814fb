// libFuzzer harness for the result-JSON reader (read_identified_parameters, used by
// `dynid validate --params`): names and values must come back paired and finite.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynid/report/identification_report.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dynid::fuzz::scratch_file(data, size, ".json");
  dynid::fuzz::expect_clean([&] {
    std::vector<std::string> names;
    Eigen::VectorXd values;
    nlohmann::json options_used;
    dynid::read_identified_parameters(path, names, values, options_used);
    dynid::fuzz::require(values.size() == static_cast<Eigen::Index>(names.size()),
                         "one value per parameter name");
    dynid::fuzz::require(values.allFinite(), "finite parameter values");
  });
  return 0;
}
