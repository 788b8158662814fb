// The articulated-body algorithm against the CRBA + LᵀDL forward dynamics (a different algorithm
// on the same model) and against the inverse dynamics it must invert (RNEA) on chains, branching
// trees, forests with prismatic roots, with the joint terms (armature, friction) on and off. The
// closed form of a planar 2R arm is in dynamics_test.cpp
// (Planar2.RneaAndArticulatedBodyMatchClosedForm).
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "dynid/dynamics/articulated_body.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;
using testing::rel_diff;

// ABA against CRBA + LᵀDL and against RNEA at random states of `model`, for every combination of
// the gravity and joint-term options.
void expect_aba_matches(const Model& model, unsigned seed, const std::string& what) {
  const int n = model.dof();
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 8; ++k) {
    const RneaOptions options{k % 2 == 0, k % 4 < 2};
    const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng, 2.0),
                          tau = random_vector(n, rng, 20.0);
    Eigen::VectorXd ddq_aba(n), ddq_crba(n), tau_back(n);
    articulated_body_forward_dynamics(model, ws, q, dq, tau, ddq_aba, options);
    crba_forward_dynamics(model, ws, q, dq, tau, ddq_crba, options);
    // Both solve with M: the difference carries cond(M)·ε (M is well conditioned here, ≤ 1e3).
    EXPECT_LT(rel_diff(ddq_aba, ddq_crba), 1e-12) << what << ", state " << k;
    // RNEA is the oracle ABA must invert. Ia always belongs to the inertia (as mass_matrix), while
    // RneaOptions::joint_terms = false leaves Ia·q̈ out of the RNEA: add it back for that case.
    rnea(model, ws, q, dq, ddq_aba, tau_back, options);
    if (!options.joint_terms) {
      for (int j = 0; j < n; ++j) tau_back[j] += model.joints[j].friction.Ia * ddq_aba[j];
    }
    EXPECT_LT(rel_diff(tau_back, tau), 1e-12) << what << ", state " << k;
  }
}

TEST(ArticulatedBody, ChainsMatchCrbaAndInvertRnea) {
  for (int n : {1, 2, 6, 7, 12, 30}) {
    expect_aba_matches(random_tree(n, 100 + n, true, true), 200 + n, "chain " + std::to_string(n));
  }
}

TEST(ArticulatedBody, TreesAndPrismaticRootsMatchCrbaAndInvertRnea) {
  // Seeds 1 and 5 give forests whose prismatic root has a child, seed 4 four roots
  // (MassMatrix.DepthFirstAndOtherJointOrdersAgree); 2 and 3 single-root trees.
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    const Model model = random_tree(8, seed, true);
    bool prismatic_root = false;
    for (const Joint& j : model.joints) {
      prismatic_root |= j.parent < 0 && j.type == JointType::kPrismatic;
    }
    if (seed == 1 || seed == 5) {
      ASSERT_TRUE(prismatic_root) << "seed " << seed;
    }
    expect_aba_matches(model, seed, "tree seed " + std::to_string(seed));
  }
  // A chain on a prismatic root, the first joint of a gantry.
  Model gantry = random_tree(5, 41, true, true);
  gantry.joints[0].type = JointType::kPrismatic;
  gantry.finalize();
  expect_aba_matches(gantry, 41, "prismatic root chain");
}

TEST(ForwardDynamics, TakesTheArticulatedBodyAlgorithmForLongChainsOnly) {
  const auto chain = [](int n) { return random_tree(n, 7, false, true); };
  EXPECT_FALSE(prefers_articulated_body(Workspace(chain(kArticulatedBodyMinChain - 1))));
  EXPECT_TRUE(prefers_articulated_body(Workspace(chain(kArticulatedBodyMinChain))));
  // A star of many joints on one root is shallow: CRBA + LᵀDL stays cheaper.
  Model star = random_tree(3 * kArticulatedBodyMinChain, 8, false, true);
  for (int j = 1; j < star.dof(); ++j) star.joints[j].parent = 0;
  star.finalize();
  EXPECT_FALSE(prefers_articulated_body(Workspace(star)));
  // Either way forward_dynamics returns the one result.
  const Model model = chain(kArticulatedBodyMinChain + 3);
  Workspace ws(model);
  std::mt19937 rng(3);
  const int n = model.dof();
  const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng),
                        tau = random_vector(n, rng, 10.0);
  Eigen::VectorXd ddq(n), ddq_crba(n);
  forward_dynamics(model, ws, q, dq, tau, ddq);
  crba_forward_dynamics(model, ws, q, dq, tau, ddq_crba);
  EXPECT_LT(rel_diff(ddq, ddq_crba), 1e-12);
}

}  // namespace
}  // namespace dynid
