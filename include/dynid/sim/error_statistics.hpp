#pragma once

#include <Eigen/Core>

namespace dynid {

/// Statistics of an error signal and its distance to a Gaussian (seed 2 §3.5: the error PDF is
/// compared with a Gaussian one). Moments are population (maximum-likelihood) moments.
struct ErrorStatistics {
  long samples = 0;           ///< number of samples N
  double rms = 0.0;           ///< sqrt(Σ e²/N)
  double max_abs = 0.0;       ///< max |e|
  double mean = 0.0;          ///< μ = Σ e/N
  double std = 0.0;           ///< σ = sqrt(Σ (e − μ)²/N)
  double skewness = 0.0;      ///< m3/σ³ (0 for a Gaussian)
  double kurtosis = 0.0;      ///< m4/σ⁴ (3 for a Gaussian; not the excess)
  double ks_statistic = 0.0;  ///< Kolmogorov–Smirnov D = sup |F_N(e) − Φ((e − μ)/σ)|
  double ks_p_value = 1.0;    ///< asymptotic P(D_N > D) for a fully specified normal (Stephens'
                              ///< correction); optimistic here since μ, σ are estimated
                              ///< (Lilliefors) and samples of a run are correlated
};

/// Computes ErrorStatistics of e (size N ≥ 2; allocates a sorted copy). A constant e (σ = 0) gets
/// skewness = kurtosis = 0, ks_statistic = 1 and ks_p_value = 0 (no Gaussian to compare with).
/// Throws dynid::Error if e has fewer than 2 samples or a non-finite value.
ErrorStatistics error_statistics(const Eigen::Ref<const Eigen::VectorXd>& e);

/// Kolmogorov survival function Q_KS(λ) = 2 Σ_{k≥1} (−1)^{k−1} exp(−2k²λ²) (Q(0) = 1).
double kolmogorov_survival(double lambda);

}  // namespace dynid
