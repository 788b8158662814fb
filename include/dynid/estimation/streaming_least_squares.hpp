#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynid/common/error.hpp"
#include "dynid/estimation/estimate.hpp"

namespace dynid {

/// How StreamingLeastSquares folds rows into its per-group summaries.
enum class Accumulation {
  /// Triangular factor R_g of [W_g y_g] updated by Householder QR of [R_g; new rows]
  /// (Golub–Van Loan §5.1, §6.5): backward stable whatever the conditioning, ≈ 2(p+1)² flops per
  /// row in matrix–vector kernels.
  kHouseholder,
  /// Gram matrix [W_g y_g]ᵀ[W_g y_g] updated by a symmetric rank-k product: ≈ (p+1)² flops per row
  /// in matrix–matrix kernels (about 3× faster), but round-off grows with κ², so solving throws
  /// NormalEquationsError beyond kNormalEquationsConditionLimit (re-accumulate with kHouseholder).
  kNormalEquations,
};

/// Options of StreamingLeastSquares.
struct StreamingOptions {
  Accumulation accumulation = Accumulation::kHouseholder;  ///< see Accumulation
  /// Per group, the sorted distinct columns that can be non-zero in its rows; empty = all columns.
  /// A joint's torque row has no entries for links outside its subtree or for other joints'
  /// friction, so each per-joint summary shrinks from (p+1)² to (p_g+1)² numbers and flops.
  std::vector<std::vector<Eigen::Index>> group_columns;
};

/// With Accumulation::kNormalEquations, the largest accepted condition number of the
/// column-equilibrated, weighted [W y] of all groups: round-off in the Gram matrix then perturbs
/// the solution and the residual by at most ≈ κ²·u ≈ 1e-6 relative (u = 1.1e-16), far below any
/// noise-driven σ. A noise-free fit (y in the range of W) has an unbounded κ and is refused.
inline constexpr double kNormalEquationsConditionLimit = 1e5;  // echoed as "1e5" by identify_stream

/// Thrown by StreamingLeastSquares::solve_* with Accumulation::kNormalEquations when the
/// accumulated normal equations exceed kNormalEquationsConditionLimit; re-accumulate the rows with
/// Accumulation::kHouseholder (identify_stream does so with a second pass over the file).
class NormalEquationsError : public Error {
 public:
  using Error::Error;
};

/// The accumulated content of a StreamingLeastSquares, for storage and exact merging elsewhere
/// (partial results of identify --stream, streaming_partial.hpp): everything solve_* reads.
struct StreamingState {
  Accumulation accumulation = Accumulation::kHouseholder;  ///< how `summary` was accumulated
  Eigen::Index parameters = 0;                             ///< p
  struct Group {
    std::vector<Eigen::Index> columns;  ///< the p_g columns kept (sorted), without the y column
    /// (p_g+1)×(p_g+1): upper-triangular factor R_g of [W_g y_g] (kHouseholder) or the upper
    /// triangle of its Gram matrix (kNormalEquations); the strict lower triangle is zero.
    Eigen::MatrixXd summary;
    Eigen::Index rows = 0;  ///< rows folded into summary
  };
  std::vector<Group> groups;  ///< one per row group (joint)
};

/// Least squares of y = W·x + e accumulated block by block in O(G·(p+1)²) memory, independent of
/// the number of rows: for every row group g (joint) it keeps the upper-triangular factor R_g of
/// [W_g y_g] (the "extra column" trick: R_g = [R_gp z_g; 0 ρ_g], R_gpᵀR_gp = W_gᵀW_g,
/// R_gpᵀz_g = W_gᵀy_g), or its Gram matrix (StreamingOptions::accumulation), seed 1 eq. 35 solved
/// through the factor. The combined factor of all groups gives OLS; the per-group factors give
/// exact per-group residuals, variances and WLS in the same single pass. Accumulators fed with
/// disjoint rows (e.g. by several threads) are combined with merge().
class StreamingLeastSquares {
 public:
  /// p = parameters (columns of W) ≥ 1, G = groups ≥ 1. Throws dynid::Error otherwise, or when
  /// options.group_columns is neither empty nor G lists of sorted distinct columns in [0, p).
  explicit StreamingLeastSquares(Eigen::Index parameters, int groups = 1,
                                 const StreamingOptions& options = {});

  /// Adds rows; row r of the whole stream (counted from the first row ever added) belongs to
  /// group r mod G (sample-major torque regressor: group = joint). W is b×p, y has b entries.
  /// Throws dynid::Error on wrong sizes, NaN/Inf (naming the stream row), or a non-zero entry in a
  /// column outside the row's group_columns.
  void add(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& y);

  /// Adds rows with explicit group indices in [0, G). Same errors, plus out-of-range groups.
  void add(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& y,
           const Eigen::Ref<const Eigen::VectorXi>& groups);

