#include "dynid/closed_loop/maximum_likelihood.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <random>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include "dynid/closed_loop/closed_loop.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identification/processed_slice.hpp"
#include "dynid/signal/lowpass_design.hpp"
#include "dynid/signal/noise_floor.hpp"

namespace dynid {

Eigen::MatrixXd differential_sensitivity(const Model& model, const ParameterLayout& layout,
                                         bool coupling, const ProcessedRecord& processed,
                                         const std::vector<int>& columns,
                                         const Eigen::VectorXi& sample,
                                         const Eigen::VectorXi& joint) {
  const int n = model.dof();
  const Eigen::Index m = processed.record.t.size();
  const Eigen::Index rows = sample.size();
  if (joint.size() != rows) {
    throw Error("differential_sensitivity: " + std::to_string(rows) + " sample indices but " +
                std::to_string(joint.size()) + " joint indices");
  }
  for (Eigen::Index i = 0; i < rows; ++i) {
    if (sample[i] < 0 || sample[i] >= m || joint[i] < 0 || joint[i] >= n) {
      throw Error("differential_sensitivity: row " + std::to_string(i) + " names sample " +
                  std::to_string(sample[i]) + ", joint " + std::to_string(joint[i]) +
                  " outside the record (" + std::to_string(m) + " samples, " + std::to_string(n) +
                  " joints)");
    }
  }
  const auto p = static_cast<Eigen::Index>(columns.size());
  // Every entry is written below. The record is differentiated in chunks of samples (row k of W
  // depends on sample k only), so the perturbed regressors stay small instead of 6n copies of
  // the whole record's regressor (megabytes each, page-faulted afresh).
  Eigen::MatrixXd out(3 * n * rows, p);
  std::vector<Eigen::Index> order(static_cast<std::size_t>(rows));
  for (Eigen::Index i = 0; i < rows; ++i) order[static_cast<std::size_t>(i)] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index a, Eigen::Index b) { return sample[a] < sample[b]; });
  constexpr Eigen::Index kChunk = 32;
  ProcessedRecord work;
  std::size_t next = 0;  // first entry of `order` not yet written
  for (Eigen::Index k0 = 0; k0 < m && next < order.size(); k0 += kChunk) {
    const Eigen::Index len = std::min(kChunk, m - k0);
    if (sample[order[next]] >= k0 + len) continue;  // no rows in this chunk
    work = processed_slice(processed, k0, len);
    std::size_t end = next;
    while (end < order.size() && sample[order[end]] < k0 + len) ++end;
    Eigen::MatrixXd* channel[3] = {&work.record.q, &work.record.dq, &work.record.ddq};
    const Eigen::MatrixXd* original[3] = {&processed.record.q, &processed.record.dq,
                                          &processed.record.ddq};
    for (int c = 0; c < 3; ++c) {
      // W is quadratic in q̇ and linear in q̈, so central differences are exact for any step; for
      // q the step balances the O(h²) truncation against rounding (relative ~1e-10).
      const double h = c == 0 ? 1e-5 : 1e-2;
      for (int j = 0; j < n; ++j) {
        const auto base = original[c]->col(j).segment(k0, len);
        channel[c]->col(j) = base.array() + h;
        const Eigen::MatrixXd plus = processed_regressor(model, layout, coupling, work);
        channel[c]->col(j) = base.array() - h;
        const Eigen::MatrixXd minus = processed_regressor(model, layout, coupling, work);
        channel[c]->col(j) = base;
        for (std::size_t o = next; o < end; ++o) {
          const Eigen::Index i = order[o];
          const Eigen::Index r = static_cast<Eigen::Index>(sample[i] - k0) * n + joint[i];
          for (Eigen::Index k = 0; k < p; ++k) {
            out(3 * n * i + c * n + j, k) =
                (plus(r, columns[k]) - minus(r, columns[k])) / (2.0 * h);
          }
        }
      }
    }
    next = end;
  }
  return out;
}

