// Closed-loop identification through identify() (issue 13): a plain PID loop on the native RK4
// plant (forward dynamics, not the regressor; tanh-smoothed Coulomb friction) with encoder and
// torque noise fed back through the controller, fixed seeds. Oracles: the model's own parameters
// (the truth the plant ran with), Table 3's t ratio from Boost's Student-t (seed 2's printed
// 0.6795), and an explicit projection of a hand-made signal.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/closed_loop/closed_loop.hpp"
#include "dynid/closed_loop/maximum_likelihood.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/model/robots.hpp"
#include "support/closed_loop_runs.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

constexpr double kRate = 100.0;

struct ClosedRun {
  JointRecord run;
  ReferenceRecord reference;
};

// Plain PID (no feed-forward), noise fed back, `periods` periods after a dropped start-up one, on
// the reference `c`.
ClosedRun plain_pid_run_of(const Model& m, const FourierCoefficients& c, unsigned seed, int periods,
                           double q_noise, double tau_noise) {
  const TrajectorySamples tr = sample_trajectory(FourierTrajectory(c), kRate, false);
  SimulateOptions so = testing::noisy_sensors(q_noise, tau_noise, seed, periods + 1);
  so.feed_forward = FeedForward::kNone;
  so.plant.engine = PlantEngine::kNative;
  const ClosedLoopResult r = simulate_reference(m, tr.t, tr.q, tr.dq, tr.ddq, so);
  const Eigen::Index skip = tr.t.size(), rows = r.t.size() - skip;
  ClosedRun out;
  out.run = {r.t.tail(rows), r.q.bottomRows(rows), {}, {}, r.tau.bottomRows(rows)};
  out.reference.qr = r.qr.bottomRows(rows);
  return out;
}

// The planar2 test reference truncated to its first `harmonics` (≤ 4).
ClosedRun plain_pid_run_harmonics(const Model& m, unsigned seed, int periods, int harmonics,
                                  double q_noise, double tau_noise) {
  FourierCoefficients c = testing::planar2_reference();
  for (int j = 0; j < 2; ++j) {
    for (int h = harmonics; h < 4; ++h) c.a[static_cast<size_t>(j)][h] = 0.0;
    for (int h = harmonics; h < 4; ++h) c.b[static_cast<size_t>(j)][h] = 0.0;
  }
  return plain_pid_run_of(m, c, seed, periods, q_noise, tau_noise);
}

ClosedRun plain_pid_run(const Model& m, unsigned seed, int periods, double q_noise,
                        double tau_noise) {
  return plain_pid_run_harmonics(m, seed, periods, 4, q_noise, tau_noise);
}

IdentifyOptions closed_options(ClosedLoopMethod method) {
  IdentifyOptions o;
  o.layout.armature = true;
  o.layout.viscous = true;
  o.layout.coulomb = true;
  o.layout.offset = true;
  o.closed_loop.method = method;
  o.signal.torque_time_offset = 0.5 / kRate;  // the command is held over the next step
  return o;
}

Eigen::VectorXd truth_of(const Model& m, const IdentificationResult& r,
                         const ParameterLayout& layout) {
  const Eigen::VectorXd theta_b = r.base.reduce(layout.parameters(m));
  Eigen::VectorXd out(static_cast<Eigen::Index>(r.names.size()));
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto it = std::find(r.base.names.begin(), r.base.names.end(), r.names[i]);
    out[static_cast<Eigen::Index>(i)] = theta_b[it - r.base.names.begin()];
  }
  return out;
}

