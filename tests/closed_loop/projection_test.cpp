// Stage 1 of the projection method (seed 2 eqs. 10–12, Forssell–Ljung). Oracles: (1) a known
// two-input non-causal FIR plus coloured noise independent of the reference, drawn here with a
// fixed seed: the coefficients and the smallest adequate order are known; (2) a plain PID closed
// loop on planar2 run twice from the same reference, with and without measurement noise fed back:
// the projected signals of the noisy run must approach those of the noise-free run.
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/closed_loop/projection.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

double rms(const Eigen::Ref<const Eigen::VectorXd>& x) {
  return std::sqrt(x.squaredNorm() / static_cast<double>(x.size()));
}

// True FIR taps s_k, k = −3 … 10 (non-causal part −3 … −1), from reference i to torque j.
double tap(int j, int i, int k) {
  if (k < -3 || k > 10) return 0.0;
  return (j == i ? 1.0 : 0.4) * std::exp(-0.3 * std::abs(k - 2)) * (k % 2 == 0 ? 1.0 : -0.5) *
         (j + 1);
}

struct FirData {
  JointRecord run;
  Eigen::MatrixXd qr, dqr, ddqr;
};

FirData fir_data(long m, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  FirData d;
  const int n = 2;
  d.qr.resize(m, n);
  Eigen::MatrixXd noise(m, 2 * n);
  for (int i = 0; i < n; ++i) {
    double a = 0.0;
    for (long t = 0; t < m; ++t) d.qr(t, i) = a = 0.7 * a + g(rng);  // AR(1) reference
  }
  for (int j = 0; j < 2 * n; ++j) {
    double a = 0.0;
    for (long t = 0; t < m; ++t) noise(t, j) = a = 0.8 * a + 0.3 * g(rng);  // coloured noise
  }
  d.run.t = Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) * 0.005);
  d.run.tau = Eigen::MatrixXd::Constant(m, n, 1.5) + noise.leftCols(n);
  d.run.q = 0.5 * d.qr + noise.rightCols(n) * 0.01;
  for (long t = 0; t < m; ++t)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int k = -3; k <= 10; ++k)
          if (t - k >= 0 && t - k < m) d.run.tau(t, j) += tap(j, i, k) * d.qr(t - k, i);
  d.dqr = d.qr;  // any signal: the derivative outputs are the position FIR applied to it
  d.ddqr = d.qr;
  return d;
}

TEST(Projection, ChoosesTheSmallestAdequateOrderAndRecoversAKnownFir) {
  const FirData d = fir_data(8000, 21);
  const ProjectionResult p = project_on_reference(d.run, d.qr, d.dqr, d.ddqr);
  // Orders 2, 4, 8 miss taps 9, 10 (and −3 for 2): their remainders correlate with the reference
  // at those lags; 12 covers −3 … 10.
  ASSERT_GE(p.tests.size(), 4u);
  for (std::size_t k = 0; k + 1 < p.tests.size(); ++k) EXPECT_FALSE(p.tests[k].passed);
  EXPECT_TRUE(p.tests.back().passed);
  EXPECT_EQ(p.m1, 12);
  EXPECT_EQ(p.m2, 12);
  for (const ProjectionTest& t : p.tests)
    std::printf("M = %d: max |z| %.2f (bound %.2f)\n", t.m1, t.max_z, t.threshold);
  const int w = p.m1 + p.m2 + 1;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      for (int k = -p.m1; k <= p.m2; ++k)
        EXPECT_NEAR(p.fir(i * w + k + p.m1, j), tap(j, i, k), 0.03) << j << i << k;
  EXPECT_NEAR(p.fir(2 * w, 0), 1.5, 0.2);  // the constant
  for (int j = 0; j < 2; ++j) EXPECT_LT(std::abs(p.correlation[j]), 1e-9);
  // Positions 0.5·qr: the derivative outputs are the same FIR on dqr, ddqr.
  EXPECT_LT((p.processed.record.dq - 0.5 * d.dqr.middleRows(p.m2, p.processed.record.t.size()))
                .cwiseAbs()
                .maxCoeff(),
            0.01);
  // Given orders are used as given and tested too.
  ProjectionOptions o;
  o.m1 = 4;
  o.m2 = 11;
  const ProjectionResult g = project_on_reference(d.run, d.qr, d.dqr, d.ddqr, o);
  EXPECT_EQ(g.m1, 4);
  EXPECT_EQ(g.processed.record.t.size(), 8000 - 15);
  EXPECT_DOUBLE_EQ(g.processed.record.t[0], d.run.t[11]);
  ASSERT_EQ(g.tests.size(), 1u);
  EXPECT_TRUE(g.tests[0].passed);
  EXPECT_TRUE(g.warnings.empty());
  // Given orders that miss taps fail the test: a warning that says so and names the fix, not
  // only the status of the test (issue 28 item 3).
  o.m1 = o.m2 = 2;
  const ProjectionResult short_fir = project_on_reference(d.run, d.qr, d.dqr, d.ddqr, o);
  ASSERT_FALSE(short_fir.tests.back().passed);
  ASSERT_EQ(short_fir.warnings.size(), 1u);
  EXPECT_EQ(short_fir.warnings[0].rfind("the torque remainder of the projection still correlates "
                                        "with the reference",
                                        0),
            0u)
      << short_fir.warnings[0];
  EXPECT_NE(short_fir.warnings[0].find("give larger orders with --fir"), std::string::npos);
}