namespace {

// The rows of one sample: first row, count, and the variances of their torques and of the
// 3n variables (q, q̇, q̈ of every joint) the rows are built from.
struct SampleRows {
  Eigen::Index first = 0, count = 0;
};

// Whitened residual L⁻¹·b of one sample, S = L·Lᵀ = J·diag(var_x)·Jᵀ + diag(var_tau) (seed 2
// eqs. 15–16), and its analytic Jacobian (docs/methods/closed_loop.md, "Jacobian"):
// ∂(L⁻¹b)/∂θ_k = −L⁻¹W_k − Φ(L⁻¹·∂S/∂θ_k·L⁻ᵀ)·L⁻¹b, ∂S/∂θ_k = D_k·Aᵀ + A·D_kᵀ, A = J·diag(var_x),
// D_k = ∂J/∂θ_k (row a: column k of row a's sensitivity), Φ = lower triangle with half the
// diagonal (the derivative of a Cholesky factor). J is linear in θ, so this is exact.
class SampleCost : public ceres::CostFunction {
 public:
  SampleCost(const EquationBlock& block, const Eigen::MatrixXd& sensitivity,
             const Eigen::VectorXd& var_x, const Eigen::VectorXd& var_tau_row, SampleRows rows)
      : block_(block),
        sensitivity_(sensitivity),
        var_x_(var_x),
        var_tau_row_(var_tau_row),
        rows_(rows) {
    set_num_residuals(static_cast<int>(rows.count));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(block.W.cols()));
  }

  // Returns false when S is not positive definite. jacobian: r × p, or null.
  bool whiten(const Eigen::Ref<const Eigen::VectorXd>& theta, Eigen::Ref<Eigen::VectorXd> residual,
              Eigen::MatrixXd* whitened_rows = nullptr, Eigen::VectorXd* whitened_y = nullptr,
              Eigen::MatrixXd* jacobian = nullptr) const {
    const Eigen::Index r = rows_.count, n3 = var_x_.size();
    const auto W = block_.W.middleRows(rows_.first, r);
    const Eigen::VectorXd b = block_.y.segment(rows_.first, r) - W * theta;
    // The sensitivity blocks of the sample's rows are contiguous: row a·n3 + c of `stacked` is
    // ∂W_a/∂x_c, so one product gives J row-major (J(a, c) = ∂(W_a θ)/∂x_c).
    const auto stacked = sensitivity_.middleRows(n3 * rows_.first, n3 * r);
    const Eigen::VectorXd j_flat = stacked * theta;
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
        J(j_flat.data(), r, n3);
    const Eigen::MatrixXd A = J * var_x_.asDiagonal();
    Eigen::MatrixXd S = A * J.transpose();
    S.diagonal() += var_tau_row_.segment(rows_.first, r);
    const Eigen::LLT<Eigen::MatrixXd> llt(S);
    if (llt.info() != Eigen::Success) return false;
    const auto L = llt.matrixL();
    residual = L.solve(b);
    if (whitened_rows) *whitened_rows = L.solve(W);
    if (whitened_y) *whitened_y = L.solve(block_.y.segment(rows_.first, r));
    if (jacobian) {
      jacobian->noalias() = -L.solve(W);
      // Φ(L⁻¹∂S_k L⁻ᵀ)·res, row a, is linear in D_k: Σ_c Dt_k(a,c)·G(a,c) + Σ_c At(a,c)·H_k(a,c)
      // with Dt_k = L⁻¹D_k, G(a,·) = Σ_{b≤a} w_ab·res_b·At(b,·), H_k(a,·) = Σ_{b≤a} w_ab·res_b·
      // Dt_k(b,·), w = 1 below the diagonal and ½ on it (Φ). With P = Φ-weighted prefix sums of
      // res_b·L⁻¹(b,·), H_k = P·D_k, so the term of every θ_k is Z·stacked with
      // Z(a, e·n3 + c) = L⁻¹(a,e)·G(a,c) + P(a,e)·At(a,c): one r × r·n3 by r·n3 × p product
      // instead of p triangular solves and r × r products.
      const Eigen::MatrixXd Linv = L.solve(Eigen::MatrixXd::Identity(r, r));
      const Eigen::MatrixXd At = Linv.triangularView<Eigen::Lower>() * A;  // L⁻¹A, r × n3
      Eigen::MatrixXd G(r, n3), P(r, r), Z = Eigen::MatrixXd::Zero(r, r * n3);
      Eigen::RowVectorXd g_sum = Eigen::RowVectorXd::Zero(n3), p_sum = Eigen::RowVectorXd::Zero(r);
      for (Eigen::Index a = 0; a < r; ++a) {
        G.row(a) = g_sum + 0.5 * residual[a] * At.row(a);
        g_sum += residual[a] * At.row(a);
        P.row(a) = p_sum + 0.5 * residual[a] * Linv.row(a);
        p_sum += residual[a] * Linv.row(a);
        for (Eigen::Index e = 0; e <= a; ++e) {
          Z.block(a, e * n3, 1, n3) = Linv(a, e) * G.row(a) + P(a, e) * At.row(a);
        }
      }
      jacobian->noalias() -= Z * stacked;
    }
    return true;
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::VectorXd> theta(parameters[0], block_.W.cols());
    Eigen::Map<Eigen::VectorXd> out(residuals, rows_.count);
    if (jacobians == nullptr || jacobians[0] == nullptr) return whiten(theta, out);
    Eigen::MatrixXd jac(rows_.count, block_.W.cols());
    if (!whiten(theta, out, nullptr, nullptr, &jac)) return false;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        jacobians[0], rows_.count, block_.W.cols()) = jac;
    return true;
  }

 private:
  const EquationBlock& block_;
  const Eigen::MatrixXd& sensitivity_;
  const Eigen::VectorXd& var_x_;
  const Eigen::VectorXd& var_tau_row_;
  SampleRows rows_;
};

