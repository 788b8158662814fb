#include "dynid/identification/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "dynid/common/error.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/recursive_least_squares.hpp"

namespace dynid {

namespace {

// Lag-1 residual autocorrelation above which the intervals' white-noise assumption is named.
constexpr double kCorrelatedResidualWarning = 0.5;

// A window's smallest eigenvalue above this fraction of the largest counts as excited (eq. 38).
constexpr double kExcitedEigenvalueRatio = 1e-6;

}  // namespace

EquationBlock differential_equations(const Model& model, const ParameterLayout& layout,
                                     bool coupling, const ProcessedRecord& processed,
                                     const Eigen::VectorXd& zero_velocity_threshold) {
  const int n = model.dof();
  if (zero_velocity_threshold.size() != 0 && zero_velocity_threshold.size() != n) {
    throw Error("differential_equations: " + std::to_string(zero_velocity_threshold.size()) +
                " zero-velocity thresholds for " + std::to_string(n) + " joints");
  }
  const JointRecord& r = processed.record;
  const Eigen::Index m = r.t.size();
  EquationBlock b;
  b.W = processed_regressor(model, layout, coupling, processed);
  b.columns = stacked_regressor_names(model, layout, coupling);
  for (const auto& joint : model.joints) b.group_names.push_back(joint.name);
  // Sample-major rows: y(k·n + j) = tau(k, j).
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> tau = r.tau;
  b.y = Eigen::Map<const Eigen::VectorXd>(tau.data(), m * n);
  b.group.resize(m * n);
  b.sample.resize(m * n);
  b.t.resize(m * n);
  for (Eigen::Index k = 0; k < m; ++k) {
    for (int j = 0; j < n; ++j) {
      b.group[k * n + j] = j;
      b.sample[k * n + j] = static_cast<int>(k);
      b.t[k * n + j] = r.t[k];
    }
  }
  if (!layout.coulomb || zero_velocity_threshold.size() == 0) return b;
  return moving_rows(b, r.dq, zero_velocity_threshold);
}

EquationBlock moving_rows(const EquationBlock& block, const Eigen::MatrixXd& dq,
                          const Eigen::VectorXd& threshold) {
  std::vector<Eigen::Index> keep;
  keep.reserve(static_cast<size_t>(block.y.size()));
  for (Eigen::Index i = 0; i < block.y.size(); ++i) {
    const int j = block.group[i];
    if (std::abs(dq(block.sample[i], j)) >= threshold[j]) keep.push_back(i);
  }
  const auto rows = static_cast<Eigen::Index>(keep.size());
  EquationBlock out;
  out.columns = block.columns;
  out.group_names = block.group_names;
  out.W.resize(rows, block.W.cols());
  out.y.resize(rows);
  out.group.resize(rows);
  out.sample.resize(rows);
  out.t.resize(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    out.W.row(i) = block.W.row(keep[i]);
    out.y[i] = block.y[keep[i]];
    out.group[i] = block.group[keep[i]];
    out.sample[i] = block.sample[keep[i]];
    out.t[i] = block.t[keep[i]];
  }
  return out;
}

EquationBlock stack_equations(const std::vector<EquationBlock>& blocks, int gap) {
  if (blocks.empty()) throw Error("stack_equations: no blocks");
  if (blocks.size() == 1) return blocks.front();
  Eigen::Index rows = 0;
  long long span = 0;
  for (const auto& b : blocks) {
    if (b.columns != blocks.front().columns || b.group_names != blocks.front().group_names) {
      throw Error(
          "stack_equations: the runs' equations have different columns or row groups; stack "
          "runs of one robot and one friction set");
    }
    rows += b.y.size();
    if (b.sample.size()) span += static_cast<long long>(b.sample.maxCoeff()) + 1;
  }
  if (gap < 1) throw Error("stack_equations: gap " + std::to_string(gap) + " is not >= 1");
  if (span + gap * static_cast<long long>(blocks.size()) > std::numeric_limits<int>::max()) {
    throw Error("stack_equations: too many samples to index (" + std::to_string(span) + ")");
  }
  EquationBlock out;
  out.columns = blocks.front().columns;
  out.group_names = blocks.front().group_names;
  out.W.resize(rows, blocks.front().W.cols());
  out.y.resize(rows);
  out.group.resize(rows);
  out.sample.resize(rows);
  out.t.resize(rows);
  Eigen::Index at = 0;
  long long offset = 0;
  for (const auto& b : blocks) {
    const Eigen::Index r = b.y.size();
    out.W.middleRows(at, r) = b.W;
    out.y.segment(at, r) = b.y;
    out.group.segment(at, r) = b.group;
    out.sample.segment(at, r) = b.sample.array() + static_cast<int>(offset);
    out.t.segment(at, r) = b.t;
    at += r;
    if (b.sample.size()) offset += static_cast<long long>(b.sample.maxCoeff()) + 1 + gap;
  }
  return out;
}

EquationBlock select_base_columns(const EquationBlock& block, const BaseParameters& base) {
  if (block.columns != base.layout_names) {
    throw Error(
        "select_base_columns: the equations' columns are not the base-parameter layout; build "
        "both from the same model, layout and coupling");
  }
  EquationBlock out = select_columns(block, base.base);
  out.columns = base.names;
  return out;
}

EquationBlock select_columns(const EquationBlock& block, const std::vector<int>& columns) {
  EquationBlock out;
  out.W.resize(block.W.rows(), static_cast<Eigen::Index>(columns.size()));
  for (size_t c = 0; c < columns.size(); ++c) {
    out.W.col(static_cast<Eigen::Index>(c)) = block.W.col(columns[c]);
    out.columns.push_back(block.columns[static_cast<size_t>(columns[c])]);
  }
  out.y = block.y;
  out.group = block.group;
  out.sample = block.sample;
  out.t = block.t;
  out.group_names = block.group_names;
  return out;
}

EquationBlock select_named_columns(const EquationBlock& block,
                                   const std::vector<std::string>& names) {
  std::vector<int> columns;
  columns.reserve(names.size());
  for (const std::string& name : names) {
    const auto it = std::find(block.columns.begin(), block.columns.end(), name);
    if (it == block.columns.end()) {
      throw Error("parameter '" + name +
                  "' is not a column of these equations; build them with the model, friction set "
                  "and coupling of the result");
    }
    columns.push_back(static_cast<int>(it - block.columns.begin()));
  }
  return select_columns(block, columns);
}

DataIdentifiability data_identifiability(const EquationBlock& block,
                                         const DataIdentifiabilityOptions& options) {
  const Eigen::Index p = block.W.cols();
  DataIdentifiability out;
  out.tolerance = options.roundoff_tolerance;
  out.absorbs.clear();
  // Column scaling: a zero column (no data at all) stays zero and is never kept. So does a column
  // that is zero up to round-off (below kRoundOffColumn × the largest column norm): unit scaling
  // would blow it up into an independent direction. Seen on a joint held still: the kinetic-energy
  // columns of its link that cancel analytically came out 1e-17 and 1e-33, not 0, and were
  // "estimated" with σ ~ 1e19. Columns of one regressor differ by the motion's and geometry's
  // scale, orders of magnitude, never twelve.
  constexpr double kRoundOffColumn = 1e-12;
  const Eigen::VectorXd norms = block.W.colwise().norm().transpose();
  double largest = 0.0;
  for (Eigen::Index c = 0; c < p; ++c) {
    if (std::isfinite(norms[c])) largest = std::max(largest, norms[c]);
  }
  std::vector<int> nonzero;
  for (Eigen::Index c = 0; c < p; ++c) {
    if (norms[c] > kRoundOffColumn * largest && std::isfinite(norms[c]))
      nonzero.push_back(static_cast<int>(c));
  }
  if (nonzero.empty()) {
    for (Eigen::Index c = 0; c < p; ++c) out.not_excited.push_back(static_cast<int>(c));
    return out;
  }
  const auto q = static_cast<Eigen::Index>(nonzero.size());
  const Eigen::Index m = block.W.rows();
  Eigen::MatrixXd S(m, q);
  for (Eigen::Index c = 0; c < q; ++c) S.col(c) = block.W.col(nonzero[c]) / norms[nonzero[c]];
  // The R factor of S (q × q) carries everything below: singular values, the sweep, the
  // regrouping; Qᵀy gives the residual of the fit on every column.
  Eigen::HouseholderQR<Eigen::MatrixXd> thin(S);
  const Eigen::Index h = std::min(q, m);
  const Eigen::MatrixXd R = thin.matrixQR().topRows(h).triangularView<Eigen::Upper>();
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(R).singularValues();
  const double smax = sv.size() ? sv[0] : 0.0;
  // The statistical rule (docs/methods/identification.md, "What the data determine"). In the
  // scaled parameters φ = diag(‖W_c‖)·θ a unit direction v with singular value σ is fitted with
  // standard deviation ŝ/σ (ŝ the residual noise std per equation). Its plausible magnitude:
  // a unit-norm combination of columns with coefficient φ carries a torque of norm |φ| on a run
  // that excites it as these data excite their best direction, and no parameter combination of
  // a physical model carries more than the robot's whole torque, ‖y‖. A direction is determined
  // when ŝ/σ ≤ precision·‖y‖, i.e. σ ≥ ŝ/(precision·‖y‖): below, its estimate cannot be told
  // from zero or from a value as large as everything measured. Without a usable y (no rows to
  // spare, no torque) only the round-off floor applies.
  const double ynorm = block.y.size() == m && block.y.allFinite() ? block.y.norm() : 0.0;
  double threshold = options.roundoff_tolerance * smax;
  if (ynorm > 0.0 && m > q && options.precision > 0.0) {
    const Eigen::VectorXd qty = thin.householderQ().adjoint() * block.y;
    const double noise = qty.tail(m - q).norm() / std::sqrt(static_cast<double>(m - q));
    out.noise_std = noise;
    out.plausible_magnitude = ynorm;
    threshold = std::max(threshold, noise / (options.precision * ynorm));
  }
  out.tolerance = smax > 0.0 ? threshold / smax : options.roundoff_tolerance;
  // Keep the earliest columns that are determined (a left-to-right sweep, as the model's base
  // parameters are chosen): a column is kept when its distance to the span of the kept ones (the
  // singular value of the direction it adds) passes the threshold.
  std::vector<Eigen::Index> kept_local;
  Eigen::MatrixXd basis(R.rows(), 0);
  for (Eigen::Index c = 0; c < q; ++c) {
    Eigen::VectorXd v = R.col(c);
    if (basis.cols()) v -= basis * (basis.transpose() * v);
    if (basis.cols()) v -= basis * (basis.transpose() * v);  // re-orthogonalise
    if (v.norm() > threshold) {
      basis.conservativeResize(Eigen::NoChange, basis.cols() + 1);
      basis.col(basis.cols() - 1) = v / v.norm();
      kept_local.push_back(c);
    }
  }
  // Each kept column adds a direction above the threshold, but together they may still hold one
  // below it (σ_min of a triangular factor can be far below its smallest pivot): leave out the
  // kept column that carries most of the weakest direction (the later one on a tie), until none
  // is left.
  while (!kept_local.empty()) {
    Eigen::MatrixXd Rk(R.rows(), static_cast<Eigen::Index>(kept_local.size()));
    for (size_t i = 0; i < kept_local.size(); ++i)
      Rk.col(static_cast<Eigen::Index>(i)) = R.col(kept_local[i]);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Rk, Eigen::ComputeThinV);
    const Eigen::Index last = svd.singularValues().size() - 1;
    if (svd.singularValues()[last] > threshold) break;
    const Eigen::VectorXd weakest = svd.matrixV().col(last).cwiseAbs();
    Eigen::Index drop = 0;
    for (Eigen::Index i = 1; i < weakest.size(); ++i)
      if (weakest[i] >= weakest[drop] * (1.0 - 1e-9)) drop = i;
    kept_local.erase(kept_local.begin() + drop);
  }
  out.rank = static_cast<int>(kept_local.size());
  std::vector<bool> is_kept(static_cast<size_t>(p), false);
  for (Eigen::Index c : kept_local) is_kept[static_cast<size_t>(nonzero[c])] = true;
  for (Eigen::Index c = 0; c < p; ++c) {
    (is_kept[static_cast<size_t>(c)] ? out.kept : out.not_excited).push_back(static_cast<int>(c));
  }
  // Data regrouping: each dropped column d = S_kept·k (scaled); θ_kept absorbs k·θ_d.
  Eigen::MatrixXd Rk(R.rows(), static_cast<Eigen::Index>(kept_local.size()));
  for (size_t i = 0; i < kept_local.size(); ++i)
    Rk.col(static_cast<Eigen::Index>(i)) = R.col(kept_local[i]);
  const auto solver = Rk.colPivHouseholderQr();
  out.absorbs.assign(out.kept.size(), {});
  for (Eigen::Index c = 0; c < q; ++c) {
    const int col = nonzero[c];
    if (is_kept[static_cast<size_t>(col)] || kept_local.empty()) continue;
    const Eigen::VectorXd k = solver.solve(Eigen::VectorXd(R.col(c)));
    // Exactly dependent (to round-off, the floor below which no noise level matters) or only
    // undetermined at this noise: the first is a regrouping of these data, named as such.
    if ((R.col(c) - Rk * k).norm() <= options.roundoff_tolerance * smax)
      out.regrouped.push_back(col);
    for (Eigen::Index i = 0; i < k.size(); ++i) {
      if (std::abs(k[i]) < options.absorb_threshold) continue;
      const int kc = out.kept[static_cast<size_t>(i)];
      // Unscale: W_d = Σ W_kept·k·‖W_d‖/‖W_kept‖.
      out.absorbs[static_cast<size_t>(i)].emplace_back(col, k[i] * norms[col] / norms[kc]);
    }
  }
  return out;
}

