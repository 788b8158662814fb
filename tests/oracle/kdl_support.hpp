#pragma once

#include <map>
#include <string>
#include <vector>

#include <kdl/tree.hpp>

#include "dynid/model/model.hpp"

namespace dynid::testing {

/// Index of each KDL tree joint (q_nr) in dynid's joint order, matched by joint name.
inline std::vector<unsigned> kdl_indices(const KDL::Tree& tree, const Model& model) {
  std::map<std::string, unsigned> by_name;
  for (const auto& [name, element] : tree.getSegments()) {
    const KDL::Joint& joint = element.segment.getJoint();
    if (joint.getType() != KDL::Joint::None) by_name[joint.getName()] = GetTreeElementQNr(element);
  }
  std::vector<unsigned> out;
  for (const Joint& j : model.joints) out.push_back(by_name.at(j.name));
  return out;
}

}  // namespace dynid::testing
