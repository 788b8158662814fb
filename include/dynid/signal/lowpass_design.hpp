#pragma once

#include <complex>

#include <Eigen/Core>

namespace dynid {

/// Analog prototype of a low-pass design.
enum class LowpassFamily {
  kButterworth,  ///< maximally flat: |H|² = 1/(1+(Ω/Ωc)^(2N))
  kChebyshev1,  ///< equiripple passband: |H|² = 1/(1+ε²·T_N²(Ω/Ωc)), ε² = 10^(ripple/10) − 1
};

/// Specification of a digital IIR low-pass filter (bilinear transform with pre-warping).
struct LowpassOptions {
  LowpassFamily family = LowpassFamily::kButterworth;  ///< analog prototype
  int order = 4;                                       ///< filter order N ≥ 1 (number of poles)
  double cutoff_hz = 10.0;  ///< Butterworth: −3 dB frequency; Chebyshev I: passband edge, where
                            ///< the gain is 1/sqrt(1+ε²) (−ripple dB); 0 < cutoff < rate/2
  double sample_rate_hz = 1000.0;  ///< sample rate of the data the filter is applied to [Hz]
  double ripple_db = 0.5;  ///< Chebyshev I passband ripple [dB] > 0 (ignored by Butterworth)
};

/// A digital filter as a cascade of second-order sections (SOS), one row per section:
/// [b0 b1 b2 a0 a1 a2] with a0 = 1, H(z) = Π_s (b0 + b1 z⁻¹ + b2 z⁻²)/(1 + a1 z⁻¹ + a2 z⁻²).
/// A first-order section has b2 = a2 = 0. Same layout as scipy.signal's `sos` arrays.
struct SosFilter {
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> sos;  ///< sections × 6

  /// Number of sections.
  int sections() const { return static_cast<int>(sos.rows()); }
  /// Filter order (number of poles): 2 per section minus the first-order sections.
  int order() const;
};

/// Designs a digital low-pass filter as cascaded second-order sections. The analog prototype poles
/// (Butterworth: p_k = Ωc·exp(jπ(2k+N−1)/(2N)); Chebyshev I: p_k = Ωc·(−sinh μ·sin θ_k +
/// j·cosh μ·cos θ_k), μ = asinh(1/ε)/N, θ_k = π(2k−1)/(2N)) are placed at the pre-warped cut-off
/// Ωc = 2·fs·tan(π·fc/fs) and mapped by the bilinear transform z = (2fs + s)/(2fs − s); all zeros
/// are at z = −1. Conjugate pairs become second-order sections, each normalised to unit DC gain;
/// the overall DC gain is 1 (Chebyshev I with even N: 1/sqrt(1+ε²), the bottom of the ripple).
/// Identity: |H(e^{jω})| = |H_a(j·2fs·tan(ω/2))| with the analytic |H_a| of LowpassFamily.
/// Used with filtfilt as the zero-phase filter of seed 2 §3.4 (8th-order Chebyshev, 80 Hz).
/// Throws dynid::Error for order < 1, sample rate ≤ 0, cut-off ≤ 0 or ≥ Nyquist, ripple ≤ 0.
SosFilter design_lowpass(const LowpassOptions& options);

/// design_lowpass rescaled to a DC gain of exactly 1 (the first section's numerator divided by the
/// product of the sections' DC gains): identification filters every signal, and an even-order
/// Chebyshev I design would scale them all by 1/sqrt(1+ε²) (q enters the model non-linearly).
/// Identity: H(1) = 1. Throws as design_lowpass.
SosFilter design_lowpass_unit_dc(const LowpassOptions& options);

/// Complex frequency response H(e^{j·2π·f/fs}) of the filter at frequency f [Hz] for sample rate
/// fs [Hz] (evaluates the sections directly; no allocation).
std::complex<double> frequency_response(const SosFilter& filter, double frequency_hz,
                                        double sample_rate_hz);

}  // namespace dynid
