// Trajectory families: analytic derivatives against central finite differences of the position,
// boundary conditions, via-point interpolation and continuity, profile velocities/accelerations
// against their closed forms, and errors.
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/excitation/bang_bang_trajectory.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/joint_fourier.hpp"
#include "dynid/excitation/polynomial_spline.hpp"
#include "dynid/excitation/slope_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/excitation/trapezoidal_trajectory.hpp"

namespace dynid {
namespace {

struct State {
  Eigen::VectorXd q, dq, ddq;
};

State at(const Trajectory& tr, double t) {
  State s{Eigen::VectorXd(tr.dof()), Eigen::VectorXd(tr.dof()), Eigen::VectorXd(tr.dof())};
  tr.evaluate(t, s.q, s.dq, s.ddq);
  return s;
}

// Central differences (4th order) of q and dq: dq ≈ q', ddq ≈ dq'.
void expect_derivatives_match(const Trajectory& tr, double t, double h, double tol) {
  const State m2 = at(tr, t - 2 * h), m1 = at(tr, t - h), p1 = at(tr, t + h),
              p2 = at(tr, t + 2 * h), s = at(tr, t);
  const Eigen::VectorXd dq_fd = (m2.q - 8 * m1.q + 8 * p1.q - p2.q) / (12 * h);
  const Eigen::VectorXd ddq_fd = (m2.dq - 8 * m1.dq + 8 * p1.dq - p2.dq) / (12 * h);
  for (int j = 0; j < tr.dof(); ++j) {
    EXPECT_NEAR(s.dq[j], dq_fd[j], tol * (1 + std::abs(s.dq[j]))) << "t=" << t << " j=" << j;
    EXPECT_NEAR(s.ddq[j], ddq_fd[j], tol * (1 + std::abs(s.ddq[j]))) << "t=" << t << " j=" << j;
  }
}

FourierCoefficients random_fourier(unsigned seed, const std::vector<int>& harmonics, double f0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  FourierCoefficients c = FourierCoefficients::zeros(harmonics, f0);
  for (int i = 0; i < c.dof(); ++i) {
    for (Eigen::Index k = 0; k < c.a[i].size(); ++k) {
      c.a[i][k] = u(rng);
      c.b[i][k] = u(rng);
    }
    c.q0[i] = u(rng);
  }
  return c;
}

TEST(Fourier, DerivativesEqualFiniteDifferences) {
  const FourierTrajectory tr(random_fourier(1, {5, 3, 1}, 0.2));
  for (double t : {0.0, 0.37, 1.9, 4.2, 7.3}) expect_derivatives_match(tr, t, 1e-3, 1e-7);
}

TEST(Fourier, MatchesSeriesTermByTermAndIsPeriodic) {
  const FourierCoefficients c = random_fourier(2, {4, 2}, 0.25);
  const FourierTrajectory tr(c);
  const double w = 2 * M_PI * c.f0, t = 1.234;
  // Direct evaluation of eq. 17 with std::sin/cos per harmonic (no recurrence).
  for (int i = 0; i < 2; ++i) {
    double q = c.q0[i];
    for (int k = 1; k <= c.a[i].size(); ++k)
      q += c.a[i][k - 1] / (w * k) * std::sin(w * k * t) -
           c.b[i][k - 1] / (w * k) * std::cos(w * k * t);
    EXPECT_NEAR(at(tr, t).q[i], q, 1e-13);
  }
  EXPECT_DOUBLE_EQ(tr.period(), 4.0);
  EXPECT_NEAR((at(tr, t).q - at(tr, t + 3 * tr.period()).q).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.bandwidth(), 1.0);
}

TEST(Fourier, RestAtEndsProjectionGivesZeroVelocityAndAcceleration) {
  FourierCoefficients c = random_fourier(3, {5, 4, 2}, 0.1);
  const FourierCoefficients before = c;
  project_rest_at_ends(c);
  const FourierTrajectory tr(c);
  for (double t : {0.0, tr.period()}) {
    const State s = at(tr, t);
    EXPECT_LT(s.dq.norm(), 1e-12);
    EXPECT_LT(s.ddq.norm(), 1e-12);
  }
  EXPECT_NEAR((at(tr, 0).q - at(tr, tr.period()).q).norm(), 0.0, 1e-12);
  // Orthogonal projection: the removed part is orthogonal to the kept part, and projecting again
  // changes nothing.
  for (int i = 0; i < c.dof(); ++i) {
    EXPECT_NEAR((before.a[i] - c.a[i]).dot(c.a[i]), 0.0, 1e-12);
    EXPECT_NEAR((before.b[i] - c.b[i]).dot(c.b[i]), 0.0, 1e-12);
  }
  FourierCoefficients again = c;
  project_rest_at_ends(again);
  for (int i = 0; i < c.dof(); ++i) EXPECT_LT((again.a[i] - c.a[i]).norm(), 1e-15);
}

TEST(Fourier, Errors) {
  FourierCoefficients c = random_fourier(4, {2, 2}, 0.0);
  EXPECT_THROW(FourierTrajectory{c}, Error);  // zero f0
  c.f0 = 0.1;
  c.b[1].resize(3);
  EXPECT_THROW(FourierTrajectory{c}, Error);
  EXPECT_THROW(FourierCoefficients::zeros({2, 0}, 0.1), Error);
}

// One-joint Fourier reference (issue 14 item 1). Oracles: finite differences, a fine grid for the
// range, a direct DFT for the spectrum, and the Schroeder formula evaluated term by term.
TEST(JointFourier, MovesOnlyItsJointOverTheRangeAtRestAtTheEnds) {
  const Eigen::Vector3d pose(0.3, -0.2, 0.5);
  JointFourierOptions o;  // 5 harmonics at 0.1 Hz, at rest at the ends
  const FourierTrajectory tr(joint_fourier_reference(pose, 1, 0.7, -0.4, o));
  ASSERT_DOUBLE_EQ(tr.period(), 10.0);
  for (double t : {0.0, 0.37, 1.9, 4.2, 7.3, 9.99}) expect_derivatives_match(tr, t, 1e-3, 1e-7);
  for (double t : {0.0, tr.period()}) {
    EXPECT_LT(std::abs(at(tr, t).dq[1]), 1e-12);
    EXPECT_LT(std::abs(at(tr, t).ddq[1]), 1e-12);
  }
  const int m = 20000;
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i <= m; ++i) {
    const double t = tr.period() * i / m;
    const State s = at(tr, t);
    lo = std::min(lo, s.q[1]);
    hi = std::max(hi, s.q[1]);
    EXPECT_EQ(s.q[0], 0.3);  // the held joints are exactly at the pose, still
    EXPECT_EQ(s.q[2], 0.5);
    EXPECT_EQ(s.dq[0], 0.0);
    EXPECT_EQ(s.ddq[2], 0.0);
    if (i % 1000 == 0) {
      EXPECT_NEAR((s.q - at(tr, t + 2 * tr.period()).q).norm(), 0.0, 1e-12);
    }
  }
  // The fine grid reaches the range (to its spacing) and never leaves it (to round-off).
  EXPECT_NEAR(lo, -0.4, 1e-6);
  EXPECT_NEAR(hi, 0.7, 1e-6);
  EXPECT_GE(lo, -0.4 - 1e-12);
  EXPECT_LE(hi, 0.7 + 1e-12);
}

TEST(JointFourier, SpectrumHasLinesAtTheHarmonicsOnlyWithSchroederPhasesAndOneOverK) {
  const Eigen::Vector2d pose(0.0, 0.0);
  JointFourierOptions o;
  o.harmonics = 5;
  o.f0 = 0.2;
  o.rest_at_ends = false;
  const FourierTrajectory tr(joint_fourier_reference(pose, 0, -1.0, 0.5, o));
  // Direct DFT of one period of q1, N samples.
  const int n = 400;
  Eigen::VectorXd q(n);
  for (int i = 0; i < n; ++i) q[i] = at(tr, tr.period() * i / n).q[0];
  std::vector<double> amplitude(n / 2), phase(n / 2);
  for (int k = 0; k < n / 2; ++k) {
    double re = 0, im = 0;
    for (int i = 0; i < n; ++i) {
      re += q[i] * std::cos(2 * M_PI * k * i / n);
      im -= q[i] * std::sin(2 * M_PI * k * i / n);
    }
    amplitude[k] = 2 * std::hypot(re, im) / n;
    phase[k] = std::atan2(im, re);
  }
  const double g = amplitude[1];  // the gain on sin(wt)/1
  for (int k = 6; k < n / 2; ++k) EXPECT_LT(amplitude[k], 1e-12 * g) << "line at k = " << k;
  for (int k = 1; k <= 5; ++k) {
    EXPECT_NEAR(amplitude[k] * k, g, 1e-12 * g) << k;  // amplitudes g/k
    // sin(x + φ) = cos(x + φ − π/2): the DFT phase of line k is φ_k − π/2 (mod 2π).
    const double phi = -M_PI * k * (k - 1) / 5.0 - M_PI / 2;
    EXPECT_NEAR(std::remainder(phase[k] - phi, 2 * M_PI), 0.0, 1e-9) << k;
  }
  // The scaled series spans exactly the range: min and max from the same samples, refined.
  EXPECT_NEAR(q.minCoeff(), -1.0, 1e-3);
  EXPECT_NEAR(q.maxCoeff(), 0.5, 1e-3);
  EXPECT_LE(q.maxCoeff(), 0.5 + 1e-12);
}

TEST(JointFourier, Errors) {
  const Eigen::Vector2d pose(0.0, 0.0);
  EXPECT_THROW(joint_fourier_reference(pose, 2, -1.0, 1.0), Error);
  EXPECT_THROW(joint_fourier_reference(pose, -1, -1.0, 1.0), Error);
  EXPECT_THROW(joint_fourier_reference(pose, 0, 1.0, 1.0), Error);
  JointFourierOptions o;
  o.harmonics = 1;  // one harmonic at rest at both ends does not move
  EXPECT_THROW(joint_fourier_reference(pose, 0, -1.0, 1.0, o), Error);
  o.harmonics = 3;
  o.f0 = 0.0;
  EXPECT_THROW(joint_fourier_reference(pose, 0, -1.0, 1.0, o), Error);
}

TEST(Sampling, GridAndValues) {
  const FourierTrajectory tr(random_fourier(5, {3, 3}, 0.5));
  const TrajectorySamples s = sample_trajectory(tr, 10.0);  // period 2 s: 21 samples incl. end
  ASSERT_EQ(s.t.size(), 21);
  EXPECT_DOUBLE_EQ(s.t[20], 2.0);
  const TrajectorySamples p = sample_trajectory(tr, 10.0, false);
  ASSERT_EQ(p.t.size(), 20);
  const State st = at(tr, s.t[7]);
  EXPECT_EQ((s.q.row(7).transpose() - st.q).norm(), 0.0);
  EXPECT_EQ((s.ddq.row(7).transpose() - st.ddq).norm(), 0.0);
  EXPECT_THROW(sample_trajectory(tr, 0.0), Error);
  EXPECT_THROW(sample_trajectory(tr, std::nan("")), Error);
}

void check_spline(SplineOrder order, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd times(5);
  times << 0.0, 0.7, 1.5, 1.9, 3.0;
  Eigen::MatrixXd pts(2, 5);
  for (Eigen::Index i = 0; i < pts.size(); ++i) pts.data()[i] = u(rng);
  SplineOptions opt;
  opt.order = order;
  const PolynomialSpline sp(times, pts, opt);
  EXPECT_DOUBLE_EQ(sp.duration(), 3.0);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR((at(sp, times[k]).q - pts.col(k)).norm(), 0.0, 1e-12);
  // Rest at both ends.
  EXPECT_LT(at(sp, 0.0).dq.norm(), 1e-12);
  EXPECT_LT(at(sp, 3.0).dq.norm(), 1e-12);
  if (order == SplineOrder::kQuintic) {
    EXPECT_LT(at(sp, 0.0).ddq.norm(), 1e-12);
    EXPECT_LT(at(sp, 3.0).ddq.norm(), 1e-12);
  }
  // C2 at interior via-points: left and right limits of q, dq, ddq agree.
  const double e = 1e-9;
  for (int k = 1; k < 4; ++k) {
    const State l = at(sp, times[k] - e), r = at(sp, times[k] + e);
    EXPECT_NEAR((l.q - r.q).norm(), 0.0, 1e-7);
    EXPECT_NEAR((l.dq - r.dq).norm(), 0.0, 1e-6);
    EXPECT_NEAR((l.ddq - r.ddq).norm(), 0.0, 1e-5);
  }
  // Derivatives inside segments.
  for (double t : {0.3, 1.1, 1.7, 2.5}) expect_derivatives_match(sp, t, 1e-4, 1e-6);
}

TEST(Spline, CubicInterpolatesWithC2Continuity) {
  check_spline(SplineOrder::kCubic, 6);
}
TEST(Spline, QuinticInterpolatesWithC2Continuity) {
  check_spline(SplineOrder::kQuintic, 7);
}

TEST(Spline, QuinticHonoursGivenKnotVelocitiesAndAccelerations) {
  Eigen::VectorXd times(3);
  times << 0.0, 1.0, 2.5;
  Eigen::MatrixXd pts(1, 3), v(1, 3), a(1, 3);
  pts << 0.0, 1.0, -0.5;
  v << 0.0, 0.3, 0.0;
  a << 0.0, -2.0, 0.0;
  SplineOptions opt;
  opt.velocities = v;
  opt.accelerations = a;
  const PolynomialSpline sp(times, pts, opt);
  for (double t : {1.0 - 1e-10, 1.0 + 1e-10}) {
    EXPECT_NEAR(at(sp, t).dq[0], 0.3, 1e-8);
    EXPECT_NEAR(at(sp, t).ddq[0], -2.0, 1e-7);
  }
}

TEST(Spline, Errors) {
  Eigen::VectorXd times(3);
  times << 0.0, 1.0, 1.0;
  const Eigen::MatrixXd pts = Eigen::MatrixXd::Zero(2, 3);
  EXPECT_THROW(PolynomialSpline(times, pts), Error);  // not increasing
  times << 0.5, 1.0, 2.0;
  EXPECT_THROW(PolynomialSpline(times, pts), Error);  // does not start at 0
  times << 0.0, 1.0, 2.0;
  EXPECT_THROW(PolynomialSpline(times, Eigen::MatrixXd::Zero(2, 4)), Error);
  SplineOptions cubic;
  cubic.order = SplineOrder::kCubic;
  cubic.velocities = Eigen::MatrixXd::Zero(2, 3);
  EXPECT_THROW(PolynomialSpline(times, pts, cubic), Error);
}

TEST(Trapezoid, SlowestJointHitsVmaxAndAmaxOthersAreSynchronised) {
  Eigen::MatrixXd wp(2, 3);
  wp << 0.0, 2.0, 1.0,  //
      0.0, 0.5, 0.5;
  Eigen::Vector2d v(1.0, 1.0), a(2.0, 4.0);
  const TrapezoidalTrajectory tr(wp, v, a, 0.25);
  ASSERT_EQ(tr.moves().size(), 2u);
  // Move 1: joint 1 limits, T = D/v + v/a = 2 + 0.5 = 2.5 s.
  const Move& m = tr.moves()[0];
  EXPECT_NEAR(m.duration, 2.5, 1e-12);
  const State mid = at(tr, 1.25);
  EXPECT_NEAR(mid.dq[0], 1.0, 1e-12);           // cruise at v_max
  EXPECT_NEAR(at(tr, 0.1).ddq[0], 2.0, 1e-12);  // accelerating at a_max
  EXPECT_NEAR(at(tr, 2.4).ddq[0], -2.0, 1e-12);
  // Joint 2 covers 0.5 in the same 2.5 s with its a_max: v solves 0.5 = v(2.5 − v/4).
  const double v2 = mid.dq[1];
  EXPECT_NEAR(v2 * (2.5 - v2 / 4.0), 0.5, 1e-12);
  EXPECT_NEAR(at(tr, 0.01).ddq[1], 4.0, 1e-12);
  // Arrives at the way-points at rest; dwell holds them.
  EXPECT_NEAR((at(tr, 2.5).q - wp.col(1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((at(tr, 2.6).q - wp.col(1)).norm(), 0.0, 1e-12);
  EXPECT_EQ(at(tr, 2.6).dq.norm(), 0.0);
  EXPECT_NEAR((at(tr, tr.duration()).q - wp.col(2)).norm(), 0.0, 1e-12);
  // Velocity is the integral of acceleration: finite differences inside the phases.
  for (double t : {0.2, 1.0, 2.3, 3.0, 4.0}) expect_derivatives_match(tr, t, 1e-5, 1e-6);
}

TEST(Trapezoid, ErrorsWhenVmaxCannotBeReached) {
  Eigen::MatrixXd wp(1, 2);
  wp << 0.0, 0.1;
  EXPECT_THROW(TrapezoidalTrajectory(wp, Eigen::VectorXd::Constant(1, 1.0),
                                     Eigen::VectorXd::Constant(1, 1.0)),
               Error);  // needs D >= v²/a = 1
  EXPECT_THROW(TrapezoidalTrajectory(wp, Eigen::VectorXd::Constant(1, 0.0),
                                     Eigen::VectorXd::Constant(1, 1.0)),
               Error);
  Eigen::MatrixXd same(1, 2);
  same << 0.3, 0.3;
  EXPECT_THROW(TrapezoidalTrajectory(same, Eigen::VectorXd::Constant(1, 0.1),
                                     Eigen::VectorXd::Constant(1, 1.0)),
               Error);
}

TEST(BangBang, AccelerationSwitchesSignAtHalfTime) {
  Eigen::MatrixXd wp(2, 3);
  wp << 0.0, 1.0, 0.0,  //
      0.0, -0.25, 0.0;
  const BangBangTrajectory tr(wp, Eigen::Vector2d(4.0, 4.0));
  // Joint 1 limits: T = 2 sqrt(1/4) = 1 s, peak speed a·T/2 = 2 rad/s at t = 0.5.
  EXPECT_NEAR(tr.moves()[0].duration, 1.0, 1e-12);
  EXPECT_NEAR(at(tr, 0.25).ddq[0], 4.0, 1e-12);
  EXPECT_NEAR(at(tr, 0.75).ddq[0], -4.0, 1e-12);
  EXPECT_NEAR(at(tr, 0.5).dq[0], 2.0, 1e-12);
  // Joint 2: 4|D|/T² = 1 rad/s², opposite sign.
  EXPECT_NEAR(at(tr, 0.25).ddq[1], -1.0, 1e-12);
  EXPECT_NEAR((at(tr, 1.0).q - wp.col(1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(at(tr, 1.5).dq[0], -2.0, 1e-12);  // back
  EXPECT_NEAR((at(tr, 2.0).q - wp.col(2)).norm(), 0.0, 1e-12);
  EXPECT_THROW(BangBangTrajectory(wp, Eigen::Vector2d(4.0, -1.0)), Error);
}

TEST(Slope, ConstantVelocityBothDirections) {
  const SlopeTrajectory tr(Eigen::Vector2d(-1.0, 0.0), Eigen::Vector2d(1.0, 0.0),
                           Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(1.0, 1.0), 2, 0.5);
  const auto iv = tr.constant_velocity_intervals();
  ASSERT_EQ(iv.size(), 4u);
  for (size_t i = 0; i < iv.size(); ++i) {
    const double sign = i % 2 == 0 ? 1.0 : -1.0;
    EXPECT_NEAR(iv[i].second - iv[i].first, 2.0 / 0.5 - 0.5 / 1.0, 1e-12);  // D/v − v/a
    for (int k = 0; k <= 10; ++k) {
      const State s = at(tr, iv[i].first + (iv[i].second - iv[i].first) * k / 10.0);
      EXPECT_NEAR(s.dq[0], sign * 0.5, 1e-12);
      EXPECT_NEAR(s.ddq[0], 0.0, 1e-12);
      EXPECT_EQ(s.dq[1], 0.0);
    }
  }
  EXPECT_NEAR((at(tr, tr.duration()).q - Eigen::Vector2d(-1.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_THROW(SlopeTrajectory(Eigen::Vector2d(0, 0), Eigen::Vector2d(0.1, 0),
                               Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1)),
               Error);
  EXPECT_THROW(SlopeTrajectory(Eigen::Vector2d(0, 0), Eigen::Vector2d(2, 0),
                               Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(1, 1), 0),
               Error);
}

}  // namespace
}  // namespace dynid
