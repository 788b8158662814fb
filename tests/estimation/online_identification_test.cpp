// On-line identification (OnlineIdentification): equal to the batch solutions it stands for,
// real-time safe (no heap allocation per sample), clear about bad input, and able to follow a
// payload change inside a simulated 1 kHz control loop.
#include "dynid/estimation/online_identification.hpp"

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/estimation/recursive_least_squares.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/sim/plant.hpp"
#include "support/asan.hpp"
#include "support/random_models.hpp"

// Every malloc of this test binary is counted while g_count_mallocs is set (operator new and
// Eigen's aligned allocator both end in malloc). AddressSanitizer owns malloc in its build.
#if !DYNID_UNDER_ASAN
namespace {
std::atomic<bool> g_count_mallocs{false};
std::atomic<long> g_mallocs{0};
}  // namespace
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* __libc_calloc(std::size_t n, std::size_t size);
extern "C" void* __libc_realloc(void* p, std::size_t size);
extern "C" void* malloc(std::size_t size) {
  if (g_count_mallocs.load(std::memory_order_relaxed)) ++g_mallocs;
  return __libc_malloc(size);
}
extern "C" void* calloc(std::size_t n, std::size_t size) {
  if (g_count_mallocs.load(std::memory_order_relaxed)) ++g_mallocs;
  return __libc_calloc(n, size);
}
extern "C" void* realloc(void* p, std::size_t size) {
  if (g_count_mallocs.load(std::memory_order_relaxed)) ++g_mallocs;
  return __libc_realloc(p, size);
}
#endif

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;

struct Samples {
  std::vector<Eigen::VectorXd> q, dq, ddq, tau;
};

// m random states of the model with torques from its RNEA plus N(0, sigma²) noise.
Samples random_samples(const Model& model, int m, unsigned seed, double sigma) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  const int n = model.dof();
  Samples s;
  Workspace ws(model);
  for (int k = 0; k < m; ++k) {
    s.q.push_back(random_vector(n, rng, 3.0));
    s.dq.push_back(random_vector(n, rng, 2.0));
    s.ddq.push_back(random_vector(n, rng, 5.0));
    Eigen::VectorXd tau(n);
    rnea(model, ws, s.q.back(), s.dq.back(), s.ddq.back(), tau);
    for (int j = 0; j < n; ++j) tau[j] += noise(rng);
    s.tau.push_back(tau);
  }
  return s;
}

// The base regressor of sample k (n × p): the base columns of the full torque regressor.
Eigen::MatrixXd base_rows(const Model& model, const ParameterLayout& layout,
                          const BaseParameters& base, const Samples& s, int k) {
  Workspace ws(model);
  Eigen::MatrixXd Y(model.dof(), layout.columns(model.dof()));
  torque_regressor(model, ws, layout, s.q[k], s.dq[k], s.ddq[k], Y);
  return base.select(Y);
}

TEST(OnlineIdentification, WithoutForgettingEqualsRecursiveLeastSquares) {
  const Model model = random_tree(6, 31, true);
  const ParameterLayout layout = ParameterLayout::full();
  BaseParameterOptions bo;
  bo.layout = layout;
  const BaseParameters base = compute_base_parameters(model, bo);
  const Samples s = random_samples(model, 150, 31, 0.05);
  OnlineIdentificationOptions oo;
  oo.forgetting_factor = 1.0;
  oo.initial_covariance = 1e3;
  OnlineIdentification online(model, layout, base, oo);
  RecursiveLeastSquaresOptions ro;
  ro.initial_covariance = 1e3;
  RecursiveLeastSquares batch(base.rank, ro);
  for (int k = 0; k < 150; ++k) {
    ASSERT_EQ(online.update(s.q[k], s.dq[k], s.ddq[k], s.tau[k]), OnlineStatus::kUpdated);
    batch.update(base_rows(model, layout, base, s, k), s.tau[k]);
  }
  EXPECT_EQ(online.samples(), 150);
  EXPECT_LT((online.estimate() - batch.x()).norm(), 1e-10 * batch.x().norm());
  EXPECT_LT((online.covariance_diagonal() - batch.P().diagonal()).norm(),
            1e-10 * batch.P().diagonal().norm());
}

