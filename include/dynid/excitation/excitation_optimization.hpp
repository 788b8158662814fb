#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/common/progress.hpp"

#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// What the excitation optimisation minimises.
enum class ExcitationCriterion {
  kConditionNumber,  ///< κ(W_b) = σ_max/σ_min of the stacked base regressor (seed 2 eq. 20)
  kDOptimality,      ///< −log det(W_bᵀW_b) (D-optimal design)
};

/// The NLopt algorithm used for every start.
enum class ExcitationAlgorithm {
  kCobyla,        ///< NLOPT_LN_COBYLA: derivative-free, nonlinear inequality constraints
  kAugLagBobyqa,  ///< NLOPT_AUGLAG with NLOPT_LN_BOBYQA inner solver (derivative-free)
  kSlsqp,         ///< NLOPT_LD_SLSQP with forward finite-difference gradients
};

/// Options of the Fourier excitation design. Limits left empty are taken from the model
/// (Joint::limits); a limit that is infinite in both is not enforced.
struct ExcitationOptions {
  ExcitationCriterion criterion = ExcitationCriterion::kConditionNumber;  ///< objective
  ExcitationAlgorithm algorithm = ExcitationAlgorithm::kCobyla;           ///< NLopt algorithm
  double f0 = 0.1;    ///< fundamental frequency [Hz]; period 1/f0 (seed 2 §3.3: 0.1 Hz)
  int harmonics = 5;  ///< harmonics per joint N (seed 2 §3.3: 5)
  std::vector<int> harmonics_per_joint;  ///< optional per-joint N_i; overrides `harmonics`
  /// Bandwidth limit [Hz]: max_i N_i·f0 ≤ f_max is required (enforced by construction; an error
  /// otherwise). 0 = no limit.
  double f_max = 0.0;
  bool rest_at_ends = true;  ///< zero dq, ddq at t = 0 and t = T (project_rest_at_ends)
  ParameterLayout layout;    ///< regressor columns whose base set is excited (rigid by default)
  /// Samples per period used inside the optimisation; 0 = 15 per period of the highest harmonic.
  int samples_per_period = 0;
  /// Samples per period of the final constraint check; 0 = 10× the optimisation samples.
  int check_samples_per_period = 0;

  Eigen::VectorXd q_min;        ///< n lower position limits [rad or m]; empty = model lower
  Eigen::VectorXd q_max;        ///< n upper position limits; empty = model upper
  Eigen::VectorXd dq_max;       ///< n speed limits |dq| [rad/s or m/s]; empty = model velocity
  Eigen::VectorXd ddq_max;      ///< n acceleration limits |ddq| [rad/s² or m/s²]; empty = none
  Eigen::VectorXd tau_max;      ///< n torque limits |tau| [N·m or N]; empty = model effort
  double limit_fraction = 1.0;  ///< use this fraction (0, 1] of every joint/torque limit (margin)

  /// Workspace: every link origin z > z_min in the base frame [m]; −inf = no floor.
  double z_min = -std::numeric_limits<double>::infinity();
  /// Workspace box (base frame) every link origin must stay inside [m]; ±inf = unbounded.
  Eigen::Vector3d box_min = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector3d box_max = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());

  /// Inside the optimisation every joint/torque limit is tightened by this fraction (position:
  /// of the range) so that the peaks between the optimisation samples still meet the limits on
  /// the fine check grid.
  double grid_margin = 0.03;
  double workspace_margin = 0.01;  ///< same for the workspace planes, in metres [m]

  int starts = 4;            ///< multi-start: number of random initial points
  unsigned seed = 20261123;  ///< seed of the random initial points (deterministic runs)
  ProgressCallback
      progress;  ///< every 20 evaluations and after each start (common/progress.hpp): the
                 ///< larger of the evaluations and the time budget spent; may be empty
  int max_evaluations = 3000;  ///< evaluation budget per start
  double max_time = 10.0;      ///< wall-clock budget of base parameters + all starts [s]; 0 = none
                               ///< (the final fine-grid check gets one more max_time at most)
  double relative_tolerance = 1e-6;    ///< NLopt relative tolerance on the criterion and x
  double constraint_tolerance = 1e-9;  ///< NLopt tolerance on the (normalised) constraints
};

