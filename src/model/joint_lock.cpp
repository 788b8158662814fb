#include "dynid/model/joint_lock.hpp"

#include <cmath>
#include <unordered_map>

#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

namespace dynid {
namespace {

struct Pose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Pose operator*(const Pose& b) const { return {R * b.R, p + R * b.p}; }
};

/// Pose of frame j in its parent's frame with the joint at position v (Joint's convention).
Pose joint_pose(const Joint& j, double v) {
  if (j.type == JointType::kPrismatic) return {j.R_PJ, j.p_PJ + j.R_PJ * (v * j.axis)};
  return {j.R_PJ * Eigen::AngleAxisd(v, j.axis).toRotationMatrix(), j.p_PJ};
}

std::string joint_list(const Model& model) {
  std::string s;
  for (const Joint& j : model.joints) s += (s.empty() ? "" : ", ") + j.name;
  return s;
}

}  // namespace

Model lock_joints(const Model& model, const JointSelection& selection) {
  if (selection.empty()) return model;
  const int n = model.dof();
  std::unordered_map<std::string, int> index;
  for (int j = 0; j < n; ++j) index.emplace(model.joints[j].name, j);
  auto find = [&](const std::string& name, const char* what) {
    const auto it = index.find(name);
    if (it == index.end()) {
      throw Error(std::string(what) + " '" + printable(name) +
                  "' is not a moving joint of robot '" + model.name + "'; its moving joints are " +
                  joint_list(model));
    }
    return it->second;
  };
  std::vector<int> kept;  // old indices in the new order
  std::vector<int> new_index(static_cast<size_t>(n), -1);
  for (const std::string& name : selection.joints) {
    const int j = find(name, "joint");
    if (new_index[j] >= 0)
      throw Error("joint '" + name + "' is listed twice in the joints identified; list it once");
    new_index[j] = static_cast<int>(kept.size());
    kept.push_back(j);
  }
  std::vector<double> value(static_cast<size_t>(n), 0.0);
  std::vector<bool> lock_given(static_cast<size_t>(n), false);
  for (const JointLock& lock : selection.locks) {
    const int j = find(lock.name, "locked joint");
    if (lock_given[j]) throw Error("joint '" + lock.name + "' is locked twice; give one value");
    if (new_index[j] >= 0) {
      throw Error("joint '" + lock.name +
                  "' is both identified and locked; drop it from the joints or from the locks");
    }
    const Joint& jt = model.joints[j];
    if (!std::isfinite(lock.value) || lock.value < jt.limits.lower ||
        lock.value > jt.limits.upper) {
      throw Error("joint '" + lock.name + "' is locked at " + short_number(lock.value) +
                  ", outside its limits [" + short_number(jt.limits.lower) + ", " +
                  short_number(jt.limits.upper) + "]; give a value inside them");
    }
    lock_given[j] = true;
    value[j] = lock.value;
  }
  if (selection.joints.empty()) {
    for (int j = 0; j < n; ++j) {
      if (lock_given[j]) continue;
      new_index[j] = static_cast<int>(kept.size());
      kept.push_back(j);
    }
  }
  if (kept.empty()) {
    throw Error("every moving joint of robot '" + model.name +
                "' is locked; leave at least one joint to identify");
  }
  Model out = model;
  out.joints.assign(kept.size(), Joint{});
  out.links.assign(kept.size(), LinkParams::Zero());
  // Per old joint: the kept joint its frame is fixed to (-1: the base) and its pose there.
  std::vector<int> anchor(static_cast<size_t>(n), -1);
  std::vector<Pose> in_anchor(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {  // parents precede children in the model
    const Joint& jt = model.joints[j];
    const int p = jt.parent;
    // The parent's frame, as the kept joint it is fixed to and the pose in that joint's frame.
    const int p_anchor = p < 0 ? -1 : new_index[p] >= 0 ? new_index[p] : anchor[p];
    const Pose X_p = p >= 0 && new_index[p] < 0 ? in_anchor[p] : Pose{};
    if (new_index[j] >= 0) {
      Joint k = jt;
      k.parent = p_anchor;
      k.R_PJ = X_p.R * jt.R_PJ;
      k.p_PJ = X_p.p + X_p.R * jt.p_PJ;
      if (k.parent >= new_index[j]) {
        throw Error("joint '" + jt.name + "' is listed before the joint it is carried by, '" +
                    out.joints[k.parent].name +
                    "', in the joints identified; list every joint after the joints it is mounted "
                    "on (as the log's columns would be reordered)");
      }
      out.joints[new_index[j]] = k;
      out.links[new_index[j]] += model.links[j];
      continue;
    }
    anchor[j] = p_anchor;
    in_anchor[j] = X_p * joint_pose(jt, value[j]);
    if (p_anchor >= 0) {
      out.links[p_anchor] += transform_link_params(model.links[j], in_anchor[j].R, in_anchor[j].p);
    }
    out.locked_joints.push_back({jt.name, value[j]});
  }
  // The transmission keeps the kept joints' rows and columns; a locked joint must not share a
  // motor with a kept one (its motor could not be held while the other moves).
  const Eigen::MatrixXd& N = model.transmission.N;
  const auto m = static_cast<Eigen::Index>(kept.size());
  Eigen::MatrixXd N_kept(m, m);
  Eigen::VectorXd offset(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    for (Eigen::Index c = 0; c < m; ++c) N_kept(r, c) = N(kept[r], kept[c]);
    offset(r) = model.transmission.q_offset(kept[r]);
  }
  for (int a = 0; a < n; ++a) {
    if (new_index[a] >= 0) continue;
    for (int b : kept) {
      if (N(a, b) != 0.0 || N(b, a) != 0.0) {
        throw Error("the transmission of robot '" + model.name + "' couples locked joint '" +
                    model.joints[a].name + "' with joint '" + model.joints[b].name +
                    "'; identify both or lock both");
      }
    }
  }
  out.transmission.N = N_kept;
  out.transmission.q_offset = offset;
  std::vector<std::string> already_said;  // the file's inertias were checked when it was loaded
  out.finalize(&already_said);
  return out;
}

}  // namespace dynid