// Exponential forgetting per sample: the closed-form weighted least squares with weights λ^{m−k}
// and the decayed prior, solved densely (no recursion).
TEST(OnlineIdentification, ForgettingEqualsWeightedLeastSquares) {
  const Model model = load_robot("puma560");
  const ParameterLayout layout = ParameterLayout::full();
  BaseParameterOptions bo;
  bo.layout = layout;
  const BaseParameters base = compute_base_parameters(model, bo);
  const int m = 400, p = base.rank;
  const double lambda = 0.99, c = 1e2;
  const Samples s = random_samples(model, m, 5, 0.1);
  std::mt19937 rng(6);
  const Eigen::VectorXd x0 = random_vector(p, rng);
  OnlineIdentificationOptions oo;
  oo.forgetting_factor = lambda;
  oo.initial_covariance = c;
  oo.max_covariance = std::numeric_limits<double>::infinity();
  OnlineIdentification online(model, layout, base, oo);
  online.set_initial_estimate(x0);
  Eigen::MatrixXd A = std::pow(lambda, m) / c * Eigen::MatrixXd::Identity(p, p);
  Eigen::VectorXd b = std::pow(lambda, m) / c * x0;
  for (int k = 0; k < m; ++k) {
    ASSERT_EQ(online.update(s.q[k], s.dq[k], s.ddq[k], s.tau[k]), OnlineStatus::kUpdated);
    const Eigen::MatrixXd W = base_rows(model, layout, base, s, k);
    const double w = std::pow(lambda, m - 1 - k);
    A += w * W.transpose() * W;
    b += w * W.transpose() * s.tau[k];
  }
  const Eigen::VectorXd x = A.ldlt().solve(b);
  EXPECT_LT((online.estimate() - x).norm(), 1e-8 * x.norm());
}

TEST(OnlineIdentification, UpdateDoesNotAllocate) {
  if (DYNID_UNDER_ASAN) GTEST_SKIP() << "AddressSanitizer owns malloc in this build";
#if !DYNID_UNDER_ASAN
  const Model model = load_robot("iiwa14");
  const ParameterLayout layout = ParameterLayout::full();
  BaseParameterOptions bo;
  bo.layout = layout;
  const BaseParameters base = compute_base_parameters(model, bo);
  const Samples s = random_samples(model, 20, 8, 0.1);
  OnlineIdentification online(model, layout, base);
  g_mallocs = 0;
  g_count_mallocs = true;
  for (int k = 0; k < 20; ++k) online.update(s.q[k], s.dq[k], s.ddq[k], s.tau[k]);
  g_count_mallocs = false;
  EXPECT_EQ(g_mallocs.load(), 0);
  EXPECT_EQ(online.samples(), 20);
  // The counter itself works: an Eigen vector allocates.
  g_count_mallocs = true;
  Eigen::VectorXd v(1000);
  g_count_mallocs = false;
  v.setZero();
  EXPECT_GT(g_mallocs.load(), 0);
#endif
}

TEST(OnlineIdentification, BadInputLeavesTheEstimateUnchanged) {
  const Model model = load_robot("puma560");
  const ParameterLayout layout = ParameterLayout::rigid();
  BaseParameterOptions bo;
  bo.layout = layout;
  const BaseParameters base = compute_base_parameters(model, bo);
  OnlineIdentification online(model, layout, base);
  const Samples s = random_samples(model, 2, 9, 0.1);
  ASSERT_EQ(online.update(s.q[0], s.dq[0], s.ddq[0], s.tau[0]), OnlineStatus::kUpdated);
  const Eigen::VectorXd x = online.estimate();
  Eigen::VectorXd bad = s.tau[1];
  bad[2] = std::nan("");
  EXPECT_EQ(online.update(s.q[1], s.dq[1], s.ddq[1], bad), OnlineStatus::kNonFinite);
  EXPECT_EQ(online.update(s.q[1].head(3), s.dq[1], s.ddq[1], s.tau[1]), OnlineStatus::kWrongSize);
  EXPECT_EQ(online.estimate(), x);
  EXPECT_EQ(online.samples(), 1);
  EXPECT_THROW(online.set_initial_estimate(x), Error);
  OnlineIdentificationOptions o;
  o.forgetting_factor = 0.0;
  EXPECT_THROW(OnlineIdentification(model, layout, base, o), Error);
  o = {};
  o.initial_covariance = -1.0;
  EXPECT_THROW(OnlineIdentification(model, layout, base, o), Error);
  EXPECT_THROW(OnlineIdentification(model, ParameterLayout::full(), base), Error);
}

