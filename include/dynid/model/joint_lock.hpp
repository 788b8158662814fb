#pragma once

// Joints the log does not have (issue 26 item 1): a robot file often has more moving joints than a
// log (a gripper, fingers, a head, a mobile base). The joints not identified are held fixed at a
// value, which is a model transformation: each becomes a fixed joint and its child link's inertia
// merges into the nearest identified ancestor (docs/methods/model.md, "Locked joints").

#include <string>
#include <vector>

#include "dynid/model/model.hpp"

namespace dynid {

/// Which moving joints a log holds, and where the others are held.
struct JointSelection {
  /// The joints identified, in the log's order (joint j of the result is joints[j-1]); empty:
  /// every joint not named in `locks`, in model order.
  std::vector<std::string> joints;
  /// Where joints not identified are held [rad or m]; a joint left out of `joints` and not named
  /// here is held at 0.
  std::vector<JointLock> locks;

  /// True when the selection changes nothing (no joints named, no locks).
  bool empty() const { return joints.empty() && locks.empty(); }
};

/// `model` with every joint not selected held fixed: a locked revolute joint at angle v becomes
/// the constant pose (R_PJ·Rot(axis, v), p_PJ), a prismatic one (R_PJ, p_PJ + v·R_PJ·axis); the
/// link it moves, and every link fixed to it, is merged into the nearest kept ancestor
/// (transform_link_params; dropped when that is the fixed base), its friction is dropped, and the
/// kept children are re-parented with the composed pose. The kept joints come in
/// `selection.joints` order, the transmission keeps their rows and columns, and
/// Model::locked_joints lists the locked joints in model order with their values. Identity:
/// rnea(lock_joints(m, s), q_kept) equals rnea(m, q_full) on the kept joints for q_full holding
/// the locked joints at their values with zero velocity and acceleration.
/// Throws dynid::Error naming the joint for an unknown or repeated name (the message lists the
/// model's joints), a joint both selected and locked, a non-finite value or one outside the joint's
/// limits, no joint left, a parent listed after its child, and a transmission that couples a locked
/// joint with a kept one.
Model lock_joints(const Model& model, const JointSelection& selection);

}  // namespace dynid
