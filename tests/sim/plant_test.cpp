// Plants: RK4 accuracy and order, energy balance, friction model, MuJoCo vs native agreement.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/energy.hpp"
#include "dynid/sim/plant.hpp"
#include "sim/sim_support.hpp"
#include "support/random_models.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

PlantOptions native(double dt, int substeps = 1) {
  PlantOptions o;
  o.dt = dt;
  o.native.max_step = 1.0;
  o.native.substeps = substeps;
  return o;
}

// Small oscillation about q = −π/2: q(t) = −π/2 + A cos(ωt), ω² = m g l / J. The nonlinearity
// shifts the frequency by ω·A²/16 (Landau–Lifshitz §28), i.e. a phase error ω t A²/16 = 5.4e-7 rad
// after 2 s for A = 1e-3, so |q − closed form| ≤ A·5.4e-7 plus the RK4 error (≈ 1e-14 per step).
TEST(NativePlant, SmallAnglePendulumMatchesClosedForm) {
  const double m = 1.0, l = 0.5, ic = 0.01, ia = 0.02, g = 9.81, A = 1e-3;
  const Model model = testing::pendulum(m, l, ic, ia, g);
  const double w = std::sqrt(m * g * l / (m * l * l + ic + ia));
  auto plant = make_plant(model, native(1e-3));
  plant->reset(Eigen::VectorXd::Constant(1, -kPi / 2 + A), Eigen::VectorXd::Zero(1));
  const Eigen::VectorXd tau = Eigen::VectorXd::Zero(1);
  double worst = 0.0;
  for (int k = 1; k <= 2000; ++k) {
    plant->step(tau);
    worst = std::max(worst, std::abs(plant->q()[0] - (-kPi / 2 + A * std::cos(w * k * 1e-3))));
  }
  EXPECT_NEAR(plant->time(), 2.0, 1e-12);
  EXPECT_LT(worst, 2.0 * A * 5.4e-7);
}

// Global error of classical RK4 is O(h⁴): halving h divides it by 16 (order 4 ± 0.2).
TEST(NativePlant, Rk4ConvergesWithOrderFour) {
  const Model model = testing::pendulum();
  auto run = [&](double h) {
    auto plant = make_plant(model, native(h));
    plant->reset(Eigen::VectorXd::Constant(1, 0.3), Eigen::VectorXd::Constant(1, 1.0));
    const int steps = static_cast<int>(std::lround(1.0 / h));
    for (int k = 0; k < steps; ++k) plant->step(Eigen::VectorXd::Constant(1, 0.5));
    return plant->q()[0];
  };
  const double ref = run(6.25e-5);
  const double e1 = std::abs(run(4e-3) - ref), e2 = std::abs(run(2e-3) - ref),
               e3 = std::abs(run(1e-3) - ref);
  EXPECT_NEAR(std::log2(e1 / e2), 4.0, 0.2);
  EXPECT_NEAR(std::log2(e2 / e3), 4.0, 0.2);
}

// Sub-steps: one dt split into 8 internal RK4 steps equals 8 plain steps of dt/8.
TEST(NativePlant, SubstepsEqualSmallerSteps) {
  const Model model = testing::random_tree(3, 11, false, true);
  auto a = make_plant(model, native(8e-3, 8));
  auto b = make_plant(model, native(1e-3, 1));
  const Eigen::VectorXd tau = Eigen::VectorXd::Constant(3, 0.7);
  for (int k = 0; k < 20; ++k) {
    a->step(tau);
    for (int s = 0; s < 8; ++s) b->step(tau);
  }
  EXPECT_LT((a->q() - b->q()).norm(), 1e-12);
  EXPECT_LT((a->dq() - b->dq()).norm(), 1e-12);
}

Model frictionless(Model model) {
  for (auto& j : model.joints) j.friction.Fv = j.friction.Fc = j.friction.Fo = 0.0;
  return model;
}

double energy(const Model& model, Workspace& ws, const Plant& p) {
  return kinetic_energy(model, ws, p.q(), p.dq()) + potential_energy(model, ws, p.q());
}

// Without friction and torque the total energy (dynamics/energy.hpp, an independent computation)
// is conserved up to the RK4 error, which drops ~16× when h halves.
TEST(NativePlant, ConservesEnergyWithoutFriction) {
  const Model model = frictionless(testing::random_tree(5, 3, true, true));
  Workspace ws(model);
  std::mt19937 rng(5);
  const Eigen::VectorXd q0 = testing::random_vector(5, rng, 1.0),
                        dq0 = testing::random_vector(5, rng, 1.0);
  auto drift = [&](double h) {
    auto plant = make_plant(model, native(h));
    plant->reset(q0, dq0);
    const double e0 = energy(model, ws, *plant);
    double worst = 0.0;
    for (int k = 0; k < static_cast<int>(std::lround(2.0 / h)); ++k) {
      plant->step(Eigen::VectorXd::Zero(5));
      worst = std::max(worst, std::abs(energy(model, ws, *plant) - e0));
    }
    return worst / std::max(1.0, std::abs(e0));
  };
  const double d1 = drift(1e-3), d2 = drift(5e-4);
  EXPECT_LT(d1, 1e-7);  // seen: 3.8e-9
  EXPECT_GT(d1 / d2, 8.0);
}

