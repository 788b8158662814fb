// rnea_derivatives against central differences of rnea (an independent evaluation: the RNEA in
// link frames, differentiated numerically) and against the CRBA mass matrix, on chains, branching
// trees and forests with prismatic roots, with and without gravity and joint terms.
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/rnea_derivatives.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;
using testing::rel_diff;

// Central differences of rnea with respect to variable `which` (0: q, 1: q̇, 2: q̈), step h.
Eigen::MatrixXd rnea_central_difference(const Model& model, Workspace& ws,
                                        const Eigen::VectorXd (&x)[3], int which, double h,
                                        const RneaOptions& options) {
  const int n = model.dof();
  Eigen::MatrixXd out(n, n);
  Eigen::VectorXd plus(n), minus(n);
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
    xp[which][k] += h;
    xm[which][k] -= h;
    rnea(model, ws, xp[0], xp[1], xp[2], plus, options);
    rnea(model, ws, xm[0], xm[1], xm[2], minus, options);
    out.col(k) = (plus - minus) / (2.0 * h);
  }
  return out;
}

void expect_derivatives_match(const Model& model, unsigned seed, const std::string& what) {
  const int n = model.dof();
  Workspace ws(model);
  std::mt19937 rng(seed);
  for (int k = 0; k < 4; ++k) {
    const RneaOptions options{k % 2 == 0, k < 2};
    const Eigen::VectorXd x[3] = {random_vector(n, rng, 3.0), random_vector(n, rng, 2.0),
                                  random_vector(n, rng, 5.0)};
    Eigen::MatrixXd d_q(n, n), d_dq(n, n), d_ddq(n, n);
    rnea_derivatives(model, ws, x[0], x[1], x[2], d_q, d_dq, d_ddq, options);
    // Position: O(h²) truncation against O(ε/h) rounding, both ≈ 1e-9 relative at h = 1e-5.
    EXPECT_LT(rel_diff(d_q, rnea_central_difference(model, ws, x, 0, 1e-5, options)), 1e-7)
        << what << ", state " << k;
    // The RNEA is quadratic in q̇ (q̇ stays away from the Coulomb step at 0 for this step) and
    // linear in q̈: central differences are exact up to rounding.
    EXPECT_LT(rel_diff(d_dq, rnea_central_difference(model, ws, x, 1, 1e-3, options)), 1e-9)
        << what << ", state " << k;
    EXPECT_LT(rel_diff(d_ddq, rnea_central_difference(model, ws, x, 2, 1e-2, options)), 1e-10)
        << what << ", state " << k;
    // ∂τ/∂q̈ is the mass matrix (CRBA), with Ia exactly when the RNEA includes the joint terms.
    Eigen::MatrixXd M(n, n);
    mass_matrix(model, ws, x[0], M);
    if (!options.joint_terms) {
      for (int j = 0; j < n; ++j) M(j, j) -= model.joints[j].friction.Ia;
    }
    EXPECT_LT(rel_diff(d_ddq, M), 1e-13) << what << ", state " << k;
  }
}

TEST(RneaDerivatives, ChainsMatchCentralDifferencesAndMassMatrix) {
  for (int n : {1, 2, 7, 18}) {
    expect_derivatives_match(random_tree(n, 300 + n, true, true), 400 + n,
                             "chain " + std::to_string(n));
  }
}

TEST(RneaDerivatives, TreesAndPrismaticRootsMatchCentralDifferencesAndMassMatrix) {
  // Seeds 1 and 5: forests whose prismatic root has a child; 4: four roots; 2, 3: one root.
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    expect_derivatives_match(random_tree(8, seed, true), 500 + seed,
                             "tree seed " + std::to_string(seed));
  }
}

}  // namespace
}  // namespace dynid