// One 2 s period of a three-harmonic reference per joint at 200 Hz.
void three_harmonics(Eigen::VectorXd& t, Eigen::MatrixXd& q, Eigen::MatrixXd& dq,
                     Eigen::MatrixXd& ddq) {
  const int m = 400;
  const double w = M_PI;
  t = Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) * 0.005);
  q.resize(m, 2);
  dq.resize(m, 2);
  ddq.resize(m, 2);
  const double a[2][3] = {{0.4, 0.2, 0.1}, {0.3, -0.15, 0.1}}, ph[2] = {0.0, 0.7};
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < 2; ++j) {
      q(k, j) = dq(k, j) = ddq(k, j) = 0.0;
      for (int h = 1; h <= 3; ++h) {
        const double x = h * w * t[k] + h * ph[j];
        q(k, j) += a[j][h - 1] * std::sin(x);
        dq(k, j) += a[j][h - 1] * h * w * std::cos(x);
        ddq(k, j) -= a[j][h - 1] * h * h * w * w * std::sin(x);
      }
    }
}

TEST(Projection, NoiseFedBackThroughAPidLoopIsProjectedAway) {
  const Model model = load_robot("planar2");
  Eigen::VectorXd t;
  Eigen::MatrixXd q, dq, ddq;
  three_harmonics(t, q, dq, ddq);
  SimulateOptions o;
  o.plant.engine = PlantEngine::kNative;
  o.feed_forward = FeedForward::kNone;
  o.loop.periods = 12;
  o.loop.record_truth = true;
  const ClosedLoopResult clean = simulate_reference(model, t, q, dq, ddq, o);
  o.sensors.position_noise_std = 2e-3;
  o.sensors.torque_noise_std = 0.5;
  o.sensors.seed = 4;
  const ClosedLoopResult noisy = simulate_reference(model, t, q, dq, ddq, o);
  const long m = noisy.t.size();
  Eigen::MatrixXd dqr(m, 2), ddqr(m, 2);
  for (long k = 0; k < m; ++k) {
    dqr.row(k) = dq.row(k % t.size());
    ddqr.row(k) = ddq.row(k % t.size());
  }
  auto project = [&](const ClosedLoopResult& r, const ProjectionOptions& po) {
    JointRecord run{r.t, r.q, {}, {}, r.tau};
    return project_on_reference(run, r.qr, dqr, ddqr, po);
  };
  const ProjectionResult pn = project(noisy, {});
  ProjectionOptions same;
  same.m1 = pn.m1;
  same.m2 = pn.m2;
  const ProjectionResult pc = project(clean, same);
  const JointRecord& a = pn.processed.record;
  const JointRecord& b = pc.processed.record;
  const long first = pn.m2, len = a.t.size();
  std::printf("M1 = M2 = %d, test max |z| %.2f (bound %.2f)\n", pn.m1, pn.tests.back().max_z,
              pn.tests.back().threshold);
  for (int j = 0; j < 2; ++j) {
    const double tau_noise =
        rms(noisy.tau.col(j).segment(first, len) - clean.tau.col(j).segment(first, len));
    const double tau_left = rms(a.tau.col(j) - b.tau.col(j));
    const double q_noise =
        rms(noisy.q.col(j).segment(first, len) - clean.q.col(j).segment(first, len));
    const double q_left = rms(a.q.col(j) - b.q.col(j));
    // The projection keeps the reference's band (3 harmonics): its velocity is compared with the
    // noise-free run's projected velocity; the loss of the loop's higher harmonics is printed.
    const double dq_err = rms(a.dq.col(j) - b.dq.col(j));
    const double dq_band = rms(b.dq.col(j) - clean.dq_true.col(j).segment(first, len));
    // Velocity by central differences of the noisy positions, for comparison.
    Eigen::VectorXd dq_diff(len);
    for (long k = 0; k < len; ++k)
      dq_diff[k] = (noisy.q(first + k + 1, j) - noisy.q(first + k - 1, j)) / 0.01;
    const double dq_diff_err = rms(dq_diff - clean.dq_true.col(j).segment(first, len));
    std::printf(
        "joint %d: tau noise %.3g -> %.3g after projection; q noise %.3g -> %.3g; dq error "
        "%.3g (differencing: %.3g; noise-free projection vs true dq %.3g); corr %.2g\n",
        j + 1, tau_noise, tau_left, q_noise, q_left, dq_err, dq_diff_err, dq_band,
        pn.correlation[j]);
    EXPECT_LT(tau_left, 0.2 * tau_noise);
    EXPECT_LT(q_left, 0.2 * q_noise);
    EXPECT_LT(dq_err, 0.2 * dq_diff_err);
    // Orthogonal by construction up to the dropped rank-deficient directions (seed 2: 2.9e-14).
    EXPECT_LT(std::abs(pn.correlation[j]), 1e-6);
  }
}