Eigen::VectorXd squared_or_zero(const Eigen::VectorXd& std, int n, const char* name) {
  if (std.size() == 0) return Eigen::VectorXd::Zero(n);
  if (std.size() != n || !std.allFinite() || (std.array() < 0.0).any()) {
    throw Error(std::string("maximum likelihood: the ") + name + " noise needs " +
                std::to_string(n) + " finite standard deviations >= 0, got " +
                std::to_string(std.size()));
  }
  return std.array().square();
}

// The per-sample layout and noise variances of eq. 15 for `block`, after checking the sizes.
struct Eq15 {
  Eigen::VectorXd var_x;            // variances of q, q̇, q̈ of every joint (3n)
  Eigen::VectorXd var_tau_row;      // torque variance of every row
  std::vector<SampleRows> samples;  // the rows of each sample
};

Eq15 eq15_setup(const EquationBlock& block, const Eigen::MatrixXd& sensitivity,
                const MeasurementNoise& noise, const Eigen::VectorXd& start) {
  const Eigen::Index m = block.W.rows(), p = block.W.cols();
  const auto n = static_cast<int>(noise.tau.size());
  if (n < 1 || block.y.size() != m || block.sample.size() != m || block.group.size() != m ||
      sensitivity.rows() != 3 * n * m || sensitivity.cols() != p || start.size() != p) {
    throw Error("maximum likelihood: sizes do not match (W " + std::to_string(m) + "x" +
                std::to_string(p) + ", sensitivity " + std::to_string(sensitivity.rows()) + "x" +
                std::to_string(sensitivity.cols()) + ", start " + std::to_string(start.size()) +
                ", " + std::to_string(n) + " joints)");
  }
  if (!start.allFinite()) throw Error("maximum likelihood: the start estimate is not finite");
  if (!noise.tau.allFinite() || !(noise.tau.array() > 0.0).all()) {
    throw Error(
        "maximum likelihood needs a torque noise standard deviation > 0 for every joint; give "
        "--noise-std tau=S or measure it with dynid average");
  }
  if (m <= p) {
    throw Error("maximum likelihood: " + std::to_string(m) + " equations for " + std::to_string(p) +
                " parameters; record a longer run");
  }
  Eq15 out;
  Eigen::VectorXd& var_x = out.var_x;
  var_x.resize(3 * n);
  var_x << squared_or_zero(noise.q, n, "position"), squared_or_zero(noise.dq, n, "velocity"),
      squared_or_zero(noise.ddq, n, "acceleration");
  Eigen::VectorXd& var_tau_row = out.var_tau_row;
  var_tau_row.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    if (block.group[i] < 0 || block.group[i] >= n) {
      throw Error("maximum likelihood: row " + std::to_string(i) + " has joint " +
                  std::to_string(block.group[i]) + " outside the " + std::to_string(n) +
                  " joints of the noise description");
    }
    var_tau_row[i] = noise.tau[block.group[i]] * noise.tau[block.group[i]];
  }
  std::vector<SampleRows>& samples = out.samples;
  for (Eigen::Index i = 0; i < m; ++i) {
    if (i > 0 && block.sample[i] < block.sample[i - 1]) {
      throw Error("maximum likelihood: sample indices decrease at row " + std::to_string(i));
    }
    if (i == 0 || block.sample[i] != block.sample[i - 1]) samples.push_back({i, 0});
    ++samples.back().count;
  }
  return out;
}

}  // namespace