// Work–energy balance with torque and the full plant friction (viscous, smoothed Coulomb,
// Stribeck/stiction, offset): E(T) − E(0) = ∫ (τ − F(dq))·dq dt, with E from dynamics/energy.hpp
// and F from its closed form written here. τ is held over each 0.1 ms step, so the trapezoidal
// rule per step with that τ has a global error O(dt²) ≈ 1e-8 relative.
TEST(NativePlant, FrictionWorkMatchesEnergyChange) {
  const Model model = testing::random_tree(3, 21, false, true);
  Workspace ws(model);
  PlantOptions o;
  o.dt = 1e-4;
  o.native.friction.smoothing_velocity = 0.05;
  o.native.friction.stiction = Eigen::Vector3d(0.6, 0.1, 0.9);
  o.native.friction.stribeck_velocity = 0.1;
  auto plant = make_plant(model, o);
  plant->reset(Eigen::Vector3d(0.2, -0.4, 0.5), Eigen::Vector3d(1.0, -0.5, 0.2));
  auto power = [&](const Eigen::Vector3d& tau, const Eigen::VectorXd& dq) {
    double p = 0.0;
    for (int j = 0; j < 3; ++j) {
      const JointFriction& f = model.joints[j].friction;
      const double v = dq[j];
      const double level = f.Fc + (o.native.friction.stiction[j] - f.Fc) * std::exp(-v * v / 0.01);
      p += (tau[j] - (f.Fv * v + level * std::tanh(v / 0.05) + f.Fo)) * v;
    }
    return p;
  };
  const double e0 = energy(model, ws, *plant);
  double work = 0.0;
  for (int k = 0; k < 10000; ++k) {
    const double t = k * o.dt;
    const Eigen::Vector3d tau(2.0 * std::sin(3 * t), -1.0, 0.5 * std::cos(2 * t));
    const double p0 = power(tau, plant->dq());
    plant->step(tau);
    work += 0.5 * o.dt * (p0 + power(tau, plant->dq()));
  }
  const double e1 = energy(model, ws, *plant);
  EXPECT_NEAR(e1 - e0, work, 1e-6 * std::max(1.0, std::abs(work)));
}

TEST(PlantFriction, MatchesClosedFormAndSlopeBound) {
  Model model = testing::pendulum();
  model.joints[0].friction = {0.0, 0.3, 1.2, 0.1};
  PlantFrictionOptions o;
  o.smoothing_velocity = 0.02;
  o.stiction = Eigen::VectorXd::Constant(1, 2.0);
  o.stribeck_velocity = 0.1;
  check_plant_friction(model, o);
  double max_fd = 0.0;
  Eigen::VectorXd out(1), out2(1);
  for (double v = -1.0; v <= 1.0; v += 1e-3) {
    plant_friction_torque(model, o, Eigen::VectorXd::Constant(1, v), out);
    const double expected =
        0.3 * v + (1.2 + 0.8 * std::exp(-(v / 0.1) * (v / 0.1))) * std::tanh(v / 0.02) + 0.1;
    EXPECT_NEAR(out[0], expected, 1e-14);
    plant_friction_torque(model, o, Eigen::VectorXd::Constant(1, v + 1e-7), out2);
    max_fd = std::max(max_fd, std::abs(out2[0] - out[0]) / 1e-7);
  }
  EXPECT_LE(max_fd, plant_friction_max_slope(model.joints[0].friction, o, 0));
  // Far from zero the plant friction tends to the identified model's Fv·dq + Fc·sign(dq) + Fo.
  plant_friction_torque(model, o, Eigen::VectorXd::Constant(1, -2.0), out);
  EXPECT_NEAR(out[0], 0.3 * -2.0 - 1.2 + 0.1, 1e-12);
}

// MuJoCo (on the exported URDF) and the native engine integrate the same ODE with the same RK4
// and zero-order-hold torque, so they agree up to MuJoCo's import of the inertias (its iterative
// 3×3 eigen-decomposition is accurate to ~2e-7 of the tensor norm, tests/oracle) amplified by the
// motion: over 1 s we require 1e-7 rad (seen: 1.2e-9).
TEST(MujocoPlant, AgreesWithNativeOpenLoop) {
  Model model = testing::random_tree(4, 7, true, true);
  for (auto& j : model.joints) j.friction.Fc = 0.0;  // MuJoCo's frictionloss is a different model
  PlantOptions on, om;
  on.dt = om.dt = 1e-3;
  om.engine = PlantEngine::kMujoco;
  auto a = make_plant(model, on);
  auto b = make_plant(model, om);
  EXPECT_EQ(b->engine(), "mujoco");
  const Eigen::Vector4d q0(0.1, -0.2, 0.05, 0.3), dq0(0.2, 0.0, -0.1, 0.4);
  a->reset(q0, dq0);
  b->reset(q0, dq0);
  Eigen::VectorXd ddq_a(4), ddq_b(4), tau(4);
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const double t = k * 1e-3;
    for (int j = 0; j < 4; ++j) tau[j] = 3.0 * std::sin(2 * kPi * (j + 1) * 0.7 * t);
    if (k % 100 == 0) {
      a->acceleration(tau, ddq_a);
      b->acceleration(tau, ddq_b);
      EXPECT_LT((ddq_a - ddq_b).norm(), 1e-5 * std::max(1.0, ddq_a.norm())) << "t = " << t;
    }
    a->step(tau);
    b->step(tau);
    worst = std::max(worst, (a->q() - b->q()).cwiseAbs().maxCoeff());
  }
  EXPECT_NEAR(b->time(), 1.0, 1e-9);
  EXPECT_LT(worst, 1e-7);
}