TEST(Projection, BadInputIsAClearError) {
  const FirData d = fir_data(600, 3);
  EXPECT_EQ(
      testing::error_of([&] { project_on_reference(d.run, Eigen::MatrixXd(), d.dqr, d.ddqr); }),
      "projection needs the reference columns qr1..qr2 in the run: log the controller's "
      "reference (dynid simulate writes them)");
  Eigen::MatrixXd flat = d.qr;
  flat.setConstant(0.25);
  EXPECT_EQ(testing::error_of([&] { project_on_reference(d.run, flat, d.dqr, d.ddqr); }),
            "every reference qr1..qr2 is constant: the run excites nothing; move at least one "
            "joint");
  ProjectionOptions o;
  o.m1 = 50;
  o.m2 = 50;
  EXPECT_EQ(testing::error_of([&] { project_on_reference(d.run, d.qr, d.dqr, d.ddqr, o); }),
            "FIR orders M1 = 50, M2 = 50 need at least 912 samples (203 coefficients per signal, "
            "4 rows each, plus the 100 window samples), but the run has 600: use smaller orders "
            "or a longer run");
  o.m2 = -1;
  EXPECT_NE(testing::error_of([&] {
              project_on_reference(d.run, d.qr, d.dqr, d.ddqr, o);
            }).find("FIR orders must be both given"),
            std::string::npos);
  Eigen::MatrixXd bad = d.qr;
  bad(5, 0) = std::nan("");
  EXPECT_EQ(testing::error_of([&] { project_on_reference(d.run, bad, d.dqr, d.ddqr); }),
            "projection: qr contains NaN or Inf");
}

