#include "dynid/estimation/streaming_least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/estimation/statistics.hpp"
#include "factor_solve.hpp"
#include "gram_update.hpp"

namespace dynid {

using estimation_detail::check_names;
using estimation_detail::column_list;
using estimation_detail::solve_factor;
using estimation_detail::triangular_append;

namespace {
// Rows gathered per group before they are folded in; bounds the scratch memory.
constexpr Eigen::Index kChunk = 256;
// Normal equations: folds summed into a partial Gram matrix before it is added to the total. Each
// addition to the growing total rounds at ≈ u·|total|, so two levels cut the additions to the
// total 64-fold (10⁶ samples: 61 instead of 3 906) and their round-off ≈ 8-fold.
constexpr int kFoldsPerPartial = 64;
// Group variances below this fraction of the largest are floored (WLS weights stay finite).
constexpr double kVarianceFloor = 1e-12;

// Eigen-decomposition of a group's Gram matrix after column equilibration (D⁻¹GD⁻¹, unit
// diagonal), shared by the accuracy test and the factor.
struct ScaledGram {
  Eigen::VectorXd d;  // column norms of [W_g y_g]
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig;
  bool positive = false;  // every column non-zero
};

ScaledGram scaled_gram(const Eigen::MatrixXd& upper) {
  ScaledGram s;
  const Eigen::MatrixXd G = upper.selfadjointView<Eigen::Upper>();
  s.d = G.diagonal().cwiseMax(0.0).cwiseSqrt();
  s.positive = (s.d.array() > 0.0).all();
  const Eigen::VectorXd inv = s.d.unaryExpr([](double v) { return v > 0.0 ? 1.0 / v : 0.0; });
  s.eig.compute(inv.asDiagonal() * G * inv.asDiagonal());
  return s;
}
}  // namespace

StreamingLeastSquares::StreamingLeastSquares(Eigen::Index parameters, int groups,
                                             const StreamingOptions& options)
    : parameters_(parameters), options_(options) {
  if (parameters < 1) {
    throw Error("StreamingLeastSquares: parameters is " + std::to_string(parameters) +
                "; W needs at least one column");
  }
  if (groups < 1) {
    throw Error("StreamingLeastSquares: groups is " + std::to_string(groups) +
                "; pass at least one row group (e.g. the joint count)");
  }
  const auto& cols = options.group_columns;
  if (!cols.empty() && static_cast<int>(cols.size()) != groups) {
    throw Error("StreamingOptions::group_columns has " + std::to_string(cols.size()) +
                " lists for " + std::to_string(groups) +
                " groups; give one list per group or none");
  }
  groups_.resize(groups);
  for (int g = 0; g < groups; ++g) {
    Group& grp = groups_[g];
    if (cols.empty()) {
      grp.columns.resize(parameters);
      for (Eigen::Index c = 0; c < parameters; ++c) grp.columns[c] = c;
    } else {
      grp.columns = cols[g];
      for (std::size_t i = 0; i < grp.columns.size(); ++i) {
        const Eigen::Index c = grp.columns[i];
        if (c < 0 || c >= parameters || (i > 0 && c <= grp.columns[i - 1])) {
          throw Error("StreamingOptions::group_columns[" + std::to_string(g) +
                      "] is not a sorted list of distinct columns in [0, " +
                      std::to_string(parameters) + "); fix entry " + std::to_string(i));
        }
      }
    }
    grp.columns.push_back(parameters);  // the y column
    const auto q = static_cast<Eigen::Index>(grp.columns.size());
    grp.summary = Eigen::MatrixXd::Zero(q, q);
    if (options.accumulation == Accumulation::kNormalEquations) {
      grp.partial = Eigen::MatrixXd::Zero(q, q);
    }
    // Rows q… stay zero: the padding the Gram kernel reads.
    grp.pending = Eigen::MatrixXd::Zero(estimation_detail::gram_padded_rows(q), kChunk);
  }
  work_.resize(parameters + 1);
}

void StreamingLeastSquares::reset() {
  for (auto& g : groups_) {
    g.summary.setZero();
    g.partial.setZero();
    g.partial_folds = 0;
    g.pending_rows = 0;
    g.rows = 0;
  }
  rows_ = 0;
}

std::vector<Eigen::Index> StreamingLeastSquares::group_rows() const {
  std::vector<Eigen::Index> rows;
  for (const auto& g : groups_) rows.push_back(g.rows);
  return rows;
}

void StreamingLeastSquares::check_block(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                        const Eigen::Ref<const Eigen::VectorXd>& y) const {
  estimation_detail::check_sizes(W, y, parameters_);
  if (!W.allFinite()) {
    for (Eigen::Index i = 0; i < W.rows(); ++i) {
      if (!W.row(i).allFinite()) {
        throw Error("W row " + std::to_string(rows_ + i) +
                    " contains NaN or Inf; remove or repair that sample");
      }
    }
  }
  if (!y.allFinite()) {
    for (Eigen::Index i = 0; i < y.size(); ++i) {
      if (!std::isfinite(y(i))) {
        throw Error("y row " + std::to_string(rows_ + i) +
                    " is NaN or Inf; remove or repair that sample");
      }
    }
  }
}

void StreamingLeastSquares::fold(Group& g) const {
  if (g.pending_rows == 0) return;
  const Eigen::Index q = g.summary.rows();
  if (options_.accumulation == Accumulation::kHouseholder) {
    Eigen::MatrixXd B = g.pending.topLeftCorner(q, g.pending_rows).transpose();
    triangular_append(g.summary, B, work_);
  } else {
    estimation_detail::gram_update_upper(q, g.pending_rows, g.pending.data(), g.pending.rows(),
                                         g.partial.data());
    if (++g.partial_folds == kFoldsPerPartial) drain(g);
  }
  g.pending_rows = 0;
}

void StreamingLeastSquares::drain(Group& g) const {
  if (g.partial_folds == 0) return;
  g.summary.triangularView<Eigen::Upper>() += g.partial;
  g.partial.setZero();
  g.partial_folds = 0;
}

void StreamingLeastSquares::flush() const {
  for (auto& g : groups_) {
    fold(g);
    drain(g);
  }
}

void StreamingLeastSquares::add_full_row(int group, const Eigen::Ref<const Eigen::MatrixXd>& W,
                                         const Eigen::Ref<const Eigen::VectorXd>& y,
                                         Eigen::Index i) {
  Group& g = groups_[group];
  const auto pg = static_cast<Eigen::Index>(g.columns.size()) - 1;
  std::size_t next = 0;
  for (Eigen::Index c = 0; c < parameters_; ++c) {
    if (next < static_cast<std::size_t>(pg) && g.columns[next] == c) {
      g.pending(static_cast<Eigen::Index>(next++), g.pending_rows) = W(i, c);
    } else if (W(i, c) != 0.0) {
      throw Error("W row " + std::to_string(rows_ + i) + " (group " + std::to_string(group) +
                  ") is non-zero in column " + std::to_string(c) +
                  ", which StreamingOptions::group_columns excludes; add it to that list");
    }
  }
  g.pending(pg, g.pending_rows) = y(i);
  ++g.rows;
  if (++g.pending_rows == kChunk) fold(g);
}

void StreamingLeastSquares::add(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y) {
  check_block(W, y);
  const Eigen::Index G = groups();
  for (Eigen::Index i = 0; i < W.rows(); ++i) {
    add_full_row(static_cast<int>((rows_ + i) % G), W, y, i);
  }
  rows_ += W.rows();
}

void StreamingLeastSquares::add(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const Eigen::Ref<const Eigen::VectorXi>& groups) {
  check_block(W, y);
  if (groups.size() != W.rows()) {
    throw Error("groups has " + std::to_string(groups.size()) + " entries but W has " +
                std::to_string(W.rows()) + " rows; pass one group index per row");
  }
  const int G = this->groups();
  for (Eigen::Index i = 0; i < groups.size(); ++i) {
    if (groups(i) < 0 || groups(i) >= G) {
      throw Error("groups row " + std::to_string(rows_ + i) + " is " + std::to_string(groups(i)) +
                  " but must be in [0, " + std::to_string(G) + "); use the joint index of the row");
    }
  }
  for (Eigen::Index i = 0; i < W.rows(); ++i) add_full_row(groups(i), W, y, i);
  rows_ += W.rows();
}

void StreamingLeastSquares::add_row(int group, const Eigen::Ref<const Eigen::VectorXd>& w,
                                    double y) {
  if (group < 0 || group >= groups()) {
    throw Error("add_row: group " + std::to_string(group) + " is outside [0, " +
                std::to_string(groups()) + "); pass the joint index of the row");
  }
  Group& g = groups_[group];
  const auto pg = static_cast<Eigen::Index>(g.columns.size()) - 1;
  if (w.size() != pg) {
    throw Error("add_row: w has " + std::to_string(w.size()) + " entries but group " +
                std::to_string(group) + " has " + std::to_string(pg) +
                " columns; pass the row at StreamingOptions::group_columns only");
  }
  if (!w.allFinite() || !std::isfinite(y)) {
    throw Error("row " + std::to_string(rows_) + " (group " + std::to_string(group) +
                ") contains NaN or Inf; remove or repair that sample");
  }
  g.pending.col(g.pending_rows).head(pg) = w;
  g.pending(pg, g.pending_rows) = y;
  ++g.rows;
  ++rows_;
  if (++g.pending_rows == kChunk) fold(g);
}

void StreamingLeastSquares::add_row_gathered(int group, const double* source,
                                             const std::vector<Eigen::Index>& offsets, double y) {
  if (group < 0 || group >= groups()) {
    throw Error("add_row_gathered: group " + std::to_string(group) + " is outside [0, " +
                std::to_string(groups()) + "); pass the joint index of the row");
  }
  Group& g = groups_[group];
  const auto pg = static_cast<Eigen::Index>(g.columns.size()) - 1;
  if (static_cast<Eigen::Index>(offsets.size()) != pg) {
    throw Error("add_row_gathered: " + std::to_string(offsets.size()) + " offsets but group " +
                std::to_string(group) + " has " + std::to_string(pg) +
                " columns; pass one offset per StreamingOptions::group_columns entry");
  }
  double* col = g.pending.col(g.pending_rows).data();
  // Non-finite entries have all exponent bits set: tested with integer ops as the row is copied
  // (a branch per entry cost as much as the copy).
  constexpr std::uint64_t kExponent = 0x7ff0000000000000ULL;
  bool finite = std::isfinite(y);
  for (Eigen::Index c = 0; c < pg; ++c) {
    const double v = source[offsets[c]];
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    finite &= (bits & kExponent) != kExponent;
    col[c] = v;
  }
  col[pg] = y;
  if (!finite) {
    g.pending.col(g.pending_rows).head(pg + 1).setZero();  // the Gram kernel reads the whole block
    throw Error("row " + std::to_string(rows_) + " (group " + std::to_string(group) +
                ") contains NaN or Inf; remove or repair that sample");
  }
  ++g.rows;
  ++rows_;
  if (++g.pending_rows == kChunk) fold(g);
}

void StreamingLeastSquares::merge(const StreamingLeastSquares& other) {
  if (other.parameters_ != parameters_ || other.groups() != groups() ||
      other.options_.accumulation != options_.accumulation) {
    throw Error(
        "merge: the accumulators differ in parameters, groups or accumulation; merge only "
        "accumulators built with the same sizes and options");
  }
  for (int g = 0; g < groups(); ++g) {
    if (other.groups_[g].columns != groups_[g].columns) {
      throw Error("merge: group " + std::to_string(g) +
                  " keeps different columns in the two accumulators; use the same group_columns");
    }
  }
  other.flush();
  flush();
  for (int g = 0; g < groups(); ++g) {
    Group& mine = groups_[g];
    const Group& theirs = other.groups_[g];
    if (theirs.rows == 0) continue;
    if (options_.accumulation == Accumulation::kHouseholder) {
      Eigen::MatrixXd B = theirs.summary;
      triangular_append(mine.summary, B, work_);
    } else {
      mine.summary += theirs.summary;
    }
    mine.rows += theirs.rows;
  }
  rows_ += other.rows_;
}

StreamingState StreamingLeastSquares::state() const {
  flush();
  StreamingState s;
  s.accumulation = options_.accumulation;
  s.parameters = parameters_;
  for (const Group& g : groups_) {
    StreamingState::Group out;
    out.columns.assign(g.columns.begin(), g.columns.end() - 1);
    out.summary = g.summary.triangularView<Eigen::Upper>();
    out.rows = g.rows;
    s.groups.push_back(std::move(out));
  }
  return s;
}

StreamingLeastSquares StreamingLeastSquares::from_state(const StreamingState& state) {
  if (state.groups.empty()) throw Error("streaming state: no row group; the state is corrupt");
  StreamingOptions options;
  options.accumulation = state.accumulation;
  for (const auto& g : state.groups) options.group_columns.push_back(g.columns);
  // The constructor checks p and the column lists.
  StreamingLeastSquares out(state.parameters, static_cast<int>(state.groups.size()), options);
  for (std::size_t i = 0; i < state.groups.size(); ++i) {
    const StreamingState::Group& g = state.groups[i];
    Group& mine = out.groups_[i];
    const Eigen::Index q = mine.summary.rows();
    const std::string which = "streaming state: group " + std::to_string(i);
    if (g.summary.rows() != q || g.summary.cols() != q) {
      throw Error(which + " has a " + std::to_string(g.summary.rows()) + "x" +
                  std::to_string(g.summary.cols()) + " summary for " + std::to_string(q - 1) +
                  " columns; the state is corrupt");
    }
    if (!g.summary.allFinite() ||
        !g.summary.triangularView<Eigen::StrictlyLower>().toDenseMatrix().isZero(0.0)) {
      throw Error(which +
                  " has a summary that is not finite or not upper triangular; the state is "
                  "corrupt");
    }
    if (g.rows < 0) throw Error(which + " has a negative row count; the state is corrupt");
    mine.summary = g.summary;
    mine.rows = g.rows;
    out.rows_ += g.rows;
  }
  return out;
}

double StreamingLeastSquares::relative_error(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  if (x.size() != parameters_) {
    throw Error("relative_error: x has " + std::to_string(x.size()) + " entries for " +
                std::to_string(parameters_) + " parameters");
  }
  flush();
  double rss = 0.0, yy = 0.0;
  for (const Group& g : groups_) {
    if (g.rows == 0) continue;
    const auto pg = static_cast<Eigen::Index>(g.columns.size()) - 1;
    Eigen::VectorXd xa(pg + 1);
    for (Eigen::Index c = 0; c < pg; ++c) xa(c) = x(g.columns[c]);
    xa(pg) = -1.0;
    if (options_.accumulation == Accumulation::kHouseholder) {
      rss += (g.summary.triangularView<Eigen::Upper>() * xa).squaredNorm();
      yy += g.summary.col(pg).squaredNorm();
    } else {
      // ‖e_g‖² = [x; −1]ᵀ G_g [x; −1] straight from the Gram matrix: compact_factor() would drop
      // the directions a single run leaves unexcited, which still carry residual.
      rss += std::max(0.0, xa.dot(g.summary.selfadjointView<Eigen::Upper>() * xa));
      yy += g.summary(pg, pg);
    }
  }
  return yy > 0.0 ? std::sqrt(rss / yy)
                  : (rss > 0.0 ? std::numeric_limits<double>::quiet_NaN() : 0.0);
}

double StreamingLeastSquares::normal_equations_condition(const Eigen::VectorXd& weights) const {
  flush();
  const Eigen::Index q = parameters_ + 1;
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(q, q);
  for (int g = 0; g < groups(); ++g) {
    const Group& grp = groups_[g];
    if (grp.rows == 0) continue;
    const Eigen::MatrixXd Gg = grp.summary.selfadjointView<Eigen::Upper>();
    const double w2 = weights(g) * weights(g);
    for (std::size_t r = 0; r < grp.columns.size(); ++r)
      for (std::size_t c = 0; c < grp.columns.size(); ++c)
        G(grp.columns[r], grp.columns[c]) += w2 * Gg(r, c);
  }
  const ScaledGram s = scaled_gram(G);
  const double lmin = s.eig.eigenvalues()(0), lmax = s.eig.eigenvalues().maxCoeff();
  if (!s.positive || !(lmin > 0.0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(lmax / lmin);  // κ of the equilibrated [W y] is √(λmax/λmin) of its Gram
}

Eigen::MatrixXd StreamingLeastSquares::compact_factor(const Group& g) const {
  const Eigen::Index q = g.summary.rows();
  if (g.rows == 0) return Eigen::MatrixXd::Zero(q, q);
  if (options_.accumulation == Accumulation::kHouseholder) return g.summary;
  // G = D V Λ Vᵀ D = SᵀS with S = Λ^½ Vᵀ D (negative round-off eigenvalues clamped); the R of
  // S = QR is the upper-triangular factor with RᵀR = G. Eigenvalues below λmax/limit² are round-off
  // of an exactly rank-deficient group (a joint that alone does not see every parameter) and are
  // zeroed, so that the group's rank and residual come out right.
  const ScaledGram s = scaled_gram(g.summary);
  const double floor = s.eig.eigenvalues().maxCoeff() /
                       (kNormalEquationsConditionLimit * kNormalEquationsConditionLimit);
  const Eigen::VectorXd lambda =
      s.eig.eigenvalues().unaryExpr([floor](double l) { return l > floor ? l : 0.0; });
  const Eigen::MatrixXd S =
      lambda.cwiseSqrt().asDiagonal() * s.eig.eigenvectors().transpose() * s.d.asDiagonal();
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(S);
  return qr.matrixQR().triangularView<Eigen::Upper>();
}

Eigen::MatrixXd StreamingLeastSquares::group_factor(int group) const {
  if (group < 0 || group >= groups()) {
    throw Error("group " + std::to_string(group) + " is outside [0, " + std::to_string(groups()) +
                "); pass a valid group index");
  }
  flush();
  const Group& g = groups_[group];
  const Eigen::MatrixXd Rc = compact_factor(g);
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(Rc.rows(), parameters_ + 1);
  for (std::size_t c = 0; c < g.columns.size(); ++c) R.col(g.columns[c]) = Rc.col(c);
  return R;
}

Eigen::MatrixXd StreamingLeastSquares::factor() const {
  const Eigen::Index q = parameters_ + 1;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(q, q);
  for (int g = 0; g < groups(); ++g) {
    Eigen::MatrixXd B = group_factor(g);
    triangular_append(R, B, work_);
  }
  return R;
}

Estimate StreamingLeastSquares::solve(const Eigen::VectorXd& weights, EstimatorKind kind,
                                      const EstimationOptions& options) const {
  const Eigen::Index p = parameters_, q = p + 1, m = rows_;
  check_names(options, p);
  if (m < p) {
    throw Error("W has " + std::to_string(m) + " rows for " + std::to_string(p) +
                " parameters; at least " + std::to_string(p) + " rows (" + std::to_string(p + 1) +
                " for the statistics) are needed: add samples");
  }
  flush();
  if (options_.accumulation == Accumulation::kNormalEquations) {
    const double kappa = normal_equations_condition(weights);
    if (!(kappa <= kNormalEquationsConditionLimit)) {
      throw NormalEquationsError(
          "the normal equations of these rows are too ill-conditioned to be solved accurately "
          "(column-equilibrated condition number of [W y] " +
          short_number(kappa) + " > " + short_number(kNormalEquationsConditionLimit) +
          ": poorly excited or noise-free data); accumulate the rows with "
          "Accumulation::kHouseholder");
    }
  }
  const int G = groups();
  std::vector<Eigen::MatrixXd> factors(G);
  for (int g = 0; g < G; ++g) factors[g] = compact_factor(groups_[g]);
  // Combined factor of the weighted rows: rows of group g scaled by weights(g).
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(q, q);
  for (int g = 0; g < G; ++g) {
    if (groups_[g].rows == 0) continue;
    const auto& cols = groups_[g].columns;
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(factors[g].rows(), q);
    for (std::size_t c = 0; c < cols.size(); ++c) B.col(cols[c]) = weights(g) * factors[g].col(c);
    triangular_append(R, B, work_);
  }
  const auto s = solve_factor(R, m, options);

  Estimate e;
  e.x = s.x;
  e.singular_values = s.singular_values;
  e.unidentifiable = s.unidentifiable;
  e.dependent_columns = s.dependent_columns;
  e.summary.estimator = kind;
  e.summary.rows = m;
  e.summary.columns = p;
  e.summary.rank = s.rank;
  e.summary.rank_tolerance = s.tolerance;
  e.summary.condition_number = s.condition_number;
  e.summary.passes = 1;

  // Residuals per group from the factors: ‖e_g‖ = ‖R_g·[x_g; −1]‖ (x at the group's columns),
  // ‖y_g‖ = ‖R_g(:, y)‖ (Q_g is orthogonal).
  e.group_rows.resize(G);
  e.group_rms.resize(G);
  e.group_relative_error.resize(G);
  e.group_variance.resize(G);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EstimationOptions group_options = options;  // names are those of all p columns
  group_options.names.clear();
  double rss = 0.0, rss_weighted = 0.0, yy = 0.0;
  for (int g = 0; g < G; ++g) {
    const Eigen::MatrixXd& Rg = factors[g];
    const auto& cols = groups_[g].columns;
    const auto pg = static_cast<Eigen::Index>(cols.size()) - 1;
    const Eigen::Index mg = groups_[g].rows;
    e.group_rows(g) = double(mg);
    if (mg == 0) {
      e.group_rms(g) = e.group_relative_error(g) = e.group_variance(g) = nan;
      continue;
    }
    Eigen::VectorXd xa(pg + 1);
    for (Eigen::Index c = 0; c < pg; ++c) xa(c) = s.x(cols[c]);
    xa(pg) = -1.0;
    const double eg2 = (Rg.triangularView<Eigen::Upper>() * xa).squaredNorm();
    const double yg2 = Rg.col(pg).squaredNorm();
    rss += eg2;
    rss_weighted += weights(g) * weights(g) * eg2;
    yy += yg2;
    e.group_rms(g) = std::sqrt(eg2 / double(mg));
    e.group_relative_error(g) = yg2 > 0.0 ? std::sqrt(eg2 / yg2) : (eg2 > 0.0 ? nan : 0.0);
    // Gautier: σ_g² from the least-squares solution of the subsystem of group g alone,
    // ‖y_g − W_g x_g‖²/(m_g − rank W_g), unbiased whatever the noise of the other groups.
    const auto sg = solve_factor(Rg, mg, group_options);
    Eigen::VectorXd xg(pg + 1);
    xg.head(pg) = sg.x;
    xg(pg) = -1.0;
    const Eigen::Index dof_g = mg - sg.rank;
    e.group_variance(g) =
        dof_g > 0 ? (Rg.triangularView<Eigen::Upper>() * xg).squaredNorm() / double(dof_g) : nan;
  }
  e.residual_rms = std::sqrt(rss / double(m));
  e.relative_error = yy > 0.0 ? std::sqrt(rss / yy) : (rss > 0.0 ? nan : 0.0);
  e.degrees_of_freedom = m - s.rank;
  e.residual_variance =
      e.degrees_of_freedom > 0 ? rss_weighted / double(e.degrees_of_freedom) : nan;
  // Gautier: C = σ²(WᵀW)⁻¹ = σ²·R⁻¹R⁻ᵀ (pseudo-inverse when rank deficient).
  e.covariance = e.residual_variance * (s.g * s.g.transpose());
  fill_parameter_statistics(e, options);

  if (s.rank < p) {
    e.summary.warnings.push_back(
        "W is rank deficient (rank " + std::to_string(s.rank) + " < " + std::to_string(p) +
        "): parameters " + column_list(options, s.unidentifiable) +
        " are not identifiable individually; " +
        (options.rank_deficient_remedy.empty() ? "regroup them into base parameters or drop " +
                                                     column_list(options, s.dependent_columns)
                                               : options.rank_deficient_remedy));
  }
  // A column zero by design (a load inertia a planar run cannot reach) makes σ_min 0 and the
  // condition number infinite; the rank warning above names those parameters, so what this one
  // reports is the conditioning of the r directions the data do determine, σ_max/σ_r.
  const bool deficient = s.rank < p && s.rank > 0;
  const double conditioning =
      deficient ? s.singular_values(0) / s.singular_values(s.rank - 1) : s.condition_number;
  if (conditioning > options.condition_warning) {
    e.summary.warnings.push_back(
        "condition number " + short_number(conditioning) +
        (deficient ? " of the " + std::to_string(s.rank) + " determined directions" : "") +
        " exceeds " + short_number(options.condition_warning) +
        ": the data excite some parameters poorly");
    if (s.rank == p) {
      // Parameters dominating the weakest singular direction.
      for (Eigen::Index j = 0; j < p; ++j) {
        if (std::abs(s.v(j, p - 1)) >= options.weak_direction_threshold) {
          e.poorly_excited.push_back(j);
        }
      }
      std::sort(e.poorly_excited.begin(), e.poorly_excited.end());
      e.poorly_excited.erase(std::unique(e.poorly_excited.begin(), e.poorly_excited.end()),
                             e.poorly_excited.end());
    }
  }
  std::vector<Eigen::Index> poor;
  for (Eigen::Index j : e.poorly_excited) {
    if (std::find(e.unidentifiable.begin(), e.unidentifiable.end(), j) == e.unidentifiable.end())
      poor.push_back(j);
  }
  if (!poor.empty()) {
    e.summary.warnings.push_back("poorly excited parameters: " + column_list(options, poor));
  }
  return e;
}

Estimate StreamingLeastSquares::solve_ordinary(const EstimationOptions& options) const {
  return solve(Eigen::VectorXd::Ones(groups()), EstimatorKind::kOrdinaryLeastSquares, options);
}

Estimate StreamingLeastSquares::solve_weighted(const Eigen::Ref<const Eigen::VectorXd>& group_std,
                                               const EstimationOptions& options) const {
  if (group_std.size() != groups()) {
    throw Error("group_std has " + std::to_string(group_std.size()) + " entries for " +
                std::to_string(groups()) + " groups; pass one standard deviation per group");
  }
  for (int g = 0; g < groups(); ++g) {
    if (!(group_std(g) > 0.0) || !std::isfinite(group_std(g))) {
      throw Error("group_std(" + std::to_string(g) + ") is " + std::to_string(group_std(g)) +
                  "; pass a positive finite noise standard deviation");
    }
  }
  Estimate e = solve(group_std.cwiseInverse(), EstimatorKind::kWeightedLeastSquares, options);
  e.group_variance = group_std.cwiseAbs2();
  return e;
}

Estimate StreamingLeastSquares::solve_weighted(const EstimationOptions& options) const {
  const int G = groups();
  // Step 1 (Gautier): OLS of each group's subsystem gives σ_g² (Estimate::group_variance).
  const Estimate ols = solve_ordinary(options);
  std::vector<std::string> warnings;
  Eigen::VectorXd variance = ols.group_variance;
  double vmax = 0.0;
  for (int g = 0; g < G; ++g) {
    if (groups_[g].rows == 0) continue;
    if (!std::isfinite(variance(g))) {
      variance(g) = ols.residual_variance;  // too few rows in the group: pooled variance
      warnings.push_back("group " + std::to_string(g) +
                         " has too few rows to estimate its noise variance; used the pooled one");
    }
    if (std::isfinite(variance(g))) vmax = std::max(vmax, variance(g));
  }
  // Step 2: rows of group g divided by σ_g, solved again.
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(G);
  if (vmax > 0.0 && std::isfinite(vmax)) {
    for (int g = 0; g < G; ++g) {
      if (groups_[g].rows == 0) continue;
      if (!(variance(g) >= kVarianceFloor * vmax)) {
        variance(g) = kVarianceFloor * vmax;
        warnings.push_back("group " + std::to_string(g) +
                           " has a (near) zero residual variance; its weight was bounded");
      }
      weights(g) = 1.0 / std::sqrt(variance(g));
    }
  } else {
    warnings.push_back("all residuals are zero: weighted least squares equals OLS");
  }
  Estimate e = solve(weights, EstimatorKind::kWeightedLeastSquares, options);
  e.group_variance = variance;
  e.summary.passes = 2;
  e.summary.warnings.insert(e.summary.warnings.begin(), warnings.begin(), warnings.end());
  return e;
}

}  // namespace dynid
