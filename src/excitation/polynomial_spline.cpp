#include "dynid/excitation/polynomial_spline.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "dynid/common/error.hpp"

namespace dynid {

PolynomialSpline::PolynomialSpline(const Eigen::VectorXd& times, const Eigen::MatrixXd& points,
                                   const SplineOptions& options)
    : order_(options.order), times_(times), points_(points) {
  const Eigen::Index m = times.size();
  const Eigen::Index n = points.rows();
  if (m < 2) throw Error("spline times: need at least 2 via-points, got " + std::to_string(m));
  if (n < 1 || points.cols() != m)
    throw Error(
        "spline points: need an n×m matrix with one column per time (m = " + std::to_string(m) +
        "), got " + std::to_string(points.rows()) + "×" + std::to_string(points.cols()));
  if (!times.allFinite() || !points.allFinite())
    throw Error("spline times/points: NaN or Inf; give finite values");
  if (times[0] != 0.0)
    throw Error("spline times: the first via-point must be at t = 0; shift the times");
  for (Eigen::Index k = 0; k + 1 < m; ++k)
    if (!(times[k + 1] > times[k]))
      throw Error("spline times: must be strictly increasing; times[" + std::to_string(k + 1) +
                  "] <= times[" + std::to_string(k) + "]");
  const bool given_v = options.velocities.size() > 0;
  const bool given_a = options.accelerations.size() > 0;
  if (order_ == SplineOrder::kCubic && (given_v || given_a))
    throw Error(
        "spline velocities/accelerations: only a quintic spline takes them; "
        "use SplineOrder::kQuintic or leave them empty");
  if (given_v && (options.velocities.rows() != n || options.velocities.cols() != m ||
                  !options.velocities.allFinite()))
    throw Error("spline velocities: need a finite n×m matrix like the points");
  if (given_a && (options.accelerations.rows() != n || options.accelerations.cols() != m ||
                  !options.accelerations.allFinite()))
    throw Error("spline accelerations: need a finite n×m matrix like the points");

  // Clamped cubic spline (zero end velocities): knot second derivatives M (m×n).
  const Eigen::VectorXd h = times.tail(m - 1) - times.head(m - 1);
  Eigen::MatrixXd delta(m - 1, n);  // slopes Δ_k
  for (Eigen::Index k = 0; k + 1 < m; ++k)
    delta.row(k) = (points.col(k + 1) - points.col(k)).transpose() / h[k];
  // The system is tridiagonal: sub[k]·M_{k−1} + diag[k]·M_k + super[k]·M_{k+1} = rhs_k. It is
  // strictly diagonally dominant (2(h_{k−1} + h_k) > h_{k−1} + h_k), so elimination without
  // pivoting (Thomas) is stable, and costs O(m) where a dense LU of --via points cost O(m³) time
  // and O(m²) memory (10⁴ via-points did not finish).
  Eigen::VectorXd sub = Eigen::VectorXd::Zero(m), diag(m), super = Eigen::VectorXd::Zero(m);
  Eigen::MatrixXd rhs(m, n);
  diag[0] = 2.0 * h[0];
  super[0] = h[0];
  rhs.row(0) = 6.0 * delta.row(0);
  for (Eigen::Index k = 1; k + 1 < m; ++k) {
    sub[k] = h[k - 1];
    diag[k] = 2.0 * (h[k - 1] + h[k]);
    super[k] = h[k];
    rhs.row(k) = 6.0 * (delta.row(k) - delta.row(k - 1));
  }
  sub[m - 1] = h[m - 2];
  diag[m - 1] = 2.0 * h[m - 2];
  rhs.row(m - 1) = -6.0 * delta.row(m - 2);
  for (Eigen::Index k = 1; k < m; ++k) {
    const double f = sub[k] / diag[k - 1];
    diag[k] -= f * super[k - 1];
    rhs.row(k) -= f * rhs.row(k - 1);
  }
  Eigen::MatrixXd M(m, n);  // m×n
  M.row(m - 1) = rhs.row(m - 1) / diag[m - 1];
  for (Eigen::Index k = m - 2; k >= 0; --k)
    M.row(k) = (rhs.row(k) - super[k] * M.row(k + 1)) / diag[k];

  coefficients_.resize(static_cast<size_t>(m - 1));
  if (order_ == SplineOrder::kCubic) {
    for (Eigen::Index k = 0; k + 1 < m; ++k) {
      auto& c = coefficients_[static_cast<size_t>(k)];
      c = Eigen::Matrix<double, Eigen::Dynamic, 6>::Zero(n, 6);
      c.col(0) = points.col(k);
      c.col(1) = (delta.row(k) - h[k] * (2.0 * M.row(k) + M.row(k + 1)) / 6.0).transpose();
      c.col(2) = 0.5 * M.row(k).transpose();
      c.col(3) = ((M.row(k + 1) - M.row(k)) / (6.0 * h[k])).transpose();
    }
    return;
  }

  // Quintic: knot velocities and accelerations, given or from the cubic spline.
  Eigen::MatrixXd V(n, m), Acc(n, m);
  if (given_v) {
    V = options.velocities;
  } else {
    for (Eigen::Index k = 0; k + 1 < m; ++k)
      V.col(k) = (delta.row(k) - h[k] * (2.0 * M.row(k) + M.row(k + 1)) / 6.0).transpose();
    V.col(m - 1).setZero();
    V.col(0).setZero();
  }
  if (given_a) {
    Acc = options.accelerations;
  } else {
    Acc = M.transpose();
    Acc.col(0).setZero();
    Acc.col(m - 1).setZero();
  }
  for (Eigen::Index k = 0; k + 1 < m; ++k) {
    auto& c = coefficients_[static_cast<size_t>(k)];
    c.resize(n, 6);
    const double hk = h[k], h2 = hk * hk, h3 = h2 * hk, h4 = h3 * hk, h5 = h4 * hk;
    for (Eigen::Index j = 0; j < n; ++j) {
      const double p0 = points(j, k), p1 = points(j, k + 1);
      const double v0 = V(j, k), v1 = V(j, k + 1), a0 = Acc(j, k), a1 = Acc(j, k + 1);
      c(j, 0) = p0;
      c(j, 1) = v0;
      c(j, 2) = 0.5 * a0;
      c(j, 3) = (20.0 * (p1 - p0) - (8.0 * v1 + 12.0 * v0) * hk - (3.0 * a0 - a1) * h2) / (2 * h3);
      c(j, 4) =
          (30.0 * (p0 - p1) + (14.0 * v1 + 16.0 * v0) * hk + (3.0 * a0 - 2.0 * a1) * h2) / (2 * h4);
      c(j, 5) = (12.0 * (p1 - p0) - 6.0 * (v1 + v0) * hk + (a1 - a0) * h2) / (2 * h5);
    }
  }
}

void PolynomialSpline::evaluate(double t, Eigen::Ref<Eigen::VectorXd> q,
                                Eigen::Ref<Eigen::VectorXd> dq,
                                Eigen::Ref<Eigen::VectorXd> ddq) const {
  const Eigen::Index m = times_.size();
  const double t_end = times_[m - 1];
  const bool outside = t < 0.0 || t > t_end;  // hold the end point at rest
  const double tc = std::clamp(t, 0.0, t_end);
  const auto it = std::upper_bound(times_.data(), times_.data() + m - 1, tc);
  const Eigen::Index k = std::max<Eigen::Index>(0, (it - times_.data()) - 1);
  const auto& c = coefficients_[static_cast<size_t>(k)];
  const double x = tc - times_[k];
  for (Eigen::Index j = 0; j < q.size(); ++j) {
    q[j] = c(j, 0) + x * (c(j, 1) + x * (c(j, 2) + x * (c(j, 3) + x * (c(j, 4) + x * c(j, 5)))));
    dq[j] = c(j, 1) + x * (2 * c(j, 2) + x * (3 * c(j, 3) + x * (4 * c(j, 4) + x * 5 * c(j, 5))));
    ddq[j] = 2 * c(j, 2) + x * (6 * c(j, 3) + x * (12 * c(j, 4) + x * 20 * c(j, 5)));
  }
  if (outside) {
    dq.setZero();
    ddq.setZero();
  }
}

}  // namespace dynid
