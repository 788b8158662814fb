#include "dynid/excitation/joint_fourier.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "dynid/common/error.hpp"

namespace dynid {
namespace {

// Position of joint j of a Fourier series at t, and its first two derivatives.
struct Sample {
  double q, dq, ddq;
};
Sample joint_sample(const FourierTrajectory& tr, int j, double t) {
  const int n = tr.dof();
  Eigen::VectorXd q(n), dq(n), ddq(n);
  tr.evaluate(t, q, dq, ddq);
  return {q[j], dq[j], ddq[j]};
}

// Minimum and maximum of joint j over one period: a grid of 64 samples per period of the highest
// harmonic brackets every extremum (the series has at most 2N of them per period), and Newton's
// method on dq = 0 from the best grid samples makes them exact to round-off.
std::pair<double, double> joint_extremes(const FourierTrajectory& tr, int j, int harmonics) {
  const double period = tr.period();
  const int m = 64 * harmonics;
  const double dt = period / m;
  int i_min = 0, i_max = 0;
  double q_min = joint_sample(tr, j, 0.0).q, q_max = q_min;
  for (int i = 1; i < m; ++i) {
    const double q = joint_sample(tr, j, i * dt).q;
    if (q < q_min) q_min = q, i_min = i;
    if (q > q_max) q_max = q, i_max = i;
  }
  auto polish = [&](int i, double q_grid, bool is_max) {
    double t = i * dt;
    for (int it = 0; it < 20; ++it) {
      const Sample s = joint_sample(tr, j, t);
      if (s.ddq == 0.0) break;
      const double step = std::clamp(-s.dq / s.ddq, -dt, dt);  // stay in the bracketing cell
      t += step;
      if (std::abs(step) < 1e-15 * period) break;
    }
    const double q = joint_sample(tr, j, t).q;
    return is_max ? std::max(q, q_grid) : std::min(q, q_grid);
  };
  return {polish(i_min, q_min, false), polish(i_max, q_max, true)};
}

}  // namespace

FourierCoefficients joint_fourier_reference(const Eigen::VectorXd& pose, int joint, double from,
                                            double to, const JointFourierOptions& options) {
  const int n = static_cast<int>(pose.size());
  if (joint < 0 || joint >= n) {
    throw Error("one-joint Fourier reference: joint " + std::to_string(joint + 1) +
                " is not one of the " + std::to_string(n) + " joints of the pose");
  }
  if (!pose.allFinite()) throw Error("one-joint Fourier reference: the pose has NaN or Inf");
  if (options.harmonics < 1) {
    throw Error("one-joint Fourier reference: harmonics must be >= 1; got " +
                std::to_string(options.harmonics));
  }
  if (!std::isfinite(from) || !std::isfinite(to) || from == to) {
    throw Error("one-joint Fourier reference: the range needs two different finite positions");
  }
  const int h = options.harmonics;
  FourierCoefficients c = FourierCoefficients::zeros(std::vector<int>(n, h), options.f0);
  c.validate();  // f0
  c.q0 = pose;
  c.q0[joint] = 0.0;
  // sin(wkt + φ)/k = [a_k sin(wkt) − b_k cos(wkt)]/(wk) with a_k = w cos φ, b_k = −w sin φ.
  const double w = 2.0 * M_PI * options.f0;
  for (int k = 1; k <= h; ++k) {
    const double phi = -M_PI * k * (k - 1) / h;
    c.a[joint][k - 1] = w * std::cos(phi);
    c.b[joint][k - 1] = -w * std::sin(phi);
  }
  if (options.rest_at_ends) project_rest_at_ends(c);
  if (c.a[joint].norm() + c.b[joint].norm() < 1e-12 * w) {
    throw Error("one-joint Fourier reference: " + std::to_string(h) +
                " harmonic(s) at rest at both ends do not move the joint; use 2 or more, or "
                "drop the rest at the ends");
  }
  const auto [x_min, x_max] = joint_extremes(FourierTrajectory(c), joint, h);
  const double lo = std::min(from, to), hi = std::max(from, to);
  const double gain = (hi - lo) / (x_max - x_min);
  c.a[joint] *= gain;
  c.b[joint] *= gain;
  c.q0[joint] = lo - gain * x_min;
  return c;
}

}  // namespace dynid
