#pragma once

// Shared by the libFuzzer harnesses (fuzz/README.md): the rule "dynid::Error is a clean
// rejection, anything else is a bug" and a scratch file for readers that only take a path.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/model/model.hpp"

namespace dynid::fuzz {

/// Runs `body`; a dynid::Error (the documented rejection of bad input) returns normally, any other
/// exception is reported and aborts, so that libFuzzer records the input as a crash.
template <class Body>
void expect_clean(Body&& body) {
  try {
    body();
  } catch (const dynid::Error&) {
    // Clean rejection.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: exception other than dynid::Error escaped: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: non-std exception escaped\n");
    std::abort();
  }
}

/// Aborts with `what` when `ok` is false (an invariant of an accepted input does not hold).
inline void require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz: invariant violated: %s\n", what);
    std::abort();
  }
}

/// Writes the input to a per-process scratch file with the given extension and returns its path
/// (readers such as read_identified_parameters take a path, not text).
inline std::string scratch_file(const uint8_t* data, size_t size, const std::string& extension) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("dynid_fuzz_" + std::to_string(::getpid()) + extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

/// Invariants every model a loader accepts must satisfy (Model::finalize's contract): at least one
/// joint, parents before children, one parameter set per joint, finite numbers, an n×n
/// transmission.
inline void require_valid_model(const Model& model) {
  const int n = model.dof();
  require(n >= 1, "an accepted model has at least one joint");
  require(static_cast<int>(model.links.size()) == n, "one link parameter set per joint");
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joints[static_cast<size_t>(j)];
    require(joint.parent >= -1 && joint.parent < j, "parents precede children");
    require(joint.R_PJ.allFinite() && joint.p_PJ.allFinite() && joint.axis.allFinite(),
            "finite joint frames");
  }
  std::set<std::string> names;
  for (const Joint& joint : model.joints) names.insert(joint.name);
  require(names.size() == model.joints.size(), "unique joint names");
  require(model.standard_parameters().allFinite(), "finite standard parameters");
  require(model.gravity.allFinite(), "finite gravity");
  require(model.transmission.N.rows() == n && model.transmission.N.cols() == n &&
              model.transmission.N.allFinite(),
          "finite n x n transmission");
}

}  // namespace dynid::fuzz