Eigen::VectorXd maximum_likelihood_residual(const EquationBlock& block,
                                            const Eigen::MatrixXd& sensitivity,
                                            const MeasurementNoise& noise,
                                            const Eigen::VectorXd& theta,
                                            Eigen::MatrixXd* jacobian) {
  const Eq15 eq = eq15_setup(block, sensitivity, noise, theta);
  const Eigen::Index m = block.W.rows(), p = block.W.cols();
  Eigen::VectorXd out(m);
  if (jacobian) jacobian->resize(m, p);
  for (const SampleRows& s : eq.samples) {
    const SampleCost cost(block, sensitivity, eq.var_x, eq.var_tau_row, s);
    Eigen::MatrixXd jac(s.count, p);
    if (!cost.whiten(theta, out.segment(s.first, s.count), nullptr, nullptr,
                     jacobian ? &jac : nullptr)) {
      throw Error("maximum likelihood: the noise covariance of sample " +
                  std::to_string(block.sample[s.first]) + " is not positive definite");
    }
    if (jacobian) jacobian->middleRows(s.first, s.count) = jac;
  }
  return out;
}

Estimate maximum_likelihood(const EquationBlock& block, const Eigen::MatrixXd& sensitivity,
                            const MeasurementNoise& noise, const Eigen::VectorXd& start,
                            const EstimationOptions& estimation_options,
                            const MaximumLikelihoodOptions& options,
                            MaximumLikelihoodSummary* summary) {
  const Eq15 eq = eq15_setup(block, sensitivity, noise, start);
  const Eigen::VectorXd& var_x = eq.var_x;
  const Eigen::VectorXd& var_tau_row = eq.var_tau_row;
  const std::vector<SampleRows>& samples = eq.samples;
  const Eigen::Index m = block.W.rows(), p = block.W.cols();

  // Eq. 15 by Levenberg–Marquardt from the OLS start, analytic Jacobian (SampleCost; S depends
  // on θ through B, eq. 16).
  Eigen::VectorXd theta = start;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (const SampleRows& s : samples) {
    problem.AddResidualBlock(new SampleCost(block, sensitivity, var_x, var_tau_row, s), nullptr,
                             theta.data());
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = options.function_tolerance;
  so.parameter_tolerance = options.parameter_tolerance;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.num_threads = 1;
  // Progress per iteration: ML is the slow estimator (seconds for a 6-joint base set).
  class ProgressReport final : public ceres::IterationCallback {
   public:
    ProgressReport(const ProgressCallback& progress, int max_iterations)
        : progress_(progress), max_iterations_(std::max(max_iterations, 1)) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& it) override {
      std::ostringstream what;
      what << "maximum likelihood iteration " << it.iteration << ", cost " << std::setprecision(4)
           << it.cost;
      progress_(std::min(1.0, static_cast<double>(it.iteration) / max_iterations_), what.str());
      return ceres::SOLVER_CONTINUE;
    }

   private:
    const ProgressCallback& progress_;
    int max_iterations_;
  };
  ProgressReport report(options.progress, options.max_iterations);
  if (options.progress) so.callbacks.push_back(&report);
  ceres::Solver::Summary cs;
  ceres::Solve(so, &problem, &cs);
  if (!theta.allFinite() || cs.termination_type == ceres::FAILURE) {
    throw Error("maximum likelihood did not converge (" + cs.message +
                "); check the noise standard deviations and the start estimate");
  }

  // Statistics at the estimate on the whitened rows: the information F = W̃ᵀW̃.
  Eigen::MatrixXd Wt(m, p);
  Eigen::VectorXd yt(m), et(m);
  for (const SampleRows& s : samples) {
    SampleCost cost(block, sensitivity, var_x, var_tau_row, s);
    Eigen::MatrixXd rows;
    Eigen::VectorXd y, e(s.count);
    if (!cost.whiten(theta, e, &rows, &y)) {
      throw Error("maximum likelihood: the noise covariance of sample " +
                  std::to_string(block.sample[s.first]) + " is singular at the estimate");
    }
    Wt.middleRows(s.first, s.count) = rows;
    yt.segment(s.first, s.count) = y;
    et.segment(s.first, s.count) = e;
  }
  Estimate est = ordinary_least_squares(Wt, yt, block.group, estimation_options);
  const double dof = static_cast<double>(m - est.summary.rank);
  const double variance_factor = et.squaredNorm() / dof;
  if (est.residual_variance > 0.0) est.covariance *= variance_factor / est.residual_variance;
  est.x = theta;
  est.residual_variance = variance_factor;
  fill_parameter_statistics(est, estimation_options);
  const Eigen::VectorXd e = block.y - block.W * theta;
  est.residual_rms = e.norm() / std::sqrt(static_cast<double>(m));
  est.relative_error = e.norm() / std::max(block.y.norm(), 1e-300);
  for (Eigen::Index g = 0; g < est.group_rms.size(); ++g) {
    double e2 = 0.0, y2 = 0.0, count = 0.0;
    for (Eigen::Index i = 0; i < m; ++i) {
      if (block.group[i] != g) continue;
      e2 += e[i] * e[i];
      y2 += block.y[i] * block.y[i];
      count += 1.0;
    }
    est.group_rms[g] = count > 0 ? std::sqrt(e2 / count) : NAN;
    est.group_relative_error[g] = y2 > 0 ? std::sqrt(e2 / y2) : NAN;
  }
  est.summary.estimator = EstimatorKind::kMaximumLikelihood;
  est.summary.passes = static_cast<int>(cs.iterations.size());
  if (options.projected_dimensions > 0) {
    EquationBlock whitened = block;
    whitened.W = Wt;
    whitened.y = yt;
    projected_statistics(est, whitened, options.projected_dimensions, false, estimation_options);
  } else if (options.hac) {
    apply_hac_covariance(est, Wt, et, block.sample, estimation_options);
  }
  if (summary != nullptr) {
    summary->iterations = static_cast<int>(cs.iterations.size());
    summary->initial_cost = cs.initial_cost;
    summary->final_cost = cs.final_cost;
    summary->converged = cs.termination_type == ceres::CONVERGENCE;
    summary->termination = cs.message;
    summary->variance_factor = variance_factor;
  }
  return est;
}

