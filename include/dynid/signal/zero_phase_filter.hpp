#pragma once

#include <Eigen/Core>

#include "dynid/signal/lowpass_design.hpp"

namespace dynid {

/// Options of the forward–backward (zero-phase) filter.
struct FiltfiltOptions {
  int padding = -1;  ///< odd-reflection samples added at each end; −1 = 3·(2·sections + 1 −
                     ///< min(#b2 = 0, #a2 = 0)), scipy.signal.sosfiltfilt's default (≈ 3·order)
  bool steady_state_initial_conditions = true;  ///< start each pass in the step steady state of
                                                ///< its first (padded) sample (scipy sosfilt_zi)
};

/// Causal filtering of each column of x (samples × channels) through the cascade, Direct Form II
/// transposed per section: y_k = b0·x_k + z1, z1 ← b1·x_k − a1·y_k + z2, z2 ← b2·x_k − a2·y_k.
/// zi (sections × 2) is the initial state per unit input, scaled per column by x(0, c)
/// (empty = zero state). Returns the filtered matrix (same size). No per-sample allocation.
/// Throws dynid::Error if zi has the wrong size.
Eigen::MatrixXd sosfilt(const SosFilter& filter, const Eigen::Ref<const Eigen::MatrixXd>& x,
                        const Eigen::Ref<const Eigen::MatrixXd>& zi = Eigen::MatrixXd());

/// The Direct-Form-II-transposed states (sections × 2) of the cascade in steady state for a unit
/// step input (scipy.signal.sosfilt_zi): section s sees the step scaled by the DC gain of the
/// sections before it, and its states are z2 = b2·u − a2·g·u, z1 = b1·u − a1·g·u + z2 with
/// g = (b0+b1+b2)/(1+a1+a2). Throws dynid::Error if a section has a pole at z = 1.
Eigen::MatrixXd sosfilt_steady_state(const SosFilter& filter);

/// Number of padding samples filtfilt uses by default: 3·(2·sections + 1 − min(#b2=0, #a2=0)).
int filtfilt_default_padding(const SosFilter& filter);

/// Zero-phase filtering of each column of x (samples × channels): odd reflection padding
/// (2·x_0 − x_{p..1} before, 2·x_{m−1} − x_{m−2..m−1−p} after), a forward pass, a backward pass,
/// each started in the steady state of its first sample, then the padding is removed
/// (scipy.signal.sosfiltfilt; Gustafsson's edge problem is reduced, not removed: trim the edges
/// for identification, see trim_edges). Identity: the effective response is |H(e^{jω})|², with no
/// phase lag. This is the "8th-order Chebyshev low-pass" step of seed 2 §3.4.
/// Throws dynid::Error if x has no more than `padding` rows (the message gives the number needed),
/// or contains NaN/Inf.
Eigen::MatrixXd filtfilt(const SosFilter& filter, const Eigen::Ref<const Eigen::MatrixXd>& x,
                         const FiltfiltOptions& options = {});

/// Convenience: design_lowpass(options) then filtfilt of x.
Eigen::MatrixXd lowpass_filtfilt(const LowpassOptions& design,
                                 const Eigen::Ref<const Eigen::MatrixXd>& x,
                                 const FiltfiltOptions& options = {});

}  // namespace dynid
