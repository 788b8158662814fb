#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "dynid/dynamics/articulated_body.hpp"
#include "dynid/dynamics/energy.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "support/planar2.hpp"
#include "support/random_models.hpp"
#include "support/rk4.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;
using testing::rel_diff;

// The closed form is the oracle of both directions: RNEA gives its torque, the articulated-body
// algorithm its acceleration back.
TEST(Planar2, RneaAndArticulatedBodyMatchClosedForm) {
  const testing::Planar2 arm;
  const Model model = arm.model();
  Workspace ws(model);
  std::mt19937 rng(7);
  for (int k = 0; k < 50; ++k) {
    const Eigen::VectorXd q = random_vector(2, rng, 3.0), dq = random_vector(2, rng, 2.0),
                          ddq = random_vector(2, rng, 5.0);
    Eigen::VectorXd tau(2), ddq_aba(2);
    rnea(model, ws, q, dq, ddq, tau);
    EXPECT_LT(rel_diff(tau, arm.torque(q, dq, ddq)), 1e-12) << "state " << k;
    articulated_body_forward_dynamics(model, ws, q, dq, arm.torque(q, dq, ddq), ddq_aba);
    EXPECT_LT(rel_diff(ddq_aba, ddq), 1e-12) << "state " << k;
  }
}

TEST(Rnea, JointTermsAddArmatureAndFriction) {
  const Model model = random_tree(5, 3, true);
  Workspace ws(model);
  std::mt19937 rng(11);
  const Eigen::VectorXd q = random_vector(5, rng), dq = random_vector(5, rng),
                        ddq = random_vector(5, rng);
  Eigen::VectorXd with(5), without(5);
  rnea(model, ws, q, dq, ddq, with);
  rnea(model, ws, q, dq, ddq, without, RneaOptions{true, false});
  for (int j = 0; j < 5; ++j) {
    const JointFriction& f = model.joints[j].friction;
    const double expected = f.Ia * ddq[j] + f.Fv * dq[j] + f.Fc * (dq[j] > 0 ? 1.0 : -1.0) + f.Fo;
    EXPECT_NEAR(with[j] - without[j], expected, 1e-12);
  }
}

TEST(MassMatrix, SymmetricPositiveDefiniteAndConsistentWithRnea) {
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    const Model model = random_tree(7, seed, true);
    Workspace ws(model);
    std::mt19937 rng(seed);
    for (int k = 0; k < 10; ++k) {
      const Eigen::VectorXd q = random_vector(7, rng, 3.0), dq = random_vector(7, rng),
                            ddq = random_vector(7, rng);
      Eigen::MatrixXd M(7, 7);
      mass_matrix(model, ws, q, M);
      EXPECT_LT((M - M.transpose()).norm(), 1e-12 * M.norm());
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff(), 0.0);
      Eigen::VectorXd c(7), tau(7);
      rnea(model, ws, q, dq, Eigen::VectorXd::Zero(7), c);
      rnea(model, ws, q, dq, ddq, tau);
      EXPECT_LT(rel_diff(M * ddq + c, tau), 1e-12) << "seed " << seed;
    }
  }
}

TEST(ForwardDynamics, InvertsRnea) {
  const Model model = random_tree(6, 5, true);
  Workspace ws(model);
  std::mt19937 rng(5);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd q = random_vector(6, rng, 3.0), dq = random_vector(6, rng),
                          ddq = random_vector(6, rng);
    Eigen::VectorXd tau(6), ddq_back(6);
    rnea(model, ws, q, dq, ddq, tau);
    forward_dynamics(model, ws, q, dq, tau, ddq_back);
    EXPECT_LT(rel_diff(ddq_back, ddq), 1e-10);
  }
}

// Kinetic energy against ½ dqᵀ M dq (CRBA), an independent algorithm.
TEST(Energy, KineticEnergyEqualsHalfDqMDq) {
  const Model model = random_tree(7, 9, true);
  Workspace ws(model);
  std::mt19937 rng(9);
  const Eigen::VectorXd q = random_vector(7, rng, 3.0), dq = random_vector(7, rng);
  Eigen::MatrixXd M(7, 7);
  mass_matrix(model, ws, q, M);
  EXPECT_NEAR(kinetic_energy(model, ws, q, dq), 0.5 * dq.dot(M * dq),
              1e-12 * dq.squaredNorm() * M.norm());
}

// The gradient of the potential energy is the gravity torque (finite differences).
TEST(Energy, PotentialGradientIsGravityTorque) {
  const Model model = random_tree(6, 12, true);
  Workspace ws(model);
  std::mt19937 rng(12);
  const Eigen::VectorXd q = random_vector(6, rng, 3.0);
  Eigen::VectorXd g(6);
  rnea(model, ws, q, Eigen::VectorXd::Zero(6), Eigen::VectorXd::Zero(6), g,
       RneaOptions{true, false});
  const double h = 1e-6;
  for (int j = 0; j < 6; ++j) {
    Eigen::VectorXd qp = q, qm = q;
    qp[j] += h;
    qm[j] -= h;
    const double fd = (potential_energy(model, ws, qp) - potential_energy(model, ws, qm)) / (2 * h);
    EXPECT_NEAR(fd, g[j], 1e-6 * std::max(1.0, std::abs(g[j])));
  }
}

