#pragma once

// The run record and its preparation (docs/design.md §8, "prepare"): what every equation builder,
// experiment, load and closed-loop method stands on, without identify() itself.

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/signal/lowpass_design.hpp"

namespace dynid {

/// A recorded run on the joint side: time, positions, optional derivatives, torques.
struct JointRecord {
  Eigen::VectorXd t;    ///< m time stamps [s], strictly increasing
  Eigen::MatrixXd q;    ///< m × n [rad or m]
  Eigen::MatrixXd dq;   ///< m × n or empty: derived from q when absent
  Eigen::MatrixXd ddq;  ///< m × n or empty: derived from dq when absent
  Eigen::MatrixXd tau;  ///< m × n joint torques [N·m or N]
};

/// Signal processing before estimation (issue 4; seed 2 §3.4, Gautier's parallel filtering).
/// Negative / zero "auto" values are replaced by defaults that the result reports back.
struct SignalOptions {
  bool filter =
      true;  ///< zero-phase low-pass of q and tau with the same filter (parallel filtering)
  LowpassFamily family = LowpassFamily::kButterworth;  ///< filter prototype
  int order = 4;                                       ///< filter order
  /// Low-pass cut-off [Hz]; 0 = auto: choose_cutoff() (signal/noise_floor.hpp), 1.5 × the upper
  /// end of the band where the position spectrum stands 20 dB above its noise floor, in
  /// [1 Hz, min(20 Hz, rate/10)].
  double cutoff_hz = 0.0;
  /// Where a non-zero cutoff_hz comes from, as the echo says it: "given" (the caller's), or e.g.
  /// "as identify used it" for a value a stored result supplies (never "given" for those).
  std::string cutoff_source = "given";
  double ripple_db = 0.5;  ///< Chebyshev I passband ripple
  int decimate = 0;        ///< keep every k-th sample; 0 = auto: rate/(10·cutoff), ≥ 1
  int trim = -1;  ///< samples dropped at each end after filtering; −1 = auto: 3·rate/cutoff
  bool savitzky_golay =
      false;  ///< differentiate with Savitzky–Golay instead of central differences
  /// Rows of joint j with |dq_j| below the threshold are removed from a Coulomb model's fit. One
  /// value = all joints; else n values. Empty = auto: threshold_j = max(zero_velocity_fraction·
  /// max|dq_j|, zero_velocity_noise_multiple·σ_dq,j), and the Coulomb columns are the filtered
  /// expected (smooth) sign (coulomb_width). Both fractions 0 keep every row: removing rows by the
  /// size of a filtered, noisy velocity selects on the regressor (docs/methods/identification.md
  /// §3 has what each choice does on the TX40 and on a plant with a Stribeck bump).
  std::vector<double> zero_velocity;
  /// Where non-empty zero_velocity thresholds come from, as the echo says it (as cutoff_source).
  std::string zero_velocity_source = "given";
  /// Automatic zero-velocity rule: fraction of max|dq_j| of the processed record (FIGAROH's TX40
  /// rule; 0 with zero_velocity_noise_multiple 0 keeps every row, docs/methods/identification.md
  /// §3).
  double zero_velocity_fraction = 0.01;
  /// Automatic zero-velocity rule: multiple k of the processed velocity's noise std σ_dq.
  double zero_velocity_noise_multiple = 3.0;
  /// The torque logged at time stamp t acts at t + torque_time_offset [s]; the torques are
  /// re-interpolated (linearly) onto the position time stamps before filtering. A controller that
  /// logs the command it then holds for one period (zero-order hold, as `dynid simulate` does)
  /// needs +T/2: central differences centre q̈ on the sample, the held torque half a period later.
  /// A torque sensor lagging by d needs −d. 0 = as logged.
  double torque_time_offset = 0.0;
  /// Filter the Coulomb columns of the regressor (sign(dq), or [dq>0] and −[dq<0]; with a known
  /// velocity noise σ_dq the expected sign erf(dq/(√2·σ_dq)) and its halves) with the same
  /// zero-phase filter as tau, from the full-rate velocity (Gautier's parallel filtering applied to
  /// the one discontinuous column): the filtered torque's smeared Coulomb step at a velocity
  /// reversal is then matched by the model instead of biasing Fv and Fc. Only with `filter`;
  /// coupled-motor Coulomb columns stay unfiltered.
  bool filter_coulomb_columns = false;
  /// Transition velocity v_c,j [rad/s or m/s] of the smooth Coulomb law Fc·erf(dq/(√2·v_c)): the
  /// band where a real joint's friction goes through pre-sliding from −Fc to +Fc and where a
  /// stopped joint's friction is near zero on average. With velocity noise σ_dq the expected
  /// column is erf(dq̂/(√2·√(v_c² + σ_dq²))) (Gaussian convolution of erf; docs/methods/
  /// identification.md §3). 1 value = all joints, else n values; empty = 0 unless identify()
  /// uses the default coulomb_width_fraction. Only with the filtered expected-sign columns.
  std::vector<double> coulomb_width;
  /// Default v_c,j when coulomb_width is empty: this fraction of max|dq_j| of the processed run
  /// (docs/methods/identification.md §3: the pre-sliding band of geared joints; 0 = none, the
  /// default; 0.005 reproduces the TX40's published friction with every row kept).
  double coulomb_width_fraction = 0.0;
  /// Where non-empty coulomb_width values come from, as the echo says it (as cutoff_source).
  std::string coulomb_width_source = "given";
};

/// Per-joint zero-velocity thresholds [rad/s or m/s] from SignalOptions::zero_velocity: one value
/// for all n joints, or n values; empty gives an empty vector (the caller's automatic rule).
/// Throws dynid::UsageError for any other count.
Eigen::VectorXd given_zero_velocity(const std::vector<double>& zero_velocity, int n);

/// Per-joint Coulomb transition velocities [rad/s or m/s] from SignalOptions::coulomb_width: one
/// value for all n joints, or n values; empty gives an empty vector. Throws dynid::UsageError for
/// any other count or a value that is negative or not finite.
Eigen::VectorXd given_coulomb_width(const std::vector<double>& width, int n);

/// The preprocessed data actually used for estimation (useful for plots and validation).
struct ProcessedRecord {
  JointRecord record;    ///< filtered, differentiated, trimmed and decimated
  double rate_hz = 0.0;  ///< sample rate of `record`
  /// With SignalOptions::filter_coulomb_columns: [dq_j > 0] and [dq_j < 0] at the full rate,
  /// filtered like tau, trimmed and decimated like `record` (m × n each); else empty.
  Eigen::MatrixXd moving_positive, moving_negative;
  /// Per joint, the transition velocity v_c of the Coulomb columns above [rad/s or m/s] (zeros
  /// for the expected sign of the noise alone); empty without expected-sign columns.
  Eigen::VectorXd coulomb_width;
  /// With expected-sign columns and coupled motors: per motor k, the same law applied to the motor
  /// velocity n_k·dq (v_c,k = √Σ n_kj² v_c,j², σ_k = √Σ n_kj² σ_j²), filtered like tau (m ×
  /// motors).
  Eigen::MatrixXd coupled_sign;
  double cutoff_hz = 0.0;  ///< low-pass cut-off used [Hz]; 0 without filter
  int trim = 0;            ///< samples dropped at each end after filtering (resolved)
  int decimate = 1;        ///< every decimate-th sample kept (resolved)
  /// Per joint, std of the white position noise floor of the input (position_noise_floor) and of
  /// the resulting noise on the processed velocity [rad/s or m/s]; 0 when not measurable.
  Eigen::VectorXd position_noise_std, velocity_noise_std;
};

/// Rows n_k = N_k/max|N_kj| of the coupled motors of `model` (coupled_motors, coupling_regressor):
/// motors × n, empty without coupled motors.
Eigen::MatrixXd coupled_motor_rows(const Model& model);

/// Sample-major regressor of a processed record (stacked_regressor), with the Coulomb columns
/// replaced by their filtered versions when the record carries them (filter_coulomb_columns).
Eigen::MatrixXd processed_regressor(const Model& model, const ParameterLayout& layout,
                                    bool coupling, const ProcessedRecord& processed);

/// Sample-major stacked regressor of the layout plus coupling columns for a record:
/// rows k·n … k·n+n−1 are sample k. Size (m·n) × (layout.columns(n) + coupling_columns(model)).
Eigen::MatrixXd stacked_regressor(const Model& model, const ParameterLayout& layout, bool coupling,
                                  const JointRecord& record);

/// Names of the columns of stacked_regressor.
std::vector<std::string> stacked_regressor_names(const Model& model, const ParameterLayout& layout,
                                                 bool coupling);

/// Filters, differentiates, trims and decimates a record as SignalOptions says; fills in the auto
/// choices (written to `choices`). Throws dynid::Error for too few samples or bad time stamps.
/// `coupled_rows` (motors × n, optional): rows n_k of the coupled motors (coupling_regressor); with
/// expected-sign Coulomb columns their motor velocities n_k·dq get the same law (coupled_sign).
ProcessedRecord preprocess(const JointRecord& record, const SignalOptions& options,
                           std::vector<std::pair<std::string, std::string>>& choices,
                           const Eigen::MatrixXd& coupled_rows = Eigen::MatrixXd());

}  // namespace dynid