/// Worst margin of one constraint group over all samples: limit − value in the group's unit,
/// ≥ 0 when it holds at every sample.
struct ConstraintMargin {
  std::string name;     ///< e.g. "position max q3", "velocity q1", "torque q2", "workspace z_min"
  double margin = 0.0;  ///< worst (smallest) margin; negative = violated [rad, rad/s, N·m, m...]
  double time = 0.0;    ///< time of the worst sample [s]
  /// The limit as given (q_max, q_min, dq_max, ddq_max, tau_max, z_min, a box face) and the worst
  /// value the trajectory reaches against it (max q, min q, max |dq|, ..., min z), in `unit`.
  double limit = 0.0, reached = 0.0;
  std::string unit;  ///< rad, m, rad/s, m/s, rad/s², m/s², N·m, N
  /// margin over the constraint's own size (the position range; the velocity, acceleration or
  /// torque limit; 0.1 m for the workspace): −0.2 is a violation by 20 % of it. Compares
  /// constraints of different units (tightest_constraint).
  double relative = 0.0;
};

/// Outcome of the excitation design.
struct ExcitationResult {
  FourierCoefficients coefficients;  ///< the optimised trajectory
  ExcitationCriterion criterion = ExcitationCriterion::kConditionNumber;  ///< what was minimised
  double value = 0.0;                     ///< criterion on the optimisation grid
  double condition_number = 0.0;          ///< κ(W_b) on the fine check grid
  double log_det = 0.0;                   ///< log det(W_bᵀW_b) on the fine check grid
  bool constraints_satisfied = false;     ///< every constraint at every sample of the check grid
  std::vector<ConstraintMargin> margins;  ///< worst margin per constraint group (check grid)
  std::vector<std::string> base_names;    ///< names of the excited base parameters (columns of W_b)
  int evaluations = 0;                    ///< criterion evaluations over all starts
  int starts_feasible = 0;  ///< starts whose final point met every constraint (optimisation grid)
  double seconds = 0.0;     ///< wall-clock time of the optimisation
};

/// Designs a finite-Fourier excitation trajectory (seed 2 §2.3 eqs. 17–20; Swevers et al. 1997):
/// decision variables δ_i = [a_i(1..N_i), b_i(1..N_i), q_i0] for every joint; minimises the
/// criterion of the base regressor W_b stacked over one period (rows = samples·n) subject to, at
/// every sample, q_min ≤ q ≤ q_max, |dq| ≤ dq_max, |ddq| ≤ ddq_max, |rnea(q, dq, ddq)| ≤ tau_max
/// (model parameters, gravity and joint friction), every link origin above z_min and inside the
/// box; bandwidth N·f0 ≤ f_max by construction. Multi-start NLopt from a fixed seed, keeping the
/// best point that satisfies every constraint; the result is re-checked on a finer grid.
/// Throws dynid::Error for invalid options (sizes, f0 ≤ 0, bandwidth above f_max, a joint with no
/// finite position, velocity or acceleration limit to bound its coefficients). When no start finds
/// a feasible point, the least-violating point is returned with constraints_satisfied = false
/// (a numerical outcome, reported, not thrown).
ExcitationResult optimize_excitation(const Model& model, const ExcitationOptions& options = {});

/// The constraint closest to violation, or most violated: the smallest ConstraintMargin::relative
/// of r.margins (a NaN one first: not met); nullptr when there is none.
const ConstraintMargin* tightest_constraint(const ExcitationResult& r);

/// Evaluation of a given trajectory under the options' criterion and constraints (the check that
/// optimize_excitation runs at the end): criterion values on `samples_per_period` samples of one
/// period and the worst constraint margins. `value` is the selected criterion; the coefficients
/// are copied (after project_rest_at_ends when options.rest_at_ends). Throws like
/// optimize_excitation for invalid options.
ExcitationResult evaluate_excitation(const Model& model, const FourierCoefficients& coefficients,
                                     const ExcitationOptions& options, int samples_per_period);

}  // namespace dynid