// RK4 integration of the forward dynamics; the helper is shared with the regressor tests.
TEST(Energy, EnergyBalanceAlongSimulatedTrajectory) {
  // d/dt(E_k + E_p) = (tau − friction)ᵀ dq: integrate both sides along an RK4 simulation driven by
  // a smooth torque; friction without Coulomb so the right-hand side is smooth.
  Model model = random_tree(4, 21, true, true);
  for (auto& j : model.joints) j.friction.Fc = 0.0;
  Workspace ws(model);
  const int n = model.dof();
  auto torque = [&](double t) {
    Eigen::VectorXd tau(n);
    for (int j = 0; j < n; ++j) tau[j] = 3.0 * std::sin(2.0 * t + j);
    return tau;
  };
  auto deriv = [&](double t, const Eigen::VectorXd& x) {
    Eigen::VectorXd dx(2 * n), ddq(n);
    forward_dynamics(model, ws, x.head(n), x.tail(n), torque(t), ddq);
    dx << x.tail(n), ddq;
    return dx;
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * n);
  const double dt = 1e-3;
  double work = 0.0;
  auto power = [&](double t, const Eigen::VectorXd& s) {
    double p = 0.0;
    for (int j = 0; j < n; ++j) {
      const JointFriction& f = model.joints[j].friction;
      p += (torque(t)[j] - f.Fv * s[n + j] - f.Fo) * s[n + j];
    }
    return p;
  };
  const double H0 =
      kinetic_energy(model, ws, x.head(n), x.tail(n)) + potential_energy(model, ws, x.head(n));
  double t = 0.0;
  for (int k = 0; k < 1000; ++k) {
    Eigen::VectorXd k1;
    const Eigen::VectorXd x_next = testing::rk4_step(deriv, t, x, dt, &k1);
    // Simpson's rule on the power; the midpoint state by cubic Hermite interpolation (O(dt⁴)).
    const Eigen::VectorXd x_mid = 0.5 * (x + x_next) + dt / 8 * (k1 - deriv(t + dt, x_next));
    work += dt / 6 * (power(t, x) + 4 * power(t + dt / 2, x_mid) + power(t + dt, x_next));
    x = x_next;
    t += dt;
  }
  const double H1 =
      kinetic_energy(model, ws, x.head(n), x.tail(n)) + potential_energy(model, ws, x.head(n));
  EXPECT_NEAR(H1 - H0, work, 1e-6 * std::max(1.0, std::abs(work)));
  EXPECT_GT(std::abs(work), 0.1);  // the test would be vacuous if nothing moved
}

TEST(Kinematics, ChildPoseComposesParentPose) {
  const Model model = random_tree(6, 30, true);
  Workspace ws(model);
  std::mt19937 rng(30);
  const Eigen::VectorXd q = random_vector(6, rng, 3.0);
  forward_kinematics(model, ws, q);
  for (int j = 0; j < 6; ++j) {
    const Joint& jt = model.joints[j];
    // Independent evaluation from the joint definition with Eigen's Isometry3d.
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    for (int i : ws.ancestors[j]) {
      const Joint& ji = model.joints[i];
      Eigen::Isometry3d Xi = Eigen::Isometry3d::Identity();
      Xi.linear() = ji.R_PJ;
      Xi.translation() = ji.p_PJ;
      if (ji.type == JointType::kRevolute) {
        Xi.rotate(Eigen::AngleAxisd(q[i], ji.axis));
      } else {
        Xi.translate(ji.axis * q[i]);
      }
      X = Xi * X;
    }
    EXPECT_LT((X.linear() - ws.links[j].R_WJ).norm(), 1e-12) << jt.name;
    EXPECT_LT((X.translation() - ws.links[j].p_WJ).norm(), 1e-12) << jt.name;
  }
}

// Velocities and accelerations of each link origin against finite differences of the pose along the
// path q(t) = q0 + dq0·t + ½ddq0·t².
TEST(Kinematics, VelocitiesAndAccelerationsMatchFiniteDifferences) {
  Model model = random_tree(6, 31, true);
  model.gravity.setZero();
  Workspace ws(model);
  std::mt19937 rng(31);
  const Eigen::VectorXd q0 = random_vector(6, rng, 3.0), dq0 = random_vector(6, rng),
                        ddq0 = random_vector(6, rng);
  auto pose = [&](double t, int j) {
    forward_kinematics(model, ws, q0 + dq0 * t + 0.5 * ddq0 * t * t);
    return std::make_pair(ws.links[j].R_WJ, ws.links[j].p_WJ);
  };
  const double h = 1e-4;
  forward_kinematics(model, ws, q0, dq0, ddq0, false);
  const std::vector<LinkState> states = ws.links;
  for (int j = 0; j < 6; ++j) {
    const auto [Rm, pm] = pose(-h, j);
    const auto [R0, p0] = pose(0, j);
    const auto [Rp, pp] = pose(h, j);
    const Eigen::Vector3d v_fd = R0.transpose() * (pp - pm) / (2 * h);
    const Eigen::Vector3d a_fd = R0.transpose() * (pp - 2 * p0 + pm) / (h * h);
    const Eigen::Matrix3d W = R0.transpose() * (Rp - Rm) / (2 * h);  // [ω×] in frame j
    EXPECT_LT((v_fd - states[j].v).norm(), 1e-6);
    EXPECT_LT((a_fd - states[j].a).norm(), 1e-4);
    EXPECT_LT((Eigen::Vector3d(W(2, 1), W(0, 2), W(1, 0)) - states[j].w).norm(), 1e-6);
  }
}

}  // namespace
}  // namespace dynid