namespace {

BlockEstimate estimate_as_given(const EquationBlock& block, const BlockEstimationOptions& options);

// θ_c = θ̃_c / s_c for the estimate of the column-scaled block W̃ = W·diag(s)⁻¹... with s the column
// norms: every σ, interval and history entry scales the same way; relative σ does not change.
void unscale(BlockEstimate& b, const Eigen::VectorXd& s) {
  Estimate& e = b.estimate;
  const Eigen::ArrayXd inv = s.array().inverse();
  e.x.array() *= inv;
  e.covariance = inv.matrix().asDiagonal() * e.covariance * inv.matrix().asDiagonal();
  e.std_dev.array() *= inv;
  e.ci_lower.array() *= inv;
  e.ci_upper.array() *= inv;
  if (e.std_dev_white.size()) {
    e.std_dev_white.array() *= inv;
    e.ci_lower_white.array() *= inv;
    e.ci_upper_white.array() *= inv;
  }
  if (b.history_x.size()) {
    b.history_x = b.history_x * inv.matrix().asDiagonal();
    b.history_std = b.history_std * inv.matrix().asDiagonal();
  }
}

}  // namespace

BlockEstimate estimate_block(const EquationBlock& block, const BlockEstimationOptions& options) {
  BlockEstimate out = estimate_as_given(block, options);
  const Eigen::Index p = block.W.cols();
  if (out.estimate.summary.rank >= p) return out;
  // Numerically rank deficient as given, but the columns may only differ in scale by more than
  // the estimator's round-off tolerance max(m, p)·ε allows (a 6-joint arm's inertia and friction
  // columns span 1e10 with many rows): solve the column-scaled problem, which has the same
  // solution, and scale back. Only then, so that well-scaled problems keep their numbers.
  const Eigen::VectorXd s = block.W.colwise().norm().transpose();
  if ((s.array() <= 0.0).any() || !s.allFinite()) return out;
  EquationBlock scaled = block;
  scaled.W = block.W * s.cwiseInverse().asDiagonal();
  BlockEstimate again = estimate_as_given(scaled, options);
  if (again.estimate.summary.rank <= out.estimate.summary.rank) return out;
  unscale(again, s);
  again.residual = block.y - block.W * again.estimate.x;
  again.covariance_choice +=
      "; solved on unit-norm columns (the columns' scales differ beyond round-off), condition "
      "number of the scaled regressor";
  return again;
}

