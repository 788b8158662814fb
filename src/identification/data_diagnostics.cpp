#include "dynid/identification/data_diagnostics.hpp"

#include <cmath>
#include <sstream>

#include "dynid/common/error.hpp"

namespace dynid {

std::vector<LockstepJoints> find_lockstep_joints(const std::vector<Eigen::MatrixXd>& velocities,
                                                 double threshold) {
  std::vector<LockstepJoints> out;
  if (velocities.empty()) return out;
  const Eigen::Index n = velocities.front().cols();
  // Per run the correlation matrix of the centred velocities; a pair counts when every run has it.
  Eigen::MatrixXd weakest = Eigen::MatrixXd::Constant(n, n, INFINITY);
  Eigen::MatrixXd signed_weakest = Eigen::MatrixXd::Zero(n, n);
  for (const Eigen::MatrixXd& v : velocities) {
    if (v.cols() != n)
      throw Error("find_lockstep_joints: runs with " + std::to_string(n) + " and " +
                  std::to_string(v.cols()) + " joints; give runs of one robot");
    if (v.rows() < 2) return {};
    const Eigen::MatrixXd c = v.rowwise() - v.colwise().mean();
    const Eigen::MatrixXd cov = c.transpose() * c;
    for (Eigen::Index a = 0; a < n; ++a) {
      for (Eigen::Index b = a + 1; b < n; ++b) {
        const double d = std::sqrt(cov(a, a) * cov(b, b));
        const double r = d > 0.0 ? cov(a, b) / d : 0.0;
        if (std::abs(r) < weakest(a, b)) {
          weakest(a, b) = std::abs(r);
          signed_weakest(a, b) = r;
        }
      }
    }
  }
  for (Eigen::Index a = 0; a < n; ++a) {
    for (Eigen::Index b = a + 1; b < n; ++b) {
      if (weakest(a, b) > threshold)
        out.push_back({static_cast<int>(a), static_cast<int>(b), signed_weakest(a, b), {}});
    }
  }
  return out;
}

std::string lockstep_text(const Model& model, const LockstepJoints& pair) {
  std::ostringstream s;
  s.precision(4);
  s << model.joints[static_cast<size_t>(pair.first)].name << " and "
    << model.joints[static_cast<size_t>(pair.second)].name
    << " move in lockstep (velocity correlation " << pair.correlation << ")";
  if (pair.undetermined.empty()) {
    s << "; no parameter of theirs is left undetermined here, but each is told apart only by the "
         "little motion they do not share: a run that moves them independently determines them "
         "better";
    return s.str();
  }
  s << ", which leaves ";
  for (size_t i = 0; i < pair.undetermined.size(); ++i)
    s << (i == 0 ? "" : ", ") << pair.undetermined[i];
  s << " undetermined; a run that moves them independently determines them";
  return s.str();
}

}  // namespace dynid
