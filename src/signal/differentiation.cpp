#include "dynid/signal/differentiation.hpp"

#include <Eigen/QR>

#include <string>

#include "dynid/common/error.hpp"
#include "dynid/signal/sampling_check.hpp"

namespace dynid {

namespace {}  // namespace

Eigen::MatrixXd central_difference(const Eigen::Ref<const Eigen::VectorXd>& t,
                                   const Eigen::Ref<const Eigen::MatrixXd>& x, int derivative) {
  if (derivative != 1 && derivative != 2) {
    throw Error("central difference derivative is " + std::to_string(derivative) +
                ": give 1 (velocity) or 2 (acceleration)");
  }
  check_time_rows("central difference", t, x);
  const Eigen::Index m = t.size();
  if (m < 3) {
    throw Error("central difference needs at least 3 samples, got " + std::to_string(m) +
                ": give a longer record");
  }
  check_sampling(t);
  Eigen::MatrixXd d(m, x.cols());
  for (Eigen::Index k = 0; k < m; ++k) {
    // Nodes a, b, c of the quadratic: centred inside, one-sided at the ends.
    const Eigen::Index i = k == 0 ? 1 : (k == m - 1 ? m - 2 : k);
    const double ta = t(i - 1), tb = t(i), tc = t(i + 1), tau = t(k);
    const double da = (ta - tb) * (ta - tc), db = (tb - ta) * (tb - tc), dc = (tc - ta) * (tc - tb);
    double wa, wb, wc;
    if (derivative == 1) {  // derivatives of the Lagrange basis at tau
      wa = ((tau - tb) + (tau - tc)) / da;
      wb = ((tau - ta) + (tau - tc)) / db;
      wc = ((tau - ta) + (tau - tb)) / dc;
    } else {
      wa = 2.0 / da;
      wb = 2.0 / db;
      wc = 2.0 / dc;
    }
    d.row(k) = wa * x.row(i - 1) + wb * x.row(i) + wc * x.row(i + 1);
  }
  return d;
}

Eigen::MatrixXd savitzky_golay(const Eigen::Ref<const Eigen::VectorXd>& t,
                               const Eigen::Ref<const Eigen::MatrixXd>& x,
                               const SavitzkyGolayOptions& options) {
  const int w = options.window, p = options.order, d = options.derivative;
  if (w < 1 || w % 2 == 0) {
    throw Error("Savitzky-Golay window is " + std::to_string(w) +
                " samples: give an odd window (e.g. 11)");
  }
  if (p < 0 || w <= p) {
    throw Error("Savitzky-Golay order " + std::to_string(p) + " with window " + std::to_string(w) +
                ": give 0 <= order < window");
  }
  if (d < 0 || d > 2 || d > p) {
    throw Error("Savitzky-Golay derivative is " + std::to_string(d) +
                ": give 0, 1 or 2, at most the polynomial order " + std::to_string(p));
  }
  check_time_rows("Savitzky-Golay", t, x);
  const Eigen::Index m = t.size();
  if (m < w) {
    throw Error("Savitzky-Golay window of " + std::to_string(w) + " samples exceeds the " +
                std::to_string(m) + " samples given: shorten the window or give more data");
  }
  if (m >= 2) check_sampling(t);
  const int half = w / 2;
  const double factorial = d == 2 ? 2.0 : 1.0;
  Eigen::MatrixXd out(m, x.cols());
  Eigen::MatrixXd v(w, p + 1);  // Vandermonde in scaled local time
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(w, p + 1);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(p + 1);
  Eigen::VectorXd y(p + 1), weights(w);
  for (Eigen::Index k = 0; k < m; ++k) {
    Eigen::Index start = k - half;
    if (start < 0) start = 0;
    if (start + w > m) start = m - w;
    // Scale local time by the window span for conditioning.
    const double scale = 0.5 * (t(start + w - 1) - t(start));
    for (int r = 0; r < w; ++r) {
      const double s = (t(start + r) - t(k)) / scale;
      double power = 1.0;
      for (int c = 0; c <= p; ++c) {
        v(r, c) = power;
        power *= s;
      }
    }
    qr.compute(v);
    // weights = V (VᵀV)⁻¹ e_d = Q R⁻ᵀ e_d: the coefficient c_d of the fit is weightsᵀ·x.
    e.setZero();
    e(d) = 1.0;
    y = qr.matrixQR()
            .topLeftCorner(p + 1, p + 1)
            .triangularView<Eigen::Upper>()
            .transpose()
            .solve(e);
    weights.setZero();
    weights.head(p + 1) = y;
    weights.applyOnTheLeft(qr.householderQ());
    const double gain = factorial / std::pow(scale, d);
    out.row(k).noalias() = gain * (weights.transpose() * x.middleRows(start, w));
  }
  return out;
}

}  // namespace dynid
