#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "dynid/common/error.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/urdf_loader.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "support/chain_urdf.hpp"
#include "support/error_of.hpp"
#include "support/planar2.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// The planar 2R arm in a vertical plane has the six textbook base parameters (Khalil & Dombre,
// "Modeling, Identification and Control of Robots", §12.6, example of the 2R planar arm):
// ZZ1R = ZZ1 + l1²·M2, MX1R = MX1 + l1·M2, MY1, ZZ2, MX2, MY2.
TEST(BaseParameters, Planar2HasTextbookBaseSet) {
  testing::Planar2 arm;
  arm.l1 = 0.7;
  const Model model = arm.model();
  const BaseParameters bp = compute_base_parameters(model);
  ASSERT_EQ(bp.rank, 6);
  EXPECT_EQ(bp.names, (std::vector<std::string>{"ZZ1R", "MX1R", "MY1", "ZZ2", "MX2", "MY2"}));
  EXPECT_EQ(bp.expressions[0], "ZZ1R = ZZ1 + 0.49*M2");
  EXPECT_EQ(bp.expressions[1], "MX1R = MX1 + 0.7*M2");
  EXPECT_EQ(bp.expressions[2], "MY1 = MY1");
  // Everything else of a planar arm has no effect at all (seed 2 eq. 6).
  EXPECT_EQ(sorted(bp.unidentifiable_names()),
            sorted({"XX1", "XY1", "XZ1", "YY1", "YZ1", "MZ1", "M1", "XX2", "XY2", "XZ2", "YY2",
                    "YZ2", "MZ2"}));
}

TEST(BaseParameters, WithoutGravityTheFirstMomentsOfLinkOneVanish) {
  Model model = testing::Planar2().model();
  model.gravity.setZero();
  const BaseParameters bp = compute_base_parameters(model);
  EXPECT_EQ(bp.names, (std::vector<std::string>{"ZZ1R", "ZZ2", "MX2", "MY2"}));
}

// W·theta = W_b·theta_b on states the base computation never saw.
TEST(BaseParameters, BaseModelReproducesFullModelOnFreshStates) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Model model = random_tree(6, seed, true, seed == 1);
    BaseParameterOptions options;
    options.layout = ParameterLayout::full();
    const BaseParameters bp = compute_base_parameters(model, options);
    const Eigen::VectorXd theta = options.layout.parameters(model);
    const Eigen::VectorXd theta_b = bp.reduce(theta);
    Workspace ws(model);
    Eigen::MatrixXd Y(6, options.layout.columns(6));
    std::mt19937 rng(seed + 1000);
    for (int k = 0; k < 10; ++k) {
      torque_regressor(model, ws, options.layout, random_vector(6, rng, 3.0),
                       random_vector(6, rng, 2.0), random_vector(6, rng, 5.0), Y);
      const Eigen::VectorXd tau = Y * theta;
      EXPECT_LT((bp.select(Y) * theta_b - tau).norm(), 1e-9 * std::max(1.0, tau.norm()));
    }
  }
}

// Seed 2 eqs. 4–8: the energy model gives the same count as the torque model.
TEST(BaseParameters, EnergyRegressorGivesTheSameBaseSet) {
  for (unsigned seed : {4u, 5u, 6u, 7u}) {
    const Model model = random_tree(6, seed, seed % 2 == 0, seed > 5);
    BaseParameterOptions options;
    options.layout.armature = true;
    const BaseParameters torque = compute_base_parameters(model, options);
    options.regressor = BaseRegressor::kEnergy;
    const BaseParameters energy = compute_base_parameters(model, options);
    EXPECT_EQ(torque.rank, energy.rank) << "seed " << seed;
    EXPECT_EQ(torque.names, energy.names) << "seed " << seed;
    EXPECT_LT((torque.K_d - energy.K_d).norm(), 1e-7 * std::max(1.0, torque.K_d.norm()));
  }
}

TEST(BaseParameters, DeterministicAcrossCalls) {
  const Model model = random_tree(7, 8, true, true);
  const BaseParameters a = compute_base_parameters(model), b = compute_base_parameters(model);
  EXPECT_EQ(a.names, b.names);
  EXPECT_EQ(a.expressions, b.expressions);
}