namespace {

BlockEstimate estimate_as_given(const EquationBlock& block, const BlockEstimationOptions& options) {
  const Eigen::MatrixXd& W = block.W;
  const Eigen::VectorXd& y = block.y;
  const Eigen::VectorXi& groups = block.group;
  const Eigen::Index rows = y.size();
  const auto n = static_cast<Eigen::Index>(block.group_names.size());
  BlockEstimate out;
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = block.columns;
  switch (options.estimator) {
    case IdentificationEstimator::kOls:
    case IdentificationEstimator::kMl:  // the start of maximum likelihood (identify())
      out.estimate = ordinary_least_squares(W, y, groups, eo);
      break;
    case IdentificationEstimator::kWls:
      out.estimate = weighted_least_squares(W, y, groups, eo);
      break;
    case IdentificationEstimator::kRls: {
      if (!options.record_history) {
        out.estimate = recursive_least_squares(W, y, {}, eo);
        break;
      }
      RecursiveLeastSquares rls(W.cols());
      const Eigen::Index p = W.cols();
      out.history_t = block.t;
      out.history_x.resize(rows, p);
      out.history_std.resize(rows, p);
      rls.set_callback([&](Eigen::Index k, const Eigen::VectorXd& x) {
        // σ after k equations: σ² = J/(k − p) times diag(P) = Σ_j U_ij² D_j (O(p²), no P).
        const Eigen::Index i = k - 1;
        out.history_x.row(i) = x.transpose();
        const Eigen::MatrixXd U = rls.covariance_factor();
        const Eigen::VectorXd& D = rls.covariance_diagonal();
        const double s2 = k > p ? rls.cost() / static_cast<double>(k - p)
                                : std::numeric_limits<double>::quiet_NaN();
        for (Eigen::Index c = 0; c < p; ++c) {
          out.history_std(i, c) = std::sqrt(s2 * U.row(c).array().square().matrix().dot(D));
        }
      });
      rls.update(W, y);
      out.estimate = rls.estimate(eo);
      break;
    }
  }
  // Residuals per group, unweighted.
  const Eigen::VectorXd e = y - W * out.estimate.x;
  out.residual = e;
  Eigen::VectorXd e2 = Eigen::VectorXd::Zero(n), y2 = Eigen::VectorXd::Zero(n),
                  cnt = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < rows; ++i) {
    e2[groups[i]] += e[i] * e[i];
    y2[groups[i]] += y[i] * y[i];
    cnt[groups[i]] += 1.0;
  }
  out.group_rms = (e2.array() / cnt.array().max(1.0)).sqrt();
  out.group_relative_error = (e2.array() / y2.array().max(1e-300)).sqrt();
  out.relative_error = e.norm() / y.norm();
  // Lag-1 autocorrelation of each group's residual series over consecutive samples: the
  // intervals assume white residuals; filtered data or unmodelled dynamics make them correlated.
  Eigen::VectorXd lag = Eigen::VectorXd::Zero(n), prev_e = Eigen::VectorXd::Zero(n);
  std::vector<long long> prev_k(static_cast<size_t>(n), -2);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const int j = groups[i];
    const long long k = block.sample[i];
    if (k == prev_k[static_cast<size_t>(j)] + 1) lag[j] += e[i] * prev_e[j];
    prev_k[static_cast<size_t>(j)] = k;
    prev_e[j] = e[i];
  }
  out.group_autocorrelation = lag.array() / e2.array().max(1e-300);
  std::string correlated;
  double worst = 0.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (out.group_autocorrelation[j] > kCorrelatedResidualWarning) {
      correlated += (correlated.empty() ? "" : ", ") + block.group_names[static_cast<size_t>(j)];
      worst = std::max(worst, out.group_autocorrelation[j]);
    }
  }
  // Default intervals: HAC sandwich over samples (the estimator's own bread, so WLS weights and
  // the RLS prior carry over); the white-noise ones stay as std_white.
  Eigen::MatrixXd Ws = W;
  Eigen::VectorXd es = e;
  if (options.estimator == IdentificationEstimator::kWls) {
    for (Eigen::Index i = 0; i < rows; ++i) {
      const double v = out.estimate.group_variance[groups[i]];
      const double w = v > 0.0 && std::isfinite(v) ? 1.0 / std::sqrt(v) : 1.0;
      Ws.row(i) *= w;
      es[i] *= w;
    }
  }
  HacOptions hac;
  hac.bandwidth = options.hac_bandwidth;
  out.hac = apply_hac_covariance(out.estimate, Ws, es, block.sample, eo, hac);
  const HacSummary& h = out.hac;
  std::ostringstream c;
  c << std::setprecision(3);
  if (out.estimate.covariance_kind == "white") {
    c << "white-noise sigma^2 (W^T W)^-1 (no residual degrees of freedom for a sandwich)";
  } else {
    c << "Newey-West (HAC) sandwich over samples, Bartlett window of " << h.bandwidth
      << " samples (";
    if (options.hac_bandwidth >= 0) {
      c << "given";
    } else {
      c << "Andrews AR(1) rule, b >= " << hac.min_bandwidth_fraction;
    }
    c << "), ci_* = value -+ " << h.critical_value << " std (fixed-b critical value at b = " << h.b
      << ", Kiefer-Vogelsang 2005): std and ci_* allow for correlated residuals "
         "(filtering, unmodelled dynamics); std_white assumes white residuals and is "
      << h.median_ratio << "x smaller (median)";
  }
  out.covariance_choice = c.str();
  if (!correlated.empty()) {
    std::ostringstream w;
    w << "residuals of " << correlated << " are correlated (lag-1 autocorrelation up to "
      << std::setprecision(2) << worst
      << "): filtered noise or dynamics the model lacks; std/ci_* account for it (HAC), "
         "std_white would be about "
      << std::setprecision(2) << h.median_ratio
      << "x too narrow; judge the model on a validation run";
    out.estimate.summary.warnings.push_back(w.str());
  }
  out.warnings = out.estimate.summary.warnings;
  return out;
}

}  // namespace