// Direct OLS on the filtered closed-loop run is biased by the noise fed back; the projection and
// spectral preparations are not, with OLS or with maximum likelihood on the projected signals
// (noise of the projected signals from the remainders), and their intervals hold the truth.
TEST(ClosedLoopIdentification, ProjectionAndSpectralRemoveTheBiasOfDirectOls) {
  const Model m = testing::planar2_with_friction();
  constexpr int kSeeds = 4;
  constexpr int kMethods = 5;
  const char* label[kMethods] = {"direct", "projection", "spectral", "projection+ml",
                                 "spectral+ml"};
  Eigen::MatrixXd mean_z;
  int outside[kMethods] = {0, 0, 0, 0, 0}, total = 0;
  std::vector<std::string> names;
  for (int s = 0; s < kSeeds; ++s) {
    const ClosedRun c = plain_pid_run(m, 300 + s, 6, 2e-3, 0.3);
    for (int k = 0; k < kMethods; ++k) {
      const ClosedLoopMethod method =
          k == 0 ? ClosedLoopMethod::kNone
                 : (k % 2 == 1 ? ClosedLoopMethod::kProjection : ClosedLoopMethod::kSpectral);
      IdentifyOptions o = closed_options(method);
      if (k >= 3) o.estimator = IdentificationEstimator::kMl;
      const IdentificationResult r =
          k == 0 ? identify(m, c.run, o) : identify(m, {c.run}, {c.reference}, o);
      const Eigen::VectorXd truth = truth_of(m, r, o.layout);
      if (mean_z.size() == 0) {
        mean_z = Eigen::MatrixXd::Zero(truth.size(), kMethods);
        names = r.names;
      }
      ASSERT_EQ(r.names, names);
      const Eigen::VectorXd z = (r.estimate.x - truth).cwiseQuotient(r.estimate.std_dev);
      mean_z.col(k) += z / kSeeds;
      for (Eigen::Index i = 0; i < truth.size(); ++i)
        outside[k] += truth[i] < r.estimate.ci_lower[i] || truth[i] > r.estimate.ci_upper[i];
      if (k == 0) total += static_cast<int>(truth.size());
      for (const std::string& w : r.warnings)  // the channel-clustered widening, if any
        if (k > 0 && w.find("disagree") != std::string::npos)
          std::printf("seed %d %s: %s\n", s, label[k], w.c_str());
      if (s == 0 && k > 0) {
        ASSERT_EQ(r.closed_loop.size(), 1u);
        std::printf("%s: rank %d per channel, M1 = %d, dof %ld\n", label[k], r.closed_loop[0].rank,
                    r.closed_loop[0].m1, static_cast<long>(r.estimate.degrees_of_freedom));
      }
    }
  }
  for (Eigen::Index i = 0; i < mean_z.rows(); ++i)
    std::printf(
        "%-6s mean z: direct %7.2f  projection %6.2f  spectral %6.2f  projection+ml %6.2f  "
        "spectral+ml %6.2f\n",
        names[static_cast<size_t>(i)].c_str(), mean_z(i, 0), mean_z(i, 1), mean_z(i, 2),
        mean_z(i, 3), mean_z(i, 4));
  std::printf(
      "truths outside the 99.9 %% intervals: direct %d, projection %d, spectral %d, "
      "projection+ml %d, spectral+ml %d of %d\n",
      outside[0], outside[1], outside[2], outside[3], outside[4], total);
  // Direct OLS: several parameters biased by more than 3 of their own σ (ZZ1R by about 15).
  int direct_biased = 0;
  for (Eigen::Index i = 0; i < mean_z.rows(); ++i) direct_biased += std::abs(mean_z(i, 0)) > 3.0;
  EXPECT_GE(direct_biased, 5);
  EXPECT_LT(mean_z(0, 0), -10.0);  // ZZ1R
  // Projection and spectral: no rigid-body parameter biased by 3 σ (a mean of 4 seeds spreads by
  // 0.5). The shoulder's Fv1 and Fc1 stay biased by about 4 σ: the preparation keeps only the
  // reference's 4 harmonics, so sign(q̂') switches where the band-limited velocity does, not the
  // loop's; a noise-free run shows the same offsets (docs/methods/closed_loop.md).
  for (int k = 1; k < kMethods; ++k)
    for (Eigen::Index i = 0; i < mean_z.rows(); ++i)
      if (names[static_cast<size_t>(i)].rfind("F", 0) != 0 &&
          names[static_cast<size_t>(i)].rfind("Ia", 0) != 0) {
        EXPECT_LT(std::abs(mean_z(i, k)), 3.0) << label[k] << " " << names[static_cast<size_t>(i)];
      }
  // Every truth inside the 99.9 % intervals (degrees of freedom counted on the projection).
  EXPECT_LE(outside[1], 1);
  EXPECT_LE(outside[2], 1);
  EXPECT_LE(outside[3], 1);
  EXPECT_LE(outside[4], 1);
  EXPECT_GE(outside[0], 10);
}

