#include "dynid/signal/integration.hpp"

#include <cmath>
#include <string>

#include "dynid/common/error.hpp"

namespace dynid {

double integrate_samples(const Eigen::Ref<const Eigen::VectorXd>& t,
                         const Eigen::Ref<const Eigen::VectorXd>& f, Eigen::Index first,
                         Eigen::Index last, IntegrationRule rule) {
  if (t.size() != f.size()) {
    throw Error("integrate_samples: " + std::to_string(t.size()) + " time stamps but " +
                std::to_string(f.size()) + " values; give one value per time stamp");
  }
  if (first < 0 || last >= t.size() || first >= last) {
    throw Error("integrate_samples: interval [" + std::to_string(first) + ", " +
                std::to_string(last) + "] is not inside the " + std::to_string(t.size()) +
                " samples with first < last");
  }
  double sum = 0.0;
  switch (rule) {
    case IntegrationRule::kTrapezoid:
      for (Eigen::Index k = first; k < last; ++k)
        sum += 0.5 * (t[k + 1] - t[k]) * (f[k] + f[k + 1]);
      return sum;
    case IntegrationRule::kZeroOrderHold:
      for (Eigen::Index k = first; k < last; ++k) sum += (t[k + 1] - t[k]) * f[k];
      return sum;
    case IntegrationRule::kSimpson:
      break;
  }
  if (last - first == 1) return 0.5 * (t[last] - t[first]) * (f[first] + f[last]);
  Eigen::Index k = first;
  for (; k + 2 <= last; k += 2) {
    // Integral of the quadratic through (k, k+1, k+2) with steps a, b (reduces to h/3·(1, 4, 1)).
    const double a = t[k + 1] - t[k], b = t[k + 2] - t[k + 1], s = a + b;
    sum += s / 6.0 * ((2.0 - b / a) * f[k] + s * s / (a * b) * f[k + 1] + (2.0 - a / b) * f[k + 2]);
  }
  if (k < last) {
    // Odd step count: the last step [k, k+1] under the quadratic through (k−1, k, k+1).
    const double a = t[k] - t[k - 1], b = t[k + 1] - t[k];
    sum += (2.0 * b * b + 3.0 * a * b) / (6.0 * (a + b)) * f[k + 1] +
           (b * b + 3.0 * a * b) / (6.0 * a) * f[k] - b * b * b / (6.0 * a * (a + b)) * f[k - 1];
  }
  return sum;
}

namespace {

// ∫ v and ∫ v² of v(u) = c0 + c1·u + c2·u² over [u0, u1].
void piece_integrals(double c0, double c1, double c2, double u0, double u1, double& i1,
                     double& i2) {
  // d[k] = (u1^k − u0^k)/k, k = 1..5.
  double d[6], a = 1.0, b = 1.0;
  for (int k = 1; k <= 5; ++k) {
    a *= u1;
    b *= u0;
    d[k] = (a - b) / k;
  }
  i1 = c0 * d[1] + c1 * d[2] + c2 * d[3];
  i2 = c0 * c0 * d[1] + 2.0 * c0 * c1 * d[2] + (c1 * c1 + 2.0 * c0 * c2) * d[3] +
       2.0 * c1 * c2 * d[4] + c2 * c2 * d[5];
}

}  // namespace

StepVelocityIntegrals step_velocity_integrals(double h, double dx, double v0, double v1) {
  // v(u) = v0 + B·u + C·u², u = s/h ∈ [0, 1]: v(1) = v1 and h·∫₀¹ v du = dx give
  // B = 6M − 2D, C = 3(D − 2M) with D = v1 − v0, M = dx/h − v0.
  const double D = v1 - v0, M = dx / h - v0;
  const double B = 6.0 * M - 2.0 * D, C = 3.0 * (D - 2.0 * M);
  double cuts[4] = {0.0, 0.0, 0.0, 1.0};
  int count = 1;
  auto add_root = [&](double r) {
    if (r > 0.0 && r < 1.0) cuts[count++] = r;
  };
  const double scale = std::abs(v0) + std::abs(B) + std::abs(C);
  if (std::abs(C) > 1e-12 * scale) {
    const double disc = B * B - 4.0 * C * v0;
    if (disc > 0.0) {
      // Numerically stable pair of roots.
      const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
      double r1 = q / C, r2 = q != 0.0 ? v0 / q : r1;
      if (r1 > r2) std::swap(r1, r2);
      add_root(r1);
      add_root(r2);
    }
  } else if (B != 0.0) {
    add_root(-v0 / B);
  }
  cuts[count++] = 1.0;
  StepVelocityIntegrals out;
  for (int i = 0; i + 1 < count; ++i) {
    const double u0 = cuts[i], u1 = cuts[i + 1];
    if (u1 <= u0) continue;
    double i1 = 0.0, i2 = 0.0;
    piece_integrals(v0, B, C, u0, u1, i1, i2);
    const double um = 0.5 * (u0 + u1);
    if (v0 + um * (B + um * C) >= 0.0) {
      out.positive += h * i1;
      out.positive_square += h * i2;
    } else {
      out.negative += h * i1;
      out.negative_square += h * i2;
    }
  }
  return out;
}

}  // namespace dynid
