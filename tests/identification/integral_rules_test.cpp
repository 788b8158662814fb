// Quadrature rules of the integral model (signal/integration.hpp): each is exact for the
// polynomial order it claims and not beyond (oracle: the antiderivative in closed form).
#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/signal/integration.hpp"

namespace dynid {
namespace {

// Polynomial with coefficients c (c[0] + c[1]·t + …) and its exact integral over [a, b].
double poly(const std::vector<double>& c, double t) {
  double s = 0.0;
  for (size_t k = c.size(); k-- > 0;) s = s * t + c[k];
  return s;
}
double poly_integral(const std::vector<double>& c, double a, double b) {
  double s = 0.0;
  for (size_t k = 0; k < c.size(); ++k)
    s += c[k] * (std::pow(b, k + 1) - std::pow(a, k + 1)) / (k + 1);
  return s;
}

Eigen::VectorXd sampled(const std::vector<double>& c, const Eigen::VectorXd& t) {
  Eigen::VectorXd f(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) f[i] = poly(c, t[i]);
  return f;
}

const std::vector<double> kCubic = {0.3, -1.2, 2.5, 4.0};
const std::vector<double> kQuadratic = {0.3, -1.2, 2.5};
const std::vector<double> kQuartic = {0.3, -1.2, 2.5, 4.0, -3.0};

TEST(IntegrationRule, SimpsonIsExactForCubicsOnUniformEvenSteps) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(11, 0.1, 0.6);
  const double exact = poly_integral(kCubic, t[2], t[10]);
  EXPECT_NEAR(integrate_samples(t, sampled(kCubic, t), 2, 10, IntegrationRule::kSimpson), exact,
              1e-14);
  // …and not for quartics: the error is h⁴/180·(b − a)·f⁗ with h = 0.05, b − a = 0.4, f⁗ = −72.
  const double h = t[1] - t[0];
  const double err = integrate_samples(t, sampled(kQuartic, t), 2, 10, IntegrationRule::kSimpson) -
                     poly_integral(kQuartic, t[2], t[10]);
  EXPECT_NEAR(err, std::pow(h, 4) / 180.0 * 0.4 * (4 * 3 * 2 * -3.0), 1e-14);
  EXPECT_GT(std::abs(err), 1e-8);
}

TEST(IntegrationRule, SimpsonIsExactForQuadraticsOnIrregularAndOddSteps) {
  Eigen::VectorXd t(8);
  t << 0.0, 0.07, 0.1, 0.22, 0.25, 0.4, 0.43, 0.6;
  const Eigen::VectorXd f = sampled(kQuadratic, t);
  for (Eigen::Index last : {2, 3, 5, 7}) {  // even and odd step counts
    EXPECT_NEAR(integrate_samples(t, f, 0, last, IntegrationRule::kSimpson),
                poly_integral(kQuadratic, t[0], t[last]), 1e-14)
        << last;
  }
  // One step: the trapezoid (exact for lines only).
  const Eigen::VectorXd line = sampled({1.0, 2.0}, t);
  EXPECT_NEAR(integrate_samples(t, line, 3, 4, IntegrationRule::kSimpson),
              poly_integral({1.0, 2.0}, t[3], t[4]), 1e-15);
  EXPECT_GT(std::abs(integrate_samples(t, sampled(kCubic, t), 0, 7, IntegrationRule::kSimpson) -
                     poly_integral(kCubic, t[0], t[7])),
            1e-6);
}

TEST(IntegrationRule, TrapezoidIsExactForLinesAndZeroOrderHoldForHeldValues) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(6, 0.0, 1.0);
  EXPECT_NEAR(integrate_samples(t, sampled({1.0, -2.0}, t), 0, 5, IntegrationRule::kTrapezoid),
              poly_integral({1.0, -2.0}, 0.0, 1.0), 1e-15);
  EXPECT_GT(
      std::abs(integrate_samples(t, sampled(kQuadratic, t), 0, 5, IntegrationRule::kTrapezoid) -
               poly_integral(kQuadratic, 0.0, 1.0)),
      1e-3);
  Eigen::VectorXd held(6);
  held << 1.0, -2.0, 3.0, 0.5, 4.0, 99.0;  // the last value is held beyond the interval
  EXPECT_NEAR(integrate_samples(t, held, 0, 5, IntegrationRule::kZeroOrderHold),
              0.2 * (1.0 - 2.0 + 3.0 + 0.5 + 4.0), 1e-15);
}

TEST(IntegrationRule, BadIntervalsAreErrors) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(5, 0.0, 1.0);
  EXPECT_THROW(integrate_samples(t, t, 2, 2, IntegrationRule::kSimpson), Error);
  EXPECT_THROW(integrate_samples(t, t, 0, 5, IntegrationRule::kSimpson), Error);
  EXPECT_THROW(integrate_samples(t, t.head(4), 0, 3, IntegrationRule::kSimpson), Error);
}

// Velocity integrals of one step: exact when the position is a cubic over the step, including
// sign changes inside it (oracle: a 200 000-point midpoint sum of the analytic velocity).
TEST(StepVelocityIntegrals, ExactForCubicPositionsWithSignChanges) {
  const double h = 0.01;
  // x(s) = c1·s + c2·s² + c3·s³: velocity 0, 1 or 2 sign changes on the step.
  const std::vector<std::array<double, 3>> cases = {
      {0.5, 10.0, 100.0}, {0.2, -60.0, 2000.0}, {-0.3, 80.0, -5000.0}, {-1.0, 0.0, 0.0}};
  for (const auto& c : cases) {
    auto v = [&](double s) { return c[0] + 2 * c[1] * s + 3 * c[2] * s * s; };
    const double dx = c[0] * h + c[1] * h * h + c[2] * h * h * h;
    const StepVelocityIntegrals got = step_velocity_integrals(h, dx, v(0.0), v(h));
    StepVelocityIntegrals ref;
    const int kN = 200000;
    for (int i = 0; i < kN; ++i) {
      const double x = v((i + 0.5) * h / kN), w = h / kN;
      (x > 0 ? ref.positive : ref.negative) += x * w;
      (x > 0 ? ref.positive_square : ref.negative_square) += x * x * w;
    }
    const double scale = std::abs(c[0]) + 2 * std::abs(c[1]) * h + 3 * std::abs(c[2]) * h * h;
    EXPECT_NEAR(got.positive, ref.positive, 1e-9 * scale * h) << c[0];
    EXPECT_NEAR(got.negative, ref.negative, 1e-9 * scale * h) << c[0];
    EXPECT_NEAR(got.positive_square, ref.positive_square, 1e-9 * scale * scale * h) << c[0];
    EXPECT_NEAR(got.negative_square, ref.negative_square, 1e-9 * scale * scale * h) << c[0];
  }
}

}  // namespace
}  // namespace dynid
