#pragma once

#include <Eigen/Core>

#include "dynid/excitation/fourier_trajectory.hpp"

namespace dynid {

/// Options of a one-joint Fourier reference (joint_fourier_reference).
struct JointFourierOptions {
  int harmonics = 5;         ///< harmonics N (seed 2 §3.3: 5)
  double f0 = 0.1;           ///< fundamental frequency [Hz]; the period is 1/f0 (seed 2: 0.1 Hz)
  bool rest_at_ends = true;  ///< zero dq, ddq at t = 0 and 1/f0 (project_rest_at_ends)
};

/// A finite Fourier series (seed 2 eqs. 17–19) that moves joint `joint` (0-based) only, over
/// exactly [min(from, to), max(from, to)], while every other joint i stays at pose[i]. The shape
/// is not optimised: x(t) = Σ_{k=1..N} sin(2π k f0 t + φ_k)/k with Schroeder phases
/// φ_k = −π k (k − 1)/N (a flat velocity spectrum, |dq_k| equal for every k, with a low crest
/// factor), projected onto rest at the ends when asked, then scaled and shifted so that its
/// minimum and maximum over one period are the range (docs/methods/excitation.md, "One joint").
/// Units: positions rad or m, like pose. The coefficients have N harmonics for every joint (zero
/// for the held ones), so the spectrum has lines at k·f0, k ≤ N, only.
/// Throws dynid::Error for joint outside 0..pose.size()−1, harmonics < 1, f0 not finite and > 0,
/// from == to or not finite, a non-finite pose, or a series that does not move (harmonics 1 with
/// rest at the ends).
FourierCoefficients joint_fourier_reference(const Eigen::VectorXd& pose, int joint, double from,
                                            double to, const JointFourierOptions& options = {});

}  // namespace dynid
