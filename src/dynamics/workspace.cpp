#include "dynid/dynamics/workspace.hpp"

#include <algorithm>

namespace dynid {

Workspace::Workspace(const Model& model)
    : links(model.dof()),
      ancestors(model.dof()),
      twists(model.dof()),
      composite(model.dof()),
      subtree_end(model.dof()),
      forces(model.dof(), 6),
      scratch_nn(model.dof(), model.dof()),
      scratch_n(model.dof()),
      scratch_n2(model.dof()),
      articulated(model.dof()),
      derivative(model.dof()) {
  for (int j = 0; j < model.dof(); ++j) {
    for (int i = j; i >= 0; i = model.joints[i].parent) ancestors[j].push_back(i);
    twists[j].resize(ancestors[j].size());
    depth_sum += static_cast<int>(ancestors[j].size());
  }
  std::vector<int> size(model.dof(), 1);
  for (int j = model.dof() - 1; j >= 0; --j) {
    subtree_end[j] = std::max(subtree_end[j], j + 1);
    const int p = model.joints[j].parent;
    if (p >= 0) {
      subtree_end[p] = std::max(subtree_end[p], subtree_end[j]);
      size[p] += size[j];
    }
  }
  for (int j = 0; j < model.dof(); ++j) depth_first &= subtree_end[j] - j == size[j];
}

}  // namespace dynid