namespace {

// Processed-signal noise from raw σ_q, σ_τ and the white-noise gains g_k of k derivatives.
MeasurementNoise scaled_noise(const Eigen::VectorXd& sq, const Eigen::VectorXd& st, double g0,
                              double g1, double g2) {
  MeasurementNoise out;
  out.q = g0 * sq;
  out.dq = g1 * sq;
  out.ddq = g2 * sq;
  out.tau = g0 * st;
  return out;
}

}  // namespace

MeasurementNoise processed_noise(const SensorNoise& given, const SignalOptions& signal,
                                 const ProcessedRecord& processed, const JointRecord& raw,
                                 std::string& how) {
  const auto n = processed.record.q.cols();
  const double rate = processed.rate_hz * processed.decimate;
  auto check = [&](const Eigen::VectorXd& x, const char* what) {
    if (x.size() != 0 && (x.size() != n || !x.allFinite() || (x.array() < 0.0).any()))
      throw Error(std::string("the ") + what + " noise needs " + std::to_string(n) +
                  " finite standard deviations >= 0, got " + std::to_string(x.size()));
  };
  check(given.q, "position");
  check(given.tau, "torque");
  for (Eigen::Index j = 0; j < given.tau.size(); ++j)
    if (!(given.tau[j] > 0.0))
      throw Error(
          "maximum likelihood needs a torque noise standard deviation > 0 for every joint; the "
          "given one of joint " +
          std::to_string(j + 1) + " is 0 (--noise-std tau=0, or a --noise FILE whose tau" +
          std::to_string(j + 1) + " std is 0): give a std > 0");
  Eigen::VectorXd sq = given.q, st = given.tau;
  std::string source_q = "given", source_tau = "given";
  if (sq.size() == 0) {
    sq = processed.position_noise_std;
    source_q = "estimated (white floor of q's spectrum)";
  }
  if (st.size() == 0) {
    st = position_noise_floor(raw.tau, rate).noise_std;
    source_tau = "estimated (white floor of tau's spectrum)";
    for (Eigen::Index j = 0; j < st.size(); ++j)
      if (!std::isfinite(st[j]) || !(st[j] > 0.0))
        throw Error("maximum likelihood: the torque noise of joint " + std::to_string(j + 1) +
                    " is not visible in the data (no white floor in its spectrum); give "
                    "--noise-std tau=S or --noise FILE from dynid average");
  }
  sq = sq.unaryExpr([](double v) { return std::isfinite(v) ? v : 0.0; });
  // Gains of the processing chain identify() applied (preprocess(): unit-DC-gain low-pass).
  SosFilter filter;
  const bool filtered = signal.filter && processed.cutoff_hz > 0.0;
  if (filtered) {
    LowpassOptions lp;
    lp.family = signal.family;
    lp.order = signal.order;
    lp.cutoff_hz = processed.cutoff_hz;
    lp.sample_rate_hz = rate;
    lp.ripple_db = signal.ripple_db;
    filter = design_lowpass_unit_dc(lp);
  }
  const SosFilter* f = filtered ? &filter : nullptr;
  const double g0 = white_noise_gain(f, 0, rate), g1 = white_noise_gain(f, 1, rate),
               g2 = white_noise_gain(f, 2, rate);
  const MeasurementNoise out = scaled_noise(sq, st, g0, g1, g2);
  std::ostringstream s;
  s << std::setprecision(3) << "raw std q [" << sq.transpose() << "] " << source_q << ", tau ["
    << st.transpose() << "] " << source_tau << "; through the "
    << (filtered ? "filter" : "unfiltered chain") << " and central differences: q x " << g0
    << ", dq x " << g1 << ", ddq x " << g2 << ", tau x " << g0;
  how = s.str();
  return out;
}

