// RNEA against Orocos KDL's TreeIdSolver_RNE / ChainIdSolver_RNE on the same URDF text.
#include <map>
#include <random>

#include <gtest/gtest.h>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/urdf_writer.hpp"
#include "dynid/model/robots.hpp"
#include "oracle/kdl_support.hpp"
#include "oracle/oracle_support.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::kdl_indices;
using testing::random_tree;
using testing::random_vector;

class KdlTreeOracle : public ::testing::TestWithParam<unsigned> {};

TEST_P(KdlTreeOracle, RneaMatchesTreeIdSolver) {
  const unsigned seed = GetParam();
  Model model = random_tree(8, seed, true, false);
  for (auto& j : model.joints) j.friction = {};  // KDL has no joint friction or armature
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromString(to_urdf(model), tree));
  ASSERT_EQ(tree.getNrOfJoints(), 8u);
  const std::vector<unsigned> idx = kdl_indices(tree, model);
  KDL::TreeIdSolver_RNE solver(
      tree, KDL::Vector(model.gravity.x(), model.gravity.y(), model.gravity.z()));
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(8, rng, 3.0), dq = random_vector(8, rng, 2.0),
                          ddq = random_vector(8, rng, 5.0);
    KDL::JntArray kq(8), kdq(8), kddq(8), ktau(8);
    for (int j = 0; j < 8; ++j) {
      kq(idx[j]) = q[j];
      kdq(idx[j]) = dq[j];
      kddq(idx[j]) = ddq[j];
    }
    ASSERT_GE(solver.CartToJnt(kq, kdq, kddq, KDL::WrenchMap(), ktau), 0);
    Eigen::VectorXd tau(8), tau_kdl(8);
    rnea(model, ws, q, dq, ddq, tau);
    for (int j = 0; j < 8; ++j) tau_kdl[j] = ktau(idx[j]);
    EXPECT_LT((tau - tau_kdl).norm() / tau_kdl.norm(), testing::kOracleTolerance) << "state " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(RandomTrees, KdlTreeOracle, ::testing::Values(1u, 2u, 3u, 4u));

// RNEA (rigid body) against ChainIdSolver_RNE on 20 random states.
void expect_chain_matches(const Model& model, const KDL::Chain& chain, unsigned seed) {
  const int n = model.dof();
  ASSERT_EQ(chain.getNrOfJoints(), static_cast<unsigned>(n));
  KDL::ChainIdSolver_RNE solver(
      chain, KDL::Vector(model.gravity.x(), model.gravity.y(), model.gravity.z()));
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng, 2.0),
                          ddq = random_vector(n, rng, 5.0);
    KDL::JntArray kq(n), kdq(n), kddq(n), ktau(n);
    kq.data = q;
    kdq.data = dq;
    kddq.data = ddq;
    KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(solver.CartToJnt(kq, kdq, kddq, f_ext, ktau), 0);
    Eigen::VectorXd tau(n);
    rnea(model, ws, q, dq, ddq, tau, RneaOptions{true, false});
    EXPECT_LT((tau - ktau.data).norm() / ktau.data.norm(), testing::kOracleTolerance)
        << "state " << k;
  }
}

TEST(KdlChainOracle, RneaMatchesChainIdSolver) {
  Model model = random_tree(7, 77, true, true);
  for (auto& j : model.joints) j.friction = {};
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromString(to_urdf(model), tree));
  KDL::Chain chain;
  ASSERT_TRUE(tree.getChain("base_link", model.joints.back().link_name, chain));
  expect_chain_matches(model, chain, 77);
}

// Mass matrix against ChainDynParam::JntToMass and forward dynamics against ChainFdSolver_RNE
// (KDL's CRBA + RNE + dense solve) on a random chain with prismatic joints and on iiwa14.
void expect_mass_and_forward_dynamics_match(const Model& model, const KDL::Chain& chain,
                                            unsigned seed) {
  const int n = model.dof();
  ASSERT_EQ(chain.getNrOfJoints(), static_cast<unsigned>(n));
  const KDL::Vector g(model.gravity.x(), model.gravity.y(), model.gravity.z());
  KDL::ChainDynParam dyn(chain, g);
  KDL::ChainFdSolver_RNE fd(chain, g);
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng, 2.0),
                          tau = random_vector(n, rng, 20.0);
    KDL::JntArray kq(n), kdq(n), ktau(n), kddq(n);
    kq.data = q;
    kdq.data = dq;
    ktau.data = tau;
    KDL::JntSpaceInertiaMatrix H(n);
    ASSERT_GE(dyn.JntToMass(kq, H), 0);
    Eigen::MatrixXd M(n, n);
    mass_matrix(model, ws, q, M);
    EXPECT_LT((M - H.data).norm() / H.data.norm(), testing::kOracleTolerance) << "state " << k;
    KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(fd.CartToJnt(kq, kdq, ktau, f_ext, kddq), 0);
    Eigen::VectorXd ddq(n);
    forward_dynamics(model, ws, q, dq, tau, ddq, RneaOptions{true, false});
    // Both sides solve with M, so the comparison carries cond(M) (≈ 1e3–1e4 here).
    EXPECT_LT((ddq - kddq.data).norm() / kddq.data.norm(), 1e3 * testing::kOracleTolerance)
        << "state " << k;
  }
}

TEST(KdlChainOracle, MassMatrixAndForwardDynamicsMatchChainDynParamAndFdSolver) {
  Model model = random_tree(7, 78, true, true);
  for (auto& j : model.joints) j.friction = {};
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromString(to_urdf(model), tree));
  KDL::Chain chain;
  ASSERT_TRUE(tree.getChain("base_link", model.joints.back().link_name, chain));
  expect_mass_and_forward_dynamics_match(model, chain, 78);
  Model iiwa = load_robot("iiwa14");
  for (auto& j : iiwa.joints) j.friction = {};  // KDL has no armature
  KDL::Tree iiwa_tree;
  ASSERT_TRUE(kdl_parser::treeFromFile(builtin_robots_dir() + "/iiwa14.urdf", iiwa_tree));
  KDL::Chain iiwa_chain;
  ASSERT_TRUE(iiwa_tree.getChain(iiwa_tree.getRootSegment()->first, iiwa.joints.back().link_name,
                                 iiwa_chain));
  expect_mass_and_forward_dynamics_match(iiwa, iiwa_chain, 14);
}

// The iiwa14 URDF file itself (Drake's parameters) read by kdl_parser and by dynid's loader.
TEST(KdlChainOracle, Iiwa14UrdfFileMatchesChainIdSolver) {
  const Model model = load_robot("iiwa14");
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromFile(builtin_robots_dir() + "/iiwa14.urdf", tree));
  KDL::Chain chain;
  ASSERT_TRUE(tree.getChain(tree.getRootSegment()->first, model.joints.back().link_name, chain));
  expect_chain_matches(model, chain, 14);
}

}  // namespace
}  // namespace dynid
