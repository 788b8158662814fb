#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "dynid/dynamics/energy.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/energy_regressor.hpp"
#include "dynid/regressor/load_regressor.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "support/random_models.hpp"
#include "support/rk4.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;
using testing::rel_diff;

struct TreeCase {
  int n;
  unsigned seed;
  bool prismatic;
  bool chain;
};

class RegressorOnTrees : public ::testing::TestWithParam<TreeCase> {};

TEST_P(RegressorOnTrees, TorqueRegressorTimesThetaEqualsRnea) {
  const auto c = GetParam();
  const Model model = random_tree(c.n, c.seed, c.prismatic, c.chain);
  Workspace ws(model);
  const ParameterLayout layout = ParameterLayout::full();
  const Eigen::VectorXd theta = layout.parameters(model);
  Eigen::MatrixXd Y(c.n, layout.columns(c.n));
  std::mt19937 rng(c.seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(c.n, rng, 3.0), dq = random_vector(c.n, rng, 2.0),
                          ddq = random_vector(c.n, rng, 5.0);
    torque_regressor(model, ws, layout, q, dq, ddq, Y);
    Eigen::VectorXd tau(c.n);
    rnea(model, ws, q, dq, ddq, tau);
    EXPECT_LT(rel_diff(Y * theta, tau), 1e-12) << "state " << k;
  }
}

TEST_P(RegressorOnTrees, EnergyRegressorEqualsCrbaKineticPlusPotential) {
  const auto c = GetParam();
  const Model model = random_tree(c.n, c.seed, c.prismatic, c.chain);
  Workspace ws(model);
  const ParameterLayout layout = ParameterLayout::full();
  const Eigen::VectorXd theta = layout.parameters(model);
  Eigen::VectorXd h(layout.columns(c.n));
  Eigen::MatrixXd M(c.n, c.n);
  std::mt19937 rng(c.seed + 100);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd q = random_vector(c.n, rng, 3.0), dq = random_vector(c.n, rng, 2.0);
    energy_regressor(model, ws, layout, q, dq, h);
    mass_matrix(model, ws, q, M);
    const double H = 0.5 * dq.dot(M * dq) + potential_energy(model, ws, q);
    EXPECT_NEAR(h.dot(theta), H, 1e-11 * std::max(1.0, std::abs(H)));
  }
}

INSTANTIATE_TEST_SUITE_P(Trees, RegressorOnTrees,
                         ::testing::Values(TreeCase{7, 1, false, true}, TreeCase{7, 2, true, true},
                                           TreeCase{9, 3, true, false}, TreeCase{6, 4, true, false},
                                           TreeCase{1, 5, false, true}));

// Every built-in robot, with its own friction and armature values.
TEST(TorqueRegressor, BuiltInRobotsMatchRnea) {
  for (const auto& name : builtin_robot_names()) {
    const Model model = load_robot(name);
    const int n = model.dof();
    Workspace ws(model);
    const ParameterLayout layout = ParameterLayout::full();
    Eigen::MatrixXd Y(n, layout.columns(n));
    std::mt19937 rng(17);
    for (int k = 0; k < 10; ++k) {
      const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng, 2.0),
                            ddq = random_vector(n, rng, 5.0);
      torque_regressor(model, ws, layout, q, dq, ddq, Y);
      Eigen::VectorXd tau(n);
      rnea(model, ws, q, dq, ddq, tau);
      EXPECT_LT(rel_diff(Y * layout.parameters(model), tau), 1e-12) << name;
    }
  }
}

// The regressor writes through Y's storage with its outer stride: rows k·n … k·n+n−1 of a stacked
// regressor (as the estimators fill it) must equal the same call on an n-row matrix, and the
// rows around it must stay untouched.
TEST(TorqueRegressor, WritesIntoARowBlockOfAStackedRegressor) {
  const Model model = load_robot("iiwa14");
  const int n = model.dof();
  Workspace ws(model);
  const ParameterLayout layout = ParameterLayout::full();
  std::mt19937 rng(29);
  const Eigen::VectorXd q = random_vector(n, rng, 3.0), dq = random_vector(n, rng, 2.0),
                        ddq = random_vector(n, rng, 5.0);
  Eigen::MatrixXd alone(n, layout.columns(n));
  torque_regressor(model, ws, layout, q, dq, ddq, alone);
  Eigen::MatrixXd stacked = Eigen::MatrixXd::Constant(3 * n, layout.columns(n), 7.0);
  torque_regressor(model, ws, layout, q, dq, ddq, stacked.middleRows(n, n));
  EXPECT_EQ(stacked.middleRows(n, n), alone);
  EXPECT_TRUE((stacked.topRows(n).array() == 7.0).all());
  EXPECT_TRUE((stacked.bottomRows(n).array() == 7.0).all());
}