// Column-scaled condition number of the base columns of `bp` on fresh random states.
double scaled_condition(const Model& model, const BaseParameterOptions& options,
                        const BaseParameters& bp) {
  const int n = model.dof();
  Workspace ws(model);
  std::mt19937 rng(77);
  Eigen::MatrixXd Y(n, options.layout.columns(n)), W(200 * n, bp.rank);
  for (int k = 0; k < 200; ++k) {
    torque_regressor(model, ws, options.layout, random_vector(n, rng, 2.0),
                     random_vector(n, rng, 1.0), random_vector(n, rng, 1.0), Y);
    W.middleRows(k * n, n) = bp.select(Y);
  }
  const Eigen::VectorXd norms = W.colwise().norm().transpose();
  W = W * norms.cwiseInverse().asDiagonal();
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(W).singularValues();
  return s[0] / s[s.size() - 1];
}

// Issue 25 item 1: every joint axis of the PUMA 560 tilted by 0.1 rad off its frame's z (as in
// ../shared/regressions/arm6-closed-loop). Gautier's rule alone makes ZZ_j dependent, whose
// weight in its null vector is about the tilt squared, so ZZ_j ≈ −80·XX_j − 80·YY_j + …: base
// columns nearly dependent on any trajectory (condition number 1e8) and coefficients compounding
// to 1e10. Threshold pivoting regroups YY_j, as for an untilted axis: the rigid-body base columns
// are as well conditioned as the untilted arm's (4.4). With armature columns the link's inertia
// about its axis and the rotor's are told apart only through the tilt (condition number ~1/tilt²:
// 278 here), a property of the model, not of the base set.
TEST(BaseParameters, NearlyAlignedAxesGiveWellConditionedBaseColumns) {
  Model model = load_robot("puma560");
  for (auto& joint : model.joints) {
    joint.axis = (Eigen::AngleAxisd(0.1, Eigen::Vector3d(1.0, 2.0, 0.0).normalized()) * joint.axis)
                     .normalized();
  }
  model.finalize();
  for (const bool armature : {false, true}) {
    BaseParameterOptions options;
    options.layout = armature ? ParameterLayout::full() : ParameterLayout::rigid();
    const BaseParameters pivoted = compute_base_parameters(model, options);
    BaseParameterOptions gautier = options;
    gautier.pivot_threshold = 0.0;
    const BaseParameters plain = compute_base_parameters(model, gautier);
    EXPECT_EQ(pivoted.rank, plain.rank);
    EXPECT_GT(scaled_condition(model, options, plain), 1e6) << armature;
    EXPECT_LT(scaled_condition(model, options, pivoted), armature ? 1e3 : 10.0) << armature;
    EXPECT_GT(plain.K_d.cwiseAbs().maxCoeff(), 1e9) << armature;
    EXPECT_LT(pivoted.K_d.cwiseAbs().maxCoeff(), 200.0) << armature;
    // The base model still reproduces the full model.
    const Eigen::VectorXd theta = options.layout.parameters(model);
    const Eigen::VectorXd theta_b = pivoted.reduce(theta);
    Workspace ws(model);
    Eigen::MatrixXd Y(6, options.layout.columns(6));
    std::mt19937 rng(5);
    for (int k = 0; k < 10; ++k) {
      torque_regressor(model, ws, options.layout, random_vector(6, rng, 2.0),
                       random_vector(6, rng, 1.0), random_vector(6, rng, 1.0), Y);
      const Eigen::VectorXd tau = Y * theta;
      EXPECT_LT((pivoted.select(Y) * theta_b - tau).norm(), 1e-9 * std::max(1.0, tau.norm()));
    }
  }
  // The untilted arm, for comparison.
  const Model straight = load_robot("puma560");
  EXPECT_LT(scaled_condition(straight, {}, compute_base_parameters(straight)), 10.0);
}

// The threshold changes nothing where Gautier's rule already pivots on weights above it.
TEST(BaseParameters, ThresholdPivotingLeavesTheBuiltInRobotsAlone) {
  for (const std::string& name : builtin_robot_names()) {
    const Model model = load_robot(name);
    BaseParameterOptions options;
    options.layout = ParameterLayout::full();
    BaseParameterOptions gautier = options;
    gautier.pivot_threshold = 0.0;
    const BaseParameters a = compute_base_parameters(model, options);
    const BaseParameters b = compute_base_parameters(model, gautier);
    EXPECT_EQ(a.names, b.names) << name;
    EXPECT_EQ(a.expressions, b.expressions) << name;
  }
}

