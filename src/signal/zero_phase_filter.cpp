#include "dynid/signal/zero_phase_filter.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "dynid/common/error.hpp"

namespace dynid {

namespace {

// Filters one column in place (DF2T per section); z holds the per-section states (sections × 2).
void filter_column(const SosFilter& f, double* data, Eigen::Index m, Eigen::Index stride,
                   Eigen::MatrixXd& z) {
  const int ns = f.sections();
  for (Eigen::Index k = 0; k < m; ++k) {
    double v = data[k * stride];
    for (int s = 0; s < ns; ++s) {
      const double b0 = f.sos(s, 0), b1 = f.sos(s, 1), b2 = f.sos(s, 2);
      const double a1 = f.sos(s, 4), a2 = f.sos(s, 5);
      const double y = b0 * v + z(s, 0);
      z(s, 0) = b1 * v - a1 * y + z(s, 1);
      z(s, 1) = b2 * v - a2 * y;
      v = y;
    }
    data[k * stride] = v;
  }
}

void check_zi(const SosFilter& f, const Eigen::Ref<const Eigen::MatrixXd>& zi) {
  if (zi.size() != 0 && (zi.rows() != f.sections() || zi.cols() != 2)) {
    throw Error("sosfilt initial state is " + std::to_string(zi.rows()) + "x" +
                std::to_string(zi.cols()) + ": give sections x 2 (" + std::to_string(f.sections()) +
                "x2) or an empty matrix");
  }
}

}  // namespace

Eigen::MatrixXd sosfilt(const SosFilter& filter, const Eigen::Ref<const Eigen::MatrixXd>& x,
                        const Eigen::Ref<const Eigen::MatrixXd>& zi) {
  check_zi(filter, zi);
  Eigen::MatrixXd y = x;
  Eigen::MatrixXd z(filter.sections(), 2);
  for (Eigen::Index c = 0; c < y.cols(); ++c) {
    if (zi.size() == 0 || y.rows() == 0) {
      z.setZero();
    } else {
      z = zi * y(0, c);
    }
    filter_column(filter, y.col(c).data(), y.rows(), 1, z);
  }
  return y;
}

Eigen::MatrixXd sosfilt_steady_state(const SosFilter& filter) {
  Eigen::MatrixXd zi(filter.sections(), 2);
  double scale = 1.0;  // amplitude of the step reaching section s
  for (int s = 0; s < filter.sections(); ++s) {
    const auto& c = filter.sos.row(s);
    const double den = c(3) + c(4) + c(5);
    if (std::abs(den) < 1e-300) {
      throw Error("filter section " + std::to_string(s) +
                  " has a pole at z = 1 (no steady state): design a stable low-pass filter");
    }
    const double g = (c(0) + c(1) + c(2)) / den;
    const double y = g * scale;
    zi(s, 1) = c(2) * scale - c(5) * y;
    zi(s, 0) = c(1) * scale - c(4) * y + zi(s, 1);
    scale = y;
  }
  return zi;
}

int filtfilt_default_padding(const SosFilter& filter) {
  const int ns = filter.sections();
  int b2_zero = 0, a2_zero = 0;
  for (int s = 0; s < ns; ++s) {
    b2_zero += filter.sos(s, 2) == 0.0;
    a2_zero += filter.sos(s, 5) == 0.0;
  }
  return 3 * (2 * ns + 1 - std::min(b2_zero, a2_zero));
}

Eigen::MatrixXd filtfilt(const SosFilter& filter, const Eigen::Ref<const Eigen::MatrixXd>& x,
                         const FiltfiltOptions& options) {
  const int pad = options.padding < 0 ? filtfilt_default_padding(filter) : options.padding;
  const Eigen::Index m = x.rows();
  if (m <= pad) {
    throw Error("zero-phase filter input has " + std::to_string(m) + " samples but the order-" +
                std::to_string(filter.order()) + " filter pads " + std::to_string(pad) +
                " samples per end: give at least " + std::to_string(pad + 1) +
                " samples or lower the filter order");
  }
  if (!x.allFinite()) {
    throw Error("zero-phase filter input contains NaN or Inf: clean or drop those samples first");
  }
  const Eigen::MatrixXd zi =
      options.steady_state_initial_conditions ? sosfilt_steady_state(filter) : Eigen::MatrixXd();
  Eigen::MatrixXd z(filter.sections(), 2);
  const Eigen::Index mp = m + 2 * pad;
  Eigen::VectorXd buf(mp);  // one padded column, reused for every channel
  Eigen::MatrixXd y(m, x.cols());
  for (Eigen::Index c = 0; c < x.cols(); ++c) {
    const double x0 = x(0, c), xe = x(m - 1, c);
    for (int i = 0; i < pad; ++i) {
      buf(i) = 2.0 * x0 - x(pad - i, c);
      buf(pad + m + i) = 2.0 * xe - x(m - 2 - i, c);
    }
    buf.segment(pad, m) = x.col(c);
    // Forward pass.
    if (zi.size() != 0) {
      z = zi * buf(0);
    } else {
      z.setZero();
    }
    filter_column(filter, buf.data(), mp, 1, z);
    // Backward pass: run over the reversed sequence (negative stride from the end).
    if (zi.size() != 0) {
      z = zi * buf(mp - 1);
    } else {
      z.setZero();
    }
    filter_column(filter, buf.data() + (mp - 1), mp, -1, z);
    y.col(c) = buf.segment(pad, m);
  }
  return y;
}

Eigen::MatrixXd lowpass_filtfilt(const LowpassOptions& design,
                                 const Eigen::Ref<const Eigen::MatrixXd>& x,
                                 const FiltfiltOptions& options) {
  return filtfilt(design_lowpass(design), x, options);
}

}  // namespace dynid