TEST(ClosedLoopIdentification, RepeatedStatisticIsSeedTwoTableThree) {
  // Seed 2 Table 3: n = 30 estimates, ratio t_0.9995(29)/sqrt(29) = 0.6795 on every row.
  std::vector<std::pair<std::vector<std::string>, Eigen::VectorXd>> est;
  for (int i = 0; i < 30; ++i)
    est.emplace_back(std::vector<std::string>{"a", "b"},
                     Eigen::Vector2d(1.0 + (i % 2 ? 0.1 : -0.1), 2.0));
  const RepeatedEstimate r = repeated_statistics(est, 0.999);
  ASSERT_EQ(r.n, 30);
  EXPECT_NEAR(r.mean[0], 1.0, 1e-12);
  // Alternating ±0.1 over 30: std = 0.1·sqrt(30/29).
  EXPECT_NEAR(r.std_dev[0], 0.1 * std::sqrt(30.0 / 29.0), 1e-12);
  EXPECT_NEAR(r.ci_half_width[0] / r.std_dev[0], 0.6795, 5e-5);
  EXPECT_EQ(r.std_dev[1], 0.0);
  est.resize(1);
  EXPECT_EQ(testing::error_of([&] { repeated_statistics(est, 0.999); }),
            "the repeated statistic needs at least 2 estimates, got 1: give more periods or runs");
}

// The noise of spectrally projected signals (maximum likelihood after a projection): white noise
// of unit std through the Fourier fit of harmonics 0…H over N samples has variance (2H + 1)/N, and
// its analytic derivatives 2ω²Σh²/N and 2ω⁴Σh⁴/N (h = 1…H), the closed forms projected_noise()
// must reproduce from the projector alone (basis by random projection, central differences).
TEST(ClosedLoopIdentification, ProjectedNoiseMatchesTheSpectralClosedForm) {
  const Model m = testing::planar2_with_friction();
  const ClosedRun c = plain_pid_run(m, 3, 3, 1e-3, 0.1);
  ClosedLoopIdOptions co;
  co.method = ClosedLoopMethod::kSpectral;
  std::vector<std::pair<std::string, std::string>> choices;
  const ClosedLoopRun cl = prepare_closed_loop(c.run, c.reference, co, choices);
  SensorNoise unit;
  unit.q = unit.tau = Eigen::Vector2d::Ones();
  std::string how;
  const MeasurementNoise noise =
      projected_noise(unit, *cl.projector, 1.0 / kRate, cl.processed, cl.torque_remainder_std, how);
  const int H = cl.report.spectrum.band_harmonic;
  const double N = static_cast<double>(cl.projector->samples());
  const double w = 2.0 * M_PI * cl.report.spectrum.f0_hz;
  double h2 = 0.0, h4 = 0.0;
  for (int h = 1; h <= H; ++h) {
    h2 += h * h;
    h4 += std::pow(h, 4);
  }
  ASSERT_EQ(H, 4);
  EXPECT_NEAR(noise.q[0], std::sqrt((2.0 * H + 1.0) / N), 1e-9);
  EXPECT_NEAR(noise.tau[1], std::sqrt((2.0 * H + 1.0) / N), 1e-9);
  const double g1 = std::sqrt(2.0 * w * w * h2 / N), g2 = std::sqrt(2.0 * std::pow(w, 4) * h4 / N);
  EXPECT_NEAR(noise.dq[0] / g1, 1.0, 1e-3);
  EXPECT_NEAR(noise.ddq[1] / g2, 1.0, 1e-3);
}

