// RNEA against Orocos KDL's TreeIdSolver_RNE / ChainIdSolver_RNE on the same URDF text.
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/urdf_writer.hpp"
#include "dynid/model/robots.hpp"
#include "oracle/kdl_bridge.hpp"
#include "oracle/oracle_support.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;

class KdlTreeOracle : public ::testing::TestWithParam<unsigned> {};

TEST_P(KdlTreeOracle, RneaMatchesTreeIdSolver) {
  const unsigned seed = GetParam();
  Model model = random_tree(8, seed, true, false);
  for (auto& j : model.joints) j.friction = {};  // KDL has no joint friction or armature
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  kdl::Tree tree(to_urdf(model), kdl::UrdfSource::kText, names, model.gravity.data());
  ASSERT_EQ(tree.joint_count(), 8);
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(8, rng, 3.0), dq = random_vector(8, rng, 2.0),
                          ddq = random_vector(8, rng, 5.0);
    Eigen::VectorXd tau(8), tau_kdl(8);
    ASSERT_GE(tree.inverse_dynamics(q.data(), dq.data(), ddq.data(), tau_kdl.data()), 0);
    rnea(model, ws, q, dq, ddq, tau);
    EXPECT_LT((tau - tau_kdl).norm() / tau_kdl.norm(), testing::kOracleTolerance) << "state " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(RandomTrees, KdlTreeOracle, ::testing::Values(1u, 2u, 3u, 4u));

// RNEA (rigid body) against ChainIdSolver_RNE on 20 random states.
void expect_chain_matches(const Model& model, kdl::Chain& chain, unsigned seed) {
  const int n = model.dof();
  ASSERT_EQ(chain.joint_count(), n);
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng, 2.0),
                          ddq = random_vector(n, rng, 5.0);
    Eigen::VectorXd tau(n), tau_kdl(n);
    ASSERT_GE(chain.inverse_dynamics(q.data(), dq.data(), ddq.data(), tau_kdl.data()), 0);
    rnea(model, ws, q, dq, ddq, tau, RneaOptions{true, false});
    EXPECT_LT((tau - tau_kdl).norm() / tau_kdl.norm(), testing::kOracleTolerance) << "state " << k;
  }
}

TEST(KdlChainOracle, RneaMatchesChainIdSolver) {
  Model model = random_tree(7, 77, true, true);
  for (auto& j : model.joints) j.friction = {};
  kdl::Chain chain(to_urdf(model), kdl::UrdfSource::kText, "base_link",
                   model.joints.back().link_name, model.gravity.data());
  expect_chain_matches(model, chain, 77);
}

// Mass matrix against ChainDynParam::JntToMass and forward dynamics against ChainFdSolver_RNE
// (KDL's CRBA + RNE + dense solve) on a random chain with prismatic joints and on iiwa14.
void expect_mass_and_forward_dynamics_match(const Model& model, kdl::Chain& chain, unsigned seed) {
  const int n = model.dof();
  ASSERT_EQ(chain.joint_count(), n);
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng, 2.0),
                          tau = random_vector(n, rng, 20.0);
    Eigen::MatrixXd H(n, n);
    ASSERT_GE(chain.mass_matrix(q.data(), H.data()), 0);
    Eigen::MatrixXd M(n, n);
    mass_matrix(model, ws, q, M);
    EXPECT_LT((M - H).norm() / H.norm(), testing::kOracleTolerance) << "state " << k;
    Eigen::VectorXd ddq(n), ddq_kdl(n);
    ASSERT_GE(chain.forward_dynamics(q.data(), dq.data(), tau.data(), ddq_kdl.data()), 0);
    forward_dynamics(model, ws, q, dq, tau, ddq, RneaOptions{true, false});
    // Both sides solve with M, so the comparison carries cond(M) (≈ 1e3–1e4 here).
    EXPECT_LT((ddq - ddq_kdl).norm() / ddq_kdl.norm(), 1e3 * testing::kOracleTolerance)
        << "state " << k;
  }
}

TEST(KdlChainOracle, MassMatrixAndForwardDynamicsMatchChainDynParamAndFdSolver) {
  Model model = random_tree(7, 78, true, true);
  for (auto& j : model.joints) j.friction = {};
  kdl::Chain chain(to_urdf(model), kdl::UrdfSource::kText, "base_link",
                   model.joints.back().link_name, model.gravity.data());
  expect_mass_and_forward_dynamics_match(model, chain, 78);
  Model iiwa = load_robot("iiwa14");
  for (auto& j : iiwa.joints) j.friction = {};  // KDL has no armature
  kdl::Chain iiwa_chain(builtin_robots_dir() + "/iiwa14.urdf", kdl::UrdfSource::kFile, "",
                        iiwa.joints.back().link_name, iiwa.gravity.data());
  expect_mass_and_forward_dynamics_match(iiwa, iiwa_chain, 14);
}

// The iiwa14 URDF file itself (Drake's parameters) read by kdl_parser and by dynid's loader.
TEST(KdlChainOracle, Iiwa14UrdfFileMatchesChainIdSolver) {
  const Model model = load_robot("iiwa14");
  kdl::Chain chain(builtin_robots_dir() + "/iiwa14.urdf", kdl::UrdfSource::kFile, "",
                   model.joints.back().link_name, model.gravity.data());
  expect_chain_matches(model, chain, 14);
}

}  // namespace
}  // namespace dynid