// A held joint (constant reference, seed 2's one-joint runs) is in the span of the FIR's constant:
// the FIR is fitted on the moving reference and recovers its taps as well as with both moving
// (within 0.03), the held reference's rows of the coefficients are zero, and the held joint's
// projected velocity and acceleration are zero.
TEST(Projection, HeldJointIsLeftOutOfTheFirAndTakenAsStill) {
  FirData d = fir_data(8000, 23);
  // Reference 2 held: it no longer drives the torques (its former contribution taken out).
  const long m = d.qr.rows();
  for (long t = 0; t < m; ++t)
    for (int j = 0; j < 2; ++j)
      for (int k = -3; k <= 10; ++k)
        if (t - k >= 0 && t - k < m) d.run.tau(t, j) -= tap(j, 1, k) * d.qr(t - k, 1);
  Eigen::MatrixXd qr = d.qr;
  qr.col(1).setConstant(0.25);
  const ProjectionResult p = project_on_reference(d.run, qr, d.dqr, d.ddqr);
  EXPECT_EQ(p.held_joints, std::vector<int>{1});
  EXPECT_TRUE(p.tests.back().passed);
  EXPECT_EQ(p.m1, 12);  // the taps of reference 1 reach lag 10, as with both moving
  const int w = p.m1 + p.m2 + 1;
  ASSERT_EQ(p.fir.rows(), 2 * w + 1);
  EXPECT_EQ(p.fir.middleRows(w, w).cwiseAbs().maxCoeff(), 0.0);
  for (int j = 0; j < 2; ++j)
    for (int k = -p.m1; k <= p.m2; ++k)
      EXPECT_NEAR(p.fir(k + p.m1, j), tap(j, 0, k), 0.03) << j << " " << k;
  EXPECT_EQ(p.processed.record.dq.col(1).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(p.processed.record.ddq.col(1).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(p.processed.record.dq.col(0).cwiseAbs().maxCoeff(), 0.0);
}

// The automatic order keeps every dimension a periodic reference spans (options.min_rank = 2L + 1,
// which prepare_closed_loop sets from the reference's lines): a 3-harmonic reference held by one
// joint spans 7, which M = 2 (5 lags and the constant) cannot keep even when its remainder passes.
TEST(Projection, AutomaticOrderKeepsTheDimensionsTheReferenceSpans) {
  Eigen::VectorXd t1;
  Eigen::MatrixXd q1, dq1, ddq1;
  three_harmonics(t1, q1, dq1, ddq1);
  const Eigen::Index period = t1.size(), m = 6 * period;
  JointRecord run;
  run.t = Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) * 0.005);
  Eigen::MatrixXd qr(m, 2), dqr(m, 2), ddqr(m, 2);
  for (Eigen::Index k = 0; k < m; ++k) {
    qr.row(k) << q1(k % period, 0), 0.3;
    dqr.row(k) << dq1(k % period, 0), 0.0;
    ddqr.row(k) << ddq1(k % period, 0), 0.0;
  }
  // Torque: a two-tap response to the reference plus white noise; position: the reference.
  std::mt19937_64 rng(29);
  std::normal_distribution<double> g(0.0, 0.05);
  run.tau.resize(m, 2);
  run.q = qr;
  for (Eigen::Index k = 0; k < m; ++k) {
    const double prev = k > 0 ? qr(k - 1, 0) : qr(m - 1, 0);
    run.tau.row(k) << 2.0 * qr(k, 0) - 0.5 * prev + g(rng), 0.4 * qr(k, 0) + g(rng);
  }
  const ProjectionResult free = project_on_reference(run, qr, dqr, ddqr);
  ProjectionOptions o;
  o.min_rank = 7;
  const ProjectionResult kept = project_on_reference(run, qr, dqr, ddqr, o);
  std::printf("without min_rank: M = %d, rank %d; with min_rank 7: M = %d, rank %d\n", free.m1,
              free.projector->rank(), kept.m1, kept.projector->rank());
  EXPECT_EQ(free.m1, 2);
  EXPECT_LT(free.projector->rank(), 7);
  EXPECT_GT(kept.m1, 2);
  EXPECT_EQ(kept.projector->rank(), 7);
  EXPECT_TRUE(kept.tests.back().passed);
  EXPECT_TRUE(kept.warnings.empty());
}

}  // namespace
}  // namespace dynid