TEST(TorqueRegressor, AsymmetricFrictionColumnsFollowSeed2Eq2) {
  Model model = random_tree(4, 40, true);
  Workspace ws(model);
  ParameterLayout layout = ParameterLayout::full();
  layout.asymmetric = true;
  const int n = 4;
  ASSERT_EQ(layout.columns(n), 10 * n + 6 * n);
  EXPECT_EQ(layout.names(n)[10 * n + 1], "Fvp1");
  EXPECT_EQ(layout.names(n)[10 * n + 4], "Fcn1");
  Eigen::VectorXd theta = layout.parameters(model);
  // Give each direction its own values and compare with seed 2 eq. 2 evaluated by hand.
  std::mt19937 rng(40);
  for (int j = 0; j < n; ++j)
    theta.segment(10 * n + 6 * j + 1, 4) = random_vector(4, rng).cwiseAbs();
  const Eigen::VectorXd q = random_vector(n, rng), ddq = random_vector(n, rng);
  Eigen::VectorXd dq(n);
  dq << 0.7, -0.4, 0.0, -1.3;
  Eigen::MatrixXd Y(n, layout.columns(n));
  torque_regressor(model, ws, layout, q, dq, ddq, Y);
  Eigen::VectorXd rigid(n);
  rnea(model, ws, q, dq, ddq, rigid, RneaOptions{true, false});
  for (int j = 0; j < n; ++j) {
    const double* b = theta.data() + 10 * n + 6 * j;  // Ia Fvp Fvn Fcp Fcn Fo
    const double friction = dq[j] > 0 ? b[1] * dq[j] + b[3] : dq[j] < 0 ? b[2] * dq[j] - b[4] : 0.0;
    EXPECT_NEAR((Y * theta)[j], rigid[j] + b[0] * ddq[j] + friction + b[5], 1e-12);
  }
}

// ∫ tauᵀ dq dt = d·theta along an RK4 simulation (seed 1 eqs. 8–18). The simulated torque comes
// from forward dynamics, not from the regressor; friction is viscous + offset in the plant.
TEST(IntegralRegressor, RowTimesThetaEqualsWorkAlongSimulation) {
  Model model = random_tree(4, 50, true, true);
  for (auto& j : model.joints) j.friction.Fc = 0.0;
  Workspace ws(model);
  const int n = model.dof();
  auto torque = [&](double t) {
    Eigen::VectorXd tau(n);
    for (int j = 0; j < n; ++j) tau[j] = 4.0 * std::sin(1.5 * t + 0.7 * j) + 1.0;
    return tau;
  };
  auto deriv = [&](double t, const Eigen::VectorXd& x) {
    Eigen::VectorXd dx(2 * n), ddq(n);
    forward_dynamics(model, ws, x.head(n), x.tail(n), torque(t), ddq);
    dx << x.tail(n), ddq;
    return dx;
  };
  const double dt = 5e-4;
  const int steps = 2000;
  Eigen::VectorXd t(steps + 1);
  Eigen::MatrixXd Q(steps + 1, n), DQ(steps + 1, n), TAU(steps + 1, n);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * n);
  for (int k = 0; k <= steps; ++k) {
    t[k] = k * dt;
    Q.row(k) = x.head(n).transpose();
    DQ.row(k) = x.tail(n).transpose();
    TAU.row(k) = torque(t[k]).transpose();
    x = testing::rk4_step(deriv, t[k], x, dt);
  }
  ParameterLayout layout = ParameterLayout::full();
  const Eigen::VectorXd theta = layout.parameters(model);
  Eigen::VectorXd d(layout.columns(n));
  // A long integral over the whole run and a short one in the middle (seed 1 §IV).
  for (auto [a, b] : {std::pair{0, steps}, std::pair{700, 1300}}) {
    double y = 0.0;
    integral_regressor(model, ws, layout, t.segment(a, b - a + 1), Q.middleRows(a, b - a + 1),
                       DQ.middleRows(a, b - a + 1), TAU.middleRows(a, b - a + 1), y, d);
    EXPECT_GT(std::abs(y), 0.1);
    EXPECT_NEAR(d.dot(theta), y, 1e-6 * std::abs(y)) << "interval " << a << ".." << b;
  }
}

// Seed 1 eqs. 19–28 against a direct Newton–Euler evaluation about the centre of mass.
TEST(LoadRegressor, MatchesDirectNewtonEulerOfRigidBody) {
  std::mt19937 rng(60);
  for (int k = 0; k < 20; ++k) {
    const LinkParams body = testing::random_link(rng);
    const double m = body(9);
    const Eigen::Vector3d c = body.segment<3>(6) / m;
    const Eigen::Matrix3d I_P = inertia_about_origin(body);
    const Eigen::Matrix3d I_C =
        I_P - m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    const Eigen::Vector3d w = random_vector(3, rng, 2.0), dw = random_vector(3, rng, 5.0),
                          ddp = random_vector(3, rng, 5.0);
    const Eigen::Matrix3d R_WS =
        Eigen::Quaterniond(Eigen::Vector4d(random_vector(4, rng))).normalized().toRotationMatrix();
    const Eigen::Vector3d g_S = R_WS.transpose() * Eigen::Vector3d(0, 0, -9.81);
    // Eqs. 19–21: F = m(p̈ + dω×c + ω×(ω×c)) − m·g; eq. 20: N = I_C dω + ω×(I_C ω) + c×F.
    const Eigen::Vector3d ddq_c = ddp + dw.cross(c) + w.cross(w.cross(c));
    const Eigen::Vector3d F = m * ddq_c - m * g_S;
    const Eigen::Vector3d N = I_C * dw + w.cross(I_C * w) + c.cross(F);
    Eigen::Matrix<double, 10, 1> phi;
    phi << m, body(6), body(7), body(8), body(0), body(1), body(2), body(3), body(4), body(5);
    Eigen::Matrix<double, 6, 1> W;
    W << F, N;
    EXPECT_LT((load_regressor(w, dw, ddp, g_S) * phi - W).norm(), 1e-12 * std::max(1.0, W.norm()));
  }
}

}  // namespace
}  // namespace dynid
