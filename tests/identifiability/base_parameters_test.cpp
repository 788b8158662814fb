#include <random>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/torque_regressor.hpp"
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