MeasurementNoise projected_noise(const SensorNoise& given, const SignalProjector& projector,
                                 double ts, const ProcessedRecord& processed,
                                 const Eigen::VectorXd& torque_remainder_std, std::string& how) {
  const Eigen::Index n = processed.record.q.cols(), len = projector.samples();
  if (processed.record.q.rows() != len || torque_remainder_std.size() != n || !(ts > 0.0))
    throw Error(
        "projected_noise: the projector, the processed record and the remainders differ "
        "in size");
  Eigen::VectorXd sq = given.q.size() ? given.q : processed.position_noise_std;
  Eigen::VectorXd st = given.tau.size() ? given.tau : torque_remainder_std;
  if (sq.size() != n || st.size() != n || !sq.allFinite() || !st.allFinite() ||
      (sq.array() < 0.0).any())
    throw Error("the noise needs " + std::to_string(n) +
                " finite standard deviations >= 0 for q and tau");
  for (Eigen::Index j = 0; j < n; ++j)
    if (!(st[j] > 0.0))
      throw Error("maximum likelihood: the torque noise of joint " + std::to_string(j + 1) +
                  " is 0 after the projection; give --noise-std tau=S or --noise FILE");
  // An orthonormal basis U of P's range: P applied to a fixed-seed Gaussian matrix has rank d.
  const Eigen::Index d = projector.rank(), cols = std::min<Eigen::Index>(d + 8, len);
  std::mt19937_64 rng(13);
  std::normal_distribution<double> z;
  Eigen::MatrixXd Z(len, cols);
  for (Eigen::Index c = 0; c < cols; ++c)
    for (Eigen::Index k = 0; k < len; ++k) Z(k, c) = z(rng);
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(projector.project(Z), Eigen::ComputeThinU);
  const Eigen::MatrixXd U = svd.matrixU().leftCols(std::min(d, cols));
  const Eigen::Index inner = len - 2;
  if (inner < 1) throw Error("projected_noise: fewer than 3 samples");
  const Eigen::MatrixXd d1 = (U.bottomRows(inner) - U.topRows(inner)) / (2.0 * ts);
  const Eigen::MatrixXd d2 =
      (U.bottomRows(inner) - 2.0 * U.middleRows(1, inner) + U.topRows(inner)) / (ts * ts);
  const double g0 = std::sqrt(U.squaredNorm() / static_cast<double>(len));
  const double g1 = std::sqrt(d1.squaredNorm() / static_cast<double>(inner));
  const double g2 = std::sqrt(d2.squaredNorm() / static_cast<double>(inner));
  const MeasurementNoise out = scaled_noise(sq, st, g0, g1, g2);
  std::ostringstream s;
  s << std::setprecision(3) << "std q [" << sq.transpose() << "] "
    << (given.q.size() ? "given" : "of the remainder q - q^ (taken as white)") << ", tau ["
    << st.transpose() << "] "
    << (given.tau.size() ? "given" : "of the remainder tau - tau^ (taken as white)")
    << "; through the projection (" << d << " of " << len
    << " dimensions per channel) and its derivatives: q x " << g0 << ", dq x " << g1 << ", ddq x "
    << g2 << ", tau x " << g0;
  how = s.str();
  return out;
}