ExcitationSummary persistent_excitation(const EquationBlock& block, int window) {
  const Eigen::Index m = block.W.rows(), p = block.W.cols();
  ExcitationSummary out;
  // Default: a tenth of the run (but at least 10 equations per parameter): short enough to say
  // from when the condition holds, long enough to span a slow excitation's period.
  out.window = window > 0 ? window : static_cast<int>(std::max<Eigen::Index>(10 * p, m / 10));
  out.holds_from_t = std::numeric_limits<double>::quiet_NaN();
  if (m == 0 || p == 0) return out;
  const Eigen::VectorXd norms = block.W.colwise().norm().transpose();
  // Scale each column to unit mean square per equation so that α, β compare like with like.
  Eigen::VectorXd scale(p);
  for (Eigen::Index c = 0; c < p; ++c)
    scale[c] = norms[c] > 0.0 ? std::sqrt(static_cast<double>(m)) / norms[c] : 1.0;
  const Eigen::Index rho = std::min<Eigen::Index>(out.window, m);
  const Eigen::Index stride = std::max<Eigen::Index>(1, rho / 2);
  out.min_eigenvalue = std::numeric_limits<double>::infinity();
  out.max_eigenvalue = 0.0;
  std::vector<std::pair<double, bool>> windows;  // (t at window end, condition holds)
  for (Eigen::Index start = 0; start + rho <= m; start += stride) {
    const Eigen::MatrixXd D = block.W.middleRows(start, rho) * scale.asDiagonal();
    const Eigen::MatrixXd G = D.transpose() * D;
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G).eigenvalues();
    out.min_eigenvalue = std::min(out.min_eigenvalue, std::max(0.0, ev[0]));
    out.max_eigenvalue = std::max(out.max_eigenvalue, ev[p - 1]);
    windows.emplace_back(block.t[start + rho - 1],
                         ev[p - 1] > 0.0 && ev[0] > kExcitedEigenvalueRatio * ev[p - 1]);
    ++out.windows;
  }
  // The first time from which every later window is excited.
  for (auto it = windows.rbegin(); it != windows.rend() && it->second; ++it) {
    out.holds_from_t = it->first;
  }
  if (!std::isfinite(out.min_eigenvalue)) out.min_eigenvalue = 0.0;
  return out;
}

}  // namespace dynid