TEST(BaseParameters, NothingIdentifiableIsAnError) {
  const Eigen::MatrixXd W = Eigen::MatrixXd::Zero(10, 2);
  try {
    classify_columns(W, {"a", "b"}, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no parameter"), std::string::npos);
  }
}

}  // namespace
}  // namespace dynid

namespace dynid {
namespace {

// The PUMA 560 has 36 base inertial parameters (Khalil & Dombre, "Modeling, Identification and
// Control of Robots", 2002, §9.10 / Gautier & Khalil 1990), independent of the numerical values.
TEST(BaseParameters, Puma560HasThePublishedCount) {
  const BaseParameters bp = compute_base_parameters(load_robot("puma560"));
  EXPECT_EQ(bp.rank, 36);
  EXPECT_EQ(bp.names.front(), "ZZ1R");
}

}  // namespace
}  // namespace dynid

namespace dynid {
namespace {

using testing::random_tree;

BaseParameters with(const Model& model, BaseParameterOptions options, BaseAlgorithm algorithm) {
  options.algorithm = algorithm;
  return compute_base_parameters(model, options);
}

// Expressions without their coefficients: "ZZ1R = ZZ1 + YY2 - M3".
std::vector<std::string> terms_of(const std::vector<std::string>& expressions) {
  std::vector<std::string> out;
  for (const std::string& e : expressions) {
    std::string t;
    std::size_t i = 0;
    while (i < e.size()) {
      const std::size_t star = e.find('*', i), space = e.find(' ', i);
      if (star != std::string::npos && (space == std::string::npos || star < space)) {
        i = star + 1;  // drop "<coefficient>*"
        continue;
      }
      const std::size_t end = space == std::string::npos ? e.size() : space + 1;
      t += e.substr(i, end - i);
      i = end;
    }
    out.push_back(t);
  }
  return out;
}

// The tree algorithm and the dense left-to-right sweep (the oracle: a different algorithm on the
// whole sampled regressor, with its own sample count) classify every column alike and give the
// same regrouping coefficients.
void expect_same(const Model& model, const BaseParameterOptions& options, const std::string& what) {
  const BaseParameters dense = with(model, options, BaseAlgorithm::kDense);
  const BaseParameters tree = with(model, options, BaseAlgorithm::kTree);
  EXPECT_EQ(tree.rank, dense.rank) << what;
  EXPECT_EQ(tree.base, dense.base) << what;
  EXPECT_EQ(tree.dependent, dense.dependent) << what;
  EXPECT_EQ(tree.unidentifiable, dense.unidentifiable) << what;
  EXPECT_EQ(tree.names, dense.names) << what;
  // Same terms in every expression; printed coefficients may differ in the 6th digit (K_d of the
  // two algorithms agrees to 1e-7, checked below).
  EXPECT_EQ(terms_of(tree.expressions), terms_of(dense.expressions)) << what;
  if (tree.K_d.rows() == dense.K_d.rows() && tree.K_d.cols() == dense.K_d.cols()) {
    EXPECT_LT((tree.K_d - dense.K_d).cwiseAbs().maxCoeff(), 1e-7) << what;
  }
}

TEST(BaseParametersTree, EqualsTheDenseSweepOnEveryBuiltInRobot) {
  for (const std::string& name : builtin_robot_names()) {
    const Model model = load_robot(name);
    BaseParameterOptions options;
    expect_same(model, options, name + " rigid");
    options.layout = ParameterLayout::full();
    expect_same(model, options, name + " full");
  }
}

TEST(BaseParametersTree, EqualsTheDenseSweepOnRandomTrees) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const int n = 4 + static_cast<int>(seed % 5) * 3;  // 4 … 16 joints
    const Model model = random_tree(n, seed, seed % 2 == 0, seed % 3 == 0);
    BaseParameterOptions options;
    options.layout = seed % 4 == 0 ? ParameterLayout::full() : ParameterLayout{};
    options.layout.armature = seed % 2 == 1;
    expect_same(model, options, "random tree seed " + std::to_string(seed));
  }
}

