#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/identification/identify.hpp"

namespace dynid {

/// Options of select_cutoff() (Ceres style).
struct CutoffSelectionOptions {
  /// Ratio of successive candidate cut-offs, from the spectral rule's value up to the upper bound
  /// (which is always a candidate).
  double grid_ratio = 1.5;
  /// The kept samples are cut into this many equal blocks; the even ones are fitted and the odd
  /// ones predicted, then the reverse (two-fold cross-validation). Even, >= 2.
  int blocks = 8;
  /// Samples within this many periods of the lowest candidate cut-off (0.5/f_min seconds) of a
  /// block boundary are not predicted, so the noise a filter smears across the boundary is not
  /// both fitted and predicted; at most a quarter of a block.
  double guard_periods = 0.5;
  /// Highest power of the motion in a regressor entry: 1 where the entries are linear in the
  /// filtered signals, 2 where they hold products of them (the load's ω×(ω×c), issue 25 item 4).
  /// A product of two signals of band f_b reaches 2·f_b, and a low-pass does not commute with it
  /// unless it passes 2·f_b nearly untouched: the candidates then start at
  /// max(f_s, degree·f_b/ε^(1/(2·order))) with ε = 1e-3, the zero-phase filter's relative
  /// amplitude loss there, and f_b = f_s/margin the band the spectral rule saw. identify keeps 1:
  /// its held-out torque errors discriminate the candidates (docs/methods/identification.md §6).
  int regressor_degree = 1;
};

/// A candidate cut-off and its held-out torque error.
struct CutoffCandidate {
  double cutoff_hz = 0.0;  ///< candidate low-pass cut-off [Hz]
  double held_out_error = 0.0;  ///< ‖τ_ref − Ŷθ̂‖/‖τ_ref‖ over the predicted samples (fraction)
};

/// The signal options identify() uses, with the automatic cut-off resolved.
struct CutoffSelection {
  SignalOptions signal;   ///< the input options with cutoff_hz set when it was automatic
  bool selected = false;  ///< whether cutoff_hz was chosen here (automatic and filtering on)
  std::string reason;     ///< one line for choices["cutoff"]: the rule, candidates, errors
  std::vector<CutoffCandidate> candidates;  ///< empty when the spectral rule alone decided
};

/// Automatic low-pass cut-off (SignalOptions::cutoff_hz = 0) chosen by held-out torque prediction:
/// the spectral rule choose_cutoff() (signal/noise_floor.hpp) gives the lowest candidate f_s, a
/// geometric grid (grid_ratio) runs from f_s to the upper bound min(20 Hz, rate/10); for each
/// candidate the record is preprocessed with one common trim and decimation, the base parameters
/// are fitted (least squares, the given zero-velocity rows left out) on alternate blocks of
/// samples and the other blocks are predicted; the error of every candidate is measured against
/// the same reference, the torque filtered at the upper bound, so candidates that filter τ harder
/// gain nothing from it. The lowest error wins; the spectral value is kept when there is nothing
/// to choose (f_s at the upper bound) or the record cannot be split (too short, rank-deficient
/// half). With a given cut-off or without filtering, options.signal is returned unchanged.
/// Derivation and measurements: docs/methods/identification.md ("Cut-off by held-out prediction").
/// Throws what preprocess() throws for an unusable record.
CutoffSelection select_cutoff(const Model& model, const JointRecord& record,
                              const IdentifyOptions& options,
                              const CutoffSelectionOptions& selection = {});

/// The equations of a model that is linear in its parameters, built from `record` processed with
/// one candidate's signal options: rows W·θ ≈ y, each with the (processed) sample it belongs to.
struct CutoffEquations {
  Eigen::MatrixXd W;       ///< rows × p
  Eigen::VectorXd y;       ///< rows
  Eigen::VectorXi sample;  ///< per row, its sample index in the processed record (nondecreasing)
  /// Per row, whether it is fitted (e.g. not a near-still Coulomb row); empty: every row.
  std::vector<bool> fitted;
};

/// Builds CutoffEquations from the record processed with the given signal options (its cut-off
/// set, trim and decimation resolved by the selection). Throws dynid::Error when it cannot.
using CutoffEquationBuilder = std::function<CutoffEquations(const SignalOptions& candidate)>;

/// The held-out rule of select_cutoff() for any model linear in its parameters (issue 25 item 4:
/// one cut-off mechanism for every command): candidates from the spectral rule on record.q up to
/// min(20 Hz, rate/10); for each, `build` gives the equations, the parameters are fitted on
/// alternate blocks of samples and the others predicted by the equations built at the upper
/// bound, and the lowest held-out error of y wins. A model whose regressor is nonlinear in the
/// motion (products of velocities: Coriolis terms, the load's ω×(ω×c)) is biased by a cut-off
/// near the motion's band, which this measures and the spectral rule does not. `what` names y
/// in the reason ("torque", "wrench"). Returns `signal` unchanged when its cut-off is given or it
/// does not filter; the spectral value when the held-out comparison is not possible.
CutoffSelection select_cutoff_held_out(const JointRecord& record, const SignalOptions& signal,
                                       const CutoffEquationBuilder& build, const std::string& what,
                                       const CutoffSelectionOptions& selection = {});

/// Replaces the `cutoff` entry of `choices` by selection.reason when the cut-off was selected.
void echo_cutoff_selection(const CutoffSelection& selection,
                           std::vector<std::pair<std::string, std::string>>& choices);

}  // namespace dynid