// MuJoCo's frictionloss (Coulomb as a soft constraint) brings a joint to rest like the native
// smoothed Coulomb does: a pendulum-free joint (gravity along the axis) launched at 1 rad/s with
// Fc = 1 N·m and J = 0.27 kg·m² stops after t = J·v/Fc = 0.27 s in both.
TEST(MujocoPlant, CoulombStopsTheJointInBothEngines) {
  Model model = testing::pendulum(1.0, 0.5, 0.01, 0.01, 0.0);
  model.gravity = Eigen::Vector3d(0, 0, -9.81);  // along the axis: no gravity torque
  model.joints[0].friction.Fc = 1.0;
  const double J = 1.0 * 0.25 + 0.01 + 0.01;
  for (PlantEngine engine : {PlantEngine::kNative, PlantEngine::kMujoco}) {
    PlantOptions o;
    o.engine = engine;
    o.native.friction.smoothing_velocity = 1e-3;
    auto plant = make_plant(model, o);
    plant->reset(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, 1.0));
    for (int k = 0; k < 135; ++k) plant->step(Eigen::VectorXd::Zero(1));  // t = 0.135 s: half way
    EXPECT_NEAR(plant->dq()[0], 1.0 - 0.135 / J, 0.02) << plant->engine();
    EXPECT_NEAR(plant->q()[0], 0.135 - 0.5 * 0.135 * 0.135 / J, 0.002) << plant->engine();
    for (int k = 0; k < 300; ++k) plant->step(Eigen::VectorXd::Zero(1));
    EXPECT_LT(std::abs(plant->dq()[0]), 0.02) << plant->engine();
    EXPECT_NEAR(plant->q()[0], 0.5 * J, 0.005) << plant->engine();  // stopping distance J v²/(2Fc)
  }
}

// A light joint (J = 1.2e-3 kg·m², like a wrist) is where MuJoCo's default soft frictionloss acts
// like viscous damping; with the plant's stiff friction constraint it decelerates at the Coulomb
// rate Fc/J and stops after J·v/Fc = 24 ms, as the closed form says.
TEST(MujocoPlant, CoulombOnALightJointDeceleratesAtFcOverJ) {
  Model model = testing::pendulum(0.1, 0.1, 1e-4, 1e-4, 0.0);
  model.gravity = Eigen::Vector3d(0, 0, -9.81);  // along the axis: no gravity torque
  model.joints[0].friction.Fc = 0.05;
  const double J = 0.1 * 0.01 + 1e-4 + 1e-4, t_stop = J * 1.0 / 0.05;
  PlantOptions o;
  o.engine = PlantEngine::kMujoco;
  auto plant = make_plant(model, o);
  plant->reset(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, 1.0));
  for (int k = 0; k < 12; ++k) plant->step(Eigen::VectorXd::Zero(1));  // half of t_stop
  EXPECT_NEAR(plant->dq()[0], 1.0 - 0.012 / t_stop, 0.05);
  for (int k = 0; k < 48; ++k) plant->step(Eigen::VectorXd::Zero(1));
  EXPECT_LT(std::abs(plant->dq()[0]), 0.02);
  EXPECT_NEAR(plant->q()[0], 0.5 * J / 0.05, 0.1 * 0.5 * J / 0.05);  // stopping distance J v²/(2Fc)
}

TEST(Plant, RejectsBadInput) {
  const Model model = testing::pendulum();
  PlantOptions o;
  o.dt = 0.0;
  EXPECT_THROW(make_plant(model, o), Error);
  o.dt = 1e-3;
  o.native.friction.smoothing_velocity = -1.0;
  EXPECT_THROW(make_plant(model, o), Error);
  o.native.friction.smoothing_velocity = 0.01;
  o.native.friction.stiction = Eigen::Vector2d(1, 1);
  EXPECT_THROW(make_plant(model, o), Error);
  o.native.friction.stiction.resize(0);
  for (PlantEngine engine : {PlantEngine::kNative, PlantEngine::kMujoco}) {
    o.engine = engine;
    auto plant = make_plant(model, o);
    EXPECT_THROW(plant->step(Eigen::VectorXd::Zero(2)), Error);
    EXPECT_THROW(plant->step(Eigen::VectorXd::Constant(1, NAN)), Error);
    EXPECT_THROW(plant->reset(Eigen::VectorXd::Constant(1, INFINITY), Eigen::VectorXd::Zero(1)),
                 Error);
  }
}

}  // namespace
}  // namespace dynid