  /// Adds one row of `group` given only at its group_columns (w has p_g entries, in that order):
  /// the allocation-free path for streams built row by row. Throws dynid::Error on a bad group or
  /// size, or NaN/Inf (naming the stream row).
  void add_row(int group, const Eigen::Ref<const Eigen::VectorXd>& w, double y);

  /// add_row with the row's p_g entries read as source[offsets[0]], source[offsets[1]], ... (its
  /// group_columns, in order) straight into the pending block: no intermediate vector when the row
  /// is gathered from a larger buffer (identify_stream reads a joint's base columns out of the
  /// regressor's storage). Same errors as add_row (offsets must have p_g entries).
  void add_row_gathered(int group, const double* source, const std::vector<Eigen::Index>& offsets,
                        double y);

  /// Adds the rows accumulated by `other` (same parameters, groups and options), as if they had
  /// been added here. Throws dynid::Error on a mismatch.
  void merge(const StreamingLeastSquares& other);

  /// The accumulated state (pending rows folded in first): what a partial result stores.
  StreamingState state() const;

  /// An accumulator holding `state`, as if its rows had been added to a new one with
  /// group_columns = the state's columns. Throws dynid::Error when the state is inconsistent
  /// (p < 1, no group, columns not sorted in [0, p), summary of the wrong size, not finite or not
  /// upper triangular, negative rows): a corrupt stored state is refused, not solved.
  static StreamingLeastSquares from_state(const StreamingState& state);

  /// ‖y − W·x‖/‖y‖ over every row added, from the factors (‖e_g‖ = ‖R_g·[x_g; −1]‖), with x from
  /// another accumulator's solve (a run's share of a joint fit); NaN when ‖y‖ = 0 and the
  /// residual is not. Throws dynid::Error when x does not have p entries.
  double relative_error(const Eigen::Ref<const Eigen::VectorXd>& x) const;

  /// Ordinary least squares from the accumulated factor (rank, condition number, statistics).
  /// Throws dynid::Error if fewer rows than parameters were added, and NormalEquationsError with
  /// Accumulation::kNormalEquations when the normal equations are too ill-conditioned.
  Estimate solve_ordinary(const EstimationOptions& options = {}) const;

  /// Gautier's two-step weighted least squares: σ_g² from the OLS of each group's rows alone, then
  /// rows of group g divided by σ_g and all solved again. Same errors as solve_ordinary.
  Estimate solve_weighted(const EstimationOptions& options = {}) const;

  /// Least squares with known per-group noise standard deviations (rows of g divided by σ_g > 0).
  /// Throws dynid::Error on a size mismatch or a non-positive / non-finite σ_g.
  Estimate solve_weighted(const Eigen::Ref<const Eigen::VectorXd>& group_std,
                          const EstimationOptions& options = {}) const;

  /// Upper-triangular (p+1)×(p+1) factor of [W y] over all groups, with unit group weights.
  Eigen::MatrixXd factor() const;
  /// (p+1)×(p+1) factor of [W_g y_g] of group g (upper triangular in group g's columns).
  Eigen::MatrixXd group_factor(int group) const;

  Eigen::Index rows() const { return rows_; }                      ///< rows added so far
  Eigen::Index parameters() const { return parameters_; }          ///< p
  int groups() const { return static_cast<int>(groups_.size()); }  ///< G
  /// Rows added per group.
  std::vector<Eigen::Index> group_rows() const;
  /// Forgets all rows (keeps sizes).
  void reset();

 private:
  struct Group {
    std::vector<Eigen::Index> columns;  // the p_g columns kept, then p (the y column)
    Eigen::MatrixXd summary;  // (p_g+1)²: factor R_g or upper triangle of the Gram matrix
    Eigen::MatrixXd partial;  // normal equations: Gram of the folds not yet added to summary
    int partial_folds = 0;
    Eigen::MatrixXd pending;  // rows not yet folded in, one per column: (p_g+1) × kChunk
    Eigen::Index pending_rows = 0;
    Eigen::Index rows = 0;
  };
  void check_block(const Eigen::Ref<const Eigen::MatrixXd>& W,
                   const Eigen::Ref<const Eigen::VectorXd>& y) const;
  void add_full_row(int group, const Eigen::Ref<const Eigen::MatrixXd>& W,
                    const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index i);
  void fold(Group& g) const;
  void drain(Group& g) const;  // adds partial to summary (normal equations)
  // κ of the column-equilibrated [W y] with rows of group g scaled by weights(g) (NE mode).
  double normal_equations_condition(const Eigen::VectorXd& weights) const;
  void flush() const;
  // Compact (p_g+1)² upper-triangular factor of group g; empty when it has no rows.
  Eigen::MatrixXd compact_factor(const Group& g) const;
  Estimate solve(const Eigen::VectorXd& weights, EstimatorKind kind,
                 const EstimationOptions& options) const;

  Eigen::Index parameters_;
  StreamingOptions options_;
  Eigen::Index rows_ = 0;
  mutable std::vector<Group> groups_;  // mutable: solving folds pending rows in first
  mutable Eigen::RowVectorXd work_;    // Householder workspace
};

}  // namespace dynid
