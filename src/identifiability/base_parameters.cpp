#include "dynid/identifiability/base_parameters.hpp"

#include <cmath>
#include <random>
#include <sstream>

#include <Eigen/QR>

#include "dynid/common/error.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/regressor/energy_regressor.hpp"
#include "dynid/regressor/torque_regressor.hpp"

namespace dynid {

namespace {

// Random joint value inside the limits, or in [−π, π] (revolute) / [−0.5, 0.5] m (prismatic).
double random_position(const Joint& joint, std::mt19937& rng) {
  double lo = joint.limits.lower, hi = joint.limits.upper;
  if (!std::isfinite(lo) || !std::isfinite(hi) || hi - lo < 1e-6) {
    const double span = joint.type == JointType::kRevolute ? M_PI : 0.5;
    lo = -span;
    hi = span;
  }
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

Eigen::MatrixXd sample_regressor(const Model& model, const BaseParameterOptions& options,
                                 int samples) {
  const int n = model.dof();
  const int p = options.layout.columns(n);
  const std::vector<int> motors = coupled_motors(model);
  const int extra = options.coupling && options.regressor == BaseRegressor::kTorque
                        ? 3 * static_cast<int>(motors.size())
                        : 0;
  Workspace ws(model);
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd q(n), dq(n), ddq(n);
  auto draw = [&]() {
    for (int j = 0; j < n; ++j) {
      q[j] = random_position(model.joints[j], rng);
      dq[j] = u(rng);
      ddq[j] = u(rng);
    }
  };
  if (options.regressor == BaseRegressor::kTorque) {
    Eigen::MatrixXd W(static_cast<Eigen::Index>(samples) * n, p + extra);
    for (int k = 0; k < samples; ++k) {
      draw();
      torque_regressor(model, ws, options.layout, q, dq, ddq, W.block(k * n, 0, n, p));
      if (extra) coupling_regressor(model, motors, dq, ddq, W.block(k * n, p, n, extra));
    }
    return W;
  }
  // Seed 2 eqs. 4–8: differences of the energy row between random states (the constant part of
  // the potential energy cancels).
  Eigen::MatrixXd W(samples, p);
  Eigen::VectorXd h0(p), h(p);
  draw();
  energy_regressor(model, ws, options.layout, q, dq, h0);
  for (int k = 0; k < samples; ++k) {
    draw();
    energy_regressor(model, ws, options.layout, q, dq, h);
    W.row(k) = (h - h0).transpose();
  }
  return W;
}

std::string format_coefficient(double k, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << std::abs(k);
  return s.str();
}

}  // namespace

BaseParameters classify_columns(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const std::vector<std::string>& names,
                                const BaseParameterOptions& options) {
  const Eigen::Index p = W.cols();
  if (static_cast<Eigen::Index>(names.size()) != p) {
    throw Error("classify_columns: " + std::to_string(names.size()) + " names for " +
                std::to_string(p) + " columns");
  }
  BaseParameters out;
  out.layout_names = names;
  const Eigen::VectorXd norms = W.colwise().norm();
  const double largest = norms.size() ? norms.maxCoeff() : 0.0;
  // Left-to-right sweep with a growing orthonormal basis (modified Gram–Schmidt, twice for
  // stability): a column is dependent when its residual is tiny compared with its own norm.
  Eigen::MatrixXd Q(W.rows(), p);
  int r = 0;
  for (Eigen::Index c = 0; c < p; ++c) {
    if (!(norms[c] > options.zero_tolerance * largest)) {
      out.unidentifiable.push_back(static_cast<int>(c));
      continue;
    }
    Eigen::VectorXd v = W.col(c);
    for (int pass = 0; pass < 2; ++pass) {
      for (int k = 0; k < r; ++k) v -= Q.col(k).dot(v) * Q.col(k);
    }
    if (v.norm() > options.dependence_tolerance * norms[c]) {
      Q.col(r++) = v / v.norm();
      out.base.push_back(static_cast<int>(c));
    } else {
      out.dependent.push_back(static_cast<int>(c));
    }
  }
  out.rank = r;
  if (r == 0) throw Error("no parameter of the model has any effect on the sampled regressor");
  Eigen::MatrixXd W1(W.rows(), r), W2(W.rows(), out.dependent.size());
  for (int k = 0; k < r; ++k) W1.col(k) = W.col(out.base[k]);
  for (size_t k = 0; k < out.dependent.size(); ++k) W2.col(k) = W.col(out.dependent[k]);
  out.K_d = W2.cols() ? Eigen::MatrixXd(W1.colPivHouseholderQr().solve(W2)) : Eigen::MatrixXd(r, 0);
  // Coefficients that are zero or integers up to round-off are snapped, so the expressions are
  // exact where the regrouping rules are exact.
  for (Eigen::Index i = 0; i < out.K_d.rows(); ++i) {
    for (Eigen::Index j = 0; j < out.K_d.cols(); ++j) {
      double& k = out.K_d(i, j);
      if (std::abs(k) < 1e-9) k = 0.0;
      if (std::abs(k - std::round(k)) < 1e-9) k = std::round(k);
    }
  }
  for (int i = 0; i < r; ++i) {
    const std::string& lead = names[out.base[i]];
    std::ostringstream expr;
    bool regrouped = false;
    for (size_t j = 0; j < out.dependent.size(); ++j) {
      const double k = out.K_d(i, j);
      if (k == 0.0) continue;
      regrouped = true;
      expr << (k < 0 ? " - " : " + ");
      if (std::abs(k) != 1.0) expr << format_coefficient(k, options.coefficient_digits) << "*";
      expr << names[out.dependent[j]];
    }
    out.names.push_back(regrouped ? lead + "R" : lead);
    out.expressions.push_back(out.names.back() + " = " + lead + expr.str());
  }
  return out;
}

BaseParameters compute_base_parameters(const Model& model, const BaseParameterOptions& options) {
  const int n = model.dof();
  const int p = options.layout.columns(n);
  const int samples =
      options.samples > 0 ? options.samples : std::max(100, 4 * p / std::max(1, n) + 50);
  std::vector<std::string> names = options.layout.names(n);
  if (options.coupling && options.regressor == BaseRegressor::kTorque) {
    for (const auto& name : coupling_column_names(model)) names.push_back(name);
  }
  BaseParameters out = classify_columns(sample_regressor(model, options, samples), names, options);
  out.samples = samples;
  return out;
}

Eigen::VectorXd BaseParameters::reduce(const Eigen::Ref<const Eigen::VectorXd>& theta) const {
  Eigen::VectorXd b(rank);
  for (int i = 0; i < rank; ++i) {
    b[i] = theta[base[i]];
    for (size_t j = 0; j < dependent.size(); ++j) b[i] += K_d(i, j) * theta[dependent[j]];
  }
  return b;
}

Eigen::MatrixXd BaseParameters::select(const Eigen::Ref<const Eigen::MatrixXd>& W) const {
  Eigen::MatrixXd Wb(W.rows(), rank);
  for (int i = 0; i < rank; ++i) Wb.col(i) = W.col(base[i]);
  return Wb;
}

std::vector<std::string> BaseParameters::unidentifiable_names() const {
  std::vector<std::string> out;
  for (int c : unidentifiable) out.push_back(layout_names[c]);
  return out;
}

}  // namespace dynid