// A logged reference with a jitter of 2e-6 rad does not repeat exactly, so the period cannot be
// detected; given (--period / --f0), it is checked against qr and the spectral preparation runs.
// Its Fourier basis depends only on the period and the band, so the estimate equals the one from
// the exact reference. Inconsistent periods are refused.
TEST(ClosedLoopIdentification, SpectralTakesAGivenPeriod) {
  const Model m = testing::planar2_with_friction();
  const ClosedRun c = plain_pid_run(m, 7, 3, 1e-3, 0.1);
  IdentifyOptions o = closed_options(ClosedLoopMethod::kSpectral);
  const IdentificationResult exact = identify(m, {c.run}, {c.reference}, o);
  ReferenceRecord jittered = c.reference;
  for (Eigen::Index k = 0; k < jittered.qr.rows(); ++k)
    for (Eigen::Index j = 0; j < jittered.qr.cols(); ++j)
      jittered.qr(k, j) += 2e-6 * std::sin(1.7 * static_cast<double>(k) + static_cast<double>(j));
  EXPECT_NE(
      testing::error_of([&] { identify(m, {c.run}, {jittered}, o); }).find("qr does not repeat"),
      std::string::npos);
  const double period = 1.0 / testing::planar2_reference().f0;  // 5 s, 500 samples
  o.closed_loop.period = period;
  const IdentificationResult given = identify(m, {c.run}, {jittered}, o);
  ASSERT_EQ(given.names, exact.names);
  for (Eigen::Index i = 0; i < exact.estimate.x.size(); ++i)
    EXPECT_NEAR(given.estimate.x[i], exact.estimate.x[i],
                1e-9 * (1 + std::abs(exact.estimate.x[i])))
        << exact.names[static_cast<size_t>(i)];
  EXPECT_EQ(given.closed_loop.front().spectrum.period_samples, 500);
  o.closed_loop.period = period + 0.005;  // 500.5 samples
  EXPECT_EQ(testing::error_of([&] { identify(m, {c.run}, {jittered}, o); }),
            "--period 5.005 s is 500.5 samples at this run's sampling interval 0.01 s; the "
            "spectral lines need a whole number of samples per period: check --period/--f0 or "
            "resample the run");
  o.closed_loop.period = 4.0;
  EXPECT_NE(testing::error_of([&] {
              identify(m, {c.run}, {jittered}, o);
            }).find("qr1 does not repeat with --period 4 s"),
            std::string::npos);
  o.closed_loop.period = 2.0 * period;  // 1000 samples of a 1500-sample run
  EXPECT_EQ(testing::error_of([&] { identify(m, {c.run}, {jittered}, o); }),
            "--period 10 s (1000 samples) leaves fewer than two whole periods in the run's 1500 "
            "samples: check --period/--f0 or record more periods");
}

TEST(ClosedLoopIdentification, BadReferencesAreClearErrors) {
  const Model m = testing::planar2_with_friction();
  ClosedRun c = plain_pid_run(m, 1, 2, 0.0, 0.0);
  const IdentifyOptions o = closed_options(ClosedLoopMethod::kProjection);
  EXPECT_EQ(testing::error_of([&] { identify(m, {c.run}, {ReferenceRecord{}}, o); }),
            "closed-loop identification needs the reference columns qr1..qr2 in the run: log the "
            "controller's reference (dynid simulate writes them)");
  ReferenceRecord flat = c.reference;
  flat.qr.setConstant(0.5);  // one held joint is a one-joint run; all held is nothing
  EXPECT_EQ(testing::error_of([&] { identify(m, {c.run}, {flat}, o); }),
            "every reference qr1..qr2 is constant: the run excites nothing; move at least one "
            "joint");
  ReferenceRecord drifting = c.reference;
  for (Eigen::Index k = 0; k < drifting.qr.rows(); ++k) drifting.qr(k, 0) += 1e-3 * k;
  EXPECT_EQ(testing::error_of([&] {
              identify(m, {c.run}, {drifting}, closed_options(ClosedLoopMethod::kSpectral));
            }),
            "--closed-loop spectral needs a periodic reference sampled a whole number of times "
            "per period, with at least two periods: qr does not repeat; use --closed-loop "
            "projection");
}

