#include "dynid/estimation/estimate.hpp"

#include <sstream>

namespace dynid {

const char* to_string(EstimatorKind kind) {
  switch (kind) {
    case EstimatorKind::kOrdinaryLeastSquares:
      return "ordinary_least_squares";
    case EstimatorKind::kWeightedLeastSquares:
      return "weighted_least_squares";
    case EstimatorKind::kRecursiveLeastSquares:
      return "recursive_least_squares";
    case EstimatorKind::kMaximumLikelihood:
      return "maximum_likelihood";
  }
  return "unknown";
}

std::string Summary::brief_report() const {
  std::ostringstream out;
  out << to_string(estimator) << ": " << rows << " rows, " << columns << " parameters, rank "
      << rank << ", condition number " << condition_number << ", " << passes << " pass"
      << (passes == 1 ? "" : "es");
  for (const std::string& w : warnings) out << "; warning: " << w;
  return out.str();
}

}  // namespace dynid