// The example of issue 16 item 4: iiwa14 under computed-torque control at 1 kHz (nominal model,
// 4-harmonic reference), the native RK4 plant (forward dynamics by the CRBA, smoothed Coulomb
// friction), torque noise 0.05 N·m; at t = 4 s the flange picks up a 3 kg payload. The estimator
// starts from the nominal base parameters and forgets with λ = 0.999 (1 s memory). Like seed 1
// Fig. 6, the estimate settles after the change: its a-priori torque prediction error, the
// payload's whole effect at the pick-up, is below a tenth of it over the last second.
TEST(OnlineIdentification, TracksAPayloadChangeInA1kHzLoop) {
  const Model nominal = load_robot("iiwa14");
  const int n = nominal.dof();
  Model loaded = nominal;
  // 3 kg at 0.1 m along the flange z axis, as a point mass: m, m·c and the inertia about the
  // origin.
  const double mp = 3.0;
  const Eigen::Vector3d cp(0.0, 0.0, 0.1);
  LinkParams& l7 = loaded.links[n - 1];
  l7(0) += mp * cp.z() * cp.z();  // XX
  l7(3) += mp * cp.z() * cp.z();  // YY
  l7.segment<3>(6) += mp * cp;
  l7(9) += mp;
  const ParameterLayout layout = ParameterLayout::full();
  BaseParameterOptions bo;
  bo.layout = layout;
  const BaseParameters base = compute_base_parameters(nominal, bo);
  OnlineIdentificationOptions oo;
  oo.forgetting_factor = 0.999;
  oo.initial_covariance = 1.0;
  OnlineIdentification online(nominal, layout, base, oo);
  online.set_initial_estimate(base.reduce(layout.parameters(nominal)));

  PlantOptions po;
  po.dt = 1e-3;
  std::unique_ptr<Plant> plant = make_plant(nominal, po);
  Workspace ws(nominal);
  std::mt19937 rng(16);
  std::normal_distribution<double> noise(0.0, 0.05);
  const double kp = 400.0, kd = 40.0;
  Eigen::VectorXd qr(n), dqr(n), ddqr(n), tau(n), ddq(n), v(n), tau_meas(n);
  auto reference = [&](double t) {
    for (int j = 0; j < n; ++j) {
      qr[j] = dqr[j] = ddqr[j] = 0.0;
      for (int h = 1; h <= 4; ++h) {
        const double w = 2.0 * M_PI * 0.25 * h * (1.0 + 0.13 * j);
        const double a = 0.5 / h, phase = 0.7 * j + 1.3 * h;
        qr[j] += a * std::sin(w * t + phase);
        dqr[j] += a * w * std::cos(w * t + phase);
        ddqr[j] -= a * w * w * std::sin(w * t + phase);
      }
    }
  };
  reference(0.0);
  plant->reset(qr, dqr);
  const int steps = 8000, change = 4000;
  double err_before = 0.0, err_after = 0.0, effect = 0.0, err_first = 0.0, effect_first = 0.0;
  Eigen::VectorXd tau_nominal(n), tau_loaded(n);
  for (int k = 0; k < steps; ++k) {
    if (k == change) {
      const Eigen::VectorXd q = plant->q(), dq = plant->dq();
      plant = make_plant(loaded, po);
      plant->reset(q, dq);
    }
    reference(k * po.dt);
    v = ddqr + kp * (qr - plant->q()) + kd * (dqr - plant->dq());
    rnea(nominal, ws, plant->q(), plant->dq(), v, tau);  // computed torque, nominal model
    plant->acceleration(tau, ddq);
    for (int j = 0; j < n; ++j) tau_meas[j] = tau[j] + noise(rng);
    ASSERT_EQ(online.update(plant->q(), plant->dq(), ddq, tau_meas), OnlineStatus::kUpdated);
    const double e2 = (online.predicted_torque() - tau).squaredNorm() / n;
    if (k >= change - 1000 && k < change) err_before += e2 / 1000;
    const bool first = k == change, last = k >= steps - 1000;
    if (first || last) {
      rnea(nominal, ws, plant->q(), plant->dq(), ddq, tau_nominal);
      rnea(loaded, ws, plant->q(), plant->dq(), ddq, tau_loaded);
      const double d2 = (tau_loaded - tau_nominal).squaredNorm() / n;
      if (first) {
        err_first = e2;
        effect_first = d2;
      } else {
        err_after += e2 / 1000;
        effect += d2 / 1000;
      }
    }
    plant->step(tau);
  }
  err_before = std::sqrt(err_before);
  err_first = std::sqrt(err_first);
  effect_first = std::sqrt(effect_first);
  err_after = std::sqrt(err_after);
  effect = std::sqrt(effect);
  RecordProperty("payload_effect_rms", std::to_string(effect));
  RecordProperty("prediction_error_rms_after", std::to_string(err_after));
  std::printf(
      "payload effect %.3g N·m (at the pick-up %.3g), prediction error: last s before %.3g, at "
      "the pick-up %.3g, last s %.3g\n",
      effect, effect_first, err_before, err_first, err_after);
  EXPECT_GT(effect, 1.0);  // the payload matters (N·m)
  // At the pick-up the a-priori prediction is still the unloaded arm's.
  EXPECT_GT(err_first, 0.9 * effect_first);
  EXPECT_LT(err_after, 0.1 * effect);
  EXPECT_LT(err_before, 0.1 * effect);
}

}  // namespace
}  // namespace dynid
