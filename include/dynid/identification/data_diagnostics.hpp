#pragma once

// What the data show about the motion, computed once by identify() and said by its warnings and
// by the physical fit's advice (issue 26 item 5): joints that move together.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid {

/// |correlation| of two joints' velocities above which they move in lockstep: the motion one
/// makes on its own is then below 1 − 0.99² ≈ 2 % of its variance, too little to tell apart the
/// parameters that only that motion separates.
inline constexpr double kLockstepCorrelation = 0.99;

/// Two joints whose velocities are (anti-)proportional over every run.
struct LockstepJoints {
  int first = 0;             ///< joint index, first < second
  int second = 0;            ///< joint index
  double correlation = 0.0;  ///< Pearson correlation of their velocities; of smallest |r| over runs
  /// Base parameters this leaves undetermined: the not excited ones of the two joints, else those
  /// of the two joints whose estimate has a relative std above 100 % (identify() fills it).
  std::vector<std::string> undetermined;
};

/// The pairs of joints whose velocities have |Pearson correlation| > threshold in every run
/// (velocities: per run, samples × n [rad/s or m/s], all with the same n). A joint that does not
/// move in a run (zero variance there) pairs with none. Pairs in joint order. Throws
/// dynid::Error for runs with different joint counts.
std::vector<LockstepJoints> find_lockstep_joints(const std::vector<Eigen::MatrixXd>& velocities,
                                                 double threshold = kLockstepCorrelation);

/// One clause naming the pair and what it leaves undetermined, e.g. "shoulder and elbow move in
/// lockstep (velocity correlation 0.997), which leaves ZZ2R, Fv2 undetermined; a run that moves
/// them independently determines them".
std::string lockstep_text(const Model& model, const LockstepJoints& pair);

}  // namespace dynid