// Issue 25 item 3: a reference whose harmonics span no more projected dimensions than the model
// has parameters (2 harmonics: 5 per channel, 10 in all, for 11) left no degrees of freedom in the
// projected residual, and identify refused. The estimate exists; its intervals now take the
// noise from the torque remainder outside the projected span (interval_source
// "torque_remainder"). Over 3 seeds and both methods on the native RK4 plant (not the regressor)
// the truth lies inside the 99.9 % intervals and the errors spread by 1.04 σ (rms z): intervals
// of the right size. The plant has no friction here: with tanh Coulomb friction in the plant the
// same runs put MX2 about 3 σ off on every seed alike (a bias, not noise: the band-limited sign of
// the projected velocity, docs/methods/closed_loop.md), which no noise estimate can see when the
// projected equations are fitted exactly.
TEST(ClosedLoopIdentification, NoIntervalDegreesOfFreedomLeftStillGivesAnEstimate) {
  const Model m = load_robot("planar2");
  int outside = 0, total = 0;
  double z2 = 0.0;
  for (const ClosedLoopMethod method :
       {ClosedLoopMethod::kProjection, ClosedLoopMethod::kSpectral}) {
    for (unsigned seed : {410u, 411u, 412u}) {
      const ClosedRun c = plain_pid_run_harmonics(m, seed, 3, 2, 2e-3, 0.3);
      IdentifyOptions o = closed_options(method);
      o.layout.coulomb = false;
      const IdentificationResult r = identify(m, {c.run}, {c.reference}, o);
      ASSERT_EQ(r.closed_loop.size(), 1u);
      const Eigen::Index dims = 2 * r.closed_loop[0].rank;
      ASSERT_LE(dims, r.data_rank) << "the case needs no spare projected dimension";
      EXPECT_EQ(r.interval_source, "torque_remainder");
      EXPECT_TRUE(r.estimate.std_dev.allFinite());
      EXPECT_GT(r.estimate.std_dev.minCoeff(), 0.0);
      bool warned = false;
      for (const std::string& w : r.warnings)
        warned |= w.find("torque remainder") != std::string::npos;
      EXPECT_TRUE(warned);
      // What the estimates stand for: their base parameters plus the data regrouping of the
      // ones these two harmonics leave undetermined.
      const Eigen::VectorXd theta_b = r.base.reduce(o.layout.parameters(m));
      const auto base_value = [&](const std::string& name) {
        return theta_b[std::find(r.base.names.begin(), r.base.names.end(), name) -
                       r.base.names.begin()];
      };
      Eigen::VectorXd truth = truth_of(m, r, o.layout);
      Eigen::VectorXd missing(static_cast<Eigen::Index>(r.not_excited.size()));
      for (size_t u = 0; u < r.not_excited.size(); ++u)
        missing[static_cast<Eigen::Index>(u)] = base_value(r.not_excited[u]);
      if (missing.size() > 0) truth += r.data_regrouping * missing;
      for (Eigen::Index i = 0; i < truth.size(); ++i) {
        const bool out = truth[i] < r.estimate.ci_lower[i] || truth[i] > r.estimate.ci_upper[i];
        outside += out;
        const double z = (r.estimate.x[i] - truth[i]) / r.estimate.std_dev[i];
        z2 += z * z;
        if (out)
          std::printf("seed %u: %s %.4g outside [%.4g, %.4g]\n", seed,
                      r.names[static_cast<size_t>(i)].c_str(), truth[i], r.estimate.ci_lower[i],
                      r.estimate.ci_upper[i]);
      }
      total += static_cast<int>(truth.size());
    }
  }
  const double rms_z = std::sqrt(z2 / total);
  std::printf(
      "no interval degrees of freedom: %d of %d truths outside the 99.9 %% intervals, rms z %.3f\n",
      outside, total, rms_z);
  EXPECT_LE(outside, 2);
  // Intervals of the right size, not merely wide: the errors in units of σ spread by about 1.
  EXPECT_GT(rms_z, 0.4);
  EXPECT_LT(rms_z, 2.0);
}

