#include "dynid/excitation/fourier_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "dynid/common/error.hpp"

namespace dynid {

int FourierCoefficients::max_harmonics() const {
  int n_max = 0;
  for (const auto& ai : a) n_max = std::max(n_max, static_cast<int>(ai.size()));
  return n_max;
}

FourierCoefficients FourierCoefficients::zeros(const std::vector<int>& harmonics, double f0) {
  FourierCoefficients c;
  c.f0 = f0;
  for (int n_i : harmonics) {
    if (n_i < 1)
      throw Error("Fourier harmonics: every joint needs at least 1 harmonic; got " +
                  std::to_string(n_i));
    c.a.push_back(Eigen::VectorXd::Zero(n_i));
    c.b.push_back(Eigen::VectorXd::Zero(n_i));
  }
  c.q0 = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(harmonics.size()));
  return c;
}

void FourierCoefficients::validate() const {
  if (!std::isfinite(f0) || f0 <= 0.0)
    throw Error("Fourier f0: the fundamental frequency must be finite and > 0 Hz; got " +
                std::to_string(f0));
  if (a.empty()) throw Error("Fourier coefficients: no joint; give a and b for every joint");
  if (b.size() != a.size() || q0.size() != static_cast<Eigen::Index>(a.size()))
    throw Error("Fourier coefficients: a, b and q0 must have one entry per joint (a: " +
                std::to_string(a.size()) + ", b: " + std::to_string(b.size()) +
                ", q0: " + std::to_string(q0.size()) + ")");
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].size() < 1 || a[i].size() != b[i].size())
      throw Error("Fourier coefficients of joint " + std::to_string(i + 1) +
                  ": a and b need the same number (>= 1) of harmonics");
    if (!a[i].allFinite() || !b[i].allFinite() || !std::isfinite(q0[i]))
      throw Error("Fourier coefficients of joint " + std::to_string(i + 1) +
                  ": NaN or Inf; give finite values");
  }
}

void project_rest_at_ends(FourierCoefficients& c) {
  c.validate();
  for (size_t i = 0; i < c.a.size(); ++i) {
    Eigen::VectorXd& a = c.a[i];
    Eigen::VectorXd& b = c.b[i];
    const Eigen::Index n_i = a.size();
    // dq(0) = Σ a_k = 0: project a onto the orthogonal complement of 1.
    a.array() -= a.sum() / static_cast<double>(n_i);
    // ddq(0) = ω Σ k b_k = 0: project b onto the orthogonal complement of k.
    const Eigen::VectorXd k = Eigen::VectorXd::LinSpaced(n_i, 1.0, static_cast<double>(n_i));
    b -= (k.dot(b) / k.squaredNorm()) * k;
  }
}

FourierTrajectory::FourierTrajectory(FourierCoefficients coefficients)
    : coefficients_(std::move(coefficients)) {
  coefficients_.validate();
}

void FourierTrajectory::evaluate(double t, Eigen::Ref<Eigen::VectorXd> q,
                                 Eigen::Ref<Eigen::VectorXd> dq,
                                 Eigen::Ref<Eigen::VectorXd> ddq) const {
  const FourierCoefficients& c = coefficients_;
  const double w = 2.0 * M_PI * c.f0;
  // Reduce t to one period so that sin/cos stay accurate for large t.
  const double period = 1.0 / c.f0;
  const double tr = t - std::floor(t / period) * period;
  const double s1 = std::sin(w * tr), c1 = std::cos(w * tr);
  for (int i = 0; i < c.dof(); ++i) {
    const Eigen::VectorXd& a = c.a[i];
    const Eigen::VectorXd& b = c.b[i];
    double qi = c.q0[i], dqi = 0.0, ddqi = 0.0;
    double sk = s1, ck = c1;  // sin(kωt), cos(kωt) by the angle-addition recurrence
    for (Eigen::Index k = 1; k <= a.size(); ++k) {
      const double wk = w * static_cast<double>(k);
      const double ak = a[k - 1], bk = b[k - 1];
      qi += (ak * sk - bk * ck) / wk;     // eq. 17
      dqi += ak * ck + bk * sk;           // eq. 18
      ddqi += wk * (-ak * sk + bk * ck);  // eq. 19
      const double s_next = sk * c1 + ck * s1;
      ck = ck * c1 - sk * s1;
      sk = s_next;
    }
    q[i] = qi;
    dq[i] = dqi;
    ddq[i] = ddqi;
  }
}

}  // namespace dynid
