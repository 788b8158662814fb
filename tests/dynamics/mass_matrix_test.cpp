// The mass matrix's two column-carrying paths: subtrees as contiguous index ranges (joints in
// depth-first order, every URDF) and the membership walk for any other parents-first order (MDH
// trees, hand-built models). The same tree in both orders must give the same matrix, and each must
// satisfy M·q̈ + c = RNEA. Children of a root (revolute or prismatic) take the CRBA's root shortcut.
#include <algorithm>
#include <functional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;
using testing::rel_diff;

// `model` with its joints renumbered in depth-first order (children in index order); pos[j] is
// the new index of joint j.
Model depth_first_copy(const Model& model, std::vector<int>& pos) {
  const int n = model.dof();
  std::vector<std::vector<int>> children(n);
  std::vector<int> order;
  for (int j = 0; j < n; ++j) {
    if (model.joints[j].parent >= 0) children[model.joints[j].parent].push_back(j);
  }
  std::function<void(int)> visit = [&](int j) {
    order.push_back(j);
    for (int c : children[j]) visit(c);
  };
  for (int j = 0; j < n; ++j) {
    if (model.joints[j].parent < 0) visit(j);
  }
  pos.assign(n, -1);
  for (int k = 0; k < n; ++k) pos[order[k]] = k;
  Model out = model;
  for (int j = 0; j < n; ++j) {
    out.joints[pos[j]] = model.joints[j];
    out.joints[pos[j]].parent = model.joints[j].parent < 0 ? -1 : pos[model.joints[j].parent];
    out.links[pos[j]] = model.links[j];
  }
  out.finalize();
  return out;
}

TEST(MassMatrix, DepthFirstAndOtherJointOrdersAgree) {
  // Trees that are not depth-first as generated: one root (seed 2), forests with a prismatic
  // root that has a child (seeds 1, 5) and four roots (seed 4).
  for (unsigned seed : {1u, 2u, 4u, 5u}) {
    const Model scrambled = random_tree(8, seed, true);
    std::vector<int> pos;
    const Model ordered = depth_first_copy(scrambled, pos);
    Workspace ws_s(scrambled), ws_o(ordered);
    ASSERT_FALSE(ws_s.depth_first) << "seed " << seed << ": the test needs a scrambled order";
    ASSERT_TRUE(ws_o.depth_first);
    std::mt19937 rng(seed);
    for (int t = 0; t < 5; ++t) {
      const Eigen::VectorXd q = random_vector(8, rng, 3.0), dq = random_vector(8, rng),
                            ddq = random_vector(8, rng);
      Eigen::VectorXd q_o(8), dq_o(8), ddq_o(8);
      for (int j = 0; j < 8; ++j) {
        q_o[pos[j]] = q[j];
        dq_o[pos[j]] = dq[j];
        ddq_o[pos[j]] = ddq[j];
      }
      // Stale entries must not survive: both matrices start as garbage.
      Eigen::MatrixXd M_s = Eigen::MatrixXd::Constant(8, 8, 1e3), M_o = M_s;
      mass_matrix(scrambled, ws_s, q, M_s);
      mass_matrix(ordered, ws_o, q_o, M_o);
      Eigen::MatrixXd M_back(8, 8);
      for (int i = 0; i < 8; ++i) {
        for (int k = 0; k < 8; ++k) M_back(i, k) = M_o(pos[i], pos[k]);
      }
      EXPECT_LT(rel_diff(M_back, M_s), 1e-13) << "seed " << seed;
      // Each against the recursive Newton–Euler algorithm.
      Eigen::VectorXd c(8), tau(8), ddq_back(8);
      rnea(ordered, ws_o, q_o, dq_o, Eigen::VectorXd::Zero(8), c);
      rnea(ordered, ws_o, q_o, dq_o, ddq_o, tau);
      EXPECT_LT(rel_diff(M_o * ddq_o + c, tau), 1e-12) << "seed " << seed;
      forward_dynamics(ordered, ws_o, q_o, dq_o, tau, ddq_back);
      EXPECT_LT(rel_diff(ddq_back, ddq_o), 1e-10) << "seed " << seed;
      rnea(scrambled, ws_s, q, dq, Eigen::VectorXd::Zero(8), c);
      rnea(scrambled, ws_s, q, dq, ddq, tau);
      EXPECT_LT(rel_diff(M_s * ddq + c, tau), 1e-12) << "seed " << seed;
    }
  }
}

}  // namespace
}  // namespace dynid
