#include "dynid/identification/option_text.hpp"

#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"

namespace dynid {

namespace {

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, sep)) out.push_back(item);
  return out;
}

}  // namespace

ParameterLayout friction_layout(const std::string& text, bool armature) {
  ParameterLayout layout;
  layout.armature = armature;
  if (text == "none") return layout;
  for (const auto& item : split(text, ',')) {
    if (item == "viscous") {
      layout.viscous = true;
    } else if (item == "coulomb") {
      layout.coulomb = true;
    } else if (item == "offset") {
      layout.offset = true;
    } else if (item == "asymmetric") {
      layout.viscous = layout.coulomb = layout.asymmetric = true;
    } else {
      throw UsageError("--friction: unknown term '" + item +
                       "'; use a comma list of viscous, coulomb, offset, asymmetric, or none");
    }
  }
  return layout;
}

void apply_filter_text(const std::string& text, SignalOptions& s) {
  const auto parts = split(text, ':');
  const std::string kind = parts.empty() ? "" : parts[0];
  try {
    if (kind == "auto") return;
    if (kind == "none") {
      s.filter = false;
    } else if (kind == "butterworth" || kind == "chebyshev") {
      s.family = kind == "butterworth" ? LowpassFamily::kButterworth : LowpassFamily::kChebyshev1;
      if (kind == "chebyshev") s.order = 8;  // seed 2 §3.4
      if (parts.size() > 1) s.order = std::stoi(parts[1]);
      if (parts.size() > 2) s.ripple_db = std::stod(parts[2]);
    } else {
      throw UsageError("");
    }
  } catch (const std::exception&) {
    throw UsageError("--filter '" + text +
                     "' is not understood; use auto, none, butterworth[:ORDER] or "
                     "chebyshev[:ORDER[:RIPPLE_DB]] (the cut-off is --cutoff)");
  }
}

void apply_fir_text(const std::string& text, ProjectionOptions& projection) {
  const auto parts = split(text, ',');
  try {
    size_t a = 0, b = 0;
    if (parts.size() != 2) throw UsageError("");
    projection.m1 = std::stoi(parts[0], &a);
    projection.m2 = std::stoi(parts[1], &b);
    if (a != parts[0].size() || b != parts[1].size() || projection.m1 < 0 || projection.m2 < 0)
      throw UsageError("");
  } catch (const std::exception&) {
    throw UsageError("--fir '" + text +
                     "' is not M1,M2 (two integers >= 0: future and past reference lags)");
  }
}

}  // namespace dynid
