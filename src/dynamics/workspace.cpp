#include "dynid/dynamics/workspace.hpp"

namespace dynid {

Workspace::Workspace(const Model& model)
    : links(model.dof()),
      ancestors(model.dof()),
      twists(model.dof()),
      composite(model.dof()),
      scratch_nn(model.dof(), model.dof()),
      scratch_n(model.dof()),
      scratch_n2(model.dof()) {
  for (int j = 0; j < model.dof(); ++j) {
    for (int i = j; i >= 0; i = model.joints[i].parent) ancestors[j].push_back(i);
    twists[j].resize(ancestors[j].size());
  }
}

}  // namespace dynid