// Seed 2 section 3 moves one joint at a time, the others held by their controllers (constant
// references). planar2 with viscous friction and offsets (no Coulomb friction in the plant: its
// band-limited sign biases Fv1 and Fc1 on every run alike, see the first test), joint 1 on the
// 4-harmonic test reference, joint 2 held at 0.8 rad, 4 periods under a plain PID.
Model one_joint_plant() {
  Model m = load_robot("planar2");
  m.joints[0].friction.Fv = 1.5;
  m.joints[0].friction.Fo = 0.3;
  m.joints[1].friction.Fv = 0.8;
  m.joints[1].friction.Fo = -0.2;
  return m;
}

ClosedRun one_joint_run(const Model& m, unsigned seed, int periods) {
  FourierCoefficients c = testing::planar2_reference();
  c.a[1].setZero();
  c.b[1].setZero();
  return plain_pid_run_of(m, c, seed, periods, 1e-3, 0.1);
}

IdentifyOptions one_joint_options(ClosedLoopMethod method) {
  IdentifyOptions o = closed_options(method);
  o.layout.coulomb = false;
  return o;
}

// What each estimate stands for on these data (its base parameter plus the data regrouping of
// the ones the run does not excite), from the plant's own parameters.
Eigen::VectorXd standing_truth(const Model& m, const IdentificationResult& r,
                               const ParameterLayout& layout) {
  return estimated_base_values(r, r.base.reduce(layout.parameters(m)));
}

// Issue 28 item 3: the projection method on a one-joint run, as seed 2 applies it (only the
// spectral variant accepted one; the projection refused "reference qr2 is constant"). The FIR is
// fitted on the moving reference; its automatic order keeps the 9 dimensions a 4-harmonic
// reference spans (M = 2 kept 7); the held joint is taken as still. Both methods recover what the
// run excites, the plant's truth inside the 99.9 % intervals.
TEST(ClosedLoopIdentification, OneJointRunsByProjectionAndSpectralLines) {
  const Model m = one_joint_plant();
  const ClosedRun c = one_joint_run(m, 41, 4);
  ASSERT_EQ(c.reference.qr.col(1).maxCoeff(), c.reference.qr.col(1).minCoeff());
  for (const ClosedLoopMethod method :
       {ClosedLoopMethod::kProjection, ClosedLoopMethod::kSpectral}) {
    const IdentifyOptions o = one_joint_options(method);
    const IdentificationResult r = identify(m, {c.run}, {c.reference}, o);
    ASSERT_EQ(r.closed_loop.size(), 1u);
    const ClosedLoopReport& rep = r.closed_loop[0];
    EXPECT_EQ(rep.held_joints, std::vector<int>{1});
    EXPECT_EQ(rep.rank, 9);  // 2·4 lines + the constant, per channel
    if (method == ClosedLoopMethod::kProjection) {
      EXPECT_EQ(rep.reference_dimensions, 9);
      EXPECT_TRUE(rep.test_passed);
    }
    EXPECT_FALSE(r.not_excited.empty());  // link 2's own parameters, joint 2's friction
    const Eigen::VectorXd truth = standing_truth(m, r, o.layout);
    int outside = 0;
    for (Eigen::Index i = 0; i < truth.size(); ++i) {
      const bool out = truth[i] < r.estimate.ci_lower[i] || truth[i] > r.estimate.ci_upper[i];
      outside += out;
      std::printf("%s %-6s %9.4g truth %9.4g  [%9.4g, %9.4g]%s\n",
                  method == ClosedLoopMethod::kProjection ? "projection" : "spectral  ",
                  r.names[static_cast<size_t>(i)].c_str(), r.estimate.x[i], truth[i],
                  r.estimate.ci_lower[i], r.estimate.ci_upper[i], out ? "  OUTSIDE" : "");
    }
    EXPECT_EQ(outside, 0);
  }
}