// Special geometry: parallel and perpendicular axes, prismatic joints, zero gravity (more
// parameters vanish or regroup than for a generic tree).
TEST(BaseParametersTree, EqualsTheDenseSweepOnSpecialGeometry) {
  for (int variant = 0; variant < 4; ++variant) {
    Model model = random_tree(7, 40 + variant, variant % 2 == 1, variant < 2);
    for (int j = 0; j < model.dof(); ++j) {
      Joint& joint = model.joints[j];
      if (variant < 3) {  // all axes along z of frames related by rotations about z or x
        joint.R_PJ = Eigen::Matrix3d(Eigen::AngleAxisd((j % 3 == 1 && variant > 0) ? M_PI / 2 : 0.0,
                                                       Eigen::Vector3d::UnitX()));
        joint.axis =
            (variant == 2 && j % 2 == 0) ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
      }
    }
    if (variant == 3) model.gravity.setZero();
    model.finalize();
    expect_same(model, BaseParameterOptions{}, "variant " + std::to_string(variant));
  }
}

// Issue 10: `model --base` on 500 joints ran for minutes at 2 GB and 2000 joints ended in
// std::bad_alloc. A 1000-joint chain now loads and gets its base parameters (timing in
// bench/model/model_bench.cpp). Correctness: (1) the base model reproduces the full model's torques
// on states the computation never saw (a regressor row of the full model is the oracle); (2) the
// regrouping is local, so the count grows by exactly 7 per generic revolute link (10 parameters,
// 3 regrouped into the parent: Khalil & Dombre, "Modeling, Identification and Control of Robots",
// 2002, §9.5), compared with the dense sweep on the first 12 links. 1000 joints is the limit of
// every loader (kMaxJoints, issue 27 item 4): the largest model that can reach this computation.
TEST(BaseParametersTree, ThousandJointChainLoadsAndGetsItsBaseParameters) {
  static_assert(kMaxJoints == 1000, "the chain below is at the joint limit");
  const Model model = parse_urdf(testing::chain_urdf(1000, 11), "chain1000.urdf");
  ASSERT_EQ(model.dof(), 1000);
  const BaseParameters bp = compute_base_parameters(model);
  EXPECT_EQ(bp.algorithm, BaseAlgorithm::kTree);

  const Model prefix = parse_urdf(testing::chain_urdf(12, 11), "chain12.urdf");
  BaseParameterOptions dense_options;
  dense_options.algorithm = BaseAlgorithm::kDense;
  const BaseParameters head = compute_base_parameters(prefix, dense_options);
  EXPECT_EQ(bp.rank, head.rank + 7 * (1000 - 12));
  for (int i = 0; i < head.rank; ++i) EXPECT_EQ(bp.names[i], head.names[i]) << i;

  // Regrouping along a 1000-link chain sums far-away masses into the first links, so W_b·theta_b
  // cancels terms of size Σ|W_b||theta_b| ≈ 1e18 down to |tau| ≈ 5e7: the check is at round-off
  // of that sum (the dense sweep, where it still runs, does no better; see the 60-joint case).
  const Eigen::VectorXd theta = model.standard_parameters();
  const Eigen::VectorXd theta_b = bp.reduce(theta);
  Workspace ws(model);
  Eigen::MatrixXd Y(1000, ParameterLayout{}.columns(1000));
  std::mt19937 rng(99);
  for (int k = 0; k < 2; ++k) {
    torque_regressor(model, ws, ParameterLayout{}, random_vector(1000, rng, 2.0),
                     random_vector(1000, rng, 1.0), random_vector(1000, rng, 1.0), Y);
    const Eigen::VectorXd tau = Y * theta;
    const Eigen::MatrixXd Yb = bp.select(Y);
    const double sum = (Yb.cwiseAbs() * theta_b.cwiseAbs()).norm();
    EXPECT_LT((Yb * theta_b - tau).norm(), 1e-12 * sum);
  }
}

TEST(BaseParametersTree, EqualsTheDenseSweepOnASixtyJointChain) {
  const Model model = parse_urdf(testing::chain_urdf(60, 11), "chain60.urdf");
  expect_same(model, BaseParameterOptions{}, "chain60");
}

TEST(BaseParametersTree, TimeLimitIsAnError) {
  const Model model = random_tree(60, 5, true);
  BaseParameterOptions options;
  options.max_seconds = 1e-9;
  for (BaseAlgorithm a : {BaseAlgorithm::kTree, BaseAlgorithm::kDense}) {
    options.algorithm = a;
    const std::string msg = testing::error_of([&] { compute_base_parameters(model, options); });
    EXPECT_NE(msg.find("base parameters: time limit of 1e-09 s reached"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace dynid