void maximum_likelihood_stage(const Model& model, const IdentifyOptions& options, bool coupling,
                              const std::vector<EquationBlock>& blocks,
                              const std::vector<ProcessedRecord>& processed,
                              const JointRecord& first_raw, const std::vector<int>& columns,
                              const EquationBlock& stacked, const ProjectedRun& projected,
                              BlockEstimate& fit,
                              std::vector<std::pair<std::string, std::string>>& choices) {
  if (blocks.size() != processed.size() || blocks.empty())
    throw Error("maximum_likelihood_stage: one processed record per block is needed");
  const int n = model.dof();
  std::vector<Eigen::MatrixXd> parts;
  Eigen::Index rows = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    parts.push_back(differential_sensitivity(model, options.layout, coupling, processed[b], columns,
                                             blocks[b].sample, blocks[b].group));
    rows += parts.back().rows();
  }
  Eigen::MatrixXd sensitivity(rows, static_cast<Eigen::Index>(columns.size()));
  Eigen::Index at = 0;
  for (const auto& part : parts) {
    sensitivity.middleRows(at, part.rows()) = part;
    at += part.rows();
  }
  std::string how;
  const MeasurementNoise noise =
      projected.projector
          ? projected_noise(options.noise, *projected.projector, 1.0 / processed.front().rate_hz,
                            processed.front(), projected.torque_remainder_std, how)
          : processed_noise(options.noise, options.signal, processed.front(), first_raw, how);
  choices.emplace_back("noise", how);
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = stacked.columns;
  MaximumLikelihoodSummary summary;
  MaximumLikelihoodOptions mo;
  mo.projected_dimensions = projected.projector ? projected.dimensions : 0;
  mo.progress = options.progress;
  fit.estimate = maximum_likelihood(stacked, sensitivity, noise, fit.estimate.x, eo, mo, &summary);
  const Eigen::VectorXd e = stacked.y - stacked.W * fit.estimate.x;
  fit.residual = e;
  fit.relative_error = e.norm() / std::max(stacked.y.norm(), 1e-300);
  Eigen::VectorXd e2 = Eigen::VectorXd::Zero(n), y2 = Eigen::VectorXd::Zero(n),
                  cnt = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < e.size(); ++i) {
    e2[stacked.group[i]] += e[i] * e[i];
    y2[stacked.group[i]] += stacked.y[i] * stacked.y[i];
    cnt[stacked.group[i]] += 1.0;
  }
  fit.group_rms = (e2.array() / cnt.array().max(1.0)).sqrt();
  fit.group_relative_error = (e2.array() / y2.array().max(1e-300)).sqrt();
  std::ostringstream c;
  c << std::setprecision(3)
    << "maximum likelihood with errors in q, dq, ddq and tau (Bona, Curatella eqs. 15-16; Ceres "
       "Levenberg-Marquardt from OLS, "
    << summary.iterations << " iterations, " << summary.termination << "); variance factor "
    << summary.variance_factor << " (about 1 when the noise is right); "
    << fit.estimate.covariance_kind << " covariance on the whitened rows";
  if (mo.projected_dimensions > 0)
    c << " (" << mo.projected_dimensions << " dimensions spanned, Student-t intervals with "
      << fit.estimate.degrees_of_freedom << " degrees of freedom)";
  fit.covariance_choice = c.str();
}

}  // namespace dynid