// Issue 28 item 2: Table 3's repeated statistic on a one-joint run (it was refused, "reference qr2
// is constant ... excite every joint", and only after the whole-run estimate). Every period is
// identified alone. Oracles: the plant's truth lies inside the whole run's intervals; spectral:
// least squares on the same lines of every period makes the whole-run estimate the mean of the
// per-period ones, so they agree within Table 3's half-width; projection (its one-period FIR
// windows lose their ends): the mean lies within the whole run's half-width of the truth. Table 3
// measures repeatability only: a model error common to every period (the held joint moves by its
// tracking error while the equations take it as still) shifts every period alike (ZZ1R: 2.52 on
// every period for 2.17), which no spread over periods can show. The request's checks run in
// repeated_pieces(), before any estimate.
TEST(ClosedLoopIdentification, RepeatedPeriodsOfAOneJointRun) {
  const Model m = one_joint_plant();
  const ClosedRun c = one_joint_run(m, 43, 4);
  for (const ClosedLoopMethod method :
       {ClosedLoopMethod::kSpectral, ClosedLoopMethod::kProjection}) {
    const IdentifyOptions o = one_joint_options(method);
    const RepeatedPieces pieces = repeated_pieces({c.run}, {c.reference}, o, RepeatOver::kPeriods);
    ASSERT_EQ(pieces.runs.size(), 4u);
    ASSERT_EQ(pieces.references.size(), 4u);
    const RepeatedEstimate rep = identify_repeated(m, pieces, o);
    EXPECT_EQ(rep.n, 4);
    ASSERT_FALSE(rep.names.empty());
    const IdentificationResult whole = identify(m, {c.run}, {c.reference}, o);
    const Eigen::VectorXd truth = standing_truth(m, whole, o.layout);
    int compared = 0;
    for (size_t i = 0; i < rep.names.size(); ++i) {
      const auto at = std::find(whole.names.begin(), whole.names.end(), rep.names[i]);
      if (at == whole.names.end()) continue;  // determined on one period, not on the whole run
      const auto w = at - whole.names.begin();
      const auto k = static_cast<Eigen::Index>(i);
      ++compared;
      std::printf("%s %-5s periods %8.4g ± %-8.3g whole run %8.4g [%8.4g, %8.4g] truth %8.4g\n",
                  method == ClosedLoopMethod::kProjection ? "projection" : "spectral  ",
                  rep.names[i].c_str(), rep.mean[k], rep.ci_half_width[k], whole.estimate.x[w],
                  whole.estimate.ci_lower[w], whole.estimate.ci_upper[w], truth[w]);
      if (method == ClosedLoopMethod::kSpectral) {
        EXPECT_LE(std::abs(rep.mean[k] - whole.estimate.x[w]), rep.ci_half_width[k])
            << rep.names[i];
      } else {
        // The FIR window of one period loses M samples at each end, so the periods are not the
        // whole run cut in four: their mean is another estimate, as uncertain as the whole run's.
        const double half = 0.5 * (whole.estimate.ci_upper[w] - whole.estimate.ci_lower[w]);
        EXPECT_LE(std::abs(rep.mean[k] - truth[w]), half) << rep.names[i];
      }
      EXPECT_GE(truth[w], whole.estimate.ci_lower[w]) << rep.names[i];
      EXPECT_LE(truth[w], whole.estimate.ci_upper[w]) << rep.names[i];
    }
    EXPECT_GE(compared, 5);
  }
  // A reference that does not repeat is refused by the plan, with the repeat's own message.
  ReferenceRecord drifting = c.reference;
  for (Eigen::Index k = 0; k < drifting.qr.rows(); ++k) drifting.qr(k, 0) += 1e-3 * k;
  EXPECT_EQ(testing::error_of([&] {
              repeated_pieces({c.run}, {drifting}, one_joint_options(ClosedLoopMethod::kSpectral),
                              RepeatOver::kPeriods);
            }),
            "--repeat periods needs a periodic reference with at least two periods in the run: qr "
            "does not repeat (run 1)");
}

}  // namespace
}  // namespace dynid
